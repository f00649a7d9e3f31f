"""``robokin sim`` and ``robokin export -o NAME.xml`` (issue 17, items 1 and 3)."""

from __future__ import annotations

import json

import numpy as np
import pytest

import robokin
from robokin import trajectory
from robokin.cli import main
from robokin.trajectory import io

pytest.importorskip("mujoco")


@pytest.fixture()
def plan_csv(tmp_path):
    robot = robokin.load("ur5")
    plan = trajectory.quintic(np.zeros(6), np.radians([20, -30, 40, 10, 20, 30]), 1.0,
                              dt=0.005).replace(joint_names=robot.joint_names)
    return io.write_csv(plan, tmp_path / "plan.csv")


def test_sim_command_writes_the_run_and_passes(tmp_path, plan_csv, capsys):
    out = tmp_path / "run"
    assert main(["sim", "ur5", str(plan_csv), "--out", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["ok"] and len(summary["joints"]) == 6
    assert summary["timing"]["real_time_factor"] < 1.0
    for name in ("model.xml", "simulated.csv", "tracking.png", "torques.png",
                 "contacts.csv", "summary.json"):
        assert (out / name).stat().st_size > 40, name
    # the names checked against the inputs before the run are the names written
    from robokin.sim.report import RUN_FILES

    assert sorted(p.name for p in out.iterdir()) == sorted(RUN_FILES)
    assert summary["joints"][1]["torque_limit"] == 150.0


def test_sim_command_exit_codes(tmp_path, plan_csv, capsys):
    # a tolerance no servo meets: the verdict fails (1)
    assert main(["sim", "ur5", str(plan_csv), "--out", str(tmp_path / "a"),
                 "--tolerance-deg", "1e-6"]) == 1
    assert "fails its verdict" in capsys.readouterr().err
    # a plan for another robot: input error (2)
    assert main(["sim", "scara", str(plan_csv), "--out", str(tmp_path / "b")]) == 2
    assert main(["sim", "ur5", str(plan_csv), "--out", str(tmp_path / "c"),
                 "--bandwidth", "nan"]) == 2


def test_export_chooses_the_format_by_suffix(tmp_path, capsys):
    assert main(["export", "scara", "-o", str(tmp_path / "scara.xml")]) == 0
    text = (tmp_path / "scara.xml").read_text()
    assert text.startswith("<mujoco") and '<site name="tool"' in text
    assert main(["export", "scara", "-o", str(tmp_path / "scara.urdf")]) == 0
    assert "<robot" in (tmp_path / "scara.urdf").read_text()
    assert main(["export", "aubo_i5", "--scene", "press", "-o",
                 str(tmp_path / "cell.xml")]) == 0
    assert 'name="lower_die"' in (tmp_path / "cell.xml").read_text()
    assert main(["export", "scara", "-o", str(tmp_path / "scara.txt")]) == 0
    assert "<robot" in (tmp_path / "scara.txt").read_text()  # URDF, as always
    assert main(["export", "scara", "--format", "stl"]) == 2
    assert main(["export", "scara", "--scene", "press", "-o",
                 str(tmp_path / "x.urdf")]) == 2
    capsys.readouterr()
    assert main(["export", "scara", "--format", "mjcf"]) == 0
    assert capsys.readouterr().out.startswith("<mujoco")


def test_sim_command_drives_motors(tmp_path, capsys):
    robot = robokin.load("scara")
    plan = trajectory.quintic(np.array([0.0, 0.0, 0.0, 0.05]),
                              np.array([0.4, 0.6, 1.5, 0.12]), 1.0, dt=0.005)
    motors = plan.to_actuator_space(robot)
    path = io.write_csv(motors, tmp_path / "motors.csv")
    assert main(["sim", "scara", str(path), "--motors", "--out", str(tmp_path / "m"),
                 "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["servo"]["actuators"] == "motor" and summary["ok"]
    assert main(["sim", "ur5", str(path), "--motors", "--out", str(tmp_path / "u")]) == 2


@pytest.mark.parametrize(("factor", "text"), [
    (0.0126, "79x faster than real time"),   # 1 / 0.0126 = 79.4
    (0.25, "4.0x faster than real time"),
    (1.02, "at about real time"),
    (2.5, "2.5x slower than real time"),
    (40.0, "40x slower than real time"),
])
def test_speed_text(factor, text):
    from robokin.sim.report import speed_text

    assert speed_text(factor) == text


def test_sim_says_how_much_faster_than_real_time(tmp_path, plan_csv, capsys):
    """Issue 25: "0.0126 x real time" read as 80 times slower."""
    assert main(["sim", "ur5", str(plan_csv), "--out", str(tmp_path / "run")]) == 0
    out = capsys.readouterr().out
    line = next(ln for ln in out.splitlines() if "simulated at" in ln)
    assert "x faster than real time" in line and "x real time" not in line
