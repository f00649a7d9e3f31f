"""What a plan may end at: one configuration, a set of them, or a tool pose.

:func:`goal_configurations` turns the ``goal`` argument of
:meth:`~robokin.planning.Planner.plan` into candidate goal configurations (k, n):

* a configuration (n,): that configuration;
* a goal set (k, n): each row;
* a TCP pose (4, 4) in the world: every solution ``robot.ik(T)`` returns inside the
  joint limits, with the whole-turn equivalents of joints whose range exceeds
  2 pi (a UR joint at +-360 deg reaches each angle twice); for a 7R arm, samples
  of the pose's whole self-motion manifold (``robot.self_motion(T)``: every branch,
  every interval inside the joint limits), spread over the intervals by their length,
  at least one each (:class:`ManifoldGoals`). The planner asks for denser samples
  (:meth:`Goals.grown`) while every goal so far is in collision or the search cannot
  reach them; from the second round on they include the aligned continua (where two
  axes on one line let a pair of joints turn against each other, e.g. the Panda's
  q2 = 0: configurations no branch sample holds).

For a four-joint arm a (4, 4) array is ambiguous; it is read as a pose when it is
a rigid transform (last row 0 0 0 1, orthonormal rotation), else as four
configurations.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import numpy.typing as npt

from robokin._text import short_repr
from robokin._validation import _real_array, check_finite
from robokin.exceptions import InputError

if TYPE_CHECKING:
    from robokin.kinematics.ik.self_motion import SelfMotion
    from robokin.kinematics.ik.self_motion_continua import Continua
    from robokin.robot import Robot

__all__ = ["GoalKind", "Goals", "ManifoldGoals", "goal_configurations", "outside_limits"]

GoalKind = Literal["configuration", "set", "pose"]
#: Tolerance [rad, m] of the joint-limit test of starts and goals.
LIMIT_TOL = 1e-9
#: Self-motion samples of a 7R pose goal's first round (spread over the in-limit
#: intervals by length, at least one each); each later round doubles the density.
MANIFOLD_FIRST = 32
#: Rounds of manifold samples at most: the last has 2**7 = 128 times the first
#: round's density (32 samples over 2.9 rad: a spacing of 0.7 mrad), 8160 in all.
MANIFOLD_ROUNDS = 8


@dataclass(frozen=True, eq=False)
class ManifoldGoals:
    """The self-motion manifold of a 7R pose goal, sampled round by round.

    Round r places ``counts[i] * 2**r`` samples at the centres of equal cells of
    in-limit interval i, so no sample repeats an earlier round's (a round's centres
    are the earlier rounds' cell boundaries) and every round is spread over every
    branch and interval. The aligned continua inside the limits (:meth:`lines`:
    configurations off the branches) join from round 1 on, ``line_counts[i] *
    2**(r - 1)`` samples on continuum i, spread the same way (from round 0 where no
    interval is inside the limits): the first round stays the branches' (0.5 ms a
    pose goal), the continua come with the denser rounds the planner asks for when
    every goal so far collides or cannot be reached.

    Attributes:
        motion: ``robot.self_motion(T)``.
        counts: (m,) first-round samples of each interval (>= 1).
        first: About how many samples round 0 (or the continua's first round) has.
    """

    motion: SelfMotion
    counts: np.ndarray
    first: int = MANIFOLD_FIRST
    _cache: dict[str, Any] = field(default_factory=dict, repr=False)

    @classmethod
    def of(cls, motion: SelfMotion, first: int = MANIFOLD_FIRST) -> ManifoldGoals:
        """The sampler of ``motion`` with about ``first`` samples in round 0."""
        return cls(motion, _shares(np.diff(motion.intervals, axis=1)[:, 0], first), first)

    def lines(self) -> tuple[Continua | None, np.ndarray]:
        """The continua inside the limits and their first-round samples (>= 1 each).

        (``motion.continua()``, solved on first use and kept; None where the manifold
        was made without the dispatcher.)
        """
        if "lines" not in self._cache:
            lines = self.motion.continua()
            length = np.zeros(0) if lines is None else lines.s_hi - lines.s_lo
            self._cache["lines"] = (lines, _shares(length, self.first))
        out: tuple[Continua | None, np.ndarray] = self._cache["lines"]
        return out

    def round(self, r: int) -> np.ndarray:
        """The configurations (k, n) of round r inside the joint limits [rad]."""
        sm, per = self.motion, self.counts * 2**r
        a, b = sm.intervals[:, 0], sm.intervals[:, 1]
        cell, u = _cells(per)
        t = a[cell] + (b[cell] - a[cell]) * u
        q = sm.sample(t, within_limits=True)[np.arange(len(t)), sm.interval_branch[cell]]
        start = 1 if len(sm.intervals) else 0
        if r >= start:
            lines, counts = self.lines()
            if lines is not None and len(counts):
                piece, u = _cells(counts * 2**(r - start))
                extra = lines.at(piece, u)
                # (a continuum meets its branch at one point: a branch sample there
                # once; rows compared at 1e-10 as whole records: thousands late on)
                same = np.isin(_as_records(extra), _as_records(q))
                q = np.vstack([q, extra[~same]])
        q = q[np.isfinite(q).all(axis=1)]
        return np.ascontiguousarray(np.clip(q, sm.limits[:, 0], sm.limits[:, 1]))


def _shares(length: np.ndarray, first: int) -> np.ndarray:
    """About ``first`` samples spread over pieces by length, at least one each (int64)."""
    total = float(length.sum())
    share = length / total * first if total > 0 else np.zeros_like(length)
    return np.maximum(1, np.rint(share)).astype(np.int64)


def _as_records(q: np.ndarray) -> np.ndarray:
    """Rows (k, n) rounded to 1e-10 (-0 as 0) as (k,) opaque records, to compare whole rows."""
    r = np.ascontiguousarray(np.round(q, 10) + 0.0)
    return r.view(np.dtype((np.void, r.dtype.itemsize * r.shape[1]))).ravel()


def _cells(per: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(segment, fraction) of the centres of ``per[i]`` equal cells of each segment i."""
    seg = np.repeat(np.arange(len(per)), per)
    j = np.arange(int(per.sum())) - np.repeat(np.cumsum(per) - per, per)
    return seg, (j + 0.5) / per[seg]


@dataclass(frozen=True, eq=False)
class Goals:
    """Candidate goal configurations.

    Attributes:
        kind: ``"configuration"``, ``"set"`` or ``"pose"``.
        q: Candidate goals (k, n) [rad, m], inside the joint limits; k may be 0
            (then ``reason`` says why).
        index: (k,) the row of each candidate in the goal set the caller gave
            (a configuration: 0; a pose: the candidate's own number).
        pose: The TCP pose (4, 4) in the world for a pose goal, else None.
        reason: Why there is no candidate (empty when k > 0).
        manifold: A 7R pose goal's self-motion sampler (``q`` holds its rounds
            0 .. ``rounds - 1``), else None.
        rounds: The manifold rounds in ``q``.
    """

    kind: GoalKind
    q: np.ndarray
    index: np.ndarray
    pose: np.ndarray | None = None
    reason: str = ""
    manifold: ManifoldGoals | None = None
    rounds: int = 1

    @property
    def can_grow(self) -> bool:
        """Whether :meth:`grown` has denser manifold samples to add."""
        return self.manifold is not None and self.rounds < MANIFOLD_ROUNDS

    def grown(self) -> tuple[Goals, np.ndarray]:
        """These goals with the next manifold round appended, and its new rows."""
        if self.manifold is None or not self.can_grow:
            raise ValueError("no denser samples: not a manifold goal, or the last round")
        new = self.manifold.round(self.rounds)
        rows = np.arange(len(self.q), len(self.q) + len(new))
        q = np.ascontiguousarray(np.vstack([self.q, new]))
        return (Goals(self.kind, q, np.arange(len(q)), self.pose, self.reason,
                      self.manifold, self.rounds + 1), rows)


def outside_limits(q: np.ndarray, limits: np.ndarray) -> str:
    """Why configuration q (n,) is outside the joint limits (n, 2), or ''."""
    lo, hi = limits[:, 0] - LIMIT_TOL, limits[:, 1] + LIMIT_TOL
    if bool(np.all((q >= lo) & (q <= hi))):
        return ""
    for j in range(q.shape[0]):
        if q[j] < lo[j]:
            return f"joint {j + 1} at {q[j]:.6g} is below its lower limit {limits[j, 0]:.6g}"
        if q[j] > hi[j]:
            return f"joint {j + 1} at {q[j]:.6g} is above its upper limit {limits[j, 1]:.6g}"
    return ""


def _is_rigid(T: np.ndarray) -> bool:
    R = T[:3, :3]
    return bool(
        np.allclose(T[3], [0.0, 0.0, 0.0, 1.0], atol=1e-9)
        and np.allclose(R @ R.T, np.eye(3), atol=1e-6)
        and np.linalg.det(R) > 0
    )


def _in_frame(robot: Robot, solver: Robot, T: np.ndarray) -> np.ndarray:
    """The pose of ``solver``'s tool when ``robot``'s is at T (the same joint values).

    ``robot.fk(q) = pre @ solver.fk(q) @ post`` with ``pre = robot.base @
    solver.base^-1`` and ``post = solver.tool^-1 @ robot.tool``.
    """
    from robokin.spatial import invert

    if np.array_equal(robot.base, solver.base) and np.array_equal(robot.tool, solver.tool):
        return T
    pre = np.asarray(robot.base) @ invert(solver.base)
    post = invert(solver.tool) @ np.asarray(robot.tool)
    out: np.ndarray = invert(pre) @ T @ invert(post)
    return out


def _manifold_goals(robot: Robot, T: np.ndarray) -> Goals | None:
    """A 7-joint arm's pose goal on its self-motion manifold; None when it has none.

    Every 7-joint arm whose whole manifold is exact (``exact_parameter``): a
    closed form (``auto_parameter``), a robot on a linear track (the robot's own six
    joints at each track value, ~25 ms a pose on a UR5 on a rail) and a general 7R
    arm (the general held-joint 6R solver continued, ~10-30 ms a pose); an arm whose
    held chain only the numeric solver samples keeps ``robot.ik``'s solutions. The
    samples cover the in-limit intervals, then the aligned continua too
    (:class:`ManifoldGoals`); a pose inside the limits only at one point of a
    continuum has that configuration (``best("margin")``).
    """
    from robokin.kinematics.ik.self_motion import exact_parameter

    if exact_parameter(robot) is None:
        return None
    # a rotation orthonormal to 1e-12 only (a pose written to 12 digits) is projected
    # onto SO(3) by self_motion itself (_validation.check_rigid)
    sm = robot.self_motion(T)
    if not sm.reachable:
        return None  # robot.ik says why (or finds what the manifold missed)
    sampler = ManifoldGoals.of(sm)
    q = sampler.round(0)
    if not len(q):  # inside the limits only at a point (a continuum's, a hair's)
        best = sm.best("margin")
        if best is None:  # (no in-limit row found after all: robot.ik says why)
            return None
        return Goals("pose", best.q[None], np.arange(1), T)
    return Goals("pose", q, np.arange(len(q)), T, "", sampler, 1)


def _pose_goals(robot: Robot, T: np.ndarray, solver: Robot) -> Goals:
    """Every in-limit IK solution of the pose T, whole turns included."""
    from robokin._validation import check_transform

    T = check_transform(T, "goal")
    Ts = _in_frame(robot, solver, T)
    manifold = _manifold_goals(solver, Ts)
    if manifold is not None:
        return Goals("pose", manifold.q, manifold.index, T, "", manifold.manifold, 1)
    sols = solver.ik(Ts)
    inside = sols.keep_within_limits()
    q = np.asarray(inside.expand_turns().solutions(), dtype=float).reshape(-1, robot.n)
    if q.shape[0] == 0:
        status = np.asarray(inside.status).reshape(-1)
        why = str(status[0]) if status.size else "no solution"
        return Goals("pose", q, np.zeros(0, dtype=np.int64), T,
                     f"the goal pose is unreachable: {why}")
    q = np.clip(q, robot.limits[:, 0], robot.limits[:, 1])
    return Goals("pose", np.ascontiguousarray(q), np.arange(q.shape[0]), T)


def goal_configurations(robot: Robot, goal: npt.ArrayLike, *,
                        solver: Robot | None = None) -> Goals:
    """The candidate goal configurations of ``goal`` (see the module docstring).

    Args:
        robot: The robot as placed in the scene (poses are in the world).
        goal: A configuration (n,), a goal set (k, n) [rad, m], or a TCP pose (4, 4).
        solver: The same arm with other base and tool transforms (the robot before
            the scene placed it) to solve a pose goal with, the pose moved into its
            frames: its IK set-up, built on first use (0.2 s for the Panda's
            self-motion), then serves every Planner of that robot. Default: robot.

    Returns:
        The candidates inside the joint limits; none (with a reason) when every
        configuration is outside them or the pose has no solution.

    Raises:
        InputError: not numbers, a wrong shape, non-finite values or an empty set.
    """
    n = robot.n
    g = _real_array(goal, "goal", "a configuration, a goal set or a pose")
    if g.shape == (4, 4) and (n != 4 or _is_rigid(g)):
        return _pose_goals(robot, g, robot if solver is None else solver)
    if g.ndim == 1 and g.shape[0] == n:
        kind: GoalKind = "configuration"
        q = g[None, :]
    elif g.ndim == 2 and g.shape[1] == n and g.shape[0] >= 1:
        kind = "set"
        q = g
    else:
        raise InputError(
            "goal", f"expected a configuration ({n},), a goal set (k, {n}) or a TCP "
            f"pose (4, 4), got shape {g.shape} ({short_repr(goal)})")
    check_finite(q, "goal")
    limits = np.asarray(robot.limits, dtype=float)
    keep = np.all((q >= limits[:, 0] - LIMIT_TOL) & (q <= limits[:, 1] + LIMIT_TOL), axis=1)
    if not keep.any():
        what = "the goal" if kind == "configuration" else "every goal"
        return Goals(kind, np.zeros((0, n)), np.zeros(0, dtype=np.int64), None,
                     f"{what} is outside the joint limits: {outside_limits(q[0], limits)}")
    out = np.clip(q[keep], limits[:, 0], limits[:, 1])
    return Goals(kind, np.ascontiguousarray(out), np.flatnonzero(keep))
