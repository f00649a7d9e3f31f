"""OMPL's per-call overhead on robokin's checks, and state-check costs (simple scenes).

The first planning benchmark, kept for the measurement behind the compiled
RRT-Connect (docs/decisions.md): how much of OMPL's search time on robokin's
checks is spent outside the compiled kernels. The issue's benchmark, on the
committed problem set, is ``bench_plan.py``.

Run: ``python benchmarks/bench_plan_overhead.py [--problems 30] [--baseline 8] [--json out.json]``.

Scenes in the spirit of MotionBenchMaker (Chamzas et al., "MotionBenchMaker: a tool
to generate and benchmark motion planning datasets", IEEE RA-L 7(2), 2022): a table
with objects on it, a shelf with three cells, a cage of bars, each with the UR5 and
the Panda carrying a parallel gripper (boxes). Problems: seeded random collision-free
starts, and goals with the tool in the scene's region of interest (over the table,
in a shelf cell, inside the cage), kept only when the straight joint-space edge
between them collides (the planner must go around). Everything is seeded: the same
command gives the same problems.

Measured, per (robot, scene), in one run on this machine:

* robokin ``Planner.plan`` (compiled RRT-Connect, shortcutting, corner cutting),
  time limit 1 s: success rate, median and p95 time, path length; **every path
  re-checked independently**: each segment sampled at 0.01 rad (largest joint
  step) with pinocchio's forward kinematics and coal's collision test on every
  checked pair; an invalid path is counted (the goal is 0).
* the baseline a user would write today: OMPL's RRTConnect and path simplification
  with a pinocchio + coal state checker as a Python callback (OMPL's discrete
  motion validator, its default resolution), time limit 2 s, on the first
  ``--baseline`` problems of each family;
* OMPL's RRTConnect with robokin's checks as Python callbacks (state checker and a
  motion validator that hands whole edges to the compiled kernel): how much of the
  time OMPL's per-call overhead takes (docs/decisions.md);
* state-check cost: robokin's kernel (batch and one state per call) and
  pinocchio + coal per state.

Timings on a shared 2-core machine are noisy: run several times and report ranges.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
import zlib
from dataclasses import dataclass, field

import numpy as np

import robokin
from robokin import planning
from robokin.collision import Scene
from robokin.model import geometry as geo
from robokin.spatial import pose_from_xyz_rpy

ROBOTS = ("ur5", "panda")
SCENES = ("table", "shelf", "cage")


# ----------------------------------------------------------------------- scenes
def _gripper(scene: Scene, robot: str) -> None:
    """A parallel gripper (palm and two fingers) on the flange; TCP between the tips."""
    if robot == "panda":  # Franka hand: 0.2 m wide, TCP 0.1034 m beyond the flange
        palm, finger, tcp = (0.06, 0.2, 0.06), (0.02, 0.02, 0.05), 0.1034
    else:  # a Robotiq 2F-85-sized box gripper
        palm, finger, tcp = (0.08, 0.13, 0.09), (0.02, 0.025, 0.05), 0.145
    z_palm = palm[2] / 2
    z_fing = palm[2] + finger[2] / 2
    y_f = palm[1] / 2 - finger[1] / 2 - 0.01
    shapes = [
        geo.box(palm, pose_from_xyz_rpy([0, 0, z_palm], [0, 0, 0])),
        geo.box(finger, pose_from_xyz_rpy([0, y_f, z_fing], [0, 0, 0])),
        geo.box(finger, pose_from_xyz_rpy([0, -y_f, z_fing], [0, 0, 0])),
    ]
    scene.set_tool(shapes, pose_from_xyz_rpy([0, 0, tcp], [0, 0, 0]), name="gripper")


def _box(scene: Scene, name: str, size, xyz, rpy=(0, 0, 0)) -> None:
    scene.add_box(name, size, pose_from_xyz_rpy(list(xyz), list(rpy)))


def make_scene(kind: str, robot: str) -> Scene:
    """One benchmark scene (metres; the robot's base at the origin, z up)."""
    s = Scene(kind)
    _gripper(s, robot)
    if kind == "table":
        _box(s, "table_top", (0.7, 1.2, 0.04), (0.6, 0.0, 0.0))
        _box(s, "table_leg", (0.05, 0.05, 0.6), (0.9, 0.5, -0.32))
        _box(s, "can", (0.08, 0.08, 0.2), (0.5, 0.15, 0.12))
        _box(s, "carton", (0.15, 0.25, 0.15), (0.65, -0.25, 0.095))
        _box(s, "bin_wall", (0.3, 0.02, 0.12), (0.45, 0.42, 0.08))
    elif kind == "shelf":
        x0, w, d = 0.55, 0.8, 0.3  # front face, width, depth
        for k, z in enumerate((0.0, 0.35, 0.7, 1.05)):
            _box(s, f"board_{k}", (d, w, 0.02), (x0 + d / 2, 0.0, z))
        for side in (-1, 1):
            _box(s, f"side_{side:+d}", (d, 0.02, 1.07), (x0 + d / 2, side * w / 2, 0.525))
        _box(s, "back", (0.02, w, 1.07), (x0 + d, 0.0, 0.525))
        _box(s, "floor", (2.0, 2.0, 0.02), (0.0, 0.0, -0.35))
    elif kind == "cage":
        cx, cy, half, top = 0.5, 0.0, 0.22, 0.55
        for i, (dx, dy) in enumerate(((1, 1), (1, -1), (-1, 1), (-1, -1))):
            _box(s, f"post_{i}", (0.03, 0.03, top), (cx + dx * half, cy + dy * half, top / 2 - 0.1))
        for i, z in enumerate((top - 0.1, 0.2)):
            _box(s, f"bar_x+_{i}", (0.03, 2 * half, 0.03), (cx + half, cy, z))
            _box(s, f"bar_y+_{i}", (2 * half, 0.03, 0.03), (cx, cy + half, z))
            _box(s, f"bar_y-_{i}", (2 * half, 0.03, 0.03), (cx, cy - half, z))
        _box(s, "roof", (2 * half, 2 * half, 0.02), (cx, cy, top - 0.08))
        _box(s, "base_plate", (2 * half, 2 * half, 0.02), (cx, cy, -0.1))
    else:
        raise ValueError(kind)
    return s


def in_region(kind: str, p: np.ndarray) -> np.ndarray:
    """Whether TCP positions p (m, 3) are in the scene's region of interest."""
    x, y, z = p[:, 0], p[:, 1], p[:, 2]
    if kind == "table":
        return (x > 0.3) & (x < 0.9) & (np.abs(y) < 0.55) & (z > 0.05) & (z < 0.3)
    if kind == "shelf":
        cell = ((z > 0.05) & (z < 0.3)) | ((z > 0.4) & (z < 0.65))
        return (x > 0.6) & (x < 0.8) & (np.abs(y) < 0.35) & cell
    return (np.abs(x - 0.5) < 0.17) & (np.abs(y) < 0.17) & (z > 0.0) & (z < 0.35)


# --------------------------------------------------------------------- problems
def seed_ompl(seed: int = 1) -> None:
    """Seed OMPL's process-wide generator (before its first use: the problem filter
    and the OMPL runs then repeat from run to run)."""
    from ompl import util as ou

    ou.setLogLevel(ou.LOG_NONE)
    ou.RNG.setSeed(seed)


seed_ompl()


def make_problems(pl: planning.Planner, kind: str, count: int, seed: int,
                  check_s: float = 3.0) -> tuple[list[tuple[np.ndarray, np.ndarray]], int]:
    """``count`` (start, goal) pairs: free, goal in the region, direct edge blocked,
    and solvable: OMPL's RRTConnect (on robokin's checks) finds a path within
    ``check_s`` seconds (a random goal can lie in a part of the free space no path
    reaches). Returns the problems and how many candidates were dropped as unsolved.
    """
    rng = np.random.default_rng(seed)
    lo, hi = pl.limits[:, 0], pl.limits[:, 1]
    lo, hi = np.maximum(lo, -math.pi), np.minimum(hi, math.pi)
    starts: list[np.ndarray] = []
    goals: list[np.ndarray] = []
    for _ in range(400):
        q = rng.uniform(lo, hi, (4000, pl.n))
        q = q[pl.is_free(q)]
        p = pl.robot.fk(q)[:, :3, 3]
        inside = in_region(kind, p)
        starts.extend(q[~inside][: 2 * count])
        goals.extend(q[inside])
        if len(goals) >= 4 * count and len(starts) >= 4 * count:
            break
    out: list[tuple[np.ndarray, np.ndarray]] = []
    S, G = np.array(starts), np.array(goals)
    rng.shuffle(S)
    rng.shuffle(G)
    k = min(len(S), len(G), 8 * count)
    S, G = S[:k], G[:k]
    blocked = ~pl.edges_free(S, G)
    dropped = 0
    for a, b, blk in zip(S, G, blocked):
        if not blk:
            continue
        if check_s > 0 and not pl.plan(a, b, planner="ompl:RRTConnect",
                                       time_limit=check_s, simplify=False,
                                       smooth=False).success:
            dropped += 1
            continue
        out.append((a, b))
        if len(out) == count:
            break
    return out, dropped


# ------------------------------------------------------------ pinocchio + coal
@dataclass
class PinCoal:
    """The robot and scene as pinocchio + coal, as a user would set them up."""

    model: object
    data: object
    gmodel: object
    gdata: object
    n: int
    checks: int = 0

    def free(self, q: np.ndarray) -> bool:
        import pinocchio as pin

        self.checks += 1
        return not pin.computeCollisions(self.model, self.data, self.gmodel, self.gdata,
                                         q, True)


def pin_coal(pl: planning.Planner) -> PinCoal:
    """pinocchio model (benchmarks/peers.py) with every checked pair as a GeometryModel."""
    import pinocchio as pin
    from peers import pinocchio_model

    robot = pl.robot
    model, data, _ = pinocchio_model(robot)
    prob = pl.model.problem
    ch = robot.chain
    nc = ch.n_chain
    gm = pin.GeometryModel()
    ids = []
    for s, shape in enumerate(prob.shapes):
        k = int(prob.link[s])
        if k == 0:
            joint, place = 0, ch.base
        elif k <= nc:
            joint, place = k, ch.frame_offsets[k - 1]
        else:
            joint, place = nc, ch.arrays.consts[-1]
        M = place @ shape.placement
        go = pin.GeometryObject(f"s{s}", joint, pin.SE3(M[:3, :3].copy(), M[:3, 3].copy()),
                                shape.coal_geometry())
        ids.append(gm.addGeometryObject(go))
    obs = []
    for ob in prob.objects:
        T = ob.pose
        go = pin.GeometryObject(ob.name, 0, pin.SE3(T[:3, :3].copy(), T[:3, 3].copy()),
                                ob.shape.coal_geometry())
        obs.append(gm.addGeometryObject(go))
    for p in range(prob.P):
        a = ids[int(prob.pa[p])]
        b = ids[int(prob.pb[p])] if prob.is_self[p] else obs[int(prob.pb[p])]
        gm.addCollisionPair(pin.CollisionPair(a, b))
    gd = pin.GeometryData(gm)
    out = PinCoal(model, data, gm, gd, robot.n)
    # the same configuration must give the same free/colliding answer as robokin
    rng = np.random.default_rng(7)
    q = rng.uniform(pl.limits[:, 0], pl.limits[:, 1], (200, robot.n))
    mine = pl.is_free(q)
    theirs = np.array([out.free(x) for x in q])
    if not np.array_equal(mine, theirs):
        raise SystemExit("pinocchio + coal disagrees with robokin on a state")
    out.checks = 0
    return out


def dense_valid(pc: PinCoal, path: np.ndarray, step: float = 0.01) -> bool:
    """Every segment sampled every ``step`` rad (largest joint step) is free."""
    for a, b in zip(path[:-1], path[1:]):
        k = max(int(np.ceil(np.abs(b - a).max() / step)), 1)
        for t in np.linspace(0.0, 1.0, k + 1):
            if not pc.free(a + t * (b - a)):
                return False
    return True


# ------------------------------------------------------------------------ OMPL
def ompl_baseline(pc: PinCoal, lo: np.ndarray, hi: np.ndarray, start: np.ndarray,
                  goal: np.ndarray, time_limit: float) -> tuple[bool, float, np.ndarray]:
    """OMPL RRTConnect + simplification, pinocchio + coal as a Python state checker."""
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    ou.setLogLevel(ou.LOG_NONE)
    n = pc.n
    space = ob.RealVectorStateSpace(n)
    b = ob.RealVectorBounds(n)
    for j in range(n):
        b.setLow(j, float(lo[j]))
        b.setHigh(j, float(hi[j]))
    space.setBounds(b)
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(
        lambda s: pc.free(np.array([s[j] for j in range(n)])))
    st, gl = space.allocState(), space.allocState()
    for j in range(n):
        st[j], gl[j] = float(start[j]), float(goal[j])
    ss.setStartAndGoalStates(st, gl)
    ss.setPlanner(og.RRTConnect(ss.getSpaceInformation()))
    t = time.perf_counter()
    solved = ss.solve(time_limit)
    ok = ss.haveExactSolutionPath() and str(solved) == "Exact solution"
    path = np.zeros((0, n))
    if ok:
        ss.simplifySolution()
        p = ss.getSolutionPath()
        path = np.array([[p.getState(i)[j] for j in range(n)]
                         for i in range(p.getStateCount())])
    return ok, time.perf_counter() - t, path


# ------------------------------------------------------------------------- run
@dataclass
class Family:
    robot: str
    scene: str
    times: list[float] = field(default_factory=list)
    cpu: list[float] = field(default_factory=list)
    ok: list[bool] = field(default_factory=list)
    valid: list[bool] = field(default_factory=list)
    length: list[float] = field(default_factory=list)
    search: list[float] = field(default_factory=list)
    base_times: list[float] = field(default_factory=list)
    base_cpu: list[float] = field(default_factory=list)
    base_ok: list[bool] = field(default_factory=list)
    ompl_times: list[float] = field(default_factory=list)
    ompl_ok: list[bool] = field(default_factory=list)
    dropped: int = 0
    ompl_search_s: float = 0.0
    ompl_kernel_s: float = 0.0
    ompl_calls: int = 0
    own_search_s: float = 0.0
    state_us: float = 0.0
    state1_us: float = 0.0
    pin_state_us: float = 0.0


def _pct(x: list[float], q: float) -> float:
    return float(np.percentile(x, q)) if x else math.nan


def ompl_overhead(pl: planning.Planner, problems: list, fam: Family) -> None:
    """OMPL's RRTConnect on robokin's checks: time in the compiled checks vs the rest.

    The compiled kernels the model calls (``plan_check_states``, ``plan_check_edges``)
    are wrapped to sum the time spent inside them; the rest of OMPL's search time
    is OMPL itself plus the calls from C++ into the Python callbacks and back
    (state conversion, argument checks). The compiled RRT-Connect's search on the
    same problems is timed alongside.
    """
    from robokin.planning import _model

    real = _model._k
    spent = {"kernel": 0.0, "calls": 0}

    class Timed:
        def __getattr__(self, name):
            fn = getattr(real, name)
            if not name.startswith("plan_check_"):
                return fn

            def call(*a):
                t = time.perf_counter()
                out = fn(*a)
                spent["kernel"] += time.perf_counter() - t
                spent["calls"] += 1
                return out
            return call

    _model._k = Timed()  # type: ignore[assignment]
    total = 0.0
    try:
        for i, (a, b) in enumerate(problems):
            res = pl.plan(a, b, planner="ompl:RRTConnect", time_limit=2.0, seed=i,
                          simplify=False, smooth=False)
            total += res.stats.get("search_s", res.time)
    finally:
        _model._k = real
    own = sum(pl.plan(a, b, seed=i, simplify=False, smooth=False).stats["search_s"]
              for i, (a, b) in enumerate(problems))
    fam.ompl_search_s = total
    fam.ompl_kernel_s = spent["kernel"]
    fam.ompl_calls = spent["calls"]
    fam.own_search_s = own


def state_costs(pl: planning.Planner, pc: PinCoal, fam: Family) -> None:
    rng = np.random.default_rng(3)
    q = rng.uniform(pl.limits[:, 0], pl.limits[:, 1], (20000, pl.n))
    t = time.perf_counter()
    pl.is_free(q)
    fam.state_us = (time.perf_counter() - t) / len(q) * 1e6
    m = pl.margin()
    t = time.perf_counter()
    for x in q[:2000]:
        pl.model.check_states(x, m)
    fam.state1_us = (time.perf_counter() - t) / 2000 * 1e6
    t = time.perf_counter()
    for x in q[:2000]:
        pc.free(x)
    fam.pin_state_us = (time.perf_counter() - t) / 2000 * 1e6


def run_family(robot_name: str, kind: str, args: argparse.Namespace) -> Family:
    robot = robokin.load(robot_name)
    scene = make_scene(kind, robot_name)
    pl = planning.Planner(robot, scene)
    pc = pin_coal(pl)
    fam = Family(robot_name, kind)
    problems, fam.dropped = make_problems(pl, kind, args.problems,
                                          seed=zlib.crc32(f"{robot_name}/{kind}".encode()),
                                          check_s=args.solvable_s)
    for i, (a, b) in enumerate(problems):
        res = pl.plan(a, b, time_limit=args.time_limit, seed=i)
        fam.ok.append(res.success)
        fam.times.append(res.time)
        fam.cpu.append(res.stats.get("cpu_s", res.time))
        if res.success:
            fam.search.append(res.stats.get("search_s", math.nan))
            fam.length.append(res.length)
            fam.valid.append(dense_valid(pc, np.asarray(res.q)))
    lo, hi = pl.limits[:, 0], pl.limits[:, 1]
    for i, (a, b) in enumerate(problems[: args.baseline]):
        c = time.process_time()
        ok, t, _ = ompl_baseline(pc, lo, hi, a, b, args.baseline_limit)
        fam.base_cpu.append(time.process_time() - c)
        fam.base_ok.append(ok)
        fam.base_times.append(t)
        res = pl.plan(a, b, time_limit=args.time_limit, seed=i, planner="ompl:RRTConnect")
        fam.ompl_ok.append(res.success)
        fam.ompl_times.append(res.time)
    ompl_overhead(pl, problems[: args.baseline], fam)
    state_costs(pl, pc, fam)
    return fam


def report(fams: list[Family]) -> dict:
    rows = []
    print("| robot | scene | solved | invalid | median [ms] wall / CPU | p95 [ms] | "
          "length [rad] | baseline solved | baseline median [ms] wall / CPU | ratio | "
          "OMPL+robokin median [ms] | state [us] batch / single / pin+coal | dropped |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for f in fams:
        med, p95 = 1e3 * _pct(f.times, 50), 1e3 * _pct(f.times, 95)
        cmed = 1e3 * _pct(f.cpu, 50)
        bmed, bcpu = 1e3 * _pct(f.base_times, 50), 1e3 * _pct(f.base_cpu, 50)
        omed = 1e3 * _pct(f.ompl_times, 50)
        row = dict(robot=f.robot, scene=f.scene, problems=len(f.ok), solved=sum(f.ok),
                   invalid=len(f.valid) - sum(f.valid), median_ms=med, p95_ms=p95,
                   cpu_median_ms=cmed, length=_pct(f.length, 50),
                   baseline_solved=sum(f.base_ok), baseline_n=len(f.base_ok),
                   baseline_median_ms=bmed, baseline_cpu_median_ms=bcpu,
                   ompl_robokin_median_ms=omed, state_us=f.state_us,
                   state1_us=f.state1_us, pin_state_us=f.pin_state_us,
                   search_median_ms=1e3 * _pct(f.search, 50), dropped=f.dropped)
        rows.append(row)
        print(f"| {f.robot} | {f.scene} | {sum(f.ok)}/{len(f.ok)} | {row['invalid']} | "
              f"{med:.2f} / {cmed:.2f} | {p95:.2f} | {row['length']:.2f} | "
              f"{sum(f.base_ok)}/{len(f.base_ok)} | {bmed:.0f} / {bcpu:.0f} | "
              f"{bmed / med:.0f}x | {omed:.2f} | {f.state_us:.2f} / {f.state1_us:.2f} / "
              f"{f.pin_state_us:.0f} | {f.dropped} |")
    allt = [t for f in fams for t in f.times]
    allc = [t for f in fams for t in f.cpu]
    allb = [t for f in fams for t in f.base_times]
    allbc = [t for f in fams for t in f.base_cpu]
    solved = sum(sum(f.ok) for f in fams)
    total = sum(len(f.ok) for f in fams)
    invalid = sum(r["invalid"] for r in rows)
    calls = sum(f.ompl_calls for f in fams)
    o_total = sum(f.ompl_search_s for f in fams)
    o_kernel = sum(f.ompl_kernel_s for f in fams)
    own = sum(f.own_search_s for f in fams)
    print(f"\nOMPL RRTConnect on robokin's checks (the baseline problems): search "
          f"{o_total:.3f} s, of it {o_kernel:.3f} s in the kernels "
          f"({100 * o_kernel / max(o_total, 1e-12):.0f} %), {calls} callbacks, "
          f"{1e6 * (o_total - o_kernel) / max(calls, 1):.1f} us outside the kernels "
          f"per callback; the compiled RRT-Connect's search on the same problems: "
          f"{own:.3f} s")
    summary = dict(solved=solved, problems=total, invalid=invalid,
                   ompl_search_s=o_total, ompl_kernel_s=o_kernel, ompl_calls=calls,
                   own_search_s=own,
                   median_ms=1e3 * _pct(allt, 50), p95_ms=1e3 * _pct(allt, 95),
                   cpu_median_ms=1e3 * _pct(allc, 50), cpu_p95_ms=1e3 * _pct(allc, 95),
                   baseline_median_ms=1e3 * _pct(allb, 50),
                   baseline_cpu_median_ms=1e3 * _pct(allbc, 50),
                   dropped=sum(f.dropped for f in fams))
    print(f"\nall: solved {solved}/{total} ({100 * solved / max(total, 1):.1f} %), "
          f"invalid {invalid}, median {summary['median_ms']:.2f} ms wall / "
          f"{summary['cpu_median_ms']:.2f} ms CPU, p95 {summary['p95_ms']:.2f} ms wall; "
          f"baseline median {summary['baseline_median_ms']:.0f} ms wall / "
          f"{summary['baseline_cpu_median_ms']:.0f} ms CPU "
          f"({summary['baseline_median_ms'] / summary['median_ms']:.0f}x wall, "
          f"{summary['baseline_cpu_median_ms'] / summary['cpu_median_ms']:.0f}x CPU); "
          f"{summary['dropped']} unsolvable candidates dropped")
    return dict(families=rows, summary=summary)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--problems", type=int, default=30, help="problems per family")
    ap.add_argument("--baseline", type=int, default=8,
                    help="problems per family also run by the OMPL baselines")
    ap.add_argument("--time-limit", type=float, default=1.0)
    ap.add_argument("--baseline-limit", type=float, default=2.0)
    ap.add_argument("--solvable-s", type=float, default=3.0,
                    help="drop candidate problems OMPL's RRTConnect does not solve in "
                    "this many seconds (0: keep all)")
    ap.add_argument("--robots", nargs="*", default=list(ROBOTS))
    ap.add_argument("--scenes", nargs="*", default=list(SCENES))
    ap.add_argument("--json", default=None, help="write the figures to this file")
    args = ap.parse_args()
    fams = []
    for r in args.robots:
        for s in args.scenes:
            fams.append(run_family(r, s, args))
            print(f"... {r} {s} done", file=sys.stderr)
    out = report(fams)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(out, fh, indent=1)
    fail = out["summary"]["invalid"] > 0
    sys.exit(1 if fail else 0)


if __name__ == "__main__":
    main()
