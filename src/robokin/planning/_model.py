"""The compiled collision model the planners check states and edges against.

One :class:`CollisionModel` per (robot, scene): the shapes, the checked pairs, the
bounding volumes and the motion-bound coefficients are laid out once for the C
kernels (``csrc/plan_check.c``) and live as long as the model (its
:class:`~robokin.planning.Planner` owns it). The shapes, pairs and coal objects
come from the collision checker's compiled problem
(:class:`robokin.collision._problem._Problem`): one description of "which pairs
are checked" (the robot file's and the scene's exclusions) serves both.

The guarantee the kernels give and how (certified distance bounds, conservative
advancement along an edge) is described in ``docs/planning.md`` and at the top of
``csrc/plan_check.c``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from robokin._native import kernels as _k

if TYPE_CHECKING:
    from robokin.collision.scene import Scene
    from robokin.model.chain import Chain
    from robokin.robot import Robot

__all__ = ["CollisionModel", "EdgeReport", "StateReport"]

#: Core kind of each shape kind (plan_geom.c's PG_*).
_CORE = {
    "sphere": _k.PG_POINT,
    "capsule": _k.PG_SEGMENT,
    "box": _k.PG_BOX,
    "cylinder": _k.PG_CYLINDER,
    "mesh": _k.PG_HULL,
}
_ROUND = (_k.PG_POINT, _k.PG_SEGMENT)


@dataclass(frozen=True)
class StateReport:
    """Validity of states.

    Attributes:
        free: (m,) bool: every checked pair is farther apart than its margin.
        pair: (m,) int: the pair that decided a state that is not free (-1 if free).
    """

    free: np.ndarray
    pair: np.ndarray


@dataclass(frozen=True)
class EdgeReport:
    """Validity of straight joint-space edges.

    Attributes:
        free: (m,) bool: proven free along the whole edge.
        pair: (m,) int: the pair found at or below its margin (-1 if free).
        where: (m,) float: where along the edge, in [0, 1] (NaN if free).
        stats: Work done: states, pair bounds, exact distances, coal calls,
            edges, edges left unproven (counted as hits).
    """

    free: np.ndarray
    pair: np.ndarray
    where: np.ndarray
    stats: dict[str, int]


_STATS = ("states", "bounds", "exact", "coal_calls", "edges", "unproven")


def _prismatic_travel(chain: Chain, limits: np.ndarray) -> np.ndarray:
    """Largest |v_k| of each chain joint over the joint limits (0 for revolute ones).

    v = sign (M q + c) + offset is affine in q, so its extremes over the limit box
    come from interval arithmetic.
    """
    arr = chain.arrays
    lo, hi = limits[:, 0], limits[:, 1]
    M = np.asarray(arr.M, dtype=float)
    base = np.asarray(arr.c, dtype=float)
    vmin = base + np.where(M > 0, M * lo, M * hi).sum(axis=1)
    vmax = base + np.where(M > 0, M * hi, M * lo).sum(axis=1)
    sign, off = np.asarray(arr.sign, float), np.asarray(arr.offset, float)
    ends = np.stack([sign * vmin + off, sign * vmax + off], axis=1)
    travel = np.abs(ends).max(axis=1)
    prismatic = np.asarray(arr.kind, float) != 0.0
    return np.where(prismatic & np.isfinite(travel), travel, 0.0)


class CollisionModel:
    """A robot in a scene, compiled for the planning kernels.

    Args:
        robot: The robot (placed by the scene: base, tool transform, tool shapes).
        scene: The static scene.
        self_collision: Also check the robot's non-adjacent, non-excluded links.

    Raises:
        InputError: the robot has no collision geometry.
        MissingExtraError: coal or trimesh is missing (``robokin[collision]``).
    """

    def __init__(self, robot: Robot, scene: Scene, *, self_collision: bool = True) -> None:
        """Lay out shapes, pairs and motion bounds; build coal objects for meshes."""
        from robokin.collision._problem import _Problem

        self.problem = _Problem(robot, scene, self_collision)
        pr = self.problem
        self.robot = pr.robot  # the placed robot
        self.chain = pr.chain
        self.n = int(self.robot.n)
        self.nc = int(pr.nc)
        shapes = list(pr.shapes) + [ob.shape for ob in pr.objects]
        S = len(pr.shapes)
        kinds = np.array([_CORE[s.kind] for s in shapes], dtype=np.int64)
        shape_i, shape_f, hull = self._shape_tables(shapes, kinds, S)
        pair_i = self._pair_table(kinds, S)
        reach = self._shape_reach(S)
        self.P = int(pr.P)
        self.names = [(a, b) for a, b in zip(pr.body_a, pr.body_b)]
        self.is_self = np.array(pr.is_self, dtype=bool)
        self.has_mesh = np.array(pr.has_mesh, dtype=bool)
        self.capsule = _k.plan_model(
            np.ascontiguousarray(self.chain.arrays.packed), shape_i, shape_f, hull,
            pair_i, reach, S,
        )
        self.exact_callback = self._coal_distance if self.has_mesh.any() else None

    # -------------------------------------------------------------- layout
    def _shape_tables(
        self, shapes: list[Any], kinds: np.ndarray, S: int
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per shape [kind, link, hull start, hull count] and [rb pose, h, radius, cr]."""
        pr = self.problem
        N = len(shapes)
        rb = np.concatenate([pr.rb_local, pr.ob_rb_pose]).reshape(N, 4, 4)
        h = np.concatenate([pr.rb_h, pr.ob_rb_h]).reshape(N, 3)
        rad = np.concatenate([pr.rb_r, pr.ob_rb_r]).reshape(N)
        shape_i = np.zeros((N, 4), dtype=np.int64)
        shape_f = np.zeros((N, 21))
        hulls: list[np.ndarray] = []
        start = 0
        for x, sh in enumerate(shapes):
            shape_i[x, 0] = kinds[x]
            shape_i[x, 1] = pr.link[x] if x < S else -1
            if sh.kind == "mesh":
                c, _ = sh.local_box()
                v = np.asarray(sh.trimesh().convex_hull.vertices, dtype=float) - c
                hulls.append(v)
                shape_i[x, 2:] = (start, len(v))
                start += len(v)
            shape_f[x, :16] = rb[x].reshape(16)
            shape_f[x, 16:19] = h[x]
            shape_f[x, 19] = rad[x]
            shape_f[x, 20] = sh.size[0] if sh.kind == "cylinder" else 0.0
        hull = np.concatenate(hulls) if hulls else np.zeros((0, 3))
        return shape_i, shape_f, np.ascontiguousarray(hull, dtype=np.float64)

    def _pair_table(self, kinds: np.ndarray, S: int) -> np.ndarray:
        """Per pair: shapes, distance method, self flag, motion-bound shape and joints.

        The columns: shape a, shape b (objects after the S robot shapes), method,
        self, the shape whose motion bounds the pair's, and the chain joints
        j0 <= j < j1 that move it relative to the other. An object pair moves with every joint before its robot shape's link; a
        self pair (links la < lb) with the joints between them, on the farther
        link's shape.
        """
        pr = self.problem
        P, nc = int(pr.P), self.nc
        link = np.asarray(pr.link)
        out = np.zeros((P, 7), dtype=np.int64)
        for p in range(P):
            a = int(pr.pa[p])
            b = int(pr.pb[p]) + (0 if pr.is_self[p] else S)
            ka, kb = int(kinds[a]), int(kinds[b])
            if ka == _k.PG_HULL or kb == _k.PG_HULL:
                method = _k.PD_HULL
            elif ka in _ROUND and kb in _ROUND:
                method = _k.PD_SEGSEG
            elif ka in _ROUND and kb == _k.PG_BOX:
                method = _k.PD_SEGBOX
            elif ka == _k.PG_BOX and kb in _ROUND:
                method = _k.PD_BOXSEG
            else:
                method = _k.PD_GJK
            if pr.is_self[p]:
                la, lb = int(link[a]), int(link[b])
                mover = b if lb >= la else a
                j0, j1 = min(la, lb, nc), min(max(la, lb), nc)
            else:
                mover, j0, j1 = a, 0, min(int(link[a]), nc)
            out[p] = (a, b, method, int(pr.is_self[p]), mover, j0, j1)
        return out

    def _shape_reach(self, S: int) -> np.ndarray:
        """(S, nc): how far a point of each robot shape travels per unit |dv_j|.

        For a revolute joint j that moves the shape, its static reach from joint
        j's origin (the collision checker's bound from the link constants and the
        shape's bounding spheres) plus the largest travel of every prismatic joint
        between j and the shape (from the joint limits); 1 for a prismatic joint
        that moves it; 0 for a joint that does not.
        """
        pr = self.problem
        nc = self.nc
        kind = np.asarray(self.chain.arrays.kind, dtype=float)
        travel = _prismatic_travel(self.chain, np.asarray(self.robot.limits, float))
        reach = np.array(pr.reach, dtype=float)  # (nc, S), rows of joints moving s
        link = np.asarray(pr.link)
        out = np.zeros((S, nc))
        for s in range(S):
            top = min(int(link[s]), nc)
            for j in range(top):
                out[s, j] = 1.0 if kind[j] != 0.0 else reach[j, s] + travel[j + 1 : top].sum()
        return np.ascontiguousarray(out)

    # -------------------------------------------------------------- checks
    def margins(self, clearance: float, self_clearance: float) -> np.ndarray:
        """(P,) margins: ``clearance`` for scene pairs, ``self_clearance`` for self pairs."""
        return np.ascontiguousarray(
            np.where(self.is_self, float(self_clearance), float(clearance))
        )

    def _coal_distance(self, p: int, q: np.ndarray) -> float:
        """Coal's exact distance of pair p at configuration q (meshes)."""
        from robokin.kinematics.forward import link_frames

        frames = link_frames(self.chain, q[None, :])[0]
        return float(self.problem.exact(int(p), frames))

    def check_states(self, q: np.ndarray, margin: np.ndarray) -> StateReport:
        """Validity of the states q (m, n) [rad, m]."""
        q = np.ascontiguousarray(q, dtype=np.float64).reshape(-1, self.n)
        m = q.shape[0]
        status = np.empty(m, dtype=np.int64)
        pair = np.empty(m, dtype=np.int64)
        _k.plan_check_states(self.capsule, q, margin, self.exact_callback, status, pair)
        return StateReport(status == _k.PC_FREE, pair)

    def check_edges(self, q0: np.ndarray, q1: np.ndarray, margin: np.ndarray) -> EdgeReport:
        """Validity of the straight edges q0[i] -> q1[i], each (m, n) [rad, m]."""
        a = np.ascontiguousarray(q0, dtype=np.float64).reshape(-1, self.n)
        b = np.ascontiguousarray(q1, dtype=np.float64).reshape(-1, self.n)
        m = a.shape[0]
        status = np.empty(m, dtype=np.int64)
        pair = np.empty(m, dtype=np.int64)
        where = np.empty(m)
        stats = _k.plan_check_edges(
            self.capsule, a, b, margin, self.exact_callback, status, pair, where
        )
        return EdgeReport(
            status == _k.PC_FREE, pair, where, dict(zip(_STATS, stats, strict=True))
        )

    def distances(self, q: np.ndarray) -> np.ndarray:
        """(m, P) certified lower bounds on every pair's distance [m] at states q (m, n).

        Exact (to 1e-9 m) for primitives; for a pair with a mesh, the distance to
        its convex hull.
        """
        q = np.ascontiguousarray(q, dtype=np.float64).reshape(-1, self.n)
        out = np.empty((q.shape[0], self.P))
        _k.plan_distances(self.capsule, q, out)
        return out
