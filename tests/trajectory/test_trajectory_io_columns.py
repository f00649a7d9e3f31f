"""CSV joint columns by name, times that must increase (issue 15, item 3).

Written as the attack: a correctly labelled log with two columns swapped must give
the same answer as the unswapped one, in ``robokin compare`` and ``robokin check``.
"""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

import robokin
from robokin.cli import main
from robokin.exceptions import ModelError
from robokin.trajectory import io, quintic

NAMES = ("shoulder", "elbow", "wrist")


def _csv(path, t, q, names, units=("deg",) * 3):
    head = "t [s]," + ",".join(f"{n} [{u}]" for n, u in zip(names, units))
    rows = [",".join(repr(float(v)) for v in (ti, *qi)) for ti, qi in zip(t, q)]
    path.write_text(head + "\n" + "\n".join(rows) + "\n")
    return path


def _swapped(path, out, i, j):
    """The same file with columns i and j (header and data) exchanged."""
    lines = path.read_text().splitlines()
    swapped = []
    for ln in lines:
        cells = ln.split(",")
        cells[i], cells[j] = cells[j], cells[i]
        swapped.append(",".join(cells))
    out.write_text("\n".join(swapped) + "\n")
    return out


def test_swapped_labelled_columns_read_the_same(tmp_path, rng):
    t = np.linspace(0, 1, 11)
    q = rng.normal(size=(11, 3))
    a = _csv(tmp_path / "a.csv", t, np.degrees(q), NAMES)
    b = _swapped(a, tmp_path / "b.csv", 1, 3)
    assert b.read_text().splitlines()[0].startswith("t [s],wrist [deg]")
    ra = io.read_csv(a, joint_names=NAMES)
    rb = io.read_csv(b, joint_names=NAMES)
    np.testing.assert_allclose(rb.q, q, rtol=1e-15)
    np.testing.assert_array_equal(ra.q, rb.q)
    assert rb.joint_names == NAMES
    # without names the file's own order is kept (the old behaviour, now opt-in)
    assert io.read_csv(b).joint_names == ("wrist", "elbow", "shoulder")


def test_mixed_units_follow_their_columns_when_swapped(tmp_path):
    t = np.array([0.0, 1.0])
    q = np.array([[90.0, 100.0, 0.5], [45.0, 200.0, 0.25]])
    a = _csv(tmp_path / "a.csv", t, q, NAMES, units=("deg", "mm", "rad"))
    b = _swapped(a, tmp_path / "b.csv", 1, 2)
    for p in (a, b):
        tr = io.read_csv(p, joint_names=NAMES)
        np.testing.assert_allclose(tr.q[0], [np.pi / 2, 0.1, 0.5])
        np.testing.assert_array_equal(tr.revolute(), [True, False, True])


@pytest.mark.parametrize(("header", "message"), [
    ("t [s],shoulder [deg],elbow [deg],wrist_1 [deg]",
     r"unknown \['wrist_1'\]; missing \['wrist'\]; expected the names "
     r"\['shoulder', 'elbow', 'wrist'\]"),
    ("t [s],shoulder [deg],elbow [deg]", r"2 joint columns do not match the 3 joints"),
    ("t [s],shoulder [deg],elbow [deg],wrist [deg],extra [deg]",
     r"unknown \['extra'\]"),
    ("t [s],shoulder [deg],shoulder [deg],wrist [deg]", r"repeats the joint"),
])
def test_unknown_missing_or_extra_names_are_refused(tmp_path, header, message):
    p = tmp_path / "log.csv"
    width = header.count(",") + 1
    p.write_text(header + "\n" + ",".join(["0"] * width) + "\n")
    with pytest.raises(ModelError, match=message):
        io.read_csv(p, joint_names=NAMES)


