"""Affine joint maps: dependent chain joints and actuator (motor) coordinates.

Both are the same object, ``y = A @ x + b``:

* dependent joints: ``q_chain = M @ q + c`` maps the robot's independent joint
  coordinates ``q`` (n) to the values of every chain joint (n_chain);
* actuators: ``q = A @ phi + b`` maps motor coordinates ``phi`` (m) to joint
  coordinates ``q`` (n).

See ``docs/conventions.md``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from robokin.exceptions import ModelError

__all__ = ["AffineMap"]


def _frozen(a: npt.ArrayLike, ndim: int, name: str) -> np.ndarray:
    arr = np.array(a, dtype=np.float64)
    if arr.ndim != ndim:
        raise ModelError(f"{name} must have {ndim} dimensions, got shape {arr.shape}")
    if not np.isfinite(arr).all():
        raise ModelError(f"{name} holds a non-finite value")
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True, eq=False)
class AffineMap:
    """The affine map ``y = matrix @ x + offset``.

    Attributes:
        matrix: Shape (n_out, n_in).
        offset: Shape (n_out,).
    """

    matrix: np.ndarray
    offset: np.ndarray
    is_identity: bool = field(init=False)

    def __post_init__(self) -> None:
        A = _frozen(self.matrix, 2, "matrix")
        b = _frozen(self.offset, 1, "offset")
        if b.shape[0] != A.shape[0]:
            raise ModelError(
                f"offset has {b.shape[0]} entries but the matrix has {A.shape[0]} rows"
            )
        object.__setattr__(self, "matrix", A)
        object.__setattr__(self, "offset", b)
        ident = A.shape[0] == A.shape[1] and np.array_equal(A, np.eye(A.shape[0])) and not b.any()
        object.__setattr__(self, "is_identity", bool(ident))

    @classmethod
    def identity(cls, n: int) -> AffineMap:
        """The identity map on n coordinates."""
        return cls(np.eye(n), np.zeros(n))

    @property
    def n_in(self) -> int:
        """Number of input coordinates."""
        return self.matrix.shape[1]

    @property
    def n_out(self) -> int:
        """Number of output coordinates."""
        return self.matrix.shape[0]

    def apply(self, x: np.ndarray) -> np.ndarray:
        """Map inputs ``(..., n_in)`` to outputs ``(..., n_out)``."""
        if self.is_identity:
            return x
        return x @ self.matrix.T + self.offset

    def apply_rate(self, xd: np.ndarray) -> np.ndarray:
        """Map velocities or accelerations (the offset drops out)."""
        if self.is_identity:
            return xd
        return xd @ self.matrix.T

    def inverse(self, y: np.ndarray, *, what: str = "map") -> np.ndarray:
        """Solve ``matrix @ x + offset = y`` for x, ``(..., n_out) -> (..., n_in)``.

        Raises:
            ModelError: the matrix has no left inverse (rank below n_in), naming ``what``.
        """
        if self.is_identity:
            return y
        return (y - self.offset) @ self.pseudo_inverse(what=what).T

    def pseudo_inverse(self, *, what: str = "map") -> np.ndarray:
        """The left inverse ``(n_in, n_out)``; raises ModelError when rank-deficient."""
        A = self.matrix
        if np.linalg.matrix_rank(A) < A.shape[1]:
            raise ModelError(
                f"the {what} matrix (shape {A.shape}) has rank "
                f"{np.linalg.matrix_rank(A)} < {A.shape[1]}: it cannot be inverted"
            )
        return np.linalg.pinv(A)
