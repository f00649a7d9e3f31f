"""The least-squares stages of a calibration (scipy ``least_squares``, exact Jacobian).

Residuals are ``model - measured`` per pose: the position [m], then for poses the
rotation vector of ``R_model R_measured^T`` times a weight [m/rad]. The rotation
rows of the Jacobian carry the inverse left Jacobian of SO(3) at the residual,
so the Jacobian is exact, not a small-residual approximation.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from robokin.calibration._model import Evaluation, Model

__all__ = ["Problem", "inverse_left_jacobian"]


def inverse_left_jacobian(phi: np.ndarray) -> np.ndarray:
    r"""``J_l^{-1}(phi)`` of SO(3), (N, 3) -> (N, 3, 3).

    .. math:: J_l^{-1} = I - \tfrac12 [\phi]_\times
              + \Big(\frac{1}{\theta^2} - \frac{1 + \cos\theta}{2\theta\sin\theta}\Big)
              [\phi]_\times^2

    (Barfoot, State Estimation for Robotics, 2017, eq. 7.75.)
    """
    th = np.linalg.norm(phi, axis=-1)
    K = np.zeros(phi.shape[:-1] + (3, 3))
    K[..., 0, 1], K[..., 0, 2] = -phi[..., 2], phi[..., 1]
    K[..., 1, 0], K[..., 1, 2] = phi[..., 2], -phi[..., 0]
    K[..., 2, 0], K[..., 2, 1] = -phi[..., 1], phi[..., 0]
    small = th < 1e-6
    ths = np.where(small, 1.0, th)
    c = np.where(small, 1.0 / 12.0,
                 1.0 / ths**2 - (1.0 + np.cos(ths)) / (2.0 * ths * np.sin(ths)))
    return np.eye(3) - 0.5 * K + c[..., None, None] * (K @ K)


@dataclass
class Problem:
    """One identification problem: the model, the data and what is fitted.

    Attributes:
        model: The parametric model.
        q: Joint coordinates (N, n).
        measured: Points (N, 3) or poses (N, 4, 4) in the measuring frame.
        pose: Whether rotations are fitted.
        base: Registered base ``B_0``.
        tool: Tool ``T_0``.
        torque: Joint torques (N, n_chain) or None.
        rotation_weight: [m/rad].
    """

    model: Model
    q: np.ndarray
    measured: np.ndarray
    pose: bool
    base: np.ndarray
    tool: np.ndarray
    torque: np.ndarray | None
    rotation_weight: float = 0.1

    def full(self, x_active: np.ndarray, active: np.ndarray,
             x0: np.ndarray) -> np.ndarray:
        """The full parameter vector with ``active`` entries replaced."""
        x = x0.copy()
        x[active] = x_active
        return x

    def evaluate(self, x: np.ndarray, active: np.ndarray | None,
                 rows: np.ndarray | None = None) -> Evaluation:
        """Model poses (and Jacobian) at full parameters ``x`` for poses ``rows``."""
        q = self.q if rows is None else self.q[rows]
        tq = None if self.torque is None or rows is None else self.torque[rows]
        if rows is None:
            tq = self.torque
        return self.model.evaluate(q, x, self.base, self.tool, active, torque=tq)

    def split_residual(self, ev: Evaluation, rows: np.ndarray | None = None
                       ) -> tuple[np.ndarray, np.ndarray | None]:
        """Position residuals (N, 3) and rotation residuals (N, 3) [rad] or None."""
        meas = self.measured if rows is None else self.measured[rows]
        if not self.pose:
            return ev.T[:, :3, 3] - meas, None
        from robokin.spatial import pose_error

        e = pose_error(meas, ev.T)  # (p_model - p_meas, log(R_model R_meas^T))
        return e[:, :3], e[:, 3:]

    def residual_and_jacobian(self, x: np.ndarray, active: np.ndarray,
                              rows: np.ndarray | None = None,
                              weights: np.ndarray | None = None
                              ) -> tuple[np.ndarray, np.ndarray]:
        """Stacked residuals (M,) and Jacobian (M, p) of the active parameters.

        ``weights`` (one per pose of ``rows``) scale each pose's rows.
        """
        ev = self.evaluate(x, active, rows)
        rp, rr = self.split_residual(ev, rows)
        assert ev.Jp is not None and ev.Jr is not None
        if rr is None:
            r3, J3 = rp, ev.Jp
        else:
            w = self.rotation_weight
            Jr = inverse_left_jacobian(rr) @ ev.Jr
            r3 = np.concatenate([rp, w * rr], axis=1)
            J3 = np.concatenate([ev.Jp, w * Jr], axis=1)
        if weights is not None:
            r3 = r3 * weights[:, None]
            J3 = J3 * weights[:, None, None]
        return r3.reshape(-1), J3.reshape(-1, len(active))

    def solve(self, x0: np.ndarray, active: np.ndarray, *,
              rows: np.ndarray | None = None, weights: np.ndarray | None = None,
              max_nfev: int = 100) -> np.ndarray:
        """Least-squares fit of the active parameters from ``x0`` (full vector).

        ``scipy.optimize.least_squares`` with MINPACK's Levenberg-Marquardt
        (``method="lm"``, its own QR: no threaded LAPACK, which on a loaded
        machine made the trust-region solver's SVD 100x slower) and the exact
        Jacobian; the trust-region solver when there are fewer residuals than
        parameters. Returns the full vector.
        """
        from scipy.optimize import least_squares

        cache: dict[str, tuple[bytes, tuple[np.ndarray, np.ndarray]]] = {}

        def both(xa: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            key = xa.tobytes()
            hit = cache.get("last")
            if hit is None or hit[0] != key:
                hit = (key, self.residual_and_jacobian(self.full(xa, active, x0),
                                                       active, rows, weights))
                cache["last"] = hit
            return hit[1]

        def fun(xa: np.ndarray) -> np.ndarray:
            return both(xa)[0]

        def jac(xa: np.ndarray) -> np.ndarray:
            return both(xa)[1]

        m = (len(self.q) if rows is None else len(rows)) * (6 if self.pose else 3)
        method: Literal["lm", "trf"] = "lm" if m >= len(active) else "trf"
        res = least_squares(fun, x0[active], jac=jac, method=method, x_scale="jac",
                            max_nfev=max_nfev, xtol=1e-12, ftol=1e-12, gtol=1e-12)
        return self.full(res.x, active, x0)

    def solve_robust(self, x0: np.ndarray, active: np.ndarray, scale: float,
                     rounds: int = 8) -> np.ndarray:
        r"""Robust fit: the soft-L1 loss of each pose's residual, by reweighting.

        Minimises :math:`\sum_i \rho(|r_i|^2 / c^2)` with
        :math:`\rho(z) = 2(\sqrt{1 + z} - 1)` (scipy's ``soft_l1``) over the
        poses, by iteratively reweighted least squares: each round a
        least-squares fit (:meth:`solve`) with pose weights
        :math:`\sqrt{\rho'(z_i)} = (1 + z_i)^{-1/4}`.

        Args:
            x0: Start (full vector).
            active: Fitted parameters.
            scale: ``c`` [m], a few times the noise.
            rounds: Most reweighting rounds.
        """
        x = x0
        for _ in range(rounds):
            ev = self.evaluate(x, None)
            rp, rr = self.split_residual(ev)
            r2 = (rp**2).sum(1)
            if rr is not None:
                r2 = r2 + self.rotation_weight**2 * (rr**2).sum(1)
            w = (1.0 + r2 / scale**2) ** -0.25
            x_new = self.solve(x, active, weights=w)
            step = np.abs(x_new - x).max()
            x = x_new
            if step < 1e-12:
                break
        return x
