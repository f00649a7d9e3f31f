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
80..85    theta3 subproblem 4: A, B, C, atan2(B, A), its cosine, sine
86..91    theta5 subproblem 4: A, B, C, atan2(B, A), its cosine, sine
92, 93    |a|^2, |b|^2 of the two-link (elbow) problem
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
    cross,
    dot,
    fatan2,
    rot,
    scale,
    sp1,
    sp4_coeffs,
    sub,
    vec,
)

SIGN, OFFSET, LO, HI, S3, S4, SING_TOL, DISC_TOL, MIRROR = 51, 57, 63, 69, 75, 76, 77, 78, 79
# Pose-independent constants derived by ``pack`` (per family, see the kernels):
# subproblem-4 coefficients and their phase for theta3 and theta5, |a|^2, |b|^2.
A3, B3, C3, PHI3, CPHI3, SPHI3 = 80, 81, 82, 83, 84, 85
A5, B5, C5, PHI5, CPHI5, SPHI5 = 86, 87, 88, 89, 90, 91
AA, BB = 92, 93
N_PARAMS = 94

_TWO_PI = 2.0 * math.pi
_INV_TWO_PI = 1.0 / _TWO_PI
# Status codes >= BAD_POSE: the pose failed validation (code - BAD_POSE is the
# ``check_poses`` code); nothing was solved.
BAD_POSE = 16


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
def _joint(v, sign, offset, lo, hi):
    """Chain angle ``v`` to the joint coordinate, wrapped to [-pi, pi] and moved by
    whole turns into ``[lo, hi]`` when it fits. Returns (q, inside).

    ``_subproblems.to_joint`` without the float modulo and with few branches."""
    q = sign * (v - offset)
    q -= _TWO_PI * math.floor((q + math.pi) * _INV_TWO_PI)
    lo_e = lo - 1e-9
    hi_e = hi + 1e-9
    if q < lo_e:
        q2 = q + _TWO_PI * math.ceil((lo_e - q) * _INV_TWO_PI)
        if q2 <= hi_e:
            q = q2
    elif q > hi_e:
        q2 = q - _TWO_PI * math.ceil((q - hi_e) * _INV_TWO_PI)
        if q2 >= lo_e:
            q = q2
    return q, (q >= lo_e) & (q <= hi_e)


@njit(cache=True, inline="always")
def _write(P, Q, inside, slot, v1, v2, v3, v4, v5, v6):
    # unrolled: a loop over a tuple indexed by the loop variable is much slower
    q1, k1 = _joint(v1, P[SIGN], P[OFFSET], P[LO], P[HI])
    q2, k2 = _joint(v2, P[SIGN + 1], P[OFFSET + 1], P[LO + 1], P[HI + 1])
    q3, k3 = _joint(v3, P[SIGN + 2], P[OFFSET + 2], P[LO + 2], P[HI + 2])
    q4, k4 = _joint(v4, P[SIGN + 3], P[OFFSET + 3], P[LO + 3], P[HI + 3])
    q5, k5 = _joint(v5, P[SIGN + 4], P[OFFSET + 4], P[LO + 4], P[HI + 4])
    q6, k6 = _joint(v6, P[SIGN + 5], P[OFFSET + 5], P[LO + 5], P[HI + 5])
    Q[slot, 0] = q1
    Q[slot, 1] = q2
    Q[slot, 2] = q3
    Q[slot, 3] = q4
    Q[slot, 4] = q5
    Q[slot, 5] = q6
    inside[slot] = k1 & k2 & k3 & k4 & k5 & k6


@njit(cache=True, inline="always")
def _wrist_disc(A, B, C, d, xperp2):
    """A^2 + B^2 - (d - C)^2 for unit vectors, using |x_perp|^2 = 1 - d^2 exactly."""
    return A * A + B * B - C * C - 1.0 + xperp2 + 2.0 * d * C


@njit(cache=True, inline="always")
def _unit2(y, x):
    """(cos, sin) of ``atan2(y, x)`` without the trigonometry."""
    r = math.sqrt(x * x + y * y)
    if r > 0.0:
        return x / r, y / r
    return 1.0, 0.0


