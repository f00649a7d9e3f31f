# /// script
# requires-python = ">=3.10"
# dependencies = ["robokin[sim]"]
# ///
"""The SCARA in MuJoCo: decoupled motor commands, inverse dynamics, a plot.

Plans a move that swings the SCARA's arm while its shaft turns half a turn and
rises 100 mm, drives the four motors in MuJoCo with the decoupled commands
``phi = A^+ (q - b)`` and with naive ones that ignore the ball-screw / ball-spline
coupling, and prints how far each run strays from the plan; then the torques and
power the plan needs (inverse dynamics). Writes the comparison plot.

Requirements: robokin[sim] (MuJoCo).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import robokin
from robokin import sim, trajectory
from robokin.sim.report import plot_decoupling


def main() -> None:
    """Simulate the shaft motion both ways and report the errors and the torques."""
    robot = robokin.load("scara")
    q0 = np.array([0.0, 0.0, 0.0, 0.05])  # [rad, rad, rad, m]
    q1 = np.array([0.5, 0.8, np.pi, 0.15])  # half a shaft turn, 100 mm up
    plan = trajectory.quintic(q0, q1, 2.0, dt=0.005)
    check = sim.check_decoupling(robot, plan)
    for label, err in (("decoupled", check.decoupled_error),
                       ("naive", check.naive_error)):
        print(f"{label:9s} commands: shaft rotation off by {np.degrees(err[0]):.3f} deg,"
              f" height off by {err[1] * 1000:.2f} mm")
    print("decoupling check", "passed" if check.passed else "FAILED")

    inv = sim.inverse_dynamics(robot, plan)
    print("peak joint torques:", "  ".join(
        f"{n} {v:.3g}" for n, v in zip(robot.joint_names, inv.peak)))
    if inv.motor_power is not None and inv.motor_names is not None:  # it has motors
        peak_power = np.abs(inv.motor_power).max(axis=0)  # [W]
        print("peak motor power [W]:", "  ".join(
            f"{n} {v:.3g}" for n, v in zip(inv.motor_names, peak_power)))
    print(f"mass properties: {inv.links.describe()}")
    out_dir = Path("robokin-examples")
    out_dir.mkdir(exist_ok=True)
    plot_decoupling(check, path=out_dir / "scara_decoupling.png", overwrite=True)
    print(f"wrote {out_dir / 'scara_decoupling.png'}")
    if not check.passed:
        raise SystemExit("the decoupled commands did not follow the plan")


if __name__ == "__main__":
    main()
