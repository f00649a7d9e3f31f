"""What the numeric solver returns: :class:`IKResult`, :class:`IKPathResult`.

:func:`ik_result` turns the compiled solver's rows (``csrc/lm.c``: q, then the
result columns ``K.R_*``) into an :class:`IKResult`, with the reason of every
target that was not reached.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from robokin import _native

__all__ = ["IKPathResult", "IKResult", "ik_result"]

K = _native.kernels  # result columns and codes

@dataclass(frozen=True, eq=False)
class IKResult:
    """The outcome of :func:`solve` for a batch of targets of leading shape (...).

    Attributes:
        q: Joint coordinates [rad, m], shape (..., n): the solution where
            ``success``, else the best configuration found (always within limits).
        success: (...) bool, converged to the tolerance.
        error: (...) final residual [m, rad]: the norm of the selected task error
            rows (position and rotation together).
        position_error: (...) norm of the selected position rows [m].
        rotation_error: (...) norm of the selected rotation rows [rad].
        iterations: (...) int, iterations used over all attempts.
        restarts: (...) int, restarts used (seed-table and random).
        reason: (...) str, ``"converged"`` or why not (with the error reached).

    For a single target (``T`` of shape (4, 4)) the fields are scalars (``q`` is
    (n,), ``reason`` a str, ``iterations`` an int).
    """

    q: npt.NDArray[np.float64]
    success: npt.NDArray[np.bool_] | np.bool_
    error: npt.NDArray[np.float64] | float
    iterations: npt.NDArray[np.int64] | int
    restarts: npt.NDArray[np.int64] | int
    reason: npt.NDArray[np.object_] | str
    position_error: npt.NDArray[np.float64] | float
    rotation_error: npt.NDArray[np.float64] | float

    def __bool__(self) -> bool:
        """True when every target converged."""
        return bool(np.all(self.success))


@dataclass(frozen=True, eq=False)
class IKPathResult:
    """The outcome of :func:`ik_path` for a path of m poses.

    Attributes:
        q: Joint path (m, n) [rad, m]; after ``first_failure`` the rows repeat the
            last good configuration.
        success: (m,) bool.
        error: (m,) residual reached per sample [m, rad] (inf where not run).
        first_failure: Index of the first failed sample, or None.
        reason: ``"converged"`` or why the path stops.
    """

    q: np.ndarray
    success: np.ndarray
    error: np.ndarray
    first_failure: int | None
    reason: str

    def __bool__(self) -> bool:
        """True when every sample converged."""
        return self.first_failure is None


def ik_result(out: np.ndarray, lead: tuple[int, ...], n: int,
              timed_out: np.ndarray | None) -> IKResult:
    """The :class:`IKResult` of the solver's rows ``out`` (N, n + K.N_RES).

    Args:
        out: Per target: q (n), then the result columns (``K.R_*``).
        lead: The targets' leading shape (``()`` for one pose: scalar fields).
        n: Number of joint coordinates.
        timed_out: (N,) bool, targets stopped by the time budget, or None.
    """
    if not lead and out[0, n + K.R_CODE] == K.CODE_OK:
        row = out[0, n:].tolist()
        return IKResult(
            q=out[0, :n], success=np.True_, error=row[K.R_ERR],
            iterations=int(row[K.R_ITERS]), restarts=int(row[K.R_RESTARTS]),
            reason="converged", position_error=row[K.R_EP], rotation_error=row[K.R_ER],
        )
    code = out[:, n + K.R_CODE]
    success = code == K.CODE_OK
    reason = np.empty(out.shape[0], dtype=object)
    reason[:] = "converged"
    for i in np.flatnonzero(~success):
        why = ("time budget exhausted" if timed_out is not None and timed_out[i] else
               "restart budget exhausted")
        last = "stalled in a local minimum or at joint limits" \
            if code[i] == K.CODE_STALL else "iteration budget of the last descent spent"
        reason[i] = (
            f"not converged: error {out[i, n + K.R_ERR]:.3g} (position "
            f"{out[i, n + K.R_EP]:.3g} m, rotation {out[i, n + K.R_ER]:.3g} rad) after "
            f"{int(out[i, n + K.R_RESTARTS])} restart(s); {why} ({last})"
        )
    if not lead:
        row = out[0, n:].tolist()
        return IKResult(
            q=out[0, :n], success=np.bool_(success[0]), error=row[K.R_ERR],
            iterations=int(row[K.R_ITERS]), restarts=int(row[K.R_RESTARTS]),
            reason=reason[0], position_error=row[K.R_EP], rotation_error=row[K.R_ER],
        )
    return IKResult(
        q=out[:, :n].reshape(lead + (n,)),
        success=success.reshape(lead),
        error=out[:, n + K.R_ERR].reshape(lead),
        iterations=out[:, n + K.R_ITERS].astype(np.int64).reshape(lead),
        restarts=out[:, n + K.R_RESTARTS].astype(np.int64).reshape(lead),
        reason=reason.reshape(lead),
        position_error=out[:, n + K.R_EP].reshape(lead),
        rotation_error=out[:, n + K.R_ER].reshape(lead),
    )
