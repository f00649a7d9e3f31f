"""Paden–Kahan subproblems on 3-tuples, compiled with numba (``cache=True``).

Vectors are plain ``(x, y, z)`` tuples so the closed forms allocate nothing.
Rotations are applied with Rodrigues' formula
``rot(k, t) v = v cos t + (k x v) sin t + k (k . v)(1 - cos t)``.

* :func:`sp1`: the angle that turns ``p`` into ``q`` about ``k`` (subproblem 1).
* :func:`sp4_coeffs` / :func:`two_roots`: ``h . rot(k, t) p = d`` (subproblem 4);
  subproblem 3 (``|a + rot(k, t) b| = d``) reduces to it.

References:
    Paden, "Kinematics and control of robot manipulators", PhD thesis, 1985;
    Elias and Wen, "IK-Geo", arXiv:2211.05737 (2022), section III.
"""

from __future__ import annotations

import math

from numba import njit

_NJ = {"cache": True, "inline": "always"}


@njit(**_NJ)
def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(**_NJ)
def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@njit(**_NJ)
def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


@njit(**_NJ)
def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@njit(**_NJ)
def scale(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


@njit(**_NJ)
def vec(arr, i):
    """Row ``i`` of a flat array holding 3-vectors (``arr[3i:3i+3]``)."""
    return (arr[3 * i], arr[3 * i + 1], arr[3 * i + 2])


@njit(**_NJ)
def rot(k, c, s, v):
    """``rot(k, t) v`` given ``c = cos t``, ``s = sin t``."""
    kv = dot(k, v) * (1.0 - c)
    x = cross(k, v)
    return (
        v[0] * c + x[0] * s + k[0] * kv,
        v[1] * c + x[1] * s + k[1] * kv,
        v[2] * c + x[2] * s + k[2] * kv,
    )


_TAN_PI_8 = 0.41421356237309503
_HALF_PI = 0.5 * math.pi
_QUARTER_PI = 0.25 * math.pi


@njit(**_NJ)
def _atan_core(u):
    """atan(u) for |u| <= tan(pi/8): u + u^3 p(u^2), p a degree-10 least-squares
    fit on Chebyshev nodes to (atan(u) - u) / u^3 (relative error < 3e-16),
    evaluated by Estrin's scheme (short dependency chains)."""
    s = u * u
    s2 = s * s
    s4 = s2 * s2
    q0 = -0.33333333333333326 + 0.19999999999994086 * s
    q1 = -0.14285714284481754 + 0.11111111005585772 * s
    q2 = -0.0909090431754569 + 0.07692179168372903 * s
    q3 = -0.06664474627546399 + 0.05857954331450998 * s
    q4 = -0.05084928654128961 + 0.03922789786600753 * s - 0.019183482806421463 * s2
    p = (q0 + s2 * q1) + s4 * ((q2 + s2 * q3) + s4 * q4)
    return u + u * s * p


@njit(**_NJ)
def fatan2(y, x):
    """``math.atan2`` to within a few ulp (< 1e-15 rad) without the libm call and
    with few branches; zeros, infinities and NaN go to ``math.atan2``."""
    ax = abs(x)
    ay = abs(y)
    if not (ax < math.inf and ay < math.inf) or (ax == 0.0 and ay == 0.0):
        return math.atan2(y, x)
    swap = ay > ax
    num = ax if swap else ay
    den = ay if swap else ax
    big = num > _TAN_PI_8 * den
    u = ((num - den) if big else num) / ((num + den) if big else den)
    r = _atan_core(u) + (_QUARTER_PI if big else 0.0)
    r = (_HALF_PI - r) if swap else r
    r = (math.pi - r) if x < 0.0 else r
    return math.copysign(r, y)


@njit(**_NJ)
def sp1(k, p, q):
    """Subproblem 1: ``t`` with ``rot(k, t) p = q`` (least squares if inexact)."""
    kp = dot(k, p)
    return fatan2(dot(q, cross(k, p)), dot(q, p) - kp * dot(k, q))


@njit(**_NJ)
def sp4_coeffs(h, k, p):
    """``h . rot(k, t) p = A cos t + B sin t + C``: returns (A, B, C)."""
    kp = dot(k, p)
    hk = dot(h, k)
    return dot(h, p) - hk * kp, dot(h, cross(k, p)), hk * kp


@njit(**_NJ)
def two_roots(A, B, rhs, disc, tol, mirror):
    """Roots of ``A cos t + B sin t = rhs`` given ``disc = A^2 + B^2 - rhs^2``.

    Returns ``(t_plus, t_minus, n, boundary)``: ``n`` roots (0, 1 or 2);
    ``boundary`` is True when ``disc`` was clamped to zero within ``tol`` (a double
    root: the pose is on a singular boundary). With ``mirror`` (near-family seeds), a
    slightly negative ``disc`` gives two seeds mirrored about the double root instead.
    """
    phi = math.atan2(B, A)
    r2 = A * A + B * B
    if disc < 0.0:
        if disc < -tol * r2:
            return 0.0, 0.0, 0, False
        base = phi + math.atan2(0.0, rhs)  # the double root: phi (rhs > 0) or phi + pi
        if mirror:
            g = math.atan2(math.sqrt(-disc), abs(rhs))
            return base + g, base - g, 2, True
        return base, base, 1, True
    g = math.atan2(math.sqrt(disc), rhs)
    if disc <= tol * r2 * 1e-3:
        return phi + g, phi - g, 1, True
    return phi + g, phi - g, 2, False


@njit(**_NJ)
def to_joint(v, sign, offset, lo, hi):
    """Chain angle ``v`` to the joint coordinate, wrapped to [-pi, pi) and moved by
    whole turns into ``[lo, hi]`` when it fits. Returns (q, inside)."""
    q = sign * (v - offset)
    q = (q + math.pi) % (2.0 * math.pi) - math.pi
    tw = 2.0 * math.pi
    eps = 1e-9
    if q < lo - eps:
        q2 = q + tw * math.ceil((lo - eps - q) / tw)
        if q2 <= hi + eps:
            q = q2
    elif q > hi + eps:
        q2 = q - tw * math.ceil((q - hi - eps) / tw)
        if q2 >= lo - eps:
            q = q2
    return q, (q >= lo - eps) and (q <= hi + eps)
