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
        g = (
            abs(T[i])
            - ha[i]
            - (hb[0] * A[i, 0] + hb[1] * A[i, 1] + hb[2] * A[i, 2])
            - rr
        )
        if g > best:
            best = g
    for j in range(3):  # B's face normals
        g = (
            abs(T[0] * R[0, j] + T[1] * R[1, j] + T[2] * R[2, j])
            - (ha[0] * A[0, j] + ha[1] * A[1, j] + ha[2] * A[2, j])
            - hb[j]
            - rr
        )
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
                out[p, i] = _sat(
                    Rw[a],
                    cw[a],
                    h[a],
                    r[a],
                    ob_pose[b, :3, :3],
                    ob_pose[b, :3, 3],
                    ob_h[b],
                    ob_r[b],
                )
    return out


@njit(cache=True, inline="always")
def _seg_seg(p1, q1, p2, q2):
    """Distance between segments [p1, q1] and [p2, q2] (Ericson 2005, sec. 5.1.9)."""
    d1 = q1 - p1
    d2 = q2 - p2
    r = p1 - p2
    a = d1[0] * d1[0] + d1[1] * d1[1] + d1[2] * d1[2]
    e = d2[0] * d2[0] + d2[1] * d2[1] + d2[2] * d2[2]
    f = d2[0] * r[0] + d2[1] * r[1] + d2[2] * r[2]
    eps = 1e-18
    if a <= eps and e <= eps:
        s = 0.0
        t = 0.0
    elif a <= eps:
        s = 0.0
        t = min(max(f / e, 0.0), 1.0)
    else:
        c = d1[0] * r[0] + d1[1] * r[1] + d1[2] * r[2]
        if e <= eps:
            t = 0.0
            s = min(max(-c / a, 0.0), 1.0)
        else:
            b = d1[0] * d2[0] + d1[1] * d2[1] + d1[2] * d2[2]
            denom = a * e - b * b
            if denom > eps * a * e:
                s = min(max((b * f - c * e) / denom, 0.0), 1.0)
            else:
                s = 0.0
            t = (b * s + f) / e
            if t < 0.0:
                t = 0.0
                s = min(max(-c / a, 0.0), 1.0)
            elif t > 1.0:
                t = 1.0
                s = min(max((b - c) / a, 0.0), 1.0)
    dx = p1[0] + d1[0] * s - p2[0] - d2[0] * t
    dy = p1[1] + d1[1] * s - p2[1] - d2[1] * t
    dz = p1[2] + d1[2] * s - p2[2] - d2[2] * t
    return np.sqrt(dx * dx + dy * dy + dz * dz)


@njit(cache=True)
def capsule_distances(
    frames, link, seg, seg_r, ob_seg, ob_r, pa, pb, is_self, pairs, out
):
    """Exact distances of capsule/sphere pairs at every sample.

    Args:
        frames: Link frames (m, L, 4, 4).
        link: Frame index of each robot shape (S,).
        seg: Axis end points of each robot shape in its link frame (S, 2, 3).
        seg_r: Radii (S,).
        ob_seg, ob_r: The same for the objects, in the world (O, 2, 3), (O,).
        pa, pb, is_self: The pairs (P,).
        pairs: Which pairs to compute (k,).
        out: (k, m) output.
    """
    m = frames.shape[0]
    S = link.shape[0]
    for i in range(m):
        w = np.empty((S, 2, 3))
        for s in range(S):
            F = frames[i, link[s]]
            for e in range(2):
                for a in range(3):
                    w[s, e, a] = (
                        F[a, 0] * seg[s, e, 0]
                        + F[a, 1] * seg[s, e, 1]
                        + F[a, 2] * seg[s, e, 2]
                        + F[a, 3]
                    )
        for k in range(pairs.shape[0]):
            p = pairs[k]
            a = pa[p]
            b = pb[p]
            if is_self[p]:
                d = _seg_seg(w[a, 0], w[a, 1], w[b, 0], w[b, 1]) - seg_r[a] - seg_r[b]
            else:
                d = (
                    _seg_seg(w[a, 0], w[a, 1], ob_seg[b, 0], ob_seg[b, 1])
                    - seg_r[a]
                    - ob_r[b]
                )
            out[k, i] = d
    return out


@njit(cache=True)
def propagate_bounds(LB, known, C, rows):
    """Spread known lower bounds along each row through the motion bounds.

    ``d_j >= d_i - |C_j - C_i|`` for a known ``d_i`` (C is the cumulative motion
    bound along the trajectory); LB rows are raised in place.
    """
    m = LB.shape[1]
    for r in range(rows.shape[0]):
        p = rows[r]
        run = -np.inf  # max over known i <= j of (d_i + C_i)
        for j in range(m):
            if known[p, j]:
                v = LB[p, j] + C[p, j]
                if v > run:
                    run = v
            g = run - C[p, j]
            if g > LB[p, j]:
                LB[p, j] = g
        run = -np.inf  # max over known i >= j of (d_i - C_i)
        for j in range(m - 1, -1, -1):
            if known[p, j]:
                v = LB[p, j] - C[p, j]
                if v > run:
                    run = v
            g = run + C[p, j]
            if g > LB[p, j]:
                LB[p, j] = g


