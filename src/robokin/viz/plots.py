"""Matplotlib figures: joint motion, tool position, tool path, plan vs run, the arm.

Figures are built with :class:`matplotlib.figure.Figure` directly (no pyplot
state), so they render headless with the Agg canvas and never open a window;
:func:`save_figure` writes PNG, SVG or PDF (by suffix) through a temporary file.
Angles are drawn in degrees and lengths in millimetres unless asked otherwise.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import numpy.typing as npt

from robokin.exceptions import InputError
from robokin.io.atomic import file_stem, save_figure_atomic

if TYPE_CHECKING:
    from robokin.kinematics.ik.self_motion import SelfMotion
    from robokin.robot import Robot
    from robokin.trajectory.samples import Trajectory

__all__ = [
    "FIGURE_FORMATS",
    "place_labels",
    "plot_comparison",
    "plot_joints",
    "plot_self_motion",
    "plot_robot",
    "plot_tool_path",
    "plot_tool_position",
    "save_figure",
    "plot_cross_section",
    "save_workspace_plots",
]

#: The figure files :func:`save_figure` writes, by suffix.
FIGURE_FORMATS = (".png", ".svg", ".pdf")


def _figure(figsize=(9.0, 7.0)):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def save_figure(fig: Any, path: str | Path, *, overwrite: bool = False,
                dpi: int = 120) -> Path:
    """Save ``fig`` as PNG, SVG or PDF (chosen by the suffix), atomically.

    Raises:
        InputError: unknown suffix, or the file exists and ``overwrite`` is False.
    """
    path = Path(path)
    if path.suffix.lower() not in FIGURE_FORMATS:
        raise InputError("path", f"expected a {', '.join(FIGURE_FORMATS)} file, got "
                         f"{path.name}")
    return save_figure_atomic(fig, path, overwrite=overwrite, dpi=dpi)


def place_labels(ax: Any, labels: list[tuple[float, float, str]], *,
                 fontsize: float = 6.0) -> list[Any]:
    """Write text labels at data points so that no two overlap.

    Each label is centred on its point (points outside the axes' view get no
    label); one that would overlap a label already
    placed moves up or down (alternately, a line further each time) until it
    overlaps none. Call it once the axes' limits and aspect are final.

    Args:
        ax: A matplotlib Axes.
        labels: ``(x, y, text)`` per label, in data coordinates, in the order to
            place them (earlier ones keep their place).
        fontsize: Font size [pt].

    Returns:
        The matplotlib ``Annotation`` of each label drawn.
    """
    fig = ax.figure
    fig.draw_without_rendering()  # the final layout (constrained) and aspect
    renderer = fig.canvas.get_renderer()
    step = fontsize * 1.3  # one line [pt]
    placed: list[Any] = []
    texts = []
    for x, y, text in labels:
        if not ax.viewLim.contains(x, y):  # outside the view: not drawn
            continue
        note = ax.annotate(text, (x, y), xytext=(0.0, 0.0), textcoords="offset points",
                           fontsize=fontsize, ha="center", va="center",
                           annotation_clip=True)
        for k in range(1, 41):
            box = note.get_window_extent(renderer)
            if not any(box.overlaps(other) for other in placed):
                break
            shift = (k + 1) // 2 * step * (1 if k % 2 else -1)
            note.set_position((0.0, shift))
        placed.append(note.get_window_extent(renderer))
        texts.append(note)
    return texts


Plane = Literal["xy", "xz", "yz"]
_AXES = {"x": 0, "y": 1, "z": 2}


def _plane_axes(plane: str) -> tuple[int, int, int]:
    if plane not in ("xy", "xz", "yz"):
        raise InputError("plane", f"expected 'xy', 'xz' or 'yz', got {plane!r}")
    a, b = _AXES[plane[0]], _AXES[plane[1]]
    return a, b, 3 - a - b


def plot_cross_section(
    ws: Any,
    plane: Plane = "xy",
    *,
    at: float | None = None,
    thickness: float | None = None,
    color_by: Literal["manipulability", "density"] = "manipulability",
    ax: Any = None,
) -> Any:
    """Plot a slab of the point cloud in a coordinate plane.

    Args:
        ws: The sampled workspace.
        plane: ``"xy"`` (top view), ``"xz"`` or ``"yz"`` (side views).
        at: Position of the slab along the third axis [m]; default the middle
            of the bounds.
        thickness: Slab thickness [m]; default 5 % of the extent along the
            third axis (at least 1 % of the largest extent).
        color_by: ``"manipulability"`` colours the subset with known
            manipulability; ``"density"`` draws a 2D histogram of all samples.
        ax: A matplotlib Axes to draw in; a new figure when None.

    Returns:
        The matplotlib Axes.
    """
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(6, 5.5))
    a, b, c = _plane_axes(plane)
    lo, hi = ws.bounds[0, c], ws.bounds[1, c]
    at = 0.5 * (lo + hi) if at is None else float(at)
    if thickness is None:
        thickness = max(0.05 * (hi - lo), 0.01 * float(np.max(ws.extent)))
    names = "xyz"
    if color_by == "manipulability" and ws.manipulability.size:
        pts = ws.points[ws.manipulability_index]
        sel = np.abs(pts[:, c] - at) <= 0.5 * thickness
        if not sel.any():  # a thin arm (e.g. planar): fall back to all of the subset
            sel = np.ones(len(pts), dtype=bool)
        sc = ax.scatter(
            pts[sel, a],
            pts[sel, b],
            c=ws.manipulability[sel],
            s=2,
            cmap="viridis",
            linewidths=0,
        )
        ax.figure.colorbar(sc, ax=ax, label="manipulability")
    elif color_by in ("density", "manipulability"):
        pts = ws.points
        sel = np.abs(pts[:, c] - at) <= 0.5 * thickness
        if not sel.any():
            sel = np.ones(len(pts), dtype=bool)
        h = ax.hist2d(pts[sel, a], pts[sel, b], bins=120, cmin=1, cmap="magma")
        ax.figure.colorbar(h[3], ax=ax, label="samples")
    else:
        raise InputError(
            "color_by", f"expected 'manipulability' or 'density', got {color_by!r}"
        )
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"{names[a]} [m]")
    ax.set_ylabel(f"{names[b]} [m]")
    ax.set_title(
        f"{ws.robot_name}: {plane.upper()} section, "
        f"{names[c]} = {at:.3f} ± {0.5 * thickness:.3f} m"
    )
    ax.grid(True, alpha=0.3)
    return ax


def save_workspace_plots(ws: Any, out_dir: str | Path) -> list[Path]:
    """Write the XY / XZ cross sections (manipulability and density) as PNG files.

    The figures of :func:`plot_cross_section`, each
    written atomically (an existing file is replaced only once the new one is
    complete).

    Args:
        ws: The sampled workspace (:func:`robokin.kinematics.workspace.sample_workspace`).
        out_dir: An existing folder.

    Returns:
        The paths written.

    Raises:
        InputError: ``out_dir`` is not a folder, or a file cannot be written.
    """
    out = Path(out_dir)
    if not out.is_dir():
        raise InputError("out_dir", f"{out} is not a folder")
    written = []
    paths = dict(zip(("xy", "xz"), workspace_plot_paths(ws.robot_name, out)))
    for plane in ("xy", "xz"):
        fig = _figure(figsize=(12.0, 5.5))
        axes = fig.subplots(1, 2)
        plot_cross_section(ws, plane, color_by="manipulability", ax=axes[0])
        plot_cross_section(ws, plane, color_by="density", ax=axes[1])
        written.append(save_figure(fig, paths[plane], overwrite=True, dpi=110))
    return written


def workspace_plot_paths(robot_name: str, out_dir: str | Path) -> list[Path]:
    """The files :func:`save_workspace_plots` writes for ``robot_name``: XY, then XZ."""
    return [Path(out_dir) / f"{file_stem(robot_name)}_workspace_{plane}.png"
            for plane in ("xy", "xz")]


def _finish(fig, path, overwrite):
    if path is not None:
        save_figure(fig, path, overwrite=overwrite)
    return fig


def _scales(traj, degrees: bool):
    rev = traj.revolute()
    ang = 180.0 / np.pi if degrees else 1.0
    au = "deg" if degrees else "rad"
    lu = "mm" if degrees else "m"
    s = np.where(rev, ang, 1000.0 if degrees else 1.0)
    mixed = rev.any() and not rev.all()
    unit = f"{au} | {lu}" if mixed else (au if rev.all() else lu)
    return s, unit


def plot_joints(traj: Trajectory, *, path: str | Path | None = None, degrees: bool = True,
                via: bool = True, title: str | None = None,
                overwrite: bool = False) -> Any:
    """Joint position, velocity and acceleration over time: three panels, a line per joint.

    Via points (``traj.via_times``) are marked by dotted vertical lines and dots
    on the position curves.

    Args:
        traj: A :class:`~robokin.trajectory.Trajectory`.
        path: Save to this PNG/SVG/PDF file too.
        degrees: Angles in degrees (lengths in mm), else rad and m.
        via: Mark the via points.
        title: Figure title.
        overwrite: Replace an existing file.

    Returns:
        The matplotlib Figure.
    """
    fig = _figure((10.0, 8.0))
    axes = fig.subplots(3, 1, sharex=True)
    s, unit = _scales(traj, degrees)
    names = traj.names()
    for ax, data, lab in ((axes[0], traj.q, unit), (axes[1], traj.qd, f"{unit}/s"),
                          (axes[2], traj.qdd, f"{unit}/s²")):
        for j in range(traj.n):
            ax.plot(traj.t, data[:, j] * s[j], label=names[j], linewidth=1.2)
        ax.set_ylabel(lab)
        ax.grid(True, alpha=0.3)
    axes[0].set_title("position")
    axes[1].set_title("velocity")
    axes[2].set_title("acceleration")
    axes[2].set_xlabel("time [s]")
    if via and traj.via_times.size:
        vt = traj.via_times
        qv = traj.at(vt) * s
        for ax in axes:
            for v in vt:
                ax.axvline(v, color="0.6", linestyle=":", linewidth=0.8)
        for j in range(traj.n):
            axes[0].plot(vt, qv[:, j], "o", color="k", markersize=3,
                         label="via points" if j == 0 else None)
    axes[0].legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize="small")
    fig.suptitle(title or f"joint motion: {traj.duration:.3g} s, {len(traj)} samples")
    return _finish(fig, path, overwrite)


def plot_self_motion(sm: SelfMotion, *, path: str | Path | None = None,
                     degrees: bool = True, mm: bool = True, samples: int = 721,
                     title: str | None = None, overwrite: bool = False) -> Any:
    """The branches of a self-motion manifold: one panel per joint, a line per branch.

    Each branch's joint value over the parameter t is drawn thin where it leaves a
    joint limit and thick over its intervals inside every limit
    (``sm.intervals``); limits are dashed, limit crossings dots and singular
    points crosses.

    Args:
        sm: A :class:`~robokin.kinematics.ik.self_motion.SelfMotion`
            (``robot.self_motion(T)``).
        path: Save to this PNG/SVG/PDF file too.
        degrees: Angles in degrees, else rad.
        mm: Prismatic joints (a track, and the parameter when it is one) in
            millimetres, else m.
        samples: Parameter values drawn per branch.
        title: Figure title.
        overwrite: Replace an existing file.

    Returns:
        The matplotlib Figure.
    """
    angle, length = (180.0 / np.pi if degrees else 1.0), (1000.0 if mm else 1.0)
    rev = sm.revolute
    per = np.where(rev, angle, length)  # (n,): rad or m -> drawn
    units = [("deg" if degrees else "rad") if r else ("mm" if mm else "m") for r in rev]
    if sm.joint is None or rev[sm.joint]:  # the swivel, or a revolute joint
        s_t, unit_t = angle, "deg" if degrees else "rad"
    else:
        s_t, unit_t = length, units[sm.joint]
    lo, hi = sm.domain
    t = np.linspace(lo, hi, int(samples))
    q = sm.sample(t)  # (m, k, n)
    inside = sm.inside(t)
    q = _break_wraps(q, sm.limits, rev)
    n = q.shape[-1]
    fig = _figure((10.0, 1.6 * n + 1.0))
    axes = fig.subplots(n, 1, sharex=True)
    colors = [f"C{b % 10}" for b in range(sm.n_branches)]
    for j, ax in enumerate(axes):
        s = per[j]
        for b in range(sm.n_branches):
            ax.plot(t * s_t, q[:, b, j] * s, color=colors[b], linewidth=0.6, alpha=0.5)
            ax.plot(t * s_t, np.where(inside[:, b], q[:, b, j], np.nan) * s,
                    color=colors[b], linewidth=2.0, label=f"branch {b}" if j == 0 else None)
        for v in sm.limits[j]:
            ax.axhline(v * s, color="0.3", linestyle="--", linewidth=0.8)
        for c in sm.crossings:
            if c.joint == j:
                ax.plot(c.t * s_t, sm.limits[j, 0 if c.limit == "lower" else 1] * s, "o",
                        color=colors[c.branch], markersize=3)
        ax.set_ylabel(f"q{j + 1} [{units[j]}]")
        ax.grid(True, alpha=0.3)
    for p in sm.singular:
        qp = sm.sample(p.t)[p.branch]
        for j, ax in enumerate(axes):
            ax.plot(p.t * s_t, qp[j] * per[j], "x", color="k", markersize=4)
    axes[-1].set_xlabel(f"{sm.parameter} [{unit_t}]")
    axes[0].legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize="small")
    fig.suptitle(title or f"self-motion over {sm.parameter}: {len(sm.intervals)} "
                          "in-limit interval(s) (thick)")
    return _finish(fig, path, overwrite)


def _break_wraps(q: np.ndarray, limits: np.ndarray, revolute: np.ndarray) -> np.ndarray:
    """``q`` (m, k, n) with NaN where a revolute joint jumps by a turn between samples.

    A branch row passing +-pi (outside the limits of an arm whose range is under a
    turn) is drawn as two lines, not a vertical stroke across the panel: the sample
    after a step larger than pi is blanked (the step from one sample to the next is
    far below pi elsewhere at the plot's 721 values; a joint with a range over a
    turn keeps its steps, and so does a prismatic one).
    """
    step = np.abs(np.diff(q, axis=0))
    wraps = revolute & ((limits[:, 1] - limits[:, 0]) <= 2.0 * np.pi)  # (n,)
    with np.errstate(invalid="ignore"):
        jump = (step > np.pi) & wraps
    out = q.copy()
    out[1:][jump] = np.nan
    return out


def _positions(traj: Trajectory, robot: Robot | None) -> np.ndarray:
    if traj.pose is not None:
        return traj.pose[:, :3, 3]
    if robot is None:
        raise InputError("robot", "the trajectory has no tool poses: pass the robot")
    return traj.tool_poses(robot)[:, :3, 3]


def plot_tool_position(traj: Trajectory, robot: Robot | None = None, *, path: str | Path | None = None,
                       mm: bool = True, relative: bool = False,
                       title: str | None = None, overwrite: bool = False) -> Any:
    """Tool position x, y, z over time (one line each).

    Args:
        traj: The trajectory (its ``pose`` is used when set).
        robot: Computes the tool poses when the trajectory has none.
        path: Save to a file too.
        mm: Millimetres (else metres).
        relative: Plot the displacement from the start.
        title: Figure title.
        overwrite: Replace an existing file.
    """
    p = _positions(traj, robot)
    if relative:
        p = p - p[0]
    k = 1000.0 if mm else 1.0
    fig = _figure((9.0, 4.5))
    ax = fig.subplots()
    for i, axis in enumerate("xyz"):
        ax.plot(traj.t, p[:, i] * k, label=axis)
    ax.set_xlabel("time [s]")
    word = "displacement" if relative else "position"
    ax.set_ylabel(f"tool {word} [{'mm' if mm else 'm'}]")
    ax.grid(True, alpha=0.3)
    ax.legend()
    fig.suptitle(title or f"tool {word} over time")
    return _finish(fig, path, overwrite)


def plot_tool_path(traj: Trajectory, robot: Robot | None = None, *, path: str | Path | None = None,
                   mm: bool = True, title: str | None = None,
                   overwrite: bool = False) -> Any:
    """Tool path in 3D, with its projections onto the XY, XZ and YZ planes.

    The 3D panel shows the path and its shadows on the three walls; three 2D
    panels show each projection with equal axes. Via points are marked.
    """
    p = _positions(traj, robot) * (1000.0 if mm else 1.0)
    u = "mm" if mm else "m"
    fig = _figure((10.0, 8.5))
    ax3 = fig.add_subplot(2, 2, 1, projection="3d")
    ax3.plot(p[:, 0], p[:, 1], p[:, 2], color="C0", linewidth=1.6, label="tool path")
    lo, hi = p.min(axis=0), p.max(axis=0)
    pad = 0.05 * max(float((hi - lo).max()), 1e-9)
    lo, hi = lo - pad, hi + pad
    shadow = {"color": "0.55", "linewidth": 0.8, "linestyle": "--"}
    ax3.plot(p[:, 0], p[:, 1], np.full(len(p), lo[2]), **shadow)
    ax3.plot(p[:, 0], np.full(len(p), hi[1]), p[:, 2], **shadow)
    ax3.plot(np.full(len(p), lo[0]), p[:, 1], p[:, 2], **shadow)
    ax3.set_xlim(lo[0], hi[0])
    ax3.set_ylim(lo[1], hi[1])
    ax3.set_zlim(lo[2], hi[2])
    ax3.set_xlabel(f"x [{u}]")
    ax3.set_ylabel(f"y [{u}]")
    ax3.set_zlabel(f"z [{u}]")
    vt = traj.via_times
    vi = np.unique(np.clip(np.searchsorted(traj.t, vt - 1e-9), 0, len(traj) - 1))
    ax3.scatter(p[vi, 0], p[vi, 1], p[vi, 2], color="k", s=10)
    for k, (a, b, name) in enumerate(((0, 1, "XY"), (0, 2, "XZ"), (1, 2, "YZ")),
                                     start=2):
        ax = fig.add_subplot(2, 2, k)
        ax.plot(p[:, a], p[:, b], color="C0", linewidth=1.4)
        ax.plot(p[vi, a], p[vi, b], "o", color="k", markersize=3)
        ax.plot(p[0, a], p[0, b], "s", color="C2", markersize=6, label="start")
        ax.plot(p[-1, a], p[-1, b], "^", color="C3", markersize=6, label="end")
        ax.set_xlabel(f"{'xyz'[a]} [{u}]")
        ax.set_ylabel(f"{'xyz'[b]} [{u}]")
        ax.set_title(f"{name} projection")
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, alpha=0.3)
        if k == 2:
            ax.legend(fontsize="small")
    fig.suptitle(title or "tool path")
    return _finish(fig, path, overwrite)


def plot_comparison(cmp: Any, *, path: str | Path | None = None, degrees: bool = True,
                    title: str | None = None, overwrite: bool = False) -> Any:
    """Plan vs real run: per-joint error over time, and the plan's acceleration."""
    rev = np.asarray(cmp.is_revolute, bool)
    s = np.where(rev, 180.0 / np.pi if degrees else 1.0, 1000.0 if degrees else 1.0)
    unit = ("deg" if degrees else "rad") if rev.all() else (
        ("mm" if degrees else "m") if not rev.any() else "deg | mm")
    fig = _figure((10.0, 7.0))
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    for j, name in enumerate(cmp.joint_names):
        ax1.plot(cmp.t, cmp.error[:, j] * s[j],
                 label=f"{name} (max {cmp.max_abs[j] * s[j]:.3g})", linewidth=1.0)
        ax2.plot(cmp.t, cmp.plan_qdd[:, j] * s[j], linewidth=1.0)
    ax1.set_ylabel(f"error real − plan [{unit}]")
    ax1.grid(True, alpha=0.3)
    ax1.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize="small")
    ax2.set_ylabel(f"planned acceleration [{unit}/s²]")
    ax2.set_xlabel("time [s]")
    ax2.grid(True, alpha=0.3)
    fig.suptitle(title or "tracking error: logged run vs plan")
    return _finish(fig, path, overwrite)


