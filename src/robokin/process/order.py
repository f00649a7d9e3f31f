"""The visiting order of a point set (holes, picks) with the IK branch at each point.

Each pose is a cluster of configurations (every IK solution, every sampled tool
rotation); the order and the configuration per pose are chosen together as a
generalised travelling salesman over the clusters (``_tsp.py``: nearest neighbour,
2-opt, Or-opt and re-insertion with the exact best configurations of an order by
dynamic programming, iterated with perturbations), and a Held-Karp lower bound
says how far from the optimum the answer can be at most. The moves between the
points are not checked against the scene (a planner's job); the configurations
at the points are.
"""

from __future__ import annotations

import hashlib
import math
import time
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt
from typing_extensions import Unpack

from robokin import _native
from robokin.process._collide import Collider
from robokin.process._graph import ArmFacts, Layers, arm_facts, build_layers, check_size
from robokin.process._inputs import SearchKeywords, search_inputs
from robokin.process._search import Search
from robokin.process._tsp import (
    Tour,
    TourProblem,
    double_bridge,
    held_karp_bound,
    improve,
    nearest_neighbour,
)
from robokin.process.costs import Costs
from robokin.process.report import OrderResult

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["order"]

_STARTS = 8  # nearest-neighbour starts without q_start
_KICKS = 30  # perturbations of the iterated local search
_NEAR = 8  # neighbour-list length of the re-insertion move


def order(
    robot: Robot,
    poses: npt.ArrayLike,
    **options: Unpack[SearchKeywords],
) -> OrderResult:
    """Visit every pose once, in the order and with the IK branches that cost least.

    Args:
        robot: The :class:`~robokin.Robot`.
        poses: Tool poses (P, 4, 4) [m] to visit, in any order.
        free_axis: ``"z"`` lets the tool turn about its own z axis (a drill).
        free_range: ``(lo, hi)`` [rad] of that turn (default a full turn).
        free_step: Its sampling [rad] (default 5 deg).
        q_start: The configuration (n,) the arm starts from (the path begins
            there); None: it may begin at any pose.
        scene: A scene the configurations at the poses must clear, or None.
        clearance: Distance [m] they keep from it.
        travel_weight: Cost per radian (metre) of joint travel.
        singularity_weight: Cost of one pose at zero manipulability.
        singularity_margin: Relative manipulability below which a pose starts to
            cost.
        singular_tol: Relative manipulability below which a configuration is
            never used.
        limit_weight: Cost of one joint of one pose at its limit.
        limit_margin: Distance to a limit [rad, m] below which a joint starts to
            cost.

    Returns:
        An :class:`~robokin.process.OrderResult`: ``order``, ``q``, ``travel``,
        the ``lower_bound`` and ``gap``.

    Raises:
        InputError: a bad argument (named).
    """
    t0 = time.perf_counter()
    inputs = search_inputs(robot, poses, **options)
    placed, T, samples, qs, costs = (inputs.placed, inputs.T, inputs.samples,
                                     inputs.q_start, inputs.costs)
    check_size(T.shape[0], samples.count)
    facts = arm_facts(placed.robot)
    layers = build_layers(facts, T, samples, costs)
    search = Search(facts, layers, costs, math.inf, qs)
    if placed.scene is not None:
        Collider(placed, search).check_layers(np.arange(T.shape[0]))
    usable = np.isfinite(layers.cost) & ~search.blocked
    ok = np.flatnonzero(usable.any(axis=1))
    skipped = np.flatnonzero(~usable.any(axis=1))
    reason = "ok" if skipped.size == 0 else _skip_reason(layers, search, int(skipped[0]))
    if ok.size == 0:
        return _empty(facts, skipped, reason, t0)
    sub = _sub_layers(layers, ok, usable[ok])
    pb = _problem(facts, sub, costs, qs)
    best, stats = _tour(pb, facts, sub, costs, qs, T)
    return _result(facts, sub, costs, qs, ok, best, pb, skipped, reason, stats, t0)


def _sub_layers(layers: Layers, rows: np.ndarray, usable: np.ndarray) -> Layers:
    """The layers of ``rows`` (poses), unusable nodes masked."""
    cost = np.where(usable, layers.cost[rows], np.inf)
    return replace(layers, Q=layers.Q[rows], cost=cost, mu=layers.mu[rows],
                   code=layers.code[rows], singular_ik=layers.singular_ik[rows])


def _problem(facts: ArmFacts, layers: Layers, costs: Costs,
             qs: np.ndarray | None) -> TourProblem:
    """The clusters, their least distances and neighbour lists."""
    Q = np.ascontiguousarray(np.where(np.isfinite(layers.cost)[..., None], layers.Q, 0.0))
    circle = facts.modes() == _native.kernels.PM_CIRCLE
    P = Q.shape[0]
    D = np.empty((P, P))
    _native.kernels.process_clusters(Q, np.ascontiguousarray(layers.cost),
                                     circle.astype(np.uint8), D)
    D *= costs.travel_weight
    far = D + np.diag(np.full(P, np.inf))
    near = np.argsort(far, axis=1, kind="stable")[:, :min(_NEAR, max(P - 1, 1))]
    return TourProblem(Q, layers.cost, circle, costs.travel_weight, qs, D, near)


