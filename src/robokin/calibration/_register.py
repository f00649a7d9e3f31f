r"""Closed-form registration of the measuring frame (and the tool), before the fit.

Points: ``m_i = R_B (R_i t + p_i) + t_B`` with the nominal flange poses ``(R_i,
p_i)``, the unknown base ``(R_B, t_B)`` and tool point ``t``. Writing ``A = R_B``
and ``W_{jk} = A_{:,j} t_k`` makes it linear in ``(A, W, t_B)`` (39 unknowns, 3
equations a pose); ``R_B`` is the rotation nearest ``A`` and ``t`` follows.
Alternating Kabsch fits (Horn 1987; Kabsch 1976) for ``R_B, t_B`` and linear
fits for ``t`` then polish it.

Poses: ``M_i = B F_i X``. The rotations satisfy ``R_{M_i} Y = R_B R_{F_i}`` with
``Y = R_X^T``, linear and homogeneous in ``(Y, R_B)``: the null vector of the
stacked system, projected onto SO(3) (the Kronecker form of the robot-world /
hand-eye problem, Shah, J. Mech. Robot. 5(3), 2013). The translations are then
linear.

Both are exact for exact data and need no starting guess, so any tracker
placement converges.
"""

from __future__ import annotations

import numpy as np

__all__ = ["nearest_rotation", "register_points", "register_poses"]


def nearest_rotation(A: np.ndarray) -> np.ndarray:
    """The rotation matrix nearest ``A`` (3, 3) in the Frobenius norm."""
    U, _, Vt = np.linalg.svd(A)
    S = np.eye(3)
    S[2, 2] = np.sign(np.linalg.det(U @ Vt)) or 1.0
    return U @ S @ Vt


def _kabsch(src: np.ndarray, dst: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``R, t`` minimising ``sum |R src_i + t - dst_i|^2``."""
    cs, cd = src.mean(0), dst.mean(0)
    R = nearest_rotation((dst - cd).T @ (src - cs))
    return R, cd - R @ cs


def register_points(
    flange: np.ndarray, measured: np.ndarray, tool0: np.ndarray, iterations: int = 30
) -> tuple[np.ndarray, np.ndarray]:
    """Base pose and tool point from measured points.

    Args:
        flange: Nominal flange poses (N, 4, 4) in the robot base frame.
        measured: Measured tool points (N, 3) in the measuring frame.
        tool0: Fallback tool point (3,) in the flange frame, used when the poses
            do not turn enough for the linear solution.
        iterations: Alternating refinements.

    Returns:
        The base (4, 4) (measuring frame -> robot base) and the tool point (3,).
    """
    R, p = flange[:, :3, :3], flange[:, :3, 3]
    N = len(measured)
    t = np.asarray(tool0, float)
    if N >= 13:
        # rows: m_i = A p_i + sum_jk R_i[j,k] W_jk + t_B
        M = np.zeros((N, 3, 39))
        for r in range(3):
            M[:, r, 3 * r: 3 * r + 3] = p  # A[r, :] . p_i
            for j in range(3):
                for k in range(3):
                    M[:, r, 9 + 3 * (3 * j + k) + r] = R[:, j, k]
            M[:, r, 36 + r] = 1.0
        # normal equations: a threaded lstsq of (3N, 39) took 0.3 s on a loaded
        # machine; the 39 x 39 system is instant and precise enough for a start
        Mf = M.reshape(-1, 39)
        G = Mf.T @ Mf
        ev = np.linalg.svd(G, compute_uv=False)
        if ev[-1] > 1e-12 * ev[0]:
            sol = np.linalg.solve(G, Mf.T @ measured.reshape(-1))
            A = nearest_rotation(sol[:9].reshape(3, 3))
            Wm = sol[9:36].reshape(3, 3, 3)  # [j, k, :] = A[:, j] t_k
            t = np.einsum("aj,jka->k", A, Wm) / 3.0
    B = np.eye(4)
    for _ in range(iterations):
        pts = np.einsum("nij,j->ni", R, t) + p
        RB, tB = _kabsch(pts, measured)
        local = np.einsum("ji,nj->ni", RB, measured - tB) - p  # R_B^T (m - t_B) - p
        t_new = np.einsum("nji,nj->i", R, local) / N  # mean R_i^T (...)
        B[:3, :3], B[:3, 3] = RB, tB
        done = np.abs(t_new - t).max() < 1e-12
        t = t_new
        if done:
            break
    return B, t


def register_poses(flange: np.ndarray, measured: np.ndarray,
                   tool0: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Base pose and tool pose from measured poses ``M_i = B F_i X``.

    When the flange rotations leave the split between ``B`` and ``X`` open (every
    joint axis parallel: ``B Rz(phi)`` and ``Rz(-phi) X`` fit alike), the
    solution nearest the nominal tool ``tool0`` is taken, and the translations
    are the least-norm ones.

    Args:
        flange: Nominal flange poses (N, 4, 4) in the robot base frame.
        measured: Measured tool poses (N, 4, 4) in the measuring frame.
        tool0: The nominal tool (4, 4), for that choice (default identity).

    Returns:
        ``B`` (4, 4) and ``X`` (4, 4).
    """
    RF, RM = flange[:, :3, :3], measured[:, :3, :3]
    N = len(measured)
    I3 = np.eye(3)
    rows = np.zeros((N, 9, 18))
    for i in range(N):
        # column-major vec: vec(A Y) = (I kron A) vec(Y); vec(B C) = (C^T kron I) vec(B)
        rows[i, :, :9] = np.kron(I3, RM[i])
        rows[i, :, 9:] = -np.kron(RF[i].T, I3)
    Rf = rows.reshape(-1, 18)
    _, e, Vt = np.linalg.svd(Rf.T @ Rf)  # the 18 x 18 Gram matrix: see register_points
    null = Vt[e <= max(e[-1], 1e-10 * e[0]) * 1e3 + 1e-300]
    if len(null) > 1:  # the split is open: the member nearest the nominal tool
        Y0 = (np.eye(3) if tool0 is None else np.asarray(tool0)[:3, :3]).T
        target = Y0.reshape(-1, order="F")
        coef, *_ = np.linalg.lstsq(null[:, :9].T, target, rcond=None)
        v = coef @ null
    else:
        v = Vt[-1]
    Y = v[:9].reshape(3, 3, order="F")
    RB = v[9:].reshape(3, 3, order="F")
    if np.linalg.det(RB) < 0:
        Y, RB = -Y, -RB
    RB = nearest_rotation(RB)
    RX = nearest_rotation(Y).T
    # t_M = R_B R_F t_X + R_B t_F + t_B
    A = np.zeros((N, 3, 6))
    A[:, :, :3] = np.einsum("ij,njk->nik", RB, RF)
    A[:, :, 3:] = I3
    b = measured[:, :3, 3] - np.einsum("ij,nj->ni", RB, flange[:, :3, 3])
    Af = A.reshape(-1, 6)
    sol = np.linalg.pinv(Af.T @ Af, rcond=1e-10) @ (Af.T @ b.reshape(-1))
    B = np.eye(4)
    X = np.eye(4)
    B[:3, :3], B[:3, 3] = RB, sol[3:]
    X[:3, :3], X[:3, 3] = RX, sol[:3]
    return B, X
