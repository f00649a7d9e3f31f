"""The answer of a planning query (:class:`PlanResult`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from robokin.trajectory.samples import Trajectory

__all__ = ["PlanResult"]


@dataclass(frozen=True, eq=False)
class PlanResult:
    """A planned path, or why there is none.

    Attributes:
        success: Whether a collision-free path was found.
        q: The path (K, n) [rad, m]: ``q[0]`` the start, ``q[-1]`` the goal
            reached; every straight segment ``q[i] -> q[i + 1]`` is proven free
            (robot against the scene and itself, tool included, with the clearance
            asked for). Empty (0, n) on failure.
        reason: ``"solved"``, or why not (a start in collision naming the pair, no
            goal left, the time limit, ...).
        time: Wall-clock time of the query [s] (trajectory retiming excluded).
        planner: The planner that ran (``"rrtconnect"``, ``"ompl:RRTstar"``, ...).
        goal: The goal configuration reached (n,), or None.
        goal_index: Its row in the goal set given (for a pose goal: in
            ``goals``), or None.
        goals: The candidate goal configurations (k, n) the planner aimed at.
        raw: The planner's own path (before shortcutting and corner cutting).
        trajectory: The retimed trajectory when asked for (``retime=True``), else None.
        stats: Counters of the query: states and edges checked, tree nodes,
            seconds per stage.
    """

    success: bool
    q: np.ndarray
    reason: str
    time: float
    planner: str
    goal: np.ndarray | None = None
    goal_index: int | None = None
    goals: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    raw: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    trajectory: Trajectory | None = None
    stats: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        """Freeze the arrays."""
        for name in ("q", "goals", "raw", "goal"):
            a = getattr(self, name)
            if isinstance(a, np.ndarray):
                a.setflags(write=False)

    def __bool__(self) -> bool:
        """True when a path was found."""
        return self.success

    @property
    def length(self) -> float:
        """Joint-space length of the path (sum of segment norms) [rad, m]."""
        if self.q.shape[0] < 2:
            return 0.0
        return float(np.linalg.norm(np.diff(self.q, axis=0), axis=1).sum())

    def __repr__(self) -> str:
        """A one-line summary."""
        if not self.success:
            return f"PlanResult(success=False, reason={self.reason!r}, time={self.time:.4g})"
        return (f"PlanResult(success=True, waypoints={self.q.shape[0]}, "
                f"length={self.length:.4g}, time={self.time:.4g}, planner={self.planner!r})")
