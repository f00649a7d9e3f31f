"""Input checks shared by the public functions (``check_*`` helpers).

Arrays are converted to float64 only from real numbers: complex values (whose
imaginary part a cast would drop), masked arrays (whose mask a cast would drop),
booleans and text are refused, not silently cast. Poses are bounded: a
translation beyond :data:`MAX_TRANSLATION` metres is refused, since FK,
Jacobians and IK in float64 lose every digit of a sub-millimetre result there.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from robokin._text import short_repr
from robokin.exceptions import InputError

__all__ = [
    "MAX_TRANSLATION",
    "check_finite",
    "check_joints",
    "check_pose_magnitude",
    "check_transform",
    "check_vector",
]

#: Largest translation accepted in a pose, and largest length in a robot file [m].
#: (1000 km: float64 then still resolves 0.1 nm.)
MAX_TRANSLATION = 1.0e6


def _real_array(x: npt.ArrayLike, name: str, expected: str) -> np.ndarray:
    """``x`` as float64, refusing what a cast would silently change."""
    if np.ma.isMaskedArray(x):
        raise InputError(name, "a masked array: fill or drop the masked values "
                         "first (robokin does not ignore a mask)")
    try:
        a = np.asarray(x)
    except (TypeError, ValueError) as exc:
        raise InputError(name, f"expected {expected}, got {short_repr(x)}") from exc
    kind = a.dtype.kind
    if kind == "c":
        raise InputError(name, f"expected real numbers, got complex values "
                         f"({a.dtype})")
    if kind not in "fiuO":
        raise InputError(name, f"expected {expected}, got {a.dtype} values "
                         f"({short_repr(x)})")
    if kind == "O" and not all(isinstance(v, (int, float, np.integer, np.floating))
                               and not isinstance(v, (bool, np.bool_))
                               for v in a.flat):
        # None would become NaN, a bool 1.0, a complex number lose its imaginary part
        raise InputError(name, f"expected {expected}, got {short_repr(x)}")
    try:
        return np.asarray(a, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(name, f"expected {expected}, got {short_repr(x)}") from exc


def check_joints(q: npt.ArrayLike, n: int, name: str = "q") -> np.ndarray:
    """Return ``q`` as a float64 array of shape ``(..., n)``; raise InputError if not.

    Finiteness is checked by the caller's compiled kernel where one runs (it is free
    there); use :func:`check_finite` otherwise.

    Raises:
        InputError: not real numbers (complex, masked, boolean or text values
            included), or a shape other than ``(..., n)``.
    """
    if type(q) is not np.ndarray or q.dtype != np.float64:
        q = _real_array(q, name, "numbers")
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
        InputError: not real numbers, wrong shape, non-finite entries, a
            translation beyond :data:`MAX_TRANSLATION`, a last row other than
            ``[0, 0, 0, 1]``, or a rotation block that is not orthonormal (1e-6).
    """
    T = _real_array(T, name, "a 4x4 matrix")
    if T.ndim < 2 or T.shape[-2:] != (4, 4):
        raise InputError(name, f"expected shape (..., 4, 4), got {T.shape}")
    check_finite(T, name)
    check_pose_magnitude(T, name)
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
        T = _real_array(T, name, "a 4x4 matrix")
    if T.ndim < 2 or T.shape[-2:] != (4, 4):
        raise InputError(name, f"expected shape (..., 4, 4), got {T.shape}")
    from robokin._native import kernels

    flat = np.ascontiguousarray(T).reshape(-1, 4, 4)
    code, index = kernels.check_poses(flat, 1e-6)
    if code:
        where = np.unravel_index(index, T.shape[:-2]) if T.ndim > 2 else ()
        at = f" (pose {tuple(int(i) for i in where)})" if where else ""
        raise InputError(name, _POSE_PROBLEMS[int(code)] + at)
    return check_pose_magnitude(T, name)


def check_pose_magnitude(T: np.ndarray, name: str = "T") -> np.ndarray:
    """Refuse a pose (..., 4, 4) whose translation is finite but beyond
    :data:`MAX_TRANSLATION` [m]; returns ``T`` (NaN and infinity are left to the
    finiteness checks, which name them as such).

    Cheap on one pose (three Python floats), so it runs before the compiled
    single-pose IK.

    Raises:
        InputError: naming ``name``, the value, the bound and the pose's index.
    """
    if T.shape == (4, 4):
        worst = max(abs(v) if abs(v) != math.inf else 0.0 for v in T[:3, 3].tolist())
        if worst > MAX_TRANSLATION:
            raise InputError(name, f"translation {worst:.3g} m is beyond the "
                             f"{MAX_TRANSLATION:g} m robokin accepts")
        return T
    t = np.abs(T[..., :3, 3])
    bad = (t > MAX_TRANSLATION) & np.isfinite(t)
    if bad.any():
        idx = tuple(int(i) for i in np.argwhere(bad)[0][:-1])
        at = f" (pose {idx})" if idx else ""
        raise InputError(name, f"translation {float(t[bad].max()):.3g} m is beyond "
                         f"the {MAX_TRANSLATION:g} m robokin accepts{at}")
    return T


def check_vector(x: npt.ArrayLike, size: int, name: str) -> np.ndarray:
    """Return ``x`` as float64 of shape ``(..., size)``, finite; raise InputError if not."""
    x = _real_array(x, name, "numbers")
    if x.ndim == 0 or x.shape[-1] != size:
        raise InputError(name, f"expected shape (..., {size}), got {x.shape}")
    return check_finite(x, name)
