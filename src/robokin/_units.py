"""The unit names files may give, and their factors to SI (one table for every reader).

Robot files, their sections, path, motion and scene files and controller profiles
write lengths in ``m`` or ``mm`` and angles in ``rad`` or ``deg``; a reader that
accepts more (``cm``) extends :data:`LENGTH_UNITS` with its own entries.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from types import MappingProxyType

__all__ = ["ANGLE_UNITS", "LENGTH_UNITS"]

#: Length unit name -> metres per unit.
LENGTH_UNITS: Mapping[str, float] = MappingProxyType({"m": 1.0, "mm": 1e-3})
#: Angle unit name -> radians per unit.
ANGLE_UNITS: Mapping[str, float] = MappingProxyType({"rad": 1.0, "deg": math.pi / 180.0})
