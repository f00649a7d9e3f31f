"""Inverse kinematics: closed forms per family, a numeric fallback, solution sets."""

from __future__ import annotations

from typing import Any

__all__ = ["family", "solve"]


def solve(robot, T, *, q_near=None, method: str = "auto", **options: Any):
    """Every joint solution for target poses ``T`` (..., 4, 4); see ``Robot.ik``."""
    from robokin.kinematics.ik.dispatch import solve as _solve

    return _solve(robot, T, q_near=q_near, method=method, **options)


def family(robot):
    """The closed-form family of the robot's chain (see ``analytic.detect``)."""
    from robokin.kinematics.ik.analytic.detect import detect

    return detect(robot)
