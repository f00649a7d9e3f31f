"""The ``robokin`` command: the app, its command modules and the entry point.

The command only parses, calls the library and formats.

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

import sys
import traceback
import warnings
from typing import Annotated, Any

import typer
import typer.core

from robokin.cli import (
    actuators,
    calibrate,
    cell,
    collision,
    demo,
    follow,
    ik,
    motion,
    plan,
    retime,
    robots,
    schema,
    self_motion,
    sim,
    urdf,
    view,
    workspace,
)
from robokin.cli.common import DomainFailure

__all__ = ["COMMAND_MODULES", "MULTI_VALUE_OPTIONS", "app", "main"]


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
                if isinstance(param, (typer.core.TyperOption, typer.core.TyperArgument)) \
                        and isinstance(param.help, str):
                    param.help = _literal_help(param.help)


app = typer.Typer(
    cls=_Group,
    add_completion=False,
    no_args_is_help=True,
    help="robokin: kinematics of industrial serial manipulators.",
    pretty_exceptions_enable=False,
)

#: The command modules, in the order ``robokin --help`` lists their commands. Each
#: defines its commands on its own ``commands = typer.Typer()``; adding a module
#: here is how a command joins ``robokin`` (docs/conventions.md, "Where things go").
COMMAND_MODULES = (robots, demo, ik, self_motion, motion, urdf, collision, plan, view, actuators,
                   workspace, sim, retime, schema, cell, follow, calibrate)
for _module in COMMAND_MODULES:
    app.registered_commands.extend(_module.commands.registered_commands)


@app.callback()
def _root(
    debug: Annotated[bool, typer.Option("--debug", help="Show tracebacks.")] = False,
) -> None:
    # --debug is taken out of the arguments by main() (wherever it stands); the
    # option is declared here for --help.
    del debug


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

    args, debug = _split_debug(list(sys.argv[1:] if argv is None else argv))
    args = _gather_values(args)

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

