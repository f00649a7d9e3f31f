"""``check_*`` helpers: what a cast would silently change is refused (issue 15, item 4)."""

from __future__ import annotations

import numpy as np
import pytest

import robokin
from robokin._validation import (
    MAX_TRANSLATION,
    check_joints,
    check_rigid,
    check_transform,
    check_vector,
)
from robokin.exceptions import InputError


@pytest.fixture(scope="module")
def ur5():
    return robokin.load("ur5")


def test_an_overflowed_pose_is_refused_not_solved(ur5):
    # the attack: before, ik() returned NaN rows marked valid
    T = ur5.fk(np.array([0.1, -1.0, 1.2, -0.5, 0.4, 0.2])).copy()
    T[0, 3] = 1e300
    for method in ("auto", "analytic", "numeric"):
        with pytest.raises(InputError, match=r"'T'.*1e\+300 m is beyond the 1e\+06 m"):
            ur5.ik(T, method=method)
    with pytest.raises(InputError, match=r"beyond .*\(pose \(1,\)\)"):
        ur5.ik(np.stack([ur5.fk(np.zeros(6)), T]))
    with pytest.raises(InputError, match="beyond"):
        ur5.ik(T.tolist())
    with pytest.raises(InputError, match="beyond"):
        robokin.load("panda").ik(T[None])  # a numeric-only arm


def test_the_bound_is_the_documented_one_and_leaves_real_poses_alone(ur5):
    assert MAX_TRANSLATION == 1e6
    T = np.eye(4)
    T[2, 3] = MAX_TRANSLATION
    check_transform(T)  # at the bound: accepted (no solution, but a fair question)
    assert len(ur5.ik(T)) == 0
    T[2, 3] = np.nextafter(MAX_TRANSLATION, np.inf)
    with pytest.raises(InputError, match="beyond"):
        check_transform(T)
    T[2, 3] = np.inf  # non-finite values keep their own message
    with pytest.raises(InputError, match="non-finite"):
        check_transform(T)
    with pytest.raises(InputError, match="non-finite"):
        ur5.ik(T)
    q = np.array([0.1, -1.0, 1.2, -0.5, 0.4, 0.2])
    sols = ur5.ik(ur5.fk(q))
    assert np.isfinite(sols.q[sols.valid]).all() and len(sols) == 8


@pytest.mark.parametrize(("value", "message"), [
    (np.array([1 + 1j, 0, 0]), "complex values"),
    ([1 + 0j, 0, 0], "complex values"),
    (np.ma.masked_array([1.0, 2.0, 3.0], mask=[0, 1, 0]), "masked array"),
    ([True, False, True], "bool values"),
    (["1", "2", "3"], "<U1 values"),
    ([1, "2", 3], "values"),
    ([None, 1, 2], "expected numbers"),
])
def test_values_a_cast_would_change_are_refused(value, message):
    for check in (lambda v: check_joints(v, 3), lambda v: check_vector(v, 3, "q")):
        with pytest.raises(InputError, match=message):
            check(value)


def test_the_public_functions_refuse_them_too(ur5):
    with pytest.raises(InputError, match="complex"):
        ur5.fk(np.zeros(6, dtype=complex))
    with pytest.raises(InputError, match="masked"):
        ur5.jacobian(np.ma.masked_array(np.zeros(6)))
    with pytest.raises(InputError, match="complex"):
        check_transform(np.eye(4, dtype=complex))
    with pytest.raises(InputError, match="masked"):
        ur5.ik(np.ma.masked_array(np.eye(4)))
    # one configuration (the compiled fast path) and the numeric solver too
    with pytest.raises(InputError, match="masked"):
        ur5.fk(np.ma.masked_array(np.zeros(6), mask=[1, 0, 0, 0, 0, 0]))
    T = ur5.fk(np.full(6, 0.3))
    for bad, message in ((np.ma.masked_array(T), "masked"), (T.astype(complex), "complex"),
                         (np.eye(4, dtype=bool), "bool")):
        with pytest.raises(InputError, match=message):
            ur5.ik(bad, method="numeric")
    # plain integers and float32 are still numbers
    np.testing.assert_array_equal(check_joints(np.arange(3, dtype=np.int32), 3),
                                  [0.0, 1.0, 2.0])
    assert check_joints(np.zeros(3, np.float32), 3).dtype == np.float64


