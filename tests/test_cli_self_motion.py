"""``robokin self-motion NAME x y z roll pitch yaw`` (issue 29): the whole self-motion
of a 7-joint arm at one pose, from the command line.

Oracles: the configuration that made the pose lies in a printed interval of a branch
whose row there is that configuration; every printed configuration reaches the pose
(forward kinematics) inside the limits, its margin recomputed from the limits; the
intervals are the library's for the same pose (the CLI only converts units); the
crossings table's joints are at their limits in the library's rows.
"""

from __future__ import annotations

import base64
import json
import re

import numpy as np
import pytest

import robokin
from reference import iiwa14_srs, ur5_on_a_track
from robokin.cli import main
from robokin.cli.self_motion import interval_motion
from robokin.io.robot_files import save_robot
from robokin.spatial import pose_from_xyz_rpy, xyz_rpy_from_pose

QP = np.array([0.0, -0.3, 0.0, -2.0, 0.0, 1.8, 0.7])  # the README's Panda configuration


def run(capsys, *args):
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def _pose_args(robot, q, deg=False, mm=False):
    xyz, rpy = xyz_rpy_from_pose(robot.fk(q))
    vals = np.concatenate([xyz * 1000.0 if mm else xyz, np.degrees(rpy) if deg else rpy])
    return [repr(float(v)) for v in vals]


def _pose_of(args, deg=False, mm=False):
    v = np.array([float(a) for a in args])
    return pose_from_xyz_rpy(v[:3] / 1000.0 if mm else v[:3],
                             v[3:] / (180.0 / np.pi) if deg else v[3:])


def test_the_generating_configuration_is_in_a_printed_interval_of_its_branch(capsys):
    panda = robokin.load("panda")
    pose = _pose_args(panda, QP)
    code, out, err = run(capsys, "self-motion", "panda", *pose, "--json")
    assert code == 0, err
    doc = json.loads(out)
    T = _pose_of(pose)
    sm = panda.self_motion(T)
    assert doc["parameter"] == "joint7" and doc["unit"] == "rad" and doc["branches"] == 8
    got = np.array([[iv["from"], iv["to"]] for iv in doc["intervals"]])
    np.testing.assert_array_equal(got, sm.intervals)
    assert [iv["branch"] for iv in doc["intervals"]] == sm.interval_branch.tolist()
    rows = sm.sample(QP[6])
    holding = [iv["branch"] for iv in doc["intervals"] if iv["from"] <= QP[6] <= iv["to"]]
    assert any(np.abs(rows[b] - QP).max() < 1e-9 for b in holding), holding
    assert len(doc["crossings"]) == len(sm.crossings) > 0
    for c in doc["crossings"]:
        j = panda.joint_names.index(c["joint"])
        v = sm.sample(c["t"])[c["branch"], j]
        assert v == pytest.approx(panda.limits[j, 0 if c["limit"] == "lower" else 1],
                                  abs=1e-9)


def test_best_and_nearest_reach_the_pose_inside_the_limits(capsys):
    panda = robokin.load("panda")
    pose = _pose_args(panda, QP, deg=True)
    near = np.degrees(QP)
    code, out, err = run(capsys, "self-motion", "panda", *pose, "--deg", "--near",
                         *near, "--json")
    assert code == 0, err
    doc = json.loads(out)
    T = _pose_of(pose, deg=True)
    lim = panda.limits
    best = np.radians(doc["best"]["q"])
    assert doc["best"]["criterion"] == "margin"
    assert np.all((best >= lim[:, 0]) & (best <= lim[:, 1]))
    np.testing.assert_allclose(panda.fk(best), T, atol=1e-12)
    margin = np.minimum(best - lim[:, 0], lim[:, 1] - best).min()
    assert np.radians(doc["best"]["score"]) == pytest.approx(margin, abs=1e-12)
    assert margin > 0.5  # the Panda has wide margins on this pose (1.12 rad found)
    nearest = np.radians(doc["nearest"]["q"])
    np.testing.assert_allclose(nearest, QP, atol=1e-6)
    assert 0 <= doc["nearest"]["distance"] < 1e-4  # [deg]
    assert doc["nearest"]["t"] == pytest.approx(np.degrees(QP[6]), abs=1e-4)
    deg_iv = np.array([[iv["from"], iv["to"]] for iv in doc["intervals"]])
    np.testing.assert_allclose(np.radians(deg_iv), panda.self_motion(T).intervals,
                               rtol=1e-15, atol=1e-15)


