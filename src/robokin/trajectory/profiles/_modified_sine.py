"""Modified sine (combined sine) cam law.

Acceleration is a quarter sine wave of period 1/2 up to its peak over the first
eighth of the motion, a sine of period 3/2 from the peak through zero to the
negative peak over the middle three quarters, and a quarter sine back to zero
over the last eighth: ``C_v = 1.76``, ``C_a = 5.53``, continuous acceleration,
a lower peak acceleration than cycloidal for a small rise in peak velocity.
"""

from __future__ import annotations

import numpy as np

from robokin.trajectory.profiles.base import Profile, symmetric

__all__ = ["ModifiedSineProfile"]

_W1 = 4.0 * np.pi  # first piece: a = sin(W1 tau), tau in [0, 1/8]
_W2 = 4.0 * np.pi / 3.0  # second: a = cos(W2 (tau - 1/8)), tau in [1/8, 7/8]


def _unit(tau):
    """Half profile on [0, 1/2] with unit peak acceleration."""
    v1 = 1.0 / _W1
    s1 = 1.0 / (8.0 * _W1) - 1.0 / _W1**2
    p1 = tau < 0.125
    u = tau - 0.125
    a = np.where(p1, np.sin(_W1 * tau), np.cos(_W2 * u))
    v = np.where(p1, (1.0 - np.cos(_W1 * tau)) / _W1, v1 + np.sin(_W2 * u) / _W2)
    s = np.where(p1, tau / _W1 - np.sin(_W1 * tau) / _W1**2,
                 s1 + v1 * u + (1.0 - np.cos(_W2 * u)) / _W2**2)
    return s, v, a


_S_HALF, _V_HALF, _ = (float(x) for x in _unit(np.array(0.5)))
_A = 0.5 / _S_HALF


class ModifiedSineProfile(Profile):
    """Modified-sine rest-to-rest profile (C_v ~ 1.760, C_a ~ 5.528)."""

    name = "modified_sine"
    peak_velocity = _A * _V_HALF
    peak_acceleration = _A

    def _evaluate(self, tau):
        def half(u):
            s, v, a = _unit(u)
            return _A * s, _A * v, _A * a

        return symmetric(half, tau)
