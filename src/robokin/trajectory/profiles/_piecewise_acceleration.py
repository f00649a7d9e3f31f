"""Piecewise-continuous acceleration: a trapezoidal acceleration curve.

Acceleration ramps linearly up over a fraction ``ramp`` of the motion, holds,
ramps down to zero at mid-motion, and mirrors for braking. Acceleration is
continuous (jerk is bounded), unlike LSPB's steps. ``ramp = 1/8`` is the
classic modified-trapezoid cam law; ``ramp = 1/4`` is the triangular
acceleration (constant jerk pieces).
"""

from __future__ import annotations

import numpy as np

from robokin.exceptions import InputError
from robokin.trajectory.profiles.base import Profile, symmetric

__all__ = ["PiecewiseAccelerationProfile"]


def _unit(tau, r):
    """Half profile on [0, 1/2] with unit peak acceleration."""
    L = 0.5 - 2.0 * r
    v1, s1 = r / 2.0, r * r / 6.0
    v2, s2 = v1 + L, s1 + v1 * L + L * L / 2.0
    p1 = tau < r
    p3 = tau > 0.5 - r
    u = tau - r
    w = tau - (0.5 - r)
    rr = max(r, 1e-300)
    a = np.where(p1, tau / rr, np.where(p3, 1.0 - w / rr, 1.0))
    v = np.where(p1, tau**2 / (2 * rr), np.where(p3, v2 + w - w**2 / (2 * rr), v1 + u))
    s = np.where(p1, tau**3 / (6 * rr),
                 np.where(p3, s2 + v2 * w + w**2 / 2 - w**3 / (6 * rr),
                          s1 + v1 * u + u**2 / 2))
    return s, v, a


class PiecewiseAccelerationProfile(Profile):
    """Trapezoidal-acceleration rest-to-rest profile.

    Args:
        ramp: Duration of each acceleration ramp as a fraction of the motion,
            in (0, 1/4].
    """

    name = "piecewise_acceleration"

    def __init__(self, ramp: float = 0.125) -> None:
        r = float(ramp)
        if not 0.0 < r <= 0.25:
            raise InputError("ramp", f"must be in (0, 0.25], got {ramp!r}")
        self.ramp = r
        s_half, v_half, _ = _unit(np.array(0.5), r)
        self._A = 0.5 / float(s_half)
        self.peak_velocity = self._A * float(v_half)
        self.peak_acceleration = self._A

    def __repr__(self) -> str:
        return f"PiecewiseAccelerationProfile(ramp={self.ramp!r})"

    def _evaluate(self, tau):
        A = self._A

        def half(u):
            s, v, a = _unit(u, self.ramp)
            return A * s, A * v, A * a

        return symmetric(half, tau)
