"""Time-optimal retiming: the same path, run as fast as the joint limits allow.

::

    from robokin import trajectory
    fast = trajectory.retime(robot, traj)                 # limits from the robot file
    fast = trajectory.retime(robot, traj, v_max=2.0, a_max=8.0, j_max=None, dt=0.005)
    res = trajectory.retime_detailed(robot, traj)         # + sections, limits, jerk
    slow = res.slowed(cycle_time=12.0)                    # the same path in 12 s

The geometric path of ``traj`` (any planner's output: joint moves, Cartesian lines,
via points with their blends, or a bare (m, n) array of joint positions) is kept
and only the time law along it changes. Where the source stops (a rest-to-rest
segment, a corner, a dwell) the retimed motion stops too; dwells keep their
duration unless ``keep_dwells=False``. Between stops the fastest time law within
the per-joint speed and acceleration limits (and an optional tool speed) comes
from TOPP-RA through ``toppra``; with jerk limits, from ``ruckig``. The methods,
their accuracy and the sources are in ``docs/retiming.md``; the pieces live in
:mod:`robokin.trajectory._retime_path` (the path) and
:mod:`robokin.trajectory._retime_laws` (the time laws).

**Every sample within the limits.** The result is sampled every ``dt`` with its
exact derivatives (``qd = q' sd``, ``qdd = q'' sd^2 + q' sdd``, the jerk likewise)
and checked on every sample and on every node of the time law; a stretch whose
largest ratio to a limit exceeds 1 is slowed by exactly that ratio (velocity
ratios scale as 1/c, acceleration as 1/c^2, jerk as 1/c^3) and checked again, so
no sample exceeds a limit by more than rounding. The slow-down applied is reported
per stretch (``SectionTiming.stretch``; 1.0 where none was needed).

**Exact end.** Samples fall at ``0, dt, 2 dt, ...`` and a last one at the exact
end, so the duration is the minimum time itself, not rounded up to a whole
number of samples (``round_to_dt=True`` stretches the motion to the next whole
sample instead, for a controller that needs a fixed period).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, Literal, TypedDict

import numpy as np
import numpy.typing as npt
from typing_extensions import Unpack

from robokin.exceptions import InputError
from robokin.trajectory._retime_laws import (
    ConstAccelLaw,
    RuckigLaw,
    TimeLaw,
    jerk_limited_law,
    topp_ra_law,
)
from robokin.trajectory._retime_path import Piece, source_of, split_path
from robokin.trajectory.joint import check_max_samples
from robokin.trajectory.samples import Trajectory

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["RetimeLimits", "RetimeResult", "SectionTiming", "retime",
           "retime_detailed"]

#: How many times a stretch is re-checked (and slowed) before giving up.
_CHECK_ROUNDS = 6
#: Slack of the final check, relative (the target is "no excess beyond 1e-6").
_CHECK_TOL = 1e-12

LimitArg = npt.ArrayLike | None


# ----------------------------------------------------------------------- limits
@dataclass(frozen=True, eq=False)
class RetimeLimits:
    """The limits a retiming keeps to (SI).

    Attributes:
        velocity: Joint speed limits [rad/s or m/s], shape (n,).
        acceleration: Joint acceleration limits [rad/s^2 or m/s^2], shape (n,).
        jerk: Joint jerk limits [rad/s^3 or m/s^3], shape (n,), or None.
        tool_speed: Largest tool-point speed [m/s], or None.
        sources: Per kind (``"velocity"``, ...), where the values come from:
            ``"argument"`` or the robot file's ``rate_limits`` source.
    """

    velocity: np.ndarray
    acceleration: np.ndarray
    jerk: np.ndarray | None = None
    tool_speed: float | None = None
    sources: dict[str, str] = field(default_factory=dict)


def _per_joint(value: Any, kind: str, arg: str, robot: Robot, n: int,
               names: tuple[str, ...]) -> np.ndarray:
    """One positive finite limit per joint, from the argument or the robot file."""
    if value is None:
        lim = getattr(robot, "rate_limits", None)
        arr = None if lim is None else lim.get(kind)
        name = getattr(robot, "name", "robot")
        if arr is None:
            raise InputError(arg, f"robot '{name}' has no {kind} limits (a "
                             f"rate_limits section in its robot file); pass {arg}=")
        unknown = np.flatnonzero(np.isnan(arr))
        if unknown.size:
            raise InputError(arg, f"robot '{name}' gives no {kind} limit for joint "
                             f"{names[unknown[0]]}; pass {arg}=")
        return np.asarray(arr, float)
    try:
        out = np.broadcast_to(np.asarray(value, dtype=float), (n,)).copy()
    except (TypeError, ValueError):
        raise InputError(arg, f"expected one number or {n} (one per joint), got "
                         f"{value!r}") from None
    bad = ~(np.isfinite(out) & (out > 0))
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise InputError(arg, f"every {kind} limit must be a positive finite number; "
                         f"got {float(out[k])!r} for joint {names[k]}")
    return out


def resolve_limits(robot: Robot, n: int, names: tuple[str, ...], v_max: LimitArg,
                   a_max: LimitArg, j_max: LimitArg | Literal["robot"],
                   tool_speed: float | None) -> RetimeLimits:
    """The limits of one call: arguments first, then the robot file.

    Raises:
        InputError: naming the argument: a zero, negative or non-finite limit, the
            wrong count, or a limit neither given nor in the robot file.
    """
    src_file = getattr(getattr(robot, "rate_limits", None), "source", "") or "robot file"
    sources = {}
    v = _per_joint(v_max, "velocity", "v_max", robot, n, names)
    sources["velocity"] = "argument" if v_max is not None else src_file
    a = _per_joint(a_max, "acceleration", "a_max", robot, n, names)
    sources["acceleration"] = "argument" if a_max is not None else src_file
    j = None
    if j_max is not None:
        from_file = isinstance(j_max, str)
        if from_file and j_max != "robot":
            raise InputError("j_max", f"expected limits, None or 'robot', got {j_max!r}")
        j = _per_joint(None if from_file else j_max, "jerk", "j_max", robot, n, names)
        sources["jerk"] = src_file if from_file else "argument"
    if tool_speed is not None:
        if isinstance(tool_speed, bool) or not (
                isinstance(tool_speed, int | float) and math.isfinite(tool_speed)
                and tool_speed > 0):
            raise InputError("tool_speed", f"must be a positive finite speed [m/s], "
                             f"got {tool_speed!r}")
        sources["tool_speed"] = "argument"
    return RetimeLimits(v, a, j, None if tool_speed is None else float(tool_speed),
                        sources)


# ----------------------------------------------------------------------- result
@dataclass(frozen=True)
class SectionTiming:
    """One stretch of the retimed motion (a rest-to-rest move or a dwell).

    Attributes:
        kind: ``"move"`` or ``"dwell"``.
        label: The source segment label at its middle ('' when unknown).
        method: ``"toppra"``, ``"ruckig"`` or ``"dwell"``.
        t_start: Start in the retimed motion [s].
        t_end: End in the retimed motion [s].
        source_start: Start in the source [s] (sample index for a bare path).
        source_end: End in the source [s].
        stretch: How many times slower than its own time-optimal law it runs: the
            final check's slow-down (1.0 when none was needed) times any asked
            for (a slower cycle time, ``round_to_dt``); 1.0 for a dwell.
    """

    kind: str
    label: str
    method: str
    t_start: float
    t_end: float
    source_start: float
    source_end: float
    stretch: float = 1.0

    @property
    def duration(self) -> float:
        """``t_end - t_start`` [s]."""
        return self.t_end - self.t_start

    @property
    def source_duration(self) -> float:
        """``source_end - source_start`` [s]."""
        return self.source_end - self.source_start


@dataclass(frozen=True, eq=False)
class _Plan:
    """What a retiming computed, kept to re-sample it (slower, rounded)."""

    robot: Robot
    pieces: list[Piece]
    laws: list[TimeLaw | None]
    dwell: list[float]
    limits: RetimeLimits
    dt: float
    source_t: np.ndarray | None
    source_via: np.ndarray
    labels: tuple[str, ...]
    joint_names: tuple[str, ...]
    is_revolute: np.ndarray
    max_samples: int


@dataclass(frozen=True, eq=False)
class RetimeResult:
    """A retimed motion and how it was made.

    Attributes:
        trajectory: The retimed :class:`Trajectory` (``pose`` set to the tool poses).
        jerk: Joint jerk at every sample [rad/s^3 or m/s^3], shape (m, n), exact
            (the trajectory holds positions, velocities and accelerations).
        limits: The limits it keeps to.
        sections: One :class:`SectionTiming` per move and dwell.
        source_duration: Duration of the source [s] (None for a bare path).
    """

    trajectory: Trajectory
    jerk: np.ndarray
    limits: RetimeLimits
    sections: tuple[SectionTiming, ...]
    source_duration: float | None
    _plan: _Plan = field(repr=False)

    @property
    def robot(self) -> Any:
        """The robot it was retimed for."""
        return self._plan.robot

    @property
    def duration(self) -> float:
        """The cycle time [s]: the motion and the kept dwells."""
        return self.trajectory.duration

    @property
    def dwell_time(self) -> float:
        """Time spent in dwells [s]."""
        return float(sum(s.duration for s in self.sections if s.kind == "dwell"))

    @property
    def motion_time(self) -> float:
        """Time spent moving [s]."""
        return self.duration - self.dwell_time

    def slowed(self, cycle_time: float) -> RetimeResult:
        """The same path retimed to a longer cycle time.

        Every move is stretched by one factor ``c = (cycle_time - dwells) /
        (motion time)``, so every velocity falls by ``1/c``, every acceleration by
        ``1/c^2`` and every jerk by ``1/c^3``: the margins to the limits are the
        same everywhere and as large as the cycle time allows. Dwells keep their
        duration.

        Args:
            cycle_time: The wanted duration [s], at least :attr:`duration`.

        Raises:
            InputError: ``cycle_time`` below the minimum (or not a number).
        """
        target = cycle_time
        if isinstance(target, bool) or not (isinstance(target, int | float)
                                            and math.isfinite(target)):
            raise InputError("cycle_time", f"expected a duration [s], got {target!r}")
        if target < self.duration * (1 - 1e-12):
            raise InputError("cycle_time", f"{target:.6g} s is shorter than the "
                             f"minimum cycle time {self.duration:.6g} s of this path "
                             "under these limits")
        return _stretch_all(self, (target - self.dwell_time) / self.motion_time)


# --------------------------------------------------------------------- sampling
@dataclass(frozen=True)
class _Samples:
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    qddd: np.ndarray
    piece: np.ndarray      # (m,) index of the piece each sample belongs to
    offsets: np.ndarray    # (P + 1,) start of each piece, then the end


def _durations(plan: _Plan, laws: list[TimeLaw | None]) -> np.ndarray:
    return np.array([plan.dwell[k] if law is None else law.duration
                     for k, law in enumerate(laws)])


def _time_grid(T: float, dt: float, cap: int) -> np.ndarray:
    """Sample times ``0, dt, 2 dt, ...`` and the exact end ``T``.

    ``T`` replaces the last multiple of ``dt`` when that is within 1e-6 dt of it.
    """
    k = math.floor(T / dt * (1 + 1e-12))
    if k + 2 > cap:
        raise InputError("dt", f"the retimed motion of {T:.6g} s at dt {dt:g} s needs "
                         f"{k + 2:,} samples, more than the limit of {cap:,}")
    t = np.arange(k + 1) * dt
    if T - t[-1] <= 1e-6 * dt:
        t[-1] = T
        return t
    return np.concatenate([t, [T]])


def _evaluate(path: Any, law: TimeLaw, tau: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Joint position, velocity, acceleration and jerk at law times ``tau``."""
    s, sd, sdd, sddd = law.evaluate(tau)
    d1, d2, d3 = path(s, 1), path(s, 2), path(s, 3)
    sd_, sdd_, sddd_ = sd[:, None], sdd[:, None], sddd[:, None]
    return (path(s), d1 * sd_, d2 * sd_**2 + d1 * sdd_,
            d3 * sd_**3 + 3.0 * d2 * sd_ * sdd_ + d1 * sddd_)


