"""A held joint whose value puts its two neighbours' axes on one line.

Holding joint j of a 7R arm at a value v can make the axes of joints j-1 and j+1
coincide (the Panda at q2 = 0: axes 1 and 3). The remaining six joints then move
two of their axes on one line: only q_{j-1} + s q_{j+1} is fixed (s = +1 for
axes pointing the same way, -1 for opposite ones), the chain left is degenerate
for the general 6R elimination, and the solutions form one-parameter families
(the split of that sum), one per branch of the rest.

Every family is found exactly by holding one of the pair as well, at a value c
(and again at c + pi/2, the union kept, one row per family: where the helper
chain is singular at a family's member, as the Panda's with q6 = 0 and q5 = pi/2,
the general 6R elimination can miss that double root, and at the other value the
member is regular):
with q_{j-1} = c the arm is an ordinary held-joint problem (``solve_fixed`` on the
other joint, here a general 6R chain), whose isolated solutions include every
family's member at q_{j-1} = c; the rows with q_j within 1e-4 rad of v are kept
(the helper's rows next to a wrist singularity have q_j off by 1e-6), q_j set to
v exactly and the others Newton-polished to the pose (a row that does not reach
1e-12 is dropped), and the split is then chosen inside both joints' limits
(the in-limit value of q_{j-1} nearest ``q_near``'s, else nearest the middle of
its range), every angle at its in-limit turn. The rows are flagged
``singular`` (a continuum: any split reaches the pose). c is the middle of joint
j-1's limits (for the Panda 0); the pair's other joint is held instead when j-1
is not the chain's first joint and j+1 is its last (one reduced chain serves
every value of an end joint).

Detection is geometric: the two axes coincide when their Jacobian columns at a
configuration with joint j at v agree up to the sign s (within 1e-12 of the
chain's length scale), the criterion the compiled kernels use for joints on one
line.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from robokin.kinematics.arm import Arm
from robokin.kinematics.forward import forward_kinematics
from robokin.kinematics.ik.analytic._common import fit_turns
from robokin.kinematics.ik.solutions import SolutionSet
from robokin.kinematics.jacobian import jacobian_and_pose
from robokin.spatial import pose_error, wrap_angle

__all__ = ["CoincidentPair", "coincident_pair", "solve_coincident"]

#: Jacobian columns this close (relative to the chain's length scale): one line
COINCIDENT = 1e-12
#: Rows of the helper problem whose held joint is this close to the value [rad]
NEAR_VALUE = 1e-4
#: Pose error (m, rad) a returned row must reach
EXACT = 1e-12
#: The second helper value is c + this [rad]: where the helper chain is singular at
#: a family's member (a double root the general 6R elimination can miss: the Panda
#: with q6 = 0, q5 = pi/2), its member at the other value is regular (axis 2 turned)
HELPER_TURN = np.pi / 2
#: A second-helper row this close [rad] to a first-helper row after the split is
#: that family again (next to a second singular set, q4 = 1e-9, the two copies
#: differ by up to 2e-5 along the thin set); the first helper's rows are all kept
SAME_FAMILY = 1e-4


def _turn_gap(Q: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Largest angle difference (modulo 2 pi) of rows Q (k, n) from q (n,)."""
    return np.asarray(np.abs(wrap_angle(Q - q)).max(axis=-1))


@dataclass(frozen=True)
class CoincidentPair:
    """Joints ``a`` and ``b`` on one line with joint ``held`` at its value.

    Attributes:
        held: The held joint's index.
        a: The joint held again at ``c`` (the helper problem), index.
        b: The other joint of the pair, index.
        sign: +1 when the axes point the same way (q_a + q_b fixed), -1 when
            opposite (q_a - q_b fixed).
        c: The value joint ``a`` is held at in the helper problem [rad].
    """

    held: int
    a: int
    b: int
    sign: float
    c: float


def coincident_pair(robot: Arm, j: int, v: float) -> CoincidentPair | None:
    """The pair of joints that joint ``j`` held at ``v`` puts on one line, if any.

    Args:
        robot: The arm (7R: revolute joints).
        j: The held joint's index (a middle joint: 0 < j < n - 1).
        v: Its value [rad].

    Returns:
        The pair, or None when joints j-1 and j+1 do not share a line (or are not
        both revolute).
    """
    n = robot.n
    if not (0 < j < n - 1) or not (robot.is_revolute[j - 1] and robot.is_revolute[j + 1]):
        return None
    q = np.zeros(n)
    q[j] = v
    J, T = jacobian_and_pose(robot.chain, q)
    scale = max(1.0, float(np.linalg.norm(T[:3, 3])))
    ca, cb = J[:, j - 1], J[:, j + 1]
    sign = 1.0 if float(ca[3:] @ cb[3:]) >= 0.0 else -1.0
    if float(np.abs(ca - sign * cb).max()) > COINCIDENT * scale:
        return None
    a, b = (j - 1, j + 1) if j - 1 == 0 or j + 1 != n - 1 else (j + 1, j - 1)
    lo, hi = robot.limits[a]
    c = 0.5 * (lo + hi) if np.isfinite(lo) and np.isfinite(hi) else 0.0
    return CoincidentPair(j, a, b, sign, float(c))


