"""The self-motion plot: one panel per joint, thick in-limit intervals (real Agg render)."""

from __future__ import annotations

import numpy as np

from reference import iiwa14_srs, ur5_on_a_track
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


def test_a_branch_through_pi_is_not_drawn_across_the_panel():
    """The Panda's ready pose: branches 0 and 1 pass q1 = +-pi (outside q1's limits,
    +-2.8973): the drawn lines never step by more than pi between samples, and every
    other sample is drawn (only the one after each wrap is blanked)."""
    import robokin

    panda = robokin.load("panda")
    sm = panda.self_motion(panda.fk(np.array([0.0, -0.3, 0.0, -2.0, 0.0, 1.8, 0.7])))
    t = np.linspace(*sm.domain, 721)
    raw = sm.sample(t)[:, :, 0]  # q1 of every branch [rad]
    wraps = np.abs(np.diff(raw, axis=0)) > np.pi
    assert wraps.any()  # the pose exercises the case
    fig = plot_self_motion(sm, degrees=False)
    for b in range(sm.n_branches):
        drawn = fig.axes[0].lines[2 * b].get_ydata()
        steps = np.abs(np.diff(drawn))
        assert not (steps[np.isfinite(steps)] > np.pi).any()
        blanked = np.isnan(drawn) & np.isfinite(raw[:, b])
        assert blanked.sum() == wraps[:, b].sum()


def test_a_prismatic_parameter_is_drawn_in_millimetres():
    """A UR5 on a linear track, the track as the parameter: its panel and the x axis
    in mm (the track's range 0-2 m drawn 0-2000), the revolute joints in degrees."""
    arm = ur5_on_a_track()
    q = np.array([0.7, 0.3, -1.2, 1.1, -0.5, 0.8, 0.2])
    sm = arm.self_motion(arm.fk(q), "track")
    assert sm.revolute.tolist() == [False] + [True] * 6
    fig = plot_self_motion(sm, samples=61)
    axes = fig.axes
    assert axes[0].get_ylabel() == "q1 [mm]" and axes[1].get_ylabel() == "q2 [deg]"
    assert axes[-1].get_xlabel() == "track [mm]"
    x = axes[0].lines[0].get_xdata()
    assert x[0] == 0.0 and x[-1] == 2000.0
    dashed = [ln.get_ydata()[0] for ln in axes[0].lines if ln.get_linestyle() == "--"]
    assert dashed == [0.0, 2000.0]  # the track's limits
