"""The standalone HTML animation: self-contained, loads, plays, shows the robot."""

from __future__ import annotations

import json
import re
from types import SimpleNamespace

import numpy as np
import pytest

import robokin
from browser_shots import (
    orange_fraction,
    read_png,
    red_fraction,
    require_chromium,
    run_chromium,
)
from robokin.collision.scene import Scene
from robokin.exceptions import InputError
from robokin.viz.html import animation_html, write_html


def _embedded(text: str) -> dict:
    m = re.search(
        r'<script id="robokin-data" type="application/json">(.*?)</script>', text, re.S
    )
    assert m is not None
    return json.loads(m.group(1))


def _ur5_motion(m: int = 300) -> np.ndarray:
    s = np.linspace(0.0, 1.0, m)[:, None]
    q0 = np.array([0.0, -1.2, 1.4, -1.8, -1.57, 0.0])
    q1 = np.array([1.2, -0.8, 1.0, -1.6, -1.57, 0.5])
    return q0 + s * (q1 - q0)


def _scene():
    scene = Scene("cell")
    pose = np.eye(4)
    pose[:3, 3] = [0.5, 0.2, -0.1]
    scene.add_box("table", size=(0.6, 0.8, 0.05), pose=pose)
    return scene


def test_page_is_self_contained_and_carries_the_motion():
    robot = robokin.load("ur5")
    q = _ur5_motion(300)
    text = animation_html(
        robot, SimpleNamespace(t=np.arange(300) * 0.01, q=q), scene=_scene()
    )
    # No server, no network: nothing is fetched from anywhere.
    assert re.search(r"https?://", text) is None
    assert re.search(r"<script[^>]*\bsrc=", text) is None
    assert "<link" not in text
    data = _embedded(text)
    assert len(data["t"]) == 300
    assert data["t"][-1] == pytest.approx(2.99)
    assert [s["name"] for s in data["scene"]] == ["table"]
    # The key points are the FK frames: the last one is the tool position.
    import base64

    pts = np.frombuffer(base64.b64decode(data["points"]), dtype="<f4").reshape(
        300, -1, 3
    )
    np.testing.assert_allclose(pts[:, -1], robot.fk(q)[:, :3, 3], atol=1e-6)
    np.testing.assert_allclose(pts[:, 0], 0.0, atol=1e-7)


def test_long_motions_are_thinned_but_keep_the_closest_sample():
    robot = robokin.load("scara")
    m = 5000
    q = np.zeros((m, 4))
    q[:, 0] = np.linspace(-1, 1, m)
    dist = np.abs(np.linspace(-1, 1, m) - 0.3123) + 0.01
    rep = SimpleNamespace(
        min_distance=float(dist.min()),
        collisions=[(4321, 4322, "link2", "post")],
        distances=dist,
    )
    data = _embedded(animation_html(robot, q, report=rep, max_frames=500))
    assert 500 <= len(data["t"]) <= 505
    assert min(data["distance"]) == pytest.approx(dist.min(), abs=1e-7)
    assert sum(data["colliding"]) >= 1
    assert data["collisions"] == [[4321, 4322, "link2", "post"]]
    assert data["t"][1] == pytest.approx(0.05)  # stride 10 of 5 ms samples


def test_bad_trajectory_is_named():
    robot = robokin.load("ur5")
    with pytest.raises(InputError, match="trajectory"):
        animation_html(robot, np.zeros((10, 5)))
    with pytest.raises(InputError, match="increase"):
        animation_html(robot, SimpleNamespace(t=np.zeros(3), q=np.zeros((3, 6))))


def test_page_loads_and_shows_the_robot_in_chromium(tmp_path):
    require_chromium()
    robot = robokin.load("ur5")
    path = write_html(
        tmp_path / "anim.html", robot, _ur5_motion(200), scene=_scene(), autoplay=False
    )
    dom = run_chromium(path.as_uri(), tmp_path / "profile")
    # The script ran to the end: it marks the body with the frame count.
    assert 'data-rendered="200"' in dom
    assert "robokin-rendered frames=200" in dom
    shot = tmp_path / "anim.png"
    run_chromium(path.as_uri(), tmp_path / "profile", screenshot=shot, size=(900, 600))
    img = read_png(shot)
    assert img.shape == (600, 900, 3)
    canvas = img[60:540]
    assert canvas.std() > 10.0  # not blank
    assert orange_fraction(canvas) > 0.002  # the arm's links
    assert red_fraction(canvas) < 0.005  # no collision shown (the tool's x axis is red)


def test_colliding_samples_are_drawn_red(tmp_path):
    require_chromium()
    robot = robokin.load("ur5")
    q = _ur5_motion(50)
    rep = SimpleNamespace(min_distance=0.0, collisions=[(0, 49, "wrist", "table")])
    path = write_html(
        tmp_path / "red.html", robot, q, scene=_scene(), report=rep, autoplay=False
    )
    shot = tmp_path / "red.png"
    run_chromium(path.as_uri(), tmp_path / "profile", screenshot=shot)
    img = read_png(shot)[60:540]
    assert red_fraction(img) > 0.02  # the arm and the table it hits
    assert orange_fraction(img) < 5e-4


SCENE_YAML = """
name: test cell
units: {length: mm, angle: deg}
objects:
  - {name: table, type: box, size: [600, 800, 40], xyz: [450, 0, -100]}
  - {name: post, type: cylinder, radius: 40, length: 600, xyz: [0, 550, 300]}
"""


