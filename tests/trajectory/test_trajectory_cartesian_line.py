"""Cartesian lines: on the line to 1e-9 m, continuous joints, failures with time and reason."""

import numpy as np
import pytest

import robokin
from robokin import trajectory
from robokin.spatial import matrix_from_axis_angle, trans
from robokin.trajectory import PathError


def _deviation(P, p0, p1):
    u = (p1 - p0) / np.linalg.norm(p1 - p0)
    d = P - p0
    return np.linalg.norm(d - (d @ u)[:, None] * u, axis=1)


@pytest.fixture(scope="module")
def aubo():
    return robokin.load("aubo_i5")


Q0 = np.array([0.1, 0.5, 1.2, 0.4, 1.3, 0.6])


def _goal(robot, q, dp, rotvec=(0.0, 0.0, 0.0)):
    T0 = robot.fk(q)
    T1 = T0 @ matrix_from_axis_angle(np.asarray(rotvec))
    T1[:3, 3] += dp
    return T0, T1


@pytest.mark.parametrize("ik", ["follow", "analytic"])
def test_line_stays_on_the_line_to_1e9(aubo, ik):
    T0, T1 = _goal(aubo, Q0, [0.1, 0.15, -0.2], [0.2, -0.3, 0.1])
    tr = trajectory.cartesian_line(aubo, Q0, T1, 2.0, 0.005, ik=ik)
    P = aubo.fk(tr.q)
    dev = _deviation(P[:, :3, 3], T0[:3, 3], T1[:3, 3])
    assert dev.max() < 1e-9
    np.testing.assert_allclose(P[-1], T1, atol=1e-9)
    # orientation follows the slerp: the stored poses are reached
    np.testing.assert_allclose(P, tr.pose, atol=1e-9)
    # progress along the line is the quintic time scaling
    s = np.linalg.norm(P[:, :3, 3] - T0[:3, 3], axis=1) / np.linalg.norm(T1[:3, 3] - T0[:3, 3])
    tau = tr.t / 2.0
    np.testing.assert_allclose(s, 10 * tau**3 - 15 * tau**4 + 6 * tau**5, atol=1e-9)


def test_line_joint_path_is_continuous_and_rates_consistent(aubo):
    _, T1 = _goal(aubo, Q0, [0.2, -0.1, 0.05], [0.0, 0.0, 0.5])
    tr = trajectory.cartesian_line(aubo, Q0, T1, 1.5)
    assert np.abs(np.diff(tr.q, axis=0)).max() < 0.02  # no branch flip at 5 ms
    np.testing.assert_allclose(tr.q[0], Q0, atol=1e-12)
    fd = np.gradient(tr.q, tr.t, axis=0)
    np.testing.assert_allclose(tr.qd[1:-1], fd[1:-1], atol=2e-4)  # O(dt^2) of the FD
    fdd = np.gradient(tr.qd, tr.t, axis=0)
    np.testing.assert_allclose(tr.qdd[1:-1], fdd[1:-1], atol=2e-3)
    np.testing.assert_allclose(tr.qd[[0, -1]], 0.0, atol=1e-12)
    # tool velocity from J qd equals the line's velocity
    v = np.einsum("mij,mj->mi", aubo.jacobian(tr.q), tr.qd)[:, :3]
    np.testing.assert_allclose(v, np.gradient(tr.pose[:, :3, 3], tr.t, axis=0,
                                              edge_order=2), atol=5e-5)


@pytest.mark.parametrize("name, q", [
    ("panda", [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]),  # 7 joints: redundant
    ("scara", [0.3, 1.0, 0.2, 0.1]),  # 4 joints: the line keeps the reachable attitude
    ("ur5", [0.1, -1.2, 1.5, -1.0, -1.5, 0.3]),
])
def test_line_on_other_arms(name, q):
    r = robokin.load(name)
    q = np.array(q)
    T0 = r.fk(q)
    T1 = trans(0.02, -0.03, 0.01) @ T0  # a short line, keeps the tool attitude
    tr = trajectory.cartesian_line(r, q, T1, 1.0, 0.01)
    P = r.fk(tr.q)[:, :3, 3]
    assert _deviation(P, T0[:3, 3], T1[:3, 3]).max() < 1e-9
    np.testing.assert_allclose(P[-1], T1[:3, 3], atol=1e-9)
    assert np.abs(np.diff(tr.q, axis=0)).max() < 0.05


