"""Scenes, collision and minimum distance along a motion (needs ``robokin[collision]``).

.. code-block:: python

    from robokin import collision

    scene = collision.Scene.load("press.yaml")
    rep = collision.check(robot, scene, q_samples)   # (m, n) or a Trajectory
    rep.min_distance, rep.collides, rep.collisions, rep.closest
"""

from __future__ import annotations

from pathlib import Path

from robokin._text import short_repr
from robokin.collision.check import check
from robokin.collision.report import (
    Closest,
    Collision,
    CollisionReport,
    Interval,
    PairMinimum,
)
from robokin.collision.scene import Scene, SceneObject, Tool

__all__ = [
    "Closest",
    "Collision",
    "CollisionReport",
    "Interval",
    "PairMinimum",
    "Scene",
    "SceneObject",
    "Tool",
    "check",
    "scene_path",
]


def scene_path(name: str) -> Path:
    """Path of a bundled scene file, e.g. ``scene_path("press")``."""
    from robokin.exceptions import InputError

    here = Path(__file__).parent / "scenes"
    path = here / f"{name}.yaml"
    if not path.is_file():
        names = sorted(p.stem for p in here.glob("*.yaml"))
        raise InputError("name", f"no bundled scene {short_repr(name)}; scenes: {names}")
    return path
