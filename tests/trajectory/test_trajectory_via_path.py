"""Multi-segment paths: C1/C2 continuity at every via point, lines, durations from limits."""

import numpy as np
import pytest

import robokin
from robokin import InputError, trajectory
from robokin.spatial import trans


@pytest.fixture(scope="module")
def aubo():
    return robokin.load("aubo_i5")


Q_HOME = np.radians([0, 10, 80, 0, 90, 0])


def _junction_jumps(tr, values):
    """Per interior via point: |left extrapolation - right extrapolation| of ``values``.

    Quadratic extrapolation from three samples on each side to the junction sample:
    a smooth curve gives O(dt^3) differences, a step gives the step.
    """
    out = []
    for v in tr.via_times[1:-1]:
        i = int(np.argmin(np.abs(tr.t - v)))
        left = 3 * values[i - 1] - 3 * values[i - 2] + values[i - 3]
        right = 3 * values[i + 1] - 3 * values[i + 2] + values[i + 3]
        out.append(np.abs(left - right).max())
    return np.array(out)


def _press_path(robot, smooth=True):
    pb = trajectory.PathBuilder(robot, Q_HOME, dt=0.005, v_max=1.5, a_max=3.0,
                                smooth=smooth)
    q_above = np.radians([-40, 20, 90, -20, 90, 0])
    pb.joint(q_above, label="above pick")
    T_above = robot.fk(q_above)
    pb.line(trans(0, 0, -0.1) @ T_above, duration=1.0, label="approach")
    pb.dwell(0.5)
    pb.line(T_above, duration=1.0, label="retract")
    pb.joint(np.radians([20, 15, 85, -10, 90, 30]), label="via 1")
    pb.joint(np.radians([50, 10, 70, 0, 90, 40]), label="via 2")
    T_front = robot.fk(np.radians([60, 10, 70, 0, 90, 40]))
    pb.pose(T_front, label="press front")
    c, s = np.cos(np.radians(60)), np.sin(np.radians(60))
    pb.line(trans(0.12 * c, 0.12 * s, 0) @ T_front, duration=1.5, label="entry")
    pb.dwell(1.0)
    pb.line(T_front, duration=1.5, label="exit")
    pb.joint(Q_HOME, label="home")
    return pb


def test_press_path_is_continuous_at_every_via_point(aubo):
    pb = _press_path(aubo)
    tr = pb.build()
    assert len(tr.via_times) == len(pb.segments) + 1
    assert tr.labels[1] == "approach" and tr.labels[-1] == "home"
    np.testing.assert_allclose(np.diff(tr.t), 0.005, atol=1e-9)  # fixed dt throughout
    # positions, velocities and accelerations have no steps at any junction
    for arr, tol in ((tr.q, 2e-5), (tr.qd, 1e-4), (tr.qdd, 2e-3)):
        assert _junction_jumps(tr, arr).max() < tol
    # and a path that really has a step is caught by the same measure
    bad = tr.qd.copy()
    i = int(np.argmin(np.abs(tr.t - tr.via_times[5])))
    bad[i:] += 0.05
    assert _junction_jumps(tr, bad).max() > 0.04
    # starts and ends at rest, hits every joint via point
    np.testing.assert_allclose(tr.qd[[0, -1]], 0.0, atol=1e-12)
    np.testing.assert_allclose(tr.q[-1], Q_HOME, atol=1e-12)
    for seg, v in zip(pb.segments, tr.via_times[1:]):
        np.testing.assert_allclose(tr.at([v])[0], seg.q_end, atol=1e-9)
    # within the limits used to derive the durations
    assert tr.check_limits(aubo, velocity=1.5, acceleration=3.0).ok


def test_lines_inside_the_path_stay_straight(aubo):
    tr = _press_path(aubo).build()
    P = aubo.fk(tr.q)[:, :3, 3]
    for k, label in enumerate(tr.labels):
        if label not in ("approach", "entry"):
            continue
        m = (tr.t >= tr.via_times[k] - 1e-9) & (tr.t <= tr.via_times[k + 1] + 1e-9)
        seg = P[m]
        u = (seg[-1] - seg[0]) / np.linalg.norm(seg[-1] - seg[0])
        d = seg - seg[0]
        assert np.linalg.norm(d - (d @ u)[:, None] * u, axis=1).max() < 1e-9


