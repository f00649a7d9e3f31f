"""Re-framing keeps the forward kinematics exactly and the link frames near nominal.

Oracles: the input chain's own FK; the nominal chain's link frames.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import robokin
from robokin.calibration import synthetic
from robokin.calibration._frames import frames_at_zero, reframe
from robokin.exceptions import ModelError

from .conftest import TOOL, TRACKER, irb140


@pytest.mark.parametrize("name", ["ur5", "aubo_i5", "puma560_modified", "panda",
                                  "scara", "qfmd010", "improved_dh_arm", "irb140"])
def test_reframe_onto_itself_is_the_same_chain(name):
    robot = irb140() if name == "irb140" else robokin.load(name)
    c = reframe(robot.chain, robot.chain)
    q = synthetic.random_configurations(robot, np.random.default_rng(1), 30)
    np.testing.assert_allclose(robot.replace(chain=c).fk(q), robot.fk(q), atol=1e-12)
    np.testing.assert_allclose(robot.replace(chain=c).fk_all(q), robot.fk_all(q),
                               atol=1e-12)


@pytest.mark.parametrize("name", ["ur5", "aubo_i5", "panda", "scara", "qfmd010"])
def test_perturbed_robot_keeps_link_frames_near_nominal(name):
    robot = robokin.load(name)
    true = synthetic.perturb(robot, np.random.default_rng(2)).robot
    q = synthetic.random_configurations(robot, np.random.default_rng(3), 30)
    # 0.5 mm / 0.05 deg errors: link frames within a few mm of the nominal ones
    d = np.abs(true.fk_all(q)[..., :3, 3] - robot.fk_all(q)[..., :3, 3]).max()
    assert d < 5e-3
    W, _ = frames_at_zero(true.chain)
    Wn, _ = frames_at_zero(robot.chain)
    assert np.abs(W[:, :3, 3] - Wn[:, :3, 3]).max() < 5e-3


def test_reframe_refuses_different_joints():
    with pytest.raises(ModelError, match="same joints"):
        reframe(robokin.load("ur5").chain, robokin.load("panda").chain)


def test_calibrated_robot_keeps_names_geometry_and_limits(ur5):
    from robokin import calibration

    from .conftest import make_case
    case = make_case(ur5, "position", n=80, hold=0, seed=3)
    res = calibration.calibrate(ur5, case.q, case.measured)
    r = res.robot
    assert r.joint_names == ur5.joint_names
    np.testing.assert_array_equal(r.limits, ur5.limits)
    assert r.geometry is ur5.geometry and r.dynamics is ur5.dynamics
    # base = measuring frame -> robot base, tool = flange -> TCP
    np.testing.assert_allclose(r.base[:3, 3], TRACKER[:3, 3], atol=1e-4)
    np.testing.assert_allclose(r.tool[:3, 3], TOOL[:3, 3], atol=1e-4)
    assert math.isfinite(res.residual_rms)


@pytest.mark.parametrize("name", ["ur5", "puma560_modified", "panda", "scara",
                                  "irb140"])
def test_joint_frames_are_the_compiled_chain_at_rest(name):
    """Oracle: the compiled kernels (robot.fk and robot.jacobian, chain.h), with a base
    and a tool on the robot: ``B @ tip @ T_tool`` is the tool pose at q = 0 and each
    frame's z axis (times the joint's sign) is the Jacobian's angular column there
    (linear, for a prismatic joint);
    joint_frames is the same walk with every joint motion the identity (issue 24:
    one chain walk, the model's Chain.frames_at)."""
    from robokin.calibration._frames import joint_frames

    robot = irb140() if name == "irb140" else robokin.load(name)
    base = robokin.spatial.pose_from_xyz_rpy([0.1, -0.2, 0.3], [0.2, -0.1, 0.4])
    robot = robot.with_base(base).with_tool(TOOL)
    chain = robot.chain
    if not chain.coupling.is_identity:
        pytest.skip("the Jacobian columns are per coordinate, not per chain joint")
    signs = np.array([j.sign for j in chain.joints])
    for q, frames in (
            (np.zeros(robot.n), frames_at_zero(chain)),
            (-np.array([j.offset for j in chain.joints]) * signs,
             (joint_frames(chain), None))):
        W, tip = frames
        if tip is not None:
            np.testing.assert_allclose(base @ tip @ chain.tool, robot.fk(q), atol=1e-12)
        axes = np.einsum("ij,kj->ki", base[:3, :3], W[:, :3, 2]) * signs[:, None]
        J = robot.jacobian(q)
        columns = np.where(robot.is_revolute[:, None], J[3:].T, J[:3].T)  # prismatic: v
        np.testing.assert_allclose(axes, columns, atol=1e-12)
