"""DH tables derived from URDF arms and from any robot."""

import math
from pathlib import Path

import numpy as np
import pytest

import robokin
from robokin.exceptions import InputError
from robokin.io.dh_extract import dh_from_robot, dh_rows_for_transform
from robokin.spatial import rotx, roty, rotz, trans

DATA = Path(__file__).parent.parent / "data" / "urdf"


def random_q(robot, rng, m=30):
    lim = np.clip(robot.limits, -3.0, 3.0)
    return rng.uniform(lim[:, 0], lim[:, 1], (m, robot.n))


def test_ur5_urdf_gives_urs_published_table():
    pytest.importorskip("yourdfpy")
    from robokin.io.urdf import dh_from_urdf

    ext = dh_from_urdf(DATA / "ur5.urdf")
    # Universal Robots' table, as in src/robokin/robots/ur5.yaml (mm, deg there)
    import yaml

    doc = yaml.safe_load((Path(robokin.__file__).parent / "robots" / "ur5.yaml").read_text())
    for row, pub in zip(ext.rows, doc["joints"], strict=True):
        assert row["joint"] == "revolute"
        np.testing.assert_allclose(
            [row["a"] * 1e3, row["d"] * 1e3, math.degrees(row["alpha"]),
             math.degrees(row["theta"])],
            [pub["a"], pub["d"], pub["alpha"], pub["theta"]], atol=1e-9)
    # what remains is ROS-Industrial's base_link -> base turn, and no tool
    np.testing.assert_allclose(ext.base, rotz(math.pi), atol=1e-12)
    np.testing.assert_allclose(ext.tool, np.eye(4), atol=1e-12)
    assert ext.needs_virtual_frames
    assert any("parallel" in n for n in ext.notes)


def test_modified_table_of_the_ur5_urdf_is_the_shifted_standard_one(rng):
    pytest.importorskip("yourdfpy")
    from robokin.io.urdf import dh_from_urdf

    std = dh_from_urdf(DATA / "ur5.urdf")
    mod = dh_from_urdf(DATA / "ur5.urdf", convention="modified")
    for i, row in enumerate(mod.rows):
        prev = std.rows[i - 1] if i else {"a": 0.0, "alpha": 0.0}
        assert (row["a"], row["alpha"]) == (prev["a"], prev["alpha"])
        assert (row["d"], row["theta"]) == (std.rows[i]["d"], std.rows[i]["theta"])
    urdf = robokin.Robot.from_urdf(DATA / "ur5.urdf", geometry=False)
    q = random_q(urdf, rng)
    np.testing.assert_allclose(robokin.Robot(mod.chain()).fk(q), urdf.fk(q), atol=1e-12)


def test_panda_urdf_gives_frankas_modified_table():
    pytest.importorskip("yourdfpy")
    from robokin.io.urdf import dh_from_urdf

    ext = dh_from_urdf(DATA / "panda.urdf", tip_link="panda_link8",
                       convention="modified")
    ref = [dict(r) for r in robokin.load("panda").meta["document"]["joints"][:7]]
    # frame 7 sits at the foot of the tool point: Franka's 0.107 m flange row
    # becomes d7 (as UR's d6 carries their flange) and no tool remains
    ref[6]["d"] = 0.107
    for row, pub in zip(ext.rows, ref, strict=True):
        np.testing.assert_allclose(
            [row["a"], row["alpha"], row["d"], row["theta"]],
            [pub["a"], pub["alpha"], pub["d"], pub["theta"]], atol=1e-12)
    np.testing.assert_allclose(ext.tool, np.eye(4), atol=1e-12)
    np.testing.assert_allclose(ext.base, np.eye(4), atol=1e-12)


@pytest.mark.parametrize("name", robokin.robots.names())
@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_every_builtin_arm_has_a_table_with_the_same_fk(name, convention, rng):
    robot = robokin.load(name)
    for virtual in (False, True):
        ext = dh_from_robot(robot, convention, virtual_frames=virtual)
        q = random_q(robot, rng)
        np.testing.assert_allclose(robokin.Robot(ext.chain()).fk(q), robot.fk(q), atol=1e-12)
        if virtual:
            np.testing.assert_array_equal(ext.base, np.eye(4))
            np.testing.assert_array_equal(ext.tool, np.eye(4))
            assert bool(ext.virtual_frames) == ext.needs_virtual_frames
        assert all(r.get("sign", 1) == 1 for r in ext.rows)


def test_a_standard_table_gives_itself_back():
    # Puma 560 (Corke): no offsets, frame 0 at the base
    robot = robokin.load("puma560")
    ext = dh_from_robot(robot)
    ref = robot.meta["document"]["joints"]
    for row, pub in zip(ext.rows, ref, strict=True):
        np.testing.assert_allclose(
            [row["a"], row["d"], math.degrees(row["alpha"]), math.degrees(row["theta"])],
            [pub["a"], pub["d"], pub["alpha"], pub["theta"]], atol=1e-9)
    assert not ext.needs_virtual_frames


def test_dependent_joints_keep_their_coupling(rng):
    robot = robokin.load("qfmd010")
    ext = dh_from_robot(robot)
    forearm = next(r for r in ext.rows if r["name"] == "forearm")
    assert forearm["depends"] == {"theta2": -1.0, "theta3": 1.0}
    assert [c["name"] for c in ext.coordinates] == ["theta1", "theta2", "theta3", "theta4"]
    q = random_q(robot, rng)
    np.testing.assert_allclose(robokin.Robot(ext.chain()).fk(q), robot.fk(q), atol=1e-12)


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_virtual_frame_rows_for_any_transform(convention, rng):
    from robokin.kinematics.forward import forward_kinematics
    from robokin.model.dh import chain_from_dh

    for T, count in [
        (np.eye(4), 0),
        (rotz(0.3) @ trans(0, 0, 0.2) @ trans(0.1, 0, 0) @ rotx(-0.4), 1),
        (trans(0.1, -0.2, 0.3) @ roty(0.5) @ rotz(0.2) @ rotx(0.7), 2),
    ]:
        rows = dh_rows_for_transform(T, convention)
        assert len(rows) == count if convention == "standard" else len(rows) <= 2
        table = [{"joint": "fixed", "theta": r[0], "d": r[1], "a": r[2], "alpha": r[3]}
                 for r in rows]
        table.append({"name": "j", "a": 0, "alpha": 0, "d": 0, "theta": 0})
        chain = chain_from_dh(table, convention)
        np.testing.assert_allclose(forward_kinematics(chain, np.zeros(1)), T, atol=1e-12)


def test_bad_convention_is_an_input_error():
    with pytest.raises(InputError, match="expected 'standard' or 'modified'"):
        dh_from_robot(robokin.load("ur5"), "craig")