def test_smooth_does_not_stop_at_joint_via_points(aubo):
    tr = _press_path(aubo).build()
    stop = _press_path(aubo, smooth=False).build()
    v_smooth = np.abs(tr.qd[np.argmin(np.abs(tr.t - tr.via_times[5]))]).max()
    v_stop = np.abs(stop.qd[np.argmin(np.abs(stop.t - stop.via_times[5]))]).max()
    assert v_smooth > 0.05 and v_stop < 1e-12


def test_line_blending_into_joint_motion_at_speed(aubo):
    pb = trajectory.PathBuilder(aubo, Q_HOME, dt=0.005)
    T0 = aubo.fk(Q_HOME)
    pb.line(trans(0.1, 0.0, 0.0) @ T0, duration=1.0, speed_out=0.1, label="out")
    pb.joint(np.radians([30, 20, 70, 0, 90, 0]), duration=1.5)
    pb.joint(Q_HOME, duration=1.5)
    tr = pb.build()
    i = int(np.argmin(np.abs(tr.t - 1.0)))
    v_tool = aubo.jacobian(tr.q[i]) @ tr.qd[i]
    np.testing.assert_allclose(v_tool[:3], [0.1, 0.0, 0.0], atol=1e-9)
    for arr, tol in ((tr.qd, 1e-4), (tr.qdd, 2e-3)):
        assert _junction_jumps(tr, arr).max() < tol


def test_via_path_from_dicts_and_errors(aubo):
    steps = [{"joint": np.radians([10, 20, 70, 0, 90, 0]), "duration": 1.0},
             {"dwell": 0.2},
             {"joint": Q_HOME, "duration": 1.0, "profile": "cycloidal"}]
    tr = trajectory.via_path(aubo, Q_HOME, steps)
    assert tr.duration == pytest.approx(2.2)
    with pytest.raises(InputError, match="exactly one"):
        trajectory.via_path(aubo, Q_HOME, [{"duration": 1.0}])
    with pytest.raises(InputError, match="no v_max"):
        trajectory.via_path(aubo, Q_HOME, [{"joint": Q_HOME + 0.1}])
    with pytest.raises(InputError, match="no segments"):
        trajectory.PathBuilder(aubo, Q_HOME).build()


def test_six_segment_path_of_5000_samples(aubo, rng):
    vias = Q_HOME + rng.uniform(-0.5, 0.5, (6, 6))
    pb = trajectory.PathBuilder(aubo, Q_HOME, dt=0.005)
    for q, d in zip(vias, [4.0, 4.0, 4.0, 4.0, 4.5, 4.5]):
        pb.joint(q, duration=d)
    tr = pb.build()
    assert len(tr) == 5001 and tr.duration == pytest.approx(25.0, abs=1e-9)
    for arr, tol in ((tr.qd, 1e-5), (tr.qdd, 1e-4)):
        assert _junction_jumps(tr, arr).max() < tol


@pytest.mark.parametrize("max_samples", ["abc", 0, 1.5])
def test_a_bad_max_samples_is_refused_when_the_builder_is_made(aubo, max_samples):
    with pytest.raises(InputError, match="max_samples") as info:
        trajectory.PathBuilder(aubo, Q_HOME, max_samples=max_samples)
    assert info.value.argument == "max_samples"


def test_max_samples_caps_the_whole_path(aubo):
    pb = trajectory.PathBuilder(aubo, Q_HOME, dt=0.01, max_samples=150)
    pb.joint(Q_HOME + 0.1, duration=1.0).joint(Q_HOME, duration=1.0)
    with pytest.raises(InputError, match="by segment 2.*limit of 150") as info:
        pb.build()
    assert info.value.argument == "max_samples"
    assert len(trajectory.PathBuilder(aubo, Q_HOME, dt=0.01, max_samples=300)
               .joint(Q_HOME + 0.1, duration=1.0).joint(Q_HOME, duration=1.0)
               .build()) == 201
