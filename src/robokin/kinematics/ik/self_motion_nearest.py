"""The in-limit point of a self-motion nearest a configuration, on the exact intervals.

Used by ``SelfMotion.nearest`` and ``ik_near(..., method="self_motion")`` on the
held-joint families (the Panda with q7 held), whose in-limit intervals come from
the compiled ``held_manifold`` pass. Per branch and interval: the distance to
``q_near`` (revolute joints 2 pi wrapped, prismatic ones not: ``_wrapped``) at the
interval's ends and at a grid inside it; the
``_KEEP`` smallest local minima of those samples are refined by safeguarded
Newton steps between their neighbouring samples (to ``_TOL`` rad in t; the best value seen kept); the candidates
(refined minima and every interval end, where a constrained minimum lies) are
tried nearest first, and the first whose row is inside every limit (``MANIFOLD_SLACK``) is
returned, clamped into the limits, each revolute joint but the parameter at its 2 pi
equivalent nearest ``q_near`` where that is inside the limits (as
``SolutionSet.nearest``); a tie of t and t -+ 2 pi goes to the unwrapped nearer.

Then (``nearer_points``, for the compiled swivel's answers too) the solutions the
branches' samples do not hold: the numeric solve from ``q_near`` (a swing next to an
aligned shoulder) and the aligned continua (where joint j puts axes j-1 and j+1 on
one line, the pair turning against each other: a continuum at one parameter value),
each taken where it is nearer and exact, then descended along the self-motion.
"""

from __future__ import annotations

import numpy as np

from robokin.kinematics.arm import Arm
from robokin.kinematics.ik.fixed import Dispatch
from robokin.kinematics.ik.self_motion_base import _Family
from robokin.kinematics.ik.self_motion_continua import (
    EXACT,
    LINE_PAIRS,
    held_rows,
    onto,
    pair_steps,
)
from robokin.kinematics.ik.self_motion_intervals import _within
from robokin.spatial import wrap_angle as _wrap

__all__ = ["interval_nearest", "nearer_points"]

#: Parameter values per interval (ends included).
GRID = 32
#: Local minima refined.
_KEEP = 3
#: Step or bracket width [rad] at which the Newton search stops.
_TOL = 1e-10
#: Newton iterations at most.
_MAX_ITER = 40
#: Central-difference step [rad] of the Newton derivatives.
_H = 1e-5


def interval_nearest(fam: _Family, limits: np.ndarray, intervals: np.ndarray,
                     branches: np.ndarray, q_near: np.ndarray, *, grid: int = GRID
                     ) -> tuple[np.ndarray, float, int, float] | None:
    """The in-limit configuration on the intervals nearest ``q_near``, or None.

    Args:
        fam: The self-motion family (its ``rows(t)`` gives every branch at t).
        limits: Joint limits (n, 2) [rad].
        intervals: (m, 2) in-limit parameter intervals [rad].
        branches: (m,) the branch of each interval.
        q_near: The configuration (n,) [rad].
        grid: Values per interval (ends included), at least 3.

    Returns:
        ``(q (n,), t, branch, distance)``, or None when no row is inside the limits.
    """
    if not len(intervals):
        return None
    g = max(int(grid), 3)
    a, b = intervals[:, :1], intervals[:, 1:]
    t = a + (b - a) * np.linspace(0.0, 1.0, g)  # (m, g)
    br = np.asarray(branches, dtype=np.int64)
    d = _distances(fam, limits, t, br, q_near)
    mt, mb, md = _refined_minima(fam, limits, t, d, br, q_near)
    # interval ends are candidates exactly (a constrained minimum lies there)
    cand_t = np.concatenate([mt, t[:, 0], t[:, -1]])
    cand_b = np.concatenate([mb, br, br])
    cand_d = np.concatenate([md, d[:, 0], d[:, -1]])
    t_near = None if fam.joint is None else float(q_near[fam.joint])
    found = _first_inside(fam, limits, cand_t, cand_b, cand_d, t, d, br, t_near)
    if found is None:
        return None
    q, t_best, b_best, dist = found
    # the 2 pi equivalent of each revolute joint but the parameter nearest q_near,
    # where it is inside the limits (SolutionSet.nearest's rule)
    shifted = q_near + _wrap(q - q_near)
    keep = (_wrapped(fam) & (np.abs(shifted - q) > np.pi)  # a whole turn, not rounding
            & (shifted >= limits[:, 0]) & (shifted <= limits[:, 1]))
    if fam.joint is not None:
        keep[fam.joint] = False  # the parameter: t itself (the tie rule below)
    return np.where(keep, shifted, q), t_best, b_best, dist


