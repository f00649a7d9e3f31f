"""The planning baseline and the independent path check (issue 26, item 6).

What a Python user writes today without robokin's planner: OMPL's RRTConnect with
path simplification, its state validity checker a Python callback running
pinocchio's forward kinematics and coal's collision checks on the robot's URDF
(SRDF pairs removed) and the scene's primitives. The same checker, dense at 0.01
rad, is the **independent re-check** of every robokin path: pinocchio + coal on the
URDF, no robokin geometry code.

Used by ``benchmarks/bench_plan.py`` (see ``docs/benchmarks.md``)::

    from plan_problems import load_problems
    from plan_baseline import Baseline, recheck_path

    problems = load_problems()
    base = Baseline(problems[0])            # checker for the problem's robot and scene
    res = base.plan(time_limit=2.0, seed=0) # OMPL RRTConnect + simplification
    ok = recheck_path(problems[0], path)    # every 0.01 rad of a robokin path

Run alone it times the baseline on the problem set:
``python benchmarks/plan_baseline.py [--per-family 10] [--time-limit 2]``.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
#: Dense checking step [rad]: the longest straight joint-space move (Euclidean
#: norm over the joints) between two checked states.
RESOLUTION = 0.01


# ------------------------------------------------------------------ URDF reading
@dataclass(frozen=True)
class UrdfJoint:
    """One URDF joint, as far as the baseline needs it (read with ElementTree)."""

    name: str
    type: str
    parent: str
    child: str
    lower: float
    upper: float
    mimic: str | None
    multiplier: float
    offset: float


def urdf_joints(urdf: str | Path) -> dict[str, UrdfJoint]:
    """Every joint of a URDF by name (plain ElementTree: the files are ours)."""
    out = {}
    for el in ET.parse(urdf).getroot().findall("joint"):
        lim = el.find("limit")
        mim = el.find("mimic")
        jtype = el.get("type", "")
        lo, hi = -math.inf, math.inf
        if lim is not None and jtype in ("revolute", "prismatic"):
            lo, hi = float(lim.get("lower", 0)), float(lim.get("upper", 0))
        out[el.get("name", "")] = UrdfJoint(
            name=el.get("name", ""), type=jtype,
            parent=el.find("parent").get("link", ""),  # type: ignore[union-attr]
            child=el.find("child").get("link", ""),  # type: ignore[union-attr]
            lower=lo, upper=hi,
            mimic=None if mim is None else mim.get("joint"),
            multiplier=1.0 if mim is None else float(mim.get("multiplier", 1)),
            offset=0.0 if mim is None else float(mim.get("offset", 0)),
        )
    return out


def arm_joint_names(joints: Mapping[str, UrdfJoint], tip_link: str) -> list[str]:
    """The movable joints from the root to ``tip_link``, root first."""
    by_child = {j.child: j for j in joints.values()}
    path, link = [], tip_link
    while link in by_child:
        j = by_child[link]
        path.append(j)
        link = j.parent
    return [j.name for j in reversed(path) if j.type != "fixed"]


def tool_joint_values(joints: Mapping[str, UrdfJoint], arm: Iterable[str],
                      given: Mapping[str, float]) -> dict[str, float]:
    """Positions of every movable joint off the arm: given, or 0 clamped; mimics follow."""
    arm = set(arm)

    def value(name: str, depth: int = 0) -> float:
        j = joints[name]
        if j.mimic is not None and depth < 20:
            return j.multiplier * value(j.mimic, depth + 1) + j.offset
        v = given.get(name, 0.0)
        return min(max(v, j.lower), j.upper)

    return {n: value(n) for n, j in joints.items()
            if j.type not in ("fixed",) and n not in arm}


# -------------------------------------------------------------------- checker
def _coal_shape(obj: Mapping[str, Any]) -> Any:
    import coal

    t, s = obj["type"], obj["size"]
    if t == "box":
        return coal.Box(*s)
    if t == "cylinder":
        return coal.Cylinder(s[0], s[1])
    if t == "sphere":
        return coal.Sphere(s[0])
    raise ValueError(f"the baseline reads boxes, cylinders and spheres, not {t!r}")


def _se3(xyz: Sequence[float], quat_xyzw: Sequence[float]) -> Any:
    import pinocchio as pin

    x, y, z, w = quat_xyzw
    R = pin.Quaternion(w, x, y, z).normalized().toRotationMatrix()
    return pin.SE3(R, np.asarray(xyz, dtype=float))


class PinCoalChecker:
    """State validity with pinocchio + coal: the URDF's collision shapes, the SRDF's
    pairs removed, the tool's joints locked, the scene's primitives.

    coal's cached GJK guess, which pinocchio enables, is turned off: with it,
    boolean collision checks miss real contacts (see ``__init__``).

    Args:
        urdf: The robot's URDF.
        srdf: Its SRDF (None: every pair of geometry objects on different
            bodies is checked).
        tip_link: The arm's tip: the movable joints from the root to it are the
            configuration; every other movable joint is locked.
        tool_joints: Positions of locked joints (default 0 clamped; mimics follow).
        objects: Scene objects ``{name, type, size, xyz, quat}`` (quat x y z w).
    """

    def __init__(self, urdf: str | Path, srdf: str | Path | None, tip_link: str,
                 tool_joints: Mapping[str, float] | None = None,
                 objects: Sequence[Mapping[str, Any]] = ()) -> None:
        """Build the reduced model, its geometry and the checked pairs."""
        import pinocchio as pin

        joints = urdf_joints(urdf)
        arm = arm_joint_names(joints, tip_link)
        locked = tool_joint_values(joints, arm, tool_joints or {})
        full = pin.buildModelFromUrdf(str(urdf))
        geom = pin.buildGeomFromUrdf(full, str(urdf), pin.GeometryType.COLLISION)
        q_ref = pin.neutral(full)
        for name, v in locked.items():
            q_ref[full.joints[full.getJointId(name)].idx_q] = v
        lock_ids = [full.getJointId(n) for n in locked]
        self.model, self.geom = pin.buildReducedModel(full, geom, lock_ids, q_ref)
        self.joint_names = tuple(self.model.names[i] for i in range(1, self.model.njoints))
        if list(self.joint_names) != arm:
            raise RuntimeError(f"pinocchio's joints {self.joint_names} are not the arm's {arm}")
        self.lower = np.array([joints[n].lower for n in arm])
        self.upper = np.array([joints[n].upper for n in arm])
        self.geom.addAllCollisionPairs()
        if srdf is not None:
            pin.removeCollisionPairs(self.model, self.geom, str(srdf))
        robot_objects = list(range(len(self.geom.geometryObjects)))
        self.self_pairs = len(self.geom.collisionPairs)
        for obj in objects:
            gid = self.geom.addGeometryObject(pin.GeometryObject(
                str(obj["name"]), 0, 0, _se3(obj["xyz"], obj["quat"]), _coal_shape(obj)))
            for r in robot_objects:
                self.geom.addCollisionPair(pin.CollisionPair(r, gid))
        self.data = self.model.createData()
        self.gdata = pin.GeometryData(self.geom)
        # pinocchio turns on coal's cached GJK guess for every pair; with it,
        # collide() missed 88 of 2100 colliding Panda states (penetrations up to
        # 2 cm, a cylinder against a cylinder) that it finds without the cache
        # (pin 4.1.0, coal 3.0.3; docs/benchmarks.md). Off: no miss, same speed.
        import coal

        with warnings.catch_warnings():  # the flag's setter is deprecated, not the flag
            warnings.simplefilter("ignore", DeprecationWarning)
            for req in self.gdata.collisionRequests:
                req.enable_cached_gjk_guess = False
                req.gjk_initial_guess = coal.GJKInitialGuess.DefaultGuess
        self.tip_frame = self.model.getFrameId(tip_link)
        self.calls = 0

    def tip_pose(self, q: np.ndarray) -> np.ndarray:
        """The tip link's pose (4, 4) at ``q`` by pinocchio's forward kinematics."""
        import pinocchio as pin

        pin.framesForwardKinematics(self.model, self.data, np.asarray(q, dtype=float))
        return self.data.oMf[self.tip_frame].homogeneous.copy()

    def free(self, q: np.ndarray) -> bool:
        """Whether one configuration (n,) is in its limits and collision-free."""
        import pinocchio as pin

        self.calls += 1
        q = np.asarray(q, dtype=float)
        if np.any(q < self.lower - 1e-9) or np.any(q > self.upper + 1e-9):
            return False
        return not pin.computeCollisions(self.model, self.data, self.geom, self.gdata,
                                         q, True)

    def colliding_pair(self, q: np.ndarray) -> tuple[str, str] | None:
        """The first colliding pair's geometry names at ``q``, or None."""
        import pinocchio as pin

        pin.computeCollisions(self.model, self.data, self.geom, self.gdata,
                              np.asarray(q, dtype=float), False)
        for k, res in enumerate(self.gdata.collisionResults):
            if res.isCollision():
                p = self.geom.collisionPairs[k]
                objs = self.geom.geometryObjects
                return objs[p.first].name, objs[p.second].name
        return None