def _sample(plan: _Plan, laws: list[TimeLaw | None]) -> _Samples:
    dur = _durations(plan, laws)
    off = np.concatenate([[0.0], np.cumsum(dur)])
    t = _time_grid(float(off[-1]), plan.dt, plan.max_samples)
    m, n = t.size, plan.is_revolute.size
    piece = np.clip(np.searchsorted(off, t, side="right") - 1, 0, len(laws) - 1)
    out = [np.zeros((m, n)) for _ in range(4)]
    for k, (pc, law) in enumerate(zip(plan.pieces, laws)):
        idx = np.flatnonzero(piece == k)
        if not idx.size:
            continue
        if law is None:
            out[0][idx] = _dwell_q(plan, pc)
            continue
        vals = _evaluate(pc.path, law, t[idx] - off[k])
        for o, v in zip(out, vals):
            o[idx] = v
    return _Samples(t, out[0], out[1], out[2], out[3], piece=piece, offsets=off)


def _dwell_q(plan: _Plan, pc: Piece) -> np.ndarray:
    """Where a dwell stands: the end of the move before it, or the start of the next."""
    k = plan.pieces.index(pc)
    for other in plan.pieces[k - 1::-1] if k else []:
        if other.path is not None:
            return np.asarray(other.path(other.path.length))
    for other in plan.pieces[k + 1:]:
        if other.path is not None:
            return np.asarray(other.path(0.0))
    raise AssertionError("unreachable: split_path refuses a path that does not move")


