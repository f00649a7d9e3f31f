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
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from robokin._native import kernels
from robokin.kinematics.arm import Arm
from robokin.kinematics.forward import forward_kinematics
from robokin.kinematics.ik.analytic._common import fit_turns
from robokin.kinematics.ik.coincident import (
    EXACT,
    HELPER_TURN,
    CoincidentPair,
    coincident_pair,
)
from robokin.kinematics.ik.solutions import SolutionSet
from robokin.kinematics.jacobian import jacobian_and_pose
from robokin.spatial import pose_error, wrap_angle

__all__ = ["near_coincident_pair", "solve_near_coincident"]

#: Held values this close [rad] to an aligned value v0 take this path (the general
#: 6R solver declines the chain up to ~1e-4 rad on the Panda; it solves 1e-3 exactly)
NEAR = 1e-3
#: Aligned values tried: the special values where real arms line their axes up
ALIGNED = (0.0, np.pi / 2, -np.pi / 2, np.pi, -np.pi)
#: A family whose 6 x 5 matrix has a smallest singular value below this (relative)
#: is singular itself: seeded over the whole turn instead
FAMILY_RANK = 1e-6
#: Helper rows (joint a held) with the held joint this close [rad] to v0 seed the search
KEEP = 1e-2
#: Relative cut of the Newton step's SVD (far below |v - v0| ~ 1e-9)
RCOND = 1e-15
#: Largest Newton step [rad] of any joint
MAX_STEP = 0.5
#: Newton iterations, then ones with the coarser cut
STEPS = 15
FINAL = 3
FINAL_RCOND = 1e-10
#: Newton iterations of a row moved into the limits (its split or joints held: the
#: rest well conditioned, converged in 2-3 where it can be)
PIN_STEPS = 6
#: Two rows this close [rad] (every joint) are one solution (next to a second
#: aligned set, q5 = 1e-9 on the Panda, Newton leaves copies 1e-6 apart)
SAME = 1e-4
#: Pose error (m, rad; norms) a returned row must reach: a margin below the promised
#: ``EXACT`` (1e-12; a converged row reaches 1e-16, one stuck near 1e-12 is suspect)
ACCEPT = EXACT / 10
#: Two Newton seeds of one pose this close [rad] (every joint) are one
SAME_SEED = 1e-3
#: Largest move [rad] of the split that brings a row into the pair's limits
SHIFT = 1e-2
#: Rows flagged singular: free-joint Jacobian's smallest / largest singular value below
FLAG = 1e-5


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


def _newton(robot: Arm, q: np.ndarray, T: np.ndarray, free: np.ndarray,
            steps: int = STEPS, final: int = FINAL) -> np.ndarray:
    """Newton on the joints ``free`` of rows q (m, n) to poses T (m, 4, 4), SVD steps.

    Each row's best iterate is kept (at a doubly singular configuration, the
    smallest singular value ~1e-14, the steps can wander once converged); the last
    ``FINAL`` steps cut at ``FINAL_RCOND`` (such directions left out). One batch
    for all rows, a row leaving it once at 1e-16; the compiled Jacobian and
    residual (``chain.h``) are called directly on the batch (the public wrappers'
    checks cost more than the step itself on a few rows).
    """
    q = np.array(q, dtype=np.float64, order="C")
    T = np.ascontiguousarray(T, dtype=np.float64)
    n = robot.n
    rev = robot.is_revolute[free]
    packed = robot.chain.arrays.packed
    best: np.ndarray = q.copy()
    low = np.full(len(q), np.inf)
    act = np.arange(len(q))  # rows not yet at 1e-16
    k = 0
    while k < steps + final:
        if k == steps:
            act = np.flatnonzero(low > 1e-16)
            q[act] = best[act]  # the coarser steps from each row's best
        if not len(act):
            if k >= steps:
                break
            k = steps  # every row at 1e-16 or at a fixed point: the coarser steps
            continue
        J, e = _jacobian_residual(robot, packed, n, q[act], T[act])
        err = np.abs(e).max(axis=-1, initial=0.0)
        better = err < low[act]
        if better.any():
            best[act[better]], low[act[better]] = q[act[better]], err[better]
        go = err > 1e-16
        if not go.all():
            act, J, e = act[go], J[go], e[go]
        if len(act):
            act = _step(q, act, J, e, free, rev, RCOND if k < steps else FINAL_RCOND)
        k += 1
    return best


