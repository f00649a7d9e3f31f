"""Inertial data (issue 17, item 2): robot files, URDF, estimates, strict mode."""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml

import robokin
from robokin.io.robot_files import document_from_robot, load_parts, parts_from_document
from robokin.model.dynamics import (
    LinkInertia,
    RobotDynamics,
    estimate_link,
    resolve_links,
)
from robokin.model.geometry import box, capsule, link_names


def _random_dynamics(robot, seed=0):
    rng = np.random.default_rng(seed)
    links = {}
    for name in link_names(robot)[1:-1]:
        A = rng.normal(size=(3, 3))
        links[name] = LinkInertia(rng.uniform(0.5, 3.0), rng.normal(size=3) * 0.1,
                                  A @ A.T * 0.01)
    limits = np.arange(1, robot.n + 1) * 10.0
    return RobotDynamics.from_mapping(robot, links, torque_limits=limits, source="test")


def _world(robot, q):
    """Every link's data in the world frame at q (frames differ between models)."""
    return [lk.moved(F) for lk, F in zip(robot.dynamics.links, robot.fk_all(q))
            if lk is not None]


@pytest.mark.parametrize("name", ["ur5", "panda", "scara", "improved_dh_arm", "puma560"])
def test_inertial_data_round_trips_through_urdf(name):
    robot = robokin.load(name)
    robot = robot.replace(dynamics=_random_dynamics(robot))
    back = robokin.Robot.from_urdf(robot.to_urdf())
    assert "<inertial>" in robot.to_urdf()
    np.testing.assert_array_equal(back.dynamics.torque_limits, robot.dynamics.torque_limits)
    q = np.random.default_rng(1).uniform(-1, 1, robot.n)
    q = np.clip(q, robot.limits[:, 0], robot.limits[:, 1])
    for a, b in zip(_world(robot, q), _world(back, q)):
        assert a.mass == pytest.approx(b.mass, abs=1e-12)
        np.testing.assert_allclose(a.com, b.com, atol=1e-12)
        np.testing.assert_allclose(a.inertia, b.inertia, atol=1e-12)


def test_inertial_data_round_trips_through_robot_files(tmp_path):
    robot = robokin.load("ur5")
    changed = robot.replace(dynamics=_random_dynamics(robot, 3), name="ur5_copy")
    path = robokin.save(changed, tmp_path / "copy.yaml")
    back = load_parts(path)
    for a, b in zip(changed.dynamics.links, back.dynamics.links):
        if a is None:
            assert b is None
            continue
        assert a.mass == pytest.approx(b.mass, rel=1e-15)
        np.testing.assert_allclose(a.com, b.com, atol=1e-15)
        np.testing.assert_allclose(a.inertia, b.inertia, atol=1e-15)
    np.testing.assert_array_equal(back.dynamics.torque_limits,
                                  changed.dynamics.torque_limits)
    # a file loaded unchanged writes its own section back, units kept
    doc = document_from_robot(robokin.load("ur5"))
    assert doc["dynamics"]["links"]["shoulder_pan"]["mass"] == 3.7


def test_dynamics_section_declared_units_and_rpy():
    doc = yaml.safe_load(robokin.robots.path("scara").read_text())
    doc["dynamics"] = {"units": {"length": "mm", "mass": "g"}, "links": {
        "elbow": {"mass": 2000, "com": [-100, 0, 0], "inertia": [1e4, 2e4, 3e4, 0, 0, 0],
                  "rpy": [0, 0, 90]}}}
    lk = parts_from_document(doc).dynamics.link("elbow")
    assert lk.mass == 2.0
    np.testing.assert_allclose(lk.com, [-0.1, 0, 0])
    # 1e4 g mm^2 = 1e-5 kg m^2; the tensor's axes turned 90 deg about z
    np.testing.assert_allclose(np.diag(lk.inertia), [2e-5, 1e-5, 3e-5], atol=1e-18)


@pytest.mark.parametrize("bad, field", [
    ({"links": {"elbow": {"mass": -1.0}}}, "dynamics.links.elbow.mass"),
    ({"links": {"nope": {"mass": 1.0}}}, "dynamics.links.nope"),
    ({"links": {"elbow": {"mass": 1.0, "inertia": [1, 1, 1, 0, 0, 5.0]}}},
     "dynamics.links.elbow.inertia"),
    ({"torque_limits": {"nope": 3.0}}, "dynamics.torque_limits.nope"),
    ({"links": {"elbow": {"mass": "3"}}}, "dynamics.links.elbow.mass"),
])
def test_dynamics_section_errors_name_the_field(bad, field):
    doc = yaml.safe_load(robokin.robots.path("scara").read_text())
    doc["dynamics"] = bad
    with pytest.raises(robokin.ModelError) as exc:
        parts_from_document(doc, file="scara.yaml")
    assert exc.value.field == field


def test_estimate_from_shapes_matches_closed_forms():
    # a box: m = rho V, I = m (b^2 + c^2) / 12 ...
    b = estimate_link([box((0.1, 0.2, 0.3), np.eye(4))], 1000.0)
    m = 1000.0 * 0.1 * 0.2 * 0.3
    assert b.mass == pytest.approx(m)
    np.testing.assert_allclose(np.diag(b.inertia),
                               m / 12 * np.array([0.04 + 0.09, 0.01 + 0.09, 0.01 + 0.04]))
    # two shapes combine about their common centre of mass
    T = np.eye(4)
    T[:3, 3] = [1.0, 0, 0]
    two = estimate_link([box((0.1, 0.1, 0.1)), box((0.1, 0.1, 0.1), T)], 1000.0)
    np.testing.assert_allclose(two.com, [0.5, 0, 0])
    assert two.inertia[2, 2] == pytest.approx(2 * (1.0 * 0.02 / 12 + 1.0 * 0.25))
    # a capsule's trimesh volume is within 1 % of pi r^2 (L + 4 r / 3)
    c = estimate_link([capsule(0.05, 0.4)], 1000.0)
    assert c.mass == pytest.approx(1000 * math.pi * 0.05**2 * (0.4 + 4 * 0.05 / 3),
                                   rel=0.01)


def test_missing_data_is_estimated_and_said_so():
    links = resolve_links(robokin.load("scara"))
    assert links.origin[1:4] == ("estimated", "estimated", "none")
    assert "ESTIMATED" in links.describe()
    assert "rotate" in links.describe()  # no data and no shapes
    ur5 = resolve_links(robokin.load("ur5"))
    assert set(ur5.origin[1:-1]) == {"data"}


def test_strict_mode_refuses_missing_data_naming_the_field():
    with pytest.raises(robokin.ModelError, match="no mass data") as exc:
        resolve_links(robokin.load("qfmd010"), strict=True)
    assert exc.value.field == "dynamics.links.theta1"
    resolve_links(robokin.load("panda"), strict=True)  # complete data passes


def test_link_inertia_checks_its_input():
    with pytest.raises(robokin.InputError, match="mass"):
        LinkInertia(-1.0)
    with pytest.raises(robokin.InputError, match="symmetric"):
        LinkInertia(1.0, np.zeros(3), [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]])
    with pytest.raises(robokin.InputError, match="inertia"):
        LinkInertia.from_moments(1.0, np.zeros(3), [1, 2, 3])


def test_builtin_arms_carry_a_source():
    for name in robokin.robots.names():
        dyn = robokin.load(name).dynamics
        assert dyn is not None and dyn.source, name
