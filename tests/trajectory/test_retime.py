"""Time-optimal retiming (issue 18): closed-form minimum times, every sample within
the limits, the path kept, stops and dwells kept, exact end, slower cycle times."""

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import robokin
from robokin import trajectory
from robokin.spatial import trans

pytest.importorskip("toppra")
pytest.importorskip("ruckig")

Q_HOME = np.radians([0, -60, 80, -20, 90, 0])


@pytest.fixture(scope="module")
def ur5():
    return robokin.load("ur5")


@pytest.fixture(scope="module")
def aubo():
    return robokin.load("aubo_i5")


def trapezoid_time(dist, v, a):
    """Rest-to-rest minimum time of one joint: bang-coast-bang, or bang-bang."""
    return dist / v + v / a if dist >= v * v / a else 2.0 * math.sqrt(dist / a)


def one_joint_move(robot, joint, D, duration=2.0, dt=0.005):
    q0 = Q_HOME.copy()
    q1 = q0.copy()
    q1[joint] += D
    return trajectory.quintic(q0, q1, duration, dt=dt)


def assert_within_limits(res, tol=1e-6):
    """No sample exceeds a limit by more than ``tol`` relative (issue 18 target)."""
    tr, lim = res.trajectory, res.limits
    assert (np.abs(tr.qd) <= lim.velocity * (1 + tol)).all()
    assert (np.abs(tr.qdd) <= lim.acceleration * (1 + tol)).all()
    if lim.jerk is not None:
        assert (np.abs(res.jerk) <= lim.jerk * (1 + tol)).all()


# ------------------------------------------------------------------ closed forms
@pytest.mark.parametrize("D, v, a", [
    (1.3, 1.1, 2.3),     # reaches the speed limit: bang-coast-bang
    (0.4, 1.1, 2.3),     # does not: bang-bang
    (2.0, 0.7, 5.0),
    (-1.7, 2.0, 0.9),    # backwards
    (1.25, 1.25, 1.25),  # D = v^2/a: the apex touches the speed limit
    (1.0, 0.25, 11.0),   # the switches fall inside the first and last grid intervals
])
@pytest.mark.parametrize("dt", [0.005, 0.0037])
def test_single_joint_rest_to_rest_matches_the_closed_form(ur5, D, v, a, dt):
    # neither the sampling period nor the grid is aligned with the switch times:
    # the exact final timing step makes the duration the closed form itself
    res = trajectory.retime_detailed(ur5, one_joint_move(ur5, 2, D, dt=0.005),
                                     v_max=v, a_max=a, dt=dt)
    assert res.duration == pytest.approx(trapezoid_time(abs(D), v, a), abs=1e-6)
    assert_within_limits(res)
    tr = res.trajectory
    assert tr.t[-1] == res.duration
    assert np.allclose(np.diff(tr.t)[:-1], dt)  # every step dt but a shorter last one


@pytest.mark.parametrize("grid_points", [37, 500, 2001])
def test_the_grid_does_not_change_the_closed_form(ur5, grid_points):
    res = trajectory.retime_detailed(ur5, one_joint_move(ur5, 0, 1.3), v_max=1.1,
                                     a_max=2.3, grid_points=grid_points)
    assert res.duration == pytest.approx(trapezoid_time(1.3, 1.1, 2.3), abs=1e-6)


