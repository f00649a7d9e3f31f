"""Cell-design figures: sections through a reachability map, placements on the floor.

Sections are the classic capability-map picture (Zacharias et al., IROS 2007):
a plane of voxels coloured by reachability index from blue (few orientations)
to red (every orientation), unreachable voxels left blank. The floor map shows
each candidate base position coloured by its placement score, infeasible ones
in grey by reason. Lengths are drawn in millimetres.

The figures read a map or a placement through the protocols below (what
:class:`~robokin.cell.reach_map.ReachMap` and
:class:`~robokin.cell.placement.Placement` hold), so this module imports neither:
their ``plot_sections`` / ``plot_floor`` methods call in here, one way.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, Protocol

import numpy as np
import numpy.typing as npt

from robokin._text import short_repr
from robokin._validation import check_finite_number
from robokin.cell.grid import VoxelGrid
from robokin.exceptions import InputError
from robokin.viz.plots import _figure as figure
from robokin.viz.plots import save_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["FloorSource", "SectionSource", "plot_floor", "plot_sections"]

Axis = Literal["x", "y", "z"]
_AXES: dict[object, Axis] = {"x": "x", "y": "y", "z": "z"}
Quantity = Literal["index", "manipulability", "solutions"]


class SectionSource(Protocol):
    """What :func:`plot_sections` reads of a reachability map (a ``ReachMap``)."""

    @property
    def robot_name(self) -> str:
        """The robot's name."""
        ...

    @property
    def grid(self) -> VoxelGrid:
        """The voxel grid."""
        ...

    @property
    def orientations(self) -> np.ndarray:
        """Tool orientations (K, 3, 3)."""
        ...

    @property
    def index(self) -> Any:
        """Reachability index per voxel (V,), a NumPy or Zarr array."""
        ...

    @property
    def base(self) -> np.ndarray | None:
        """The robot's base pose (4, 4) [m], or None."""
        ...

    def as_grid(self, values: npt.ArrayLike) -> np.ndarray:
        """Per-voxel values arranged on the grid."""
        ...

    def section(self, axis: Axis, at: float, quantity: Quantity = "index"
                ) -> tuple[np.ndarray, np.ndarray]:
        """A plane of voxels normal to ``axis`` through ``at`` [m], and its extent."""
        ...


class FloorSource(Protocol):
    """What :func:`plot_floor` reads of a placement search (a ``Placement``)."""

    @property
    def candidates(self) -> np.ndarray:
        """Base poses (C, 4, 4) [m]."""
        ...

    @property
    def feasible(self) -> np.ndarray:
        """(C,) bool."""
        ...

    @property
    def score(self) -> np.ndarray:
        """(C,) placement scores."""
        ...

    @property
    def reason(self) -> np.ndarray:
        """(C,) why each candidate fails, or ``"ok"``."""
        ...

    @property
    def best_index(self) -> int | None:
        """Index of the best feasible candidate, or None."""
        ...

_LABELS = {
    "index": "reachability index",
    "manipulability": "best manipulability",
    "solutions": "IK solutions in the voxel",
}


def _figure(size: tuple[float, float]) -> Figure:
    fig: Figure = figure(size)
    return fig


def _densest_layer(m: SectionSource, k: int) -> float:
    """Coordinate [m] of the layer normal to axis k with the largest summed index."""
    cube = m.as_grid(np.asarray(m.index[...]))
    other = tuple(i for i in range(3) if i != k)
    return float(m.grid.axis(k)[int(np.argmax(cube.sum(axis=other)))])


def _check_sections(sections: Sequence[tuple[str, float]]) -> list[tuple[Axis, float]]:
    """The ``(axis, at [m])`` pairs, ``at`` a finite float, or :class:`InputError`."""
    out: list[tuple[Axis, float]] = []
    for pair in sections:
        try:
            axis, at = pair
        except (TypeError, ValueError):
            raise InputError("sections", f"expected (axis, at [m]) pairs, got "
                             f"{short_repr(pair)}") from None
        name = _AXES.get(axis)
        if name is None:
            raise InputError("sections", f"axis must be 'x', 'y' or 'z', got "
                             f"{short_repr(axis)}")
        out.append((name, check_finite_number(at, "sections")))
    if not out:
        raise InputError("sections", "expected at least one (axis, at) pair")
    return out


