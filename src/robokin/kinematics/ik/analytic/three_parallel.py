"""6R arms with three parallel axes (UR3/5/10/16, AUBO-i5/i10, Doosan...).

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
"""

from __future__ import annotations

from robokin.kinematics.ik.analytic._geometry import (
    Poe,
    angle_between_axes,
    line_distance,
)

__all__ = ["measure"]

NAME = "three_parallel"


def measure(poe: Poe) -> tuple[float, float, str, str]:
    """Deviation from the family: (angle [rad], distance [m], text, why-not)."""
    h, o = poe.h, poe.o
    ang = max(angle_between_axes(h[1], h[2]), angle_between_axes(h[1], h[3]))
    dist = line_distance(o[4], h[4], o[5], h[5])
    text = f"axes 2-4 parallel within {ang:.1e} rad; axes 5, 6 meet within {dist:.1e} m"
    degenerate = []
    if angle_between_axes(h[0], h[1]) < 0.1:
        degenerate.append("axis 1 is parallel to axis 2")
    if angle_between_axes(h[4], h[5]) < 0.1:
        degenerate.append("axes 5 and 6 are parallel")
    if angle_between_axes(h[1], h[4]) < 0.1:
        degenerate.append("axis 5 is parallel to axis 2")
    return ang, dist, text, "; ".join(degenerate)

