"""The in-limit intervals of a self-motion family: exact points, grid check, bisection.

The limits of each joint are exact points of the family (``_Family.points``); the
intervals lie between them and are decided at their midpoints; a checking grid and
bisection catch what the exact points miss (the module docstring of
:mod:`~robokin.kinematics.ik.self_motion`). The compiled SRS swivel needs none of
this (``_SwivelFamily.exact``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robokin._native import kernels as K
from robokin._validation import ROTATION_EXACT
from robokin.kinematics.arm import Arm
from robokin.kinematics.ik.self_motion_base import (
    FINE_T,
    _Family,
    _into_limits,
    _shrunk,
)
from robokin.kinematics.ik.self_motion_families import (
    HeldKernel,
    LimitCrossing,
    SingularPoint,
    _HeldFamily,
    _setup,
    one_per_point,
)
from robokin.spatial import wrap_angle as _wrap

#: The membership slack (``chain.h`` ``MANIFOLD_SLACK``, 1e-12): a row is inside its
#: limits where every coordinate is within it of them. ``SelfMotion.inside``, the
#: pieces of every family (decided at their midpoints) and the compiled kernels
#: (``held_manifold.c``, ``self_motion.c``) all take it, with the same comparison.
MANIFOLD_SLACK: float = K.MANIFOLD_SLACK
#: Parameter values on the checking grid.
GRID = 721
#: Bisection steps (a 2 pi domain to 2**-52 of its width).
_BISECT = 56
#: ``_state_change``: a bracket whose ends' margins are both this close to 0 [rad] is
#: done (the rows' rounding next to a singularity, a tenth of the slack).
_STATE_NOISE = 1e-13
_TWO_PI = 2 * np.pi
#: A range end's row is solved for a corner only where the continued family's track
#: there is within this of every limit [rad] (its nodes are solved rows).
_NEAR = 1e-6
#: Crossings of joints within this of a cut [in t] are the same corner (``_touches``).
_CORNER = 1e-9
#: Parameter values on the compiled held-joint kernel's first grid (``held_manifold``).
KERNEL_GRID = 181
#: At most this many grid changes without an exact point are bisected (a pose on a
#: singular manifold, e.g. the SRS arm stretched with its wrist in line, has many).
_MAX_BISECT = 64


def _exact_points(robot: Arm, fam: _Family, limits: np.ndarray) -> dict[str, list[Any]]:
    """Every limit point and aligned-axes point of every branch, exactly."""
    out: dict[str, list[Any]] = {"limit": [], "fold": [], "aligned": []}
    rev = np.asarray(robot.is_revolute, bool)
    queries: list[tuple[int, float]] = []
    tags: list[tuple[str, Any]] = []
    for j in range(robot.n):
        lo, hi = limits[j]
        if j == fam.joint or (rev[j] and hi - lo >= _TWO_PI):
            continue  # the parameter, or every angle has an in-limit turn
        queries += [(j, float(lo)), (j, float(hi))]
        tags += [("limit", "lower"), ("limit", "upper")]
    for j, value in _aligned_values(robot):
        if j != fam.joint:
            queries.append((j, value))
            tags.append(("aligned", "aligned axes"))
    for (j, _), (kind, text), found in zip(queries, tags, fam.points(queries), strict=True):
        if kind == "limit":
            out["limit"] += [(t, b, j, text) for t, b in found]
        else:
            out["aligned"] += [(t, b, text) for t, b in found]
    return out


def _aligned_values(robot: Arm) -> list[tuple[int, float]]:
    """(joint, value): where axes j-1 and j+1 of a meeting triple line up."""
    setup = _setup(robot)
    if setup.aligned is None:
        setup.aligned = _find_aligned(robot)
    return setup.aligned


def _find_aligned(robot: Arm) -> list[tuple[int, float]]:
    from robokin.kinematics.ik.analytic._geometry import poe_from_chain
    from robokin.kinematics.ik.swivel import _sp4

    poe = poe_from_chain(robot.chain)
    sign, offset = robot.chain.arrays.sign, robot.chain.arrays.offset
    found = []
    for j in range(1, robot.chain.n_chain - 1):
        a, h, b = poe.h[j - 1], poe.h[j], poe.h[j + 1]
        for c in (1.0, -1.0):
            tp, tm, real = _sp4(h, a, b, np.array(c))
            if bool(real) and abs(float(tp) - float(tm)) < 1e-6:
                v = float((tp + tm) / 2)
                found.append((j, float(_wrap((v - offset[j]) * sign[j]))))
    return found


def _grid(fam: _Family, m: int, marks: dict[str, list[Any]]) -> np.ndarray:
    """The checking grid: m values over the range, refined next to aligned points.

    Next to a point where a triple lines up a branch's outer angles swing by up to
    pi over a tiny parameter range, where the held-joint solver can miss a limit
    crossing: values at 10^-k (k = 1..12) either side catch those for bisection.
    """
    lo, hi = fam.domain
    t = [np.linspace(lo, hi, m)]
    near = np.array([10.0 ** -k for k in range(1, 13)])
    for ts, *_ in marks["aligned"]:
        t.append(np.clip(np.concatenate([ts - near, ts + near]), lo, hi))
    return np.unique(np.concatenate(t))


def _state_changes(fam: _Family, t: np.ndarray, q: np.ndarray, valid: np.ndarray,
                   limits: np.ndarray, marks: dict[str, list[Any]]
                   ) -> tuple[list[tuple[float, int]], int]:
    """Branch ends (bisected on existence) and unexplained in-limit changes on the grid.

    Returns ``([(t, branch), ...] extra breakpoints, how many were bisected)``; the
    fold ends are added to ``marks["fold"]``. All cells are bisected together (one
    batch per step), with the renumberings of the rows (``_swap_cells``) in cells
    that hold an exact point or a fold: each is a breakpoint of its moved slots, and
    the branch ends a fold cell hides between its grid values (``_cell_islands``).
    """
    inside = valid & _within(q, limits)
    exact: dict[int, list[float]] = {}
    for tt, b, *_ in marks["limit"] + marks["aligned"]:
        exact.setdefault(b, []).append(tt)
    folds, changes = [], []
    for b in range(fam.k):
        folds += [(int(i), b) for i in np.flatnonzero(valid[1:, b] != valid[:-1, b])]
        for i in np.flatnonzero((inside[1:, b] != inside[:-1, b])
                                & valid[1:, b] & valid[:-1, b]):
            if not any(t[i] <= x <= t[i + 1] for x in exact.get(b, [])):
                changes.append((i, b))
    changes = changes[:_MAX_BISECT]
    # slots renumbered inside a cell that holds an exact point or a fold (elsewhere a
    # slot keeps one state on either side of the jump: its states at the cell's ends)
    marked = np.zeros((len(t) - 1, fam.k), dtype=bool)
    for b, xs in exact.items():
        at = np.searchsorted(t, np.asarray(xs), side="right") - 1
        marked[at[(at >= 0) & (at < len(t) - 1)], b] = True
    marked |= (valid[1:] != valid[:-1]).any(axis=1)[:, None]
    sc, moved, sk = _swap_cells(t, q, valid, marked)
    folds, extra = _cell_islands(fam, t, valid, folds)
    cells = folds + changes
    if not cells and not len(sc) and not extra:
        return [], 0
    idx = np.array([i for i, _ in cells] + [i for i, *_ in extra], dtype=int)
    br = np.array([b for _, b in cells] + [b for _, b, *_ in extra], dtype=int)
    kind = np.array([c >= len(folds) for c in range(len(cells))] + [False] * len(extra),
                    dtype=bool)  # in-limit change
    state0 = np.where(kind, inside[idx, br], valid[idx, br])
    lo, hi = t[idx].astype(np.float64), t[idx + 1].astype(np.float64)
    far = np.where(state0, lo, hi)  # each fold's row on its valid side: the scan's far end
    if extra:  # a probe pair's bracket: its states and its valid side's probe
        x = slice(len(cells), None)
        lo[x], hi[x] = [a for _, _, a, _, _ in extra], [e for _, _, _, e, _ in extra]
        state0[x] = [v for *_, v in extra]
        far[x] = np.where(state0[x], lo[x], hi[x])
    # a renumbering (in the same batches): slot sk's row at the midpoint nearer its
    # row at the bracket's left end than at its right end lies left of the jump
    s_lo, s_hi = t[sc].astype(np.float64), t[sc + 1].astype(np.float64)
    qa, qe = q[sc, sk], q[sc + 1, sk]
    # (the numpy calls per step are most of a step's cost next to its few rows: the
    # swaps' and the in-limit changes' are skipped where there are none)
    act = np.arange(len(sc))
    has_changes = bool(changes)
    lo_s, hi_s = limits[:, 0] - MANIFOLD_SLACK, limits[:, 1] + MANIFOLD_SLACK  # (_within's)
    for _ in range(_BISECT):
        mid = 0.5 * (lo + hi)
        # a cell of two adjacent floats is done: its midpoint is one of its ends, whose
        # state is known (lo's is state0, hi's not), so solving it would change nothing
        go = np.flatnonzero((mid != lo) & (mid != hi))
        if len(act):  # (a bracket once within _SWAP_T stays so)
            act = act[s_hi[act] - s_lo[act] > _SWAP_T]
        if not len(go) and not len(act):
            break  # every cell two adjacent floats: the rest would change nothing
        m, mid, kg = len(go), mid[go], kind[go]
        if len(act):
            s_mid = 0.5 * (s_lo[act] + s_hi[act])
            qm, vm = fam.slot_rows(np.concatenate([mid, s_mid]), np.concatenate([br[go], sk[act]]),
                                   np.concatenate([kg, np.ones(len(act), dtype=bool)]))
            now = vm[:m]
        else:
            qm, now = fam.slot_rows(mid, br[go], kg)
        if has_changes:
            now = np.where(kg, now & _in_bounds(qm[:m], lo_s, hi_s), now)
        same = now == state0[go]
        lo[go], hi[go] = np.where(same, mid, lo[go]), np.where(same, hi[go], mid)
        if len(act):
            r = qm[m:]
            with np.errstate(invalid="ignore"):
                left = _turn_gap(r - qa[act]) <= _turn_gap(r - qe[act])
            left &= vm[m:]
            s_lo[act[left]], qa[act[left]] = s_mid[left], r[left]
            s_hi[act[~left]], qe[act[~left]] = s_mid[~left], r[~left]
    swaps = [(float(x), int(b)) for x, m in zip(s_lo.tolist(), moved, strict=True)
             for b in np.flatnonzero(m).tolist()]
    ends = np.where(state0, lo, hi)  # the last point of the state that holds there
    marks["fold"] += [(float(e), int(b), "fold") for e, b, k in zip(ends, br, kind) if not k]
    fold = ~kind
    if fold.any():  # the row on the fold's side of its cell: the scan's far end
        near = far[fold]
        for tc, bc, jc, what in _fold_crossings(fam, ends[fold], near, br[fold], limits, exact):
            if what == "fold":  # the rows end before the joint leaves: a second fold
                marks["fold"].append((tc, bc, "fold"))
            else:
                marks["limit"].append((tc, bc, jc, what))
    return [(float(e), int(b)) for e, b in zip(ends, br)] + swaps, len(changes)


def _cell_islands(fam: _Family, t: np.ndarray, valid: np.ndarray,
                  folds: list[tuple[int, int]]
                  ) -> tuple[list[tuple[int, int]], list[tuple[int, int, float, float, bool]]]:
    """Branch ends the grid's fold cells hide: more than one change of a slot in a cell.

    A cell where some slot's rows end (a fold) may hold another slot's whole island
    (rows at neither grid value) or a slot's end and return: next to the Panda's reach
    boundary all 8 rows end within ~1e-5 of q7, 4 of them after a gap (seed 1, uniform
    #3146: 8 rows on [0.7270, 0.73088], 4 on [0.70853, 0.7270], the grid values 0.7243
    and 0.7324). Each such cell is probed at ``_ISLAND_PROBES`` values (one batch); a
    slot whose validity changes more than once along them has one bracket per change
    between neighbouring probes, and its grid fold, if any, is dropped (its bisection
    would find one change of several).

    Returns ``(folds kept, [(cell, slot, lo, hi, valid at lo)])``.
    """
    if not folds:
        return folds, []
    cells = np.unique([i for i, _ in folds])
    u = np.linspace(0.0, 1.0, _ISLAND_PROBES + 2)[1:-1]
    ts = t[cells, None] + (t[cells + 1] - t[cells])[:, None] * u[None, :]  # (c, p)
    vp = fam.validity(ts.ravel())
    at = np.concatenate([valid[cells, None], vp.reshape(ts.shape + (-1,)),
                         valid[cells + 1, None]], axis=1)  # (c, p + 2, k)
    tt = np.concatenate([t[cells, None], ts, t[cells + 1, None]], axis=1)
    change = at[:, 1:] != at[:, :-1]  # (c, p + 1, k)
    many = change.sum(axis=1) > 1  # (c, k)
    if not many.any():
        return folds, []
    extra: list[tuple[int, int, float, float, bool]] = []
    for ci, b in zip(*np.nonzero(many), strict=True):
        for k in np.flatnonzero(change[ci, :, b]):
            extra.append((int(cells[ci]), int(b), float(tt[ci, k]), float(tt[ci, k + 1]),
                          bool(at[ci, k, b])))
    drop = {(int(cells[ci]), int(b)) for ci, b in zip(*np.nonzero(many), strict=True)}
    return [f for f in folds if (int(f[0]), int(f[1])) not in drop], extra


#: Interior values probed in each fold cell of the grid for hidden branch ends
#: (``_cell_islands``: an island or a return at least 1/8 of the cell long is seen).
_ISLAND_PROBES = 7


#: A slot's row moving more than this many times as far between two grid values as
#: to another slot's row (and more than ``_SWAP_FLOOR`` rad) changed slots there.
_SWAP_RATIO = 10.0
_SWAP_FLOOR = 1e-6
#: A renumbering is bisected to this [in t] (its cut: the pieces either side are
#: decided at their midpoints).
_SWAP_T = 1e-12


def _turn_gap(d: np.ndarray) -> np.ndarray:
    """(...): the largest |d| (..., n) over its last axis, modulo whole turns (|d| < 4 pi).

    Rows shifted into the limits differ by less than 4 pi. The largest by pairwise
    ``np.maximum`` (NaN propagates as in ``max``, the same value): ``max(axis=-1)``
    over the 7 joints cost ~3x that in ``_swap_cells`` (issue 29, helper polish29).
    """
    d = np.abs(d)
    g = np.minimum(d, np.abs(d - _TWO_PI))
    out: np.ndarray = g[..., 0].copy()
    for j in range(1, g.shape[-1]):
        np.maximum(out, g[..., j], out=out)
    return out


def _swap_cells(t: np.ndarray, q: np.ndarray, valid: np.ndarray, marked: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Grid cells where a closed form renumbers its rows: (cells (c,), moved (c, k), slot (c,)).

    The held closed form numbers the quartic's roots by the eliminated variable's
    angle and switches the elimination with the conditioning (``pieper.c``
    ``pk_general``: the rtb-data iiwa14 at joint_a3 = +-1.074e-4 on every pose), and
    numbers the roots left after a fold in order: a slot holds another configuration
    past such a value. A cell whose slots stay valid and keep their in-limit states
    shows no change there, and a piece across it was decided on the other
    configuration at its midpoint (issue 29, helper corner29). Slot k moved in cell
    i when its step there exceeds ``_SWAP_FLOOR`` and ``_SWAP_RATIO`` times its
    steps in the cells either side, and its row at one end is ``_SWAP_RATIO`` times
    nearer another slot's row at the other end than its own; ``slot``: the one of
    each cell ``_state_changes`` bisects (every moved slot is cut there).
    """
    none = (np.zeros(0, dtype=int), np.zeros((0, q.shape[1]), dtype=bool), np.zeros(0, dtype=int))
    cells = np.flatnonzero(marked.any(axis=1))
    if len(t) < 4 or q.shape[1] < 2 or not len(cells):
        return none
    # a jump stands out of the slot's steps in the cells either side (rows move
    # smoothly between them); only such cells are compared with the other slots
    near = np.clip(cells[:, None] + np.array([-1, 0, 1]), 0, len(t) - 2)  # (c, 3)
    with np.errstate(invalid="ignore"):
        step = _turn_gap(q[near + 1] - q[near])  # (c, 3, k)
    step = np.where(valid[near + 1] & valid[near], step, np.nan)
    own = step[:, 1]
    side = np.fmin(step[:, 0], step[:, 2])
    with np.errstate(invalid="ignore"):
        jump = (own > _SWAP_FLOOR) & ~(own <= _SWAP_RATIO * side) & marked[cells]
    keep = jump.any(axis=1)
    cells, own, jump = cells[keep], own[keep], jump[keep]
    if not len(cells):
        return none
    a, e = q[cells], q[cells + 1]  # (c, k, n)
    both = valid[cells, :, None] & valid[cells + 1, None, :]  # (c, k, l): k at the start, l at the end
    with np.errstate(invalid="ignore"):
        gap = _turn_gap(e[:, None, :, :] - a[:, :, None, :])  # (c, k, l)
    gap = np.where(both, gap, np.inf)
    idx = np.arange(q.shape[1])
    gap[:, idx, idx] = np.inf
    # slot k's start row went to another slot, or its end row came from one (a fold
    # renumbers the slots of the roots left: the rows are numbered in order)
    other = np.minimum(gap.min(axis=2), gap.min(axis=1))
    moved = jump & (other * _SWAP_RATIO < own)  # (c, k)
    keep = moved.any(axis=1)
    cells, moved = cells[keep], moved[keep]
    if not len(cells):
        return none
    return cells, moved, np.argmax(moved, axis=1)


