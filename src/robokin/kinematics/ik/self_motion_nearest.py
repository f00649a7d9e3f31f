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

from collections.abc import Callable

import numpy as np

from robokin.kinematics.arm import Arm
from robokin.kinematics.ik.fixed import Dispatch, _held_solvers
from robokin.kinematics.ik.self_motion_base import _Family
from robokin.kinematics.ik.self_motion_continua import (
    EXACT,
    LINE_PAIRS,
    held_rows,
    onto,
    pair_steps,
)
from robokin.kinematics.ik.self_motion_intervals import _in_bounds, _within
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
                     branches: np.ndarray, q_near: np.ndarray, *, grid: int = GRID,
                     slack: float = 1e-9) -> tuple[np.ndarray, float, int, float] | None:
    """The in-limit configuration on the intervals nearest ``q_near``, or None.

    Args:
        fam: The self-motion family (its ``rows(t)`` gives every branch at t).
        limits: Joint limits (n, 2) [rad].
        intervals: (m, 2) in-limit parameter intervals [rad].
        branches: (m,) the branch of each interval.
        q_near: The configuration (n,) [rad].
        grid: Values per interval (ends included), at least 3.
        slack: A row this far outside a limit [rad, m] is taken, clamped (an
            interval's end where a joint crosses its limit steeply is off it by its
            slope times the last bit of t: the Panda's q1 next to an aligned
            shoulder 4e-11 out); the caller takes it back onto the pose.

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
    found = _first_inside(fam, limits, cand_t, cand_b, cand_d, t, d, br, t_near, slack)
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
                  t_near: float | None = None, slack: float = 0.0
                  ) -> tuple[np.ndarray, float, int, float] | None:
    """The nearest candidate whose row is inside the limits (+ ``slack``), clamped; else None.

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
        if not bool(_within(q, limits + np.array([-slack, slack]))):
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
                  q: np.ndarray, dispatch: Dispatch, *, exact: bool = False,
                  seeds: Callable[[], np.ndarray] | None = None) -> np.ndarray:
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
        seeds: Gives rows (m, k, n) of the branches at their aligned-axes points
            (NaN: none), called where a pose has no row held at a pair's value
            nearer than the answer: moved along the continua they are within
            ``_SWING_ON`` of as the held rows are (a swing 1e-9..1e-4 off its
            continuum, where no end joint has a held closed form: the Panda's
            shoulder).

    Returns:
        (m, n): q (a new array), a row polished where its pose error was above
        ``EXACT``, the rows a nearer solution replaced; q_near's own row where q_near
        is inside the limits and within ``EXACT`` of its pose.
    """
    from robokin.kinematics.forward import forward_kinematics
    from robokin.kinematics.ik import numeric

    if not len(q):
        return q
    q = np.array(q, dtype=np.float64)
    lo, hi = limits[:, 0], limits[:, 1]
    # the branch answers as exact as the rows off them: an answer at a corner of two
    # limits, clamped into them 1e-12 off the pose, is polished with the joints at
    # their limits kept there (the corner's exact point), else with every joint free
    ok = np.isfinite(q).all(-1)
    if exact:  # (the kernel's rows clamped onto a limit can be 1e-12 off the pose)
        with np.errstate(invalid="ignore"):
            ok &= (np.minimum(np.abs(q - lo), np.abs(q - hi)) <= 1e-12).any(-1)
    ok = np.flatnonzero(ok)
    _, err = onto(robot, q[ok], T[ok], steps=0) if len(ok) else (q[ok], np.zeros(0))
    for i in ok[err > EXACT]:  # (rare: a corner)
        row, e = _at_limits(robot, q[i], T[i], limits)
        if e <= EXACT:
            q[i] = row
    # q_near itself where it solves its pose inside the limits (the search's answer next
    # to a swing is up to ~5e-6 from it: t to rounding where q moves ~1e5 times faster);
    # its forward kinematics first (the pose error's rotation log only where that is
    # within 1e-9 of the pose: ~45 us a call otherwise)
    mine = _within(q_near, limits)
    if mine.any():
        F = forward_kinematics(robot.chain, q_near[mine])
        close = np.flatnonzero(mine)[np.abs(F - T[mine]).max(axis=(-2, -1)) <= 1e-9]
        mine[:] = False
        if len(close):
            _, own = onto(robot, q_near[close], T[close], steps=0)
            mine[close[own <= EXACT]] = True
    q[mine] = q_near[mine]
    wrapped = np.asarray(robot.is_revolute, dtype=bool)
    best = _distance(q, q_near, wrapped)
    best[np.isnan(best)] = np.inf
    idx = np.flatnonzero(best > _TIE)  # q_near itself not the answer
    if not len(idx):
        return q
    found = np.zeros(len(q), dtype=bool)  # rows taken off the branches

    def take(idx: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """Rows (p, n) as q[idx] where each is a solution inside the limits, nearer.

        Nearer than best[idx]; all at once (``onto``'s Newton steps). Returns which
        were taken (p,).
        """
        rows, err = onto(robot, rows, T[idx], steps=0)
        loose = err > EXACT  # (the numeric solver's rows are within EXACT already)
        if loose.any():
            rows[loose], err[loose] = onto(robot, rows[loose], T[idx[loose]])
        # a continuum's point at a limit can come out 1e-11..1e-8 past it (an aligned
        # joint 1e-7 off its value), a numeric one 1e-3: taken back to the limit (and a
        # row past one by rounding: clamped, it can leave the pose by ~1e-12)
        past = np.flatnonzero(~_in_bounds(rows, lo, hi) & _within(rows, limits + _PAST))
        for i in past:
            rows[i], err[i] = _at_limits(robot, rows[i], T[idx[i]], limits)
        stuck = np.flatnonzero(((err > EXACT) | ~_within(rows, limits))
                               & _within(rows, limits + _PAST))
        if len(stuck):  # Newton's steps stall next to a swing: an end joint held there
            rows[stuck], err[stuck] = _snapped(robot, rows[stuck], T[idx[stuck]], limits,
                                               dispatch)
        d = _distance(np.clip(rows, lo, hi), q_near[idx], wrapped)
        ok: np.ndarray = (err <= EXACT) & _within(rows, limits) & (d < best[idx] - _TIE)
        q[idx[ok]], best[idx[ok]], found[idx[ok]] = np.clip(rows[ok], lo, hi), d[ok], True
        return ok

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
    values = np.array([v for _, v, *_ in pairs])
    # a swing's signs (the end joints' held seeds below run there only): the numeric
    # solve from q_near stalls off the pose, or ends next to a pair's aligned value
    swing = np.zeros((len(q), len(pairs)), dtype=bool)
    if len(idx):
        local = numeric.solve(robot, T[idx], q0=q_near[idx], tol=EXACT, max_restarts=0)
        ql = np.asarray(local.q, dtype=np.float64).reshape(len(idx), -1)
        # (next to a singular point the steps stall 1e-11..1e-9 off the pose: ``take``'s
        # Newton steps finish those)
        reached = np.asarray(local.success).reshape(-1).copy()
        if not reached.all():
            _, el = onto(robot, ql[~reached], T[idx[~reached]], steps=0)
            reached[~reached] = el <= _NEAR_MISS
        if pairs:
            with np.errstate(invalid="ignore"):
                off = np.abs(_wrap(ql[:, [j for j, *_ in pairs]] - values))
            swing[idx] = ~reached[:, None] | ~(off > _SWING_NEAR)
        dl = np.where(reached, _distance(ql, q_near[idx], wrapped), np.inf)
        nearer = dl < best[idx] - _GAIN
        if nearer.any():
            take(idx[nearer], ql[nearer])

    def take_moved(idx: np.ndarray, held: np.ndarray, valid: np.ndarray) -> np.ndarray:
        """Held rows (p, k, n) of poses idx moved along their continua: the nearest taken.

        Moved along every line a row's joints are within ``_SWING_ON`` of (a swing's
        lines, 1e-9..1e-4 off: the move leaves the pose by about that times its step,
        which ``take`` takes back where it can), then along its exact lines only.
        Returns the poses (of idx) where a row was taken.
        """
        taken = np.zeros(len(q), dtype=bool)
        k = held.shape[-2]
        if not k:
            return np.flatnonzero(taken)
        near = np.repeat(q_near[idx], k, axis=0)
        with np.errstate(invalid="ignore"):
            off = np.abs(_wrap(held[..., [j for j, *_ in pairs]] - values))
            loose = ((off > 0.0) & (off <= _SWING_ON)).any(-1).any(-1)  # (p,)
        for on in (_SWING_ON, 0.0):
            if on == 0.0:  # (again only where a line was taken 1e-9..1e-4 off)
                idx, held, valid, near = (idx[loose], held[loose], valid[loose],
                                          np.repeat(q_near[idx[loose]], k, axis=0))
                if not len(idx):
                    break
            moved = pair_steps(held.reshape(-1, robot.n), near, pairs, lo, hi, wrapped, on=on)
            # (a row with a joint the lines do not move outside its limits is no answer:
            # it would hide an in-limit row farther from q_near, the Panda's q6 0.6 out)
            ok = (valid.reshape(-1) & np.isfinite(moved).all(-1)
                  & _within(moved, limits + _PAST))
            d = np.where(ok, _distance(moved, near, wrapped), np.inf).reshape(len(idx), k)
            c = np.argmin(d, axis=1)
            r = np.arange(len(idx))
            nearer = d[r, c] < best[idx] - _TIE
            if nearer.any():
                ok = take(idx[nearer], moved.reshape(len(idx), k, robot.n)[r, c][nearer])
                taken[idx[nearer][ok]] = True
        return np.flatnonzero(taken)

    on_none = np.ones((len(q), len(pairs)), dtype=bool)  # no held row at v taken
    for p, (j, v, *_) in enumerate(pairs):
        assert gap is not None
        idx = np.flatnonzero(gap[:, p] < best - _TIE)
        if len(idx):
            on_none[take_moved(idx, *held_rows(robot, T[idx], j, v, q_near[idx], dispatch)),
                    p] = False
    for p, (_, _, a, b, _) in enumerate(pairs):
        # a branch passing 1e-9..1e-6 from the continuum (q_j never at v: no row held
        # there) swings q_a and q_b by ~pi next to it: its solutions with an end joint
        # of the pair at q_near's value, moved along the continua they are on (where
        # the numeric solve shows a swing: ``swing``)
        assert gap is not None
        idx = np.flatnonzero(on_none[:, p] & swing[:, p] & (gap[:, p] < best - _TIE))
        for e in (a, b) if len(idx) else ():
            if e not in (0, robot.n - 1) or robot.joint_names[e] not in _held_solvers(robot):
                continue  # (a held closed form only: a middle joint's set-up is per value)
            at = np.clip(np.where(wrapped[e], _wrap(q_near[idx, e]), q_near[idx, e]),
                         lo[e], hi[e])
            take_moved(idx, *held_rows(robot, T[idx], e, at, q_near[idx], dispatch))
    if seeds is not None and gap is not None:
        idx = np.flatnonzero((on_none & (gap < best[:, None] - _TIE)).any(-1))
        rows = seeds() if len(idx) else None
        if rows is not None and rows.shape[1]:
            take_moved(idx, rows[idx], np.isfinite(rows[idx]).all(-1))
    if found.any():  # (the search's own rows are refined minima already)
        q[found] = _descend(robot, T[found], limits, q_near[found], q[found], wrapped)
    return q


def _snapped(robot: Arm, rows: np.ndarray, T: np.ndarray, limits: np.ndarray,
             dispatch: Dispatch) -> tuple[np.ndarray, np.ndarray]:
    """Rows (m, n) near poses T (m, 4, 4) replaced by a held closed form's nearest row.

    Next to a swing (a joint 1e-9 from putting two axes on one line) Newton's steps
    stall ~1e-11 off the pose, or a hair past a limit: the pose is solved with each
    end joint that has a held closed form held at the row's value clipped into its
    limits; of those solutions within ``EXACT`` of the pose and inside every limit the
    one nearest the row is taken (next to a swing ~1e-2 away: its joints turn ~1e9
    times as fast as the held one; the caller keeps it only where it is nearer
    q_near). Returns the rows and their pose errors (inf where none is found).
    """
    out, err = rows.copy(), np.full(len(rows), np.inf)
    gap = np.full(len(rows), np.inf)
    wrapped = np.asarray(robot.is_revolute, dtype=bool)
    for e in (robot.n - 1, 0):
        if robot.joint_names[e] not in _held_solvers(robot):
            continue
        at = np.clip(rows[:, e], limits[e, 0], limits[e, 1])
        held, valid = held_rows(robot, T, e, at, rows, dispatch)
        m, k = held.shape[:2]
        if not k:
            continue
        flat = held.reshape(-1, robot.n)
        _, e_all = onto(robot, np.where(valid.reshape(-1, 1), flat, 0.0),
                        np.repeat(T, k, axis=0), steps=0)
        ok = valid & (e_all.reshape(m, k) <= EXACT) & _within(held, limits)
        d = np.where(ok, _distance(held, rows[:, None], wrapped), np.inf)
        c = np.argmin(d, axis=1)
        r = np.arange(m)
        better = d[r, c] < gap
        out[better], err[better] = held[r, c][better], e_all.reshape(m, k)[r, c][better]
        gap[better] = d[r, c][better]
    return out, err


def _at_limits(robot: Arm, q: np.ndarray, T: np.ndarray, limits: np.ndarray
               ) -> tuple[np.ndarray, float]:
    """A row q (n,) at most ``_PAST`` outside its limits, onto pose T (4, 4) inside them.

    The row moved along the self-motion until the joint farthest outside is at its
    limit (steps along the Jacobian's null vector, each taken back onto the pose by
    Newton's steps), else clipped into the limits, its joints at a limit (to 1e-12)
    kept there and the others polished (``coincident._polish``: a corner's exact
    point; a joint that polish takes past its limit held there too, up to three
    rounds), else every joint polished. Every candidate's error is taken after its
    clamp into the limits. Returns the row (clipped) and its pose error
    [m, rad]; inf where none is within ``EXACT`` of the pose inside the limits (the
    row as given).
    """
    from robokin.kinematics.ik.coincident import _polish
    from robokin.kinematics.jacobian import jacobian_and_pose

    lo, hi = limits[:, 0], limits[:, 1]
    row = q.copy()
    for _ in range(_SLIDES):
        over = np.maximum(lo - row, row - hi)
        k = int(np.argmax(over))
        if over[k] <= 0.0:
            break
        J, _ = jacobian_and_pose(robot.chain, row[None])
        n = np.linalg.svd(J[0])[2][-1]  # the self-motion's tangent
        if abs(n[k]) < 1e-9:
            break
        row = row + n * ((np.clip(row[k], lo[k], hi[k]) - row[k]) / n[k])
        row = onto(robot, row[None], T[None])[0][0]
    # (each candidate's error is taken after its clamp into the limits: a joint 1e-12
    # past one, clamped, leaves the pose by ~1e-12, more than EXACT)
    if bool(_within(row, limits)):
        row = np.clip(row, lo, hi)
        _, e = onto(robot, row[None], T[None], steps=0)
        if e[0] <= EXACT:
            return row, float(e[0])
    start = np.clip(q, lo, hi)
    held = np.minimum(np.abs(start - lo), np.abs(start - hi)) <= 1e-12
    for _ in range(3):  # a joint the polish takes past its limit is held there next
        row = _polish(robot, start[None], T[None], np.flatnonzero(~held))[0]
        clamped = np.clip(row, lo, hi)
        _, e = onto(robot, clamped[None], T[None], steps=0)
        if e[0] <= EXACT and bool(_within(row, limits)):
            return clamped, float(e[0])
        past = ((row < lo) | (row > hi)) & ~held
        if not past.any() or past.all():
            break
        held |= past
        start = clamped
    row = _polish(robot, np.clip(q, lo, hi)[None], T[None], np.arange(robot.n))[0]
    if bool(_within(row, limits)):
        row = np.clip(row, lo, hi)
        _, e = onto(robot, row[None], T[None], steps=0)
        if e[0] <= EXACT:
            return row, float(e[0])
    return q, np.inf


#: A branch row this close to a pair's aligned value [rad] is moved along that pair's
#: continuum as if on it (``take_moved``; ``take`` takes it back onto the pose and keeps
#: it only where it is exact and nearer): the Panda's shoulder with q2 = 1e-6 at q0 passes
#: the continuum 9.8e-7..1.0e-6 off, which ``_ON_ALIGNED`` (1e-6, the continua's own
#: test) missed by rounding (session 25).
_SWING_ON = 1e-4

#: The numeric solution from q_near this close to a pair's aligned value [rad] (or
#: stalled off the pose) marks a possible swing next to it (``nearer_points``).
_SWING_NEAR = 1e-3

#: Steps along the self-motion at most taking a row back to the limit it is past.
_SLIDES = 6

#: A numeric solution this close to its pose [m, rad] is finished by Newton's steps
#: (``onto``): the damped steps stall 1e-11..5e-6 off a pose next to a singular point.
_NEAR_MISS = 1e-4

#: A row found off the branches this far [rad, m] past a limit is taken back to it
#: (:func:`_at_limits`); farther, it is not a solution inside the limits.
_PAST = np.array([-1e-2, 1e-2])


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


