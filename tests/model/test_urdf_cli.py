"""``robokin import`` / ``export`` / ``dh``: output, files written only where named."""

import json
from pathlib import Path

import numpy as np
import pytest

import robokin
from robokin.cli import main

pytest.importorskip("yourdfpy")

DATA = Path(__file__).parent.parent / "data" / "urdf"


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
