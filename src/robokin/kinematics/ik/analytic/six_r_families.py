"""The two 6R families with a closed form, and how near an arm is to each.

Each family is a pair of conditions on the axes of the canonical chain (a set of
parallel axes, a set of axes that meet) plus axis pairs that must not be parallel;
:func:`measure` grades an arm against one :class:`SixRShape`.

``three_parallel``: 6R arms with three parallel axes (UR3/5/10/16, AUBO-i5/i10, Doosan...).

Axes 2, 3, 4 are parallel and axes 5, 6 meet. Up to 8 solutions from Paden–Kahan
subproblems on the chain's product-of-exponentials geometry:

1. ``h2 . R1^T p' = h2 . (o_w - o1)`` (the component along the parallel axes is not
   changed by joints 2-4): subproblem 4 for theta1 (shoulder, 2 roots);
2. ``h2 . R5 h6 = h2 . R1^T R06 h6``: subproblem 4 for theta5 (wrist, 2 roots);
3. theta6 by subproblem 1 (free at the wrist singularity, theta5 = 0: axes 2, 3, 4,
   6 parallel; then theta6 is kept at ``q_near`` or 0 and the row is flagged
   ``singular``), theta2 + theta3 + theta4 by subproblem 1;
4. the planar two-link problem: subproblem 3 for theta3 (elbow, 2 roots),
   subproblem 1 for theta2; theta4 from the sum.

Nothing is hard-coded: joint signs (the AUBO-i5's reversed joint 3), zero offsets,
base and tool all come from the canonical chain.

References:
    Elias and Wen, "IK-Geo", arXiv:2211.05737 (2022), the 'three parallel, two
    intersecting' case; Paden (1985) subproblems 1, 3, 4.

``spherical_wrist``: 6R arms with a spherical wrist (Puma 560, KUKA, ABB, Fanuc, Staubli).

Axes 4, 5, 6 meet in the wrist centre ``o_w`` and axes 2, 3 are parallel; shoulder
and elbow offsets are allowed. Up to 8 solutions:

1. the wrist centre ``p_w = p - R06 (t - o_w)`` fixes joints 1-3: subproblem 4 for
   theta1 (``h2 . R1^T (p_w - o1) = h2 . (o_w - o1)``, shoulder, 2 roots),
   subproblem 3 for theta3 (elbow, 2 roots), subproblem 1 for theta2;
2. the wrist ``R4 R5 R6 = (R1 R2 R3)^T R06``: subproblem 4 for theta5 (wrist flip,
   2 roots), subproblem 1 for theta6 and theta4. At theta5 = 0 (axes 4 and 6 line
   up) theta6 is kept at ``q_near`` or 0 and the row is flagged ``singular``.

The geometry comes from the canonical chain, so standard and modified DH models of
the same arm (``puma560`` / ``puma560_modified``) are solved identically.

References:
    Elias and Wen, "IK-Geo", arXiv:2211.05737 (2022), 'spherical wrist, two
    parallel'; Paden (1985) subproblems 1, 3, 4.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from robokin.kinematics.ik.analytic._geometry import (
    Poe,
    angle_between_axes,
    closest_point,
    line_distance,
)

if TYPE_CHECKING:
    from robokin.kinematics.ik.analytic._six_r import Kind

__all__ = ["SHAPES", "SPHERICAL_WRIST", "THREE_PARALLEL", "SixRShape", "measure"]

#: Axes closer to parallel than this [rad] make a family degenerate.
_PARALLEL = 0.1


@dataclass(frozen=True)
class SixRShape:
    """The axis conditions of a 6R family (0-based axis indices).

    Attributes:
        name: The family's name (``Family.name``).
        parallel: Axes parallel to the first of them.
        meet: Axes meeting in one point (two: their common normal is zero).
        text: The measured text, formatted with ``ang`` [rad] and ``dist`` [m].
        degenerate: ``(axis pairs, reason)``: the family fails when any pair is
            within :data:`_PARALLEL` of parallel.
    """

    name: Kind
    parallel: tuple[int, ...]
    meet: tuple[int, ...]
    text: str
    degenerate: tuple[tuple[tuple[tuple[int, int], ...], str], ...]


THREE_PARALLEL = SixRShape(
    "three_parallel", (1, 2, 3), (4, 5),
    "axes 2-4 parallel within {ang:.1e} rad; axes 5, 6 meet within {dist:.1e} m",
    ((((0, 1),), "axis 1 is parallel to axis 2"),
     (((4, 5),), "axes 5 and 6 are parallel"),
     (((1, 4),), "axis 5 is parallel to axis 2")))
SPHERICAL_WRIST = SixRShape(
    "spherical_wrist", (1, 2), (3, 4, 5),
    "axes 2, 3 parallel within {ang:.1e} rad; axes 4-6 meet within {dist:.1e} m",
    ((((0, 1),), "axis 1 is parallel to axis 2"),
     (((3, 4), (4, 5)), "wrist axes are parallel")))
#: The families in the order detection tries them.
SHAPES = (THREE_PARALLEL, SPHERICAL_WRIST)


def _meet_distance(poe: Poe, axes: tuple[int, ...]) -> float:
    """How far [m] the axes miss a common point."""
    h, o = poe.h, poe.o
    if len(axes) == 2:
        a, b = axes
        return line_distance(o[a], h[a], o[b], h[b])
    c = closest_point(o[list(axes)], h[list(axes)])
    dist = 0.0
    for k in axes:
        d = c - o[k]
        dist = max(dist, float(np.linalg.norm(d - np.dot(d, h[k]) * h[k])))
    return dist


def measure(poe: Poe, shape: SixRShape) -> tuple[float, float, str, str]:
    """Deviation from the family: (angle [rad], distance [m], text, why-not)."""
    h = poe.h
    first = shape.parallel[0]
    ang = max(angle_between_axes(h[first], h[k]) for k in shape.parallel[1:])
    dist = _meet_distance(poe, shape.meet)
    degenerate = [why for pairs, why in shape.degenerate
                  if any(angle_between_axes(h[a], h[b]) < _PARALLEL for a, b in pairs)]
    return ang, dist, shape.text.format(ang=ang, dist=dist), "; ".join(degenerate)
