"""A held joint whose value puts its two neighbours' axes next to one line.

The Panda with joint 2 held at v = 1e-9 (or any |v| <= ``NEAR`` rad): axes 1 and 3
nearly coincide. The chain left is nearly degenerate (the general 6R solver
declines it) and its exact solutions are isolated points on what would be, at the
aligned value v0 (here 0), one-parameter families of solutions
(``coincident.py``): only q1 + q3 and q4..q7 are fixed there, the split t = q1 free.

The solutions are found from those families, to first order in v - v0 and then
exactly. Along a family (the held joint at v0) the frame past the pair does not
move and the held joint's axis turns rigidly about the common line by t, so its
Jacobian column is ``c(t) = c0 + c1 cos t + c2 sin t``. Moving the held joint by
dv off v0 is compensated by the family's own five coordinates (the common axis and
the four others: a 6 x 5 matrix A, regular where the family is) exactly when
``c(t)`` lies in A's range, i.e. ``n . c(t) = 0`` with n A's left null vector:
``alpha + beta cos t + gamma sin t = 0``, at most two splits t per family (the
generating configuration's among them). Each is a seed (the held joint at v, the
pair split at t) for Newton on the six free joints, each step a least-squares
solve through the SVD with a relative cut far below the chain's smallest singular
value (~|v - v0| of its largest): the step along the ill-conditioned family
direction is inexact by ~1e-16 / |v - v0| rad, which moves the pose by ~1e-16.
A row that does not reach ``ACCEPT`` (1e-13 m, rad) is dropped, never returned
as valid. Where a family is itself singular (A rank-deficient) or the first-order
equation vanishes identically, eight splits spread over the turn are seeded
instead.

Rows are flagged ``singular`` where the 6 x 6 Jacobian of the free joints has a
smallest singular value below ``FLAG`` of its largest (next to a continuum).

Everything after the helper solves runs compiled (``csrc/near_coincident.c``,
kernel ``near_coincident``, :func:`near_rows`), one seed at a time; a step is the
pivoted QR's solution where its pivots show no singular value near the cut (then
it is the SVD step exactly), the SVD's otherwise (docs/ik.md, "Joint 2 held next
to 0").
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from robokin._native import kernels
from robokin.kinematics.arm import Arm
from robokin.kinematics.ik.coincident import (
    EXACT,
    HELPER_TURN,
    CoincidentPair,
    coincident_pair,
)
from robokin.kinematics.ik.solutions import SolutionSet
from robokin.spatial import wrap_angle

__all__ = ["near_coincident_pair", "near_rows", "placed", "solve_near_coincident",
           "status_text"]

#: What the sets' ``method`` adds to the helper problem's
METHOD = "near-coincident axes, Newton"
#: Held values this close [rad] to an aligned value v0 take this path (the general
#: 6R solver declines the chain up to ~1e-4 rad on the Panda; it solves 1e-3 exactly)
NEAR = 1e-3
#: Aligned values tried: the special values where real arms line their axes up
ALIGNED = (0.0, np.pi / 2, -np.pi / 2, np.pi, -np.pi)
#: Helper rows (joint a held) with the held joint this close [rad] to v0 seed the search
KEEP = 1e-2
#: The compiled pass's constants (``csrc/near_coincident.c``, where they are used):
#: the Newton step's relative SVD cut (far below |v - v0| ~ 1e-9), the largest step
#: [rad] of any joint, the iterations (then ``FINAL`` ones from the best iterate
#: with the coarser cut), those of a row moved into the limits (the rest well
#: conditioned, converged in 2-3 where it can be)
RCOND = kernels.NC_RCOND
MAX_STEP = kernels.NC_MAX_STEP
STEPS = kernels.NC_STEPS
FINAL = kernels.NC_FINAL
FINAL_RCOND = kernels.NC_FINAL_RCOND
PIN_STEPS = kernels.NC_PIN_STEPS
#: Two rows this close [rad] (every joint) are one solution (next to a second
#: aligned set, q5 = 1e-9 on the Panda, Newton leaves copies 1e-6 apart)
SAME = kernels.NC_SAME
#: Pose error (m, rad; norms) a returned row must reach: a margin below the promised
#: ``EXACT`` (1e-12; a converged row reaches 1e-16, one stuck near 1e-12 is suspect)
ACCEPT = EXACT / 10
#: Two Newton seeds of one pose this close [rad] (every joint) are one
SAME_SEED = kernels.NC_SAME_SEED
#: Largest move [rad] of the split that brings a row into the pair's limits
SHIFT = kernels.NC_SHIFT
#: Rows flagged singular: free-joint Jacobian's smallest / largest singular value below
FLAG = kernels.NC_FLAG
#: A family whose 6 x 5 matrix has a smallest singular value below this (relative)
#: is singular itself: seeded over the whole turn instead
FAMILY_RANK = kernels.NC_FAMILY_RANK


def near_coincident_pair(robot: Arm, j: int, v: float) -> tuple[CoincidentPair, float] | None:
    """The pair of joints next to one line with joint ``j`` at ``v``, and the aligned value.

    Args:
        robot: The arm (7R).
        j: The held joint's index.
        v: Its value [rad].

    Returns:
        ``(pair, v0)``: the pair that ``j`` held at v0 puts exactly on one line, with
        0 < |v - v0| <= ``NEAR``; or None.
    """
    for v0 in ALIGNED:
        if 0.0 < abs(v - v0) <= NEAR:
            pair = coincident_pair(robot, j, v0)
            if pair is not None:
                return pair, v0
    return None


def solve_near_coincident(robot: Arm, T: np.ndarray, pair: CoincidentPair, v0: float,
                          v: float,
                          held_solve: Callable[[int, float, np.ndarray], SolutionSet]
                          ) -> SolutionSet:
    """Every solution of poses T (N, 4, 4) with joint ``pair.held`` at v, v next to v0.

    Args:
        robot: The arm.
        T: Validated poses (N, 4, 4) [m].
        pair: ``coincident_pair(robot, pair.held, v0)``.
        v0: The aligned value [rad].
        v: The held value [rad], 0 < |v - v0| <= ``NEAR``.
        held_solve: As in :func:`~robokin.kinematics.ik.coincident.solve_coincident`
            (here joint ``pair.a`` held at ``pair.c`` and ``pair.c + pi / 2``).

    Returns:
        A set (N, k, n) of exact rows (pose error <= ``EXACT``), the held column at
        v, each angle at its in-limit turn, ``singular`` where next to a continuum.
    """
    N, n = len(T), robot.n
    helpers = [held_solve(pair.a, c, T) for c in (pair.c, pair.c + HELPER_TURN)]
    poses, rows = [], []
    for helper in helpers:  # the first helper's rows of a pose, then the second's
        Qh, okh = helper.q.reshape(N, -1, n), helper.valid.reshape(N, -1)
        okh = okh & (np.abs(wrap_angle(Qh[..., pair.held] - v0)) <= KEEP)
        p, r = np.nonzero(okh)
        poses.append(p)
        rows.append(Qh[p, r])
    pose = np.concatenate(poses)
    by_pose = np.argsort(pose, kind="stable")  # each pose's rows in one block, in order
    rows_out = near_rows(robot, T, np.concatenate(rows)[by_pose], pose[by_pose], pair, v0, v)
    return _assemble(robot, N, rows_out, helpers[0], pair)


def near_rows(robot: Arm, T: np.ndarray, H: np.ndarray, pose: np.ndarray,
              pair: CoincidentPair, v0: float, v: float) -> tuple[np.ndarray, ...]:
    """The compiled pass (``kernels.near_coincident``) on helper rows H (M, n).

    Args:
        robot: The arm.
        T: Validated poses (N, 4, 4) [m].
        H: Exact helper rows (joint ``pair.a`` held, joint ``pair.held`` within
            ``KEEP`` of v0), (M, n), each pose's rows in order.
        pose: Their poses (M,), non-decreasing.
        pair: The aligned pair.
        v0: The aligned value [rad].
        v: The held value [rad].

    Returns:
        ``(q (S, n), pose (S,), exact (S,), singular (S,), slot (S,))`` per seed row:
        slot is the row's place among its pose's solutions, -1 when dropped.
    """
    n = robot.n
    S = kernels.NC_SEEDS * len(H)
    q = np.empty((S, n))
    at = np.empty(S, np.int64)
    exact = np.empty(S, bool)
    flag = np.empty(S, bool)
    slot = np.empty(S, np.int64)
    m = kernels.near_coincident(robot.chain.arrays.packed, np.ascontiguousarray(T),
                                np.ascontiguousarray(H, dtype=np.float64),
                                np.ascontiguousarray(pose, dtype=np.int64), pair.held, pair.a,
                                pair.b, pair.sign, v0, v, ACCEPT, q, at, exact, flag, slot)
    return q[:m], at[:m], exact[:m], flag[:m], slot[:m]


def placed(N: int, n: int, rows: tuple[np.ndarray, ...]) -> tuple[np.ndarray, ...]:
    """:func:`near_rows`' rows in their slots: ``(q (N, k, n), valid, singular (N, k))``.

    k is the most exact rows of a pose (at least 1); slots no row took are NaN.
    """
    q, pose, exact, flag, slot = rows
    k = max(1, int(np.bincount(pose[exact], minlength=N).max(initial=0)))
    out = np.full((N, k, n), np.nan)
    ok = np.zeros((N, k), bool)
    sing = np.zeros((N, k), bool)
    put = slot >= 0
    out[pose[put], slot[put]] = q[put]
    ok[pose[put], slot[put]] = True
    sing[pose[put], slot[put]] = flag[put]
    return out, ok, sing


def status_text(ok: np.ndarray, why: np.ndarray) -> np.ndarray:
    """Per pose (N,) status, object dtype: "ok" where ``ok`` (N, k) has a row.

    Elsewhere the helper's status ``why`` (N,), or "no solution with the held value"
    where the helper found rows.
    """
    return np.where(ok.any(axis=-1), "ok",
                    np.where(why == "ok", "no solution with the held value", why)
                    ).astype(object)


def _assemble(robot: Arm, N: int, rows: tuple[np.ndarray, ...], fam: SolutionSet,
              pair: CoincidentPair) -> SolutionSet:
    """The set (N, k, n) of the rows placed in their pose's slots (one per solution)."""
    out, ok, sing = placed(N, robot.n, rows)
    return SolutionSet(out, ok, robot.is_revolute, robot.limits, flags={"singular": sing},
                       status=status_text(ok, fam.status.reshape(N)),
                       method=f"{fam.method} + {METHOD}",
                       info={"near_coincident": (robot.joint_names[pair.a],
                                                 robot.joint_names[pair.b])})
