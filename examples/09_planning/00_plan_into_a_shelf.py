# /// script
# requires-python = ">=3.10"
# dependencies = ["robokin[plan]"]
# ///
"""Plan a collision-free motion into a shelf, to a tool pose, and retime it.

Builds a shelf in code, mounts a gripper on the UR5, and asks the planner for a
path from an upright configuration to a tool pose inside the middle cell: every
in-limit IK solution of the pose is a goal, every straight segment of the path is
proven collision-free, and the time-optimal trajectory along it is checked again
step by step. Then plans the way back with the same planner (the first query
also loads the IK solvers; later ones take milliseconds). Prints the planning
times, the branch reached and the cycle time.

Requirements: robokin[plan] (coal, trimesh, toppra, ruckig; OMPL for its planners).
"""

from __future__ import annotations

import numpy as np

import robokin
from robokin import collision, planning
from robokin.model import geometry
from robokin.spatial import pose_from_xyz_rpy


def _at(x: float, y: float, z: float) -> np.ndarray:
    return pose_from_xyz_rpy(np.array([x, y, z]), np.zeros(3))  # [m]


def main() -> None:
    """Plan from upright into the shelf's middle cell; print what came out."""
    scene = collision.Scene("shelf")
    for k, z in enumerate((0.05, 0.4, 0.75)):  # three boards [m]
        scene.add_box(f"board_{k}", (0.3, 0.8, 0.02), _at(0.7, 0.0, z))
    for side in (-1, 1):
        scene.add_box(f"side_{side:+d}", (0.3, 0.02, 0.72), _at(0.7, side * 0.4, 0.4))
    scene.add_box("back", (0.02, 0.8, 0.72), _at(0.85, 0.0, 0.4))
    scene.set_tool([geometry.box((0.08, 0.12, 0.07), _at(0.0, 0.0, 0.035))],
                   tcp=_at(0.0, 0.0, 0.14))

    planner = planning.Planner(robokin.load("ur5"), scene)
    start = np.array([0.0, -1.57, 0.0, -1.57, 0.0, 0.0])  # upright [rad]
    goal = pose_from_xyz_rpy(np.array([0.72, 0.0, 0.57]),  # TCP in the cell [m]
                             np.array([0.0, np.pi / 2, 0.0]))  # tool along +x
    res = planner.plan(start, goal, clearance=0.005, seed=0)  # 5 mm [m]
    if not res.success or res.goal is None:
        print("no path:", res.reason)
        return
    print(f"path in {res.time * 1e3:.1f} ms: {len(res.q)} waypoints, joint-space "
          f"length {res.length:.2f} rad; goal {res.goal_index} of {len(res.goals)} "
          "IK solutions (numbered from 0)")
    traj = planner.trajectory(res, clearance=0.005)
    print(f"time-optimal trajectory: {traj.duration:.2f} s, {len(traj)} samples, "
          "every step proven collision-free")
    print("end [deg]:", np.degrees(res.goal).round(1))
    back = planner.plan(res.goal, start, clearance=0.005, seed=1)
    print(f"the way back: {back.reason} in {back.time * 1e3:.1f} ms, "
          f"{len(back.q)} waypoints")


if __name__ == "__main__":
    main()