#: Values of s = sqrt(|t - t_f| / |t_g - t_f|) scanned between a fold and its grid row.
_FOLD_SCAN = 17
#: The bisection state of a value with no row on the branch (``_fold_crossings``).
_NO_ROW = 2


def _fold_crossings(fam: _Family, tf: np.ndarray, tg: np.ndarray, br: np.ndarray,
                    limits: np.ndarray, exact: dict[int, list[float]]
                    ) -> list[tuple[float, int, int, str]]:
    """Limit crossings between each fold t_f and its cell's grid row t_g (issue 29).

    Next to a fold a joint moves like sqrt(|t - t_f|) (hundreds of rad per unit
    sqrt(t) on the rtb-data iiwa14), so a crossing within 1e-6 of the fold is missed
    by the exact points, the grid and the bisection of the fold itself. Branch b's
    rows (``fam.rows``) are scanned at t = t_f + (t_g - t_f) s^2 (``_FOLD_SCAN``
    values of s in [0, 1]); a joint changing sides of a limit (``MANIFOLD_SLACK``)
    between two scanned rows, with no exact crossing of b there (``exact``), is
    bisected on the rows (the joint's side, or no row) to the last in-limit value: a
    crossing record ``(t, b, j, "lower" | "upper")``, or ``"fold"`` where the rows
    end first (a second fold within the cell: the rtb-data iiwa14's pose #38 has an
    in-limit stretch of 4.9e-8 next to its fold). The docs: ``docs/ik.md``, "Round 7f".
    """
    s2 = np.linspace(0.0, 1.0, _FOLD_SCAN) ** 2
    ts = tf[:, None] + (tg - tf)[:, None] * s2  # (folds, scan)
    q, valid = fam.slot_rows(ts.ravel(), np.repeat(br, _FOLD_SCAN))
    qb = q.reshape(ts.shape + (-1,))  # (folds, scan, n)
    ok = valid.reshape(ts.shape)
    with np.errstate(invalid="ignore"):
        low = qb < limits[:, 0] - MANIFOLD_SLACK
        high = qb > limits[:, 1] + MANIFOLD_SLACK
    side = high.astype(np.int8) - low.astype(np.int8)  # -1 below, 0 inside, 1 above
    cells: list[tuple[int, int, int]] = []  # (fold, scan index k: between k and k + 1, j)
    change = (side[:, 1:] != side[:, :-1]) & ((side[:, 1:] == 0) | (side[:, :-1] == 0))
    for f, k, j in zip(*np.nonzero(change & ok[:, 1:, None] & ok[:, :-1, None]), strict=True):
        a, e = sorted((ts[f, k], ts[f, k + 1]))
        if not any(a <= x <= e for x in exact.get(int(br[f]), [])):
            cells.append((int(f), int(k), int(j)))
    if not cells:
        return []
    f_i, k_i, j_i = (np.array(c) for c in zip(*cells, strict=True))
    b_i = br[f_i]
    lo, hi = ts[f_i, k_i], ts[f_i, k_i + 1]
    state0, state1 = side[f_i, k_i, j_i], side[f_i, k_i + 1, j_i]
    for _ in range(_BISECT):
        mid = 0.5 * (lo + hi)
        go = np.flatnonzero((mid != lo) & (mid != hi))  # not yet two adjacent floats
        if not len(go):
            break  # every cell two adjacent floats
        mid, jg = mid[go], j_i[go]
        qm, vm = fam.slot_rows(mid, b_i[go])
        qj = qm[np.arange(len(go)), jg]
        with np.errstate(invalid="ignore"):
            now = ((qj > limits[jg, 1] + MANIFOLD_SLACK).astype(np.int8)
                   - (qj < limits[jg, 0] - MANIFOLD_SLACK).astype(np.int8))
        now = np.where(vm, now, _NO_ROW)  # rows missing: a second fold
        same = now == state0[go]
        lo[go], hi[go] = np.where(same, mid, lo[go]), np.where(same, hi[go], mid)
        state1[go] = np.where(same, state1[go], now)
    inner = np.where(state0 == 0, lo, hi)  # the in-limit end
    out_side = np.where(state0 == 0, state1, state0)
    return [(float(t), int(b), int(j), "fold" if o == _NO_ROW else "upper" if o > 0 else "lower")
            for t, b, j, o in zip(inner, b_i, j_i, out_side, strict=True)]


