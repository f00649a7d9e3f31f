"""The trajectory a motion file describes (the file is read by :mod:`robokin.io.motion_files`).

:func:`plan_from_document` resolves the file's robot, converts its values to SI
units and builds the path with :class:`~robokin.trajectory.path.PathBuilder`;
errors name the motion file's field.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from robokin.exceptions import InputError, ModelError
from robokin.io.motion_files import MAX_MOTION_SAMPLES, check_budget, motion_limits
from robokin.robot import Robot
from robokin.robots import load as load_robot
from robokin.spatial import matrix_from_rpy
from robokin.trajectory.path import PathBuilder
from robokin.trajectory.samples import Trajectory

__all__ = ["plan_from_document"]


def plan_from_document(
    spec: Any, file: Path, progress: Any = None, *,
    max_samples: int = MAX_MOTION_SAMPLES,
) -> tuple[Robot, Trajectory]:
    """Build the trajectory a validated motion file describes: ``(robot, traj)``.

    Args:
        spec: The validated document
            (:func:`robokin.io.motion_files.load_motion_file`).
        file: The motion file (robot files resolve relative to its folder).
        progress: Optional ``progress(done, total)`` per segment.
        max_samples: Most samples the trajectory may hold; checked before any
            sampling.

    Raises:
        ModelError: a field that does not fit the robot, or a motion of more than
            ``max_samples`` samples (file and field named).
        PathError: a line that cannot be followed.
        UnreachableError: a pose with no IK solution.
    """
    source = getattr(spec, "_source", None)
    try:
        return _plan(spec, file, progress, max_samples)
    except ModelError as exc:
        raise (exc if source is None else source.locate(exc)) from None


def _plan(spec: Any, file: Path, progress: Any, max_samples: int
          ) -> tuple[Robot, Trajectory]:
    check_budget(spec, file, max_samples)
    # the builder's argument names -> the motion file's fields
    top = {"v_max": "limits.velocity", "a_max": "limits.acceleration",
           "tool_speed": "tool_speed", "tool_acceleration": "tool_acceleration",
           "dt": "dt", "ik": "ik", "q_start": "start", "max_samples": "dt"}

    @contextmanager
    def fields(where: str | None) -> Iterator[None]:
        """Re-raise a builder's InputError as a ModelError naming the file's field."""
        try:
            yield
        except InputError as exc:
            field = top.get(exc.argument) or (
                f"{where}.{exc.argument}" if where else exc.argument)
            raise ModelError(exc.reason, file=file, field=field) from None

    robot = _robot(spec, file)
    L = 1e-3 if spec.units.length == "mm" else 1.0
    A = math.pi / 180.0 if spec.units.angle == "deg" else 1.0
    jscale = np.where(robot.is_revolute, A, L)

    def joints(values: Sequence[float], field: str) -> np.ndarray:
        if len(values) != robot.n:
            raise ModelError(f"{robot.name} has {robot.n} joints, got {len(values)} "
                             "values", file=file, field=field)
        return np.asarray(values, float) * jscale

    v_max, a_max = motion_limits(spec, robot, file)
    with fields(None):
        pb = PathBuilder(robot, joints(spec.start, "start"), dt=spec.dt,
                         v_max=v_max, a_max=a_max,
                         tool_speed=None if spec.tool_speed is None else spec.tool_speed * L,
                         tool_acceleration=None if spec.tool_acceleration is None
                         else spec.tool_acceleration * L,
                         smooth=spec.smooth, ik=spec.ik, max_samples=max_samples)

    def pose(target: Any, field: str) -> np.ndarray:
        return _target_pose(robot, pb.q_end, target, L, A, file, field)

    total = len(spec.segments)
    for i, st in enumerate(spec.segments):
        field = f"segments[{i}]"
        kinds = [k for k in ("joint", "pose", "line", "dwell") if getattr(st, k) is not None]
        if len(kinds) != 1:
            raise ModelError("needs exactly one of joint, pose, line, dwell", file=file,
                             field=field)
        common = {"label": st.label or f"{kinds[0]} {i + 1}"}
        with fields(field):
            _add_step(pb, st, joints, pose, field, L, common)
        if progress is not None:
            progress(i + 1, total + 1)
    with fields("segments"):
        traj = pb.build()
    if progress is not None:
        progress(total + 1, total + 1)
    return robot, traj


def _robot(spec: Any, file: Path) -> Robot:
    """The motion file's robot: a robot file next to it, or a built-in name."""
    name = spec.robot
    candidate = file.parent / name
    try:
        return load_robot(candidate if candidate.suffix in (".yaml", ".yml")
                          and candidate.exists() else name)
    except ModelError as exc:
        if exc.file is not None:
            raise
        raise ModelError(exc.reason, file=file, field="robot") from None


def _target_pose(robot: Robot, q_end: Any, target: Any, L: float, A: float,
                 file: Path, field: str) -> np.ndarray:
    """The pose a ``pose:`` / ``line:`` target names (rpy kept when omitted)."""
    T = robot.fk(q_end).copy()
    if target.xyz is not None and target.dxyz is not None:
        raise ModelError("give xyz or dxyz, not both", file=file, field=field)
    if target.rpy is not None:
        T[:3, :3] = matrix_from_rpy(np.asarray(target.rpy) * A)[:3, :3]
    if target.xyz is not None:
        T[:3, 3] = np.asarray(target.xyz) * L
    elif target.dxyz is not None:
        T[:3, 3] += np.asarray(target.dxyz) * L
    return T


def _add_step(pb: PathBuilder, st: Any, joints: Callable[[Sequence[float], str], np.ndarray],
              pose: Callable[[Any, str], np.ndarray], field: str, L: float,
              common: dict[str, Any]) -> None:
    """Add one validated motion-file step to the path builder."""
    if st.joint is not None:
        pb.joint(joints(st.joint, f"{field}.joint"), st.duration,
                 profile=st.profile, stop=st.stop, **common)
    elif st.pose is not None:
        pb.pose(pose(st.pose, f"{field}.pose"), st.duration, profile=st.profile,
                stop=st.stop, **common)
    elif st.line is not None:
        pb.line(pose(st.line, f"{field}.line"), st.duration, profile=st.profile,
                speed_in=st.speed_in * L, speed_out=st.speed_out * L, **common)
    else:
        pb.dwell(st.dwell, **common)
