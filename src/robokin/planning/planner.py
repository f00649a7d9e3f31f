"""Collision-free planning in a scene: :class:`Planner` and :func:`plan`.

A :class:`Planner` compiles one robot in one scene once (shapes, pairs, bounds:
:class:`~robokin.planning._model.CollisionModel`) and answers many queries. A
query checks the start and the goals, runs the planner (the compiled
RRT-Connect by default, or one of OMPL's), shortcuts and smooths the path, and
optionally retimes it. Every straight segment of a returned path is proven
collision-free; ``docs/planning.md`` has the algorithm and the guarantee.
"""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from robokin._native import kernels as _k
from robokin._text import short_repr
from robokin._validation import check_finite, check_finite_number, check_joints
from robokin.exceptions import InputError
from robokin.planning._model import CollisionModel
from robokin.planning._ompl import OMPL_PLANNERS, ompl_plan
from robokin.planning.goals import Goals, goal_configurations, outside_limits
from robokin.planning.result import PlanResult
from robokin.planning.smoothing import SHARP_TURN, retime_checked

if TYPE_CHECKING:
    from robokin.collision.scene import Scene
    from robokin.robot import Robot
    from robokin.trajectory.samples import Trajectory

__all__ = ["DEFAULT_PLANNER", "PLANNERS", "Planner", "plan"]

#: The compiled RRT-Connect.
DEFAULT_PLANNER = "rrtconnect"
#: Every planner name :meth:`Planner.plan` accepts.
PLANNERS = (DEFAULT_PLANNER, *(f"ompl:{name}" for name in OMPL_PLANNERS))
#: Longest RRT-Connect edge [rad, m]: the smaller of RANGE and RANGE_FRACTION of the
#: diagonal of the joint-limit box (docs/planning.md: on the issue-26 problem set 0.5
#: halved the median CPU time of the thin shelf and the cage against 1.0, and was
#: no worse on the other families; 1.0 had been best on the earlier simple scenes).
RANGE = 0.5
RANGE_FRACTION = 0.1
#: Most tree nodes of one RRT-Connect query (bounds memory and time).
MAX_NODES = 200_000
#: Shortcut attempts by default (``simplify=True``): point-pair tries; half as many
#: greedy vertex-pair checks first; a sixth (at least 3) failures in a row end the
#: point pairs. docs/planning.md: 20 tries cost 0.35 ms on the benchmark's table
#: problems; 80 shorten the retimed motions by a further ~20 % for ~1.5 ms more; the
#: greedy vertex pass and 3 failures (not 5) cut the median query 4.7 -> 4.1 ms CPU
#: at the same median path length (2026-12-02).
SHORTCUT_TRIES = 20
#: Rounds of corner cutting.
SMOOTH_ROUNDS = 3


def _nonnegative(value: object, name: str) -> float:
    v = check_finite_number(value, name)
    if v < 0:
        raise InputError(name, f"expected a distance >= 0 [m], got {v}")
    return v