def _within(q: np.ndarray, limits: np.ndarray) -> np.ndarray:
    """(...) bool: rows q (..., n) inside every limit (MANIFOLD_SLACK); NaN rows False."""
    return _in_bounds(q, limits[:, 0] - MANIFOLD_SLACK, limits[:, 1] + MANIFOLD_SLACK)


def _in_bounds(q: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(...) bool: rows q (..., n) within [lo, hi] (n,) each; NaN rows False."""
    with np.errstate(invalid="ignore"):  # (the ufunc's reduce: ``np.all``'s wrapper costs ~4 us)
        out: np.ndarray = np.logical_and.reduce((q >= lo) & (q <= hi), axis=-1)
        return out


def _intervals(fam: _Family, limits: np.ndarray, marks: dict[str, list[Any]],
               extra: list[tuple[float, int]]) -> tuple[np.ndarray, np.ndarray]:
    """Per branch: the maximal parameter intervals inside every limit.

    The pieces between a branch's cuts are decided at their midpoints: between cuts
    a joint keeps its side of each limit. Not where the midpoint's row has a joint
    within ``MANIFOLD_SLACK`` of a limit: its side there is rounding's (a joint
    touching its limit, whose two crossings either side of the touch are found or not
    by the last bits), and the rows further on may be out by far more than the slack
    with no crossing between (the offset iiwa's #5084, q4 at its limit at q's value:
    with the touch's crossings lost to rounding, the whole piece between two folds,
    rows 7e-5 out at its ends, was inside). Such a piece is inside as a whole where
    its rows at both ends are inside too (a piece between two crossings at a
    corner), else over its midpoint's in-slack stretch (``_widen`` from the
    midpoint, up to the piece's ends).
    """
    lo_d, hi_d = fam.domain
    cuts: dict[int, list[float]] = {b: [lo_d, hi_d] for b in range(fam.k)}
    for t, b, *_ in marks["limit"] + marks["fold"]:
        cuts[b].append(t)
    for t, b in extra:
        cuts[b].append(t)
    pieces: list[tuple[int, float, float]] = []
    mids, owners, spans = [], [], []
    for b in range(fam.k):
        c = np.unique(np.clip(cuts[b], lo_d, hi_d)).tolist()
        for a, e in zip(c[:-1], c[1:], strict=True):
            if e > a:
                mids.append(0.5 * (a + e))
                owners.append(b)
                spans.append((a, e))
    if not mids:
        return np.zeros((0, 2)), np.zeros(0, dtype=int)
    q, valid = fam.slot_rows(np.array(mids), np.array(owners, dtype=int))
    ok = valid & _within(q, limits)
    with np.errstate(invalid="ignore"):
        out = ((q < limits[:, 0] - MANIFOLD_SLACK)
               | (q > limits[:, 1] + MANIFOLD_SLACK))  # (pieces, n)
        at = np.abs(q[..., None] - limits).min(-1) <= MANIFOLD_SLACK  # (pieces, n)
    out[~valid] = True  # no row: no corner next to it
    if fam.joint is not None:
        at[:, fam.joint] = False  # the parameter (its range's ends are cuts)
    kept = list(spans)  # each piece's part inside
    touching = np.flatnonzero(ok & at.any(axis=1))
    if len(touching):  # its rows at both ends inside too, or its midpoint's stretch
        qe, ve = fam.slot_rows(np.array([spans[i] for i in touching]).ravel(),
                               np.repeat(np.array(owners)[touching], 2))
        touching = touching[~(ve & _within(qe, limits)).reshape(-1, 2).all(axis=1)]
    if len(touching):
        stretch = _widen(fam, limits, [(mids[i], mids[i], owners[i]) for i in touching],
                         [True] * len(touching), [spans[i] for i in touching])
        for i, (_, a, e) in zip(touching.tolist(), stretch, strict=True):
            if a > mids[i]:  # (a periodic family's stretch shifted by a turn)
                a, e = a - _TWO_PI, e - _TWO_PI
            kept[i] = (max(a, spans[i][0]), min(e, spans[i][1]))
    for (a, e), b, good in zip(kept, owners, ok, strict=True):
        if not good:
            continue
        if pieces and pieces[-1][0] == b and pieces[-1][2] == a:
            pieces[-1] = (b, pieces[-1][1], e)
        else:
            pieces.append((b, a, e))
    pieces = sorted(pieces + _touches(fam, limits, marks["limit"], spans, owners, out))
    if fam.periodic:
        pieces = _join_wrap(pieces, lo_d, hi_d)
    arr = np.array([[a, e] for _, a, e in pieces]).reshape(-1, 2)
    return arr, np.array([b for b, _, _ in pieces], dtype=int)


def _node_cuts(fam: _Family, limits: np.ndarray, intervals: np.ndarray, owner: np.ndarray,
               t_nodes: np.ndarray, tracks: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray, list[tuple[float, int, int, str]]]:
    """The intervals cut where a solved node row of their branch is outside.

    The continued family decides each piece between its crossings at the piece's
    midpoint; a crossing its scan misses joins two pieces. On the offset iiwa's special
    poses a branch meeting the aligned-wrist line (q6 = 0, q5 + q7 fixed; the line
    holds q2 at its limit) crosses q2's limit exactly there, and Newton's crossing lands
    on the line: special #7320 of seed 0 listed [-0.5248, 1.4990] with q2 up to 0.46
    rad past its limit over its first half. ``t_nodes`` (m,) and ``tracks`` (m, k, n):
    the family's node rows (solved, to ~1e-13). Each interval with a node row more than
    ``_NODE_OUT`` outside keeps only its in-limit runs: every change of state between
    neighbouring nodes and its two ends (their own rows: an end at one joint's crossing
    can have another joint out) is bisected on ``fam.slot_rows`` (one batch per step)
    to its last in-limit value, a limit crossing of the joint furthest out past it. An
    interval outside at both ends and at every node in it has no change of state: it
    is dropped (session 16: offset iiwa special #8920 of seed 0).

    Returns ``(intervals, owner, crossings [(t, branch, joint, "lower"|"upper")])``;
    the arrays unchanged (the same objects) where no node is outside.
    """
    if not len(intervals):
        return intervals, owner, []
    lo_l, hi_l = limits[:, 0], limits[:, 1]
    with np.errstate(invalid="ignore"):
        X = _into_limits(fam.robot, tracks)
        excess = np.maximum(lo_l - X, X - hi_l).max(axis=-1)  # (m, k), NaN: no row
    a, e = intervals[:, 0], intervals[:, 1]
    within = (t_nodes[None, :] > a[:, None]) & (t_nodes[None, :] < e[:, None])  # (i, m)
    node_out = excess[:, owner].T > _NODE_OUT  # (i, m)
    hit = np.flatnonzero((within & node_out).any(axis=1))
    if not len(hit):
        return intervals, owner, []
    # the intervals' ends by their rows (an end at one joint's crossing can have another
    # joint far out: #7320's -0.5248, q3 at its limit, q2 0.46 past its own)
    qe, ve = fam.slot_rows(np.concatenate([a[hit], e[hit]]), np.tile(owner[hit], 2))
    with np.errstate(invalid="ignore"):
        end_ok = ve & (np.maximum(lo_l - qe, qe - hi_l).max(axis=-1) <= _NODE_OUT)
    seqs: list[tuple[int, list[float], list[bool]]] = []
    for n_, i in enumerate(hit.tolist()):
        k = np.flatnonzero(within[i] & np.isfinite(excess[:, owner[i]]))
        ts = [float(a[i])] + t_nodes[k].tolist() + [float(e[i])]
        ok = ([bool(end_ok[n_])] + (excess[k, owner[i]] <= _NODE_OUT).tolist()
              + [bool(end_ok[len(hit) + n_])])
        seqs.append((i, ts, ok))
    brk = [(si, j) for si, (_, _, ok) in enumerate(seqs) for j in range(len(ok) - 1)
           if ok[j] != ok[j + 1]]
    lo = np.array([seqs[si][1][j] for si, j in brk])
    hi = np.array([seqs[si][1][j + 1] for si, j in brk])
    s0 = np.array([seqs[si][2][j] for si, j in brk])
    bb = np.array([owner[seqs[si][0]] for si, j in brk], dtype=int)
    keep = np.ones(len(intervals), dtype=bool)
    keep[hit] = False
    if not len(brk):  # every hit interval outside at its ends and at its nodes: dropped
        return intervals[keep], owner[keep], []
    inner, joint, side = _state_change(fam, limits, lo, hi, s0, bb)
    cuts: dict[int, list[float]] = {i: [] for i in range(len(seqs))}
    crossings: list[tuple[float, int, int, str]] = []
    for n_, (si, _) in enumerate(brk):
        cuts[si].append(float(inner[n_]))
        crossings.append((float(inner[n_]), int(bb[n_]), int(joint[n_]), str(side[n_])))
    new: list[tuple[int, float, float]] = []
    for si, (i, ts, ok) in enumerate(seqs):
        ends = iter(cuts[si])
        start: float | None = ts[0] if ok[0] else None
        for j in range(len(ok) - 1):
            if ok[j] == ok[j + 1]:
                continue
            x = next(ends)
            if ok[j]:  # in -> out: a run ends at x
                assert start is not None
                new.append((int(owner[i]), start, x))
                start = None
            else:  # out -> in: a run starts at x
                start = x
        if start is not None:
            new.append((int(owner[i]), start, ts[-1]))
    iv, ob = _merged(intervals[keep], owner[keep], new)
    return iv, ob, crossings


def _state_change(fam: _Family, limits: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                  s0: np.ndarray, bb: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Changes of state (inside every limit or not) on branch rows, to adjacent doubles.

    ``lo``, ``hi`` (p,): brackets of branches ``bb`` (p,), the state at ``lo`` ``s0``
    (p,) and the other at ``hi``; each is shrunk on ``fam.slot_rows`` (one batch per
    step) by :func:`_shrunk`, on the rows' margin inside the limits (the slack less
    the farthest any joint is past its limit: >= 0 inside, NaN without a row, which
    is outside), to adjacent doubles, ``FINE_T`` wide, or ends both within
    ``_STATE_NOISE`` of the state's edge (the in-limit end is one whose row was found
    inside). Returns the last in-limit value (p,), and the joint furthest out
    past it (p,) with its side ``"lower"``/``"upper"`` (p,): a limit crossing there
    (joint 0 where the outer value has no row).
    """
    def margin(t: np.ndarray, b: np.ndarray) -> np.ndarray:
        q, v = fam.slot_rows(t, b)
        with np.errstate(invalid="ignore"):
            m = MANIFOLD_SLACK - np.maximum(limits[:, 0] - q, q - limits[:, 1]).max(axis=-1)
        return np.where(v, m, np.nan)

    def state(t: np.ndarray, a: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        m = margin(t, bb[a])
        return m, (m >= 0.0) == s0[a], np.ones(len(a), dtype=bool)

    if len(lo):
        m0 = margin(np.concatenate([lo, hi]), np.tile(bb, 2))
        lo, hi, _ = _shrunk(state, lo, hi, m0[:len(lo)], m0[len(lo):], 4 * _BISECT,
                            _STATE_NOISE, FINE_T)
    inner, outer = np.where(s0, lo, hi), np.where(s0, hi, lo)
    q_out, _ = fam.slot_rows(outer, bb)
    with np.errstate(invalid="ignore"):
        below, above = limits[:, 0] - q_out, q_out - limits[:, 1]
    far = np.fmax(below, above)
    joint = np.argmax(np.nan_to_num(far, nan=-np.inf), axis=1)
    r = np.arange(len(joint))
    side = np.where(above[r, joint] > below[r, joint], "upper", "lower")
    return inner, joint, side


def _node_fills(fam: _Family, limits: np.ndarray, intervals: np.ndarray, owner: np.ndarray,
                t_nodes: np.ndarray, tracks: np.ndarray, starts: np.ndarray | None = None
                ) -> tuple[np.ndarray, np.ndarray, list[tuple[float, int, int, str]]]:
    """The in-limit runs of node rows that no interval of their branch holds, added.

    ``_node_cuts``'s other half: a crossing the scan misses can also join an
    in-limit piece to an outside one, and the piece's midpoint then drops both.
    On the offset iiwa's special pose of ``test_node_cuts_...`` (q4 = 0, q6 = -1e-6)
    with joint 7 the parameter, the branch through q1's upper limit at t = 0.08835
    (there q4 = q6 = 0 too: the held 6 x 6 singular) lost that crossing on the AVX2
    and baseline kernels (the rows' bisection found no row next to it) and with it
    [0.08835, 1.48407], whose rows are regular (smallest singular value 1e-3 at
    t = 0.5) and inside every limit; the AVX-512 kernel kept it. A node row inside by
    more than ``_NODE_OUT`` outside every interval of its branch starts a run over
    its neighbouring in-limit node rows; each end between an in-limit and another
    node (outside, or no row) is bisected on ``fam.slot_rows`` (``_state_change``),
    a run reaching the range's end ends there. ``starts`` (m, k) bool, if given: the
    node rows that may start a run (a degenerate manifold's regular rows: its
    near-continuum rows, singular, are not required in an interval, and bisecting
    every one of them cost the reach-boundary pose ~4,200 more solves).

    Returns ``(intervals, owner, crossings [(t, branch, joint, "lower"|"upper")])``
    (the ends whose outer row is outside: a fold's is not a crossing); the arrays
    unchanged (the same objects) where every in-limit node row is held.
    """
    lo_l, hi_l = limits[:, 0], limits[:, 1]
    with np.errstate(invalid="ignore"):
        X = _into_limits(fam.robot, tracks)
        excess = np.maximum(lo_l - X, X - hi_l).max(axis=-1)  # (m, k), NaN: no row
        inside = excess < -_NODE_OUT
        state = excess <= _NODE_OUT
    held = np.zeros(inside.shape, dtype=bool)
    for (a, e), b in zip(intervals, owner, strict=True):
        held[:, b] |= (t_nodes >= a) & (t_nodes <= e)
    lost = inside & ~held
    if starts is not None:
        lost &= starts
    if not lost.any():
        return intervals, owner, []
    m = len(t_nodes)
    runs: list[tuple[int, int, int]] = []  # (branch, first node, last node)
    for b in np.flatnonzero(lost.any(axis=0)).tolist():
        i = 0
        while i < m:
            if not state[i, b]:
                i += 1
                continue
            j = i
            while j + 1 < m and state[j + 1, b]:
                j += 1
            if lost[i:j + 1, b].any():
                runs.append((b, i, j))
            i = j + 1
    # the ends to bisect: (run, is its start, in-limit node, the node beyond)
    ends = [(r, first, i0 if first else i1, i0 - 1 if first else i1 + 1)
            for r, (_, i0, i1) in enumerate(runs) for first in (True, False)
            if (i0 > 0 if first else i1 < m - 1)]
    bounds = {(r, True): float(t_nodes[i0]) for r, (_, i0, _) in enumerate(runs)}
    bounds.update({(r, False): float(t_nodes[i1]) for r, (_, _, i1) in enumerate(runs)})
    crossings: list[tuple[float, int, int, str]] = []
    if ends:
        bb = np.array([runs[r][0] for r, *_ in ends], dtype=int)
        inn = np.array([t_nodes[i] for _, _, i, _ in ends])
        out = np.array([t_nodes[o] for *_, o in ends])
        inner, joint, side = _state_change(fam, limits, inn, out, np.ones(len(ends), bool),
                                           bb)
        for n_, (r, first, _, o) in enumerate(ends):
            bounds[(r, first)] = float(inner[n_])
            if np.isfinite(excess[o, runs[r][0]]):  # outside, not past a fold
                crossings.append((float(inner[n_]), int(bb[n_]), int(joint[n_]),
                                  str(side[n_])))
    new = [(b, bounds[(r, True)], bounds[(r, False)]) for r, (b, _, _) in enumerate(runs)]
    iv, ob = _merged(intervals, owner, new)
    return iv, ob, crossings


#: Intervals of one branch at most this many ulps of t apart are one (``_joined``).
_ULPS = 8


def _joined(intervals: np.ndarray, owner: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The intervals (m, 2) of branches ``owner`` (m,), a branch's within rounding joined.

    Within rounding: at most ``_ULPS`` ulps of t apart. The continued family's corner
    rule and its widened ends can list one corner twice, ulps apart: the random 7R's
    range-end corner of
    ``test_a_corner_at_the_range_end_is_a_one_point_interval[q0]`` on the baseline
    kernel was [t - 1.8e-15, t - 1.8e-15] and [t - 8.9e-16, t] (session 17; q6 = 1e-9,
    so one ulp of t moves the joints ~700 times as far: the first point's row is out
    by 1.4e-12, the second interval's start by 8e-14). A one-point interval that
    close to another is that corner listed again and is dropped; two longer ones are
    joined. The arrays unchanged (the same objects) when nothing is joined; sorted by
    branch then start either way.
    """
    if len(intervals) < 2:
        return intervals, owner
    order = np.lexsort((intervals[:, 0], owner))
    iv, ob = intervals[order], owner[order]
    tol = _ULPS * np.spacing(np.maximum(np.abs(iv[:-1, 1]), 1.0))
    join = (ob[1:] == ob[:-1]) & (iv[1:, 0] - iv[:-1, 1] <= tol)
    if not join.any():
        return intervals, owner
    out: list[list[float]] = [iv[0].tolist()]
    keep = [int(ob[0])]
    for (a, e), b, j in zip(iv[1:].tolist(), ob[1:].tolist(), join.tolist(), strict=True):
        if j and a == e:  # a point next to an interval: the same corner again
            continue
        if j and out[-1][0] == out[-1][1]:
            out[-1] = [a, e]
        elif j:
            out[-1][1] = max(out[-1][1], e)
        else:
            out.append([a, e])
            keep.append(int(b))
    return np.array(out).reshape(-1, 2), np.array(keep, dtype=owner.dtype)


#: A node row outside by more than this [rad] cuts its interval (``_node_cuts``; a joint
#: riding its limit within rounding, 1e-15 to 1e-11, does not).
_NODE_OUT = 1e-9


def _touches(fam: _Family, limits: np.ndarray, crossings: list[Any],
             spans: list[tuple[float, float]], owners: list[int], out: np.ndarray
             ) -> list[tuple[int, float, float]]:
    """The one-point intervals (b, t, t) of corners: the rule of ``hm_intervals``.

    A cut t of branch b (a limit crossing, or an end of the range) whose pieces on
    both sides are outside is an interval of its own when b's row at t is inside
    (``MANIFOLD_SLACK``): two joints at limits at t, the branch leaving through one
    on either side. A crossing is solved only where every joint out at either
    piece's midpoint (``out``, (pieces, n)) crosses a limit within ``_CORNER`` of t
    on b (between cuts a joint keeps its side): a piece out by a joint without a
    crossing there is no corner (on uniform poses such rows can be inside where a
    crossing next to a fold was missed: ``docs/ik.md``, "Corners"). The range's
    ends are solved (a crossing there, with the parameter at its own limit, is not
    always recorded) unless the continued family's track there has a joint out by
    more than ``_NEAR`` or does not reach it.
    """
    lo_d, hi_d = fam.domain
    at: dict[int, list[tuple[float, int]]] = {}
    for t, b, j, *_ in crossings:
        at.setdefault(b, []).append((t, j))
    left = {(b, e): i for i, ((_, e), b) in enumerate(zip(spans, owners, strict=True))}
    right = {(b, a): i for i, ((a, _), b) in enumerate(zip(spans, owners, strict=True))}
    ends = {lo_d: 0, hi_d: 1}
    predict = getattr(fam, "predict", None)  # the continued family's tracks: no solve
    far = np.zeros((2, fam.k), dtype=bool)
    if predict is not None:
        p = predict(np.array([lo_d, hi_d]))[..., None] + np.array([-_TWO_PI, 0.0, _TWO_PI])
        with np.errstate(invalid="ignore"):
            close = ((p >= limits[:, :1] - _NEAR) & (p <= limits[:, 1:] + _NEAR)).any(-1)
        far = ~close.all(-1)  # (2, k): a joint out by > _NEAR, or no track there
    ts, bs = [], []
    out_any: list[bool] = np.logical_or.reduce(out, axis=1).tolist()  # (python scalars in
    # the loops: ~1 us a numpy call)
    for b in range(fam.k):
        cuts = at.get(b, [])
        for t in {min(max(float(t), lo_d), hi_d) for t, _ in cuts} | {lo_d, hi_d}:
            sides = [s[(b, t)] for s in (left, right) if (b, t) in s]
            if not sides or any(not out_any[i] for i in sides):
                continue  # in a piece inside (or no piece): covered
            need = np.flatnonzero(out[sides].any(0))
            near = {j for tc, j in cuts if abs(tc - t) <= _CORNER}
            if (not far[ends[t], b]) if t in ends else set(need.tolist()) <= near:
                ts.append(t)
                bs.append(b)
    if not ts:
        return []
    values, idx = np.unique(ts, return_inverse=True)  # the range's ends: once
    q, valid, _ = fam.rows(values)
    br = np.array(bs)
    ok = valid[idx, br] & _within(q[idx, br], limits)
    return [(b, t, t) for t, b, good in zip(ts, bs, ok.tolist(), strict=True) if good]


def _join_wrap(pieces: list[tuple[int, float, float]], lo: float, hi: float
               ) -> list[tuple[int, float, float]]:
    """Periodic parameter: a branch's piece ending at hi and one starting at lo join.

    The joined interval is given as (start, end + 2 pi) with end + 2 pi > hi.
    """
    out = list(pieces)
    for b in {p[0] for p in pieces}:
        own = [p for p in out if p[0] == b]
        first = next((p for p in own if p[1] == lo), None)
        last = next((p for p in own if p[2] == hi), None)
        if first is not None and last is not None and first is not last:
            out.remove(first)
            out.remove(last)
            out.append((b, last[1], first[2] + _TWO_PI))
    return sorted(out)


_KINDS = ("lower", "upper", "aligned axes", "fold")  # HM_KIND_* 0-3


def _held_kernel(robot: Arm, fam: _HeldFamily) -> HeldKernel:
    """The :class:`HeldKernel` of a held-joint family of ``robot``."""
    aligned = np.array([[j, v] for j, v in _aligned_values(robot)],
                       dtype=np.float64).reshape(-1, 2)
    return HeldKernel(np.ascontiguousarray(fam.params, dtype=np.float64), aligned, fam.joint,
                      (fam.name, fam.domain), np.array(fam.domain),
                      f"analytic:pieper ({fam.name} held), compiled")


def _compiled(kern: HeldKernel, T: np.ndarray, grid: int = KERNEL_GRID
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict[str, Any], bool]:
    """A held-joint (Pieper) family's intervals and points by the compiled kernel.

    ``csrc/held_manifold.c``: a grid of the parameter with the rows' slopes dq/dt,
    crossings bracketed and refined by safeguarded Newton on q_j(t) - limit, folds
    bisected, pieces decided at their midpoints. Returns ``(intervals, owner,
    points, info, close)``: the intervals (m, 2) by branch, then start, and their
    branches (m,); the points are the kernel's rows ``[t, branch, joint, kind]``
    (``HM_KIND_*``; :func:`_held_records` makes the records when they are read);
    ``info["flags"]`` is nonzero when the kernel could not certify the pose (then
    the caller takes the solved-points path); ``close``: :func:`_points_refined`'s
    cheap test, computed by the kernel (False: it has nothing to find). The arrays
    are the kernel's own (``held_manifold_one``: packed in C, none built here).
    """
    out = K.held_manifold_one(kern.params, np.ascontiguousarray(T, dtype=np.float64),
                              kern.aligned, int(grid), 0.0)
    assert out is not None  # (a C-contiguous float64 array, its pose not tested: never None)
    return _info_added(out, int(grid))


#: The pose test ``held_manifold_one`` applies to a pose not checked yet
#: (:func:`_compiled_unchecked`): chain.h ``pose_problem`` with its rotation block's
#: rows within this of orthonormal (the largest entry of R R^T - I). R R^T - I and
#: R^T R - I share their eigenvalues, so an entry of ``check_rigid``'s R^T R - I is at
#: most 3 times this, rounding (~5e-16 an entry) included below ``ROTATION_EXACT``:
#: such a pose is one ``check_rigid`` returns as it is.
_EXACT = ROTATION_EXACT / 5


def _compiled_unchecked(kern: HeldKernel, T: object
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict[str, Any], bool] | None:
    """:func:`_compiled` of the caller's T, not checked yet, or None (no row computed).

    The kernel tests T first: a C-contiguous float64 (4, 4) ndarray that
    ``check_transform`` accepts and ``check_rigid`` returns as it is (``_EXACT``).
    None where it is not so: the caller checks T (``check_rigid``: the error, or the
    projected pose) and calls :func:`_compiled`. The check's ~5 us a pose are the
    kernel's ~0.05 (issue 29, helper ppy31).
    """
    out = K.held_manifold_one(kern.params, T, kern.aligned, KERNEL_GRID, _EXACT)
    return None if out is None else _info_added(out, KERNEL_GRID)


def _info_added(out: tuple[np.ndarray, np.ndarray, np.ndarray, int, int, bool], grid: int
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict[str, Any], bool]:
    """``held_manifold_one``'s outputs with its flags and pk_one calls as the ``info`` dict."""
    intervals, owner, points, flags, evals, close = out
    info = {"bisected": 0, "grid": grid, "compiled": True, "flags": flags, "solves": evals}
    return intervals, owner, points, info, close


def _held_records(points: np.ndarray) -> tuple[tuple[LimitCrossing, ...],
                                               tuple[SingularPoint, ...]]:
    """The records of the held-joint kernel's points (p, 4) ``[t, branch, joint, kind]``.

    Crossings by branch then t; singular points: the folds, then the aligned-axes
    points (each by branch then t; repeats of one merged, :func:`one_per_point`).
    """
    p = one_per_point(points, K.HM_KIND_ALIGNED)
    p = p[np.lexsort((p[:, 0], p[:, 1]))]
    limit = p[:, 3] <= K.HM_KIND_UPPER
    cross = tuple(LimitCrossing(t, int(b), int(j), _KINDS[int(k)])
                  for t, b, j, k in p[limit].tolist())
    fold = p[:, 3] == K.HM_KIND_FOLD
    sing = tuple(SingularPoint(t, int(b), _KINDS[int(k)])
                 for t, b, _, k in np.concatenate([p[fold], p[~fold & ~limit]]).tolist())
    return cross, sing


#: Crossings of one branch this close [in t] (or to an end of the range) may be a
#: graze or a corner: their rows are evaluated (``_points_refined``).
_PAIR = K.SM_PAIR  # 1e-6 (the swivel kernel's cheap test reads the same value)
#: The sort key of points [t, branch, joint, kind]: t + 64 branch (64 wider than any
#: parameter range); an interval's length (its end minus its start).
_KEYS = np.array([1.0, 64.0, 0.0, 0.0])
_LENGTH = np.array([-1.0, 1.0])
#: Probes of a graze stretch's extent either side of its point [in t]: from 1e-9 (a
#: crossing through the limit at |dq/dt| >= 1e-3 is out there: no graze, not widened).
_PROBES = 10.0 ** -np.arange(9, 2, -1)
#: Search steps of a graze stretch's end within a decade of ``_PROBES`` (``_SPLIT``
#: values each: the bracket shrinks 4 times per step, to ~1e-3 of the decade: the
#: stretches are 1e-6 to 1e-4 long, their ends inside to ~1e-9 of the last value).
_WIDEN = 5
_SPLIT = 3
#: Doubling probes past ``_PROBES`` of a family's touch inside at every probe (2e-3 ..
#: 8.2 [in t]), up to the branch's nearest crossing of another joint.
_FAR = 12
#: A family's touches of one branch closer than this [in t] are one (the first probe:
#: they widen alike); farther ones are each widened (a graze's extremum, located to
#: ~1e-6 where it is flat, beside another joint's crossing: ``_points_refined``; the
#: offset iiwa's q4 at its limit, special poses #6091 .. #9781 of seed 0).
_TOUCH_APART = float(_PROBES[0])
#: A listed interval at most this long is a point (a few ulps): widened as a graze.
_POINT = K.SM_POINT  # 1e-12
#: A corner's row out by at most this [rad] is refined on the pose's equations.
_CONDITIONING = 1e-7


def _points_refined(fam: _Family, limits: np.ndarray, intervals: np.ndarray,
                    owner: np.ndarray, points: np.ndarray, upper: int, every: bool = False,
                    touch: np.ndarray | None = None, singular: np.ndarray | None = None
                    ) -> tuple[np.ndarray, np.ndarray, tuple[tuple[float, int, np.ndarray], ...]]:
    """Graze stretches and corners the intervals miss (issue 29, helper rates29).

    ``points`` (p, 4) ``[t, branch, joint, kind]``: the kernels' points (kind at
    most ``upper``: a limit crossing; the Python paths' crossings have kind 0). Two
    classes of
    in-limit points are not held by the intervals of every path (the compiled
    kernels' and the Python families'):

    * *Grazes*: a joint's extremum within ``MANIFOLD_SLACK`` of its limit. The
      branch is inside over a stretch of ~2 sqrt(slack / |q''|) (1e-6 to 1e-5 in t)
      about it, but the kernels list it as the point [t, t] (or not at all when the
      pieces either side are decided outside at their midpoints). Each one-point
      interval, and each crossing of a branch within ``_PAIR`` of another crossing
      of it or of a range end whose row is inside, is widened to the last in-slack
      value either side (geometric probes 1e-9 .. 1e-3, then ``_WIDEN`` search
      steps on the rows); a side with no probe outside is not widened. (An
      interval at most ``_POINT`` long, a few ulps, is widened from its ends the
      same way, and so is one at most ``_PAIR`` long between two crossings of
      one joint of its branch with no aligned or fold point of the branch within
      ``_PROBES[-1]``: a graze whose extremum is past the limit by an ulp or two,
      which the kernels' rounding decides (the baseline copy, without FMA, where
      the AVX2 copy's extremum touches it exactly); a longer one, or one ending at
      a fold, an aligned point, a range end or crossings of two joints, ends
      there: next to an aligned point the outer joints swing by up to pi between
      the widening's probes.)
      On the solved-points path of a joint parameter (``every``, not the swivel's
      reference) the range's ends are such candidates too
      (the parameter at its limit), and every interval is widened so: its ends
      at crossings of a joint with |dq/dt| below ~1e-3 move out to the last
      in-slack value (a transversal crossing is out at 1e-9 and stays).
    * *Corners out by conditioning*: such a crossing whose row is out by at most
      ``_CONDITIONING`` with two or more joints within it of a limit (next to an
      aligned triple the closed forms' rows are 1e-11 to 1e-9 off). The row is
      refined by Gauss-Newton on the pose with those joints held exactly at their
      limits (``_held_refine``); when it reproduces T to 1e-13, is inside and lies
      within 1e-6 of the branch's row, the corner is the interval [t*, t*] at its
      parameter value t*, and ``SelfMotion.sample`` returns that row there.

    ``every``: every crossing is a corner candidate (the solved-points path, where a
    closed-form row costs little against the pose's 50-150 ms; not the continued
    family, whose rows are general-6R solves: +10-15 % CPU on uniform random 7R
    poses), not only close ones; a graze is
    widened only from a close one (a lone uncovered crossing inside, next to a piece
    decided outside, is a crossing missed nearby: ``docs/ik.md``, "Corners"); with a
    joint parameter such a crossing whose row is inside and whose joint is not
    tangent there is listed as
    the point [t, t] alone, not widened (a corner whose second crossing the
    held-joint solve cannot give: the rtb-data iiwa14 with the elbow stretched).

    ``touch`` (q, 3) ``[t, branch, joint]``: points a family knows the branch
    stays within the slack of a limit beyond rounding (the continued family's
    grazes and shallow crossings, ``_ContinuedFamily._grazes``): candidates like
    the close crossings, kept even inside an interval (an interval ending at a
    shallow crossing is widened to the in-slack stretch past it). One per
    ``_TOUCH_APART`` of a branch is kept; of touches within ``_PAIR`` of each other
    only the first may widen past ``_PROBES[-1]`` (``_widen``'s ``reach``).

    ``singular`` (s, 2) ``[t, branch]``: the aligned and fold points of a family whose
    ``points`` hold its crossings only (the Python paths'); the kernels' points hold
    theirs (kind above ``upper``).

    Returns ``(intervals, owner, corners)``; the arrays unchanged (the same objects)
    when nothing is found: a uniform pose computes no row here (its cost is the
    test for short intervals and close points, ~5 us; the compiled swivel's kernel
    computes the same test, ``swivel_manifold_one``'s ``close`` flag, and calls this
    only where it is set).
    """
    lo_d, hi_d = fam.domain
    joint = every and not fam.periodic  # the solved points of a joint parameter
    # the cheap test first (a uniform pose ends here): no short interval, no two
    # crossings of a branch within _PAIR, none within it of a range end (the aligned
    # and fold points make no candidate below: a crossing within _PAIR of a fold, ~1.5 %
    # of uniform Panda poses, cost ~120 us here for nothing; session 28)
    crossings = points[points[:, 3] <= upper]
    key = np.dot(crossings, _KEYS)  # by branch, then t
    key.sort()
    t = crossings[:, 0]
    # (count_nonzero and matmul, not min / any / column slices: each numpy call costs
    # ~0.5-2 us on these sizes, ~50 us the whole compiled swivel call)
    touch = np.zeros((0, 3)) if touch is None else touch
    if not every and not len(touch) and not (np.count_nonzero(key[1:] - key[:-1] <= _PAIR)
            or np.count_nonzero(t <= lo_d + _PAIR) or np.count_nonzero(t >= hi_d - _PAIR)
            or np.count_nonzero(np.dot(intervals, _LENGTH) <= _POINT)):
        return intervals, owner, ()
    cuts = points[points[:, 3] <= upper, :3]
    near = np.zeros(len(cuts), dtype=bool)  # a crossing close to another or to an end
    if len(cuts):
        t = cuts[:, 0]
        key = cuts[:, :2] @ _KEYS[:2]
        near = (t - lo_d <= _PAIR) | (hi_d - t <= _PAIR)
        order = np.argsort(key, kind="stable")
        close = np.diff(key[order]) <= _PAIR
        near[order[1:][close]] = True
        near[order[:-1][close]] = True
    if joint:  # the range's ends as crossings of the parameter
        # (a corner there: the parameter at its limit, another joint at its own; the
        # row out by conditioning next to the iiwa's stretched elbow, the other
        # joint's crossing not found: a singular held solve)
        br = np.arange(fam.k, dtype=np.float64)
        ends = np.column_stack([np.repeat([lo_d, hi_d], fam.k), np.tile(br, 2),
                                np.full(2 * fam.k, float(fam.joint or 0))])
        cuts = np.concatenate([cuts, ends])
        near = np.concatenate([near, np.ones(2 * fam.k, dtype=bool)])
    point = intervals[:, 1] - intervals[:, 0] <= _POINT
    point |= _short_grazes(fam, intervals, owner, points, upper, singular)
    cand = near | every
    c, near = cuts[cand], near[cand]
    if len(c):  # crossings already in an interval of their branch: nothing to find
        held = ((intervals[None, :, 0] <= c[:, :1]) & (c[:, :1] <= intervals[None, :, 1])
                & (owner[None, :] == c[:, 1:2])).any(axis=1)
        c, near = c[~held], near[~held]
    far = np.zeros(0, dtype=bool)  # per touch: its sides may go past _PROBES[-1]
    if len(touch):  # not deep inside an interval (nothing to widen)
        deep = ((intervals[None, :, 0] + _PROBES[-1] < touch[:, :1])
                & (touch[:, :1] < intervals[None, :, 1] - _PROBES[-1])
                & (owner[None, :] == touch[:, 1:2])).any(axis=1)
        touch = touch[~deep]
        touch = touch[np.lexsort((touch[:, 0], touch[:, 1]))]
        gap = np.full(len(touch), np.inf)  # from the previous touch of its branch
        gap[1:] = np.where(touch[1:, 1] == touch[:-1, 1], np.diff(touch[:, 0]), np.inf)
        # one per _TOUCH_APART (they widen alike); of a run within _PAIR only the first
        # goes far (the others, e.g. another joint's crossing beside a graze's extremum
        # located to ~1e-6 where it is flat, whose row can be out: to _PROBES[-1] at most)
        keep = gap > _TOUCH_APART
        touch, far = touch[keep], (gap > _PAIR)[keep]
        c = np.concatenate([c, touch[:, :3]])
        near = np.concatenate([near, np.ones(len(touch), dtype=bool)])
    # joint: every interval's ends too (a crossing of a joint moving slowly with t,
    # e.g. the iiwa's wrist with the elbow stretched, |dq/dt| 1e-4: the row is inside
    # by the slack up to 1e-8 beyond the exact crossing, where q's value can lie)
    stretch = [(float(a), float(e), int(b)) for (a, e), b, p in zip(intervals, owner, point)
               if p or joint]
    reach = [False] * len(stretch)  # a touch's side inside at every probe: to the last one
    caps = [(lo_d, hi_d)] * len(stretch)  # how far a touch's side goes (its branch's
    # nearest crossings of another joint)
    lim_pts = points[points[:, 3] <= upper]
    bounds = [_bound(lim_pts, a, e, b) for a, e, b in stretch]  # no side goes past these
    first_touch = len(c) - len(touch)
    corners: list[tuple[float, int, np.ndarray]] = []
    points_only: list[tuple[int, float, float]] = []
    if len(c):
        ts, inv = np.unique(c[:, 0], return_inverse=True)
        q, valid, _ = fam.rows(ts)
        b = c[:, 1].astype(int)
        r = q[inv, b]
        excess = np.maximum(limits[:, 0] - r, r - limits[:, 1])  # (c, n)
        worst = np.where(valid[inv, b], excess.max(axis=-1), np.inf)
        inside = worst <= MANIFOLD_SLACK
        lone = np.flatnonzero(inside & ~near)
        if len(lone):  # a graze only where its joint stays at the limit either side
            tangent = _tangent(fam, limits, c[lone])
            # else the point alone: in limits, its neighbours not (a corner whose
            # other crossing was not found, e.g. next to the iiwa's stretched elbow)
            points_only = [(int(b[i]), float(c[i, 0]), float(c[i, 0]))
                           for i in lone[~tangent]] if joint else []
            inside[lone] = tangent
        for i in np.flatnonzero(inside):
            stretch.append((float(c[i, 0]), float(c[i, 0]), int(b[i])))
            reach.append(bool(i >= first_touch and far[i - first_touch]))
            other = lim_pts[(lim_pts[:, 1] == b[i]) & (lim_pts[:, 2] != c[i, 2]), 0]
            caps.append((float(other[other < c[i, 0]].max(initial=lo_d)),
                         float(other[other > c[i, 0]].min(initial=hi_d))))
            bounds.append((float(other[other < c[i, 0]].max(initial=-np.inf)),
                           float(other[other > c[i, 0]].min(initial=np.inf))))
        for i in np.flatnonzero((worst > MANIFOLD_SLACK) & (worst <= _CONDITIONING)):
            hold = np.flatnonzero(np.abs(excess[i]) <= _CONDITIONING)
            if len(hold) < 2:
                continue
            row = _held_refine(fam, limits, r[i], hold)
            if row is not None:
                tc = _param(fam, row)
                if tc is not None:
                    corners.append((tc, int(b[i]), row))
    new = (_widen(fam, limits, stretch, reach, caps, bounds)
           + [(b, t, t) for t, b, _ in corners]
           + points_only)
    iv, ob = _merged(intervals, owner, new)
    if not corners and np.array_equal(iv, intervals) and np.array_equal(ob, owner):
        return intervals, owner, ()  # nothing widened or added: the kernel's arrays
    return iv, ob, tuple(corners)


def _bound(lim_pts: np.ndarray, a: float, e: float, b: int) -> tuple[float, float]:
    """How far the stretch [a, e] of branch b may widen: (lo, hi), +-inf for none.

    Its nearest crossings either side of a joint not crossing at its ends.

    The probes of :func:`_widen` are a decade apart, so a side's search between its
    last inside and first outside probe can pass a stretch where another joint is
    out: SRS special #8651 of seed 0 (q6 = -1e-7), branch 7's one-point intervals at
    q7's crossing -9.39e-7 and q5's 6.7e-16 were widened into one over (-1.79e-7, 0),
    where q5 is past its limit by up to 0.17 rad (session 16). A crossing is where a
    joint leaves or enters its range, so no in-limit stretch runs through one of a
    joint other than its own (a graze's own joint crosses twice within it).
    """
    own = lim_pts[lim_pts[:, 1] == b]
    ends = (np.abs(own[:, 0] - a) <= _TOUCH_APART) | (np.abs(own[:, 0] - e) <= _TOUCH_APART)
    at = own[ends, 2]
    t = own[~np.isin(own[:, 2], at), 0]
    return float(t[t < a].max(initial=-np.inf)), float(t[t > e].min(initial=np.inf))


def _short_grazes(fam: _Family, intervals: np.ndarray, owner: np.ndarray,
                  points: np.ndarray, upper: int, singular: np.ndarray | None
                  ) -> np.ndarray:
    """(m,) bool: the intervals ``_points_refined`` widens like a one-point interval.

    Longer than ``_POINT``, at most ``_PAIR`` long, between two crossings of one joint
    of its branch (a graze whose extremum is past the limit by an ulp or two: the
    baseline copy, without FMA), with no aligned or fold point of the branch within
    ``_PROBES[-1]`` (there the outer joints swing by up to pi between the widening's
    probes). ``points`` and ``upper`` as ``_points_refined``'s; ``singular`` (s, 2)
    ``[t, branch]`` the aligned and fold points its ``points`` do not hold.
    """
    length = intervals[:, 1] - intervals[:, 0]
    out = np.zeros(len(intervals), dtype=bool)
    short = np.flatnonzero((length > _POINT) & (length <= _PAIR))
    if not len(short):
        return out
    lim_pts = points[points[:, 3] <= upper]
    own = lim_pts[:, None, 1] == owner[None, short]
    at_a = own & (lim_pts[:, None, 0] == intervals[None, short, 0])  # (p, s)
    at_e = own & (lim_pts[:, None, 0] == intervals[None, short, 1])
    joints = lim_pts[:, 2, None]
    same = ((at_a[:, None, :] & at_e[None, :, :])
            & (joints[:, None, :] == joints[None, :, :])).any(axis=(0, 1))
    sing = points[points[:, 3] > upper, :2]
    if singular is not None:
        sing = np.concatenate([sing, singular.reshape(-1, 2)])
    ts = sing[:, 0]
    if fam.periodic:  # (the swivel: an aligned point at -pi is one at pi)
        ts = np.concatenate([ts - 2 * np.pi, ts, ts + 2 * np.pi])
        sing = np.tile(sing, (3, 1))
    swing = ((sing[:, None, 1] == owner[None, short])
             & (ts[:, None] >= intervals[None, short, 0] - _PROBES[-1])
             & (ts[:, None] <= intervals[None, short, 1] + _PROBES[-1])).any(axis=0)
    out[short[same & ~swing]] = True
    return out


def _tangent(fam: _Family, limits: np.ndarray, c: np.ndarray) -> np.ndarray:
    """(c,) bool: crossing [t, b, j]'s joint within the slack of its limit at t +- 1e-8.

    A graze (the joint's extremum at its limit) stays there to ~1e-16; a crossing
    through the limit is out by ~1e-8 |dq/dt| on one side. Only a tangent lone
    crossing is widened (the solved-points path's ``every``): a crossing into the limits
    followed by a piece decided outside is a missed crossing (rtb-data iiwa14,
    uniform pose #119 of seed 0: a 6.4e-4 stretch), not a graze.
    """
    ts = np.concatenate([c[:, 0] - 1e-8, c[:, 0] + 1e-8])
    m = len(c)
    b, j = np.tile(c[:, 1].astype(int), 2), np.tile(c[:, 2].astype(int), 2)
    q, valid = fam.slot_rows(ts, b)
    x = q[np.arange(2 * m), j]
    with np.errstate(invalid="ignore"):
        at = (valid & (x >= limits[j, 0] - MANIFOLD_SLACK)
              & (x <= limits[j, 1] + MANIFOLD_SLACK))
    out: np.ndarray = at[:m] & at[m:]
    return out


def _param(fam: _Family, row: np.ndarray) -> float | None:
    """The parameter value of a refined row, in the domain (the swivel: wrapped)."""
    t = fam.param_of(row)
    lo, hi = fam.domain
    if fam.periodic:
        return float(_wrap(t))
    return t if lo <= t <= hi else None


def _held_refine(fam: _Family, limits: np.ndarray, r: np.ndarray, hold: np.ndarray
                 ) -> np.ndarray | None:
    """Row r refined on the pose with joints ``hold`` exactly at their nearer limits.

    Gauss-Newton (least squares over the free joints' Jacobian columns: 6 x (n -
    len(hold))) on ``pose_error``, at most 8 steps; the row when its pose error is
    at most 1e-13 (position [m] and rotation [rad]), every free joint is inside
    (``MANIFOLD_SLACK``) and it moved by at most 1e-6 rad, else None.
    """
    from robokin.kinematics.ik.self_motion_families import _size
    from robokin.kinematics.jacobian import jacobian_and_pose
    from robokin.spatial import pose_error

    robot: Arm = fam.robot
    T: np.ndarray = fam.T  # type: ignore[attr-defined]
    q: np.ndarray = np.array(r, dtype=np.float64)
    lim = limits[hold]
    q[hold] = np.where(np.abs(r[hold] - lim[:, 0]) <= np.abs(r[hold] - lim[:, 1]),
                       lim[:, 0], lim[:, 1])
    free = np.setdiff1d(np.arange(len(q)), hold)
    for _ in range(8):
        J, P = jacobian_and_pose(robot.chain, q)
        e = pose_error(P, T)
        if _size(e) <= 1e-15:
            break
        step = np.linalg.lstsq(J[:, free], e, rcond=None)[0]
        q[free] += step
        if np.abs(step).max() <= 1e-15:
            e = pose_error(jacobian_and_pose(robot.chain, q)[1], T)
            break
    else:
        e = pose_error(jacobian_and_pose(robot.chain, q)[1], T)
    if (_size(e) > 1e-13 or not _within(q, limits)
            or np.abs(q - r).max() > 1e-6):
        return None
    return q


def _widen(fam: _Family, limits: np.ndarray, points: list[tuple[float, float, int]],
           reach: list[bool] | None = None, caps: list[tuple[float, float]] | None = None,
           bounds: list[tuple[float, float]] | None = None
           ) -> list[tuple[int, float, float]]:
    """Each in-limit stretch (a, e, b) (a point: a = e) widened to its in-slack extent.

    Probes at ``_PROBES`` before a and after e (one batch); a side with a probe
    outside (and the first inside) is searched between its last inside and first
    outside probe, ``_SPLIT`` values per step (one batch per step, both sides and
    every stretch together), ``_WIDEN`` steps (to ~1e-3 of that decade), and ends
    1e-3 of its distance inside the last inside value found (a graze's joint there
    ~0.998 of the slack from its limit: ``test_swivel.test_intervals_are_exact``'s
    ends at a limit to 1e-12 hold after the swivel's 2 pi shift). A side inside at
    every probe is not widened, except for the points flagged in ``reach`` (a
    family's touches: a joint riding its limit within the slack, e.g. the offset
    iiwa's q4 out by 1e-15 over 2e-2 of t): to the last probe, and with ``caps``
    (per point, the parameter values [lo, hi] a flagged side goes at most to) on by
    probes doubling to ``_FAR`` (to 8 rad) and the same search, to its last inside
    value. ``bounds`` (per point, [lo, hi]: :func:`_bound`) stop the search of a side
    with a probe outside there.
    """
    if not points:
        return []
    m, p = len(points), len(_PROBES)  # (the first probe alone: most points are corners)
    t0 = np.array([a for a, _, _ in points] + [e for _, e, _ in points])  # (2m,) sides
    side = np.repeat([-1.0, 1.0], m)
    br = np.tile(np.array([b for _, _, b in points]), 2)
    lo_d, hi_d = fam.domain

    def inside(ts: np.ndarray, b: np.ndarray) -> np.ndarray:
        """(rows of ts (s, w)) on branches b (s,) inside (the range's ends included)."""
        q, valid = fam.slot_rows(ts.ravel(), np.repeat(b, ts.shape[1]))
        ok = (valid & _within(q, limits)).reshape(ts.shape)
        if not fam.periodic:
            ok &= (ts >= lo_d) & (ts <= hi_d)
        out: np.ndarray = ok
        return out

    ok = np.zeros((2 * m, p), dtype=bool)  # the first probe, then the rest where inside
    ok[:, 0] = inside(t0[:, None] + side[:, None] * _PROBES[:1], br)[:, 0]
    more = np.flatnonzero(ok[:, 0])
    if len(more):
        ok[more, 1:] = inside(t0[more, None] + side[more, None] * _PROBES[None, 1:], br[more])
    first_out = np.argmin(ok, axis=1)  # the first probe outside (0 if none is)
    go = ~ok.all(axis=1) & (first_out > 0)  # inside at 1e-9 and outside further on
    d = np.zeros(2 * m)

    def search(a: np.ndarray, e: np.ndarray, g: np.ndarray) -> np.ndarray:
        """The last inside distance of sides g, inside at a (g,) and outside at e."""
        tb, sb, bb = t0[g], side[g], br[g]
        frac = np.arange(1, _SPLIT + 1) / (_SPLIT + 1)
        for _ in range(_WIDEN):
            x = a[:, None] + (e - a)[:, None] * frac[None, :]  # (g, split)
            inn = inside(tb[:, None] + sb[:, None] * x, bb)
            k = np.argmin(inn, axis=1)  # the first value outside (0: none, or the first)
            none = inn.all(axis=1)
            new_a = np.where(none, x[:, -1], np.where(k > 0, x[np.arange(len(k)), k - 1], a))
            e = np.where(none, e, x[np.arange(len(k)), k])
            a = new_a
        return a

    if go.any():
        last = search(_PROBES[first_out[go] - 1], _PROBES[first_out[go]], np.flatnonzero(go))
        d[go] = last * (1.0 - 1e-3)  # inside the last inside value: its row stays within
        # the slack after a 2 pi shift of the swivel (rounding) at q'' up to ~1e11
        if bounds is not None:  # not past another joint's crossing (_bound)
            pairs = list(zip(points, bounds, strict=True))
            room = np.concatenate([[a - lo for (a, _, _), (lo, _) in pairs],
                                   [hi - e for (_, e, _), (_, hi) in pairs]])
            d[go] = np.minimum(d[go], room[go])
    if reach is not None:
        full = ok.all(axis=1) & np.tile(np.array(reach, dtype=bool), 2)
        d[full] = _PROBES[-1] * (1.0 - 1e-3)
        if caps is not None and full.any():
            # on to the side's cap (the branch's nearest crossing of another joint):
            # probes doubling from 2e-3, then the search between the last inside and
            # the first outside one (the offset iiwa #5084: q4 within 1e-14 of its
            # limit over ~0.06 of t about q's value, its crossings rounding's)
            g = np.flatnonzero(full)
            cap = np.concatenate([[p0 - c0 for (p0, _, _), (c0, _) in zip(points, caps, strict=True)],
                                  [c1 - p1 for (_, p1, _), (_, c1) in zip(points, caps, strict=True)]])
            x = np.minimum(_PROBES[-1] * 2.0 ** np.arange(1, _FAR + 1)[None, :],
                           cap[g, None])  # (g, _FAR)
            inn = inside(t0[g, None] + side[g, None] * x, br[g])
            k = np.argmin(inn, axis=1)
            out_at = ~inn.all(axis=1)
            far = np.where(out_at, 0.0, x[:, -1])
            if out_at.any():
                o = np.flatnonzero(out_at)
                lo_x = np.where(k[o] > 0, x[o, np.maximum(k[o] - 1, 0)], _PROBES[-1])
                far[o] = search(lo_x, x[o, k[o]], g[o]) * (1.0 - 1e-3)
            d[g] = np.maximum(d[g], far)
    ends = t0 + side * d
    out = []
    for a, e, b in zip(ends[:m].tolist(), ends[m:].tolist(), br[:m].tolist(), strict=True):
        if not fam.periodic:
            a, e = max(a, lo_d), min(e, hi_d)
        elif a < lo_d:
            a, e = a + _TWO_PI, e + _TWO_PI
        out.append((int(b), a, e))
    return out


def _merged(intervals: np.ndarray, owner: np.ndarray, new: list[tuple[int, float, float]]
            ) -> tuple[np.ndarray, np.ndarray]:
    """The intervals with ``new`` (b, start, end) added, overlapping ones of a branch joined."""
    every = sorted([(int(b), float(a), float(e)) for (a, e), b in zip(intervals, owner)] + new)
    out: list[tuple[int, float, float]] = []
    for b, a, e in every:
        if out and out[-1][0] == b and a <= out[-1][2]:
            out[-1] = (b, out[-1][1], max(out[-1][2], e))
        else:
            out.append((b, a, e))
    arr = np.array([[a, e] for _, a, e in out]).reshape(-1, 2)
    return arr, np.array([b for b, _, _ in out], dtype=int)
