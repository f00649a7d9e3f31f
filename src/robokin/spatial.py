"""SE(3) helpers on batches of 4x4 homogeneous transforms.

Every function takes any leading batch shape ``(...)`` and returns the same leading
shape. Angles are radians, lengths metres. Rotation vectors become matrices by
Rodrigues' formula here (numpy only: the 7R self-motion and the Pieper set-up use it,
and a first call should not import scipy); the other rotation conversions go through
``scipy.spatial.transform.Rotation`` (imported lazily). Conventions are listed in
``docs/conventions.md``: RPY is roll about x, then pitch about y, then yaw about z,
all about the fixed (base) axes, i.e. ``R = Rz(yaw) @ Ry(pitch) @ Rx(roll)``;
quaternions are ``(w, x, y, z)``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from robokin._native import kernels
from robokin._validation import _real_array
from robokin.exceptions import InputError

if TYPE_CHECKING:
    from scipy.spatial.transform import Rotation

__all__ = [
    "axis_angle_from_matrix",
    "invert",
    "matrix_from_axis_angle",
    "matrix_from_quaternion",
    "matrix_from_rpy",
    "pose_error",
    "pose_from_xyz_rpy",
    "quaternion_from_matrix",
    "rotation_from_rotvec",
    "rotvec_from_rotation",
    "rotx",
    "roty",
    "rotz",
    "rpy_from_matrix",
    "trans",
    "wrap_angle",
    "xyz_rpy_from_pose",
]


def _rot(angle: npt.ArrayLike, i: int, j: int) -> np.ndarray:
    a = np.asarray(angle, dtype=np.float64)
    T = np.zeros(a.shape + (4, 4))
    c, s = np.cos(a), np.sin(a)
    k = 3 - i - j
    T[..., k, k] = 1.0
    T[..., 3, 3] = 1.0
    T[..., i, i] = c
    T[..., j, j] = c
    T[..., i, j] = -s
    T[..., j, i] = s
    return T


def rotx(angle: npt.ArrayLike) -> np.ndarray:
    """Rotation about x by ``angle`` [rad], shape (...) -> (..., 4, 4)."""
    return _rot(angle, 1, 2)


def roty(angle: npt.ArrayLike) -> np.ndarray:
    """Rotation about y by ``angle`` [rad], shape (...) -> (..., 4, 4)."""
    return _rot(angle, 2, 0)


def rotz(angle: npt.ArrayLike) -> np.ndarray:
    """Rotation about z by ``angle`` [rad], shape (...) -> (..., 4, 4)."""
    return _rot(angle, 0, 1)


def trans(
    x: npt.ArrayLike, y: npt.ArrayLike = 0.0, z: npt.ArrayLike = 0.0
) -> np.ndarray:
    """Pure translation [m].

    Args:
        x: Either the x offset, shape (...), or a vector ``(..., 3)`` when y and z
            are omitted.
        y: The y offset, shape (...).
        z: The z offset, shape (...).

    Returns:
        Transforms of shape (..., 4, 4).
    """
    x = np.asarray(x, dtype=np.float64)
    if (
        x.ndim >= 1
        and x.shape[-1] == 3
        and np.ndim(y) == 0
        and np.ndim(z) == 0
        and (y == 0.0 and z == 0.0)
    ):
        xyz = x
    else:
        xyz = np.stack(
            np.broadcast_arrays(x, np.asarray(y, float), np.asarray(z, float)), -1
        )
    T = np.zeros(xyz.shape[:-1] + (4, 4))
    T[..., 0, 0] = T[..., 1, 1] = T[..., 2, 2] = T[..., 3, 3] = 1.0
    T[..., :3, 3] = xyz
    return T


def invert(T: npt.ArrayLike) -> np.ndarray:
    """Inverse of rigid transforms, (..., 4, 4) -> (..., 4, 4), using R^T."""
    T = np.asarray(T, dtype=np.float64)
    out = np.zeros_like(T)
    Rt = np.swapaxes(T[..., :3, :3], -1, -2)
    out[..., :3, :3] = Rt
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", Rt, T[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out


def _rotation() -> type[Rotation]:
    """The Rotation class of scipy (scipy is imported on first use)."""
    from scipy.spatial.transform import Rotation

    return Rotation


def _from_R(R: np.ndarray) -> np.ndarray:
    T = np.zeros(R.shape[:-2] + (4, 4))
    T[..., :3, :3] = R
    T[..., 3, 3] = 1.0
    return T


def _shaped(x: npt.ArrayLike, name: str, tail: tuple[int, ...]) -> np.ndarray:
    """``x`` as float64 of shape ``(...) + tail``, or an InputError naming ``name``."""
    a = _real_array(x, name, "numbers")
    if a.shape[a.ndim - len(tail):] != tail or a.ndim < len(tail):
        want = ", ".join(map(str, tail))
        raise InputError(name, f"expected shape (..., {want}), got {a.shape}")
    return a


def _apply(fn: Callable[[np.ndarray], Rotation], x: npt.ArrayLike, width: int,
           name: str) -> np.ndarray:
    """Run a scipy Rotation constructor on a batch of any leading shape."""
    x = _shaped(x, name, (width,))
    lead = x.shape[:-1]
    R: np.ndarray = fn(x.reshape(-1, width)).as_matrix().reshape(lead + (3, 3))
    return _from_R(R)


def _as(fn_name: str, T: npt.ArrayLike, **kw: Any) -> np.ndarray:
    T = _shaped(T, "T", (4, 4))
    lead = T.shape[:-2]
    rot = _rotation().from_matrix(T[..., :3, :3].reshape(-1, 3, 3))
    out: np.ndarray = getattr(rot, fn_name)(**kw)
    return out.reshape(lead + out.shape[1:])


def matrix_from_rpy(rpy: npt.ArrayLike) -> np.ndarray:
    """Rotation ``Rz(yaw) Ry(pitch) Rx(roll)`` as a transform; (..., 3) -> (..., 4, 4)."""
    return _apply(lambda x: _rotation().from_euler("xyz", x), rpy, 3, "rpy")


def rpy_from_matrix(T: npt.ArrayLike) -> np.ndarray:
    """Roll, pitch, yaw [rad] of the rotation block; (..., 4, 4) -> (..., 3)."""
    import warnings

    with warnings.catch_warnings():  # gimbal lock: scipy warns and sets roll = 0
        warnings.simplefilter("ignore", UserWarning)
        return _as("as_euler", T, seq="xyz")


def pose_from_xyz_rpy(xyz: npt.ArrayLike, rpy: npt.ArrayLike) -> np.ndarray:
    """Pose from a position [m] (..., 3) and roll-pitch-yaw [rad] (..., 3)."""
    R = matrix_from_rpy(rpy)
    p = np.asarray(xyz, dtype=np.float64)
    T: np.ndarray = np.broadcast_to(
        R, np.broadcast_shapes(R.shape, p.shape[:-1] + (4, 4))).copy()
    T[..., :3, 3] = p
    return T


def xyz_rpy_from_pose(T: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Position (..., 3) [m] and roll-pitch-yaw (..., 3) [rad] of a pose."""
    T = np.asarray(T, dtype=np.float64)
    return T[..., :3, 3].copy(), rpy_from_matrix(T)


