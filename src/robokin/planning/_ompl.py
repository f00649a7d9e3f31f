"""OMPL's geometric planners on robokin's exact checks (needs ``robokin[plan]``).

The Open Motion Planning Library (Sucan, Moll & Kavraki, IEEE Robotics &
Automation Magazine 19(4), 2012) supplies the planner algorithms; robokin supplies
the state validity checker and a motion validator that hands each whole edge to
the compiled edge check (conservative advancement, so an edge OMPL accepts is
proven free, not sampled). OMPL's own simplification is not used: robokin's
shortcutting and smoothing run on the path it returns.

OMPL draws its random numbers from a process-wide generator: its planners are
not repeatable across calls within one process the way the compiled
RRT-Connect is.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from robokin.exceptions import MissingExtraError

__all__ = ["OMPL_PLANNERS", "OmplOutcome", "ompl_plan"]

#: OMPL's geometric planners robokin offers (``planner="ompl:<name>"``).
OMPL_PLANNERS = ("RRTConnect", "RRT", "RRTstar", "InformedRRTstar", "SORRTstar",
                 "AORRTC", "PRM", "PRMstar", "BITstar", "FMT", "BFMT", "KPIECE1",
                 "BKPIECE1", "LBKPIECE1")


@dataclass(frozen=True)
class OmplOutcome:
    """What an OMPL run returned.

    Attributes:
        path: The path (K, n) when solved exactly, else None.
        status: OMPL's status text (``"Exact solution"``, ``"Timeout"``, ...).
        states: State validity calls made.
        edges: Motion validator calls made.
    """

    path: np.ndarray | None
    status: str
    states: int
    edges: int


def _ompl() -> Any:
    try:
        from ompl import base, geometric, util
    except ImportError:  # pragma: no cover - the extra is installed in CI
        raise MissingExtraError("ompl", "plan") from None
    util.setLogLevel(util.LOG_NONE)
    return base, geometric


def ompl_plan(
    name: str,
    n: int,
    lo: np.ndarray,
    hi: np.ndarray,
    start: np.ndarray,
    goals: np.ndarray,
    state_free: Callable[[np.ndarray], bool],
    edge_free: Callable[[np.ndarray, np.ndarray], bool],
    time_limit: float,
    planner_range: float | None,
) -> OmplOutcome:
    """Run OMPL's planner ``name`` from start (n,) to any of goals (k, n).

    Args:
        name: One of :data:`OMPL_PLANNERS`.
        n: Joints.
        lo: Lower sampling bounds (n,); hi: upper ones.
        hi: Upper sampling bounds (n,).
        start: The start configuration (n,), already checked.
        goals: Goal configurations (k, n), already checked.
        state_free: Whether one configuration (n,) is free.
        edge_free: Whether the straight edge between two configurations is free.
        time_limit: Seconds OMPL may plan.
        planner_range: Longest tree edge (planners that have one), or None (OMPL's
            default: a fifth of the diagonal of the bounds).

    Returns:
        The outcome.
    """
    ob, og = _ompl()
    space = ob.RealVectorStateSpace(n)
    bounds = ob.RealVectorBounds(n)
    for j in range(n):
        bounds.setLow(j, float(lo[j]))
        bounds.setHigh(j, float(hi[j]))
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)
    counts = {"states": 0, "edges": 0}

    def vec(s: Any) -> np.ndarray:
        return np.array([s[j] for j in range(n)])

    class Validity(ob.StateValidityChecker):  # type: ignore[name-defined]
        def isValid(self, s: Any) -> bool:  # noqa: N802 - OMPL's name
            counts["states"] += 1
            return bool(state_free(vec(s)))

    class Motion(ob.MotionValidator):  # type: ignore[name-defined]
        def checkMotion(self, s1: Any, s2: Any, *rest: Any) -> bool:  # noqa: N802
            counts["edges"] += 1
            return bool(edge_free(vec(s1), vec(s2)))

    validity, motion = Validity(si), Motion(si)
    si.setStateValidityChecker(validity)
    si.setMotionValidator(motion)
    si.setup()
    start_state = space.allocState()
    for j in range(n):
        start_state[j] = float(start[j])
    goal = ob.GoalStates(si)
    for row in goals:
        g = space.allocState()
        for j in range(n):
            g[j] = float(row[j])
        goal.addState(g)
    pdef = ob.ProblemDefinition(si)
    pdef.addStartState(start_state)
    pdef.setGoal(goal)
    planner = getattr(og, name)(si)
    if planner_range is not None and hasattr(planner, "setRange"):
        planner.setRange(float(planner_range))
    planner.setProblemDefinition(pdef)
    planner.setup()
    status = str(planner.solve(float(time_limit)))
    path = None
    if pdef.hasExactSolution():
        sol = pdef.getSolutionPath()
        path = np.array([vec(sol.getState(i)) for i in range(sol.getStateCount())])
    planner.clear()
    return OmplOutcome(path, status, counts["states"], counts["edges"])