def checker_for(problem: Any, robots: Mapping[str, Any] | None = None) -> PinCoalChecker:
    """The baseline checker of a problem (its robot, SRDF, tool joints and objects)."""
    from plan_problems import ROBOTS

    spec = (robots or ROBOTS)[problem.robot]
    return PinCoalChecker(spec.urdf, spec.srdf, spec.tip_link, spec.tool_joints,
                          problem.objects)


# -------------------------------------------------------------- dense re-check
@dataclass(frozen=True)
class Recheck:
    """The independent check of a path.

    Attributes:
        valid: Every state at most :data:`RESOLUTION` apart along every segment
            is in the limits and collision-free.
        segment: The first bad segment (-1 when valid).
        where: Where along it, in [0, 1] (NaN when valid).
        states: States checked.
        reason: What is wrong ("" when valid).
    """

    valid: bool
    segment: int
    where: float
    states: int
    reason: str


def dense_states(a: np.ndarray, b: np.ndarray, resolution: float = RESOLUTION
                 ) -> np.ndarray:
    """States from a to b (both included), at most ``resolution`` apart (Euclidean)."""
    steps = max(1, math.ceil(float(np.linalg.norm(b - a)) / resolution))
    t = np.linspace(0.0, 1.0, steps + 1)[:, None]
    return a + t * (b - a)


