"""The 6R closed forms (``_six_r`` / ``csrc/six_r.c``) at the poses users hit (issue 23).

Oracles (``tests/special_values.py``): forward kinematics of the generating
configuration, numpy's SVD of the Jacobian (position rows divided by the arm's size
L, so the classes do not depend on the arm's scale), and the joint limits.

* Every returned solution reproduces its pose to 1e-12 m x max(1, L) and 1e-12 rad
  (position distance and rotation angle of FK against the target).
* Non-singular (smallest singular value >= 1e-5): the generating configuration is
  among the solutions, to 1e-7 rad (angles modulo 2 pi). A solution that reproduces
  the pose to 1e-12 lies within 1e-12 / 1e-5 of it.
* Singular (smallest singular value < 1e-10): a valid solution flagged singular.
* Every pose has a valid solution, and one inside the limits (their 1e-9 slack)
  when the generating configuration is inside them.
"""

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings

import robokin
import robokin._native as native
from robokin._native import kernels as K
from robokin.kinematics.ik.analytic._six_r import pack, raw_solve
from special_values import (
    angle_gap,
    arm_size,
    configurations,
    draw_configurations,
    inside_limits,
    pose_error,
    sigma_min,
)

SIX_R = ["ur5", "aubo_i5", "puma560", "puma560_modified"]
POSE_TOL = 1e-12
NONSINGULAR = 1e-5
SINGULAR = 1e-10
BACK_TOL = 1e-7


def check_against_oracle(robot, q, T, sols):
    """Assert the module docstring's properties for configurations q (N, n) (or one
    configuration (n,) and its one-pose set)."""
    L = max(1.0, arm_size(robot))
    one = q.ndim == 1
    q, T = (q[None], T[None]) if one else (q, T)
    valid, Q = sols.valid, sols.q
    within, singular = sols.flags["within_limits"], sols.flags["singular"]
    if one:
        valid, Q, within, singular = valid[None], Q[None], within[None], singular[None]
    dp, dr = pose_error(robot, np.where(valid[..., None], Q, 0.0), T[:, None])
    assert (dp[valid] <= POSE_TOL * L).all(), dp[valid].max()
    assert (dr[valid] <= POSE_TOL).all(), dr[valid].max()
    assert not (singular & ~valid).any() and not (within & ~valid).any()
    np.testing.assert_array_equal(within[valid], inside_limits(robot, Q[valid]))
    assert valid.any(axis=-1).all(), q[~valid.any(axis=-1)]
    sig = sigma_min(robot, q)
    gap = np.where(valid, angle_gap(robot, Q, q[:, None]).max(axis=-1), np.inf).min(-1)
    miss = (sig >= NONSINGULAR) & (gap > BACK_TOL)
    assert not miss.any(), (q[miss], gap[miss])
    unflagged = (sig < SINGULAR) & ~(singular & valid).any(axis=-1)
    assert not unflagged.any(), q[unflagged]
    outside = inside_limits(robot, q) & ~(within & valid).any(axis=-1)
    assert not outside.any(), q[outside]


@pytest.mark.parametrize("name", SIX_R)
def test_special_configurations_batch(name):
    # 20,000 configurations biased to special values, the batch path
    robot = robokin.load(name)
    q = draw_configurations(robot, np.random.default_rng(23), 20_000)
    T = robot.fk(q)
    check_against_oracle(robot, q, T, robot.ik(T))


@pytest.mark.parametrize("name", SIX_R)
def test_special_configurations_hypothesis(name):
    robot = robokin.load(name)

    @settings(max_examples=150, deadline=None, derandomize=True,
              suppress_health_check=[HealthCheck.too_slow])
    @given(configurations(robot))
    def one(q):
        T = robot.fk(q)
        sols = robot.ik(T)  # the single-pose path
        check_against_oracle(robot, q, T, sols)

    one()


# ------------------------------------------------------- the issue's examples
UR5_ISSUE = [0.5242586074560771, 0.021787275077687518, -0.6288161978063318,
             -1.1265421402299252, -1e-9, -0.5131604980023674]


