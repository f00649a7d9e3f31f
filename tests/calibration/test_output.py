"""The calibrated robot out into the ecosystem: robot file and URDF with the same FK.

Oracles: the calibrated robot's own FK against the files read back.
"""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

import robokin
from robokin import calibration

from .conftest import make_case


@pytest.fixture(scope="module", params=["ur5", "irb"])
def result(request, ur5, irb):
    robot = ur5 if request.param == "ur5" else irb
    case = make_case(robot, "pose", n=100, hold=0, seed=16)
    return case, calibration.calibrate(robot, case.q, case.measured, kind="pose")


def test_robot_file_has_the_same_fk(result, tmp_path):
    case, res = result
    path = robokin.save(res.robot, tmp_path / "calibrated.yaml")
    back = robokin.load(path)
    np.testing.assert_allclose(back.fk(case.q), res.robot.fk(case.q), atol=1e-12)
    assert back.joint_names == res.robot.joint_names


def test_urdf_has_the_same_fk_within_1e9(result, tmp_path):
    pytest.importorskip("yourdfpy")
    case, res = result
    text = res.robot.to_urdf()
    xyz = np.array([[float(v) for v in m.split()] for m in
                    re.findall(r'<origin xyz="([^"]*)"', text)])
    # link origins: the arm's own lengths (and the tracker placement of the base)
    assert np.abs(xyz).max() < 2.5
    path = tmp_path / "calibrated.urdf"
    path.write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        back = robokin.Robot.from_urdf(path)
    np.testing.assert_allclose(back.fk(case.q), res.robot.fk(case.q), atol=1e-9)