@njit(cache=True)
def motion_bounds(
    frames,
    pre,
    link,
    sph_c,
    sph_r,
    sph_start,
    sph_count,
    Rst,
    prismatic,
    spins,
    dq,
    pa,
    pb,
    is_self,
    out,
):
    """Bound on how much each pair's distance can change over each interval.

    A point of a shape on link k moves at most ``sum_j W_j |dq_j|`` between two
    samples, with ``W_j`` its distance from joint j's axis (revolute; 1 for a
    prismatic joint). ``W_j`` is bounded by the reach at the interval's start
    plus what the joints after j can add, and by the static chain bound ``Rst``.

    Args:
        frames: Link frames (m, L, 4, 4).
        pre: Constant from link frame j-1 to joint j (nc, 4, 4).
        link: Link index of each shape (S,).
        sph_c, sph_r: Bounding spheres in their link frames (Q, 3), (Q,).
        sph_start, sph_count: Each shape's spheres (S,).
        Rst: Static reach bounds (nc, S).
        prismatic: (nc,) bool. spins: (S,) shape invariant under its own joint.
        dq: |joint steps| (m - 1, nc).
        pa, pb, is_self: The pairs (P,).
        out: (P, m - 1) output.
    """
    m1 = dq.shape[0]
    nc = dq.shape[1]
    S = link.shape[0]
    P = pa.shape[0]
    for i in range(m1):
        W = np.zeros((S, nc))
        o = np.empty((nc, 3))
        z = np.empty((nc, 3))
        for j in range(nc):
            F = frames[i, j]
            for a in range(3):
                o[j, a] = (
                    F[a, 0] * pre[j, 0, 3]
                    + F[a, 1] * pre[j, 1, 3]
                    + F[a, 2] * pre[j, 2, 3]
                    + F[a, 3]
                )
                z[j, a] = (
                    F[a, 0] * pre[j, 0, 2]
                    + F[a, 1] * pre[j, 1, 2]
                    + F[a, 2] * pre[j, 2, 2]
                )
        for s in range(S):
            kk = min(link[s], nc)
            if kk == 0:
                continue
            F = frames[i, link[s]]
            after = 0.0  # what joints after j can move the shape within the interval
            for j in range(kk - 1, -1, -1):
                if prismatic[j]:
                    W[s, j] = 1.0
                else:
                    f = 0.0
                    for q in range(sph_start[s], sph_start[s] + sph_count[s]):
                        c0 = (
                            F[0, 0] * sph_c[q, 0]
                            + F[0, 1] * sph_c[q, 1]
                            + F[0, 2] * sph_c[q, 2]
                            + F[0, 3]
                        )
                        c1 = (
                            F[1, 0] * sph_c[q, 0]
                            + F[1, 1] * sph_c[q, 1]
                            + F[1, 2] * sph_c[q, 2]
                            + F[1, 3]
                        )
                        c2 = (
                            F[2, 0] * sph_c[q, 0]
                            + F[2, 1] * sph_c[q, 1]
                            + F[2, 2] * sph_c[q, 2]
                            + F[2, 3]
                        )
                        r0 = c0 - o[j, 0]
                        r1 = c1 - o[j, 1]
                        r2 = c2 - o[j, 2]
                        al = r0 * z[j, 0] + r1 * z[j, 1] + r2 * z[j, 2]
                        pp = r0 * r0 + r1 * r1 + r2 * r2 - al * al
                        v = np.sqrt(max(pp, 0.0)) + sph_r[q]
                        if v > f:
                            f = v
                    W[s, j] = min(Rst[j, s], f + after)
                    if j == kk - 1 and spins[s]:
                        W[s, j] = 0.0
                after += (1.0 if prismatic[j] else Rst[j, s]) * dq[i, j]
        for p in range(P):
            a = pa[p]
            if is_self[p]:
                b = pb[p]
                lo = min(link[a], link[b])
                hi = min(max(link[a], link[b]), nc)
                s2 = b if link[b] >= link[a] else a
                acc = 0.0
                for j in range(lo, hi):
                    acc += W[s2, j] * dq[i, j]
                out[p, i] = acc
            else:
                acc = 0.0
                for j in range(nc):
                    acc += W[a, j] * dq[i, j]
                out[p, i] = acc
    return out
