"""robokin: kinematics of industrial serial manipulators.

Model an arm (DH, modified DH, virtual frames, elementary sequences, URDF), compute
where it is, find every way to reach a pose, plan smooth motion, check it against the
machine it works in, look at it, and hand it to a real controller.

Heavy parts (scipy, pydantic, the optional extras) load lazily, so
``import robokin`` stays fast.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from robokin.exceptions import (
    InputError,
    MissingExtraError,
    ModelError,
    RobokinError,
    UnreachableError,
)
from robokin.robot import Robot

__version__ = "0.1.0"

__all__ = [
    "InputError",
    "MissingExtraError",
    "ModelError",
    "RobokinError",
    "Robot",
    "UnreachableError",
    "__version__",
    "load",
    "save",
]

if TYPE_CHECKING:
    from robokin import collision, trajectory  # noqa: F401
    from robokin.kinematics import ik  # noqa: F401


def load(name_or_path: str | Path) -> Robot:
    """Load a built-in robot by name (``robokin.robots.names()``) or a robot file.

    Raises:
        ModelError: unknown name (the message lists the built-in names) or a bad file.
    """
    from robokin import robots

    return robots.load(name_or_path)


def save(robot: Robot, path: str | Path) -> Path:
    """Write a robot file atomically (see :func:`robokin.io.robot_files.save_robot`)."""
    from robokin.io.robot_files import save_robot

    return save_robot(robot, path)


def __getattr__(name: str) -> Any:
    # Lazy subpackages: ``robokin.ik``, ``robokin.trajectory``, ``robokin.collision``,
    # ``robokin.calibration``, ``robokin.io`` (the file readers: PyYAML, pydantic),
    # ``robokin.sim`` (MuJoCo, robokin[sim]), ``robokin.cell`` (Dask, robokin[scale]).
    import importlib

    if name == "ik":
        return importlib.import_module("robokin.kinematics.ik")
    if name in (
        "calibration",
        "cell",
        "trajectory",
        "collision",
        "robots",
        "spatial",
        "viz",
        "kinematics",
        "model",
        "io",
        "sim",
        "planning",
    ):
        return importlib.import_module(f"robokin.{name}")
    raise AttributeError(f"module 'robokin' has no attribute {name!r}")
