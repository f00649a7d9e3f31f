"""Inverse kinematics: closed forms per family, a numeric fallback, solution sets."""

from __future__ import annotations

# ``solve`` is the dispatcher itself: no wrapper frame (single poses take a few us).
from robokin.kinematics.ik.dispatch import solve

__all__ = ["family", "solve"]


def family(robot):
    """The closed-form family of the robot's chain (see ``analytic.detect``)."""
    from robokin.kinematics.ik.analytic.detect import detect

    return detect(robot)
