"""The ``robokin`` command. It only parses, calls the library and formats.

Radians and metres unless ``--deg`` / ``--mm`` is given. Errors are one line on
stderr (the traceback with ``--debug``, accepted anywhere on the command line);
warnings and notes are one line each, ``robokin: warning: ...``. ``--json``
output is strict JSON: a NaN or infinite number is written ``null`` and listed
with its reason under ``"nulls"``.

Exit codes: 0 success; 1 only for a "no" answer (no IK solution, a collision, a
violated clearance or joint limit); 2 for usage and input errors (a bad option, a
missing, binary, oversized or malformed file, a folder given as a file, a file
that cannot be written); 3 for an internal error (a bug: please report it).
"""

from __future__ import annotations

import math
import sys
import traceback
import warnings
from pathlib import Path
from typing import Annotated, Any

import typer
import typer.core

from robokin.cli_output import FormatOption
from robokin.io.strict_json import strict_json as json_text


def _literal_help(text: str | None) -> str | None:
    """Help text shown as written: rich markup escaped, so ``[mm]`` stays."""
    from rich.markup import escape

    return None if text is None else escape(text.replace("\\[", "["))


class _Group(typer.core.TyperGroup):
    """The command group; help texts are literal (units in brackets are not markup)."""

    def __init__(self, **attrs: Any) -> None:
        """Build the group and escape every command's and parameter's help."""
        super().__init__(**attrs)
        for cmd in self.commands.values():
            cmd.help = _literal_help(cmd.help)
            cmd.short_help = _literal_help(cmd.short_help)
            for param in cmd.params:
                if isinstance(getattr(param, "help", None), str):
                    param.help = _literal_help(param.help)  # type: ignore[attr-defined]


app = typer.Typer(
    cls=_Group,
    add_completion=False,
    no_args_is_help=True,
    help="robokin: kinematics of industrial serial manipulators.",
    pretty_exceptions_enable=False,
)

_DEBUG = {"on": False}


class DomainFailure(Exception):
    """A command ran but its answer is 'no' (exit code 1)."""


def cell(value: Any, limit: int = 60, *, markup: bool = True) -> str:
    r"""Text for a table cell or a line of output, safe to print.

    At most ``limit`` characters, rich markup escaped unless ``markup=False`` (for
    ``print(..., markup=False)``), control characters shown as ``\xNN``: a name or
    a source from a file is never markup or a terminal escape sequence, and never a
    megabyte for rich to wrap. Print it through :func:`robokin.cli_output.console`
    (no emoji codes).
    """
    from rich.markup import escape

    from robokin._text import printable

    text = printable(str(value))
    if len(text) > limit:
        text = text[: limit - 1] + "…"
    return escape(text) if markup else text


@app.callback()
def _root(
    debug: Annotated[bool, typer.Option("--debug", help="Show tracebacks.")] = False,
) -> None:
    _DEBUG["on"] = debug


def _console():
    from robokin.cli_output import console

    return console()


def _load(name: str):
    import robokin

    return robokin.load(name)


@app.command()
def robots(output_format: FormatOption = None) -> None:
    """List the built-in robots."""
    import robokin.robots as lib
    from robokin.cli_output import (
        Column,
        OutputTable,
        emit,
        resolve_format,
        tables_json,
    )

    fmt = resolve_format(output_format)
    table = OutputTable("built-in robots", [Column("name"), Column("joints", right=True),
                                            Column("source")])
    for name in lib.names():
        r = _load(name)
        table.add_row(name, r.n, r.source or "")
    if fmt == "json":
        print(json_text({"tables": tables_json([table])}))
    else:
        emit(table, fmt)


