"""The exact search of a layered graph: the compiled DP, turns, forbidden nodes and edges.

:class:`Search` owns the graph of one call: the base layers (``_graph.Layers``),
the circle joints expanded into their whole turns so far (``_turns.py``), nodes
found in collision and edges found in collision (``_collide.py``). :meth:`Search.run`
solves it exactly (``process_dp``), certifies or refines the turns, and returns the
chosen node of every layer with the real joint values.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from robokin import _native
from robokin.process._graph import ArmFacts, Layers, node_costs
from robokin.process._turns import shift_choices, turn_offsets, unwrap
from robokin.process.costs import Costs
from robokin.spatial import wrap_angle

__all__ = ["Search", "Solution"]


@dataclass(frozen=True, eq=False)
class Solution:
    """The optimum of one search.

    Attributes:
        node: Base node chosen per layer (L,) (-1 where the layer has none).
        q: Joint values per layer (L, n) [rad, m], whole turns chosen (NaN where
            no node).
        value: Objective up to each chosen node (L,) (NaN where none).
        restart: (L,) bool: a segment of the path starts at this layer.
        reached: (L, M) bool: base nodes some path of the segment reaches.
        value_full: The search's values (L, M E) of every node of the searched
            graph (inf where not reached).
        cost: The objective of the whole path (every segment).
        expanded: Circle joints that needed their whole turns expanded.
    """

    node: np.ndarray
    q: np.ndarray
    value: np.ndarray
    restart: np.ndarray
    reached: np.ndarray
    value_full: np.ndarray
    cost: float
    expanded: tuple[int, ...]


@dataclass(eq=False)
class Search:
    """The graph of one call, its forbidden parts, and its exact search.

    Attributes:
        facts: The arm.
        layers: The base layers.
        costs: The objective's weights.
        max_step: Largest joint change per step [rad, m] (``math.inf``: none).
        q_start: Where the arm starts (n,), or None.
        blocked: (L, M) bool: base nodes found in collision.
        forbidden: Base edges (layer, u, v) found in collision.
        expanded: Circle joints expanded into their whole turns.
        rounds: DP runs so far.
    """

    facts: ArmFacts
    layers: Layers
    costs: Costs
    max_step: float
    q_start: np.ndarray | None
    blocked: np.ndarray = field(default_factory=lambda: np.zeros((0, 0), bool))
    forbidden: set[tuple[int, int, int]] = field(default_factory=set)
    expanded: frozenset[int] = frozenset()
    rounds: int = 0
    _arrays: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None

    def __post_init__(self) -> None:
        """Start with nothing blocked."""
        if self.blocked.shape != self.layers.shape:
            self.blocked = np.zeros(self.layers.shape, dtype=bool)

    # ------------------------------------------------------------------ the graph
    @property
    def turns(self) -> np.ndarray:
        """Whole-turn offsets (E, n) of the expanded joints (E = 1: none)."""
        return turn_offsets(self.facts.limits, tuple(sorted(self.expanded)))

    def mode(self) -> np.ndarray:
        """The kernel modes of the searched graph."""
        return self.facts.modes(self.expanded)

    def graph(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(Q (L, M E, n), cost (L, M E), circle (n,) uint8, offsets (E, n))``."""
        if self._arrays is None:
            self._arrays = self._build()
        Q, cost, circle, offsets = self._arrays
        E = offsets.shape[0]
        blocked = np.repeat(self.blocked, E, axis=1)
        if blocked.any():
            cost = np.where(blocked, np.inf, cost)
        return Q, cost, circle, offsets

    def _build(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        lay = self.layers
        mode = self.mode()
        circle = (mode == _native.kernels.PM_CIRCLE).astype(np.uint8)
        offsets = self.turns
        if offsets.shape[0] == 1 and not self.expanded:
            return lay.Q, lay.cost, circle, offsets
        L, M = lay.shape
        E, n = offsets.shape
        Qe = (lay.Q[:, :, None, :] + offsets[None, None]).reshape(-1, n)
        valid = np.repeat((lay.code != _native.kernels.PN_NONE).reshape(-1), E)
        sing = np.repeat(lay.singular_ik.reshape(-1), E)
        Qc, cost, _, _ = node_costs(self.facts, Qe, valid, sing, mode,
                                    self.costs.node_weights(self.facts.mu_ref))
        return Qc.reshape(L, M * E, n), cost.reshape(L, M * E), circle, offsets

    def expand(self, joints: set[int]) -> None:
        """Split ``joints`` into their whole turns from now on."""
        self.expanded = self.expanded | frozenset(joints)
        self._arrays = None

    # ----------------------------------------------------------------- the search
    def start_costs(self, Q0: np.ndarray, circle: np.ndarray) -> np.ndarray:
        """Cost of the approach from ``q_start`` to each node of layer 0 (M E,)."""
        if self.q_start is None:
            return np.zeros(Q0.shape[0])
        d = Q0 - self.q_start
        d = np.where(circle.astype(bool), wrap_angle(d), d)
        step = np.abs(d).max(axis=-1)
        return np.where(np.isfinite(step), self.costs.travel_weight * step, np.inf)

    def forbidden_edges(self, E: int) -> np.ndarray:
        """The forbidden base edges, on every pair of turns, sorted (F, 3) int64."""
        if not self.forbidden:
            return np.zeros((0, 3), dtype=np.int64)
        base = np.array(sorted(self.forbidden), dtype=np.int64)
        a = np.arange(E)
        rows = []
        for i, u, v in base:
            uu, vv = np.meshgrid(u * E + a, v * E + a, indexing="ij")
            rows.append(np.stack([np.full(uu.size, i), uu.ravel(), vv.ravel()], axis=1))
        out = np.concatenate(rows)
        order = np.lexsort((out[:, 1], out[:, 2], out[:, 0]))
        return np.ascontiguousarray(out[order])

    def dp(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """One run of ``process_dp``: ``(choice (L,), value (L, M E), restart (L,), Q)``."""
        Q, cost, circle, offsets = self.graph()
        L, ME = cost.shape
        value = np.empty((L, ME))
        pred = np.empty((L, ME), dtype=np.int32)
        restart = np.empty(L, dtype=np.uint8)
        choice = np.empty(L, dtype=np.int32)
        start = self.start_costs(Q[0], circle)
        _native.kernels.process_dp(
            Q, np.ascontiguousarray(cost), circle, float(self.max_step),
            self.costs.travel_weight, start, self.forbidden_edges(offsets.shape[0]),
            value, pred, restart, choice)
        self.rounds += 1
        return choice, value, restart.astype(bool), Q

    def run(self) -> Solution:
        """The exact optimum of the graph as it stands (turns certified or expanded)."""
        while True:
            choice, value, restart, Q = self.dp()
            q, uncertified = self._turns(choice, restart, Q)
            if not uncertified:
                break
            self.expand(uncertified)
        return self._solution(choice, value, restart, q)

    def _turns(self, choice: np.ndarray, restart: np.ndarray,
               Q: np.ndarray) -> tuple[np.ndarray, set[int]]:
        """Real joint values of the chosen nodes, and the joints left uncertified."""
        L = choice.shape[0]
        n = self.facts.n
        q = np.full((L, n), np.nan)
        has = choice >= 0
        q[has] = Q[np.flatnonzero(has), choice[has]]
        circle = np.flatnonzero(self.mode() == _native.kernels.PM_CIRCLE)
        bad: set[int] = set()
        lim = self.facts.limits
        margin = self.costs.limit_margin if self.costs.limit_weight > 0.0 else 0.0
        for a, b in _segments(restart, has):
            for j in circle:
                qs = None
                if a == 0 and self.q_start is not None:
                    qs = float(self.q_start[j])
                u = unwrap(q[a:b, j])
                k = shift_choices(u, float(lim[j, 0]), float(lim[j, 1]), margin, qs)
                if k is None:
                    bad.add(int(j))
                else:
                    q[a:b, j] = u + 2.0 * math.pi * k
        return q, bad

    def _solution(self, choice: np.ndarray, value: np.ndarray, restart: np.ndarray,
                  q: np.ndarray) -> Solution:
        E = self.turns.shape[0]
        L = choice.shape[0]
        has = choice >= 0
        val = np.full(L, np.nan)
        val[has] = value[np.flatnonzero(has), choice[has]]
        ends = np.flatnonzero(has & np.r_[restart[1:], True])
        total = float(val[ends].sum()) if ends.size else math.nan
        reached = np.isfinite(value).reshape(L, -1, E).any(axis=2)
        node = np.where(has, choice // E, -1)
        return Solution(node, q, val, restart, reached, value, total,
                        tuple(sorted(self.expanded)))


def _segments(restart: np.ndarray, has: np.ndarray) -> list[tuple[int, int]]:
    """[a, b) layer ranges of the path's segments that have nodes."""
    L = restart.shape[0]
    starts = list(np.flatnonzero(restart)) + [L]
    out = []
    for a, b in zip(starts[:-1], starts[1:], strict=True):
        idx = np.flatnonzero(has[a:b])
        if idx.size:
            out.append((int(a + idx[0]), int(a + idx[-1] + 1)))
    return out