def _ratios(plan: _Plan, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
            qddd: np.ndarray) -> np.ndarray:
    """Per sample, the largest ratio to a limit, each kind made linear in 1/c."""
    lim = plan.limits
    r = np.abs(qd) / lim.velocity
    r = np.maximum(r, np.sqrt(np.abs(qdd) / lim.acceleration))
    if lim.jerk is not None:
        r = np.maximum(r, np.cbrt(np.abs(qddd) / lim.jerk))
    out = r.max(axis=1)
    if lim.tool_speed is not None:
        v = np.einsum("kij,kj->ki", plan.robot.jacobian(q)[..., :3, :], qd)
        out = np.maximum(out, np.linalg.norm(v, axis=1) / lim.tool_speed)
    result: np.ndarray = out
    return result


def _law_checkpoints(law: TimeLaw) -> np.ndarray:
    """Times inside a law where a limit is most likely at its peak."""
    base = getattr(law, "base", law)
    c = getattr(law, "factor", 1.0)
    if isinstance(base, ConstAccelLaw):
        t = base.t
        pts = np.concatenate([t, (t[:-1] + t[1:]) / 2])
    elif isinstance(base, RuckigLaw):
        t = base.phase_t
        pts = np.concatenate([t, (t[:-1] + t[1:]) / 2])
    else:  # pragma: no cover - every law is one of the two
        pts = np.linspace(0.0, base.duration, 1001)
    return np.asarray(pts * c)


