"""The ``robokin`` command. It only parses, calls the library and formats.

Radians and metres unless ``--deg`` / ``--mm`` is given. Errors are one line on
stderr (traceback with ``--debug``). Exit codes: 0 success, 1 domain failure (IK
found nothing, collision, clearance violated), 2 usage error.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Annotated

import typer

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="robokin: kinematics of industrial serial manipulators.",
    pretty_exceptions_enable=False,
)

_DEBUG = {"on": False}


class DomainFailure(Exception):
    """A command ran but its answer is 'no' (exit code 1)."""


@app.callback()
def _root(
    debug: Annotated[bool, typer.Option("--debug", help="Show tracebacks.")] = False,
) -> None:
    _DEBUG["on"] = debug


def _console():
    from rich.console import Console

    return Console()


def _load(name: str):
    import robokin

    return robokin.load(name)


@app.command()
def robots() -> None:
    """List the built-in robots."""
    from rich.table import Table

    import robokin.robots as lib

    table = Table(title="built-in robots")
    for col in ("name", "joints", "source"):
        table.add_column(col)
    for name in lib.names():
        r = _load(name)
        table.add_row(name, str(r.n), (r.source or "")[:70])
    _console().print(table)


@app.command()
def show(
    name: Annotated[str, typer.Argument(help="Built-in name or robot file.")],
) -> None:
    """Show a robot: its joints, limits and the canonical chain's tool pose at zero."""
    import numpy as np
    from rich.table import Table

    from robokin.io.robot_files import document_from_robot

    r = _load(name)
    doc = document_from_robot(r)
    units = doc.get("units", {})
    table = Table(
        title=f"{r.name}: {doc.get('convention', '?')} "
        f"({units.get('length', 'm')}, {units.get('angle', 'rad')})"
    )
    rows = doc["joints"]
    keys = []
    for row in rows:
        for k in row:
            if k not in keys:
                keys.append(k)
    for k in keys:
        table.add_column(k)
    for row in rows:
        table.add_row(*[str(row.get(k, "")) for k in keys])
    con = _console()
    con.print(table)
    lim = Table(title="joint limits (deg / mm)")
    for col in ("joint", "kind", "lower", "upper"):
        lim.add_column(col)
    for c, (lo, hi) in zip(r.chain.coordinates, r.limits):
        s = 180 / math.pi if c.kind == "revolute" else 1000.0
        lim.add_row(c.name, c.kind, f"{lo * s:.6g}", f"{hi * s:.6g}")
    con.print(lim)
    if r.actuators is not None:
        act = Table(title="actuators: q = A phi + b")
        act.add_column("A")
        act.add_column("b")
        for row_a, b in zip(r.actuators.matrix, r.actuators.offset):
            act.add_row(np.array2string(row_a, precision=6), f"{b:.6g}")
        con.print(act)
    T0 = r.fk(np.zeros(r.n))
    con.print(
        "tool at q = 0 [m]: " + "  ".join(f"{v:.6f}" for v in T0[:3, 3]), markup=False
    )
    if r.source:
        con.print(f"[dim]source: {r.source}[/dim]")


_NUMERIC_ARGS = {"ignore_unknown_options": True}


@app.command(context_settings=_NUMERIC_ARGS)
def fk(
    name: Annotated[str, typer.Argument(help="Built-in name or robot file.")],
    q: Annotated[list[float], typer.Argument(help="Joint values (rad, m).")],
    deg: Annotated[bool, typer.Option("--deg", help="Angles in degrees.")] = False,
    mm: Annotated[bool, typer.Option("--mm", help="Lengths in millimetres.")] = False,
    as_json: Annotated[
        bool, typer.Option("--json", help="Machine-readable output.")
    ] = False,
) -> None:
    """Forward kinematics: the tool pose as a matrix, position and RPY."""
    import numpy as np

    from robokin.spatial import rpy_from_matrix

    r = _load(name)
    if len(q) != r.n:
        raise typer.BadParameter(f"{r.name} has {r.n} joints, got {len(q)} values")
    qv = np.array(q, dtype=float)
    rev = r.is_revolute
    if deg:
        qv = np.where(rev, np.radians(qv), qv)
    if mm:
        qv = np.where(~rev, qv / 1000.0, qv)
    T = r.fk(qv)
    rpy = rpy_from_matrix(T)
    L = 1000.0 if mm else 1.0
    A = 180 / math.pi if deg else 1.0
    if as_json:
        print(
            json.dumps(
                {
                    "pose": T.tolist(),
                    "xyz": (T[:3, 3] * L).tolist(),
                    "rpy": (rpy * A).tolist(),
                }
            )
        )
        return
    con = _console()
    con.print(np.array2string(T, precision=6, suppress_small=True))
    lu, au = ("mm" if mm else "m"), ("deg" if deg else "rad")
    con.print(
        f"xyz [{lu}]: " + "  ".join(f"{v:.6f}" for v in T[:3, 3] * L), markup=False
    )
    con.print(f"rpy [{au}]: " + "  ".join(f"{v:.6f}" for v in rpy * A), markup=False)


@app.command()
def demo(
    out: Annotated[Path, typer.Option("--out", help="Output folder.")] = Path("robokin-demo"),
    clearance: Annotated[float, typer.Option(help="Required clearance [mm].")] = 4.0,
    view: Annotated[bool, typer.Option("--view", help="Open the 3D viewer after.")] = False,
    force: Annotated[
        bool, typer.Option("--force", help="Write into a folder holding other files.")
    ] = False,
) -> None:
    """The main job: the AUBO-i5 loads a press (plan, check, plots, HTML report).

    Exits 0 only when the plan is collision-free with at least the required
    clearance and inside the joint limits.
    """
    from robokin.demo import run_demo

    result = run_demo(out=out, clearance_mm=clearance, view=view, force=force,
                      console=_console())
    if not result.ok:
        raise DomainFailure("the plan is not collision-free with the required clearance "
                            "(see the report)")


def _register_extra_commands() -> None:
    """Commands defined in other modules register themselves on ``app``."""
    import importlib

    for mod in (
        "robokin.cli_ik",
        "robokin.cli_motion",
        "robokin.cli_urdf",
        "robokin.cli_collision",
        "robokin.cli_view",
        "robokin.cli_actuators",
        "robokin.cli_workspace",
    ):
        try:
            importlib.import_module(mod)
        except ModuleNotFoundError as exc:
            if exc.name != mod:
                raise


def main(argv: list[str] | None = None) -> int:
    """Entry point: run the app, map errors to one stderr line and an exit code."""
    from robokin.exceptions import RobokinError

    _register_extra_commands()
    args = sys.argv[1:] if argv is None else argv
    debug = "--debug" in args
    try:
        app(args=args, standalone_mode=False)
    except DomainFailure as exc:
        print(f"robokin: {exc}", file=sys.stderr)
        return 1
    except RobokinError as exc:
        if debug:
            raise
        print(f"robokin: error: {exc}", file=sys.stderr)
        return 2 if isinstance(exc, (ValueError, ImportError)) else 1
    except typer.Exit as exc:
        return exc.exit_code
    except typer.Abort:
        print("robokin: aborted", file=sys.stderr)
        return 1
    except Exception as exc:  # usage errors (click's, vendored by typer) and the rest
        if hasattr(exc, "show") and hasattr(exc, "exit_code"):
            exc.show()
            return int(exc.exit_code)
        if debug:
            raise
        print(f"robokin: error: {type(exc).__name__}: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
