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


@njit(**_NJ)
def sp1(k, p, q):
    """Subproblem 1: ``t`` with ``rot(k, t) p = q`` (least squares if inexact)."""
    kp = dot(k, p)
    return math.atan2(dot(q, cross(k, p)), dot(q, p) - kp * dot(k, q))


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
