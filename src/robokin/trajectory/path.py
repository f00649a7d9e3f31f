"""Multi-segment paths through via points: joint moves, Cartesian lines, dwells.

Build a path step by step and sample it once::

    path = trajectory.PathBuilder(robot, q_home, dt=0.005, v_max=2.0, a_max=4.0)
    path.joint(q_above_pick)                 # joint-space move to a via point
    path.line(T_pick, duration=1.0)          # straight line down
    path.dwell(0.5)
    path.line(T_above_pick, duration=1.0)    # straight line up
    path.pose(T_press_front)                 # joint move to a pose (IK nearest)
    path.line(T_press_inside, duration=1.5)  # straight entry
    traj = path.build()

With ``smooth=True`` (the default) the arm does not stop at joint via points: the
velocities and accelerations at each via point come from a C2 cubic spline through
the consecutive joint via points, and each joint segment is the quintic meeting
them, so velocity *and* acceleration are continuous across every via point. A
Cartesian line ends at rest unless given ``speed_in`` / ``speed_out``; the joint
segment next to it then starts (ends) with the line's own joint velocity and
acceleration at the junction (``J^+ [v; w]``), so the junction is continuous too.
``stop=True`` on a via point, a dwell, or ``smooth=False`` make the arm halt there.

Durations are given per segment or derived from joint velocity and acceleration
limits (``v_max``, ``a_max``) and rounded up to whole samples; a smoothed run
whose spline overshoots the limits has its derived (never its given) durations
stretched until it keeps them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import numpy.typing as npt

from robokin._validation import check_finite, check_joints, check_transform
from robokin.exceptions import InputError, UnreachableError
from robokin.trajectory.cartesian import IKMode, PathError, cartesian_line
from robokin.trajectory.joint import (
    check_max_samples,
    evaluate_polynomial,
    quintic_coefficients,
    time_grid,
)
from robokin.trajectory.profiles import Profile, get_profile
from robokin.trajectory.samples import Trajectory

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["PathBuilder", "Segment", "via_path"]

Kind = Literal["joint", "line", "dwell"]


@dataclass
class Segment:
    """One step of a path (built by :class:`PathBuilder`).

    Attributes:
        kind: ``"joint"``, ``"line"`` or ``"dwell"``.
        q_end: Joint configuration at the end (n,).
        duration: [s] (None until resolved).
        profile: Time scaling of rest-to-rest joint moves and of lines.
        stop: The arm halts at the end of this segment.
        label: Free text shown in reports.
        T_goal: Goal pose of a line.
        speed_in: Line start speed [m/s].
        speed_out: Line end speed [m/s].
        line: The sampled line (set while building).
        given: The duration was given (never stretched to meet limits).
    """

    kind: Kind
    q_end: np.ndarray
    duration: float | None = None
    profile: Profile | None = None
    stop: bool = False
    label: str = ""
    T_goal: np.ndarray | None = None
    speed_in: float = 0.0
    speed_out: float = 0.0
    line: Trajectory | None = field(default=None, repr=False)
    given: bool = False


def _profile(seg: Segment) -> Profile:
    """The time scaling of a joint or line segment (a dwell has none)."""
    if seg.profile is None:
        raise InputError("profile", f"segment '{seg.label}' ({seg.kind}) has no time "
                         "scaling")
    return seg.profile


class PathBuilder:
    """Collects via points and segments, then samples the whole path at ``dt``.

    Args:
        robot: The :class:`~robokin.robot.Robot`.
        q_start: Start configuration (n,) [rad, m].
        dt: Sampling period [s] (0.005 = 200 Hz).
        v_max: Joint speed limits for derived durations, scalar or (n,).
        a_max: Joint acceleration limits, scalar or (n,).
        tool_speed: Largest tool speed on lines [m/s] for derived durations.
        tool_acceleration: Largest tool acceleration on lines [m/s^2].
        smooth: Pass through joint via points without stopping.
        ik: Path-following mode of lines (see :func:`cartesian_line`).
        max_samples: Most samples the whole path may hold (default
            :data:`robokin.trajectory.joint.MAX_SAMPLES`), checked before any
            segment is sampled.
    """

    def __init__(
        self, robot: Robot, q_start: npt.ArrayLike, *, dt: float = 0.005,
        v_max: npt.ArrayLike | None = None, a_max: npt.ArrayLike | None = None,
        tool_speed: float | None = None, tool_acceleration: float | None = None,
        smooth: bool = True, ik: IKMode = "follow", max_samples: int | None = None,
    ) -> None:
        """Check the start and the limits (see the class docstring)."""
        self.robot = robot
        n = robot.n
        q0 = check_finite(check_joints(q_start, n, "q_start"), "q_start")
        if q0.shape != (n,):
            raise InputError("q_start", f"expected shape ({n},), got {q0.shape}")
        if not dt > 0:
            raise InputError("dt", f"must be positive [s], got {dt!r}")
        self.q_start = q0.copy()
        self.dt = float(dt)
        self.v_max = None if v_max is None else np.broadcast_to(
            np.asarray(v_max, float), (n,)).copy()
        self.a_max = None if a_max is None else np.broadcast_to(
            np.asarray(a_max, float), (n,)).copy()
        self.tool_speed = tool_speed
        self.tool_acceleration = tool_acceleration
        self.smooth = smooth
        self.ik = ik
        check_max_samples(max_samples)
        self.max_samples = max_samples
        self.segments: list[Segment] = []

    # ----------------------------------------------------------------- adding
    @property
    def q_end(self) -> np.ndarray:
        """The configuration at the end of the path so far."""
        return self.segments[-1].q_end if self.segments else self.q_start

    def _duration(self, duration: float | None) -> float | None:
        if duration is None:
            return None
        d = float(duration)
        if not d > 0:
            raise InputError("duration", f"must be positive [s], got {duration!r}")
        return max(self.dt, math.ceil(d / self.dt - 1e-9) * self.dt)

    def joint(self, q: npt.ArrayLike, duration: float | None = None, *,
              profile: str | Profile = "quintic", stop: bool = False,
              label: str = "") -> PathBuilder:
        """Joint-space move to the via point ``q`` (n,) [rad, m]."""
        n = self.robot.n
        qv = check_finite(check_joints(q, n, "q"), "q")
        if qv.shape != (n,):
            raise InputError("q", f"expected shape ({n},), got {qv.shape}")
        self.segments.append(Segment("joint", qv.copy(), self._duration(duration),
                                     get_profile(profile), stop, label or "joint",
                                     given=duration is not None))
        return self

    def pose(self, T: npt.ArrayLike, duration: float | None = None, *,
             profile: str | Profile = "quintic", stop: bool = False,
             label: str = "",
             method: Literal["auto", "analytic", "numeric"] = "auto") -> PathBuilder:
        """Joint-space move to the IK solution of pose ``T`` nearest the current end.

        Raises:
            UnreachableError: ``T`` has no solution within the joint limits.
        """
        T = check_transform(T, "T")
        q_near = self.q_end
        sols = self.robot.ik(T, q_near=q_near, method=method)
        try:
            q = sols.nearest(q_near)
        except UnreachableError as exc:
            raise UnreachableError(f"via point {len(self.segments) + 1} "
                                   f"({label or 'pose'}): {exc}") from None
        return self.joint(q, duration, profile=profile, stop=stop, label=label or "pose")

    def line(self, T_goal: npt.ArrayLike, duration: float | None = None, *,
             profile: str | Profile = "quintic", speed_in: float = 0.0,
             speed_out: float = 0.0, label: str = "") -> PathBuilder:
        """Straight tool line from the current end to ``T_goal`` (4, 4) [m].

        The line is followed immediately (so the next via point knows where the
        arm is); its failure raises at once.

        Raises:
            PathError: the line cannot be followed (index, time, reason).
        """
        T1 = check_transform(T_goal, "T_goal")
        seg_no = len(self.segments) + 1
        try:
            tr = cartesian_line(
                self.robot, self.q_end, T1, self._duration(duration), self.dt,
                profile=profile, speed_in=speed_in, speed_out=speed_out,
                v_max=self.v_max, a_max=self.a_max, tool_speed=self.tool_speed,
                tool_acceleration=self.tool_acceleration, ik=self.ik,
                max_samples=self.max_samples)
        except PathError as exc:
            exc.args = (f"segment {seg_no} ({label or 'line'}): {exc.args[0]} "
                        "(time from the segment start)",)
            raise
        if speed_in and not (self.segments and self.segments[-1].kind == "joint"):
            raise InputError("speed_in", "a line may start moving only after a joint "
                             "segment (which then blends into it)")
        self.segments.append(Segment("line", tr.q[-1].copy(), tr.duration,
                                     get_profile(profile), not speed_out,
                                     label or "line", T1, speed_in, speed_out, tr))
        return self

    def dwell(self, duration: float, *, label: str = "") -> PathBuilder:
        """Stay still for ``duration`` [s]."""
        self.segments.append(Segment("dwell", self.q_end.copy(),
                                     self._duration(duration), None, True,
                                     label or "dwell"))
        return self

    # --------------------------------------------------------------- building
    def _rest_duration(self, seg: Segment, q_from: np.ndarray) -> float:
        if self.v_max is None and self.a_max is None:
            raise InputError("duration", f"segment '{seg.label}' has no duration and "
                             "the path no v_max / a_max to derive one")
        T = _profile(seg).min_duration(seg.q_end - q_from, self.v_max, self.a_max)
        return max(self.dt, math.ceil(T / self.dt - 1e-9) * self.dt)

    def build(self, *, progress: Any = None) -> Trajectory:
        """Sample the whole path.

        Args:
            progress: Optional callable ``progress(done, total)`` per segment.

        Returns:
            The :class:`Trajectory` (``via_times`` at every segment junction,
            ``labels`` per segment, ``pose`` the tool poses).

        Raises:
            InputError: no segments, or a duration that cannot be derived.
        """
        if not self.segments:
            raise InputError("segments", "the path has no segments")
        segs = self.segments
        for a, b in zip(segs, segs[1:]):
            if a.kind == "line" and a.speed_out and b.kind != "joint":
                raise InputError("speed_out", f"line '{a.label}' ends moving, so a "
                                 "joint segment must follow it")
        starts = [self.q_start] + [s.q_end for s in segs[:-1]]
        durations: list[float] = []
        for seg, q_from in zip(segs, starts):
            if seg.duration is None:
                seg.duration = self._rest_duration(seg, q_from)
            durations.append(seg.duration)
        self._check_samples(segs, durations)
        # Boundary conditions per junction: (qd, qdd) or None (free: via point).
        n = self.robot.n
        zero = np.zeros(n)
        k = len(segs)
        bc: list[tuple[np.ndarray, np.ndarray] | None] = [None] * (k + 1)
        bc[0] = bc[k] = (zero, zero)
        for i, seg in enumerate(segs):
            if seg.line is not None:  # a line segment (sampled when added)
                bc[i] = (seg.line.qd[0], seg.line.qdd[0])
                bc[i + 1] = (seg.line.qd[-1], seg.line.qdd[-1])
            elif seg.kind == "dwell" or seg.stop or not self.smooth:
                bc[i + 1] = (zero, zero) if bc[i + 1] is None else bc[i + 1]
                if seg.kind == "dwell":
                    bc[i] = (zero, zero)
        if not self.smooth:
            bc = [(zero, zero) if b is None else b for b in bc]
        coeffs = self._joint_coefficients(segs, starts, bc)
        parts = []
        for i, (seg, dur, c) in enumerate(zip(segs, durations, coeffs)):
            if seg.line is not None:  # a line segment
                parts.append(seg.line.replace(labels=(seg.label,), pose=None))
            else:
                t = time_grid(dur, self.dt, max_samples=self.max_samples)
                if seg.kind == "dwell":
                    m = t.size
                    q = np.broadcast_to(seg.q_end, (m, n))
                    parts.append(Trajectory(t, q, np.zeros((m, n)), np.zeros((m, n)),
                                            labels=(seg.label,)))
                elif c is None:  # rest-to-rest with its own profile
                    s, sd, sdd = _profile(seg).scale(t, dur)
                    d = seg.q_end - starts[i]
                    parts.append(Trajectory(t, starts[i] + s[:, None] * d,
                                            sd[:, None] * d, sdd[:, None] * d,
                                            labels=(seg.label,)))
                else:
                    parts.append(Trajectory(t, *evaluate_polynomial(c, t, dur),
                                            labels=(seg.label,)))
            if progress is not None:
                progress(i + 1, k)
        traj = Trajectory.concatenate(parts)
        return traj.replace(joint_names=self.robot.joint_names,
                            is_revolute=self.robot.is_revolute,
                            pose=self.robot.fk(traj.q))

    def _check_samples(self, segs: list[Segment], durations: list[float]) -> None:
        """Refuse a path of more than ``max_samples`` samples before sampling it."""
        cap = check_max_samples(self.max_samples)
        total = 0.0
        for i, (seg, duration) in enumerate(zip(segs, durations)):
            total += duration / self.dt + 1.0
            if total > cap:
                raise InputError(
                    "max_samples",
                    f"the path reaches {total:,.0f} samples at dt {self.dt:g} s by "
                    f"segment {i + 1} ('{seg.label}', {duration:g} s), more "
                    f"than the limit of {cap:,} (pass max_samples= to raise it)")

    def _joint_coefficients(self, segs, starts, bc) -> list[np.ndarray | None]:
        """Quintic coefficients of every joint segment (None: plain profile move)."""
        out: list[np.ndarray | None] = [None] * len(segs)
        i = 0
        while i < len(segs):
            if segs[i].kind != "joint":
                i += 1
                continue
            j = i
            while j + 1 < len(segs) and segs[j + 1].kind == "joint" and bc[j + 1] is None:
                j += 1
            run = list(range(i, j + 1))
            rest = (all(b is not None and not b[0].any() and not b[1].any()
                        for b in (bc[i], bc[j + 1])) and len(run) == 1)
            if rest and _profile(segs[i]).name != "quintic":
                i = j + 1  # a single rest-to-rest move keeps its own profile
                continue
            self._fit_run(segs, starts, bc, run, out)
            i = j + 1
        return out

    def _fit_run(self, segs, starts, bc, run, out) -> None:
        """Spline-smoothed quintics through a run of joint via points."""
        from scipy.interpolate import CubicSpline

        first, last = run[0], run[-1]
        pts = np.array([starts[first]] + [segs[r].q_end for r in run])
        for _ in range(8):
            dur = np.array([segs[r].duration for r in run])
            tv = np.concatenate([[0.0], np.cumsum(dur)])
            (v0, a0), (v1, a1) = bc[first], bc[last + 1]
            if len(run) > 1:
                sp = CubicSpline(tv, pts, bc_type=((1, v0), (1, v1)), axis=0)
                vel, acc = sp(tv, 1), sp(tv, 2)
            else:
                vel = np.array([v0, v1])
                acc = np.array([a0, a1])
            vel[0], vel[-1], acc[0], acc[-1] = v0, v1, a0, a1
            worst = 1.0
            for k, r in enumerate(run):
                c = quintic_coefficients(pts[k], pts[k + 1], dur[k], vel[k], vel[k + 1],
                                         acc[k], acc[k + 1])
                out[r] = c
                if self.v_max is None and self.a_max is None:
                    continue
                tt = np.linspace(0.0, dur[k], 64)
                _, qd, qdd = evaluate_polynomial(c, tt, dur[k])
                if self.v_max is not None:
                    worst = max(worst, float((np.abs(qd) / self.v_max).max()))
                if self.a_max is not None:
                    worst = max(worst, math.sqrt(float((np.abs(qdd) / self.a_max).max())))
            free = [r for r in run if not segs[r].given]
            if worst <= 1.0 + 1e-9 or not free:
                return
            for r in free:  # stretch the derived durations and refit
                segs[r].duration = max(self.dt, math.ceil(
                    segs[r].duration * worst * 1.02 / self.dt - 1e-9) * self.dt)


def via_path(
    robot: Robot, q_start: npt.ArrayLike, steps: list[dict[str, Any]], *,
    dt: float = 0.005, **options: Any,
) -> Trajectory:
    """Build a path from a list of steps (the dict form of :class:`PathBuilder`).

    Each step is one of ``{"joint": q, ...}``, ``{"pose": T, ...}``,
    ``{"line": T, ...}``, ``{"dwell": seconds}``; other keys (``duration``,
    ``profile``, ``stop``, ``label``, ``speed_in``, ``speed_out``) pass through.

    Raises:
        InputError: a step of unknown kind.
    """
    pb = PathBuilder(robot, q_start, dt=dt, **options)
    for i, step in enumerate(steps):
        step = dict(step)
        kinds = [k for k in ("joint", "pose", "line", "dwell") if k in step]
        if len(kinds) != 1:
            raise InputError(f"steps[{i}]", "needs exactly one of joint, pose, line, "
                             f"dwell; got keys {sorted(step)}")
        kind = kinds[0]
        value = step.pop(kind)
        if kind == "dwell":
            pb.dwell(value, **step)
        else:
            getattr(pb, kind)(value, **step)
    return pb.build()
