"""URDF export: every built-in arm round-trips through URDF with the same FK and
limits; pinocchio reads what we write; geometry and dependent joints survive."""

import math
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
import pytest

import robokin
from robokin.io.urdf_export import urdf_from_robot
from robokin.spatial import rotx, trans

pytest.importorskip("yourdfpy")
from robokin import Robot  # noqa: E402

DATA = Path(__file__).parent.parent / "data" / "urdf"


def random_q(robot, rng, m=50):
    lim = np.clip(robot.limits, -4.0, 4.0)
    return rng.uniform(lim[:, 0], lim[:, 1], (m, robot.n))


@pytest.mark.parametrize("name", robokin.robots.names())
def test_every_builtin_arm_round_trips(name, rng):
    robot = robokin.load(name)
    back = Robot.from_urdf(urdf_from_robot(robot))
    assert back.joint_names == robot.joint_names
    np.testing.assert_array_equal(back.limits, robot.limits)
    np.testing.assert_array_equal(back.is_revolute, robot.is_revolute)
    q = random_q(robot, rng)
    np.testing.assert_allclose(back.fk(q), robot.fk(q), rtol=0, atol=1e-12)


def test_base_and_tool_transforms_survive(rng):
    robot = robokin.load("aubo_i5").with_base(trans(1, 2, 0.5) @ rotx(0.3)).with_tool(
        trans(0, 0, 0.12) @ rotx(math.pi / 2))
    text = urdf_from_robot(robot)
    root = ET.fromstring(text)
    assert root.find("joint[@name='world_to_base']/parent").get("link") == "world"
    assert root.find("link[@name='tool0']") is not None
    back = Robot.from_urdf(text)
    q = random_q(robot, rng)
    np.testing.assert_allclose(back.fk(q), robot.fk(q), atol=1e-12)


@pytest.mark.parametrize("name", ["ur5", "aubo_i5", "panda", "scara", "improved_dh_arm"])
def test_pinocchio_reads_the_export(name, rng):
    pin = pytest.importorskip("pinocchio")
    robot = robokin.load(name)
    model = pin.buildModelFromXML(urdf_from_robot(robot))
    data = model.createData()
    for qi in random_q(robot, rng, 10):
        qp = pin.neutral(model)
        for jname, v in zip(robot.joint_names, qi):
            j = model.joints[model.getJointId(jname)]
            if j.nq == 1:
                qp[j.idx_q] = v
            else:  # continuous: (cos, sin)
                qp[j.idx_q], qp[j.idx_q + 1] = math.cos(v), math.sin(v)
        pin.framesForwardKinematics(model, data, qp)
        T = data.oMf[model.getFrameId("tool0")].homogeneous
        np.testing.assert_allclose(T, robot.fk(qi), atol=1e-12)


def test_reversed_joint_and_offsets_are_written_as_urdf_expects(rng):
    rows = [
        {"name": "a", "a": 0.3, "alpha": 0.5, "d": 0.2, "theta": 0.4, "sign": -1,
         "limits": [-1, 2]},
        {"name": "b", "joint": "prismatic", "a": 0.1, "alpha": -0.7, "d": 0.3,
         "theta": 0.2, "sign": -1, "limits": [0, 0.5]},
        {"name": "c", "a": 0.0, "alpha": 0.0, "d": 0.1, "theta": -0.3},
    ]
    robot = robokin.Robot.from_dh(rows, "modified")
    text = urdf_from_robot(robot)
    root = ET.fromstring(text)
    # a reversed revolute joint turns about -z; its zero offset is in the origin
    axis = [float(v) for v in root.find("joint[@name='a']/axis").get("xyz").split()]
    assert axis == [0.0, 0.0, -1.0]
    assert root.find("joint[@name='c']").get("type") == "continuous"
    assert root.find("joint[@name='b']").get("type") == "prismatic"
    back = Robot.from_urdf(text)
    q = random_q(robot, rng)
    np.testing.assert_allclose(back.fk(q), robot.fk(q), atol=1e-12)
    # modified DH: the URDF child link frames are the DH link frames
    np.testing.assert_allclose(back.fk_all(q), robot.fk_all(q), atol=1e-12)
    np.testing.assert_array_equal(back.limits[:2], robot.limits[:2])
    # continuous where a revolute joint is unlimited, mandatory <limit> attributes
    for j in root.findall("joint"):
        if j.get("type") in ("revolute", "prismatic"):
            lim = j.find("limit")
            assert {"lower", "upper", "effort", "velocity"} <= set(lim.attrib)


def test_dependent_joints_become_mimic_joints(rng):
    robot = robokin.load("qfmd010")
    root = ET.fromstring(urdf_from_robot(robot))
    level = root.find("joint[@name='level']/mimic")
    assert level.get("joint") == "theta3" and float(level.get("multiplier")) == -1.0
    # forearm = theta3 - theta2: two coaxial mimic joints
    assert root.find("joint[@name='forearm_theta2']/mimic").get("joint") == "theta2"
    assert root.find("joint[@name='forearm_theta3']/mimic").get("joint") == "theta3"
    # theta3 drives no chain joint of its own: a zero-length master joint
    assert root.find("joint[@name='theta3']/child").get("link") == "theta3_coordinate"


def test_imported_robot_exports_its_link_frames_and_geometry(rng):
    pytest.importorskip("trimesh")
    robot = Robot.from_urdf(DATA / "industrial6.urdf")
    again = Robot.from_urdf(urdf_from_robot(robot))
    assert again.meta["urdf"].child_links == robot.meta["urdf"].child_links
    q = random_q(robot, rng, 10)
    np.testing.assert_allclose(again.fk_all(q), robot.fk_all(q), atol=1e-12)
    ur5 = Robot.from_urdf(DATA / "ur5.urdf", missing_mesh="ignore")
    back = Robot.from_urdf(urdf_from_robot(ur5))
    for a, b in zip(ur5.geometry.shapes, back.geometry.shapes):
        assert [s.kind for s in a] == [s.kind for s in b]
        for s1, s2 in zip(a, b):
            assert s1.size == s2.size
            np.testing.assert_allclose(s1.placement, s2.placement, atol=1e-12)


def test_capsules_export_as_cylinder_and_spheres():
    from robokin.model import geometry as geo

    robot = robokin.load("ur5")
    g = geo.RobotGeometry.from_mapping(
        robot, {"elbow": [geo.capsule_between([0, 0, 0], [0.3, 0, 0], 0.05)]})
    root = ET.fromstring(urdf_from_robot(robot.replace(geometry=g)))
    link = root.find("link[@name='elbow_link']")
    kinds = [el[0].tag for el in link.iter("geometry")]
    assert kinds.count("cylinder") == 2 and kinds.count("sphere") == 4