def plot_sections(
    m: SectionSource,
    *,
    path: str | Path | None = None,
    quantity: Quantity = "index",
    sections: Sequence[tuple[str, float]] | None = None,
    overwrite: bool = True,
) -> Figure:
    """Sections through a reachability map as heatmaps.

    Args:
        m: The map (a :class:`~robokin.cell.reach_map.ReachMap`).
        path: Save the figure here (``.png``, ``.svg``, ``.pdf``), atomically.
        quantity: ``"index"``, ``"manipulability"`` or ``"solutions"``.
        sections: ``[(axis, at [m]), ...]`` planes normal to ``axis``; default
            the x-z plane through the robot's base and the x-y plane through
            the layer with the most reachability.
        overwrite: Replace an existing file at ``path``.

    Returns:
        The matplotlib figure.

    Raises:
        InputError: an unknown quantity or axis, a section that is not an
            ``(axis, at)`` pair with a finite ``at``, or no manipulability in the
            map.
    """
    if sections is None:
        y = float(m.base[1, 3]) if m.base is not None else _densest_layer(m, 1)
        sections = [("y", y), ("z", _densest_layer(m, 2))]
    checked = _check_sections(sections)
    fig = _figure((5.2 * len(checked) + 1.0, 5.0))
    label = _LABELS.get(quantity, quantity)
    vmax = 1.0 if quantity == "index" else None
    image = None
    for i, (axis, at) in enumerate(checked):
        values, ext = m.section(axis, at, quantity)
        shown = np.ma.masked_less_equal(values.T.astype(float), 0.0)
        ax = fig.add_subplot(1, len(checked), i + 1)
        u, v = [c for c in "xyz" if c != axis]
        image = ax.imshow(
            shown,
            origin="lower",
            extent=(ext[0, 0] * 1e3, ext[1, 0] * 1e3, ext[0, 1] * 1e3, ext[1, 1] * 1e3),
            cmap="jet",
            vmin=0.0,
            vmax=vmax,
            interpolation="nearest",
        )
        ax.set_facecolor("0.93")
        ax.set_xlabel(f"{u} [mm]")
        ax.set_ylabel(f"{v} [mm]")
        ax.set_aspect("equal")
        ax.set_title(f"{axis} = {at * 1e3:.0f} mm")
    if image is not None:
        fig.colorbar(image, ax=fig.axes, label=label, shrink=0.85)
    fig.suptitle(
        f"{m.robot_name}: {label}, {m.grid.voxel * 1e3:g} mm voxels, "
        f"{m.orientations.shape[0]} orientations"
    )
    if path is not None:
        save_figure(fig, path, overwrite=overwrite)
    return fig


_REASON_COLOURS = {
    "out of reach": "0.80",
    "no continuous branch": "0.62",
    "collision": "#e8a3a3",
    "clearance": "#f2cf9b",
    "manipulability": "#c9c3e6",
}


def _category(reason: str) -> str:
    for key in _REASON_COLOURS:
        if reason.startswith(key):
            return key
    return "out of reach"


