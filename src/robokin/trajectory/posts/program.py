r"""Programs for real controllers from sampled trajectories, joint paths and process paths.

:func:`write_program` is the one entry point (``robokin traj --program DIALECT`` and
``robokin follow`` call it): it turns a motion into a :class:`ProgramJob` in the
controller's units and convention, has the dialect's post processor render it, and
writes the files atomically, all or none.

What becomes of each kind of motion:

- a sampled joint trajectory (:class:`~robokin.trajectory.samples.Trajectory`):
  joint moves through a subset of its samples: every ``stride``-th (and the last),
  or by default the samples Douglas-Peucker keeps so that every sample lies within
  ``tolerance`` [rad] (per joint) of the joint-space polyline through them
  (:func:`decimate`; the via points are always kept). A controller's synchronous
  joint move (PTP, MoveAbsJ, J, MOVJ, movej) is a straight line in joint space, so
  its path passes within ``tolerance`` of every planned sample where the points are
  reached exactly (its timing is the controller's); with blending, corners are cut
  by the zone. Each move's speed is the fraction of
  the joints' rate limits the trajectory uses on that stretch (robots with rate
  limits), else ``joint_speed``;
- a process path (the result of :func:`robokin.process.follow`: ``.q`` (N, n),
  ``.feasible``): a joint move to the first configuration, then linear moves through
  the TCP poses of the others (``robot.fk(q)``, so a free tool angle is included)
  with each one's configuration flags, at ``speed``, blended by ``zone`` except at
  the end;
- a point set (the result of :func:`robokin.process.order`: ``.order``, ``.q``) or a
  plain (N, n) array of configurations: a joint move to each, stopping exactly at
  each point of a point set.

Frames: the Cartesian targets are TCP poses in the base (work-object) frame: the
world frame unless ``work_object`` (its world pose) is given. The programs declare
the tool (the TCP in the controller's flange frame) and the base frame (in the
controller's robot root frame), from the robot's tool and base transforms and the
``root`` / ``flange`` frames of the robot file's ``controller:`` section
(docs/controllers.md).
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypedDict

import numpy as np
import numpy.typing as npt
from typing_extensions import Unpack

from robokin._text import short_repr
from robokin.exceptions import InputError, ModelError
from robokin.io.atomic import staged_outputs
from robokin.spatial import invert
from robokin.trajectory.controllers import controller_profile
from robokin.trajectory.posts.arm_config import arm_configuration
from robokin.trajectory.posts.base import (
    Move,
    MoveKind,
    PostProcessor,
    ProgramJob,
    Target,
    euler_deg,
    quaternion_wxyz,
)
from robokin.trajectory.posts.registry import get_post, post_names
from robokin.trajectory.samples import Trajectory

if TYPE_CHECKING:
    from robokin.robot import Robot
    from robokin.trajectory.io import ControllerProfile

__all__ = ["Program", "chord_deviation", "decimate", "program_job", "render_program",
           "write_program"]

_JOINT: MoveKind = "joint"
_LINEAR: MoveKind = "linear"
#: Configuration flags closer than this to their boundary get a note [m, rad, deg].
_NEAR_SHOULDER, _NEAR_ELBOW, _NEAR_WRIST = 1e-3, 1e-3, 1e-2


@dataclass(frozen=True)
class Program:
    """A rendered (and possibly written) controller program.

    Attributes:
        dialect: The post processor's name (``"kuka_krl"``).
        title: Its language, for people (``"KUKA KRL"``).
        name: The program name as written.
        texts: ``{relative file name: text}``.
        moves: How many motion statements it holds.
        description: What it holds (one line).
        notes: Remarks (also written as comments in the program).
        files: The files written (empty until written).
    """

    dialect: str
    title: str
    name: str
    texts: Mapping[str, str]
    moves: int
    description: str
    notes: tuple[str, ...] = ()
    files: tuple[Path, ...] = field(default=())

    def describe(self) -> str:
        """One line for a terminal summary."""
        return f"{self.title} program {self.name}: {self.description}"


# ------------------------------------------------------------------ decimation
def decimate(q: npt.ArrayLike, tolerance: float, keep: Sequence[int] = ()) -> np.ndarray:
    """Indices of samples whose polyline passes within ``tolerance`` of every sample.

    Douglas-Peucker on the joint-space polyline: a sample is kept when it is
    farther than ``tolerance`` from the chord between the kept samples around it,
    its distance measured to the nearest point of the chord (Euclidean projection)
    and taken per joint (max-norm): every sample of the plan lies within
    ``tolerance``, joint by joint, of a point of the controller's joint path. The
    first and last samples and ``keep`` are always kept.

    Args:
        q: Samples (m, n) [rad, m].
        tolerance: Largest deviation allowed [rad, m], >= 0.
        keep: Indices kept regardless (e.g. the via points).

    Returns:
        Sorted indices (k,).

    Raises:
        InputError: a negative or non-finite tolerance.
    """
    q = np.asarray(q, dtype=np.float64)
    if not (math.isfinite(tolerance) and tolerance >= 0.0):
        raise InputError("tolerance", f"expected a deviation >= 0, got {tolerance}")
    m = len(q)
    if m <= 2:
        return np.arange(m)
    anchors = sorted({0, m - 1, *(int(k) for k in keep if 0 <= int(k) < m)})
    chosen = set(anchors)
    stack = list(zip(anchors[:-1], anchors[1:]))
    while stack:
        a, b = stack.pop()
        if b - a < 2:
            continue
        dev = chord_deviation(q[a:b + 1])[1:-1]
        k = int(np.argmax(dev))
        if dev[k] > tolerance:
            mid = a + 1 + k
            chosen.add(mid)
            stack += [(a, mid), (mid, b)]
    return np.array(sorted(chosen))


def chord_deviation(q: npt.ArrayLike) -> np.ndarray:
    """Per sample, the max-norm distance to the nearest point of the first-last chord.

    Args:
        q: Samples (m, n); the chord runs from ``q[0]`` to ``q[-1]``.

    Returns:
        (m,) distances [rad, m] (0 at both ends).
    """
    q = np.asarray(q, dtype=np.float64)
    d = q[-1] - q[0]
    dd = float(d @ d)
    s = np.zeros(len(q)) if dd == 0.0 else np.clip((q - q[0]) @ d / dd, 0.0, 1.0)
    return np.abs(q - (q[0] + s[:, None] * d)).max(axis=1)


def _stride_indices(m: int, stride: int) -> np.ndarray:
    if isinstance(stride, bool) or not isinstance(stride, (int, np.integer)) or stride < 1:
        raise InputError("stride", f"expected a whole number >= 1, got {short_repr(stride)}")
    idx = np.arange(0, m, int(stride))
    return idx if idx[-1] == m - 1 else np.append(idx, m - 1)


# ------------------------------------------------------------------ the motion
@dataclass(frozen=True)
class _Plan:
    """What a motion becomes before the targets are computed."""

    q: np.ndarray                # (k, n) configurations, model SI
    kinds: tuple[MoveKind, ...]  # per configuration
    speeds: np.ndarray       # (k,) joint fraction or TCP speed [mm/s]
    zones: np.ndarray        # (k,) [mm]
    description: str
    notes: tuple[str, ...] = ()


def _joint_speeds(robot: Robot, traj: Trajectory, idx: np.ndarray,
                  joint_speed: float) -> tuple[np.ndarray, str]:
    """The fraction of the rate limits each stretch uses (or the constant)."""
    vel = None if robot.rate_limits is None else robot.rate_limits.velocity
    speeds = np.full(len(idx), joint_speed)
    if vel is None or not np.isfinite(vel).all() or len(idx) < 2:
        return speeds, f"joint moves at {100 * joint_speed:g} % of the axes' speed"
    dq = np.abs(np.diff(traj.q[idx], axis=0))
    dt = np.maximum(np.diff(traj.t[idx]), 1e-12)
    frac = (dq / dt[:, None] / vel).max(axis=1)
    speeds[1:] = np.clip(np.ceil(frac * 100.0) / 100.0, 0.01, 1.0)
    return speeds, ("joint speeds: the share of the rate limits the trajectory uses "
                    "on each stretch")


def _trajectory_plan(robot: Robot, traj: Trajectory, stride: int | None,
                     tolerance: float | None, joint_speed: float, zone_mm: float) -> _Plan:
    if traj.space != "joint" or traj.n != robot.n:
        raise InputError("motion", f"expected a joint-space trajectory of {robot.n} "
                         f"joints, got {traj.n} ({traj.space} space)")
    if stride is not None and tolerance is not None:
        raise InputError("stride", "give stride or tolerance, not both")
    if stride is not None:
        idx = _stride_indices(len(traj), stride)
        how = f"one sample in {stride}"
    else:
        tol = 1e-3 if tolerance is None else float(tolerance)
        vias = np.searchsorted(traj.t, np.asarray(traj.via_times) - 1e-9)
        idx = decimate(traj.q, tol, keep=vias.tolist())
        how = f"samples within {tol:g} rad of the plan (joint space)"
    speeds, speed_note = _joint_speeds(robot, traj, idx, joint_speed)
    zones = np.full(len(idx), zone_mm)
    zones[[0, -1]] = 0.0
    return _Plan(traj.q[idx], (_JOINT,) * len(idx), speeds, zones,
                 f"{len(idx)} joint moves through {len(traj)} samples of a "
                 f"{traj.duration:.3f} s trajectory ({how})", (speed_note,))


def _result_plan(robot: Robot, motion: Any, stride: int | None, joint_speed: float,
                 speed_mm_s: float, zone_mm: float) -> _Plan:
    feasible = getattr(motion, "feasible", True)
    if not bool(np.all(feasible)):
        reason = getattr(motion, "reason", "") or "no reason given"
        raise InputError("motion", f"the process path is not feasible ({reason}); "
                         "robokin writes programs for feasible motions only")
    q = np.asarray(motion.q, dtype=np.float64)
    if q.ndim != 2 or q.shape[1] != robot.n or len(q) == 0:
        raise InputError("motion", f"expected .q of shape (N, {robot.n}), got {q.shape}")
    idx = np.arange(len(q)) if stride is None else _stride_indices(len(q), stride)
    q = q[idx]
    k = len(q)
    if hasattr(motion, "order"):
        zones = np.zeros(k)
        return _Plan(q, (_JOINT,) * k, np.full(k, joint_speed), zones,
                     f"{k} points in visiting order, a joint move to each")
    kinds: tuple[MoveKind, ...] = (_JOINT,) + (_LINEAR,) * (k - 1)
    speeds = np.full(k, speed_mm_s)
    speeds[0] = joint_speed
    zones = np.full(k, zone_mm)
    zones[[0, -1]] = 0.0
    free = getattr(motion, "free_angle", None)
    extra = ""
    if free is not None and np.any(np.asarray(free) != 0):
        extra = ", the tool turned about its axis where the path search chose"
    return _Plan(q, kinds, speeds, zones,
                 f"a process path: a joint move to its start, {k - 1} linear moves "
                 f"through its poses{extra}")


def _array_plan(robot: Robot, q: np.ndarray, stride: int | None, joint_speed: float,
                zone_mm: float) -> _Plan:
    if q.ndim != 2 or q.shape[1] != robot.n or len(q) == 0:
        raise InputError("motion", f"expected configurations (N, {robot.n}), got {q.shape}")
    if stride is not None:
        q = q[_stride_indices(len(q), stride)]
    zones = np.full(len(q), zone_mm)
    zones[[0, -1]] = 0.0
    return _Plan(q, (_JOINT,) * len(q), np.full(len(q), joint_speed), zones,
                 f"{len(q)} joint moves through the given configurations")


def _plan(robot: Robot, motion: Any, stride: int | None, tolerance: float | None,
          joint_speed: float, speed_mm_s: float, zone_mm: float) -> _Plan:
    if isinstance(motion, Trajectory):
        return _trajectory_plan(robot, motion, stride, tolerance, joint_speed, zone_mm)
    if tolerance is not None:
        raise InputError("tolerance", "applies to sampled trajectories; use stride")
    if hasattr(motion, "q"):
        return _result_plan(robot, motion, stride, joint_speed, speed_mm_s, zone_mm)
    try:
        arr = np.asarray(motion, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError("motion", "expected a Trajectory, a process result (.q, "
                         f".feasible) or configurations (N, n), got {short_repr(motion)}"
                         ) from None
    if not np.isfinite(arr).all():
        raise InputError("motion", "holds a non-finite value")
    return _array_plan(robot, arr, stride, joint_speed, zone_mm)


# ------------------------------------------------------------------ the job
def _check_fraction(x: float, name: str) -> float:
    if isinstance(x, bool) or not isinstance(x, (int, float)) or not 0.0 < x <= 1.0:
        raise InputError(name, f"expected a fraction of the maximum speed in (0, 1], "
                         f"got {short_repr(x)}")
    return float(x)


def _check_positive(x: float, name: str, *, zero: bool = False) -> float:
    ok = isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) \
        and (x >= 0.0 if zero else x > 0.0)
    if not ok:
        raise InputError(name, f"expected a {'non-negative' if zero else 'positive'} "
                         f"number, got {short_repr(x)}")
    return float(x)


def _frames(robot: Robot, profile: ControllerProfile, q0: np.ndarray,
            work_object: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Root (world) [m], tool in the controller flange [m], base in the root [m]."""
    frames = robot.fk_all(q0)
    root = frames[0] @ profile.frame("root")
    flange = frames[-1] @ profile.frame("flange")
    tool = invert(flange) @ robot.fk(q0)
    return root, tool, invert(root) @ work_object