def _step(q: np.ndarray, act: np.ndarray, J: np.ndarray, e: np.ndarray, free: np.ndarray,
          rev: np.ndarray, cut: float) -> np.ndarray:
    """One SVD step of rows ``act`` of q (m, n) in place; the rows it moved.

    J (k, 6, n) and e (k, 6) are those rows' Jacobians and residuals; the step is a
    least-squares solve on the columns ``free`` with singular values below ``cut``
    of the largest left out. A row the step leaves bitwise where it was is at a
    fixed point of the iteration (the next steps would repeat this one): it leaves
    the batch, which changes no result.
    """
    U, s, Vt = np.linalg.svd(J[:, :, free], full_matrices=False)
    inv = np.where(s > cut * s[:, :1], 1.0 / np.where(s > 0, s, 1.0), 0.0)
    step = np.einsum("mji,mj,mkj,mk->mi", Vt, inv, U, e)
    # at most MAX_STEP rad per joint (a step along a near-null direction can be
    # thousands of radians), the angles kept in [-pi, pi] (their rounding small)
    step *= np.minimum(1.0, MAX_STEP / np.maximum(np.abs(step).max(axis=-1), 1e-300))[:, None]
    old = q[act[:, None], free]
    x = old + step
    new = np.where(rev, wrap_angle(x), x)
    q[act[:, None], free] = new
    return act[np.any(new != old, axis=-1)]


