"""Kinematic calibration: identify a robot's errors from measured tool positions or poses.

``calibrate(robot, q, measured, kind="position" | "pose")`` returns the calibrated
robot, the identified parameters with standard deviations, and what could not
be identified and why; ``evaluate`` gives per-pose errors, ``holdout_report`` the
before/after statistics and plot, ``select_poses`` a well-conditioned subset of
candidate poses. See ``docs/calibration.md``.
"""

from __future__ import annotations

from robokin.calibration.calibrate import CalibrationResult, Parameter, calibrate

__all__ = ["CalibrationResult", "Parameter", "calibrate"]
