"""Collision-free motion planning in a scene.

.. code-block:: python

    from robokin import planning

    res = planning.plan(robot, scene, start, goal, time_limit=1.0, seed=0)
    res.success, res.q, res.reason, res.time   # q (K, n): start ... goal
    planner = planning.Planner(robot, scene)    # many queries against one scene
    res = planner.plan(start, T_goal)           # a (4, 4) TCP pose: every IK branch
    traj = planner.trajectory(res)              # time-optimal, every step checked

Every straight segment of a returned path is proven collision-free (robot against
the scene and itself, tool included): certified distance bounds and conservative
advancement in compiled kernels, coal for meshes the bounds cannot clear. The
default planner is a compiled RRT-Connect; OMPL's planners (``robokin[plan]``)
run on the same checks (``planner="ompl:RRTstar"``, ...). See
``docs/planning.md``.
"""

from __future__ import annotations

from robokin.planning.goals import Goals, goal_configurations
from robokin.planning.planner import DEFAULT_PLANNER, PLANNERS, Planner, plan
from robokin.planning.result import PlanResult

__all__ = [
    "DEFAULT_PLANNER",
    "PLANNERS",
    "Goals",
    "PlanResult",
    "Planner",
    "goal_configurations",
    "plan",
]
