"""``robokin motors`` and ``robokin joints``: convert between joint and motor space.

Radians and metres unless ``--deg`` / ``--mm`` is given (``--deg`` applies to
revolute joints and rotary motors, ``--mm`` to prismatic joints and linear motors).
"""

from __future__ import annotations

import math
from typing import Annotated

import numpy as np
import typer

from robokin.cli import output
from robokin.cli.common import NUMERIC_ARGS, json_text, load_robot
from robokin.cli.options import DegFlag, JsonFlag, MmFlag, RobotName

__all__ = ["commands", "joints", "motors"]

commands = typer.Typer()

_DEG = math.pi / 180.0


def _motor_kinds(robot) -> list[str]:
    if robot.actuators is None:
        return ["rotary" if r else "linear" for r in robot.is_revolute]
    kinds = robot.meta.get("actuator_kinds")
    return list(kinds) if kinds else ["rotary"] * robot.actuators.n_in


def _scales(angular: np.ndarray, deg: bool, mm: bool) -> np.ndarray:
    """Display units per SI unit, per coordinate."""
    return np.where(angular, 1.0 / _DEG if deg else 1.0, 1000.0 if mm else 1.0)


def _units(angular: np.ndarray, deg: bool, mm: bool) -> list[str]:
    return [("deg" if deg else "rad") if a else ("mm" if mm else "m") for a in angular]


def _motor_names(robot) -> list[str]:
    if robot.actuators is None:
        return list(robot.joint_names)
    return list(robot.actuator_names)


def _report(title: str, names: list[str], values: np.ndarray, units: list[str],
            inside: np.ndarray, fmt: str, key: str) -> None:
    if fmt == "json":
        print(json_text({key: values.tolist(), "names": names, "units": units,
                          "within_limits": inside.tolist()}))
        return
    table = output.OutputTable(title, [
        output.Column("name"), output.Column("value", output.general(12), True),
        output.Column("unit"), output.Column("within limits")])
    for nm, v, u, ok in zip(names, values, units, inside):
        table.add_row(nm, float(v), u, "yes" if ok else "no",
                      style=None if ok else "red")
    output.emit(table, fmt)


def _inside(values: np.ndarray, limits: np.ndarray | None) -> np.ndarray:
    if limits is None:
        return np.ones(values.shape, bool)
    return (values >= limits[:, 0] - 1e-9) & (values <= limits[:, 1] + 1e-9)


@commands.command(context_settings=NUMERIC_ARGS)
def motors(
    name: RobotName,
    q: Annotated[list[float], typer.Argument(help="Joint values (rad, m).")],
    deg: DegFlag = False,
    mm: MmFlag = False,
    as_json: JsonFlag = False,
    output_format: output.FormatOption = None,
) -> None:
    """Motor coordinates from joint coordinates: phi = A^+ (q - b)."""
    fmt = output.resolve_format(output_format, as_json)
    r = load_robot(name)
    if len(q) != r.n:
        raise typer.BadParameter(f"{r.name} has {r.n} joints, got {len(q)} values")
    rev = r.is_revolute
    qv = np.array(q, dtype=float) / _scales(rev, deg, mm)
    phi = r.actuators_from_joints(qv)
    angular = np.array([k == "rotary" for k in _motor_kinds(r)])
    lim = r.limits if r.actuators is None else r.actuator_limits
    _report(f"{r.name}: motor coordinates", _motor_names(r),
            phi * _scales(angular, deg, mm), _units(angular, deg, mm),
            _inside(phi, lim), fmt, "phi")
    if fmt != "json" and r.actuators is None:
        output.say("no actuator map: motors drive the joints one to one", fmt)


@commands.command(context_settings=NUMERIC_ARGS)
def joints(
    name: RobotName,
    phi: Annotated[list[float], typer.Argument(help="Motor values (rad, m).")],
    deg: DegFlag = False,
    mm: MmFlag = False,
    as_json: JsonFlag = False,
    output_format: output.FormatOption = None,
) -> None:
    """Joint coordinates from motor coordinates: q = A phi + b."""
    fmt = output.resolve_format(output_format, as_json)
    r = load_robot(name)
    angular = np.array([k == "rotary" for k in _motor_kinds(r)])
    if len(phi) != angular.size:
        raise typer.BadParameter(
            f"{r.name} has {angular.size} motors, got {len(phi)} values")
    pv = np.array(phi, dtype=float) / _scales(angular, deg, mm)
    q = r.joints_from_actuators(pv)
    rev = r.is_revolute
    _report(f"{r.name}: joint coordinates", list(r.joint_names), q * _scales(rev, deg, mm),
            _units(rev, deg, mm), _inside(q, r.limits), fmt, "q")
