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
from reference import pose_errors
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
