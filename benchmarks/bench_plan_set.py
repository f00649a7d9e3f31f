"""robokin's planner against the OMPL + pinocchio/coal baseline on the problem set.

The problem set is ``benchmarks/data/plan_problems.json.gz`` (written by
``plan_problems.py``: seven MotionBenchMaker-style families, the UR5 with a
gripper and the Panda with its hand, 100 problems each, loaded from URDF + SRDF
as MoveIt users have them). Measured, per robot and family, in one run:

* robokin: ``planning.Planner(robot, scene).plan(start, goal)`` (goal: the goal
  configuration, or with ``--goal pose`` the grasp pose, every IK branch):
  success, median and p95 time, joint-space path length; **every path re-checked
  independently** (``plan_baseline.recheck_path``: pinocchio + coal on the URDF,
  every 0.01 rad, and the end at the goal); an invalid path is counted;
* the baseline (``plan_baseline.Baseline``): OMPL RRTConnect + simplification
  with a pinocchio + coal state checker as a Python callback, on the first
  ``--baseline`` problems of each family;

Run: ``python benchmarks/bench_plan_set.py [--per-family 100] [--time-limit 1]
[--baseline 5] [--baseline-time 2] [--goal configuration|pose] [--json out.json]``.
``run_problem_set`` is the function ``bench_plan.py`` can call. Without
``robokin.planning`` (this branch before the planner is merged) only the
baseline runs.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from plan_baseline import (
    Baseline,
    PinCoalChecker,
    checker_for,
    path_length,
    recheck_path,
)
from plan_problems import ROBOTS, Problem, load_problems


@dataclass(frozen=True)
class Outcome:
    """One planner on one problem."""

    id: str
    robot: str
    family: str
    planner: str
    success: bool
    time: float
    length: float
    valid: bool | None  # the independent re-check (None: not solved)
    reason: str


def robokin_planner(time_limit: float, goal: str = "configuration",
                    seed: int = 0) -> Callable[[Problem, Any], tuple[bool, np.ndarray, float, str]]:
    """A plan function running ``robokin.planning.Planner`` (one per problem's scene)."""
    from robokin import planning

    def plan(problem: Problem, robot: Any) -> tuple[bool, np.ndarray, float, str]:
        planner = planning.Planner(robot, problem.scene())
        target = problem.goal_pose if goal == "pose" else problem.goal
        t0 = time.perf_counter()
        res = planner.plan(problem.start, target, time_limit=time_limit, seed=seed)
        elapsed = time.perf_counter() - t0
        return bool(res.success), np.asarray(res.q), elapsed, str(res.reason)

    return plan


def run_problem_set(problems: Sequence[Problem], *, time_limit: float = 1.0,
                    goal: str = "configuration", baseline: int = 5,
                    baseline_time: float = 2.0, robokin: bool = True,
                    progress: bool = True) -> list[Outcome]:
    """robokin (when ``robokin.planning`` exists) and the baseline on ``problems``.

    Args:
        problems: From :func:`plan_problems.load_problems`.
        time_limit: robokin's time limit per problem [s].
        goal: ``"configuration"`` or ``"pose"`` (robokin plans to the grasp pose).
        baseline: Problems per (robot, family) the baseline also runs on.
        baseline_time: The baseline's time limit [s].
        robokin: Run robokin's planner.
        progress: Print a line per family to stderr.
    """
    plan = None
    if robokin:
        try:
            plan = robokin_planner(time_limit, goal)
        except ImportError as exc:
            print(f"robokin.planning is not available ({exc}): baseline only", file=sys.stderr)
    robots = {name: spec.robot() for name, spec in ROBOTS.items()}
    out: list[Outcome] = []
    seen: dict[tuple[str, str], int] = {}
    for p in problems:
        k = seen[(p.robot, p.family)] = seen.get((p.robot, p.family), 0) + 1
        checker: PinCoalChecker = checker_for(p)
        if plan is not None:
            ok, q, t, why = plan(p, robots[p.robot])
            rc = recheck_path(p, q, checker=checker, goal=goal) if ok else None
            out.append(Outcome(p.id, p.robot, p.family, "robokin", ok, t,
                               path_length(q) if ok else float("nan"),
                               None if rc is None else rc.valid,
                               why if not ok else ("" if rc is None else rc.reason)))
        if k <= baseline:
            res = Baseline(p, checker).plan(baseline_time, seed=0)
            rc = recheck_path(p, res.q, checker=checker) if res.success else None
            out.append(Outcome(p.id, p.robot, p.family, "ompl+pinocchio", res.success,
                               res.time, res.length if res.success else float("nan"),
                               None if rc is None else rc.valid,
                               "" if rc is None else rc.reason))
        if progress and k == 1:
            print(f"{p.robot} {p.family} ...", file=sys.stderr)
    return out


def summarize(outcomes: Sequence[Outcome]) -> list[dict[str, Any]]:
    """Per planner, robot and family: solved, invalid, median / p95 time, median length."""
    groups: dict[tuple[str, str, str], list[Outcome]] = {}
    for o in outcomes:
        groups.setdefault((o.planner, o.robot, o.family), []).append(o)
    rows = []
    for (planner, robot, family), items in groups.items():
        solved = [o for o in items if o.success]
        times = [o.time for o in solved]
        rows.append({
            "planner": planner, "robot": robot, "family": family, "problems": len(items),
            "solved": len(solved), "invalid": sum(o.valid is False for o in solved),
            "median_s": statistics.median(times) if times else float("nan"),
            "p95_s": float(np.percentile(times, 95)) if times else float("nan"),
            "median_length_rad": statistics.median([o.length for o in solved])
            if solved else float("nan"),
        })
    return rows


def main(argv: Sequence[str] | None = None) -> None:
    """Run and print the table (and write JSON with ``--json``)."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--per-family", type=int, default=100)
    ap.add_argument("--time-limit", type=float, default=1.0)
    ap.add_argument("--baseline", type=int, default=5)
    ap.add_argument("--baseline-time", type=float, default=2.0)
    ap.add_argument("--goal", choices=("configuration", "pose"), default="configuration")
    ap.add_argument("--robot", choices=list(ROBOTS), default=None)
    ap.add_argument("--family", default=None)
    ap.add_argument("--json", default=None)
    args = ap.parse_args(argv)
    problems = load_problems(robot=args.robot, family=args.family)
    counts: dict[tuple[str, str], int] = {}
    chosen = []
    for p in problems:
        counts[(p.robot, p.family)] = counts.get((p.robot, p.family), 0) + 1
        if counts[(p.robot, p.family)] <= args.per_family:
            chosen.append(p)
    outcomes = run_problem_set(chosen, time_limit=args.time_limit, goal=args.goal,
                               baseline=args.baseline, baseline_time=args.baseline_time)
    rows = summarize(outcomes)
    print(f"{'planner':15s} {'robot':12s} {'family':17s} solved invalid  median    p95  length")
    for r in rows:
        print(f"{r['planner']:15s} {r['robot']:12s} {r['family']:17s} "
              f"{r['solved']:3d}/{r['problems']:<3d} {r['invalid']:5d} "
              f"{r['median_s']:8.4f} {r['p95_s']:7.3f} {r['median_length_rad']:6.2f}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"rows": rows, "outcomes": [asdict(o) for o in outcomes]}, fh, indent=1)


if __name__ == "__main__":
    main()
