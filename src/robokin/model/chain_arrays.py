"""The arrays robokin's compiled kernels read, declared once per chain.

A :class:`ChainArrays` is built by :class:`~robokin.model.chain.Chain` when the chain
is made (it is the chain's ``arrays`` field) and is the only thing the kernels
receive: they read its :attr:`ChainArrays.packed` vector. Its layout is declared
once, in ``robokin/_native/_declare.py`` (``PACKED_LAYOUT``): :func:`chain_arrays`
packs the sections in that order and ``chain.h``'s ``chain_view`` parses them by the
header generated from it (a test parses a packed chain back). All arrays are
float64 and read-only; SI units.

``packed`` layout (``nc`` chain joints, ``n`` independent coordinates)::

    [LAYOUT_TAG, nc, n, identity]          4
    consts      C_0 .. C_nc                (nc + 1) * 16
    xform       per constant               (nc + 1) * 6
    kind, sign, offset                     3 * nc
    M (row-major), c                       nc * n + nc
    base                                   16
    frame  F_k, link  G_k (last * tool)    2 * nc * 16
    lower, upper, seed_lower, seed_upper   4 * n
    wrap                                   n
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

__all__ = ["MAX_JOINTS", "ChainArrays", "chain_arrays"]

MAX_JOINTS = 32  # chain joints and coordinates the kernels take; chain.h MAXJ

F64 = npt.NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class ChainArrays:
    r"""The canonical chain as the compiled kernels read it.

    .. math::

        T(q) = C_0 \, J_1(v_1) C_1 \cdots J_{n_c}(v_{n_c}) C_{n_c}, \qquad
        v = \mathrm{sign} \odot (M q + c) + \mathrm{offset}

    Attributes:
        n_chain: Chain joints ``nc``.
        n: Independent coordinates.
        identity: True when ``q_chain = q`` (no dependent joints).
        consts: ``C_0 = B L_0``, ``C_k = F_k G_k`` (``C_nc`` times the tool),
            shape (nc + 1, 4, 4) [m].
        xform: Per constant ``[1, cos a, sin a, tx, ty, tz]`` when it is
            ``Trans(t) Rx(a)`` (every DH row's is), else zeros; (nc + 1, 6).
        kind: 1.0 for a prismatic chain joint, 0.0 for a revolute one; (nc,).
        sign: +1 or -1 per chain joint; (nc,).
        offset: Chain value at zero coordinate [rad or m]; (nc,).
        M: Coupling matrix, (nc, n).
        c: Coupling offset [rad or m], (nc,).
        base: Base transform (4, 4).
        frame: ``F_k``, the link frame after joint k, (nc, 4, 4).
        link: ``G_k`` on to the next joint; the last one carries the tool, (nc, 4, 4).
        lower, upper: Limits of the coordinates [rad or m], (n,).
        seed_lower, seed_upper: Finite range random IK restarts are drawn from:
            the limits where they span at most a turn (revolute) or 2 m
            (prismatic), else a turn / 2 m centred in them, (n,).
        wrap: 1.0 where a whole turn of the coordinate is whole turns of every
            chain joint it drives (it may be shifted by 2 pi), else 0.0; (n,).
        limits: ``[lower, upper]`` as one (n, 2) array.
        is_revolute: (n,) bool: which coordinates are angles.
        packed: Everything above in one vector (layout in the module docstring).
    """

    n_chain: int
    n: int
    identity: bool
    consts: F64
    xform: F64
    kind: F64
    sign: F64
    offset: F64
    M: F64
    c: F64
    base: F64
    frame: F64
    link: F64
    lower: F64
    upper: F64
    seed_lower: F64
    seed_upper: F64
    wrap: F64
    limits: F64
    is_revolute: npt.NDArray[np.bool_]
    packed: F64


def _xform_params(consts: np.ndarray) -> np.ndarray:
    """Per constant ``[1, cos a, sin a, tx, ty, tz]`` when it is ``Trans(t) Rx(a)``."""
    P = np.zeros((consts.shape[0], 6))
    R = consts[:, :3, :3]
    ca, sa = R[:, 1, 1], R[:, 2, 1]
    is_tx = (
        (R[:, 0, 0] == 1.0) & (R[:, 0, 1] == 0.0) & (R[:, 0, 2] == 0.0)
        & (R[:, 1, 0] == 0.0) & (R[:, 2, 0] == 0.0) & (R[:, 1, 2] == -sa)
        & (R[:, 2, 2] == ca)
    )
    P[is_tx] = np.column_stack([np.ones_like(ca), ca, sa, consts[:, :3, 3]])[is_tx]
    return P


def _seed_range(lower: np.ndarray, upper: np.ndarray,
                is_revolute: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Where random restarts are drawn; always finite.

    The limits where they span at most one turn (revolute) or [-1, 1] m
    (prismatic), else one turn / 2 m centred in them (``[-pi, pi]`` or
    ``[-1, 1]`` when that lies inside).
    """
    width = np.where(is_revolute, 2.0 * math.pi, 2.0)
    lo_ok, hi_ok = np.isfinite(lower), np.isfinite(upper)
    lo = np.where(lo_ok, lower, 0.0)
    hi = np.where(hi_ok, upper, 0.0)
    centred = (~lo_ok | (lo <= -0.5 * width)) & (~hi_ok | (hi >= 0.5 * width))
    mid = np.where(lo_ok & hi_ok, 0.5 * (lo + hi),
                   np.where(lo_ok, lo + 0.5 * width, np.where(hi_ok, hi - 0.5 * width, 0.0)))
    mid = np.where(centred, 0.0, mid)
    slo = np.where(lo_ok, np.maximum(lo, mid - 0.5 * width), mid - 0.5 * width)
    shi = np.where(hi_ok, np.minimum(hi, mid + 0.5 * width), mid + 0.5 * width)
    return slo, shi


def _wrap_flags(M: np.ndarray, kind: np.ndarray, is_revolute: np.ndarray) -> np.ndarray:
    """Coordinates whose whole turns are whole turns of every chain joint they drive.

    Coordinate j wraps when it is revolute and every chain joint it drives
    (``M[:, j] != 0``) is revolute with a whole coefficient (``np.allclose``'s test,
    |m - round(m)| <= 1e-8 + 1e-5 |round(m)|, on all of them at once).
    """
    whole = np.round(M)
    near_whole = np.abs(M - whole) <= 1e-8 + 1e-5 * np.abs(whole)
    bad = (M != 0.0) & ((kind != 0.0)[:, None] | ~near_whole)
    wrap: np.ndarray = (np.asarray(is_revolute, dtype=bool) & ~bad.any(axis=0)).astype(
        np.float64)
    return wrap


def _ro(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a, dtype=np.float64)
    a.setflags(write=False)
    return a


def _ro_bool(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a, dtype=bool)
    a.setflags(write=False)
    return a


def chain_arrays(
    *,
    head: np.ndarray,
    frame_offsets: np.ndarray,
    link_offsets: np.ndarray,
    base: np.ndarray,
    tool: np.ndarray,
    kind: np.ndarray,
    sign: np.ndarray,
    offset: np.ndarray,
    M: np.ndarray,
    c: np.ndarray,
    limits: np.ndarray,
    is_revolute: np.ndarray,
    identity: bool,
) -> ChainArrays:
    """The kernel arrays of a canonical chain, from its parts.

    Args:
        head: ``L_0`` (4, 4).
        frame_offsets: ``F_k`` (nc, 4, 4).
        link_offsets: ``G_k`` (nc, 4, 4).
        base: ``B`` (4, 4).
        tool: The tool transform (4, 4).
        kind: 1.0 prismatic, 0.0 revolute per chain joint, (nc,).
        sign: +1 / -1 per chain joint, (nc,).
        offset: Zero offsets [rad or m], (nc,).
        M: Coupling matrix (nc, n).
        c: Coupling offset (nc,).
        limits: Coordinate limits (n, 2) [rad or m].
        is_revolute: (n,) bool per coordinate.
        identity: True when ``q_chain = q``.

    Returns:
        The :class:`ChainArrays`, every array read-only.
    """
    nc, n = kind.shape[0], is_revolute.shape[0]
    consts = np.empty((nc + 1, 4, 4))
    consts[0] = base @ head
    consts[1:] = frame_offsets @ link_offsets
    consts[nc] = consts[nc] @ tool
    link = np.array(link_offsets, dtype=np.float64)
    link[nc - 1] = link[nc - 1] @ tool
    lim = np.asarray(limits, dtype=np.float64).reshape(n, 2)
    seed_lo, seed_hi = _seed_range(lim[:, 0], lim[:, 1], is_revolute)
    parts = {
        "consts": consts, "xform": _xform_params(consts), "kind": kind, "sign": sign,
        "offset": offset, "M": M, "c": c, "base": np.asarray(base),
        "frame": np.asarray(frame_offsets), "link": link,
        "lower": lim[:, 0], "upper": lim[:, 1], "seed_lower": seed_lo,
        "seed_upper": seed_hi, "wrap": _wrap_flags(M, kind, is_revolute),
    }
    packed = _pack(parts, nc, n, identity)
    return ChainArrays(
        n_chain=nc, n=n, identity=identity, packed=_ro(packed), limits=_ro(lim),
        is_revolute=_ro_bool(is_revolute),
        **{k: _ro(v) for k, v in parts.items()},
    )


def _pack(parts: Mapping[str, npt.ArrayLike], nc: int, n: int, identity: bool) -> F64:
    """The sections in ``PACKED_LAYOUT``'s order after the head, each of its shape."""
    # imported here, not by ``import robokin``: _declare declares every kernel (~13 ms)
    from robokin._native._declare import LAYOUT_TAG, PACKED_LAYOUT

    dims = {"nc": nc, "n": n, "nc + 1": nc + 1}
    chunks = [np.array([LAYOUT_TAG, nc, n, float(identity)])]
    if set(parts) != {s.name for s in PACKED_LAYOUT}:  # pragma: no cover - a coding error
        raise RuntimeError(f"chain_arrays: sections {sorted(parts)} differ from PACKED_LAYOUT")
    for section in PACKED_LAYOUT:
        value = np.asarray(parts[section.name], dtype=np.float64)
        shape = tuple(d if isinstance(d, int) else dims[d] for d in section.shape)
        if value.shape != shape:  # pragma: no cover - a coding error
            raise RuntimeError(f"chain_arrays: {section.name} is {value.shape}, not {shape}")
        chunks.append(value.ravel())
    return np.concatenate(chunks)
