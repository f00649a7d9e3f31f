"""The links a URDF hangs on the chain (issue 26): a gripper's tree below the tip joins
the tool (fingers frozen at their defaults, mimics followed), a camera on a middle
link stays on that link. Oracles: a hand-written product of the URDF's transforms,
and pinocchio's own URDF parser (its geometry placements oMg)."""

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from robokin.exceptions import InputError
from robokin.kinematics.forward import link_frames

pytest.importorskip("yourdfpy")
from robokin import Robot  # noqa: E402

DATA = Path(__file__).parent.parent / "data" / "urdf"
URDF = DATA / "gripper_arm.urdf"


def T(x=0.0, y=0.0, z=0.0):
    out = np.eye(4)
    out[:3, 3] = (x, y, z)
    return out


def R(axis, angle):
    c, s = math.cos(angle), math.sin(angle)
    out = np.eye(4)
    i, j = {"x": (1, 2), "y": (2, 0), "z": (0, 1)}[axis]
    out[i, i], out[i, j], out[j, i], out[j, j] = c, -s, s, c
    return out


def hand_pose(q):
    """The hand frame in the base frame: the URDF's origins and joints, by hand."""
    q1, q2, q3 = q
    return (T(z=0.1) @ R("z", q1) @ T(z=0.3) @ R("x", 0.2) @ R("y", q2)
            @ T(x=0.4) @ R("y", -q3) @ T(x=0.3) @ R("y", math.pi / 2)
            @ T(z=0.01) @ R("z", -math.pi / 4))


def world_shapes(robot, q, link):
    F = link_frames(robot.chain, q)
    k = robot.geometry.index(link)
    return [F[k] @ s.placement for s in robot.geometry.shapes[k]]


def pin_shapes(q, values, links):
    """oMg of the geometry objects of ``links`` from pinocchio's URDF parser."""
    pin = pytest.importorskip("pinocchio")
    model = pin.buildModelFromUrdf(str(URDF))
    geom = pin.buildGeomFromUrdf(model, str(URDF), pin.GeometryType.COLLISION)
    data, gdata = model.createData(), pin.GeometryData(geom)
    qq = pin.neutral(model)
    for name, v in {**dict(zip(("joint_1", "joint_2", "joint_3"), q)), **values}.items():
        qq[model.joints[model.getJointId(name)].idx_q] = v
    pin.updateGeometryPlacements(model, data, geom, gdata, qq)
    return [gdata.oMg[i].homogeneous for i, o in enumerate(geom.geometryObjects)
            if model.frames[o.parentFrame].name in links]


def assert_same_poses(ours, ref):
    assert len(ours) == len(ref)
    for P in ours:
        assert min(np.abs(P - Q).max() for Q in ref) < 1e-12


def test_gripper_tree_joins_the_tool_with_fingers_at_their_defaults(rng):
    robot = Robot.from_urdf(URDF, tip_link="tcp")
    info = robot.meta["urdf"]
    # the tool: everything rigid with the last link but the last link itself
    tool = {"flange", "hand", "tcp", "finger_left", "finger_right", "wrist_cam"}
    assert {k for k, v in info.owners.items() if v == "tool"} == tool
    assert info.owners["link_3"] == "joint_3"
    assert info.dropped_links == ()
    # 0 clamped into [0.01, 0.04]; the mimic follows: 1 * 0.01 + 0.005
    assert info.tool_joints == {"finger_left_joint": 0.01, "finger_right_joint": 0.015,
                                "wrist_cam_joint": 0.0}
    assert info.parts()["tool"] == ("finger_left", "finger_right", "hand", "wrist_cam")
    for q in [np.zeros(3), np.array([math.pi / 2, -math.pi / 2, 1e-9]),
              *rng.uniform(-2, 2, (4, 3))]:
        H = hand_pose(q)
        # oracle 1: the hand-written product, shape by shape
        left = H @ T(z=0.06) @ T(y=0.01) @ T(0, 0.01, 0.025)
        right = H @ T(z=0.06) @ T(y=-0.015) @ T(0, -0.01, 0.025)
        cam = H @ T(0.03, 0, 0.02) @ R("x", 0.1) @ T(x=0.03)
        body = H @ T(z=0.03)
        assert_same_poses(world_shapes(robot, q, "tool"), [body, left, right, cam])
        # oracle 2: pinocchio, the fingers at the same positions
        assert_same_poses(world_shapes(robot, q, "tool"),
                          pin_shapes(q, info.tool_joints, tool))
        # the TCP is the tool frame
        np.testing.assert_allclose(robot.fk(q), H @ T(z=0.1), atol=1e-12)


def test_a_camera_on_a_middle_link_stays_on_that_link(rng):
    robot = Robot.from_urdf(URDF, tip_link="tcp")
    assert robot.meta["urdf"].owners["camera"] == "joint_2"
    assert len(robot.geometry.link("joint_2")) == 3  # link_2, the mount, the camera
    for q in rng.uniform(-2, 2, (5, 3)):
        assert_same_poses(world_shapes(robot, q, "joint_2"),
                          pin_shapes(q, {}, {"link_2", "camera_mount", "camera"}))


def test_tool_joints_choose_the_fingers_positions(rng):
    robot = Robot.from_urdf(URDF, tip_link="tcp",
                            tool_joints={"finger_left_joint": 0.04, "wrist_cam_joint": -1})
    info = robot.meta["urdf"]
    assert info.tool_joints == {"finger_left_joint": 0.04, "finger_right_joint": 0.045,
                                "wrist_cam_joint": -1.0}
    q = rng.uniform(-2, 2, 3)
    tool = {"hand", "finger_left", "finger_right", "wrist_cam"}
    assert_same_poses(world_shapes(robot, q, "tool"), pin_shapes(q, info.tool_joints, tool))


@pytest.mark.parametrize("values, match", [
    ({"joint_2": 0.1}, "not a joint below the tip.*finger_left_joint, wrist_cam_joint"),
    ({"finger_right_joint": 0.02}, "mimics 'finger_left_joint'"),
    ({"finger_left_joint": 0.05}, r"in its limits \[0.01, 0.04\]"),
    ({"finger_left_joint": math.nan}, "finite number"),
    ({"wrist_cam_joint": "abc"}, "finite number"),
])
def test_bad_tool_joints_are_refused_by_name(values, match):
    with pytest.raises(InputError, match=match) as err:
        Robot.from_urdf(URDF, tip_link="tcp", tool_joints=values)
    assert err.value.argument == "tool_joints"


def test_a_tool_joint_that_mimics_the_arm_is_left_out_with_a_warning():
    xml = URDF.read_text().replace(
        '<limit lower="-1" upper="1" effort="1" velocity="1"/>\n  </joint>',
        '<limit lower="-1" upper="1" effort="1" velocity="1"/>\n'
        '    <mimic joint="joint_1"/>\n  </joint>')
    assert "<mimic joint=\"joint_1\"/>" in xml
    with pytest.warns(UserWarning, match="wrist_cam_joint.*mimics the arm's joint 'joint_1'"):
        robot = Robot.from_urdf(xml, tip_link="tcp")
    assert "wrist_cam" in robot.meta["urdf"].dropped_links
    assert "wrist_cam" not in robot.meta["urdf"].owners


def test_without_a_gripper_tree_nothing_changes():
    """The tip's own fixed links still move with it; no joint is frozen."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        robot = Robot.from_urdf(DATA / "industrial6.urdf")
    assert robot.meta["urdf"].tool_joints == {}
