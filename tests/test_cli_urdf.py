"""``robokin import`` / ``export`` / ``dh``: output, files written only where named."""

import json
from pathlib import Path

import numpy as np
import pytest

import robokin
from robokin.cli import main

pytest.importorskip("yourdfpy")

DATA = Path(__file__).parent / "data" / "urdf"


def run(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_import_writes_a_robot_file_with_the_same_fk(capsys, tmp_path, rng):
    out = tmp_path / "ur5.yaml"
    code, text, _ = run(capsys, "import", str(DATA / "ur5.urdf"), "-o", str(out))
    assert code == 0 and "base_link -> tool0" in text
    loaded = robokin.load(out)
    urdf = robokin.Robot.from_urdf(DATA / "ur5.urdf", geometry=False)
    q = rng.uniform(-3, 3, (20, 6))
    np.testing.assert_allclose(loaded.fk(q), urdf.fk(q), atol=1e-12)


def test_import_without_o_prints_and_writes_nothing(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, text, _ = run(capsys, "import", str(DATA / "branched.urdf"),
                        "--tip", "right_tool", "--base", "torso")
    assert code == 0 and "right_elbow" in text and "left_elbow" not in text
    assert list(tmp_path.iterdir()) == []


def test_export_then_import_round_trips(capsys, tmp_path, rng):
    out = tmp_path / "panda.urdf"
    code, _, _ = run(capsys, "export", "panda", "-o", str(out))
    assert code == 0
    back = robokin.Robot.from_urdf(out)
    panda = robokin.load("panda")
    q = rng.uniform(-1, 1, (20, 7))
    np.testing.assert_allclose(back.fk(q), panda.fk(q), atol=1e-12)
    code, text, _ = run(capsys, "export", "scara")
    assert code == 0 and text.startswith("<?xml") and 'type="prismatic"' in text


def test_dh_prints_urs_table(capsys):
    code, text, _ = run(capsys, "dh", str(DATA / "ur5.urdf"), "--mm", "--json")
    assert code == 0
    doc = json.loads(text)
    np.testing.assert_allclose([r["a"] for r in doc["rows"]], [0, -425, -392.25, 0, 0, 0],
                               atol=1e-9)
    np.testing.assert_allclose([r["d"] for r in doc["rows"]],
                               [89.159, 0, 0, 109.15, 94.65, 82.3], atol=1e-9)
    np.testing.assert_allclose(doc["base"]["rpy"][2] % 360, 180, atol=1e-9)
    code, text, _ = run(capsys, "dh", str(DATA / "ur5.urdf"))
    assert code == 0 and "needs virtual frames" in text and "-0.425" in text
    code, text, _ = run(capsys, "dh", str(DATA / "ur5.urdf"), "--virtual-frames",
                        "--modified")
    assert code == 0 and "base_frame" in text


def test_errors_are_one_line(capsys, tmp_path):
    code, _, err = run(capsys, "import", str(DATA / "malformed.urdf"), "-o",
                       str(tmp_path / "x.yaml"))
    assert code == 2 and "not valid XML" in err and "Traceback" not in err
    assert not (tmp_path / "x.yaml").exists()
    code, _, err = run(capsys, "dh", str(DATA / "branched.urdf"))
    assert code == 2 and "ambiguous tip link" in err
    code, _, err = run(capsys, "import", str(DATA / "ur5.urdf"), "--package", "bad")
    assert code == 2


def test_o_never_writes_over_the_file_being_read(capsys, tmp_path):
    urdf = tmp_path / "arm.urdf"
    urdf.write_text((DATA / "ur5.urdf").read_text())
    before = urdf.read_bytes()
    code, _, err = run(capsys, "import", str(urdf), "-o", str(urdf))
    assert code == 2 and "--out" in err and "input file" in err
    assert urdf.read_bytes() == before
    robot_file = tmp_path / "arm.yaml"
    assert run(capsys, "import", str(urdf), "-o", str(robot_file))[0] == 0
    before = robot_file.read_bytes()
    code, _, err = run(capsys, "export", str(robot_file), "-o", str(robot_file))
    assert code == 2 and "input file" in err
    assert robot_file.read_bytes() == before


def test_export_into_a_missing_folder_names_it_and_files_get_normal_permissions(
    capsys, tmp_path
):
    missing = tmp_path / "nope" / "ur5.urdf"
    code, _, err = run(capsys, "export", "ur5", "-o", str(missing))
    assert code == 2 and str(tmp_path / "nope") in err and ".tmp" not in err
    import os

    umask = os.umask(0)
    os.umask(umask)
    out = tmp_path / "ur5.urdf"
    assert run(capsys, "export", "ur5", "-o", str(out))[0] == 0
    assert out.stat().st_mode & 0o777 == 0o666 & ~umask  # not mkstemp's 0600
    out.chmod(0o640)
    assert run(capsys, "export", "ur5", "-o", str(out))[0] == 0
    assert out.stat().st_mode & 0o777 == 0o640  # a replaced file keeps its mode


def test_import_reports_every_shape_it_leaves_out(tmp_path, capsys):
    (tmp_path / "notes.txt").write_text("not a mesh")
    meshes = "".join(
        f'<collision><geometry><mesh filename="{f}"/></geometry></collision>'
        for f in ("gone.stl", "https://example.com/arm.stl", "notes.txt"))
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(
        '<robot name="r"><link name="a"/><link name="b">' + meshes + '</link>'
        '<joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
        '<limit lower="0" upper="1"/></joint></robot>')
    out = tmp_path / "arm.yaml"
    code, _, err = run(capsys, "import", str(urdf), "-o", str(out))
    assert code == 0
    notes = [ln for ln in err.splitlines() if ln.startswith("robokin: note: left out")]
    assert len(notes) == 3
    assert "gone.stl" in notes[0] and "remote" in notes[1] and "notes.txt" in notes[2]
    text = out.read_text()
    assert "notes.txt" not in text and ".stl" not in text and "geometry" not in text


def test_import_notes_a_missing_package_once(capsys, tmp_path, monkeypatch):
    """Issue 25: irb140.urdf's 14 meshes of one missing package made 14 notes of ~400
    characters. Oracle: the URDF itself, whose 14 meshes all name that package."""
    import warnings

    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("AMENT_PREFIX_PATH", raising=False)
    urdf = DATA / "irb140.urdf"
    n_meshes = urdf.read_text().count('filename="package://abb_irb140_support/')
    assert n_meshes == 14
    code, _, err = run(capsys, "import", str(urdf), "-o", str(tmp_path / "irb.yaml"))
    assert code == 0
    notes = [ln for ln in err.splitlines() if ln.startswith("robokin: note:")]
    assert len(notes) == 1, err
    assert notes[0].startswith("robokin: note: left out 14 visual and collision meshes "
                               "of links base_link, link_1, link_2, link_3, link_4, "
                               "link_5, link_6: package 'abb_irb140_support' not found")
    assert "--package abb_irb140_support=DIR" in notes[0]
    # the API: every shape still listed, one warning for the one reason

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robot = robokin.Robot.from_urdf(urdf)
    assert len(robot.meta["urdf_dropped_shapes"]) == 14
    assert [str(w.message)[:20] for w in caught] == ["left out 14 visual a"]
    assert caught[0].filename == __file__  # points at the caller
