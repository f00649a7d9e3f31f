"""The demo's shortest cycle (issue 18): the press-loading path retimed under the
AUBO-i5's limits, side by side with the planned 24 s, still collision-free."""

import io
import json

import numpy as np
import pytest

import robokin

pytest.importorskip("coal")
pytest.importorskip("toppra")


@pytest.fixture(scope="module")
def planned():
    from robokin import collision
    from robokin.cli.demo import plan_press_loading

    scene = collision.Scene.load(collision.scene_path("press"))
    bare = robokin.load("aubo_i5")
    robot = scene.attach(bare)
    traj, _ = plan_press_loading(robot, scene)
    return robot, bare, scene, traj


def test_minimum_cycle_time_beside_the_planned_one(planned):
    from robokin.cli.demo_job import cycle_times

    robot, bare, scene, traj = planned
    c = cycle_times(robot, bare, scene, traj, clearance=0.004)
    assert c["planned_s"] == pytest.approx(24.0)
    assert 2.0 < c["minimum_s"] < c["minimum_demo_caps_s"] < c["planned_s"]
    assert not c["retimed_collides"] and c["retimed_min_clearance_mm"] >= 4.0


def test_the_retimed_demo_path_keeps_its_lines_and_limits(planned):
    from robokin import trajectory

    robot, _, _, traj = planned
    res = trajectory.retime_detailed(robot, traj)
    lim = robot.rate_limits
    out = res.trajectory
    assert (np.abs(out.qd) <= lim.velocity * (1 + 1e-6)).all()
    assert (np.abs(out.qdd) <= lim.acceleration * (1 + 1e-6)).all()
    assert res.dwell_time == pytest.approx(2.0)  # gripper close and release kept
    for s in res.sections:  # the straight approaches, lifts, entries, retracts
        if s.label not in ("approach the part", "lift the part", "enter the press",
                           "retract"):
            continue
        i0, i1 = (int(round(t / 0.005)) for t in (s.source_start, s.source_end))
        a, b = traj.pose[i0, :3, 3], traj.pose[i1, :3, 3]
        inside = (out.t >= s.t_start) & (out.t <= s.t_end)
        d = out.pose[inside, :3, 3] - a
        u = (b - a) / np.linalg.norm(b - a)
        assert np.linalg.norm(d - np.outer(d @ u, u), axis=1).max() < 1e-6  # [m]


def test_report_and_summary_show_it(tmp_path):
    from rich.console import Console

    from robokin.cli.demo import run_demo

    console = Console(file=io.StringIO(), width=160)
    result = run_demo(out=tmp_path, console=console, html_animation=False)
    summary = json.loads((tmp_path / "summary.json").read_text())
    c = summary["cycle_time"]
    assert c["minimum_s"] < c["planned_s"] == 24.0
    html = (tmp_path / "report.html").read_text()
    assert "shortest cycle of this path" in html and f"{c['minimum_s']:.2f} s" in html
    assert "shortest cycle" in console.file.getvalue()
    assert result.ok
