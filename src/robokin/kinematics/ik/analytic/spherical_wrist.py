"""6R arms with a spherical wrist (Puma 560, KUKA, ABB, Fanuc, Staubli).

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

import numpy as np

from robokin.kinematics.ik.analytic._geometry import (
    Poe,
    angle_between_axes,
    closest_point,
)

__all__ = ["measure"]

NAME = "spherical_wrist"


def measure(poe: Poe) -> tuple[float, float, str, str]:
    """Deviation from the family: (angle [rad], distance [m], text, why-not)."""
    h, o = poe.h, poe.o
    ang = angle_between_axes(h[1], h[2])
    c = closest_point(o[3:6], h[3:6])
    dist = 0.0
    for k in (3, 4, 5):
        d = c - o[k]
        dist = max(dist, float(np.linalg.norm(d - np.dot(d, h[k]) * h[k])))
    text = f"axes 2, 3 parallel within {ang:.1e} rad; axes 4-6 meet within {dist:.1e} m"
    degenerate = []
    if angle_between_axes(h[0], h[1]) < 0.1:
        degenerate.append("axis 1 is parallel to axis 2")
    if angle_between_axes(h[3], h[4]) < 0.1 or angle_between_axes(h[4], h[5]) < 0.1:
        degenerate.append("wrist axes are parallel")
    return ang, dist, text, "; ".join(degenerate)

