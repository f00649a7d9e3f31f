"""Build peer-library models (roboticstoolbox-python, pinocchio) from a robokin robot.

Both are built from the robot's canonical chain (constants, joint signs, offsets), so
all three libraries evaluate the same kinematics; the benchmarks check the poses
agree to 1e-9 before timing anything. Used only by ``benchmarks/``.
"""

from __future__ import annotations

import numpy as np

from robokin.spatial import rotz


def _constants(robot):
    """Per-joint placements P_k (offset folded in) and the final constant, canonical form."""
    chain = robot.chain
    if not chain.coupling.is_identity:
        raise ValueError("peer models need a chain without dependent joints")
    consts = chain.arrays.consts
    placements = []
    for k, j in enumerate(chain.joints):
        P = consts[k].copy()
        if j.kind == "revolute":
            P = P @ rotz(j.offset)
        else:
            P[:3, 3] += P[:3, 2] * j.offset
        placements.append(P)
    return placements, consts[-1]


def rtb_ets(robot):
    """A roboticstoolbox ETS with the robot's kinematics."""
    import roboticstoolbox as rtb
    from spatialmath import SE3

    placements, last = _constants(robot)
    ets = rtb.ETS()
    for P, j in zip(placements, robot.chain.joints):
        if not np.allclose(P, np.eye(4)):
            ets *= rtb.ET.SE3(SE3(P, check=False))
        flip = j.sign < 0
        ets *= rtb.ET.Rz(flip=flip) if j.kind == "revolute" else rtb.ET.tz(flip=flip)
    ets *= rtb.ET.SE3(SE3(last, check=False))
    return ets


def pinocchio_model(robot):
    """A pinocchio (model, data, tool_frame_id) with the robot's kinematics."""
    import pinocchio as pin

    placements, last = _constants(robot)
    model = pin.Model()
    parent = 0
    for P, j in zip(placements, robot.chain.joints):
        axis = np.array([0.0, 0.0, j.sign])
        if j.kind == "revolute":
            jm = (
                pin.JointModelRZ()
                if j.sign > 0
                else pin.JointModelRevoluteUnaligned(axis)
            )
        else:
            jm = (
                pin.JointModelPZ()
                if j.sign > 0
                else pin.JointModelPrismaticUnaligned(axis)
            )
        placement = pin.SE3(P[:3, :3].copy(), P[:3, 3].copy())
        parent = model.addJoint(parent, jm, placement, j.name)
    tool = pin.Frame(
        "tool",
        parent,
        0,
        pin.SE3(last[:3, :3].copy(), last[:3, 3].copy()),
        pin.FrameType.OP_FRAME,
    )
    fid = model.addFrame(tool)
    return model, model.createData(), fid
