"""The planning benchmark's problem set, in the spirit of MotionBenchMaker (issue 26).

Seven scene families, written here (not MotionBenchMaker's code or data; the
families follow its paper: Chamzas et al., "MotionBenchMaker: A Tool to Generate
and Benchmark Motion Planning Datasets", IEEE RA-L 7(2), 2022): ``table_pick``,
``table_under_pick``, ``box``, ``bookshelf_small``, ``bookshelf_tall``,
``bookshelf_thin`` and ``cage``; for two robots, each given as MoveIt users have
them (a URDF and an SRDF in ``benchmarks/data/``):

* ``ur5_gripper``: a UR5 with a Robotiq-like two-finger gripper hung below its
  flange (fingers frozen open), tip ``grasp_tcp``;
* ``panda``: the Franka Panda with its hand (fingers open at 0.04 m), tip
  ``panda_hand_tcp``.

Every problem has its own scene: the family's furniture placed at a random
distance and angle around the robot, its objects at random places; a start and a
goal configuration, both in the limits and collision-free (at least
:data:`CLEARANCE` from everything by robokin's check, and free by the
pinocchio + coal baseline's): the goal reaches a grasp of a target object (a side
or top grasp, its approach and yaw drawn at random) by one IK solution drawn
from every collision-free branch, the start a grasp of another object (or, one
time in four, a random free configuration). 100 problems per family and robot,
from one seed: ``python benchmarks/plan_problems.py`` writes
``benchmarks/data/plan_problems.json.gz`` (committed: the set stays fixed while
robokin changes); :func:`load_problems` reads it.

Objects are boxes, cylinders and spheres placed by ``xyz`` and a quaternion
``quat`` (x, y, z, w), as in a MoveIt planning scene;
:meth:`Problem.scene` builds the robokin scene and :meth:`Problem.moveit_scene`
the MoveIt ``.scene`` text of the same objects.
"""

from __future__ import annotations

import argparse
import gzip
import json
import math
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

HERE = Path(__file__).resolve().parent
DATA = HERE / "data"
#: The committed problem set.
PROBLEMS_FILE = DATA / "plan_problems.json.gz"
#: Smallest distance [m] of a start or goal to anything (robokin's check).
CLEARANCE = 0.002
FAMILIES = ("table_pick", "table_under_pick", "box", "bookshelf_small",
            "bookshelf_tall", "bookshelf_thin", "cage")


@dataclass(frozen=True)
class RobotSpec:
    """A benchmark robot as MoveIt users have it.

    Attributes:
        name: Its name in the problem set.
        urdf: The URDF.
        srdf: The SRDF (its disabled pairs; written by :func:`write_srdfs`).
        tip_link: The planning tip (the TCP between the fingers).
        flange: The link the gripper hangs on (the SRDF's end effector parent).
        tool_joints: Positions of the gripper's joints (fingers open).
        tool_links: The gripper's links (the SRDF's gripper group).
        closing: The TCP axis the fingers close along (``"x"`` or ``"y"``).
    """

    name: str
    urdf: Path
    srdf: Path
    tip_link: str
    flange: str
    tool_joints: Mapping[str, float]
    tool_links: tuple[str, ...]
    closing: str

    def robot(self) -> Any:
        """The robokin robot: URDF + SRDF, the gripper's tree in the tool."""
        import robokin

        return robokin.Robot.from_urdf(self.urdf, tip_link=self.tip_link, srdf=self.srdf,
                                       tool_joints=dict(self.tool_joints))


ROBOTS: dict[str, RobotSpec] = {
    "ur5_gripper": RobotSpec(
        "ur5_gripper", DATA / "ur5_gripper.urdf", DATA / "ur5_gripper.srdf",
        "grasp_tcp", "tool0", {"finger_joint": 0.0},
        ("gripper_base_link", "left_knuckle", "left_fingertip", "right_knuckle",
         "right_fingertip"), "x"),
    "panda": RobotSpec(
        "panda", DATA / "panda_hand.urdf", DATA / "panda_hand.srdf",
        "panda_hand_tcp", "panda_link8", {"panda_finger_joint1": 0.04},
        ("panda_hand", "panda_leftfinger", "panda_rightfinger"), "y"),
}