def recheck_path(problem: Any, path: np.ndarray, *, checker: PinCoalChecker | None = None,
                 resolution: float = RESOLUTION, goal: str = "configuration") -> Recheck:
    """Check a path (K, n) densely with pinocchio + coal (no robokin code).

    Also checks that the path starts at the problem's start (1e-9 rad) and ends
    at its goal: the goal configuration (1e-6 rad), or with ``goal="pose"`` any
    configuration whose tip is at the goal pose (1e-6 m and rad, pinocchio's
    forward kinematics).
    """
    chk = checker or checker_for(problem)
    path = np.asarray(path, dtype=float)
    if path.ndim != 2 or len(path) < 1 or path.shape[1] != len(chk.joint_names):
        return Recheck(False, -1, math.nan, 0, f"not a path of shape (K, "
                       f"{len(chk.joint_names)}): {path.shape}")
    if np.max(np.abs(path[0] - np.asarray(problem.start))) > 1e-9:
        return Recheck(False, 0, 0.0, 0, "the path does not begin at the start")
    if goal == "pose":
        T, G = chk.tip_pose(path[-1]), np.asarray(problem.goal_pose)
        dR = T[:3, :3].T @ G[:3, :3]
        # atan2 of the sine and cosine parts: acos of the trace alone loses half the
        # digits near 0 (a 4.6e-13 rotation error read as 1.4e-6 rad)
        sin = 0.5 * float(np.linalg.norm([dR[2, 1] - dR[1, 2], dR[0, 2] - dR[2, 0],
                                          dR[1, 0] - dR[0, 1]]))
        angle = math.atan2(sin, (float(np.trace(dR)) - 1) / 2)
        if np.linalg.norm(T[:3, 3] - G[:3, 3]) > 1e-6 or angle > 1e-6:
            return Recheck(False, len(path) - 1, 1.0, 0, "the path does not end at the "
                           "goal pose")
    elif np.max(np.abs(path[-1] - np.asarray(problem.goal))) > 1e-6:
        return Recheck(False, len(path) - 1, 1.0, 0, "the path does not end at the goal")
    count = 0
    segments = [(path[0], path[0])] + list(zip(path[:-1], path[1:]))
    for i, (a, b) in enumerate(segments):
        states = dense_states(a, b, resolution)
        for k, q in enumerate(states):
            count += 1
            if not chk.free(q):
                pair = chk.colliding_pair(q)
                why = "outside the joint limits" if pair is None else f"{pair[0]} hits {pair[1]}"
                return Recheck(False, max(i - 1, 0), k / max(len(states) - 1, 1),
                               count, why)
    return Recheck(True, -1, math.nan, count, "")


