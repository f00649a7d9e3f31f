"""Input checks shared by the public functions (``check_*`` helpers).

Arrays are converted to float64 only from real numbers: complex values (whose
imaginary part a cast would drop), masked arrays (whose mask a cast would drop),
booleans and text are refused, not silently cast. Arrays the compiled kernels
cannot read as they are (another byte order, an unaligned buffer such as
``np.frombuffer(b, offset=1)``, a strided view) are copied, never refused. Poses are bounded: a
translation beyond :data:`MAX_TRANSLATION` metres is refused, since FK,
Jacobians and IK in float64 lose every digit of a sub-millimetre result there.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from robokin import _native
from robokin._text import short_repr
from robokin.exceptions import InputError

__all__ = [
    "MAX_TRANSLATION",
    "check_broadcasts",
    "check_finite",
    "check_joints",
    "check_nonnegative",
    "check_rigid",
    "check_transform",
    "check_vector",
    "frozen_floats",
]

#: Largest translation accepted in a pose, and largest length in a robot file [m]
#: (1000 km: float64 then still resolves 0.1 nm). The compiled pose check's bound.
MAX_TRANSLATION: float = _native.kernels.MAX_TRANSLATION


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
        out = np.asarray(a, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(name, f"expected {expected}, got {short_repr(x)}") from exc
    # an unaligned buffer (np.frombuffer(b, offset=1)): copied, as other layouts are
    return out if out.flags.aligned else out.copy()


def check_joints(q: npt.ArrayLike, n: int, name: str = "q") -> np.ndarray:
    """Return ``q`` as a float64 array of shape ``(..., n)``; raise InputError if not.

    Finiteness is checked by the caller's compiled kernel where one runs (it is free
    there); use :func:`check_finite` otherwise.

    Raises:
        InputError: not real numbers (complex, masked, boolean or text values
            included), or a shape other than ``(..., n)``.
    """
    if type(q) is not np.ndarray or q.dtype != np.float64 or not q.flags.aligned:
        q = _real_array(q, name, "numbers")
    if q.ndim == 0 or q.shape[-1] != n:
        raise InputError(
            name, f"expected shape (..., {n}) for {n} joints, got {q.shape}"
        )
    return q


def check_broadcasts(x: np.ndarray, target: tuple[int, ...], name: str,
                     what: str = "the targets'") -> np.ndarray:
    """Return ``x`` if it broadcasts to the shape ``target`` without growing it.

    Per-pose arguments (``q_near``, ``q0``, ``q_current``) are read this way: one row
    for every pose, or rows that broadcast over the pose batch.

    Raises:
        InputError: naming ``name``, its shape and ``target`` (described by ``what``).
    """
    try:
        ok = np.broadcast_shapes(x.shape, target) == target
    except ValueError:
        ok = False
    if not ok:
        raise InputError(name, f"shape {x.shape} does not broadcast to {what} {target}")
    return x


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

    The test is the compiled one every IK target passes (``chain.h``
    ``pose_problem``): finite entries, a translation within
    :data:`MAX_TRANSLATION`, a last row ``[0, 0, 0, 1]`` (to 1e-9), an orthonormal
    rotation block (to 1e-6) that is not a reflection.

    Raises:
        InputError: not real numbers, a wrong shape, or the first pose that fails
            the test: what is wrong and the pose's batch index.
    """
    if type(T) is not np.ndarray or T.dtype != np.float64 or not T.flags.aligned:
        T = _real_array(T, name, "a 4x4 matrix")
    if T.ndim < 2 or T.shape[-2:] != (4, 4):
        raise InputError(name, f"expected shape (..., 4, 4), got {T.shape}")
    flat = np.ascontiguousarray(T).reshape(-1, 4, 4)
    code, index = _native.kernels.check_poses(flat, 1e-6)
    if code:
        raise _pose_problem(T, flat[index], name, int(code), int(index))
    return T


#: The fast name IK code uses; the same check.
check_poses_fast = check_transform


#: A rotation block farther than this from orthonormal (largest entry of
#: ``R^T R - I``) is projected onto SO(3) by :func:`check_rigid`; below it the pose
#: is used as given (forward kinematics' own rotations are within ~1e-15).
ROTATION_EXACT = 1e-14
_EYE3 = np.eye(3)


