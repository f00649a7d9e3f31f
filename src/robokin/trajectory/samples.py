"""The :class:`Trajectory` value: a motion sampled in time, plus limit checks.

A trajectory is what a controller consumes: times ``t`` (m,) [s] and, per sample,
joint positions ``q`` (m, n) [rad or m], velocities ``qd`` and accelerations
``qdd``. Stored arrays are read-only; every method returns a new value.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import numpy.typing as npt

from robokin._validation import frozen_floats
from robokin.exceptions import InputError

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["LimitReport", "LimitViolation", "Trajectory"]

Space = Literal["joint", "actuator"]


@dataclass(frozen=True, eq=False)
class Trajectory:
    """A sampled motion.

    Attributes:
        t: Sample times [s], shape (m,), increasing.
        q: Joint positions [rad or m], shape (m, n).
        qd: Joint velocities [rad/s or m/s], shape (m, n).
        qdd: Joint accelerations [rad/s^2 or m/s^2], shape (m, n).
        joint_names: One name per column, or None.
        pose: Tool poses (m, 4, 4) in the world frame when known (Cartesian
            segments set it), else None; :meth:`tool_poses` computes it.
        via_times: Times [s] of the via points (segment junctions, start and
            end included), shape (k,).
        space: ``"joint"``, or ``"actuator"`` for motor coordinates.
        is_revolute: (n,) bool, angles (True) or lengths (False); None when
            unknown (every column then counts as an angle in files).
        labels: One label per segment (between consecutive via times), or empty.
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    joint_names: tuple[str, ...] | None = None
    pose: np.ndarray | None = None
    via_times: np.ndarray = field(default_factory=lambda: np.empty(0))
    space: Space = "joint"
    is_revolute: np.ndarray | None = None
    labels: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        """Check the shapes and times; freeze the arrays."""
        t = frozen_floats(self.t, "t", ndim=1)
        q = frozen_floats(self.q, "q", ndim=2)
        m, n = q.shape
        if t.shape[0] != m:
            raise InputError("t", f"expected {m} times for {m} samples, got {t.shape[0]}")
        if m > 1 and not (np.diff(t) > 0).all():
            raise InputError("t", "times must be strictly increasing")
        qd = frozen_floats(self.qd, "qd", ndim=2)
        qdd = frozen_floats(self.qdd, "qdd", ndim=2)
        for name, arr in (("qd", qd), ("qdd", qdd)):
            if arr.shape != (m, n):
                raise InputError(name, f"expected shape {(m, n)}, got {arr.shape}")
        pose = None if self.pose is None else frozen_floats(self.pose, "pose", ndim=3)
        if pose is not None and pose.shape != (m, 4, 4):
            raise InputError("pose", f"expected shape {(m, 4, 4)}, got {pose.shape}")
        names = self.joint_names
        if names is not None:
            names = tuple(str(s) for s in names)
            if len(names) != n:
                raise InputError("joint_names", f"expected {n} names, got {len(names)}")
        rev = self.is_revolute
        if rev is not None:
            rev = np.array(rev, dtype=bool).reshape(-1)
            if rev.shape != (n,):
                raise InputError("is_revolute", f"expected {n} flags, got {rev.shape}")
            rev.setflags(write=False)
        via = frozen_floats(self.via_times, "via_times", ndim=1)
        for k, v in (("t", t), ("q", q), ("qd", qd), ("qdd", qdd), ("pose", pose),
                     ("joint_names", names), ("is_revolute", rev), ("via_times", via),
                     ("labels", tuple(self.labels))):
            object.__setattr__(self, k, v)

    # ------------------------------------------------------------------ basics
    @property
    def n(self) -> int:
        """Number of joints (columns)."""
        return self.q.shape[1]

    def __len__(self) -> int:
        """Number of samples m."""
        return self.t.shape[0]

    @property
    def duration(self) -> float:
        """Last time minus first time [s]."""
        return float(self.t[-1] - self.t[0]) if len(self) else 0.0

    @property
    def dt(self) -> float:
        """The (median) sampling period [s]."""
        return float(np.median(np.diff(self.t))) if len(self) > 1 else 0.0

    def names(self) -> tuple[str, ...]:
        """Joint names, ``q1 .. qn`` when none were given."""
        return self.joint_names or tuple(f"q{i + 1}" for i in range(self.n))

    def revolute(self) -> np.ndarray:
        """(n,) bool: angle columns (all True when unknown)."""
        return np.ones(self.n, bool) if self.is_revolute is None else self.is_revolute

    def replace(self, **changes: Any) -> Trajectory:
        """A copy with some fields replaced."""
        kw = {f: getattr(self, f) for f in self.__dataclass_fields__}
        kw.update(changes)
        return Trajectory(**kw)

    def __repr__(self) -> str:
        """A short summary: samples, joints, duration, space."""
        return (f"Trajectory(samples={len(self)}, joints={self.n}, "
                f"duration={self.duration:.6g} s, space={self.space!r})")

    # -------------------------------------------------------------- operations
    def _repr_html_(self) -> str:
        """Jupyter: samples, duration, a small plot of the joints and their peaks.

        The plot shows at most :data:`robokin._html.MAX_POINTS` samples per
        joint (degrees for angles, mm for lengths): bounded for any length.
        """
        from robokin import _html

        rev = self.revolute()
        scale = np.where(rev, 180.0 / np.pi, 1000.0)
        peaks = self.peaks()
        rows = [[name, "deg" if r else "mm", lo * k, hi * k, v * k, a * k]
                for name, r, k, lo, hi, v, a in zip(
                    self.names(), rev, scale, peaks["min"], peaks["max"],
                    peaks["velocity"], peaks["acceleration"])]
        unit = "deg" if rev.all() else "mm" if not rev.any() else "deg / mm"
        return _html.box(
            f"Trajectory: {len(self):,} samples, {self.duration:.3f} s, "
            f"{self.n} joints, {max(len(self.via_times) - 2, 0)} via points",
            _html.line_plot(self.t, self.q * scale, labels=self.names()[:10],
                            xlabel="t [s]", ylabel=f"q [{unit}]"),
            _html.table(["joint", "unit", "min", "max", "peak |vel| /s",
                         "peak |acc| /s²"], rows))

    def at(self, times: npt.ArrayLike) -> np.ndarray:
        """Joint positions at arbitrary times (linear interpolation), (k,) -> (k, n).

        Times outside ``[t[0], t[-1]]`` hold the end values.
        """
        tt = np.asarray(times, dtype=np.float64)
        return np.stack([np.interp(tt, self.t, self.q[:, j]) for j in range(self.n)],
                        axis=-1)

    def shifted(self, dt: float) -> Trajectory:
        """The same motion with every time moved by ``dt`` [s]."""
        pose = self.pose
        return self.replace(t=self.t + dt, via_times=self.via_times + dt, pose=pose)

    def tool_poses(self, robot: Robot) -> np.ndarray:
        """Tool poses (m, 4, 4) [m]: the stored ones, or ``robot.fk(q)``."""
        if self.pose is not None:
            return self.pose
        q = self.q if self.space == "joint" else robot.joints_from_actuators(self.q)
        return robot.fk(q)

    def to_actuator_space(self, robot: Robot) -> Trajectory:
        """Motor coordinates ``phi = A^+ (q - b)``, ``phid = A^+ qd``, ``phidd = A^+ qdd``.

        The identity (a copy relabelled ``space="actuator"``) when the robot has no
        actuator map.

        Raises:
            InputError: the trajectory is already in actuator space or has the
                wrong number of joints.
            ModelError: the actuator matrix cannot be inverted.
        """
        if self.space != "joint":
            raise InputError("space", "the trajectory is already in actuator space")
        if self.n != robot.n:
            raise InputError("robot", f"has {robot.n} joints, the trajectory {self.n}")
        A = robot.actuators
        if A is None:
            return self.replace(space="actuator", joint_names=self.joint_names)
        what = f"actuator map of '{robot.name}'"
        names = robot.actuator_names
        return self.replace(
            q=A.inverse(self.q, what=what), qd=A.inverse_rate(self.qd, what=what),
            qdd=A.inverse_rate(self.qdd, what=what), space="actuator",
            joint_names=names, is_revolute=np.ones(A.n_in, bool),
        )

    def to_joint_space(self, robot: Robot) -> Trajectory:
        """Back from motor coordinates: ``q = A phi + b`` (and rates)."""
        if self.space != "actuator":
            return self
        A = robot.actuators
        if A is None:
            return self.replace(space="joint", joint_names=robot.joint_names)
        return self.replace(q=A.apply(self.q), qd=A.apply_rate(self.qd),
                            qdd=A.apply_rate(self.qdd), space="joint",
                            joint_names=robot.joint_names,
                            is_revolute=robot.is_revolute)

    @staticmethod
    def concatenate(parts: Sequence[Trajectory]) -> Trajectory:
        """Join trajectories end to start; a repeated junction sample is kept once.

        Each part is shifted so it starts where the previous one ended.
        """
        if not parts:
            raise InputError("parts", "need at least one trajectory")
        ts, qs, qds, qdds, poses, vias = [], [], [], [], [], []
        t0 = parts[0].t[0]
        have_pose = all(p.pose is not None for p in parts)
        for k, p in enumerate(parts):
            shift = t0 - p.t[0]
            sl = slice(1 if k else 0, None)
            ts.append(p.t[sl] + shift)
            qs.append(p.q[sl])
            qds.append(p.qd[sl])
            qdds.append(p.qdd[sl])
            if have_pose and p.pose is not None:
                poses.append(p.pose[sl])
            vias.append(p.via_times + shift if p.via_times.size else
                        np.array([p.t[0] + shift, p.t[-1] + shift]))
            t0 = p.t[-1] + shift
        via = np.unique(np.round(np.concatenate(vias), 12))
        first = parts[0]
        return Trajectory(np.concatenate(ts), np.concatenate(qs), np.concatenate(qds),
                          np.concatenate(qdds), joint_names=first.joint_names,
                          pose=np.concatenate(poses) if have_pose else None,
                          via_times=via, space=first.space,
                          is_revolute=first.is_revolute,
                          labels=tuple(lb for p in parts for lb in p.labels))

    # ------------------------------------------------------------------ limits
    def peaks(self) -> dict[str, np.ndarray]:
        """Per joint (n,): peak ``|qd|``, peak ``|qdd|``, min and max ``q``."""
        return {
            "velocity": np.abs(self.qd).max(axis=0) if len(self) else np.zeros(self.n),
            "acceleration": np.abs(self.qdd).max(axis=0) if len(self) else np.zeros(self.n),
            "min": self.q.min(axis=0), "max": self.q.max(axis=0),
        }

    def check_limits(
        self,
        robot: Robot | None = None,
        *,
        position: npt.ArrayLike | None = None,
        velocity: npt.ArrayLike | float | None = None,
        acceleration: npt.ArrayLike | float | None = None,
        tol: float = 1e-9,
    ) -> LimitReport:
        """Every stretch of samples where a joint leaves its limits.

        Args:
            robot: Takes position limits from ``robot.limits`` (joint space) or
                ``robot.actuator_limits`` (actuator space) unless ``position``
                is given.
            position: Limits (n, 2) [rad or m].
            velocity: Largest ``|qd|``, a scalar or (n,) [rad/s or m/s].
            acceleration: Largest ``|qdd|``, a scalar or (n,) [rad/s^2 or m/s^2].
            tol: Slack before a sample counts as a violation.

        Returns:
            A :class:`LimitReport` listing each violation with its time span.
        """
        n = self.n
        if position is None and robot is not None:
            position = robot.limits if self.space == "joint" else robot.actuator_limits
        out: list[LimitViolation] = []
        names = self.names()
        if position is not None:
            lim = np.asarray(position, dtype=float).reshape(n, 2)
            out += _stretches("position", self.q < lim[:, 0] - tol, self, self.q,
                              lim[:, 0], names, below=True)
            out += _stretches("position", self.q > lim[:, 1] + tol, self, self.q,
                              lim[:, 1], names)
        for kind, arr, limit in (("velocity", self.qd, velocity),
                                 ("acceleration", self.qdd, acceleration)):
            if limit is None:
                continue
            lim = np.broadcast_to(np.asarray(limit, dtype=float), (n,))
            out += _stretches(kind, np.abs(arr) > lim + tol, self, np.abs(arr), lim, names)
        out.sort(key=lambda v: (v.t_start, v.joint, v.kind))
        return LimitReport(tuple(out))