# ------------------------------------------------------------------ problems
@dataclass(frozen=True)
class Problem:
    """One planning problem.

    Attributes:
        id: ``robot/family/NNN``.
        robot: A key of :data:`ROBOTS`.
        family: One of :data:`FAMILIES`.
        objects: The scene: ``{name, type, size, xyz, quat}`` each (size: a
            box's full sizes, a cylinder's radius and length, a sphere's radius
            [m]; quat x y z w), in the robot's base frame.
        start: Start configuration (n,) [rad].
        goal: Goal configuration (n,) [rad] (one IK branch of ``goal_pose``).
        goal_pose: The grasp: the TCP pose (4, 4) in the robot's base frame.
        target: The object grasped at the goal.
    """

    id: str
    robot: str
    family: str
    objects: tuple[dict[str, Any], ...]
    start: np.ndarray
    goal: np.ndarray
    goal_pose: np.ndarray
    target: str
    extra: dict[str, Any] = field(default_factory=dict)

    def scene(self) -> Any:
        """The robokin scene of the objects."""
        return scene_from_objects(self.objects, name=self.id)

    def moveit_scene(self) -> str:
        """The objects as a MoveIt ``.scene`` text (``saveGeometryToStream``'s format)."""
        out = [self.id]
        for obj in self.objects:
            dims = " ".join(f"{v:.9g}" for v in obj["size"])
            out += [f"* {obj['name']}", " ".join(f"{v:.9g}" for v in obj["xyz"]),
                    " ".join(f"{v:.9g}" for v in obj["quat"]), "1", obj["type"], dims,
                    "0 0 0", "0 0 0 1", "0 0 0 0", "0"]
        out.append(".")
        return "\n".join(out) + "\n"


def object_pose(obj: Mapping[str, Any]) -> np.ndarray:
    """An object's pose (4, 4) from its ``xyz`` and ``quat`` (x, y, z, w)."""
    T = np.eye(4)
    T[:3, :3] = Rotation.from_quat(obj["quat"]).as_matrix()
    T[:3, 3] = obj["xyz"]
    return T


def scene_from_objects(objects: Sequence[Mapping[str, Any]], name: str = "scene") -> Any:
    """A robokin :class:`~robokin.collision.Scene` of problem objects."""
    from robokin import collision

    scene = collision.Scene(name)
    for obj in objects:
        T, s = object_pose(obj), obj["size"]
        if obj["type"] == "box":
            scene.add_box(obj["name"], s, T)
        elif obj["type"] == "cylinder":
            scene.add_cylinder(obj["name"], s[0], s[1], T)
        else:
            scene.add_sphere(obj["name"], s[0], T)
    return scene


def load_problems(path: str | Path = PROBLEMS_FILE, *, robot: str | None = None,
                  family: str | None = None) -> list[Problem]:
    """Read the problem set (optionally one robot's or one family's problems)."""
    with gzip.open(path, "rt") as fh:
        doc = json.load(fh)
    out = []
    for p in doc["problems"]:
        if (robot is None or p["robot"] == robot) and (family is None or p["family"] == family):
            out.append(Problem(p["id"], p["robot"], p["family"], tuple(p["objects"]),
                               np.array(p["start"]), np.array(p["goal"]),
                               np.array(p["goal_pose"]), p["target"], p.get("extra", {})))
    return out


# ------------------------------------------------------------- scene families
def _box(name: str, size: Sequence[float], xyz: Sequence[float], yaw: float = 0.0
         ) -> dict[str, Any]:
    return {"name": name, "type": "box", "size": [float(v) for v in size],
            "xyz": [float(v) for v in xyz],
            "quat": Rotation.from_euler("z", yaw).as_quat().tolist()}


def _cylinder(name: str, r: float, h: float, xyz: Sequence[float]) -> dict[str, Any]:
    return {"name": name, "type": "cylinder", "size": [float(r), float(h)],
            "xyz": [float(v) for v in xyz], "quat": [0.0, 0.0, 0.0, 1.0]}