def plot_floor(
    pl: FloorSource,
    *,
    path: str | Path | None = None,
    scene: Any = None,
    mark: Any = None,
    overwrite: bool = True,
) -> Figure:
    """The candidate bases seen from above, coloured by placement score.

    Each (x, y) cell shows the best candidate standing there (over heights and
    yaws): feasible ones coloured by score, infeasible ones in grey tones by
    reason. The best placement is starred. The legend sits below the map, so it
    hides no cell.

    Args:
        pl: The placement search result (a :class:`~robokin.cell.placement.Placement`).
        path: Save the figure here (``.png``, ``.svg``, ``.pdf``), atomically.
        scene: Draw the footprints of this scene's boxes.
        mark: An extra base pose (4, 4) to mark with a ring (e.g. the cell's
            current placement).
        overwrite: Replace an existing file at ``path``.

    Returns:
        The matplotlib figure.
    """
    from matplotlib.colors import Normalize
    from matplotlib.lines import Line2D
    from matplotlib.patches import Rectangle

    xy = pl.candidates[:, :2, 3]
    keys = np.round(xy, 9)
    cells, inverse = np.unique(keys, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    order = np.lexsort((-pl.score, ~pl.feasible))  # feasible first, best score first
    pick = np.full(len(cells), -1)
    for c in order[::-1]:
        pick[inverse[c]] = c
    step = _grid_step(cells)
    fig = _figure((7.5, 6.2))
    ax = fig.add_subplot(1, 1, 1)
    feasible_scores = pl.score[pl.feasible]
    norm = Normalize(0.0, float(feasible_scores.max()) if feasible_scores.size else 1.0)
    import matplotlib as mpl

    cmap = mpl.colormaps["viridis"]
    for cell, c in zip(cells, pick):
        colour = (cmap(norm(pl.score[c])) if pl.feasible[c]
                  else _REASON_COLOURS[_category(str(pl.reason[c]))])
        ax.add_patch(Rectangle(((cell[0] - step / 2) * 1e3, (cell[1] - step / 2) * 1e3),
                               step * 1e3, step * 1e3, fc=colour, ec="white", lw=0.5))
    if scene is not None:
        _draw_footprints(ax, scene)
    handles = [Line2D([], [], ls="", marker="s", ms=9, color=col, label=key)
               for key, col in _REASON_COLOURS.items()]
    if pl.best_index is not None:
        b = pl.candidates[pl.best_index, :2, 3] * 1e3
        ax.plot(b[0], b[1], marker="*", ms=16, color="gold", mec="black", ls="")
        handles.append(Line2D([], [], ls="", marker="*", ms=12, color="gold", mec="black",
                              label="best"))
    if mark is not None:
        p = np.asarray(mark, dtype=float)[:2, 3] * 1e3
        ax.plot(p[0], p[1], marker="o", ms=14, mfc="none", mec="red", mew=2, ls="")
        handles.append(Line2D([], [], ls="", marker="o", ms=10, mfc="none", mec="red",
                              label="current base"))
    lo, hi = cells.min(axis=0) - step, cells.max(axis=0) + step
    ax.set_xlim(lo[0] * 1e3, hi[0] * 1e3)
    ax.set_ylim(lo[1] * 1e3, hi[1] * 1e3)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    sm = mpl.cm.ScalarMappable(norm=norm, cmap=cmap)
    fig.colorbar(sm, ax=ax, label="score: smallest manipulability along the task",
                 shrink=0.85)
    # below the map, never over it: the best cells are often in a corner
    fig.legend(handles=handles, fontsize=7, loc="outside lower center",
               ncol=min(len(handles), 4), frameon=False)
    n_ok = int(pl.feasible.sum())
    ax.set_title(f"robot bases: {n_ok} of {len(pl.feasible)} feasible")
    if path is not None:
        save_figure(fig, path, overwrite=overwrite)
    return fig


def _grid_step(cells: np.ndarray) -> float:
    steps = []
    for k in range(2):
        u = np.unique(cells[:, k])
        if u.size > 1:
            steps.append(float(np.min(np.diff(u))))
    return min(steps) if steps else 0.1


def _draw_footprints(ax: Any, scene: Any) -> None:
    from matplotlib.patches import Rectangle

    for obj in scene.objects:
        if obj.shape.kind != "box":
            continue
        c = obj.pose[:3, 3] * 1e3
        s = np.abs(obj.pose[:3, :3]) @ (np.asarray(obj.shape.size) * 1e3)
        ax.add_patch(Rectangle((c[0] - s[0] / 2, c[1] - s[1] / 2), s[0], s[1],
                               fc="none", ec="0.3", lw=0.8, ls="--"))
        ax.text(c[0], c[1], obj.name[:24], fontsize=6, ha="center",
                va="center", color="0.3", clip_on=True)
