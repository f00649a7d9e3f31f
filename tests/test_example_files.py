"""The example input files and the README's commands on them (issue 25).

``examples/07_command_line/`` holds a robot file, its URDF, a scene, a motion file,
the trajectory CSV planned from it and a ROS 2 bag. Every line of the README's
"Try the commands on the example files" block runs here, in a copy of the folder,
and must succeed; where a line has an independent answer it is checked against it
(the committed CSV is what ``robokin traj`` makes of the motion file, the committed
URDF is the same arm as the robot file, the committed bag is what its script
writes, retiming uses the motion file's limits). Editing the README edits the test.
"""

from __future__ import annotations

import importlib.util
import json
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import robokin
from robokin.cli import main

ROOT = Path(__file__).resolve().parents[1]
FOLDER = ROOT / "examples" / "07_command_line"
SECTION = "## Try the commands on the example files"


def readme_block() -> list[str]:
    """The command lines of the README's example-files block, in order."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = text.split(SECTION, 1)[1]
    block = section.split("```bash\n", 1)[1].split("```", 1)[0]
    return [ln for ln in block.splitlines() if ln.strip()]


def robokin_lines() -> list[str]:
    return [ln for ln in readme_block() if ln.startswith("robokin ")]


# the optional packages a command needs (skipped, saying which, when missing)
NEEDS = {"check": "coal", "retime": "toppra", "compare": "rosbags", "view": None,
         "import": "yourdfpy", "dh": "yourdfpy", "sim": "mujoco", "place": "dask"}


@pytest.fixture(scope="module")
def cell(tmp_path_factory):
    """A copy of the example folder, set up as the README's first line sets it up."""
    first = readme_block()[0]
    steps = [s.strip() for s in " ".join(shlex.split(first, comments=True)).split("&&")]
    assert steps == ["cd examples/07_command_line", "mkdir -p out"], first
    dest = tmp_path_factory.mktemp("example") / "07_command_line"
    shutil.copytree(FOLDER, dest, ignore=shutil.ignore_patterns("out", "__pycache__"))
    (dest / "out").mkdir()
    return dest


def run(cell, monkeypatch, capsys, line: str) -> tuple[int, str]:
    args = shlex.split(line, comments=True)
    assert args[0] == "robokin"
    needed = NEEDS.get(args[1])
    if needed and importlib.util.find_spec(needed) is None:
        pytest.skip(f"`{line}` needs {needed} (not installed)")
    monkeypatch.chdir(cell)
    code = main(args[1:])
    out, err = capsys.readouterr()
    assert code == 0, f"{line}\n{out}\n{err}"
    return code, out + err


def test_every_example_file_is_used_by_a_readme_line():
    lines = " ".join(robokin_lines())
    files = {p.name for p in FOLDER.iterdir() if not p.name.startswith(("0", "."))
             and p.name not in ("out", "__pycache__")}
    assert files == {"arm.yaml", "arm.urdf", "cell.yaml", "pick.yaml", "plan.csv",
                     "run_bag"}
    for name in files:
        assert f" {name}" in lines, name
    assert "examples/07_command_line/out/" in (ROOT / ".gitignore").read_text()


@pytest.mark.parametrize("line", robokin_lines(), ids=lambda ln: " ".join(ln.split()[1:3]))
def test_readme_line_runs(cell, monkeypatch, capsys, line):
    _, text = run(cell, monkeypatch, capsys, line)
    command = shlex.split(line, comments=True)[1]
    check = CHECKS.get(command)
    if check is not None:
        check(cell, line, text)


# ----------------------------------------------------------- per-command oracles
def _fk(cell, line, text):
    arm = robokin.load(cell / "arm.yaml")
    q = np.radians([float(v) for v in shlex.split(line, comments=True)[3:9]])
    xyz = arm.fk(q)[:3, 3] * 1000.0
    assert "xyz [mm]: " + "  ".join(f"{v:.6f}" for v in xyz) in text


def _ik(cell, line, text):
    assert "8 solution(s) [analytic" in text