def _place(objects: list[dict[str, Any]], T: np.ndarray) -> list[dict[str, Any]]:
    """Objects built in a local frame, moved by ``T`` (4, 4)."""
    out = []
    for obj in objects:
        P = T @ object_pose(obj)
        out.append({**obj, "xyz": P[:3, 3].tolist(),
                    "quat": Rotation.from_matrix(P[:3, :3]).as_quat().tolist()})
    return out


def _frame(rng: np.random.Generator, dist: tuple[float, float], angle: float,
           z: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
    """A local scene frame at a random distance and bearing, facing the robot (its +x away)."""
    d, a = rng.uniform(*dist), rng.uniform(-angle, angle)
    yaw = a + rng.uniform(-0.15, 0.15)
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("z", yaw).as_matrix()
    T[:3, 3] = [d * math.cos(a), d * math.sin(a), rng.uniform(*z)]
    return T


def _scatter(rng: np.random.Generator, n: int, x: tuple[float, float],
             y: tuple[float, float], gap: float) -> list[tuple[float, float]]:
    """Up to n points in a rectangle at least ``gap`` apart."""
    pts: list[tuple[float, float]] = []
    for _ in range(50 * n):
        p = (rng.uniform(*x), rng.uniform(*y))
        if all(math.hypot(p[0] - q[0], p[1] - q[1]) >= gap for q in pts):
            pts.append(p)
            if len(pts) == n:
                break
    return pts


Targets = list[tuple[str, str]]  # (object name, grasp kind: "side" | "top" | "any")


def _items(rng: np.random.Generator, prefix: str, spots: Sequence[tuple[float, float]],
           z: float) -> tuple[list[dict[str, Any]], Targets]:
    """Cylinders (graspable) and small boxes standing on a surface at height z."""
    objs, targets = [], []
    for i, (x, y) in enumerate(spots):
        name = f"{prefix}{i}"
        if rng.uniform() < 0.75:
            r, h = rng.uniform(0.018, 0.026), rng.uniform(0.08, 0.16)
            objs.append(_cylinder(name, r, h, (x, y, z + h / 2)))
            targets.append((name, "any"))
        else:
            s = rng.uniform(0.04, 0.07, 3)
            objs.append(_box(name, s, (x, y, z + s[2] / 2), rng.uniform(-1, 1)))
    return objs, targets


def table_pick(rng: np.random.Generator) -> tuple[list[dict[str, Any]], Targets]:
    """A table in front of the robot, its top at about base height, objects on it."""
    T = _frame(rng, (0.62, 0.68), 0.35, (-0.04, 0.04))
    top = [_box("table_top", (0.6, 1.1, 0.04), (0, 0, -0.02))]
    legs = [_box(f"table_leg{i}", (0.05, 0.05, 0.7), (sx * 0.26, sy * 0.5, -0.39))
            for i, (sx, sy) in enumerate([(-1, -1), (-1, 1), (1, -1), (1, 1)])]
    items, targets = _items(rng, "item", _scatter(rng, 7, (-0.2, 0.2), (-0.45, 0.45), 0.13),
                            0.0)
    return _place(top + legs + items, T), targets


def table_under_pick(rng: np.random.Generator) -> tuple[list[dict[str, Any]], Targets]:
    """Objects under a table, on a board at base height: reached under the top."""
    T = _frame(rng, (0.6, 0.68), 0.3)
    h = rng.uniform(0.36, 0.42)
    parts = [_box("table_top", (0.6, 1.1, 0.04), (0, 0, h - 0.02)),
             _box("floor_board", (0.6, 1.1, 0.02), (0, 0, -0.01))]
    parts += [_box(f"table_leg{i}", (0.05, 0.05, h - 0.04), (sx * 0.26, sy * 0.5, h / 2 - 0.02))
              for i, (sx, sy) in enumerate([(-1, -1), (-1, 1), (1, -1), (1, 1)])]
    parts += _items(rng, "top_item", _scatter(rng, 4, (-0.2, 0.2), (-0.45, 0.45), 0.15), h)[0]
    items, targets = _items(rng, "item", _scatter(rng, 4, (-0.18, 0.1), (-0.35, 0.35), 0.15),
                            0.0)
    return _place(parts + items, T), [(n, "side") for n, _ in targets]


def box(rng: np.random.Generator) -> tuple[list[dict[str, Any]], Targets]:
    """An open box on a table; objects inside, picked from above."""
    T = _frame(rng, (0.55, 0.62), 0.35, (-0.03, 0.03))
    w, d, h, t = rng.uniform(0.36, 0.42), rng.uniform(0.42, 0.5), rng.uniform(0.14, 0.2), 0.012
    parts = [_box("table_top", (0.6, 1.1, 0.04), (0, 0, -0.02)),
             _box("box_bottom", (w, d, t), (0, 0, t / 2)),
             _box("box_front", (t, d, h), (-w / 2 + t / 2, 0, h / 2)),
             _box("box_back", (t, d, h), (w / 2 - t / 2, 0, h / 2)),
             _box("box_left", (w, t, h), (0, d / 2 - t / 2, h / 2)),
             _box("box_right", (w, t, h), (0, -d / 2 + t / 2, h / 2))]
    spots = _scatter(rng, 4, (-w / 2 + 0.07, w / 2 - 0.07), (-d / 2 + 0.07, d / 2 - 0.07), 0.11)
    items, targets = _items(rng, "item", spots, t)
    return _place(parts + items, T), [(n, "top") for n, _ in targets]


def _bookshelf(rng: np.random.Generator, levels: int, spacing: tuple[float, float],
               bottom: tuple[float, float], board: float, depth: float
               ) -> tuple[list[dict[str, Any]], Targets]:
    T = _frame(rng, (0.62, 0.7), 0.4)
    width = rng.uniform(0.8, 0.95)
    gap = rng.uniform(*spacing)
    z0 = rng.uniform(*bottom)
    height = z0 + levels * gap + board
    parts = [_box("shelf_side_left", (depth, board, height), (0, width / 2, height / 2)),
             _box("shelf_side_right", (depth, board, height), (0, -width / 2, height / 2)),
             _box("shelf_back", (board, width, height), (depth / 2, 0, height / 2))]
    targets: Targets = []
    items: list[dict[str, Any]] = []
    for k in range(levels + 1):
        z = z0 + k * gap
        parts.append(_box(f"shelf_board{k}", (depth, width, board), (0, 0, z + board / 2)))
        if k < levels:
            spots = _scatter(rng, 3, (-depth / 2 + 0.06, depth / 2 - 0.1),
                             (-width / 2 + 0.08, width / 2 - 0.08), 0.16)
            objs, tg = _items(rng, f"level{k}_item", spots, z + board)
            objs = [o for o in objs if o["type"] != "cylinder"
                    or z + board + o["size"][1] < z + gap - 0.02]
            items += objs
            names = {o["name"] for o in objs}
            targets += [(n, "side") for n, _ in tg if n in names]
    return _place(parts + items, T), targets


def bookshelf_small(rng: np.random.Generator) -> tuple[list[dict[str, Any]], Targets]:
    """A low two-level shelf."""
    return _bookshelf(rng, 2, (0.3, 0.36), (0.0, 0.12), 0.02, 0.36)


def bookshelf_tall(rng: np.random.Generator) -> tuple[list[dict[str, Any]], Targets]:
    """A tall shelf, four levels from the floor up past the shoulder."""
    return _bookshelf(rng, 4, (0.28, 0.32), (-0.05, 0.05), 0.02, 0.36)


def bookshelf_thin(rng: np.random.Generator) -> tuple[list[dict[str, Any]], Targets]:
    """A shelf of thin, closely spaced levels."""
    return _bookshelf(rng, 4, (0.22, 0.25), (0.0, 0.1), 0.012, 0.3)


def cage(rng: np.random.Generator) -> tuple[list[dict[str, Any]], Targets]:
    """An object in a cage of bars on a table, reached through the open front."""
    T = _frame(rng, (0.55, 0.62), 0.35, (-0.03, 0.03))
    s, h, b = rng.uniform(0.34, 0.4), rng.uniform(0.3, 0.36), 0.02
    parts = [_box("table_top", (0.6, 1.1, 0.04), (0, 0, -0.02))]
    corners = [(-1, -1), (-1, 1), (1, -1), (1, 1)]
    parts += [_box(f"cage_post{i}", (b, b, h), (sx * s / 2, sy * s / 2, h / 2))
              for i, (sx, sy) in enumerate(corners)]
    parts += [_box("cage_top_front", (b, s, b), (-s / 2, 0, h)),
              _box("cage_top_back", (b, s, b), (s / 2, 0, h)),
              _box("cage_top_left", (s, b, b), (0, s / 2, h)),
              _box("cage_top_right", (s, b, b), (0, -s / 2, h)),
              _box("cage_top_cross", (b, s, b), (0, 0, h))]
    for side, y in (("left", s / 2), ("right", -s / 2)):
        parts += [_box(f"cage_{side}_bar{k}", (s, b, b), (0, y, z))
                  for k, z in enumerate((h / 3, 2 * h / 3))]
    parts += [_box(f"cage_back_bar{k}", (b, s, b), (s / 2, 0, z))
              for k, z in enumerate((h / 3, 2 * h / 3))]
    items, targets = _items(rng, "item", [(rng.uniform(-0.06, 0.04), rng.uniform(-0.05, 0.05))],
                            0.0)
    if not targets:  # the one object must be graspable
        items, targets = [_cylinder("item0", 0.022, 0.12, (0, 0, 0.06))], [("item0", "side")]
    outside = _items(rng, "outside", [(0.0, sy * (s / 2 + 0.18)) for sy in (-1, 1)], 0.0)
    return _place(parts + items + outside[0], T), [(n, "side") for n, _ in targets] + \
        [(n, "any") for n, _ in outside[1]]


FAMILY_BUILDERS: dict[str, Callable[[np.random.Generator], tuple[list[dict[str, Any]], Targets]]] = {
    "table_pick": table_pick, "table_under_pick": table_under_pick, "box": box,
    "bookshelf_small": bookshelf_small, "bookshelf_tall": bookshelf_tall,
    "bookshelf_thin": bookshelf_thin, "cage": cage,
}


# --------------------------------------------------------------------- grasps
def grasp_pose(rng: np.random.Generator, obj: Mapping[str, Any], kind: str,
               closing: str) -> np.ndarray:
    """A TCP pose grasping an upright object: a side grasp (approach horizontal,
    roughly from the robot) or a top grasp (approach down, tilted up to 0.3 rad)."""
    c = np.asarray(obj["xyz"], dtype=float)
    if kind == "any":
        kind = "side" if rng.uniform() < 0.6 else "top"
    if kind == "side":
        bearing = math.atan2(c[1], c[0]) + rng.uniform(-0.5, 0.5)
        a = np.array([math.cos(bearing), math.sin(bearing), rng.uniform(-0.15, 0.15)])
        c = c + np.array([0, 0, rng.uniform(-0.2, 0.2) * obj["size"][-1] / 2])
    else:
        tilt = Rotation.from_rotvec(rng.uniform(-0.3, 0.3, 3) * [1, 1, 0]).as_matrix()
        a = tilt @ np.array([0.0, 0.0, -1.0])
        top = c[2] + (obj["size"][1] / 2 if obj["type"] == "cylinder" else 0.0)
        c = np.array([c[0], c[1], top - 0.03])
    a /= np.linalg.norm(a)
    helper = np.array([0.0, 0.0, 1.0]) if abs(a[2]) < 0.9 else \
        np.array([math.cos(rng.uniform(0, 2 * math.pi)), math.sin(rng.uniform(0, 2 * math.pi)), 0])
    close = np.cross(helper, a)
    close /= np.linalg.norm(close)
    if rng.uniform() < 0.5:
        close = -close
    R = np.eye(3)
    if closing == "x":
        R[:, 0], R[:, 2] = close, a
        R[:, 1] = np.cross(a, close)
    else:
        R[:, 1], R[:, 2] = close, a
        R[:, 0] = np.cross(close, a)
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, c
    return T


# ------------------------------------------------------------------ generation
class _Validity:
    """A start or goal must pass robokin's check (with clearance) and the baseline's."""

    def __init__(self, spec: RobotSpec, robot: Any, objects: list[dict[str, Any]]) -> None:
        from plan_baseline import PinCoalChecker

        self.robot = robot
        self.scene = scene_from_objects(objects)
        self.base = PinCoalChecker(spec.urdf, spec.srdf, spec.tip_link, spec.tool_joints,
                                   objects)

    def ok(self, q: np.ndarray) -> bool:
        from robokin import collision

        if not self.base.free(q):
            return False
        rep = collision.check(self.robot, self.scene, q[None], subdivide=False)
        return (not rep.collides) and rep.min_distance >= CLEARANCE


def _ik_choice(rng: np.random.Generator, robot: Any, T: np.ndarray, valid: _Validity
               ) -> np.ndarray | None:
    """One collision-free IK solution of T, drawn at random among all branches."""
    sols: list[np.ndarray] = []
    if robot.n == 7:
        for v in rng.uniform(robot.limits[6, 0], robot.limits[6, 1], 4):
            sols += list(robot.ik(T, fixed={robot.joint_names[6]: float(v)}))
    else:
        sols = list(robot.ik(T))
    lim = robot.limits
    sols = [q for q in sols if np.all(q >= lim[:, 0]) and np.all(q <= lim[:, 1])]
    for i in rng.permutation(len(sols)):
        if valid.ok(sols[i]):
            return np.asarray(sols[i], dtype=float)
    return None


def _random_free(rng: np.random.Generator, robot: Any, valid: _Validity) -> np.ndarray | None:
    lim = np.clip(robot.limits, -math.pi, math.pi)
    for _ in range(200):
        q = rng.uniform(lim[:, 0], lim[:, 1])
        if valid.ok(q):
            return q
    return None


def make_problem(rng: np.random.Generator, spec: RobotSpec, robot: Any, family: str,
                 index: int, attempts: int = 40) -> Problem:
    """One problem: a perturbed scene with a reachable grasp goal and a free start."""
    for _ in range(attempts):
        objects, targets = FAMILY_BUILDERS[family](rng)
        if not targets:
            continue
        valid = _Validity(spec, robot, objects)
        by_name = {o["name"]: o for o in objects}
        order = rng.permutation(len(targets))
        goal = None
        for i in order[:4]:
            name, kind = targets[i]
            T = grasp_pose(rng, by_name[name], kind, spec.closing)
            q = _ik_choice(rng, robot, T, valid)
            if q is not None:
                goal, goal_pose, target = q, T, name
                break
        if goal is None:
            continue
        start = None
        others = [t for t in targets if t[0] != target]
        if others and rng.uniform() < 0.75:
            for i in rng.permutation(len(others))[:4]:
                name, kind = others[i]
                q = _ik_choice(rng, robot, grasp_pose(rng, by_name[name], kind, spec.closing),
                               valid)
                if q is not None and np.linalg.norm(q - goal) > 0.5:
                    start = q
                    break
        if start is None:
            start = _random_free(rng, robot, valid)
        if start is None or np.linalg.norm(start - goal) < 0.5:
            continue
        return Problem(f"{spec.name}/{family}/{index:03d}", spec.name, family,
                       tuple(objects), start, goal, goal_pose, target)
    raise RuntimeError(f"no valid {family} problem for {spec.name} in {attempts} scenes")


def generate(per_family: int = 100, seed: int = 0, robots: Sequence[str] = tuple(ROBOTS),
             families: Sequence[str] = FAMILIES, progress: bool = True) -> list[Problem]:
    """The problem set: ``per_family`` problems per family and robot, from ``seed``.

    Each (robot, family) draws from its own generator (``seed``, robot and
    family index), so a subset regenerates identically.
    """
    out = []
    for ri, rname in enumerate(ROBOTS):
        if rname not in robots:
            continue
        spec = ROBOTS[rname]
        robot = spec.robot()
        for fi, family in enumerate(FAMILIES):
            if family not in families:
                continue
            rng = np.random.default_rng([seed, ri, fi])
            t0 = time.perf_counter()
            for k in range(per_family):
                out.append(make_problem(rng, spec, robot, family, k))
            if progress:
                print(f"{rname:12s} {family:18s} {per_family} problems in "
                      f"{time.perf_counter() - t0:.1f} s", file=sys.stderr)
    return out


def _rounded(a: Any, digits: int = 9) -> Any:
    return np.round(np.asarray(a, dtype=float), digits).tolist()


def save_problems(problems: Sequence[Problem], path: str | Path = PROBLEMS_FILE,
                  seed: int = 0) -> None:
    """Write the set (gzip-compressed JSON); positions rounded to 1e-9."""
    doc = {
        "format": "robokin planning problems 1",
        "generator": "benchmarks/plan_problems.py",
        "seed": seed,
        "robots": {k: {"urdf": str(v.urdf.relative_to(HERE)), "srdf": str(v.srdf.relative_to(HERE)),
                       "tip_link": v.tip_link, "tool_joints": dict(v.tool_joints)}
                   for k, v in ROBOTS.items()},
        "problems": [
            {"id": p.id, "robot": p.robot, "family": p.family, "target": p.target,
             "objects": [{**o, "size": _rounded(o["size"]), "xyz": _rounded(o["xyz"]),
                          "quat": _rounded(o["quat"])} for o in p.objects],
             "start": p.start.tolist(), "goal": p.goal.tolist(),
             "goal_pose": _rounded(p.goal_pose, 12)}
            for p in problems
        ],
    }
    with gzip.GzipFile(path, "wb", mtime=0) as fh:
        fh.write(json.dumps(doc, separators=(",", ":")).encode())


def write_srdfs(samples: int = 10_000) -> None:
    """(Re)write each robot's SRDF with the Setup Assistant's rules (pinocchio + coal)."""
    from plan_baseline import default_collision_pairs, urdf_joints, write_srdf

    for spec in ROBOTS.values():
        pairs = default_collision_pairs(spec.urdf, spec.tip_link, spec.tool_joints,
                                        samples=samples)
        joints = urdf_joints(spec.urdf).values()
        root = next(iter({j.parent for j in joints} - {j.child for j in joints}))
        write_srdf(spec.srdf, _robot_name(spec.urdf), root, spec.tip_link, spec.flange,
                   spec.tool_links, pairs)
        print(f"{spec.srdf.name}: {len(pairs)} disabled pairs", file=sys.stderr)


def _robot_name(urdf: Path) -> str:
    import xml.etree.ElementTree as ET

    return ET.parse(urdf).getroot().get("name", "")


def main(argv: Sequence[str] | None = None) -> None:
    """Generate the problem set (and, with --write-srdf, the robots' SRDFs)."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--per-family", type=int, default=100)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", type=Path, default=PROBLEMS_FILE)
    ap.add_argument("--robot", action="append", choices=list(ROBOTS))
    ap.add_argument("--family", action="append", choices=list(FAMILIES))
    ap.add_argument("--write-srdf", action="store_true",
                    help="rewrite benchmarks/data/*.srdf first")
    ap.add_argument("--scenes", type=Path, default=None,
                    help="also write each problem's scene as a MoveIt .scene file here")
    args = ap.parse_args(argv)
    if args.write_srdf:
        write_srdfs()
    problems = generate(args.per_family, args.seed, args.robot or tuple(ROBOTS),
                        args.family or FAMILIES)
    save_problems(problems, args.out, args.seed)
    print(f"{len(problems)} problems -> {args.out}", file=sys.stderr)
    if args.scenes is not None:
        args.scenes.mkdir(parents=True, exist_ok=True)
        for p in problems:
            (args.scenes / (p.id.replace("/", "_") + ".scene")).write_text(p.moveit_scene())


if __name__ == "__main__":
    main()
