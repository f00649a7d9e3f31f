"""Plots of a collision report (matplotlib, headless 'Agg' when saving)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from robokin.collision.report import CollisionReport

__all__ = ["plot_distance"]


def plot_distance(
    report: CollisionReport,
    pairs: Sequence[tuple[str, str]] | None = None,
    *,
    count: int = 4,
    clearance: float | None = None,
    out: str | Path | None = None,
    ax: Any = None,
) -> Any:
    """Distance over time of the closest body pairs, with the clearance marked.

    Args:
        report: A :class:`~robokin.collision.CollisionReport`.
        pairs: ``[(body_a, body_b), ...]`` to draw; default the ``count`` pairs
            that came closest.
        count: How many pairs by default.
        clearance: Threshold [m] to mark; default ``report.clearance`` (drawn
            when > 0). Contact (0) is always marked.
        out: Save the figure here (PNG, SVG, PDF by suffix; atomically, see
            :func:`robokin.io.atomic.write_atomic`) and close it.
        ax: Draw into this matplotlib Axes instead of a new figure.

    Returns:
        The matplotlib Figure.
    """
    import matplotlib

    if out is not None and ax is None:
        matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    if pairs is None:
        pairs = [(p.body_a, p.body_b) for p in report.pairs[:count]]
    thr = report.clearance if clearance is None else float(clearance)
    if ax is None:
        fig, ax = plt.subplots(figsize=(9, 4.5), constrained_layout=True)
    else:
        fig = ax.figure
    t = np.asarray(report.t)
    lowest = np.inf
    for a, b in pairs:
        d = report.distances(a, b)
        lowest = min(lowest, float(d.min()))
        ax.plot(t, d * 1e3, lw=1.4, label=f"{a} – {b}")
    for iv in report.intervals:
        ax.axvspan(
            iv.t_start, max(iv.t_end, iv.t_start + 1e-9), color="tab:red", alpha=0.15
        )
    ax.axhline(0.0, color="k", lw=0.8)
    if thr > 0:
        ax.axhline(
            thr * 1e3,
            color="tab:red",
            ls="--",
            lw=1.2,
            label=f"clearance {thr * 1e3:g} mm",
        )
    c = report.closest
    if c is not None:
        ax.plot(
            [c.t],
            [c.distance * 1e3],
            "o",
            color="tab:red",
            ms=6,
            label=f"min {c.distance * 1e3:.2f} mm ({c.body_a} – {c.body_b})",
        )
    ax.set_xlabel("time [s]")
    ax.set_ylabel("distance [mm]")
    ax.set_title("minimum distance over time")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    if np.isfinite(lowest):
        top = ax.get_ylim()[1]
        ax.set_ylim(min(lowest * 1e3, 0.0) - 0.05 * max(top, 1.0), top)
    if out is not None:
        from robokin.io.atomic import save_figure_atomic

        try:
            save_figure_atomic(fig, out, argument="out", dpi=120)
        finally:
            plt.close(fig)
    return fig
