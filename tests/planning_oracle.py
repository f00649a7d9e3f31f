"""The independent check the planning tests hold robokin's answers to, and their scenes.

Built from the declared data only, not from the planner's compiled model or the
collision checker's problem: the robot as the scene places it
(``scene.attach``), each shape's coal geometry placed by the robot's link frames
(``link_frames``, tested against pinocchio and the DH tables elsewhere), the
scene's objects, and the checked pairs re-derived from the robot geometry's
``self_pairs`` and the scene's exclusions. Distances are coal's (``coal.distance``),
one call per pair, each with a fresh request and result whose GJK starts from
coal's default guess: no cached guess carried from one call to the next (a cached
guess made pinocchio's collision checks miss 88 of 2100 colliding Panda states;
``benchmarks/plan_baseline.py``).
"""

from __future__ import annotations

import coal
import numpy as np

from robokin.collision import Scene
from robokin.kinematics.forward import link_frames
from robokin.model import geometry as geo
from robokin.spatial import pose_from_xyz_rpy


def _request():
    """A distance request that starts GJK from coal's default guess, never a cached one."""
    req = coal.DistanceRequest()
    req.gjk_initial_guess = coal.GJKInitialGuess.DefaultGuess
    return req


def _tf(T):
    return coal.Transform3s(np.ascontiguousarray(T[:3, :3]), np.ascontiguousarray(T[:3, 3]))


class Oracle:
    """Minimum distance of a robot in a scene, pair by pair with coal."""

    def __init__(self, robot, scene):
        placed = scene.attach(robot)
        self.robot = placed
        geo = placed.geometry
        self.shapes = [(k, s) for k, ss in enumerate(geo.shapes) for s in ss]
        self.objects = list(scene.objects)
        names = geo.names
        self.pairs = []  # (shape index, object index or None, other shape index)
        for i, (k, _) in enumerate(self.shapes):
            for j, ob in enumerate(self.objects):
                if frozenset((names[k], ob.name)) not in scene.exclude:
                    self.pairs.append((i, j, None))
        checked = set(geo.self_pairs())
        for i, (ka, _) in enumerate(self.shapes):
            for j, (kb, _) in enumerate(self.shapes):
                if j > i and (min(ka, kb), max(ka, kb)) in checked:
                    self.pairs.append((i, None, j))
        self.geom = [s.coal_geometry() for _, s in self.shapes]
        self.ob_geom = [ob.shape.coal_geometry() for ob in self.objects]
        self.ob_tf = [_tf(ob.pose) for ob in self.objects]

    def distances(self, q):
        """(P,) coal distance of every checked pair at configuration q (n,)."""
        F = link_frames(self.robot.chain, np.asarray(q, float)[None])[0]
        tf = [_tf(F[k] @ s.placement) for k, s in self.shapes]
        out = np.empty(len(self.pairs))
        for p, (i, j, other) in enumerate(self.pairs):
            res = coal.DistanceResult()
            if other is None:
                out[p] = coal.distance(self.geom[i], tf[i], self.ob_geom[j], self.ob_tf[j],
                                       _request(), res)
            else:
                out[p] = coal.distance(self.geom[i], tf[i], self.geom[other], tf[other],
                                       _request(), res)
        return out

    def min_distance(self, q):
        d = self.distances(q)
        return float(d.min()) if d.size else np.inf

    def segment_min(self, a, b, step=0.01):
        """Smallest distance over the segment a -> b sampled every ``step`` (largest joint)."""
        a, b = np.asarray(a, float), np.asarray(b, float)
        k = max(int(np.ceil(np.abs(b - a).max() / step)), 1)
        return min(self.min_distance(a + t * (b - a)) for t in np.linspace(0, 1, k + 1))

    def path_min(self, path, step=0.01):
        path = np.asarray(path, float)
        if len(path) == 1:
            return self.min_distance(path[0])
        return min(self.segment_min(a, b, step) for a, b in zip(path[:-1], path[1:]))


# ------------------------------------------------------------------ scenes
def pose(xyz, rpy=(0.0, 0.0, 0.0)):
    return pose_from_xyz_rpy(np.asarray(xyz, float), np.asarray(rpy, float))


def gripper(scene):
    """A palm box and two finger boxes on the flange, TCP 0.14 m beyond it."""
    scene.set_tool([geo.box((0.08, 0.12, 0.07), pose((0, 0, 0.035))),
                    geo.box((0.02, 0.02, 0.05), pose((0, 0.045, 0.095))),
                    geo.box((0.02, 0.02, 0.05), pose((0, -0.045, 0.095)))],
                   pose((0, 0, 0.14)), name="gripper")


def shelf_scene():
    """Boxes (a shelf in front of the robot), a cylinder post and a sphere."""
    s = Scene("shelf")
    gripper(s)
    for k, z in enumerate((0.05, 0.4, 0.75)):
        s.add_box(f"board_{k}", (0.3, 0.8, 0.02), pose((0.7, 0, z)))
    for side in (-1, 1):
        s.add_box(f"side_{side:+d}", (0.3, 0.02, 0.72), pose((0.7, side * 0.4, 0.4)))
    s.add_box("back", (0.02, 0.8, 0.72), pose((0.85, 0, 0.4)))
    s.add_cylinder("post", 0.04, 1.0, pose((-0.45, 0.45, 0.3)))
    s.add_sphere("ball", 0.08, pose((0.0, -0.55, 0.5)))
    s.add_capsule("rail", 0.03, 0.6, pose((-0.4, -0.3, 0.9), (0.0, np.pi / 2, 0.3)))
    return s
