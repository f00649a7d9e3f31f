"""Helpers shared by the closed-form families: joint wrapping, set assembly, errors."""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from robokin._native import kernels as _K
from robokin.kinematics.arm import Arm
from robokin.kinematics.ik.solutions import SolutionSet
from robokin.model.chain import Chain
from robokin.spatial import wrap_angle

__all__ = ["STATUS_TEXT", "fit_turns", "fk_error", "make_set", "q_near_rows",
           "read_only_joint_data"]

# Status code -> text. Codes 0-2 are those the 6R kernels return (csrc/six_r.c);
# the SCARA and palletizer closed forms use them too. 3: palletizer, 4: near.polish,
# 5: general_6r (csrc/general6r.c).
_STATUS = {
    _K.STATUS_OK: "ok",
    _K.STATUS_OUT_OF_REACH: "out of reach",
    _K.STATUS_NO_ORIENTATION: "orientation not achievable",
    3: "not reachable: tool cannot tilt",
    4: "near-family Newton polish did not converge",
    5: "no solution: the general 6R elimination is degenerate at this pose",
}
STATUS_TEXT = np.array([_STATUS[k] for k in range(len(_STATUS))], dtype=object)


def fit_turns(q: np.ndarray, is_revolute: np.ndarray, limits: np.ndarray) -> np.ndarray:
    """Revolute values wrapped into [-pi, pi), then by the wrap-into-limits rule.

    The rule is the compiled one (kernel ``wrap_into``, docs/conventions.md "Joint
    values and limits"): a value within its limits up to 1e-9 stays, else it moves
    by the fewest whole turns that bring it within them, else it stays wrapped.
    Prismatic values are left alone.

    Args:
        q: Joint coordinates [rad, m], shape (..., n).
        is_revolute: Which joints are revolute, shape (n,).
        limits: Joint limits [rad, m], shape (n, 2).

    Returns:
        The coordinates, shape (..., n).
    """
    w = np.ascontiguousarray(wrap_angle(np.asarray(q, dtype=np.float64)))
    lo = np.ascontiguousarray(np.broadcast_to(limits[:, 0], w.shape), dtype=np.float64)
    hi = np.ascontiguousarray(np.broadcast_to(limits[:, 1], w.shape), dtype=np.float64)
    out = np.empty(w.shape)
    _K.wrap_into(w.reshape(-1), lo.reshape(-1), hi.reshape(-1), out.reshape(-1))
    return np.where(is_revolute, out, q)


def inside_limits(q: np.ndarray, limits: np.ndarray) -> npt.NDArray[np.bool_]:
    """(..., k) bool: every coordinate within its limits (1e-9 slack)."""
    return np.asarray(((q >= limits[:, 0] - 1e-9) & (q <= limits[:, 1] + 1e-9)).all(axis=-1))


def q_near_rows(q_near: Any, lead: tuple[int, ...], n: int) -> np.ndarray:
    """``q_near`` broadcast to the pose batch and flattened to (N, n).

    Without ``q_near``, one row of NaN: no preference (the 6R kernels then keep
    q6 = 0 at a wrist singularity).
    """
    if q_near is None:
        return np.full((1, n), np.nan)
    qn = np.asarray(q_near, dtype=np.float64)
    if qn.ndim == 1:
        return np.ascontiguousarray(qn.reshape(1, n))
    return np.ascontiguousarray(np.broadcast_to(qn, lead + (n,)).reshape(-1, n))


def fk_error(chain: Chain, q: np.ndarray, T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Position [m] and rotation [rad] error of FK(q) against T.

    Args:
        chain: The canonical chain.
        q: Configurations (..., k, n); rows holding NaN (not solutions) get NaN.
        T: Target poses (..., 4, 4).

    Returns:
        ``(dp, dr)``, each (..., k): the norms of the two halves of
        :func:`robokin.spatial.pose_error`.
    """
    from robokin.kinematics.forward import forward_kinematics
    from robokin.spatial import pose_error

    rows = np.isfinite(q).all(axis=-1)
    F = forward_kinematics(chain, np.where(rows[..., None], q, 0.0))
    e = pose_error(F, T[..., None, :, :])
    dp = np.where(rows, np.linalg.norm(e[..., :3], axis=-1), np.nan)
    dr = np.where(rows, np.linalg.norm(e[..., 3:], axis=-1), np.nan)
    return dp, dr


def make_set(
    robot: Arm,
    q: np.ndarray,
    valid: np.ndarray,
    *,
    inside: np.ndarray | None,
    singular: np.ndarray,
    branches: dict[str, np.ndarray],
    status_codes: np.ndarray,
    method: str,
    info: dict[str, Any] | None = None,
    error: np.ndarray | None = None,
) -> SolutionSet:
    """Assemble a SolutionSet from (..., k, n) slots."""
    if inside is None:
        inside = inside_limits(q, robot.limits)
    status = np.asarray(STATUS_TEXT[status_codes], dtype=object)
    return SolutionSet(
        q, valid, robot.is_revolute, robot.limits,
        flags={"within_limits": inside & valid, "singular": singular & valid},
        branches=branches, status=status, method=method, error=error,
        info=dict(info or {}),
    )


def read_only_joint_data(chain: Chain) -> tuple[np.ndarray, np.ndarray]:
    """The chain's ``is_revolute`` (n,) and ``limits`` (n, 2), read-only.

    What a solver's closure hands to every :class:`SolutionSet` it builds (the
    limits are copied only when the chain's are writeable).
    """
    is_rev = np.array(chain.is_revolute, dtype=bool)
    is_rev.setflags(write=False)
    limits = np.asarray(chain.limits, dtype=np.float64)
    if limits.flags.writeable:
        limits = limits.copy()
        limits.setflags(write=False)
    return is_rev, limits


def branch_labels(lead: tuple[int, ...],
                  table: dict[str, tuple[int, ...]]) -> dict[str, np.ndarray]:
    """Per-slot constant labels broadcast over the pose batch (read-only views).

    The views are kept per batch shape and table (keyed by the table's values,
    at most 65 kept).
    """
    key = (lead, tuple(table.items()))
    out = _LABEL_CACHE.get(key)
    if out is None:
        k = len(next(iter(table.values())))
        out = {name: np.broadcast_to(np.asarray(v, dtype=np.int8), lead + (k,))
               for name, v in table.items()}
        if len(_LABEL_CACHE) > 64:
            _LABEL_CACHE.clear()
        _LABEL_CACHE[key] = out
    return dict(out)


_LABEL_CACHE: dict[Any, dict[str, np.ndarray]] = {}
