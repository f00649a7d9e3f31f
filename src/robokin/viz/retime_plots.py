"""The bottleneck plot of a cycle-time report (:mod:`robokin.trajectory.cycle_time`).

One row per joint, one column per limited quantity (velocity, acceleration, and
jerk when limited): the joint's value along the path against its limits (red
dashes), for the time-optimal motion (solid) and, when asked, the slower one
(dashed). Red bands mark where that joint is at that limit: the bottleneck. The
horizontal axis is the time of the time-optimal motion; the slower motion is drawn
at the same points of the path (each of its moves is the time-optimal one
stretched by one factor, so its sample at ``t`` in a section lies where the
time-optimal motion is at ``t / c``). Section boundaries are dotted and labelled
on top.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from robokin.viz.plots import _figure, _scales, save_figure

__all__ = ["plot_bottlenecks"]

_KIND_UNITS = {"velocity": "/s", "acceleration": "/s²", "jerk": "/s³"}


def _same_path_times(fast: Any, slow: Any) -> np.ndarray:
    """Times of the time-optimal motion at the path points of the slower one."""
    t = slow.trajectory.t
    out = np.empty_like(t)
    for a, b in zip(fast.sections, slow.sections):
        inside = (t >= b.t_start) & (t <= b.t_end)
        c = b.duration / a.duration if a.duration > 0 else 1.0
        out[inside] = a.t_start + (t[inside] - b.t_start) / c
    return out


def _values(result: Any, kind: str) -> np.ndarray:
    tr = result.trajectory
    return {"velocity": tr.qd, "acceleration": tr.qdd, "jerk": result.jerk}[kind]


def plot_bottlenecks(report: Any, *, path: str | Path | None = None,
                     degrees: bool = True, title: str | None = None,
                     overwrite: bool = False) -> Any:
    """Velocity and acceleration (and jerk) of each joint against its limits.

    Args:
        report: A :class:`~robokin.trajectory.cycle_time.CycleTimeReport`.
        path: Also save to this PNG/SVG/PDF file.
        degrees: Angles in degrees (lengths in mm), else rad and m.
        title: Figure title (default: the cycle times).
        overwrite: Replace an existing file.

    Returns:
        The matplotlib Figure.
    """
    fast = report.minimum
    slow = report.slower
    tr = fast.trajectory
    lim = fast.limits
    kinds = ["velocity", "acceleration"] + (["jerk"] if lim.jerk is not None else [])
    n = tr.n
    fig = _figure((4.2 * len(kinds) + 1.0, 1.55 * n + 1.6))
    axes = np.atleast_2d(fig.subplots(n, len(kinds), sharex=True, squeeze=False))
    scale, _ = _scales(tr, degrees)
    units = np.where(tr.revolute(), "deg" if degrees else "rad", "mm" if degrees else "m")
    names = tr.names()
    x_fast = tr.t
    x_slow = None if slow is None else _same_path_times(fast, slow)
    starts = np.array([s.t_start for s in fast.sections])
    for c, kind in enumerate(kinds):
        limit = lim.get(kind) if hasattr(lim, "get") else getattr(lim, kind)
        active = report.active[kind]
        for j in range(n):
            ax = axes[j, c]
            s = scale[j]
            at = active[:, j]
            ax.fill_between(x_fast, 0, 1, where=at, color="tab:red", alpha=0.15,
                            transform=ax.get_xaxis_transform(), linewidth=0)
            ax.plot(x_fast, _values(fast, kind)[:, j] * s, color="tab:blue", lw=1.0,
                    label=f"minimum {fast.duration:.3g} s")
            if slow is not None and x_slow is not None:
                ax.plot(x_slow, _values(slow, kind)[:, j] * s, color="tab:orange",
                        lw=1.0, ls="--", label=f"retimed {slow.duration:.3g} s")
            for sign in (1, -1):
                ax.axhline(sign * limit[j] * s, color="tab:red", ls="--", lw=0.8)
            for x in starts[1:]:
                ax.axvline(x, color="0.6", ls=":", lw=0.7)
            ax.grid(True, alpha=0.25)
            ax.tick_params(labelsize=7)
            label = f"[{units[j]}{_KIND_UNITS[kind]}]"
            ax.set_ylabel(f"{names[j]}\n{label}" if c == 0 else label, fontsize=8)
        axes[-1, c].set_xlabel("time in the time-optimal motion [s]")
        top = axes[0, c].secondary_xaxis("top")
        ends = np.concatenate([starts[1:], [fast.duration]])
        top.set_xticks((starts + ends) / 2, [s.label or s.kind for s in fast.sections],
                       fontsize=6, rotation=35, ha="left")
        axes[0, c].set_title(kind, fontsize=10, pad=46)
    axes[0, -1].legend(fontsize=7, loc="upper right")
    planned = "" if fast.source_duration is None else \
        f", planned {fast.source_duration:.3g} s"
    fig.suptitle(title or f"bottlenecks: minimum cycle time {fast.duration:.3g} s"
                 f"{planned} (red bands: the joint at that limit)", fontsize=11)
    if path is not None:
        save_figure(fig, path, overwrite=overwrite)
    return fig
