"""The compiled collision check behind :func:`robokin.collision.check`.

Shapes, bounding volumes, pairs and coal functors are built once per (robot,
scene) and reused; :meth:`_Problem.run` does one trajectory (see the algorithm in
:mod:`robokin.collision.check`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from robokin._native import kernels as _k
from robokin.collision._shapes import (
    collision_intervals,
    rounded_box,
    segment_of,
    spins_about_last_joint,
)
from robokin.collision.report import (
    TIE,
    Closest,
    Collision,
    CollisionReport,
    Interval,
    PairMinimum,
)
from robokin.exceptions import InputError
from robokin.model.geometry import RobotGeometry

if TYPE_CHECKING:
    from robokin.collision.scene import Scene, SceneObject
    from robokin.robot import Robot



def _coal():
    from robokin.model.geometry import _coal

    return _coal()


class _Problem:
    """The compiled check: shapes, bounding spheres, pairs, coal functors."""

    def __init__(self, robot: Robot, scene: Scene, self_collision: bool) -> None:
        self.coal = _coal()
        placed = scene.attach(robot)
        self.robot = placed
        geo = placed.geometry
        if geo is None:  # pragma: no cover - Scene.attach always sets a geometry
            geo = RobotGeometry.empty(placed)
        self.chain = placed.chain
        self.nc = self.chain.n_chain
        self._robot_shapes(geo, robot.name)
        self._scene_objects(list(scene.objects))
        self._pairs(geo, scene.excluded_pairs(placed), self_collision)
        self._distance_functors()
        self._closed_forms()
        self.req = self.coal.DistanceRequest()
        self.req.gjk_tolerance = 1e-9  # [m] (coal: 1e-6) distances exact to ~1e-9
        self.res = self.coal.DistanceResult()
        # Constants for the motion bounds.
        self.reach = self._static_reach()

    # ------------------------------------------------------------ the set-up
    def _robot_shapes(self, geo: RobotGeometry, name: str) -> None:
        """The robot's shapes, their links, bounding spheres and reach."""
        # Robot shapes, frame index = link index (0 base .. nc + 1 tool).
        shapes, link = [], []
        for k, ss in enumerate(geo.shapes):
            for s in ss:
                if s.kind == "mesh":
                    s.check_file()
                shapes.append(s)
                link.append(k)
        if not shapes:
            raise InputError(
                "robot",
                f"{name} has no collision geometry (no shapes on its links "
                "or tool), so nothing can be checked: give it a geometry: section "
                "or the scene a tool with shapes",
            )
        self.shapes = shapes
        self.link = np.array(link, dtype=np.int64)
        S = len(shapes)
        self.place = np.array([s.placement for s in shapes]).reshape(S, 4, 4)
        cs, rs, owner = [], [], []
        for i, s in enumerate(shapes):
            c, r = s.bounding_spheres()
            cs.append(c)
            rs.append(r)
            owner.append(np.full(len(r), i))
        self.sph_c = np.concatenate(cs) if cs else np.zeros((0, 3))
        self.sph_r = np.concatenate(rs) if rs else np.zeros(0)
        self.sph_owner = np.concatenate(owner) if owner else np.zeros(0, int)
        self.sph_start = np.searchsorted(self.sph_owner, np.arange(S)).astype(np.int64)
        self.sph_count = np.bincount(self.sph_owner, minlength=S).astype(np.int64)
        # Largest reach of each shape from its link frame origin.
        self.rho = np.zeros(S)
        if S:
            np.maximum.at(
                self.rho,
                self.sph_owner,
                np.linalg.norm(self.sph_c, axis=1) + self.sph_r,
            )
        self.spins = np.array(
            [spins_about_last_joint(s, k, self.chain) for s, k in zip(shapes, link)], dtype=bool
        )

    def _scene_objects(self, objects: list[SceneObject]) -> None:
        """The scene's objects: oriented boxes for the broad phase, coal transforms."""
        coal = self.coal
        # Scene objects: oriented boxes for the broad phase, fixed coal transforms.
        self.objects = objects
        O = len(objects)
        self.ob_R = np.zeros((O, 3, 3))
        self.ob_t = np.zeros((O, 3))
        self.ob_h = np.zeros((O, 3))
        self.ob_T3 = []
        for j, ob in enumerate(objects):
            c, h = ob.shape.local_box()
            pose = ob.shape.placement
            self.ob_R[j] = pose[:3, :3]
            self.ob_t[j] = pose[:3, :3] @ c + pose[:3, 3]
            self.ob_h[j] = h
            self.ob_T3.append(
                coal.Transform3s(
                    np.ascontiguousarray(pose[:3, :3]), np.ascontiguousarray(pose[:3, 3])
                )
            )

    def _pairs(self, geo: RobotGeometry, excluded: frozenset[frozenset[str]],
               self_collision: bool) -> None:
        """The shape pairs to check and the sphere combinations of the self pairs."""
        link, objects, S = self.link, self.objects, len(self.shapes)
        # Pairs at shape level: (robot shape, object) then (robot shape, robot shape).
        names = geo.names
        pa, pb, is_self = [], [], []
        for i in range(S):
            for j, ob in enumerate(objects):
                if frozenset((names[link[i]], ob.name)) in excluded:
                    continue
                pa.append(i)
                pb.append(j)
                is_self.append(False)
        if self_collision:
            checked = set(geo.self_pairs())
            for i in range(S):
                for j in range(i + 1, S):
                    a, b = link[i], link[j]
                    if (min(a, b), max(a, b)) in checked:
                        pa.append(i)
                        pb.append(j)
                        is_self.append(True)
        self.pa = np.array(pa, dtype=np.int64)
        self.pb = np.array(pb, dtype=np.int64)
        self.is_self = np.array(is_self, dtype=bool)
        P = len(pa)
        self.P = P
        self.body_a = [names[link[i]] for i in pa]
        self.body_b = [
            names[link[j]] if s else objects[j].name for j, s in zip(pb, is_self)
        ]
        # Self pairs are ordered with body_a the lower link (j > i within shapes
        # sorted by link, so link[pa] <= link[pb]).
        self.self_pairs = np.flatnonzero(self.is_self)
        # Sphere combinations for self pairs (grouped by pair).
        c1, c2 = [], []
        for p in self.self_pairs.tolist():
            i, j = pa[p], pb[p]
            rows_a = np.arange(
                self.sph_start[i], self.sph_start[i] + np.sum(self.sph_owner == i)
            )
            rows_b = np.arange(
                self.sph_start[j], self.sph_start[j] + np.sum(self.sph_owner == j)
            )
            A_, B_ = np.meshgrid(rows_a, rows_b, indexing="ij")
            c1.append(A_.ravel())
            c2.append(B_.ravel())
        self.self_c1 = np.concatenate(c1) if c1 else np.zeros(0, int)
        self.self_c2 = np.concatenate(c2) if c2 else np.zeros(0, int)

    def _distance_functors(self) -> None:
        """Exact geometry: coal distance functors (meshes: exact BVH and convex hull)."""
        coal, shapes, objects = self.coal, self.shapes, self.objects
        pa, pb, is_self, P = self.pa, self.pb, self.is_self, self.P
        # Exact geometry: distance functors (meshes: exact BVH and convex hull).
        self.has_mesh = np.zeros(P, dtype=bool)
        self.fn_exact: list[Any] = []
        self.fn_hull: list[Any] = []
        self.geoms: list[tuple[Any, Any]] = []
        cache: dict[tuple[int, int], Any] = {}

        def functor(g1, g2):
            key = (id(g1), id(g2))
            f = cache.get(key)
            if f is None:
                f = coal.ComputeDistance(g1, g2)
                cache[key] = f
            return f

        for p in range(P):
            sa = shapes[pa[p]]
            sb = shapes[pb[p]] if is_self[p] else objects[pb[p]].shape
            ga, gb = sa.coal_geometry(), sb.coal_geometry()
            self.geoms.append((ga, gb))
            self.fn_exact.append(functor(ga, gb))
            mesh = sa.kind == "mesh" or sb.kind == "mesh"
            self.has_mesh[p] = mesh
            self.fn_hull.append(
                functor(sa.coal_convex(), sb.coal_convex()) if mesh else None
            )

    def _closed_forms(self) -> None:
        """Capsule/sphere segments and rounded boxes of every shape and object."""
        shapes, objects = self.shapes, self.objects
        S, O = len(shapes), len(objects)
        pa, pb, is_self, P = self.pa, self.pb, self.is_self, self.P
        # Capsule/sphere pairs have a closed-form distance: computed for all samples
        # at once (segment-segment distance minus the radii).
        self.seg_local = np.zeros((S, 2, 3))
        self.seg_r = np.zeros(S)
        seg_ok = np.zeros(S, dtype=bool)
        for i, sh in enumerate(shapes):
            seg, rad = segment_of(sh)
            if seg is not None:
                self.seg_local[i], self.seg_r[i], seg_ok[i] = seg, rad, True
        ob_seg = [segment_of(ob.shape) for ob in objects]
        self.analytic = np.zeros(P, dtype=bool)
        for p in range(P):
            if seg_ok[pa[p]]:
                self.analytic[p] = (seg_ok[pb[p]] if is_self[p]
                                    else ob_seg[pb[p]][0] is not None)
        self.ob_seg = np.array([sg if sg is not None else np.zeros((2, 3))
                                for sg, _ in ob_seg]).reshape(O, 2, 3)
        self.ob_seg_r = np.array([rad for _, rad in ob_seg]) if O else np.zeros(0)

        # Rounded bounding boxes (pose in the parent frame, half sizes, radius).
        rbs = [rounded_box(sh) for sh in shapes]
        self.rb_local = np.array([x[0] for x in rbs]).reshape(S, 4, 4)
        self.rb_h = np.array([x[1] for x in rbs]).reshape(S, 3)
        self.rb_r = np.array([x[2] for x in rbs]).reshape(S)
        obs = [rounded_box(ob.shape) for ob in objects]
        self.ob_rb_pose = np.array([x[0] for x in obs]).reshape(O, 4, 4)
        self.ob_rb_h = np.array([x[1] for x in obs]).reshape(O, 3)
        self.ob_rb_r = np.array([x[2] for x in obs]).reshape(O)

    # ------------------------------------------------------------ motion bounds
    def _static_reach(self) -> np.ndarray:
        """(nc, S): bound on the distance from joint j's origin to shape s.

        The lengths of the constants after joint j up to the shape's link frame,
        plus the shape's reach from that frame; prismatic joints in between count at
        zero travel (``motion_bounds`` adds their largest travel along the
        trajectory). Rows of joints that do not move the shape stay 0.
        """
        ch, nc, S = self.chain, self.nc, len(self.shapes)
        a_len = np.linalg.norm(ch.frame_offsets[:, :3, 3], axis=1)
        b_len = np.linalg.norm(ch.link_offsets[:, :3, 3], axis=1)
        tool_len = float(np.linalg.norm(ch.tool[:3, 3]))
        reach = np.zeros((nc, S))
        for s in range(S):
            k = self.link[s]
            top = min(k, nc)
            for j in range(1, top + 1):  # joints 1..k move link k
                # constants after J_j up to frame k
                total = a_len[j - 1 : top].sum() + b_len[j - 1 : top - 1].sum()
                if k == nc + 1:  # tool: F_nc G_nc tool after the last joint
                    total += b_len[nc - 1] + tool_len
                reach[j - 1, s] = total + self.rho[s]
        return reach

    def motion(self, q: np.ndarray, frames: np.ndarray) -> np.ndarray:
        """Per interval and pair, the bound on the motion closing the distance, (P, m-1).

        ``frames`` are the link frames of ``q`` (:meth:`frames`).
        """
        m = q.shape[0]
        P = self.P
        if m < 2 or P == 0:
            return np.zeros((P, max(m - 1, 0)))
        Ms = np.empty((P, m - 1))
        _k.motion_bounds(
            self.chain.arrays.packed,
            np.ascontiguousarray(q, dtype=np.float64),
            np.ascontiguousarray(frames),
            self.link,
            self.sph_c,
            self.sph_r,
            self.sph_start,
            self.sph_count,
            self.reach,
            self.spins,
            self.pa,
            self.pb,
            self.is_self,
            Ms,
        )
        return Ms

    # ---------------------------------------------------------------- bounds
    def lower_bounds(self, frames: np.ndarray) -> np.ndarray:
        """Broad-phase lower bounds on every pair's distance, (P, m).

        Separating-axis gaps between rounded bounding boxes (compiled kernel).
        """
        m = frames.shape[0]
        out = np.full((self.P, m), -np.inf)
        _k.rounded_box_bounds(
            np.ascontiguousarray(frames),
            self.link,
            self.rb_local,
            self.rb_h,
            self.rb_r,
            self.ob_rb_pose,
            self.ob_rb_h,
            self.ob_rb_r,
            self.pa,
            self.pb,
            self.is_self,
            self.analytic,
            out,
        )
        return out

    # -------------------------------------------------------------- analytic
    def analytic_distances(self, frames: np.ndarray, pairs: np.ndarray) -> np.ndarray:
        """Closed-form distances of capsule/sphere pairs at every sample, (len(pairs), m)."""
        out = np.empty((len(pairs), frames.shape[0]))
        _k.capsule_distances(
            np.ascontiguousarray(frames),
            self.link,
            self.seg_local,
            self.seg_r,
            self.ob_seg,
            self.ob_seg_r,
            self.pa,
            self.pb,
            self.is_self,
            np.ascontiguousarray(pairs, dtype=np.int64),
            out,
        )
        return out

    # ----------------------------------------------------------------- exact
    def _T3(self, frame: np.ndarray, s: int):
        W = frame @ self.place[s]
        return self.coal.Transform3s(np.ascontiguousarray(W[:3, :3]), W[:3, 3].copy())

    def _pair_transforms(self, p: int, frames_i: np.ndarray):
        """The coal transforms of pair p's two shapes at one configuration."""
        a = self.pa[p]
        Ta = self._T3(frames_i[self.link[a]], a)
        if self.is_self[p]:
            b = self.pb[p]
            return Ta, self._T3(frames_i[self.link[b]], b)
        return Ta, self.ob_T3[self.pb[p]]

    def exact(self, p: int, frames_i: np.ndarray, hull: bool = False) -> float:
        """Exact (or convex-hull lower-bound) distance of pair p at one configuration."""
        Ta, Tb = self._pair_transforms(p, frames_i)
        fn = self.fn_hull[p] if hull else self.fn_exact[p]
        res = self.res
        res.clear()  # coal keeps the minimum over calls otherwise
        return float(fn(Ta, Tb, self.req, res))

    def nearest(
        self, p: int, frames_i: np.ndarray
    ) -> tuple[float, np.ndarray, np.ndarray]:
        """Distance and nearest points (world) of pair p at one configuration."""
        Ta, Tb = self._pair_transforms(p, frames_i)
        res = self.coal.DistanceResult()
        ga, gb = self.geoms[p]
        d = self.coal.distance(ga, Ta, gb, Tb, self.req, res)
        return (
            float(d),
            np.array(res.getNearestPoint1()),
            np.array(res.getNearestPoint2()),
        )

    # ------------------------------------------------------------------- run
    def frames(self, q: np.ndarray) -> np.ndarray:
        from robokin.kinematics.forward import link_frames

        return link_frames(self.chain, q)

    def run(
        self, q, t, clearance, subdivide, tol, pair_tol, pair_rtol
    ) -> CollisionReport:
        m = q.shape[0]
        times = np.arange(m, dtype=float) if t is None else t
        P = self.P
        frames = self.frames(q)
        if P == 0:
            return CollisionReport(math.inf, False, [], [], [], None, [], clearance, times,
                                   _problem=self, _q=q)
        LB = self.lower_bounds(frames)
        Ms = self.motion(q, frames)  # (P, m-1)
        C = np.zeros((P, m))
        np.cumsum(Ms, axis=1, out=C[:, 1:])
        D = np.full((P, m), np.nan)
        done = np.zeros((P, m), dtype=bool)  # exact known
        hulled = np.zeros((P, m), dtype=bool)
        self.queries = 0
        an = np.flatnonzero(self.analytic)
        if len(an):
            D[an] = self.analytic_distances(frames, an)
            done[an] = True
            LB[an] = D[an]

        # Per-run caches: shape poses as coal transforms, pair data as Python values.
        T3 = self.coal.Transform3s
        tcache: dict[tuple[int, int], Any] = {}
        place, link_l = self.place, self.link.tolist()
        pa_l, pb_l, self_l = self.pa.tolist(), self.pb.tolist(), self.is_self.tolist()
        mesh_l, fn_e, fn_h = self.has_mesh.tolist(), self.fn_exact, self.fn_hull
        ob_T3, req, res = self.ob_T3, self.req, self.res

        def pose(i: int, s: int):
            key = (i, s)
            T = tcache.get(key)
            if T is None:
                W = frames[i, link_l[s]] @ place[s]
                T = tcache[key] = T3(np.ascontiguousarray(W[:3, :3]), W[:3, 3].copy())
            return T

        def query(fn, p: int, i: int) -> float:
            Ta = pose(i, pa_l[p])
            Tb = pose(i, pb_l[p]) if self_l[p] else ob_T3[pb_l[p]]
            res.clear()  # coal keeps the minimum over calls otherwise
            return float(fn(Ta, Tb, req, res))

        def evaluate(ps: np.ndarray, idx: np.ndarray, force_exact: bool) -> None:
            n = 0
            for p, i in zip(ps.tolist(), idx.tolist()):
                if mesh_l[p] and not force_exact and not hulled[p, i]:
                    v = query(fn_h[p], p, i)
                    n += 1
                    hulled[p, i] = True
                    if v > LB[p, i]:
                        LB[p, i] = v
                    if v > clearance:
                        continue
                v = query(fn_e[p], p, i)
                n += 1
                D[p, i] = v
                LB[p, i] = v
                done[p, i] = True
            self.queries += n

        def propagate(rows: np.ndarray) -> None:
            if len(rows) and m >= 2:
                _k.propagate_bounds(
                    LB, done | hulled, C, np.ascontiguousarray(rows, dtype=np.int64)
                )

        # 1. Exact queries where they decide something (see _settle).
        self._settle(D, LB, done, evaluate, propagate, clearance, pair_tol, pair_rtol)
        # 2. Subdivision: intervals whose ends do not clear the motion between.
        self.subdivisions = 0
        between = (self._subdivide(q, D, LB, Ms, done, evaluate, clearance, tol)
                   if subdivide and m >= 2 else {})
        return self._report(q, times, frames, D, between, clearance)

    def _settle(self, D: np.ndarray, LB: np.ndarray, done: np.ndarray,
                evaluate: Callable[..., None], propagate: Callable[[np.ndarray], None],
                clearance: float, pair_tol: float, pair_rtol: float) -> None:
        """Exact queries where they decide something, filling ``D`` and ``done``.

        A sample whose bound does not clear the threshold is queried (to classify
        it), or one whose bound lies below its pair's best so far (to find the
        pair's minimum). Each round queries a strided subset plus each pair's
        lowest bound, then spreads the new values to the neighbours through the
        motion bounds; the stride halves per round. Pair minima are settled to
        ``pair_tol``; a last pass settles the global minimum exactly.
        """
        P, m = D.shape
        cols = np.arange(m)
        stride = 0  # first round: only each pair's lowest bound
        final = False
        best = np.where(done, D, np.inf).min(axis=1)
        active = np.arange(P)
        while True:
            if final:
                g = best.min()
                cand = np.flatnonzero(np.where(done, np.inf, LB).min(axis=1) < g - TIE)
                need = ~done[cand] & (LB[cand] < g - TIE)
            else:
                cand = active
                Lc = LB[cand]
                bc = best[cand]
                rel = pair_rtol * np.abs(np.where(np.isfinite(bc), bc, 0.0))
                slack = np.maximum(pair_tol, rel)[:, None]
                need = ~done[cand] & (
                    (Lc <= clearance) | (Lc < best[cand, None] - slack)
                )
            keep = need.any(axis=1)
            rows, need = cand[keep], need[keep]
            if not final:
                active = rows
            if not len(rows):
                if final or pair_tol <= TIE:
                    break
                final = True
                continue
            pick = np.zeros_like(need)
            if stride:
                pick |= need & ((cols % stride) == 0)[None, :]
            work = np.where(need, LB[rows], np.inf)
            pick[np.arange(len(rows)), np.argmin(work, axis=1)] = True
            ps, idx = np.nonzero(pick)
            evaluate(rows[ps], idx, force_exact=False)
            propagate(rows)
            best[rows] = np.where(done[rows], D[rows], np.inf).min(axis=1)
            stride = max(m // 32, 1) if stride == 0 else max(stride // 4, 1)

    def _subdivide(self, q: np.ndarray, D: np.ndarray, LB: np.ndarray, Ms: np.ndarray,
                   done: np.ndarray, evaluate: Callable[..., None], clearance: float,
                   tol: float) -> dict[tuple[int, int], tuple[float, float]]:
        """Hits between samples: (pair, interval) -> (fraction, distance).

        The intervals whose end distances do not clear the motion bound between
        them get exact ends, then a bisection (:meth:`_bisect`).
        """
        between: dict[tuple[int, int], tuple[float, float]] = {}
        bad = (LB[:, :-1] + LB[:, 1:] <= Ms + 2 * clearance) & (Ms > tol)
        bad &= ~((D[:, :-1] <= clearance) | (D[:, 1:] <= clearance))
        if not bad.any():
            return between
        ps, idx = np.nonzero(bad)
        for off in (0, 1):
            sel = ~done[ps, idx + off]
            evaluate(ps[sel], idx[sel] + off, force_exact=True)
        still = D[ps, idx] + D[ps, idx + 1] <= Ms[ps, idx] + 2 * clearance
        still &= (D[ps, idx] > clearance) & (D[ps, idx + 1] > clearance)
        for p, i in zip(ps[still].tolist(), idx[still].tolist()):
            found = self._bisect(p, q[i], q[i + 1], D[p, i], D[p, i + 1], Ms[p, i],
                                 clearance, tol)
            if found is not None:
                between[(p, i)] = found
        return between

    def _bisect(self, p, q0, q1, d0, d1, M, thr, tol):
        """Search an interval for a configuration at or below ``thr``; (fraction, d) or None."""
        stack = [(0.0, 1.0, d0, d1)]
        found = None
        target = thr
        evals = 0
        while stack and evals < 4096:
            a, b, da, db = stack.pop()
            Mab = M * (b - a)
            if da + db > Mab + 2 * target or Mab <= tol:
                continue
            mid = 0.5 * (a + b)
            fr = self.frames(q0 + mid * (q1 - q0))
            d = self.exact(p, fr)
            evals += 1
            self.queries += 1
            self.subdivisions += 1
            if (found is None and d <= target) or (found is not None and d < found[1]):
                found = (mid, d)
            if d <= 0.0:
                found = (mid, d)
                break
            if d <= target:
                target = 0.0  # a violation is known; keep looking for a collision
            stack.append((mid, b, d, db))
            stack.append((a, mid, da, d))
        return found

    # ---------------------------------------------------------------- report
    def _groups(self):
        groups: dict[tuple[str, str], list[int]] = {}
        for p in range(self.P):
            groups.setdefault((self.body_a[p], self.body_b[p]), []).append(p)
        return groups

    def _report(self, q, times, frames, D, between, clearance) -> CollisionReport:
        m = q.shape[0]
        groups = self._groups()

        def t_at(i: int, frac: float = 0.0) -> float:
            if frac == 0.0 or i + 1 >= m:
                return float(times[i])
            return float(times[i] + frac * (times[i + 1] - times[i]))

        pairs: list[PairMinimum] = []
        best_overall = None  # (d, p, i, frac, between)
        intervals: list[Interval] = []
        violations: list[Interval] = []
        for (ba, bb), plist in groups.items():
            sub = D[plist]  # (k, m)
            per_sample = np.nanmin(np.where(np.isnan(sub), np.inf, sub), axis=0)
            i = int(np.argmin(per_sample))
            dmin = float(per_sample[i])
            p_best = plist[
                int(np.nanargmin(np.where(np.isnan(sub[:, i]), np.inf, sub[:, i])))
            ]
            kind = "self" if self.is_self[plist[0]] else "object"
            pairs.append(PairMinimum(ba, bb, dmin, i, t_at(i), kind))
            cand = (dmin, p_best, i, 0.0, False)
            if best_overall is None or cand[0] < best_overall[0]:
                best_overall = cand
            btw = {i0: v for (p, i0), v in between.items() if p in plist}
            for (p, i0), (frac, dv) in between.items():
                if p in plist and (best_overall is None or dv < best_overall[0]):
                    best_overall = (dv, p, i0, frac, True)
            for thr, out in ((0.0, intervals), (clearance, violations)):
                if out is violations and clearance <= 0.0:
                    continue
                mask = per_sample <= thr
                bmask = np.zeros(max(m - 1, 0), dtype=bool)
                bfrac: dict[int, tuple[float, float]] = {}
                for i0, (frac, dv) in btw.items():
                    if dv <= thr:
                        bmask[i0] = True
                        bfrac[i0] = (frac, dv)
                out.extend(collision_intervals(mask, bmask, bfrac, per_sample, ba, bb, t_at))
        pairs.sort(key=lambda r: r.distance)
        closest = (None if best_overall is None
                   else self._closest(q, frames, best_overall, t_at))
        min_distance = math.inf if closest is None else closest.distance
        intervals.sort(key=lambda r: (r.first_index, r.body_a, r.body_b))
        violations.sort(key=lambda r: (r.first_index, r.body_a, r.body_b))
        collisions = [Collision(r.first_index, r.last_index, r.body_a, r.body_b)
                      for r in intervals]
        return CollisionReport(
            min_distance=min_distance,
            collides=bool(intervals),
            collisions=collisions,
            intervals=intervals,
            violations=violations,
            closest=closest,
            pairs=pairs,
            clearance=clearance,
            t=times,
            queries=self.queries,
            subdivisions=self.subdivisions,
            _problem=self,
            _q=q,
        )

    def _closest(self, q: np.ndarray, frames: np.ndarray,
                 best: tuple[float, int, int, float, bool],
                 t_at: Callable[..., float]) -> Closest:
        """The nearest points at ``best``, the minimum (d, pair, sample, fraction, between)."""
        dmin, p, i, frac, between = best
        fr = self.frames(q[i] + frac * (q[i + 1] - q[i])) if between else frames[i]
        _, point_a, point_b = self.nearest(p, fr)
        return Closest(float(dmin), int(i), t_at(i, frac), self.body_a[p], self.body_b[p],
                       point_a, point_b, between)

    def closest_at(
        self, q: np.ndarray, idx: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The closest pair's distance and nearest points at samples ``idx``.

        Pairs are queried in increasing lower-bound order (broad phase, and the
        closed form for capsule/sphere pairs) until no bound is below the best.
        """
        k = idx.size
        dist = np.full(k, np.inf)
        pa = np.full((k, 3), np.nan)
        pb = np.full((k, 3), np.nan)
        if k == 0 or self.P == 0:
            return dist, pa, pb
        frames = self.frames(q[idx])
        lb = self.lower_bounds(frames)  # (P, k); -inf where not bounded
        an = np.flatnonzero(self.analytic)
        if an.size:
            lb[an] = self.analytic_distances(frames, an) - TIE
        for i in range(k):
            for p in np.argsort(lb[:, i], kind="stable"):
                if lb[p, i] >= dist[i]:
                    break
                d, a, b = self.nearest(int(p), frames[i])
                if d < dist[i]:
                    dist[i], pa[i], pb[i] = d, a, b
        return dist, pa, pb

    def profile(self, q: np.ndarray, body_a: str, body_b: str) -> np.ndarray:
        """Exact distance of one body pair at every sample, (m,)."""
        plist = [
            p
            for p in range(self.P)
            if {self.body_a[p], self.body_b[p]} == {body_a, body_b}
        ]
        if not plist:
            raise InputError("pair", f"({body_a!r}, {body_b!r}) is not a checked pair")
        frames = self.frames(q)
        out = np.full(q.shape[0], np.inf)
        for i in range(q.shape[0]):
            for p in plist:
                out[i] = min(out[i], self.exact(p, frames[i]))
        return out
