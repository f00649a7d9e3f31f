"""Small, bounded HTML for Jupyter: tables and inline SVG line plots.

The ``_repr_html_`` methods of :class:`~robokin.robot.Robot`, solution sets,
trajectories and collision reports build their output here. Everything is
bounded whatever the size of the data: a table shows at most ``max_rows`` rows
(and says how many it left out), a plot at most :data:`MAX_POINTS` points per
line (evenly spaced samples), so a batch of 10^5 solutions or a trajectory of
10^6 samples is a few kilobytes of HTML. Text from files (names) is escaped.
No plotting library is imported: the SVG is written directly.
"""

from __future__ import annotations

import html
from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

__all__ = ["MAX_POINTS", "MAX_ROWS", "box", "line_plot", "table"]

#: Most rows a table shows.
MAX_ROWS = 20
#: Most points per line of a plot.
MAX_POINTS = 240
_COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b",
            "#e377c2", "#7f7f7f", "#bcbd22", "#17becf")
_STYLE = ("font-family: sans-serif; font-size: 12px; border-collapse: collapse; "
          "margin: 4px 0")


def _cell(value: Any) -> str:
    if isinstance(value, float | np.floating):
        text = f"{float(value):.6g}"
    else:
        text = str(value)
    return html.escape(text[:200])


def table(headers: Sequence[str], rows: Sequence[Sequence[Any]], *,
          max_rows: int = MAX_ROWS, right: Sequence[bool] | None = None) -> str:
    """An HTML table of at most ``max_rows`` rows (the count of the others said).

    Args:
        headers: Column headers (escaped).
        rows: Rows of values; floats are shown with 6 significant digits.
        max_rows: Most rows shown.
        right: Right-align each column (default: columns of numbers).

    Returns:
        The ``<table>`` element (and a note of left-out rows).
    """
    shown = list(rows[:max_rows])
    if right is None:
        right = [bool(shown) and all(isinstance(r[j], int | float | np.number)
                                     for r in shown) for j in range(len(headers))]
    align = ["right" if r else "left" for r in right]
    head = "".join(f'<th style="text-align:{a}; padding: 1px 6px">{html.escape(h)}</th>'
                   for h, a in zip(headers, align))
    body = "".join(
        "<tr>" + "".join(f'<td style="text-align:{a}; padding: 1px 6px">{_cell(v)}</td>'
                         for v, a in zip(row, align)) + "</tr>"
        for row in shown)
    out = f'<table style="{_STYLE}"><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>'
    if len(rows) > max_rows:
        out += f"<div><i>… {len(rows) - max_rows:,} more rows not shown</i></div>"
    return out


def line_plot(x: npt.ArrayLike, ys: npt.ArrayLike, *, labels: Sequence[str] = (),
              xlabel: str = "", ylabel: str = "", width: int = 460,
              height: int = 170, hline: float | None = None) -> str:
    """An inline SVG line plot: one line per column of ``ys``, at most 10 lines.

    Args:
        x: Abscissae (m,), increasing.
        ys: Ordinates (m,) or (m, k).
        labels: A legend entry per line.
        xlabel: The x axis label (with unit).
        ylabel: The y axis label (with unit).
        width: Width [px].
        height: Height [px].
        hline: A dashed horizontal line (e.g. a threshold), or None.

    Returns:
        The ``<svg>`` element; lines are downsampled to :data:`MAX_POINTS`
        evenly spaced samples (first and last kept).
    """
    xv = np.asarray(x, dtype=float).reshape(-1)
    Y = np.asarray(ys, dtype=float).reshape(xv.shape[0], -1)[:, :len(_COLOURS)]
    if xv.size == 0:
        return ""
    keep = np.unique(np.linspace(0, xv.size - 1, min(xv.size, MAX_POINTS)).round()
                     .astype(int))
    xv, Y = xv[keep], Y[keep]
    finite = Y[np.isfinite(Y)]
    lo, hi = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
    if hline is not None and np.isfinite(hline):
        lo, hi = min(lo, hline), max(hi, hline)
    if hi - lo < 1e-12:
        lo, hi = lo - 1.0, hi + 1.0
    x0, x1 = float(xv[0]), float(xv[-1]) if xv[-1] > xv[0] else float(xv[0]) + 1.0
    left, right, top, bottom = 52, 8, 8, 30
    pw, ph = width - left - right, height - top - bottom

    def px(v: np.ndarray) -> np.ndarray:
        return left + (v - x0) / (x1 - x0) * pw

    def py(v: np.ndarray | float) -> Any:
        return top + (hi - np.asarray(v)) / (hi - lo) * ph

    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" '
             f'height="{height}" style="display: block; font-family: sans-serif; '
             'font-size: 10px">',
             f'<rect x="{left}" y="{top}" width="{pw}" height="{ph}" fill="none" '
             'stroke="#999"/>']
    for j in range(Y.shape[1]):
        ok = np.isfinite(Y[:, j])
        pts = " ".join(f"{a:.1f},{b:.1f}" for a, b in zip(px(xv[ok]), py(Y[ok, j])))
        parts.append(f'<polyline fill="none" stroke="{_COLOURS[j]}" stroke-width="1.3" '
                     f'points="{pts}"/>')
    if hline is not None and np.isfinite(hline):
        yh = float(py(hline))
        parts.append(f'<line x1="{left}" x2="{left + pw}" y1="{yh:.1f}" y2="{yh:.1f}" '
                     'stroke="#d62728" stroke-dasharray="4 3"/>')
    for v, anchor in ((hi, top + 8), (lo, top + ph)):
        parts.append(f'<text x="{left - 4}" y="{anchor}" text-anchor="end">{v:.4g}</text>')
    parts.append(f'<text x="{left}" y="{height - 14}">{x0:.4g}</text>')
    parts.append(f'<text x="{left + pw}" y="{height - 14}" text-anchor="end">'
                 f'{x1:.4g}</text>')
    parts.append(f'<text x="{left + pw / 2}" y="{height - 3}" text-anchor="middle">'
                 f'{html.escape(xlabel)}</text>')
    parts.append(f'<text x="10" y="{top + ph / 2}" text-anchor="middle" '
                 f'transform="rotate(-90 10 {top + ph / 2})">{html.escape(ylabel)}</text>')
    for j, name in enumerate(list(labels)[:Y.shape[1]]):
        parts.append(f'<text x="{left + 6 + 70 * (j % 6)}" y="{top + 12 + 12 * (j // 6)}"'
                     f' fill="{_COLOURS[j]}">{html.escape(str(name)[:12])}</text>')
    parts.append("</svg>")
    return "".join(parts)


def box(title: str, *parts: str) -> str:
    """A titled block holding ``parts`` (HTML, already escaped)."""
    return (f'<div style="font-family: sans-serif; font-size: 12px">'
            f"<div><b>{html.escape(title)}</b></div>{''.join(parts)}</div>")


def note(text: str) -> str:
    """One line of text (escaped)."""
    return f"<div>{html.escape(text)}</div>"
