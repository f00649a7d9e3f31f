# /// script
# requires-python = ">=3.10"
# dependencies = ["robokin"]
# ///
"""Workspace of the SCARA and a standalone HTML animation of the UR5.

Samples 300,000 SCARA configurations inside the joint limits (batch FK), prints
the reachable bounds and the volume of its position workspace (Monte Carlo, with
its standard error), saves the XY / XZ sections
coloured by manipulability, then writes a self-contained HTML file that plays
a UR5 motion in any browser with no server and no network.

Requirements: robokin (core only).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # write files, no window

import numpy as np  # noqa: E402

import robokin  # noqa: E402
from robokin import trajectory  # noqa: E402
from robokin.kinematics.workspace import sample_workspace  # noqa: E402
from robokin.viz.html import write_html  # noqa: E402
from robokin.viz.plots import save_workspace_plots  # noqa: E402


def main(out_dir: Path = Path("robokin-examples") / "visualisation") -> None:
    """Write the workspace plots and the animation into ``out_dir``."""
    scara = robokin.load("scara")
    ws = sample_workspace(scara, 300_000, rng=np.random.default_rng(0))
    lo, hi = ws.bounds * 1000  # [mm]
    print(
        f"SCARA workspace: x {lo[0]:.0f}..{hi[0]:.0f}, y {lo[1]:.0f}..{hi[1]:.0f}, "
        f"z {lo[2]:.0f}..{hi[2]:.0f} mm; volume {ws.volume:.4f} "
        f"+- {ws.volume_std_error:.4f} m^3"
    )
    out_dir.mkdir(parents=True, exist_ok=True)
    for path in save_workspace_plots(ws, out_dir):
        print("wrote", path)

    ur5 = robokin.load("ur5")
    q0 = np.array([0.0, -1.2, 1.4, -1.8, -1.57, 0.0])  # [rad]
    q1 = np.array([1.2, -0.8, 1.0, -1.6, -1.57, 0.5])
    tr = trajectory.quintic(q0, q1, 2.0, dt=0.01)
    html = write_html(
        out_dir / "ur5_motion.html", ur5, tr, title="UR5: a quintic joint move"
    )
    print("wrote", html, "- open it in a browser")


if __name__ == "__main__":
    main()
