# /// script
# requires-python = ">=3.10"
# dependencies = ["robokin"]
# ///
"""Position-only IK of the QFMD010 palletizer.

The QFMD010's parallelogram linkage keeps the tool level, so it has four
independent joints and reaches a position plus a yaw angle, not a full pose.
This asks the closed-form palletizer solver for a pick and a place position,
prints every solution and checks the tool positions with FK.

Requirements: robokin (core only).
"""

from __future__ import annotations

import numpy as np

import robokin


def main() -> None:
    """Solve the palletizer's IK for two positions."""
    robot = robokin.load("qfmd010")
    print(
        robot, "independent joints:", robot.joint_names, "chain joints:", robot.n_chain
    )
    lim = robot.limits
    for label, q_ref in (
        ("pick", [0.3, 0.5, 0.4, 0.2]),
        ("place", [-0.8, 0.3, 0.6, -0.5]),
    ):
        q_ref = np.clip(np.array(q_ref), lim[:, 0], lim[:, 1])  # [rad]
        T = robot.fk(q_ref)  # the tool stays level: only position and yaw matter
        sols = robot.ik(T)
        q_all = sols.q[sols.valid]
        print(
            f"{label}: target [mm] {np.round(T[:3, 3] * 1000, 1)}, {len(q_all)} solutions "
            f"({sols.method})"
        )
        for q in q_all:
            p_err = np.linalg.norm(robot.fk(q)[:3, 3] - T[:3, 3])  # [m]
            inside = bool(robot.within_limits(q))
            print(
                f"  {np.round(np.degrees(q), 2)} deg  position error {p_err:.1e} m  "
                f"within limits: {inside}"
            )
            if p_err > 1e-8:
                raise SystemExit("an IK solution misses the position")


if __name__ == "__main__":
    main()
