"""Cycloidal: ``s = tau - sin(2 pi tau) / (2 pi)``, smooth acceleration from zero to zero."""

from __future__ import annotations

import numpy as np

from robokin.trajectory.profiles.base import Profile

__all__ = ["CycloidalProfile"]

_TWO_PI = 2.0 * np.pi


class CycloidalProfile(Profile):
    """Cycloidal rest-to-rest motion (C_v = 2, C_a = 2 pi); acceleration is continuous."""

    name = "cycloidal"
    peak_velocity = 2.0
    peak_acceleration = _TWO_PI

    def _evaluate(self, tau):
        w = _TWO_PI * tau
        return tau - np.sin(w) / _TWO_PI, 1.0 - np.cos(w), _TWO_PI * np.sin(w)
