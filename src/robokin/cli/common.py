"""What the command modules of ``robokin`` share: errors, safe text, robots, output.

A command module (``robokin/cli/<topic>.py``) defines its commands on its own
``commands = typer.Typer()`` and takes from here what every command needs;
:mod:`robokin.cli.entry` lists the modules and runs the app (see
``docs/conventions.md``, "Where things go").
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from robokin.cli.output import console as _output_console
from robokin.io.strict_json import strict_json as json_text

if TYPE_CHECKING:
    from robokin.collision import Scene
    from robokin.model.parts import RobotParts
    from robokin.robot import Robot

__all__ = ["NUMERIC_ARGS", "DomainFailure", "cell", "console", "joint_values", "json_text",
           "load_robot", "load_scene", "outside_limits_notes", "scene_file", "scene_robot",
           "tool_pose"]

#: ``context_settings`` of commands whose positional arguments are numbers that
#: may be negative (``fk ur5 0 -1.5 ...``).
NUMERIC_ARGS = {"ignore_unknown_options": True}


class DomainFailure(Exception):
    """A command ran but its answer is 'no' (exit code 1)."""


def cell(value: Any, limit: int = 60, *, markup: bool = True) -> str:
    r"""Text for a table cell or a line of output, safe to print.

    At most ``limit`` characters, rich markup escaped unless ``markup=False`` (for
    ``print(..., markup=False)``), control characters shown as ``\xNN``: a name or
    a source from a file is never markup or a terminal escape sequence, and never a
    megabyte for rich to wrap. Print it through :func:`robokin.cli.output.console`
    (no emoji codes).
    """
    from rich.markup import escape

    from robokin._text import printable

    text = printable(str(value))
    if len(text) > limit:
        text = text[: limit - 1] + "…"
    return escape(text) if markup else text


def console() -> Any:
    """The rich console commands print to (stdout; see :func:`robokin.cli.output.console`)."""
    return _output_console()


def load_robot(name: str) -> Robot:
    """A built-in robot by name, or a robot file (``robokin.load``)."""
    from robokin.robots import load

    return load(name)


def tool_pose(x: float, y: float, z: float, roll: float, pitch: float, yaw: float, *,
              deg: bool = False, mm: bool = False) -> np.ndarray:
    """The pose (4, 4) [m] of the arguments ``x y z roll pitch yaw`` in the CLI units.

    Raises:
        typer.BadParameter: a value is not finite (naming it).
    """
    import typer

    from robokin.spatial import pose_from_xyz_rpy

    values = (x, y, z, roll, pitch, yaw)
    for label, v in zip(("x", "y", "z", "roll", "pitch", "yaw"), values):
        if not math.isfinite(v):
            raise typer.BadParameter(f"{label} must be a finite number, got {v}")
    per_m = 1000.0 if mm else 1.0
    per_rad = 180.0 / math.pi if deg else 1.0
    return pose_from_xyz_rpy(np.array(values[:3]) / per_m, np.array(values[3:]) / per_rad)


def joint_values(text: str, robot: Robot, option: str, *, deg: bool = False,
                 mm: bool = False) -> np.ndarray:
    """An option's joint values ``q1 ... qn`` (CLI units, spaces or commas) -> (n,) SI.

    Raises:
        typer.BadParameter: not numbers, or not as many as the robot has joints
            (naming ``option``).
    """
    import typer

    try:
        vals = [float(v) for v in text.replace(",", " ").split()]
    except ValueError:
        raise typer.BadParameter(f"expected {robot.n} numbers, got {text!r}",
                                 param_hint=option) from None
    if len(vals) != robot.n:
        raise typer.BadParameter(f"{option} needs {robot.n} values, got {len(vals)}")
    per_m = 1000.0 if mm else 1.0
    per_rad = 180.0 / math.pi if deg else 1.0
    return np.where(robot.is_revolute, np.array(vals) / per_rad, np.array(vals) / per_m)


def scene_file(spec: str | Path) -> Path:
    """The scene file a SCENE argument names: a file, or a bundled scene (``press``).

    A path that does not exist and has no suffix is a bundled scene's name.
    """
    from robokin import collision

    path = Path(spec)
    if not path.exists() and path.suffix == "":
        path = collision.scene_path(str(spec))
    return path


def load_scene(spec: str | Path) -> Scene:
    """The scene a SCENE argument names (:func:`scene_file`)."""
    from robokin import collision

    return collision.Scene.load(scene_file(spec))


def scene_robot(scene: Scene, robot: str | None) -> str:
    """The robot to use with ``scene``: ``--robot`` if given, else the scene's.

    Raises:
        InputError: neither names a robot (naming ``--robot``).
    """
    from robokin.exceptions import InputError

    name = robot or scene.robot_name
    if name is None:
        raise InputError("--robot", "the scene names no robot; pass --robot")
    return name


def outside_limits_notes(robot: RobotParts, q: npt.ArrayLike, *, deg: bool = False,
                         mm: bool = False) -> list[str]:
    """One line per joint of ``q`` (SI, shape (n,)) outside ``robot``'s limits.

    Values and limits in the units the user typed (degrees with ``deg``,
    millimetres with ``mm``); the joint named, its limits given.
    """
    out = []
    for name, rev, v, (lo, hi) in zip(robot.joint_names, robot.is_revolute,
                                      np.asarray(q, float), robot.limits):
        if lo - 1e-12 <= v <= hi + 1e-12:
            continue
        s, unit = ((180 / math.pi, "deg") if deg else (1.0, "rad")) if rev else \
            ((1000.0, "mm") if mm else (1.0, "m"))
        hint = " (degrees? pass --deg)" if rev and not deg and abs(v) > 2 * math.pi \
            else ""
        out.append(f"joint {cell(name, markup=False)!r} = {v * s:g} {unit} is outside "
                   f"its limits [{lo * s:g}, {hi * s:g}] {unit}{hint}; the pose is "
                   "computed anyway")
    return out