def path_length(path: np.ndarray) -> float:
    """Joint-space length: the sum of the segments' Euclidean norms [rad]."""
    path = np.asarray(path, dtype=float)
    return float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum()) if len(path) > 1 else 0.0


# ------------------------------------------------------------------- planning
@dataclass(frozen=True)
class BaselineResult:
    """One OMPL + pinocchio/coal run.

    Attributes:
        success: An exact solution was found within the time limit.
        q: The simplified path (K, n) (empty when not solved).
        time: Wall-clock time [s]: setup excluded, planning and simplification.
        length: Joint-space length of ``q`` [rad].
        checks: State validity calls.
        plan_time: The planner's part of ``time`` [s].
    """

    success: bool
    q: np.ndarray
    time: float
    length: float
    checks: int
    plan_time: float = math.nan


class Baseline:
    """OMPL RRTConnect + simplification on a :class:`PinCoalChecker` callback.

    Args:
        problem: A :class:`plan_problems.Problem`.
        checker: A checker to reuse (default: one for the problem).
    """

    def __init__(self, problem: Any, checker: PinCoalChecker | None = None) -> None:
        """Set up the checker (not timed)."""
        self.problem = problem
        self.checker = checker or checker_for(problem)

    def plan(self, time_limit: float = 2.0, seed: int = 0) -> BaselineResult:
        """Plan from the problem's start to its goal configuration.

        OMPL checks motions by sampling at ``RESOLUTION`` (its longest valid
        segment), the way MoveIt's OMPL interface does; the simplifier gets the
        time left.
        """
        from ompl import base as ob
        from ompl import geometric as og
        from ompl import util as ou

        ou.setLogLevel(ou.LOG_NONE)
        ou.RNG.setSeed(int(seed) + 1)
        chk = self.checker
        n = len(chk.joint_names)
        space = ob.RealVectorStateSpace(n)
        bounds = ob.RealVectorBounds(n)
        for j in range(n):
            bounds.setLow(j, float(max(chk.lower[j], -2 * math.pi)))
            bounds.setHigh(j, float(min(chk.upper[j], 2 * math.pi)))
        space.setBounds(bounds)
        si = ob.SpaceInformation(space)
        buf = np.zeros(n)

        class Validity(ob.StateValidityChecker):  # type: ignore[misc, name-defined]
            def isValid(self, s: Any) -> bool:  # noqa: N802 - OMPL's name
                for j in range(n):
                    buf[j] = s[j]
                return chk.free(buf)

        validity = Validity(si)
        si.setStateValidityChecker(validity)
        si.setStateValidityCheckingResolution(RESOLUTION / space.getMaximumExtent())
        si.setup()
        start, goal = space.allocState(), space.allocState()
        for j in range(n):
            start[j] = float(self.problem.start[j])
            goal[j] = float(self.problem.goal[j])
        pdef = ob.ProblemDefinition(si)
        pdef.setStartAndGoalStates(start, goal)
        planner = og.RRTConnect(si)
        planner.setProblemDefinition(pdef)
        planner.setup()
        chk.calls = 0
        t0 = time.perf_counter()
        planner.solve(float(time_limit))
        t_plan = time.perf_counter() - t0
        q = np.zeros((0, n))
        solved = pdef.hasExactSolution()
        if solved:
            path = pdef.getSolutionPath()
            left = time_limit - t_plan
            if left > 0:
                og.PathSimplifier(si).simplify(path, left)
            q = np.array([[path.getState(i)[j] for j in range(n)]
                          for i in range(path.getStateCount())])
        elapsed = time.perf_counter() - t0
        return BaselineResult(bool(solved), q, elapsed, path_length(q), chk.calls, t_plan)


