"""The nearest in-limit point of a held-joint self-motion (``self_motion_nearest``).

Oracles (independent of the search under test):
* dense samples: every branch of ``SelfMotion.sample`` at 5,000 values of the
  parameter over its range, the rows inside every joint limit, the smallest 2 pi
  wrapped distance to q_near; the answer is never farther than that (1e-12);
* forward kinematics of the answer reproduces the pose to 1e-12 (position [m] and
  rotation angle [rad], ``reference.pose_errors``), and it is inside the limits;
* from q0 itself (inside the limits) the answer is q0.
"""

from __future__ import annotations

import numpy as np
import pytest

import robokin
from reference import pose_errors, random_7r, ur5_on_a_track
from robokin.kinematics.arm import arm_of
from robokin.kinematics.ik.dispatch import solve
from robokin.kinematics.ik.self_motion_families import _family
from robokin.kinematics.ik.self_motion_nearest import interval_nearest
from robokin.spatial import wrap_angle

PANDA = robokin.load("panda")
DENSE = 5000


def _dense_best(sm, qn):
    Q = sm.sample(np.linspace(*sm.domain, DENSE), within_limits=True).reshape(-1, 7)
    d = np.linalg.norm(wrap_angle(Q - qn), axis=-1)
    return float(np.nanmin(d)) if np.isfinite(d).any() else np.inf


def _cases():
    """36 seeded (q0, q_near): random in-limit q0; q_near near, far, or past a limit."""
    rng = np.random.default_rng(2029)
    lo, hi = PANDA.limits[:, 0], PANDA.limits[:, 1]
    out = []
    for i in range(36):
        q0 = rng.uniform(lo, hi)
        if i % 6 == 5:  # special values users hit: 0 and +-pi/2 where in range
            q0[[0, 2, 4, 6]] = np.clip([0.0, np.pi / 2, -np.pi / 2, 0.0], lo[[0, 2, 4, 6]],
                                       hi[[0, 2, 4, 6]])
        kind = i % 3
        if kind == 0:
            qn = q0 + rng.normal(0.0, 0.3, 7)
        elif kind == 1:
            qn = rng.uniform(lo, hi)  # far: another part of the manifold may be nearer
        else:
            qn = q0.copy()
            qn[3] = hi[3] + 0.2  # past q4's upper limit: a constrained minimum
        out.append((q0, qn))
    return out


@pytest.mark.parametrize("i", range(36))
def test_ik_near_self_motion_is_as_near_as_dense_samples(i):
    q0, qn = _cases()[i]
    T = PANDA.fk(q0)
    res = PANDA.ik_near(T, qn, method="self_motion")
    assert res.success
    best = _dense_best(PANDA.self_motion(T), qn)
    got = float(np.linalg.norm(wrap_angle(res.q - qn)))
    assert got <= best + 1e-12
    assert PANDA.within_limits(res.q)
    dp, dr = pose_errors(PANDA.fk(res.q), T)
    assert dp <= 1e-12 and dr <= 1e-12


def test_from_q0_itself_the_answer_is_q0():
    rng = np.random.default_rng(11)
    for _ in range(5):
        q0 = rng.uniform(PANDA.limits[:, 0] * 0.95, PANDA.limits[:, 1] * 0.95)
        p = PANDA.self_motion(PANDA.fk(q0)).nearest(q0)
        assert p is not None and np.abs(p.q - q0).max() < 1e-7 and -p.score < 1e-7


def test_no_interval_gives_none():
    # oracle: an empty interval list has no point (the search must not invent one)
    q0 = np.zeros(7)
    fam = _family(arm_of(PANDA), PANDA.fk(q0), "auto", solve, False)
    assert interval_nearest(fam, PANDA.limits, np.zeros((0, 2)), np.zeros(0, int), q0) is None


@pytest.mark.parametrize("parameter", ["track", "j1", "j6"])
def test_joints_with_a_range_over_a_turn_come_back_without_a_full_turn(parameter):
    # Session 16: a UR5 (joints +-6.28 rad) on a linear track. With j6 as the
    # parameter, t and t - 2 pi are both in its domain and equally near q0 by the
    # wrapped distance; nearest(q0) returned q0 with j6 a full turn away. The tie now
    # goes to the unwrapped nearer value, and the other revolute joints come back at
    # their 2 pi equivalent nearest q_near (SolutionSet.nearest's rule); the track
    # (prismatic) is never wrapped. Oracles: q0 itself (1e-9), FK of the answer.
    arm = ur5_on_a_track(6.0)
    for q0 in (np.array([0.7, 0.3, -1.2, 1.1, -0.5, 0.8, 0.2]),
               np.array([4.5, -2.9, 1.0, -2.0, 2.5, -0.4, -3.0])):
        T = arm.fk(q0)
        sm = arm.self_motion(T, parameter)
        got = sm.nearest(q0)
        assert got is not None
        np.testing.assert_allclose(got.q, q0, atol=1e-9)
        assert got.t == pytest.approx(q0[arm.joint_names.index(parameter)], abs=1e-9)
        dp, dr = pose_errors(arm.fk(got.q), T)
        assert dp < 1e-12 and dr < 1e-12


@pytest.mark.parametrize("i", range(6))
def test_a_general_7r_arm_takes_its_continued_manifold(i):
    # Session 17: method="self_motion" refused every 7-joint arm without a closed form
    # (its continued manifold then cost up to ~1 s a pose; now ~10-30 ms). A general
    # 7R arm (random_7r: the general held-joint 6R solver, joint 7 continued) now
    # takes it. Oracles: the dense samples of its manifold (never nearer than the
    # answer), FK of the answer (1e-12), inside the limits; special values of q0.
    arm = random_7r()
    rng = np.random.default_rng(1700 + i)
    lo, hi = arm.limits[:, 0], arm.limits[:, 1]
    q0 = rng.uniform(lo, hi)
    if i % 2:  # joints at 0 and pi/2 where in range
        q0[[1, 3, 5]] = np.clip([0.0, np.pi / 2, 0.0], lo[[1, 3, 5]], hi[[1, 3, 5]])
    qn = q0 + rng.normal(0.0, 0.3, 7) if i < 3 else rng.uniform(lo, hi)
    T = arm.fk(q0)
    res = arm.ik_near(T, qn, method="self_motion")
    assert res.success
    got = float(np.linalg.norm(wrap_angle(res.q - qn)))
    assert got <= _dense_best(arm.self_motion(T), qn) + 1e-12
    assert arm.within_limits(res.q)
    dp, dr = pose_errors(arm.fk(res.q), T)
    assert dp <= 1e-12 and dr <= 1e-12
