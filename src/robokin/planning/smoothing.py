"""From a planner's path to one a robot would run: corner cutting, then retiming.

A planner's path (after shortcutting) is a polyline. :func:`robokin.trajectory.retime`
runs a C2 spline through its waypoints and must stop where the path turns by more
than :data:`~robokin.trajectory._retime_path.CORNER_DEG` (60 deg). Two steps, each
keeping the guarantee that what the robot runs is collision-free:

1. Corner cutting (:meth:`robokin.planning.Planner.simplify`, compiled in
   ``csrc/plan_path.c``): Chaikin's corner cutting (Chaikin, "An algorithm for high
   speed curve generation", Computer Graphics and Image Processing 3(4), 1974) of
   the corners sharp enough to stop the arm (turning by more than
   :data:`SHARP_TURN`): corner w_i is replaced by the points a quarter of the way
   to its neighbours when the new segment between them is proven free; otherwise
   it stays. The other new segments lie on old ones. Each round halves those
   corners' turns. Gentler corners are left to the spline: cutting them too added
   knots and made the retimed motion longer (docs/planning.md has the numbers).
2. :func:`retime_checked`: the time-optimal C2 spline through the waypoints under
   the robot's limits, then every step between consecutive samples proven free as
   a straight edge (a controller interpolates between them). The spline leaves the
   proven polyline a little between knots, hence the check; where a step is not
   proven free, the arm stops at both ends of the path segment beside it, so that
   stretch follows the proven segment exactly, and the path is retimed again.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from robokin.trajectory._retime_path import CORNER_DEG

if TYPE_CHECKING:
    from robokin.robot import Robot
    from robokin.trajectory.samples import Trajectory

__all__ = ["SHARP_TURN", "EdgeCheck", "retime_checked"]

#: A batch edge check: (q0 (m, n), q1 (m, n)) -> (m,) bool, True when proven free.
EdgeCheck = Callable[[np.ndarray, np.ndarray], np.ndarray]
#: Corners turning by more than this [rad] are cut: 5 deg below the turn at which
#: retiming stops the arm (robokin.trajectory._retime_path.CORNER_DEG).
SHARP_TURN = math.radians(CORNER_DEG - 5.0)


def _nearest_segment(q: np.ndarray, x: np.ndarray) -> int:
    """The segment of the polyline q (K, n) nearest the configuration x (n,)."""
    a, d = q[:-1], np.diff(q, axis=0)
    dd = np.einsum("ij,ij->i", d, d)
    t = np.clip(np.einsum("ij,ij->i", x - a, d) / np.where(dd > 0, dd, 1.0), 0.0, 1.0)
    return int(np.argmin(np.linalg.norm(a + t[:, None] * d - x, axis=1)))


def retime_checked(
    robot: Robot, q: np.ndarray, free: EdgeCheck, **retime_options: Any
) -> tuple[Trajectory, int]:
    """Retime the path q (K, n) time-optimally and prove every sampled step free.

    The C2 spline through the waypoints first; where a sampled step is not proven
    free, the segment of the path it runs beside is run on its own (the arm stops
    at both its ends, a repeated sample being a dwell, so that stretch is a
    two-knot spline: the straight, proven segment itself), and the whole is retimed
    again, until every step is proven free (at worst stopping at every waypoint).

    Args:
        robot: The robot (its rate limits are the default limits).
        q: Waypoints [rad, m], shape (K, n), K >= 2; every segment free.
        free: The batch edge check.
        **retime_options: Passed to :func:`robokin.trajectory.retime` (``v_max``,
            ``a_max``, ``j_max``, ``dt``, ...).

    Returns:
        The trajectory, and how many interior waypoints it stops at for the check
        (0: it runs through them all).
    """
    from robokin.trajectory.retiming import retime

    K = q.shape[0]
    stop = np.zeros(K, dtype=bool)
    stop[[0, -1]] = True
    while True:
        src = np.repeat(q, np.where(stop, 2, 1), axis=0)[1:-1]
        tr = retime(robot, src, **retime_options)
        bad = np.flatnonzero(~free(tr.q[:-1], tr.q[1:]))
        if bad.size == 0 or stop.all():
            return tr, int(stop[1:-1].sum())
        before = stop.copy()
        for i in bad:
            k = _nearest_segment(q, 0.5 * (tr.q[i] + tr.q[i + 1]))
            stop[k] = stop[k + 1] = True
        if np.array_equal(stop, before):  # pragma: no cover - a stretch between stops
            stop[:] = True  # is its own segment; rounding alone could bring us here
