"""What a collision check answers: the report and its records.

:class:`CollisionReport` is what :func:`robokin.collision.check` returns; the records
(:class:`Collision`, :class:`Interval`, :class:`PairMinimum`, :class:`Closest`) are
its parts. They hold data only; the check that fills them is in ``check.py`` and
``_problem.py``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt

from robokin._text import short_repr
from robokin.exceptions import InputError

__all__ = ["TIE", "Closest", "Collision", "CollisionReport", "Interval", "PairMinimum"]

TIE = 1e-9  # [m] pair minima are exact to this (bounds within it of the best stop)


class Collision(NamedTuple):
    """A collision interval: samples ``first_index..last_index`` (inclusive)."""

    first_index: int
    last_index: int
    body_a: str
    body_b: str


class Interval(NamedTuple):
    """A collision (or clearance violation) interval with its times.

    ``between_samples`` is True when it was found only by subdivision, between
    samples ``first_index`` and ``last_index``; ``t_start``/``t_end`` then give
    the time of the first colliding intermediate configuration found.
    """

    first_index: int
    last_index: int
    body_a: str
    body_b: str
    t_start: float
    t_end: float
    min_distance: float
    between_samples: bool


class PairMinimum(NamedTuple):
    """The minimum over time of one body pair's distance."""

    body_a: str
    body_b: str
    distance: float
    index: int  # type: ignore[assignment]  # the field (public API) shadows tuple.index
    t: float
    kind: str  # "object" or "self"


@dataclass(frozen=True)
class Closest:
    """Where and when the robot came closest.

    Attributes:
        distance: Minimum distance [m] (<= 0 when colliding).
        index: Sample index (for a point found between samples: the sample before).
        t: Time [s] (or fractional sample index when no times were given).
        body_a: A robot link.
        body_b: A scene object or another robot link.
        point_a: Nearest point on ``body_a`` in the world (3,) [m].
        point_b: Nearest point on ``body_b`` in the world (3,) [m].
        between_samples: True when found by subdivision between samples.
    """

    distance: float
    index: int
    t: float
    body_a: str
    body_b: str
    point_a: np.ndarray
    point_b: np.ndarray
    between_samples: bool = False


@dataclass
class CollisionReport:
    """The result of :func:`check`.

    Attributes:
        min_distance: Minimum distance over the trajectory [m]; inf with nothing
            to check. Includes configurations evaluated between samples.
        collides: True when any pair collides at a sample or between samples.
        collisions: ``[(first_index, last_index, body_a, body_b), ...]``.
        intervals: The same with times and whether found between samples.
        violations: Intervals where the distance is at or below ``clearance``.
        closest: The global minimum, or None with nothing to check.
        pairs: Every body pair's minimum over time, closest first.
        clearance: The threshold used [m].
        t: Times of the samples (m,) [s] (sample indices when none were given).
        queries: Number of exact coal queries made.
        subdivisions: Number of intermediate configurations evaluated.
    """

    min_distance: float
    collides: bool
    collisions: list[Collision]
    intervals: list[Interval]
    violations: list[Interval]
    closest: Closest | None
    pairs: list[PairMinimum]
    clearance: float
    t: np.ndarray
    queries: int = 0
    subdivisions: int = 0
    _problem: Any = field(default=None, repr=False)
    _q: Any = field(default=None, repr=False)

    def _repr_html_(self) -> str:
        """Jupyter: the verdict, the closest pair, collisions, pairs and a plot.

        The plot is the minimum distance over every checked pair at up to 120
        evenly spaced samples; tables are capped: bounded for any trajectory.
        """
        from robokin import _html

        verdict = ("COLLIDES" if self.collides else
                   "clearance VIOLATED" if self.violated else "OK")
        parts = [_html.note(f"minimum distance {self.min_distance * 1e3:.3f} mm, "
                            f"clearance {self.clearance * 1e3:g} mm: {verdict}")]
        c = self.closest
        if c is not None:
            parts.append(_html.note(f"closest: {c.body_a} - {c.body_b} at t = "
                                    f"{c.t:.3f} s (sample {c.index})"))
        m = self.t.shape[0]
        if self._problem is not None and m:
            idx = np.unique(np.linspace(0, m - 1, min(m, 120)).round().astype(int))
            d = self.closest_at(idx)[0]
            parts.append(_html.line_plot(self.t[idx], d * 1e3, xlabel="t [s]",
                                         ylabel="min distance [mm]",
                                         hline=self.clearance * 1e3))
        if self.intervals:
            parts += [_html.note("collisions"), _html.table(
                ["body", "body", "t start [s]", "t end [s]", "depth [mm]"],
                [[iv.body_a, iv.body_b, iv.t_start, iv.t_end, -iv.min_distance * 1e3]
                 for iv in self.intervals], max_rows=10)]
        parts += [_html.note("closest pairs"), _html.table(
            ["body", "body", "min distance [mm]", "t [s]", "sample"],
            [[p.body_a, p.body_b, p.distance * 1e3, p.t, p.index] for p in self.pairs],
            max_rows=8)]
        return _html.box(f"CollisionReport: {m:,} samples", *parts)

    @property
    def violated(self) -> bool:
        """True when the minimum distance is at or below the clearance (or collides)."""
        return self.collides or self.min_distance <= self.clearance

    @property
    def sample_min_distance(self) -> float:
        """Minimum over the given samples only [m] (subdivision points excluded)."""
        return min((p.distance for p in self.pairs), default=math.inf)

    def distances(self, body_a: str, body_b: str) -> np.ndarray:
        """Exact distance of one body pair at every sample, (m,) [m].

        Raises:
            InputError: the pair is not checked.
        """
        return self._problem.profile(self._q, body_a, body_b)

    def closest_at(
        self, indices: npt.ArrayLike
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The closest body pair at the given samples (exact, over all checked pairs).

        Args:
            indices: Sample indices (k,) into the checked trajectory (negative
                indices count from the end).

        Returns:
            ``(distance, point_a, point_b)``: the minimum distance over every
            checked pair at each sample (k,) [m] (<= 0 when colliding; inf with
            nothing to check), and the nearest points (k, 3) [m] in the world on
            the robot link and on the other body (NaN with nothing to check).

        Raises:
            InputError: an index is not an integer or out of range.
        """
        m = self.t.shape[0]
        try:
            raw = np.asarray(indices)
            idx = raw.astype(np.int64).reshape(-1)
        except (TypeError, ValueError):
            raise InputError(
                "indices", f"expected sample indices, got {short_repr(indices)}"
            ) from None
        if raw.size and not np.array_equal(raw.reshape(-1), idx):
            raise InputError("indices", "expected integer sample indices")
        if idx.size and (idx.min() < -m or idx.max() >= m):
            raise InputError(
                "indices", f"expected indices in [-{m}, {m - 1}] ({m} samples)"
            )
        idx = np.where(idx < 0, idx + m, idx)
        if self._problem is None:
            k = idx.size
            return np.full(k, np.inf), np.full((k, 3), np.nan), np.full((k, 3), np.nan)
        return self._problem.closest_at(self._q, idx)
