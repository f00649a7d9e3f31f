# /// script
# requires-python = ">=3.10"
# dependencies = ["robokin"]
# ///
"""Forward kinematics and every inverse-kinematics solution.

Takes the UR5 to a pose, asks the closed-form solver for all of its joint
solutions (up to eight: shoulder left/right, elbow up/down, wrist flipped or
not), checks each one with FK, and picks the one nearest the current
configuration, as a controller would to avoid a branch flip.

Requirements: robokin (core only).
"""

from __future__ import annotations

import numpy as np

import robokin


def main() -> None:
    """Solve IK for one pose and print every solution with its FK error."""
    robot = robokin.load("ur5")
    q_goal = np.array([0.5, -1.1, 1.3, -0.9, 0.7, 0.3])  # [rad]
    T = robot.fk(q_goal)  # (4, 4) tool pose in the base frame [m]
    print("target position [mm]:", np.round(T[:3, 3] * 1000, 2))

    sols = robot.ik(T)
    q_all = sols.q[sols.valid]  # (k, n) the real solutions
    print(f"{len(q_all)} solutions ({sols.method})")
    names = list(sols.branches)
    for i, q in enumerate(q_all):
        err = np.abs(robot.fk(q) - T).max()
        labels = ", ".join(
            f"{b}={int(sols.branches[b][sols.valid][i]):+d}" for b in names
        )
        print(f"  {np.round(np.degrees(q), 2)} deg  |FK - T| = {err:.1e}  {labels}")
        if err > 1e-8:
            raise SystemExit("an IK solution does not reach the pose")

    q_now = q_goal + 0.05  # [rad] the arm is near the goal already
    q_best = sols.nearest(q_now)
    print(
        "nearest to the current configuration:", np.round(np.degrees(q_best), 2), "deg"
    )


if __name__ == "__main__":
    main()