def test_ur5_issue_example_is_solved_exactly_and_flagged():
    # issue 23: answered 'out of reach' (the numeric solver finds 5 solutions)
    robot = robokin.load("ur5")
    q = np.array(UR5_ISSUE)
    T = robot.fk(q)
    sols = robot.ik(T)
    assert sols.status == "ok"
    dp, dr = pose_error(robot, sols.solutions(), T)
    assert dp.max() <= POSE_TOL and dr.max() <= POSE_TOL
    # the wrist within 1e-9 of its singularity: the generating branch is flagged, and
    # comes back to the conditioning of the pose (rounding / 1e-9)
    near = sols.nearest(q, respect_limits=False)
    assert angle_gap(robot, near, q).max() < 1e-6
    assert sols.singular[sols.valid].any() and sols.within_limits[sols.valid].all()


@pytest.mark.parametrize("name", ["ur5", "aubo_i5"])
def test_near_singular_wrists_are_never_out_of_reach(name):
    # issue 23: 1.3 % (UR5) / 2.5 % (AUBO-i5) of these were 'out of reach', valid
    # rows reproduced the pose to 1.4e-8
    robot = robokin.load(name)
    rng = np.random.default_rng(5)
    lim = np.clip(robot.limits, -np.pi, np.pi)
    q = rng.uniform(lim[:, 0], lim[:, 1], (4000, 6))
    q[:, 4] = rng.choice([-1, 1], 4000) * 10 ** rng.uniform(-9, -7, 4000)
    T = robot.fk(q)
    sols = robot.ik(T)
    assert (sols.status == "ok").all()
    check_against_oracle(robot, q, T, sols)


@pytest.mark.parametrize("name", ["puma560", "puma560_modified"])
def test_puma_wrist_split_inside_the_limits(name):
    # issue 23: 0.03 % of in-limit wrist-singular targets got only splits outside
    # the limits (q4 has 280 degrees of range)
    robot = robokin.load(name)
    rng = np.random.default_rng(9)
    q = rng.uniform(robot.limits[:, 0], robot.limits[:, 1], (20_000, 6))
    q[:, 4] = 0.0
    T = robot.fk(q)
    sols = robot.ik(T)
    assert (sols.valid & sols.within_limits & sols.singular).any(axis=-1).all()
    check_against_oracle(robot, q, T, sols)


def test_in_limit_split_narrower_than_the_solvable_window():
    # AUBO-i5, q5 = 0 and q2 exactly at its limit: the elbow is solvable for q6 in a
    # window 0.02 rad wide (near full stretch), and inside it q2 stays within its limit
    # only for q6 within about 1e-5 of the generating value. The split search found
    # only the solvable window (q2 0.005 rad outside); oracle: FK and the limits.
    robot = robokin.load("aubo_i5")
    q = np.array([-1e-9, robot.limits[1, 1], -7.1244128998069201e-03, 1e-7, 0.0,
                  -5.5681006068983940e-01])
    T = robot.fk(q)
    sols = robot.ik(T)
    check_against_oracle(robot, q, T, sols)
    assert (sols.valid & sols.within_limits & sols.singular).any()


def test_puma_split_nearest_the_preferred_q6():
    # q4 = 150 deg, q6 = 60 deg at q5 = 0: q4 + q6 = 210 deg, so keeping q6 = 0 would
    # need q4 = 210 deg (outside [-110, 170]); the splits inside the limits nearest
    # q6 = 0 are q6 = +-40 deg with q4 at a limit. With q_near, q_near's own split.
    robot = robokin.load("puma560")
    q = np.radians([20.0, 40.0, -60.0, 150.0, 0.0, 60.0])
    T = robot.fk(q)
    sols = robot.ik(T)
    rows = sols.valid & sols.singular
    assert rows.any()
    best = sols.q[rows & sols.within_limits]
    assert len(best)
    k = np.argmin(np.abs(best[:, 5]))
    np.testing.assert_allclose(abs(best[k, 5]), math.radians(40.0), atol=1e-9)
    assert np.abs(best[k, 3] - robot.limits[3]).min() < 2e-9  # q4 at a limit
    own = robot.ik(T, q_near=q)
    assert angle_gap(robot, own.nearest(q), q).max() < 1e-9


@pytest.mark.parametrize("name", ["ur5", "aubo_i5", "puma560"])
def test_q_near_split_at_singular_targets(name):
    # q5 = 0 exactly: q_near's split (q6) where the arm can follow it
    robot = robokin.load(name)
    rng = np.random.default_rng(4)
    lim = np.clip(robot.limits, -np.pi, np.pi)
    q = rng.uniform(lim[:, 0], lim[:, 1], (3000, 6))
    q[:, 4] = 0.0
    T = robot.fk(q)
    near = robot.ik(T, q_near=q).nearest(q, respect_limits=False)
    assert (angle_gap(robot, near, q).max(axis=-1) < 1e-9).all()


