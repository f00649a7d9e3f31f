"""``robokin demo --plan`` (robokin.cli.demo_plan): the press cycle with planned free moves.

Oracles: the cycle passes through the hand-made plan's via configurations at the
ends of its steps, keeps the process lines on their straight Cartesian paths, and
coal finds every sample clear of the press by the demo's clearance; the summary's
numbers are those of the trajectory written.
"""

import io
import json

import numpy as np
import pytest

import robokin
from planning_oracle import Oracle
from robokin.collision import Scene, scene_path

pytest.importorskip("coal")


def test_the_planned_cycle_passes_the_via_points_and_clears_the_press():
    from robokin.cli.demo_job import DT, PLAN, plan_press_loading
    from robokin.cli.demo_plan import planned_cycle

    scene = Scene.load(scene_path("press"))
    bare = robokin.load("aubo_i5")
    hand, _ = plan_press_loading(scene.attach(bare), scene)
    cycle, summary = planned_cycle(bare, scene, hand, PLAN, clearance=0.004, dt=DT)
    assert not summary["collides"] and summary["min_clearance_mm"] >= 4.0
    assert len(summary["moves"]) == 2  # the two free moves were planned
    vias = hand.at(hand.via_times)
    got = cycle.at(cycle.via_times)
    assert len(got) == len(vias)
    np.testing.assert_allclose(got, vias, atol=1e-6)
    oracle = Oracle(bare, scene)
    scene_pairs = [p for p, (_, j, _) in enumerate(oracle.pairs) if j is not None]
    for q in cycle.q[::10]:
        assert oracle.distances(q)[scene_pairs].min() > 0.004 - 2e-6
    assert summary["duration_s"] == pytest.approx(cycle.duration, abs=1e-3)
    assert cycle.duration < hand.duration  # run at the limits, not the hand-made 24 s


def test_demo_plan_reports_the_cycle_next_to_the_hand_made_one(tmp_path):
    from rich.console import Console

    from robokin.cli.demo import run_demo
    from robokin.trajectory.io import read_csv

    console = Console(file=io.StringIO(), width=140)
    result = run_demo(out=tmp_path, console=console, plan=True, html_animation=False)
    text = console.file.getvalue()
    assert result.ok
    p = result.summary["planned_by_robokin"]
    assert "planned by robokin" in text and f"{p['duration_s']:.2f} s cycle" in text
    assert p["hand_made_minimum_s"] == result.summary["cycle_time"]["minimum_s"]
    tr = read_csv(tmp_path / "planned_trajectory.csv")
    assert tr.duration == pytest.approx(p["duration_s"], abs=1e-3)
    saved = json.loads((tmp_path / "summary.json").read_text())
    assert saved["planned_by_robokin"]["moves"] == p["moves"]
    assert "Planned by robokin" in (tmp_path / "report.html").read_text()
