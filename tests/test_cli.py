"""The ``robokin`` command: output, exit codes, one-line errors."""

import json
import subprocess
import sys

import numpy as np
import pytest

import robokin
from robokin.cli import main


def run(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_robots_lists_every_builtin(capsys):
    code, out, _ = run(capsys, "robots")
    assert code == 0
    for name in robokin.robots.names():
        assert name in out


def test_show_prints_the_table_and_limits(capsys):
    code, out, _ = run(capsys, "show", "aubo_i5")
    assert code == 0
    assert "upper_arm" in out and "408" in out and "-175" in out and "AuboRobot" in out


def test_fk_json_matches_the_library(capsys):
    code, out, _ = run(
        capsys, "fk", "ur5", "0", "-90", "0", "-90", "0", "0", "--deg", "--json"
    )
    assert code == 0
    doc = json.loads(out)
    T = robokin.load("ur5").fk(np.radians([0, -90, 0, -90, 0, 0]))
    np.testing.assert_allclose(doc["pose"], T, atol=1e-12)
    # straight up: d1 + |a2| + |a3| + d5 = 1.001059 m
    np.testing.assert_allclose(doc["xyz"], [0, -0.19145, 1.001059], atol=1e-9)


def test_fk_mm_units_for_the_prismatic_joint(capsys):
    code, out, _ = run(
        capsys, "fk", "scara", "0", "0", "0", "100", "--deg", "--mm", "--json"
    )
    assert code == 0
    # z = c1 + c4 + l4 = 400 - 150 + 100 mm; x = c2 + c3 = 600 mm
    np.testing.assert_allclose(json.loads(out)["xyz"], [600, 0, 350], atol=1e-9)


@pytest.mark.parametrize(
    ("args", "code", "match"),
    [
        (["fk", "ur5", "1", "2"], 2, "6 joints, got 2"),
        (["fk", "ur7", "1"], 2, "unknown robot 'ur7'"),
        (["fk", "ur5", "0", "0", "0", "nan", "0", "0"], 2, "non-finite"),
        (["show", "/nonexistent/robot.yaml"], 2, "no such file"),
        (["nosuchcommand"], 2, "No such command"),
    ],
)
def test_errors_are_one_line_with_exit_codes(capsys, args, code, match):
    got, out, err = run(capsys, *args)
    assert got == code
    assert match in out + err
    assert "Traceback" not in out + err


def test_console_script_runs():
    res = subprocess.run(
        [
            sys.executable,
            "-m",
            "robokin",
            "fk",
            "puma560",
            "0",
            "0",
            "0",
            "0",
            "0",
            "0",
            "--json",
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert res.returncode == 0, res.stderr
    np.testing.assert_allclose(
        json.loads(res.stdout)["xyz"], [0.4521, -0.15005, 0.4318], atol=1e-12
    )
