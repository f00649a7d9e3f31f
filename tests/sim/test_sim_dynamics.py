"""Simulated torques and inverse dynamics against closed forms (issue 17, items 3, 5).

A pendulum: one hinge about a horizontal axis, a point mass m at l. Holding it
at q (from the horizontal) takes ``m g l cos(q)``; moving it adds ``m l^2 qdd``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import robokin
from robokin import trajectory
from robokin.model.dynamics import LinkInertia, RobotDynamics
from robokin.trajectory import Trajectory

pytest.importorskip("mujoco")

from robokin import sim  # noqa: E402

M, L, G = 2.0, 0.5, 9.81


def pendulum(torque_limit=None):
    robot = robokin.Robot.from_elementary(
        [{"op": "rx", "value": math.pi / 2},
         {"op": "rz", "joint": "revolute", "name": "hinge"},
         {"op": "tx", "value": L}], name="pendulum")
    dyn = RobotDynamics.from_mapping(
        robot, {"hinge": LinkInertia(M, [L, 0, 0], np.zeros((3, 3)))},
        torque_limits=None if torque_limit is None else [torque_limit])
    return robot.replace(dynamics=dyn)


def dwell_plan(angles, hold=0.6, move=0.4, dt=0.005):
    parts = []
    for a, b in zip(angles[:-1], angles[1:]):
        parts.append(trajectory.quintic(np.array([a]), np.array([a]), hold, dt=dt))
        parts.append(trajectory.quintic(np.array([a]), np.array([b]), move, dt=dt))
    parts.append(trajectory.quintic(np.array([angles[-1]]), np.array([angles[-1]]),
                                    hold, dt=dt))
    return Trajectory.concatenate(parts).replace(joint_names=("hinge",))


def test_pendulum_inverse_dynamics_is_m_g_l_cos_q_plus_m_l2_qdd():
    robot = pendulum()
    q = np.linspace(-1.4, 1.4, 29)
    qdd = np.linspace(-2.0, 2.0, 29)
    plan = Trajectory(np.arange(29) * 0.1, q[:, None], np.zeros((29, 1)), qdd[:, None],
                      joint_names=("hinge",))
    inv = sim.inverse_dynamics(robot, plan)
    expected = M * G * L * np.cos(q) + M * L**2 * qdd
    np.testing.assert_allclose(inv.tau[:, 0], expected, atol=1e-10)


def test_pendulum_simulated_torque_matches_m_g_l_cos_q():
    robot = pendulum()
    angles = [-1.2, -0.4, 0.3, 1.1]
    plan = dwell_plan(angles)
    res = sim.simulate(robot, plan)
    # at the end of every hold the arm is still: the servo holds m g l cos(q)
    for k, a in enumerate(angles):
        i = int(np.searchsorted(res.t, (k + 1) * 0.6 + k * 0.4 - 1e-9)) - 1
        assert res.q[i, 0] == pytest.approx(a, abs=1e-6)
        assert res.tau[i, 0] == pytest.approx(M * G * L * math.cos(a), rel=1e-6, abs=1e-9)
    # and along the whole run: m g l cos(q) + m l^2 qdd (qdd of the simulated
    # motion, differentiated from 5 ms samples: a torque acts over the step after
    # it, so the two are half a step apart, worth I * jerk * dt / 2 ~ 0.2 N m here)
    qdd = np.gradient(res.qd[:, 0], res.t)
    expected = M * G * L * np.cos(res.q[:, 0]) + M * L**2 * qdd
    assert np.abs(res.tau[:, 0] - expected).max() < 0.03 * M * G * L


def test_torque_limits_clamp_and_fail_the_verdict():
    robot = pendulum(torque_limit=5.0)  # m g l = 9.81 N m: it cannot hold level
    plan = dwell_plan([0.0, 0.2])
    res = sim.simulate(robot, plan)
    assert np.abs(res.tau).max() <= 5.0 + 1e-9
    assert not res.ok and any("limit" in r for r in res.reasons)
    inv = sim.inverse_dynamics(robot, plan)
    assert not inv.feasible
    assert inv.violations[0].startswith("hinge needs")


def test_motor_power_equals_joint_power():
    robot = robokin.load("scara")
    plan = trajectory.quintic(np.array([0, 0, 0, 0.05]),
                              np.array([0.5, 0.8, 3.0, 0.15]), 1.5, dt=0.01)
    inv = sim.inverse_dynamics(robot, plan)
    np.testing.assert_allclose(inv.motor_power.sum(axis=1), inv.power.sum(axis=1),
                               atol=1e-9)
    # the lift holds the shaft's weight: m g (estimated mass of the shaft capsule)
    lift = robokin.load("scara")
    from robokin.model.dynamics import resolve_links

    m_shaft = resolve_links(lift).links[4].mass
    still = Trajectory(np.arange(3.0), np.tile([0.1, 0.2, 0.3, 0.1], (3, 1)),
                       np.zeros((3, 4)), np.zeros((3, 4)), joint_names=lift.joint_names)
    np.testing.assert_allclose(sim.inverse_dynamics(lift, still).tau[:, 3],
                               m_shaft * G, rtol=1e-9)


def test_a_coupled_chain_simulates_stably_and_tracks():
    # the QFMD010's parallelogram: forearm = theta3 - theta2 held by a tendon
    # equality, theta3 driven through a tendon spread over the joints it moves
    robot = robokin.load("qfmd010")
    plan = trajectory.quintic(np.full(4, 0.1), np.array([1.0, 0.3, 0.2, 1.0]), 2.0,
                              dt=0.005)
    res = sim.simulate(robot, plan)
    assert res.ok, res.reasons
    inv = sim.inverse_dynamics(robot, plan)
    scale = np.abs(inv.tau).max(axis=0)
    # the servo errors (a few 1e-4 rad) add their PD torques to the model torques
    assert np.all(np.abs(res.tau - inv.tau).max(axis=0) < 0.1 * scale)