def _traj(cell, line, text):
    """The committed plan.csv is what `robokin traj pick.yaml` writes."""
    from robokin.trajectory.io import read_csv

    arm = robokin.load(cell / "arm.yaml")
    fresh = read_csv(cell / "out" / "plan.csv", joint_names=arm.joint_names)
    committed = read_csv(FOLDER / "plan.csv", joint_names=arm.joint_names)
    np.testing.assert_allclose(fresh.t, committed.t, atol=1e-12)
    np.testing.assert_allclose(fresh.q, committed.q, atol=1e-9)


def _check(cell, line, text):
    assert "clearance 10 mm: OK" in text


def _retime(cell, line, text):
    """The motion file's limits: are the ones used (library, same limits)."""
    from robokin.io.motion_files import load_motion_file
    from robokin.trajectory.cycle_time import cycle_time_report
    from robokin.trajectory.motion_plan import plan_from_document

    folder = cell / shlex.split(line, comments=True)[-1]
    doc = json.loads((folder / "cycle_time.json").read_text())
    if "pick.yaml" in line:
        assert "limits: velocity and acceleration from pick.yaml (limits:)" in text
        arm, traj = plan_from_document(*load_motion_file(cell / "pick.yaml"))
        v, a = np.radians(120.0), np.radians(400.0)  # pick.yaml: 120 deg/s, 400 deg/s^2
        want = cycle_time_report(arm, traj, v_max=v, a_max=a).minimum_cycle_time
        robot_file = cycle_time_report(arm, traj).minimum_cycle_time
        assert doc["minimum_cycle_time_s"] == pytest.approx(want, rel=1e-9)
        assert abs(want - robot_file) > 0.1  # the two limits give other answers
        assert doc["limits"]["sources"] == {"velocity": "pick.yaml (limits:)",
                                            "acceleration": "pick.yaml (limits:)"}
    else:
        assert ("limits: velocity and acceleration from example_arm's robot file "
                "(rate_limits:)") in text


def _compare(cell, line, text):
    assert "run_bag vs plan.csv" in text
    assert (cell / "out" / "run_vs_plan.png").stat().st_size > 10_000


def _view(cell, line, text):
    assert (cell / "out" / "pick.html").stat().st_size > 50_000


def _import(cell, line, text):
    """arm.urdf is the same arm as arm.yaml: the imported one has the same FK."""
    arm = robokin.load(cell / "arm.yaml")
    back = robokin.load(cell / "out" / "arm_from_urdf.yaml")
    q = np.random.default_rng(25).uniform(arm.limits[:, 0], arm.limits[:, 1], (50, 6))
    q[0] = 0.0
    np.testing.assert_allclose(back.fk(q), arm.fk(q), atol=1e-12)


def _sim(cell, line, text):
    assert "PASS" in text and "faster than real time" in text


def _place(cell, line, text):
    assert (cell / "out" / "place" / "placement.png").stat().st_size > 10_000


CHECKS = {"fk": _fk, "ik": _ik, "traj": _traj, "check": _check, "retime": _retime,
          "compare": _compare, "view": _view, "import": _import, "sim": _sim,
          "place": _place}


# ------------------------------------------------------------------ the bag
def test_the_committed_bag_is_what_its_script_writes(tmp_path):
    pytest.importorskip("rosbags")
    from robokin.trajectory.ros2 import read_bag_log

    proc = subprocess.run(
        [sys.executable, str(FOLDER / "00_write_run_bag.py"), "--out",
         str(tmp_path / "bag")], capture_output=True, text=True, timeout=120, check=False)
    assert proc.returncode == 0, proc.stderr
    arm = robokin.load(FOLDER / "arm.yaml")
    fresh = read_bag_log(tmp_path / "bag", joint_names=arm.joint_names)
    committed = read_bag_log(FOLDER / "run_bag", joint_names=arm.joint_names)
    np.testing.assert_array_equal(fresh.t, committed.t)
    np.testing.assert_allclose(fresh.q, committed.q, atol=1e-12)
    assert len(committed.t) == 337  # 6.72 s at 50 Hz
