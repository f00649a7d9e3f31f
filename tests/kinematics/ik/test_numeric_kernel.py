"""The compiled numeric IK kernel (``_native/csrc/lm.c``): lanes, threads, copies.

Four targets advance per vector; a target's steps do not depend on which lane or
thread runs it, so thread counts and batch splits must not change a bit, and the
baseline copy (CPUs without AVX2 + FMA) must solve like the AVX2 copy (the same
source, other roundings).
"""

import numpy as np
import pytest

import robokin
from reference import pose_errors, random_q
from robokin._native import _base, kernels
from robokin.exceptions import InputError
from robokin.kinematics.ik import numeric
from robokin.kinematics.ik.lm_options import option_vector
from robokin.kinematics.ik.restart_seeds import NO_TABLE

K = kernels
ARMS = ["ur5", "panda", "improved_dh_arm", "aubo_i5", "puma560"]


def _batch(robot, n, seed):
    rng = np.random.default_rng(seed)
    T = robot.fk(random_q(robot, rng, n))
    q0 = random_q(robot, rng, n)  # far seeds: table and random restarts are needed
    return T, q0


CASES = [(name, None, None) for name in ARMS] + [
    ("ur5", "xyz", None),  # task space, 3 x 3
    ("panda", "x y z rz", None),
    ("improved_dh_arm", "xyz", None),
    ("scara", "x y z rz", None),  # as many task rows as joints
    ("scara", None, None),  # more task rows than joints: the joint-space solve
    ("panda", None, (1.0, 0.25)),  # weights
    ("qfmd010", "xyz", None),  # a dependent joint: q_chain = M q (5 from 4)
    ("qfmd010", "x y z rz", None),
]


@pytest.mark.parametrize(("name", "mask", "weights"), CASES)
def test_the_baseline_copy_solves_the_same_batch_alike(name, mask, weights, monkeypatch):
    robot = robokin.load(name)
    T, q0 = _batch(robot, 300, 7)
    kw = dict(q0=q0, mask=mask, weights=weights)
    # one descent each: the same steps, other roundings (fused multiply-adds)
    fast1 = numeric.solve(robot, T, max_restarts=0, **kw)
    fast = numeric.solve(robot, T, rng=np.random.default_rng(3), **kw)
    monkeypatch.setattr(numeric, "K", _base)
    base1 = numeric.solve(robot, T, max_restarts=0, **kw)
    base = numeric.solve(robot, T, rng=np.random.default_rng(3), **kw)
    assert (fast1.success == base1.success).mean() >= 0.98
    same = (fast1.iterations == base1.iterations) & fast1.success & base1.success
    assert same.sum() >= 0.95 * (fast1.success & base1.success).sum()
    np.testing.assert_allclose(fast1.q[same], base1.q[same], rtol=0, atol=1e-9)
    # with restarts (which amplify rounding differences) both solve everything
    assert fast.success.all() and base.success.all()
    assert (base.restarts > 0).sum() > 10  # restarts are exercised
    for res in (fast, base):
        dp, dr = pose_errors(robot.fk(res.q), T)
        assert dp.max() <= 1e-9  # every case selects x, y, z
        if mask is None:
            assert dr.max() <= 1.5e-9
        assert robot.within_limits(res.q, tol=0.0).all()


def test_thread_count_does_not_change_the_results():
    robot = robokin.load("improved_dh_arm")
    T, q0 = _batch(robot, 200, 8)
    a = numeric.solve(robot, T, q0=q0, parallel=True, rng=np.random.default_rng(1))
    b = numeric.solve(robot, T, q0=q0, parallel=False, rng=np.random.default_rng(1))
    np.testing.assert_array_equal(a.q, b.q)
    np.testing.assert_array_equal(a.iterations, b.iterations)
    np.testing.assert_array_equal(a.restarts, b.restarts)


def test_bad_target_and_bad_q0_in_a_lane_batch_are_named():
    robot = robokin.load("ur5")
    T, q0 = _batch(robot, 20, 9)
    T[13, 0, 0] = np.nan
    with pytest.raises(InputError, match="13"):
        numeric.solve(robot, T, q0=q0)
    T, q0 = _batch(robot, 20, 9)
    T[4, :3, :3] *= 2.0  # not a rotation
    with pytest.raises(InputError, match="4"):
        numeric.solve(robot, T, q0=q0)


