"""Compiled broad-phase kernels (numba, cached on disk).

Every shape is bounded by a *rounded box*: an oriented box (centre, axes, half
sizes) grown by a radius. A capsule is a segment (half sizes ``(0, 0, L/2)``)
grown by its radius, a sphere a point grown by its radius, a box or a cylinder's
bounding box a box with radius 0. For two rounded boxes and any unit axis ``n``
the gap between their projections on ``n`` is a lower bound on their distance
(the separating axis theorem); the kernel takes the largest gap over the 15
candidate axes (3 + 3 face normals, 9 edge cross products).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange


@njit(cache=True, inline="always")
def _sat(Ra, ca, ha, ra, Rb, cb, hb, rb):
    """Largest separating-axis gap between two rounded boxes (a lower bound)."""
    d0 = cb[0] - ca[0]
    d1 = cb[1] - ca[1]
    d2 = cb[2] - ca[2]
    # centre offset and B's axes in A's frame
    T = np.empty(3)
    R = np.empty((3, 3))
    A = np.empty((3, 3))
    for i in range(3):
        T[i] = Ra[0, i] * d0 + Ra[1, i] * d1 + Ra[2, i] * d2
        for j in range(3):
            v = Ra[0, i] * Rb[0, j] + Ra[1, i] * Rb[1, j] + Ra[2, i] * Rb[2, j]
            R[i, j] = v
            A[i, j] = abs(v)
    rr = ra + rb
    best = -np.inf
    for i in range(3):  # A's face normals
        g = abs(T[i]) - ha[i] - (hb[0] * A[i, 0] + hb[1] * A[i, 1] + hb[2] * A[i, 2]) - rr
        if g > best:
            best = g
    for j in range(3):  # B's face normals
        g = (abs(T[0] * R[0, j] + T[1] * R[1, j] + T[2] * R[2, j])
             - (ha[0] * A[0, j] + ha[1] * A[1, j] + ha[2] * A[2, j]) - hb[j] - rr)
        if g > best:
            best = g
    for i in range(3):  # edge-edge axes e_i x R[:, j]
        i1 = (i + 1) % 3
        i2 = (i + 2) % 3
        for j in range(3):
            n2 = 1.0 - R[i, j] * R[i, j]
            if n2 < 1e-12:
                continue
            j1 = (j + 1) % 3
            j2 = (j + 2) % 3
            proj = abs(T[i2] * R[i1, j] - T[i1] * R[i2, j])
            sa = ha[i1] * A[i2, j] + ha[i2] * A[i1, j]
            sb = hb[j1] * A[i, j2] + hb[j2] * A[i, j1]
            g = (proj - sa - sb) / np.sqrt(n2) - rr
            if g > best:
                best = g
    # the centre direction (tight for round shapes)
    dn = np.sqrt(T[0] * T[0] + T[1] * T[1] + T[2] * T[2])
    if dn > 1e-12:
        u0 = T[0] / dn
        u1 = T[1] / dn
        u2 = T[2] / dn
        sa = ha[0] * abs(u0) + ha[1] * abs(u1) + ha[2] * abs(u2)
        sb = 0.0
        for j in range(3):
            sb += hb[j] * abs(u0 * R[0, j] + u1 * R[1, j] + u2 * R[2, j])
        g = dn - sa - sb - rr
        if g > best:
            best = g
    return best


@njit(cache=True, parallel=True)
def rounded_box_bounds(
    frames, link, local, h, r, ob_pose, ob_h, ob_r, pa, pb, is_self, skip, out
):
    """Lower bounds on every pair's distance at every sample.

    Args:
        frames: Link frames (m, L, 4, 4).
        link: Frame index of each robot shape (S,).
        local: Pose of each robot shape's bounding box in its link frame (S, 4, 4).
        h: Half sizes of those boxes (S, 3); r: their radii (S,).
        ob_pose, ob_h, ob_r: The same for the objects, poses in the world (O, 4, 4).
        pa, pb: Pair members (P,): robot shape, and robot shape or object.
        is_self: (P,) True when pb is a robot shape.
        skip: (P,) True for pairs to leave untouched.
        out: (P, m) output.
    """
    m = frames.shape[0]
    S = link.shape[0]
    P = pa.shape[0]
    for i in prange(m):
        Rw = np.empty((S, 3, 3))
        cw = np.empty((S, 3))
        for s in range(S):
            F = frames[i, link[s]]
            for a in range(3):
                for b in range(3):
                    acc = 0.0
                    for k in range(3):
                        acc += F[a, k] * local[s, k, b]
                    Rw[s, a, b] = acc
                acc = F[a, 3]
                for k in range(3):
                    acc += F[a, k] * local[s, k, 3]
                cw[s, a] = acc
        for p in range(P):
            if skip[p]:
                continue
            a = pa[p]
            b = pb[p]
            if is_self[p]:
                out[p, i] = _sat(Rw[a], cw[a], h[a], r[a], Rw[b], cw[b], h[b], r[b])
            else:
                out[p, i] = _sat(Rw[a], cw[a], h[a], r[a], ob_pose[b, :3, :3],
                                 ob_pose[b, :3, 3], ob_h[b], ob_r[b])
    return out
