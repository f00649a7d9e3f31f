"""Aligned continua of a 7R arm's self-motion: where one joint puts two axes on a line.

Where joint j is at a value v that puts axes j-1 and j+1 on one line
(``coincident.coincident_pair``: the Panda's q2 = 0; the iiwa's q2, q4 or q6 = 0), every
configuration turning that pair against each other, q_a + s and q_b - sign s, reaches
the same pose. Where a branch of the self-motion passes q_j = v there is therefore a
continuum at that one parameter value, which the branches' rows (``sample``) meet in a
single point: ``SelfMotion.nearest`` and ``SelfMotion.best`` search it here
(``self_motion_nearest.nearer_points``, :func:`continua_best`). Its rows come from the
pose solved with joint j held at v (``fixed.solve_fixed``: one row per family).
Pairs sharing a joint make one line of several axes (the iiwa stretched, q2 = q4 =
q6 = 0: axes 1, 3, 5 and 7): every two of its joints then turn against each other
(:func:`line_moves`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from robokin.exceptions import InputError
from robokin.kinematics.arm import Arm, Derived
from robokin.kinematics.ik.fixed import Dispatch
from robokin.kinematics.ik.self_motion_intervals import _within
from robokin.spatial import wrap_angle as _wrap

__all__ = ["EXACT", "LINE_PAIRS", "Continua", "continua", "continua_best", "held_rows",
           "line_moves", "onto", "pair_step", "pair_steps"]

#: An aligned point's row is on its pair's continuum when its joint is this close to
#: the aligned value [rad] (the kernels' aligned rows: within 1.4e-8, session 23).
_ON_ALIGNED = 1e-6
#: Pose error [m, rad] a solution found off the branches must reach (after
#: :func:`onto`; the held-joint rows reach 4e-13).
EXACT = 4e-13
#: Rounds at most over a row's aligned pairs with a joint in common (the iiwa
#: stretched, q2 = q4 = q6 = 0: q1 + q3 + q5 + q7 fixed, a descent one pair at a time
#: on a convex quadratic between wraps; one round is exact for pairs with none).
_ROUNDS = 64


def _line_pairs(robot: Arm) -> list[tuple[int, float, int, int, float]]:
    """``(j, v, a, b, sign)``: joint j at v puts joints a and b on one line.

    (``coincident.coincident_pair`` of each aligned value.)
    """
    from robokin.kinematics.ik.coincident import coincident_pair
    from robokin.kinematics.ik.self_motion_intervals import _aligned_values

    return [(j, v, p.a, p.b, p.sign) for j, v in _aligned_values(robot)
            if (p := coincident_pair(robot, j, v)) is not None]


#: The arm's line-sharing pairs at its aligned values (:func:`_line_pairs`).
LINE_PAIRS: Derived[list[tuple[int, float, int, int, float]]] = Derived(
    "joint pairs on one line at aligned values", _line_pairs)


def onto(robot: Arm, q: np.ndarray, T: np.ndarray, steps: int = 3
         ) -> tuple[np.ndarray, np.ndarray]:
    """Rows q (m, n) taken onto poses T (m, 4, 4) by ``steps`` least-squares Newton steps.

    Returns the rows and their largest position [m] / rotation [rad] error (m,).
    (The steps are ``coincident._polish``'s on every joint, the errors ``fk_error``'s.)
    """
    from robokin.kinematics.ik.analytic._common import fk_error
    from robokin.kinematics.ik.coincident import _polish

    if steps:
        q = _polish(robot, q, T, np.arange(robot.n), iterations=steps)
    dp, dr = fk_error(robot.chain, q[:, None], T)
    err: np.ndarray = np.maximum(dp[:, 0], dr[:, 0])
    return q, err


_TURNS = np.array([-1.0, 0.0, 1.0]) * 2.0 * np.pi


def pair_steps(rows: np.ndarray, q_near: np.ndarray,
               pairs: list[tuple[int, float, int, int, float]], lo: np.ndarray,
               hi: np.ndarray, wrapped: np.ndarray, *, on: float = _ON_ALIGNED
               ) -> np.ndarray:
    """Rows (m, n) moved along their continua to the points nearest q_near (m, n).

    Each row goes to the point inside the limits nearest its q_near; NaN rows where
    a joint no pair moves is outside. A row is on pair (a, b)'s continuum where its
    joint j is within ``on`` [rad] of the pair's value v (default ``_ON_ALIGNED``; 0:
    the exact continua only). Pairs sharing a joint
    make one line of several axes (the iiwa stretched, q2 = q4 = q6 = 0: axes 1, 3, 5
    and 7, c1 q1 + c3 q3 + c5 q5 + c7 q7 fixed): then every two of its joints turn
    against each other, taken in turn (a convex quadratic under one linear
    constraint and bounds, between wraps: two coordinates at a time reach its
    minimum, as in sequential minimal optimisation), up to ``_ROUNDS`` times.
    """
    out = np.array(rows, dtype=np.float64)
    on_line = np.stack([np.abs(_wrap(out[:, j] - v)) <= on for j, v, *_ in pairs], -1)
    for pattern in np.unique(on_line, axis=0):
        if not pattern.any():
            continue
        sel = np.flatnonzero((on_line == pattern).all(-1))
        moves = line_moves([p for p, o in zip(pairs, pattern, strict=True) if o])
        free = np.zeros(len(lo), dtype=bool)
        free[[x for a, b, _ in moves for x in (a, b)]] = True
        sub = out[sel]
        with np.errstate(invalid="ignore"):
            inside = np.all(free | ((sub >= lo - 1e-12) & (sub <= hi + 1e-12)), axis=-1)
        sub[~inside] = np.nan
        # a moved joint a hair outside clipped (farther, ``pair_step`` moves it inside:
        # clipped, the row would leave its pose)
        with np.errstate(invalid="ignore"):
            hair = free & (sub >= lo - 1e-12) & (sub <= hi + 1e-12)
        sub = np.where(hair, np.clip(sub, lo, hi), sub)
        keep = np.flatnonzero(inside)
        if not len(keep):
            out[sel] = sub
            continue
        lines = len(free.nonzero()[0]) < 2 * len(moves)  # a line of three or more joints
        for _ in range(_ROUNDS if lines else 1):
            before = sub[keep].copy()
            for a, b, sign in moves:
                sub[keep] = pair_step(sub[keep], a, b, sign, lo, hi, wrapped,
                                      q_near[sel[keep]])
            if np.array_equal(sub[keep], before):
                break
        out[sel] = sub
    return out


def line_moves(on: list[tuple[int, float, int, int, float]]) -> list[tuple[int, int, float]]:
    """``(a, b, sign)``: every two joints of one line turning against each other.

    The pairs on a line (q_a + sign q_b fixed) chained into groups with
    coefficients c (c_b = sign c_a): a group's joints x, y keep c_x q_x + c_y q_y
    with the rest still, so q_x + (c_y / c_x) q_y is fixed.
    """
    coef: dict[int, float] = {}
    group: dict[int, int] = {}
    for _, _, a, b, sign in on:
        if a not in coef:
            coef[a], group[a] = 1.0, a
        if b not in coef:
            coef[b], group[b] = sign * coef[a], group[a]
        elif group[b] != group[a]:  # two groups joined: b's scaled to c_b = sign c_a
            scale, old = sign * coef[a] / coef[b], group[b]
            for x in [x for x in coef if group[x] == old]:
                coef[x], group[x] = coef[x] * scale, group[a]
    joints = sorted(coef)
    return [(x, y, coef[y] / coef[x]) for i, x in enumerate(joints) for y in joints[i + 1:]
            if group[x] == group[y]]


def pair_step(q: np.ndarray, a: int, b: int, sign: float, lo: np.ndarray, hi: np.ndarray,
              wrapped: np.ndarray, q_near: np.ndarray) -> np.ndarray:
    """Rows q (m, n) with q_a + s, q_b - sign s nearest q_near (m, n), both inside.

    Each row unchanged (s = 0) where its pair is inside and nothing nearer is.
    """
    if not len(q):
        return np.array(q, dtype=np.float64)
    ra, rb, s_lo, s_hi = _turned_ranges(q, a, b, sign, lo, hi)  # (m, 3, 1), (m, 1, 3)
    u = _wrap(q_near[:, a] - q[:, a])[:, None] + _TURNS  # (m, 3): s putting q_a at q_near's
    v = -sign * (_wrap(q_near[:, b] - q[:, b])[:, None] + _TURNS)
    vertex = 0.5 * (u[:, :, None] + v[:, None, :]).reshape(len(q), 1, 1, 9)
    s = np.concatenate([np.broadcast_to(vertex, s_lo.shape + (9,)),
                        s_lo[..., None], s_hi[..., None]], axis=-1)  # (m, 3, 3, 11)
    s = np.clip(s, s_lo[..., None], s_hi[..., None])
    qa = ra[..., None] + s
    qb = rb[..., None] - sign * s
    na, nb = q_near[:, a, None, None, None], q_near[:, b, None, None, None]
    fa = _wrap(qa - na) if wrapped[a] else qa - na
    fb = _wrap(qb - nb) if wrapped[b] else qb - nb
    f = np.where((s_lo <= s_hi)[..., None], fa * fa + fb * fb, np.inf).reshape(len(q), -1)
    k = np.argmin(f, axis=1)
    m = np.arange(len(q))
    out: np.ndarray = q.copy()
    found = np.isfinite(f[m, k])
    # (a range end reached by rounding a hair outside: clipped)
    out[found, a] = np.clip(qa.reshape(len(q), -1)[m, k][found], lo[a], hi[a])
    out[found, b] = np.clip(qb.reshape(len(q), -1)[m, k][found], lo[b], hi[b])
    return out


def held_rows(robot: Arm, T: np.ndarray, j: int, v: float | np.ndarray, q_near: np.ndarray,
              dispatch: Dispatch) -> tuple[np.ndarray, np.ndarray]:
    """Poses T (m, 4, 4) solved with joint j held at v: rows (m, k, n) and valid (m, k).

    v: one value [rad] or one per pose (m,). One row per family at a coincident
    value (``fixed.solve_fixed``), its pair split nearest q_near (m, n).
    """
    from robokin.kinematics.ik.fixed import solve_fixed

    sols = solve_fixed(robot, T, {robot.joint_names[j]: v}, dispatch=dispatch, q_near=q_near)
    return np.asarray(sols.q, dtype=np.float64), np.asarray(sols.valid, dtype=bool)


#: Values of s per in-limit stretch of a continuum, then zoom rounds of 9 around the
#: best (:func:`continua_best`, as ``SelfMotion.best`` samples an interval).
_SAMPLES = 33
_ZOOMS = 6


def _line_rows(robot: Arm, T: np.ndarray, limits: np.ndarray, dispatch: Dispatch
               ) -> Iterator[tuple[np.ndarray, list[tuple[int, int, float]], np.ndarray]]:
    """The rows of pose T (4, 4) on aligned continua: ``(row (n,), moves, free (n,))``.

    For each line-sharing pair (:data:`LINE_PAIRS`) the pose solved with its joint held
    at its value (:func:`held_rows`); each row with the moves of the lines it is on
    (within ``_ON_ALIGNED``: :func:`line_moves`) and the joints they move (``free``),
    where it is inside every limit but those joints'. (A pair whose value is outside
    its joint's limits, every turn of it, has none: not solved.)
    """
    pairs = robot.derived(LINE_PAIRS)
    lo, hi = limits[:, 0], limits[:, 1]
    for j, v, *_ in pairs:
        if not np.any((v + _TURNS >= lo[j] - 1e-12) & (v + _TURNS <= hi[j] + 1e-12)):
            continue
        rows, valid = held_rows(robot, T[None], j, v, np.zeros((1, robot.n)), dispatch)
        for r in rows[0][valid[0]]:
            on = [p for p in pairs if abs(float(_wrap(r[p[0]] - p[1]))) <= _ON_ALIGNED]
            moves = line_moves(on)
            free = np.zeros(len(r), dtype=bool)
            free[[x for a, b, _ in moves for x in (a, b)]] = True
            if np.all(free | ((r >= lo - 1e-12) & (r <= hi + 1e-12))):
                yield r, moves, free


def continua_best(robot: Arm, T: np.ndarray, limits: np.ndarray,
                  score: Callable[[np.ndarray], np.ndarray], best: float,
                  dispatch: Dispatch) -> tuple[np.ndarray, float] | None:
    """The configuration of an aligned continuum of pose T (4, 4) scoring above ``best``.

    For each line-sharing pair (:data:`LINE_PAIRS`) the pose is solved with its joint
    held at its value (:func:`held_rows`); from each row inside the limits but for the
    joints a line moves, each move of its line (:func:`line_moves`) is sampled over
    its in-limit stretches of s (``_SAMPLES`` values each, the pair's 2 pi turns
    included), then zoomed ``_ZOOMS`` times around the best; on a line of three or more
    joints the moves are taken in turn, twice. The best row above ``best`` is taken
    onto the pose (:func:`onto`) and returned with its score if its pose error is
    within :data:`EXACT` and it is inside every limit.

    Args:
        robot: The arm (7R).
        T: The pose (4, 4) [m].
        limits: Joint limits (n, 2) [rad].
        score: Configurations (p, n) -> scores (p,) (``SelfMotion.best``'s criterion).
        best: The score to beat (-inf: none).
        dispatch: ``dispatch.solve``.

    Returns:
        ``(q (n,), score)``, or None.
    """
    lo, hi = limits[:, 0], limits[:, 1]
    found: tuple[np.ndarray, float] | None = None
    for r, moves, free in _line_rows(robot, T, limits, dispatch):
        q, val = r, -np.inf
        for _ in range(2 if len(free.nonzero()[0]) < 2 * len(moves) else 1):
            for a, b, sign in moves:
                q, val = _line_best(q, a, b, sign, lo, hi, score)
        if val > (best if found is None else found[1]):
            found = (q, val)
    if found is None:
        return None
    q, err = onto(robot, found[0][None], T[None])
    if not (err[0] <= EXACT and bool(_within(q[0], limits))):
        return None
    q0 = np.clip(q[0], lo, hi)
    return q0, float(score(q0[None])[0])


def _turned_ranges(q: np.ndarray, a: int, b: int, sign: float, lo: np.ndarray,
                   hi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The ranges of s keeping the move q_a + s, q_b - sign s of rows q (m, n) inside.

    Per pair of 2 pi turns of the two joints: ``ra = q_a + 2 pi i`` (m, 3, 1), ``rb =
    q_b + 2 pi k`` (m, 1, 3) (i, k in -1..1) and the range [s_lo, s_hi] (m, 3, 3)
    [rad] (empty where s_lo > s_hi).
    """
    ra = q[:, a, None, None] + _TURNS[:, None]
    rb = q[:, b, None, None] + _TURNS[None, :]
    ea, eb = sign * (rb - hi[b]), sign * (rb - lo[b])
    s_lo = np.maximum(lo[a] - ra, np.minimum(ea, eb))
    s_hi = np.minimum(hi[a] - ra, np.maximum(ea, eb))
    return ra, rb, s_lo, s_hi


def _stretches(q: np.ndarray, a: int, b: int, sign: float, lo: np.ndarray, hi: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The in-limit stretches of s of the move q_a + s, q_b - sign s of row q (n,).

    Each pair of 2 pi turns of the two joints whose ranges of s keeping both inside
    their limits overlap (:func:`_turned_ranges`): ``(s_lo, s_hi, ra, rb)``, (p,) each
    [rad].
    """
    ra3, rb3, lo3, hi3 = _turned_ranges(q[None], a, b, sign, lo, hi)
    s_lo, s_hi = lo3[0].ravel(), hi3[0].ravel()  # (9,)
    ra, rb = np.broadcast_to(ra3[0], (3, 3)).ravel(), np.broadcast_to(rb3[0], (3, 3)).ravel()
    keep = s_lo <= s_hi
    return s_lo[keep], s_hi[keep], ra[keep], rb[keep]


@dataclass(frozen=True)
class Continua:
    """The aligned continua of one pose as straight pieces in joint space.

    Piece i is the row ``base[i]`` with joints ``a[i]`` and ``b[i]`` moved,
    q_a = base_a + s and q_b = base_b - sign s, for s in [``s_lo[i]``, ``s_hi[i]``]:
    every point solves the pose (to the held row's 4e-13) inside every limit.

    Attributes:
        base: (p, n) rows [rad, m]; a, b: (p,) the moved joints; sign: (p,);
        s_lo, s_hi: (p,) the stretch [rad].
    """

    base: np.ndarray
    a: np.ndarray
    b: np.ndarray
    sign: np.ndarray
    s_lo: np.ndarray
    s_hi: np.ndarray

    @classmethod
    def empty(cls, n: int) -> Continua:
        """No piece, for an arm of n joints."""
        none = np.zeros(0, dtype=np.int64)
        return cls(np.zeros((0, n)), none, none.copy(), np.zeros(0), np.zeros(0), np.zeros(0))

    def at(self, piece: npt.ArrayLike, u: npt.ArrayLike) -> np.ndarray:
        """Rows (m, n) of pieces ``piece`` (m,) at fractions ``u`` (m,) of their stretch.

        Raises:
            InputError: ``piece`` not indices of pieces, ``u`` not finite numbers in
                [0, 1] of the same length.
        """
        piece, u = _piece_args(piece, u, len(self.base))
        s = self.s_lo[piece] + (self.s_hi[piece] - self.s_lo[piece]) * u
        out: np.ndarray = self.base[piece].copy()
        r = np.arange(len(piece))
        out[r, self.a[piece]] += s
        out[r, self.b[piece]] -= self.sign[piece] * s
        return out


def _piece_args(piece: npt.ArrayLike, u: npt.ArrayLike, n: int
                ) -> tuple[np.ndarray, np.ndarray]:
    """``Continua.at``'s arguments checked: piece indices in [0, n), u in [0, 1]."""
    p = np.asarray(piece)
    if p.ndim != 1 or (p.size and not np.issubdtype(p.dtype, np.integer)):
        raise InputError("piece", f"expected a 1-D array of piece indices, got {p!r:.60}")
    if p.size and (p.min() < 0 or p.max() >= n):
        raise InputError("piece", f"indices must be in [0, {n}) (the pieces), got "
                                  f"{int(p.min())}..{int(p.max())}")
    x = np.asarray(u, dtype=np.float64)
    if x.shape != p.shape or not np.all((x >= 0.0) & (x <= 1.0)):
        raise InputError("u", f"expected fractions in [0, 1], one per piece ({len(p)}), "
                              f"got shape {x.shape}")
    return p.astype(np.int64), x


def continua(robot: Arm, T: np.ndarray, limits: np.ndarray, dispatch: Dispatch) -> Continua:
    """Every aligned continuum of pose T (4, 4) inside the limits, as :class:`Continua`.

    For each line-sharing pair (:data:`LINE_PAIRS`) the pose is solved with its joint
    held at its value (:func:`held_rows`); from each row inside the limits but for the
    joints its lines move, each move of its lines (:func:`line_moves`) over each of its
    in-limit stretches of s (:func:`_stretches`; on a line of three or more joints, a
    2- or 3-dimensional set, each pair's move from the held row). Pieces shorter than
    1e-9 rad are left out (a point: the branches hold it), and a piece the held rows of
    several families or two turns of the pair give once (the same joints and ends, to
    1e-9).
    """
    lo, hi = limits[:, 0], limits[:, 1]
    pieces: list[tuple[np.ndarray, int, int, float, float, float]] = []
    seen: set[tuple[object, ...]] = set()
    for r, moves, _ in _line_rows(robot, T, limits, dispatch):
        for a, b, sign in moves:
            s_lo, s_hi, ra, rb = _stretches(r, a, b, sign, lo, hi)
            for x, y, qa, qb in zip(s_lo, s_hi, ra, rb, strict=True):
                rest = np.delete(r, [a, b])
                key = (a, b, *np.round(rest, 9), round(float(qa + x), 9),
                       round(float(qa + y), 9), round(float(qb - sign * x), 9))
                if y - x > 1e-9 and key not in seen:
                    seen.add(key)
                    base = r.copy()
                    base[a], base[b] = qa, qb
                    pieces.append((base, a, b, sign, float(x), float(y)))
    if not pieces:
        return Continua.empty(robot.n)
    base, a, b, sign, s_lo, s_hi = zip(*pieces, strict=True)
    return Continua(np.array(base), np.array(a), np.array(b), np.array(sign),
                    np.array(s_lo), np.array(s_hi))


def _line_best(q: np.ndarray, a: int, b: int, sign: float, lo: np.ndarray, hi: np.ndarray,
               score: Callable[[np.ndarray], np.ndarray]) -> tuple[np.ndarray, float]:
    """The row q moved along one move (q_a + s, q_b - sign s) to its best sampled score.

    Every in-limit stretch of s (the pair's 2 pi turns) sampled at ``_SAMPLES`` values in
    one batch, then ``_ZOOMS`` rounds of 9 values around the best.
    """
    s_lo, s_hi, ra, rb = _stretches(q, a, b, sign, lo, hi)
    # (q itself counts only inside its limits: a row's moved joints may start outside)
    inside = bool(np.all((q >= lo) & (q <= hi)))
    best_q, best_s = q, float(score(q[None])[0]) if inside else -np.inf
    if not len(s_lo):
        return best_q, best_s
    s = s_lo[:, None] + (s_hi - s_lo)[:, None] * np.linspace(0.0, 1.0, _SAMPLES)
    for _ in range(_ZOOMS + 1):
        rows = np.repeat(q[None], s.size, axis=0)
        rows[:, a] = np.clip((ra[:, None] + s).ravel(), lo[a], hi[a])
        rows[:, b] = np.clip((rb[:, None] - sign * s).ravel(), lo[b], hi[b])
        val = score(rows)
        i = int(np.argmax(val))
        if val[i] > best_s:
            best_q, best_s = rows[i], float(val[i])
        k, c = (int(x) for x in np.unravel_index(i, s.shape))  # the stretch, the value
        step = (s[k, -1] - s[k, 0]) / (s.shape[1] - 1)
        s_lo, s_hi = s_lo[k:k + 1], s_hi[k:k + 1]
        ra, rb = ra[k:k + 1], rb[k:k + 1]
        s = np.linspace(max(s[k, c] - step, s_lo[0]), min(s[k, c] + step, s_hi[0]), 9)[None]
    return best_q, best_s
