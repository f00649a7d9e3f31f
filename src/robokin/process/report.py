"""What a process search answers: its records (data only).

:class:`FollowResult` is what :func:`robokin.process.follow` returns, with its
per-waypoint :class:`WaypointReport` (what a plot or the 3D views colour green and
red) and the :class:`Failure` its ``reason`` describes; :class:`OrderResult` is
what :func:`robokin.process.order` returns.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

__all__ = ["KINDS", "Failure", "FollowResult", "OrderResult", "WaypointReport"]

FailureKind = Literal["out of reach", "limits", "singular", "collision", "jump"]
#: Why a waypoint fails, in the order the checks remove configurations.
KINDS: tuple[str, ...] = ("out of reach", "limits", "singular", "collision", "jump")

#: Marker colours (RGB 0-255) of the per-waypoint diagnostics.
GREEN = (40, 160, 60)
RED = (215, 40, 40)
ORANGE = (235, 140, 20)


@dataclass(frozen=True)
class Failure:
    """The first waypoint a motion cannot pass, and why.

    Attributes:
        index: The waypoint (0-based).
        kind: ``"out of reach"`` (no IK solution for any sampled tool rotation),
            ``"limits"`` (every solution is outside the joint limits),
            ``"singular"`` (every solution inside the limits is singular),
            ``"collision"`` (every remaining configuration collides or comes
            within the clearance) or ``"jump"`` (the waypoint has configurations,
            but none within ``max_step`` of any configuration that reaches the
            waypoint before: every path dies here).
        message: The sentence ``reason`` gives.
    """

    index: int
    kind: FailureKind
    message: str


@dataclass(frozen=True, eq=False)
class WaypointReport:
    """Per-waypoint diagnostics of :func:`~robokin.process.follow` (N waypoints).

    Attributes:
        status: (N,) str: ``"ok"`` or one of :data:`KINDS` (``"jump"`` marks the
            waypoint where every path from the one before dies).
        usable: (N,) int: configurations (IK solutions x tool rotations) inside
            the limits, not singular and clear of the scene.
        reachable: (N,) bool: ``usable > 0`` (green), else red.
        segment: (N,) int: which continuous piece of the motion the waypoint is on
            (one piece when feasible; -1 where the waypoint has no configuration).
        step: (N,) largest joint change into the waypoint [rad, m] (NaN at a
            segment's start).
        manipulability: (N,) relative manipulability of the chosen configuration
            (1 = the arm's best; NaN where none).
        limit_distance: (N,) distance of the chosen configuration's nearest joint
            to its limit [rad, m].
        clearance: (N,) distance to the scene of the chosen configuration [m]
            (NaN without a scene).
        position: (N, 3) tool positions of the waypoints [m] (world frame).
    """

    status: np.ndarray
    usable: np.ndarray
    reachable: np.ndarray
    segment: np.ndarray
    step: np.ndarray
    manipulability: np.ndarray
    limit_distance: np.ndarray
    clearance: np.ndarray
    position: np.ndarray

    def colors(self) -> np.ndarray:
        """(N, 3) uint8 RGB per waypoint: green reachable, red not, orange a jump."""
        out = np.empty((self.status.shape[0], 3), dtype=np.uint8)
        out[:] = GREEN
        out[~self.reachable] = RED
        out[self.status == "jump"] = ORANGE
        return out


@dataclass(frozen=True, eq=False)
class FollowResult:
    """The result of :func:`~robokin.process.follow`.

    Attributes:
        feasible: True when the whole path has a motion: every waypoint reached,
            every step at most ``max_step``, inside the limits, not singular, and
            (with a scene) clear of it.
        q: Joint configurations (N, n) [rad, m], the optimum of the sampled
            graph (NaN rows where a waypoint has none; when not feasible, each
            continuous piece is optimal on its own).
        free_angle: (N,) rotation of the tool about its free axis [rad] at each
            waypoint (0 without a free axis; NaN where none).
        max_step: The largest step of ``q``: per step the largest joint change
            [rad, m] (across a piece boundary too, so a jump shows).
        travel: Joint travel of ``q``: the sum over steps of the largest joint
            change [rad, m].
        reason: ``"ok"``, or the first bad waypoint and why
            (``failure.message``).
        failure: The first :class:`Failure`, or None.
        cost: The objective (``robokin.process.costs``) of ``q``, the approach
            from ``q_start`` included.
        approach: Largest joint change from ``q_start`` to ``q[0]`` (0 without
            ``q_start``).
        tool_poses: (N, 4, 4) the tool poses ``q`` reaches: the waypoints with the
            free rotation applied, ``poses[i] @ Rz(free_angle[i])``.
        waypoints: The per-waypoint :class:`WaypointReport`.
        stats: Search facts: ``nodes`` (IK solutions x rotations x waypoints),
            ``usable``, ``rounds`` (DP runs), ``expanded`` (joints searched over
            their whole turns), ``collision_checks`` (configurations checked),
            ``seconds``.
    """

    feasible: bool
    q: np.ndarray
    free_angle: np.ndarray
    max_step: float
    travel: float
    reason: str
    failure: Failure | None
    cost: float
    approach: float
    tool_poses: np.ndarray
    waypoints: WaypointReport
    stats: dict[str, Any]

    def __repr__(self) -> str:
        """A one-line summary."""
        return (f"FollowResult(feasible={self.feasible}, waypoints={self.q.shape[0]}, "
                f"travel={self.travel:.4g}, max_step={self.max_step:.4g}, "
                f"reason={self.reason!r})")


@dataclass(frozen=True, eq=False)
class OrderResult:
    """The result of :func:`~robokin.process.order`.

    Attributes:
        order: (P,) indices into ``poses`` in visiting order (the reachable ones;
            see ``skipped``).
        q: (P, n) one configuration per visited pose, in visiting order [rad, m].
        free_angle: (P,) the tool's rotation about its free axis at each [rad].
        travel: Joint travel of ``q`` (the sum over steps of the largest joint
            change) [rad, m].
        cost: The objective: travel times its weight, node costs, and the approach
            from ``q_start``.
        approach: Largest joint change from ``q_start`` to ``q[0]`` (0 without).
        lower_bound: A lower bound on ``cost`` over every order and every IK
            branch (Held-Karp 1-tree bound on the cluster graph, plus each pose's
            least node cost).
        gap: ``(cost - lower_bound) / lower_bound``: how far from optimal the
            result can be at most (0 when the bound is met).
        feasible: Every pose has a usable configuration.
        skipped: Indices of poses without one (left out of ``order``).
        reason: ``"ok"`` or which pose is unusable and why.
        stats: Search facts (``starts``, ``improvements``, ``seconds``).
    """

    order: np.ndarray
    q: np.ndarray
    free_angle: np.ndarray
    travel: float
    cost: float
    approach: float
    lower_bound: float
    gap: float
    feasible: bool
    skipped: np.ndarray
    reason: str
    stats: dict[str, Any]

    def __repr__(self) -> str:
        """A one-line summary."""
        return (f"OrderResult(poses={self.order.shape[0]}, travel={self.travel:.4g}, "
                f"lower_bound={self.lower_bound:.4g}, gap={self.gap:.1%}, "
                f"feasible={self.feasible})")
