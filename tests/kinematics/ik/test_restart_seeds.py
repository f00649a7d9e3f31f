"""Numeric IK restart seed table: its rows are FK of in-limit configurations, the grid
search finds the nearest rows, and restarts from it give exact, in-limit solutions."""

from __future__ import annotations

import numpy as np
import pytest

import robokin
from reference import pose_errors, random_q
from robokin.kinematics.ik import numeric, restart_seeds
from robokin.kinematics.ik.lm_options import option_vector

ARMS = ("ur5", "aubo_i5", "puma560", "panda", "scara", "qfmd010", "improved_dh_arm")


@pytest.mark.parametrize("name", ARMS)
def test_table_rows_are_fk_of_in_limit_configurations_bucketed_by_cell(name):
    robot = robokin.load(name)
    tab, cstart, gdat = restart_seeds.seed_table(robot.arm).kernel_args()
    n = robot.n
    assert tab.shape == (restart_seeds.TABLE_SIZE, 12 + n)
    q = tab[:, 12:]
    assert robot.within_limits(q, tol=0.0).all()
    T = robot.fk(q)
    np.testing.assert_allclose(tab[:, :3], T[:, :3, 3], atol=1e-12, rtol=0)
    np.testing.assert_allclose(tab[:, 3:12], T[:, :3, :3].reshape(-1, 9), atol=1e-12,
                               rtol=0)
    G = int(gdat[6])
    assert cstart.shape == (G**3 + 1,) and cstart[0] == 0 and cstart[-1] == len(tab)
    assert np.all(np.diff(cstart) >= 0)
    cells = restart_seeds.grid_cells(tab[:, :3], gdat[:3], gdat[3:6], G)
    for c in np.flatnonzero(np.diff(cstart)):
        assert (cells[cstart[c]:cstart[c + 1]] == c).all()
    # the same table every time (a fixed sampling seed), read-only
    again = restart_seeds.build_seed_table(robot.chain).kernel_args()
    for a, b in zip((tab, cstart, gdat), again, strict=True):
        np.testing.assert_array_equal(a, b)
        assert not a.flags.writeable


@pytest.mark.parametrize("rot_w", [0.0, restart_seeds.TABLE_ROT])
def test_grid_search_finds_the_nearest_rows_of_the_cells_it_scans(rot_w):
    from robokin._native import kernels as K

    robot = robokin.load("panda")
    tab, cstart, gdat = restart_seeds.seed_table(robot.arm).kernel_args()
    G = int(gdat[6])
    cells = np.clip(np.floor((tab[:, :3] - gdat[:3]) * gdat[3:6]).astype(int), 0, G - 1)
    rng = np.random.default_rng(3)
    T = robot.fk(random_q(robot, rng, 30))
    T[:5, :3, 3] += 5.0  # outside the table's box: the search widens
    k = 4
    for Tt in T:
        idx = K.table_nearest(tab, cstart, gdat, Tt, k, rot_w)
        found = len(idx)
        assert found == k
        d = (np.sum((tab[:, :3] - Tt[:3, 3]) ** 2, axis=1)
             + rot_w * np.sum((tab[:, 3:12] - Tt[:3, :3].ravel()) ** 2, axis=1))
        c = np.clip(np.floor((Tt[:3, 3] - gdat[:3]) * gdat[3:6]).astype(int), 0, G - 1)
        cheb = np.abs(cells - c).max(axis=1)
        r = 1
        while (cheb <= r).sum() < k:
            r += 1
        scanned = np.flatnonzero(cheb <= r)
        want = scanned[np.argsort(d[scanned], kind="stable")[:k]]
        np.testing.assert_allclose(d[idx], d[want], rtol=1e-12, atol=1e-15)
    # a table pose is its own nearest row
    row = 123
    Tt = np.eye(4)
    Tt[:3, 3] = tab[row, :3]
    Tt[:3, :3] = tab[row, 3:12].reshape(3, 3)
    idx = K.table_nearest(tab, cstart, gdat, Tt, 1, rot_w)
    d0 = (np.sum((tab[idx[0], :3] - Tt[:3, 3]) ** 2)
          + rot_w * np.sum((tab[idx[0], 3:12] - Tt[:3, :3].ravel()) ** 2))
    assert d0 == 0.0
    assert (rot_w == 0.0 and np.allclose(tab[idx[0], :3], tab[row, :3])) or idx[0] == row


