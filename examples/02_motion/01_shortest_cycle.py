# /// script
# requires-python = ">=3.10"
# dependencies = ["robokin[retime]", "matplotlib"]
# ///
"""The shortest cycle of a pick-and-place path, and what limits it.

Plans a UR5 pick-and-place path (a joint move, a straight line down, a dwell, the
line back up, a joint move home), retimes the same path to its minimum cycle time
within the UR5's joint limits from its robot file (TOPP-RA through toppra), prints
which joint and which limit holds each section back, retimes it again to a slower
cycle time with its margins, and writes the bottleneck plot.

Requirements: robokin with the retime extra (toppra, ruckig).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # write files, no window

import numpy as np  # noqa: E402

import robokin  # noqa: E402
from robokin import trajectory  # noqa: E402
from robokin.spatial import trans  # noqa: E402
from robokin.trajectory.cycle_time import cycle_time_report  # noqa: E402
from robokin.viz.retime_plots import plot_bottlenecks  # noqa: E402


def main(out_dir: Path = Path("robokin-examples") / "shortest_cycle") -> None:
    """Plan, retime, report and plot into ``out_dir``."""
    robot = robokin.load("ur5")
    q_home = np.array([0.0, -1.2, 1.4, -1.8, -1.57, 0.0])  # [rad]
    q_above = np.array([0.9, -1.0, 1.2, -1.8, -1.57, 0.3])  # [rad]
    path = trajectory.PathBuilder(robot, q_home, dt=0.005)
    path.joint(q_above, duration=3.0, label="to the part")
    T_above = robot.fk(q_above)
    path.line(trans(0, 0, -0.1) @ T_above, duration=1.5, label="down")  # [m]
    path.dwell(0.5, label="grip")
    path.line(T_above, duration=1.5, label="up")
    path.joint(q_home, duration=3.0, label="home")
    planned = path.build()

    report = cycle_time_report(robot, planned, cycle_time=5.0)  # [s]
    print(report)
    for b in report.bottlenecks[:6]:
        print(f"  {b.t_start:6.3f} .. {b.t_end:6.3f} s: {b.joint_name} at its {b.kind} "
              f"limit ({b.section})")
    out = report.minimum.trajectory
    margins = report.margins or {}  # set: a cycle time was asked for
    print(f"planned {planned.duration:.2f} s -> minimum {out.duration:.3f} s, "
          f"{len(out)} samples; velocity margins at 5 s: "
          f"{np.round(margins['velocity'] * 100, 1)} %")

    out_dir.mkdir(parents=True, exist_ok=True)
    plot_bottlenecks(report, path=out_dir / "bottlenecks.png", overwrite=True)
    print("wrote bottlenecks.png in", out_dir)


if __name__ == "__main__":
    main()
