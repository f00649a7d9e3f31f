"""Universal Robots' factory calibration: exact FK, physical link frames, URDF out.

Oracles: a hand-written standard DH product of the nominal table plus the deltas
(tests/reference.dh_standard), the URDF read back, and the nominal link frames.
The sample (tests/data/calibration/ur5_calibration.conf) carries d deltas of
hundreds of metres like real UR ones (ros-industrial/universal_robot#357).
"""

from __future__ import annotations

import math
import re
import warnings

import numpy as np
import pytest

import robokin
from robokin import calibration
from robokin.calibration.ur import ur_nominal
from robokin.exceptions import InputError, ModelError

from ..reference import dh_standard
from .conftest import DATA

SAMPLE = DATA / "calibration" / "ur5_calibration.conf"
UR5 = [(0.0, 0.089159, 0.0, math.pi / 2), (0.0, 0.0, -0.425, 0.0),
       (0.0, 0.0, -0.39225, 0.0), (0.0, 0.10915, 0.0, math.pi / 2),
       (0.0, 0.09465, 0.0, -math.pi / 2), (0.0, 0.0823, 0.0, 0.0)]


def _deltas() -> dict[str, list[float]]:
    text = SAMPLE.read_text()
    return {k: [float(v) for v in re.search(rf"delta_{k} = \[(.*)\]", text).group(1)
                .split(",")] for k in ("theta", "d", "a", "alpha")}


def _reference_rows():
    d = _deltas()
    return [(t + d["theta"][i], dd + d["d"][i], a + d["a"][i], al + d["alpha"][i], "r")
            for i, (t, dd, a, al) in enumerate(UR5)]


def _origins(urdf: str) -> np.ndarray:
    return np.array([[float(v) for v in m.split()] for m in
                     re.findall(r'<origin xyz="([^"]*)"', urdf)])


def test_fk_equals_the_hand_written_dh_product():
    robot = calibration.load_ur_calibration(SAMPLE, "ur5")
    assert max(abs(v) for v in _deltas()["d"]) > 100  # the sample is UR-like
    rows = _reference_rows()
    q = np.random.default_rng(0).uniform(-math.pi, math.pi, (50, 6))
    q[0] = 0.0
    ref = np.array([dh_standard(rows, qq) for qq in q])
    np.testing.assert_allclose(robot.fk(q), ref, atol=1e-9)


def test_link_frames_stay_near_the_nominal_ones():
    robot = calibration.load_ur_calibration(SAMPLE, "ur5")
    q = np.random.default_rng(1).uniform(-math.pi, math.pi, (30, 6))
    # the calibration moves the arm by ~1 mm, never metres
    dist = np.linalg.norm(robot.fk_all(q)[..., :3, 3]
                          - ur_nominal("ur5").fk_all(q)[..., :3, 3], axis=-1)
    assert dist.max() < 5e-3


def test_urdf_has_the_same_fk_and_no_metre_offsets(tmp_path):
    pytest.importorskip("yourdfpy")
    robot = calibration.load_ur_calibration(SAMPLE, "ur5")
    text = robot.to_urdf()
    assert np.abs(_origins(text)).max() < 0.5
    path = tmp_path / "ur5_calibrated.urdf"
    path.write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        back = robokin.Robot.from_urdf(path)
    q = np.random.default_rng(2).uniform(-math.pi, math.pi, (50, 6))
    np.testing.assert_allclose(back.fk(q), robot.fk(q), atol=1e-9)
    # the naive conversion (the DH rows as joint origins) is what #357 hit
    naive = robokin.Robot.from_dh([dict(theta=t, d=d, a=a, alpha=al)
                                   for t, d, a, al, _ in _reference_rows()])
    np.testing.assert_allclose(naive.fk(q), robot.fk(q), atol=1e-9)
    assert np.abs(_origins(naive.to_urdf())).max() > 10.0


def test_robot_file_round_trip(tmp_path):
    robot = calibration.load_ur_calibration(SAMPLE, "ur5")
    path = robokin.save(robot, tmp_path / "ur5_calibrated.yaml")
    back = robokin.load(path)
    q = np.random.default_rng(3).uniform(-math.pi, math.pi, (20, 6))
    np.testing.assert_allclose(back.fk(q), robot.fk(q), atol=1e-12)


def test_calibrated_table_format_and_a_nominal_robot(tmp_path):
    rows = _reference_rows()
    text = "\n".join(f"dh_{k}: [{', '.join(repr(r[i]) for r in rows)}]"
                     for i, k in enumerate(("theta", "d", "a", "alpha")))
    path = tmp_path / "kinematics.yaml"
    path.write_text(text + "\n")
    robot = calibration.load_ur_calibration(path, robokin.load("ur5"))
    q = np.random.default_rng(4).uniform(-math.pi, math.pi, (20, 6))
    ref = np.array([dh_standard(rows, qq) for qq in q])
    np.testing.assert_allclose(robot.fk(q), ref, atol=1e-9)
    assert robot.joint_names == robokin.load("ur5").joint_names


@pytest.mark.parametrize(("text", "match"), [
    ("[mounting]\ndelta_theta = [0, 0, 0, 0, 0, 0]\n", r"found \['delta_theta'\]"),
    ("delta_theta = [0,0,0]\ndelta_a = [0,0,0]\n", r"'delta_theta' must hold 6"),
    ("delta_a = [0, x, 0, 0, 0, 0]\n", r"'delta_a' must hold numbers"),
    ("hello\n", "none of them"),
])
def test_malformed_files_name_the_field(tmp_path, text, match):
    path = tmp_path / "calibration.conf"
    path.write_text(text)
    with pytest.raises(ModelError, match=match):
        calibration.load_ur_calibration(path)


def test_wrong_type_is_refused():
    with pytest.raises(InputError, match=r"another type"):
        calibration.load_ur_calibration(SAMPLE, "ur10")
    with pytest.raises(InputError, match=r"unknown UR type 'ur6'"):
        calibration.load_ur_calibration(SAMPLE, "ur6")
    with pytest.raises(InputError, match="6 revolute"):
        calibration.load_ur_calibration(SAMPLE, robokin.load("panda"))
