"""Kinematic calibration: identify a robot's errors from measured tool positions or poses.

``calibrate(robot, q, measured, kind="position" | "pose")`` returns the calibrated
robot, the identified parameters with standard deviations, and what could not
be identified and why; ``evaluate`` gives per-pose errors, ``holdout_report`` the
before/after statistics (``plot_errors`` their plot), ``select_poses`` a
well-conditioned subset of candidate poses, ``load_ur_calibration`` a Universal
Robots factory calibration as a robot. See ``docs/calibration.md``.
"""

from __future__ import annotations

from robokin.calibration import synthetic
from robokin.calibration._calibrate import CalibrationResult, Parameter, calibrate
from robokin.calibration._evaluate import (
    ErrorStats,
    HoldoutReport,
    evaluate,
    holdout_report,
    plot_errors,
)
from robokin.calibration._select import observability_index, select_poses
from robokin.calibration.ur import load_ur_calibration

__all__ = [
    "CalibrationResult",
    "ErrorStats",
    "HoldoutReport",
    "Parameter",
    "calibrate",
    "evaluate",
    "holdout_report",
    "load_ur_calibration",
    "observability_index",
    "plot_errors",
    "select_poses",
    "synthetic",
]