def test_out_of_reach_reports_sample_time_and_reason(aubo):
    T0, T1 = _goal(aubo, Q0, [1.5, 0.0, 0.0])
    with pytest.raises(PathError, match="out of reach") as info:
        trajectory.cartesian_line(aubo, Q0, T1, 2.0)
    err = info.value
    assert 0 < err.index < 401 and err.time == pytest.approx(err.index * 0.005)
    # the failing sample really is beyond the arm's reach from the shoulder
    res = err.result
    assert res.success[: err.index].all() and not res.success[err.index:].any()
    assert res.kind == "out_of_reach"


def test_joint_limit_stops_the_line(aubo):
    from robokin.model.chain import Joint
    from robokin.spatial import rotz

    coords = list(aubo.chain.coordinates)
    c0 = coords[0]
    coords[0] = Joint(c0.name, c0.kind, (-0.2, 0.2), c0.sign, c0.offset)
    tight = aubo.replace(chain=aubo.chain.replace(coordinates=tuple(coords)))
    np.testing.assert_allclose(tight.limits[0], [-0.2, 0.2])
    np.testing.assert_allclose(tight.limits[1:], aubo.limits[1:])
    T1 = rotz(0.4) @ tight.fk(Q0)  # the shoulder has to turn from 0.1 to 0.5 rad
    with pytest.raises(PathError, match="joint limit: shoulder") as info:
        trajectory.cartesian_line(tight, Q0, T1, 1.0)
    res = info.value.result
    assert res.kind == "joint_limit"
    assert res.q[info.value.index - 1, 0] <= 0.2 + 1e-12
    assert info.value.time == pytest.approx(info.value.index * 0.005)


def test_duration_from_limits(aubo):
    _, T1 = _goal(aubo, Q0, [0.1, 0.1, -0.1])
    tr = trajectory.cartesian_line(aubo, Q0, T1, v_max=0.5, a_max=1.0)
    assert np.abs(tr.qd).max() <= 0.5 * 1.02
    assert np.abs(tr.qdd).max() <= 1.0 * 1.05
    tr2 = trajectory.cartesian_line(aubo, Q0, T1, tool_speed=0.05)
    L = np.linalg.norm([0.1, 0.1, -0.1])
    assert tr2.duration == pytest.approx(1.875 * L / 0.05, abs=0.005)

def test_a_line_to_an_unreachable_goal_says_so():
    import numpy as np
    import pytest

    import robokin
    from robokin import trajectory

    robot = robokin.load("ur5")
    q0 = np.radians([0, -90, 90, -90, -90, 0])
    goal = robot.fk(q0)
    goal[0, 3] = 5.0  # 5 m away: far beyond the UR5's 0.95 m reach
    with pytest.raises(trajectory.PathError, match="goal itself is unreachable: out of reach"):
        trajectory.cartesian_line(robot, q0, goal, 2.0)


def test_the_followers_residual_is_spatial_pose_error_bit_for_bit(aubo):
    """The follower's residual (trajectory.cartesian._err, the compiled kernel called
    directly) is robokin.spatial.pose_error's (the oracle: the public, checked
    function) bit for bit, rotations near pi and the identity included, on a
    non-contiguous path too (follow_poses makes its own contiguous copy)."""
    from robokin.spatial import pose_error
    from robokin.trajectory.cartesian import _err, follow_poses, line_poses

    rng = np.random.default_rng(3)
    q = rng.uniform(-2.0, 2.0, (40, 6))
    T = aubo.fk(q)
    Tt = T[rng.permutation(40)]
    Tt[0] = T[0]  # identical poses: zero residual
    Tt[1] = T[1] @ matrix_from_axis_angle(np.array([np.pi - 1e-9, 0.0, 0.0]))
    e = np.empty(6)
    for a, b in zip(T, Tt, strict=True):
        size = _err(a, b, e)
        ref = pose_error(a, b)
        assert e.tobytes() == ref.tobytes() and size == np.abs(ref).max()
    # a strided (non-contiguous) path follows like its contiguous copy
    T0, T1 = _goal(aubo, Q0, [0.02, 0.01, -0.03])
    path = line_poses(T0, T1, np.linspace(0.0, 1.0, 21))
    wide = np.zeros((21, 4, 8))
    wide[:, :, ::2] = path
    strided = wide[:, :, ::2]
    assert not strided.flags.c_contiguous
    a = follow_poses(aubo, strided, Q0)
    b = follow_poses(aubo, path, Q0)
    assert a.first_failure is None and a.error.max() < 1e-9
    assert a.q.tobytes() == b.q.tobytes()