@app.command()
def show(
    name: Annotated[str, typer.Argument(help="Built-in name or robot file.")],
    output_format: FormatOption = None,
) -> None:
    """Show a robot: its joints, limits and the tool pose at zero, in mm and degrees.

    Every arm is shown in the same units whatever units its robot file declares:
    lengths in mm, angles in degrees (prismatic limits in mm).
    """
    import numpy as np

    from robokin.cli_output import (
        Column,
        OutputTable,
        emit,
        general,
        resolve_format,
        say,
        tables_json,
    )
    from robokin.io.robot_files import document_from_robot
    from robokin.io.robot_tables import MM_PER_M, joint_rows_mm_deg

    fmt = resolve_format(output_format)
    r = _load(name)
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
    """Forward kinematics: the tool pose as a matrix, position and RPY.

    With --mm every length is in millimetres (the matrix's translation too), with
    --deg every angle in degrees; --json says which under "units".
    """
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
    con = _console()
    con.print(f"tool pose (4x4, translation in {lu}):", markup=False)
    con.print(np.array2string(shown, precision=6, suppress_small=True), markup=False)
    con.print(
        f"xyz [{lu}]: " + "  ".join(f"{v:.6f}" for v in T[:3, 3] * L), markup=False
    )
    con.print(f"rpy [{au}]: " + "  ".join(f"{v:.6f}" for v in rpy * A), markup=False)


def outside_limits_notes(robot: Any, q: Any, *, deg: bool = False, mm: bool = False
                         ) -> list[str]:
    """One line per joint of ``q`` (SI, shape (n,)) outside ``robot``'s limits.

    Values and limits in the units the user typed (degrees with ``deg``,
    millimetres with ``mm``); the joint named, its limits given.
    """
    import numpy as np

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


@app.command()
def demo(
    out: Annotated[Path, typer.Option("--out", help="Output folder.")] = Path("robokin-demo"),
    clearance: Annotated[float, typer.Option(help="Required clearance [mm].")] = 4.0,
    view: Annotated[bool, typer.Option("--view", help="Open the 3D viewer after.")] = False,
    force: Annotated[
        bool, typer.Option("--force", help="Write into a folder holding other files.")
    ] = False,
    sim: Annotated[
        bool, typer.Option("--sim", help="Also run the plan in MuJoCo (robokin[sim]).")
    ] = False,
    place: Annotated[
        bool, typer.Option("--place", help="Also map the feasible robot bases (robokin[scale]).")
    ] = False,
    scheduler: Annotated[
        str | None, typer.Option(help="Dask scheduler address for --place (default: this machine).")
    ] = None,
    plan: Annotated[
        bool, typer.Option("--plan", help="Also plan the free moves with robokin's planner "
                           "and compare the cycle time.")
    ] = False,
) -> None:
    """The main job: the AUBO-i5 loads a press (plan, check, plots, HTML report).

    Exits 0 only when the plan is collision-free with at least the required
    clearance and inside the joint limits.
    """
    from robokin.demo import run_demo

    result = run_demo(out=out, clearance_mm=clearance, view=view, force=force,
                      console=_console(), sim=sim, place=place, scheduler=scheduler,
                      plan=plan)
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
        "robokin.cli_sim",
        "robokin.cli_retime",
        "robokin.cli_schema",
        "robokin.cli_cell",
        "robokin.cli_plan",
    ):
        try:
            importlib.import_module(mod)
        except ModuleNotFoundError as exc:
            if exc.name != mod:
                raise


def _split_debug(args: list[str]) -> tuple[list[str], bool]:
    """Remove ``--debug`` wherever it stands (before a ``--`` separator)."""
    end = args.index("--") if "--" in args else len(args)
    head = [a for a in args[:end] if a != "--debug"]
    return head + args[end:], len(head) != end


#: Options that take as many values as the robot has joints (``--near q1 ... qn``).
MULTI_VALUE_OPTIONS = ("--near", "--start", "--goal", "--goal-pose")


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


