"""``robokin traj`` and ``robokin compare``: files written, summary, exit codes, errors."""

import json
import re

import numpy as np
import pytest

from robokin.cli import main
from robokin.trajectory.io import read_csv

MOTION = """\
robot: aubo_i5
units: {length: mm, angle: deg}
dt: 0.005
start: [0, 10, 80, 0, 90, 0]
limits: {velocity: 90, acceleration: 180}
segments:
  - joint: [-40, 20, 90, -20, 90, 0]
  - line: {dxyz: [0, 0, -100]}
    duration: 1.0
    label: approach
  - dwell: 0.5
  - joint: [0, 10, 80, 0, 90, 0]
"""


def run(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_traj_writes_csv_plot_and_summary(tmp_path, capsys):
    f = tmp_path / "press.yaml"
    f.write_text(MOTION)
    code, out, _ = run(capsys, "traj", str(f))
    assert code == 0
    assert "4 segments" in out and "no violation" in out and "shoulder" in out
    tr = read_csv(tmp_path / "press.csv")
    np.testing.assert_allclose(tr.q[0], np.radians([0, 10, 80, 0, 90, 0]), atol=1e-12)
    np.testing.assert_allclose(np.diff(tr.t), 0.005, atol=1e-9)
    assert (tmp_path / "press.png").stat().st_size > 20_000
    # never replaces what exists unless -o names it
    code, _, err = run(capsys, "traj", str(f))
    assert code == 2 and "exist" in err  # "exist": two files (issue 25 names both)
    code, out, _ = run(capsys, "traj", str(f), "-o", str(tmp_path / "press.csv"),
                       "--no-plot", "--json")
    doc = json.loads(out)
    assert code == 0 and doc["samples"] == len(tr)
    assert max(doc["peak_velocity"]) <= np.radians(90) + 1e-9


def test_traj_reports_limit_violations_with_exit_1(tmp_path, capsys):
    f = tmp_path / "fast.yaml"
    f.write_text(MOTION.replace("limits: {velocity: 90, acceleration: 180}",
                                "limits: {velocity: 90}")
                 .replace("  - joint: [-40, 20, 90, -20, 90, 0]\n",
                          "  - joint: [-40, 20, 90, -20, 90, 0]\n    duration: 0.2\n"))
    code, out, err = run(capsys, "traj", str(f), "--no-plot")
    assert code == 1 and "velocity of shoulder" in out and "limit violation" in err


def test_traj_file_errors_name_the_field(tmp_path, capsys):
    f = tmp_path / "bad.yaml"
    f.write_text(MOTION.replace("[-40, 20, 90, -20, 90, 0]", "[-40, 20]"))
    code, _, err = run(capsys, "traj", str(f))
    assert code == 2 and "segments[0].joint" in err and "6 joints" in err


def test_compare_prints_the_error_table(tmp_path, capsys):
    f = tmp_path / "press.yaml"
    f.write_text(MOTION)
    run(capsys, "traj", str(f), "--no-plot")
    plan = read_csv(tmp_path / "press.csv")
    q = plan.q + np.radians(0.25)
    log = tmp_path / "log.csv"
    # a log labels its columns with the robot's joint names (matched by name)
    log.write_text("t [s]," + ",".join(f"{n} [deg]" for n in plan.names()) + "\n" + "\n".join(
        ",".join(repr(float(v)) for v in [t, *np.degrees(r)]) for t, r in zip(plan.t, q)))
    code, out, _ = run(capsys, "compare", str(tmp_path / "press.csv"), str(log), "--json")
    assert code == 0
    rows = json.loads(out)["joints"]
    assert [r["joint"] for r in rows] == list(plan.names())
    for r in rows:
        assert abs(r["max"] - 0.25) < 1e-9 and abs(r["rms"] - 0.25) < 1e-9
    assert (tmp_path / "log_vs_plan.png").exists()


@pytest.mark.parametrize(("old", "new", "field", "reason"), [
    ("velocity: 90", "velocity: -90", "limits.velocity", "positive"),
    ("  - dwell: 0.5\n", "  - dwell: 0.5\n  - joint: [0, 0, 90, 0, 90, 0]\n"
     "    profile: bogus\n", "segments[3].profile", "unknown profile"),
    ("robot: aubo_i5", "robot: no_such_arm", "robot", "unknown robot"),
])
def test_traj_builder_errors_name_the_file_field(tmp_path, capsys, old, new, field, reason):
    assert old in MOTION
    f = tmp_path / "bad.yaml"
    f.write_text(MOTION.replace(old, new, 1))
    code, _, err = run(capsys, "traj", str(f), "--no-plot")
    assert code == 2
    # the message names the file, the line of the field and the field
    assert re.search(rf"bad\.yaml:\d+: {re.escape(field)}:", err) and reason in err