def test_cli_view_writes_html_with_scene_and_collision_check(tmp_path):
    pytest.importorskip("coal")
    from robokin import trajectory
    from robokin.cli import main
    from robokin.trajectory.io import write_csv

    robot = robokin.load("ur5")
    q0 = np.array([0.0, -1.2, 1.4, -1.8, -1.57, 0.0])
    q1 = np.array([1.2, -0.8, 1.0, -1.6, -1.57, 0.5])
    tr = trajectory.quintic(q0, q1, 1.0, dt=0.01)
    csv = write_csv(tr, tmp_path / "motion.csv", robot.joint_names)
    (tmp_path / "cell.yaml").write_text(SCENE_YAML)
    out = tmp_path / "view.html"
    rc = main(
        [
            "view",
            "ur5",
            "--traj",
            str(csv),
            "--scene",
            str(tmp_path / "cell.yaml"),
            "--html",
            str(out),
        ]
    )
    assert rc == 0
    data = _embedded(out.read_text())
    assert len(data["t"]) == tr.t.size
    assert sorted(s["name"] for s in data["scene"]) == ["post", "table"]
    # The distances shown are the checker's, sample by sample.
    from robokin import collision

    scene = collision.Scene.load(tmp_path / "cell.yaml")
    rep = collision.check(robot, scene, tr)
    assert data["distance"] is not None and data["closest"] is not None
    assert min(data["distance"]) == pytest.approx(rep.sample_min_distance, abs=1e-6)
    import base64

    seg = np.frombuffer(base64.b64decode(data["closest"]), dtype="<f4").reshape(
        -1, 2, 3
    )
    lengths = np.linalg.norm(seg[:, 1] - seg[:, 0], axis=-1)
    np.testing.assert_allclose(lengths, np.maximum(data["distance"], 0.0), atol=1e-5)


TOOL_SCENE_YAML = """
name: tool cell
units: {length: mm, angle: deg}
tool:
  tcp: {xyz: [0, 0, 100]}
  shapes:
    - {name: tip, type: sphere, radius: 20, xyz: [0, 0, 100]}
objects:
  - {name: ball, type: sphere, radius: 10, xyz: [%f, %f, %f]}
"""


def test_cli_view_checks_the_robot_with_the_scene_tool_attached_once(tmp_path):
    # A tool sphere (r 20 mm) at a 100 mm TCP and a ball (r 10 mm) 60 mm beyond
    # the TCP along the tool axis: 30 mm apart. Attaching the tool twice (a TCP
    # 200 mm out) would put the tip through the ball.
    pytest.importorskip("coal")
    from robokin.cli import main
    from robokin.trajectory import Trajectory
    from robokin.trajectory.io import write_csv

    robot = robokin.load("ur5")
    q = np.array([0.0, -1.2, 1.4, -1.8, -1.57, 0.0])
    flange = robot.fk(q)
    tcp = flange[:3, 3] + 0.1 * flange[:3, 2]
    c = (tcp + 0.06 * flange[:3, 2]) * 1000.0
    (tmp_path / "cell.yaml").write_text(TOOL_SCENE_YAML % tuple(c))
    z = np.zeros((2, 6))
    tr = Trajectory(np.array([0.0, 0.1]), np.stack([q, q]), z, z)
    csv = write_csv(tr, tmp_path / "motion.csv", robot.joint_names)
    out = tmp_path / "view.html"
    argv = ["view", "ur5", "--traj", str(csv), "--scene", str(tmp_path / "cell.yaml")]
    assert main([*argv, "--html", str(out)]) == 0
    data = _embedded(out.read_text())
    np.testing.assert_allclose(data["distance"], [0.03, 0.03], atol=1e-6)
    assert data["colliding"] == [0, 0]


def test_cli_view_of_a_robot_without_geometry_still_draws_and_says_why(
    tmp_path, capsys
):
    pytest.importorskip("coal")
    import yaml

    from robokin.cli import main

    doc = yaml.safe_load(robokin.load("ur5").path.read_text())
    doc.pop("geometry", None)
    doc.pop("collision", None)
    (tmp_path / "bare.yaml").write_text(yaml.safe_dump(doc))
    (tmp_path / "cell.yaml").write_text(SCENE_YAML)
    q = _ur5_motion(5)
    csv = tmp_path / "m.csv"
    # columns are matched to the robot's joints by name (issue 15)
    names = robokin.load("ur5").joint_names
    header = "t [s]," + ",".join(f"{n} [rad]" for n in names)
    rows = np.column_stack([np.arange(5) * 0.1, q])
    np.savetxt(csv, rows, delimiter=",", header=header, comments="")
    out = tmp_path / "v.html"
    argv = ["view", str(tmp_path / "bare.yaml"), "--traj", str(csv)]
    argv += ["--scene", str(tmp_path / "cell.yaml"), "--html", str(out)]
    assert main(argv) == 0
    assert "no collision geometry" in capsys.readouterr().err
    data = _embedded(out.read_text())
    assert len(data["t"]) == 5 and data["distance"] is None


def test_cli_view_html_never_writes_over_an_input_file(tmp_path, capsys):
    from robokin.cli import main

    csv = tmp_path / "m.csv"
    header = "t [s]," + ",".join(f"j{k} [rad]" for k in range(6))
    rows = np.column_stack([np.arange(3) * 0.1, _ur5_motion(3)])
    np.savetxt(csv, rows, delimiter=",", header=header, comments="")
    before = csv.read_bytes()
    assert main(["view", "ur5", "--traj", str(csv), "--html", str(csv)]) == 2
    assert "--html" in capsys.readouterr().err
    assert csv.read_bytes() == before
    assert main(["view", "ur5", "--html", str(tmp_path)]) == 2
    assert "folder" in capsys.readouterr().err
