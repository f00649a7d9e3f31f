"""The press-loading job of ``robokin demo``: the plan, its cycle times, placements.

What the demo computes, apart from the files it writes
(:mod:`robokin.cli.demo_report`) and the run that ties them together
(:mod:`robokin.cli.demo`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from robokin import cell, collision, trajectory
from robokin.exceptions import InputError, MissingExtraError, UnreachableError
from robokin.trajectory import retime

if TYPE_CHECKING:
    from robokin.cell.placement import Placement
    from robokin.collision.scene import Scene
    from robokin.robot import Robot
    from robokin.trajectory.samples import Trajectory

__all__ = ["A_MAX", "DT", "PLACE_EVERY", "PLACE_SPAN", "PLACE_STEP", "PLAN", "V_MAX",
           "cycle_times", "placement_summary", "placement_task", "plan_press_loading",
           "search_placement"]

# AUBO-i5 published joint speed limit (150 deg/s on joints 1-3, 180 on 4-6: the demo
# caps all six at 150); the acceleration cap is this demo's own choice for smooth
# motion, not a manufacturer figure (the robot file's rate_limits hold AUBO's).
V_MAX = math.radians(150.0)
A_MAX = math.radians(300.0)
DT = 0.005

# (label, kind, target pose name, duration [s]); "joint" moves go to the closed-form
# solution nearest the scene's taught configuration, "line" moves are straight.
PLAN = (
    ("prepare to grasp", "joint", "pick_approach", 5.0),
    ("approach the part", "line", "pick", 2.5),
    ("close the gripper", "dwell", None, 1.0),
    ("lift the part", "line", "pick_approach", 2.5),
    ("move to the press", "joint", "press_approach", 6.0),
    ("enter the press", "line", "press_place", 3.0),
    ("release the part", "dwell", None, 1.0),
    ("retract", "line", "press_approach", 3.0),
)


def plan_press_loading(
    robot: Robot, scene: Scene, *, dt: float = DT, progress: Any = None
) -> tuple[Trajectory, list[dict[str, Any]]]:
    """Plan the press-loading motion.

    Args:
        robot: The AUBO-i5 as placed in the scene (``scene.attach(robot)``).
        scene: The press scene (its named poses and taught configurations).
        dt: Sampling period [s].
        progress: Optional ``progress(done, total)`` callable.

    Returns:
        The sampled :class:`~robokin.trajectory.Trajectory` and, per via pose, a
        record of the IK (number of solutions, the branch chosen).

    Raises:
        UnreachableError: a via pose has no solution inside the joint limits.
    """
    q0 = np.zeros(robot.n)
    path = trajectory.PathBuilder(
        robot, q0, dt=dt, v_max=V_MAX, a_max=A_MAX, ik="analytic"
    )
    via: list[dict[str, Any]] = []
    for label, kind, pose, duration in PLAN:
        if pose is None:  # a dwell: no target
            path.dwell(duration, label=label)
            continue
        T = scene.tcp_pose(pose)
        if kind == "line":
            path.line(T, duration, label=label)
            via.append(
                {
                    "label": label,
                    "pose": pose,
                    "kind": "line",
                    "q_deg": np.degrees(path.q_end).round(4).tolist(),
                }
            )
            continue
        sols = robot.ik(T, q_near=path.q_end).keep_within_limits()
        hint = scene.pose_joints.get(pose, path.q_end)
        try:
            q = sols.nearest(hint)
        except UnreachableError as exc:
            raise UnreachableError(f"via point '{label}' ({pose}): {exc}") from None
        k = int(np.argmin(sols.distance(q)))
        branch = {name: int(v[k]) for name, v in sols.branches.items()}
        via.append(
            {
                "label": label,
                "pose": pose,
                "kind": "joint",
                "solutions": int(sols.count),
                "branch": branch,
                "q_deg": np.degrees(q).round(4).tolist(),
            }
        )
        path.joint(q, duration, label=label)
    traj = path.build(progress=progress)
    return traj, via


# Placement search (``--place``): candidate bases every PLACE_STEP within
# PLACE_SPAN of the cell's base in x and y; the task is the motion after the first
# move (from home, a configuration and not a task pose), every PLACE_EVERY-th sample.
PLACE_SPAN = 0.4  # [m]
PLACE_STEP = 0.1  # [m]
PLACE_EVERY = 10  # samples (50 ms)


def placement_task(traj: Trajectory, every: int = PLACE_EVERY) -> np.ndarray:
    """The tool poses (N, 4, 4) [m] the arm must reach wherever it stands.

    The press-loading motion from the end of its first move (from home) on, every
    ``every``-th sample.
    """
    if traj.pose is None:  # the planner stores them: a changed plan must too
        raise InputError("traj", "has no tool poses to reach")
    first = traj.via_times[1] if len(traj.via_times) > 1 else traj.t[0]
    return np.ascontiguousarray(traj.pose[traj.t >= first - 1e-9][::every])


def search_placement(bare: Robot, scene: Scene, traj: Trajectory, *, clearance: float,
                     scheduler: Any = None, progress: Any = None) -> Placement:
    """Score robot bases on a floor grid around the cell's base for the motion.

    Returns:
        A :class:`robokin.cell.Placement`; the cell's own base is a candidate.
    """
    offsets = np.round(np.arange(-PLACE_SPAN, PLACE_SPAN + 1e-9, PLACE_STEP), 9)
    base = scene.base
    yaw = math.atan2(base[1, 0], base[0, 0])
    candidates = cell.base_grid(base[0, 3] + offsets, base[1, 3] + offsets, base[2, 3], yaw)
    return cell.place(bare, placement_task(traj), candidates, scene=scene,
                      clearance=clearance, scheduler=scheduler, progress=progress)


def placement_summary(pl: Placement, scene: Scene) -> dict[str, Any]:
    """The placement search in the summary: its counts and the cell's own base."""
    own = int(np.argmin(np.linalg.norm(pl.candidates[:, :3, 3] - scene.base[:3, 3],
                                       axis=1)))
    return {**pl.summary(), "cell_base_feasible": bool(pl.feasible[own]),
            "cell_base_reason": str(pl.reason[own]),
            "cell_base_score": float(pl.score[own])}


def cycle_times(robot: Robot, bare: Robot, scene: Scene, traj: Trajectory,
                clearance: float) -> dict[str, Any]:
    """The shortest cycle of the planned path, and the retimed motion's clearance.

    The minimum cycle time (dwells kept) under the robot file's limits and under the
    demo's caps; the retimed motion is checked against the press again.
    """
    try:
        fast = retime(robot, traj)
        capped = retime(robot, traj, v_max=V_MAX, a_max=A_MAX)
    except MissingExtraError as exc:
        return {"planned_s": round(traj.duration, 3), "note": str(exc)}
    rep = collision.check(bare, scene, fast, clearance=clearance)
    return {"planned_s": round(traj.duration, 3),
            "minimum_s": round(fast.duration, 3),
            "minimum_demo_caps_s": round(capped.duration, 3),
            "retimed_collides": bool(rep.collides),
            "retimed_min_clearance_mm": round(float(rep.min_distance) * 1000.0, 3)}
