"""Collision and clearance of a process search against a scene, checked lazily.

Checking every node of every layer would cost one distance query per IK solution
per tool rotation per waypoint, most of them never near the optimum. Instead
(as lazy PRM does for roadmaps) the search runs on the graph as it stands and
only its answer is checked:

1. **Nodes of the path.** Each chosen configuration is checked (``collision.check``
   at the samples, ``subdivide=False``). Where one collides or comes within the
   clearance, every node of the layers around it (``WINDOW`` either side) is
   checked too, and the colliding ones are removed from the graph.
2. **Edges of the path.** Each piece of the motion is checked as a motion
   (``subdivide=True``: the straight joint-space line between consecutive
   configurations, bisected until provably clear). An edge found in collision or
   within the clearance is removed (every pair of whole turns of its two nodes:
   the same motion).
3. The search runs again, until its answer passes both checks.

Nothing removed is ever put back, and only configurations and motions shown in
collision are removed, so the final answer is the exact optimum of the graph
without its colliding parts, and it is collision-free: at every waypoint and along
every straight joint-space step between waypoints the distance to the scene (and
between the robot's checked links) is above the clearance, to the check's
tolerance (``collision.check``: grazing closer than 1 um between samples counts as
clear).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from robokin.collision.report import CollisionReport
    from robokin.process._inputs import Placed
    from robokin.process._search import Search, Solution

__all__ = ["WINDOW", "Collider"]

WINDOW = 8  # layers either side of a colliding path node whose nodes are all checked


@dataclass(eq=False)
class Collider:
    """The collision state of one search.

    Attributes:
        placed: The robot, the bare robot and the scene.
        search: The search whose graph loses colliding nodes and edges.
        checked: (L, M) bool: base nodes already checked.
        checks: Configurations checked so far (nodes and motion samples).
    """

    placed: Placed
    search: Search
    checked: np.ndarray = field(default_factory=lambda: np.zeros((0, 0), bool))
    checks: int = 0

    def __post_init__(self) -> None:
        """Nothing checked yet."""
        self.checked = np.zeros(self.search.layers.shape, dtype=bool)

    def _report(self, q: np.ndarray, subdivide: bool) -> CollisionReport:
        from robokin.collision.check import check

        bare, scene = self.placed.bare, self.placed.scene
        if bare is None or scene is None:
            raise RuntimeError("a Collider needs a scene")  # pragma: no cover
        self.checks += q.shape[0]
        return check(bare, scene, q, clearance=self.placed.clearance,
                     subdivide=subdivide)

    def check_nodes(self, mask: np.ndarray) -> int:
        """Check the usable, unchecked nodes of ``mask`` (L, M); returns how many collide."""
        lay = self.search.layers
        todo = mask & ~self.checked & np.isfinite(lay.cost) & ~self.search.blocked
        idx = np.flatnonzero(todo)
        if idx.size == 0:
            return 0
        q = lay.Q.reshape(-1, lay.Q.shape[-1])[idx]
        rep = self._report(q, subdivide=False)
        bad = np.zeros(idx.size, dtype=bool)
        for iv in list(rep.violations) + list(rep.intervals):
            bad[iv.first_index:iv.last_index + 1] = True
        self.checked.flat[idx] = True
        self.search.blocked.flat[idx[bad]] = True  # the next search.graph() masks them
        return int(bad.sum())

    def check_layers(self, layers: np.ndarray) -> int:
        """Check every node of the given layers."""
        mask = np.zeros(self.search.layers.shape, dtype=bool)
        mask[layers] = True
        return self.check_nodes(mask)

    def passes(self, sol: Solution) -> bool:
        """Check the answer's nodes, then its steps; False when the graph changed."""
        L, M = self.search.layers.shape
        has = sol.node >= 0
        mask = np.zeros((L, M), dtype=bool)
        mask[np.flatnonzero(has), sol.node[has]] = True
        if self.check_nodes(mask):
            blocked = self.search.blocked[np.arange(L), np.clip(sol.node, 0, None)]
            hit = np.flatnonzero(has & blocked)
            near = np.unique(np.clip(hit[:, None] + np.arange(-WINDOW, WINDOW + 1), 0,
                                     L - 1))
            self.check_layers(near)
            return False
        return not self._forbid_steps(sol)

    def _forbid_steps(self, sol: Solution) -> int:
        """Check every piece of the motion as a motion; forbid the colliding steps."""
        starts = list(np.flatnonzero(sol.restart)) + [sol.node.shape[0]]
        found = 0
        for a, b in zip(starts[:-1], starts[1:], strict=True):
            if b - a < 2 or sol.node[a] < 0:
                continue
            rep = self._report(sol.q[a:b], subdivide=True)
            for iv in list(rep.violations) + list(rep.intervals):
                if not iv.between_samples:
                    continue
                for i in range(iv.first_index, max(iv.last_index, iv.first_index + 1)):
                    edge = (a + i, int(sol.node[a + i]), int(sol.node[a + i + 1]))
                    if edge not in self.search.forbidden:
                        self.search.forbidden.add(edge)
                        found += 1
        return found

    def clearance(self, sol: Solution) -> np.ndarray:
        """Distance to the scene of the chosen configurations (L,) [m]."""
        out = np.full(sol.node.shape[0], np.nan)
        has = np.flatnonzero(sol.node >= 0)
        if has.size:
            rep = self._report(sol.q[has], subdivide=False)
            out[has] = rep.closest_at(np.arange(has.size))[0]
        return out