def _mm(T: np.ndarray) -> np.ndarray:
    out = np.array(T, dtype=np.float64)
    out[..., :3, 3] *= 1000.0
    return out


def _config_notes(cfg: Any, cartesian: np.ndarray) -> list[str]:
    """Targets whose flags sit on a boundary (a singularity): say which."""
    notes = []
    near = {"the shoulder (wrist point on axis 1)": np.abs(cfg.reach) < _NEAR_SHOULDER,
            "the elbow (arm stretched or folded)": np.minimum(
                np.abs(cfg.elbow), np.pi - np.abs(cfg.elbow)) < _NEAR_ELBOW,
            "the wrist (axis 5 at 0)": np.abs(cfg.joints_deg[:, 4]) < _NEAR_WRIST}
    for what, mask in near.items():
        hits = np.flatnonzero(mask & cartesian)
        if hits.size:
            notes.append(f"{hits.size} Cartesian target(s) (first: {hits[0] + 1}) are at "
                         f"the boundary of a configuration flag, at {what}: the "
                         "controller may choose the other branch there")
    return notes


class _JobKeywords(TypedDict, total=False):
    """The keywords of :func:`program_job` that :func:`write_program` passes on."""

    name: str
    stride: int | None
    tolerance: float | None
    joint_speed: float
    speed: float
    zone: float
    cartesian: bool
    work_object: npt.ArrayLike | None
    created: datetime | None