# ------------------------------------------------------------------ SRDF maker
def _shaped_ancestor(joints: Mapping[str, UrdfJoint], link: str, shaped: set[str]
                     ) -> str | None:
    by_child = {j.child: j for j in joints.values()}
    while link in by_child:
        link = by_child[link].parent
        if link in shaped:
            return link
    return None


def _rigid_pairs(chk: PinCoalChecker, link_of: Sequence[str],
                 pairs: Mapping[frozenset[str], Any],
                 reasons: dict[frozenset[str], str]) -> None:
    """Links on one body (pinocchio checks no pair there): Always or Never.

    Rigidly attached links are in collision either in every configuration or in
    none, so the Setup Assistant disables them all; coal decides which.
    """
    import coal

    objs = chk.geom.geometryObjects
    for i in range(len(objs)):
        for j in range(i + 1, len(objs)):
            a, b = link_of[i], link_of[j]
            pair = frozenset((a, b))
            if a == b or pair in pairs or objs[i].parentJoint != objs[j].parentJoint:
                continue
            req, res = coal.CollisionRequest(), coal.CollisionResult()
            hit = coal.collide(objs[i].geometry, coal.Transform3s(objs[i].placement),
                               objs[j].geometry, coal.Transform3s(objs[j].placement),
                               req, res)
            if pair not in reasons or (hit and reasons[pair] == "Never"):
                reasons[pair] = "Always" if hit else "Never"


def default_collision_pairs(urdf: str | Path, tip_link: str,
                            tool_joints: Mapping[str, float] | None = None, *,
                            samples: int = 10_000, seed: int = 0
                            ) -> list[tuple[str, str, str]]:
    """The pairs a MoveIt Setup Assistant would disable: ``(link1, link2, reason)``.

    As the Setup Assistant does: ``Adjacent`` (a link and its nearest ancestor
    that has collision geometry), ``Always`` (in collision in more than 95 % of
    ``samples`` random configurations; links on one rigid body: always or never)
    and ``Never`` (never in collision in them). Computed with pinocchio + coal,
    the tool's joints locked. Not the Assistant's ``Default`` rule (in collision
    at the all-zero configuration): on the Panda it would disable the hand
    against link 5, a contact the arm can really make.
    """
    import pinocchio as pin

    chk = PinCoalChecker(urdf, None, tip_link, tool_joints)
    joints = urdf_joints(urdf)
    model, geom = chk.model, chk.geom
    link_of = [model.frames[o.parentFrame].name for o in geom.geometryObjects]
    shaped = set(link_of)
    pairs: dict[frozenset[str], list[int]] = {}
    for k, p in enumerate(geom.collisionPairs):
        a, b = link_of[p.first], link_of[p.second]
        if a != b:
            pairs.setdefault(frozenset((a, b)), []).append(k)
    reasons: dict[frozenset[str], str] = {}
    for link in shaped:
        up = _shaped_ancestor(joints, link, shaped)
        if up is not None:
            reasons[frozenset((link, up))] = "Adjacent"
    _rigid_pairs(chk, link_of, pairs, reasons)
    rng = np.random.default_rng(seed)
    lo = np.maximum(chk.lower, -math.pi)
    hi = np.minimum(chk.upper, math.pi)
    counts = {pair: 0 for pair in pairs}
    for _ in range(samples):
        pin.computeCollisions(model, chk.data, geom, chk.gdata, rng.uniform(lo, hi), False)
        hit = np.array([r.isCollision() for r in chk.gdata.collisionResults])
        for pair, ks in pairs.items():
            counts[pair] += bool(hit[ks].any())
    for pair, c in counts.items():
        if pair in reasons:
            continue
        if c > 0.95 * samples:
            reasons[pair] = "Always"
        elif c == 0:
            reasons[pair] = "Never"
    return sorted((*sorted(p), r) for p, r in reasons.items())  # type: ignore[misc]