@njit(cache=True, inline="always")
def _roots(A, B, rhs, disc, tol, mirror, phi, cphi, sphi):
    """``two_roots`` (see ``_subproblems``) with the phase ``phi = atan2(B, A)``
    given, also returning the cosine and sine of each root.

    Returns ``(n, boundary, t+, c+, s+, t-, c-, s-)``.
    """
    r2 = A * A + B * B
    if disc < 0.0:
        if disc < -tol * r2:
            return 0, False, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0
        base = phi + math.atan2(0.0, rhs)
        if mirror:
            g = math.atan2(math.sqrt(-disc), abs(rhs))
            tp = base + g
            tm = base - g
            return 2, True, tp, math.cos(tp), math.sin(tp), tm, math.cos(tm), math.sin(tm)
        cb = math.cos(base)
        sb = math.sin(base)
        return 1, True, base, cb, sb, base, cb, sb
    sq = math.sqrt(disc)
    g = fatan2(sq, rhs)
    cg, sg = _unit2(sq, rhs)
    cp = cphi * cg - sphi * sg
    sp = sphi * cg + cphi * sg
    cm = cphi * cg + sphi * sg
    sm = sphi * cg - cphi * sg
    n = 1 if disc <= tol * r2 * 1e-3 else 2
    return n, n == 1, phi + g, cp, sp, phi - g, cm, sm


@njit(cache=True, inline="always")
def _sp1_cs(k, p, q):
    """Subproblem 1 (``sp1``): the angle and its cosine and sine."""
    kp = dot(k, p)
    y = dot(q, cross(k, p))
    x = dot(q, p) - kp * dot(k, q)
    c, s = _unit2(y, x)
    return fatan2(y, x), c, s


@njit(cache=True, inline="always")
def _clear(Q, valid, sing, inside):
    for k in range(8):
        valid[k] = False
        sing[k] = False
        inside[k] = False
        for j in range(6):
            Q[k, j] = 0.0


@njit(cache=True)
def pose_code(T):
    """0 for a rigid transform T (4, 4), else the ``check_poses`` problem code
    (1 non-finite, 2 last row, 3 rotation not orthonormal within 1e-6, 4 reflection);
    the same tests as ``robokin.kinematics._kernels.check_poses``."""
    for r in range(4):
        for c in range(4):
            if not math.isfinite(T[r, c]):
                return 1
    if (abs(T[3, 0]) > 1e-9 or abs(T[3, 1]) > 1e-9 or abs(T[3, 2]) > 1e-9
            or abs(T[3, 3] - 1.0) > 1e-9):
        return 2
    for r in range(3):
        for s in range(3):
            d = T[r, 0] * T[s, 0] + T[r, 1] * T[s, 1] + T[r, 2] * T[s, 2]
            if r == s:
                d -= 1.0
            if abs(d) > 1e-6:
                return 3
    det = (T[0, 0] * (T[1, 1] * T[2, 2] - T[1, 2] * T[2, 1])
           - T[0, 1] * (T[1, 0] * T[2, 2] - T[1, 2] * T[2, 0])
           + T[0, 2] * (T[1, 0] * T[2, 1] - T[1, 1] * T[2, 0]))
    if det < 0.0:
        return 4
    return 0