def program_job(
    robot: Robot,
    motion: Any,
    post: PostProcessor,
    *,
    name: str = "robokin",
    stride: int | None = None,
    tolerance: float | None = None,
    joint_speed: float = 0.2,
    speed: float = 0.1,
    zone: float = 0.001,
    cartesian: bool = False,
    work_object: npt.ArrayLike | None = None,
    profile: ControllerProfile | None = None,
    created: datetime | None = None,
) -> ProgramJob:
    """The :class:`ProgramJob` of ``motion`` for ``post`` (see :func:`write_program`).

    Raises:
        InputError: bad arguments, an infeasible process result, targets outside the
            joint limits, an arm the dialect does not drive.
        ModelError: a bad ``controller:`` section.
    """
    if robot.n != post.axes or not np.all(robot.is_revolute):
        raise InputError("robot", f"{post.title} programs drive {post.axes} revolute "
                         f"axes; {robot.name} has {robot.n} coordinates")
    prof = profile or controller_profile(robot)
    plan = _plan(robot, motion, stride, tolerance, _check_fraction(joint_speed, "joint_speed"),
                 1000.0 * _check_positive(speed, "speed"),
                 1000.0 * _check_positive(zone, "zone", zero=True))
    inside = np.asarray(robot.within_limits(plan.q))
    if not inside.all():
        k = int(np.argmin(inside))
        raise InputError("motion", f"target {k + 1} is outside {robot.name}'s joint "
                         f"limits: {np.round(np.degrees(plan.q[k]), 3).tolist()} deg")
    wobj = np.eye(4) if work_object is None else np.asarray(work_object, dtype=np.float64)
    if wobj.shape != (4, 4) or not np.isfinite(wobj).all():
        raise InputError("work_object", f"expected a (4, 4) pose, got {wobj.shape}")
    root, tool, base = _frames(robot, prof, plan.q[0], wobj)
    poses = _mm(invert(wobj) @ robot.fk(plan.q))
    cfg = arm_configuration(robot, plan.q, prof, prof.frame("root"))
    R = poses[:, :3, :3]
    orient = {seq: euler_deg(R, seq) for seq in ("ZYX", "XYZ", "ZYZ")}
    orient["wxyz"] = quaternion_wxyz(R)
    targets = [Target(k + 1, cfg.joints_deg[k], poses[k, :3, 3], R[k],
                      bool(cfg.behind_axis_1[k]), bool(cfg.behind_lower_arm[k]),
                      {key: v[k] for key, v in orient.items()})
               for k in range(len(plan.q))]
    moves = tuple(Move(kind, t, float(v), float(z), cartesian=cartesian and kind == "joint"
                       and k > 0)
                  for k, (kind, t, v, z) in enumerate(zip(plan.kinds, targets,
                                                          plan.speeds, plan.zones)))
    is_cart = np.array([m.kind == "linear" or m.cartesian for m in moves])
    legal, name_note = post.program_name(name)
    notes = [n for n in (name_note, *plan.notes) if n] + _config_notes(cfg, is_cart)
    return ProgramJob(legal, moves, tool=_mm(tool), base=_mm(base), robot=robot.name,
                      profile=prof.name, description=plan.description, notes=tuple(notes),
                      created=created or datetime.now().replace(microsecond=0))