def _tour(pb: TourProblem, facts: ArmFacts, layers: Layers, costs: Costs,
          qs: np.ndarray | None, T: np.ndarray) -> tuple[Tour, dict[str, Any]]:
    """The heuristic of ``_tsp.py``: starts, local search, perturbations."""

    def best_nodes(order: np.ndarray) -> np.ndarray:
        # the exact best node of every cluster for this order (relaxed turns)
        s = Search(facts, _sub_layers(layers, order, np.isfinite(layers.cost[order])),
                   costs, math.inf, qs)
        node = np.empty(pb.size, dtype=np.int64)
        node[order] = s.dp()[0]
        return node

    starts = [None] if qs is not None else _peripheral(pb, _STARTS)
    tours = [improve(pb, nearest_neighbour(pb, first), best_nodes) for first in starts]
    best = min(tours, key=lambda t: t.cost)  # the first of equal costs
    seed = int.from_bytes(hashlib.sha256(T.tobytes()).digest()[:8], "little")
    rng = np.random.default_rng(seed)
    # fewer kicks on big clusters (each costs a few exact node choices)
    kicks = 0 if pb.size < 4 else _KICKS if pb.cost.size <= 4096 else _KICKS // 3
    improved = 0
    for _ in range(kicks):
        t = improve(pb, double_bridge(best, rng), best_nodes)
        if t.cost < best.cost - 1e-12:
            best, improved = t, improved + 1
    return best, {"starts": len(starts), "kicks": kicks, "improvements": improved}


def _peripheral(pb: TourProblem, k: int) -> list[int | None]:
    """Up to k clusters far from the others (natural ends of an open path)."""
    P = pb.size
    x = np.array([pb.Q[i, int(np.argmin(pb.cost[i]))] for i in range(P)])
    d = pb.dist(x[:, None, :], x[None, :, :]).sum(axis=1)
    return [int(i) for i in np.argsort(-d, kind="stable")[:min(k, P)]]


def _result(facts: ArmFacts, layers: Layers, costs: Costs, qs: np.ndarray | None,
            ok: np.ndarray, best: Tour, pb: TourProblem, skipped: np.ndarray,
            reason: str, stats: dict[str, Any], t0: float) -> OrderResult:
    # the exact nodes and whole turns of the best order (certified, _turns.py)
    final = Search(facts, _sub_layers(layers, best.order,
                                      np.isfinite(layers.cost[best.order])),
                   costs, math.inf, qs)
    sol = final.run()
    q = sol.q
    steps = np.abs(np.diff(q, axis=0)).max(axis=1) if q.shape[0] > 1 else np.zeros(0)
    approach = 0.0 if qs is None else float(np.abs(q[0] - qs).max())
    angle = _angles(layers, best.order, sol.node)
    floor = float(np.min(pb.cost, axis=1).sum())
    if qs is not None:
        floor += min(float(np.min(pb.approach(k))) for k in range(pb.size))
    bound = held_karp_bound(pb.bound, sol.cost) + floor
    gap = (sol.cost - bound) / bound if bound > 0 else (0.0 if sol.cost <= 0 else math.inf)
    stats = {**stats, "seconds": time.perf_counter() - t0, "expanded": list(sol.expanded)}
    return OrderResult(order=ok[best.order], q=q, free_angle=angle,
                       travel=float(steps.sum()), cost=sol.cost, approach=approach,
                       lower_bound=bound, gap=max(gap, 0.0), feasible=skipped.size == 0,
                       skipped=skipped, reason=reason, stats=stats)


def _angles(layers: Layers, order: np.ndarray, node: np.ndarray) -> np.ndarray:
    if layers.samples.axis is None:
        return np.zeros(order.size)
    return layers.angle_of(node)


def _skip_reason(layers: Layers, search: Search, i: int) -> str:
    k = _native.kernels
    code = layers.code[i]
    kind = ("collision" if (code == k.PN_OK).any() else "singular"
            if (code == k.PN_SINGULAR).any() else "limits"
            if (code == k.PN_LIMITS).any() else "out of reach")
    return f"pose {i}: {kind}: no usable configuration (left out of the order)"


def _empty(facts: ArmFacts, skipped: np.ndarray, reason: str, t0: float) -> OrderResult:
    n = facts.n
    return OrderResult(order=np.zeros(0, dtype=np.int64), q=np.zeros((0, n)),
                       free_angle=np.zeros(0), travel=0.0, cost=0.0, approach=0.0,
                       lower_bound=0.0, gap=0.0, feasible=False, skipped=skipped,
                       reason=reason, stats={"seconds": time.perf_counter() - t0})
