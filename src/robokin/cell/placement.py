"""Robot placement: where must the arm stand so that the whole task works?

For every candidate base pose the search asks what a cell designer asks (the
questions of ROS-Industrial's REACH and of inverse reachability, Vahrenkamp et
al., "Robot placement based on reachability inversion", ICRA 2013):

1. **Reach on one branch.** Is every task pose reachable inside the joint
   limits, on one continuous IK branch, so the motion runs without a flip? (See
   :mod:`robokin.cell._tracking`.) For a set of poses in no order
   (``max_step=math.inf``) each pose only needs a solution inside the limits
   of its own (:mod:`robokin.cell._pose_set`).
2. **Clearance.** Along that branch, does the arm (and its tool) keep at least
   ``clearance`` from the scene and from itself
   (:func:`robokin.collision.check` on the task's samples)?
3. **Manipulability.** How close does the motion come to a singularity: the
   smallest Yoshikawa manipulability along the branch (it must be at least
   ``min_manipulability``).

A candidate is *feasible* when it passes all three on one branch (the best by
manipulability among those that pass). Its *score* is that smallest
manipulability (0 for infeasible candidates); ties go to the larger clearance.
The best candidate then gets the full check: the collision check with
subdivision between samples, which proves no contact is missed between them.

Candidates are chunks of Dask tasks exactly like a reachability map's voxels;
the result does not depend on the scheduler or the chunking.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from itertools import product
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import numpy.typing as npt

from robokin._text import short_repr
from robokin.cell import plots as _plots
from robokin.cell._evaluate import manipulability as _manipulability
from robokin.cell._inputs import (
    ik_method,
    manifold_sweep,
    placed_robot,
    progress_callback,
)
from robokin.cell._pose_set import PoseSet, rank_solutions
from robokin.cell._scheduler import check_scheduler, run_chunks
from robokin.cell._tracking import track
from robokin.exceptions import InputError, UnreachableError

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from robokin.collision.report import CollisionReport
    from robokin.collision.scene import Scene
    from robokin.robot import Robot

__all__ = ["Placement", "base_grid", "place"]

DEFAULT_MAX_STEP = math.radians(30.0)
_TARGETS_PER_TASK = 8192  # IK targets per Dask task (candidates x task poses)
_FULL_CHECKS = 20  # best candidates tried by the full check before giving up
OK = "ok"


@dataclass(frozen=True, eq=False)
class PlaceJob:
    """What every chunk of a placement search shares (pickled once).

    Attributes:
        robot: The robot with its tool, base frame at the world origin.
        bare: The robot before the scene placed it (for the collision check),
            or None without a scene.
        scene: The scene, or None.
        task: Task tool poses in the world (N, 4, 4) [m].
        candidates: Base poses (C, 4, 4) [m].
        clearance: Required clearance [m].
        max_step: Largest joint change between task poses on a branch [rad, m].
        min_manipulability: Smallest acceptable manipulability along the task.
        numeric: Follow numeric tracks (no closed form).
        sweep: With ``numeric`` on a 7R arm, the joint sweeping a pose's
            self-motion manifold where the numeric sample missed (or None).
    """

    robot: Robot
    bare: Robot | None
    scene: Scene | None
    task: np.ndarray
    candidates: np.ndarray
    clearance: float
    max_step: float
    min_manipulability: float
    numeric: bool
    sweep: str | None = None


@dataclass(frozen=True, eq=False)
class PlaceChunk:
    """Scores of candidates ``start .. stop - 1`` (see :class:`Placement`)."""

    start: int
    stop: int
    reachable: np.ndarray
    clearance: np.ndarray
    manipulability: np.ndarray
    branch: np.ndarray
    reason: np.ndarray
    unreached: np.ndarray
    path: np.ndarray | None = None


@dataclass(frozen=True, eq=False)
class Placement:
    """The result of :func:`place`: every candidate scored, the best one checked.

    Attributes:
        candidates: Base poses (C, 4, 4) [m] in the world.
        feasible: (C,) bool: every criterion met on one branch.
        score: (C,) the smallest manipulability along the task on the chosen
            branch, 0 where infeasible.
        reachable: (C,) bool: every task pose reached on one continuous branch
            inside the joint limits.
        clearance: (C,) smallest distance [m] to the scene (and between links)
            along the chosen branch; inf without a scene, NaN where not
            reachable.
        manipulability: (C,) smallest manipulability along the chosen branch
            (NaN where not reachable).
        branch: (C,) which solution of the first task pose the chosen branch
            starts from (for a set of poses: the solution chosen for the first
            pose; -1 where none).
        reason: (C,) ``"ok"`` or why the candidate fails.
        task: The task tool poses (N, 4, 4) [m] in the world.
        required_clearance: The clearance asked for [m].
        best_index: Index of the best feasible candidate, or None.
        best_q: The best candidate's joint path along the task (N, n) (for a
            set of poses: the solution chosen for each pose), or None.
        best_report: Its full collision check (with subdivision), or None (no
            scene, or nothing feasible).
    """

    candidates: np.ndarray
    feasible: np.ndarray
    score: np.ndarray
    reachable: np.ndarray
    clearance: np.ndarray
    manipulability: np.ndarray
    branch: np.ndarray
    reason: np.ndarray
    task: np.ndarray
    required_clearance: float
    best_index: int | None
    best_q: np.ndarray | None
    best_report: CollisionReport | None

    @property
    def ranking(self) -> np.ndarray:
        """Indices of the feasible candidates, best first (score, then clearance)."""
        idx = np.flatnonzero(self.feasible)
        order = np.lexsort((idx, -self.clearance[idx], -self.score[idx]))
        return idx[order]

    @property
    def best(self) -> np.ndarray:
        """The best base pose (4, 4) [m].

        Raises:
            UnreachableError: no candidate is feasible (the message counts the
                reasons).
        """
        if self.best_index is None:
            raise UnreachableError(f"no feasible placement among {len(self.feasible)} "
                                   f"candidates: {self.reasons_text()}")
        return self.candidates[self.best_index].copy()

    def reasons_text(self) -> str:
        """How many candidates failed for which reason, most common first."""
        return _count_reasons(self.reason[~self.feasible]) or "none"

    def summary(self) -> dict[str, Any]:
        """Plain numbers for reports and JSON."""
        best = None
        if self.best_index is not None:
            c = self.best_index
            T = self.candidates[c]
            best = {
                "index": int(c),
                "xyz_m": T[:3, 3].tolist(),
                "yaw_deg": math.degrees(math.atan2(T[1, 0], T[0, 0])),
                "score": float(self.score[c]),
                "clearance_m": float(self.clearance[c]),
                "full_check_min_distance_m": None if self.best_report is None
                else float(self.best_report.min_distance),
            }
        return {
            "candidates": int(len(self.feasible)),
            "feasible": int(self.feasible.sum()),
            "reachable": int(self.reachable.sum()),
            "task_poses": int(self.task.shape[0]),
            "required_clearance_m": self.required_clearance,
            "reasons": self.reasons_text(),
            "best": best,
        }

    def write_csv(self, path: str | Path, *, overwrite: bool = True) -> Path:
        """Every candidate, best first then the rest in order, as CSV (atomically).

        Columns: rank (1 = best, empty if infeasible), x, y, z [mm], yaw [deg],
        feasible, score, clearance [mm], manipulability, reason.
        """
        from robokin.io.atomic import write_atomic

        rank = np.zeros(len(self.feasible), dtype=np.int64)
        rank[self.ranking] = np.arange(1, self.ranking.size + 1)
        order = np.concatenate([self.ranking, np.flatnonzero(rank == 0)])
        lines = ["rank,x [mm],y [mm],z [mm],yaw [deg],feasible,score,clearance [mm],"
                 "manipulability,reason"]
        for c in order:
            T = self.candidates[c]
            yaw = math.degrees(math.atan2(T[1, 0], T[0, 0]))
            reason = str(self.reason[c]).replace('"', "'")
            lines.append(
                f"{rank[c] or ''},{T[0, 3] * 1e3:.3f},{T[1, 3] * 1e3:.3f},"
                f"{T[2, 3] * 1e3:.3f},{yaw:.3f},{int(self.feasible[c])},"
                f"{self.score[c]:.6g},{self.clearance[c] * 1e3:.3f},"
                f"{self.manipulability[c]:.6g},\"{reason}\""
            )
        return write_atomic(path, "\n".join(lines) + "\n", overwrite=overwrite)

    def plot_floor(self, path: str | Path | None = None, **kwargs: Any) -> Figure:
        """The floor heatmap (see :func:`robokin.cell.plots.plot_floor`)."""
        return _plots.plot_floor(self, path=path, **kwargs)


# ------------------------------------------------------------------ inputs
def base_grid(
    x: npt.ArrayLike,
    y: npt.ArrayLike,
    z: npt.ArrayLike = 0.0,
    yaw: npt.ArrayLike = 0.0,
) -> np.ndarray:
    """Candidate base poses on a grid: every combination of x, y, z and yaw.

    Args:
        x: Positions [m], a number or a 1-D sequence.
        y: Positions [m].
        z: Heights [m].
        yaw: Rotations about the world z axis [rad].

    Returns:
        Base poses (C, 4, 4), x varying slowest and yaw fastest.

    Raises:
        InputError: an empty or non-finite axis (naming it).
    """
    axes = []
    for name, values in (("x", x), ("y", y), ("z", z), ("yaw", yaw)):
        try:
            v = np.atleast_1d(np.asarray(values, dtype=np.float64))
        except (TypeError, ValueError):
            raise InputError(name, f"expected numbers, got {short_repr(values)}") from None
        if v.ndim != 1 or v.size == 0 or not np.isfinite(v).all():
            raise InputError(name, f"expected a number or a non-empty 1-D list of finite "
                             f"numbers, got {short_repr(values)}")
        axes.append(v)
    rows = np.array(list(product(*axes)), dtype=np.float64)
    return poses_from_xyz_yaw(rows)


def poses_from_xyz_yaw(rows: np.ndarray) -> np.ndarray:
    """Base poses (C, 4, 4) from rows ``(x, y, z, yaw)`` (C, 4) [m, rad]."""
    from robokin.spatial import rotz

    T = rotz(rows[:, 3])
    T[:, :3, 3] = rows[:, :3]
    return T


def _candidates(candidates: npt.ArrayLike) -> np.ndarray:
    from robokin._validation import check_transform

    try:
        arr = np.asarray(candidates, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError("candidates", f"expected base poses (C, 4, 4) or rows "
                         f"(x, y, z, yaw) (C, 4), got {short_repr(candidates)}") from None
    if arr.ndim == 2 and arr.shape[1] == 4 and arr.shape != (4, 4):
        if not np.isfinite(arr).all():
            raise InputError("candidates", "holds a non-finite value")
        arr = poses_from_xyz_yaw(arr)
    if arr.shape == (4, 4):
        arr = arr[None]
    if arr.ndim != 3 or arr.shape[1:] != (4, 4):
        raise InputError("candidates", f"expected base poses (C, 4, 4) or rows (x, y, z, "
                         f"yaw) (C, 4), got shape {arr.shape}")
    if arr.shape[0] == 0:
        raise InputError("candidates", "is empty: give at least one base pose")
    return np.ascontiguousarray(check_transform(arr, "candidates"))


def _task(task: Any, world: Robot) -> np.ndarray:
    """Task poses (N, 4, 4): given, a trajectory's poses, or FK of its joints."""
    from robokin._validation import check_transform

    if not isinstance(task, np.ndarray) and (hasattr(task, "tool_poses")
                                             or hasattr(task, "q")):
        T = _trajectory_poses(task, world)
    else:
        try:
            T = np.asarray(task, dtype=np.float64)
        except (TypeError, ValueError):
            raise InputError("task", f"expected tool poses (N, 4, 4) or a trajectory, "
                             f"got {short_repr(task)}") from None
    if T.shape == (4, 4):
        T = T[None]
    if T.ndim != 3 or T.shape[1:] != (4, 4) or T.shape[0] == 0:
        raise InputError("task", f"expected tool poses (N, 4, 4) with N >= 1, got shape "
                         f"{T.shape}")
    return np.ascontiguousarray(check_transform(T, "task"))


