"""Compiled closed forms of the two 6R families (numba, ``cache=True``, lazy import).

Both kernels read one flat parameter vector (see :func:`pack` in ``_six_r.py``):

========  ==========================================================
index     content (3-vectors are counted in triples: vec i = [3i, 3i+3))
========  ==========================================================
vec 0-5   unit joint axes h1..h6 (base frame, zero chain values)
vec 6-10  points o1, o2, o3, o4, ow (ow: axes 5/6 meet (three parallel)
          or axes 4/5/6 meet (spherical wrist))
vec 12    tool origin t at zero chain values
vec 13-15 rows of the tool rotation R_M at zero chain values
vec 16    unit vector e perpendicular to the 'sum' axis (h2 or h4)
51..56    joint signs; 57..62 joint offsets; 63..68 / 69..74 lower / upper limits
75, 76    s3 = h3.h2, s4 = h4.h2 (three parallel)
77, 78    singular tolerance, discriminant tolerance
79        1.0: mirror seeds past a boundary (near-family), else 0.0
========  ==========================================================

Each pose yields 8 slots, ``slot = 4 * shoulder + 2 * elbow + wrist`` with
0 = the '+' root and 1 = the '-' root of the corresponding subproblem.
Status codes: 0 ok, 1 out of reach, 2 orientation not achievable.
"""

from __future__ import annotations

import math

from numba import njit, prange

from robokin.kinematics.ik.analytic._subproblems import (
    add,
    dot,
    rot,
    scale,
    sp1,
    sp4_coeffs,
    sub,
    to_joint,
    two_roots,
    vec,
)

SIGN, OFFSET, LO, HI, S3, S4, SING_TOL, DISC_TOL, MIRROR = 51, 57, 63, 69, 75, 76, 77, 78, 79
N_PARAMS = 80


@njit(cache=True, inline="always")
def _mv(r0, r1, r2, v):
    return (dot(r0, v), dot(r1, v), dot(r2, v))


@njit(cache=True, inline="always")
def _mtv(r0, r1, r2, v):
    return (
        r0[0] * v[0] + r1[0] * v[1] + r2[0] * v[2],
        r0[1] * v[0] + r1[1] * v[1] + r2[1] * v[2],
        r0[2] * v[0] + r1[2] * v[1] + r2[2] * v[2],
    )


@njit(cache=True, inline="always")
def _target(T, P):
    """Rows of R06 = R_T R_M^T and the target position."""
    m0 = vec(P, 13)
    m1 = vec(P, 14)
    m2 = vec(P, 15)
    t0 = (T[0, 0], T[0, 1], T[0, 2])
    t1 = (T[1, 0], T[1, 1], T[1, 2])
    t2 = (T[2, 0], T[2, 1], T[2, 2])
    r0 = (dot(t0, m0), dot(t0, m1), dot(t0, m2))
    r1 = (dot(t1, m0), dot(t1, m1), dot(t1, m2))
    r2 = (dot(t2, m0), dot(t2, m1), dot(t2, m2))
    return r0, r1, r2, (T[0, 3], T[1, 3], T[2, 3])


@njit(cache=True, inline="always")
def _write(P, Q, inside, slot, v1, v2, v3, v4, v5, v6):
    ok = True
    vals = (v1, v2, v3, v4, v5, v6)
    for j in range(6):
        q, ins = to_joint(vals[j], P[SIGN + j], P[OFFSET + j], P[LO + j], P[HI + j])
        Q[slot, j] = q
        ok = ok and ins
    inside[slot] = ok


@njit(cache=True, inline="always")
def _wrist_disc(A, B, C, d, xperp2):
    """A^2 + B^2 - (d - C)^2 for unit vectors, using |x_perp|^2 = 1 - d^2 exactly."""
    return A * A + B * B - C * C - 1.0 + xperp2 + 2.0 * d * C