def matrix_from_quaternion(wxyz: npt.ArrayLike) -> np.ndarray:
    """Rotation from unit quaternions ``(w, x, y, z)``; (..., 4) -> (..., 4, 4)."""
    return _apply(lambda x: _rotation().from_quat(x[:, [1, 2, 3, 0]]), wxyz, 4, "wxyz")


def quaternion_from_matrix(T: npt.ArrayLike) -> np.ndarray:
    """Unit quaternion ``(w, x, y, z)`` with w >= 0; (..., 4, 4) -> (..., 4)."""
    xyzw = _as("as_quat", T, canonical=True)
    out: np.ndarray = xyzw[..., [3, 0, 1, 2]]
    return out


def matrix_from_axis_angle(rotvec: npt.ArrayLike) -> np.ndarray:
    """Rotation from a rotation vector (axis times angle [rad]); (..., 3) -> (..., 4, 4)."""
    return _from_R(_rodrigues(_shaped(rotvec, "rotvec", (3,))))


def rotvec_from_rotation(R: npt.ArrayLike) -> np.ndarray:
    """Rotation vectors of rotation matrices; (..., 3, 3) -> (..., 3).

    Axis times angle [rad], the angle in [0, pi].
    """
    R = _shaped(R, "R", (3, 3))
    lead = R.shape[:-2]
    if R.size == 0:
        return np.zeros(lead + (3,))
    out: np.ndarray = _rotation().from_matrix(R.reshape(-1, 3, 3)).as_rotvec()
    return out.reshape(lead + (3,))