def _gather_values(args: list[str]) -> list[str]:
    """Join the values after a :data:`MULTI_VALUE_OPTIONS` option into one token.

    ``--near 0 -1.5 1.5`` becomes ``--near=0,-1.5,1.5`` (click options take a fixed
    number of values). The numbers after the option are its values, except those a
    command's required positional arguments still need: ``ik ur5 --near q1..q6 x y z
    r p w`` leaves the last six for the pose.
    """
    if not any(a in MULTI_VALUE_OPTIONS for a in args):
        return args
    group = typer.main.get_command(app)
    commands: dict[str, Any] = getattr(group, "commands", {})
    at = next((i for i, a in enumerate(args) if a in commands), None)
    if at is None:
        return args
    cmd = commands[args[at]]
    with_value = {o for p in cmd.params if p.param_type_name == "option"
                  and not p.is_flag for o in p.opts}
    arguments = [p for p in cmd.params if p.param_type_name == "argument"]
    needed = None if any(p.nargs < 0 for p in arguments) else len(arguments)
    out, gathered, positional, i = list(args[: at + 1]), [], 0, at + 1
    while i < len(args):
        tok = args[i]
        if tok == "--":
            out += args[i:]
            break
        if tok in MULTI_VALUE_OPTIONS:
            j = i + 1
            while j < len(args) and _is_number(args[j]):
                j += 1
            if j > i + 1:
                gathered.append((len(out), args[i + 1: j]))
                out.append(f"{tok}={','.join(args[i + 1: j])}")
                i = j
                continue
        if tok in with_value:
            out += args[i: i + 2]
            i += 2
            continue
        if not tok.startswith("-") or _is_number(tok):
            positional += 1
        out.append(tok)
        i += 1
    if needed is not None and gathered and positional < needed:
        where, values = gathered[-1]
        keep = max(len(values) - (needed - positional), 1)
        opt = out[where].split("=", 1)[0]
        out[where: where + 1] = [f"{opt}={','.join(values[:keep])}", *values[keep:]]
    return out


def _one_line(text: object) -> str:
    return " ".join(str(text).split())


def _show_warning(message: Any, category: type, filename: str, lineno: int,
                  file: Any = None, line: Any = None) -> None:
    print(f"robokin: warning: {_one_line(message)}", file=sys.stderr)


def main(argv: list[str] | None = None) -> int:
    """Entry point: run the app, map errors to one stderr line and an exit code.

    Exit codes: 0 success, 1 a "no" answer (:class:`DomainFailure`, an
    :class:`~robokin.exceptions.UnreachableError`), 2 usage and input errors, 3
    an internal error. ``--debug`` (anywhere before a ``--``) prints the
    traceback above the one-line message; the exit code is the same.
    """
    from robokin.exceptions import RobokinError, UnreachableError

    # click's classes as this typer raises them (recent typer vendors click)
    # (found at run time, so their attributes are unknown to the type checker)
    mro = typer.BadParameter.__mro__
    click_error: type[Any] = next(c for c in mro if c.__name__ == "ClickException")
    usage_error: type[Any] = next(c for c in mro if c.__name__ == "UsageError")

    _register_extra_commands()
    args, debug = _split_debug(list(sys.argv[1:] if argv is None else argv))
    args = _gather_values(args)
    _DEBUG["on"] = debug

    def fail(code: int, line: str) -> int:
        # --debug adds the traceback; the exit code stays the one of the error
        if debug:
            traceback.print_exc()
        print(line, file=sys.stderr)
        return code

    with warnings.catch_warnings():
        warnings.showwarning = _show_warning
        try:
            app(args=args, standalone_mode=False)
        except DomainFailure as exc:
            return fail(1, f"robokin: {_one_line(exc)}")
        except UnreachableError as exc:
            return fail(1, f"robokin: {_one_line(exc)}")
        except RobokinError as exc:
            return fail(2, f"robokin: error: {_one_line(exc)}")
        except typer.Exit as exc:
            return exc.exit_code
        except typer.Abort:
            print("robokin: aborted", file=sys.stderr)
            return 2
        except click_error as exc:  # usage errors: one line, not click's block
            if type(exc).__name__ == "NoArgsIsHelpError":
                return 2  # the help was printed: nothing to add
            hint = ""
            if isinstance(exc, usage_error) and getattr(exc, "ctx", None) is not None:
                hint = f" (see: {exc.ctx.command_path} --help)"
            return fail(2, f"robokin: error: {_one_line(exc.format_message())}{hint}")
        except OSError as exc:
            where = f"{exc.filename}: " if getattr(exc, "filename", None) else ""
            return fail(2, f"robokin: error: {where}{_one_line(exc.strerror or exc)}")
        except Exception as exc:  # a bug: say so, in one line
            return fail(3, f"robokin: internal error: {type(exc).__name__}: "
                        f"{_one_line(exc)[:300]}"
                        + ("" if debug else " (run with --debug for the traceback)"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
