"""Trapezoidal velocity: a linear segment with parabolic blends (LSPB)."""

from __future__ import annotations

import numpy as np

from robokin.exceptions import InputError
from robokin.trajectory.profiles.base import Profile, positive_limits

__all__ = ["TrapezoidalProfile", "lspb_timing"]


class TrapezoidalProfile(Profile):
    """Constant acceleration for a fraction ``blend`` of the time, cruise, then brake.

    ``blend = 0.5`` is the triangular (bang-bang) profile. ``C_v = 1 / (1 - f)``,
    ``C_a = 1 / (f (1 - f))`` with ``f = blend``.

    Args:
        blend: Acceleration time over total time, in (0, 0.5].
    """

    name = "trapezoidal"

    def __init__(self, blend: float = 0.25) -> None:
        f = float(blend)
        if not 0.0 < f <= 0.5:
            raise InputError("blend", f"must be in (0, 0.5], got {blend!r}")
        self.blend = f
        self.peak_velocity = 1.0 / (1.0 - f)
        self.peak_acceleration = 1.0 / (f * (1.0 - f))

    def __repr__(self) -> str:
        return f"TrapezoidalProfile(blend={self.blend!r})"

    def _evaluate(self, tau):
        f = self.blend
        v = self.peak_velocity
        a = self.peak_acceleration
        acc = tau < f
        dec = tau > 1.0 - f
        u = 1.0 - tau
        s = np.where(acc, 0.5 * a * tau**2,
                     np.where(dec, 1.0 - 0.5 * a * u**2, v * (tau - 0.5 * f)))
        sd = np.where(acc, a * tau, np.where(dec, a * u, v))
        sdd = np.where(acc, a, np.where(dec, -a, 0.0))
        return s, sd, sdd


def lspb_timing(distance, v_max, a_max) -> tuple[float, float]:
    """The shortest synchronised LSPB: ``(duration [s], blend fraction)``.

    Every coordinate uses the same normalised profile (they start and stop
    together); the blend fraction ``f`` and duration ``T`` minimise ``T`` subject
    to ``|qd| <= v_max`` and ``|qdd| <= a_max`` for every coordinate:
    ``T(f) = max_j max(D_j / (v_j (1 - f)), sqrt(D_j / (a_j f (1 - f))))``.

    Args:
        distance: Travel per coordinate (n,) [rad or m].
        v_max: Speed limits, scalar or (n,) > 0.
        a_max: Acceleration limits, scalar or (n,) > 0.
    """
    d = np.abs(np.asarray(distance, dtype=np.float64)).reshape(-1)
    v = positive_limits(v_max, d.shape[0], "v_max")
    a = positive_limits(a_max, d.shape[0], "a_max")
    if not d.any():
        return 0.0, 0.5
    # Per coordinate: T >= D/(v(1-f)) and T >= sqrt(D/(a f(1-f))). The first grows
    # with f, the second falls until f = 1/2: the optimum is where the binding pair
    # crosses, or f = 1/2. A dense grid plus a local refinement finds it exactly
    # enough (the result is then snapped to satisfy both bounds).
    f = np.linspace(1e-4, 0.5, 2001)

    def T_of(f):
        f = np.asarray(f)[..., None]
        return np.maximum(d / (v * (1 - f)), np.sqrt(d / (a * f * (1 - f)))).max(-1)

    k = int(np.argmin(T_of(f)))
    lo, hi = f[max(k - 1, 0)], f[min(k + 1, f.size - 1)]
    for _ in range(60):  # golden-section on the bracket
        m1, m2 = lo + 0.382 * (hi - lo), lo + 0.618 * (hi - lo)
        if T_of(m1) <= T_of(m2):
            hi = m2
        else:
            lo = m1
    fb = float(min(0.5, 0.5 * (lo + hi)))
    return float(T_of(fb)) * (1 + 1e-12), fb