def _post_for(robot: Robot, dialect: str | PostProcessor, options: Mapping[str, Any] | None,
              profile: ControllerProfile | None) -> PostProcessor:
    """The post with the robot file's options for it, then the call's."""
    if isinstance(dialect, PostProcessor):
        return get_post(dialect, **dict(options or {}))
    prof = profile or controller_profile(robot)
    key = str(dialect).strip().lower().replace("-", "_")
    merged: dict[str, Any] = {}
    posts = prof.posts or {}
    unknown = sorted(set(posts) - set(post_names()))
    if unknown:
        raise ModelError(f"unknown post processor(s) {unknown}; available: {post_names()}",
                         file=robot.path, field="controller.posts")
    if key in posts:
        merged.update(posts[key])
        try:
            get_post(key, **merged)
        except InputError as exc:
            raise ModelError(exc.reason, file=robot.path,
                             field=f"controller.posts.{key}.{exc.argument}") from None
    merged.update(options or {})
    return get_post(key, **merged)


def render_program(
    robot: Robot,
    motion: Any,
    dialect: str | PostProcessor,
    *,
    options: Mapping[str, Any] | None = None,
    profile: ControllerProfile | None = None,
    **job: Unpack[_JobKeywords],
) -> Program:
    """The program's texts, not written (arguments as :func:`write_program`)."""
    post = _post_for(robot, dialect, options, profile)
    pj = program_job(robot, motion, post, profile=profile, **job)
    texts = post.render(pj)
    return Program(post.name, post.title, pj.name, texts, len(pj.moves),
                   pj.description, pj.notes)