def _trajectory_poses(task: Any, world: Robot) -> np.ndarray:
    """Tool poses of a trajectory at the robot's placement, shape (N, 4, 4) [m].

    A :class:`~robokin.trajectory.Trajectory` gives its own
    (``tool_poses(world)``: the stored poses, else FK of its joints, converted
    from actuator space first); another object its ``pose``, else FK of its
    ``q`` (N, n).
    """
    tool_poses = getattr(task, "tool_poses", None)
    if callable(tool_poses):
        return np.asarray(tool_poses(world))
    pose = getattr(task, "pose", None)
    return np.asarray(pose) if pose is not None else world.fk(np.asarray(task.q))


def _check_span(task: np.ndarray, robot: Robot) -> None:
    """Refuse a task no base can reach: two poses farther apart than twice the reach."""
    from robokin.cell._facts import reach_bound

    p = task[:, :3, 3]
    far = int(np.argmax(np.linalg.norm(p - p.mean(axis=0), axis=-1)))
    d = np.linalg.norm(p - p[far], axis=-1)
    other = int(np.argmax(d))
    reach = reach_bound(robot)
    if d[other] > 2.0 * reach:
        raise InputError(
            "task",
            f"poses {min(far, other)} and {max(far, other)} are {d[other]:.3f} m apart, "
            f"more than twice the arm's reach ({reach:.3f} m): no base reaches both",
        )


