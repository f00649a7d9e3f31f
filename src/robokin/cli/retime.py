"""``robokin retime``: the shortest cycle of a path within the joint limits.

Reads a motion file (YAML, planned as ``robokin traj`` plans it) or a trajectory
CSV (with ``--robot``), retimes the same path to its minimum cycle time within the
joint speed and acceleration limits, and writes into ``--out``. The limits are, for
each kind, those of the option (``--v-max``, ``--a-max``, ``--j-max``), else the
motion file's ``limits:``, else the robot file's ``rate_limits:``; the command says
which it used (``cycle_time.json`` too, under ``limits.sources``). Files:

* ``retimed.csv`` -- the time-optimal motion (time, joints, velocities,
  accelerations; SI units);
* ``retimed_<T>s.csv`` -- with ``--cycle-time T``, the same path in ``T`` seconds;
* ``bottlenecks.png`` -- each joint's velocity and acceleration against its limits;
* ``cycle_time.json`` -- the report: planned, minimum, per section the limiting
  joint and limit, every bottleneck stretch, the margins at ``T``.

Exit codes: 0; 1 when ``--cycle-time`` is shorter than the minimum (the files of
the minimum are still written) or a line of the motion file cannot be followed;
2 for usage and input errors (a bad limit, a robot without limits and none given).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from robokin.cli.common import DomainFailure, cell, json_text
from robokin.cli.options import NoPlotFlag

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["commands", "retime_command"]

commands = typer.Typer()

MARKER = "cycle_time.json"  # a folder holding this was written by robokin retime
_ARGS = {"v_max": "--v-max", "a_max": "--a-max", "j_max": "--j-max",
         "tool_speed": "--tool-speed", "dt": "--dt", "cycle_time": "--cycle-time"}


def _per_joint(text: str | None, option: str, scale: Any) -> Any:
    """``"1.5"`` or ``"1,2,3"`` (one per joint) -> SI array; ``robot`` passes through."""
    import numpy as np

    from robokin.exceptions import InputError

    if text is None:
        return None
    if option == "--j-max" and text.strip().lower() == "robot":
        return "robot"
    try:
        vals = np.array([float(v) for v in text.split(",")])
    except ValueError:
        raise InputError(option, f"expected a number or one per joint separated by "
                         f"commas, got {text!r}") from None
    if vals.size not in (1, scale.size):
        raise InputError(option, f"expected 1 or {scale.size} values, got {vals.size}")
    return vals * scale


def _load(file: Path, robot: str | None) -> tuple[Any, Any, dict[str, Any]]:
    """The robot, the trajectory and the file's own limits (SI; motion files only).

    The limits are ``{"v_max": (n,) or None, "a_max": (n,) or None}`` from a motion
    file's ``limits:``; a trajectory CSV has none.
    """
    import robokin
    from robokin.exceptions import InputError

    suffix = file.suffix.lower()
    if suffix in (".yaml", ".yml"):
        from robokin.io.motion_files import load_motion_file, motion_limits
        from robokin.trajectory import PathError
        from robokin.trajectory.motion_plan import plan_from_document

        if robot is not None:
            raise InputError("--robot", "a motion file names its own robot; --robot is "
                             "for trajectory CSVs")
        spec, path = load_motion_file(file)
        try:
            rob, traj = plan_from_document(spec, path)
        except PathError as exc:
            raise DomainFailure(str(exc)) from None
        v_max, a_max = motion_limits(spec, rob, path)
        return rob, traj, {"v_max": v_max, "a_max": a_max}
    if suffix == ".csv":
        from robokin.trajectory.io import read_csv

        if robot is None:
            raise InputError("--robot", "a trajectory CSV needs --robot (a built-in "
                             "name or a robot file)")
        rob = robokin.load(robot)
        return rob, read_csv(file, joint_names=rob.joint_names,
                             is_revolute=rob.is_revolute), {}
    raise InputError("TRAJ", f"expected a motion file (.yaml) or a trajectory CSV "
                     f"(.csv), got {file.name!r}")


def _choose_limits(options: dict[str, Any], own: dict[str, Any], file: Path,
                   robot: Robot) -> dict[str, str]:
    """Fill ``options`` with the motion file's limits where no option gives one.

    Returns where each limit comes from, for the user: the option, the motion
    file's ``limits:`` or the robot file's ``rate_limits:``.
    """
    robot_file = f"{robot.name}'s robot file (rate_limits:)"
    sources = {}
    for key, kind in (("v_max", "velocity"), ("a_max", "acceleration"),
                      ("j_max", "jerk")):
        if isinstance(options[key], str):  # --j-max robot
            sources[kind] = robot_file
        elif options[key] is not None:
            sources[kind] = _ARGS[key]
        elif own.get(key) is not None:
            options[key] = own[key]
            sources[kind] = f"{file.name} (limits:)"
        elif key != "j_max":
            sources[kind] = robot_file
    if options["tool_speed"] is not None:
        sources["tool speed"] = "--tool-speed"
    return sources


def _sources_line(sources: dict[str, str]) -> str:
    """``limits: velocity and acceleration from m.yaml (limits:)`` (one clause per source)."""
    by: dict[str, list[str]] = {}
    for kind, src in sources.items():
        by.setdefault(src, []).append(kind)
    return "limits: " + "; ".join(f"{' and '.join(kinds)} from {src}"
                                  for src, kinds in by.items())


def _check_out(out: Path, force: bool) -> None:
    from robokin.exceptions import InputError

    if out.exists() and not out.is_dir():
        raise InputError("--out", f"{out} exists and is not a folder")
    if out.is_dir() and any(out.iterdir()) and not (out / MARKER).exists() and not force:
        raise InputError("--out", f"{out} holds files robokin retime did not write; "
                         "choose another --out (or pass --force)")
    out.mkdir(parents=True, exist_ok=True)


def _print(rep: Any, robot: Robot, files: list[Path], sources: dict[str, str]) -> None:
    from rich.table import Table

    from robokin.cli.output import console

    con = console()
    planned = rep.source_duration
    head = f"{cell(robot.name)}: minimum cycle time {rep.minimum_cycle_time:.3f} s"
    if planned is not None:
        head += f" (planned {planned:.3f} s, {planned / rep.minimum_cycle_time:.2f}x)"
    con.print(head)
    con.print(cell(_sources_line(sources), 400, markup=False), markup=False,
              soft_wrap=True)
    table = Table(title="per section")
    cols = ["section", "planned \\[s]", "minimum \\[s]"]
    cols += [] if rep.slower is None else [f"at {rep.cycle_time:g} s \\[s]"]
    for col in cols + ["limited by"]:
        table.add_column(col)
    for k, s in enumerate(rep.sections):
        row = [cell(s.label or f"{s.kind} {k + 1}"),
               "" if math.isnan(s.planned) else f"{s.planned:.3f}", f"{s.minimum:.3f}"]
        row += [] if s.slower is None else [f"{s.slower:.3f}"]
        table.add_row(*row, cell(s.limiting))
    con.print(table)
    if rep.margins is not None:
        con.print(f"retimed to {rep.cycle_time:.3f} s; smallest margins to the "
                  "limits: " + ", ".join(f"{k.replace('_', ' ')} {v.min():.1%}"
                                         for k, v in rep.margins.items()))
    con.print("wrote " + ", ".join(str(f) for f in files), markup=False)


@commands.command("retime", context_settings={"ignore_unknown_options": True})
def retime_command(
    file: Annotated[Path, typer.Argument(
        help="Motion file (YAML) or trajectory CSV.", metavar="TRAJ")],
    out: Annotated[Path, typer.Option("--out", help="Output folder.")] = Path(
        "robokin-retime"),
    robot: Annotated[str | None, typer.Option(
        "--robot", help="Built-in name or robot file (for a CSV).")] = None,
    cycle_time: Annotated[float | None, typer.Option(
        "--cycle-time", help="Also retime to this longer cycle time \\[s].")] = None,
    v_max: Annotated[str | None, typer.Option(
        "--v-max", help="Joint speed limits: one or one per joint, comma separated "
        "\\[rad/s, m/s] (default: the robot file's).")] = None,
    a_max: Annotated[str | None, typer.Option(
        "--a-max", help="Joint acceleration limits \\[rad/s², m/s²].")] = None,
    j_max: Annotated[str | None, typer.Option(
        "--j-max", help="Joint jerk limits \\[rad/s³, m/s³], or 'robot' (default: "
        "none).")] = None,
    tool_speed: Annotated[float | None, typer.Option(
        "--tool-speed", help="Largest tool speed \\[m/s].")] = None,
    deg: Annotated[bool, typer.Option(
        "--deg", help="Angular limits in degrees per second.")] = False,
    mm: Annotated[bool, typer.Option(
        "--mm", help="Linear limits and --tool-speed in millimetres.")] = False,
    dt: Annotated[float, typer.Option("--dt", help="Sampling period \\[s].")] = 0.005,
    no_dwells: Annotated[bool, typer.Option(
        "--no-dwells", help="Drop the dwells (they take no time).")] = False,
    no_plot: NoPlotFlag = False,
    force: Annotated[bool, typer.Option(
        "--force", help="Write into a folder that holds other files.")] = False,
    as_json: Annotated[bool, typer.Option("--json", help="Machine-readable summary.")
                       ] = False,
) -> None:
    """Retime a path to its shortest cycle within the joint limits; report what limits it.

    Exit code 1 when --cycle-time is shorter than the minimum (the minimum's files
    are still written).
    """
    import numpy as np

    from robokin.exceptions import InputError
    from robokin.trajectory.cycle_time import cycle_time_report
    from robokin.trajectory.io import write_csv

    rob, traj, own_limits = _load(file, robot)
    lin = 1e-3 if mm else 1.0
    scale = np.where(rob.is_revolute, math.pi / 180.0 if deg else 1.0, lin)
    options = {"v_max": _per_joint(v_max, "--v-max", scale),
               "a_max": _per_joint(a_max, "--a-max", scale),
               "j_max": _per_joint(j_max, "--j-max", scale),
               "tool_speed": None if tool_speed is None else tool_speed * lin,
               "dt": dt, "keep_dwells": not no_dwells}
    from robokin.io.atomic import check_distinct

    names = ["retimed.csv", MARKER] + ([] if cycle_time is None else
                                       [f"retimed_{cycle_time:g}s.csv"])
    names += [] if no_plot else ["bottlenecks.png"]
    check_distinct([(out / n, "--out") for n in names],
                   [(file, "TRAJ"), (rob.path, "--robot")])
    sources = _choose_limits(options, own_limits, file, rob)
    _check_out(out, force)
    try:
        rep = cycle_time_report(rob, traj, **options)
        too_short = cycle_time is not None and cycle_time < rep.minimum_cycle_time
        if cycle_time is not None and not too_short:
            rep = rep.with_cycle_time(cycle_time)
    except InputError as exc:
        opt = _ARGS.get(exc.argument, exc.argument)
        raise InputError(opt, exc.reason.replace(f"pass {exc.argument}=",
                                                 f"give {opt}")) from None
    files = [write_csv(rep.minimum.trajectory, out / "retimed.csv", rates=True,
                       overwrite=True)]
    if rep.slower is not None:
        files.append(write_csv(rep.slower.trajectory,
                               out / f"retimed_{cycle_time:g}s.csv", rates=True,
                               overwrite=True))
    if not no_plot:
        from robokin.viz.retime_plots import plot_bottlenecks

        files.append(out / "bottlenecks.png")
        plot_bottlenecks(rep, path=files[-1], overwrite=True,
                         title=f"{rob.name}: {file.name}"[:200] + f": minimum cycle "
                         f"time {rep.minimum_cycle_time:.3g} s")
    from robokin.io.atomic import write_atomic

    doc = {"robot": rob.name, "source": str(file), **rep.to_dict(),
           "files": [str(f) for f in files]}
    doc["limits"]["sources"] = sources
    files.append(write_atomic(out / MARKER, json_text(doc, indent=2) + "\n",
                              overwrite=True))
    if as_json:
        print(json_text(doc))
    else:
        _print(rep, rob, files, sources)
    if too_short:
        raise DomainFailure(f"a cycle time of {cycle_time:g} s is shorter than the "
                            f"minimum {rep.minimum_cycle_time:.6g} s of this path "
                            "under these limits")