# ------------------------------------------------------------------ the kernel
@pytest.mark.parametrize("name", SIX_R)
def test_the_check_band_loses_nothing(name):
    # Only solutions near a boundary or singularity are checked against the chain
    # (and polished, flagged): checking every one gives the same bits, so the others
    # met the tolerance by construction and are not singular.
    robot = robokin.load(name)
    kind = robokin.ik.family(robot).name
    rng = np.random.default_rng(2)
    q = np.concatenate([draw_configurations(robot, rng, 5000),
                        rng.uniform(-np.pi, np.pi, (5000, 6))])
    T = np.ascontiguousarray(robot.fk(q))
    packed = robot.chain.arrays.packed
    a = raw_solve(pack(robot.chain, kind), T, packed=packed)
    b = raw_solve(pack(robot.chain, kind, check_all=True), T, packed=packed)
    for x, y in zip(a, b, strict=True):
        np.testing.assert_array_equal(x, y)


@pytest.mark.parametrize("name", SIX_R)
def test_one_pose_batch_and_threads_give_the_same_bits(name):
    robot = robokin.load(name)
    q = draw_configurations(robot, np.random.default_rng(8), 3 * K.SIX_R_PARALLEL_MIN)
    T = robot.fk(q)
    before = native.num_threads()
    try:
        runs = []
        for k in (1, 2):
            native.set_num_threads(k)
            runs.append(robot.ik(T, q_near=q))
    finally:
        native.set_num_threads(before)
    for x, y in zip(runs[0].flags.values(), runs[1].flags.values(), strict=True):
        np.testing.assert_array_equal(x, y)
    np.testing.assert_array_equal(runs[0].q, runs[1].q)
    perm = np.random.default_rng(0).permutation(len(T))
    shuffled = robot.ik(T[perm], q_near=q[perm])
    np.testing.assert_array_equal(shuffled.q, runs[0].q[perm])
    for i in range(0, len(T), 37):  # the single-pose path (the AVX2 copy on AVX-512)
        one = robot.ik(T[i], q_near=q[i])
        np.testing.assert_array_equal(one.q, runs[0].q[i])
        np.testing.assert_array_equal(one.singular, runs[0].singular[i])
        np.testing.assert_array_equal(one.within_limits, runs[0].within_limits[i])


def test_avx2_and_avx512_copies_agree_to_the_bit():
    try:
        from robokin._native import _avx2, _avx512
    except ImportError as e:  # not built, or a copy this CPU does not run
        pytest.skip(f"the AVX2 and AVX-512 copies cannot both be imported here: {e}")
    if not (_avx2.cpu_has_avx2_fma() and _avx512.cpu_has_avx512()):
        pytest.skip("this CPU does not run both copies")
    for name in SIX_R[:3]:
        robot = robokin.load(name)
        q = draw_configurations(robot, np.random.default_rng(1), 4000)
        T = np.ascontiguousarray(robot.fk(q))
        P, packed = robokin.ik.family(robot).solver.params, robot.chain.arrays.packed
        a = _avx2.six_r_ik(P, T, np.ascontiguousarray(q), packed)
        b = _avx512.six_r_ik(P, T, np.ascontiguousarray(q), packed)
        for x, y in zip(a, b, strict=True):
            np.testing.assert_array_equal(x, y)


def test_a_pose_beyond_reach_by_more_than_the_tolerance_has_no_solution():
    # the stretched arm moved 1e-9 m further out: no row may claim to reach it
    robot = robokin.load("ur5")
    q = np.array([0.3, -0.7, 0.0, 0.4, 0.9, -0.5])
    T = robot.fk(q)
    d = T[:3, 3] - robot.fk_all(q)[2, :3, 3]
    ok = robot.ik(T)
    assert ok.status == "ok"
    T2 = T.copy()
    T2[:3, 3] += 1e-7 * d / np.linalg.norm(d)
    far = robot.ik(T2)
    if len(far):  # every row it keeps reproduces the moved pose
        dp, dr = pose_error(robot, far.solutions(), T2)
        assert dp.max() <= POSE_TOL and dr.max() <= POSE_TOL
