"""Following IK branches along a task, for every candidate base of a chunk at once.

A task is an ordered sequence of N tool poses. A branch is continuous when the
joint configuration can follow it pose after pose with no step larger than
``max_step`` and never outside the joint limits. From every solution of the
first pose one track starts; at each next pose it moves to the solution (of the
closed form's k) whose nearest equivalent (revolute joints shifted by whole
turns towards the current value) is closest in the largest joint change, inside
the limits. A track dies where that step exceeds ``max_step`` (a branch flip,
a singularity crossed, a limit in the way) or no solution is left.

Arms without a closed form get one track per candidate: a numeric solution of
the first pose (seed-table restarts), then one damped-least-squares descent per
pose from the previous configuration (no restarts, so it cannot jump branches).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from robokin.cell._evaluate import solve_poses, solve_task
from robokin.spatial import wrap_angle

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["Tracks", "track"]


@dataclass(frozen=True, eq=False)
class Tracks:
    """Branches followed along a task for C candidates, k tracks each.

    Attributes:
        q: Joint path of every track (C, k, N, n) [rad, m] (NaN where it never
            started).
        alive: (C, k) bool: the track reaches the last pose.
        died_at: (C, k) int: the pose index where the track died (N if alive,
            0 if it never started).
        unreached: (C,) int: as ``PoseSet.unreached`` (``robokin.cell._pose_set``),
            from the same ``solve_task`` call.
    """

    q: np.ndarray
    alive: np.ndarray
    died_at: np.ndarray
    unreached: np.ndarray


def track(robot: Robot, T: np.ndarray, max_step: float, numeric: bool,
          sweep: str | None = None) -> Tracks:
    """Follow every branch of poses T (C, N, 4, 4) in the robot's world frame.

    Args:
        robot: The robot (its base at the world origin of ``T``).
        T: Task poses per candidate (C, N, 4, 4) [m].
        max_step: Largest joint change between consecutive poses [rad, m].
        numeric: Follow one numeric track instead of the closed form's branches.
        sweep: With ``numeric`` on a 7R arm, the joint sweeping the first pose's
            self-motion manifold where its numeric sample missed (or None).

    Returns:
        The :class:`Tracks`.
    """
    if numeric:
        return _track_numeric(robot, T, max_step, sweep)
    C, N = T.shape[:2]
    q, ok, unreached = solve_task(robot, T, False)
    k, n = q.shape[-2:]
    rev = np.asarray(robot.is_revolute, dtype=bool)
    lim = np.asarray(robot.limits)
    paths = np.full((C, k, N, n), np.nan)
    cur = q[:, 0].copy()
    alive = ok[:, 0].copy()
    died = np.where(alive, N, 0)
    paths[:, :, 0] = cur
    for i in range(1, N):
        # candidate solutions s (C, 1, k, n) against current track values (C, k, 1, n)
        d = q[:, i][:, None] - cur[:, :, None]
        d[..., rev] = wrap_angle(d[..., rev])
        s = cur[:, :, None] + d
        inside = ok[:, i][:, None] & ((s >= lim[:, 0]) & (s <= lim[:, 1])).all(axis=-1)
        step = np.where(inside, np.abs(d).max(axis=-1), np.inf)
        j = np.argmin(step, axis=-1)
        best = np.take_along_axis(step, j[..., None], axis=-1)[..., 0]
        nxt = np.take_along_axis(s, j[..., None, None], axis=2)[:, :, 0]
        still = alive & (best <= max_step) & np.isfinite(best)
        died[alive & ~still] = i
        alive = still
        cur = np.where(alive[..., None], nxt, cur)
        paths[:, :, i] = np.where(alive[..., None], cur, np.nan)
    return Tracks(paths, alive, died, unreached)


def _track_numeric(robot: Robot, T: np.ndarray, max_step: float, sweep: str | None
                   ) -> Tracks:
    from robokin.kinematics.ik.numeric import solve

    C, N = T.shape[:2]
    n = robot.n
    paths = np.full((C, 1, N, n), np.nan)
    first, found = solve_poses(robot, np.ascontiguousarray(T[:, 0]), True, sweep)
    cur = first.reshape(C, n)
    alive = found.reshape(C)
    died = np.where(alive, N, 0)
    unreached = np.where(alive, -1, 0)
    paths[:, 0, 0] = np.where(alive[:, None], cur, np.nan)
    for i in range(1, N):
        if not alive.any():
            break
        res = solve(robot, np.ascontiguousarray(T[:, i]), q0=cur, max_restarts=0)
        q = np.asarray(res.q, dtype=np.float64).reshape(C, n)
        ok = (np.asarray(res.success, dtype=bool).reshape(C) & robot.within_limits(q)
              & (np.abs(q - cur).max(axis=-1) <= max_step))
        still = alive & ok
        died[alive & ~still] = i
        alive = still
        cur = np.where(alive[:, None], q, cur)
        paths[:, 0, i] = np.where(alive[:, None], cur, np.nan)
    return Tracks(paths, alive[:, None], died[:, None], unreached)