@njit(cache=True)
def three_parallel_one(T, P, qn, Q, valid, sing, inside):
    """All solutions of one pose, axes 2, 3, 4 parallel and axes 5, 6 meeting."""
    h1 = vec(P, 0)
    h2 = vec(P, 1)
    h3 = vec(P, 2)
    h5 = vec(P, 4)
    h6 = vec(P, 5)
    o1 = vec(P, 6)
    o2 = vec(P, 7)
    o3 = vec(P, 8)
    o4 = vec(P, 9)
    ow = vec(P, 10)
    t = vec(P, 12)
    e = vec(P, 16)
    s3 = P[S3]
    s4 = P[S4]
    stol = P[SING_TOL]
    dtol = P[DISC_TOL]
    mir = P[MIRROR] != 0.0
    for k in range(8):
        valid[k] = False
        sing[k] = False
        inside[k] = False
        for j in range(6):
            Q[k, j] = 0.0
    r0, r1, r2, p = _target(T, P)
    pp = sub(sub(p, _mv(r0, r1, r2, sub(t, ow))), o1)
    A, B, C = sp4_coeffs(pp, h1, h2)
    rhs = dot(h2, sub(ow, o1)) - C
    t1p, t1m, n1, bd1 = two_roots(A, B, rhs, A * A + B * B - rhs * rhs, dtol, mir)
    if n1 == 0:
        return 1
    g6 = _mv(r0, r1, r2, h6)
    A5, B5, C5 = sp4_coeffs(h2, h5, h6)
    a = sub(o3, o2)
    b = sub(o4, o3)
    A3, B3, C3 = sp4_coeffs(a, h3, b)
    aa = dot(a, a)
    bb = dot(b, b)
    any_wrist = False
    any_ok = False
    for i1 in range(n1):
        th1 = t1p if i1 == 0 else t1m
        c1 = math.cos(th1)
        s1 = math.sin(th1)
        x = rot(h1, c1, -s1, g6)  # R1^T R06 h6
        d5 = dot(h2, x)
        xp = sub(x, scale(h2, d5))
        t5p, t5m, n5, _ = two_roots(A5, B5, d5 - C5, _wrist_disc(A5, B5, C5, d5, dot(xp, xp)),
                                   dtol, mir)
        if n5 == 0:
            continue
        any_wrist = True
        y = _mtv(r0, r1, r2, rot(h1, c1, s1, h2))  # R06^T R1 h2
        yp = sub(y, scale(h6, dot(y, h6)))
        singular = math.sqrt(dot(yp, yp)) < stol
        if singular:
            n5 = 1
        pl = sub(rot(h1, c1, -s1, pp), sub(o2, o1))  # R1^T pp - (o2 - o1)
        for i5 in range(n5):
            th5 = t5p if i5 == 0 else t5m
            c5 = math.cos(th5)
            s5 = math.sin(th5)
            if singular:
                th6 = P[SIGN + 5] * qn[5] + P[OFFSET + 5]
            else:
                th6 = sp1(h6, y, rot(h5, c5, -s5, h2))
            c6 = math.cos(th6)
            s6 = math.sin(th6)
            w = rot(h6, c6, -s6, rot(h5, c5, -s5, e))
            w = rot(h1, c1, -s1, _mv(r0, r1, r2, w))
            th234 = sp1(h2, e, w)
            d = sub(pl, rot(h2, math.cos(th234), math.sin(th234), sub(ow, o4)))
            rhs3 = 0.5 * (dot(d, d) - aa - bb) - C3
            t3p, t3m, n3, bd3 = two_roots(A3, B3, rhs3, A3 * A3 + B3 * B3 - rhs3 * rhs3, dtol, mir)
            for i3 in range(n3):
                th3 = t3p if i3 == 0 else t3m
                u = add(a, rot(h3, math.cos(th3), math.sin(th3), b))
                th2 = sp1(h2, u, d)
                th4 = s4 * (th234 - th2 - s3 * th3)
                slot = 4 * i1 + 2 * i3 + i5
                _write(P, Q, inside, slot, th1, th2, th3, th4, th5, th6)
                valid[slot] = True
                sing[slot] = singular or bd1 or bd3
                any_ok = True
    if any_ok:
        return 0
    return 1 if any_wrist else 2


