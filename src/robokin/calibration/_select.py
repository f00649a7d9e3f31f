r"""Pose selection: the k candidate poses that identify the parameters best.

The criterion is D-optimality: the log-determinant of ``J^T J`` of the scaled
identification Jacobian, equivalently the observability index O1 of Borm and
Menq (Int. J. Robotics Research 10(1), 1991): :math:`O_1 = (\sigma_1 \cdots
\sigma_p)^{1/p} / \sqrt{N}`. Greedy addition (each step the pose whose rank-3,
or rank-6 for poses, update raises the determinant most, by the matrix
determinant lemma) is followed by exchange passes (Fedorov 1972): a selected
pose is swapped for a candidate when that raises the determinant.
Deterministic: the same candidates give the same indices.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from robokin.calibration._identify import structural_rules
from robokin.calibration._model import Model
from robokin.exceptions import InputError

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["observability_index", "select_poses"]


def _jacobians(robot: Robot, q: np.ndarray, kind: str,
               parallel_tol: float) -> np.ndarray:
    """Per-pose identification Jacobians (N, 3 or 6, p) at the nominal robot."""
    model = Model.from_chain(robot.chain, parallel_tol=parallel_tol)
    absorbed = structural_rules(model, kind)
    active = np.array([i for i, n in enumerate(model.names) if n not in absorbed])
    ev = model.evaluate(q, np.zeros(model.size), robot.base, robot.tool, active)
    assert ev.Jp is not None and ev.Jr is not None
    if kind == "pose":
        # rotations weighted by a length: the arm's reach, so both count alike
        reach = float(np.linalg.norm(robot.fk(q)[:, :3, 3] - robot.base[:3, 3],
                                     axis=1).mean()) or 1.0
        return np.concatenate([ev.Jp, reach * ev.Jr], axis=1)
    return ev.Jp


def _check(robot: Robot, candidate_q: npt.ArrayLike, kind: str) -> np.ndarray:
    from robokin._validation import check_finite, check_joints

    if kind not in ("position", "pose"):
        raise InputError("kind", f"expected 'position' or 'pose', got {kind!r}")
    q = check_finite(check_joints(candidate_q, robot.n, "candidate_q"), "candidate_q")
    if q.ndim != 2:
        raise InputError("candidate_q", f"expected (N, {robot.n}), got {q.shape}")
    return q


def observability_index(robot: Robot, q: npt.ArrayLike, kind: str = "position", *,
                        parallel_tol: float = math.radians(10.0)) -> float:
    """O1 of the poses ``q`` (N, n) for ``robot``'s identifiable parameters (larger is better).

    The Jacobian is in SI units (m per m, m per rad): its scaling is the same
    for every pose set, so the index ranks pose sets of one robot the way the
    determinant criterion of :func:`select_poses` does (a fixed column scaling
    multiplies every set's O1 by the same factor). It does not compare robots.
    """
    qa = _check(robot, q, kind)
    J = _jacobians(robot, qa, kind, parallel_tol)
    Jf = J.reshape(-1, J.shape[-1])
    e = np.linalg.svd(Jf.T @ Jf, compute_uv=False)
    s = np.sqrt(np.maximum(e, 1e-300))
    return float(math.exp(np.log(s).mean()) / math.sqrt(len(qa)))


def select_poses(
    robot: Robot,
    candidate_q: npt.ArrayLike,
    k: int,
    kind: str = "position",
    *,
    exchange_passes: int = 3,
    parallel_tol: float = math.radians(10.0),
) -> np.ndarray:
    """Indices of the ``k`` candidate poses that identify the parameters best.

    Args:
        robot: The nominal robot.
        candidate_q: Candidate joint coordinates (C, n) (e.g. collision-free,
            reachable configurations).
        k: How many to select (at least the parameters' count / 3, or / 6 for
            poses).
        kind: ``"position"`` or ``"pose"``.
        exchange_passes: Exchange passes after the greedy start.
        parallel_tol: As :func:`~robokin.calibration.calibrate`.

    Returns:
        Indices (k,) into ``candidate_q``, in the order they were chosen.

    Raises:
        InputError: ``k`` out of range, bad candidates.
    """
    q = _check(robot, candidate_q, kind)
    C = len(q)
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 1 <= k <= C:
        raise InputError("k", f"expected a whole number in [1, {C}], got {k!r}")
    J = _jacobians(robot, q, kind, parallel_tol)
    p = J.shape[-1]
    norms = np.linalg.norm(J.reshape(-1, p), axis=0)
    J = J / np.where(norms > 0, norms, 1.0) * math.sqrt(C)
    eps = 1e-6
    A = eps * np.eye(p)
    chosen: list[int] = []
    free = np.ones(C, bool)
    for _ in range(int(k)):
        gain = _gains(J, np.linalg.inv(A), +1)
        gain[~free] = -np.inf
        best = int(np.argmax(gain))
        chosen.append(best)
        free[best] = False
        A += J[best].T @ J[best]
    for _ in range(exchange_passes):
        improved = False
        for slot in range(len(chosen)):
            i = chosen[slot]
            A_minus = A - J[i].T @ J[i]
            Ainv = np.linalg.inv(A_minus)
            gain = _gains(J, Ainv, +1)
            gain[~free] = -np.inf
            best = int(np.argmax(gain))
            if gain[best] > _gains(J[i:i + 1], Ainv, +1)[0] + 1e-12:
                chosen[slot] = best
                free[i], free[best] = True, False
                A = A_minus + J[best].T @ J[best]
                improved = True
        if not improved:
            break
    return np.array(chosen, dtype=np.intp)


def _gains(J: np.ndarray, Ainv: np.ndarray, sign: int) -> np.ndarray:
    """``log det(I + sign J_c A^-1 J_c^T)`` per candidate (matrix determinant lemma)."""
    M = np.einsum("cip,pq,cjq->cij", J, Ainv, J)
    M = sign * M + np.eye(J.shape[1])
    sgn, logdet = np.linalg.slogdet(M)
    return np.where(sgn > 0, logdet, -np.inf)