def write_srdf(path: Path, robot: str, base_link: str, tip_link: str, flange: str,
               tool_links: Sequence[str], pairs: Sequence[tuple[str, str, str]]) -> None:
    """Write an SRDF: an arm chain, a gripper group and end effector, the pairs."""
    lines = [
        '<?xml version="1.0"?>',
        "<!-- Written by benchmarks/plan_problems.py (option write-srdf) with",
        "     plan_baseline.default_collision_pairs: the MoveIt Setup Assistant's",
        "     Adjacent / Always / Never rules computed with pinocchio + coal, 10 000",
        "     random configurations. -->",
        f'<robot name="{robot}">',
        '  <group name="arm">',
        f'    <chain base_link="{base_link}" tip_link="{tip_link}"/>',
        "  </group>",
        '  <group name="gripper">',
        *[f'    <link name="{link}"/>' for link in tool_links],
        "  </group>",
        f'  <end_effector name="gripper" parent_link="{flange}" group="gripper" '
        'parent_group="arm"/>',
        *[f'  <disable_collisions link1="{a}" link2="{b}" reason="{r}"/>' for a, b, r in pairs],
        "</robot>",
        "",
    ]
    path.write_text("\n".join(lines))


# ------------------------------------------------------------------------ main
def _summary(times: list[float], ok: list[bool]) -> str:
    solved = [t for t, s in zip(times, ok) if s]
    if not solved:
        return f"0/{len(ok)} solved"
    p95 = float(np.percentile(solved, 95))
    return (f"{len(solved)}/{len(ok)} solved, median {statistics.median(solved):.3f} s, "
            f"p95 {p95:.3f} s")


def main(argv: Sequence[str] | None = None) -> None:
    """Time the baseline on the problem set (a few problems per family)."""
    from plan_problems import load_problems

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--per-family", type=int, default=5)
    ap.add_argument("--time-limit", type=float, default=2.0)
    ap.add_argument("--robot", default=None)
    args = ap.parse_args(argv)
    problems = load_problems()
    by_family: dict[tuple[str, str], list[Any]] = {}
    for p in problems:
        if args.robot is None or p.robot == args.robot:
            by_family.setdefault((p.robot, p.family), []).append(p)
    for key, items in by_family.items():
        times, ok, per_check = [], [], []
        for p in items[: args.per_family]:
            base = Baseline(p)
            res = base.plan(args.time_limit, seed=0)
            times.append(res.time)
            ok.append(res.success)
            per_check.append(res.time / max(res.checks, 1))
            if res.success:
                rc = recheck_path(p, res.q, checker=base.checker)
                if not rc.valid:
                    print(f"  {p.id}: baseline path fails its own re-check: {rc.reason}")
        print(f"{key[0]:12s} {key[1]:18s} {_summary(times, ok)}, "
              f"{1e6 * statistics.median(per_check):.0f} us per state check")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
