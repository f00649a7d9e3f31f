"""Motion in time: time-scaling profiles, joint and Cartesian segments, via-point paths.

Every function returns a :class:`Trajectory` sampled at a fixed ``dt``: times
``t`` (m,) [s] and joint positions, velocities and accelerations (m, n)::

    from robokin import trajectory
    tr = trajectory.quintic(q0, q1, duration=2.0, dt=0.005)
    tr = trajectory.cartesian_line(robot, q_start, T_goal, duration=1.5)
    path = trajectory.PathBuilder(robot, q_home, v_max=2.0, a_max=4.0)
    path.joint(q_via).line(T_goal, duration=1.0)
    tr = path.build()

Profiles (``get_profile(name)``): cubic, quintic, trapezoidal (LSPB), cycloidal,
piecewise_acceleration, modified_sine, constant_velocity. Files: :mod:`.io`;
plan vs real run: :mod:`.compare`. The same path run as fast as the joint limits
allow: :func:`retime` (:mod:`.retiming`, needs ``robokin[retime]``), and the
cycle-time report with its bottlenecks: :mod:`.cycle_time`.
"""

from __future__ import annotations

from robokin.trajectory.cartesian import (
    PathError,
    PathFollowResult,
    cartesian_line,
    follow_poses,
    line_poses,
)
from robokin.trajectory.joint import (
    constant_velocity,
    cubic,
    cycloidal,
    modified_sine,
    piecewise_acceleration,
    profile_motion,
    quintic,
    time_grid,
    trapezoidal,
)
from robokin.trajectory.path import PathBuilder, Segment, via_path
from robokin.trajectory.profiles import PROFILES, Profile, get_profile
from robokin.trajectory.retiming import (
    RetimeLimits,
    RetimeResult,
    SectionTiming,
    retime,
    retime_detailed,
)
from robokin.trajectory.samples import LimitReport, LimitViolation, Trajectory

__all__ = [
    "PROFILES",
    "LimitReport",
    "LimitViolation",
    "PathBuilder",
    "PathError",
    "PathFollowResult",
    "Profile",
    "RetimeLimits",
    "RetimeResult",
    "SectionTiming",
    "Segment",
    "Trajectory",
    "cartesian_line",
    "constant_velocity",
    "cubic",
    "cycloidal",
    "follow_poses",
    "get_profile",
    "line_poses",
    "modified_sine",
    "piecewise_acceleration",
    "profile_motion",
    "quintic",
    "retime",
    "retime_detailed",
    "time_grid",
    "trapezoidal",
    "via_path",
]
