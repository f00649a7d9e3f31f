"""Closed-form 6R IK hot paths: the compiled atan2, the single-pose path against the
batch path, the parallel batch against the serial one, and fresh result arrays."""

import math

import numpy as np
import pytest

import robokin
from robokin._native import kernels
from robokin.exceptions import InputError
from robokin.kinematics.ik.analytic._six_r import _PARALLEL_MIN


def fatan2(y, x):
    """The 6R kernels' atan2 (csrc/six_r.c) on arrays."""
    y = np.ascontiguousarray(y, dtype=np.float64)
    x = np.ascontiguousarray(x, dtype=np.float64)
    out = np.empty_like(y)
    kernels.atan2(y, x, out)
    return out

SIX_R = ["ur5", "aubo_i5", "puma560", "puma560_modified"]


def test_fatan2_matches_libm_to_a_few_ulp():
    rng = np.random.default_rng(11)
    n = 20000
    y = rng.normal(size=n) * 10.0 ** rng.uniform(-6, 6, n)
    x = rng.normal(size=n) * 10.0 ** rng.uniform(-6, 6, n)
    # exact octant boundaries and the tan(pi/8) switch point too
    y = np.concatenate([y, [1.0, -1.0, 1.0, math.tan(math.pi / 8), 3.0, -2.0]])
    x = np.concatenate([x, [1.0, 1.0, -1.0, 1.0, 0.0, -0.0]])
    assert np.abs(fatan2(y, x) - np.arctan2(y, x)).max() < 1e-15


@pytest.mark.parametrize(
    ("y", "x"),
    [(0.0, 1.0), (-0.0, 1.0), (0.0, -1.0), (-0.0, -1.0), (0.0, 0.0), (-0.0, -0.0),
     (math.inf, 1.0), (1.0, -math.inf), (math.nan, 1.0), (1.0, math.nan), (0.0, math.nan)],
)
def test_fatan2_special_values_like_libm(y, x):
    got, want = float(fatan2([y], [x])[0]), math.atan2(y, x)
    if math.isnan(want):
        assert math.isnan(got)
    else:
        assert got == want and math.copysign(1.0, got) == math.copysign(1.0, want)


@pytest.mark.parametrize("name", SIX_R)
def test_single_pose_path_equals_batch_path(name):
    robot = robokin.load(name)
    rng = np.random.default_rng(5)
    q = rng.uniform(-3.0, 3.0, (40, 6))
    q[:10, 4] = 0.0  # wrist singular: theta6 kept at q_near
    T = robot.fk(q)
    batch = robot.ik(T, q_near=q)
    assert batch.singular[:10].any(axis=-1).all()
    for k in range(len(T)):
        one = robot.ik(T[k], q_near=q[k])
        ref = batch[k]
        np.testing.assert_array_equal(one.valid, ref.valid)
        np.testing.assert_allclose(one.q[one.valid], ref.q[ref.valid], atol=1e-12)
        for flag in ("within_limits", "singular"):
            np.testing.assert_array_equal(one.flags[flag], ref.flags[flag])
        for label, v in ref.branches.items():
            np.testing.assert_array_equal(one.branches[label], v)
        assert one.status.shape == () and one.status.dtype == object
        assert one.status == ref.status == "ok"
        assert one.method == ref.method and one.info == ref.info
    # theta6 at the wrist singularity is the given one
    sols = robot.ik(T[0], q_near=q[0])
    assert np.allclose(sols.q[sols.valid & sols.singular][:, 5], q[0, 5])


def test_single_pose_non_contiguous_and_unreachable():
    robot = robokin.load("ur5")
    T = robot.fk(np.array([0.3, -1.0, 1.2, 0.4, 0.9, -0.5]))
    a = robot.ik(T)
    b = robot.ik(np.asfortranarray(T))
    np.testing.assert_array_equal(a.q, b.q)
    far = np.eye(4)
    far[0, 3] = 5.0
    sols = robot.ik(far)
    assert len(sols) == 0 and sols.status == "out of reach"


@pytest.mark.parametrize(
    ("change", "match"),
    [(lambda T: T.__setitem__((0, 0), 2.0), "not orthonormal"),
     (lambda T: T.__setitem__((1, 3), np.nan), "non-finite"),
     (lambda T: T.__setitem__((3, 0), 0.5), "last row"),
     (lambda T: T.__setitem__((2, 2), -1.0), "reflection")],
)
def test_single_pose_still_validated(change, match):
    robot = robokin.load("ur5")
    T = np.eye(4)
    change(T)
    with pytest.raises(InputError, match=match):
        robot.ik(T)


