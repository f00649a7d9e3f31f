"""evaluate, the hold-out report and its plot.

Oracles: per-pose norms computed here from the robot's FK; the written file.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from robokin import calibration
from robokin.exceptions import InputError

from .conftest import make_case


@pytest.fixture(scope="module")
def solved(ur5):
    case = make_case(ur5, "pose", n=120, hold=100, seed=15)
    return case, calibration.calibrate(ur5, case.q, case.measured, kind="pose")


def test_evaluate_is_the_distance_to_the_fk(solved):
    case, res = solved
    T = res.robot.fk(case.q_hold)
    e = calibration.evaluate(res.robot, case.q_hold, case.measured_hold[:, :3, 3])
    np.testing.assert_allclose(e, np.linalg.norm(T[:, :3, 3]
                                                 - case.measured_hold[:, :3, 3], axis=1))
    p, r = calibration.evaluate(res.robot, case.q_hold, case.measured_hold, rotation=True)
    np.testing.assert_allclose(p, e)
    R = T[:, :3, :3] @ np.swapaxes(case.measured_hold[:, :3, :3], 1, 2)
    angle = np.arccos(np.clip((np.trace(R, axis1=1, axis2=2) - 1) / 2, -1, 1))
    np.testing.assert_allclose(r, angle, atol=1e-9)
    with pytest.raises(InputError, match="needs poses"):
        calibration.evaluate(res.robot, case.q_hold, case.measured_hold[:, :3, 3],
                             rotation=True)


def test_holdout_report_and_plot(solved, tmp_path):
    case, res = solved
    rep = calibration.holdout_report(res, case.q_hold, case.measured_hold)
    assert rep.after.rms < rep.before.rms / 10
    assert rep.rotation_after is not None and rep.rotation_before is not None
    assert rep.rotation_after.rms < rep.rotation_before.rms
    d = rep.to_dict()
    assert d["poses"] == 100 and math.isclose(d["position_m"]["after"]["rms"],
                                              rep.after.rms)
    assert "rotation [deg]" in rep.text()
    path = tmp_path / "errors.png"
    calibration.plot_errors(rep, path=path)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(InputError, match="exists"):
        calibration.plot_errors(rep, path=path)
    with pytest.raises(InputError, match=r"path.*\.png, \.svg or \.pdf"):
        calibration.plot_errors(rep, path=tmp_path / "errors.jpg")
    assert not (tmp_path / "errors.jpg").exists()
