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

