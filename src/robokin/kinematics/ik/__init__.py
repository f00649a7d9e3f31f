"""Inverse kinematics: closed forms per family, a numeric fallback, solution sets."""

from __future__ import annotations

# ``solve`` is the dispatcher itself: no wrapper frame (single poses take a few us).
from robokin.kinematics.arm import ArmSource
from robokin.kinematics.ik.analytic.detect import Family, detect
from robokin.kinematics.ik.dispatch import solve

__all__ = ["family", "solve"]


def family(robot: ArmSource) -> Family:
    """The closed-form family of the robot's chain (see ``analytic.detect``).

    Args:
        robot: A Robot, its :class:`~robokin.kinematics.arm.Arm`, or a Chain.

    Returns:
        The :class:`~robokin.kinematics.ik.analytic.detect.Family`.
    """
    return detect(robot)
