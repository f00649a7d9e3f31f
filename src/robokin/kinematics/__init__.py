"""What an arm DOES: forward kinematics, Jacobians, inverse kinematics."""

from __future__ import annotations

import importlib
from types import ModuleType


def __getattr__(name: str) -> ModuleType:
    """``robokin.kinematics.ik`` on first use: ``import robokin`` leaves the solvers out."""
    if name == "ik":
        return importlib.import_module("robokin.kinematics.ik")
    raise AttributeError(f"module 'robokin.kinematics' has no attribute {name!r}")
