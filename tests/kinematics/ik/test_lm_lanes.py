"""The C lane kernel (``_lm_lanes``): several targets per vector register.

It runs the numba kernel's algorithm step for step with different roundings, so on
the same batch both must converge on the same targets, in the same number of
iterations and restarts, to the same configurations (to rounding); inputs it does
not cover must reach the numba kernel.
"""

import shutil

import numpy as np
import pytest

import robokin
from reference import pose_errors, random_q
from robokin.exceptions import InputError
from robokin.kinematics.ik import _numeric_kernels as K
from robokin.kinematics.ik import numeric

LANES = numeric._lm_lanes  # None when not built, or built without its AVX2 copy
needs_lanes = pytest.mark.skipif(
    LANES is None, reason="_lm_lanes not built, or not used on this CPU (no AVX2 copy)")
ARMS = ["ur5", "panda", "improved_dh_arm", "aubo_i5", "puma560"]


@pytest.mark.skipif(shutil.which("cc") is None, reason="no C compiler on this machine")
def test_the_lane_kernel_was_built():
    # imported directly: numeric.py sets its handle to None where only the baseline
    # copy exists, which is a built extension all the same
    try:
        from robokin.kinematics.ik import _lm_lanes
    except ImportError:
        pytest.fail("setup.py did not build _lm_lanes")
    assert _lm_lanes.ISA in ("baseline", "avx2+fma")


@needs_lanes
def test_constants_match_the_numba_kernels():
    for name in ("N_OPTS", "N_RES", "O_TABLE_ROT", "R_CODE", "CODE_BAD_Q0", "TAB_K_MAX"):
        assert getattr(LANES, name) == getattr(K, name), name


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


@needs_lanes
@pytest.mark.parametrize(("name", "mask", "weights"), CASES)
def test_lanes_and_numba_solve_the_same_batch_alike(name, mask, weights, monkeypatch):
    robot = robokin.load(name)
    T, q0 = _batch(robot, 300, 7)
    data = numeric._chain_data(robot)
    opts = numeric._opts(mask, weights, 1e-9, None, 100, 1.0)
    assert isinstance(numeric._batch_kernel(data, opts, 300, True), numeric._LanesKernel)
    kw = dict(q0=q0, mask=mask, weights=weights)
    lanes = numeric.solve(robot, T, rng=np.random.default_rng(3), **kw)
    monkeypatch.setattr(numeric, "_lm_lanes", None)
    ref = numeric.solve(robot, T, rng=np.random.default_rng(3), **kw)
    assert ref.success.all() and lanes.success.all()
    assert (ref.restarts > 0).sum() > 10  # restarts are exercised
    same = (lanes.iterations == ref.iterations) & (lanes.restarts == ref.restarts)
    assert same.mean() >= 0.98
    np.testing.assert_allclose(lanes.q[same], ref.q[same], rtol=0, atol=1e-9)
    dp, dr = pose_errors(robot.fk(lanes.q), T)
    assert dp.max() <= 1e-9  # every case selects x, y, z
    if mask is None:
        assert dr.max() <= 1.5e-9
    assert robot.within_limits(lanes.q, tol=0.0).all()


@needs_lanes
def test_thread_count_does_not_change_the_results():
    robot = robokin.load("improved_dh_arm")
    T, q0 = _batch(robot, 200, 8)
    a = numeric.solve(robot, T, q0=q0, parallel=True, rng=np.random.default_rng(1))
    b = numeric.solve(robot, T, q0=q0, parallel=False, rng=np.random.default_rng(1))
    np.testing.assert_array_equal(a.q, b.q)
    np.testing.assert_array_equal(a.iterations, b.iterations)
    np.testing.assert_array_equal(a.restarts, b.restarts)


@needs_lanes
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


@needs_lanes
def test_unreachable_targets_in_a_lane_batch_fail_with_their_error():
    robot = robokin.load("ur5")
    T, q0 = _batch(robot, 16, 10)
    T[[2, 11], 0, 3] += 5.0  # 5 m beyond the reach
    res = numeric.solve(robot, T, q0=q0, max_restarts=20)
    assert not res.success[[2, 11]].any()
    assert res.success[np.setdiff1d(np.arange(16), [2, 11])].all()
    assert (res.position_error[[2, 11]] > 3.0).all()
    assert robot.within_limits(res.q, tol=0.0).all()


@needs_lanes
def test_single_targets_and_long_chains_go_to_numba():
    full = numeric._opts(None, None, 1e-9, None, 100, 1.0)
    ur5 = numeric._chain_data(robokin.load("ur5"))
    assert isinstance(numeric._batch_kernel(ur5, full, 100, False), numeric._LanesKernel)
    assert numeric._batch_kernel(ur5, full, 1, False) is K.solve_serial  # one target
    rows = [{"joint": "revolute", "d": 0.1, "a": 0.05, "alpha": np.pi / 2}] * 13
    long = numeric._chain_data(robokin.Robot.from_dh(rows))
    assert numeric._batch_kernel(long, full, 100, True) is K.solve_parallel


@needs_lanes
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


@needs_lanes
def test_the_baseline_copy_solves_like_the_avx2_copy():
    # CPUs without AVX2 + FMA load the baseline copy (then numba is used instead,
    # being faster); it is the same source, so it must solve the same way
    robot = robokin.load("panda")
    T, q0 = _batch(robot, 200, 13)
    fast = numeric.solve(robot, T, q0=q0, rng=np.random.default_rng(4))
    assert LANES.select_isa("baseline") == "baseline"
    try:
        base = numeric.solve(robot, T, q0=q0, rng=np.random.default_rng(4))
    finally:
        LANES.select_isa(LANES.ISA)
    assert base.success.all() and fast.success.all()
    same = (base.iterations == fast.iterations) & (base.restarts == fast.restarts)
    assert same.mean() >= 0.98
    np.testing.assert_allclose(base.q[same], fast.q[same], rtol=0, atol=1e-9)


@needs_lanes
def test_inconsistent_arrays_are_refused_not_read_out_of_bounds():
    robot = robokin.load("ur5")
    d = numeric._chain_data(robot)
    q = random_q(robot, np.random.default_rng(14), 8)
    T, q0 = robot.fk(q), q + 1e-3  # one descent from nearby each
    opts = numeric._opts(None, None, 1e-9, None, 100, 1.0)
    opts[K.O_IDENT] = 1.0
    opts[K.O_USE_Q0] = 1.0
    tab, cstart, gdat = numeric._NO_TABLE
    args = [T, q0, np.zeros((8, 1, 6)), d.consts, d.jdat, d.Mc, d.cdat, opts,
            np.empty((8, 6 + K.N_RES)), tab, cstart, gdat, 1]
    assert LANES.solve(*args) == (0, -1)  # consistent: all eight solved
    for k, bad in [(8, np.empty((7, 6 + K.N_RES))), (1, q0[:, :5].copy()),
                   (5, d.Mc[:, :3].copy()), (7, opts[:10].copy())]:
        wrong = list(args)
        wrong[k] = bad
        with pytest.raises(ValueError, match="shapes"):
            LANES.solve(*wrong)
    wrong = list(args)
    wrong[1] = q0.astype(np.float32)
    with pytest.raises(ValueError, match="q0"):
        LANES.solve(*wrong)