def plot_robot(robot: Robot, q: npt.ArrayLike, ax: Any = None, frames: bool = True, *,
               path: str | Path | None = None, frame_size: float | None = None,
               color: str = "C0", overwrite: bool = False) -> Any:
    """The arm at ``q`` as a 3D stick figure: link frames joined, joints dotted.

    Args:
        robot: The :class:`~robokin.robot.Robot`.
        q: One configuration (n,) [rad, m].
        ax: A 3D matplotlib axes to draw into (a new figure when None).
        frames: Draw each frame's x/y/z axes (red, green, blue).
        path: Save the figure too.
        frame_size: Length of the frame axes [m] (default 8 % of the arm's size).
        color: Colour of the links.
        overwrite: Replace an existing file.

    Returns:
        The Figure (of ``ax`` when given).
    """
    qv = np.asarray(q, dtype=np.float64)
    if qv.shape != (robot.n,):
        raise InputError("q", f"expected one configuration ({robot.n},), got {qv.shape}")
    F = robot.fk_all(qv)
    T_tool = robot.fk(qv)
    if not np.allclose(F[-1], T_tool, atol=1e-12):
        F = np.concatenate([F, T_tool[None]], axis=0)
    P = F[:, :3, 3]
    if ax is None:
        fig = _figure((7.0, 7.0))
        ax = fig.add_subplot(projection="3d")
    else:
        fig = ax.figure
    ax.plot(P[:, 0], P[:, 1], P[:, 2], "-", color=color, linewidth=3, label=robot.name)
    ax.scatter(P[:-1, 0], P[:-1, 1], P[:-1, 2], color="k", s=18)
    ax.scatter(*P[-1], color="C3", s=30, marker="^")
    span = float(np.ptp(P, axis=0).max()) or 0.1
    size = frame_size if frame_size is not None else 0.08 * span
    if frames:
        for T in F:
            o = T[:3, 3]
            for c, col in enumerate(("r", "g", "b")):
                e = o + size * T[:3, c]
                ax.plot([o[0], e[0]], [o[1], e[1]], [o[2], e[2]], color=col,
                        linewidth=1.0)
    mid = 0.5 * (P.max(axis=0) + P.min(axis=0))
    half = 0.55 * span + size
    ax.set_xlim(mid[0] - half, mid[0] + half)
    ax.set_ylim(mid[1] - half, mid[1] + half)
    ax.set_zlim(mid[2] - half, mid[2] + half)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.set_title(f"{robot.name}")
    return _finish(fig, path, overwrite)
