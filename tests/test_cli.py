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


# ------------------------------------------- issue 15: exit codes, one line, JSON
def _one_line(err: str) -> None:
    assert err.count("\n") == 1 and err.startswith("robokin: "), err


@pytest.mark.parametrize("args", [
    ["fk", "ur5", "0", "0", "--bogus-option"],
    ["ik", "ur5"],
    ["traj"],
    ["fk", "ur5", "x", "0", "0", "0", "0", "0"],
])
def test_usage_errors_are_one_line_with_exit_code_2(capsys, args):
    code, out, err = run(capsys, *args)
    assert code == 2
    _one_line(err)
    assert "Usage:" not in out + err and "╭" not in err


def test_input_files_that_are_not_robot_files_exit_2(capsys, tmp_path):
    binary = tmp_path / "robot.yaml"
    binary.write_bytes(b"\x7fELF\x02\x01\x01\x00\x00\x00")
    big = tmp_path / "big.yaml"
    big.write_text("name: x\nsource: " + "a" * (17 * 2**20) + "\n")
    for path, why in ((binary, "binary"), (tmp_path, "is a folder"),
                      (big, "more than the 16,777,216 bytes")):
        code, _, err = run(capsys, "show", str(path))
        assert code == 2, err
        _one_line(err)
        assert why in err


def test_no_ik_solution_exits_1_and_bad_input_exits_2(capsys):
    code, _, err = run(capsys, "ik", "ur5", "5", "0", "0", "0", "0", "0")
    assert code == 1 and "no IK solution" in err
    _one_line(err)
    code, _, err = run(capsys, "ik", "ur5", "1e300", "0", "0", "0", "0", "0")
    assert code == 2 and "beyond the 1e+06 m" in err
    _one_line(err)


def test_debug_is_accepted_after_the_subcommand(capsys):
    code, out, _ = run(capsys, "fk", "ur5", "0", "0", "0", "0", "0", "0", "--json",
                       "--debug")
    assert code == 0 and "pose" in json.loads(out)
    # --debug adds the traceback and keeps the exit code (issue 25: it was 1)
    code, _, err = run(capsys, "show", "ur7", "--debug")
    assert code == 2
    assert "Traceback" in err and "robokin.exceptions.ModelError" in err
    assert err.splitlines()[-1].startswith("robokin: error: unknown robot 'ur7'")


@pytest.mark.parametrize("args", [
    ["fk", "ur5", "1", "2"],                  # a usage error (BadParameter)
    ["fk", "ur5", "0", "0", "0", "0", "0", "0", "--nosuch-option=1"],
    ["nosuchcommand"],
    ["show", "/nonexistent/robot.yaml"],      # an input error (ModelError)
])
@pytest.mark.parametrize("where", ["first", "last"])
def test_debug_anywhere_keeps_exit_code_2(capsys, args, where):
    """Issue 25: --debug after a subcommand turned exit 2 into exit 1."""
    plain, _, _ = run(capsys, *args)
    argv = ["--debug", *args] if where == "first" else [*args, "--debug"]
    code, _, err = run(capsys, *argv)
    assert plain == code == 2
    assert err.splitlines()[-1].startswith("robokin: error: ")


def test_warnings_are_one_line(capsys, tmp_path):
    p = tmp_path / "arm.yaml"
    p.write_text("name: arm\njoints:\n  - {a: 0, alpha: 0, d: 89.159}\n"
                 "  - {a: 425, alpha: 0, d: 0}\n")
    code, _, err = run(capsys, "show", str(p))
    assert code == 0
    assert err.startswith("robokin: warning: ") and err.count("\n") == 1
    assert "425 m" in err and "units: {length: mm}" in err


def test_json_output_is_strict_json_with_nulls_explained(capsys, tmp_path):
    robot = robokin.load("ur5")
    from robokin.trajectory import io, quintic

    tr = quintic(np.zeros(6), np.full(6, 0.5), 1.0, dt=0.01)
    plan = io.write_csv(tr, tmp_path / "plan.csv", robot.joint_names)
    # the run followed the plan exactly: a zero error has no correlation (NaN)
    log = io.write_csv(tr, tmp_path / "log.csv", robot.joint_names)
    code, out, _ = run(capsys, "compare", str(plan), str(log), "--json", "--no-plot")
    assert code == 0
    doc = json.loads(out, parse_constant=lambda c: pytest.fail(f"{c} in the JSON"))
    assert doc["joints"][0]["corr_acc"] is None
    assert doc["nulls"]["joints[0].corr_acc"].startswith("NaN")


def test_show_never_hands_rich_an_unbounded_word(capsys):
    r = robokin.load("ur5")
    long = r.replace(source="x" * 1_000_000, name="[bold red]ur5[/]")
    from robokin.cli.common import cell

    assert len(cell(long.source, 300)) <= 300
    assert cell(long.name) == "\\[bold red]ur5\\[/]"