def _jacobian_residual(robot: Arm, packed: np.ndarray, n: int, q: np.ndarray,
                       T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Jacobians (m, 6, n) at rows q (m, n) and residuals (m, 6) to poses T (m, 4, 4).

    The same compiled formulas as :func:`jacobian_and_pose` and :func:`pose_error`
    on C-contiguous float64 batches (made here); a non-finite row goes through
    :func:`jacobian_and_pose` for its error.
    """
    m = len(q)
    J = np.empty((m, 6, n))
    Tq = np.empty((m, 4, 4))
    if not kernels.jacobian(packed, q, J, Tq):
        jacobian_and_pose(robot.chain, q)  # raises the InputError naming the row
    e = np.empty((m, 6))
    kernels.pose_error(Tq, T, e)
    return J, e


def _exact(robot: Arm, q: np.ndarray, T: np.ndarray, tol: float = ACCEPT) -> np.ndarray:
    """(m,) bool: rows q (m, n) reach poses T (m, 4, 4) to ``tol`` (m, rad; norms)."""
    e = pose_error(forward_kinematics(robot.chain, q), T)
    err = np.maximum(np.linalg.norm(e[:, :3], axis=-1), np.linalg.norm(e[:, 3:], axis=-1))
    return np.asarray(np.all(np.isfinite(q), axis=-1) & (err <= tol))


def _into_limits(robot: Arm, q: np.ndarray, pair: CoincidentPair) -> np.ndarray:
    """Rows q (m, n) with the pair's split moved (at most ``SHIFT``) into both limits.

    Next to aligned the pose barely depends on the split (by ~|v - v0| per radian):
    a row Newton left 1e-6 past a limit along it is as exact just inside.
    """
    la, lb = robot.limits[pair.a], robot.limits[pair.b]
    # q_a + d in la and q_b - sign d in lb
    ends = np.sort(pair.sign * (q[:, pair.b, None] - lb[None, ::-1]), axis=-1)
    lo = np.maximum(la[0] - q[:, pair.a], ends[:, 0])
    hi = np.minimum(la[1] - q[:, pair.a], ends[:, 1])
    # an empty interval (both joints at a limit: a single in-limit split, which
    # Newton misses by ~1e-7): the middle; the polish after it recomputes q_b
    d = np.where(lo <= hi, np.clip(0.0, lo, hi), 0.5 * (lo + hi))
    d = np.where((lo <= hi + SHIFT) & (np.abs(d) <= SHIFT), d, 0.0)
    out: np.ndarray = q.copy()
    out[:, pair.a] += d
    out[:, pair.b] -= pair.sign * d
    return out


def _pinned(robot: Arm, q: np.ndarray, T: np.ndarray, pair: CoincidentPair,
            free: np.ndarray, hold_split: bool) -> np.ndarray:
    """Rows q (m, n) moved into the limits where they are at most ``SHIFT`` outside.

    The pair's split is moved (:func:`_into_limits`) and held where it moved, any
    other joint outside by at most ``SHIFT`` is set to its limit and held, and the
    joints left polished to the poses T (m, 4, 4) (next to a second aligned set, q5 = 1e-7,
    Newton leaves q7 1e-8 past its limit on a continuum; there the split must stay
    free, ``hold_split`` False; True: held on every row, q_b pinned too). The caller
    checks the rows are still exact.
    """
    lim = robot.limits
    moved = _into_limits(robot, q, pair)
    past = np.maximum(lim[:, 0] - moved, moved - lim[:, 1])
    pin = (past > 0.0) & (past <= SHIFT)
    pin[:, [pair.held, pair.a]] = False
    if not hold_split:
        pin[:, pair.b] = False
    # a moved split is held (or every split, hold_split)
    pin[:, pair.a] = hold_split | (moved[:, pair.a] != q[:, pair.a])
    moved = np.where(pin, np.clip(moved, lim[:, 0], lim[:, 1]), moved)
    changed = np.any(moved != q, axis=-1) | hold_split
    masks, group = np.unique(pin[changed], axis=0, return_inverse=True)
    rows = np.flatnonzero(changed)
    for g, mask in enumerate(masks):
        at = rows[group.ravel() == g]
        rest = np.array([i for i in free if not mask[i]])
        moved[at] = _newton(robot, moved[at], T[at], rest, PIN_STEPS, 0)
    moved = fit_turns(moved, robot.is_revolute, lim)  # Newton wraps to +-pi
    moved[:, pair.held] = q[:, pair.held]
    return moved


def _distinct(pose: list[int], seeds: list[np.ndarray]) -> tuple[list[int], list[np.ndarray]]:
    """The seeds with a different pose or more than ``SAME_SEED`` apart (first kept)."""
    kept: dict[int, list[np.ndarray]] = {}
    out_pose, out = [], []
    for p, q in zip(pose, seeds):
        mine = kept.setdefault(p, [])
        if any(float(np.abs(wrap_angle(q - r)).max()) <= SAME_SEED for r in mine):
            continue
        mine.append(q)
        out_pose.append(p)
        out.append(q)
    return out_pose, out


def _past(robot: Arm, q: np.ndarray) -> np.ndarray:
    """(m,) how far [rad] rows q (m, n) are outside the limits at most (0 inside)."""
    lim = robot.limits
    return np.asarray(np.maximum(lim[:, 0] - q, q - lim[:, 1]).max(axis=-1, initial=0.0)
                      .clip(0.0))


def _splits(robot: Arm, row: np.ndarray, pair: CoincidentPair, v0: float,
            v: float) -> np.ndarray:
    """Splits t = q_a where the self-motion through ``row`` crosses the held value v.

    ``row`` is an exact solution of the pose with the held joint at w (next to v0) and
    q_a at c. To first order in the held joint's offset, the pose's distance from
    the aligned chain's image along the family's normal n is ``(w - v0) h(c)`` with
    ``h(t) = n . c(t) = alpha + beta cos t + gamma sin t``; the splits with the held
    joint at v solve ``(v - v0) h(t) = (w - v0) h(c)``. Eight splits over the turn
    besides (Newton keeps what is exact).
    """
    n = robot.n
    c = float(row[pair.a])
    w = float(wrap_angle(row[pair.held] - v0))
    total = row[pair.a] + pair.sign * row[pair.b]
    spread = c + np.arange(8) * (np.pi / 4.0)
    ts = c + np.array([0.0, 2.0 * np.pi / 3.0, 4.0 * np.pi / 3.0])
    Q = np.repeat(row[None], 3, axis=0)
    Q[:, pair.held] = v0
    Q[:, pair.a] = ts
    Q[:, pair.b] = pair.sign * (total - ts)
    J, _ = jacobian_and_pose(robot.chain, Q)
    others = [i for i in range(n) if i not in (pair.held, pair.a, pair.b)]
    U, s, _ = np.linalg.svd(J[0][:, [pair.a] + others])
    if s[-1] < FAMILY_RANK * s[0]:
        return spread
    h = U[:, -1] @ J[:, :, pair.held].T  # n . c(t) at the three splits
    # h_k = alpha + beta cos(t_k) + gamma sin(t_k): three equations, three unknowns
    M = np.stack([np.ones(3), np.cos(ts), np.sin(ts)], axis=-1)
    alpha, beta, gamma = np.linalg.solve(M, h)
    radius = float(np.hypot(beta, gamma))
    if radius <= 1e-12 * max(1.0, float(np.abs(h).max())):
        return spread
    x = (w / (v - v0) * float(h[0]) - float(alpha)) / radius
    if abs(x) > 1.0 + 1e-6:
        return spread
    phi = float(np.arctan2(gamma, beta))
    d = float(np.arccos(min(1.0, max(-1.0, x))))
    return np.array([phi + d, phi - d])


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
    pose, seeds = [], []
    for helper in helpers:
        Qh, okh = helper.q.reshape(N, -1, n), helper.valid.reshape(N, -1)
        okh = okh & (np.abs(wrap_angle(Qh[..., pair.held] - v0)) <= KEEP)
        for p, r in zip(*np.nonzero(okh)):
            row = Qh[p, r]
            total = row[pair.a] + pair.sign * row[pair.b]
            for t in _splits(robot, row, pair, v0, v):
                q = row.copy()
                q[pair.a] = t
                q[pair.b] = pair.sign * (total - t)
                q[pair.held] = v
                seeds.append(q)
                pose.append(p)
    free = np.array([i for i in range(n) if i != pair.held])
    pose, seeds = _distinct(pose, seeds)  # both helper values find each family
    pose_a = np.array(pose, int)
    q = np.zeros((0, n))
    exact = np.zeros(0, bool)
    flag = np.zeros(0, bool)
    if seeds:
        q = _newton(robot, np.array(seeds), T[pose_a], free)
        q = fit_turns(q, robot.is_revolute, robot.limits)
        q[:, pair.held] = v
        exact = _exact(robot, q, T[pose_a])
        for hold in (False, True):  # rows outside the limits: moved in where exact
            out = np.flatnonzero(_past(robot, q) > 0.0)
            if not len(out):
                break
            moved = _pinned(robot, q[out], T[pose_a[out]], pair, free, hold)
            keep = (_exact(robot, moved, T[pose_a[out]])
                    & (_past(robot, moved) < _past(robot, q[out])))
            q[out[keep]] = moved[keep]
            exact[out[keep]] = True
        s = np.linalg.svd(jacobian_and_pose(robot.chain, q)[0][:, :, free], compute_uv=False)
        flag = s[:, -1] < FLAG * s[:, 0]
    return _assemble(robot, N, pose_a, q, exact, flag, helpers[0], pair)


def _assemble(robot: Arm, N: int, pose: np.ndarray, q: np.ndarray, exact: np.ndarray,
              flag: np.ndarray, fam: SolutionSet, pair: CoincidentPair) -> SolutionSet:
    """The set (N, k, n) of the exact rows, one copy of each solution."""
    n = robot.n
    k = max(1, int(np.bincount(pose[exact], minlength=N).max(initial=0)))
    out = np.full((N, k, n), np.nan)
    ok = np.zeros((N, k), bool)
    sing = np.zeros((N, k), bool)
    slot = np.zeros(N, int)
    past = _past(robot, q)
    # the rows least outside the limits first: of two copies of a solution the one
    # inside (or nearest inside) is kept
    for i in sorted(np.flatnonzero(exact).tolist(), key=lambda i: float(past[i])):
        at = int(pose[i])
        if ok[at].any() and (np.abs(wrap_angle(out[at, ok[at]] - q[i])).max(axis=-1)
                             <= SAME).any():
            continue
        out[at, slot[at]] = q[i]
        ok[at, slot[at]] = True
        sing[at, slot[at]] = flag[i]
        slot[at] += 1
    why = fam.status.reshape(N)
    status = np.where(ok.any(axis=-1), "ok",
                      np.where(why == "ok", "no solution with the held value", why))
    return SolutionSet(out, ok, robot.is_revolute, robot.limits, flags={"singular": sing},
                       status=status.astype(object),
                       method=f"{fam.method} + near-coincident axes, Newton",
                       info={"near_coincident": (robot.joint_names[pair.a],
                                                 robot.joint_names[pair.b])})
