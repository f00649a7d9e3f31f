"""The branches of one pose's self-motion: the swivel and held-joint families.

(The continued family of arms without a held-joint closed form is in
:mod:`~robokin.kinematics.ik.self_motion_continued`.)

Each family gives ``rows(t)`` (every branch at parameter values t) and the exact
parameter values where a joint equals a value (``points``), for
:mod:`~robokin.kinematics.ik.self_motion` (the module docstring there says how they
are used). The SRS swivel's rows and intervals are compiled (``csrc/self_motion.c``;
``reference=True`` keeps its numpy twin).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from robokin.exceptions import InputError
from robokin.kinematics.arm import Arm, Derived
from robokin.kinematics.ik.fixed import Dispatch, solve_held_one
from robokin.kinematics.ik.self_motion_base import (
    _Family,
    _into_limits,
    seven_joint_serial,
)
from robokin.kinematics.ik.self_motion_polish import LimitPolish
from robokin.kinematics.ik.swivel import SwivelArm, swivel_arm

_TWO_PI = 2 * np.pi


@dataclass(frozen=True)
class LimitCrossing:
    """A branch meeting a joint limit: ``joint`` (0-based) at ``limit`` ("lower"/"upper")."""

    t: float
    branch: int
    joint: int
    limit: str


@dataclass(frozen=True)
class SingularPoint:
    """A singular point of a branch: ``kind`` "fold" or "aligned axes"."""

    t: float
    branch: int
    kind: str


#: A compiled kernel's aligned-axes points of one branch whose parameter values differ
#: by at most this [rad] are one record (:func:`one_per_point`). Measured (session 23,
#: the Panda's held-joint kernel on 3,395 uniform, special and quarter-turn poses):
#: successive points of one branch and joint 0-3e-11 apart (18,000 repeats), then one
#: pair at 3e-8, two at 3e-6, the rest 3e-3 and more; of two joints, 1e-10 and more.
ALIGNED_SAME = 1e-9


def one_per_point(points: np.ndarray, aligned: int) -> np.ndarray:
    """A kernel's points (p, 4) ``[t, branch, joint, kind]``, one row per aligned point.

    Each run of aligned-axes rows (kind ``aligned``) of one branch, successive t at
    most :data:`ALIGNED_SAME` apart, is reduced to its middle row; the other rows and
    the order are kept.

    The kernels mark an aligned point again at each refinement that meets it: the
    Panda's held-joint kernel up to 74 times within 3e-12 of t where the shoulder is
    aligned at the generating configuration (157 records where 11 are distinct), both
    kernels twice where two joints are aligned at one t (the records do not name the
    joint: two equal records). Aligned points cut no interval: only the records change.
    """
    idx = np.flatnonzero(points[:, 3] == aligned)
    if len(idx) < 2:
        return points
    rows = points[idx]
    order = np.lexsort((rows[:, 0], rows[:, 1]))
    rows, idx = rows[order], idx[order]
    new = np.ones(len(idx), dtype=bool)  # each row opens a run unless it continues one
    new[1:] = (rows[1:, 1] != rows[:-1, 1]) | (rows[1:, 0] - rows[:-1, 0] > ALIGNED_SAME)
    start = np.flatnonzero(new)
    end = np.append(start[1:], len(idx))
    keep = np.ones(len(points), dtype=bool)
    keep[idx] = False
    keep[idx[(start + end - 1) // 2]] = True  # the others' rows and each run's middle
    return points[keep]


class _SwivelFamily(_Family):
    periodic = True
    domain = (-np.pi, np.pi)
    name = "swivel"
    joint = None

    def __init__(self, arm: SwivelArm, T: np.ndarray, robot: Arm, reference: bool = False
                 ) -> None:
        self.arm = arm
        self.T = np.ascontiguousarray(T, dtype=np.float64)
        self.robot = robot
        self.reference = reference
        self._fr: dict[str, Any] | None = None

    @property
    def fr(self) -> dict[str, Any]:
        """The numpy twin's per-pose constants (built when first needed)."""
        if self._fr is None:
            self._fr = self.arm.frame(self.T)
        return self._fr

    def rows(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        if self.reference:  # the numpy twin (the tests' reference)
            q, real, sing = self.arm.configurations(self.fr, t)
            q, ok = _polish(self.robot, q, real, self.T)
            return q, ok, sing
        t = np.atleast_1d(np.asarray(t, dtype=np.float64))
        Q, valid, sing = self.arm.rows(self.T[None], t[None])
        return Q[0], valid[0], sing[0]

    def exact(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The compiled intervals (m, 2), their branches (m,) and points (p, 4).

        The points are the kernel's rows ``[psi, branch, joint, kind]`` (kind
        ``SM_KIND_*``); ``self_motion._records_of`` makes them records when read.
        """
        return self.arm.manifold_one(self.T)[:3]

    def param_of(self, q: np.ndarray) -> float:
        return float(self.arm.swivel_of(self.fr, q))

    def candidates(self, j: int, value: float) -> list[tuple[float, np.ndarray | None]]:
        if j == 3:
            return []  # the elbow does not move with the swivel
        return [(psi, None) for psi, _ in self.arm.limit_swivels(self.fr, j, value)]


class _JointFamily(_Family):
    """A family over a held joint: its candidates are the pose solved with j held."""

    robot: Arm
    dispatch: Dispatch
    T: np.ndarray
    joint: int

    def candidates(self, j: int, value: float) -> list[tuple[float, np.ndarray | None]]:
        sols = solve_held_one(self.robot, self.T, j, value, dispatch=self.dispatch)
        if "swivel" in str(sols.info.get("measured", "")) and j == 3:
            return []  # the SRS elbow held: a family, constant on the manifold
        out: list[tuple[float, np.ndarray | None]] = []
        for row in sols.q[sols.valid]:
            t = _shift_into(float(row[self.joint]), self.domain)
            if t is not None:
                out.append((t, row))
        return out


class _HeldFamily(_JointFamily):
    def __init__(self, robot: Arm, params: np.ndarray, j: int, T: np.ndarray,
                 dispatch: Dispatch, named: tuple[str, tuple[float, float]] | None = None
                 ) -> None:
        """``named``: the joint's name and limits when the caller has them (else read)."""
        self.robot = robot
        self.dispatch = dispatch
        self.params = params
        self.joint = j
        if named is None:
            lo, hi = (float(x) for x in robot.limits[j])
            named = (robot.joint_names[j], (lo, hi))
        self.name, self.domain = named
        self.T = T
        self._polisher: LimitPolish | None = None
        n = robot.n
        #: the kernel's preferred coordinates at singularities (``raw_solve``'s default)
        self.qn = np.zeros((1, n))
        #: the kernel's rows (Q (8, n), valid, singular (8,)) of kept values, by t's bits
        self.kept: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
        self.kept_shape: tuple[int, ...] = (8, n)
        #: rows near a limit refined (``polisher``); off once the compiled kernel
        #: certified the manifold: its crossings and ends are on the unrefined rows,
        #: and a refined row there moves by up to ~6e-12 (the Panda), past the slack
        self.polish = True

    @property
    def polisher(self) -> LimitPolish:
        """Rows next to a limit refined on the pose; T repeated for the kernel calls.

        Built on first use: a certified compiled pose computes no row
        (``self_motion``'s held path; ~4 us of per-arm arrays a pose otherwise).
        """
        if self._polisher is None:
            self._polisher = LimitPolish(self.robot, self.joint, self.T)
        return self._polisher

    def _solved(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The closed form's Q (m, 8, n), valid, singular (m, 8) at t (m,) contiguous float64.

        The pose repeated from ``polisher.repeated`` (kept, grown as needed), not broadcast and
        copied per call.
        """
        from robokin.kinematics.ik.analytic import pieper as pk

        Q, valid, sing, _, _ = pk.raw_solve(self.params, self.polisher.repeated(len(t)), t,
                                            self.qn)
        return Q, valid, sing

    def _distinct(self, t: np.ndarray, keep: bool = False
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``_solved`` at each distinct value of t (by its bits), once: (Q, valid, sing, i).

        Q (u, 8, n), valid and sing (u, 8) per distinct value; i (m,) the distinct
        value of each t. Values in ``kept`` (the kernel's rows of earlier calls with
        ``keep``) are not solved again, and with ``keep`` this call's are kept (up to
        ``_KEPT`` values): the exact points' values, which ``_points_refined`` solves
        again (issue 29, helper iiwapy30). The kernel's rows are a function of (T, t)
        alone, so a kept row is the row a new solve gives.
        """
        keys = t.view(np.int64).tolist()
        first: dict[int, int] = {}
        i = np.array([first.setdefault(x, len(first)) for x in keys], dtype=np.intp)
        u = t if len(first) == len(keys) else np.array(list(first), dtype=np.int64).view(np.float64)
        kept = self.kept
        old = [k for k, x in enumerate(first) if x in kept] if kept else []
        if old:
            Q = np.empty((len(u),) + self.kept_shape)
            valid = np.empty((len(u), self.kept_shape[0]), dtype=bool)
            sing = np.empty((len(u), self.kept_shape[0]), dtype=bool)
            new = np.setdiff1d(np.arange(len(u)), old)
            if len(new):
                Q[new], valid[new], sing[new] = self._solved(np.ascontiguousarray(u[new]))
            for k, x in zip(old, [x for x in first if x in kept], strict=True):
                Q[k], valid[k], sing[k] = kept[x]
        else:
            Q, valid, sing = self._solved(u)
        if keep and len(kept) + len(u) <= _KEPT:
            self.kept_shape = Q.shape[1:]
            for k, x in enumerate(first):
                kept[x] = (Q[k], valid[k], sing[k])
        return Q, valid, sing, i

    def rows(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return self._rows(t, keep=True)

    def sample_rows(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``rows(t)`` solved directly, neither looked up among the kept rows nor kept.

        The user's values (``SelfMotion.sample`` and ``inside``): the kept rows serve
        the construction's repeated small calls, and their per-value dictionary costs
        ~0.6 us a value against the closed form's ~2 (the Panda's ``sample`` per
        (pose, value) 2.3 -> 2.9 us through it). The same rows bit for bit: a
        kernel's row is a function of (T, t) alone.
        """
        return self._rows(t, keep=False)

    def _rows(self, t: np.ndarray, keep: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``rows(t)``; ``keep``: distinct values solved once, small calls' rows kept."""
        t = np.ascontiguousarray(np.atleast_1d(t), dtype=np.float64)
        if not keep or len(t) > _KEPT:  # (the grid: its values distinct, not kept)
            Q, valid, sing = self._solved(t)
            Q = Q.copy()
        else:
            Q, valid, sing, i = self._distinct(t, keep=True)
            Q, valid, sing = Q[i], valid[i], sing[i]
        Q[~valid] = np.nan
        Q = _into_limits(self.robot, Q)
        if self.polish:
            self.polisher(Q, valid, sing)
        return Q, valid, sing

    def slot_rows(self, t: np.ndarray, b: np.ndarray, read: np.ndarray | None = None
                  ) -> tuple[np.ndarray, np.ndarray]:
        """``rows(t)``'s slot b[i] at t[i], only those rows refined (``polisher``).

        The bisections read one slot per value (a fold's only its validity: ``read``
        False, not refined); refining every slot of every value was most of the
        refinement's cost on the rtb-data iiwa14 (issue 29, helper polish29). The
        rows read are ``rows(t)``'s bit for bit: every step is per row, but for an
        exactly singular held Jacobian, which refines none of its call's rows (not met).
        Each distinct value of t (by its bits) is solved once: the slots of a fold
        (2 or 4: a quartic root pair, each with its two wrists) are bisected on the
        same values, ~4 rows per value on the rtb-data iiwa14 (issue 29, helper
        iiwapy30). Where no row is read (a step of fold bisections only) the rows
        come back as the kernel gives them (not shifted into the limits either).
        """
        t = np.ascontiguousarray(np.atleast_1d(t), dtype=np.float64)
        Q, valid, sing, i = self._distinct(t)
        q, v = Q[i, b], valid[i, b]
        if read is not None and not read.any():
            return q, v
        q[~v] = np.nan
        q = _into_limits(self.robot, q)
        if not self.polish:
            return q, v
        if read is None or read.all():
            self.polisher(q[:, None], v[:, None], sing[i, b][:, None])
        else:
            r = np.flatnonzero(read)
            qr = q[r]
            self.polisher(qr[:, None], v[r, None], sing[i[r], b[r], None])
            q[r] = qr
        return q, v

    def validity(self, t: np.ndarray) -> np.ndarray:
        """``rows(t)``'s valid, the kernel's (refining a row changes no validity)."""
        t = np.ascontiguousarray(np.atleast_1d(t), dtype=np.float64)
        _, valid, _, i = self._distinct(t)
        out: np.ndarray = valid[i]
        return out


#: Values whose kernel rows a held family keeps (``_HeldFamily._distinct``): a call
#: with more (the checking grid) is neither kept nor looked up.
_KEPT = 256


def _shift_into(t: float, domain: tuple[float, float]) -> float | None:
    """T shifted by whole turns into the closed domain (1e-9 slack, clamped), or None.

    The slack is ``within_limits``' 1e-9: a held-joint row with the parameter joint
    at its own limit comes back up to a few 1e-12 past it where the held Jacobian is
    ill-conditioned (the rtb-data iiwa14, joint_a4 held at its limit with joint_a3
    at its: 2.4e-12 out), and dropping it lost that limit crossing and the interval
    it bounds (issue 29, ``benchmarks/self_motion_rates.py``).
    """
    lo, hi = domain
    for s in (0.0, _TWO_PI, -_TWO_PI):
        if lo - 1e-9 <= t + s <= hi + 1e-9:
            return min(max(t + s, lo), hi)
    return None


def _polish(robot: Arm, q: np.ndarray, real: np.ndarray, T: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray]:
    """Rows whose pose error exceeds 1e-13 get minimum-norm Gauss-Newton steps.

    The error is the larger of the position [m] and rotation [rad] norms. A step
    is kept only where it lowers it; rows still above 5e-13 (next to a singular
    point of the closed form) are dropped (NaN, not valid).
    """
    from robokin.kinematics.forward import forward_kinematics
    from robokin.kinematics.jacobian import jacobian_and_pose
    from robokin.spatial import pose_error

    ok = real.copy()
    rows = np.flatnonzero(ok.reshape(-1))
    if not rows.size:
        return q, ok
    flat = q.reshape(-1, q.shape[-1])
    e = pose_error(forward_kinematics(robot.chain, flat[rows]), T)
    for _ in range(3):
        bad = _size(e) > 1e-13
        if not bad.any():
            break
        rows, e = rows[bad], e[bad]
        J, _ = jacobian_and_pose(robot.chain, flat[rows])
        trial = flat[rows] + np.einsum("mij,mj->mi", np.linalg.pinv(J), e)
        et = pose_error(forward_kinematics(robot.chain, trial), T)
        better = _size(et) < _size(e)
        flat[rows[better]] = trial[better]
        e = np.where(better[:, None], et, e)
    lost = rows[_size(e) > 5e-13]
    flat[lost] = np.nan
    ok.reshape(-1)[lost] = False
    return flat.reshape(q.shape), ok


def _size(e: np.ndarray) -> np.ndarray:
    """The larger of the position and rotation norms of pose errors (..., 6)."""
    out: np.ndarray = np.maximum(np.linalg.norm(e[..., :3], axis=-1), np.linalg.norm(e[..., 3:], axis=-1))
    return out


@dataclass(frozen=True, slots=True, eq=False)
class HeldKernel:
    """The compiled held-joint family of one arm: what ``held_manifold`` takes per call.

    Built once per arm (``SelfMotionSetup.held``) from the family ``self_motion``
    chose for ``"auto"``, so later calls skip the family choice and the per-call
    arrays.

    Attributes:
        params: The Pieper closed form's parameters (contiguous float64).
        aligned: (A, 2) ``[joint, value]`` where a triple's outer axes line up.
        joint: The held joint (the parameter).
        named: Its name and limits (``_HeldFamily``'s ``name``, ``domain``).
        domain: (2,) its limits (copied into each SelfMotion).
        method: The SelfMotion's ``method`` text.
    """

    params: np.ndarray
    aligned: np.ndarray
    joint: int
    named: tuple[str, tuple[float, float]]
    domain: np.ndarray
    method: str


@dataclass(slots=True, eq=False)
class SelfMotionSetup:
    """What the self-motion of a 7R arm needs per chain (the Arm's :data:`SELF_MOTION` state).

    Attributes:
        swivel: The SRS arm's swivel closed form, or None (not SRS).
        parameter: ``auto_parameter``'s answer once ``parameter_known``.
        parameter_known: True once ``parameter`` is set.
        aligned: ``_aligned_values``' (joint, value) pairs, or None until needed.
        held: The compiled held-joint family's per-arm constants
            (:class:`HeldKernel`) once ``self_motion`` has taken
            it for ``"auto"``, else None.
    """

    swivel: SwivelArm | None
    parameter: str | None = None
    parameter_known: bool = False
    aligned: list[tuple[int, float]] | None = None
    held: HeldKernel | None = None


def _build_setup(arm: Arm) -> SelfMotionSetup:
    return SelfMotionSetup(swivel_arm(arm.chain))


#: The self-motion set-up of a 7R arm, per Arm (docs/conventions.md "Per-arm state").
SELF_MOTION: Derived[SelfMotionSetup] = Derived("self-motion set-up", _build_setup)


def _setup(arm: Arm) -> SelfMotionSetup:
    """The arm's :class:`SelfMotionSetup`, built on first use (a 7-joint chain)."""
    return arm.derived(SELF_MOTION)


# ------------------------------------------------------------------ choosing one
def continued_parameter(robot: Arm) -> str:
    """``"auto"``'s joint on a 7-joint arm without a swivel or a held-joint closed form.

    The arm's one prismatic joint where it has exactly one (a robot on a linear track:
    where along the rail is the question users ask of its self-motion, and holding the
    track leaves the robot's own six joints), else the last joint.
    """
    prismatic = [n for n, rev in zip(robot.joint_names, robot.is_revolute, strict=True)
                 if not rev]
    return prismatic[0] if len(prismatic) == 1 else robot.joint_names[-1]


def _family(robot: Arm, T: np.ndarray, parameter: str, dispatch: Dispatch,
            reference: bool = False) -> _Family:
    names = list(robot.joint_names)
    choices = ["auto", "swivel", *names]
    if not seven_joint_serial(robot):
        raise InputError("robot", f"self_motion needs a 7-joint serial arm without "
                                  f"coupled joints; {robot.name!r} has {robot.n} joints")
    if parameter not in choices:
        raise InputError("parameter", f"expected one of {', '.join(map(repr, choices))}, "
                                      f"got {parameter!r}")
    arm = _setup(robot).swivel
    if parameter in ("auto", "swivel") and arm is not None:
        return _SwivelFamily(arm, T, robot, reference)
    if parameter == "swivel":
        raise InputError("parameter", f"{robot.name!r} is not an SRS arm (axes 1-3 and "
                                      f"5-7 must meet): give a joint name or 'auto'")
    from robokin.kinematics.ik.fixed import _held_solvers

    held = {n: h for n, h in _held_solvers(robot).items()
            if not (arm is not None and n == names[3])}  # the SRS elbow: a family
    if parameter == "auto":
        usable = [n for n in names if n in held and n != names[3]]  # not the elbow
        # (auto_parameter says why)
        parameter = usable[-1] if usable else continued_parameter(robot)
    if parameter not in held:  # the general held-joint 6R solver, continued
        from robokin.kinematics.ik.self_motion_continued import _ContinuedFamily

        return _ContinuedFamily(robot, names.index(parameter), T, dispatch)
    return _HeldFamily(robot, held[parameter].params, names.index(parameter), T, dispatch)
