"""Clear errors (issue 17): missing mass data in strict mode, a trajectory for
another robot, non-finite gains, bad steps."""

from __future__ import annotations

import math

import numpy as np
import pytest

import robokin
from robokin import trajectory

pytest.importorskip("mujoco")

from robokin import sim  # noqa: E402


@pytest.fixture(scope="module")
def ur5_plan():
    robot = robokin.load("ur5")
    plan = trajectory.quintic(np.zeros(6), np.full(6, 0.3), 0.5, dt=0.01)
    return robot, plan.replace(joint_names=robot.joint_names)


def test_strict_mode_names_the_missing_field():
    robot = robokin.load("scara")
    plan = trajectory.quintic(np.zeros(4), np.array([0.1, 0.1, 0.1, 0.05]), 0.5, dt=0.01)
    with pytest.raises(robokin.ModelError, match="no mass data") as exc:
        sim.simulate(robot, plan, strict=True)
    assert exc.value.field == "dynamics.links.shoulder"
    with pytest.raises(robokin.ModelError, match="dynamics.links.shoulder"):
        sim.to_mjcf(robot, strict=True)
    with pytest.raises(robokin.ModelError, match="no mass data"):
        sim.inverse_dynamics(robot, plan, strict=True)


def test_a_trajectory_for_another_robot_is_refused(ur5_plan):
    robot, plan = ur5_plan
    with pytest.raises(robokin.InputError, match="argument 'traj'.*another robot"):
        sim.simulate(robokin.load("scara"), plan)
    panda = robokin.load("panda")
    other = trajectory.quintic(np.zeros(6), np.full(6, 0.3), 0.5, dt=0.01).replace(
        joint_names=tuple(f"j{i}" for i in range(6)))
    with pytest.raises(robokin.InputError, match="another robot"):
        sim.simulate(robot, other)
    with pytest.raises(robokin.InputError, match="another robot"):
        sim.inverse_dynamics(panda, plan)
    with pytest.raises(robokin.InputError, match="no actuator map"):
        sim.simulate(robot, plan.replace(space="actuator"))


@pytest.mark.parametrize("gains, match", [
    ({"bandwidth": math.nan}, "bandwidth"),
    ({"bandwidth": -3.0}, "bandwidth"),
    ({"kp": [1.0, 2, 3, 4, 5, math.inf], "kv": [1.0] * 6}, "kp"),
    ({"kp": [1.0] * 6, "kv": [1.0, 1, 1, 1, 1, math.nan]}, "kv"),
    ({"kp": [1.0] * 6}, "together"),
    ({"kp": [1.0] * 5, "kv": [1.0] * 5}, "5 entries"),
    ({"stiffness": 3}, "unknown field"),
    ("fast", "expected None"),
    ({"bandwidth": 2000.0}, "too stiff"),
])
def test_bad_gains_are_refused_naming_the_argument(ur5_plan, gains, match):
    robot, plan = ur5_plan
    with pytest.raises(robokin.InputError, match=f"argument 'gains'.*{match}"):
        sim.simulate(robot, plan, gains=gains)


def test_bad_step_contacts_and_tolerance(ur5_plan):
    robot, plan = ur5_plan
    with pytest.raises(robokin.InputError, match="argument 'dt'"):
        sim.simulate(robot, plan, dt=0.002)  # slower than 1 kHz
    with pytest.raises(robokin.InputError, match="argument 'contacts'"):
        sim.simulate(robot, plan, contacts="soft")
    with pytest.raises(robokin.InputError, match="argument 'tolerance'"):
        sim.simulate(robot, plan, tolerance=(0.0, 1e-3))
    bad = plan.replace(q=np.where(np.arange(6) == 2, np.nan, plan.q))
    with pytest.raises(robokin.InputError, match="non-finite"):
        sim.simulate(robot, bad)


def test_a_plan_too_long_to_step_is_refused_before_allocating(ur5_plan):
    robot, plan = ur5_plan
    # two samples a million seconds apart: 1e9 physics steps (7.45 GiB of step times
    # alone) used to be allocated
    long = robokin.trajectory.Trajectory(
        np.array([0.0, 1e6]), plan.q[[0, -1]], np.zeros((2, 6)), np.zeros((2, 6)),
        joint_names=robot.joint_names)
    with pytest.raises(robokin.InputError, match=r"1e\+06 s at dt 0.001 s .*more than "
                       r"the limit of 10,000,000") as exc:
        sim.simulate(robot, long)
    assert exc.value.argument == "traj"
    with pytest.raises(robokin.InputError, match="limit of 400") as exc:
        sim.simulate(robot, plan, max_samples=400)  # 0.5 s at 1 kHz: 502 > 400
    assert exc.value.argument == "traj"
    assert sim.simulate(robot, plan, max_samples=600).steps == 500
    with pytest.raises(robokin.InputError, match="argument 'max_samples'"):
        sim.simulate(robot, plan, max_samples=0.5)
