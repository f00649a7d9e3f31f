# /// script
# requires-python = ">=3.10"
# dependencies = ["robokin[collision]"]
# ///
"""Check a motion for collisions and clearance.

Builds a small cell in code (a table and a post), mounts a gripper on the UR5,
plans a joint move that swings the arm past the post, and asks the collision
checker for the minimum distance over the motion, where and when it occurs,
and any collision intervals, against a 4 mm clearance.

Requirements: robokin[collision] (coal, trimesh).
"""

from __future__ import annotations

import numpy as np

import robokin
from robokin import collision, trajectory
from robokin.model import geometry


def _at(x: float, y: float, z: float) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = [x, y, z]  # [m]
    return T


def main() -> None:
    """Check one swing past a post; print the closest approach."""
    scene = collision.Scene("cell")
    scene.add_box("table", size=(0.5, 0.8, 0.04), pose=_at(0.55, -0.3, -0.05))
    scene.add_cylinder("post", radius=0.05, length=0.8, pose=_at(0.45, 0.45, 0.4))
    scene.set_tool(
        [geometry.box((0.06, 0.11, 0.08), _at(0.0, 0.0, 0.04))], tcp=_at(0, 0, 0.12)
    )

    robot = scene.attach(robokin.load("ur5"))  # base, gripper and its TCP
    q0 = np.array([-0.3, -1.3, 1.6, -1.9, -1.57, 0.0])  # [rad]
    q1 = np.array([1.9, -1.3, 1.6, -1.9, -1.57, 0.0])
    tr = trajectory.quintic(q0, q1, 3.0, dt=0.01)

    rep = collision.check(robot, scene, tr, clearance=0.004)  # 4 mm [m]
    c = rep.closest
    print(f"{len(tr.t)} samples; minimum distance {rep.min_distance * 1000:.1f} mm")
    if c is not None:
        print(f"  between {c.body_a} and {c.body_b} at t = {c.t:.2f} s")
    for pair in rep.pairs:
        if pair.kind == "object":  # the closest robot / scene pair
            print(
                f"  closest to the scene: {pair.body_a} / {pair.body_b} "
                f"{pair.distance * 1000:.1f} mm at t = {pair.t:.2f} s"
            )
            break
    print("collides:", rep.collides, "| clearance violated:", rep.violated)
    for first, last, a, b in rep.collisions:
        print(
            f"  collision {a} / {b}: samples {first}..{last} "
            f"(t = {tr.t[first]:.2f}..{tr.t[last]:.2f} s)"
        )


if __name__ == "__main__":
    main()