def _rows(fam: _Family, t: np.ndarray, br: np.ndarray) -> np.ndarray:
    """Rows (p, g, n) of branch br[i] at t[i, :] (NaN where the branch has none)."""
    q = fam.rows(t.reshape(-1))[0]
    q = q.reshape(t.shape + q.shape[-2:])
    return np.asarray(q[np.arange(len(t)), :, br])


def _wrapped(fam: _Family) -> np.ndarray:
    """(n,) bool: the joints whose differences wrap by 2 pi: the revolute ones.

    A prismatic joint (a track) never wraps.
    """
    return np.asarray(fam.robot.is_revolute, dtype=bool)


def _distances(fam: _Family, limits: np.ndarray, t: np.ndarray, br: np.ndarray,
               q_near: np.ndarray) -> np.ndarray:
    """Distances (p, g) of branch br[i] at t[i, :] to q_near; inf off the limits.

    The :func:`_wrapped` joints' differences are wrapped into [-pi, pi).
    """
    if not t.size:
        return np.zeros(t.shape)
    q = _rows(fam, t, br)
    lo, hi = limits[:, 0], limits[:, 1]
    with np.errstate(invalid="ignore"):
        ok = np.isfinite(q).all(-1) & np.all((q >= lo - 1e-9) & (q <= hi + 1e-9), axis=-1)
    return np.where(ok, _distance(q, q_near, _wrapped(fam)), np.inf)


