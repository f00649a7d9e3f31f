"""Compiled (numba) hot loops on the canonical chain. Imported lazily: numba is slow
to import, and ``import robokin`` must stay fast.

Chain arrays (see :class:`robokin.model.chain.Chain`):
``consts`` (n_chain + 1, 4, 4) = ``[B L0, F1 G1, ..., Fn Gn T_tool]``;
``kind`` (n_chain,) 1.0 for prismatic; ``sign``, ``offset`` (n_chain,).
A transform under construction is kept as its top 3x4 block.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange


@njit(cache=True, inline="always")
def _joint_right(T, kind, v):
    """T <- T @ J(v): rotation about / translation along local z."""
    if kind == 0.0:
        c = math.cos(v)
        s = math.sin(v)
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
def _fk_one(q, consts, kind, sign, offset, T):
    """Write FK of one chain configuration into T (4x4). Returns False on NaN/inf."""
    ok = True
    C0 = consts[0]
    for r in range(3):
        for c in range(4):
            T[r, c] = C0[r, c]
    for k in range(kind.shape[0]):
        v = sign[k] * q[k] + offset[k]
        if not math.isfinite(v):
            ok = False
        _joint_right(T, kind[k], v)
        _const_right(T, consts[k + 1])
    T[3, 0] = 0.0
    T[3, 1] = 0.0
    T[3, 2] = 0.0
    T[3, 3] = 1.0
    return ok


@njit(cache=True)
def fk_serial(qc, consts, kind, sign, offset, out):
    """FK of a batch (N, n_chain) into out (N, 4, 4), one thread. Returns all-finite."""
    ok = True
    for i in range(qc.shape[0]):
        ok &= _fk_one(qc[i], consts, kind, sign, offset, out[i])
    return ok


@njit(cache=True, parallel=True)
def fk_parallel(qc, consts, kind, sign, offset, out):
    """FK of a batch (N, n_chain) into out (N, 4, 4), all threads. Returns all-finite."""
    n = qc.shape[0]
    flags = np.ones(n, dtype=np.bool_)
    for i in prange(n):
        flags[i] = _fk_one(qc[i], consts, kind, sign, offset, out[i])
    return flags.all()


@njit(cache=True)
def fk_all_serial(qc, first, frame_off, link_off, tool, kind, sign, offset, out):
    """Every link frame: out (N, n_chain + 2, 4, 4) = base, frames 1..n, flange.

    ``first`` is ``B L0``; frame k is ``... J_k F_k``; the last slot is the tool pose.
    Returns all-finite.
    """
    ok = True
    nc = kind.shape[0]
    T = np.empty((4, 4))
    for i in range(qc.shape[0]):
        for r in range(4):
            for c in range(4):
                T[r, c] = first[r, c]
        for k in range(nc):
            v = sign[k] * qc[i, k] + offset[k]
            if not math.isfinite(v):
                ok = False
            _joint_right(T, kind[k], v)
            _const_right(T, frame_off[k])
            out[i, k + 1] = T
            _const_right(T, link_off[k])
        _const_right(T, tool)
        out[i, nc + 1] = T
    return ok


@njit(cache=True, inline="always")
def _jac_one(q, consts, kind, sign, offset, J, T):
    """Chain Jacobian (6, n_chain) in the base frame at the flange+tool point."""
    nc = kind.shape[0]
    ok = True
    C0 = consts[0]
    for r in range(3):
        for c in range(4):
            T[r, c] = C0[r, c]
    # store axis z_k and origin p_k of each joint frame in J temporarily
    for k in range(nc):
        v = sign[k] * q[k] + offset[k]
        if not math.isfinite(v):
            ok = False
        _joint_right(T, kind[k], v)
        for r in range(3):
            J[r, k] = T[r, 3]
            J[3 + r, k] = T[r, 2]
        _const_right(T, consts[k + 1])
    for k in range(nc):
        zx = J[3, k]
        zy = J[4, k]
        zz = J[5, k]
        s = sign[k]
        if kind[k] == 0.0:
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
    return ok


@njit(cache=True, parallel=True)
def jacobian_batch(qc, consts, kind, sign, offset, out, poses):
    """Chain Jacobians (N, 6, n_chain) and poses (N, 4, 4). Returns all-finite."""
    n = qc.shape[0]
    flags = np.ones(n, dtype=np.bool_)
    for i in prange(n):
        flags[i] = _jac_one(qc[i], consts, kind, sign, offset, out[i], poses[i])
        poses[i, 3, 0] = 0.0
        poses[i, 3, 1] = 0.0
        poses[i, 3, 2] = 0.0
        poses[i, 3, 3] = 1.0
    return flags.all()