# ------------------------------------------- issue 25: unaligned float64 arrays
def unaligned(a) -> np.ndarray:
    """``a`` as a read-only, C-contiguous float64 array one byte off alignment
    (``np.frombuffer(b, offset=1)``, as a memory-mapped record file gives)."""
    a = np.ascontiguousarray(a, dtype=np.float64)
    u = np.frombuffer(b"\0" + a.tobytes(), dtype=np.float64, offset=1).reshape(a.shape)
    assert not u.flags.aligned and u.flags.c_contiguous and not u.flags.writeable
    return u


def _general_6r():
    """A UR5 with a twisted upper arm: the general 6R solver, not a closed form."""
    rows = [{"a": 0, "alpha": np.pi / 2, "d": 0.089}, {"a": -0.425, "alpha": 0.1, "d": 0},
            {"a": -0.392, "alpha": 0, "d": 0.05}, {"a": 0, "alpha": np.pi / 2, "d": 0.109},
            {"a": 0.01, "alpha": -np.pi / 2, "d": 0.095}, {"a": 0, "alpha": 0, "d": 0.082}]
    return robokin.Robot.from_dh(rows)


def _entries():
    """Every public entry whose arrays reach robokin._native: (name, call(make))."""
    from robokin.kinematics.forward import forward_kinematics
    from robokin.spatial import pose_error

    ur5, panda, g6 = robokin.load("ur5"), robokin.load("panda"), _general_6r()
    q = np.array([[0.1, -1.2, 1.1, -0.4, 1.3, 0.2], [0.0, -np.pi / 2, np.pi / 2, 0.0,
                                                     np.pi / 2, 0.0]])
    T = ur5.fk(q)
    q7 = np.array([0.1, -0.3, 0.2, -1.8, 0.1, 1.6, 0.3])
    T7 = panda.fk(q7)
    Tg = g6.fk(q[0])
    return [
        ("fk", lambda m: ur5.fk(m(q))),
        ("fk_all", lambda m: ur5.fk_all(m(q))),
        ("jacobian", lambda m: ur5.jacobian(m(q))),
        ("forward_kinematics", lambda m: forward_kinematics(ur5.chain, m(q))),
        ("ik closed form", lambda m: ur5.ik(m(T), q_near=m(q)).q),
        ("ik general 6R", lambda m: g6.ik(m(Tg)).q),
        # numeric IK draws random restarts from a process-wide generator unless
        # given one: the same rng for both calls
        ("ik numeric", lambda m: ur5.ik(m(T), q_near=m(q), method="numeric",
                                        rng=np.random.default_rng(1)).q),
        ("ik fixed joint", lambda m: panda.ik(m(T7), fixed={"joint7": 0.3}).q),
        ("ik_near", lambda m: ur5.ik_near(m(T), m(q)).q),
        ("ik_near numeric", lambda m: panda.ik_near(m(T7), m(q7)).q),
        ("pose_error", lambda m: pose_error(m(T), m(T[::-1]))),
        ("actuators", lambda m: robokin.load("scara").actuators_from_joints(
            m([0.1, 0.2, 0.3, 0.05]))),
    ]


@pytest.mark.parametrize("entry", _entries(), ids=lambda e: e[0])
def test_unaligned_arrays_are_copied_not_refused(entry):
    """Issue 25: a bare ValueError from robokin._native ("must be a C-contiguous
    native float64 array"). Oracle: the answer for the same values, aligned."""
    _, call = entry
    want = call(np.asarray)
    got = call(unaligned)
    np.testing.assert_array_equal(got, want)