def test_unreachable_targets_in_a_lane_batch_fail_with_their_error():
    robot = robokin.load("ur5")
    T, q0 = _batch(robot, 16, 10)
    T[[2, 11], 0, 3] += 5.0  # 5 m beyond the reach
    res = numeric.solve(robot, T, q0=q0, max_restarts=20)
    assert not res.success[[2, 11]].any()
    assert res.success[np.setdiff1d(np.arange(16), [2, 11])].all()
    assert (res.position_error[[2, 11]] > 3.0).all()
    assert robot.within_limits(res.q, tol=0.0).all()


def test_a_single_target_a_batch_and_a_split_batch_give_the_same_bits():
    robot = robokin.load("panda")
    T, q0 = _batch(robot, 24, 11)
    kw = dict(max_restarts=0)  # no random seeds: the run is a function of (T, q0)
    whole = numeric.solve(robot, T, q0=q0, **kw)
    halves = [numeric.solve(robot, T[i:i + 12], q0=q0[i:i + 12], **kw) for i in (0, 12)]
    singles = [numeric.solve(robot, T[i], q0=q0[i], **kw) for i in range(24)]
    np.testing.assert_array_equal(whole.q, np.concatenate([h.q for h in halves]))
    np.testing.assert_array_equal(whole.q, np.array([s.q for s in singles]))
    np.testing.assert_array_equal(whole.iterations, [s.iterations for s in singles])


def test_joint_angles_beyond_the_polynomial_range_use_libm():
    # a joint offset of 2e5 rad puts that joint's sin/cos argument on the libm branch
    dh = [(0.089159, 0.0, np.pi / 2), (0.0, -0.425, 0.0), (0.0, -0.39225, 0.0),
          (0.10915, 0.0, np.pi / 2), (0.09465, 0.0, -np.pi / 2), (0.0823, 0.0, 0.0)]
    table = [{"joint": "revolute", "d": d, "a": a, "alpha": al, "theta": 0.0,
              "limits": [-np.pi, np.pi]} for d, a, al in dh]
    table[1]["theta"] = 2e5
    robot = robokin.Robot.from_dh(table)
    rng = np.random.default_rng(12)
    Q = rng.uniform(-np.pi, np.pi, (40, 6))
    T = robot.fk(Q)
    res = numeric.solve(robot, T, q0=np.zeros(6), rng=np.random.default_rng(2))
    assert res.success.mean() >= 0.95
    dp, dr = pose_errors(robot.fk(res.q[res.success]), T[res.success])
    assert dp.max() <= 1e-9 and dr.max() <= 1.5e-9


def test_inconsistent_arrays_are_refused_not_read_out_of_bounds():
    robot = robokin.load("ur5")
    packed = robot.chain.arrays.packed
    q = random_q(robot, np.random.default_rng(14), 8)
    T, q0 = robot.fk(q), q + 1e-3  # one descent from nearby each
    opts = option_vector(None, None, 1e-9, None, 100, 1.0)
    opts[K.O_USE_Q0] = 1.0
    tab, cstart, gdat = NO_TABLE
    args = [packed, T, q0, np.zeros((8, 1, 6)), opts, np.empty((8, 6 + K.N_RES)), tab,
            cstart, gdat, False]
    assert K.lm_solve(*args) == (0, -1)  # consistent: all eight solved
    for k, bad in [(5, np.empty((7, 6 + K.N_RES))), (2, q0[:, :5].copy()),
                   (4, opts[:10].copy()), (3, np.zeros((8, 1, 5)))]:
        wrong = list(args)
        wrong[k] = bad
        name = ["packed", "targets", "q0", "seeds", "opts", "out"][k]
        with pytest.raises(ValueError, match=rf"lm_solve: {name} must be \("):
            K.lm_solve(*wrong)
    for k, bad in [(2, q0.astype(np.float32)), (0, packed[:-3].copy()),
                   (5, np.empty((8, 6 + K.N_RES))[:, ::-1])]:
        wrong = list(args)
        wrong[k] = bad
        with pytest.raises(ValueError, match="q0|packed|out"):
            K.lm_solve(*wrong)
