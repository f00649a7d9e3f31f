"""Motion in time: time-scaling profiles, joint and Cartesian segments, via-point paths.

Every function returns a :class:`Trajectory` sampled at a fixed ``dt``: times
``t`` (m,) [s] and joint positions, velocities and accelerations (m, n).
"""

from __future__ import annotations

from robokin.trajectory.samples import LimitReport, LimitViolation, Trajectory

__all__ = ["LimitReport", "LimitViolation", "Trajectory"]