def rotation_from_rotvec(w: npt.ArrayLike) -> np.ndarray:
    """Rotation matrices of rotation vectors [rad]; (..., 3) -> (..., 3, 3)."""
    return _rodrigues(_shaped(w, "w", (3,)))


def _rodrigues(w: np.ndarray) -> np.ndarray:
    """Rodrigues' formula, (..., 3) -> (..., 3, 3): ``I + a [w]x + b [w]x^2``.

    a = sin(x) / x and b = (1 - cos(x)) / x^2 with x = |w|; b as 2 sin^2(x / 2) / x^2
    (no cancellation); below x = 1e-4 both by their series to x^4 (error below 1e-20).
    """
    x2 = np.einsum("...i,...i->...", w, w)
    x = np.sqrt(x2)
    small = x < 1e-4
    xs = np.where(small, 1.0, x)
    h = np.sin(0.5 * xs) / xs
    a = np.where(small, 1.0 - x2 / 6.0 + x2 * x2 / 120.0, np.sin(xs) / xs)
    b = np.where(small, 0.5 - x2 / 24.0 + x2 * x2 / 720.0, 2.0 * h * h)
    K = np.zeros(w.shape[:-1] + (3, 3))
    K[..., 0, 1], K[..., 0, 2], K[..., 1, 2] = -w[..., 2], w[..., 1], -w[..., 0]
    K[..., 1, 0], K[..., 2, 0], K[..., 2, 1] = w[..., 2], -w[..., 1], w[..., 0]
    R: np.ndarray = np.eye(3) + a[..., None, None] * K + b[..., None, None] * (K @ K)
    return R


def axis_angle_from_matrix(T: npt.ArrayLike) -> np.ndarray:
    """Rotation vector (axis times angle [rad], angle in [0, pi]); (..., 4, 4) -> (..., 3)."""
    return _as("as_rotvec", T)


def wrap_angle(a: npt.ArrayLike) -> np.ndarray:
    """Angles [rad] wrapped into [-pi, pi), same shape."""
    a = np.asarray(a, dtype=np.float64)
    out: np.ndarray = (a + np.pi) % (2.0 * np.pi) - np.pi
    return out


def pose_error(current: npt.ArrayLike, target: npt.ArrayLike) -> np.ndarray:
    """The 6-vector that takes ``current`` to ``target``, both expressed in the base frame.

    Args:
        current: Poses (..., 4, 4).
        target: Poses (..., 4, 4), broadcast against ``current``.

    Returns:
        ``(..., 6)``: position difference ``p_target - p_current`` [m], then the
        rotation vector of ``R_target @ R_current.T`` [rad] (base frame): the
        residual the numeric IK descends on (one compiled formula, ``chain.h``
        ``pose_residual``).
    """
    current = _shaped(current, "current", (4, 4))
    target = _shaped(target, "target", (4, 4))
    try:
        lead = np.broadcast_shapes(current.shape[:-2], target.shape[:-2])
    except ValueError as exc:
        raise InputError("target", f"shape {target.shape} does not broadcast with "
                                   f"current's {current.shape}") from exc
    a = np.ascontiguousarray(np.broadcast_to(current, lead + (4, 4))).reshape(-1, 4, 4)
    b = np.ascontiguousarray(np.broadcast_to(target, lead + (4, 4))).reshape(-1, 4, 4)
    out = np.empty((a.shape[0], 6))
    kernels.pose_error(a, b, out)
    return out.reshape(lead + (6,))