def _number(value: Any, name: str, *, positive: bool = False) -> float:
    ok = isinstance(value, int | float | np.number) and not isinstance(value, bool)
    v = float(value) if ok else math.nan
    if not ok or math.isnan(v) or v < 0 or (positive and v == 0) or (
            math.isinf(v) and name != "max_step"):
        what = "> 0" if positive else ">= 0"
        raise InputError(name, f"expected a number {what}, got {short_repr(value)}")
    return v


# ------------------------------------------------------------------ search
def place(
    robot: Robot,
    task: Any,
    candidates: npt.ArrayLike,
    scene: Scene | None = None,
    clearance: float = 0.0,
    scheduler: Any = None,
    *,
    max_step: float = DEFAULT_MAX_STEP,
    min_manipulability: float = 0.0,
    method: Literal["auto", "analytic", "numeric"] = "auto",
    chunk: int | None = None,
    progress: Any = None,
) -> Placement:
    """Score candidate base poses for a task and check the best one in full.

    Args:
        robot: The robot (with a scene: as the scene would place it, or bare;
            the scene adds its tool).
        task: Tool (TCP) poses in the world (N, 4, 4) [m] in task order, or a
            trajectory (its ``tool_poses(robot)`` at the robot's current
            placement: its ``pose``, else FK of its joints, a trajectory in
            actuator space converted to joint space first).
        candidates: Base poses (C, 4, 4) [m] (see :func:`base_grid`), or rows
            ``(x, y, z, yaw)`` (C, 4) [m, rad].
        scene: A :class:`~robokin.collision.Scene`; its base placement is
            replaced by each candidate.
        clearance: Smallest distance [m] the arm must keep from the scene.
        scheduler: Where the chunks run (as for :func:`reach_map`).
        max_step: Largest joint change [rad, m] between consecutive task poses
            on one branch. ``math.inf`` makes the task a set of poses in no
            order, with no motion between them: each pose then needs only a
            solution of its own inside the joint limits (no branch is followed
            and no joint value carried over), the one with the best
            manipulability among those with the clearance asked for; the score
            is the smallest manipulability over the poses so chosen.
        min_manipulability: Smallest manipulability acceptable along the task.
        method: ``"auto"``, ``"analytic"`` or ``"numeric"`` (see
            :func:`reach_map`).
        chunk: Candidates per Dask task (default: about 8,192 IK targets).
        progress: True for a progress bar, or ``progress(done, total)``.

    Returns:
        The :class:`Placement`.

    Raises:
        InputError: bad arguments, or an unreachable task: poses farther apart
            than the arm can span, or a pose out of reach from every candidate
            (naming ``task``). A task every pose of which some candidate reaches
            is not an error even when no candidate is feasible.
        MissingExtraError: dask/distributed (``robokin[scale]``) or coal
            (``robokin[collision]``, with a scene) is missing.
    """
    from robokin.cell._scheduler import require_scale
    require_scale()
    check_scheduler(scheduler)
    clearance = _number(clearance, "clearance")
    max_step = _number(max_step, "max_step", positive=True)
    min_manipulability = _number(min_manipulability, "min_manipulability")
    world, bare = placed_robot(robot, scene)
    if scene is not None and bare is not None:
        tooled = scene.with_base(np.eye(4)).attach(bare)
    else:
        tooled = robot
    T = _task(task, world)
    C_poses = _candidates(candidates)
    _check_span(T, tooled)
    numeric, _ = ik_method(tooled, method)
    sweep = manifold_sweep(tooled, method) if numeric else None
    job = PlaceJob(tooled, bare, scene, T, C_poses, clearance, max_step,
                   min_manipulability, numeric, sweep)
    C, N = C_poses.shape[0], T.shape[0]
    B = _chunk(chunk, C, N)
    ranges = [(a, min(a + B, C)) for a in range(0, C, B)]
    parts: list[PlaceChunk | None] = [None] * len(ranges)

    def on_result(i: int, r: PlaceChunk) -> None:
        parts[i] = r

    with progress_callback(progress, len(ranges), "placement", scheduler) as tick:
        run_chunks(evaluate_place, job, ranges, scheduler=scheduler,
                   on_result=on_result, progress=tick, name="robokin-place")
    done = [p for p in parts if p is not None]
    return _finish(job, done)


