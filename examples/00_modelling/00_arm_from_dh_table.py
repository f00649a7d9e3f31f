# /// script
# requires-python = ">=3.10"
# dependencies = ["robokin"]
# ///
"""Model an arm from a DH table.

Builds the AUBO-i5 from its published standard DH table (joint 3 reversed), then
checks the result against the built-in model: same tool pose at random
configurations. Shows the canonical chain every model compiles to and the frames
``fk_all`` reports.

Requirements: robokin (core only).
"""

from __future__ import annotations

import math

import numpy as np

import robokin

DEG = math.pi / 180.0  # [rad/deg]

# AUBO-i5, standard DH [m, rad]: T_i = Rz(theta) Tz(d) Tx(a) Rx(alpha). Joint 3's
# axis is reversed relative to a UR arm's: alpha2 = alpha3 = 180 deg.
AUBO_I5_ROWS = [
    {"name": "shoulder", "a": 0.0, "alpha": 90 * DEG, "d": 0.122, "theta": 0.0},
    {"name": "upper_arm", "a": 0.408, "alpha": 180 * DEG, "d": 0.0, "theta": 90 * DEG},
    {"name": "forearm", "a": 0.376, "alpha": 180 * DEG, "d": 0.0, "theta": 0.0},
    {"name": "wrist_1", "a": 0.0, "alpha": 90 * DEG, "d": 0.1215, "theta": 90 * DEG},
    {"name": "wrist_2", "a": 0.0, "alpha": -90 * DEG, "d": 0.1025, "theta": 0.0},
    {"name": "wrist_3", "a": 0.0, "alpha": 0.0, "d": 0.094, "theta": 180 * DEG},
]


def main() -> None:
    """Build the arm, print its chain and compare it with the built-in AUBO-i5."""
    rows = [
        dict(r, joint="revolute", limits=[-175 * DEG, 175 * DEG]) for r in AUBO_I5_ROWS
    ]
    robot = robokin.Robot.from_dh(rows, convention="standard", name="my_aubo_i5")
    print(robot, "joints:", robot.joint_names)

    q0 = np.zeros(robot.n)  # [rad]
    print("tool pose at zero [m]:")
    print(np.array2string(robot.fk(q0), precision=4, suppress_small=True))
    frames = robot.fk_all(q0)  # (n + 1, 4, 4): base, then each link frame
    for name, T in zip(("base", *robot.joint_names), frames):
        print(f"  {name:10s} origin [mm]: {np.round(T[:3, 3] * 1000, 1)}")

    builtin = robokin.load("aubo_i5")
    rng = np.random.default_rng(0)
    q = rng.uniform(-np.pi, np.pi, size=(1000, robot.n))  # [rad]
    err = np.abs(robot.fk(q) - builtin.fk(q)).max()
    print(f"largest difference from the built-in aubo_i5 over 1000 poses: {err:.2e}")
    if err > 1e-9:
        raise SystemExit("the DH table disagrees with the built-in model")


if __name__ == "__main__":
    main()