def test_a_file_without_header_is_read_by_position_with_a_warning(tmp_path):
    p = tmp_path / "raw.csv"
    p.write_text("0,0.1,0.2,0.3\n0.5,0.4,0.5,0.6\n")
    with pytest.warns(UserWarning, match="no header line: its columns are read by "
                                         "position"):
        tr = io.read_csv(p, joint_names=NAMES)
    np.testing.assert_array_equal(tr.q, [[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]])
    p.write_text("0,0.1,0.2\n")
    with warnings.catch_warnings(), pytest.raises(ModelError, match="has 2 joint "
                                                  "columns and no header"):
        warnings.simplefilter("ignore")
        io.read_csv(p, joint_names=NAMES)


def test_a_log_whose_time_goes_backwards_is_refused_not_sorted(tmp_path):
    p = tmp_path / "log.csv"
    p.write_text("t [s],a [rad]\n0,0\n0.1,1\n0.1,1\n0.05,2\n0.2,3\n")
    with pytest.raises(ModelError, match=r"log\.csv:5: time goes backwards "
                                         r"\(0\.1 s, then 0\.05 s\)"):
        io.read_log(p)
    p.write_text("t [s],a [rad]\n0,0\n0.1,1\n0.1,1\n0.2,3\n")
    np.testing.assert_array_equal(io.read_log(p).t, [0, 0.1, 0.2])  # repeats dropped
    assert list(tmp_path.iterdir()) == [p]  # no temporary copy written


# ------------------------------------------------------------ the CLI, end to end
def _plan(tmp_path):
    robot = robokin.load("aubo_i5")
    q0 = np.radians([0, 10, 80, 0, 90, 0])
    q1 = np.radians([-40, 20, 90, -20, 90, 30])
    tr = quintic(q0, q1, 1.0, dt=0.01)
    plan = io.write_csv(tr, tmp_path / "plan.csv", robot.joint_names)
    return robot, tr, plan


def test_compare_gives_the_same_answer_for_swapped_log_columns(tmp_path, capsys):
    robot, tr, plan = _plan(tmp_path)
    err = np.radians(np.array([0.1, 0.2, 0.3, 0.4, 0.5, 0.6]))
    log = _csv(tmp_path / "log.csv", tr.t, np.degrees(tr.q + err), robot.joint_names,
               units=("deg",) * 6)
    swapped = _swapped(log, tmp_path / "swapped.csv", 2, 5)
    answers = []
    for p in (log, swapped):
        assert main(["compare", str(plan), str(p), "--json", "--no-plot"]) == 0
        answers.append(json.loads(capsys.readouterr().out)["joints"])
    assert answers[0] == answers[1]
    np.testing.assert_allclose([r["max"] for r in answers[0]],
                               np.degrees(err), rtol=1e-9)
    # a log for another arm: exit 2, one line naming the expected joints
    bad = _csv(tmp_path / "bad.csv", tr.t, tr.q, [f"j{i}" for i in range(6)],
               units=("rad",) * 6)
    assert main(["compare", str(plan), str(bad), "--no-plot"]) == 2
    msg = capsys.readouterr().err
    assert msg.count("\n") == 1 and "shoulder" in msg and "bad.csv:1:" in msg


def test_check_gives_the_same_answer_for_swapped_columns(tmp_path, capsys):
    pytest.importorskip("coal")
    from robokin.collision import Scene, scene_path

    robot = robokin.load("aubo_i5")
    sc = Scene.load(scene_path("press"))
    q0, q1 = sc.pose_joints["pick_approach"], sc.pose_joints["pick"]
    q = q0 + np.linspace(0, 1, 20)[:, None] * (q1 - q0)
    t = np.linspace(0, 1, 20)
    a = _csv(tmp_path / "a.csv", t, np.degrees(q), robot.joint_names,
             units=("deg",) * 6)
    b = _swapped(a, tmp_path / "b.csv", 1, 4)
    answers = []
    for p in (a, b):
        assert main(["check", "press", str(p), "--json"]) == 0
        answers.append(json.loads(capsys.readouterr().out))
    assert answers[0] == answers[1]
    assert answers[0]["min_distance_m"] > 0
