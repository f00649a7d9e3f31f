"""Input checks shared by the public functions (``check_*`` helpers)."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from robokin.exceptions import InputError

__all__ = ["check_finite", "check_joints", "check_transform", "check_vector"]


def check_joints(q: npt.ArrayLike, n: int, name: str = "q") -> np.ndarray:
    """Return ``q`` as a float64 array of shape ``(..., n)``; raise InputError if not.

    Finiteness is checked by the caller's compiled kernel where one runs (it is free
    there); use :func:`check_finite` otherwise.
    """
    if type(q) is not np.ndarray or q.dtype != np.float64:
        try:
            q = np.asarray(q, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise InputError(name, f"expected numbers, got {q!r:.80}") from exc
    if q.ndim == 0 or q.shape[-1] != n:
        raise InputError(
            name, f"expected shape (..., {n}) for {n} joints, got {q.shape}"
        )
    return q


def check_finite(x: np.ndarray, name: str) -> np.ndarray:
    """Raise InputError naming ``name`` if ``x`` holds NaN or infinity."""
    if not np.isfinite(x).all():
        bad = np.argwhere(~np.isfinite(x))[0]
        raise InputError(
            name, f"holds a non-finite value at index {tuple(int(i) for i in bad)}"
        )
    return x


def check_transform(T: npt.ArrayLike, name: str = "T") -> np.ndarray:
    """Return ``T`` as a float64 array of shape ``(..., 4, 4)`` holding rigid transforms.

    Raises:
        InputError: wrong shape, non-finite entries, a last row other than
            ``[0, 0, 0, 1]``, or a rotation block that is not orthonormal (1e-6).
    """
    try:
        T = np.asarray(T, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(name, f"expected a 4x4 matrix, got {T!r:.80}") from exc
    if T.ndim < 2 or T.shape[-2:] != (4, 4):
        raise InputError(name, f"expected shape (..., 4, 4), got {T.shape}")
    check_finite(T, name)
    if not np.allclose(T[..., 3, :], [0.0, 0.0, 0.0, 1.0], atol=1e-9):
        raise InputError(
            name, "the last row of a homogeneous transform must be 0 0 0 1"
        )
    R = T[..., :3, :3]
    err = np.abs(R @ np.swapaxes(R, -1, -2) - np.eye(3)).max(initial=0.0)
    if err > 1e-6:
        raise InputError(name, f"rotation block is not orthonormal (error {err:.2e})")
    if (np.linalg.det(R) < 0).any():
        raise InputError(name, "rotation block is a reflection (determinant -1)")
    return T


_POSE_PROBLEMS = {
    1: "holds a non-finite value",
    2: "the last row of a homogeneous transform must be 0 0 0 1",
    3: "rotation block is not orthonormal (tolerance 1e-6)",
    4: "rotation block is a reflection (determinant -1)",
}


def check_poses_fast(T: npt.ArrayLike, name: str = "T") -> np.ndarray:
    """:func:`check_transform` through a compiled kernel, for hot paths (IK).

    Same checks and error messages (naming the offending pose's batch index), at a
    fraction of the cost for small batches.
    """
    if type(T) is not np.ndarray or T.dtype != np.float64:
        try:
            T = np.asarray(T, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise InputError(name, f"expected a 4x4 matrix, got {T!r:.80}") from exc
    if T.ndim < 2 or T.shape[-2:] != (4, 4):
        raise InputError(name, f"expected shape (..., 4, 4), got {T.shape}")
    from robokin._native import kernels

    flat = np.ascontiguousarray(T).reshape(-1, 4, 4)
    code, index = kernels.check_poses(flat, 1e-6)
    if code:
        where = np.unravel_index(index, T.shape[:-2]) if T.ndim > 2 else ()
        at = f" (pose {tuple(int(i) for i in where)})" if where else ""
        raise InputError(name, _POSE_PROBLEMS[int(code)] + at)
    return T


def check_vector(x: npt.ArrayLike, size: int, name: str) -> np.ndarray:
    """Return ``x`` as float64 of shape ``(..., size)``, finite; raise InputError if not."""
    try:
        x = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(name, f"expected numbers, got {x!r:.80}") from exc
    if x.ndim == 0 or x.shape[-1] != size:
        raise InputError(name, f"expected shape (..., {size}), got {x.shape}")
    return check_finite(x, name)