@njit(cache=True)
def three_parallel_one(T, P, q6, Q, valid, sing, inside):
    """All solutions of one pose, axes 2, 3, 4 parallel and axes 5, 6 meeting.

    ``q6``: joint 6 value kept at the wrist singularity.
    """
    h1 = vec(P, 0)
    h2 = vec(P, 1)
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
    A3_ = P[A3]
    B3_ = P[B3]
    C3_ = P[C3]
    A5_ = P[A5]
    B5_ = P[B5]
    C5_ = P[C5]
    aa = P[AA]
    bb = P[BB]
    _clear(Q, valid, sing, inside)
    r0, r1, r2, p = _target(T, P)
    pp = sub(sub(p, _mv(r0, r1, r2, sub(t, ow))), o1)
    A, B, C = sp4_coeffs(pp, h1, h2)
    rhs = dot(h2, sub(ow, o1)) - C
    phi1 = fatan2(B, A)
    cphi1, sphi1 = _unit2(B, A)
    n1, bd1, t1p, c1p, s1p, t1m, c1m, s1m = _roots(
        A, B, rhs, A * A + B * B - rhs * rhs, dtol, mir, phi1, cphi1, sphi1)
    if n1 == 0:
        return 1
    g6 = _mv(r0, r1, r2, h6)
    a = sub(o3, o2)
    b = sub(o4, o3)
    o21 = sub(o2, o1)
    w4 = sub(ow, o4)
    # the planar part (axes 2-4 parallel): coordinates in the plane normal to h2,
    # basis (e, e2 = h2 x e); rotations about h2 are 2D rotations there
    e2 = cross(h2, e)
    a1 = dot(a, e)
    a2 = dot(a, e2)
    b1 = dot(b, e)
    b2 = dot(b, e2)
    w41 = dot(w4, e)
    w42 = dot(w4, e2)
    w4h = dot(w4, h2)
    any_wrist = False
    any_ok = False
    for i1 in range(n1):
        if i1 == 0:
            th1, c1, s1 = t1p, c1p, s1p
        else:
            th1, c1, s1 = t1m, c1m, s1m
        x = rot(h1, c1, -s1, g6)  # R1^T R06 h6
        d5 = dot(h2, x)
        xp = sub(x, scale(h2, d5))
        n5, _b5, t5p, c5p, s5p, t5m, c5m, s5m = _roots(
            A5_, B5_, d5 - C5_, _wrist_disc(A5_, B5_, C5_, d5, dot(xp, xp)), dtol, mir,
            P[PHI5], P[CPHI5], P[SPHI5])
        if n5 == 0:
            continue
        any_wrist = True
        y = _mtv(r0, r1, r2, rot(h1, c1, s1, h2))  # R06^T R1 h2
        yp = sub(y, scale(h6, dot(y, h6)))
        singular = math.sqrt(dot(yp, yp)) < stol
        if singular:
            n5 = 1
        pl = sub(rot(h1, c1, -s1, pp), o21)  # R1^T pp - (o2 - o1)
        pl1 = dot(pl, e)
        pl2 = dot(pl, e2)
        dh = dot(pl, h2) - w4h  # d's component along h2
        for i5 in range(n5):
            if i5 == 0:
                th5, c5, s5 = t5p, c5p, s5p
            else:
                th5, c5, s5 = t5m, c5m, s5m
            r5h2 = rot(h5, c5, -s5, h2)
            if singular:
                th6 = P[SIGN + 5] * q6 + P[OFFSET + 5]
                c6 = math.cos(th6)
                s6 = math.sin(th6)
            else:
                th6, c6, s6 = _sp1_cs(h6, y, r5h2)
            w = rot(h6, c6, -s6, rot(h5, c5, -s5, e))
            w = rot(h1, c1, -s1, _mv(r0, r1, r2, w))
            th234, c234, s234 = _sp1_cs(h2, e, w)
            d1 = pl1 - (c234 * w41 - s234 * w42)  # d = pl - rot(h2, th234) w4
            d2 = pl2 - (s234 * w41 + c234 * w42)
            rhs3 = 0.5 * (d1 * d1 + d2 * d2 + dh * dh - aa - bb) - C3_
            n3, bd3, t3p, c3p, s3p, t3m, c3m, s3m = _roots(
                A3_, B3_, rhs3, A3_ * A3_ + B3_ * B3_ - rhs3 * rhs3, dtol, mir,
                P[PHI3], P[CPHI3], P[SPHI3])
            for i3 in range(n3):
                if i3 == 0:
                    th3, c3, sn3 = t3p, c3p, s3p
                else:
                    th3, c3, sn3 = t3m, c3m, s3m
                sg = s3 * sn3  # rot(h3, th3) = rot(h2, s3 th3)
                u1 = a1 + c3 * b1 - sg * b2  # u = a + rot(h3, th3) b
                u2 = a2 + sg * b1 + c3 * b2
                th2 = fatan2(u1 * d2 - u2 * d1, u1 * d1 + u2 * d2)  # rot(h2, th2) u = d
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
def spherical_one(T, P, q6, Q, valid, sing, inside):
    """All solutions of one pose, axes 2, 3 parallel and axes 4, 5, 6 meeting.

    ``q6``: joint 6 value kept at the wrist singularity.
    """
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
    sign3 = P[S3]
    stol = P[SING_TOL]
    dtol = P[DISC_TOL]
    mir = P[MIRROR] != 0.0
    A3_ = P[A3]
    B3_ = P[B3]
    C3_ = P[C3]
    A5_ = P[A5]
    B5_ = P[B5]
    C5_ = P[C5]
    aa = P[AA]
    bb = P[BB]
    _clear(Q, valid, sing, inside)
    r0, r1, r2, p = _target(T, P)
    pw = sub(sub(p, _mv(r0, r1, r2, sub(t, ow))), o1)
    A, B, C = sp4_coeffs(pw, h1, h2)
    rhs = dot(h2, sub(ow, o1)) - C
    phi1 = fatan2(B, A)
    cphi1, sphi1 = _unit2(B, A)
    n1, bd1, t1p, c1p, s1p, t1m, c1m, s1m = _roots(
        A, B, rhs, A * A + B * B - rhs * rhs, dtol, mir, phi1, cphi1, sphi1)
    if n1 == 0:
        return 1
    g6 = _mv(r0, r1, r2, h6)
    a = sub(o3, o2)
    b = sub(ow, o3)
    o21 = sub(o2, o1)
    any_pos = False
    any_ok = False
    for i1 in range(n1):
        if i1 == 0:
            th1, c1, s1 = t1p, c1p, s1p
        else:
            th1, c1, s1 = t1m, c1m, s1m
        d = sub(rot(h1, c1, -s1, pw), o21)
        rhs3 = 0.5 * (dot(d, d) - aa - bb) - C3_
        n3, bd3, t3p, c3p, s3p, t3m, c3m, s3m = _roots(
            A3_, B3_, rhs3, A3_ * A3_ + B3_ * B3_ - rhs3 * rhs3, dtol, mir,
            P[PHI3], P[CPHI3], P[SPHI3])
        g61 = rot(h1, c1, -s1, g6)
        for i3 in range(n3):
            any_pos = True
            if i3 == 0:
                th3, c3, s3 = t3p, c3p, s3p
            else:
                th3, c3, s3 = t3m, c3m, s3m
            u = add(a, rot(h3, c3, s3, b))
            th2, c2, s2 = _sp1_cs(h2, u, d)
            # h3 = sign3 h2 (snapped): rot(h2, th2) rot(h3, th3) = rot(h2, th2 + sign3 th3)
            sg = sign3 * s3
            c23 = c2 * c3 - s2 * sg
            s23 = s2 * c3 + c2 * sg
            x = rot(h2, c23, -s23, g61)  # Rw h6
            d5 = dot(h4, x)
            xp = sub(x, scale(h4, d5))
            n5, _b5, t5p, c5p, s5p, t5m, c5m, s5m = _roots(
                A5_, B5_, d5 - C5_, _wrist_disc(A5_, B5_, C5_, d5, dot(xp, xp)), dtol,
                mir, P[PHI5], P[CPHI5], P[SPHI5])
            y = _mtv(r0, r1, r2, rot(h1, c1, s1, rot(h2, c23, s23, h4)))
            yp = sub(y, scale(h6, dot(y, h6)))
            singular = math.sqrt(dot(yp, yp)) < stol
            if singular and n5 > 1:
                n5 = 1
            for i5 in range(n5):
                if i5 == 0:
                    th5, c5, s5 = t5p, c5p, s5p
                else:
                    th5, c5, s5 = t5m, c5m, s5m
                if singular:
                    th6 = P[SIGN + 5] * q6 + P[OFFSET + 5]
                    c6 = math.cos(th6)
                    s6 = math.sin(th6)
                else:
                    th6, c6, s6 = _sp1_cs(h6, y, rot(h5, c5, -s5, h4))
                w = rot(h6, c6, -s6, rot(h5, c5, -s5, e))
                w = rot(h1, c1, -s1, _mv(r0, r1, r2, w))
                w = rot(h2, c23, -s23, w)
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
        status[i] = three_parallel_one(T[i], P, qn[i % m, 5], Q[i], valid[i], sing[i], inside[i])


