"""Branches a hair outside a limit: the pose's in-limit solutions next to them.

Where the elbow of a 7R arm is stretched (or folded) to within ~1e-8 rad, the pose
fixes the elbow angle only to ~sqrt(eps): q4 = 1e-9 and q4 = 0 reach the same pose to
1e-18 m, and the closed form, whose cosine of q4 rounds to 1, returns the exactly
stretched branch. A joint the self-motion does not move there (the SRS arm's
shoulder pitch, the direction of the stretched arm) then lies ~5e-10 rad away from
the generating configuration's value: at a limit, every branch is outside it by
that along its whole length, while the generating configuration, inside, reaches the
pose to 1e-16 (session 25's fuzz: three SRS poses with q2 at its limit and
q4 = +-1e-9, ``reachable`` False).

:func:`hair_bands` finds the stretches of the branches at most :data:`HAIR` outside
the limits (on a grid of :data:`SAMPLES` parameter values); ``SelfMotion`` searches
them as it searches its intervals, with the limits widened by :data:`HAIR`, and
takes the best row back inside the limits onto the pose
(``self_motion_nearest._at_limits``: along the self-motion to the limit, else with
the joints at their limits held and the others polished). Only where the searches
of the intervals found no in-limit row and the aligned continua no in-limit point:
``reachable`` (where there is no interval), ``best``, ``nearest``. A branch tangent to
a limit is the other case: q2 at its limit with the elbow 2.7e-4 from stretched, q2 =
limit - 6.5e-5 psi^2, is inside at one point, which the swivel kernel gives as an
interval of +-0.17 whose other rows are up to 2e-6 outside.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["HAIR", "SAMPLES", "bands_of", "hair_bands", "hair_grid"]

#: [rad, m] A branch row at most this far outside its limits (its largest excess) may
#: have in-limit solutions of the pose next to it: the stretched elbow's rounding
#: reaches ~1e-8; farther rows are not repaired.
HAIR = 1e-6
#: Parameter values of the grid the bands are found on (6 degrees apart on the swivel).
SAMPLES = 61


def hair_grid(rows_at: Callable[[np.ndarray], np.ndarray], domain: np.ndarray,
              limits: np.ndarray, samples: int = SAMPLES
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The branches' rows on a grid of the parameter and which are within the hair.

    Args:
        rows_at: Parameter values (m,) -> every branch's rows (m, k, n), NaN where
            a branch has none (``SelfMotion._rows``).
        domain: (2,) the parameter's range [rad, m].
        limits: Joint limits (n, 2).
        samples: Grid values over the domain (ends included).

    Returns:
        ``(t (m,), rows (m, k, n), near (m, k))``: ``near`` where a branch's row exists
        and is at most :data:`HAIR` outside every limit (its largest excess).
    """
    t = np.linspace(float(domain[0]), float(domain[1]), samples)
    rows = rows_at(t)
    with np.errstate(invalid="ignore"):
        over = np.maximum(limits[:, 0] - rows, rows - limits[:, 1]).max(-1)  # (m, k)
    return t, rows, np.isfinite(over) & (over <= HAIR)


def bands_of(t: np.ndarray, near: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The runs of ``near`` (m, k) on the grid t (m,) as parameter ranges.

    Returns:
        ``(intervals (p, 2), branch (p,))``: per run of consecutive grid rows of one
        branch within :data:`HAIR` of the limits, widened by one grid step each side
        (clipped to the domain). Empty where there is none.
    """
    starts, ends, branch = [], [], []
    step = t[1] - t[0]
    for b in np.flatnonzero(near.any(0)):
        edge = np.diff(np.concatenate([[0], near[:, b].astype(np.int8), [0]]))
        for a, e in zip(np.flatnonzero(edge == 1), np.flatnonzero(edge == -1), strict=True):
            starts.append(max(t[a] - step, t[0]))
            ends.append(min(t[e - 1] + step, t[-1]))
            branch.append(b)
    return (np.column_stack([starts, ends]).reshape(-1, 2),
            np.array(branch, dtype=np.int64))


def hair_bands(rows_at: Callable[[np.ndarray], np.ndarray], domain: np.ndarray,
               limits: np.ndarray, samples: int = SAMPLES
               ) -> tuple[np.ndarray, np.ndarray]:
    """The parameter ranges where a branch is at most :data:`HAIR` outside the limits.

    :func:`bands_of` the :func:`hair_grid` (its arguments): ``(intervals (p, 2),
    branch (p,))``, empty where there is none.
    """
    t, _, near = hair_grid(rows_at, domain, limits, samples)
    return bands_of(t, near)
