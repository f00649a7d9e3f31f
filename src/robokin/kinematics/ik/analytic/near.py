"""Near-family arms: the nominal closed form, then a few Newton steps on the true chain.

A calibrated arm's axes are parallel or meeting only to within its calibration
error (1e-4 rad, a fraction of a millimetre). The nominal family's closed form,
run on the snapped geometry, lands within that error of every true solution; Gauss–
Newton on the true chain (base-frame geometric Jacobian, pose error
``[p_T - p; log(R_T R^T)]``) then converges quadratically. A solution is kept only
if its final error is below ``tol`` (position [m] and rotation [rad]); seeds that
converge to the same solution are merged.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from robokin.kinematics.ik.analytic._common import fit_turns, fk_error, inside_limits
from robokin.spatial import pose_error, wrap_angle

if TYPE_CHECKING:
    from robokin.kinematics.arm import Arm

__all__ = ["polish"]


def polish(
    robot: Arm,
    T: np.ndarray,
    Q: np.ndarray,
    valid: np.ndarray,
    status: np.ndarray,
    *,
    iterations: int = 8,
    tol: float = 1e-9,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
    """Newton-polish closed-form seeds Q (..., k, n) onto the true chain.

    Returns:
        ``(Q, valid, within_limits, error, status, info)``; ``error`` (..., k) is the
        final position + rotation error norm (inf for invalid rows).
    """
    from robokin.kinematics.jacobian import jacobian_and_pose

    chain = robot.chain
    n = chain.n
    Q = np.array(Q, dtype=np.float64)
    valid = np.array(valid, dtype=bool)
    lead = valid.shape[:-1]
    k = valid.shape[-1]
    Tk = np.broadcast_to(T[..., None, :, :], lead + (k, 4, 4))
    idx = np.nonzero(valid)
    q = Q[idx]
    Tt = Tk[idx]
    steps = 0
    for _ in range(iterations):
        if q.shape[0] == 0:
            break
        J, F = jacobian_and_pose(chain, q)
        e = pose_error(F, Tt)
        if np.abs(e).max() < 1e-14:
            break
        if n == 6:
            try:
                dq = np.linalg.solve(J, e[..., None])[..., 0]
            except np.linalg.LinAlgError:
                dq = (np.linalg.pinv(J) @ e[..., None])[..., 0]
        else:
            dq = (np.linalg.pinv(J, rcond=1e-10) @ e[..., None])[..., 0]
        q = q + dq
        steps += 1
    q = fit_turns(q, chain.is_revolute, chain.limits)
    Q[idx] = q
    dp, dr = fk_error(chain, Q, T)
    ok = valid & (dp <= tol) & (dr <= tol)
    # merge seeds that converged to the same solution
    diff = Q[..., :, None, :] - Q[..., None, :, :]
    diff = np.where(chain.is_revolute, wrap_angle(diff), diff)
    same = (np.abs(diff).max(axis=-1) < 1e-7) & ok[..., None, :]
    earlier = np.tril(np.ones((k, k), bool), -1)
    dup = (same & earlier).any(axis=-1)
    ok &= ~dup
    error = np.where(ok, np.hypot(dp, dr), np.inf)
    status = np.array(status, copy=True)
    lost = valid.any(axis=-1) & ~ok.any(axis=-1)
    status = np.where(lost, 4, status).astype(np.int8)
    info = {
        "polished": True,
        "newton_steps": steps,
        "max_error": float(np.max(error, where=ok, initial=0.0)),
    }
    return Q, ok, inside_limits(Q, chain.limits) & ok, error, status, info