def test_unaligned_arrays_reach_collision_and_trajectories():
    pytest.importorskip("coal")
    from robokin import collision, trajectory

    scene = collision.Scene.load(collision.scene_path("press"))
    robot = robokin.load("aubo_i5")
    q = np.linspace([0, -0.2, 1.0, 0, 1.2, 0], [0.5, 0.1, 1.2, 0.2, 1.0, 0.3], 20)
    want = collision.check(robot, scene, q)
    got = collision.check(robot, scene, unaligned(q))
    np.testing.assert_array_equal(got.min_distance, want.min_distance)
    T = robot.fk(q[-1])
    a = trajectory.cartesian_line(robot, q[0], T, 1.0, dt=0.05)
    b = trajectory.cartesian_line(robot, unaligned(q[0]), unaligned(T), 1.0, dt=0.05)
    np.testing.assert_array_equal(a.q, b.q)
    c = trajectory.quintic(unaligned(q[0]), unaligned(q[-1]), 1.0, dt=0.05)
    np.testing.assert_array_equal(c.q, trajectory.quintic(q[0], q[-1], 1.0, dt=0.05).q)


def test_unaligned_arrays_reach_the_cell_functions():
    pytest.importorskip("dask")
    pytest.importorskip("zarr")
    from robokin import cell

    robot = robokin.load("ur5")
    q = np.array([[0.1, -1.2, 1.1, -0.4, 1.3, 0.2], [0.4, -1.0, 1.3, -0.6, 1.1, 0.1]])
    task = robot.fk(q)
    cands = cell.base_grid([0.0, 0.05], [0.0], [0.0], [0.0])
    want = cell.place(robot, task, cands, max_step=np.inf, scheduler="synchronous")
    got = cell.place(robot, unaligned(task), unaligned(cands), max_step=np.inf,
                     scheduler="synchronous")
    np.testing.assert_array_equal(got.feasible, want.feasible)
    np.testing.assert_array_equal(got.score, want.score)
    R = task[:, :3, :3]
    box = [[0.2, -0.1, 0.2], [0.4, 0.1, 0.4]]
    m1 = cell.reach_map(robot, region=box, voxel=0.1, orientations=R,
                        scheduler="synchronous")
    m2 = cell.reach_map(robot, region=unaligned(box), voxel=0.1,
                        orientations=unaligned(R), scheduler="synchronous")
    np.testing.assert_array_equal(m1.reachable, m2.reachable)


def test_check_rigid_projects_rotations_near_so3_and_leaves_exact_ones_alone(ur5):
    """Oracle: the nearest rotation to s R (R a rotation, s > 0) is R itself; an
    exact pose comes back as the same array; a batch projects only its bad rows."""
    T = ur5.fk(np.array([0.3, -1.1, 0.9, 0.2, 1.0, -0.4]))
    assert check_rigid(T) is T
    bad = np.stack([T, T])
    bad[1, :3, :3] *= 1 - 1e-9
    kept = bad.copy()
    out = check_rigid(bad, "goal")
    assert np.array_equal(bad, kept)  # the input is not modified
    assert np.array_equal(out[0], T)
    np.testing.assert_allclose(out[1], T, rtol=0, atol=4e-16)
    R = out[1, :3, :3]
    assert np.abs(R.T @ R - np.eye(3)).max() < 1e-15 and np.linalg.det(R) > 0
    one = check_rigid(bad[1], "goal")  # one pose (4, 4): the unbatched test
    assert np.array_equal(one, out[1]) and np.array_equal(bad, kept)


def test_check_rigid_refuses_what_check_transform_refuses():
    T = np.eye(4)
    T[:3, :3] *= 1 - 1e-4
    with pytest.raises(InputError, match="goal.*orthonormal"):
        check_rigid(T, "goal")
