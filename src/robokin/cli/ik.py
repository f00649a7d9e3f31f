"""``robokin ik``: every joint solution for a pose, as a table with flags and FK errors."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Annotated, Any

import typer

from robokin.cli.common import (
    DomainFailure,
    joint_values,
    json_text,
    load_robot,
    tool_pose,
)
from robokin.cli.options import (
    DegFlag,
    JsonFlag,
    MmFlag,
    PitchArg,
    RobotName,
    RollArg,
    XArg,
    YArg,
    YawArg,
    ZArg,
)
from robokin.cli.output import Column, FormatOption, OutputTable, emit, resolve_format
from robokin.exceptions import InputError

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["commands", "ik"]

commands = typer.Typer()


def _held_joints(robot: Robot, items: list[str], A: float, L: float) -> dict[str, float]:
    """``--fixed NAME=VALUE`` options as ``{joint: value [rad, m]}``."""
    held: dict[str, float] = {}
    for item in items:
        name, sep, text = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise InputError("--fixed", f"expected NAME=VALUE, got {item!r}")
        if name not in robot.joint_names:
            raise InputError("--fixed", f"unknown joint {name!r}; joints: "
                             + ", ".join(robot.joint_names))
        try:
            value = float(text)
        except ValueError:
            raise InputError("--fixed", f"expected a number for {name}, got "
                             f"{text!r}") from None
        if not math.isfinite(value):
            raise InputError("--fixed", f"expected a finite number for {name}, got "
                             f"{text!r}")
        revolute = robot.is_revolute[robot.joint_names.index(name)]
        held[name] = value / (A if revolute else L)
    return held


def _continuum_note(robot: Robot, sols: Any, held: dict[str, float]) -> str | None:
    """The note for a redundant arm: the solutions listed are a sample of a continuum.

    None when the pose (and the held joints) leave finitely many solutions.
    """
    mask = str(sols.info.get("mask", "x y z rx ry rz")) if isinstance(
        sols.info, dict) else "x y z rx ry rz"
    constrained = len(mask.split())
    free = robot.n - len(held)
    if free <= constrained:
        return None
    example = next(n for n in reversed(robot.joint_names) if n not in held)
    whole = ("; robokin self-motion gives all of it: its branches and their in-limit "
             "intervals" if robot.n == 7 and not held and constrained == 6 else "")
    return (f"{robot.name} has {free} free joints for {constrained} pose components: "
            f"its solutions form a continuum ({free - constrained}-dimensional "
            f"self-motion) and these are a sample of it; --fixed {example}=VALUE "
            f"holds a joint and lists every solution of the others{whole}")


@commands.command(context_settings={"ignore_unknown_options": True})
def ik(
    name: RobotName,
    x: XArg,
    y: YArg,
    z: ZArg,
    roll: RollArg,
    pitch: PitchArg,
    yaw: YawArg,
    deg: DegFlag = False,
    mm: MmFlag = False,
    near: Annotated[str | None, typer.Option(
        "--near", help="Current joint values q1 ... qn, as many as the robot has "
                       "joints (rad/m, or deg/mm with --deg/--mm).")] = None,
    method: Annotated[str, typer.Option(help="auto | analytic | numeric")] = "auto",
    limits: Annotated[bool, typer.Option("--limits", help="Only solutions inside the "
                                                            "joint limits.")] = False,
    fixed: Annotated[list[str] | None, typer.Option(
        "--fixed", help="NAME=VALUE: hold this joint at VALUE (rad/m, or deg/mm with "
        "--deg/--mm) and solve the others; repeatable. For arms with more joints than "
        "the pose constrains (the Panda's 7), every solution with that joint held.")
    ] = None,
    as_json: JsonFlag = False,
    output_format: FormatOption = None,
) -> None:
    """Inverse kinematics: every solution for the pose x y z roll pitch yaw.

    For an arm with more joints than the pose constrains (the Panda) the solutions
    form a continuum: the table is a sample of it, and --fixed NAME=VALUE holds
    joints to list every solution of the others.
    """
    import numpy as np

    from robokin.kinematics.ik.analytic._common import fk_error

    fmt = resolve_format(output_format, as_json)
    r = load_robot(name)
    L = 1000.0 if mm else 1.0
    A = 180.0 / math.pi if deg else 1.0
    T = tool_pose(x, y, z, roll, pitch, yaw, deg=deg, mm=mm)
    rev = r.is_revolute
    q_near = None if near is None else joint_values(near, r, "--near", deg=deg, mm=mm)
    held = _held_joints(r, fixed or [], A, L)
    options: dict[str, Any] = {"method": method}  # checked by Robot.ik, naming it
    if held:
        options["fixed"] = held
    try:
        sols = r.ik(T, q_near=q_near, **options)
    except InputError as exc:
        if exc.argument != "fixed":
            raise
        raise InputError("--fixed", exc.reason) from None
    continuum = _continuum_note(r, sols, held)
    if limits:
        sols = sols.keep_within_limits()
    q = sols.q[sols.valid]
    dp, dr = fk_error(r.chain, q, T) if len(q) else (np.zeros(0), np.zeros(0))
    flags = {k: v[sols.valid] for k, v in sols.flags.items()}
    branches = {k: np.asarray(v)[sols.valid] for k, v in sols.branches.items()}
    order = np.arange(len(q))
    if q_near is not None and len(q):
        order = np.argsort(sols.distance(q_near)[sols.valid], kind="stable")
    disp = np.where(rev, q * A, q * L)
    status = str(sols.status.item() if isinstance(sols.status, np.ndarray) else sols.status)
    if fmt == "json":
        print(json_text({
            "method": sols.method, "status": status,
            "fixed": {k: float(v * (A if r.is_revolute[r.joint_names.index(k)] else L))
                      for k, v in held.items()},
            "sample_of_continuum": continuum is not None,
            "solutions": [
                {"q": disp[i].tolist(),
                 "flags": {k: bool(v[i]) for k, v in flags.items()},
                 "branches": {k: int(v[i]) for k, v in branches.items()},
                 "position_error_m": float(dp[i]), "rotation_error_rad": float(dr[i])}
                for i in order],
        }))
    elif len(q):
        au, lu = ("deg" if deg else "rad"), ("mm" if mm else "m")
        units = [au if rv else lu for rv in rev]
        table = OutputTable(
            f"{r.name}: {'a sample of ' if continuum else ''}{len(q)} solution(s)"
            f"{' of a continuum' if continuum else ''} [{sols.method}]; angles {au}, "
            f"lengths {lu}",
            [Column("#", right=True),
             *[Column(f"q{j + 1} [{u}]", fmt=lambda v: f"{v:.6f}", right=True)
               for j, u in enumerate(units)],
             Column("branch"), Column("flags"),
             Column("FK err", fmt=lambda v: f"{v:.1e}", right=True)])
        for rank, i in enumerate(order, 1):
            fl = [k for k, v in flags.items() if k != "within_limits" and v[i]]
            if not flags.get("within_limits", np.ones(len(q), bool))[i]:
                fl.append("LIMITS")
            br = "".join(f"{k[0].upper()}{'+' if v[i] > 0 else '-'}"
                          for k, v in branches.items())
            table.add_row(rank, *[float(v) for v in disp[i]], br or "-",
                          ",".join(fl) or "-", float(max(dp[i], dr[i])))
        table.notes.append(
            "FK err: max of position [m] and rotation [rad] error"
            + ("; sorted by distance from --near" if q_near is not None else ""))
        if continuum is not None:
            table.notes.append(continuum)
        emit(table, fmt)
    if not len(q):
        raise DomainFailure(f"no IK solution: {status}")
