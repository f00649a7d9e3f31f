"""The command-line options and arguments many commands share, declared once.

Each is an ``Annotated`` type a command's parameter takes with its default, e.g.
``deg: DegFlag = False`` (typer reads the declaration); the command-specific ones
stay in the command modules. ``--format`` is :data:`robokin.cli.output.FormatOption`.
"""

from __future__ import annotations

from typing import Annotated

import typer

__all__ = ["DegFlag", "JsonFlag", "MmFlag", "NoPlotFlag", "PitchArg", "RobotName", "RollArg",
           "XArg", "YArg", "YawArg", "ZArg"]

#: The robot argument: a built-in name or a robot file.
RobotName = Annotated[str, typer.Argument(help="Built-in name or robot file.")]
#: ``--deg``: angles in degrees (default radians).
DegFlag = Annotated[bool, typer.Option("--deg", help="Angles in degrees.")]
#: ``--mm``: lengths in millimetres (default metres).
MmFlag = Annotated[bool, typer.Option("--mm", help="Lengths in millimetres.")]
#: ``--json``: the same as ``--format json``.
JsonFlag = Annotated[bool, typer.Option("--json", help="Same as --format json.")]
#: ``--no-plot``: write no plot.
NoPlotFlag = Annotated[bool, typer.Option("--no-plot", help="Write no plot.")]

#: The tool pose ``x y z roll pitch yaw`` as six positional arguments (``robokin ik``,
#: ``robokin self-motion``; :func:`robokin.cli.common.tool_pose` reads them).
XArg = Annotated[float, typer.Argument(help="Tool position x.")]
YArg = Annotated[float, typer.Argument(help="Tool position y.")]
ZArg = Annotated[float, typer.Argument(help="Tool position z.")]
RollArg = Annotated[float, typer.Argument(help="Roll (about x).")]
PitchArg = Annotated[float, typer.Argument(help="Pitch (about y).")]
YawArg = Annotated[float, typer.Argument(help="Yaw (about z).")]
