"""Cubic and quintic rest-to-rest profiles.

``s = 3 tau^2 - 2 tau^3`` and ``s = 10 tau^3 - 15 tau^4 + 6 tau^5``.
"""

from __future__ import annotations

import numpy as np

from robokin.trajectory.profiles.base import Profile

__all__ = ["CubicProfile", "QuinticProfile"]


class CubicProfile(Profile):
    """Cubic: zero end velocities, acceleration steps at the ends (C_v = 1.5, C_a = 6)."""

    name = "cubic"
    peak_velocity = 1.5
    peak_acceleration = 6.0

    def _evaluate(self, tau):
        return 3 * tau**2 - 2 * tau**3, 6 * tau - 6 * tau**2, 6.0 - 12.0 * tau


class QuinticProfile(Profile):
    """Quintic: zero end velocities and accelerations (C_v = 1.875, C_a = 10/sqrt(3))."""

    name = "quintic"
    peak_velocity = 1.875
    peak_acceleration = 10.0 / np.sqrt(3.0)

    def _evaluate(self, tau):
        t2 = tau * tau
        t3 = t2 * tau
        return (t3 * (10.0 - 15.0 * tau + 6.0 * t2),
                t2 * (30.0 - 60.0 * tau + 30.0 * t2),
                tau * (60.0 - 180.0 * tau + 120.0 * t2))
