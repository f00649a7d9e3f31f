"""The bottleneck plot (issue 18): a row per joint, velocity and acceleration (and
jerk) against the limits, minimum and slower motions, active stretches shaded."""

import numpy as np
import pytest

import robokin
from robokin import trajectory

pytest.importorskip("toppra")
pytest.importorskip("ruckig")
from robokin.trajectory.cycle_time import cycle_time_report  # noqa: E402
from robokin.viz.retime_plots import plot_bottlenecks  # noqa: E402


@pytest.fixture(scope="module")
def report():
    robot = robokin.load("aubo_i5")
    q0 = np.radians([0, 10, 80, 0, 90, 0])
    pb = trajectory.PathBuilder(robot, q0, dt=0.01)
    pb.joint(np.radians([30, 20, 70, 0, 90, 0]), duration=1.0, label="swing")
    T = robot.fk(pb.q_end)
    T[2, 3] -= 0.05
    pb.line(T, duration=0.5, label="down").dwell(0.2, label="grip")
    pb.joint(q0, duration=1.0, label="home")
    return cycle_time_report(robot, pb.build(), cycle_time=3.0)


def test_bottleneck_plot_has_every_joint_and_limit(report, tmp_path):
    out = tmp_path / "bottlenecks.png"
    fig = plot_bottlenecks(report, path=out)
    assert out.stat().st_size > 20_000
    axes = fig.axes
    main = [ax for ax in axes if ax.get_xlabel() or ax.get_ylabel()]
    assert len(main) == 6 * 2  # 6 joints x (velocity, acceleration)
    labels = [ln.get_label() for ln in main[-1].get_lines()]
    assert any(lb.startswith("minimum") for lb in labels)
    assert any(lb.startswith("retimed") for lb in labels)
    # the limit lines of the first joint's velocity panel, in deg/s
    limit = np.degrees(report.minimum.limits.velocity[0])
    ys = {round(abs(ln.get_ydata()[0]), 6) for ln in main[0].get_lines()
          if len(ln.get_ydata()) == 2}
    assert round(limit, 6) in ys


def test_jerk_column_when_jerk_is_limited(tmp_path):
    robot = robokin.load("panda")
    q0 = np.array([0, -0.5, 0, -2.0, 0, 1.6, 0.8])
    rep = cycle_time_report(robot, trajectory.quintic(q0, q0 + 0.4, 2.0), j_max="robot")
    fig = plot_bottlenecks(rep, path=tmp_path / "b.svg", degrees=False)
    titles = [ax.get_title() for ax in fig.axes if ax.get_title()]
    assert titles == ["velocity", "acceleration", "jerk"]
