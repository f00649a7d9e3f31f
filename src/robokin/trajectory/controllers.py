"""Controller programs: what a real controller runs, chosen by the robot's profile.

A robot file's ``controller:`` section is a
:class:`~robokin.trajectory.controller_profile.ControllerProfile` (joint order, signs, zero
offsets, units, the controller's joint names) plus ``programs``, the outputs
that controller runs, its default first. Three programs exist, each checked
against its format by the tests (nothing more is claimed):

``urscript``
    A URScript program, ``movej`` to the first sample then one ``servoj`` per
    sample (:func:`~robokin.trajectory.io.ur_script`), for Universal Robots
    controllers; radians, six revolute joints. Checked: its structure, one
    ``servoj`` per sample at the sample period, the values. It has not been run
    on a UR controller or URSim by robokin's tests.
``ros2``
    A ``trajectory_msgs/msg/JointTrajectory`` (YAML, SI, the controller's joint
    names) for any arm with a ROS 2 driver (``joint_trajectory_controller``):
    :mod:`robokin.trajectory.ros2`. Checked: it parses into rosbags' message
    type and serialises to CDR and back.
``waypoints``
    A plain waypoint file: ``#`` comment lines saying the robot, profile, sample
    period and units, then the CSV of :func:`~robokin.trajectory.io.write_csv`
    with the profile applied (time, then the joint values at the sample rate in
    the controller's order, signs, zero offsets and units), for a program that
    feeds them to a vendor SDK (AUBO's SDK takes joint angles in radians, one
    waypoint per call, then a joint-spline track move). Checked: it reads back
    (:func:`read_waypoints`) to the same joint values.

A robot without a ``controller:`` section gets the model's joint order, names
and radians, and the programs ``waypoints`` (default) and ``ros2``; URScript is
written only for a profile that names it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from robokin._text import short_repr
from robokin.exceptions import InputError, ModelError
from robokin.io.atomic import write_atomic
from robokin.trajectory.controller_profile import PROGRAMS, ControllerProfile
from robokin.trajectory.io import csv_text, read_csv, ur_script
from robokin.trajectory.samples import Trajectory

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = [
    "SUFFIXES",
    "ControllerProgram",
    "controller_profile",
    "controller_program",
    "read_waypoints",
    "waypoints_text",
    "write_controller_program",
]

#: File name ending per program.
SUFFIXES = {"urscript": ".script", "ros2": ".ros2.yaml", "waypoints": ".waypoints.csv"}
_DEFAULT_PROGRAMS = ("waypoints", "ros2")


@dataclass(frozen=True)
class ControllerProgram:
    """A program for a controller (:func:`controller_program`).

    Attributes:
        program: ``"urscript"``, ``"ros2"`` or ``"waypoints"``.
        text: The file's text.
        profile: The controller profile it was written with.
        suffix: The file name ending (``.script``, ``.ros2.yaml``,
            ``.waypoints.csv``).
        path: Where it was written (None until written).
    """

    program: str
    text: str
    profile: ControllerProfile
    suffix: str
    path: Path | None = None

    def describe(self) -> str:
        """One line: the program and the profile, e.g. for a terminal summary."""
        what = {"urscript": "URScript servoj program",
                "ros2": "ROS 2 trajectory_msgs/JointTrajectory (YAML)",
                "waypoints": "waypoint file (CSV, every sample)"}[self.program]
        return f"{what}, controller profile '{self.profile.name}'"


def controller_profile(robot: Robot) -> ControllerProfile:
    """The robot file's ``controller:`` section as a profile (a default without one).

    Raises:
        ModelError: a bad ``controller:`` section (naming the robot file).
    """
    raw = robot.meta.get("controller")
    if raw is None:
        return ControllerProfile(name=f"{robot.name} (default)")
    if not isinstance(raw, dict):
        raise ModelError(f"expected a mapping, got {short_repr(raw)}", file=robot.path,
                         field="controller")
    doc = dict(raw)
    doc.setdefault("joints", list(robot.joint_names))
    try:
        return ControllerProfile.from_dict(doc, file=robot.path)
    except ModelError as exc:
        raise ModelError(exc.reason, file=robot.path,
                         field=f"controller.{exc.field}" if exc.field else "controller"
                         ) from None


def _programs(profile: ControllerProfile) -> tuple[str, ...]:
    return profile.programs or _DEFAULT_PROGRAMS


def waypoints_text(traj: Trajectory, joint_names: Sequence[str],
                   profile: ControllerProfile, *, robot_name: str = "") -> str:
    """The waypoint file's text (module docstring): comment lines, then the CSV."""
    units = f"angles in {profile.angle_unit}, lengths in {profile.length_unit}"
    offsets = "none" if profile.offsets is None else \
        "[" + ", ".join(f"{v:.12g}" for v in profile.offsets) + "] rad or m"
    signs = "none" if profile.signs is None else str([int(s) for s in profile.signs])
    head = [f"# robokin waypoints: {robot_name or 'robot'}, controller profile "
            f"'{profile.name}'",
            f"# {len(traj)} samples every {traj.dt:.6g} s; columns in the "
            f"controller's joint order; {units}",
            f"# applied: c = sign * q + offset; signs {signs}; offsets {offsets}"]
    return "\n".join(head) + "\n" + csv_text(traj, joint_names, profile=profile)


