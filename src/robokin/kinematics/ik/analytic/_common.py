"""Helpers shared by the closed-form families: joint wrapping, set assembly, errors."""

from __future__ import annotations

from typing import Any

import numpy as np

from robokin.kinematics.ik.solutions import SolutionSet

__all__ = ["STATUS_TEXT", "fit_turns", "fk_error", "make_set", "q_near_rows"]

STATUS_TEXT = np.array(
    ["ok", "out of reach", "orientation not achievable",
     "not reachable: tool cannot tilt",
     "near-family Newton polish did not converge",
     "no solution: the general 6R elimination is degenerate at this pose"],
    dtype=object,
)


def fit_turns(q: np.ndarray, is_revolute: np.ndarray, limits: np.ndarray) -> np.ndarray:
    """Wrap revolute values into [-pi, pi), then move them by whole turns into their
    limits where that is possible (prismatic values are left alone)."""
    tw = 2.0 * np.pi
    w = (q + np.pi) % tw - np.pi
    lo, hi = limits[:, 0], limits[:, 1]
    with np.errstate(invalid="ignore"):
        up = w + tw * np.ceil((lo - 1e-9 - w) / tw)
        down = w - tw * np.ceil((w - hi - 1e-9) / tw)
    w = np.where((w < lo - 1e-9) & (up <= hi + 1e-9), up, w)
    w = np.where((w > hi + 1e-9) & (down >= lo - 1e-9), down, w)
    return np.where(is_revolute, w, q)


def inside_limits(q: np.ndarray, limits: np.ndarray) -> np.ndarray:
    """(..., k) bool: every coordinate within its limits (1e-9 slack)."""
    return ((q >= limits[:, 0] - 1e-9) & (q <= limits[:, 1] + 1e-9)).all(axis=-1)


def q_near_rows(q_near: Any, lead: tuple[int, ...], n: int) -> np.ndarray:
    """``q_near`` broadcast to the pose batch and flattened to (N, n), or (1, n) zeros."""
    if q_near is None:
        return np.zeros((1, n))
    qn = np.asarray(q_near, dtype=np.float64)
    if qn.ndim == 1:
        return np.ascontiguousarray(qn.reshape(1, n))
    return np.ascontiguousarray(np.broadcast_to(qn, lead + (n,)).reshape(-1, n))


def fk_error(chain: Any, q: np.ndarray, T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Position [m] and rotation [rad] error of FK(q) against T; q (..., k, n), T (..., 4, 4)."""
    from robokin.kinematics.forward import forward_kinematics

    F = forward_kinematics(chain, q)
    Tb = T[..., None, :, :]
    dp = np.linalg.norm(F[..., :3, 3] - Tb[..., :3, 3], axis=-1)
    dR = np.swapaxes(Tb[..., :3, :3], -1, -2) @ F[..., :3, :3]
    tr = np.clip((np.trace(dR, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
    skew = np.stack([dR[..., 2, 1] - dR[..., 1, 2], dR[..., 0, 2] - dR[..., 2, 0],
                     dR[..., 1, 0] - dR[..., 0, 1]], axis=-1)
    ang = np.arctan2(0.5 * np.linalg.norm(skew, axis=-1), tr)
    return dp, ang


def make_set(
    robot: Any,
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


def branch_labels(lead: tuple[int, ...], table: dict[str, list[int]]) -> dict[str, np.ndarray]:
    """Per-slot constant labels broadcast over the pose batch (read-only views)."""
    key = (lead, id(table))
    out = _LABEL_CACHE.get(key)
    if out is None:
        k = len(next(iter(table.values())))
        out = {name: np.broadcast_to(np.asarray(v, dtype=np.int8), lead + (k,))
               for name, v in table.items()}
        if len(_LABEL_CACHE) > 64:
            _LABEL_CACHE.clear()
        _LABEL_CACHE[key] = out
    return dict(out)


_LABEL_CACHE: dict = {}
