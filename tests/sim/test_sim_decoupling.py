"""The ADAMS check of the SCARA in MuJoCo (issue 17, item 4)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import robokin
from robokin import trajectory

pytest.importorskip("mujoco")

from robokin import sim  # noqa: E402
from robokin.sim.decoupling import naive_actuator_map  # noqa: E402


def test_scara_motors_follow_the_plan_only_when_decoupled():
    robot = robokin.load("scara")
    q0 = np.array([0.0, 0.0, 0.0, 0.05])
    q1 = np.array([math.radians(30), math.radians(45), math.pi, 0.15])
    plan = trajectory.quintic(q0, q1, 2.0, dt=0.005)
    check = sim.check_decoupling(robot, plan)
    assert check.joints == (2, 3)  # the shaft's rotation and lift
    assert check.passed
    rot, lift = check.decoupled_error
    assert rot < math.radians(0.5) and lift < 1e-4  # the shaft follows
    # naive: half a shaft turn lifts the shaft by half a lead (20 mm / 2)
    assert check.naive_error[1] == pytest.approx(0.010, abs=5e-4)
    assert check.decoupled.motor_tau is not None and check.decoupled.phi is not None
    np.testing.assert_allclose(check.decoupled.phi[-1],
                               robot.actuators.inverse(plan.q[-1]), atol=0.01)


def test_naive_map_keeps_each_joints_own_motor():
    A = robokin.load("scara").actuators.matrix
    N = naive_actuator_map(A)
    assert np.count_nonzero(N) == 4
    assert N[3, 2] == A[3, 2] and N[3, 3] == 0.0  # lift keeps the screw motor only


def test_decoupling_check_needs_a_coupled_drive():
    with pytest.raises(robokin.InputError, match="actuator map"):
        sim.check_decoupling(robokin.load("ur5"),
                             trajectory.quintic(np.zeros(6), np.ones(6), 1.0, dt=0.01))
