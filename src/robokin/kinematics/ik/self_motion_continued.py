r"""The continued self-motion family: any 7R arm, a joint held by the general 6R solver.

An arm without a held-joint closed form (no meeting triple left with the parameter
joint held: an iiwa with a shoulder offset, a general 7R DH arm) is solved at a
held value by the general held-joint 6R solver (``solve_fixed``; for the first or
last joint one reduced chain serves every value, so a sweep is one batched
compiled call). Its rows at different values are not in any fixed order; this
module continues them into branches (issue 29):

1. **Nodes.** The pose is solved at ``nodes`` values of the parameter t = q_k (one
   batch), and every row gets its slope dq/dt: the other six joints' Jacobian
   columns solve -J_k (the pose stays fixed along the manifold), as
   ``held_manifold.c``'s ``hm_slopes`` does for the closed form.
2. **Pairing by the predictor.** Rows a at t_i and b at t_{i+1} of one branch
   satisfy the trapezoid rule ``q_b - q_a = h (dq_a + dq_b) / 2`` to O(h^3); rows of
   different branches do not. A cell where some row has no unambiguous partner
   (residual above ``_PAIR``, or a second candidate within 4 times the best) is
   halved (its midpoint solved, one batch per round) up to ``_REFINE`` times:
   only cells next to a fold (where two branches meet and the slopes blow up);
   one still unpaired with as many rows at both nodes (no fold: a fast passage,
   e.g. the offset iiwa swinging q1 and q3 next to q2 = 0) up to ``_REFINE_FAST``
   times more.
   Mutual best partners (residual below ``_LINK``) are linked into tracks: the
   branch slots, each the same branch at every t.
3. **Rows at any t.** ``rows(t)`` solves the pose at t (one batch) and gives each
   track the solved row nearest its cubic Hermite prediction from the
   neighbouring nodes (mutual nearest, within ``_ASSIGN``; next to a fold a
   square-root model): every returned row is a general-6R solution (Newton-polished
   to rounding where it was above 1e-14), its slot the continued branch.
   ``sample_rows(t)`` (``SelfMotion.sample`` and ``inside``) follows instead where
   it is certified: in a cell with no fold (the branch count is the manifold's),
   each track's prediction Newton-polished on the held 6 x 6, kept when the steps
   contract quadratically and the rows are distinct, each its prediction's mutual
   nearest; any other value is solved as in ``rows`` (issue 29, round 7). On a
   ``degenerate`` manifold only cells whose tracks are regular (the held 6 x 6's
   smallest singular value at least ``_REGULAR`` at the node rows and the followed
   rows) are followed: a near-continuum's rows are solved (round 7c). Rows of both
   within 1e-9 of a limit get the held family's refining step (``LimitPolish``):
   a membership decided within rounding of the slack (issue 29, session 11).
4. **Limits on the branch.** Per track, cell and joint, the cubic Hermite model
   sampled at ``_SUB`` sub-values brackets each crossing of a limit (and of an
   aligned-axes value); each is refined by Newton steps on the six other joints
   with t free and the joint held at the limit (the pose exact to 1e-13, the joint
   exactly at its limit), kept when it stays on its track.
5. **Folds.** A track that starts or ends inside the range ends at a fold, where
   the branch turns back in t; in its fastest joint m it is smooth, so the fold
   is the zero of dt/dq_m (from the null vector of the 6 x 7 Jacobian), found by
   secant steps on the curve held at q_m (:func:`_fold_newton`); a fold those
   steps do not certify is bisected on the track's existence, and a track whose
   end row is singular (no slope) ends at that node.
6. **Bounded work.** At most ``_MAX_NODES`` nodes and the ``_MAX_TRACKS`` longest
   tracks; a pose where fewer than half of the first cells pair (every row
   singular: the arm at its reach boundary for every t) is ``degenerate``: no
   halving, folds at the tracks' last nodes.
7. **Rows the solver loses.** Next to a near-continuum (the elbow stretched) the
   general 6R solver loses some regular rows at some values, and their branches'
   tracks fall into pieces. On a ``degenerate`` manifold, and on one whose linked
   tracks exceed ``_MAX_TRACKS``, each regular node row is continued to the
   neighbouring nodes (:meth:`~_ContinuedFamily._filled`) and ``rows(t)`` continues
   a regular track whose row at t is missing or singular
   (:meth:`~_ContinuedFamily._gaps`); every added row is an exact solution
   (session 18).

The intervals are then cut at the crossings and folds and decided at the pieces'
midpoints (``self_motion_intervals._intervals``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robokin._native import kernels as _K
from robokin.kinematics.arm import Arm
from robokin.kinematics.ik.fixed import Dispatch, EndSweep, _all_last, solve_fixed
from robokin.kinematics.ik.self_motion_base import (
    FINE_T,
    _Family,
    _into_limits,
    _shrunk,
)
from robokin.kinematics.ik.self_motion_polish import REGULAR_FLOOR, LimitPolish
from robokin.kinematics.jacobian import jacobian_and_pose
from robokin.spatial import pose_error

#: Parameter values solved first (over the joint's range).
NODES = 181
#: Halvings of a cell whose rows do not pair unambiguously.
_REFINE = 6
#: Further halvings of a fast passage: a cell still unpaired after ``_REFINE`` with
#: as many rows at both nodes (no fold: a branch swinging through a near-alignment,
#: e.g. the offset iiwa near q2 = 0, q1 and q3 turning ~5 rad within 1e-4 of t).
_REFINE_FAST = 10
#: Trapezoid residual [rad] of an unambiguous pair.
_PAIR = 1e-2
#: Trapezoid residual [rad] of a pair linked after the halvings.
_LINK = 0.2
#: Largest distance [rad] of a solved row from a track's prediction in ``rows``.
_ASSIGN = 0.3
#: Sub-values per cell at which the Hermite model is checked for limit crossings.
_SUB = 8
#: Newton steps of a crossing (quadratic: 4-6 are used).
_NEWTON = 12
#: Pose error (position [m], rotation [rad]) a crossing's configuration reaches.
_EXACT = 1e-13
#: Largest distance [rad] of a refined crossing from its track's prediction.
_ON_TRACK = 1e-2
_TWO_PI = 2 * np.pi
#: Most nodes after the halvings (a degenerate pose would double them every round).
_MAX_NODES = 3 * NODES
#: Below this fraction of cells paired at the first nodes a pose is degenerate.
_DEGENERATE = 0.5
#: Most tracks kept (the longest; a degenerate pose's rows do not pair).
_MAX_TRACKS = 64
#: A joint's extremum on a track's Hermite model this close to a limit [rad] is refined
#: on the branch's rows (``_grazes``: a graze, tangent to the limit, changes no sign; the
#: model is within ~1e-6 of the rows on ordinary cells; 1e-3 cost uniform poses +3 %).
_GRAZE = 1e-4
#: A graze candidate's joint slower than this [rad per rad of t] at both nodes of a piece
#: whose node rows are both singular (a continuum's track: the joint held at a limit) is
#: not searched (``_grazes``; session 18).
_FLAT = 1e-6
#: Golden-section steps of a graze's extremum (a quarter cell, ~8e-3, to ~1e-8: the
#: excess there within ~1e-16 q'' of the extremum's).
_GOLDEN = 40
#: A crossing whose joint moves slower than this along the branch [rad per rad of t]
#: is shallow: the branch stays within MANIFOLD_SLACK of the limit past ~1e-9 of it,
#: so its in-slack stretch is widened (``_points_refined``'s touches).
_SHALLOW = 1e-3
#: A joint whose Hermite model comes this close to a limit [rad] on a piece is checked
#: on the branch's rows there (``_riding``: the model's error exceeds a riding joint's
#: excess).
_RIDE = 1e-5
#: A joint this close to a limit [rad] at another joint's crossing makes it a touch.
_AT_LIMIT = 1e-9
#: A node with a non-real root pair this close to the axis [rad of the split joint's
#: angle] has both its cells probed for an island (``_islands``; 0.84 such nodes per
#: uniform random 7R pose).
_TINY = 2e-2
#: Largest real-part distance [rad] of one root pair at neighbouring nodes.
_MATCH = 0.3
#: Values at which an island's track's rows are scanned for crossings.
_ISLAND_SCAN = 33
#: The membership slack (``self_motion_intervals.MANIFOLD_SLACK``, the kernels' 1e-12).
_SLACK: float = _K.MANIFOLD_SLACK
#: Bisection steps of a fold (a cell to two adjacent doubles).
_BISECT = 60
#: A crossing's bracket whose ends' rows are both this close to the value [rad] is
#: done (:func:`_shrunk`): the rows' rounding next to a singularity (~1e-13), a tenth of
#: the membership slack; its middle is the crossing, as the kernels' (within 1e-12).
_ROW_NOISE = 1e-13
#: Followed rows (``sample_rows``): each Newton step at most ``_CONTRACT`` times the
#: previous one squared while that is above ``_FLOOR``, the first at most
#: 1 / (4 ``_CONTRACT``) [rad]; rows pairwise more than ``_DISTINCT`` apart.
_CONTRACT = 100.0
_FLOOR = 1e-9
_DISTINCT = 1e-6
#: Smallest singular value of the held 6 x 6 of a degenerate manifold's followed rows
#: and of its tracks' node rows in a followed cell (the kernel's ``singular`` flag's).
_REGULAR = 1e-6
#: A continued row (``_filled``) this close [rad] to a node's row is that row.
_SAME_ROW = 1e-7
#: Sub-steps of ``_filled``'s continuation from one node to the next.
_FILL_SUB = 4


class _ContinuedFamily(_Family):
    """Any 7R arm, joint ``j`` held by the general held-joint 6R solver, continued.

    Attributes:
        t_nodes: (m,) the solved parameter values, sorted.
        tracks: (m, k, n) each branch's row at the nodes (NaN where it has none).
        slopes: (m, k, n) their slopes dq/dt.
        solves: Parameter values solved by the general 6R solver so far.
        held_method: What solves the pose with the joint held (``"general 6R"``,
            or ``solve_fixed``'s method without its ``" (name held)"``: a closed
            form such as ``"analytic:three_parallel"`` on a robot on a track, or
            ``"numeric"`` where the held chain has neither, e.g. two prismatic
            joints: then the rows are samples and branches can be missed).
        degenerate: Most cells of the first nodes did not pair (every row
            singular): no halving, folds at the tracks' last nodes.
        dropped: Linked tracks left out beyond the ``_MAX_TRACKS`` longest (0 but on
            poses whose rows pair into many short pieces: branches may be missing).
        filled: Node rows the continuation of lost rows added (:meth:`_filled`: on a
            degenerate manifold, or one whose tracks were more than ``_MAX_TRACKS``).
        regular_nodes: (m, k) bool, the node rows with a slope (where :meth:`_filled`
            ran, also regular: :func:`_regular`): rows are continued between two of
            them (:meth:`_gaps`), and on a degenerate manifold only they start
            ``_node_fills``' runs.
    """

    robot: Arm
    dispatch: Dispatch
    T: np.ndarray
    joint: int
    held_method: str
    dropped: int
    filled: int
    regular_nodes: np.ndarray

    def __init__(self, robot: Arm, j: int, T: np.ndarray, dispatch: Dispatch,
                 nodes: int = NODES) -> None:
        self.robot = robot
        self.dispatch = dispatch
        self.joint = j
        self.name = robot.joint_names[j]
        self.domain = (float(robot.limits[j, 0]), float(robot.limits[j, 1]))
        self.T = np.ascontiguousarray(T, dtype=np.float64)
        #: rows within 1e-9 of a limit refined on the pose (:meth:`_refined`)
        self.polisher = LimitPolish(robot, j, self.T, REGULAR_FLOOR)  # (no singular flags)
        self.solves = 0
        self.held_method = "general 6R"  # (solve_fixed's rows: their method, _solve_pairs)
        self._island_cells: list[tuple[float, float]] = []  # cells where _islands found one
        # the end joint's sweep set up once per pose (None: a middle joint, solve_fixed)
        self._sweep = EndSweep.of(robot, j, self.T)
        t = np.linspace(*self.domain, int(nodes))
        Q, pairs = self._solve_pairs(t)
        if pairs is not None:  # islands narrower than the node spacing
            t, Q = self._islands(t, Q, pairs)
        if not _finite_rows(Q).any():  # no node has a row: the manifold between two?
            t, Q = self._seeded(t, Q)
        D = _slopes(robot, Q, j)
        clean = _clean_cells(t, Q, D)
        # most cells unpaired: every row singular (the pose at the reach boundary,
        # e.g. the elbow stretched for every value): no halving, no fold search
        self.degenerate = bool(clean.mean() < _DEGENERATE) if clean.size else False
        self.filled = 0
        if self.degenerate:  # regular rows the solver missed next to the near-continuum
            Q, D = self._filled(t, Q, D)
        for rnd in range(0 if self.degenerate else _REFINE + _REFINE_FAST):
            bad = np.flatnonzero(~clean)
            if rnd >= _REFINE:  # then only the fast passages (no fold: as many rows)
                bad = bad[_same_count(Q, bad)]
            if not bad.size or len(t) + bad.size > _MAX_NODES:
                break  # clean, or a pose whose rows do not pair anywhere (degenerate)
            mid = 0.5 * (t[bad] + t[bad + 1])
            Qm = self._solve(mid)
            Dm = _slopes(robot, Qm, j)
            Q, Qm = _widen(Q, Qm)
            D, Dm = _widen(D, Dm)
            t = np.concatenate([t, mid])
            new = np.concatenate([np.zeros(len(t) - len(mid), bool), np.ones(len(mid), bool)])
            order = np.argsort(t, kind="stable")
            t, new = t[order], new[order]
            Q = np.concatenate([Q, Qm])[order]
            D = np.concatenate([D, Dm])[order]
            # only the cells next to a new node can have changed (the others were clean)
            clean = np.ones(len(t) - 1, bool)
            cells = np.flatnonzero(new[:-1] | new[1:])
            clean[cells] = _clean_cells(t, Q, D, cells)
        self.t_nodes = t
        self.tracks, self.slopes, self.dropped = _link(t, Q, D)
        if self.dropped and not self.degenerate:  # pieces: rows lost, as on a degenerate pose
            Q, D = self._filled(t, Q, D)
            if self.filled:
                self.tracks, self.slopes, self.dropped = _link(t, Q, D)
        self.k = self.tracks.shape[1]
        self._exists = np.isfinite(self.tracks).all(-1)  # (m, k)
        # the rows and their slopes (NaN slopes 0) side by side: predict's one gather
        slopes0 = np.where(np.isfinite(self.slopes), self.slopes, 0.0)
        self._XS = np.concatenate([self.tracks, slopes0], axis=-1)  # (m, k, 2n)
        m, k, n = self.tracks.shape
        slope = np.isfinite(self.slopes).all(-1) | ~self._exists  # (m, k)
        self.regular_nodes = slope & self._exists
        if self.degenerate or self.filled:  # near-continuum rows may have slopes
            self.regular_nodes &= _regular(robot, self.tracks, j)
        # per (cell, track): the fold inside the cell, its t and row (NaN: none)
        self.fold_t = np.full((m - 1, k), np.nan)
        self.fold_q = np.full((m - 1, k, n), np.nan)
        self.folds = self._folds()
        # cells where sample_rows may follow the tracks: none starts or ends in them
        # (and, on a degenerate manifold, every node row there regular)
        ends = self._exists[1:] != self._exists[:-1]
        if self.degenerate:  # followed: regular rows only
            slope &= self.regular_nodes | ~self._exists
        self._cell_ok = ~ends.any(axis=1) & (slope[1:] & slope[:-1]).all(axis=1)
        self.followed = 0

    def _seeded(self, t: np.ndarray, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Nodes t (m,) and rows Q with the numeric solver's parameter values added.

        Where no node has a row the manifold may still lie between two nodes (an
        island narrower than their spacing: the offset iiwa near its reach, seed 0
        #269, q7 in [-0.0257, -0.0085] between the nodes -0.0339 and 0). The
        numeric solver (``method="numeric"``: Levenberg-Marquardt from its seeds,
        every joint free) finds rows of the whole manifold where there are any; the
        values of the parameter joint in them become nodes, and the halvings next
        to them find the island's folds. Only on such poses (an unreachable pose
        pays the numeric solve, ~6 ms against ~43 ms for its manifold).
        """
        sols = self.dispatch(self.robot, self.T, method="numeric")
        v = np.asarray(sols.q)[np.asarray(sols.valid)][:, self.joint]
        lo, hi = self.domain
        v = np.unique(v[(v > lo) & (v < hi)])
        if not v.size:
            return t, Q
        Qv = self._solve(v)
        Q, Qv = _widen(Q, Qv)
        t2 = np.concatenate([t, v])
        order = np.argsort(t2, kind="stable")
        return t2[order], np.concatenate([Q, Qv])[order]

    def _islands(self, t: np.ndarray, Q: np.ndarray, pairs: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
        """Nodes t (m,) and rows Q with the values added where an island was found.

        An island (two branches joined by folds at both ends) narrower than the
        node spacing has no row at any node: the random 7R's uniform seed 0 #3652,
        4 rows for t in ~[-1.211, -1.200] between the nodes -1.2198 and -1.1868,
        whose rows are the 2 of other branches. Its pair of rows is born where a
        pair of complex roots of the general 6R's eliminated polynomial reaches the
        real axis (``pairs``: per node the four non-real pairs nearest it, the
        imaginary and real part of the split joint's angle [rad]). Probed (one
        batch): the midpoints of both cells of a node with a pair within ``_TINY``
        of the axis, and where a pair approaches it from node to node (matched by
        the real part, within ``_MATCH``) the value its imaginary part, linear in
        t, reaches 0 in the next cell (a pair near the axis moves ~ |t - t_0| away
        from a tangency). A probe is kept as a node only where it has more rows
        than both nodes of its cell (so poses without an island keep their nodes);
        the halvings next to it then find the island's folds (and ``_crossings``
        scans the island's tracks on their rows, :meth:`_island_crossings`).
        """
        im, re = pairs[..., 0], pairs[..., 1]  # (m, 4)
        m = len(t)
        if m < 3:
            return t, Q
        tiny = np.flatnonzero((im < _TINY).any(axis=1))
        cells = np.concatenate([tiny - 1, tiny])
        cells = np.unique(cells[(cells >= 0) & (cells < m - 1)])
        probe = [0.5 * (t[cells] + t[cells + 1]),
                 _approach(t, im, re), -_approach(-t[::-1], im[::-1], re[::-1])]
        v = np.unique(np.concatenate(probe))
        if not v.size:
            return t, Q
        Qv = self._solve(v)
        count, count_v = _finite_rows(Q).sum(axis=1), _finite_rows(Qv).sum(axis=1)
        i = np.clip(np.searchsorted(t, v) - 1, 0, m - 2)
        keep = count_v > np.maximum(count[i], count[i + 1])
        if not keep.any():
            return t, Q
        # probes closer than 1e-6 of the cell to another are one (pairs of roots give
        # the same value to rounding: cells of 1e-12 pair nothing)
        kv = np.flatnonzero(keep)
        gap_ok = np.concatenate([[True], np.diff(v[kv]) > 1e-6 * (t[1] - t[0])])
        keep[kv[~gap_ok]] = False
        self._island_cells = [(float(t[c]), float(t[c + 1])) for c in np.unique(i[keep])]
        Q, Qv = _widen(Q, Qv[keep])
        t2 = np.concatenate([t, v[keep]])
        order = np.argsort(t2, kind="stable")
        return t2[order], np.concatenate([Q, Qv])[order]

    # ------------------------------------------------------------ rows
    def _filled(self, t: np.ndarray, Q: np.ndarray, D: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
        """Node rows Q and slopes D (m, K, n) with the rows the solver lost continued.

        Next to a near-continuum (the offset iiwa with q4 = q6 = 0: the held 6 x 6's
        smallest singular value 1e-11 on the continuum's rows, 1e-4 to 1e-3 on the
        regular branches passing by) the general 6R solver misses regular rows at
        some values (an odd row count at a value: a real root lost), so those
        branches' tracks were pieces, most of them beyond the ``_MAX_TRACKS``
        longest (#6667 of the special poses: 38 of 88 in-limit regular rows in no
        interval). Run on a ``degenerate`` manifold and on one whose tracks are
        such pieces (more than ``_MAX_TRACKS``). Each regular row (:func:`_regular`,
        with a slope) is continued to both neighbouring nodes in ``_FILL_SUB`` Euler-Newton steps on the held
        6 x 6 (every step reaching the pose to ``_EXACT``); a regular result farther
        than ``_SAME_ROW`` from every row of that node is added and continued in
        turn, until no row is added. Every added row is a solution of the pose at its
        node (the tracks are linked from the rows as before); regular rows are
        isolated (at most 16 per value), so this ends.
        """
        robot, j, m = self.robot, self.joint, len(t)
        ok0 = _regular(robot, Q, j) & np.isfinite(D).all(-1)
        src_i, src_r = np.nonzero(ok0)
        for _ in range(2 * m):  # (each round adds rows; at most 16 a node)
            if not src_i.size:
                break
            si = np.concatenate([src_i, src_i])
            sr = np.concatenate([src_r, src_r])
            dst = np.concatenate([src_i + 1, src_i - 1])
            keep = (dst >= 0) & (dst < m)
            si, sr, dst = si[keep], sr[keep], dst[keep]
            q, dq = Q[si, sr], D[si, sr]
            h = (t[dst] - t[si]) / _FILL_SUB
            ok = np.ones(len(q), bool)
            for s in range(1, _FILL_SUB + 1):  # (the last at the node's own value)
                ts = t[dst] if s == _FILL_SUB else t[si] + s * h
                q, reached = _newton_held(robot, self.T, q + h[:, None] * dq, j, ts)
                dq = _slopes(robot, q, j)
                ok &= reached & np.isfinite(dq).all(-1)
                dq = np.where(ok[:, None], dq, 0.0)
            q = _into_limits(robot, q)
            if ok.any():
                ok[ok] = _regular(robot, q[ok], j)
            # not a row of its node (nor one added before it in this round)
            near = _max_last(np.abs(_wrap(Q[dst] - q[:, None])))  # (p, K)
            ok &= ~np.any(near <= _SAME_ROW, axis=1)
            add = _first_distinct(np.flatnonzero(ok), dst, q, _SAME_ROW)
            if not add.size:
                break
            # each into its node's next free slot (valid rows first)
            slot = _finite_rows(Q).sum(axis=1)[dst[add]]
            # a second row added to one node: the slot after (its rank among them)
            order = np.argsort(dst[add], kind="stable")
            ds = dst[add][order]
            first = np.searchsorted(ds, ds, side="left")
            slot[order] += np.arange(len(ds)) - first
            width = int(slot.max()) + 1
            if width > Q.shape[1]:
                pad = np.full((m, width - Q.shape[1], Q.shape[2]), np.nan)
                Q, D = np.concatenate([Q, pad], axis=1), np.concatenate([D, pad], axis=1)
            src_i, src_r = dst[add], slot
            Q[src_i, src_r] = q[add]
            D[src_i, src_r] = dq[add]
            self.filled += len(add)
        return Q, D

    def _solve(self, t: np.ndarray) -> np.ndarray:
        """Every general-6R row at held values t (m,): (m, K, n), NaN where none.

        The valid rows come first in each value's K slots; K is the most any value has.
        """
        return self._solve_pairs(t)[0]

    def _solve_pairs(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
        """:meth:`_solve`, and the kernel's near-real root pairs at each value.

        Returns:
            The rows (m, K, n) and (m, 4, 2) (``EndSweep.solve_pairs``: imaginary,
            real part [rad] of the four non-real pairs nearest the axis), or None
            where the joint is not an end joint (``solve_fixed``: no pairs).
        """
        self.solves += len(t)
        # an end joint on a general 6R reduced chain: the kernel directly (the same
        # rows as solve_fixed, without its per-call checks and assemblies)
        pairs = None
        if self._sweep is not None:
            sols, pairs = self._sweep.solve_pairs(np.ascontiguousarray(t, np.float64))
        else:
            sols = solve_fixed(self.robot, self.T, {self.name: t}, dispatch=self.dispatch)
            held = sols.method.removesuffix(f" ({self.name} held)")
            self.held_method = "general 6R" if held == "general_6r" else held
        valid = sols.valid.reshape(len(t), -1)
        q = sols.q.reshape(len(t), -1, self.robot.n)
        if (valid[:, 1:] <= valid[:, :-1]).all():  # valid rows first already (the kernel's)
            # the most rows of a value: the columns some value fills (a short-axis sum is slow)
            width = max(int(valid.any(axis=0).sum()), 1)
            q, ok = q[:, :width], valid[:, :width]
        else:
            width = max(int(valid.sum(axis=1).max(initial=0)), 1)
            order = np.argsort(~valid, axis=1, kind="stable")[:, :width]
            q = np.take_along_axis(q, order[..., None], 1)
            ok = np.take_along_axis(valid, order, 1)
        return _into_limits(self.robot, np.where(ok[..., None], q, np.nan)), pairs

    def rows(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        t = np.atleast_1d(np.asarray(t, dtype=np.float64))
        R = self._solve(t)  # (M, K, n)
        P = self.predict(t)  # (M, k, n)
        out = self._polish(_assign(P, R), t)
        if self.degenerate or self.filled:
            self._gaps(t, P, out)
        valid = _finite_rows(out)
        self._refined(out, valid)
        return out, valid, np.zeros_like(valid)

    def _gaps(self, t: np.ndarray, P: np.ndarray, out: np.ndarray) -> None:
        """Rows at t (M,) the solver lost, continued in place (where :meth:`_filled` ran).

        As at the nodes (:meth:`_filled`): a track whose rows at both nodes of t's
        cell are regular (with slopes) and whose row at t is missing or singular (a
        near-continuum row the solver gave, nearest the prediction where the
        branch's own row was lost: #6667's track at a node, 0.048 rad away) takes
        its prediction P (M, k, n) Newton-polished on the held 6 x 6, kept when it
        reaches the pose to ``_EXACT``, is regular, within ``_ASSIGN`` of the
        prediction and more than ``_DISTINCT`` from every other track's row at t
        (out (M, k, n)).
        """
        tn = self.t_nodes
        if len(tn) < 2:
            return
        i = np.minimum(np.maximum(np.searchsorted(tn, t, side="right") - 1, 0), len(tn) - 2)
        want = (self.regular_nodes[i] & self.regular_nodes[i + 1] & _finite_rows(P)
                & ((t >= tn[0]) & (t <= tn[-1]))[:, None])
        there = want & _finite_rows(out)
        if there.any():  # a singular row in a regular track's slot: continued too
            want[there] = ~_regular(self.robot, out[there], self.joint)
        mi, bi = np.nonzero(want)
        if not mi.size:
            return
        p = P[mi, bi]
        q, ok = _newton_held(self.robot, self.T, _into_limits(self.robot, p), self.joint, t[mi])
        q = _into_limits(self.robot, q)
        ok &= _max_last(np.abs(_wrap(q - p))) < _ASSIGN
        if ok.any():
            ok[ok] = _regular(self.robot, q[ok], self.joint)
        # more than _DISTINCT from every other track's row at t (its own slot's singular
        # row is replaced): checked at once where a value has one candidate, in order
        # (each against the rows placed before it) where it has more
        d = _max_last(np.abs(_wrap(out[mi] - q[:, None])))  # (p, k), NaN: no row
        d[np.arange(len(mi)), bi] = np.inf
        alone = np.bincount(mi, minlength=len(t))[mi] == 1
        one = ok & alone & ~np.any(d <= _DISTINCT, axis=1)
        for a in np.flatnonzero(ok & ~alone).tolist():
            d_a = _max_last(np.abs(_wrap(out[mi[a]] - q[a])))  # (k,)
            d_a[bi[a]] = np.inf
            if not np.any(d_a <= _DISTINCT):
                out[mi[a], bi[a]] = q[a]
        out[mi[one], bi[one]] = q[one]

    def _refined(self, Q: np.ndarray, valid: np.ndarray) -> None:
        """Rows Q (M, k, n) within 1e-9 of a limit refined in place (``LimitPolish``).

        A row reproducing the pose to ~5e-15 (``_polish``'s and ``_follow``'s
        stop) is off by that over the held 6 x 6's smallest singular value: the
        random 7R's special seed 0 #6185 (q7 at its limit with four joints at
        theirs, 1.1e-4) had its joints 9e-12 past their limits, more than
        ``MANIFOLD_SLACK``, and its range-end corner was not listed. One Newton step
        on the pose with t held, where it is short (the held family's bounds: a
        step of a singular row is not taken), brings them to ~2e-13.
        """
        self.polisher(Q, valid, np.zeros_like(valid))

    def sample_rows(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``rows(t)``, each branch followed from its nodes where that is certified.

        A value t in a cell where every track present exists at both nodes with a
        slope (no fold, no track starting or ending: the branch count is the
        manifold's) takes each track's Hermite prediction Newton-polished on the held
        6 x 6 (:meth:`_follow`); a value whose rows do not all certify, and every
        other value, is solved by ``rows`` (the general 6R solver). On a
        ``degenerate`` manifold a followed row must also be regular (:func:`_regular`;
        the cell's node rows are, by ``_cell_ok``).
        """
        t = np.atleast_1d(np.asarray(t, dtype=np.float64))
        fast = self._followable(t)
        if not fast.any():
            return self.rows(t)
        M, (_, k, n) = len(t), self.tracks.shape
        out = np.full((M, k, n), np.nan)
        idx = np.flatnonzero(fast)
        q, ok = self._follow(t[idx])
        if self.degenerate:  # a followed row next to the near-continuum: solved
            fq = _finite_rows(q)
            fine = np.ones(q.shape[:2], bool)
            fine[fq] = _regular(self.robot, q[fq], self.joint)
            ok &= fine.all(axis=1)
        out[idx[ok]] = q[ok]
        fast[idx[~ok]] = False
        self.followed += int(ok.sum())
        self._refined(out, _finite_rows(out))  # the followed rows (rows' are)
        if not fast.all():
            out[~fast] = self.rows(t[~fast])[0]
        valid = _finite_rows(out)
        return out, valid, np.zeros_like(valid)

    def _followable(self, t: np.ndarray) -> np.ndarray:
        """(M,) bool: t inside the nodes, in a cell whose every track is followable.

        Every track exists at both nodes or at neither, with finite slopes (a fold
        or a branch end in the cell, or a singular node row: not followable). On a
        ``degenerate`` manifold too (issue 29, round 7c): its regular tracks are
        followed in such cells, certified as anywhere; a near-continuum's rows are
        singular (no slope), so a cell a track of them reaches is solved.
        """
        tn = self.t_nodes
        if len(tn) < 2:
            return np.zeros(len(t), bool)
        i = np.minimum(np.maximum(np.searchsorted(tn, t, side="right") - 1, 0), len(tn) - 2)
        out: np.ndarray = self._cell_ok[i] & (t >= tn[0]) & (t <= tn[-1])
        return out

    def _follow(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Each track's row at t (M,) from its prediction: (M, k, n), (M,) certified.

        A value is certified when every track present in its cell reaches the pose
        (``_EXACT``) by Newton steps that contract quadratically (each step above
        ``_FLOOR`` at most ``_CONTRACT`` times the previous one squared, the first at
        most 1 / (4 ``_CONTRACT``): with the observed constant in Kantorovich's
        bound, h <= 1/2 and the root the only one within ~1 / (2 ``_CONTRACT``) of
        the prediction) and each row within ``_ASSIGN`` of its prediction; the rows
        pairwise more than ``_DISTINCT`` and twice the farthest row-to-prediction
        distance apart (so each track's row is the mutual nearest of its prediction
        among the value's rows: ``_assign``'s rule).
        """
        P = self.predict(t)  # (M, k, n)
        M, k, n = P.shape
        fp = _finite_rows(P)
        mi, bi = np.nonzero(fp)
        ok = np.ones(M, bool)
        out = np.full((M, k, n), np.nan)
        if not mi.size:
            return out, ok
        rev = np.asarray(self.robot.is_revolute, bool)  # a track's metres never wrap
        q0 = _into_limits(self.robot, np.where(rev, _wrap(P[mi, bi]), P[mi, bi]))
        steps = np.zeros((len(mi), _NEWTON))
        q, reached = _newton_held(self.robot, self.T, q0, self.joint, t[mi], steps)
        prev, nxt = steps[:, :-1], steps[:, 1:]
        quad = (_CONTRACT * steps[:, 0] <= 0.25) & np.all(
            (prev <= _FLOOR) | (nxt <= _CONTRACT * prev * prev), axis=1)
        row_ok = reached & quad & (steps[:, -1] == 0)  # converged before the last step
        ok[mi[~row_ok]] = False
        out[mi, bi] = q
        # each row the mutual nearest of its own prediction (_assign's rule): implied
        # (triangle inequality of the wrapped max distance) when every two rows of
        # the value are more than twice the farthest row-to-prediction apart
        moved = _max_last(np.abs(_wrap(q - P[mi, bi])))  # (p,)
        ok[mi[~(moved < _ASSIGN)]] = False
        apart = np.zeros(M)
        np.maximum.at(apart, mi, 2 * moved)
        np.maximum(apart, _DISTINCT, out=apart)
        # the value's present tracks packed into its first slots (a few of k)
        start = np.concatenate([[0], np.cumsum(fp.sum(axis=1))[:-1]])
        slot = np.arange(len(mi)) - start[mi]
        w = int(slot.max()) + 1
        if w > 1:
            Qw = np.zeros((M, w, n))
            Qw[mi, slot] = q
            there = np.zeros((M, w), bool)
            there[mi, slot] = True
            sep = _max_last(np.abs(_wrap(Qw[:, :, None] - Qw[:, None])))  # (M, w, w)
            sep[:, np.arange(w), np.arange(w)] = np.inf
            pair = there[:, :, None] & there[:, None, :]
            ok &= np.all((sep > apart[:, None, None]) | ~pair, axis=(1, 2))
        return out, ok

    def _polish(self, Q: np.ndarray, t: np.ndarray) -> np.ndarray:
        """Rows Q (M, k, n) at t (M,) polished by Newton steps on the six free joints.

        The general-6R rows reproduce the pose to ~1e-13; a step where they are above
        1e-14 brings them to rounding (kept only where it reaches ``_EXACT``), so
        rows at a limit crossing's t have the joint at its limit to ~1e-14.
        """
        M, k, n = Q.shape
        ok = _finite_rows(Q)
        if not ok.any():
            return Q
        mi, bi = np.nonzero(ok)
        q, good = _newton_held(self.robot, self.T, Q[mi, bi], self.joint, t[mi])
        out: np.ndarray = Q.copy()
        out[mi[good], bi[good]] = q[good]
        return out

    def predict(self, t: np.ndarray) -> np.ndarray:
        """Each track's cubic Hermite value at t (M, k, n) (NaN where it has none).

        Between two nodes where the track exists: the cubic Hermite of its rows and
        slopes; where it exists at one of them only (a fold in the cell): the
        tangent line from that one.
        """
        tn, X, E = self.t_nodes, self.tracks, self._exists
        M, (_, k, n) = len(t), X.shape
        out = np.full((M, k, n), np.nan)
        # (np.clip's wrapper costs more than the search)
        i = np.minimum(np.maximum(np.searchsorted(tn, t, side="right") - 1, 0), len(tn) - 2)
        fa, fb = E[i], E[i + 1]  # (M, k)
        mi, bi = np.nonzero(fa | fb)  # only the tracks present in the cell
        if not mi.size:
            return out
        c = i[mi]
        fa, fb = fa[mi, bi][:, None], fb[mi, bi][:, None]
        h = (tn[c + 1] - tn[c])[:, None]
        u = ((t[mi] - tn[c]) / (tn[c + 1] - tn[c]))[:, None]
        # each node's row and slope in one gather
        ga, gb = self._XS[c, bi], self._XS[c + 1, bi]  # (p, 2n)
        xa, xb, sa, sb = ga[:, :n], gb[:, :n], ga[:, n:], gb[:, n:]
        a = np.where(fa, xa, 0.0)
        b = np.where(fb, xb, 0.0)
        b = a + _wrap(b - a)
        u2, u3 = u * u, u * u * u
        herm = ((2 * u3 - 3 * u2 + 1) * a + (u3 - 2 * u2 + u) * h * sa
                + (-2 * u3 + 3 * u2) * b + (u3 - u2) * h * sb)
        one = np.where(fa, a + u * h * sa, xb + (u - 1) * h * sb)
        # a fold in the cell: q = q_f + (q_node - q_f) sqrt((t - t_f) / (t_node - t_f))
        tf, qf = self.fold_t[c, bi], self.fold_q[c, bi]
        fold = np.isfinite(tf)
        if fold.any():
            tnode = np.where(fa[:, 0], tn[c], tn[c + 1])
            qnode = np.where(fa, xa, xb)
            with np.errstate(invalid="ignore", divide="ignore"):
                r = np.where(fold, (t[mi] - tf) / (tnode - tf), 0.0)
                root = qf + _wrap(qnode - qf) * np.sqrt(np.maximum(r, 0.0))[:, None]
            one = np.where(fold[:, None], np.where((r >= 0)[:, None], root, np.nan), one)
        out[mi, bi] = np.where(fa & fb, herm, one)
        return out

    def param_of(self, q: np.ndarray) -> float:
        return float(q[self.joint])

    # ------------------------------------------------------------ exact points
    def marks(self, limits: np.ndarray, aligned: list[tuple[int, float]]
              ) -> dict[str, list[Any]]:
        """Limit crossings, aligned-axes points, folds and touches of every track.

        Returns the dict ``self_motion_intervals._intervals`` takes: ``"limit"``
        ``[(t, branch, joint, "lower"/"upper")]``, ``"aligned"`` ``[(t, branch,
        "aligned axes")]``, ``"fold"`` ``[(t, branch, "fold")]``; and ``"touch"``
        ``[(t, branch, joint)]``: where a branch stays within ``MANIFOLD_SLACK`` of a
        limit beyond rounding (its grazes and shallow crossings, :meth:`_grazes`),
        for ``_points_refined`` to widen to their in-slack stretch.
        """
        rev = np.asarray(self.robot.is_revolute, bool)
        queries: list[tuple[int, float, str]] = []
        for j in range(self.robot.n):
            lo, hi = (float(x) for x in limits[j])
            if j == self.joint or (rev[j] and hi - lo >= 2 * np.pi):
                continue
            queries += [(j, lo, "lower"), (j, hi, "upper")]
        queries += [(j, v, "aligned axes") for j, v in aligned if j != self.joint]
        found, shallow = self._crossings(queries)
        touch, more = self._grazes(queries, found)
        found += more
        out: dict[str, list[Any]] = {"limit": [], "fold": [], "aligned": [], "touch": touch}
        for t, b, qi in found:
            j, _, kind = queries[qi]
            if kind == "aligned axes":
                out["aligned"].append((t, b, kind))
            else:
                out["limit"].append((t, b, j, kind))
        out["touch"] += [(t, b, queries[qi][0]) for (t, b, qi), s in
                         zip(found, shallow, strict=False) if s and queries[qi][2] != "aligned axes"]
        out["fold"] = [(t, b, "fold") for t, b in self.folds]
        return out

    def _crossings(self, queries: list[tuple[int, float, str]]
                   ) -> tuple[list[tuple[float, int, int]], list[bool]]:
        """(t, track, query index) where a track's joint equals a query's value.

        With a flag per crossing of the regular pieces (the fold cells' come last,
        unflagged): True where the joint moves slower than ``_SHALLOW`` along the
        branch there (or its slope is not defined): a shallow crossing.
        """
        if not queries:
            return [], []
        tn, X, S = self.t_nodes, self.tracks, self.slopes
        both = np.isfinite(X[:-1]).all(-1) & np.isfinite(X[1:]).all(-1)  # (m-1, k)
        cc, bb = np.nonzero(both)  # the (cell, track) pieces with both ends
        u = np.linspace(0.0, 1.0, _SUB + 1)[None, :, None]
        h = (tn[cc + 1] - tn[cc])[:, None, None]
        qa, sa = X[cc, bb][:, None], S[cc, bb][:, None]
        qb = qa + _wrap(X[cc + 1, bb][:, None] - qa)
        sb = S[cc + 1, bb][:, None]
        u2, u3 = u * u, u * u * u
        P = ((2 * u3 - 3 * u2 + 1) * qa + (u3 - 2 * u2 + u) * h * sa
             + (-2 * u3 + 3 * u2) * qb + (u3 - u2) * h * sb)  # (pieces, SUB + 1, n)
        tt = tn[cc][:, None] + h[:, :, 0] * u[0, :, 0][None]  # (pieces, SUB + 1)
        starts, brackets, tracks, qidx, joints, values = [], [], [], [], [], []
        riding: list[tuple[np.ndarray, int]] = []  # (pieces, query) the model puts at v
        for qi, (j, v, kind) in enumerate(queries):
            g = _wrap(P[..., j] - v)  # (pieces, SUB + 1)
            if kind != "aligned axes":
                ride = np.flatnonzero((np.abs(g) < _RIDE).any(axis=1))
                if ride.size:
                    riding.append((ride, qi))
            change = (np.sign(g[:, :-1]) != np.sign(g[:, 1:])) & (
                np.abs(g[:, :-1] - g[:, 1:]) < np.pi)
            c, sidx = np.nonzero(change)
            if not c.size:
                continue
            g0, g1 = g[c, sidx], g[c, sidx + 1]
            w = np.where(g0 != g1, g0 / np.where(g0 != g1, g0 - g1, 1.0), 0.0)
            starts.append(tt[c, sidx] + w * (tt[c, sidx + 1] - tt[c, sidx]))
            brackets.append(np.stack([tt[c, sidx], tt[c, sidx + 1], tt[c, 0], tt[c, -1]],
                                     axis=1))
            tracks.append(bb[c])
            qidx.append(np.full(c.size, qi))
            joints.append(np.full(c.size, j))
            values.append(np.full(c.size, v))
        # a joint riding its limit (within _RIDE over a piece): the model's signs are
        # not the rows' (its error is ~1e-9 and more), so the rows' own sign changes
        # at the sub-values are bisected (issue 29, session 9)
        if riding:
            rb = self._riding(riding, tt, bb, queries)
            if rb.size:
                starts.append(0.5 * (rb[:, 0] + rb[:, 1]))
                brackets.append(rb[:, :4])
                tracks.append(rb[:, 4].astype(int))
                qi_r = rb[:, 5].astype(int)
                qidx.append(qi_r)
                joints.append(np.array([queries[k][0] for k in qi_r]))
                values.append(np.array([queries[k][1] for k in qi_r]))
                force = np.concatenate([np.zeros(sum(len(x) for x in starts[:-1]), bool),
                                        np.ones(len(rb), bool)])
        if not starts:
            return [], []
        t0, b = np.concatenate(starts), np.concatenate(tracks)
        q0 = self.predict(t0)[np.arange(len(t0)), b]
        q, ok = _newton_held(self.robot, self.T, q0, np.concatenate(joints),
                             np.concatenate(values))
        t1 = q[:, self.joint]
        lo, hi = self.domain
        ok &= (t1 >= lo) & (t1 <= hi)
        pred = self.predict(np.where(ok, t1, t0))[np.arange(len(t0)), b]
        ok &= np.abs(_wrap(pred - q)).max(-1) < _ON_TRACK
        # Newton with t free failed, or went to another root (its 6 x 6 nearly
        # singular where the joint moves ~1e-6 as fast as t): bisected on the rows
        br = np.concatenate(brackets)
        w = br[:, 1] - br[:, 0]
        lost = ~ok | (t1 < br[:, 0] - w) | (t1 > br[:, 1] + w)
        jv, vv, qv = np.concatenate(joints), np.concatenate(values), np.concatenate(qidx)
        # the joint's speed along the branch at each Newton crossing (the exact dq/dt)
        speed = np.full(len(t1), np.nan)
        speed[ok] = np.abs(_slopes(self.robot, q[ok], self.joint)[np.arange(ok.sum()), jv[ok]])
        if riding and rb.size:
            # the rows' bracket: bisected, unless Newton found a fast (transversal)
            # crossing of the same track and value in it: an ordinary crossing next
            # to a sub-value, where the model comes within _RIDE of the value (18
            # of 100 uniform random 7R poses bisected one such, found again to 1e-14)
            for i in np.flatnonzero(force):
                hit = ok & (b == b[i]) & (qv == qv[i]) & (t1 >= br[i, 0]) & (
                    t1 <= br[i, 1]) & (speed >= _SHALLOW)
                lost[i] = not hit.any()
        for i in np.flatnonzero(lost & ~force if riding and rb.size else lost):
            # a Newton crossing of the same track and value in the cell: done
            hit = ok & (b == b[i]) & (qv == qv[i]) & (t1 >= br[i, 2]) & (t1 <= br[i, 3])
            lost[i] = not hit.any()
        if lost.any():
            tb, qb, okb = self._bisected(br[lost], b[lost], jv[lost], vv[lost])
            jb = jv[lost][okb]
            sb = np.abs(_slopes(self.robot, qb[okb], self.joint)[np.arange(len(jb)), jb])
            t1, q = np.concatenate([t1, tb[okb]]), np.concatenate([q, qb[okb]])
            b, ok = np.concatenate([b, b[lost][okb]]), np.concatenate([ok, okb[okb]])
            jv, qv = np.concatenate([jv, jb]), np.concatenate([qv, qv[lost][okb]])
            speed = np.concatenate([speed, sb])
        if self._island_cells:
            ti, qi_, bi, ji, qvi = self._island_crossings(queries, t1[ok], b[ok], qv[ok])
            if len(ti):
                si = np.full(len(ti), np.inf)  # a lost row: not shallow (no touch)
                fr = _finite_rows(qi_)
                si[fr] = np.abs(_slopes(self.robot, qi_[fr], self.joint)[np.arange(fr.sum()),
                                                                           ji[fr]])
                t1, q = np.concatenate([t1, ti]), np.concatenate([q, qi_])
                b, ok = np.concatenate([b, bi]), np.concatenate([ok, np.ones(len(ti), bool)])
                jv, qv = np.concatenate([jv, ji]), np.concatenate([qv, qvi])
                speed = np.concatenate([speed, si])
        jx = jv[ok]
        flat = ~(speed[ok] >= _SHALLOW)  # NaN (a singular row): shallow too
        # another joint at a limit there too (riding it within the slack, e.g. the
        # offset iiwa #5805: q4 out by 1e-15 over 1e-4 while q5 crosses): a touch
        lim = self.robot.limits
        rq = q[ok]
        with np.errstate(invalid="ignore"):
            at = np.minimum(np.abs(rq - lim[:, 0]), np.abs(rq - lim[:, 1])) <= _AT_LIMIT
        at[np.arange(len(jx)), jx] = False
        at[:, self.joint] = False
        flat |= at.any(axis=1)
        out: list[tuple[float, int, int]] = []
        flags: list[bool] = []
        for t, bb, qi, f in zip(t1[ok].tolist(), b[ok].tolist(), qv[ok].tolist(),
                                flat.tolist(), strict=True):
            if not any(bb == b2 and qi == q2 and abs(t - t2) < 1e-9 for t2, b2, q2 in out):
                out.append((t, bb, qi))
                flags.append(f)
        for t, fb, qi in self._fold_crossings(queries):
            if not any(fb == b2 and qi == q2 and abs(t - t2) < 1e-9 for t2, b2, q2 in out):
                out.append((t, fb, qi))
                flags.append(False)
        return out, flags

    def _island_crossings(self, queries: list[tuple[int, float, str]], tf: np.ndarray,
                          bf: np.ndarray, qf: np.ndarray
                          ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Crossings of the island tracks that the model's scan did not list.

        An island's tracks (existing only inside a cell where ``_islands`` found
        one) have few nodes and may pass near a singular configuration, where the
        held Newton with t free drifts along a near-continuum (offset iiwa special
        #5140: q2, q4 ~ 0, the crossing of q1 through its limit lost and the island
        interval 0.17 rad out). Their rows (``sample_rows``) at ``_ISLAND_SCAN``
        values over each track's range: a sign change of q_j - v between two values
        with no crossing of that track and query listed between them (``tf``, ``bf``,
        ``qf``: the listed ones' t, track and query) is bisected on the rows.

        Returns (t (p,), rows (p, n), track (p,), joint (p,), query (p,)); rows NaN
        where the bisection lost the track's rows (then t is its last bracket's middle).
        """
        tn, ex = self.t_nodes, self._exists
        isl = []
        for b in range(self.k):
            tb = tn[ex[:, b]]
            if tb.size and any(a <= tb[0] and tb[-1] <= e for a, e in self._island_cells):
                isl.append((b, tb[0], tb[-1]))
        lims = [(qi, j, v) for qi, (j, v, kind) in enumerate(queries) if kind != "aligned axes"]
        empty = (np.zeros(0), np.zeros((0, self.robot.n)), np.zeros(0, int), np.zeros(0, int),
                 np.zeros(0, int))
        if not isl or not lims:
            return empty
        ts = np.concatenate([np.linspace(a, e, _ISLAND_SCAN) for _, a, e in isl])
        rows, valid, _ = self.sample_rows(ts)
        lo_l, hi_l, fl_l, fh_l, b_l, j_l, v_l, q_l = [], [], [], [], [], [], [], []
        for n_i, (b, _, _) in enumerate(isl):
            sl = slice(n_i * _ISLAND_SCAN, (n_i + 1) * _ISLAND_SCAN)
            tt, r, ok = ts[sl], rows[sl, b], valid[sl, b]
            for qi, j, v in lims:
                with np.errstate(invalid="ignore"):
                    g = np.where(ok, _wrap(r[:, j] - v), np.nan)
                sg = np.sign(g)
                ch = np.flatnonzero((sg[:-1] * sg[1:] < 0) & (np.abs(g[:-1] - g[1:]) < np.pi))
                for c in ch:
                    listed = (bf == b) & (qf == qi) & (tf >= tt[c] - 1e-9) & (tf <= tt[c + 1] + 1e-9)
                    if listed.any():
                        continue
                    lo_l.append(tt[c])
                    hi_l.append(tt[c + 1])
                    fl_l.append(g[c])
                    fh_l.append(g[c + 1])
                    b_l.append(b)
                    j_l.append(j)
                    v_l.append(v)
                    q_l.append(qi)
        if not lo_l:
            return empty
        lo, hi = np.array(lo_l), np.array(hi_l)
        t, r, found = self._bisect_rows(lo, hi, np.array(fl_l), np.array(fh_l), np.array(b_l),
                                        np.array(j_l), np.array(v_l))
        # a bisection whose rows end (the track through a singular point, #5140's q1
        # at its limit where tracks 12 and 13 meet): cut at its last bracket's middle
        # (rows NaN), the pieces either side decided on their rows
        t = np.where(found, t, 0.5 * (lo + hi))
        return t, r, np.array(b_l), np.array(j_l), np.array(q_l)

    def _riding(self, riding: list[tuple[np.ndarray, int]], tt: np.ndarray, bb: np.ndarray,
                queries: list[tuple[int, float, str]]) -> np.ndarray:
        """Brackets (p, 6) ``[a, e, a, e, track, query]`` of the rows' sign changes.

        ``riding``: per query, the pieces (indices into ``tt`` (pieces, SUB + 1), the
        sub-values, and ``bb``, their tracks) where the model is within ``_RIDE`` of
        the query's value. The branch's rows at the sub-values (``sample_rows``, each
        value once); each change of sign of q_j - v between neighbours, one of them
        past the slack, is a bracket.
        """
        pieces = np.concatenate([r for r, _ in riding])
        qis = np.concatenate([np.full(len(r), qi) for r, qi in riding])
        ts = tt[pieces]  # (p, SUB + 1)
        # pieces of one cell (other tracks, joints, limits) share their sub-values
        uniq, inv = np.unique(ts.ravel(), return_inverse=True)
        qu, vu, _ = self.sample_rows(uniq)
        m = ts.shape[1]
        b = bb[pieces]
        j = np.array([queries[k][0] for k in qis])
        v = np.array([queries[k][1] for k in qis])
        inv = inv.reshape(ts.shape)
        bm, jm = np.repeat(b, m).reshape(ts.shape), np.repeat(j, m).reshape(ts.shape)
        with np.errstate(invalid="ignore"):
            g = np.where(vu[inv, bm], _wrap(qu[inv, bm, jm] - v[:, None]), np.nan)
        # a change between two rows within the slack of the value is rounding (a joint
        # riding its limit flips sign at 1e-16): the pieces decide it with the slack
        big = np.maximum(np.abs(g[:, :-1]), np.abs(g[:, 1:])) > _SLACK
        i, k = np.nonzero((g[:, :-1] * g[:, 1:] < 0) & big)
        return np.stack([ts[i, k], ts[i, k + 1], ts[i, k], ts[i, k + 1],
                         b[i].astype(float), qis[i].astype(float)], axis=1)

    def _bisected(self, br: np.ndarray, b: np.ndarray, j: np.ndarray, v: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Crossings of joint j[i] through v[i] on track b[i] in brackets br (p, 4).

        ``br``: the model's sub-cell ``[a, e]``, then its cell ``[a, e]`` (taken where
        the branch's rows at the sub-cell's ends do not straddle the value: the
        model's sign change is not the rows', e.g. a fast passage in the cell).
        The sign change of q_j - v on the branch's rows (``sample_rows``, the held
        6 x 6 with t held: regular where the one with the joint held is not), shrunk
        to adjacent doubles (:meth:`_bisect_rows`). Returns ``(t, rows, found)``: found
        where the rows at the bracket's ends exist and straddle the value.
        """
        p = len(b)
        ends = br.T.ravel()  # (4 p,): the sub-cells' ends, then the cells'
        b4, j4, v4 = np.tile(b, 4), np.tile(j, 4), np.tile(v, 4)
        q, valid, _ = self.sample_rows(ends)
        r = q[np.arange(4 * p), b4]
        with np.errstate(invalid="ignore"):
            g4 = _wrap(r[np.arange(4 * p), j4] - v4)
        g4 = np.where(valid[np.arange(4 * p), b4], g4, np.nan).reshape(4, p)
        s4 = np.sign(g4)
        sub = s4[0] * s4[1] < 0
        found = sub | (s4[2] * s4[3] < 0)
        t_out = np.full(p, np.nan)
        rows_out = np.full((p, self.robot.n), np.nan)
        if not found.any():
            return t_out, rows_out, found
        keep = np.flatnonzero(found)  # only the straddling brackets are bisected
        t_k, r_k, f_k = self._bisect_rows(np.where(sub, br[:, 0], br[:, 2])[keep],
                                          np.where(sub, br[:, 1], br[:, 3])[keep],
                                          np.where(sub, g4[0], g4[2])[keep],
                                          np.where(sub, g4[1], g4[3])[keep],
                                          b[keep], j[keep], v[keep])
        t_out[keep], rows_out[keep] = t_k, r_k
        found[keep] = f_k
        return t_out, rows_out, found

    def _bisect_rows(self, lo: np.ndarray, hi: np.ndarray, f_lo: np.ndarray, f_hi: np.ndarray,
                     b: np.ndarray, j: np.ndarray, v: np.ndarray
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`_bisected`'s straddling brackets [lo, hi] shrunk to adjacent doubles.

        f_lo, f_hi: q_j - v (wrapped) of the branch's rows at the ends, of opposite
        signs. :func:`_shrunk` on the branch's rows (``sample_rows``), to adjacent
        doubles, ``FINE_T`` wide, or ends both within ``_ROW_NOISE`` of the value; a bracket whose
        rows end (no row assigned at a step's value) is given up.
        """
        p = len(b)

        def side(t: np.ndarray, a: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            """(q_j - v, on the low end's side, a row there) of brackets a at t (len(a),)."""
            q, valid, _ = self.sample_rows(t)
            i = np.arange(len(a))
            with np.errstate(invalid="ignore"):
                f = np.where(valid[i, b[a]], _wrap(q[i, b[a], j[a]] - v[a]), np.nan)
            return f, np.sign(f) == np.sign(f_lo[a]), np.isfinite(f)

        lo, hi, found = _shrunk(side, lo, hi, f_lo, f_hi, 4 * _BISECT, _ROW_NOISE, FINE_T)
        t = np.where(found, 0.5 * (lo + hi), np.nan)
        rows = np.full((p, self.robot.n), np.nan)
        a = np.flatnonzero(found)
        if a.size:
            q, _, _ = self.sample_rows(t[a])
            rows[a] = q[np.arange(len(a)), b[a]]
        found &= _finite_rows(rows)
        return t, rows, found

    def _fold_crossings(self, queries: list[tuple[int, float, str]]
                        ) -> list[tuple[float, int, int]]:
        """(t, track, query index) in the cells where a track ends at a fold.

        ``_crossings``' Hermite pieces need the track at both nodes; between a fold
        t_f and the track's node t_n the branch moves like sqrt(|t - t_f|) (issue 29,
        round 7e). There it is scanned in s = sqrt((t - t_f) / (t_n - t_f)) in [0, 1]
        on the quadratic q(s) = q_f + c1 s + c2 s^2 through the fold's row, the
        node's row and the node's slope (dq/ds = 2 (t_n - t_f) dq/dt at s = 1); a
        sign change of q_j - value is refined by :func:`_newton_held` (t free) and
        kept where t lies between t_f and t_n and the row is on the quadratic
        (``_ON_TRACK``) on the track's side of the fold (not its twin's).
        """
        cc, bb = np.nonzero(np.isfinite(self.fold_t))
        if not cc.size or not queries:
            return []
        tn, X, S = self.t_nodes, self.tracks, self.slopes
        at_a = np.isfinite(X[cc, bb]).all(-1)
        node = np.where(at_a, cc, cc + 1)
        tf, qf = self.fold_t[cc, bb], self.fold_q[cc, bb]
        h = tn[node] - tf  # (p,)
        qn = qf + _wrap(X[node, bb] - qf)
        sn = np.where(np.isfinite(S[node, bb]), S[node, bb], 0.0)
        c2 = 2 * h[:, None] * sn - (qn - qf)
        c1 = (qn - qf) - c2

        def model(s: np.ndarray) -> np.ndarray:  # s (p, m) -> (p, m, n)
            q: np.ndarray = (qf[:, None] + c1[:, None] * s[..., None]
                             + c2[:, None] * (s * s)[..., None])
            return q

        s = np.broadcast_to(np.linspace(0.0, 1.0, 2 * _SUB + 1), (len(cc), 2 * _SUB + 1))
        P = model(s)
        starts, tracks, cells, qidx, joints, values = [], [], [], [], [], []
        for qi, (j, v, _) in enumerate(queries):
            g = _wrap(P[..., j] - v)
            change = (np.sign(g[:, :-1]) != np.sign(g[:, 1:])) & (
                np.abs(g[:, :-1] - g[:, 1:]) < np.pi)
            c, sidx = np.nonzero(change)
            if not c.size:
                continue
            g0, g1 = g[c, sidx], g[c, sidx + 1]
            w = np.where(g0 != g1, g0 / np.where(g0 != g1, g0 - g1, 1.0), 0.0)
            starts.append(P[c, sidx] + w[:, None] * (P[c, sidx + 1] - P[c, sidx]))
            tracks.append(bb[c])
            cells.append(c)
            qidx.append(np.full(c.size, qi))
            joints.append(np.full(c.size, j))
            values.append(np.full(c.size, v))
        if not starts:
            return []
        c = np.concatenate(cells)
        q, ok = _newton_held(self.robot, self.T, np.concatenate(starts),
                             np.concatenate(joints), np.concatenate(values))
        t1 = q[:, self.joint]
        lo_t, hi_t = np.minimum(tf[c], tn[node[c]]), np.maximum(tf[c], tn[node[c]])
        lo, hi = self.domain
        ok &= (t1 >= lo_t) & (t1 <= hi_t) & (t1 >= lo) & (t1 <= hi)
        with np.errstate(invalid="ignore"):
            s1 = np.sqrt(np.clip((t1 - tf[c]) / h[c], 0.0, 1.0))
        on = qf[c] + c1[c] * s1[:, None] + c2[c] * (s1 * s1)[:, None]
        d = _wrap(q - qf[c])
        ok &= np.abs(_wrap(on - q)).max(-1) < _ON_TRACK
        # the track's side: toward its own branch (c1 + c2 s), not the twin's (-c1 ...)
        ok &= np.einsum("pn,pn->p", d, c1[c] + c2[c] * s1[:, None]) > 0
        b = np.concatenate(tracks)
        return list(zip(t1[ok].tolist(), b[ok].tolist(),
                        np.concatenate(qidx)[ok].tolist(), strict=True))

    def _grazes(self, queries: list[tuple[int, float, str]],
                found: list[tuple[float, int, int]]
                ) -> tuple[list[tuple[float, int, int]], list[tuple[float, int, int]]]:
        """Touches of a limit the sign-change scan cannot see (issue 29, session 9).

        A joint's extremum on a branch at its limit (a graze: q generated with the
        joint at its limit where the branch is tangent to it, e.g. next to q6 = 1e-9
        on the offset iiwa) changes no sign, so ``_crossings`` finds nothing there;
        nor does it see two crossings within one of its sub-values. Per track piece
        and limited joint, the extrema of the cubic Hermite model (roots of its
        derivative in the cell) within ``_GRAZE`` of a limit are refined on the
        branch's rows (``sample_rows``: golden-section search of the joint's excess
        over the limit, ``_GOLDEN`` steps in a quarter cell about the model's
        extremum). Where the branch comes toward the limit from outside and turns
        back within ``MANIFOLD_SLACK`` of it, the extremum is a touch ``(t, b, j)``
        (the branch's in-slack stretch about it is ``_points_refined``'s to find);
        where the extremum lies past the limit by more than the slack (a dip
        inside from outside, or out from inside) and the scan found no crossing of
        that joint and limit on one side of it in the cell, that side's is bisected
        on the rows (:meth:`_dip_crossings`: ``(t, b, query index)``). A candidate
        on a piece whose node rows are both singular, with the joint slower than
        ``_FLAT`` at both (a continuum's member sitting at the limit, as on the
        elbow-stretched offset iiwa with q2 or q3 at a limit), is not searched.

        Returns ``(touches, crossings)``.
        """
        lim = [(qi, j, v, kind == "upper") for qi, (j, v, kind) in enumerate(queries)
               if kind != "aligned axes"]
        if not lim:
            return [], []
        tn, X, S = self.t_nodes, self.tracks, self.slopes
        both = _finite_rows(X[:-1]) & _finite_rows(X[1:]) & _finite_rows(S[:-1]) & (
            _finite_rows(S[1:]))
        cc, bb = np.nonzero(both)
        if not cc.size:
            return [], []
        h = (tn[cc + 1] - tn[cc])[:, None]
        qa, sa = X[cc, bb], h * S[cc, bb]
        qb, sb = qa + _wrap(X[cc + 1, bb] - qa), h * S[cc + 1, bb]
        # q(u) = a0 + a1 u + a2 u^2 + a3 u^3 on u in [0, 1] (the cubic Hermite)
        a1, a2, a3 = sa, 3 * (qb - qa) - 2 * sa - sb, 2 * (qa - qb) + sa + sb
        A, B, C = 3 * a3, 2 * a2, a1  # q'(u) = A u^2 + B u + C
        disc = B * B - 4 * A * C
        with np.errstate(invalid="ignore", divide="ignore"):
            r = -0.5 * (B + np.copysign(np.sqrt(np.maximum(disc, 0.0)), B))
            us = np.stack([r / A, C / r])  # (2, pieces, n), stable for A = 0
        us = np.where((disc >= 0) & (us >= 0) & (us <= 1), us, np.nan)
        v = qa + us * (a1 + us * (a2 + us * a3))  # the extrema's values
        curv = 2 * a2 + 6 * a3 * us  # q''(u): > 0 a minimum of q
        cand: list[tuple[int, int, int, float, int]] = []  # (piece, query, sign, u, j)
        for qi, j, value, upper in lim:
            near = np.abs(_wrap(v[..., j] - value)) <= _GRAZE
            for k, p in zip(*np.nonzero(near), strict=True):
                # sign s: the excess over the limit is s (q - val) for upper, else -(q - val);
                # from outside: the excess has a minimum (q a minimum at upper)
                outside = (curv[k, p, j] > 0) == upper
                cand.append((int(p), qi, 1 if outside else -1, float(us[k, p, j]), j))
        if not cand:
            return [], []
        # a piece of a continuum's track (both node rows singular) with the joint flat
        # at both nodes: not searched (its rows are members the solver picks, which
        # cannot settle a touch; #5814: 1,316 of 1,429 candidates, 43 solves each)
        pc = np.array([c[0] for c in cand])
        jc = np.array([c[4] for c in cand])
        ca, cb = cc[pc], bb[pc]
        flat = np.flatnonzero((np.abs(S[ca, cb, jc]) < _FLAT) & (np.abs(S[ca + 1, cb, jc]) < _FLAT))
        if flat.size:
            sing = ~(_regular(self.robot, X[ca[flat], cb[flat]], self.joint)
                     | _regular(self.robot, X[ca[flat] + 1, cb[flat]], self.joint))
            skip = np.zeros(len(cand), bool)
            skip[flat[sing]] = True
            cand = [c for c, s in zip(cand, skip.tolist(), strict=True) if not s]
            if not cand:
                return [], []
        p_i = np.array([c[0] for c in cand])
        u_i = np.array([c[3] for c in cand])
        j_i = np.array([c[4] for c in cand])
        val = np.array([queries[c[1]][1] for c in cand])
        up = np.array([queries[c[1]][2] == "upper" for c in cand])
        sign = np.where(up, 1.0, -1.0)  # excess = sign (q - val)
        orient = np.array([float(c[2]) for c in cand])  # +1: minimise the excess
        b_i = bb[p_i]
        t_lo, t_hi = tn[cc[p_i]], tn[cc[p_i] + 1]
        tm = t_lo + u_i * (t_hi - t_lo)
        w = 0.125 * (t_hi - t_lo)
        lo, hi = np.maximum(t_lo, tm - w), np.minimum(t_hi, tm + w)
        rows = np.arange(len(cand))

        def f(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            """(orient * excess of the branch's joint at t, the rows)."""
            q, valid, _ = self.sample_rows(t)
            r = q[rows, b_i]
            e = sign * _wrap(r[rows, j_i] - val)
            return np.where(valid[rows, b_i], orient * e, np.inf), r

        g = 0.5 * (np.sqrt(5.0) - 1.0)
        x1, x2 = hi - g * (hi - lo), lo + g * (hi - lo)
        f1, _ = f(x1)
        f2, _ = f(x2)
        for _ in range(_GOLDEN):
            left = f1 <= f2  # the minimum in [lo, x2]
            hi = np.where(left, x2, hi)
            lo = np.where(left, lo, x1)
            x2n = np.where(left, x1, lo + g * (hi - lo))
            x1n = np.where(left, hi - g * (hi - lo), x2)
            fn, _ = f(np.where(left, x1n, x2n))
            f1, f2 = np.where(left, fn, f2), np.where(left, f1, fn)
            x1, x2 = x1n, x2n
        ts = np.where(f1 <= f2, x1, x2)
        best, _ = f(ts)
        e = orient * best  # the extremum's excess over the limit
        touches: list[tuple[float, int, int]] = []
        dips: list[int] = []
        for i in range(len(cand)):
            if not np.isfinite(e[i]):
                continue
            if orient[i] > 0 and abs(e[i]) <= _SLACK:
                if not any(b == b_i[i] and abs(t - ts[i]) < 1e-9 for t, b, _ in touches):
                    touches.append((float(ts[i]), int(b_i[i]), int(j_i[i])))
            elif orient[i] * e[i] < -_SLACK:  # past the limit: two crossings
                dips.append(i)
        return touches, self._dip_crossings(np.array(dips, dtype=int), ts, e, p_i, cc, j_i,
                                            val, b_i, [c[1] for c in cand], found)

    def _dip_crossings(self, d: np.ndarray, ts: np.ndarray, e: np.ndarray, p: np.ndarray,
                       cc: np.ndarray, j: np.ndarray, val: np.ndarray, b: np.ndarray,
                       qidx: list[int], found: list[tuple[float, int, int]]
                       ) -> list[tuple[float, int, int]]:
        """The crossings either side of the extrema ``d`` past their limits.

        An extremum at ts with the joint's excess e past the limit has a crossing on
        each side in its cell; a side where ``found`` has none of that joint and
        limit is bisected on the branch's rows (:meth:`_bisected`) between ts and
        ts +- sqrt(2 |e| / q'') (q'' the slope's change across the cell), or the
        cell's end where those rows do not straddle the limit.
        """
        if not d.size:
            return []
        tn = self.t_nodes
        c = cc[p[d]]
        a, z = tn[c], tn[c + 1]
        h = z - a
        S0, S1 = self.slopes[c, b[d], j[d]], self.slopes[c + 1, b[d], j[d]]
        curv = np.maximum(np.abs(S1 - S0) / h, 1e-12)
        half = np.sqrt(2 * np.abs(e[d]) / curv)
        qi = np.array(qidx)[d]
        br, keep = [], []
        for k in range(len(d)):
            t0, bk, qk = float(ts[d[k]]), int(b[d[k]]), int(qi[k])
            had = [t for t, b2, q2 in found if b2 == bk and q2 == qk and a[k] <= t <= z[k]]
            if not any(t < t0 for t in had):
                br.append([max(a[k], t0 - 2 * half[k]), t0, a[k], t0])
                keep.append(k)
            if not any(t > t0 for t in had):
                br.append([t0, min(z[k], t0 + 2 * half[k]), t0, z[k]])
                keep.append(k)
        if not br:
            return []
        kk = np.array(keep)
        t, _, ok = self._bisected(np.array(br), b[d][kk], j[d][kk], val[d][kk])
        out: list[tuple[float, int, int]] = []
        for tt, bb, q2 in zip(t[ok].tolist(), b[d][kk][ok].tolist(), qi[kk][ok].tolist(),
                              strict=True):
            if not any(bb == b2 and q2 == k2 and abs(tt - t2) < 1e-9 for t2, b2, k2 in out):
                out.append((tt, bb, q2))
        return out

    def _folds(self) -> list[tuple[float, int]]:
        """(t, track): where a track starts or ends inside the range (a fold).

        Found on the curve by :func:`_fold_newton` (exact to ~1e-15 in t); a fold
        it does not certify is bisected on the track's existence instead (the last
        value, to two adjacent doubles, where the track's row still exists).
        """
        exist = np.isfinite(self.tracks).all(-1)  # (m, k)
        c, b = np.nonzero(exist[1:] != exist[:-1])
        if not c.size:
            return []
        tn = self.t_nodes
        state = exist[c, b]  # True: the track exists at the cell's start
        near = np.where(state, c, c + 1)
        far = np.where(state, c + 1, c)
        if self.degenerate:  # the track's last node (its rows are all singular)
            return [(float(e), int(bb)) for e, bb in zip(tn[near], b, strict=True)]
        # a track ending on a singular row (no slope: the six free joints' Jacobian
        # singular, e.g. a member of a continuum at the stretched elbow) ends at that
        # node: neither the secant steps nor a bisection can follow it past
        stuck = ~np.isfinite(self.slopes[near, b]).all(-1)
        q_f, ok = _fold_newton(self.robot, self.T, self.tracks[near, b], self.slopes[near, b],
                               tn[far] - tn[near], self.joint)
        t_f = q_f[:, self.joint]
        lo, hi = np.minimum(tn[near], tn[far]), np.maximum(tn[near], tn[far])
        ok &= (t_f >= lo) & (t_f <= hi) & ~stuck
        ends = np.where(ok, t_f, np.where(stuck, tn[near], np.nan))
        self.fold_t[c[ok], b[ok]] = t_f[ok]
        self.fold_q[c[ok], b[ok]] = q_f[ok]
        rest = ~ok & ~stuck
        if rest.any():
            cr, br = c[rest], b[rest]
            ends[rest] = self._bisect(cr, br, state[rest])
            # the bisected end's own row, where the track has one there: the fold
            # model of `predict` (not the tangent line, which overshoots next to the
            # fold and leaves the cell's rows unassigned) and the fold-cell scan
            R, valid, _ = self.rows(ends[rest])
            i = np.flatnonzero(valid[np.arange(len(br)), br])
            self.fold_t[cr[i], br[i]] = ends[rest][i]
            self.fold_q[cr[i], br[i]] = R[i, br[i]]
        return [(float(e), int(bb)) for e, bb in zip(ends, b, strict=True)]

    def _bisect(self, c: np.ndarray, b: np.ndarray, state: np.ndarray) -> np.ndarray:
        """Fold ends (p,) in cells c by bisection on track b's existence."""
        tn = self.t_nodes
        lo, hi = tn[c].copy(), tn[c + 1].copy()
        for _ in range(_BISECT):
            mid = 0.5 * (lo + hi)
            if np.all((mid == lo) | (mid == hi)):
                break
            # folds of one cell (a branch's symmetric copies) often share their mid:
            # each value solved once (rows at a value do not depend on the others)
            uniq, inv = np.unique(mid, return_inverse=True)
            _, valid, _ = self.rows(uniq)
            same = valid[inv.ravel(), b] == state
            lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
        out: np.ndarray = np.where(state, lo, hi)
        return out


def _fold_newton(robot: Arm, T: np.ndarray, q0: np.ndarray, s0: np.ndarray, dt: np.ndarray,
                 k: int) -> tuple[np.ndarray, np.ndarray]:
    """The folds (p, n) next to rows q0 (p, n) with slopes s0 = dq/dt, toward t + dt.

    Past a fold the branch turns back in t, but it is smooth in its fastest joint
    m: held at v, the pose solved by Newton steps on the six others (t among them)
    gives t(v), and the fold is the zero of g(v) = dt/dq_m = n_k / n_m (n the null
    vector of the 6 x 7 Jacobian): secant steps from v0 = q0[m] and the point half
    a cell along the tangent. True where |g| fell below 1e-12 with the pose exact.
    """
    p, n = q0.shape
    rows = np.arange(p)
    sm = s0.copy()
    sm[:, k] = 0.0
    m = np.argmax(np.abs(np.where(np.isfinite(sm), sm, np.inf)), axis=1)
    sm_m = s0[rows, m]
    good = np.isfinite(s0).all(-1) & (np.abs(sm_m) > 0)
    tangent = np.where(good[:, None], s0 / np.where(good, sm_m, 1.0)[:, None], 0.0)

    def g_of(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        nv = np.full((p, n), np.nan)
        fin = np.flatnonzero(np.isfinite(q).all(-1) & (np.abs(q) < 1e3).all(-1))
        if fin.size:
            J, _ = jacobian_and_pose(robot.chain, q[fin])
            nv[fin] = np.linalg.svd(J)[2][:, -1, :]  # the null vectors (p, n)
        with np.errstate(divide="ignore", invalid="ignore"):
            return nv[:, k] / nv[rows, m], nv / nv[rows, m][:, None]

    v0 = q0[rows, m]
    g0 = np.where(good, 1.0 / np.where(good, sm_m, 1.0), np.nan)
    q_prev, v_prev, tan_prev = q0, v0, tangent
    v = v0 + sm_m * dt * 0.5
    ok = good.copy()
    q = q0
    for _ in range(30):
        guess = q_prev + (v - v_prev)[:, None] * tan_prev
        q, reached = _newton_held(robot, T, guess, m, v)
        g, tan = g_of(q)
        ok &= reached & np.isfinite(g)
        with np.errstate(divide="ignore", invalid="ignore"):
            v_next = v - g * (v - v_prev) / (g - g0)
        done = ~ok | (np.abs(g) < 1e-12) | ~np.isfinite(v_next) | (v_next == v)
        if done.all():
            break
        v_next = np.where(done, v, v_next)
        q_prev, v_prev, g0, tan_prev = q, v, g, tan
        v = v_next
    ok &= np.abs(g) < 1e-10
    return q, ok


def _approach(t: np.ndarray, im: np.ndarray, re: np.ndarray) -> np.ndarray:
    """Where root pairs approaching the real axis reach it in the next cell.

    t (m,) increasing nodes; im, re (m, p) per node the non-real root pairs'
    imaginary and real parts (``_ContinuedFamily._islands``, inf where none). Each
    pair at node i (1 <= i <= m - 2) is matched with the pair at node i - 1 of the
    nearest real part (within ``_MATCH`` [rad]); where its imaginary part fell,
    the line through the two reaches 0 at some t: returned (k,) where that lies
    inside the cell (t_i, t_i+1).
    """
    a, b = slice(0, -2), slice(1, -1)
    with np.errstate(invalid="ignore"):
        d = np.abs(_wrap(re[b, :, None] - re[a, None, :]))  # (m-2, p, p)
        d = np.where(np.isfinite(d), d, np.inf)
        near = np.argmin(d, axis=2)
        im_a = np.take_along_axis(im[a], near, axis=1)  # (m-2, p)
        ok = (np.take_along_axis(d, near[..., None], 2)[..., 0] < _MATCH) & (im_a > im[b])
        ok &= np.isfinite(im[b])
        tb, dt = t[b][:, None], (t[b] - t[a])[:, None]
        tz = tb + im[b] * dt / np.where(ok, im_a - im[b], 1.0)
        ok &= (tz > tb) & (tz < t[2:][:, None])
    out: np.ndarray = tz[ok]
    return out


def _wrap(x: np.ndarray) -> np.ndarray:
    """Angles wrapped into [-pi, pi] (by rounding: ``%`` is ~20x slower with NaN)."""
    out: np.ndarray = x - _TWO_PI * np.round(x / _TWO_PI)
    return out


def _finite_rows(x: np.ndarray) -> np.ndarray:
    """``np.isfinite(x).all(-1)``, the last axis (the joints) reduced one column at a time."""
    return _all_last(np.isfinite(x))


def _first_distinct(idx: np.ndarray, group: np.ndarray, q: np.ndarray, tol: float
                    ) -> np.ndarray:
    """The candidates idx (p,) of rows q kept: (kept,), in order.

    Each is kept unless a kept one before it in its group (``group[idx]``) is within
    ``tol`` [rad, 2 pi wrapped]. A candidate alone in its group is kept at once;
    groups of several are taken in turn.
    """
    if idx.size < 2:
        return idx
    g = group[idx]
    alone = np.bincount(g - g.min())[g - g.min()] == 1
    keep = alone.copy()
    for a in np.flatnonzero(~alone).tolist():
        prior = idx[:a][keep[:a] & (g[:a] == g[a])]
        keep[a] = not prior.size or bool(
            np.all(_max_last(np.abs(_wrap(q[prior] - q[idx[a]]))) > tol))
    out: np.ndarray = idx[keep]
    return out


def _max_last(x: np.ndarray) -> np.ndarray:
    """``x.max(-1)`` for a short last axis (the joints; NaN propagates alike).

    One ``np.maximum`` per joint: a reduction over a 7-long axis costs numpy ~10x
    more per element (the hot path of ``rows``: ``_assign``).
    """
    out: np.ndarray = x[..., 0].copy()
    for j in range(1, x.shape[-1]):
        np.maximum(out, x[..., j], out=out)
    return out


def _slopes(robot: Arm, Q: np.ndarray, k: int) -> np.ndarray:
    """dq/dq_k of rows Q (..., n) on the manifold of their pose (NaN rows, singular: NaN)."""
    flat = Q.reshape(-1, Q.shape[-1])
    out = np.full(flat.shape, np.nan)
    ok = np.flatnonzero(np.isfinite(flat).all(-1))
    if not ok.size:
        return out.reshape(Q.shape)
    J, _ = jacobian_and_pose(robot.chain, flat[ok])
    free = [c for c in range(flat.shape[-1]) if c != k]
    A, rhs = J[:, :, free], -J[:, :, k]
    good = np.abs(np.linalg.det(A)) > 1e-12 * np.abs(A).max(axis=(1, 2)) ** 6
    x = np.linalg.solve(A[good], rhs[good][..., None])[..., 0]
    rows = ok[good]
    out[np.ix_(rows, free)] = x
    out[rows, k] = 1.0
    return out.reshape(Q.shape)


def _regular(robot: Arm, Q: np.ndarray, k: int) -> np.ndarray:
    """(...) bool: rows Q (..., n) whose held 6 x 6 (joint k's column out) is regular.

    Its smallest singular value at least ``_REGULAR`` (NaN rows: False). A degenerate
    manifold's near-continuum rows (the offset iiwa with axes 3, 5 and 7 on one line:
    5e-15 to 3e-11) pass ``_slopes``' determinant test and Newton's, but a followed one
    is another member of the continuum than the kernel's (issue 29, round 7c).
    """
    flat = Q.reshape(-1, Q.shape[-1])
    out = np.zeros(len(flat), bool)
    ok = np.flatnonzero(_finite_rows(flat))
    if ok.size:
        J, _ = jacobian_and_pose(robot.chain, flat[ok])
        free = [c for c in range(flat.shape[-1]) if c != k]
        out[ok] = np.linalg.svd(J[:, :, free], compute_uv=False)[:, -1] >= _REGULAR
    return out.reshape(Q.shape[:-1])


def _widen(A: np.ndarray, B: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A (m, K1, n) and B (p, K2, n) padded with NaN rows to the same K."""
    K = max(A.shape[1], B.shape[1])

    def pad(X: np.ndarray) -> np.ndarray:
        extra = np.full((X.shape[0], K - X.shape[1], X.shape[2]), np.nan)
        return np.concatenate([X, extra], axis=1)

    return pad(A), pad(B)


def _residuals(t: np.ndarray, Q: np.ndarray, D: np.ndarray,
               cells: np.ndarray | None = None) -> np.ndarray:
    """Trapezoid residuals (c, K, K) of node i's rows a against node i+1's rows b.

    Per cell i in ``cells`` (default: every cell, m - 1). Inf where either row is
    missing or its slope is not finite (NaN replaced first: arithmetic on NaN is
    slow).
    """
    c = np.arange(len(t) - 1) if cells is None else cells
    ok = np.isfinite(Q).all(-1) & np.isfinite(D).all(-1)
    Qz, Dz = np.where(ok[..., None], Q, 0.0), np.where(ok[..., None], D, 0.0)
    h = (t[c + 1] - t[c])[:, None, None, None]
    a, b = Qz[c][:, :, None], Qz[c + 1][:, None, :]
    da, db = Dz[c][:, :, None], Dz[c + 1][:, None, :]
    r = np.abs(_wrap(b - a) - 0.5 * h * (da + db)).max(-1)
    r[~(ok[c][:, :, None] & ok[c + 1][:, None, :])] = np.inf
    out: np.ndarray = r
    return out


def _clean_cells(t: np.ndarray, Q: np.ndarray, D: np.ndarray,
                 cells: np.ndarray | None = None) -> np.ndarray:
    """(c,) bool: every row of both nodes pairs unambiguously across the cell.

    Per cell in ``cells`` (default: every cell).
    """
    c = np.arange(len(t) - 1) if cells is None else cells
    E = _residuals(t, Q, D, c)
    fa = np.isfinite(Q[c]).all(-1)  # (c, K)
    fb = np.isfinite(Q[c + 1]).all(-1)
    out = np.ones(len(E), bool)
    for axis, rows in ((2, fa), (1, fb)):
        s = np.sort(E, axis=axis)
        best = np.take(s, 0, axis=axis)
        second = np.take(s, 1, axis=axis) if s.shape[axis] > 1 else np.full_like(best, np.inf)
        good = (best < _PAIR) & (second > 4 * best)
        out &= np.all(good | ~rows, axis=1)
    return out


def _same_count(Q: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """(c,) bool: the cells' two nodes have as many rows (no branch starts or ends)."""
    n = np.isfinite(Q).all(-1).sum(-1)  # rows per node
    out: np.ndarray = n[cells] == n[cells + 1]
    return out


def _link(t: np.ndarray, Q: np.ndarray, D: np.ndarray
          ) -> tuple[np.ndarray, np.ndarray, int]:
    """Tracks and their slopes (m, k, n) from rows per node (m, K, n): mutual best pairs.

    With the number of linked chains left out beyond the ``_MAX_TRACKS`` longest.
    """
    m, K, n = Q.shape
    E = _residuals(t, Q, D)
    nxt = np.argmin(E, axis=2)  # (m-1, K): row a's best partner at the next node
    prv = np.argmin(E, axis=1)  # (m-1, K): row b's best partner at the previous node
    cell = np.arange(m - 1)[:, None]
    rows = np.arange(K)[None]
    mutual = (np.take_along_axis(prv, nxt, axis=1) == rows) & (
        np.take_along_axis(E, nxt[..., None], axis=2)[..., 0] < _LINK)
    link = np.where(mutual, nxt, -1)  # (m-1, K)
    has_prev = np.zeros((m, K), bool)
    c, a = np.nonzero(link >= 0)
    has_prev[c + 1, link[c, a]] = True
    exists = np.isfinite(Q).all(-1)
    link_l = link.tolist()
    chains: list[list[tuple[int, int]]] = []
    for i, r in zip(*np.nonzero(exists & ~has_prev), strict=True):
        i, r = int(i), int(r)
        chain = [(i, r)]
        while i < m - 1 and link_l[i][r] >= 0:
            i, r = i + 1, link_l[i][r]
            chain.append((i, r))
        chains.append(chain)
    del cell, rows
    # the longest _MAX_TRACKS (all but on a degenerate pose), ordered by their start
    dropped = max(len(chains) - _MAX_TRACKS, 0)
    chains = sorted(sorted(chains, key=len, reverse=True)[:_MAX_TRACKS], key=lambda c: c[0])
    if not chains:
        empty = np.full((m, 1, n), np.nan)
        return empty, empty.copy(), 0
    X = np.full((m, len(chains), n), np.nan)
    S = np.full((m, len(chains), n), np.nan)
    for b, chain in enumerate(chains):
        ii = np.array([i for i, _ in chain])
        rr = np.array([r for _, r in chain])
        X[ii, b], S[ii, b] = Q[ii, rr], D[ii, rr]
    return X, S, dropped


def _assign(P: np.ndarray, R: np.ndarray) -> np.ndarray:
    """Each track's row (M, k, n): the solved row (M, K, n) nearest its prediction P.

    Mutual nearest (2 pi wrapped, largest joint difference) within ``_ASSIGN``.
    """
    M, k, n = P.shape
    out = np.full((M, k, n), np.nan)
    if R.shape[1] == 0:
        return out
    fp, fr = _finite_rows(P), _finite_rows(R)  # (M, k), (M, K)
    R0 = np.where(fr[..., None], R, 0.0)  # (NaN arithmetic is slow)
    # distances of the predicted tracks only (most tracks live on part of the range)
    mi, bi = np.nonzero(fp)
    d = np.full((M, k, R.shape[1]), np.inf)
    x = P[mi, bi][:, None] - R0[mi]  # (p, K, n); _wrap's operations, in place
    y = np.divide(x, _TWO_PI)
    np.round(y, out=y)
    y *= _TWO_PI
    x -= y
    d[mi, bi] = _max_last(np.abs(x, out=x))  # (M, k, K)
    d[~(fp[:, :, None] & fr[:, None, :])] = np.inf
    best_row = np.argmin(d, axis=2)  # (M, k)
    best_track = np.argmin(d, axis=1)  # (M, K)
    mi = np.arange(M)[:, None]
    ok = (best_track[mi, best_row] == np.arange(k)[None]) & (
        d[mi, np.arange(k)[None], best_row] < _ASSIGN)
    m_i, b_i = np.nonzero(ok)
    out[m_i, b_i] = R[m_i, best_row[m_i, b_i]]
    return out


def _newton_held(robot: Arm, T: np.ndarray, q0: np.ndarray, joints: np.ndarray | int,
                 values: np.ndarray, steps: np.ndarray | None = None
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Configurations (M, n) of pose T with joint ``joints[i]`` at ``values[i]``.

    ``joints`` one index for every row: the six other columns taken as a slice.
    ``steps`` (M, ``_NEWTON``), if given, receives each step's largest joint change
    (inf where the 6 x 6 was singular; the rows' q do not depend on it).

    Newton steps from q0 (M, n) on the six other joints (the parameter among them:
    t free); True where the pose is reached to ``_EXACT``.
    """
    M, n = q0.shape
    q = q0.copy()
    q[np.arange(M), joints] = values
    free = np.ones((M, n), bool)
    free[np.arange(M), joints] = False
    idx = np.nonzero(free)[1].reshape(M, n - 1)
    err = np.full(M, np.inf)
    live = _finite_rows(q)
    rows = np.flatnonzero(live)  # the rows (re)evaluated: all, then the moved ones
    for it in range(_NEWTON + 1):
        # a row not moved keeps its q and error (the compiled Jacobian is lane-wise:
        # a row's J and pose do not depend on the others in the batch)
        qr = q[rows]
        alive = _finite_rows(qr) & (_max_last(np.abs(qr)) < 1e3)
        live[rows[~alive]] = False
        err[rows[~alive]] = np.inf
        rows = rows[alive]
        if not rows.size:
            break
        J, Tq = jacobian_and_pose(robot.chain, q[rows])
        e = pose_error(Tq, T)
        err[rows] = np.maximum(np.linalg.norm(e[:, :3], axis=1),
                               np.linalg.norm(e[:, 3:], axis=1))
        act = err[rows] > 0.1 * _EXACT
        if it == _NEWTON or not act.any():
            break
        moved = rows[act]
        A = (J[act][:, :, idx[0]] if isinstance(joints, int)
             else np.take_along_axis(J[act], idx[moved][:, None, :], axis=2))
        good = np.abs(np.linalg.det(A)) > 1e-14
        step = np.zeros((len(moved), n - 1))
        if good.any():
            step[good] = np.linalg.solve(A[good], e[act][good][..., None])[..., 0]
        if steps is not None:
            steps[moved, it] = np.where(good, _max_last(np.abs(step)), np.inf)
        q[moved[:, None], idx[moved]] += step
        rows = moved
    ok = err <= _EXACT
    return q, ok
