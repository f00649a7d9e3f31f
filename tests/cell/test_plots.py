"""The floor map of a placement search (``robokin.cell.plots``)."""

import numpy as np
import pytest

import robokin
from robokin import cell

pytest.importorskip("dask")


def test_the_floor_legend_covers_no_cell(tmp_path):
    """Issue 25: the legend sat inside the map, over the cells in its corner (where
    the best bases often are). Oracle: the rendered legend's box and the map's box
    (matplotlib's own extents after drawing) do not overlap."""
    ur5 = robokin.load("ur5")
    q = np.radians([[0, -60, 80, -20, 90, 0], [5, -55, 75, -20, 90, 0]])
    task = ur5.fk(q)
    pl = cell.place(ur5, task, cell.base_grid(np.linspace(-0.3, 0.3, 4),
                                              np.linspace(-0.3, 0.3, 4)))
    fig = pl.plot_floor(tmp_path / "floor.png", mark=np.eye(4))
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    ax = fig.axes[0]
    legends = [*fig.legends, *(a.get_legend() for a in fig.axes if a.get_legend())]
    assert len(legends) == 1
    box = legends[0].get_window_extent(renderer)
    assert not box.overlaps(ax.get_window_extent(renderer))
    texts = [t.get_text() for t in legends[0].get_texts()]
    assert "best" in texts and "current base" in texts
