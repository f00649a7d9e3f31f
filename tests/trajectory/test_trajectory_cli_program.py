"""``robokin traj --program DIALECT`` (issue 27 item 4): the program in the controller's
language next to the motion file, read back; today's --program FILE still works.

Oracle: tests/program_parsers.py reads the written program; its joint targets are
samples of the CSV the same run wrote (the plan), first and last included.
"""

import json

import numpy as np

import robokin
from program_parsers import parse_abb, parse_kuka
from robokin.cli import main
from robokin.trajectory.controllers import controller_profile
from robokin.trajectory.io import read_csv

MOTION = """\
robot: aubo_i5
units: {length: mm, angle: deg}
dt: 0.005
start: [0, 10, 80, 0, 90, 0]
segments:
  - joint: [-40, 20, 90, -20, 90, 0]
    duration: 1.0
  - joint: [-10, 40, 60, 30, 60, 20]
    duration: 1.0
"""


def _plan_deg(path):
    aubo = robokin.load("aubo_i5")
    return np.degrees(controller_profile(aubo).export(read_csv(path).q))


def test_dialect_program_next_to_the_motion_file(tmp_path, capsys):
    f = tmp_path / "weld path.yaml"
    f.write_text(MOTION)
    assert main(["traj", str(f), "--no-plot", "--program", "kuka_krl"]) == 0
    out = capsys.readouterr().out
    assert "weld_path.src" in out and "KUKA KRL program weld_path" in out
    assert "note: program name 'weld path' is not a legal KUKA KRL name" in out
    parsed = parse_kuka(tmp_path, "weld_path")
    plan = _plan_deg(tmp_path / "weld path.csv")
    got = np.array([m.joints for m in parsed.moves])
    assert np.abs(got[0] - plan[0]).max() < 1e-4 and np.abs(got[-1] - plan[-1]).max() < 1e-4
    dist = np.abs(got[:, None, :] - plan[None]).max(axis=2).min(axis=1)
    assert dist.max() < 1e-4 and 3 <= len(got) < len(plan) / 10
    assert np.abs(got - plan[200]).max(axis=1).min() < 1e-4  # the via point is kept
    # a second run does not replace them without --force, and writes nothing
    before = (tmp_path / "weld_path.src").read_bytes()
    (tmp_path / "weld path.csv").unlink()
    assert main(["traj", str(f), "--no-plot", "--program", "kuka_krl"]) == 2
    err = capsys.readouterr().err
    assert "weld_path.src and " in err and "weld_path.dat exist" in err
    assert not (tmp_path / "weld path.csv").exists()
    assert main(["traj", str(f), "--no-plot", "--program", "kuka_krl", "--force",
                 "--program-stride", "50"]) == 0
    assert (tmp_path / "weld_path.src").read_bytes() != before
    assert len(parse_kuka(tmp_path, "weld_path").moves) == 9  # 0, 50, .. 400


def test_dialect_options_and_folder(tmp_path, capsys):
    f = tmp_path / "m.yaml"
    f.write_text(MOTION)
    code = main(["traj", str(f), "--no-plot", "--json", "--program", "abb_rapid",
                 "--program-dir", str(tmp_path / "rapid"), "--program-tolerance", "0.5"])
    out, err = capsys.readouterr()
    assert code == 0, err
    files = json.loads(out)["controller_files"]
    assert files[0].startswith(f"wrote {tmp_path / 'rapid' / 'm.mod'}: ABB RAPID program m")
    coarse = parse_abb(tmp_path / "rapid", "m")
    # the same plan at the default tolerance (1 mrad) keeps more samples
    assert main(["traj", str(f), "--no-plot", "--force", "--program", "abb_rapid",
                 "--program-dir", str(tmp_path / "fine")]) == 0
    capsys.readouterr()
    assert 3 <= len(coarse.moves) < len(parse_abb(tmp_path / "fine", "m").moves)


def test_bad_program_values(tmp_path, capsys):
    f = tmp_path / "m.yaml"
    f.write_text(MOTION)
    assert main(["traj", str(f), "--no-plot", "--program", "krl"]) == 2
    assert "'krl' is neither a dialect (['abb_rapid'" in capsys.readouterr().err
    assert main(["traj", str(f), "--no-plot", "--program", str(tmp_path / "p.csv"),
                 "--program-stride", "4"]) == 2
    assert "--program-stride': applies to --program DIALECT" in capsys.readouterr().err
    # today's profile program by file name still works
    assert main(["traj", str(f), "--no-plot", "--force", "--program",
                 str(tmp_path / "p.waypoints.csv")]) == 0
    assert "waypoint file (CSV, every sample)" in capsys.readouterr().out