def _polish(robot: Arm, q: np.ndarray, T: np.ndarray, free: np.ndarray,
            iterations: int = 8) -> np.ndarray:
    """Newton (least squares) on the joints ``free`` of rows q (m, n) to poses T (m, 4, 4).

    At most ``iterations`` steps, fewer where every error is below 1e-16.
    """
    q = q.copy()
    for _ in range(iterations):
        J, Tq = jacobian_and_pose(robot.chain, q)
        e = pose_error(Tq, T)
        if float(np.abs(e).max(initial=0.0)) <= 1e-16:
            break
        # least squares on every row at once (pinv's rcond as lstsq's: relative cut)
        step = np.linalg.pinv(J[:, :, free], rcond=1e-10) @ e[:, :, None]
        q[:, free] += step[:, :, 0]
    return q


def _split(total: float, sign: float, la: np.ndarray, lb: np.ndarray, pref: float) -> float:
    """q_a with q_a + sign q_b = total (mod 2 pi) and both inside their limits.

    The value nearest ``pref`` of the in-limit interval (over the turns of q_b);
    ``pref`` itself when no split is inside (the row stays flagged outside).
    """
    best, gap = pref, np.inf
    for m in (-2, -1, 0, 1, 2):
        # q_b = sign (total + 2 pi m - q_a) in [lb0, lb1]  <=>  q_a in [lo, hi]
        t = total + 2.0 * np.pi * m
        ends = sorted((t - sign * lb[0], t - sign * lb[1]))
        lo, hi = max(ends[0], la[0]), min(ends[1], la[1])
        if lo > hi:
            continue
        x = min(max(pref, lo), hi)
        if abs(x - pref) < gap:
            best, gap = x, abs(x - pref)
    return float(best)


def solve_coincident(robot: Arm, T: np.ndarray, pair: CoincidentPair, v: float,
                     q_near: np.ndarray | None,
                     held_solve: Callable[[int, float, np.ndarray], SolutionSet]) -> SolutionSet:
    """Every family of solutions of poses T (N, 4, 4) with joint ``pair.held`` at v.

    Args:
        robot: The arm.
        T: Validated poses (N, 4, 4) [m].
        pair: ``coincident_pair(robot, pair.held, v)``.
        v: The held value [rad].
        q_near: Preferred configurations (N, n) for the split, or None.
        held_solve: ``held_solve(joint, value, T)``: every solution of poses T with
            that one joint held (the helper problem).

    Returns:
        A set (N, k, n): one row per family (``singular`` True), the held column
        at v, the pair's split inside the limits where one is.
    """
    N, n = len(T), robot.n
    helpers = [held_solve(pair.a, c, T) for c in (pair.c, pair.c + HELPER_TURN)]
    poses, rows, second = [], [], []
    for h, helper in enumerate(helpers):
        Q, valid = helper.q.reshape(N, -1, n), helper.valid.reshape(N, -1)
        keep = valid & (np.abs(wrap_angle(Q[..., pair.held] - v)) <= NEAR_VALUE)
        pk, rk = np.nonzero(keep)
        poses.append(pk)
        rows.append(Q[pk, rk])
        second.append(np.full(len(pk), h == 1))
    pose = np.concatenate(poses)
    later = np.concatenate(second)
    q = np.concatenate(rows).copy()
    q[:, pair.held] = v
    free = np.array([i for i in range(n) if i not in (pair.held, pair.a)])
    if len(q):
        q = _polish(robot, q, T[pose], free)
    lim = robot.limits
    q = fit_turns(q, robot.is_revolute, lim)  # each angle at its in-limit turn
    q[:, pair.held] = v
    for i in range(len(q)):
        total = q[i, pair.a] + pair.sign * q[i, pair.b]
        pref = (q_near[pose[i], pair.a] if q_near is not None
                else 0.5 * (lim[pair.a, 0] + lim[pair.a, 1]))
        qa = _split(total, pair.sign, lim[pair.a], lim[pair.b], float(pref))
        q[i, pair.a] = qa
        q[i, pair.b] = pair.sign * (total - qa)
    q = fit_turns(q, robot.is_revolute, lim)  # q_b at the in-limit turn of its split
    q[:, pair.held] = v
    if len(q):
        e = np.abs(pose_error(forward_kinematics(robot.chain, q), T[pose]))
        exact = e.max(axis=-1) <= EXACT
    else:
        exact = np.zeros(0, bool)
    k = max(1, int(np.bincount(pose[exact], minlength=N).max(initial=0)))
    out = np.full((N, k, n), np.nan)
    ok = np.zeros((N, k), bool)
    slot = np.zeros(N, int)
    for i in np.flatnonzero(exact).tolist():
        at = int(pose[i])
        if later[i] and ok[at].any() and (_turn_gap(out[at, ok[at]], q[i]) <= SAME_FAMILY).any():
            continue  # a family the first helper value found already
        out[at, slot[at]] = q[i]
        ok[at, slot[at]] = True
        slot[at] += 1
    why = helpers[0].status.reshape(N)
    status = np.where(ok.any(axis=-1), "ok",
                      np.where(why == "ok", "no solution with the held value", why))
    return SolutionSet(out, ok, robot.is_revolute, lim, flags={"singular": ok.copy()},
                       status=status.astype(object),
                       method=f"{helpers[0].method} + coincident axes split",
                       info={"coincident": (robot.joint_names[pair.a],
                                            robot.joint_names[pair.b])})
