"""Per-joint rate limits: the largest speed, acceleration and jerk of each joint.

They belong to the arm, like its position limits, and are what time-optimal
retiming (:func:`robokin.trajectory.retime`) keeps to. Values are SI, one per
independent joint coordinate: [rad/s, rad/s^2, rad/s^3] for revolute joints,
[m/s, m/s^2, m/s^3] for prismatic ones. ``NaN`` marks a value nobody published
(a URDF with ``velocity="0"``, a joint whose jerk is unknown); a consumer that
needs it asks the caller for it, naming the joint.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from robokin.exceptions import ModelError

__all__ = ["RATE_KINDS", "RateLimits"]

#: The kinds of rate limit, in order of the derivative they bound.
RATE_KINDS = ("velocity", "acceleration", "jerk")


def _frozen(values: npt.ArrayLike | None, n: int | None, kind: str
            ) -> np.ndarray | None:
    if values is None:
        return None
    arr = np.array(values, dtype=np.float64).reshape(-1)
    if n is not None and arr.shape != (n,):
        raise ModelError(f"expected {n} values (one per joint), got {arr.size}",
                         field=kind)
    bad = ~np.isnan(arr) & ~(np.isfinite(arr) & (arr > 0))
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise ModelError(f"must be finite and positive (or unknown), got "
                         f"{arr[k]!r} for joint {k + 1}", field=f"{kind}[{k}]")
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True, eq=False)
class RateLimits:
    """The rate limits of an arm's independent joint coordinates.

    Attributes:
        velocity: Largest ``|qd|`` [rad/s or m/s], shape (n,), NaN where unknown;
            None when the arm has none at all.
        acceleration: Largest ``|qdd|`` [rad/s^2 or m/s^2], shape (n,), or None.
        jerk: Largest ``|qddd|`` [rad/s^3 or m/s^3], shape (n,), or None.
        source: Where the values come from (datasheet, estimate and why).
    """

    velocity: np.ndarray | None = None
    acceleration: np.ndarray | None = None
    jerk: np.ndarray | None = None
    source: str = ""

    def __post_init__(self) -> None:
        """Check and freeze the arrays (one size for all kinds)."""
        n = None
        for kind in RATE_KINDS:
            arr = _frozen(getattr(self, kind), n, kind)
            if arr is not None:
                n = arr.size
            object.__setattr__(self, kind, arr)
        if n is None:
            raise ModelError("give at least one of velocity, acceleration, jerk")
        object.__setattr__(self, "source", str(self.source))

    @property
    def n(self) -> int:
        """Number of joints."""
        for kind in RATE_KINDS:
            arr = getattr(self, kind)
            if arr is not None:
                return int(arr.size)
        raise AssertionError("unreachable: __post_init__ requires one kind")

    def get(self, kind: str) -> np.ndarray | None:
        """The limits of one kind (``"velocity"``, ``"acceleration"``, ``"jerk"``)."""
        if kind not in RATE_KINDS:
            raise KeyError(f"unknown kind {kind!r}; kinds: {list(RATE_KINDS)}")
        arr: np.ndarray | None = getattr(self, kind)
        return arr

    def __eq__(self, other: Any) -> bool:
        """Same limits (to 1e-12 relative, NaN equal to NaN) and the same source."""
        if not isinstance(other, RateLimits):
            return NotImplemented
        for kind in RATE_KINDS:
            a, b = self.get(kind), other.get(kind)
            if (a is None) != (b is None):
                return False
            if a is not None and b is not None and not (
                    a.shape == b.shape and np.allclose(a, b, rtol=1e-12, atol=0.0,
                                                       equal_nan=True)):
                return False
        return self.source == other.source

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        """``RateLimits(velocity=[...], ...)``, the kinds that are given."""
        parts = []
        for kind in RATE_KINDS:
            arr = self.get(kind)
            if arr is not None:
                parts.append(f"{kind}={np.array2string(arr, precision=4)}")
        return f"RateLimits({', '.join(parts)})"