@pytest.mark.parametrize(
    ("args", "note"),
    [
        # 90 rad: the AUBO-i5's shoulder is limited to +-175 deg (3.05433 rad)
        (["aubo_i5", "90", "0", "0", "0", "0", "0"],
         "joint 'shoulder' = 90 rad is outside its limits [-3.05433, 3.05433] rad "
         "(degrees? pass --deg)"),
        (["aubo_i5", "0", "200", "0", "0", "0", "0", "--deg"],
         "joint 'upper_arm' = 200 deg is outside its limits [-175, 175] deg;"),
        # the SCARA's shaft travels 0..200 mm (robots/scara.yaml)
        (["scara", "0", "0", "0", "900", "--mm"],
         "joint 'lift' = 900 mm is outside its limits [0, 200] mm;"),
    ],
)
def test_fk_outside_the_limits_notes_the_joint_and_its_limits(capsys, args, note):
    """Issue 25: FK outside the limits gave no note; the pose is still printed."""
    code, out, err = run(capsys, "fk", *args, "--json")
    assert code == 0 and "pose" in json.loads(out)
    assert err.startswith("robokin: note: " + note), err
    assert len(err.splitlines()) == 1
    code, _, err = run(capsys, "fk", "aubo_i5", "3.05", "0", "0", "0", "0", "0")
    assert code == 0 and err == ""  # inside: nothing to say


# ------------------------------------------------------------ issue 25: first hour
def test_fk_mm_prints_the_matrix_in_mm_too(capsys):
    """The 4x4's translation is in the unit of the xyz line (oracle: robot.fk)."""
    q = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]
    T = robokin.load("ur5").fk(np.array(q))
    code, out, _ = run(capsys, "fk", "ur5", *map(str, q), "--mm")
    assert code == 0
    rows = [ln.strip(" []") for ln in out.splitlines() if ln.lstrip().startswith("[")]
    matrix = np.array([[float(v) for v in r.split()] for r in rows])
    np.testing.assert_allclose(matrix[:3, 3], T[:3, 3] * 1000, atol=1e-6)
    np.testing.assert_allclose(matrix[:3, :3], T[:3, :3], atol=1e-6)
    assert "translation in mm" in out
    code, out, _ = run(capsys, "fk", "ur5", *map(str, q), "--mm", "--json")
    doc = json.loads(out)
    np.testing.assert_allclose(np.array(doc["pose"])[:3, 3], T[:3, 3] * 1000, atol=1e-9)
    assert doc["units"] == {"length": "mm", "angle": "rad"}


def test_ik_of_a_redundant_arm_says_it_is_a_sample_and_fixed_holds_a_joint(capsys):
    """Oracle: the Panda configuration that made the pose comes back with --fixed
    joint7 held at its value, and every listed row reaches the pose."""
    panda = robokin.load("panda")
    q = np.array([0.1, -0.3, 0.2, -2.0, 0.3, 1.8, 0.7])
    T = panda.fk(q)
    from robokin.spatial import rpy_from_matrix

    pose = [*map(str, T[:3, 3]), *map(str, rpy_from_matrix(T))]
    code, out, _ = run(capsys, "ik", "panda", *pose)
    assert code == 0
    assert "panda: a sample of" in out and "of a continuum" in out
    assert "--fixed joint7=VALUE" in out and "robokin self-motion gives all of it" in out
    pose_deg = [*map(str, T[:3, 3]), *map(str, np.degrees(rpy_from_matrix(T)))]
    code, out, _ = run(capsys, "ik", "panda", *pose_deg, "--fixed",
                       "joint7=40.10704565915762", "--deg", "--json")
    assert code == 0, out
    doc = json.loads(out)
    assert doc["fixed"] == {"joint7": pytest.approx(40.10704565915762)}
    assert not doc["sample_of_continuum"]
    sols = np.radians([s["q"] for s in doc["solutions"]])
    np.testing.assert_allclose(sols[:, 6], 0.7, atol=1e-12)
    np.testing.assert_allclose(panda.fk(sols), np.broadcast_to(T, (len(sols), 4, 4)),
                               atol=1e-9)
    assert np.abs(sols - q).max(axis=1).min() < 1e-9
    # a six-joint arm: no note
    code, out, _ = run(capsys, "ik", "ur5", "0.4", "0.1", "0.5", "3.1", "0", "0")
    assert code == 0 and "continuum" not in out


@pytest.mark.parametrize(("fixed", "match"), [
    ("joint9=1", "unknown joint 'joint9'; joints: joint1"),
    ("joint7", "expected NAME=VALUE"),
    ("joint7=x", "expected a number for joint7"),
    ("joint7=nan", "expected a finite number"),
])
def test_ik_fixed_errors_name_the_option(capsys, fixed, match):
    code, _, err = run(capsys, "ik", "panda", "0.4", "0.1", "0.5", "3.1", "0", "0",
                       "--fixed", fixed)
    assert code == 2 and "argument '--fixed'" in err and match in err
    _one_line(err)
