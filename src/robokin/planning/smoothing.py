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
   proven polyline a little between knots, hence the check; if a step is not
   proven free, the path is retimed stopping at every waypoint instead, where the
   motion follows each proven segment exactly.
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


def retime_checked(
    robot: Robot, q: np.ndarray, free: EdgeCheck, **retime_options: Any
) -> tuple[Trajectory, bool]:
    """Retime the path q (K, n) time-optimally and prove every sampled step free.

    Args:
        robot: The robot (its rate limits are the default limits).
        q: Waypoints [rad, m], shape (K, n), K >= 2; every segment free.
        free: The batch edge check.
        **retime_options: Passed to :func:`robokin.trajectory.retime` (``v_max``,
            ``a_max``, ``j_max``, ``dt``, ...).

    Returns:
        The trajectory, and whether it runs through the waypoints without
        stopping (False: the fallback that stops at every waypoint).
    """
    from robokin.trajectory.retiming import retime

    tr = retime(robot, q, **retime_options)
    if bool(free(tr.q[:-1], tr.q[1:]).all()):
        return tr, True
    # stop at every waypoint: a repeated sample is a dwell, and each stretch between
    # two waypoints a two-knot spline, the straight segment itself
    stops = np.repeat(q, 2, axis=0)[1:-1]
    tr = retime(robot, stops, **retime_options)
    return tr, False