def read_waypoints(path: str | Path, profile: ControllerProfile,
                   joint_names: Sequence[str] | None = None) -> Trajectory:
    """Read a waypoint file back to model joint values (the profile undone).

    Raises:
        ModelError: as :func:`~robokin.trajectory.io.read_csv`.
    """
    tr = read_csv(path, profile=profile)
    return tr if joint_names is None else tr.replace(joint_names=tuple(joint_names))


def controller_program(
    robot: Robot,
    traj: Trajectory,
    program: str | None = None,
    *,
    profile: ControllerProfile | None = None,
    stride: int = 1,
) -> ControllerProgram:
    """The program for the robot's controller (the profile's default, or ``program``).

    Args:
        robot: The robot (its ``controller:`` section is the profile).
        traj: A joint-space trajectory of the robot, sampled at a fixed period.
        program: ``"urscript"``, ``"ros2"`` or ``"waypoints"`` (default: the
            profile's first); it must be one the profile lists.
        profile: A profile to use instead of the robot's.
        stride: ROS 2 only: keep every ``stride``-th sample (and the last).

    Returns:
        A :class:`ControllerProgram` (not yet written).

    Raises:
        InputError: an unknown program, one the profile does not list, URScript
            for an arm that is not six revolute joints, a trajectory that does
            not fit the robot.
        ModelError: a bad ``controller:`` section.
    """
    prof = profile or controller_profile(robot)
    runs = _programs(prof)
    kind = runs[0] if program is None else program
    if kind not in PROGRAMS:
        raise InputError("program", f"expected one of {list(PROGRAMS)}, got "
                         f"{short_repr(kind)}")
    if kind not in runs:
        raise InputError("program", f"the controller profile '{prof.name}' of "
                         f"{robot.name} runs {list(runs)}, not {kind}")
    if traj.n != robot.n or traj.space != "joint":
        raise InputError("traj", f"expected a joint-space trajectory of {robot.n} "
                         f"joints, got {traj.n} ({traj.space} space)")
    if kind == "urscript":
        if robot.n != 6 or not np.all(robot.is_revolute):
            raise InputError("program", "URScript drives six revolute joints; "
                             f"{robot.name} has {robot.n} coordinates")
        text = ur_script(traj, profile=prof, program=_identifier(robot.name))
    elif kind == "ros2":
        from robokin.trajectory.ros2 import joint_trajectory_yaml

        text = joint_trajectory_yaml(traj, robot.joint_names, profile=prof,
                                     stride=stride)
    else:
        text = waypoints_text(traj, robot.joint_names, prof, robot_name=robot.name)
    return ControllerProgram(kind, text, prof, SUFFIXES[kind])


def _identifier(name: str) -> str:
    """A URScript ``def`` name from a robot name."""
    ident = "".join(c if c.isalnum() else "_" for c in name).strip("_") or "robot"
    return f"robokin_{ident}"[:60]


def write_controller_program(
    robot: Robot,
    traj: Trajectory,
    path: str | Path,
    program: str | None = None,
    *,
    profile: ControllerProfile | None = None,
    stride: int = 1,
    overwrite: bool = False,
) -> ControllerProgram:
    """Write :func:`controller_program` to ``path`` (atomically).

    Returns:
        The :class:`ControllerProgram`, its ``path`` set.

    Raises:
        InputError: as :func:`controller_program`, or the file exists and
            ``overwrite`` is False.
        ModelError: a bad ``controller:`` section.
    """
    prog = controller_program(robot, traj, program, profile=profile, stride=stride)
    written = write_atomic(path, prog.text, overwrite=overwrite)
    return ControllerProgram(prog.program, prog.text, prog.profile, prog.suffix, written)
