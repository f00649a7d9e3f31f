"""A task that is a set of poses in no order: each pose on its own.

With ``max_step=math.inf`` a placement task is a set of tool poses (spot welds,
pick points, inspection views) that no motion joins in a given order, so there is
no branch to follow and no joint value to carry from one pose to the next: a
candidate base serves the set when every pose has a solution inside the joint
limits (and, as scored, with the clearance and manipulability asked for). For
each candidate and pose this module lists the solutions inside the limits, best
manipulability first; :mod:`robokin.cell.placement` then picks per pose the first
that meets the requirements.

(Following branches pose after pose, as :mod:`robokin.cell._tracking` does for a
motion, would carry unwrapped joint values across unrelated poses until they
left the limits: issue 25.)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from robokin.cell._evaluate import manipulability, solve_task

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["PoseSet", "rank_solutions"]


@dataclass(frozen=True, eq=False)
class PoseSet:
    """The solutions of every task pose for C candidates, k per pose.

    Attributes:
        q: Solutions (C, N, k, n) [rad, m] (NaN where not a solution).
        ok: (C, N, k) bool: a solution inside the joint limits.
        w: (C, N, k) Yoshikawa manipulability (0 where not ``ok``).
        order: (C, N, k) int: the solution slots of each pose, those inside the
            limits first, by decreasing manipulability (ties: lower slot first).
        unreached: (C,) int: the first pose without any solution inside the
            limits (-1 when every pose has one).
    """

    q: np.ndarray
    ok: np.ndarray
    w: np.ndarray
    order: np.ndarray
    unreached: np.ndarray


def rank_solutions(robot: Robot, T: np.ndarray, numeric: bool, sweep: str | None = None
                   ) -> PoseSet:
    """Every in-limit solution of poses T (C, N, 4, 4), ranked by manipulability.

    Args:
        robot: The robot (its base at the world origin of ``T``).
        T: Task poses per candidate (C, N, 4, 4) [m].
        numeric: One numeric solution per pose (seed-table restarts) instead of
            every closed-form solution.
        sweep: With ``numeric`` on a 7R arm, the joint sweeping the self-motion
            manifold where the numeric sample missed (or None).

    Returns:
        The :class:`PoseSet`.
    """
    q, ok, unreached = solve_task(robot, T, numeric, sweep)
    w = manipulability(robot.chain, q, ok)
    order = np.argsort(np.where(ok, -w, np.inf), axis=-1, kind="stable")
    return PoseSet(q, ok, w, order, unreached)
