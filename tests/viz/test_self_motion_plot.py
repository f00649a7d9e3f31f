"""The self-motion plot: one panel per joint, thick in-limit intervals (real Agg render)."""

from __future__ import annotations

import numpy as np

from reference import iiwa14_srs
from robokin.viz.plots import plot_self_motion


def test_plot_draws_every_branch_and_saves(tmp_path):
    robot = iiwa14_srs()
    sm = robot.self_motion(robot.fk(np.array([0.3, 0.8, -0.4, 1.2, 0.5, -0.9, 0.2])))
    fig = plot_self_motion(sm, path=tmp_path / "sm.png", samples=181)
    axes = fig.axes
    assert len(axes) == 7
    # two lines per branch per panel (all, in-limit), then markers
    assert len(axes[0].lines) >= 2 * sm.n_branches
    # the thick line of branch b holds exactly the in-limit samples
    t = np.linspace(*sm.domain, 181)
    thick = axes[1].lines[3].get_ydata()  # branch 1, joint 2 (degrees)
    assert np.array_equal(np.isfinite(thick), sm.inside(t)[:, 1])
    assert (tmp_path / "sm.png").stat().st_size > 1000