def test_the_text_lists_intervals_configurations_and_points(capsys):
    panda = robokin.load("panda")
    pose = _pose_args(panda, QP)
    code, out, err = run(capsys, "self-motion", "panda", *pose, "--points",
                         "--best", "manipulability", "--format", "text")
    assert code == 0, err
    sm = panda.self_motion(_pose_of(pose))
    assert f"8 branches, {len(sm.intervals)} in-limit interval(s)" in out
    assert f"{len(sm.crossings)} limit crossing(s)" in out
    assert "best manipulability" in out and "nearest" not in out.split("score:")[0]
    assert out.count("at its lower limit") + out.count("at its upper limit") == len(
        sm.crossings)
    assert out.count("branch end (fold)") == sum(s.kind == "fold" for s in sm.singular)


def test_a_manifold_of_numeric_samples_says_so(capsys):
    # Session 17: improved_dh_arm (two prismatic joints) is solved at each value of
    # its parameter by the numeric solver; the table says its branches can be missing
    # (and a Panda's, from the closed form, does not)
    arm = robokin.load("improved_dh_arm")
    q = np.clip(np.full(7, 0.3), arm.limits[:, 0], arm.limits[:, 1])
    code, out, err = run(capsys, "self-motion", "improved_dh_arm", *_pose_args(arm, q),
                         "--format", "text")
    assert code == 0, err
    assert "[continued numeric (pitch7 held)]" in out
    assert "numeric samples, and a branch can be missing" in out
    panda = robokin.load("panda")
    code, out, err = run(capsys, "self-motion", "panda", *_pose_args(panda, QP),
                         "--format", "text")
    assert code == 0 and "can be missing" not in out


def test_csv_numbers_are_plain(capsys):
    panda = robokin.load("panda")
    code, out, err = run(capsys, "self-motion", "panda", *_pose_args(panda, QP),
                         "--format", "csv")
    assert code == 0, err
    assert "np." not in out and "best margin," in out
    first = out.splitlines()[1].split(",")
    assert float(first[2]) > float(first[1])


