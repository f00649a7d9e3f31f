"""Per-waypoint diagnostics drawn: a matplotlib figure and markers for the 3D views.

:func:`plot_follow` draws what :func:`robokin.process.follow` found along the
path: the tool path with every waypoint green (usable configurations), red (none:
out of reach, limits, singular, collision) or orange (the waypoint where every
path dies, a jump), the joints of the motion against the waypoint index with the
bad waypoints shaded, and the step, manipulability and limit distance of the
chosen configurations. :func:`path_markers` gives the same colours as small
spheres that the 3D viewer (:func:`robokin.viz.viewer.view`) and the HTML export
(:func:`robokin.viz.html.write_html`) draw as part of their ``scene``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from robokin.exceptions import InputError
from robokin.process.report import FollowResult

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["path_markers", "plot_follow"]


def _check_result(result: Any) -> FollowResult:
    if not isinstance(result, FollowResult):
        raise InputError("result", f"expected the FollowResult of robokin.process.follow, "
                         f"got {type(result).__name__}")
    return result


def path_markers(result: FollowResult, *, scene: Any = None,
                 radius: float = 0.006) -> list[Any]:
    """The waypoints as coloured spheres, for the 3D viewer and the HTML export.

    Args:
        result: What :func:`robokin.process.follow` returned.
        scene: A :class:`~robokin.collision.Scene` whose objects come first in the
            list (so one ``scene=`` argument draws both), or None.
        radius: Sphere radius [m].

    Returns:
        ``robokin.viz._common.SceneShape`` records: the scene's objects, then one
        sphere per waypoint named ``waypoint NNNN`` at the waypoint's tool
        position, green / red / orange as ``result.waypoints.colors()``. Pass the
        list as ``scene=`` to ``write_html``, ``notebook_view`` or ``view``.

    Raises:
        InputError: ``result`` is not a FollowResult, or ``radius`` is not > 0.
    """
    from robokin.viz._common import SceneShape, scene_shapes

    res = _check_result(result)
    if not (isinstance(radius, (int, float)) and math.isfinite(radius) and radius > 0):
        raise InputError("radius", f"expected a radius > 0 [m], got {radius!r}")
    wp = res.waypoints
    colors = wp.colors()
    width = len(str(max(wp.position.shape[0] - 1, 0)))
    out: list[Any] = list(scene_shapes(scene))
    for i, (p, c) in enumerate(zip(wp.position, colors, strict=True)):
        pose = np.eye(4)
        pose[:3, 3] = p
        out.append(SceneShape(f"waypoint {i:0{width}d}", "sphere", (float(radius),), pose,
                              (int(c[0]), int(c[1]), int(c[2]))))
    return out


def plot_follow(result: FollowResult, *, robot: Robot | None = None, path: str | Path | None = None,
                degrees: bool = True, title: str | None = None,
                overwrite: bool = False) -> Any:
    """The diagnostics of a followed path: where it is reachable, the motion, its margins.

    Three panels: the tool path seen from above (x-y, and x-z beside it) with a
    marker per waypoint (green: usable configurations, red: none, orange: the
    jump every path dies at); the joints of the motion against the waypoint
    index, the bad waypoints shaded red and the failure written in the title;
    the largest joint step into each waypoint, the relative manipulability and
    the distance to the nearest limit of the chosen configurations.

    Args:
        result: What :func:`robokin.process.follow` returned.
        robot: The robot, for joint names and units (revolute in deg, prismatic in
            mm); None: ``q1..qn``, all angles.
        path: Also save the figure to this PNG/SVG/PDF file (atomically).
        degrees: Angles in degrees (lengths in mm), else rad and m.
        title: Title (default: feasible or the failure's reason).
        overwrite: Replace an existing file.

    Returns:
        The matplotlib Figure (no pyplot state; renders headless).

    Raises:
        InputError: ``result`` is not a FollowResult; a bad ``path``.
    """
    from robokin.viz.plots import _figure, save_figure

    res = _check_result(result)
    wp = res.waypoints
    N, n = res.q.shape
    revolute = (np.ones(n, dtype=bool) if robot is None
                else np.asarray(robot.is_revolute, dtype=bool))
    names = [f"q{j + 1}" for j in range(n)] if robot is None else list(robot.joint_names)
    scale = np.where(revolute, 180.0 / math.pi if degrees else 1.0,
                     1000.0 if degrees else 1.0)
    unit = "deg" if degrees else "rad"
    fig = _figure((11.0, 8.0))
    grid = fig.add_gridspec(3, 2, height_ratios=[1.3, 1.2, 1.0])
    _draw_path(fig.add_subplot(grid[0, 0]), wp, (0, 1))
    _draw_path(fig.add_subplot(grid[0, 1]), wp, (0, 2))
    ax_q = fig.add_subplot(grid[1, :])
    k = np.arange(N)
    for j in range(n):
        ax_q.plot(k, res.q[:, j] * scale[j], label=names[j], linewidth=1.2)
    ax_q.set_ylabel(f"joint [{unit}{' | mm' if not revolute.all() else ''}]")
    ax_q.legend(loc="upper right", fontsize="small", ncol=min(n, 6))
    ax_m = fig.add_subplot(grid[2, :], sharex=ax_q)
    _draw_margins(ax_m, res, scale.min() if revolute.any() else 1.0, unit)
    for ax in (ax_q, ax_m):
        for bad in np.flatnonzero(wp.status != "ok"):
            color = (0.92, 0.55, 0.08) if wp.status[bad] == "jump" else (0.85, 0.16, 0.16)
            ax.axvspan(bad - 0.5, bad + 0.5, color=color, alpha=0.35, lw=0)
        ax.grid(True, alpha=0.3)
    ax_m.set_xlabel("waypoint")
    fig.suptitle((title or ("feasible: " + _summary(res) if res.feasible
                            else res.reason))[:200], fontsize="medium")
    if path is not None:
        save_figure(fig, path, overwrite=overwrite)
    return fig


def _summary(res: FollowResult) -> str:
    return (f"{res.q.shape[0]} waypoints, travel {res.travel:.4g}, "
            f"largest step {res.max_step:.4g}")


def _draw_path(ax: Any, wp: Any, axes: tuple[int, int]) -> None:
    """The tool positions [mm] on two world axes, a marker per waypoint by status."""
    p = wp.position * 1000.0
    a, b = axes
    ax.plot(p[:, a], p[:, b], color="0.6", linewidth=0.8, zorder=1)
    ax.scatter(p[:, a], p[:, b], c=wp.colors() / 255.0, s=14, zorder=2,
               edgecolors="none")
    label = "xyz"
    ax.set_xlabel(f"{label[a]} [mm]")
    ax.set_ylabel(f"{label[b]} [mm]")
    ax.set_aspect("equal", adjustable="datalim")
    good = int(wp.reachable.sum())
    ax.set_title(f"tool path ({label[a]}-{label[b]}): {good} of {wp.status.size} "
                 f"reachable", fontsize="small")


def _draw_margins(ax: Any, res: FollowResult, s: float, unit: str) -> None:
    """Step into each waypoint and limit distance (left), manipulability (right)."""
    wp = res.waypoints
    k = np.arange(wp.step.size)
    ax.plot(k, wp.step * s, color="k", linewidth=1.0, label=f"step [{unit}]")
    ax.plot(k, wp.limit_distance * s, color="tab:purple", linewidth=1.0,
            label=f"to nearest limit [{unit}]")
    ax.set_ylabel(unit)
    twin = ax.twinx()
    twin.plot(k, wp.manipulability, color="tab:green", linewidth=1.0,
              label="manipulability (relative)")
    twin.set_ylim(0.0, 1.05)
    twin.set_ylabel("manipulability")
    lines = ax.get_lines() + twin.get_lines()
    ax.legend(lines, [ln.get_label() for ln in lines], loc="upper left",
              fontsize="small", ncol=3)