@njit(cache=True, parallel=True)
def three_parallel_parallel(T, P, qn, Q, valid, sing, inside, status):
    """Batch (N, 4, 4) -> slots (N, 8, 6), all threads."""
    m = qn.shape[0]
    for i in prange(T.shape[0]):
        status[i] = three_parallel_one(T[i], P, qn[i % m, 5], Q[i], valid[i], sing[i], inside[i])


@njit(cache=True)
def spherical_serial(T, P, qn, Q, valid, sing, inside, status):
    """Batch (N, 4, 4) -> slots (N, 8, 6), one thread."""
    m = qn.shape[0]
    for i in range(T.shape[0]):
        status[i] = spherical_one(T[i], P, qn[i % m, 5], Q[i], valid[i], sing[i], inside[i])


@njit(cache=True, parallel=True)
def spherical_parallel(T, P, qn, Q, valid, sing, inside, status):
    """Batch (N, 4, 4) -> slots (N, 8, 6), all threads."""
    m = qn.shape[0]
    for i in prange(T.shape[0]):
        status[i] = spherical_one(T[i], P, qn[i % m, 5], Q[i], valid[i], sing[i], inside[i])



@njit(cache=True)
def three_parallel_checked(T, P, q6, Q, valid, sing, inside):
    """One pose T (4, 4), validated first: ``BAD_POSE + code`` when it is not a
    rigid transform (nothing solved), else the status of ``three_parallel_one``."""
    code = pose_code(T)
    if code:
        return BAD_POSE + code
    return three_parallel_one(T, P, q6, Q, valid, sing, inside)


@njit(cache=True)
def spherical_checked(T, P, q6, Q, valid, sing, inside):
    """One pose T (4, 4), validated first (see ``three_parallel_checked``)."""
    code = pose_code(T)
    if code:
        return BAD_POSE + code
    return spherical_one(T, P, q6, Q, valid, sing, inside)
