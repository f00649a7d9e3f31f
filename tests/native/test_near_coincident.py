"""csrc/near_coincident.c: the near-coincident held-joint pass, called as the kernel.

Mirrors ``src/robokin/_native/csrc/near_coincident.c`` (kernel ``near_coincident``,
issue 23): a bad argument is refused naming the kernel and the argument before
anything runs; the rows it returns as exact reproduce their poses; its singular
flags agree with numpy's SVD of the free joints' Jacobian; each pose's slots are
filled from 0 without a copy of a placed row.
"""

from __future__ import annotations

import numpy as np
import pytest

import robokin
from reference import pose_errors
from robokin._native import kernels as K
from robokin.kinematics.ik import near_coincident as nco
from robokin.kinematics.ik.coincident import HELPER_TURN, coincident_pair
from robokin.spatial import wrap_angle

PANDA = robokin.load("panda")
ARM = PANDA.arm if hasattr(PANDA, "arm") else PANDA
PAIR = coincident_pair(PANDA, 1, 0.0)  # q2 = 0: axes 1 and 3 on one line


def _helper_rows(T, v0=0.0):
    """Exact rows of each pose with q1 held at the pair's helper values, q2 within KEEP."""
    H, pose = [], []
    for p in range(len(T)):
        for c in (PAIR.c, PAIR.c + HELPER_TURN):
            s = PANDA.ik(T[p], fixed={"joint1": c})
            Q = s.q[s.valid]
            Q = Q[np.abs(wrap_angle(Q[:, 1] - v0)) <= nco.KEEP]
            H.append(Q)
            pose += [p] * len(Q)
    return np.concatenate(H), np.array(pose, np.int64)


def _call(T, H, pose, v, **change):
    S = K.NC_SEEDS * len(H)
    args = dict(packed=PANDA.chain.arrays.packed, T=np.ascontiguousarray(T), H=H, pose=pose,
                held=PAIR.held, a=PAIR.a, b=PAIR.b, sign=PAIR.sign, v0=0.0, v=v,
                accept=nco.ACCEPT, Q=np.empty((S, 7)), at=np.empty(S, np.int64),
                exact=np.empty(S, bool), singular=np.empty(S, bool),
                slot=np.empty(S, np.int64))
    args.update(change)
    m = K.near_coincident(*args.values())
    return m, args


@pytest.fixture(scope="module")
def problem():
    rng = np.random.default_rng(23)
    lim = PANDA.limits
    q = rng.uniform(lim[:, 0], lim[:, 1], (6, 7))
    q[:3, 4] = 0.0  # a second aligned set (q5 = 0) on half of them
    q[:, 1] = [1e-9, -1e-7, 1e-4, -1e-9, 1e-6, -1e-3]
    return q


@pytest.mark.parametrize("row", range(6))
def test_rows_are_exact_flags_agree_with_the_svd_and_slots_are_distinct(problem, row):
    # Oracles: FK of every row the kernel calls exact within ACCEPT (1e-13 m, rad)
    # of its pose, q2 exactly v (reference.pose_errors, numpy); a row in a slot is
    # exact, slots of a pose run 0, 1, ... with rows more than SAME apart (modulo
    # 2 pi); the singular flag is numpy's SVD of the free joints' Jacobian (smallest
    # below 1e-5 of the largest) wherever that ratio is not within 10 % of 1e-5; the
    # generating configuration is among the exact rows where that Jacobian is regular.
    q = problem[row:row + 1]
    v = float(q[0, 1])
    T = PANDA.fk(q)
    H, pose = _helper_rows(T)
    m, a = _call(T, H, pose, v)
    assert m >= 1
    Q, exact, sing, slot = a["Q"][:m], a["exact"][:m], a["singular"][:m], a["slot"][:m]
    assert exact.any() and np.all(Q[:, 1] == v)
    dp, dr = pose_errors(PANDA.fk(Q[exact]), np.broadcast_to(T[0], (int(exact.sum()), 4, 4)))
    assert dp.max() <= nco.ACCEPT and dr.max() <= nco.ACCEPT
    placed = slot >= 0
    assert np.all(exact[placed]) and sorted(slot[placed]) == list(range(int(placed.sum())))
    P = Q[placed]
    for i in range(len(P)):
        for k in range(i):
            assert np.abs(wrap_angle(P[i] - P[k])).max() > nco.SAME
    sv = np.linalg.svd(np.delete(PANDA.jacobian(Q), 1, axis=-1), compute_uv=False)
    ratio = sv[:, -1] / sv[:, 0]
    clear = np.abs(ratio / nco.FLAG - 1.0) > 0.1
    assert np.array_equal(sing[clear], (ratio < nco.FLAG)[clear])
    sv0 = np.linalg.svd(np.delete(PANDA.jacobian(q[0]), 1, axis=-1), compute_uv=False)
    if sv0[-1] > 1e-5 * sv0[0]:
        assert np.abs(wrap_angle(P - q[0])).max(axis=-1).min() <= 1e-6


def test_a_pose_order_or_batch_changes_no_row(problem):
    # Oracle: the kernel on two poses together equals it on each alone, bit for bit
    # (a row depends on its seed only).
    T = PANDA.fk(problem[[0, 2]])
    v = 1e-9
    H, pose = _helper_rows(T)
    m, a = _call(T, H, pose, v)
    for p in range(2):
        Hp = H[pose == p]
        mp, b = _call(T[p:p + 1], Hp, np.zeros(len(Hp), np.int64), v)
        mine = a["at"][:m] == p
        assert mp == mine.sum()
        assert np.array_equal(a["Q"][:m][mine], b["Q"][:mp])
        assert np.array_equal(a["slot"][:m][mine], b["slot"][:mp])


def test_bad_arguments_are_refused_naming_them(problem):
    # Oracle: each message names the kernel and the argument (or the rule broken).
    T = PANDA.fk(problem[:1])
    H, pose = _helper_rows(T)
    with pytest.raises(ValueError, match="near_coincident: pose: an index outside"):
        _call(T, H, pose + 1, 1e-9)
    with pytest.raises(ValueError, match="near_coincident: .*held, a and b"):
        _call(T, H, pose, 1e-9, a=PAIR.held)
    with pytest.raises(ValueError, match="near_coincident: .*sign"):
        _call(T, H, pose, 1e-9, sign=0.5)
    with pytest.raises(ValueError, match="near_coincident: .*NC_SEEDS rows per helper row"):
        S = len(H)
        _call(T, H, pose, 1e-9, Q=np.empty((S, 7)), at=np.empty(S, np.int64),
              exact=np.empty(S, bool), singular=np.empty(S, bool), slot=np.empty(S, np.int64))
    T2 = np.concatenate([T, T])
    down = np.array([1] + [0] * (len(H) - 1), np.int64)  # each pose's rows in one block
    with pytest.raises(ValueError, match="near_coincident: pose"):
        _call(T2, np.concatenate([H, H[:1]]), np.append(down, 0), 1e-9)
    ur5 = robokin.load("ur5")
    with pytest.raises(ValueError, match="near_coincident: .*7 independent joints"):
        _call(T, H[:, :6].copy(), pose, 1e-9, packed=ur5.chain.arrays.packed,
              Q=np.empty((K.NC_SEEDS * len(H), 6)))
    with pytest.raises(ValueError, match="near_coincident: accept"):
        _call(T, H, pose, 1e-9, accept=np.nan)
