"""Compiled (numba) hot loops on the canonical chain. Imported lazily: numba is slow
to import, and ``import robokin`` must stay fast.

Chain arrays (see :class:`robokin.model.chain.Chain`):
``consts`` (n_chain + 1, 4, 4) = ``[B L0, F1 G1, ..., Fn Gn T_tool]``;
``xform`` (n_chain + 1, 6): ``[1, cos a, sin a, tx, ty, tz]`` when the constant is
``Trans(tx, ty, tz) Rx(a)`` (every standard and modified DH row is), which halves
the multiplications, else all zeros;
``joints`` (3, n_chain): rows kind (1.0 = prismatic), sign, offset.
A transform under construction is kept as its top 3x4 block.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

# sincos: Cody-Waite reduction by pi/2 and the fdlibm/musl kernel polynomials
# (__kernel_sin, __kernel_cos), < 1 ulp on the reduced range. One reduction serves
# both values, about twice as fast as two libm calls; FK is bound by them.
_INV_PIO2 = 6.36619772367581382433e-01
_PIO2_1 = 1.57079632673412561417e00  # first 33 bits of pi/2
_PIO2_2 = 6.07710050630396597660e-11  # next 33 bits
_PIO2_3 = 2.02226624871116645580e-21  # the rest
_S1, _S2, _S3 = (
    -1.66666666666666324348e-01,
    8.33333333332248946124e-03,
    -1.98412698298579493134e-04,
)
_S4, _S5, _S6 = (
    2.75573137070700676789e-06,
    -2.50507602534068634195e-08,
    1.58969099521155010221e-10,
)
_C1, _C2, _C3 = (
    4.16666666666666019037e-02,
    -1.38888888888741095749e-03,
    2.48015872894767294178e-05,
)
_C4, _C5, _C6 = (
    -2.75573143513906633035e-07,
    2.08757232129817482790e-09,
    -1.13596475577881948265e-11,
)


@njit(cache=True, inline="always")
def sincos(x):
    """(sin x, cos x) for float x; libm beyond |x| = 1e5 and for NaN / inf."""
    if not abs(x) < 1e5:
        return math.sin(x), math.cos(x)
    n = math.floor(x * _INV_PIO2 + 0.5)
    y = ((x - n * _PIO2_1) - n * _PIO2_2) - n * _PIO2_3
    z = y * y
    r = _S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))
    sy = y + z * y * (_S1 + z * r)
    rc = z * (_C1 + z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * _C6)))))
    hz = 0.5 * z
    w = 1.0 - hz
    cy = w + (((1.0 - w) - hz) + z * rc)
    q = int(n) & 3
    if q == 0:
        return sy, cy
    if q == 1:
        return cy, -sy
    if q == 2:
        return -sy, -cy
    return -cy, sy


@njit(cache=True)
def sincos_array(x, s, c):
    """Vectorised :func:`sincos` (for tests): fills ``s`` and ``c`` like ``x``."""
    for i in range(x.shape[0]):
        s[i], c[i] = sincos(x[i])


@njit(cache=True, inline="always")
def _joint_right(T, kind, v):
    """T <- T @ J(v): rotation about / translation along local z."""
    if kind == 0.0:
        s, c = sincos(v)
        for r in range(3):
            x0 = T[r, 0]
            x1 = T[r, 1]
            T[r, 0] = c * x0 + s * x1
            T[r, 1] = c * x1 - s * x0
    else:
        for r in range(3):
            T[r, 3] += T[r, 2] * v


@njit(cache=True, inline="always")
def _const_right(T, C):
    """T <- T @ C for affine C (4x4, last row 0 0 0 1)."""
    for r in range(3):
        a0 = T[r, 0]
        a1 = T[r, 1]
        a2 = T[r, 2]
        a3 = T[r, 3]
        T[r, 0] = a0 * C[0, 0] + a1 * C[1, 0] + a2 * C[2, 0]
        T[r, 1] = a0 * C[0, 1] + a1 * C[1, 1] + a2 * C[2, 1]
        T[r, 2] = a0 * C[0, 2] + a1 * C[1, 2] + a2 * C[2, 2]
        T[r, 3] = a0 * C[0, 3] + a1 * C[1, 3] + a2 * C[2, 3] + a3


@njit(cache=True, inline="always")
def _const_x(T, C, P):
    """T <- T @ C, using the Trans(tx, ty, tz) Rx(a) structure when P[0] == 1."""
    if P[0] == 1.0:
        ca = P[1]
        sa = P[2]
        tx = P[3]
        ty = P[4]
        tz = P[5]
        for r in range(3):
            a0 = T[r, 0]
            a1 = T[r, 1]
            a2 = T[r, 2]
            T[r, 3] += a0 * tx + a1 * ty + a2 * tz
            T[r, 1] = ca * a1 + sa * a2
            T[r, 2] = ca * a2 - sa * a1
    else:
        _const_right(T, C)


@njit(cache=True, inline="always")
def _fk_one(q, consts, xform, joints, T, sc):
    """Write FK of one chain configuration into T (4x4). Returns False on NaN/inf.

    ``sc`` (2, n_chain) is scratch: every joint's sine and cosine are computed first,
    in a loop of independent iterations the CPU overlaps, then the transform chain
    (the serial part) uses them. The order changes no result.
    """
    ok = True
    nc = joints.shape[1]
    for k in range(nc):
        v = joints[1, k] * q[k] + joints[2, k]
        if not math.isfinite(v):
            ok = False
        if joints[0, k] == 0.0:
            sc[0, k], sc[1, k] = sincos(v)
        else:
            sc[0, k] = v
    C0 = consts[0]
    for r in range(3):
        for c in range(4):
            T[r, c] = C0[r, c]
    for k in range(nc):
        if joints[0, k] == 0.0:
            s = sc[0, k]
            c = sc[1, k]
            for r in range(3):
                x0 = T[r, 0]
                x1 = T[r, 1]
                T[r, 0] = c * x0 + s * x1
                T[r, 1] = c * x1 - s * x0
        else:
            v = sc[0, k]
            for r in range(3):
                T[r, 3] += T[r, 2] * v
        _const_x(T, consts[k + 1], xform[k + 1])
    T[3, 0] = 0.0
    T[3, 1] = 0.0
    T[3, 2] = 0.0
    T[3, 3] = 1.0
    return ok


@njit("b1(f8[:], f8[::1], f8[:, ::1])", cache=True)
def fk_packed(q, p, T):
    """FK of one configuration into T (4, 4) from packed chain arrays; False on NaN/inf.

    One flat parameter array keeps the call overhead from Python small: a single
    configuration is dominated by argument unboxing, not arithmetic. (Without the
    optional C extension ``_fk_single`` this is the single-configuration path.)
    """
    nc = int(p[0])
    consts = p[1 : 1 + (nc + 1) * 16].reshape((nc + 1, 4, 4))
    o = 1 + (nc + 1) * 16
    xform = p[o : o + (nc + 1) * 6].reshape((nc + 1, 6))
    o += (nc + 1) * 6
    joints = p[o : o + 3 * nc].reshape((3, nc))
    return _fk_one(q, consts, xform, joints, T, np.empty((2, nc)))


@njit(cache=True)
def fk_serial(qc, consts, xform, joints, out):
    """FK of a batch (N, n_chain) into out (N, 4, 4), one thread. Returns all-finite."""
    ok = True
    sc = np.empty((2, joints.shape[1]))
    for i in range(qc.shape[0]):
        ok &= _fk_one(qc[i], consts, xform, joints, out[i], sc)
    return ok


_CHUNKS = 64  # parallel work units (each with its own scratch)


@njit(cache=True, parallel=True)
def fk_parallel(qc, consts, xform, joints, out):
    """FK of a batch (N, n_chain) into out (N, 4, 4), all threads. Returns all-finite."""
    n = qc.shape[0]
    size = (n + _CHUNKS - 1) // _CHUNKS
    flags = np.ones(_CHUNKS, dtype=np.bool_)
    for c in prange(_CHUNKS):
        sc = np.empty((2, joints.shape[1]))
        ok = True
        for i in range(c * size, min(n, (c + 1) * size)):
            ok &= _fk_one(qc[i], consts, xform, joints, out[i], sc)
        flags[c] = ok
    return flags.all()


@njit(cache=True)
def fk_all_serial(qc, first, frame_off, link_off, tool, joints, out):
    """Every link frame: out (N, n_chain + 2, 4, 4) = base, frames 1..n, flange.

    ``first`` is ``B L0``; frame k is ``... J_k F_k``; the last slot is the tool pose.
    Returns all-finite.
    """
    ok = True
    nc = joints.shape[1]
    T = np.empty((4, 4))
    for i in range(qc.shape[0]):
        for r in range(4):
            for c in range(4):
                T[r, c] = first[r, c]
        for k in range(nc):
            v = joints[1, k] * qc[i, k] + joints[2, k]
            if not math.isfinite(v):
                ok = False
            _joint_right(T, joints[0, k], v)
            _const_right(T, frame_off[k])
            out[i, k + 1] = T
            _const_right(T, link_off[k])
        _const_right(T, tool)
        out[i, nc + 1] = T
    return ok


@njit(cache=True, inline="always")
def _jac_one(q, consts, xform, joints, J, T):
    """Chain Jacobian (6, n_chain) in the base frame at the tool point; pose into T."""
    nc = joints.shape[1]
    ok = True
    C0 = consts[0]
    for r in range(3):
        for c in range(4):
            T[r, c] = C0[r, c]
    # store origin p_k and axis z_k of each joint frame in J first
    for k in range(nc):
        v = joints[1, k] * q[k] + joints[2, k]
        if not math.isfinite(v):
            ok = False
        _joint_right(T, joints[0, k], v)
        for r in range(3):
            J[r, k] = T[r, 3]
            J[3 + r, k] = T[r, 2]
        _const_x(T, consts[k + 1], xform[k + 1])
    for k in range(nc):
        zx = J[3, k]
        zy = J[4, k]
        zz = J[5, k]
        s = joints[1, k]
        if joints[0, k] == 0.0:
            dx = T[0, 3] - J[0, k]
            dy = T[1, 3] - J[1, k]
            dz = T[2, 3] - J[2, k]
            J[0, k] = s * (zy * dz - zz * dy)
            J[1, k] = s * (zz * dx - zx * dz)
            J[2, k] = s * (zx * dy - zy * dx)
            J[3, k] = s * zx
            J[4, k] = s * zy
            J[5, k] = s * zz
        else:
            J[0, k] = s * zx
            J[1, k] = s * zy
            J[2, k] = s * zz
            J[3, k] = 0.0
            J[4, k] = 0.0
            J[5, k] = 0.0
    T[3, 0] = 0.0
    T[3, 1] = 0.0
    T[3, 2] = 0.0
    T[3, 3] = 1.0
    return ok


@njit(cache=True, parallel=True)
def jacobian_batch(qc, consts, xform, joints, out, poses):
    """Chain Jacobians (N, 6, n_chain) and poses (N, 4, 4). Returns all-finite."""
    n = qc.shape[0]
    flags = np.ones(n, dtype=np.bool_)
    for i in prange(n):
        flags[i] = _jac_one(qc[i], consts, xform, joints, out[i], poses[i])
    return flags.all()


@njit(cache=True)
def jacobian_serial(qc, consts, xform, joints, out, poses):
    """As :func:`jacobian_batch`, one thread (small batches)."""
    ok = True
    for i in range(qc.shape[0]):
        ok &= _jac_one(qc[i], consts, xform, joints, out[i], poses[i])
    return ok


@njit(cache=True)
def check_poses(T, tol):
    """Validate rigid transforms T (N, 4, 4). Returns (code, index).

    code 0: all fine; 1: a non-finite entry; 2: last row is not 0 0 0 1; 3: the
    rotation block is not orthonormal within ``tol``; 4: it is a reflection.
    """
    for i in range(T.shape[0]):
        A = T[i]
        for r in range(4):
            for c in range(4):
                if not math.isfinite(A[r, c]):
                    return 1, i
        if (
            abs(A[3, 0]) > 1e-9
            or abs(A[3, 1]) > 1e-9
            or abs(A[3, 2]) > 1e-9
            or abs(A[3, 3] - 1.0) > 1e-9
        ):
            return 2, i
        for r in range(3):
            for s in range(3):
                d = A[r, 0] * A[s, 0] + A[r, 1] * A[s, 1] + A[r, 2] * A[s, 2]
                if r == s:
                    d -= 1.0
                if abs(d) > tol:
                    return 3, i
        det = (
            A[0, 0] * (A[1, 1] * A[2, 2] - A[1, 2] * A[2, 1])
            - A[0, 1] * (A[1, 0] * A[2, 2] - A[1, 2] * A[2, 0])
            + A[0, 2] * (A[1, 0] * A[2, 1] - A[1, 1] * A[2, 0])
        )
        if det < 0.0:
            return 4, i
    return 0, -1