def _check(plan: _Plan, laws: list[TimeLaw | None], samples: _Samples
           ) -> list[float]:
    """Per piece, the largest limit ratio on its samples and its law's nodes."""
    worst = [0.0] * len(laws)
    ratio = _ratios(plan, samples.q, samples.qd, samples.qdd, samples.qddd)
    for k, (pc, law) in enumerate(zip(plan.pieces, laws)):
        if law is None:
            continue
        on = ratio[samples.piece == k]
        nodes = _ratios(plan, *_evaluate(pc.path, law, _law_checkpoints(law)))
        worst[k] = float(max(on.max(initial=0.0), nodes.max()))
    return worst


def _stretch_all(result: RetimeResult, factor: float) -> RetimeResult:
    """Every move of a result run ``factor`` (>= 1) times slower, dwells kept."""
    c = max(1.0, factor)
    laws = [None if law is None else law.stretched(c) for law in result._plan.laws]
    return _finish(result._plan, laws)


def _finish(plan: _Plan, laws: list[TimeLaw | None]) -> RetimeResult:
    """Sample, check every sample, and package the result.

    A stretch that exceeds a limit is slowed by its ratio and checked again.
    """
    laws = list(laws)
    for round_ in range(_CHECK_ROUNDS):
        samples = _sample(plan, laws)
        worst = _check(plan, laws, samples)
        over = [k for k, w in enumerate(worst) if w > 1.0 + _CHECK_TOL]
        if not over:
            break
        # A stretched law's samples fall elsewhere along the path and can meet a
        # peak the last ones missed (a dense spline through many knots: each round
        # found about a tenth of the last excess, never settling in six rounds):
        # from the third round on the slow-down carries a margin growing 1000x a
        # round (4e-9 in the third, 4e-6 in the fourth: microseconds on a motion).
        margin = 4 * _CHECK_TOL * 1000.0 ** max(round_ - 1, 0)
        for k in over:
            c = worst[k] * (1.0 + margin)
            law = laws[k]
            assert law is not None
            laws[k] = law.stretched(c)
    else:  # pragma: no cover - each round removes the excess it measured
        raise AssertionError("the limit check did not settle")
    return _package(replace(plan, laws=laws), samples)


