"""Whole turns of the joints the search keeps on the circle, and their certificate.

A revolute joint whose limits span a turn or more (a UR5's +-360 deg) reaches every
angle, most of them twice. The search keeps such a joint on the circle [-pi, pi)
and measures its steps the short way round: a *relaxation* of the real problem
(every real motion is a path of the relaxed graph with the same cost, so the
relaxed optimum is a lower bound). After the search each segment of the path is
unwrapped (the short steps added up) and shifted by whole turns into the limits.
The relaxed optimum is the real one when, for every such joint, one shift

* keeps the whole segment inside the limits (to 1e-9),
* costs every waypoint no more than the best of its turns does (the relaxed node
  cost takes the best turn: ``process_nodes``' limit term), and
* (first segment, with ``q_start``) makes the approach from ``q_start`` the short
  way round, as the relaxed start cost assumed.

Where no shift of a joint passes, that joint is *expanded*: every node is split
into its whole-turn equivalents inside the limits (explicit values, steps without
wrapping) and the search runs again. Each round expands at least one more joint,
so after at most n rounds the optimum is certified or every joint is explicit;
either way it is the exact optimum of the sampled graph.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from robokin import _native
from robokin.spatial import wrap_angle

__all__ = ["limit_costs", "shift_choices", "turn_offsets", "unwrap"]

_TOL = 1e-9  # [rad] as the kernels' PR_LIMIT_TOL
_COST_TOL = 1e-12  # costs equal to this


def unwrap(x: np.ndarray) -> np.ndarray:
    """Circle values x (S,) [rad] as a continuous motion of short steps from x[0]."""
    u = np.empty_like(x)
    u[0] = x[0]
    np.cumsum(wrap_angle(np.diff(x)), out=u[1:])
    u[1:] += x[0]
    return u


def limit_costs(values: np.ndarray, lo: float, hi: float, margin: float) -> np.ndarray:
    """The kernels' limit ramp of each value (the one formula, ``process.c``)."""
    v = np.ascontiguousarray(values, dtype=np.float64).reshape(-1)
    out = np.empty_like(v)
    _native.kernels.process_limit_cost(v, float(lo), float(hi), float(margin), out)
    return out.reshape(np.shape(values))


def _turn_range(lo: float, hi: float) -> range:
    """Whole turns k for which some angle in [-pi, pi] plus 2 pi k is in [lo, hi]."""
    ka = math.ceil((lo - _TOL - math.pi) / (2.0 * math.pi))
    kb = math.floor((hi + _TOL + math.pi) / (2.0 * math.pi))
    return range(ka, kb + 1)


def turn_offsets(limits: np.ndarray, joints: tuple[int, ...]) -> np.ndarray:
    """Every combination of whole turns of ``joints``: offsets (E, n) [rad]."""
    n = limits.shape[0]
    ranges = [_turn_range(float(limits[j, 0]), float(limits[j, 1])) for j in joints]
    combos = list(itertools.product(*ranges))
    out = np.zeros((len(combos), n))
    for e, ks in enumerate(combos):
        for j, k in zip(joints, ks, strict=True):
            out[e, j] = 2.0 * math.pi * k
    return out


def shift_choices(
    u: np.ndarray,
    lo: float,
    hi: float,
    margin: float,
    q_start: float | None,
) -> int | None:
    """The whole turns k that certify one joint of one segment, or None.

    Args:
        u: The joint's unwrapped values along the segment (S,) [rad].
        lo: Its lower limit [rad].
        hi: Its upper limit [rad].
        margin: The limit margin of the costs [rad].
        q_start: Its value before the path when the segment is the first and a
            ``q_start`` was given, else None.

    Returns:
        The shift (in turns) nearest the reference (``q_start``, else the middle
        of the limits) among those that pass the three tests of the module
        docstring, or None when none does.
    """
    tp = 2.0 * math.pi
    ref = q_start if q_start is not None else (
        0.5 * (lo + hi) if math.isfinite(lo + hi) else 0.0)
    if math.isfinite(lo) and math.isfinite(hi):
        k0 = math.ceil((lo - _TOL - float(u.min())) / tp)
        k1 = math.floor((hi + _TOL - float(u.max())) / tp)
        ks = list(range(k0, k1 + 1))
    else:  # one side open: any turn keeps inside; try those near the reference
        c = round((ref - float(u[0])) / tp)
        ks = [k for k in range(c - 2, c + 3)
              if (not math.isfinite(lo) or float(u.min()) + tp * k >= lo - _TOL)
              and (not math.isfinite(hi) or float(u.max()) + tp * k <= hi + _TOL)]
    if not ks:
        return None
    best = _best_turn_costs(u, lo, hi, margin) if margin > 0.0 else None
    passing = []
    for k in ks:
        v = u + tp * k
        if best is not None and np.any(limit_costs(v, lo, hi, margin) > best + _COST_TOL):
            continue
        if q_start is not None and (
                abs(float(v[0]) - q_start)
                > abs(float(wrap_angle(float(u[0]) - q_start))) + _COST_TOL):
            continue
        passing.append(k)
    if not passing:
        return None
    return min(passing, key=lambda k: (abs(float(u[0]) + tp * k - ref), k))


def _best_turn_costs(u: np.ndarray, lo: float, hi: float, margin: float) -> np.ndarray:
    """Per value, the least limit cost over its whole-turn equivalents inside."""
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return np.zeros_like(u)
    w = wrap_angle(u)
    ks = np.array(list(_turn_range(lo, hi)), dtype=np.float64)
    v = w[:, None] + 2.0 * math.pi * ks[None, :]
    c = limit_costs(v, lo, hi, margin)
    inside = (v >= lo - _TOL) & (v <= hi + _TOL)
    return np.where(inside, c, np.inf).min(axis=1)
