"""Batch forward kinematics on the canonical chain.

``q`` has shape ``(..., n)`` (independent joint coordinates, SI units); results keep
the leading shape. The arithmetic is the compiled chain product of
``robokin/_native/csrc/chain.h``.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from robokin import _native
from robokin._native import kernels as _k
from robokin._validation import check_finite, check_joints
from robokin.exceptions import InputError
from robokin.model.chain import Chain

__all__ = ["forward_kinematics", "forward_kinematics_all", "link_frames"]

# fk1(q, packed) -> (4, 4) pose, or None for the general path; the copy that serves
# one configuration fastest (robokin._native.single), bit-identical to the batch's
fk_single = _native.single.fk1


def chain_batch(chain: Chain, q: npt.ArrayLike, name: str) -> tuple[np.ndarray, np.ndarray]:
    """``q`` checked (float64, (..., n)) and as a C-contiguous (N, n) batch."""
    q = check_joints(q, chain.n, name)
    return q, np.ascontiguousarray(q.reshape(-1, chain.n))


def raise_nonfinite(q: np.ndarray, name: str) -> None:
    """Raise the InputError for a batch whose kernel reported a non-finite value."""
    check_finite(q, name)
    raise InputError(
        name, "produced a non-finite chain joint value"
    )  # pragma: no cover


def forward_kinematics(
    chain: Chain, q: npt.ArrayLike, *, name: str = "q"
) -> np.ndarray:
    """Tool pose in the world frame.

    Args:
        chain: The canonical chain.
        q: Joint coordinates [rad or m], shape (..., n).
        name: The argument name used in error messages.

    Returns:
        Poses (..., 4, 4) [m].

    Raises:
        InputError: wrong shape or a non-finite value.
    """
    T = fk_single(q, chain.arrays.packed)
    if T is not None:
        return T
    q, flat = chain_batch(chain, q, name)
    out = np.empty((flat.shape[0], 4, 4))
    if not _k.fk(chain.arrays.packed, flat, out):
        raise_nonfinite(q, name)
    return out.reshape(q.shape[:-1] + (4, 4))


def link_frames(chain: Chain, q: npt.ArrayLike, *, name: str = "q") -> np.ndarray:
    """Base, every link frame and the tool pose: (..., n_chain + 2, 4, 4)."""
    q, flat = chain_batch(chain, q, name)
    nc = chain.n_chain
    out = np.empty((flat.shape[0], nc + 2, 4, 4))
    if not _k.frames(chain.arrays.packed, flat, out):
        raise_nonfinite(q, name)
    return out.reshape(q.shape[:-1] + (nc + 2, 4, 4))


def forward_kinematics_all(
    chain: Chain, q: npt.ArrayLike, *, name: str = "q"
) -> np.ndarray:
    """The base frame, then the link frame of every chain joint.

    Args:
        chain: The canonical chain.
        q: Joint coordinates, shape (..., n).
        name: The argument name used in error messages.

    Returns:
        Frames (..., n_chain + 1, 4, 4). For arms without dependent joints
        ``n_chain == n``. The tool pose is :func:`forward_kinematics`.
    """
    return link_frames(chain, q, name=name)[..., :-1, :, :]