def _package(plan: _Plan, smp: _Samples) -> RetimeResult:
    laws = plan.laws
    off = smp.offsets
    new_via, sections = _timings(plan, laws, off)
    labels = plan.labels if len(plan.labels) == new_via.size - 1 else ()
    traj = Trajectory(smp.t, smp.q, smp.qd, smp.qdd, joint_names=plan.joint_names,
                      pose=plan.robot.fk(smp.q), via_times=new_via,
                      is_revolute=plan.is_revolute, labels=labels)
    src = None if plan.source_t is None else float(plan.source_t[-1] - plan.source_t[0])
    jerk = smp.qddd
    jerk.setflags(write=False)
    return RetimeResult(traj, jerk, plan.limits, sections, src, plan)


def _new_time(plan: _Plan, laws: list[TimeLaw | None], off: np.ndarray,
              tau: float) -> float:
    """Where source time (or sample index) ``tau`` falls in the retimed motion."""
    src = plan.source_t if plan.source_t is not None else np.arange(
        plan.pieces[-1].last + 1, dtype=float)
    for k, pc in enumerate(plan.pieces):
        a, b = src[pc.first], src[pc.last]
        if tau > b and k < len(plan.pieces) - 1:
            continue
        law = laws[k]
        if law is None or pc.s is None:
            frac = 0.0 if b <= a else float(np.clip((tau - a) / (b - a), 0.0, 1.0))
            return float(off[k] + frac * (off[k + 1] - off[k]))
        s = np.interp(tau, src[pc.first:pc.last + 1], pc.s)
        return float(off[k] + law.time_at(np.array([s]))[0])
    return float(off[-1])


def _timings(plan: _Plan, laws: list[TimeLaw | None], off: np.ndarray
             ) -> tuple[np.ndarray, tuple[SectionTiming, ...]]:
    via = np.array([_new_time(plan, laws, off, float(v)) for v in plan.source_via])
    via[0], via[-1] = 0.0, off[-1]
    via = np.maximum.accumulate(via)
    src = plan.source_t if plan.source_t is not None else np.arange(
        plan.pieces[-1].last + 1, dtype=float)
    sections = []
    for k, (pc, law) in enumerate(zip(plan.pieces, laws)):
        a, b = float(src[pc.first]), float(src[pc.last])
        label = ""
        if plan.labels and plan.source_via.size == len(plan.labels) + 1:
            i = int(np.searchsorted(plan.source_via, (a + b) / 2, side="right")) - 1
            label = plan.labels[min(max(i, 0), len(plan.labels) - 1)]
        sections.append(SectionTiming(
            pc.kind, label, "dwell" if law is None else law.method.split(" ")[0],
            float(off[k]), float(off[k + 1]), a, b,
            float(getattr(law, "factor", 1.0))))
    return via, tuple(sections)


# ----------------------------------------------------------------- public entry
class _RetimeKeywords(TypedDict, total=False):
    """The keywords of :func:`retime_detailed`, which :func:`retime` passes on."""

    v_max: LimitArg
    a_max: LimitArg
    j_max: LimitArg | Literal["robot"]
    dt: float
    tool_speed: float | None
    keep_dwells: bool
    round_to_dt: bool
    grid_points: int | None
    max_samples: int | None


