"""``robokin robots``, ``robokin show`` and ``robokin fk``: the robots and where they are."""

from __future__ import annotations

import math
import sys
from typing import Annotated

import numpy as np
import typer

from robokin.cli.common import (
    NUMERIC_ARGS,
    console,
    json_text,
    load_robot,
    outside_limits_notes,
)
from robokin.cli.options import DegFlag, MmFlag, RobotName
from robokin.cli.output import (
    Column,
    FormatOption,
    OutputTable,
    emit,
    general,
    resolve_format,
    say,
    tables_json,
)
from robokin.io.robot_files import document_from_robot
from robokin.io.robot_tables import MM_PER_M, joint_rows_mm_deg
from robokin.robots import names as robot_names
from robokin.spatial import rpy_from_matrix

__all__ = ["commands"]

commands = typer.Typer()


@commands.command()
def robots(output_format: FormatOption = None) -> None:
    """List the built-in robots."""
    fmt = resolve_format(output_format)
    table = OutputTable("built-in robots", [Column("name"), Column("joints", right=True),
                                            Column("source")])
    for name in robot_names():
        r = load_robot(name)
        table.add_row(name, r.n, r.source or "")
    if fmt == "json":
        print(json_text({"tables": tables_json([table])}))
    else:
        emit(table, fmt)


@commands.command()
def show(
    name: RobotName,
    output_format: FormatOption = None,
) -> None:
    """Show a robot: its joints, limits and the tool pose at zero, in mm and degrees.

    Every arm is shown in the same units whatever units its robot file declares:
    lengths in mm, angles in degrees (prismatic limits in mm).
    """
    fmt = resolve_format(output_format)
    r = load_robot(name)
    doc = document_from_robot(r)
    keys, rows = joint_rows_mm_deg(doc)
    num = general(10)
    dh = OutputTable(
        f"{r.name}: {doc.get('convention', '?')} (lengths mm, angles deg)",
        [Column(k, fmt=num if k in ("a", "alpha", "d", "theta", "value",
                                     "depends_offset") else str,
                right=k in ("a", "alpha", "d", "theta", "value")) for k in keys],
        rows)
    lim = OutputTable("joint limits (deg / mm)",
                      [Column("joint"), Column("kind"), Column("lower", general(10), True),
                       Column("upper", general(10), True)])
    for c, (lo, hi) in zip(r.chain.coordinates, r.limits):
        s = 180.0 / math.pi if c.kind == "revolute" else MM_PER_M
        lim.add_row(c.name, c.kind, float(lo * s), float(hi * s))
    tables = [dh, lim]
    if r.actuators is not None:
        act = OutputTable("actuators: q = A phi + b (SI units)",
                          [Column(f"A[:, {k}]", general(10), True)
                           for k in range(r.actuators.matrix.shape[1])]
                          + [Column("b", general(10), True)])
        for row_a, b in zip(r.actuators.matrix, r.actuators.offset):
            act.add_row(*[float(v) for v in row_a], float(b))
        tables.append(act)
    tool = r.fk(np.zeros(r.n))[:3, 3] * MM_PER_M
    if fmt == "json":
        print(json_text({"robot": r.name, "units": {"length": "mm", "angle": "deg"},
                         "tool_at_zero_mm": tool.tolist(), "source": r.source,
                         "tables": tables_json(tables)}))
        return
    tables[-1].notes.append("tool at q = 0 [mm]: " + "  ".join(f"{v:.6f}" for v in tool))
    emit(tables, fmt)
    if r.source:
        say(f"source: {r.source}", fmt)


@commands.command(context_settings=NUMERIC_ARGS)
def fk(
    name: RobotName,
    q: Annotated[list[float], typer.Argument(help="Joint values (rad, m).")],
    deg: DegFlag = False,
    mm: MmFlag = False,
    as_json: Annotated[
        bool, typer.Option("--json", help="Machine-readable output.")
    ] = False,
) -> None:
    """Forward kinematics: the tool pose as a matrix, position and RPY.

    With --mm every length is in millimetres (the matrix's translation too), with
    --deg every angle in degrees; --json says which under "units".
    """
    r = load_robot(name)
    if len(q) != r.n:
        raise typer.BadParameter(f"{r.name} has {r.n} joints, got {len(q)} values")
    qv = np.array(q, dtype=float)
    rev = r.is_revolute
    if deg:
        qv = np.where(rev, np.radians(qv), qv)
    if mm:
        qv = np.where(~rev, qv / 1000.0, qv)
    T = r.fk(qv)
    for line in outside_limits_notes(r, qv, deg=deg, mm=mm):
        print(f"robokin: note: {line}", file=sys.stderr)
    rpy = rpy_from_matrix(T)
    L = 1000.0 if mm else 1.0
    A = 180 / math.pi if deg else 1.0
    shown = T.copy()
    shown[:3, 3] *= L  # the matrix in the same length unit as xyz
    lu, au = ("mm" if mm else "m"), ("deg" if deg else "rad")
    if as_json:
        print(
            json_text(
                {
                    "pose": shown.tolist(),
                    "xyz": (T[:3, 3] * L).tolist(),
                    "rpy": (rpy * A).tolist(),
                    "units": {"length": lu, "angle": au},
                }
            )
        )
        return
    con = console()
    con.print(f"tool pose (4x4, translation in {lu}):", markup=False)
    con.print(np.array2string(shown, precision=6, suppress_small=True), markup=False)
    con.print(
        f"xyz [{lu}]: " + "  ".join(f"{v:.6f}" for v in T[:3, 3] * L), markup=False
    )
    con.print(f"rpy [{au}]: " + "  ".join(f"{v:.6f}" for v in rpy * A), markup=False)