@dataclass(frozen=True)
class LimitViolation:
    """One joint outside one limit for a stretch of consecutive samples.

    Attributes:
        kind: ``"position"``, ``"velocity"`` or ``"acceleration"``.
        joint: Joint index (0-based).
        joint_name: Its name.
        first_index: First sample outside the limit.
        last_index: Last sample of the stretch.
        t_start: Time of ``first_index`` [s].
        t_end: Time of ``last_index`` [s].
        worst: The value furthest past the limit (``|qd|``/``|qdd|`` for rates).
        limit: The limit crossed.
    """

    kind: str
    joint: int
    joint_name: str
    first_index: int
    last_index: int
    t_start: float
    t_end: float
    worst: float
    limit: float

    def __str__(self) -> str:
        """One line: the limit, the worst value and when."""
        return (f"{self.kind} of {self.joint_name} at {self.worst:.6g} beyond "
                f"{self.limit:.6g} from t = {self.t_start:.4f} s to {self.t_end:.4f} s")


@dataclass(frozen=True)
class LimitReport:
    """The violations found by :meth:`Trajectory.check_limits` (empty when none).

    Attributes:
        violations: Ordered by start time.
    """

    violations: tuple[LimitViolation, ...]

    @property
    def ok(self) -> bool:
        """True when no limit is violated."""
        return not self.violations

    def __bool__(self) -> bool:
        """True when no limit is violated."""
        return self.ok

    def __len__(self) -> int:
        """The number of violations."""
        return len(self.violations)

    def __iter__(self):
        """Each violation in turn."""
        return iter(self.violations)

    def first(self) -> LimitViolation | None:
        """The earliest violation, or None."""
        return self.violations[0] if self.violations else None

    def __str__(self) -> str:
        """One line per violated limit, or that none is."""
        if not self.violations:
            return "no limit violated"
        return "\n".join(str(v) for v in self.violations)


def _stretches(kind: str, bad: np.ndarray, traj: Trajectory, values: np.ndarray,
               limit: np.ndarray, names: Sequence[str], below: bool = False
               ) -> list[LimitViolation]:
    out = []
    for j in np.flatnonzero(bad.any(axis=0)):
        col = bad[:, j].astype(np.int8)
        edges = np.diff(np.concatenate([[0], col, [0]]))
        starts = np.flatnonzero(edges == 1)
        ends = np.flatnonzero(edges == -1) - 1
        for s, e in zip(starts, ends):
            seg = values[s:e + 1, j]
            worst = seg.min() if below else seg.max()
            out.append(LimitViolation(kind, int(j), names[int(j)], int(s), int(e),
                                      float(traj.t[s]), float(traj.t[e]),
                                      float(worst), float(limit[j])))
    return out
