"""Cell design at scale: reachability maps and robot placement, on Dask.

Needs ``pip install 'robokin[scale]'`` (dask, distributed, zarr); the functions
say so on first use when it is missing.

.. code-block:: python

    from robokin import cell

    m = cell.reach_map(robot, region=[[-1, -1, 0], [1, 1, 1.2]], voxel=0.05,
                       orientations=32, scheduler=None)     # or "tcp://host:8786"
    m.centers, m.orientations, m.reachable, m.index
    pl = cell.place(robot, task_poses, cell.base_grid(x, y), scene=scene,
                    clearance=0.004)
    pl.feasible, pl.score, pl.best

Where the work runs, and what it costs per core: ``docs/scale.md``.
"""

from __future__ import annotations

from robokin.cell.grid import VoxelGrid, tool_orientations
from robokin.cell.placement import Placement, base_grid, place
from robokin.cell.reach_map import ReachMap, reach_map

__all__ = [
    "Placement",
    "ReachMap",
    "VoxelGrid",
    "base_grid",
    "place",
    "reach_map",
    "tool_orientations",
]
