"""Plots render headless to PNG/SVG/PDF files that are non-trivial, with the lines expected."""

import numpy as np
import pytest

import robokin
from robokin import InputError, trajectory
from robokin.trajectory.compare import compare
from robokin.viz import plots


@pytest.fixture(scope="module")
def robot():
    return robokin.load("aubo_i5")


@pytest.fixture(scope="module")
def path_traj(robot):
    q0 = np.radians([0, 10, 80, 0, 90, 0])
    pb = trajectory.PathBuilder(robot, q0, dt=0.01)
    pb.joint(np.radians([30, 20, 70, 0, 90, 0]), duration=1.0)
    T = robot.fk(pb.q_end)
    T[2, 3] -= 0.05
    pb.line(T, duration=0.5)
    pb.joint(q0, duration=1.0)
    return pb.build()


def _labels(ax):
    return [ln.get_label() for ln in ax.get_lines() if not ln.get_label().startswith("_")]


def test_joint_figure_three_panels_a_line_per_joint(path_traj, robot, tmp_path):
    fig = plots.plot_joints(path_traj, path=tmp_path / "joints.png")
    axes = fig.axes
    assert len(axes) == 3
    for ax in axes:
        names = [lb for lb in _labels(ax) if lb in robot.joint_names]
        assert len(names) == 0 or names == list(robot.joint_names)
    assert _labels(axes[0]).count("via points") == 1
    assert sum(lb in robot.joint_names for lb in _labels(axes[0])) == 6
    assert len([ln for ln in axes[1].get_lines()]) >= 6
    assert axes[0].get_ylabel() == "deg" and axes[2].get_ylabel() == "deg/s²"
    # via points marked: a dotted vertical line per via time in every panel
    vlines = [ln for ln in axes[1].get_lines() if ln.get_linestyle() == ":"]
    assert len(vlines) == len(path_traj.via_times) == 4
    f = tmp_path / "joints.png"
    assert f.stat().st_size > 20_000
    assert f.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("suffix, magic", [(".svg", b"<?xml"), (".pdf", b"%PDF")])
def test_tool_position_and_formats(path_traj, suffix, magic, tmp_path):
    f = tmp_path / f"xyz{suffix}"
    fig = plots.plot_tool_position(path_traj, path=f)
    assert _labels(fig.axes[0]) == ["x", "y", "z"]
    y = fig.axes[0].get_lines()[2].get_ydata()
    np.testing.assert_allclose(y, path_traj.pose[:, 2, 3] * 1000.0)
    assert f.read_bytes()[: len(magic)] == magic and f.stat().st_size > 5_000


def test_tool_path_3d_with_projections(path_traj, robot, tmp_path):
    f = tmp_path / "path.png"
    fig = plots.plot_tool_path(path_traj, robot, path=f)
    ax3, *flat = fig.axes
    assert ax3.name == "3d" and len(flat) == 3
    assert len(ax3.get_lines()) == 4  # the path and its three shadows
    titles = sorted(ax.get_title() for ax in flat)
    assert titles == ["XY projection", "XZ projection", "YZ projection"]
    assert f.stat().st_size > 30_000


def test_comparison_and_robot_figures(path_traj, robot, tmp_path):
    real = path_traj.replace(q=path_traj.q + 1e-3)
    fig = plots.plot_comparison(compare(path_traj, real), path=tmp_path / "cmp.png")
    assert len(fig.axes[0].get_lines()) == 6
    fig = plots.plot_robot(robot, np.radians([0, 10, 80, 0, 90, 0]),
                           path=tmp_path / "arm.png")
    ax = fig.axes[0]
    # one stick line plus three axes per frame (base, 6 joints: 7 frames)
    assert len(ax.get_lines()) == 1 + 3 * 7
    stick = ax.get_lines()[0]
    xs, ys, zs = stick.get_data_3d()
    T = robot.fk(np.radians([0, 10, 80, 0, 90, 0]))
    np.testing.assert_allclose([xs[-1], ys[-1], zs[-1]], T[:3, 3], atol=1e-12)
    assert (tmp_path / "arm.png").stat().st_size > 20_000
    fig = robokin.viz.plot_robot(robot, np.zeros(6), frames=False)
    assert len(fig.axes[0].get_lines()) == 1


def test_refuses_to_overwrite_and_bad_suffix(path_traj, tmp_path):
    f = tmp_path / "j.png"
    f.write_bytes(b"mine")
    with pytest.raises(InputError, match="exists"):
        plots.plot_joints(path_traj, path=f)
    assert f.read_bytes() == b"mine"
    with pytest.raises(InputError, match="png"):
        plots.plot_joints(path_traj, path=tmp_path / "j.bmp")
    with pytest.raises(InputError, match="pass the robot"):
        plots.plot_tool_position(trajectory.quintic([0.0], [1.0], 1.0))
