"""Family detection from the canonical chain's geometry."""

import math

import numpy as np
import pytest

import robokin
from robokin.exceptions import InputError


@pytest.mark.parametrize(
    ("name", "family"),
    [("ur5", "three_parallel"), ("aubo_i5", "three_parallel"),
     ("puma560", "spherical_wrist"), ("puma560_modified", "spherical_wrist"),
     ("scara", "scara"), ("qfmd010", "palletizer"),
     ("panda", "none"), ("improved_dh_arm", "none")],
)
def test_every_builtin_arm_gets_its_family(name, family):
    fam = robokin.ik.family(robokin.load(name))
    assert fam.name == family
    assert (fam.solver is None) == (family == "none")
    assert not fam.near
    if family == "none":
        assert "closed forms cover" in fam.reason


def test_detection_is_cached_per_chain():
    robot = robokin.load("ur5")
    assert robokin.ik.family(robot) is robokin.ik.family(robot)


def test_analytic_forced_on_arm_without_closed_form_raises():
    robot = robokin.load("panda")
    with pytest.raises(InputError, match="no closed form"):
        robot.ik(robot.fk(np.zeros(7)), method="analytic")


def test_generic_6r_is_general_6r_with_measurements():
    # no closed form: the general 6R elimination (issue 20), the closed forms' misses
    # still measured
    rows = [{"a": 0.1 * (k + 1), "alpha": 0.3 + 0.2 * k, "d": 0.05 * k, "theta": 0}
            for k in range(6)]
    fam = robokin.ik.family(robokin.Robot.from_dh(rows))
    assert fam.name == "general_6r" and not fam.near
    assert "Raghavan-Roth" in fam.measured
    assert {"three_parallel", "spherical_wrist", "general_6r"} <= set(fam.details)


def test_tool_and_base_are_folded_in():
    robot = robokin.load("puma560")
    tool = np.eye(4)
    tool[:3, 3] = [0.01, 0.02, 0.15]
    base = np.eye(4)
    base[:3, :3] = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]
    base[:3, 3] = [1.0, 2.0, 0.5]
    robot = robot.with_tool(tool).with_base(base)
    assert robokin.ik.family(robot).name == "spherical_wrist"
    q0 = np.array([0.2, 0.4, -0.9, 0.5, 0.6, -0.3])
    sols = robot.ik(robot.fk(q0))
    assert len(sols) == 8
    assert np.abs(robot.fk(sols.solutions()) - robot.fk(q0)).max() < 1e-9


def test_reversed_joint_and_zero_offsets_need_no_special_case():
    rows = [
        {"a": 0, "alpha": math.pi / 2, "d": 0.1, "theta": 0.3},
        {"a": 0.4, "alpha": 0, "d": 0, "theta": 1.0, "sign": -1},
        {"a": 0.35, "alpha": 0, "d": 0, "theta": -0.5},
        {"a": 0, "alpha": math.pi / 2, "d": 0.11, "theta": 0.2, "sign": -1},
        {"a": 0, "alpha": -math.pi / 2, "d": 0.09, "theta": 0},
        {"a": 0, "alpha": 0, "d": 0.08, "theta": 2.0},
    ]
    robot = robokin.Robot.from_dh(rows)
    assert robokin.ik.family(robot).name == "three_parallel"
    q = np.random.default_rng(2).uniform(-3, 3, (500, 6))
    sols = robot.ik(robot.fk(q))
    diff = (sols.q - q[:, None] + np.pi) % (2 * np.pi) - np.pi
    gap = np.where(sols.valid, np.abs(diff).max(-1), np.inf).min(-1)
    assert (gap < 1e-6).all()