@settings(max_examples=25, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(D=st.floats(0.05, 3.0), v=st.floats(0.2, 3.0), a=st.floats(0.5, 20.0),
       joint=st.integers(0, 5))
def test_closed_form_property(ur5, D, v, a, joint):
    res = trajectory.retime_detailed(ur5, one_joint_move(ur5, joint, D), v_max=v,
                                     a_max=a)
    assert res.duration == pytest.approx(trapezoid_time(D, v, a), abs=1e-6)


def test_straight_multi_joint_move_is_limited_by_the_slowest_joint(ur5):
    d = np.array([0.8, -0.5, 1.2, 0.3, 0.0, -0.9])
    v = np.array([1.0, 0.6, 2.0, 1.5, 1.0, 1.2])
    a = np.array([3.0, 0.9, 6.0, 4.0, 4.0, 2.0])
    tr = trajectory.quintic(Q_HOME, Q_HOME + d, 3.0)
    res = trajectory.retime_detailed(ur5, tr, v_max=v, a_max=a)
    L = np.linalg.norm(d)
    moving = d != 0
    V = np.min(v[moving] * L / np.abs(d[moving]))  # path speed: the slowest joint
    A = np.min(a[moving] * L / np.abs(d[moving]))
    assert res.duration == pytest.approx(trapezoid_time(L, V, A), abs=1e-6)
    assert_within_limits(res)


def test_jerk_limited_move_matches_the_closed_form(ur5):
    # all three limits reached: T = D/v + v/a + a/j (v >= a^2/j, D >= v (v/a + a/j))
    D, v, a, j = 2.0, 1.0, 2.0, 10.0
    res = trajectory.retime_detailed(ur5, one_joint_move(ur5, 1, D), v_max=v,
                                     a_max=a, j_max=j)
    assert res.duration == pytest.approx(D / v + v / a + a / j, abs=1e-6)
    assert {s.method for s in res.sections} == {"ruckig"}
    assert_within_limits(res)
    # the sampled jerk is the profile's: +-j in the ramps, 0 elsewhere
    assert np.abs(res.jerk[:, 1]).max() == pytest.approx(j, rel=1e-9)


# ------------------------------------------------------------ limits, any path
def via_path(robot, rng, n_via=4, lines=True):
    """A random path: blended joint via points, and Cartesian lines down and up."""
    pb = trajectory.PathBuilder(robot, Q_HOME, dt=0.005, v_max=1.0, a_max=2.0)
    for _ in range(n_via):
        pb.joint(Q_HOME + rng.uniform(-0.5, 0.5, robot.n))
    if lines:
        T = robot.fk(pb.q_end)
        pb.line(trans(0, 0, -0.08) @ T, duration=1.0)
        pb.dwell(0.3)
        pb.line(T, duration=1.0)
    pb.joint(Q_HOME)
    return pb.build()


@pytest.mark.parametrize("seed", range(4))
def test_every_sample_is_within_the_limits(ur5, seed):
    rng = np.random.default_rng(seed)
    tr = via_path(ur5, rng)
    v = rng.uniform(1.0, 3.0, 6)
    a = rng.uniform(2.0, 10.0, 6)
    res = trajectory.retime_detailed(ur5, tr, v_max=v, a_max=a)
    assert_within_limits(res)
    assert res.duration < tr.duration
    # time-optimal: some joint is at a limit somewhere
    peak = max((np.abs(res.trajectory.qd) / v).max(),
               np.sqrt((np.abs(res.trajectory.qdd) / a).max()))
    assert peak == pytest.approx(1.0, abs=1e-6)


def test_jerk_limits_hold_on_a_curved_path(ur5, rng):
    tr = via_path(ur5, rng)
    res = trajectory.retime_detailed(ur5, tr, v_max=2.0, a_max=5.0, j_max=50.0)
    assert_within_limits(res)
    topp = trajectory.retime_detailed(ur5, tr, v_max=2.0, a_max=5.0)
    assert res.duration > topp.duration  # jerk limits only ever cost time


def test_tool_speed_is_respected(ur5, rng):
    tr = via_path(ur5, rng)
    res = trajectory.retime_detailed(ur5, tr, v_max=3.0, a_max=10.0, tool_speed=0.25)
    out = res.trajectory
    J = ur5.jacobian(out.q)[:, :3, :]
    speed = np.linalg.norm(np.einsum("kij,kj->ki", J, out.qd), axis=1)
    assert speed.max() <= 0.25 * (1 + 1e-6)
    assert speed.max() == pytest.approx(0.25, rel=1e-3)


def test_limits_default_to_the_robot_file(aubo):
    tr = trajectory.quintic(np.zeros(6), np.full(6, 0.5), 3.0)
    res = trajectory.retime_detailed(aubo, tr)
    np.testing.assert_array_equal(res.limits.velocity, aubo.rate_limits.velocity)
    assert "datasheet" in res.limits.sources["velocity"]
    assert_within_limits(res)
    over = trajectory.retime_detailed(aubo, tr, v_max=0.5)
    assert over.limits.sources["velocity"] == "argument"
    assert over.duration > res.duration


# ----------------------------------------------------------------- the path kept
def test_cartesian_lines_stay_on_the_line(ur5):
    q0 = Q_HOME
    T0 = ur5.fk(q0)
    T1 = trans(0.05, -0.1, -0.12) @ T0
    tr = trajectory.cartesian_line(ur5, q0, T1, 2.0)
    res = trajectory.retime_detailed(ur5, tr, v_max=3.0, a_max=8.0)
    p = ur5.fk(res.trajectory.q)[:, :3, 3]
    a, b = T0[:3, 3], T1[:3, 3]
    u = (b - a) / np.linalg.norm(b - a)
    d = p - a
    off_line = np.linalg.norm(d - np.outer(d @ u, u), axis=1)
    assert off_line.max() < 1e-6  # [m]
    np.testing.assert_allclose(p[-1], b, atol=1e-9)
    # the stored poses are the tool poses
    np.testing.assert_allclose(res.trajectory.pose, ur5.fk(res.trajectory.q))


def _distance_to_polyline(points, poly):
    """For each point, the distance to the polyline through ``poly`` (k, n)."""
    a, b = poly[:-1], poly[1:]
    ab = b - a
    out = np.empty(len(points))
    for i, p in enumerate(points):
        w = np.clip(np.einsum("kj,kj->k", p - a, ab) / np.maximum(
            np.einsum("kj,kj->k", ab, ab), 1e-300), 0.0, 1.0)
        out[i] = np.linalg.norm(a + w[:, None] * ab - p, axis=1).min()
    return out


def test_via_path_geometry_is_kept(ur5, rng):
    vias = [Q_HOME + rng.uniform(-0.5, 0.5, 6) for _ in range(3)]

    def build(dt):  # the same path (durations given) sampled at another rate
        pb = trajectory.PathBuilder(ur5, Q_HOME, dt=dt)
        for qv in vias:
            pb.joint(qv, duration=1.5)
        pb.joint(Q_HOME, duration=1.5)
        return pb.build()

    res = trajectory.retime_detailed(ur5, build(0.005), v_max=2.0, a_max=6.0)
    fine = build(0.0005).q
    dist = _distance_to_polyline(res.trajectory.q, fine)
    assert dist.max() < 1e-6  # [rad]
    # the via points are passed at their new times
    for tv, qv in zip(res.trajectory.via_times[1:-1], vias):
        np.testing.assert_allclose(res.trajectory.at([tv])[0], qv, atol=1e-4)


def test_stops_and_dwells_are_kept(ur5, rng):
    tr = via_path(ur5, rng)
    res = trajectory.retime_detailed(ur5, tr, v_max=2.0, a_max=6.0)
    kinds = [s.kind for s in res.sections]
    assert kinds.count("dwell") == 1
    dwell = next(s for s in res.sections if s.kind == "dwell")
    assert dwell.duration == pytest.approx(0.3)
    out = res.trajectory
    inside = (out.t > dwell.t_start + 1e-9) & (out.t < dwell.t_end - 1e-9)
    assert np.abs(out.qd[inside]).max() == 0.0
    # each move starts and ends at rest
    for s in res.sections:
        for t in (s.t_start, s.t_end):
            k = int(np.argmin(np.abs(out.t - t)))
            assert np.abs(out.qd[k]).max() < 0.05
    without = trajectory.retime_detailed(ur5, tr, v_max=2.0, a_max=6.0,
                                         keep_dwells=False)
    assert without.duration == pytest.approx(res.duration - 0.3, abs=1e-9)
    assert res.trajectory.labels == tr.labels


def test_a_bare_joint_path_is_a_spline_through_its_points(ur5):
    pts = Q_HOME + np.array([[0, 0, 0, 0, 0, 0], [0.3, 0.1, 0, 0, 0, 0],
                             [0.5, 0.3, 0.1, 0, 0, 0], [0.6, 0.6, 0.3, 0, 0, 0]])
    res = trajectory.retime_detailed(ur5, pts, v_max=1.0, a_max=3.0)
    out = res.trajectory
    np.testing.assert_allclose(out.q[[0, -1]], pts[[0, -1]], atol=1e-12)
    assert _distance_to_polyline(pts[1:3], out.q).max() < 2e-3  # passes near them
    assert_within_limits(res)


def test_motor_space_trajectories_are_retimed_in_joint_space():
    scara = robokin.load("scara")
    q0 = np.array([0.2, 0.4, 0.0, 0.05])
    tr = trajectory.quintic(q0, q0 + [0.6, -0.4, 1.0, 0.1], 2.0,
                            ).replace(is_revolute=scara.is_revolute)
    res = trajectory.retime_detailed(scara, tr.to_actuator_space(scara), v_max=1.0,
                                     a_max=2.0)
    assert res.trajectory.space == "joint"
    np.testing.assert_allclose(res.trajectory.q[-1], q0 + [0.6, -0.4, 1.0, 0.1],
                               atol=1e-12)


# ---------------------------------------------------- end time, slower cycles
def test_round_to_dt_gives_whole_samples(ur5):
    res = trajectory.retime_detailed(ur5, one_joint_move(ur5, 0, 1.3), v_max=1.1,
                                     a_max=2.3, dt=0.01, round_to_dt=True)
    whole = math.ceil(trapezoid_time(1.3, 1.1, 2.3) / 0.01) * 0.01
    assert res.duration == pytest.approx(whole)
    np.testing.assert_allclose(np.diff(res.trajectory.t), 0.01, atol=1e-12)
    assert_within_limits(res)


def test_slowed_to_a_cycle_time_scales_every_rate(ur5, rng):
    tr = via_path(ur5, rng)
    res = trajectory.retime_detailed(ur5, tr, v_max=2.0, a_max=6.0)
    target = res.duration * 1.5
    slow = res.slowed(target)
    assert slow.duration == pytest.approx(target, abs=1e-9)
    c = (target - res.dwell_time) / res.motion_time
    assert slow.dwell_time == pytest.approx(res.dwell_time)
    peak_v = (np.abs(slow.trajectory.qd) / 2.0).max()
    peak_a = (np.abs(slow.trajectory.qdd) / 6.0).max()
    assert peak_v <= 1 / c * (1 + 1e-6) and peak_a <= 1 / c**2 * (1 + 1e-6)
    assert all(s.stretch >= c * (1 - 1e-9) for s in slow.sections if s.kind == "move")
    # the same path
    assert _distance_to_polyline(slow.trajectory.q[::7], res.trajectory.q).max() < 1e-4


def test_retime_returns_the_trajectory(ur5):
    tr = one_joint_move(ur5, 0, 1.0)
    out = trajectory.retime(ur5, tr, v_max=1.0, a_max=2.0, dt=0.005)
    assert isinstance(out, trajectory.Trajectory)
    assert out.joint_names == ur5.joint_names
    assert out.duration == pytest.approx(trapezoid_time(1.0, 1.0, 2.0), abs=1e-6)


@pytest.mark.parametrize("seed", [0, 4, 7, 12, 22])
def test_a_dense_corner_cut_polyline_settles_within_the_limits(ur5, seed):
    # Regression (issue 26): a polyline smoothed by corner cutting (many close
    # knots) once ended in "the limit check did not settle": each stretch of the
    # law met a new peak between the samples, a tenth of the last excess.
    q = np.cumsum(np.random.default_rng(seed).normal(size=(6, 6)), axis=0)
    for _ in range(2):  # Chaikin: every corner replaced by its quarter points
        a = q[1:-1] + 0.25 * (q[:-2] - q[1:-1])
        b = q[1:-1] + 0.25 * (q[2:] - q[1:-1])
        q = np.vstack([q[:1], np.stack([a, b], axis=1).reshape(-1, 6), q[-1:]])
    res = trajectory.retime_detailed(ur5, q, v_max=2.0, a_max=6.0)
    assert (np.abs(res.trajectory.qd) / 2.0).max() <= 1 + 1e-9
    assert (np.abs(res.trajectory.qdd) / 6.0).max() <= 1 + 1e-9
    np.testing.assert_allclose(res.trajectory.q[[0, -1]], q[[0, -1]], atol=1e-9)
