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
from robokin._validation import check_joints
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
    chain: Chain,
    q: npt.ArrayLike,
    *,
    method: Literal["svd", "det"] = "svd",
    where: npt.ArrayLike | None = None,
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
            Jacobian (n = 6), computed in compiled code with the Jacobian
            (``_native/csrc/manipulability.c``: no Jacobian is stored, about
            40 ns a configuration on one core against 400 ns for a stored
            Jacobian and a LAPACK determinant); equal to the SVD product to
            rounding relative to the largest singular values (near a
            singularity both are noise of order 1e-16 of them). ``|det J|``
            does not depend on the frame the Jacobian is expressed in nor on
            its reference point, so it is the manipulability of the arm, not
            of one tool frame. For n != 6 ``"det"`` falls back to the SVD
            product.
        where: Which configurations to compute, a bool mask of shape (...)
            (e.g. an IK solution set's ``valid & within_limits``); the others
            get 0 and are not read (they may be NaN). Default: all.

    Returns:
        Shape (...).

    Raises:
        InputError: an unknown ``method``, a ``where`` of another shape, or a
            non-finite value in a selected configuration.
    """
    if method not in ("svd", "det"):
        raise InputError("method", f"expected 'svd' or 'det', got {method!r}")
    q = check_joints(q, chain.n, "q")
    lead = q.shape[:-1]
    mask = None
    if where is not None:
        mask = np.asarray(where)
        if mask.dtype != np.bool_ or mask.shape != lead:
            raise InputError("where", f"expected a bool mask of shape {lead}, got "
                             f"{mask.dtype} {mask.shape}")
    if method == "det" and chain.n == 6:
        flat = np.ascontiguousarray(q.reshape(-1, 6))
        m = np.ones(flat.shape[0], dtype=bool) if mask is None else \
            np.ascontiguousarray(mask.reshape(-1))
        out = np.empty(flat.shape[0])
        if not _k.abs_det_jacobian(chain.arrays.packed, flat, m, out):
            bad = np.argwhere(~np.isfinite(q) & (True if mask is None else mask[..., None]))
            if bad.size == 0:  # pragma: no cover - finite q, overflowing joint values
                raise InputError("q", "produced a non-finite chain joint value")
            at = tuple(int(i) for i in bad[0])
            raise InputError("q", f"holds a non-finite value at index {at}")
        return out.reshape(lead)
    if mask is None:
        w: np.ndarray = np.prod(np.linalg.svd(jacobian(chain, q), compute_uv=False), axis=-1)
        return w
    out = np.zeros(lead)
    if mask.any():
        J = jacobian(chain, q[mask])
        out[mask] = np.prod(np.linalg.svd(J, compute_uv=False), axis=-1)
    return out


def min_singular_value(chain: Chain, q: npt.ArrayLike) -> np.ndarray:
    """Smallest singular value of the Jacobian, (...)."""
    return np.linalg.svd(jacobian(chain, q), compute_uv=False)[..., -1]


def is_singular(chain: Chain, q: npt.ArrayLike, tol: float = 1e-6) -> np.ndarray:
    """True where the Jacobian loses rank: smallest singular value below ``tol``, (...).

    Uses ``min(6, n)`` singular values, so a 4-axis arm is singular only when it
    loses one of its own degrees of freedom.
    """
    return min_singular_value(chain, q) < tol
