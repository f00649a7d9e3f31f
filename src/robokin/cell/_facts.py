"""Facts about a robot and a scene that cell design needs.

The default region of a map, an upper bound on the arm's reach, and stable
descriptions (hashed to recognise a map store of the same map).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from robokin.collision.scene import Scene
    from robokin.model.geometry import Shape
    from robokin.robot import Robot

__all__ = ["default_region", "describe_robot", "describe_scene", "reach_bound"]


def default_region(robot: Robot, samples: int, margin: float) -> np.ndarray:
    """The workspace bounds of the tool point, grown by ``margin`` of the extent.

    Monte-Carlo (:func:`robokin.kinematics.workspace.sample_workspace`, seed 0),
    so the same robot always gets the same region.

    Returns:
        ``[[x0, y0, z0], [x1, y1, z1]]`` [m], shape (2, 3).
    """
    from robokin.kinematics.workspace import sample_workspace

    ws = sample_workspace(robot, samples, rng=np.random.default_rng(0),
                          volume_points=0, manipulability_samples=0)
    lo, hi = ws.bounds
    pad = margin * np.maximum(hi - lo, 1e-3)
    return np.stack([lo - pad, hi + pad])


def reach_bound(robot: Robot) -> float:
    """An upper bound [m] on the distance of the tool point from the first joint.

    The radius of :func:`robokin.kinematics.workspace.reach_ball`: the sum of
    the lengths of the constant transforms after the first joint, plus the
    strokes of prismatic joints; no configuration reaches farther.
    """
    from robokin.kinematics.workspace import reach_ball

    radius = reach_ball(robot.chain)[1]
    return radius if np.isfinite(radius) else 1e3


def describe_robot(robot: Robot) -> bytes:
    """Bytes that change whenever the robot's kinematics or geometry do."""
    parts = [np.asarray(robot.chain.arrays.packed).tobytes(),
             np.asarray(robot.limits).tobytes()]
    geo = robot.geometry
    if geo is not None:
        for name, shapes in zip(geo.names, geo.shapes):
            parts.append(name.encode())
            parts.extend(_describe_shape(s) for s in shapes)
    return b"|".join(parts)


def describe_scene(scene: Scene) -> bytes:
    """Bytes that change whenever the scene's objects, tool or exclusions do."""
    parts = [np.asarray(scene.base, dtype=np.float64).tobytes()]
    for obj in scene.objects:
        parts.append(obj.name.encode())
        parts.append(_describe_shape(obj.shape))
    if scene.tool is not None:
        parts.append(np.asarray(scene.tool.tcp).tobytes())
        parts.extend(_describe_shape(s) for s in scene.tool.shapes)
    parts.extend(",".join(sorted(p)).encode() for p in sorted(scene.exclude, key=sorted))
    parts.append(repr(getattr(scene, "allowed", None)).encode())
    parts.append(repr(sorted(getattr(scene, "groups", {}).items())).encode())
    return b"|".join(parts)


def _describe_shape(shape: Shape) -> bytes:
    return b";".join([
        shape.kind.encode(),
        np.asarray(shape.size, dtype=np.float64).tobytes(),
        np.asarray(shape.placement, dtype=np.float64).tobytes(),
        str(shape.file or "").encode(),
        np.float64(shape.scale).tobytes(),
        b"" if shape.vertices is None else np.asarray(shape.vertices).tobytes(),
        b"" if shape.faces is None else np.asarray(shape.faces).tobytes(),
    ])
