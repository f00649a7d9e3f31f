"""``robokin follow SCENE PATH --program ...`` (issue 27 item 5): the motion along a
tool path in the press cell, its joint CSV, plot and controller programs.

Oracles: tests/program_parsers.py reads the KRL and RAPID programs back; their
Cartesian targets are the path's poses (positions; the tool z axis, which a turn
about it keeps) in the world frame, and the joint CSV's configurations reach those
poses (robot.fk of the placed robot). Needs robokin.process (issue 27 items 1-3).
"""

import csv
import json

import numpy as np
import pytest

import robokin
from program_parsers import parse_abb, parse_kuka
from robokin import collision
from robokin.cli import main

pytest.importorskip("robokin.process", reason="robokin.process (issue 27 items 1-3)")

SEAM = ("x [mm],y [mm],z [mm],roll [deg],pitch [deg],yaw [deg]\n"
        + "".join(f"{x},500,430,180,0,180\n" for x in range(20, 181, 10)))


def _placed():
    scene = collision.Scene.load(collision.scene_path("press"))
    return scene.attach(robokin.load("aubo_i5"))


def _world_targets(parsed):
    return np.array([m.pose for m in parsed.moves if m.pose is not None])


def test_follow_writes_joints_plot_and_programs(tmp_path, capsys):
    path = tmp_path / "seam.csv"
    path.write_text(SEAM)
    out = tmp_path / "out"
    code = main(["follow", "press", str(path), "--free-axis", "z", "--free-range",
                 "-180:180", "--program", "kuka_krl", "--program", "abb_rapid",
                 "--out", str(out), "--speed", "20", "--json"])
    text, err = capsys.readouterr()
    assert code == 0, err
    doc = json.loads(text)
    assert doc["feasible"] and doc["waypoints"] == 17
    names = sorted(p.name for p in out.iterdir())
    assert names == ["seam.dat", "seam.joints.csv", "seam.mod", "seam.png", "seam.src"]
    assert (out / "seam.png").stat().st_size > 5000
    rows = list(csv.reader((out / "seam.joints.csv").open()))
    assert rows[0][0] == "waypoint" and rows[0][-2:] == ["free_angle [deg]", "reachable"]
    q = np.radians(np.array([[float(v) for v in r[1:7]] for r in rows[1:]]))
    placed = _placed()
    T = placed.fk(q)
    want = np.array([[x / 1000, 0.5, 0.43] for x in range(20, 181, 10)])
    np.testing.assert_allclose(T[:, :3, 3], want, atol=1e-9)
    np.testing.assert_allclose(T[:, :3, 2], np.tile([0, 0, -1.0], (17, 1)), atol=1e-9)
    for parsed in (parse_kuka(out, "seam"), parse_abb(out, "seam")):
        targets = _world_targets(parsed)  # the base frame is the world: no work object
        assert len(targets) == 16 and parsed.moves[0].joints is not None
        np.testing.assert_allclose(targets[:, :3, 3], want[1:] * 1000, atol=1e-3)
        np.testing.assert_allclose(targets[:, :3, 2], np.tile([0, 0, -1.0], (16, 1)),
                                   atol=1e-6)
        np.testing.assert_allclose(parsed.moves[0].joints, np.degrees(q[0]), atol=1e-4)
    # the tool: the press cell's gripper TCP, 150 mm beyond the flange
    np.testing.assert_allclose(parse_kuka(out, "seam").tool[:3, 3], [0, 0, 150], atol=1e-3)


def test_infeasible_path_writes_the_diagnostics_and_no_program(tmp_path, capsys):
    path = tmp_path / "far.yaml"
    path.write_text("units: {length: mm, angle: deg}\nposes:\n"
                    "  - {xyz: [100, 500, 430], rpy: [180, 0, 180]}\n"
                    "  - {xyz: [100, 500, 2500], rpy: [180, 0, 180]}\n")
    code = main(["follow", "press", str(path), "--program", "kuka_krl",
                 "--out", str(tmp_path), "--html"])
    out, err = capsys.readouterr()
    assert code == 1 and "no feasible motion: waypoint 1" in err
    assert "NOT feasible" in out
    assert (tmp_path / "far.joints.csv").exists() and (tmp_path / "far.png").exists()
    # the 3D page: the press cell and the two waypoints, the second one red
    page = (tmp_path / "far.html").read_text()
    assert '"name":"waypoint 0","kind":"sphere"' in page
    assert '"name":"waypoint 1","kind":"sphere"' in page
    assert page.index('"color":[215,40,40]') > page.index('"name":"waypoint 1"')
    assert not (tmp_path / "far.src").exists()
    rows = list(csv.reader((tmp_path / "far.joints.csv").open()))
    assert rows[2][-1] == "0" and rows[2][1] == ""


def test_follow_refusals(tmp_path, capsys):
    path = tmp_path / "seam.csv"
    path.write_text(SEAM)
    for args, message in [
        (["--program", "krl"], "unknown dialect 'krl'; available: ['abb_rapid'"),
        (["--free-range", "-90:90"], "--free-range': needs --free-axis z"),
        (["--free-axis", "z", "--free-range", "90:-90"], "expected LO < HI"),
        (["--free-axis", "x"], "expected z"),
        (["--speed", "0"], "--speed': expected a positive number"),
    ]:
        assert main(["follow", "press", str(path), "--out", str(tmp_path), *args]) == 2
        assert message in capsys.readouterr().err
    (tmp_path / "seam.src").write_text("mine")
    assert main(["follow", "press", str(path), "--out", str(tmp_path),
                 "--program", "kuka_krl"]) == 2
    assert "seam.src exist(s) from an earlier run; pass --force" in capsys.readouterr().err
    assert (tmp_path / "seam.src").read_text() == "mine"
    assert not (tmp_path / "seam.joints.csv").exists()