def _refined_minima(fam: _Family, limits: np.ndarray, t: np.ndarray, d: np.ndarray,
                    br: np.ndarray, q_near: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The ``_KEEP`` smallest local minima of the samples, refined (``_newton``)."""
    left = np.concatenate([np.full((len(d), 1), np.inf), d[:, :-1]], axis=1)
    right = np.concatenate([d[:, 1:], np.full((len(d), 1), np.inf)], axis=1)
    r, c = np.nonzero(np.isfinite(d) & (d <= left) & (d <= right))
    if not len(r):
        return np.zeros(0), np.zeros(0, dtype=np.int64), np.zeros(0)
    order = np.argsort(d[r, c], kind="stable")[:_KEEP]
    r, c = r[order], c[order]
    g = t.shape[1]
    # a minimum sample at an interval's end whose distance rises inward is the
    # constrained minimum (the end is a candidate itself): not refined
    end = (c == 0) | (c == g - 1)
    if end.any():
        inward = t[r, c] + np.where(c == 0, _H, -_H)
        rises = _distances(fam, limits, inward[:, None], br[r], q_near)[:, 0] >= d[r, c]
        keep = ~(end & rises)
        r, c = r[keep], c[keep]
        if not len(r):
            return np.zeros(0), np.zeros(0, dtype=np.int64), np.zeros(0)
    lo = t[r, np.maximum(c - 1, 0)]
    hi = t[r, np.minimum(c + 1, g - 1)]
    x, f = _newton(fam, limits, lo, hi, t[r, c], br[r], q_near)
    return x, br[r], np.sqrt(f)


def _newton(fam: _Family, limits: np.ndarray, lo: np.ndarray, hi: np.ndarray,
            t0: np.ndarray, br: np.ndarray, q_near: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray]:
    """Minima (p,) of the squared distance on brackets [lo, hi], all at once.

    Returns the parameter values and their squared distances (p,).

    Safeguarded Newton steps on the squared distance (its derivatives by central
    differences, step ``_H``), the bracket shrunk on the side the slope points
    away from, a bisection where the step leaves the bracket or the curvature is
    not positive; the best value seen is
    kept, so the result is never farther than the sample it started from.
    """
    lo, hi, x = lo.copy(), hi.copy(), t0.copy()
    best_x = t0.copy()
    best_f = np.full(len(x), np.inf)
    for _ in range(_MAX_ITER):
        f = _distances(fam, limits, np.column_stack([x - _H, x, x + _H]), br, q_near) ** 2
        fm, f0, fp = f[:, 0], f[:, 1], f[:, 2]
        better = f0 < best_f
        best_x, best_f = np.where(better, x, best_x), np.where(better, f0, best_f)
        with np.errstate(invalid="ignore"):
            g = (fp - fm) / (2 * _H)
            c = (fp - 2 * f0 + fm) / _H**2
        ok = np.isfinite(g) & np.isfinite(c)
        hi = np.where(ok & (g > 0), x, hi)
        lo = np.where(ok & (g < 0), x, lo)
        with np.errstate(invalid="ignore", divide="ignore"):
            step = np.where(ok & (c > 0), -g / c, np.nan)
        new = x + step
        bad = ~np.isfinite(new) | (new <= lo) | (new >= hi)
        new = np.where(bad, 0.5 * (lo + hi), new)
        done = (np.abs(new - x) < _TOL) | (hi - lo < _TOL)
        x = new
        if np.all(done):
            break
    return best_x, best_f


def _first_inside(fam: _Family, limits: np.ndarray, cand_t: np.ndarray, cand_b: np.ndarray,
                  cand_d: np.ndarray, t: np.ndarray, d: np.ndarray, br: np.ndarray,
                  t_near: float | None = None
                  ) -> tuple[np.ndarray, float, int, float] | None:
    """The nearest candidate whose row is inside the limits (``_within``), clamped; else None.

    The grid samples are the last candidates (a row at an interval end can be
    outside its limit by more than 1e-12 where the end was bisected). Candidates
    within ``_TIE`` of the nearest distance are one tie, broken toward the parameter
    value nearest ``t_near`` unwrapped: on a joint whose range exceeds 2 pi (a UR-type
    arm) t and t -+ 2 pi are equally near by the wrapped distance, and the one that
    does not turn the joint a full turn is meant.
    """
    all_t = np.concatenate([cand_t, t.ravel()])
    all_b = np.concatenate([cand_b, np.repeat(br, t.shape[1])])
    all_d = np.concatenate([cand_d, d.ravel()])
    lo, hi = limits[:, 0], limits[:, 1]
    best: tuple[np.ndarray, float, int, float] | None = None
    for i in np.argsort(all_d, kind="stable"):
        if not np.isfinite(all_d[i]) or (best is not None and all_d[i] > best[3] + _TIE):
            break
        q = fam.rows(all_t[i:i + 1])[0][0, all_b[i]]
        if not bool(_within(q, limits)):
            continue
        if best is None:
            best = (np.clip(q, lo, hi), float(all_t[i]), int(all_b[i]), float(all_d[i]))
            if t_near is None:
                break
        elif t_near is not None and abs(all_t[i] - t_near) < abs(best[1] - t_near) - _TIE:
            best = (np.clip(q, lo, hi), float(all_t[i]), int(all_b[i]), best[3])
    return best


#: Distances [rad] this close are a tie (``_first_inside``).
_TIE = 1e-9


#: Steps at most of the descent along the self-motion (:func:`_descend`).
_DESCENT = 24
#: A descent step below this [rad]: a local minimum (:func:`_descend`).
_STILL = 1e-9
#: The numeric solution from q_near is taken only this much nearer [rad] than the
#: branch search's answer (a refined minimum: the solver's point next to it is no
#: better by more than rounding; the swings and corners it is for gain 0.05-2 rad).
_GAIN = 1e-6


def nearer_points(robot: Arm, T: np.ndarray, limits: np.ndarray, q_near: np.ndarray,
                  q: np.ndarray, dispatch: Dispatch, *, exact: bool = False) -> np.ndarray:
    """Rows q (m, n) nearest q_near (m, n) on the branches, or nearer in-limit solutions.

    The branch search (a grid per interval, refined minima) misses solutions of two
    kinds:

    1. *A swing or a corner.* Next to an aligned shoulder (q2 = 1e-9 on the Panda) a
       branch turns q1 and q3 by ~pi within ~1e-9 of t, and at a configuration with
       several joints at their limits an interval is a point or a sliver; a q_near
       there is up to ~1 rad from every sampled row. The numeric solver started at
       q_near (``numeric.solve``, tolerance ``EXACT``, no restarts) finds the
       solution next to it, taken where it is nearer by more than ``_GAIN``. On the
       compiled swivel's answers (``exact``) run only where q_near is nearer an
       aligned value (to 1e-6) or a limit than the found answer (a swing's points have
       the joint within ~1e-6 of its aligned value, a corner's joints at their
       limits); on the other families for every pose (a continued family's rows can
       be a continuum's members: the UR5 on a track at q5 = 0, its wrist's axes
       parallel to the shoulder's).
    2. *An aligned continuum.* Where joint j at a value v puts axes j-1 and j+1 on
       one line (``coincident.coincident_pair``: the Panda's q2 = 0, the iiwa's q2 or
       q6 = 0), every configuration turning those joints a, b against each other,
       q_a + s and q_b - sign s, reaches the same pose: where a branch passes q_j = v
       there is a continuum at that one parameter value, which the branches' rows
       meet in one point. Every point of it has q_j = v, so it is no nearer than
       |q_near_j - v| (wrapped): for the poses where that bound is below the found
       distance the pose is solved with joint j held at v (``held_rows``: one row
       per family, each on its continuum) and each row moved along its continuum to
       the point nearest q_near inside the limits (``self_motion_continua.pair_steps``:
       a sum of quadratics between wraps, so its minimum is one of their vertices
       clipped into the in-limit range, or an end of it), then along the continua of
       any other pair the row has on one line (q2 = q6 = 0 on the iiwa: two), every
       two joints of a longer line in turn where pairs share a joint.

    A nearer row is taken onto the pose (``onto``: Newton's least-squares steps)
    and kept if its pose error is within ``EXACT`` and it is inside every limit; such
    rows then descend along the self-motion to a local minimum of the distance
    (:func:`_descend`). So the answer is never farther than the branch search's.

    Args:
        robot: The arm (7R).
        T: Poses (m, 4, 4) [m].
        limits: Joint limits (n, 2) [rad].
        q_near: Configurations (m, n) [rad].
        q: The nearest in-limit rows found on the branches (m, n); NaN: none.
        dispatch: ``dispatch.solve`` (:func:`~robokin.kinematics.ik.fixed.solve_fixed`'s).
        exact: q's rows are within ``EXACT`` of their poses already (the compiled
            swivel's: polished, dropped above 5e-13): not checked.

    Returns:
        (m, n): q (a new array), a row polished where its pose error was above
        ``EXACT``, the rows a nearer solution replaced.
    """
    from robokin.kinematics.ik import numeric
    from robokin.kinematics.ik.coincident import _polish

    if not len(q):
        return q
    q = np.array(q, dtype=np.float64)
    lo, hi = limits[:, 0], limits[:, 1]
    # the branch answers as exact as the rows off them: an answer at a corner of two
    # limits, clamped into them 1e-12 off the pose, is polished with the joints at
    # their limits kept there (the corner's exact point), else with every joint free
    ok = np.flatnonzero(np.isfinite(q).all(-1)) if not exact else np.zeros(0, dtype=int)
    _, err = onto(robot, q[ok], T[ok], steps=0) if len(ok) else (q[ok], np.zeros(0))
    loose = ok[err > EXACT]
    for i in loose:  # (rare: a corner) the joints at a limit kept there, then all free
        at = np.minimum(np.abs(q[i] - lo), np.abs(q[i] - hi)) <= 1e-12
        for free in (np.flatnonzero(~at), np.arange(robot.n)):
            row = _polish(robot, q[i][None], T[i][None], free)[0]
            _, e = onto(robot, row[None], T[i][None], steps=0)
            if e[0] <= EXACT and bool(_within(row, limits)):
                q[i] = np.clip(row, lo, hi)
                break
    wrapped = np.asarray(robot.is_revolute, dtype=bool)
    best = _distance(q, q_near, wrapped)
    best[np.isnan(best)] = np.inf
    idx = np.flatnonzero(best > _TIE)  # q_near itself not the answer
    if not len(idx):
        return q
    found = np.zeros(len(q), dtype=bool)  # rows taken off the branches

    def take(idx: np.ndarray, rows: np.ndarray) -> None:
        """Rows (p, n) as q[idx] where each is a solution inside the limits, nearer.

        Nearer than best[idx]; all at once (``onto``'s Newton steps).
        """
        rows, err = onto(robot, rows, T[idx], steps=0)
        loose = err > EXACT  # (the numeric solver's rows are within EXACT already)
        if loose.any():
            rows[loose], err[loose] = onto(robot, rows[loose], T[idx[loose]])
        d = _distance(np.clip(rows, lo, hi), q_near[idx], wrapped)
        ok = (err <= EXACT) & _within(rows, limits) & (d < best[idx] - _TIE)
        q[idx[ok]], best[idx[ok]], found[idx[ok]] = np.clip(rows[ok], lo, hi), d[ok], True

    pairs = robot.derived(LINE_PAIRS)
    # a continuum's points have its pair's joint at the value v, a swing's within
    # ~1e-6 of it, a corner's joints at their limits: none is nearer than q_near's
    # distance to those values, so only the poses where that is below the found
    # distance are searched
    gap = np.abs(_wrap(q_near[:, [j for j, *_ in pairs]]
                       - np.array([v for _, v, *_ in pairs]))) if pairs else None
    edge = np.minimum(np.abs(q_near - lo), np.abs(q_near - hi)).min(axis=-1)
    edge[~_within(q_near, limits)] = 0.0
    if gap is not None:
        edge = np.minimum(edge, gap.min(axis=-1) - 1e-6)
    if exact:  # the swivel kernel's answers: misses only there (elsewhere, e.g. a
        idx = idx[edge[idx] < best[idx]]  # degenerate continued family: every pose)
    if len(idx):
        local = numeric.solve(robot, T[idx], q0=q_near[idx], tol=EXACT, max_restarts=0)
        ql = np.asarray(local.q, dtype=np.float64).reshape(len(idx), -1)
        dl = np.where(np.asarray(local.success).reshape(-1),
                      _distance(ql, q_near[idx], wrapped), np.inf)
        nearer = dl < best[idx] - _GAIN
        if nearer.any():
            take(idx[nearer], ql[nearer])
    for p, (j, v, *_) in enumerate(pairs):
        assert gap is not None
        idx = np.flatnonzero(gap[:, p] < best - _TIE)
        if not len(idx):
            continue
        held, valid = held_rows(robot, T[idx], j, v, q_near[idx], dispatch)
        k = held.shape[-2]
        rows = held.reshape(-1, robot.n)
        ok = valid.reshape(-1)
        near = np.repeat(q_near[idx], k, axis=0)
        moved = pair_steps(rows, near, pairs, lo, hi, wrapped)
        ok &= np.isfinite(moved).all(-1)
        d = np.where(ok, _distance(moved, near, wrapped), np.inf).reshape(len(idx), k)
        c = np.argmin(d, axis=1)
        r = np.arange(len(idx))
        nearer = d[r, c] < best[idx] - _TIE
        if nearer.any():
            take(idx[nearer], moved.reshape(len(idx), k, robot.n)[r, c][nearer])
    if found.any():  # (the search's own rows are refined minima already)
        q[found] = _descend(robot, T[found], limits, q_near[found], q[found], wrapped)
    return q


def _descend(robot: Arm, T: np.ndarray, limits: np.ndarray, q_near: np.ndarray,
             q: np.ndarray, wrapped: np.ndarray) -> np.ndarray:
    """Rows q (m, n) moved along the self-motion to a local minimum of the distance.

    A step pulls the row toward q_near within the null space of its Jacobian (the
    self-motion's tangent: the n - 6 directions of a redundant arm and those of
    singular values below 1e-9 of the largest) and takes it back onto the pose by
    Newton's least-squares steps (``onto``); it is halved until the row is
    nearer, inside the limits and within ``EXACT`` of the pose. A row stops where
    the pull's step is below ``_STILL`` (a local minimum to within ~1e-18 of the
    distance: the search's refined minima start there), where it would take a joint
    at its limit outward (a constrained minimum), after six halvings, or after
    ``_DESCENT`` steps. What it is for: a branch through a swing (q1 and q3 turning
    by ~pi within ~1e-6 of t next to an aligned shoulder), which the search's
    samples step over, from the numeric solution next to q_near.
    """
    from robokin.kinematics.jacobian import jacobian_and_pose

    q = q.copy()
    lo, hi = limits[:, 0], limits[:, 1]
    live = np.flatnonzero(np.isfinite(q).all(-1))
    alpha = np.ones(len(q))
    for _ in range(_DESCENT):
        if not len(live):
            break
        J, _ = jacobian_and_pose(robot.chain, q[live])
        _, sv, Vt = np.linalg.svd(J)  # Vt (m, n, n)
        null = np.ones((len(live), robot.n), dtype=bool)
        null[:, :sv.shape[-1]] = sv < 1e-9 * sv[:, :1]
        pull = np.where(wrapped, _wrap(q_near[live] - q[live]), q_near[live] - q[live])
        step = np.einsum("mkn,mk->mn", Vt, np.einsum("mkn,mn->mk", Vt, pull) * null)
        blocked = (((q[live] <= lo + 1e-9) & (step < -1e-12))
                   | ((q[live] >= hi - 1e-9) & (step > 1e-12))).any(-1)
        done = blocked | (np.abs(step).max(axis=-1) < _STILL)
        live, step = live[~done], step[~done]
        if not len(live):
            break
        trial, err = onto(robot, q[live] + step * alpha[live, None], T[live])
        ok = ((err <= EXACT) & _within(trial, limits)
              & (_distance(trial, q_near[live], wrapped)
                 < _distance(q[live], q_near[live], wrapped)))
        q[live[ok]] = np.clip(trial[ok], lo, hi)
        alpha[live[~ok]] *= 0.5
        live = live[alpha[live] > 1.0 / 64]
    return q


def _distance(q: np.ndarray, q_near: np.ndarray, wrapped: np.ndarray) -> np.ndarray:
    """(...) distances of rows q (..., n) to q_near (broadcast against q).

    The ``wrapped`` joints' differences (the revolute ones: :func:`_wrapped`) are
    wrapped into [-pi, pi).
    """
    with np.errstate(invalid="ignore"):
        diff = q - q_near
        out: np.ndarray = np.linalg.norm(np.where(wrapped, _wrap(diff), diff), axis=-1)
    return out


