r"""The time-scaling profile: a rest-to-rest curve ``s(tau)`` from 0 to 1 on ``tau`` in [0, 1].

A profile shapes *when* a motion covers its path, not *where* it goes. A joint
segment is ``q(t) = q0 + (q1 - q0) s(t / T)``; a Cartesian segment moves its tool
along a line by the same ``s``. In physical time, for a duration ``T``:

.. math::

    \dot s(t) = s'(\tau) / T, \qquad \ddot s(t) = s''(\tau) / T^2,
    \qquad \tau = t / T.

So a joint that travels ``D`` peaks at ``|qd| = C_v D / T`` and ``|qdd| = C_a D /
T^2``, with the profile's coefficients ``C_v = max |s'|`` and ``C_a = max |s''|``;
:meth:`Profile.min_duration` inverts that for velocity and acceleration limits.

References:
    L. Biagiotti, C. Melchiorri, *Trajectory Planning for Automatic Machines and
    Robots*, Springer 2008, chapter 3 (the coefficients C_v, C_a of each profile).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import ClassVar

import numpy as np
import numpy.typing as npt

from robokin._text import short_repr
from robokin.exceptions import InputError

__all__ = ["Profile", "positive_limits"]


def positive_limits(x: npt.ArrayLike, n: int, name: str) -> np.ndarray:
    """A speed / acceleration limit, scalar or (n,), as (n,) positive floats.

    ``inf`` is allowed: no limit.

    Raises:
        InputError: not numbers, wrong length, NaN, zero or negative.
    """
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(name, f"expected a number or {n} numbers, got {short_repr(x)}") from None
    if a.ndim > 1 or (a.ndim == 1 and a.shape[0] != n):
        raise InputError(name, f"expected a scalar or shape ({n},), got {a.shape}")
    a = np.broadcast_to(a, (n,))
    if not (a > 0).all():  # also catches NaN
        raise InputError(name, f"limits must be positive, got {a.tolist()}")
    return a


class Profile(ABC):
    """Abstract rest-to-rest time scaling ``s(tau)``, ``s(0) = 0``, ``s(1) = 1``.

    Subclasses implement :meth:`_evaluate` on ``tau`` in [0, 1] and set the peak
    coefficients. Instances are small immutable values.
    """

    name: ClassVar[str] = "profile"
    #: max |s'(tau)|
    peak_velocity: float = 1.0
    #: max |s''(tau)| (inf when the profile has velocity steps)
    peak_acceleration: float = 0.0

    @abstractmethod
    def _evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``s, s', s''`` at ``tau`` in [0, 1] (already clipped)."""

    def evaluate(self, tau: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Normalised position, velocity and acceleration, each shaped like ``tau``.

        ``tau`` outside [0, 1] holds the end values (zero rates).
        """
        tau = np.asarray(tau, dtype=np.float64)
        inside = (tau >= 0.0) & (tau <= 1.0)
        s, sd, sdd = self._evaluate(np.clip(tau, 0.0, 1.0))
        return (np.where(tau > 1.0, 1.0, np.where(tau < 0.0, 0.0, s)),
                np.where(inside, sd, 0.0), np.where(inside, sdd, 0.0))

    def scale(self, t: npt.ArrayLike, duration: float
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``s(t), ds/dt [1/s], d2s/dt2 [1/s^2]`` for a motion of ``duration`` [s]."""
        if not duration > 0:
            raise InputError("duration", f"must be positive, got {short_repr(duration)}")
        s, sd, sdd = self.evaluate(np.asarray(t, dtype=np.float64) / duration)
        return s, sd / duration, sdd / duration**2

    def min_duration(self, distance: npt.ArrayLike, v_max: npt.ArrayLike | None = None,
                     a_max: npt.ArrayLike | None = None) -> float:
        """Shortest duration [s] keeping every coordinate within its limits.

        Args:
            distance: Travel per coordinate (n,) [rad or m] (sign ignored).
            v_max: Largest speed, scalar or (n,).
            a_max: Largest acceleration, scalar or (n,).
        """
        d = np.abs(np.asarray(distance, dtype=np.float64)).reshape(-1)
        T = 0.0
        if v_max is not None:
            v = positive_limits(v_max, d.shape[0], "v_max")
            T = max(T, float(np.max(self.peak_velocity * d / v, initial=0.0)))
        if a_max is not None:
            a_max = positive_limits(a_max, d.shape[0], "a_max")
        if a_max is not None and self.peak_acceleration > 0:
            if np.isinf(self.peak_acceleration) and d.any():
                raise InputError("a_max", f"the {self.name} profile has velocity steps "
                                 "(infinite acceleration) at its ends")
            T = max(T, float(np.sqrt(np.max(self.peak_acceleration * d / a_max,
                                            initial=0.0))))
        return T

    def __repr__(self) -> str:
        """The class name and parameters."""
        return f"{type(self).__name__}()"

    def __eq__(self, other: object) -> bool:
        """Profiles of one class with the same parameters are equal."""
        return type(self) is type(other) and repr(self) == repr(other)

    def __hash__(self) -> int:
        """Hash of the representation (profiles are equal by it)."""
        return hash(repr(self))


def symmetric(half, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Evaluate a profile given on [0, 1/2] and odd-symmetric about (1/2, 1/2)."""
    second = tau > 0.5
    u = np.where(second, 1.0 - tau, tau)
    s, sd, sdd = half(u)
    return (np.where(second, 1.0 - s, s), sd, np.where(second, -sdd, sdd))