@pytest.mark.parametrize("name", ["ur5", "panda", "improved_dh_arm"])
def test_table_restarts_round_trip_to_1e9_inside_limits_independent_of_rng(name):
    robot = robokin.load(name)
    rng = np.random.default_rng(11)
    T = robot.fk(random_q(robot, rng, 200))
    mid = restart_seeds.middle(robot.chain)
    # max_restarts=4: q0 (the middle of the limits), then only table seeds
    a = numeric.solve(robot, T, q0=mid, max_restarts=4, rng=np.random.default_rng(1))
    b = numeric.solve(robot, T, q0=mid, max_restarts=4, rng=np.random.default_rng(2))
    used = a.restarts > 0
    assert used.sum() > 20  # the first descent fails often enough to exercise it
    assert a.success[used].mean() > 0.85
    np.testing.assert_array_equal(a.q, b.q)
    np.testing.assert_array_equal(a.iterations, b.iterations)
    ok = a.success
    dp, dr = pose_errors(robot.fk(a.q[ok]), T[ok])
    assert (dp <= 1e-9).all() and (dr <= 1e-9 * 1.5).all()
    assert robot.within_limits(a.q, tol=0.0).all()
    # one target at a time gives the same answers (to rounding: see
    # test_batch_equals_per_target_when_the_first_descent_converges)
    for i in np.flatnonzero(used)[:10]:
        one = numeric.solve(robot, T[i], q0=mid, max_restarts=4)
        np.testing.assert_allclose(one.q, a.q[i], rtol=0, atol=1e-12)
        assert one.restarts == a.restarts[i]


def test_results_deterministic_for_a_seeded_rng_with_table_and_random_restarts():
    robot = robokin.load("improved_dh_arm")
    T = robot.fk(random_q(robot, np.random.default_rng(5), 300))
    r1 = numeric.solve(robot, T, q0=restart_seeds.middle(robot.chain),
                       rng=np.random.default_rng(9))
    r2 = numeric.solve(robot, T, q0=restart_seeds.middle(robot.chain),
                       rng=np.random.default_rng(9))
    assert r1.success.all()
    assert (r1.restarts > restart_seeds.TABLE_SEEDS).any()  # random seeds were used too
    np.testing.assert_array_equal(r1.q, r2.q)
    np.testing.assert_array_equal(r1.restarts, r2.restarts)
    assert robot.within_limits(r1.q, tol=0.0).all()


def test_masks_choose_the_table_metric():
    K = numeric.K
    full = option_vector(None, None, 1e-9, None, 100, 1.0)
    assert full[K.O_TABLE_ROT] == restart_seeds.TABLE_ROT
    assert option_vector("xyz", None, 1e-9, None, 100, 1.0)[K.O_TABLE_ROT] == 0.0
    assert option_vector("xyz rz", None, 1e-9, None, 100, 1.0)[K.O_TABLE_ROT] == 0.0
    assert option_vector("rx ry rz", None, 1e-9, None, 100, 1.0)[K.O_TABLE_ROT] < 0.0
    assert option_vector("x y rz", None, 1e-9, None, 100, 1.0)[K.O_TABLE_ROT] < 0.0


@pytest.mark.parametrize("mask", ["xyz", "rx ry rz"])
def test_masked_solves_with_restarts_converge_inside_limits(mask):
    robot = robokin.load("panda")
    rng = np.random.default_rng(4)
    Q = random_q(robot, rng, 60)
    T = robot.fk(Q)
    res = numeric.solve(robot, T, mask=mask, q0=restart_seeds.middle(robot.chain), rng=rng)
    assert res.success.all()
    assert robot.within_limits(res.q, tol=0.0).all()
    dp, dr = pose_errors(robot.fk(res.q), T)
    if mask == "xyz":
        assert (dp <= 1e-9).all()
    else:
        assert (dr <= 1.5e-9).all()


def test_small_angle_rotation_error_matches_scipy():
    # angles below atan(0.1) take the series branch of the residual's log map
    from scipy.spatial.transform import Rotation

    from robokin.spatial import pose_error

    rng = np.random.default_rng(8)
    angles = np.concatenate([np.logspace(-9, -1.1, 40), rng.uniform(0.05, 0.2, 20)])
    for th in angles:
        a = rng.normal(size=3)
        a /= np.linalg.norm(a)
        R0 = Rotation.random(random_state=int(rng.integers(1 << 30))).as_matrix()
        T = np.eye(4)
        T[:3, :3] = R0
        Tt = np.eye(4)
        Tt[:3, :3] = Rotation.from_rotvec(a * th).as_matrix() @ R0
        e = pose_error(T, Tt)
        np.testing.assert_allclose(e[3:], a * th, rtol=1e-9 if th > 1e-6 else 1e-4,
                                   atol=1e-15)
