"""Process paths over every IK branch, and the visiting order of a point set.

.. code-block:: python

    from robokin import process

    res = process.follow(robot, poses, free_axis="z", free_range=(-pi / 2, pi / 2),
                         max_step=0.1, q_start=q0, scene=scene, clearance=0.005)
    res.feasible, res.q, res.free_angle, res.max_step, res.travel, res.reason
    process.plot_follow(res, robot=robot, path="path.png")  # green / red (matplotlib)
    write_html("path.html", robot, res.q,
               scene=process.path_markers(res, scene=scene))  # the same in 3D

    seq = process.order(robot, hole_poses, free_axis="z", q_start=q0)
    seq.order, seq.q, seq.travel, seq.lower_bound, seq.gap

``docs/process.md`` describes the graph, the objective, what is exact and what is
guaranteed.
"""

from robokin.process.costs import Costs
from robokin.process.follow import follow
from robokin.process.order import order
from robokin.process.report import Failure, FollowResult, OrderResult, WaypointReport
from robokin.process.views import path_markers, plot_follow

__all__ = ["Costs", "Failure", "FollowResult", "OrderResult", "WaypointReport", "follow",
           "order", "path_markers", "plot_follow"]
