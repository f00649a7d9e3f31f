"""Is a pose of a 7-axis arm reachable? Any in-limit point of its self-motion manifold.

A 7R arm reaches a pose in a one-parameter family of configurations (the
self-motion manifold, :meth:`robokin.Robot.self_motion`). One numeric IK sample
may lie outside the joint limits while other parts of the family lie inside, so
maps and placement search the whole family, cheapest test first, for poses the
numeric sample did not reach:

1. **A sweep of the held joint** (:data:`SWEEP_VALUES` values from one limit to the
   other, both limits included, and :data:`WINDOW_VALUES` more within one step of
   the numeric sample's own value, where a small closed loop of the manifold
   may hide between the coarse values): ``robot.ik(T, fixed={joint: values})``,
   the batched held-joint closed form, every branch at every value. An in-limit
   row is a configuration that reaches the pose: reachable.
2. **Exact limit points, where the sweep came close** (its best row at most
   :data:`CLOSE` outside the limits): where an in-limit piece of a branch ends, a
   joint is at one of its limits (or the held joint is at one of its own, the
   sweep's end values). So the pose is solved once more with each joint held at
   each of its limits (``robot.ik(T, fixed={name: limit})``, the same finite
   problems :meth:`SelfMotion.reachable` solves for its intervals): any solution
   inside every limit proves the pose reachable, and if none is, no branch
   enters the limits anywhere except as a closed loop lying wholly inside them.

What this can miss, against the exact manifold: a pose whose in-limit part falls
between two sweep values while every sweep row is more than :data:`CLOSE` outside
the limits (or the sweep finds no branch at all), or a closed in-limit loop the
sweep does not touch. On 1,000 Panda poses near the joint limits it agreed with
``SelfMotion.reachable`` on every pose (``tests/cell/test_manifold.py``,
``docs/scale.md``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["CLOSE", "SWEEP_VALUES", "WINDOW_VALUES", "reach_on_manifold", "sweep_joint"]

#: Held-joint values of the sweep (limits included).
SWEEP_VALUES = 32
#: Values of the window about the numeric sample's value (one sweep step each side).
WINDOW_VALUES = 9
#: [rad, m] A sweep row this far outside the limits (the largest excess of its
#: joints) sends the pose to the exact limit-point test.
CLOSE = 0.3
#: Poses solved per sweep call (32 values x 8 branches x 7 joints x 8 B = 14 KB each).
_BATCH = 256


def sweep_joint(robot: Robot) -> str | None:
    """The joint swept for a 7-joint arm's manifold, or None (no held-joint closed form).

    ``self_motion``'s own parameter when it is a joint (q7 on the Panda / FR3),
    else (the swivel of an SRS arm) the last joint with a held-joint closed form;
    on an arm with neither, an end joint whose held solve is a 6R closed form
    (:func:`_end_swept`: the track of a robot on a rail).
    """
    from robokin.kinematics.arm import arm_of
    from robokin.kinematics.ik.fixed import _held_solvers
    from robokin.kinematics.ik.self_motion import auto_parameter

    parameter = auto_parameter(robot)
    if parameter is None:
        return _end_swept(robot)
    if parameter != "swivel":
        return parameter
    held = [n for n in robot.joint_names if n in _held_solvers(arm_of(robot))]
    return held[-1] if held else None


def _end_swept(robot: Robot) -> str | None:
    """A 7-joint arm's end joint whose held solve is a 6R closed form, or None.

    The arm without a held-joint closed form of the Panda's kind: its first or last
    joint held leaves a six-joint chain that may have one (a robot on a linear track:
    the track held leaves the robot, a UR5's three-parallel family), which
    ``robot.ik(T, fixed=...)`` then solves completely. ``self_motion``'s ``"auto"``
    choice first (``continued_parameter``: the track), then the last, then the first.
    """
    from robokin.kinematics.arm import arm_of
    from robokin.kinematics.ik.fixed import _end_held
    from robokin.kinematics.ik.self_motion_base import seven_joint_serial
    from robokin.kinematics.ik.self_motion_families import continued_parameter

    arm = arm_of(robot)
    if not seven_joint_serial(arm):
        return None
    names = arm.joint_names
    for name in dict.fromkeys([continued_parameter(arm), names[-1], names[0]]):
        if name in (names[0], names[-1]) and _end_held(arm, name) is not None:
            return name
    return None


def reach_on_manifold(robot: Robot, T: np.ndarray, joint: str,
                      near: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """One in-limit configuration per pose, where the pose's manifold has one.

    Args:
        robot: A 7-joint robot (world frame) with a held-joint closed form for
            ``joint``.
        T: Poses (M, 4, 4) [m].
        joint: The joint swept (:func:`sweep_joint`).
        near: Configurations (M, n) near each pose (the numeric samples; NaN:
            none) whose ``joint`` value the sweep also visits closely.

    Returns:
        ``q`` (M, n) [rad] (NaN where none was found) and ``ok`` (M,) bool. Of
        the sweep's in-limit rows ``q`` is the one farthest from every limit; of
        the exact test's, the first found. Each pose is decided on its own.
    """
    M, n = T.shape[0], robot.n
    q = np.full((M, n), np.nan)
    ok = np.zeros(M, dtype=bool)
    excess = np.full(M, np.inf)
    values = _values(robot, joint, M, near)
    for a in range(0, M, _BATCH):
        b = min(a + _BATCH, M)
        q[a:b], ok[a:b], excess[a:b] = _sweep(robot, T[a:b], joint, values[a:b])
    close = np.flatnonzero(~ok & (excess <= CLOSE))
    if close.size:
        qc, okc = _limit_points(robot, T[close])
        q[close], ok[close] = qc, okc
    return q, ok


def _values(robot: Robot, joint: str, M: int, near: np.ndarray | None) -> np.ndarray:
    """The held values per pose (M, SWEEP_VALUES + WINDOW_VALUES) [rad, m].

    The sweep from limit to limit, then the window about ``near``'s value (where
    it is NaN, the window repeats the lower limit).
    """
    j = list(robot.joint_names).index(joint)
    lo, hi = (float(x) for x in robot.limits[j])
    grid = np.linspace(lo, hi, SWEEP_VALUES)
    centre = np.full(M, lo) if near is None else np.nan_to_num(near[:, j], nan=lo)
    step = (hi - lo) / (SWEEP_VALUES - 1)
    window = np.clip(centre[:, None] + step * np.linspace(-1.0, 1.0, WINDOW_VALUES), lo, hi)
    return np.concatenate([np.broadcast_to(grid, (M, SWEEP_VALUES)), window], axis=1)


def _sweep(robot: Robot, T: np.ndarray, joint: str, values: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The held-joint sweep of poses T (m, 4, 4) at ``values`` (m, v).

    Returns:
        The in-limit row farthest from the limits (m, n), whether there is one
        (m,), and the smallest excess over the limits of any row (m,) [rad, m]
        (inf: no branch at any value).
    """
    lim = np.asarray(robot.limits, dtype=np.float64)
    sols = robot.ik(T[:, None], fixed={joint: values})
    m, n = T.shape[0], robot.n
    rows = sols.q.reshape(m, -1, n)
    inside = sols.within_limits.reshape(m, -1)
    valid = sols.valid.reshape(m, -1)
    with np.errstate(invalid="ignore"):
        margin = np.minimum(rows - lim[:, 0], lim[:, 1] - rows).min(axis=-1)
    best = np.argmax(np.where(inside, margin, -np.inf), axis=-1)
    found = np.asarray(inside.any(axis=-1))
    q = np.where(found[:, None], rows[np.arange(m), best], np.nan)
    excess = np.where(valid, -margin, np.inf).min(axis=-1)
    return q, found, excess


def _limit_points(robot: Robot, T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Poses T (m, 4, 4) solved with each joint held at each of its limits.

    Joints whose range is a whole turn or more are left out (some turn of theirs
    is always inside).

    Returns:
        The first solution inside every limit per pose (m, n) and whether there
        is one (m,).
    """
    lim = np.asarray(robot.limits, dtype=np.float64)
    rev = np.asarray(robot.is_revolute, dtype=bool)
    m, n = T.shape[0], robot.n
    q = np.full((m, n), np.nan)
    ok = np.zeros(m, dtype=bool)
    for j, name in enumerate(robot.joint_names):
        if rev[j] and lim[j, 1] - lim[j, 0] >= 2 * np.pi:
            continue
        for value in lim[j]:
            todo = np.flatnonzero(~ok)
            if not todo.size:
                return q, ok
            sols = robot.ik(T[todo], fixed={name: float(value)})
            inside = sols.within_limits.reshape(todo.size, -1)
            hit = inside.any(axis=-1)
            first = np.argmax(inside, axis=-1)
            rows = sols.q.reshape(todo.size, -1, n)[np.arange(todo.size), first]
            q[todo[hit]] = rows[hit]
            ok[todo[hit]] = True
    return q, ok
