"""Geometric Jacobians, manipulability and singularity tests.

A Jacobian has shape ``(..., 6, n)``: rows ``[v; w]`` (linear velocity of the tool
point [m/s], then angular velocity [rad/s]) per unit joint rate, columns the robot's
independent coordinates (dependent joints folded in through ``M``).
"""

from __future__ import annotations

from typing import Literal

import numpy as np
import numpy.typing as npt

from robokin._native import kernels as _k
from robokin.exceptions import InputError
from robokin.kinematics.forward import chain_batch, raise_nonfinite
from robokin.model.chain import Chain

__all__ = [
    "jacobian",
    "jacobian_and_pose",
    "is_singular",
    "manipulability",
    "min_singular_value",
]


def jacobian_and_pose(
    chain: Chain, q: npt.ArrayLike, *, name: str = "q"
) -> tuple[np.ndarray, np.ndarray]:
    """Base-frame Jacobian (..., 6, n) and tool pose (..., 4, 4) in one pass."""
    q, flat = chain_batch(chain, q, name)
    N = flat.shape[0]
    J = np.empty((N, 6, chain.n))
    T = np.empty((N, 4, 4))
    if not _k.jacobian(chain.arrays.packed, flat, J, T):
        raise_nonfinite(q, name)
    lead = q.shape[:-1]
    return J.reshape(lead + (6, chain.n)), T.reshape(lead + (4, 4))


def jacobian(
    chain: Chain,
    q: npt.ArrayLike,
    *,
    frame: Literal["base", "tool"] = "base",
    name: str = "q",
) -> np.ndarray:
    """Geometric Jacobian of the tool point.

    Args:
        chain: The canonical chain.
        q: Joint coordinates, shape (..., n).
        frame: ``"base"``: velocities in base (world) coordinates; ``"tool"``: the
            same velocities expressed in the tool frame.
        name: The argument name used in error messages.

    Returns:
        Shape (..., 6, n).
    """
    if frame not in ("base", "tool"):
        raise InputError("frame", f"expected 'base' or 'tool', got {frame!r}")
    J, T = jacobian_and_pose(chain, q, name=name)
    if frame == "tool":
        Rt = np.swapaxes(T[..., :3, :3], -1, -2)
        J = np.concatenate([Rt @ J[..., :3, :], Rt @ J[..., 3:, :]], axis=-2)
    return J


def manipulability(
    chain: Chain, q: npt.ArrayLike, *, method: Literal["svd", "det"] = "svd"
) -> np.ndarray:
    r"""Yoshikawa's manipulability of configurations q.

    .. math::

        w = \sqrt{\det(J J^T)} \quad (n \ge 6), \qquad
        w = \sqrt{\det(J^T J)} \quad (n < 6)

    (Yoshikawa, "Manipulability of robotic mechanisms", IJRR 4(2), 1985, eq. 9).

    Args:
        chain: The canonical chain.
        q: Joint coordinates [rad, m], shape (..., n).
        method: ``"svd"`` (default): the product of the ``min(6, n)``
            singular values of the Jacobian, which for n != 6 never forms
            ``J^T J`` or ``J J^T`` (whose determinant loses digits: the
            condition number squared). ``"det"``: ``|det J|`` for a square
            Jacobian (n = 6), one LU per matrix instead of an SVD; equal to the
            SVD product to rounding relative to the largest singular values
            (near a singularity both are noise of order 1e-16 of them). For
            n != 6 ``"det"`` falls back to the SVD product.

    Returns:
        Shape (...).

    Raises:
        InputError: an unknown ``method``.
    """
    if method not in ("svd", "det"):
        raise InputError("method", f"expected 'svd' or 'det', got {method!r}")
    J = jacobian(chain, q)
    if method == "det" and J.shape[-1] == 6:
        return np.abs(np.linalg.det(J))
    return np.prod(np.linalg.svd(J, compute_uv=False), axis=-1)


def min_singular_value(chain: Chain, q: npt.ArrayLike) -> np.ndarray:
    """Smallest singular value of the Jacobian, (...)."""
    return np.linalg.svd(jacobian(chain, q), compute_uv=False)[..., -1]


def is_singular(chain: Chain, q: npt.ArrayLike, tol: float = 1e-6) -> np.ndarray:
    """True where the Jacobian loses rank: smallest singular value below ``tol``, (...).

    Uses ``min(6, n)`` singular values, so a 4-axis arm is singular only when it
    loses one of its own degrees of freedom.
    """
    return min_singular_value(chain, q) < tol