def test_the_swivel_of_an_srs_arm_from_a_robot_file(tmp_path, capsys):
    arm = iiwa14_srs()
    path = save_robot(arm, tmp_path / "iiwa.yaml")
    q = np.array([0.3, 0.6, -0.4, -1.2, 0.5, 0.9, -0.2])
    pose = _pose_args(arm, q)
    code, out, err = run(capsys, "self-motion", path, *pose, "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["parameter"] == "swivel" and doc["periodic"]
    loaded = robokin.load(str(path))
    sm = loaded.self_motion(_pose_of(pose))
    np.testing.assert_array_equal(
        np.array([[iv["from"], iv["to"]] for iv in doc["intervals"]]), sm.intervals)
    best = np.array(doc["best"]["q"])
    np.testing.assert_allclose(loaded.fk(best), _pose_of(pose), atol=1e-12)


def test_a_plot_is_written_and_never_replaced_without_force(tmp_path, capsys):
    panda = robokin.load("panda")
    pose = _pose_args(panda, QP)
    png = tmp_path / "branches.png"
    code, out, err = run(capsys, "self-motion", "panda", *pose, "--plot", png, "--deg")
    assert code == 0, err
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000
    assert f"wrote {png}" in out
    png.write_bytes(b"mine")
    code, _, err = run(capsys, "self-motion", "panda", *pose, "--plot", png)
    assert code == 2 and "argument '--plot'" in err and "--force" in err
    assert png.read_bytes() == b"mine"
    code, _, err = run(capsys, "self-motion", "panda", *pose, "--plot", png, "--force")
    assert code == 0, err
    assert png.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize(("args", "argument", "match"), [
    (("ur5",), "NAME", "7-joint"),
    (("panda", "--parameter", "elbow"), "--parameter", "'joint7', got 'elbow'"),
    (("panda", "--parameter", "swivel"), "--parameter", "not an SRS arm"),
    (("panda", "--best", "reach"), "--best", "margin, manipulability"),
    (("panda", "--plot", "branches.txt"), "--plot", ".png, .svg, .pdf"),
])
def test_errors_name_the_argument_and_the_choices(capsys, args, argument, match):
    name, *options = args
    code, _, err = run(capsys, "self-motion", name, "0.4", "0.1", "0.5", "3.1", "0", "0",
                       *options)
    assert code == 2
    assert f"argument '{argument}'" in err and match in err


def test_near_needs_one_value_per_joint(capsys):
    code, _, err = run(capsys, "self-motion", "panda", "0.4", "0.1", "0.5", "3.1", "0",
                       "0", "--near", "0", "1")
    assert code == 2 and "--near needs 7 values, got 2" in err


def test_a_pose_out_of_reach_exits_1_saying_so(capsys):
    code, out, err = run(capsys, "self-motion", "panda", "3", "0", "0.5", "3.1", "0", "0")
    assert code == 1
    assert "out of reach" in err and "0 in-limit interval(s)" in out


def _page_data(path):
    text = path.read_text(encoding="utf-8")
    found = re.search(r'<script id="robokin-data" type="application/json">(.*?)</script>',
                      text, re.S)
    return json.loads(found.group(1).replace("<\\/", "</"))


def _f4(text, width):
    return np.frombuffer(base64.b64decode(text), dtype="<f4").reshape(-1, width)


def test_the_html_animation_moves_the_arm_and_holds_the_tool(tmp_path, capsys):
    panda = robokin.load("panda")
    pose = _pose_args(panda, QP)
    page = tmp_path / "self_motion.html"
    code, out, err = run(capsys, "self-motion", "panda", *pose, "--html", page, "--json")
    assert code == 0, err
    doc = json.loads(out)
    sm = panda.self_motion(_pose_of(pose))
    best = sm.best("margin")
    shown = doc["animated"]
    assert shown["branch"] == best.branch and shown["from"] <= best.t <= shown["to"]
    data = _page_data(page)
    assert len(data["t"]) == shown["frames"] == 481
    tool = _f4(data["tool"], 12)[:, :3]  # position, then the rotation (float32)
    np.testing.assert_allclose(tool, np.broadcast_to(_pose_of(pose)[:3, 3], tool.shape),
                               atol=2e-6)
    points = _f4(data["points"], 3 * data["nPoints"]).reshape(len(tool), -1, 3)
    assert np.ptp(points, axis=0).max() > 0.05  # the elbow sweeps: a real self-motion


def test_interval_motion_stays_on_the_pose_inside_the_limits():
    panda = robokin.load("panda")
    T = panda.fk(QP)
    sm = panda.self_motion(T)
    for k, b in enumerate(sm.interval_branch.tolist()):
        t, Q = interval_motion(sm, b, k, frames=31)
        a, e = sm.intervals[k]
        assert len(t) == len(Q) and len(Q) % 2 == 1
        assert np.all((t >= a) & (t <= e))
        np.testing.assert_array_equal(Q, Q[::-1])  # forward, then back
        np.testing.assert_allclose(panda.fk(Q), np.broadcast_to(T, (len(Q), 4, 4)),
                                   atol=1e-12)
        lo, hi = panda.limits.T + np.array([[-1e-12], [1e-12]])
        assert np.all((lo <= Q) & (hi >= Q))
        np.testing.assert_array_equal(Q[:, 6], t)  # q7 is the parameter


def test_branch_errors_come_before_any_file_is_written(tmp_path, capsys):
    panda = robokin.load("panda")
    pose = _pose_args(panda, QP)
    sm = panda.self_motion(_pose_of(pose))
    empty = next(b for b in range(sm.n_branches) if b not in sm.interval_branch)
    png, page = tmp_path / "b.png", tmp_path / "a.html"
    code, _, err = run(capsys, "self-motion", "panda", *pose, "--plot", png, "--html",
                       page, "--branch", empty)
    assert code == 2 and "argument '--branch'" in err and "has no in-limit interval" in err
    assert not png.exists() and not page.exists()
    code, _, err = run(capsys, "self-motion", "panda", *pose, "--branch", 0)
    assert code == 2 and "pass --html FILE too" in err
    code, _, err = run(capsys, "self-motion", "panda", *pose, "--html", page, "--branch", 9)
    assert code == 2 and "expected 0 ... 7, got 9" in err


def test_a_track_as_the_parameter_prints_millimetres(tmp_path, capsys):
    arm = ur5_on_a_track()
    path = save_robot(arm, tmp_path / "ur5_track.yaml")
    loaded = robokin.load(str(path))
    q = np.array([0.7, 0.3, -1.2, 1.1, -0.5, 0.8, 0.2])
    pose = _pose_args(loaded, q, deg=True, mm=True)
    T = _pose_of(pose, deg=True, mm=True)
    code, out, err = run(capsys, "self-motion", path, *pose, "--parameter", "track",
                         "--mm", "--deg", "--json", "--plot", tmp_path / "track.png")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["parameter"] == "track" and doc["unit"] == "mm"
    assert doc["domain"] == [0.0, 2000.0]
    sm = loaded.self_motion(T, "track")
    got = np.array([[iv["from"], iv["to"]] for iv in doc["intervals"]])
    np.testing.assert_allclose(got / 1000.0, sm.intervals, rtol=0, atol=1e-15)
    holding = [iv["branch"] for iv in doc["intervals"] if iv["from"] <= 700.0 <= iv["to"]]
    rows = sm.sample(q[0])
    assert any(np.abs(rows[b] - q).max() < 1e-9 for b in holding), holding
    best = np.array(doc["best"]["q"])
    best_si = np.concatenate([best[:1] / 1000.0, np.radians(best[1:])])
    np.testing.assert_allclose(loaded.fk(best_si), T, atol=1e-9)
    assert doc["best"]["t"] == pytest.approx(best[0], abs=1e-9)  # the track is t [mm]
    code, out, err = run(capsys, "self-motion", path, *_pose_args(loaded, q, mm=True),
                         "--parameter", "track", "--mm", "--format", "text")
    assert code == 0, err
    assert "over track [mm]" in out and "q1 [mm]" in out and "q2 [rad]" in out
    assert "[rad, m]" in out  # the margin mixes a length and angles


def test_a_pose_inside_the_limits_only_on_a_continuum_exits_0_with_its_configuration(
        tmp_path, capsys):
    """Session 23: an SRS arm with q1, q2, q3 held to narrow ranges around q0 (q2 = 0):
    no branch inside its limits at q0's pose, only the continuum through q0 (q1 and q3
    turned against each other). Oracle: q0 reaches the pose inside the limits; the
    command exits 0 (it exited 1, "no part of the self-motion is inside the joint
    limits") with a note saying why, and its best configuration reaches the pose
    inside the limits."""
    import dataclasses

    arm = iiwa14_srs()
    joints = list(arm.chain.joints)
    for j, lim in {0: (0.35, 0.45), 1: (-1e-3, 1e-3), 2: (0.25, 0.35)}.items():
        joints[j] = dataclasses.replace(joints[j], limits=lim)
    arm = arm.replace(chain=arm.chain.replace(joints=tuple(joints), coordinates=tuple(joints)))
    path = save_robot(arm, tmp_path / "narrow.yaml")
    q0 = np.array([0.4, 0.0, 0.3, -1.2, 0.5, 0.8, 0.2])
    pose = _pose_args(arm, q0)
    code, out, err = run(capsys, "self-motion", path, *pose)
    assert code == 0, err
    assert "0 in-limit interval(s)" in out and "an aligned continuum is" in out
    code, out, err = run(capsys, "self-motion", path, *pose, "--json")
    best = np.array(json.loads(out)["best"]["q"])
    loaded = robokin.load(str(path))
    np.testing.assert_allclose(loaded.fk(best), _pose_of(pose), atol=1e-12)
    assert loaded.within_limits(best)


def test_an_aligned_pose_lists_its_continua(capsys):
    """Oracle: forward kinematics. The Panda's home configuration (q2 = 0: axes 1 and 3
    on one line) reaches its pose along a continuum of (q1 + s, q3 - s): the JSON lists
    its in-limit ends (session 24), each reaching the pose (1e-9, the printed pose's
    digits) inside the limits with q2 = 0 and q1 + q3 = 0, q1 at a limit at one end; the
    text says how many pieces there are and which joints turn."""
    panda = robokin.load("panda")
    q0 = np.array([0.0, 0.0, 0.0, -np.pi / 2, 0.0, np.pi / 2, np.pi / 4])
    pose = _pose_args(panda, q0)
    code, out, err = run(capsys, "self-motion", "panda", *pose, "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert len(doc["continua"]) >= 1
    T = _pose_of(pose)
    lo, hi = panda.limits[:, 0], panda.limits[:, 1]
    for piece in doc["continua"]:
        assert piece["joints"] == ["joint1", "joint3"]
        ends = np.array([piece["from"], piece["to"]])
        np.testing.assert_allclose(panda.fk(ends), np.broadcast_to(T, (2, 4, 4)), atol=1e-9)
        assert np.all(ends >= lo - 1e-12) and np.all(ends <= hi + 1e-12)
        assert np.abs(ends[:, 1]).max() <= 1e-9
        np.testing.assert_allclose(ends[:, 0] + ends[:, 2], 0.0, atol=1e-9)
        assert np.isclose(np.abs(ends[:, 0]), hi[0], atol=1e-9).any()
    code, out, err = run(capsys, "self-motion", "panda", *pose, "--format", "text")
    assert code == 0, err
    assert f"{len(doc['continua'])} aligned continuum piece(s) inside the limits" in out
    assert "joint1 / joint3" in out
