"""What a plan may end at: one configuration, a set of them, or a tool pose.

:func:`goal_configurations` turns the ``goal`` argument of
:meth:`~robokin.planning.Planner.plan` into candidate goal configurations (k, n):

* a configuration (n,): that configuration;
* a goal set (k, n): each row;
* a TCP pose (4, 4) in the world: every solution ``robot.ik(T)`` returns inside the
  joint limits, with the whole-turn equivalents of joints whose range exceeds
  2 pi (a UR joint at +-360 deg reaches each angle twice); for a redundant arm
  (more than six joints), the solutions ``robot.ik`` returns for the pose (its own
  handling of the redundancy), not the whole self-motion manifold.

For a four-joint arm a (4, 4) array is ambiguous; it is read as a pose when it is
a rigid transform (last row 0 0 0 1, orthonormal rotation), else as four
configurations.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy as np
import numpy.typing as npt

from robokin._text import short_repr
from robokin._validation import _real_array, check_finite
from robokin.exceptions import InputError

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["GoalKind", "Goals", "goal_configurations", "outside_limits"]

GoalKind = Literal["configuration", "set", "pose"]
#: Tolerance [rad, m] of the joint-limit test of starts and goals.
LIMIT_TOL = 1e-9


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
    """

    kind: GoalKind
    q: np.ndarray
    index: np.ndarray
    pose: np.ndarray | None = None
    reason: str = ""


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


def _pose_goals(robot: Robot, T: np.ndarray) -> Goals:
    """Every in-limit IK solution of the pose T, whole turns included."""
    from robokin._validation import check_transform

    T = check_transform(T, "goal")
    sols = robot.ik(T)
    inside = sols.keep_within_limits()
    q = np.asarray(inside.expand_turns().solutions(), dtype=float).reshape(-1, robot.n)
    if q.shape[0] == 0:
        status = np.asarray(inside.status).reshape(-1)
        why = str(status[0]) if status.size else "no solution"
        return Goals("pose", q, np.zeros(0, dtype=np.int64), T,
                     f"the goal pose is unreachable: {why}")
    q = np.clip(q, robot.limits[:, 0], robot.limits[:, 1])
    return Goals("pose", np.ascontiguousarray(q), np.arange(q.shape[0]), T)


def goal_configurations(robot: Robot, goal: npt.ArrayLike) -> Goals:
    """The candidate goal configurations of ``goal`` (see the module docstring).

    Args:
        robot: The robot as placed in the scene (poses are in the world).
        goal: A configuration (n,), a goal set (k, n) [rad, m], or a TCP pose (4, 4).

    Returns:
        The candidates inside the joint limits; none (with a reason) when every
        configuration is outside them or the pose has no solution.

    Raises:
        InputError: not numbers, a wrong shape, non-finite values or an empty set.
    """
    n = robot.n
    g = _real_array(goal, "goal", "a configuration, a goal set or a pose")
    if g.shape == (4, 4) and (n != 4 or _is_rigid(g)):
        return _pose_goals(robot, g)
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
