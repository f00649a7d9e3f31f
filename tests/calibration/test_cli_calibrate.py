"""``robokin calibrate``: reads a measurement CSV by column name, writes all or nothing.

Oracles: the synthetic truth behind the CSV (the written robot file must fit
the hold-out rows at the noise floor), the files on disk, the exit codes.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import robokin
from robokin import calibration
from robokin.calibration.data_files import read_measurements, write_measurements
from robokin.cli import main
from robokin.exceptions import ModelError

from .conftest import make_case


@pytest.fixture(scope="module")
def csv_case(tmp_path_factory, ur5):
    case = make_case(ur5, "pose", n=200, hold=200, seed=17)
    folder = tmp_path_factory.mktemp("cal")
    write_measurements(folder / "data.csv", ur5, case.q, case.measured, comment="test")
    write_measurements(folder / "hold.csv", ur5, case.q_hold, case.measured_hold,
                       mm=False, deg=False)
    return case, folder


def test_csv_round_trip_in_any_units(csv_case, ur5):
    case, folder = csv_case
    q, m = read_measurements(folder / "data.csv", ur5, "pose")
    np.testing.assert_allclose(q, case.q, atol=1e-12)
    np.testing.assert_allclose(m, case.measured, atol=1e-12)
    q, m = read_measurements(folder / "hold.csv", ur5)
    np.testing.assert_allclose(m, case.measured_hold[:, :3, 3], atol=1e-15)


def test_calibrate_writes_robot_report_plot_and_urdf(csv_case, capsys):
    case, folder = csv_case
    out = folder / "cal.yaml"
    rc = main(["calibrate", "ur5", str(folder / "data.csv"), "-o", str(out), "--kind",
               "pose", "--holdout", str(folder / "hold.csv"), "--urdf",
               str(folder / "cal.urdf"), "--format", "text"])
    text = capsys.readouterr().out
    assert rc == 0
    assert "j2.beta" in text and "hold-out: 200 poses" in text
    assert "tool.roll" in text.split("not identified")[0]  # poses: identified
    robot = robokin.load(out)
    e = calibration.evaluate(robot, case.q_hold, case.measured_hold[:, :3, 3])
    floor = np.linalg.norm(case.measured_hold[:, :3, 3] - case.clean_hold[:, :3, 3],
                           axis=1)
    assert np.sqrt((e**2).mean()) < 1.1 * np.sqrt((floor**2).mean())
    doc = json.loads((folder / "cal_report.json").read_text())
    assert doc["errors"]["poses"] == 200 and doc["kind"] == "pose"
    assert (folder / "cal_errors.png").read_bytes()[:4] == b"\x89PNG"
    assert "<robot" in (folder / "cal.urdf").read_text()


def test_existing_files_are_not_overwritten_without_force(csv_case, capsys):
    _, folder = csv_case
    out = folder / "keep.yaml"
    out.write_text("mine\n")
    rc = main(["calibrate", "ur5", str(folder / "data.csv"), "-o", str(out)])
    assert rc == 2
    assert "exists; pass --force" in capsys.readouterr().err
    assert out.read_text() == "mine\n"
    assert not (folder / "keep_report.json").exists()  # all or nothing
    rc = main(["calibrate", "ur5", str(folder / "data.csv"), "-o", str(out), "--force",
               "--holdout", "0.2", "--json"])
    assert rc == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["errors"]["poses"] == 40 and "tool.roll" in {
        u["name"] for u in doc["unidentifiable"]}


@pytest.mark.parametrize(("args", "match"), [
    (["--kind", "twist"], "'--kind'"),
    (["--holdout", "1.5"], "'--holdout'"),
    (["--extras", "backlash"], "'--extras'"),
])
def test_bad_options_exit_2(csv_case, capsys, args, match):
    _, folder = csv_case
    rc = main(["calibrate", "ur5", str(folder / "data.csv"), "-o",
               str(folder / "x.yaml"), *args])
    assert rc == 2 and match in capsys.readouterr().err


def test_missing_columns_are_named(tmp_path, ur5):
    path = tmp_path / "bad.csv"
    path.write_text("shoulder_pan,x,y,z\n0,1,2,3\n")
    with pytest.raises(ModelError, match=r"no column for joint 'shoulder_lift'"):
        read_measurements(path, ur5)
    path.write_text(",".join(ur5.joint_names) + ",x [in],y,z\n" + "0," * 8 + "0\n")
    with pytest.raises(ModelError, match=r"unknown unit \[in\]"):
        read_measurements(path, ur5)
    path.write_text(",".join(ur5.joint_names) + ",x,y,z\n" + "0," * 8 + "0\n")
    with pytest.raises(ModelError, match="needs a rotation"):
        read_measurements(path, ur5, "pose")