@njit(cache=True)
def spherical_one(T, P, qn, Q, valid, sing, inside):
    """All solutions of one pose, axes 2, 3 parallel and axes 4, 5, 6 meeting."""
    h1 = vec(P, 0)
    h2 = vec(P, 1)
    h3 = vec(P, 2)
    h4 = vec(P, 3)
    h5 = vec(P, 4)
    h6 = vec(P, 5)
    o1 = vec(P, 6)
    o2 = vec(P, 7)
    o3 = vec(P, 8)
    ow = vec(P, 10)
    t = vec(P, 12)
    e = vec(P, 16)
    stol = P[SING_TOL]
    dtol = P[DISC_TOL]
    mir = P[MIRROR] != 0.0
    for k in range(8):
        valid[k] = False
        sing[k] = False
        inside[k] = False
        for j in range(6):
            Q[k, j] = 0.0
    r0, r1, r2, p = _target(T, P)
    pw = sub(sub(p, _mv(r0, r1, r2, sub(t, ow))), o1)
    A, B, C = sp4_coeffs(pw, h1, h2)
    rhs = dot(h2, sub(ow, o1)) - C
    t1p, t1m, n1, bd1 = two_roots(A, B, rhs, A * A + B * B - rhs * rhs, dtol, mir)
    if n1 == 0:
        return 1
    g6 = _mv(r0, r1, r2, h6)
    a = sub(o3, o2)
    b = sub(ow, o3)
    A3, B3, C3 = sp4_coeffs(a, h3, b)
    A5, B5, C5 = sp4_coeffs(h4, h5, h6)
    aa = dot(a, a)
    bb = dot(b, b)
    any_pos = False
    any_ok = False
    for i1 in range(n1):
        th1 = t1p if i1 == 0 else t1m
        c1 = math.cos(th1)
        s1 = math.sin(th1)
        d = sub(rot(h1, c1, -s1, pw), sub(o2, o1))
        rhs3 = 0.5 * (dot(d, d) - aa - bb) - C3
        t3p, t3m, n3, bd3 = two_roots(A3, B3, rhs3, A3 * A3 + B3 * B3 - rhs3 * rhs3, dtol, mir)
        for i3 in range(n3):
            any_pos = True
            th3 = t3p if i3 == 0 else t3m
            c3 = math.cos(th3)
            s3 = math.sin(th3)
            u = add(a, rot(h3, c3, s3, b))
            th2 = sp1(h2, u, d)
            c2 = math.cos(th2)
            s2 = math.sin(th2)
            x = rot(h3, c3, -s3, rot(h2, c2, -s2, rot(h1, c1, -s1, g6)))  # Rw h6
            d5 = dot(h4, x)
            xp = sub(x, scale(h4, d5))
            t5p, t5m, n5, _ = two_roots(
                A5, B5, d5 - C5, _wrist_disc(A5, B5, C5, d5, dot(xp, xp)), dtol, mir
            )
            y = _mtv(r0, r1, r2, rot(h1, c1, s1, rot(h2, c2, s2, rot(h3, c3, s3, h4))))
            yp = sub(y, scale(h6, dot(y, h6)))
            singular = math.sqrt(dot(yp, yp)) < stol
            if singular and n5 > 1:
                n5 = 1
            for i5 in range(n5):
                th5 = t5p if i5 == 0 else t5m
                c5 = math.cos(th5)
                s5 = math.sin(th5)
                if singular:
                    th6 = P[SIGN + 5] * qn[5] + P[OFFSET + 5]
                else:
                    th6 = sp1(h6, y, rot(h5, c5, -s5, h4))
                w = rot(h6, math.cos(th6), -math.sin(th6), rot(h5, c5, -s5, e))
                w = rot(h1, c1, -s1, _mv(r0, r1, r2, w))
                w = rot(h3, c3, -s3, rot(h2, c2, -s2, w))
                th4 = sp1(h4, e, w)
                slot = 4 * i1 + 2 * i3 + i5
                _write(P, Q, inside, slot, th1, th2, th3, th4, th5, th6)
                valid[slot] = True
                sing[slot] = singular or bd1 or bd3
                any_ok = True
    if any_ok:
        return 0
    return 2 if any_pos else 1


@njit(cache=True)
def three_parallel_serial(T, P, qn, Q, valid, sing, inside, status):
    """Batch (N, 4, 4) -> slots (N, 8, 6), one thread."""
    m = qn.shape[0]
    for i in range(T.shape[0]):
        status[i] = three_parallel_one(T[i], P, qn[i % m], Q[i], valid[i], sing[i], inside[i])


@njit(cache=True, parallel=True)
def three_parallel_parallel(T, P, qn, Q, valid, sing, inside, status):
    """Batch (N, 4, 4) -> slots (N, 8, 6), all threads."""
    m = qn.shape[0]
    for i in prange(T.shape[0]):
        status[i] = three_parallel_one(T[i], P, qn[i % m], Q[i], valid[i], sing[i], inside[i])


@njit(cache=True)
def spherical_serial(T, P, qn, Q, valid, sing, inside, status):
    """Batch (N, 4, 4) -> slots (N, 8, 6), one thread."""
    m = qn.shape[0]
    for i in range(T.shape[0]):
        status[i] = spherical_one(T[i], P, qn[i % m], Q[i], valid[i], sing[i], inside[i])


@njit(cache=True, parallel=True)
def spherical_parallel(T, P, qn, Q, valid, sing, inside, status):
    """Batch (N, 4, 4) -> slots (N, 8, 6), all threads."""
    m = qn.shape[0]
    for i in prange(T.shape[0]):
        status[i] = spherical_one(T[i], P, qn[i % m], Q[i], valid[i], sing[i], inside[i])

