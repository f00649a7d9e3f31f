"""The geometric path of a trajectory, cut where the arm must stop (for retiming).

A sampled trajectory fixes a curve in joint space; retiming keeps the curve and
changes only how fast it is run. This module turns the samples into that curve:

* **Pieces.** The samples are cut where the arm is at rest (every joint speed at
  most :data:`REST_TOL` of the largest, e.g. the end of a rest-to-rest segment),
  where the path turns back or has a corner (consecutive steps more than
  :data:`CORNER_DEG` apart, where no finite acceleration can follow it without
  stopping), and around runs of identical samples (dwells). A piece between two
  such points is run from rest to rest; a dwell keeps its duration.
* **Curve.** Each moving piece becomes :class:`SplinePath`, a C2 cubic spline
  ``q(s)`` through the samples in the chord-length parameter ``s`` [rad or m of
  joint-space travel]. Samples closer than a quarter of the piece's median step
  are thinned out first (near a rest the steps shrink to 1e-7 rad, and knots that
  close make the spline's third derivative swing by 1e6). Between samples the curve
  is the spline's; on a line sampled every 5 ms it stays within 1e-9 m of the line.
* **Infinite velocity.** A step between two samples that the recorded velocities
  do not explain (its mean speed more than :data:`JUMP_FACTOR` times the larger
  recorded speed at its ends) is a jump: running it would need an infinite joint
  velocity, so it is refused, naming the samples.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from robokin.exceptions import InputError

__all__ = ["CORNER_DEG", "JUMP_FACTOR", "REST_TOL", "Piece", "SplinePath",
           "split_path"]

#: A sample is at rest when its largest joint speed is at most this fraction of
#: the trajectory's largest.
REST_TOL = 1e-9
#: A turn of the path by more than this between consecutive steps [deg] is a
#: corner (or a reversal): the arm stops there.
CORNER_DEG = 60.0
#: A step whose mean speed exceeds this many times the larger recorded speed at its
#: ends is a jump (the path would need an infinite velocity).
JUMP_FACTOR = 3.0
#: Knots closer than this fraction of a piece's median step are thinned out.
THIN = 0.25


class SplinePath:
    """One stretch of the path, ``q(s)`` for ``s`` in ``[0, length]``.

    A C2 cubic spline (``scipy.interpolate.CubicSpline``, not-a-knot ends) in the
    chord-length parameter. Callable as toppra's geometric paths are:
    ``path(s, order)``.

    Args:
        s: Knot parameters [rad or m of joint travel], shape (k,), increasing from 0.
        q: Joint positions at the knots, shape (k, n).
    """

    def __init__(self, s: np.ndarray, q: np.ndarray) -> None:
        from scipy.interpolate import CubicSpline

        self.knots = np.asarray(s, dtype=np.float64)
        self.length = float(self.knots[-1])
        self.n = int(q.shape[1])
        self._spline = CubicSpline(self.knots, q, axis=0)

    @property
    def dof(self) -> int:
        """Number of joints (toppra's name)."""
        return self.n

    @property
    def path_interval(self) -> np.ndarray:
        """``[0, length]`` (toppra's name)."""
        return np.array([0.0, self.length])

    def __call__(self, s: npt.ArrayLike, order: int = 0) -> np.ndarray:
        """The ``order``-th derivative ``d^k q / ds^k`` at ``s``, shape (..., n).

        ``s`` is clipped to ``[0, length]`` (rounding at the ends).
        """
        ss = np.clip(np.asarray(s, dtype=np.float64), 0.0, self.length)
        out: np.ndarray = self._spline(ss, order)
        return out

    def extremes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Largest ``|q'|``, ``|q''|``, ``|q'''|`` per joint over the whole path.

        ``q'''`` is constant between knots and ``q''`` linear, so knots and
        interval midpoints hold their extremes; ``q'`` is checked at knots and
        three interior points per interval.

        Returns:
            Three arrays of shape (n,).
        """
        k = self.knots
        inner = (k[:-1, None] + np.diff(k)[:, None] * np.array([0.25, 0.5, 0.75])
                 ).reshape(-1)
        s = np.sort(np.concatenate([k, inner]))
        return (np.abs(self(s, 1)).max(axis=0), np.abs(self(s, 2)).max(axis=0),
                np.abs(self(s, 3)).max(axis=0))


@dataclass(frozen=True, eq=False)
class Piece:
    """A stretch of the source samples run as one unit.

    Attributes:
        kind: ``"move"`` (run from rest to rest along ``path``) or ``"dwell"``.
        first: Index of its first source sample.
        last: Index of its last source sample.
        duration: Its duration in the source [s] (0 without times).
        path: The curve of a move, else None.
        s: Path parameter of every source sample first..last (a move), shape
            (last - first + 1,); None for a dwell.
    """

    kind: Literal["move", "dwell"]
    first: int
    last: int
    duration: float
    path: SplinePath | None = None
    s: np.ndarray | None = None


def _check_jumps(t: np.ndarray, q: np.ndarray, qd: np.ndarray) -> None:
    """Refuse a step that needs an infinite velocity (see the module docstring)."""
    h = np.diff(t)
    step = np.linalg.norm(np.diff(q, axis=0), axis=1)
    speed = np.linalg.norm(qd, axis=1)
    ends = np.maximum(speed[:-1], speed[1:])
    scale = max(1.0, float(np.abs(q).max()))
    bad = step > JUMP_FACTOR * ends * h + 1e-9 * scale
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        j = int(np.argmax(np.abs(q[k + 1] - q[k])))
        raise InputError(
            "traj",
            f"the path jumps between samples {k} and {k + 1} (t = {t[k]:.6g} s to "
            f"{t[k + 1]:.6g} s): joint {j + 1} moves {q[k + 1, j] - q[k, j]:.6g} in "
            f"{h[k]:.3g} s while the recorded speeds there are at most "
            f"{ends[k]:.3g}; following it would need an infinite joint velocity "
            "(pass the positions alone, traj.q, to retime them as a smooth path)")


def _breaks(q: np.ndarray, qd: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """Sample indices where the arm must stop, and which steps stand still."""
    m = q.shape[0]
    step = np.diff(q, axis=0)
    size = np.linalg.norm(step, axis=1)
    scale = max(1.0, float(np.abs(q).max()))
    still = size <= 1e-12 * scale
    stop = np.zeros(m, bool)
    stop[[0, -1]] = True
    if qd is not None:
        speed = np.abs(qd).max(axis=1)
        stop |= speed <= REST_TOL * max(float(speed.max()), 1e-300)
    # corners: the direction turns by more than CORNER_DEG between moving steps
    moving = np.flatnonzero(~still)
    if moving.size > 1:
        u = step[moving] / size[moving, None]
        cos = np.einsum("ij,ij->i", u[:-1], u[1:])
        corner = cos < np.cos(np.radians(CORNER_DEG))
        stop[moving[1:][corner]] = True
    # the ends of every still run stop
    edges = np.flatnonzero(np.diff(np.concatenate([[0], still.astype(np.int8), [0]])))
    stop[edges] = True
    return np.flatnonzero(stop), still


def _thinned(s: np.ndarray) -> np.ndarray:
    """Knot mask: drop samples closer than THIN x the median step to the last kept."""
    steps = np.diff(s)
    h = THIN * float(np.median(steps[steps > 0]))
    if s.size <= 2:
        return np.ones(s.size, bool)
    keep = np.zeros(s.size, bool)
    keep[0] = True
    last = 0.0
    for k in range(1, s.size - 1):
        if s[k] - last >= h:
            keep[k] = True
            last = s[k]
    kept = np.flatnonzero(keep)
    if kept.size > 1 and s[-1] - last < h:
        keep[kept[-1]] = False  # too close to the end
    keep[-1] = True
    return keep


def split_path(q: npt.ArrayLike, t: npt.ArrayLike | None = None,
               qd: npt.ArrayLike | None = None) -> list[Piece]:
    """Cut samples into moves (each a :class:`SplinePath`) and dwells.

    Args:
        q: Joint positions [rad or m], shape (m, n), m >= 2.
        t: Sample times [s], shape (m,), or None for a bare joint path.
        qd: Joint velocities [rad/s or m/s], shape (m, n), or None.

    Returns:
        The pieces in order; consecutive pieces share their boundary sample.

    Raises:
        InputError: non-finite values, fewer than two samples, a path that does
            not move, or a jump (``traj``).
    """
    Q = np.asarray(q, dtype=np.float64)
    if Q.ndim != 2 or Q.shape[0] < 2:
        raise InputError("traj", f"expected at least 2 samples (m, n), got shape "
                         f"{Q.shape}")
    T = None if t is None else np.asarray(t, dtype=np.float64)
    QD = None if qd is None else np.asarray(qd, dtype=np.float64)
    for name, arr in (("q", Q), ("t", T), ("qd", QD)):
        if arr is not None and not np.isfinite(arr).all():
            raise InputError("traj", f"{name} holds a NaN or infinite value")
    if T is not None and QD is not None:
        _check_jumps(T, Q, QD)
    stops, still = _breaks(Q, QD)
    if still.all():
        raise InputError("traj", "the path does not move: every sample is the same")
    pieces: list[Piece] = []
    for a, b in zip(stops[:-1], stops[1:]):
        a, b = int(a), int(b)
        dur = 0.0 if T is None else float(T[b] - T[a])
        if still[a:b].all():
            if pieces and pieces[-1].kind == "dwell":  # merge consecutive dwells
                prev = pieces.pop()
                a, dur = prev.first, prev.duration + dur
            pieces.append(Piece("dwell", a, b, dur))
            continue
        seg = Q[a:b + 1]
        s_all = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(seg, axis=0),
                                                                axis=1))])
        knots = _thinned(s_all)  # repeated samples (zero steps) go too
        path = SplinePath(s_all[knots], seg[knots])
        pieces.append(Piece("move", a, b, dur, path, s_all))
    return pieces


def source_of(traj: Any) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]:
    """``(q, t, qd)`` of a Trajectory, or ``(q, None, None)`` of a bare (m, n) path."""
    if hasattr(traj, "q") and hasattr(traj, "t"):
        return (np.asarray(traj.q, float), np.asarray(traj.t, float),
                np.asarray(traj.qd, float))
    return np.asarray(traj, dtype=np.float64), None, None