class Planner:
    """Plans collision-free motions of one robot in one scene.

    Args:
        robot: The robot; the scene places it (base, tool transform, tool shapes).
        scene: The static scene (:class:`~robokin.collision.Scene`).
        self_collision: Also keep the robot clear of itself (its non-adjacent,
            non-excluded links, the tool included).

    Raises:
        InputError: the robot has no collision geometry.
        MissingExtraError: coal or trimesh is missing (``robokin[collision]``).
    """

    def __init__(self, robot: Robot, scene: Scene, *, self_collision: bool = True) -> None:
        """Compile the robot in the scene (once; every query reuses it)."""
        self.model = CollisionModel(robot, scene, self_collision=self_collision)
        self.robot = self.model.robot
        self.scene = scene
        self.n = self.model.n
        # the robot before the scene placed it: pose goals are solved on it (its
        # IK set-up kept across Planners), moved from the placed robot's frames
        self._solver = scene.unplaced(robot)
        if self._solver.n != self.n:  # not the same joints: solve on the placed one
            self._solver = self.robot
        self.limits = np.asarray(self.robot.limits, dtype=float)
        self._finite = bool(np.isfinite(self.limits).all())
        self._margins: dict[tuple[float, float], np.ndarray] = {}

    def __repr__(self) -> str:
        """The robot, the scene and the number of checked pairs."""
        return (f"Planner(robot={self.robot.name!r}, scene={self.scene.name!r}, "
                f"pairs={self.model.P})")

    # --------------------------------------------------------------- checks
    def margin(self, clearance: float = 0.0, self_clearance: float = 0.0) -> np.ndarray:
        """Per checked pair, the distance it must keep [m], (P,).

        Args:
            clearance: For robot-scene pairs [m].
            self_clearance: For the robot's own pairs [m].
        """
        key = (_nonnegative(clearance, "clearance"),
               _nonnegative(self_clearance, "self_clearance"))
        m = self._margins.get(key)
        if m is None:
            m = self._margins[key] = self.model.margins(*key)
            m.setflags(write=False)  # cached: shared by every query with these margins
        return m

    def _q(self, q: npt.ArrayLike, name: str) -> np.ndarray:
        a = check_finite(check_joints(q, self.n, name), name)
        return np.ascontiguousarray(a, dtype=np.float64).reshape(-1, self.n)

    def is_free(self, q: npt.ArrayLike, *, clearance: float = 0.0,
                self_clearance: float = 0.0) -> np.ndarray:
        """Whether each configuration is collision-free (farther than the margins).

        Args:
            q: Configurations (..., n) [rad, m].
            clearance: Robot-scene margin [m].
            self_clearance: Robot-robot margin [m].

        Returns:
            Bool array of q's leading shape.
        """
        qa = self._q(q, "q")
        rep = self.model.check_states(qa, self.margin(clearance, self_clearance))
        return rep.free.reshape(np.shape(q)[:-1])

    def edges_free(self, q0: npt.ArrayLike, q1: npt.ArrayLike, *, clearance: float = 0.0,
                   self_clearance: float = 0.0) -> np.ndarray:
        """Whether each straight joint-space edge ``q0[i] -> q1[i]`` is proven free.

        Conservative advancement: True means no configuration on the segment comes
        within the margins (never optimistic; a segment closer than ~1e-9 m to
        touching may count as not free).

        Args:
            q0: Edge starts (m, n) or (n,) [rad, m].
            q1: Edge ends, the same shape.
            clearance: Robot-scene margin [m].
            self_clearance: Robot-robot margin [m].

        Returns:
            (m,) bool.
        """
        a, b = self._q(q0, "q0"), self._q(q1, "q1")
        if a.shape != b.shape:
            raise InputError("q1", f"expected the shape of q0 {a.shape}, got {b.shape}")
        return self.model.check_edges(a, b, self.margin(clearance, self_clearance)).free

    def path_free(self, q: npt.ArrayLike, *, clearance: float = 0.0,
                  self_clearance: float = 0.0) -> bool:
        """Whether every straight segment of the path q (K, n) is proven free."""
        qa = self._q(q, "q")
        if qa.shape[0] == 1:
            return bool(self.is_free(qa[0], clearance=clearance,
                                     self_clearance=self_clearance))
        return bool(self.edges_free(qa[:-1], qa[1:], clearance=clearance,
                                    self_clearance=self_clearance).all())

    def describe(self, q: npt.ArrayLike, *, clearance: float = 0.0,
                 self_clearance: float = 0.0) -> str:
        """Why configuration q (n,) is not free ('' when it is): the pair and distance."""
        qa = self._q(q, "q")[0]
        margin = self.margin(clearance, self_clearance)
        rep = self.model.check_states(qa, margin)
        if bool(rep.free[0]):
            return ""
        return self._pair_text(qa, int(rep.pair[0]), margin)

    def _pair_text(self, q: np.ndarray, p: int, margin: np.ndarray) -> str:
        from robokin.kinematics.forward import link_frames

        a, b = self.model.names[p]
        d = self.model.problem.exact(p, link_frames(self.model.chain, q[None])[0])
        if d <= 0.0:
            return f"'{a}' collides with '{b}'"
        kind = "self_clearance" if self.model.is_self[p] else "clearance"
        return (f"'{a}' is {d:.4g} m from '{b}', within the {kind} "
                f"{float(margin[p]):.4g} m")

    # ---------------------------------------------------------------- query
    def plan(
        self,
        start: npt.ArrayLike,
        goal: npt.ArrayLike,
        *,
        time_limit: float = 1.0,
        seed: int = 0,
        planner: str = DEFAULT_PLANNER,
        clearance: float = 0.0,
        self_clearance: float = 0.0,
        planner_range: float | None = None,
        simplify: bool | int = True,
        smooth: bool = True,
        retime: bool = False,
        retime_options: dict[str, Any] | None = None,
    ) -> PlanResult:
        """A collision-free path from ``start`` to ``goal``.

        Args:
            start: The start configuration (n,) [rad, m].
            goal: A configuration (n,), a goal set (k, n), or a TCP pose (4, 4) in
                the world (every in-limit IK solution is a goal; see
                :mod:`robokin.planning.goals`).
            time_limit: Seconds from the call until a path is found [s]: the
                goals' IK and the checks of the ends count, the search gets what
                is left (shortening and smoothing after it are not cut short).
            seed: Seed of every random choice: the same inputs and seed give the
                same path (the compiled planner; when the time limit does not cut
                the search).
            planner: ``"rrtconnect"`` (compiled) or ``"ompl:<name>"``; see
                :data:`PLANNERS`.
            clearance: Distance the robot keeps from the scene [m].
            self_clearance: Distance the robot's links keep from each other [m].
            planner_range: Longest tree edge [rad, m] (default: 0.5, or a tenth of
                the diagonal of the joint-limit box if that is shorter; for OMPL's
                planners that have a range too).
            simplify: Shortcut the path (every new edge checked): True (20 attempts),
                False, or the number of attempts (more: a shorter path, later).
            smooth: Cut its corners (Chaikin; every new edge checked).
            retime: Also retime it (:meth:`trajectory`) into ``result.trajectory``.
            retime_options: Passed to :meth:`trajectory` (``v_max``, ``a_max``,
                ``j_max``, ``dt``, ...).

        Returns:
            A :class:`PlanResult`; on failure ``success`` is False and ``reason``
            says why (start in collision naming the pair, goals unreachable or in
            collision, time limit).

        Raises:
            InputError: a bad argument (naming it; an unknown planner lists the
                planners).
            MissingExtraError: an OMPL planner without ``robokin[plan]``.
        """
        t0, c0 = time.perf_counter(), time.process_time()
        if planner not in PLANNERS:
            raise InputError("planner", f"unknown planner {short_repr(planner)}; "
                             f"planners: {list(PLANNERS)}")
        limit = check_finite_number(time_limit, "time_limit")
        if limit <= 0:
            raise InputError("time_limit", f"expected seconds > 0, got {limit}")
        if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
            raise InputError("seed", f"expected a whole number >= 0, got {short_repr(seed)}")
        step = self._range(planner_range)
        q0 = self._q(start, "start")
        if q0.shape[0] != 1:
            raise InputError("start", f"expected one configuration ({self.n},), got "
                             f"{np.shape(start)}")
        q0 = q0[0]
        margin = self.margin(clearance, self_clearance)
        goals = goal_configurations(self.robot, goal, solver=self._solver)
        ends = self._check_ends(q0, goals, margin, t0 + limit)
        if isinstance(ends, str):
            return PlanResult(False, np.zeros((0, self.n)), ends,
                              time.perf_counter() - t0, planner, goals=goals.q)
        goals, free = ends
        stats: dict[str, Any] = {}
        while True:
            stats.update(goals=int(free.sum()), goal_rounds=goals.rounds)
            left = limit - (time.perf_counter() - t0)  # the goals' IK and checks count
            if left <= 0:
                return PlanResult(False, np.zeros((0, self.n)),
                                  f"no path found before the time limit ({limit:g} s): the "
                                  "goals and their checks took it", time.perf_counter() - t0,
                                  planner, goals=goals.q, stats=stats)
            # a manifold goal set may grow: its first goals get half the time left
            more = goals.can_grow
            path, goal_at, why, timed_out = self._search(
                planner, q0, goals.q[free], margin, (limit, left / 2 if more else left),
                int(seed), step, stats)
            if path is not None or not (timed_out and more):
                break
            goals, free = self._grow(goals, free, margin, t0 + limit)
        if path is None:
            return PlanResult(False, np.zeros((0, self.n)), why,
                              time.perf_counter() - t0, planner, goals=goals.q,
                              stats=stats)
        raw = path
        t1 = time.perf_counter()
        path = self._simplify(path, margin, int(seed), _tries(simplify), smooth, stats)
        stats.update(simplify_s=time.perf_counter() - t1, cpu_s=time.process_time() - c0)
        index = int(goals.index[np.flatnonzero(free)[goal_at]])
        elapsed = time.perf_counter() - t0
        traj = None
        if retime:
            traj = self.trajectory(path, clearance=clearance, self_clearance=self_clearance,
                                   **(retime_options or {}))
        return PlanResult(True, path, "solved", elapsed, planner,
                          goal=goals.q[free][goal_at], goal_index=index, goals=goals.q,
                          raw=raw, trajectory=traj, stats=stats)

    def _range(self, planner_range: float | None) -> float | None:
        if planner_range is None:
            return None
        v = check_finite_number(planner_range, "planner_range")
        if v <= 0:
            raise InputError("planner_range", f"expected a length > 0, got {v}")
        return v

    def _bounds(self, q0: np.ndarray, goals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Finite sampling bounds: the joint limits (where infinite: around the ends)."""
        lo, hi = self.limits[:, 0].copy(), self.limits[:, 1].copy()
        if self._finite:
            return lo, hi
        ends = np.vstack([q0[None], goals])
        bad_lo, bad_hi = ~np.isfinite(lo), ~np.isfinite(hi)
        lo[bad_lo] = ends.min(axis=0)[bad_lo] - math.pi
        hi[bad_hi] = ends.max(axis=0)[bad_hi] + math.pi
        return lo, hi

    def _check_ends(self, q0: np.ndarray, goals: Goals, margin: np.ndarray,
                    deadline: float) -> str | tuple[Goals, np.ndarray]:
        """The goals (grown while all collide) and which are free, or why not to start.

        ``deadline``: the :func:`time.perf_counter` time the query must end by.
        """
        why = outside_limits(q0, self.limits)
        if why:
            return f"the start is outside the joint limits: {why}"
        rep = self.model.check_states(q0, margin)
        if not bool(rep.free[0]):
            return "the start is in collision: " + self._pair_text(q0, int(rep.pair[0]),
                                                                    margin)
        if goals.q.shape[0] == 0:
            return goals.reason
        free = self.model.check_states(goals.q, margin).free
        if not free.any() and goals.can_grow:
            goals, free = self._grow(goals, free, margin, deadline)
        if not free.any():
            grep = self.model.check_states(goals.q[:1], margin)
            what = "the goal is" if goals.q.shape[0] == 1 else (
                f"every goal ({goals.q.shape[0]}) is")
            return (f"{what} in collision: " + self._pair_text(goals.q[0],
                                                               int(grep.pair[0]), margin))
        return goals, free

    def _grow(self, goals: Goals, free: np.ndarray, margin: np.ndarray,
              deadline: float) -> tuple[Goals, np.ndarray]:
        """Denser manifold rounds until one adds a free goal (or none is left, or time)."""
        while goals.can_grow and time.perf_counter() < deadline:
            goals, rows = goals.grown()
            new = (self.model.check_states(goals.q[rows], margin).free if len(rows)
                   else np.zeros(0, dtype=bool))
            free = np.concatenate([free, new])
            if new.any():
                break
        return goals, free

    def _search(self, planner: str, q0: np.ndarray, goals: np.ndarray,
                margin: np.ndarray, limits: tuple[float, float], seed: int,
                step: float | None, stats: dict[str, Any]
                ) -> tuple[np.ndarray | None, int, str, bool]:
        """Run the planner: (path, goal row, reason, whether the search timed out).

        ``limits``: the query's time limit (named in the reason) and the search's.
        """
        limit, left = limits
        lo, hi = self._bounds(q0, goals)
        if step is None:
            step = min(RANGE, RANGE_FRACTION * float(np.linalg.norm(hi - lo)))
        if planner == DEFAULT_PLANNER:
            opts = np.zeros(_k.RC_N_OPTS)
            opts[_k.RC_RANGE], opts[_k.RC_TIME] = step, left
            opts[_k.RC_MAX_NODES] = MAX_NODES
            code, path, goal_at, work, search = _k.plan_rrtc(
                self.model.capsule, q0, np.ascontiguousarray(goals), lo, hi, margin,
                opts, seed % 2**64, self.model.exact_callback)
            stats.update(_work(work), iterations=search[0], nodes=search[1] + search[2],
                         search_s=search[3])
            if code == _k.RC_SOLVED:
                return np.asarray(path), int(goal_at), "solved", False
            what = {_k.RC_TIMEOUT: f"the time limit ({limit:g} s)",
                    _k.RC_NODES: f"the node limit ({MAX_NODES})"}.get(code, "an error")
            return None, -1, (f"no path found before {what}: {search[0]} iterations, "
                              f"{search[1] + search[2]} tree nodes"), code == _k.RC_TIMEOUT
        t = time.perf_counter()
        out = ompl_plan(planner.split(":", 1)[1], self.n, lo, hi, q0, goals,
                        lambda q: bool(self.model.check_states(q, margin).free[0]),
                        lambda a, b: bool(self.model.check_edges(a, b, margin).free[0]),
                        left, step)
        stats.update(states=out.states, edges=out.edges, search_s=time.perf_counter() - t)
        if out.path is None:
            return None, -1, (f"no path found before the time limit ({limit:g} "
                              f"s): OMPL says {out.status!r}"), True
        path = out.path
        goal_at = int(np.argmin(np.linalg.norm(goals - path[-1], axis=1)))
        path[-1] = goals[goal_at]
        return path, goal_at, "solved", False

    def _simplify(self, path: np.ndarray, margin: np.ndarray, seed: int,
                  tries: int, smooth: bool, stats: dict[str, Any]) -> np.ndarray:
        """Shortcuts, then the sharp corners cut (csrc/plan_path.c), new edges checked."""
        if path.shape[0] <= 2 or not (tries or smooth):
            return path
        opts = np.zeros(_k.SP_N_OPTS)
        opts[_k.SP_VERTEX_TRIES], opts[_k.SP_TRIES] = tries // 2, tries
        opts[_k.SP_MAX_FAIL] = max(3, tries // 6)
        opts[_k.SP_TIME] = math.inf
        opts[_k.SP_CUT_ROUNDS] = SMOOTH_ROUNDS if smooth else 0
        opts[_k.SP_SHARP_TURN] = SHARP_TURN
        out, work = _k.plan_simplify(self.model.capsule, np.ascontiguousarray(path),
                                     margin, opts, (seed * 0x9E3779B1 + 1) % 2**64,
                                     self.model.exact_callback)
        stats["simplify_edges"] = _work(work)["edges"]
        return _drop_repeats(np.asarray(out))

    def simplify(self, path: npt.ArrayLike, *, seed: int = 0, shortcut: bool | int = True,
                 smooth: bool = True, clearance: float = 0.0,
                 self_clearance: float = 0.0) -> np.ndarray:
        """A shorter, smoother version of a collision-free path, same ends.

        Random shortcuts (deterministic for ``seed``), then Chaikin corner cutting
        of the corners sharp enough to stop the arm (:mod:`robokin.planning.smoothing`);
        every new segment is proven free with the margins, the others lie on the
        given segments.

        Args:
            path: Waypoints (K, n) [rad, m]; every segment free.
            seed: Seed of the shortcut choices.
            shortcut: Try shortcuts: True (20 attempts), False, or how many.
            smooth: Cut the sharp corners.
            clearance: Robot-scene margin [m].
            self_clearance: Robot-robot margin [m].

        Returns:
            The new waypoints (K', n).
        """
        q = self._q(path, "path")
        margin = self.margin(clearance, self_clearance)
        return self._simplify(q, margin, int(seed), _tries(shortcut), smooth, {})

    # ------------------------------------------------------------ retiming
    def trajectory(self, path: PlanResult | npt.ArrayLike, *, clearance: float = 0.0,
                   self_clearance: float = 0.0, **retime_options: Any) -> Trajectory:
        """A time-optimal trajectory along a collision-free path, every step checked.

        :func:`robokin.trajectory.retime` through the path's waypoints under the
        robot's limits, then every step between consecutive samples proven free
        as a straight edge; where one is not, the arm stops at both ends of the path
        segment beside it and follows that segment exactly
        (:func:`robokin.planning.smoothing.retime_checked`).

        Args:
            path: A successful :class:`PlanResult` or waypoints (K, n) [rad, m].
            clearance: Robot-scene margin of the check [m].
            self_clearance: Robot-robot margin of the check [m].
            **retime_options: ``v_max``, ``a_max``, ``j_max``, ``dt``, ... of
                :func:`robokin.trajectory.retime`.

        Raises:
            InputError: a failed plan, fewer than two waypoints, or a bad option.
        """
        if isinstance(path, PlanResult):
            if not path.success:
                raise InputError("path", f"the plan failed ({path.reason}): nothing to "
                                 "retime")
            path = path.q
        q = self._q(path, "path")
        if q.shape[0] < 2:
            raise InputError("path", f"expected at least 2 waypoints, got {q.shape[0]}")
        margin = self.margin(clearance, self_clearance)
        tr, _ = retime_checked(self.robot, q,
                               lambda a, b: self.model.check_edges(a, b, margin).free,
                               **retime_options)
        return tr


def _tries(simplify: bool | int) -> int:
    """Shortcut attempts of a ``simplify``/``shortcut`` argument."""
    if isinstance(simplify, bool | np.bool_):
        return SHORTCUT_TRIES if simplify else 0
    if not isinstance(simplify, int | np.integer) or not 0 <= simplify <= 1_000_000:
        raise InputError("simplify", f"expected True, False or a number of shortcut "
                         f"attempts (0 to 1,000,000), got {short_repr(simplify)}")
    return int(simplify)


def _work(stats: tuple[int, ...]) -> dict[str, int]:
    names = ("states", "bounds", "exact", "coal_calls", "edges", "unproven")
    return dict(zip(names, (int(v) for v in stats), strict=True))


def _drop_repeats(q: np.ndarray) -> np.ndarray:
    """The path without consecutive repeated waypoints."""
    if q.shape[0] < 2:
        return q
    keep = np.ones(q.shape[0], dtype=bool)
    keep[1:] = np.any(np.diff(q, axis=0) != 0.0, axis=1)
    return q[keep]


def plan(robot: Robot, scene: Scene, start: npt.ArrayLike, goal: npt.ArrayLike, *,
         time_limit: float = 1.0, seed: int = 0, **options: Any) -> PlanResult:
    """A collision-free path for one query (builds a :class:`Planner` for it).

    Args:
        robot: The robot (the scene places it).
        scene: The static scene.
        start: The start configuration (n,) [rad, m].
        goal: A configuration (n,), a goal set (k, n) or a TCP pose (4, 4) in the
            world.
        time_limit: Seconds from the call until a path is found [s] (see
            :meth:`Planner.plan`).
        seed: Seed of every random choice (same inputs, same path).
        **options: The other keywords of :meth:`Planner.plan`.

    Returns:
        A :class:`PlanResult`.
    """
    return Planner(robot, scene).plan(start, goal, time_limit=time_limit, seed=seed,
                                      **options)
