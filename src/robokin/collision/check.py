"""Collision and minimum distance along a whole joint trajectory.

:func:`check` answers, for a trajectory of ``m`` joint samples, the exact minimum
distance over time of every (robot link, scene object) pair and every checked
pair of robot links, the global minimum (time, sample, bodies, nearest points),
and every collision interval. Between samples the motion is the straight line in
joint space; no collision in between is missed (see below).

How it stays fast (coal queries are the expensive part):

1. **Broad phase, all samples at once.** Each robot shape is covered by a few
   spheres; each object by its oriented bounding box. One vectorised pass gives a
   lower bound on every (pair, sample) distance.
2. **Motion bounds.** Between two configurations a point of link k moves at most
   ``sum_j R_jk |dq_j|`` (``R_jk`` bounds its distance from joint j's axis; 1 for
   a prismatic joint) [Schwarzer, Saha, Latombe, "Adaptive dynamic collision
   checking for single and multiple articulated robots in complex environments",
   IEEE T-RO 21(3), 2005, eq. 1]. Distances are 1-Lipschitz in that motion, so an
   exact distance at one sample lower-bounds all its neighbours.
3. **Exact queries only where they decide something.** Per pair, samples are
   taken in increasing lower-bound order and each exact coal distance tightens the
   bounds of the rest; a pair is done when no remaining bound is below its best.
   Samples whose bound is at or below the threshold are always queried (to
   classify them). Meshes go through their convex hull (a lower bound) first.
4. **Subdivision.** An interval is provably clear when
   ``d_i + d_{i+1} > M_i`` (the motion bound over it); otherwise it is bisected
   with exact queries until it is, or a collision is found (so a fast motion
   through a thin plate is caught).
5. coal geometries and distance functors are built once and reused.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from robokin._validation import _real_array, check_nonnegative
from robokin.collision.report import TIE, CollisionReport
from robokin.exceptions import InputError

if TYPE_CHECKING:
    from robokin.collision.scene import Scene
    from robokin.robot import Robot

__all__ = ["check"]



def _as_samples(
    q_samples: Any, n: int, t: npt.ArrayLike | None
) -> tuple[np.ndarray, np.ndarray | None]:
    if hasattr(q_samples, "q") and not isinstance(q_samples, np.ndarray):
        tt = getattr(q_samples, "t", None)
        q = q_samples.q
        if t is None and tt is not None:
            t = tt
    else:
        q = q_samples
    q = _real_array(q, "q_samples", "numbers").copy()
    if q.ndim == 1:
        q = q[None, :]
    if q.ndim != 2 or q.shape[1] != n or q.shape[0] == 0:
        raise InputError(
            "q_samples", f"expected shape (m, {n}) with m >= 1, got {q.shape}"
        )
    if not np.isfinite(q).all():
        bad = np.argwhere(~np.isfinite(q))[0]
        raise InputError("q_samples", f"holds a non-finite value at index {tuple(bad)}")
    if t is not None:
        t = np.asarray(t, dtype=np.float64).reshape(-1)
        if t.shape != (q.shape[0],) or not np.isfinite(t).all():
            raise InputError(
                "t", f"expected {q.shape[0]} finite times, got shape {t.shape}"
            )
    return q, t


def check(
    robot: Robot,
    scene: Scene,
    q_samples: Any,
    *,
    t: npt.ArrayLike | None = None,
    clearance: float = 0.0,
    self_collision: bool = True,
    subdivide: bool = True,
    tolerance: float = 1e-6,
    pair_tolerance: float = 1e-3,
    pair_rtol: float = 0.01,
) -> CollisionReport:
    """Collision and minimum distance of a joint trajectory in a scene.

    Args:
        robot: The robot (its ``geometry`` gives the link shapes; the scene adds
            its base placement and tool).
        scene: The static scene (:class:`~robokin.collision.Scene`).
        q_samples: Joint samples (m, n) [rad, m], or a Trajectory with ``.t``
            and ``.q``. Between samples the motion is linear in joint space.
        t: Sample times (m,) [s]; defaults to the Trajectory's, else the indices.
        clearance: Distance [m] at or below which a sample counts as a
            violation (reported in ``violations``; subdivision also guarantees
            it between samples).
        self_collision: Also check non-adjacent, non-excluded link pairs.
        subdivide: Guarantee no collision is missed between samples.
        tolerance: Motion [m] below which subdivision stops (grazing contact
            closer than this between samples counts as clear).
        pair_tolerance: Each pair's minimum over time is within
            ``max(pair_tolerance, pair_rtol * distance)`` [m] of its exact minimum
            over the samples (it is always a real sampled distance, never below
            the exact one). The global minimum, and the classification of every
            sample against ``clearance`` and contact, are exact regardless.
        pair_rtol: Relative part of that tolerance (0.01: 1 %).

    Returns:
        A :class:`CollisionReport`.

    Raises:
        InputError: bad samples, times or clearance, or a robot without any
            shapes (neither its own geometry nor the scene's tool).
        MissingExtraError: coal (or trimesh for meshes) is not installed.
    """
    check_nonnegative(clearance, "clearance", "a finite number >= 0 [m]")
    q, tt = _as_samples(q_samples, robot.n, t)
    problem = _problem_for(robot, scene, self_collision)
    return problem.run(
        q,
        tt,
        float(clearance),
        subdivide,
        float(tolerance),
        max(float(pair_tolerance), TIE),
        max(float(pair_rtol), 0.0),
    )


def _problem_for(robot: Robot, scene: Scene, self_collision: bool) -> Any:
    cache = scene.__dict__.setdefault("_check_cache", {})
    key = (id(robot), scene._fingerprint(), self_collision)
    hit = cache.get(key)
    if hit is not None and hit[0] is robot:
        return hit[1]
    from robokin.collision._problem import _Problem

    problem = _Problem(robot, scene, self_collision)
    cache.clear()
    cache[key] = (robot, problem)
    return problem