def test_results_never_share_writable_buffers():
    robot = robokin.load("puma560")
    T = robot.fk(np.array([0.1, -0.4, 0.3, 0.2, 0.7, -0.1]))
    a = robot.ik(T)
    b = robot.ik(T)
    for x, y in [(a.q, b.q), (a.valid, b.valid), (a.flags["within_limits"],
                 b.flags["within_limits"]), (a.flags["singular"], b.flags["singular"])]:
        assert not np.shares_memory(x, y)
    q_before = b.q.copy()
    a.q[...] = 99.0
    a.status[()] = "changed"
    np.testing.assert_array_equal(b.q, q_before)
    assert b.status == "ok"
    assert not a.is_revolute.flags.writeable and not a.limits.flags.writeable
    assert a.flags is not b.flags and a.branches is not b.branches and a.info is not b.info


@pytest.mark.parametrize("name", ["ur5", "puma560"])
def test_parallel_batch_equals_serial_chunks(name):
    robot = robokin.load(name)
    n = _PARALLEL_MIN + 88
    q = np.random.default_rng(9).uniform(-np.pi, np.pi, (n, 6))
    T = robot.fk(q)
    whole = robot.ik(T)  # all threads
    half = n // 2  # below the parallel threshold: one thread
    parts = [robot.ik(T[:half]), robot.ik(T[half:])]
    np.testing.assert_array_equal(whole.valid, np.concatenate([p.valid for p in parts]))
    np.testing.assert_array_equal(whole.q, np.concatenate([p.q for p in parts]))
    np.testing.assert_array_equal(whole.flags["within_limits"],
                                  np.concatenate([p.flags["within_limits"] for p in parts]))
    np.testing.assert_array_equal(whole.status, np.concatenate([p.status for p in parts]))


@pytest.mark.parametrize(
    ("q_near", "match"),
    [(np.array([0.0, 0.0, 0.0, 0.0, 0.0, np.nan]), r"non-finite value at index \(5,\)"),
     (np.array([np.inf, -np.inf, 0.0, 0.0, 0.0, 0.0]), r"non-finite value at index \(0,\)"),
     (np.zeros(5), r"expected shape \(\.\.\., 6\)")],
)
def test_single_pose_q_near_still_validated(q_near, match):
    robot = robokin.load("ur5")
    T = robot.fk(np.array([0.3, -1.0, 1.2, 0.4, 0.9, -0.5]))
    with pytest.raises(InputError, match=match):
        robot.ik(T, q_near=q_near)


@pytest.mark.parametrize(("name", "family"), [("ur5", "THREE_PARALLEL"),
                                              ("puma560", "SPHERICAL_WRIST")])