def retime_detailed(
    robot: Robot,
    traj: Any,
    *,
    v_max: LimitArg = None,
    a_max: LimitArg = None,
    j_max: LimitArg | Literal["robot"] = None,
    dt: float = 0.005,
    tool_speed: float | None = None,
    keep_dwells: bool = True,
    round_to_dt: bool = False,
    grid_points: int | None = None,
    max_samples: int | None = None,
) -> RetimeResult:
    """Retime a path to the shortest time within the joint limits (see :func:`retime`).

    Returns:
        A :class:`RetimeResult`: the trajectory, its exact jerk, the limits used,
        one :class:`SectionTiming` per move and dwell; ``.slowed(T)`` gives the
        same path in a longer cycle time ``T``.
    """
    from robokin.trajectory.path import PathBuilder

    if isinstance(traj, PathBuilder):
        traj = traj.build()
    if isinstance(traj, Trajectory) and traj.space != "joint":
        traj = traj.to_joint_space(robot)
    if not (isinstance(dt, int | float) and math.isfinite(dt) and dt > 0):
        raise InputError("dt", f"must be a positive sampling period [s], got {dt!r}")
    cap = check_max_samples(max_samples)
    if grid_points is not None and not (isinstance(grid_points, int)
                                        and 2 <= grid_points <= 1_000_000):
        raise InputError("grid_points", f"expected a count in 2 .. 1000000, got "
                         f"{grid_points!r}")
    q, t, qd = source_of(traj)
    n = robot.n
    if q.ndim != 2 or q.shape[1] != n:
        raise InputError("traj", f"robot '{robot.name}' has {n} joints, the path has "
                         f"shape {q.shape}")
    names = tuple(robot.joint_names)
    limits = resolve_limits(robot, n, names, v_max, a_max, j_max, tool_speed)
    pieces = split_path(q, t, qd)
    laws: list[TimeLaw | None] = []
    for pc in pieces:
        if pc.path is None:
            laws.append(None)
        elif limits.jerk is not None:
            laws.append(jerk_limited_law(pc.path, limits.velocity, limits.acceleration,
                                         limits.jerk, robot=robot,
                                         tool_speed=limits.tool_speed))
        else:
            laws.append(topp_ra_law(pc.path, limits.velocity, limits.acceleration,
                                    robot=robot, tool_speed=limits.tool_speed,
                                    grid_points=grid_points))
    if isinstance(traj, Trajectory):
        via = traj.via_times if traj.via_times.size >= 2 else traj.t[[0, -1]]
        labels, jn, rev = traj.labels, traj.joint_names or names, traj.revolute()
    else:
        via = np.array([float(pc.first) for pc in pieces] + [float(pieces[-1].last)])
        labels, jn, rev = (), names, np.asarray(robot.is_revolute)
    plan = _Plan(robot, pieces, laws,
                 [pc.duration if keep_dwells else 0.0 for pc in pieces], limits,
                 float(dt), t, np.asarray(via, float), tuple(labels), tuple(jn),
                 np.asarray(rev, bool), cap)
    result = _finish(plan, laws)
    if not round_to_dt:
        return result
    T = result.duration
    T_round = math.ceil(T / dt * (1 - 1e-12)) * dt
    return _stretch_all(result, (T_round - result.dwell_time) / result.motion_time)


def retime(robot: Robot, traj: Any, **options: Unpack[_RetimeKeywords]) -> Trajectory:
    """The same path, time-optimal within per-joint velocity and acceleration limits.

    Args:
        robot: The :class:`~robokin.robot.Robot` (its ``rate_limits`` are the
            default limits; its Jacobian gives the tool speed).
        traj: The path: a :class:`Trajectory` (joint moves, Cartesian lines, via
            points with blends; motor-space ones are converted), a
            :class:`~robokin.trajectory.PathBuilder`, or joint positions (m, n)
            [rad, m] (a C2 spline through them).
        v_max: Joint speed limits [rad/s or m/s], one number or (n,); default the
            robot file's.
        a_max: Joint acceleration limits [rad/s^2 or m/s^2]; default the robot
            file's.
        j_max: Joint jerk limits [rad/s^3 or m/s^3]; None (default): no jerk
            limit; ``"robot"``: the robot file's. With jerk limits each stretch is
            a ruckig profile (time-optimal for straight joint moves, conservative
            on curved stretches; see ``docs/retiming.md``).
        dt: Sampling period [s].
        tool_speed: Largest tool-point speed [m/s] (the TCP, ``robot.fk``), or None.
        keep_dwells: Keep the source's dwells (else they take no time).
        round_to_dt: Stretch the motion so the duration is a whole number of
            ``dt`` (every step exactly ``dt``); default: the exact minimum time,
            with a shorter last step.
        grid_points: TOPP-RA grid intervals per stretch, uniform (default: the
            path's spline knots, at least 100).
        max_samples: Most samples the result may hold (default
            :data:`robokin.trajectory.joint.MAX_SAMPLES`).

    Returns:
        The retimed :class:`Trajectory` (``pose`` the tool poses, ``via_times``
        the source's via points at their new times, the source's labels). It
        starts and ends at rest and stops where the source stops.

    Raises:
        InputError: naming the argument: a zero, negative or non-finite limit, a
            limit neither given nor in the robot file, a path that jumps (it
            would need an infinite joint velocity), a path that does not move,
            the wrong number of joints, a bad ``dt`` or ``max_samples``, more
            than ``max_samples`` samples (naming ``dt``).
        MissingExtraError: toppra (or ruckig, for jerk limits) is not installed
            (``pip install 'robokin[retime]'``).

    References:
        Pham, H., Pham, Q.-C., "A New Approach to Time-Optimal Path
        Parameterization Based on Reachability Analysis", IEEE T-RO 34(3), 2018.
        Berscheid, L., Kroeger, T., "Jerk-limited Real-time Trajectory
        Generation with Arbitrary Target States", RSS 2021.
    """
    return retime_detailed(robot, traj, **options).trajectory
