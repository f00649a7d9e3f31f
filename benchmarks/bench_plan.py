"""robokin's planner against the OMPL + pinocchio/coal baseline on the problem set (issue 26).

The problem set is ``benchmarks/data/plan_problems.json.gz`` (written by
``plan_problems.py``: seven MotionBenchMaker-style families — table_pick,
table_under_pick, box, bookshelf_small/tall/thin, cage — for the UR5 with a
gripper and the Panda with its hand, 100 problems each, the robots loaded from
URDF + SRDF as MoveIt users have them). Measured in one run, per robot and family:

* robokin: ``planning.Planner(robot, scene).plan(start, goal, time_limit=1)``
  (compiled RRT-Connect, shortcuts, corner cutting; the Planner is built before
  the clock starts, as the baseline's checker is): solved within the limit,
  median and p95 time (wall clock and CPU time), joint-space path length;
  **every path re-checked independently** by ``plan_baseline.recheck_path``
  (pinocchio + coal on the URDF, coal's cached GJK guess off, every 0.01 rad,
  the ends at the start and the goal); an invalid path is counted. With
  ``--pose`` it also plans to the grasp pose (every IK branch a goal) and
  records how many configurations it aimed at against the in-limit IK
  solutions (whole turns included) ``robot.ik`` returns for that pose (6-axis
  arms: the Panda's seven joints give a sampled redundancy, not a branch set);
* the baseline (``plan_baseline.Baseline``): OMPL RRTConnect + simplification
  with the pinocchio + coal state checker as a Python callback, on the first
  ``--baseline`` problems of each family's subset, in the same process, its
  paths re-checked the same way.

``--per-family N`` below 100 takes a fixed subset: N problems per (robot,
family) drawn by ``numpy.random.default_rng(--subset-seed)`` (the same N and
seed give the same problems). Medians are of the solved problems, and over
every problem with an unsolved one counted at its time limit (the baseline
leaves many unsolved); totals over all problems and over the problems both
planners ran (paired).

``python benchmarks/bench_plan.py --summarize OUT.json`` prints the tables of an
earlier run's JSON again.

Run: ``python benchmarks/bench_plan.py [--per-family 100] [--baseline 10]
[--baseline-time 2] [--pose] [--json out.json]``. Exit 1 if any path is invalid.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from plan_baseline import Baseline, checker_for, path_length, recheck_path
from plan_problems import ROBOTS, Problem, load_problems

from robokin import planning

ROBOKIN, BASELINE = "robokin", "ompl+pinocchio"


@dataclass(frozen=True)
class Outcome:
    """One planner on one problem.

    Attributes:
        id: The problem's id.
        robot: Robot name.
        family: Scene family.
        planner: ``"robokin"``, ``"robokin/pose"`` or ``"ompl+pinocchio"``.
        success: Solved within the planner's time limit.
        time: Wall-clock time [s].
        cpu: CPU time of the process during the query [s].
        length: Joint-space path length [rad] (NaN when not solved).
        valid: The independent re-check's verdict (None when not solved).
        reason: Why not solved or why invalid ("" otherwise).
        goals: Pose goals of a 6-axis arm: the IK branches the planner aimed at
            (-1 otherwise).
        branches: Pose goals of a 6-axis arm: ``robot.ik``'s in-limit solutions
            of the pose, whole turns included (-1 otherwise).
    """

    id: str
    robot: str
    family: str
    planner: str
    success: bool
    time: float
    cpu: float
    length: float
    valid: bool | None
    reason: str
    goals: int = -1
    branches: int = -1


def subset(problems: Sequence[Problem], per_family: int, seed: int) -> list[Problem]:
    """``per_family`` problems of each (robot, family), a seeded draw (all when >= their count)."""
    groups: dict[tuple[str, str], list[Problem]] = {}
    for p in problems:
        groups.setdefault((p.robot, p.family), []).append(p)
    rng = np.random.default_rng(seed)
    out = []
    for items in groups.values():
        if per_family >= len(items):
            out.extend(items)
        else:
            pick = np.sort(rng.choice(len(items), size=per_family, replace=False))
            out.extend(items[i] for i in pick)
    return out


def _robokin(p: Problem, planner: planning.Planner, robot: Any, checker: Any,
             time_limit: float, pose: bool) -> Outcome:
    """robokin on one problem, its path re-checked by pinocchio + coal."""
    target = p.goal_pose if pose else p.goal
    c0, t0 = time.process_time(), time.perf_counter()
    res = planner.plan(p.start, target, time_limit=time_limit, seed=0)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    ok = bool(res.success) and wall <= time_limit
    rc = recheck_path(p, np.asarray(res.q), checker=checker,
                      goal="pose" if pose else "configuration") if res.success else None
    goals = branches = -1
    if pose and robot.n == 6:
        goals = len(res.goals)
        sols = robot.ik(np.asarray(p.goal_pose)).keep_within_limits().expand_turns()
        branches = int(np.asarray(sols.solutions()).reshape(-1, robot.n).shape[0])
    why = str(res.reason) if not res.success else ("" if rc is None else rc.reason)
    return Outcome(p.id, p.robot, p.family, ROBOKIN + ("/pose" if pose else ""), ok, wall,
                   cpu, path_length(res.q) if res.success else math.nan,
                   None if rc is None else rc.valid, why, goals, branches)


def _baseline(p: Problem, checker: Any, time_limit: float) -> Outcome:
    """The OMPL + pinocchio/coal baseline on one problem."""
    c0 = time.process_time()
    res = Baseline(p, checker).plan(time_limit, seed=0)
    cpu = time.process_time() - c0
    rc = recheck_path(p, res.q, checker=checker) if res.success else None
    return Outcome(p.id, p.robot, p.family, BASELINE, bool(res.success), res.time, cpu,
                   res.length if res.success else math.nan,
                   None if rc is None else rc.valid, "" if rc is None else rc.reason)


def run(problems: Sequence[Problem], *, time_limit: float = 1.0, baseline: int = 10,
        baseline_time: float = 2.0, pose: bool = False, progress: bool = True
        ) -> list[Outcome]:
    """Both planners on ``problems`` (the baseline on the first ``baseline`` of each family)."""
    robots = {name: spec.robot() for name, spec in ROBOTS.items()}
    out: list[Outcome] = []
    seen: dict[tuple[str, str], int] = {}
    for p in problems:
        k = seen[(p.robot, p.family)] = seen.get((p.robot, p.family), 0) + 1
        if progress and k == 1:
            print(f"{p.robot} {p.family} ...", file=sys.stderr, flush=True)
        checker = checker_for(p)
        planner = planning.Planner(robots[p.robot], p.scene())
        out.append(_robokin(p, planner, robots[p.robot], checker, time_limit, False))
        if pose:
            out.append(_robokin(p, planner, robots[p.robot], checker, time_limit, True))
        if k <= baseline:
            out.append(_baseline(p, checker, baseline_time))
    return out


def _pct(x: Sequence[float], q: float) -> float:
    return float(np.percentile(x, q)) if len(x) else math.nan


def _row(items: Sequence[Outcome], within: float, limits: dict[str, float]
         ) -> dict[str, Any]:
    solved = [o for o in items if o.success]
    # over every problem, an unsolved one counted at its time limit (or what it took)
    every = [o.time if o.success else max(o.time, limits[o.planner]) for o in items]
    in_limit = [o for o in solved if o.time <= within]
    t = [o.time for o in solved]
    c = [o.cpu for o in solved]
    return {
        "problems": len(items), "solved": len(solved), "solved_1s": len(in_limit),
        "invalid": sum(o.valid is False for o in solved),
        "median_ms": 1e3 * _pct(t, 50), "p95_ms": 1e3 * _pct(t, 95),
        "median_all_ms": 1e3 * _pct(every, 50),
        "cpu_median_ms": 1e3 * _pct(c, 50), "cpu_p95_ms": 1e3 * _pct(c, 95),
        "median_length_rad": _pct([o.length for o in solved], 50),
    }


def summarize(outcomes: Sequence[Outcome], within: float = 1.0,
              baseline_time: float = 2.0) -> dict[str, Any]:
    """Rows per planner, robot and family; totals per planner; paired ratios; pose branches.

    Times are of the solved problems, but ``median_all_ms``: every problem, an
    unsolved one counted at its planner's time limit (``within`` for robokin,
    ``baseline_time`` for the baseline).
    """
    limits = {ROBOKIN: within, ROBOKIN + "/pose": within, BASELINE: baseline_time}
    groups: dict[tuple[str, str, str], list[Outcome]] = {}
    for o in outcomes:
        groups.setdefault((o.planner, o.robot, o.family), []).append(o)
    rows = [{"planner": k[0], "robot": k[1], "family": k[2], **_row(v, within, limits)}
            for k, v in groups.items()]
    planners = sorted({o.planner for o in outcomes})
    totals = {pl: _row([o for o in outcomes if o.planner == pl], within, limits) for pl in planners}
    base_ids = {o.id for o in outcomes if o.planner == BASELINE}
    paired = {pl: _row([o for o in outcomes if o.planner == pl and o.id in base_ids], within,
                     limits)
              for pl in planners}
    pose = [o for o in outcomes if o.planner == ROBOKIN + "/pose" and o.branches >= 0]
    return {"rows": rows, "totals": totals, "paired": paired,
            "pose_goals_below_branches": sum(o.goals < o.branches for o in pose),
            "pose_median_branches": _pct([o.branches for o in pose], 50)}


def _print(summary: dict[str, Any]) -> None:
    print("| planner | robot | family | solved in 1 s | invalid | median [ms] wall / CPU "
          "| p95 [ms] wall / CPU | length [rad] |")
    print("|---|---|---|---|---|---|---|---|")
    for r in summary["rows"]:
        print(f"| {r['planner']} | {r['robot']} | {r['family']} | {r['solved_1s']}/"
              f"{r['problems']} | {r['invalid']} | {r['median_ms']:.1f} / "
              f"{r['cpu_median_ms']:.1f} | {r['p95_ms']:.0f} / {r['cpu_p95_ms']:.0f} | "
              f"{r['median_length_rad']:.2f} |")
    for title in ("totals", "paired"):
        print(f"\n{title}:")
        for pl, r in summary[title].items():
            print(f"  {pl:15s} solved {r['solved']}/{r['problems']} (in 1 s: {r['solved_1s']}, "
                  f"{100 * r['solved_1s'] / max(r['problems'], 1):.1f} %), invalid "
                  f"{r['invalid']}, median {r['median_ms']:.1f} ms wall / "
                  f"{r['cpu_median_ms']:.1f} ms CPU, p95 {r['p95_ms']:.0f} / "
                  f"{r['cpu_p95_ms']:.0f} ms, length {r['median_length_rad']:.2f} rad; "
                  f"median over all (unsolved at the limit) {r['median_all_ms']:.1f} ms")
        rk, bl = summary[title].get(ROBOKIN), summary[title].get(BASELINE)
        if rk and bl:
            print(f"  baseline / robokin medians of the solved: "
                  f"{bl['median_ms'] / rk['median_ms']:.1f}x wall, "
                  f"{bl['cpu_median_ms'] / rk['cpu_median_ms']:.1f}x CPU; over all "
                  f"(unsolved at the limit): {bl['median_all_ms'] / rk['median_all_ms']:.1f}x")
    if "robokin/pose" in summary["totals"]:
        print(f"\npose goals aiming at fewer branches than robokin's IK returns: "
              f"{summary['pose_goals_below_branches']} (median branches "
              f"{summary['pose_median_branches']:.0f})")


def main(argv: Sequence[str] | None = None) -> None:
    """Run, print the tables, write JSON with ``--json``; exit 1 on an invalid path."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--per-family", type=int, default=100)
    ap.add_argument("--subset-seed", type=int, default=0)
    ap.add_argument("--time-limit", type=float, default=1.0)
    ap.add_argument("--baseline", type=int, default=10,
                    help="problems per (robot, family) the baseline also runs")
    ap.add_argument("--baseline-time", type=float, default=2.0)
    ap.add_argument("--pose", action="store_true", help="also plan to the grasp pose")
    ap.add_argument("--robot", choices=list(ROBOTS), default=None)
    ap.add_argument("--family", default=None)
    ap.add_argument("--json", default=None)
    ap.add_argument("--summarize", default=None, help="print the tables of a run's JSON")
    args = ap.parse_args(argv)
    if args.summarize:
        with open(args.summarize) as fh:
            data = json.load(fh)
        old = [Outcome(**o) for o in data["outcomes"]]
        _print(summarize(old, data["args"]["time_limit"], data["args"]["baseline_time"]))
        return
    chosen = subset(load_problems(robot=args.robot, family=args.family), args.per_family,
                    args.subset_seed)
    t0 = time.perf_counter()
    outcomes = run(chosen, time_limit=args.time_limit, baseline=args.baseline,
                   baseline_time=args.baseline_time, pose=args.pose)
    summary = summarize(outcomes, args.time_limit, args.baseline_time)
    _print(summary)
    print(f"\n{len(chosen)} problems, {time.perf_counter() - t0:.0f} s")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"args": vars(args), **summary,
                       "outcomes": [asdict(o) for o in outcomes]}, fh, indent=1)
    sys.exit(1 if any(o.valid is False for o in outcomes) else 0)


if __name__ == "__main__":
    main()
