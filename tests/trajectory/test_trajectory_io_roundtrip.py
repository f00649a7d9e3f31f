"""Files: CSV round trip (units, names, controller profiles), JSON, URScript, logs."""

import numpy as np
import pytest

from robokin import InputError, ModelError, trajectory
from robokin.trajectory import io


@pytest.fixture
def traj(rng):
    q0, q1 = rng.normal(size=(2, 3))
    return trajectory.quintic(q0, q1, 1.0, 0.01).replace(
        joint_names=("shoulder", "elbow", "slide"), is_revolute=[True, True, False])


def test_csv_round_trip_exact(traj, tmp_path):
    p = io.write_csv(traj, tmp_path / "plan.csv")
    header = p.read_text().splitlines()[0]
    assert header == "t [s],shoulder [rad],elbow [rad],slide [m]"
    back = io.read_csv(p)
    np.testing.assert_array_equal(back.t, traj.t)
    np.testing.assert_array_equal(back.q, traj.q)
    assert back.joint_names == traj.joint_names
    np.testing.assert_array_equal(back.is_revolute, [True, True, False])
    # no rates in the file: differentiated (second order)
    np.testing.assert_allclose(back.qd[1:-1], traj.qd[1:-1], atol=5e-3)


def test_csv_with_rates_and_controller_profile(traj, tmp_path):
    prof = io.ControllerProfile(order=(2, 0, 1), signs=(1, -1, 1),
                                offsets=(0.01, np.pi / 2, 0.0), angle_unit="deg",
                                length_unit="mm")
    p = io.write_csv(traj, tmp_path / "ctl.csv", rates=True, profile=prof)
    lines = p.read_text().splitlines()
    assert lines[0].split(",")[:4] == ["t [s]", "slide [mm]", "shoulder [deg]",
                                       "elbow [deg]"]
    row = [float(x) for x in lines[1].split(",")]
    # controller column 2 is -shoulder + 90 deg, in degrees
    assert row[2] == pytest.approx(np.degrees(-traj.q[0, 0] + np.pi / 2), abs=1e-9)
    assert row[1] == pytest.approx(1000 * (traj.q[0, 2] + 0.01), abs=1e-9)
    back = io.read_csv(p, profile=prof)
    np.testing.assert_allclose(back.q, traj.q, atol=1e-12)
    np.testing.assert_allclose(back.qd, traj.qd, atol=1e-12)
    np.testing.assert_allclose(back.qdd, traj.qdd, atol=1e-10)
    assert back.joint_names == traj.joint_names


def test_profile_from_yaml(tmp_path):
    f = tmp_path / "ctl.yaml"
    f.write_text("controller:\n  name: aubo\n  joints: [a, b]\n  order: [b, a]\n"
                 "  signs: [1, -1]\n  offsets: [0, 90]\n  angle_unit: deg\n")
    prof = io.load_profile(f)
    assert prof.order == (1, 0) and prof.offsets[1] == pytest.approx(np.pi / 2)
    f.write_text("controller: {bogus: 1}\n")
    with pytest.raises(ModelError, match="bogus"):
        io.load_profile(f)


def test_never_overwrites_silently(traj, tmp_path):
    p = tmp_path / "plan.csv"
    p.write_text("mine\n")
    with pytest.raises(InputError, match="exists"):
        io.write_csv(traj, p)
    assert p.read_text() == "mine\n"
    io.write_csv(traj, p, overwrite=True)
    assert p.read_text().startswith("t [s]")
    assert not list(tmp_path.glob(".*tmp"))  # no temporary file left behind


def test_read_errors_name_file_and_line(tmp_path):
    p = tmp_path / "bad.csv"
    p.write_text("t [s],a [rad]\n0,1\n0.1,x\n")
    with pytest.raises(ModelError, match=r"bad\.csv:3: "):
        io.read_csv(p)
    p.write_text("t [s],a [furlong]\n0,1\n")
    with pytest.raises(ModelError, match="unknown unit"):
        io.read_csv(p)
    p.write_text("t [s],a [rad]\n0,1\n0,2\n")
    with pytest.raises(ModelError, match="time does not increase"):
        io.read_csv(p)
    with pytest.raises(ModelError, match="no such file"):
        io.read_csv(tmp_path / "missing.csv")


def test_read_log_units_and_repeated_stamps(tmp_path):
    p = tmp_path / "log.csv"
    p.write_text("time [ms],j1 [deg],j2 [deg]\n0,0,10\n8,1,11\n8,1,11\n16,2,12\n")
    log = io.read_log(p)
    np.testing.assert_allclose(log.t, [0, 0.008, 0.016])
    np.testing.assert_allclose(log.q[:, 1], np.radians([10, 11, 12]))
    np.testing.assert_allclose(log.qd[:, 0], np.radians(1) / 0.008)


def test_json_round_trip(traj, tmp_path):
    p = io.write_json(traj, tmp_path / "t.json", robot_name="aubo_i5")
    back = io.read_json(p)
    np.testing.assert_array_equal(back.q, traj.q)
    np.testing.assert_array_equal(back.qdd, traj.qdd)
    assert back.joint_names == traj.joint_names


def test_ur_script(traj, tmp_path):
    s = io.ur_script(traj, mode="servoj")
    lines = s.splitlines()
    assert lines[0] == "def robokin_motion():" and lines[-1] == "end"
    assert sum(ln.strip().startswith("servoj(") for ln in lines) == len(traj) - 1
    assert "t=0.01," in s
    first = lines[2]
    vals = [float(v) for v in first[first.index("[") + 1:first.index("]")].split(",")]
    np.testing.assert_allclose(vals, traj.q[0], atol=1e-9)
    mj = io.ur_script(traj, mode="movej")
    assert mj.count("movej(") == 2
    io.write_ur_script(traj, tmp_path / "m.script")
    with pytest.raises(InputError, match="mode"):
        io.ur_script(traj, mode="jog")
