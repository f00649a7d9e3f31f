"""The Trajectory value: limit-violation reports with times, actuator space, joins."""

import numpy as np
import pytest

import robokin
from robokin import InputError, trajectory
from robokin.model.coupling import AffineMap
from robokin.trajectory import Trajectory


def test_limit_violations_report_joint_kind_and_times():
    tr = trajectory.quintic([0.0, 0.0], [1.0, 0.1], 1.0, 0.01)
    # Peak quintic speed is 1.875 D / T = 1.875 rad/s at t = 0.5 s for joint 0.
    rep = tr.check_limits(velocity=1.5, position=[[-1, 0.9], [-1, 1]])
    assert not rep.ok and not bool(rep)
    kinds = {(v.kind, v.joint) for v in rep}
    assert kinds == {("velocity", 0), ("position", 0)}
    vel = next(v for v in rep if v.kind == "velocity")
    # |qd| > 1.5 where 30 tau^2 (1 - tau)^2 > 1.5: solve for the span by hand.
    tau = np.linspace(0, 1, 100001)
    inside = tau[30 * tau**2 * (1 - tau) ** 2 > 1.5]
    assert vel.t_start == pytest.approx(inside[0], abs=0.011)
    assert vel.t_end == pytest.approx(inside[-1], abs=0.011)
    assert vel.worst == pytest.approx(1.875, rel=1e-6) and vel.limit == 1.5
    pos = next(v for v in rep if v.kind == "position")
    assert pos.t_end == pytest.approx(1.0) and pos.worst == pytest.approx(1.0)
    assert "velocity of q1" in str(vel)


def test_no_violation_is_ok():
    tr = trajectory.quintic([0.0], [0.1], 1.0)
    rep = tr.check_limits(velocity=1.0, acceleration=10.0)
    assert rep.ok and len(rep) == 0 and str(rep) == "no limit violated"


def test_limits_from_robot():
    r = robokin.load("aubo_i5")
    q0 = np.zeros(6)
    q1 = np.array([3.2, 0, 0, 0, 0, 0])  # beyond +175 deg
    tr = trajectory.quintic(q0, q1, 2.0).replace(joint_names=r.joint_names)
    rep = tr.check_limits(r)
    assert rep.first().kind == "position" and rep.first().joint_name == "shoulder"
    assert rep.first().limit == pytest.approx(np.radians(175))


def test_actuator_space_view_round_trip():
    r = robokin.load("ur5")
    A = np.diag([2.0, 1.0, 1.0, 1.0, 1.0, 1.0])
    A[1, 2] = 0.5
    b = np.linspace(0.0, 0.5, 6)
    ra = r.replace(actuators=AffineMap(A, b))
    tr = trajectory.quintic(np.zeros(6), np.full(6, 0.3), 1.0)
    act = tr.to_actuator_space(ra)
    assert act.space == "actuator"
    np.testing.assert_allclose(act.q @ A.T + b, tr.q, atol=1e-12)
    np.testing.assert_allclose(act.qd @ A.T, tr.qd, atol=1e-12)
    back = act.to_joint_space(ra)
    np.testing.assert_allclose(back.q, tr.q, atol=1e-12)
    # no map: identity
    same = tr.to_actuator_space(r)
    np.testing.assert_array_equal(same.q, tr.q)
    with pytest.raises(InputError, match="already in actuator space"):
        act.to_actuator_space(ra)


def test_value_is_read_only_and_validated():
    tr = trajectory.quintic([0.0], [1.0], 1.0)
    with pytest.raises(ValueError):
        tr.q[0, 0] = 5.0
    with pytest.raises(InputError, match="increasing"):
        Trajectory([0.0, 0.0], np.zeros((2, 1)), np.zeros((2, 1)), np.zeros((2, 1)))
    with pytest.raises(InputError, match="qd"):
        Trajectory([0.0, 1.0], np.zeros((2, 1)), np.zeros((3, 1)), np.zeros((2, 1)))


def test_concatenate_keeps_junction_once():
    a = trajectory.quintic([0.0], [1.0], 1.0, 0.1)
    b = trajectory.quintic([1.0], [0.0], 2.0, 0.1)
    c = Trajectory.concatenate([a, b])
    assert len(c) == len(a) + len(b) - 1 and c.duration == pytest.approx(3.0)
    np.testing.assert_allclose(c.via_times, [0.0, 1.0, 3.0])
    np.testing.assert_allclose(c.at([1.0]), [[1.0]], atol=1e-12)
