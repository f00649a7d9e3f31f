# /// script
# requires-python = ">=3.10"
# dependencies = ["robokin", "matplotlib"]
# ///
"""A straight Cartesian line, with plots.

Moves the UR5's tool 300 mm along a straight line at constant orientation with a
quintic speed profile, checks that the tool really stays on the line, checks the
joint limits, and saves the joint angle/velocity/acceleration plot, the tool
position over time and the 3D tool path with its projections as PNG files.

Requirements: robokin (core; matplotlib is a core dependency).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # write files, no window

import numpy as np  # noqa: E402

import robokin  # noqa: E402
from robokin import trajectory  # noqa: E402
from robokin.viz import plots  # noqa: E402


def main(out_dir: Path = Path("robokin-examples") / "cartesian_line") -> None:
    """Plan the line, check it and write the plots into ``out_dir``."""
    robot = robokin.load("ur5")
    q_start = np.array([0.0, -1.2, 1.4, -1.8, -1.57, 0.0])  # [rad]
    T_start = robot.fk(q_start)
    T_goal = T_start.copy()
    T_goal[:3, 3] += [0.0, 0.3, 0.0]  # [m] 300 mm along y, same orientation

    tr = trajectory.cartesian_line(robot, q_start, T_goal, 2.0, dt=0.005)
    p = robot.fk(tr.q)[:, :3, 3]  # (m, 3) tool positions [m]
    a, b = T_start[:3, 3], T_goal[:3, 3]
    u = (b - a) / np.linalg.norm(b - a)
    off_line = np.linalg.norm((p - a) - ((p - a) @ u)[:, None] * u, axis=1).max()
    print(
        f"{len(tr.t)} samples, {tr.t[-1]:.2f} s; largest distance from the line "
        f"{off_line * 1e6:.2f} um"
    )
    print(
        "peak joint speeds [deg/s]:", np.round(np.degrees(np.abs(tr.qd).max(axis=0)), 1)
    )
    print("within joint limits:", bool(robot.within_limits(tr.q).all()))

    out_dir.mkdir(parents=True, exist_ok=True)
    plots.plot_joints(tr, path=out_dir / "joints.png", overwrite=True)
    plots.plot_tool_position(
        tr, robot, path=out_dir / "tool_position.png", overwrite=True
    )
    plots.plot_tool_path(tr, robot, path=out_dir / "tool_path.png", overwrite=True)
    print(
        "wrote", ", ".join(sorted(f.name for f in out_dir.glob("*.png"))), "in", out_dir
    )
    if off_line > 1e-6:
        raise SystemExit("the tool left the line")


if __name__ == "__main__":
    main()
