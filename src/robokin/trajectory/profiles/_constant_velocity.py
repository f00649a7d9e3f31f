"""Constant velocity: ``s = tau`` (velocity steps at the ends)."""

from __future__ import annotations

import numpy as np

from robokin.trajectory.profiles.base import Profile

__all__ = ["ConstantVelocityProfile"]


class ConstantVelocityProfile(Profile):
    """Linear in time: every joint moves at constant speed (C_v = 1).

    The velocity jumps at the ends (its acceleration there is not finite, and the
    sampled ``qdd`` is zero); use it for motions that start and end moving, such
    as the palletizer's four axes sweeping at constant speed.
    """

    name = "constant_velocity"
    peak_velocity = 1.0
    peak_acceleration = float("inf")

    def _evaluate(self, tau):
        return tau.copy(), np.ones_like(tau), np.zeros_like(tau)