def check_rigid(T: npt.ArrayLike, name: str = "T") -> np.ndarray:
    """``T`` (..., 4, 4) checked as :func:`check_transform`, rotations projected onto SO(3).

    The closed forms that accept a solution only when its pose matches the target
    to ~1e-12 (the held-joint Pieper solver, the self-motion manifold) would find
    nothing for a rotation that is orthonormal to 1e-12 only (a pose written to 12
    digits). Every rotation within the accepted tolerance of one (1e-6, as
    :func:`check_transform`) but more than :data:`ROTATION_EXACT` from orthonormal
    is replaced by the nearest rotation (Frobenius norm: ``U V^T`` of its SVD), so
    those solvers solve the rigid pose nearest the input. Other poses are
    returned unchanged (the same array when nothing needed projecting); the
    input is never modified.

    Args:
        T: Poses (..., 4, 4).
        name: The argument's name in errors.

    Returns:
        float64 (..., 4, 4).

    Raises:
        InputError: as :func:`check_transform` (beyond 1e-6 from a rotation, a
            reflection, ...).
    """
    T = check_transform(T, name)
    if T.ndim == 2:  # one pose (self_motion's): the same test, 3 us faster unbatched
        R = T[:3, :3]
        if not np.abs(R.T @ R - _EYE3).max() > ROTATION_EXACT:
            return T
    R = T.reshape(-1, 4, 4)[:, :3, :3]
    err = np.abs(np.swapaxes(R, -1, -2) @ R - _EYE3).max(axis=(-2, -1))  # R^T R - I
    off = err > ROTATION_EXACT
    if not off.any():
        return T
    out = np.array(T, dtype=np.float64, copy=True)
    flat = out.reshape(-1, 4, 4)
    U, _, Vt = np.linalg.svd(flat[off, :3, :3])
    flat[off, :3, :3] = U @ Vt  # det +1: check_transform refused reflections
    return out


def _pose_problem(T: np.ndarray, pose: np.ndarray, name: str, code: int,
                  index: int) -> InputError:
    """The error for the pose at flat ``index`` that failed with ``code``."""
    where = np.unravel_index(index, T.shape[:-2]) if T.ndim > 2 else ()
    at = f" (pose {tuple(int(i) for i in where)})" if where else ""
    if code == 1:
        check_finite(T, name)  # raises, naming the entry
    if code == 5:
        worst = float(np.abs(pose[:3, 3]).max())
        return InputError(name, f"translation {worst:.3g} m is beyond the "
                                f"{MAX_TRANSLATION:g} m robokin accepts{at}")
    if code == 3:
        R = pose[:3, :3]
        err = float(np.abs(R @ R.T - np.eye(3)).max())
        return InputError(name, f"rotation block is not orthonormal (error {err:.2e}, "
                                f"tolerance 1e-6){at}")
    return InputError(name, _POSE_PROBLEMS[code] + at)


_POSE_PROBLEMS = {
    1: "holds a non-finite value",
    2: "the last row of a homogeneous transform must be 0 0 0 1",
    4: "rotation block is a reflection (determinant -1)",
}


def check_vector(x: npt.ArrayLike, size: int, name: str) -> np.ndarray:
    """Return ``x`` as float64 of shape ``(..., size)``, finite; raise InputError if not."""
    x = _real_array(x, name, "numbers")
    if x.ndim == 0 or x.shape[-1] != size:
        raise InputError(name, f"expected shape (..., {size}), got {x.shape}")
    return check_finite(x, name)


def check_finite_number(x: object, name: str) -> float:
    """Return ``x`` as a float: one finite real number; raise InputError if not.

    Python and NumPy integers and floats (a 0-d array too) are accepted;
    booleans, complex numbers, text, arrays of more than one value, NaN and
    infinities are refused.

    Raises:
        InputError: naming ``name``.
    """
    a = None
    if not isinstance(x, (bool, np.bool_)) and not np.ma.isMaskedArray(x):
        try:
            a = np.asarray(x)
        except (TypeError, ValueError):
            a = None
    if a is None or a.ndim != 0 or a.dtype.kind not in "fiu":
        raise InputError(name, f"expected a finite number, got {short_repr(x)}")
    v = float(a)
    if not np.isfinite(v):
        raise InputError(name, f"expected a finite number, got {v}")
    return v


def check_nonnegative(x: object, name: str, expected: str) -> float:
    """Return ``x`` as a float: a finite Python number >= 0; raise InputError if not.

    Args:
        x: The value (an ``int`` or ``float``; NumPy scalars of those kinds too).
        name: The argument named in the error.
        expected: What the message says was expected, e.g. ``"a distance >= 0 [mm]"``.

    Raises:
        InputError: ``"expected {expected}, got {x}"``, naming ``name``.
    """
    if not (isinstance(x, int | float) and math.isfinite(x) and x >= 0):
        raise InputError(name, f"expected {expected}, got {short_repr(x)}")
    return float(x)


def frozen_floats(a: npt.ArrayLike, name: str, *, ndim: int | None = None,
                  shape: tuple[int, ...] | None = None) -> npt.NDArray[np.float64]:
    """A read-only float64 copy of ``a``, of ``ndim`` dimensions or of ``shape``.

    Args:
        a: The values.
        name: The argument (or field) named in the error.
        ndim: The number of dimensions required, or None.
        shape: The shape required, or None; with a shape the values must be finite.

    Raises:
        InputError: the wrong dimensions or shape, or non-finite values with
            ``shape``, naming ``name``.
    """
    arr = np.array(a, dtype=np.float64)
    if ndim is not None and arr.ndim != ndim:
        raise InputError(name, f"expected {ndim} dimensions, got shape {arr.shape}")
    if shape is not None and (arr.shape != shape or not np.isfinite(arr).all()):
        raise InputError(name, f"expected finite values of shape {shape}, got {arr.shape}")
    arr.setflags(write=False)
    return arr