def write_program(
    robot: Robot,
    motion: Any,
    dialect: str | PostProcessor,
    out_dir: str | Path,
    *,
    force: bool = False,
    options: Mapping[str, Any] | None = None,
    profile: ControllerProfile | None = None,
    **job: Unpack[_JobKeywords],
) -> Program:
    """Write the program of ``motion`` for a controller, in its language.

    Args:
        robot: The six-axis arm (its ``controller:`` section gives the joint
            convention, frames and the dialect's options).
        motion: A joint :class:`~robokin.trajectory.samples.Trajectory`, a process
            result (``.q``, ``.feasible``; ``.order`` for a point set) or
            configurations (N, 6) [rad] (module docstring).
        dialect: A post processor name (``kuka_krl``, ``abb_rapid``, ``fanuc_tp``,
            ``yaskawa_inform``, ``staubli_val3``, ``kawasaki_as``, or a registered
            one) or instance.
        out_dir: The folder to write into (created when its parent exists).
        name: The program name (made legal for the dialect, with a note when changed).
        force: Replace files an earlier run wrote.
        stride: Keep every ``stride``-th sample or waypoint (and the last).
        tolerance: Trajectories: decimate to this joint-space deviation [rad]
            (default 1e-3 when no ``stride``).
        joint_speed: Joint moves' speed, a fraction (0, 1] of the axes' maximum
            (trajectories with rate limits: computed per stretch).
        speed: Linear moves' TCP speed [m/s].
        zone: Blending distance [m] at intermediate targets (0: exact stops).
        cartesian: Write joint moves' targets (after the first) as poses with
            configuration flags instead of joint values.
        work_object: World pose (4, 4) [m] of the frame the Cartesian targets are
            written in (default: the world frame).
        options: The dialect's options (its fields; over the robot file's
            ``controller.posts.DIALECT``).
        profile: A controller profile instead of the robot file's.
        created: The date written into dialects that date their files (default now).

    Returns:
        The :class:`Program`, its ``files`` set.

    Raises:
        InputError: unknown dialect or options (listing the valid ones), bad
            arguments, an infeasible path, targets outside the joint limits, more
            moves than the dialect holds, a file that exists (without ``force``) or
            cannot be written.
        ModelError: a bad ``controller:`` section.
    """
    prog = render_program(robot, motion, dialect, options=options, profile=profile, **job)
    folder = Path(out_dir)
    if not folder.is_dir():
        if not folder.parent.is_dir() and str(folder.parent):
            raise InputError("out_dir", f"{folder}: the folder {folder.parent} does not "
                             "exist")
        try:
            folder.mkdir()
        except OSError as exc:
            raise InputError("out_dir", f"{folder}: cannot create: "
                             f"{exc.strerror or exc}") from None
    paths = [folder / rel for rel in prog.texts]
    made = [p.parent for p in paths if not p.parent.exists()]
    for sub in dict.fromkeys(made):
        sub.mkdir(parents=True)
    try:
        with staged_outputs([(p, "out_dir", force) for p in paths],
                            how="pass force=True (--force)") as staged:
            for tmp, text in zip(staged, prog.texts.values()):
                tmp.write_text(text, encoding="ascii", errors="replace", newline="")
    except BaseException:
        for sub in dict.fromkeys(made):
            with contextlib.suppress(OSError):
                sub.rmdir()
        raise
    return Program(prog.dialect, prog.title, prog.name, prog.texts, prog.moves,
                   prog.description, prog.notes, tuple(paths))