def _chunk(chunk: int | None, C: int, N: int) -> int:
    if chunk is None:
        return max(1, min(C, -(-_TARGETS_PER_TASK // N)))
    if isinstance(chunk, bool) or not isinstance(chunk, int | np.integer) or chunk < 1:
        raise InputError("chunk", f"expected candidates per task >= 1, got {short_repr(chunk)}")
    return min(int(chunk), C)


def _finish(job: PlaceJob, parts: list[PlaceChunk]) -> Placement:
    """Assemble the chunks, rank, run the best candidate's full check."""
    cat = {f: np.concatenate([getattr(p, f) for p in parts])
           for f in ("reachable", "clearance", "manipulability", "branch", "reason",
                     "unreached")}
    reason = cat["reason"].astype(object)
    if (cat["unreached"] >= 0).all():
        raise InputError("task", _unreachable_text(job, cat["unreached"]))
    feasible = reason == OK
    score = np.where(feasible, cat["manipulability"], 0.0)
    pl = Placement(job.candidates, feasible, score, cat["reachable"], cat["clearance"],
                   cat["manipulability"], cat["branch"], reason, job.task, job.clearance,
                   None, None, None)
    for _ in range(_FULL_CHECKS):
        ranking = pl.ranking
        if ranking.size == 0:
            break
        c = int(ranking[0])
        q, report, why = _full_check(job, c)
        if why == OK:
            return replace(pl, best_index=c, best_q=q, best_report=report)
        feasible = pl.feasible.copy()
        feasible[c] = False
        reason = pl.reason.copy()
        reason[c] = why
        score = pl.score.copy()
        score[c] = 0.0
        pl = replace(pl, feasible=feasible, reason=reason, score=score)
    return pl


def _unreachable_text(job: PlaceJob, unreached: np.ndarray) -> str:
    """Why no candidate reaches the task: the pose most candidates miss first."""
    counts = np.bincount(unreached, minlength=job.task.shape[0])
    i = int(np.argmax(counts))
    return (f"no candidate base reaches every task pose: pose {i} is the first out of "
            f"reach from {int(counts[i])} of the {len(unreached)} candidates (the others "
            "miss earlier poses); move the candidates closer or check the task")


def _count_reasons(reason: np.ndarray) -> str:
    kinds: dict[str, int] = {}
    for r in reason:
        key = str(r).split(":")[0]
        kinds[key] = kinds.get(key, 0) + 1
    return ", ".join(f"{v} {k}" for k, v in sorted(kinds.items(), key=lambda kv: -kv[1]))


def _full_check(job: PlaceJob, c: int) -> tuple[np.ndarray | None, Any, str]:
    """Re-derive candidate c's branch and check it in full (between samples too)."""
    one = evaluate_place(job, c, c + 1, keep_path=True)
    q = one.path
    if q is None or one.reason[0] != OK:
        return None, None, str(one.reason[0])
    if job.scene is None or job.bare is None:
        return q, None, OK
    from robokin.collision import check

    # a motion is checked between its samples too; a set of poses (no order, no
    # motion between them) pose by pose, as when it was scored
    motion = math.isfinite(job.max_step)
    report = check(job.bare, job.scene.with_base(job.candidates[c]), q,
                   clearance=job.clearance, subdivide=motion)
    return q, report, _collision_reason(report, job.clearance, between=motion)


def _collision_reason(report: Any, clearance: float, *, between: bool = False) -> str:
    """``"ok"`` or why the check fails (collision, or too little clearance)."""
    where = " between task samples" if between else ""
    c = report.closest
    pair = "" if c is None else f" ({c.body_a}–{c.body_b})"
    if report.collides:
        iv = report.intervals[0]
        return f"collision{where}: {iv.body_a}–{iv.body_b} at task pose {iv.first_index}"
    if report.min_distance < clearance:
        return (f"clearance{where}: {report.min_distance * 1e3:.1f} mm < "
                f"{clearance * 1e3:.1f} mm required{pair}")
    return OK


# ------------------------------------------------------------------ one chunk
def evaluate_place(job: PlaceJob, start: int, stop: int, *,
                   keep_path: bool = False) -> PlaceChunk:
    """Score candidates ``start .. stop - 1`` (one Dask task).

    Args:
        job: The shared search.
        start: First candidate.
        stop: One past the last.
        keep_path: Also return the chosen branch's joint path (one candidate).

    Returns:
        A :class:`PlaceChunk`.
    """
    from robokin.spatial import invert

    Bs = job.candidates[start:stop]
    C, N = Bs.shape[0], job.task.shape[0]
    local = invert(Bs)[:, None] @ job.task[None]
    if math.isinf(job.max_step):
        return _evaluate_set(job, start, stop, local, keep_path=keep_path)
    tr = track(job.robot, local, job.max_step, job.numeric, job.sweep)
    k = tr.alive.shape[1]
    w_min = np.full((C, k), np.nan)
    if tr.alive.any():
        paths = tr.q[tr.alive]  # (A, N, n)
        w = _manipulability(job.robot.chain, paths.reshape(-1, paths.shape[-1]))
        w_min[tr.alive] = w.reshape(-1, N).min(axis=-1)
    reachable = np.asarray(tr.alive.any(axis=-1))
    clearance = np.full(C, np.nan)
    manip = np.full(C, np.nan)
    branch = np.full(C, -1, dtype=np.int64)
    reason = np.empty(C, dtype=object)
    path = None
    for c in range(C):
        if not reachable[c]:
            reason[c] = _reach_reason(tr.unreached[c], int(tr.died_at[c].max()), N)
            continue
        j, dist, why = _choose_branch(job, Bs[c], tr.q[c], tr.alive[c], w_min[c])
        branch[c], clearance[c], manip[c], reason[c] = j, dist, w_min[c, j], why
        if keep_path:
            path = tr.q[c, j].copy()
    return PlaceChunk(start, stop, reachable, clearance, manip, branch, reason,
                      tr.unreached, path)


def _evaluate_set(job: PlaceJob, start: int, stop: int, local: np.ndarray, *,
                  keep_path: bool) -> PlaceChunk:
    """:func:`evaluate_place` for a set of poses (``max_step`` infinite).

    ``local`` holds the task poses in each candidate's base frame (C, N, 4, 4).
    """
    ps = rank_solutions(job.robot, local, job.numeric, job.sweep)
    C, N = ps.ok.shape[:2]
    reachable = ps.unreached < 0
    clearance = np.full(C, np.nan)
    manip = np.full(C, np.nan)
    branch = np.full(C, -1, dtype=np.int64)
    reason = np.empty(C, dtype=object)
    path = None
    poses = np.arange(N)
    for c in range(C):
        if not reachable[c]:
            reason[c] = _reach_reason(int(ps.unreached[c]), 0, N)
            continue
        slots, dist, why = _choose_solutions(job, job.candidates[start + c], ps, c)
        w = ps.w[c, poses, slots]
        branch[c], clearance[c], manip[c], reason[c] = slots[0], dist, w.min(), why
        if keep_path:
            path = ps.q[c, poses, slots].copy()
    return PlaceChunk(start, stop, reachable, clearance, manip, branch, reason,
                      ps.unreached, path)


def _choose_solutions(job: PlaceJob, base: np.ndarray, ps: PoseSet,
                      c: int) -> tuple[np.ndarray, float, str]:
    """One solution per task pose of candidate c: (slots (N,), clearance [m], reason).

    Per pose, the solution with the best manipulability among those that meet
    the manipulability and clearance asked for (so the smallest manipulability
    over the set is as large as it can be); a pose with none keeps its best one,
    and the reason names what fails. Each pose's solutions are checked against
    the scene in rounds: the best of every pose still open, then the next...
    """
    N = ps.ok.shape[1]
    order, ok, w = ps.order[c], ps.ok[c], ps.w[c]
    poses = np.arange(N)
    slots = order[:, 0].copy()
    w_best = w[poses, slots]
    worst = int(np.argmin(w_best))
    if w_best[worst] < job.min_manipulability:
        return (slots, math.inf if job.scene is None else math.nan,
                f"manipulability: {w_best[worst]:.3g} < {job.min_manipulability:.3g} "
                f"required at task pose {worst} (its best solution inside the limits)")
    if job.scene is None or job.bare is None:
        return slots, math.inf, OK
    from robokin.collision import check

    scene = job.scene.with_base(base)
    todo = poses
    for r in range(order.shape[1]):
        cand = order[todo, r]
        usable = ok[todo, cand] & (w[todo, cand] >= job.min_manipulability)
        todo, cand = todo[usable], cand[usable]  # (ranked: nothing usable after)
        if todo.size == 0:
            break
        report = check(job.bare, scene, ps.q[c, todo, cand], clearance=job.clearance,
                       subdivide=False)
        bad = np.zeros(todo.size, dtype=bool)
        for col in report.collisions:
            bad[col.first_index : col.last_index + 1] = True
        for iv in report.violations:
            bad[iv.first_index : iv.last_index + 1] = True
        slots[todo[~bad]] = cand[~bad]
        todo = todo[bad]
    report = check(job.bare, scene, ps.q[c, poses, slots], clearance=job.clearance,
                   subdivide=False)
    return slots, float(report.min_distance), _collision_reason(report, job.clearance)


def _reach_reason(unreached: int, died_at: int, N: int) -> str:
    if unreached >= 0:
        return f"out of reach: task pose {unreached} has no solution inside the joint limits"
    return (f"no continuous branch: every branch jumps or leaves the joint limits "
            f"(the longest reaches task pose {died_at} of {N})")


def _choose_branch(job: PlaceJob, base: np.ndarray, q: np.ndarray, alive: np.ndarray,
                   w_min: np.ndarray) -> tuple[int, float, str]:
    """The best branch of one candidate: (start slot, clearance [m], reason).

    Branches are tried by decreasing smallest manipulability; the first that
    meets the manipulability and clearance requirements is chosen. When none
    does, the one that came closest (the largest clearance) is reported.
    """
    order = [j for j in np.argsort(-np.nan_to_num(w_min, nan=-1.0), kind="stable")
             if alive[j]]
    if w_min[order[0]] < job.min_manipulability:
        return (int(order[0]), math.inf if job.scene is None else math.nan,
                f"manipulability: {w_min[order[0]]:.3g} < {job.min_manipulability:.3g} "
                "required along the task")
    if job.scene is None or job.bare is None:
        return int(order[0]), math.inf, OK
    from robokin.collision import check

    scene = job.scene.with_base(base)
    tried: list[tuple[int, float, str]] = []
    for j in order:
        if w_min[j] < job.min_manipulability:
            break
        report = check(job.bare, scene, q[j], clearance=job.clearance, subdivide=False)
        why = _collision_reason(report, job.clearance)
        tried.append((int(j), float(report.min_distance), why))
        if why == OK:
            return tried[-1]
    return max(tried, key=lambda t: t[1])  # the branch that came closest to passing