def test_kernel_constants_index_what_pack_writes(name, family):
    from robokin.kinematics.ik.analytic._geometry import poe_from_chain
    from robokin.kinematics.ik.analytic._six_r import pack

    K = kernels
    chain = robokin.load(name).chain
    kind = "three_parallel" if family == "THREE_PARALLEL" else "spherical_wrist"
    P = pack(chain, kind, singular_tol=3e-9, disc_tol=7e-12, mirror=True)
    poe = poe_from_chain(chain)
    assert P.shape == (K.N_PARAMS,)
    # the sections tile the vector without overlap
    sizes = {"AXES": 18, "POINTS": 12, "WRIST": 3, "PERP2": 3, "TOOL_T": 3, "TOOL_R": 9,
             "PERP": 3, "SIGN": 6, "OFFSET": 6, "LO": 6, "HI": 6, "PLANE": 7}
    scalars = ["S3", "S4", "SING_TOL", "DISC_TOL", "MIRROR", "A3", "B3", "C3", "PHI3",
               "CPHI3", "SPHI3", "A5", "B5", "C5", "PHI5", "CPHI5", "SPHI5", "AA", "BB",
               "FAMILY", "E5", "SPLIT_TOL", "TOL_P", "TOL_R", "CHECK", "SIZE"]
    used = np.zeros(K.N_PARAMS, int)
    for key, size in list(sizes.items()) + [(k, 1) for k in scalars]:
        used[getattr(K, key):getattr(K, key) + size] += 1
    assert used.max() == 1 and used.sum() == K.N_PARAMS  # the sections tile it
    # what sits at each index
    assert P[K.FAMILY] == getattr(K, family)
    assert (P[K.SING_TOL], P[K.DISC_TOL], P[K.MIRROR]) == (3e-9, 7e-12, 1.0)
    assert P[K.CHECK] == -1.0  # mirrored (near-family) seeds: Python polishes them
    np.testing.assert_array_equal(P[K.SIGN:K.SIGN + 6], chain.arrays.sign)
    np.testing.assert_array_equal(P[K.OFFSET:K.OFFSET + 6], chain.arrays.offset)
    np.testing.assert_array_equal(P[K.LO:K.LO + 6], chain.limits[:, 0])
    np.testing.assert_array_equal(P[K.HI:K.HI + 6], chain.limits[:, 1])
    np.testing.assert_array_equal(P[K.POINTS:K.POINTS + 12], poe.o[:4].ravel())
    np.testing.assert_array_equal(P[K.TOOL_T:K.TOOL_T + 3], poe.M[:3, 3])
    np.testing.assert_array_equal(P[K.TOOL_R:K.TOOL_R + 9], poe.M[:3, :3].ravel())
    h = P[K.AXES:K.AXES + 18].reshape(6, 3)
    np.testing.assert_allclose(np.linalg.norm(h, axis=1), 1.0, atol=1e-15)
    np.testing.assert_allclose(np.abs(np.einsum("ij,ij->i", h, poe.h)), 1.0, atol=1e-12)
    hw = h[1 if family == "THREE_PARALLEL" else 3]
    e = P[K.PERP:K.PERP + 3]
    assert abs(e @ hw) < 1e-15
    np.testing.assert_array_equal(P[K.PERP2:K.PERP2 + 3], np.cross(hw, e))
    # theta5's discriminant constant: -(hw.h5)^2 - (h5.h6)^2, zero for these wrists
    assert P[K.E5] == -((hw @ h[4]) ** 2 + (h[4] @ h[5]) ** 2) and abs(P[K.E5]) < 1e-30
    assert P[K.TOL_R] == 0.5e-12  # half the guarantee
    assert P[K.TOL_P] == 0.5e-12 * max(1.0, P[K.SIZE])  # [m], arms larger than 1 m
    assert P[K.SPLIT_TOL] == 0.4e-12
    assert P[K.S3] == np.sign(h[1] @ h[2]) and abs(P[K.S4]) == 1.0
    o = P[K.POINTS:K.POINTS + 12].reshape(4, 3)
    a = o[2] - o[1]
    b = (o[3] if family == "THREE_PARALLEL" else P[K.WRIST:K.WRIST + 3]) - o[2]
    assert (P[K.AA], P[K.BB]) == (a @ a, b @ b)
    for A, B, PHI in ((K.A3, K.B3, K.PHI3), (K.A5, K.B5, K.PHI5)):
        assert P[PHI] == np.arctan2(P[B], P[A])
        np.testing.assert_allclose(P[PHI + 1:PHI + 3], [np.cos(P[PHI]), np.sin(P[PHI])],
                                   atol=1e-15)
    # the kernel reads the family from the vector: the other family's code is refused
    bad = P.copy()
    bad[K.FAMILY] = 2.0
    with pytest.raises(ValueError, match="6R parameter vector"):
        kernels.six_r_ik(bad, np.eye(4)[None], np.zeros((1, 6)), chain.arrays.packed)
    assert max(K.STATUS_OK, K.STATUS_OUT_OF_REACH, K.STATUS_NO_ORIENTATION) < K.BAD_POSE


@pytest.mark.parametrize("name", ["ur5", "puma560"])
def test_batch_results_do_not_depend_on_thread_count(name):
    import robokin._native as native

    robot = robokin.load(name)
    rng = np.random.default_rng(3)
    q = rng.uniform(-np.pi, np.pi, (3 * _PARALLEL_MIN, 6))
    q[::7, 4] = 0.0  # wrist singular rows (theta6 from q_near)
    T = robot.fk(q)
    before = native.num_threads()
    try:
        runs = []
        for k in (1, 2):
            assert native.set_num_threads(k) == k
            runs.append(robot.ik(T, q_near=q))
    finally:
        native.set_num_threads(before)
    one, two = runs
    assert one.singular.any()
    np.testing.assert_array_equal(one.q, two.q)
    np.testing.assert_array_equal(one.valid, two.valid)
    np.testing.assert_array_equal(one.status, two.status)
    for flag in ("within_limits", "singular"):
        np.testing.assert_array_equal(one.flags[flag], two.flags[flag])
