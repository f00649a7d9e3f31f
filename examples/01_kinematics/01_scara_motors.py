# /// script
# requires-python = ">=3.10"
# dependencies = ["robokin"]
# ///
"""SCARA motor angles from a lift-and-rotate motion.

On a ball-screw / ball-spline SCARA shaft a motor turn can both rotate and lift
the shaft: turning the shaft without lifting it needs both shaft motors. This
plans a joint motion that lifts the shaft 150 mm while rotating the tool 90 deg,
converts it to motor coordinates with the robot's actuator map
(``q = A phi + b``) and back, and prints the motor travel.

Requirements: robokin (core only).
"""

from __future__ import annotations

import numpy as np

import robokin
from robokin import trajectory


def main() -> None:
    """Plan the shaft motion in joint space and map it to the four motors."""
    robot = robokin.load("scara")
    motors = robot.actuator_names  # None for a robot without an actuator map
    if motors is None:
        raise SystemExit("this example needs a robot whose joints are driven by motors")
    q0 = np.array([0.2, 0.8, 0.0, 0.0])  # [rad, rad, rad, m]
    q1 = np.array([0.2, 0.8, np.pi / 2, 0.150])  # rotate 90 deg, lift 150 mm
    tr = trajectory.quintic(q0, q1, 1.5, dt=0.005)  # .t (m,), .q (m, 4)
    phi = robot.actuators_from_joints(tr.q)  # (m, 4) motor coordinates [rad]
    back = robot.joints_from_actuators(phi)
    print(f"{len(tr.t)} samples over {tr.t[-1]:.2f} s")
    for name, a, b in zip(motors, phi[0], phi[-1]):
        print(
            f"  {name}: {a:9.3f} -> {b:9.3f} rad  ({np.degrees(b - a):9.1f} deg of travel)"
        )
    print("round trip joint error:", f"{np.abs(back - tr.q).max():.1e}")

    # The coupling: one joint moving alone may need several motors, and back.
    for label, dq in (
        ("pure 100 mm lift", [0, 0, 0, 0.1]),
        ("pure 90 deg turn", [0, 0, np.pi / 2, 0]),
    ):
        dphi = robot.actuators_from_joints(q0 + np.array(dq)) - phi[0]
        moving = [
            f"{n} ({np.degrees(d):.0f} deg)"
            for n, d in zip(motors, dphi)
            if abs(d) > 1e-9
        ]
        print(f"motors that turn for a {label}:", ", ".join(moving))
    if np.abs(back - tr.q).max() > 1e-9:
        raise SystemExit("actuator map round trip failed")


if __name__ == "__main__":
    main()
