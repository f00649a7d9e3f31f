"""Follow a tool path over every IK branch: the exact optimum of a layered graph.

Every waypoint is a *layer* of the graph: its nodes are all the IK solutions of its
pose (``robot.ik``, in batches of whole layers) and, with a free tool axis, of its
pose turned about the tool's z axis at every sampled angle. An edge joins two
nodes of consecutive waypoints when no joint changes by more than ``max_step``
(revolute joints whose limits span a turn the short way round, their whole turn
chosen afterwards: ``_turns.py``). The cheapest path through the layers
(``robokin.process.costs``: joint travel plus nearness to singularity and to
limits) is found exactly by dynamic programming over the layers, compiled
(``_native/csrc/process.c``), not greedily; ties go to the lowest node index, so
the same input gives the same motion. With a scene the answer is checked and the
colliding parts removed until it is clear (``_collide.py``).

Nothing is silently dropped: where no motion exists, ``reason`` names the first
waypoint that cannot be passed and why, and ``waypoints`` says for every waypoint
whether it has usable configurations (green) or not (red), for plots
(:func:`robokin.process.plot_follow`) and the 3D views
(:func:`robokin.process.path_markers`).
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt
from typing_extensions import Unpack

from robokin import _native
from robokin.process._collide import Collider
from robokin.process._graph import ArmFacts, Layers, arm_facts, build_layers, check_size
from robokin.process._inputs import (
    Placed,
    SearchKeywords,
    check_max_step,
    search_inputs,
)
from robokin.process._search import Search, Solution
from robokin.process.report import Failure, FollowResult, WaypointReport
from robokin.spatial import wrap_angle

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["MAX_ROUNDS", "follow"]

#: Most search rounds with a scene (each removes colliding nodes or steps).
MAX_ROUNDS = 200


def follow(
    robot: Robot,
    poses: npt.ArrayLike,
    *,
    max_step: float = 0.1,
    **options: Unpack[SearchKeywords],
) -> FollowResult:
    """The joint motion along a tool path with the least cost, over every IK branch.

    Args:
        robot: The :class:`~robokin.Robot` (with a scene: as the scene places it,
            or bare; the scene adds its base placement and tool).
        poses: Tool poses (N, 4, 4) [m] in the world frame, in path order.
        free_axis: ``"z"`` lets the tool turn about its own z axis (a drill, a
            round torch, a glue nozzle); None keeps the orientation as given.
        free_range: ``(lo, hi)`` [rad] the tool may turn through (default a full
            turn, with ``free_axis``).
        free_step: Sampling of that turn [rad] (default 5 deg).
        max_step: Largest joint change between consecutive waypoints [rad; m for
            a prismatic joint]; ``math.inf`` for none.
        q_start: The configuration (n,) the arm starts from: the approach to the
            first waypoint counts in the cost (not in ``travel``). None: any start.
        scene: A :class:`~robokin.collision.Scene` to stay clear of, or None.
        clearance: Distance [m] every configuration and every step keeps from the
            scene (with ``scene``).
        travel_weight: Cost per radian (metre) of joint travel.
        singularity_weight: Cost of one waypoint at zero manipulability.
        singularity_margin: Relative manipulability below which a waypoint starts
            to cost (the arm's best is 1).
        singular_tol: Relative manipulability below which a configuration is
            singular and never used.
        limit_weight: Cost of one joint of one waypoint at its limit.
        limit_margin: Distance to a limit [rad, m] below which a joint starts to
            cost.

    Returns:
        A :class:`~robokin.process.FollowResult`: ``feasible``, ``q`` (N, n),
        ``free_angle`` (N,), ``max_step``, ``travel``, ``reason``, the
        per-waypoint ``waypoints`` report and more.

    Raises:
        InputError: a bad argument (named), or more than
            ``robokin.process._inputs.MAX_SAMPLES`` sampled poses.
        MissingExtraError: a scene without ``robokin[collision]``.
    """
    t0 = time.perf_counter()
    inputs = search_inputs(robot, poses, **options)
    placed, T, samples, qs, costs = (inputs.placed, inputs.T, inputs.samples,
                                     inputs.q_start, inputs.costs)
    step = check_max_step(max_step)
    check_size(T.shape[0], samples.count)
    facts = arm_facts(placed.robot)
    layers = build_layers(facts, T, samples, costs)
    search = Search(facts, layers, costs, step, qs)
    sol, collider, stopped = _solve(search, placed)
    return _result(facts, layers, search, sol, collider, T, stopped, t0)


def _solve(search: Search, placed: Placed) -> tuple[Solution, Collider | None, bool]:
    """The search, with the lazy collision loop when there is a scene."""
    sol = search.run()
    if placed.scene is None:
        return sol, None, False
    collider = Collider(placed, search)
    for _ in range(MAX_ROUNDS):
        if collider.passes(sol):
            return sol, collider, False
        sol = search.run()
    return sol, collider, not collider.passes(sol)


def _result(facts: ArmFacts, layers: Layers, search: Search, sol: Solution,
            collider: Collider | None, T: np.ndarray, stopped: bool,
            t0: float) -> FollowResult:
    L = T.shape[0]
    angle = layers.angle_of(sol.node)
    if layers.samples.axis is None:
        angle = np.where(sol.node >= 0, 0.0, np.nan)
    tool = T @ layers.samples.rotations[0] if layers.samples.count == 1 else (
        T @ _rotz(np.nan_to_num(angle)))
    steps = np.abs(np.diff(sol.q, axis=0)).max(axis=1) if L > 1 else np.zeros(0)
    finite_steps = steps[np.isfinite(steps)]
    status, failure = _classify(facts, layers, search, sol, T)
    if stopped and failure is None:
        failure = Failure(0, "collision", f"collision: the search stopped after "
                          f"{MAX_ROUNDS} rounds of removing colliding parts")
    approach = 0.0
    if search.q_start is not None and sol.node[0] >= 0:
        approach = float(np.abs(sol.q[0] - search.q_start).max())
    report = _waypoints(facts, layers, search, sol, collider, T, status, steps)
    stats = {"nodes": int(layers.cost.size), "usable": int(np.isfinite(layers.cost).sum()),
             "rounds": search.rounds, "expanded": list(sol.expanded),
             "collision_checks": 0 if collider is None else collider.checks,
             "seconds": time.perf_counter() - t0}
    return FollowResult(
        feasible=failure is None, q=sol.q, free_angle=angle,
        max_step=float(finite_steps.max()) if finite_steps.size else 0.0,
        travel=float(finite_steps.sum()), reason="ok" if failure is None else failure.message,
        failure=failure, cost=sol.cost, approach=approach, tool_poses=tool,
        waypoints=report, stats=stats)


def _rotz(angle: np.ndarray) -> np.ndarray:
    from robokin.spatial import rotz

    return rotz(angle)


def _usable(layers: Layers, search: Search) -> np.ndarray:
    """(L, M) bool: base nodes the search may use."""
    return np.isfinite(layers.cost) & ~search.blocked


def _classify(facts: ArmFacts, layers: Layers, search: Search, sol: Solution,
              T: np.ndarray) -> tuple[np.ndarray, Failure | None]:
    """Per-waypoint status and the first failure (see ``report.Failure``)."""
    k = _native.kernels
    usable = _usable(layers, search)
    code = layers.code
    status = np.full(code.shape[0], "ok", dtype=object)
    none = np.asarray(~usable.any(axis=1), dtype=bool)
    status[none & (code == k.PN_LIMITS).any(axis=1)] = "limits"
    status[none & (code == k.PN_SINGULAR).any(axis=1)] = "singular"
    status[none & (code == k.PN_OK).any(axis=1)] = "collision"
    status[none & (status == "ok")] = "out of reach"
    after = np.r_[False, ~none[:-1]]
    status[sol.restart & ~none & after] = "jump"
    bad = np.flatnonzero(status != "ok")
    if bad.size == 0:
        return status, None
    i = int(bad[0])
    return status, Failure(i, status[i],
                           _message(facts, layers, search, sol, T, i, status[i]))


def _message(facts: ArmFacts, layers: Layers, search: Search, sol: Solution,
             T: np.ndarray, i: int, kind: str) -> str:
    """The sentence saying why waypoint i fails."""
    K = layers.samples.count
    turns = "" if K == 1 else f" at any of the {K} tool rotations"
    head = f"waypoint {i}: {kind}"
    if kind == "out of reach":
        return f"{head}: no IK solution{turns} ({_ik_status(facts, layers, T, i)})"
    if kind == "limits":
        return (f"{head}: every IK solution{turns} is outside the joint limits "
                f"({_limit_status(facts, layers, T, i)})")
    if kind == "singular":
        mu = layers.mu[i]
        best = float(np.nanmax(mu)) if np.isfinite(mu).any() else 0.0
        return (f"{head}: every IK solution inside the limits{turns} is singular "
                f"(best relative manipulability {best:.3g} < singular_tol "
                f"{search.costs.singular_tol:g}, or flagged singular by the IK)")
    if kind == "collision":
        return (f"{head}: every configuration inside the limits and not singular"
                f"{turns} collides with the scene or comes within the clearance")
    return (f"{head}: waypoint {i} has configurations, but none within max_step "
            f"{search.max_step:g} of a configuration that reaches waypoint {i - 1}: "
            f"every path dies here ({_jump_detail(facts, search, sol, i)})")


def _ik_status(facts: ArmFacts, layers: Layers, T: np.ndarray, i: int) -> str:
    """The IK's own reason for waypoint i (at its first sampled rotation)."""
    sols = facts.robot.ik(T[i] @ layers.samples.rotations[0])
    return str(sols.status.item() if isinstance(sols.status, np.ndarray)
               else sols.status)


def _limit_status(facts: ArmFacts, layers: Layers, T: np.ndarray, i: int) -> str:
    """Which limit rejects the solutions of waypoint i (first rotation with any)."""
    k = _native.kernels
    per_rotation = (layers.code[i] == k.PN_LIMITS).reshape(-1, layers.slots).any(axis=1)
    a = int(np.argmax(per_rotation))
    sols = facts.robot.ik(T[i] @ layers.samples.rotations[a]).keep_within_limits()
    text = str(sols.status.item() if isinstance(sols.status, np.ndarray) else sols.status)
    if layers.samples.axis is not None:
        text = f"at tool rotation {layers.samples.angles[a]:.4g} rad: {text}"
    return text


def _jump_detail(facts: ArmFacts, search: Search, sol: Solution, i: int) -> str:
    """Why no step reaches waypoint i: the least step there is, and a limit in the way."""
    Q, cost, circle, _ = search.graph()
    src = Q[i - 1][np.isfinite(sol.value_full[i - 1])]
    dst = Q[i][np.isfinite(cost[i])]
    if src.size == 0 or dst.size == 0:
        return "no configuration is left to step from"
    d = dst[:, None, :] - src[None, :, :]
    exact = np.abs(np.where(circle.astype(bool), wrap_angle(d), d))
    step = exact.max(axis=-1)
    j = int(np.unravel_index(int(np.argmin(step)), step.shape)[0])
    k = int(np.argmin(step[j]))
    worst = int(np.argmax(exact[j, k]))
    text = (f"the smallest step possible is {float(step.min()):.4g}, in joint "
            f"{worst + 1}")
    text += _limit_in_the_way(facts, search, sol, i)
    around = np.abs(np.where(facts.wraps, wrap_angle(d), d)).max(axis=-1)
    if float(around.min()) <= search.max_step:
        jj, kk = np.unravel_index(int(np.argmin(around)), around.shape)
        blocked = np.flatnonzero(np.abs(d[jj, kk]) > search.max_step)
        names = ", ".join(str(int(b) + 1) for b in blocked)
        text += (f"; turning the other way round joint {names} would step "
                 f"{float(around.min()):.4g}, but that passes its limit")
    return text


def _limit_in_the_way(facts: ArmFacts, search: Search, sol: Solution, i: int) -> str:
    """Where a configuration outside the limits would continue the motion: which joint."""
    lay = search.layers
    out = lay.code[i] == _native.kernels.PN_LIMITS
    src = lay.Q[i - 1][sol.reached[i - 1]]
    if not out.any() or src.size == 0:
        return ""
    dst = lay.Q[i][out]
    d = dst[:, None, :] - src[None, :, :]
    step = np.abs(np.where(facts.wraps, wrap_angle(d), d)).max(axis=-1)
    if float(step.min()) > search.max_step:
        return ""
    v = dst[int(np.unravel_index(int(np.argmin(step)), step.shape)[0])]
    lim = facts.limits
    j = int(np.argmax(np.maximum(lim[:, 0] - v, v - lim[:, 1])))
    side = "upper" if v[j] > lim[j, 1] else "lower"
    return (f"; the configuration that would continue has joint {j + 1} at "
            f"{v[j]:.4g}, beyond its {side} limit {lim[j, 1 if side == 'upper' else 0]:.4g}")


def _waypoints(facts: ArmFacts, layers: Layers, search: Search, sol: Solution,
               collider: Collider | None, T: np.ndarray, status: np.ndarray,
               steps: np.ndarray) -> WaypointReport:
    L = T.shape[0]
    usable = _usable(layers, search)
    has = sol.node >= 0
    seg = np.cumsum(sol.restart) - 1
    seg = np.where(has, seg, -1)
    step = np.full(L, np.nan)
    step[1:] = np.where(sol.restart[1:], np.nan, steps)
    idx = np.clip(sol.node, 0, None)
    mu = np.where(has, layers.mu[np.arange(L), idx], np.nan)
    lim = facts.limits
    dist = np.minimum(sol.q - lim[:, 0], lim[:, 1] - sol.q).min(axis=1)
    clear = np.full(L, np.nan) if collider is None else collider.clearance(sol)
    return WaypointReport(status=status, usable=usable.sum(axis=1),
                          reachable=np.asarray(usable.any(axis=1), dtype=bool),
                          segment=seg, step=step,
                          manipulability=mu, limit_distance=dist, clearance=clear,
                          position=T[:, :3, 3].copy())
