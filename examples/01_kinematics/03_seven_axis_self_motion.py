# /// script
# requires-python = ">=3.10"
# dependencies = ["robokin"]
# ///
"""The whole self-motion of a Franka Panda at one pose, and a choice from it.

A 7-joint arm reaches a pose in a one-parameter family of configurations. This
takes the pose of a ready configuration, asks for the whole family
(``robot.self_motion``: every branch over q7, the intervals of q7 where a branch is
inside every joint limit, found exactly), checks that the ready configuration is on
it, picks the configuration with the widest joint-limit margin and the one nearest a
current configuration, and plots the branches.

Requirements: robokin (core only; matplotlib for the plot).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import robokin
from robokin.viz.plots import plot_self_motion


def main(out_dir: Path = Path("robokin-examples") / "self_motion") -> None:
    """Describe the Panda's self-motion at its ready pose and plot it into ``out_dir``."""
    panda = robokin.load("panda")
    ready = np.array([0.0, -0.3, 0.0, -2.0, 0.0, 1.8, 0.7])  # [rad]
    T = panda.fk(ready)
    sm = panda.self_motion(T)  # parameter: q7 (He and Liu's closed form)
    print(f"{sm.n_branches} branches over {sm.parameter}, "
          f"{len(sm.intervals)} in-limit interval(s) [{sm.method}]")
    for (a, b), branch in zip(sm.intervals, sm.interval_branch):
        print(f"  branch {branch}: q7 in [{np.degrees(a):8.3f}, {np.degrees(b):8.3f}] deg")

    rows = sm.sample(ready[6])  # every branch at q7 = 0.7: (8, 7), NaN where none
    back = np.nanmin(np.abs(rows - ready).max(axis=1))
    print(f"the ready configuration is on the manifold: {back:.1e} rad away")

    best = sm.best("margin")
    assert best is not None  # some part is inside the limits
    err = np.abs(panda.fk(best.q) - T).max()
    print(f"widest margin {np.degrees(best.score):.1f} deg on branch {best.branch} at "
          f"q7 = {np.degrees(best.t):.2f} deg: q [deg] {np.round(np.degrees(best.q), 2)}"
          f" (pose error {err:.0e})")
    current = ready + np.radians([20.0, 0.0, -20.0, 0.0, 10.0, 0.0, 15.0])
    near = sm.nearest(current)
    assert near is not None
    print(f"nearest to the current joints: q7 = {np.degrees(near.t):.2f} deg, "
          f"{np.degrees(-near.score):.2f} deg away")

    out_dir.mkdir(parents=True, exist_ok=True)
    plot_self_motion(sm, path=out_dir / "branches.png", overwrite=True)
    print("wrote", out_dir / "branches.png")


if __name__ == "__main__":
    main()
