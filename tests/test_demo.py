"""The main job end to end: ``robokin demo`` plans, checks and reports consistently."""

import io
import json

import numpy as np
import pytest

import robokin
from robokin.cli import main

pytest.importorskip("coal")


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    from rich.console import Console

    from robokin.cli.demo import run_demo

    out = tmp_path_factory.mktemp("demo")
    console = Console(file=io.StringIO(), width=120)
    result = run_demo(out=out, console=console)
    return out, result, console.file.getvalue()


def test_demo_passes_and_writes_every_output(demo):
    out, result, text = demo
    assert result.ok
    for name in (
        "trajectory.csv",
        "waypoints.csv",
        "program.waypoints.csv",
        "joints.png",
        "tool_path.png",
        "press_views.png",
        "distance.csv",
        "distance.png",
        "animation.html",
        "report.html",
        "summary.json",
    ):
        assert (out / name).stat().st_size > 400, name
    assert "PASS" in text and "minimum clearance" in text
    assert not (out / "program.script").exists()  # an AUBO controller runs no URScript


def test_outputs_agree_with_each_other(demo):
    from robokin.trajectory.io import read_csv

    out, result, _ = demo
    summary = json.loads((out / "summary.json").read_text())
    traj = read_csv(out / "trajectory.csv")
    assert len(traj.t) == summary["samples"] == result.trajectory.t.size
    assert 4500 <= summary["samples"] <= 5500  # about 25 s at 5 ms
    np.testing.assert_allclose(np.diff(traj.t), 0.005, atol=1e-9)
    np.testing.assert_allclose(traj.q, result.trajectory.q, atol=1e-8)
    dist = np.loadtxt(out / "distance.csv", delimiter=",", skiprows=1)
    assert dist.shape[0] == summary["samples"]
    if not summary["closest"]["between_samples"]:
        assert summary["min_clearance_mm"] == pytest.approx(dist[:, -1].min(), abs=1e-3)
    assert summary["min_clearance_mm"] >= summary["required_clearance_mm"]
    report = (out / "report.html").read_text()
    assert f"{summary['min_clearance_mm']:.1f} mm" in report
    assert "PASS" in report and "data:image/png;base64," in report
    way = np.loadtxt(out / "waypoints.csv", delimiter=",", skiprows=1)
    # controller waypoints are in degrees: the last one is the final configuration
    np.testing.assert_allclose(way[-1, 1:], np.degrees(traj.q[-1]), atol=1e-5)


def test_plan_reaches_the_scene_poses_on_straight_lines(demo):
    from robokin import collision

    _, result, _ = demo
    traj = result.trajectory
    scene = collision.Scene.load(collision.scene_path("press"))
    robot = scene.attach(robokin.load("aubo_i5"))
    T = robot.fk(traj.q)  # independent of the stored poses
    ends = {
        label: int(round(t / 0.005))
        for label, t in zip(traj.labels, traj.via_times[1:])
    }
    np.testing.assert_allclose(
        T[ends["approach the part"]], scene.tcp_pose("pick"), atol=1e-9
    )
    np.testing.assert_allclose(
        T[ends["enter the press"]], scene.tcp_pose("press_place"), atol=1e-9
    )
    # the entry into the press is a straight line from press_approach to press_place
    i0 = ends["move to the press"]
    i1 = ends["enter the press"]
    p = T[i0 : i1 + 1, :3, 3]
    a, b = scene.tcp_pose("press_approach")[:3, 3], scene.tcp_pose("press_place")[:3, 3]
    u = (b - a) / np.linalg.norm(b - a)
    off = (p - a) - np.outer((p - a) @ u, u)
    assert np.abs(off).max() < 1e-9
    np.testing.assert_allclose(
        T[i0 : i1 + 1, :3, :3],
        np.broadcast_to(scene.tcp_pose("press_place")[:3, :3], (i1 - i0 + 1, 3, 3)),
        atol=1e-9,
    )
    # no branch flips: no joint moves more than 1 degree in one 5 ms step
    assert np.degrees(np.abs(np.diff(traj.q, axis=0))).max() < 1.0
    assert robot.within_limits(traj.q).all()


def test_a_larger_clearance_fails_with_exit_code_1(tmp_path, capsys):
    code = main(["demo", "--out", str(tmp_path / "d"), "--clearance", "25"])
    out, err = capsys.readouterr()
    assert code == 1
    assert "not collision-free with the required clearance" in err
    summary = json.loads((tmp_path / "d" / "summary.json").read_text())
    assert not summary["ok"] and summary["required_clearance_mm"] == 25.0


def test_demo_refuses_a_folder_with_other_files(tmp_path, capsys):
    (tmp_path / "thesis.tex").write_text("mine")
    code = main(["demo", "--out", str(tmp_path)])
    _, err = capsys.readouterr()
    assert code == 2 and "did not write" in err
    assert (tmp_path / "thesis.tex").read_text() == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["thesis.tex"]


def test_demo_writes_the_aubo_i5_waypoint_program_and_says_so(demo):
    """Issue 19, item 3: the AUBO-i5's profile names a waypoint file, not URScript."""
    from robokin.trajectory.controllers import controller_profile, read_waypoints

    out, result, text = demo
    summary = json.loads((out / "summary.json").read_text())
    assert summary["controller"]["program"] == "waypoints"
    assert summary["controller"]["file"] == "program.waypoints.csv"
    assert summary["controller"]["profile"].startswith("AUBO-i5")
    assert "program.waypoints.csv" in text and "waypoint file" in text
    assert "program.waypoints.csv" in (out / "report.html").read_text()
    aubo = robokin.load("aubo_i5")
    back = read_waypoints(out / "program.waypoints.csv", controller_profile(aubo),
                          aubo.joint_names)
    np.testing.assert_allclose(back.q, result.trajectory.q, atol=1e-15)
    np.testing.assert_allclose(back.t, result.trajectory.t, atol=1e-15)
    header = (out / "program.waypoints.csv").read_text().splitlines()[3]
    assert header.startswith("t [s],shoulder_joint [rad],upperArm_joint [rad]")
