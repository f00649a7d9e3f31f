"""``robokin retime`` (issue 18): files written, the report, units, exit codes."""

import json
import math
import re

import numpy as np
import pytest

from robokin.cli import main
from robokin.trajectory.io import read_csv, write_csv

pytest.importorskip("toppra")

MOTION = """\
robot: aubo_i5
units: {length: mm, angle: deg}
dt: 0.005
start: [0, 10, 80, 0, 90, 0]
limits: {velocity: 90, acceleration: 180}
segments:
  - joint: [-40, 20, 90, -20, 90, 0]
    label: swing
  - line: {dxyz: [0, 0, -100]}
    duration: 1.0
    label: approach
  - dwell: 0.5
    label: grip
  - joint: [0, 10, 80, 0, 90, 0]
    label: home
"""


def run(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def motion(tmp_path):
    f = tmp_path / "press.yaml"
    f.write_text(MOTION)
    return f


def test_motion_file_minimum_report_and_plot(motion, tmp_path, capsys):
    out = tmp_path / "out"
    code, text, _ = run(capsys, "retime", str(motion), "--out", str(out))
    assert code == 0
    assert "minimum cycle time" in text and "approach" in text and "limited by" in text
    doc = json.loads((out / "cycle_time.json").read_text())
    assert doc["robot"] == "aubo_i5"
    assert doc["minimum_cycle_time_s"] < doc["planned_s"]
    assert [s["label"] for s in doc["sections"]] == ["swing", "approach", "grip", "home"]
    assert (out / "bottlenecks.png").stat().st_size > 20_000
    tr = read_csv(out / "retimed.csv")
    assert tr.duration == pytest.approx(doc["minimum_cycle_time_s"], abs=1e-9)


def test_csv_with_a_slower_cycle_time(motion, tmp_path, capsys):
    out = tmp_path / "a"
    run(capsys, "retime", str(motion), "--out", str(out), "--no-plot")
    code, text, _ = run(capsys, "retime", str(out / "retimed.csv"), "--robot",
                        "aubo_i5", "--out", str(tmp_path / "b"), "--cycle-time", "9",
                        "--json")
    assert code == 0
    doc = json.loads(text)
    slow = read_csv(tmp_path / "b" / "retimed_9s.csv")
    assert slow.duration == pytest.approx(9.0, abs=1e-9)
    assert min(doc["margins"]["velocity"]) > 0
    assert doc["cycle_time_s"] == 9.0


def test_a_cycle_time_below_the_minimum_is_a_no(motion, tmp_path, capsys):
    out = tmp_path / "out"
    code, _, err = run(capsys, "retime", str(motion), "--out", str(out),
                       "--cycle-time", "0.5", "--no-plot")
    assert code == 1
    assert "shorter than the minimum" in err and err.count("\n") == 1
    assert (out / "retimed.csv").exists()  # the minimum is still written


def test_limits_in_degrees_and_from_the_command_line(motion, tmp_path, capsys):
    code, text, _ = run(capsys, "retime", str(motion), "--out", str(tmp_path / "o"),
                        "--v-max", "90", "--a-max", "90,90,90,180,180,180", "--deg",
                        "--no-plot", "--json")
    assert code == 0
    lim = json.loads(text)["limits"]
    np.testing.assert_allclose(lim["velocity"], [math.pi / 2] * 6)
    np.testing.assert_allclose(lim["acceleration"], np.radians([90] * 3 + [180] * 3))
    assert lim["sources"]["velocity"] == "--v-max"  # the option that gave it (issue 25)


@pytest.mark.parametrize("args, match", [
    (["--v-max", "0"], "--v-max"),
    (["--v-max", "1,2"], "--v-max.*expected 1 or 6"),
    (["--a-max", "fast"], "--a-max"),
    (["--j-max", "robot"], "--j-max.*no jerk limits"),
    (["--tool-speed", "-1"], "--tool-speed"),
    (["--robot", "ur5"], "--robot.*names its own robot"),
])
def test_bad_options_are_one_line_errors(motion, tmp_path, capsys, args, match):
    code, _, err = run(capsys, "retime", str(motion), "--out", str(tmp_path / "o"),
                       "--no-plot", *args)
    assert code == 2
    assert err.count("\n") == 1
    assert re.search(match, err), err


def test_csv_needs_a_robot_with_limits(motion, tmp_path, capsys):
    from robokin import trajectory

    tr = trajectory.quintic(np.zeros(6), np.full(6, 0.3), 1.0)
    csv = write_csv(tr, tmp_path / "t.csv", [f"j{i}" for i in range(6)])
    code, _, err = run(capsys, "retime", str(csv), "--out", str(tmp_path / "o"))
    assert code == 2 and "needs --robot" in err
    puma = ["waist", "shoulder", "elbow", "wrist_1", "wrist_2", "wrist_3"]
    csv = write_csv(tr, tmp_path / "p.csv", puma)
    code, _, err = run(capsys, "retime", str(csv), "--robot", "puma560", "--out",
                       str(tmp_path / "o"))
    assert code == 2 and "no velocity limits" in err and "give --v-max" in err


def test_an_output_folder_with_other_files_is_refused(motion, tmp_path, capsys):
    out = tmp_path / "busy"
    out.mkdir()
    (out / "mine.txt").write_text("keep me")
    code, _, err = run(capsys, "retime", str(motion), "--out", str(out), "--no-plot")
    assert code == 2 and "--force" in err
    code, _, _ = run(capsys, "retime", str(motion), "--out", str(out), "--no-plot",
                     "--force")
    assert code == 0 and (out / "mine.txt").read_text() == "keep me"


def test_a_motion_files_limits_are_used_and_named(motion, tmp_path, capsys):
    """Issue 25: `retime motion.yaml` kept the robot file's limits and said nothing.

    Oracle: the library's report under the motion file's limits (90 deg/s,
    180 deg/s^2) and under the robot file's (AUBO-i5: 150-180 deg/s, 25-30 rad/s^2)
    differ; the command's minimum is the former. A kind the file leaves out comes
    from the robot file, an option beats both.
    """
    from robokin.io.motion_files import load_motion_file
    from robokin.trajectory.cycle_time import cycle_time_report
    from robokin.trajectory.motion_plan import plan_from_document

    robot, traj = plan_from_document(*load_motion_file(motion))
    want = cycle_time_report(robot, traj, v_max=math.radians(90),
                             a_max=math.radians(180)).minimum_cycle_time
    assert abs(want - cycle_time_report(robot, traj).minimum_cycle_time) > 0.5
    code, text, _ = run(capsys, "retime", str(motion), "--out", str(tmp_path / "a"))
    assert code == 0
    assert "limits: velocity and acceleration from press.yaml (limits:)" in text
    doc = json.loads((tmp_path / "a" / "cycle_time.json").read_text())
    assert doc["minimum_cycle_time_s"] == pytest.approx(want, rel=1e-9)
    np.testing.assert_allclose(doc["limits"]["velocity"], [math.radians(90)] * 6)
    # velocity only in the file: the acceleration is the robot file's
    motion.write_text(MOTION.replace("limits: {velocity: 90, acceleration: 180}",
                                     "limits: {velocity: 90}"))
    code, text, _ = run(capsys, "retime", str(motion), "--out", str(tmp_path / "b"))
    assert code == 0
    assert ("limits: velocity from press.yaml (limits:); acceleration from aubo_i5's "
            "robot file (rate_limits:)") in text
    robot, traj = plan_from_document(*load_motion_file(motion))
    np.testing.assert_allclose(
        json.loads((tmp_path / "b" / "cycle_time.json").read_text())["limits"][
            "acceleration"], robot.rate_limits.acceleration)
    # an option beats the file
    code, text, _ = run(capsys, "retime", str(motion), "--out", str(tmp_path / "c"),
                        "--v-max", "60", "--deg")
    assert code == 0 and "velocity from --v-max" in text


def test_a_csv_needs_robot_and_the_readme_says_so(tmp_path, capsys):
    from pathlib import Path

    csv = tmp_path / "t.csv"
    csv.write_text("t [s],a [rad]\n0,0\n1,1\n")
    code, _, err = run(capsys, "retime", str(csv), "--out", str(tmp_path / "o"))
    assert code == 2 and "--robot" in err
    readme = (Path(__file__).resolve().parents[2] / "README.md").read_text()
    row = next(ln for ln in readme.splitlines() if ln.startswith("| `robokin retime"))
    assert "TRAJ.csv --robot NAME" in row
