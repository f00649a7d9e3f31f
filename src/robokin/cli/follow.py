"""``robokin follow``: a tool path through every IK branch, then the controller's program.

``robokin follow SCENE PATH --program kuka_krl --out DIR`` reads the scene (its robot,
placement, tool and objects) and the tool path (:mod:`robokin.io.path_files`), asks
:func:`robokin.process.follow` for the joint motion over every IK branch (and the
tool's free rotation, with ``--free-axis z``), and writes into ``DIR``:
``NAME.joints.csv`` (the configuration per waypoint), ``NAME.png``
(:func:`robokin.process.plot_follow`: the tool path with every waypoint green or
red, the joints, the steps and margins), optionally ``NAME.html`` (``--html``: the
3D animation with the waypoints as green / red markers) and one program per ``--program``
(:func:`robokin.trajectory.posts.write_program`). An infeasible path writes the CSV
and the plot (to see where and why) and no program, and exits with code 1.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from robokin.cli.common import (
    NUMERIC_ARGS,
    DomainFailure,
    json_text,
    load_robot,
    load_scene,
    scene_robot,
)
from robokin.cli.options import JsonFlag, NoPlotFlag
from robokin.cli.output import FormatOption, resolve_format

if TYPE_CHECKING:
    import numpy as np

    from robokin.robot import Robot

__all__ = ["commands", "follow_command", "joints_csv_text", "parse_range"]

commands = typer.Typer()


def parse_range(text: str, option: str) -> tuple[float, float]:
    """``"lo:hi"`` [deg] as radians (lo < hi).

    Raises:
        InputError: not two numbers separated by ``:``, or lo >= hi.
    """
    from robokin.exceptions import InputError

    parts = text.split(":")
    try:
        lo, hi = (float(p) for p in parts)
    except ValueError:
        raise InputError(option, f"expected LO:HI in degrees (e.g. -180:180), got "
                         f"{text!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise InputError(option, f"expected LO < HI, finite, got {text!r}")
    return math.radians(lo), math.radians(hi)


def joints_csv_text(robot: Robot, q: np.ndarray, free_angle: np.ndarray,
                    reachable: np.ndarray) -> str:
    """The per-waypoint CSV: waypoint, the joints [deg or mm], free angle [deg], reachable.

    Numbers are written in full (the shortest text that reads back to the same
    float); a waypoint without a configuration has empty joint cells.
    """
    import numpy as np

    scale = np.where(robot.is_revolute, 180.0 / math.pi, 1000.0)
    units = ["deg" if r else "mm" for r in robot.is_revolute]
    head = (["waypoint"] + [f"{n} [{u}]" for n, u in zip(robot.joint_names, units)]
            + ["free_angle [deg]", "reachable"])
    lines = [",".join(head)]
    for k in range(q.shape[0]):
        vals = [repr(float(v)) if np.isfinite(v) else "" for v in q[k] * scale]
        fa = free_angle[k]
        lines.append(",".join([str(k), *vals, repr(math.degrees(fa))
                               if np.isfinite(fa) else "", "1" if reachable[k] else "0"]))
    return "\n".join(lines) + "\n"


def _load_inputs(scene: Path, robot: str | None) -> tuple[Any, Robot, Robot]:
    """The scene, the bare robot and the robot as the scene places it."""
    sc = load_scene(scene)
    bare = load_robot(scene_robot(sc, robot))
    return sc, bare, sc.attach(bare)


@commands.command("follow", context_settings=NUMERIC_ARGS)
def follow_command(
    scene: Annotated[Path, typer.Argument(help="Scene file (YAML), or a bundled name.")],
    path: Annotated[Path, typer.Argument(
        help="Tool path: PATH.csv (x, y, z, roll, pitch, yaw with units) or PATH.yaml.")],
    out: Annotated[Path | None, typer.Option(
        "--out", help="Folder for the joint CSV, the plot and the programs (default: "
        "the tool path's folder; created if missing).")] = None,
    program: Annotated[list[str] | None, typer.Option(
        "--program", help="A controller dialect to write the program in (repeat for "
        "several): kuka_krl, abb_rapid, fanuc_tp, yaskawa_inform, staubli_val3, "
        "kawasaki_as, or a registered one.")] = None,
    robot: Annotated[str | None, typer.Option(
        "--robot", help="Built-in name or robot file (default: the scene's).")] = None,
    free_axis: Annotated[str | None, typer.Option(
        "--free-axis", help="'z': the tool may turn about its own z axis.")] = None,
    free_range: Annotated[str | None, typer.Option(
        "--free-range", help="LO:HI [deg] the tool may turn through (default "
        "-180:180 with --free-axis).")] = None,
    free_step: Annotated[float, typer.Option(
        "--free-step", help="Sampling of the turn [deg].")] = 5.0,
    max_step: Annotated[float, typer.Option(
        "--max-step", help="Largest joint change between waypoints [deg].")
    ] = math.degrees(0.1),
    clearance: Annotated[float, typer.Option(
        "--clearance", help="Distance kept from the scene [mm].")] = 0.0,
    speed: Annotated[float, typer.Option(
        "--speed", help="TCP speed of the program's linear moves [mm/s].")] = 100.0,
    zone: Annotated[float, typer.Option(
        "--zone", help="Blending zone of the program's targets [mm] (0: exact stops).")
    ] = 1.0,
    name: Annotated[str | None, typer.Option(
        "--name", help="Program and file name (default: the tool path's name).")] = None,
    force: Annotated[bool, typer.Option(
        "--force", help="Replace the files of an earlier run.")] = False,
    no_plot: NoPlotFlag = False,
    html: Annotated[bool, typer.Option(
        "--html", help="Also write NAME.html: the motion in 3D with the scene and the "
        "waypoints as green (reachable) / red (not) markers.")] = False,
    as_json: JsonFlag = False,
    output_format: FormatOption = None,
) -> None:
    """Follow a tool path over every IK branch; write the joints, a plot and programs.

    Exit code 1 when the path has no feasible motion (the CSV and the plot still
    show where and why); no program is written then.
    """
    from robokin import process
    from robokin.exceptions import InputError
    from robokin.io.atomic import check_distinct
    from robokin.io.path_files import read_tool_path

    fmt = resolve_format(output_format, as_json)
    dialects = _check_dialects(program or [])
    if free_axis not in (None, "z"):
        raise InputError("--free-axis", f"expected z, got {free_axis!r}")
    if free_range is not None and free_axis is None:
        raise InputError("--free-range", "needs --free-axis z")
    rng = parse_range(free_range or "-180:180", "--free-range") if free_axis else None
    for value, opt in ((free_step, "--free-step"), (max_step, "--max-step"),
                       (speed, "--speed")):
        if not (math.isfinite(value) and value > 0):
            raise InputError(opt, f"expected a positive number, got {value}")
    for value, opt in ((clearance, "--clearance"), (zone, "--zone")):
        if not (math.isfinite(value) and value >= 0):
            raise InputError(opt, f"expected a number >= 0, got {value}")
    sc, bare, placed = _load_inputs(scene, robot)
    folder = out if out is not None else (path.parent if str(path.parent) else Path("."))
    stem = name or path.stem
    targets = _targets(folder, stem, no_plot, html, dialects)
    check_distinct([(p, opt) for p, opt in targets],
                   [(path, "PATH"), (scene, "SCENE"), (bare.path, "--robot")])
    _refuse_existing(targets, force)
    poses = read_tool_path(path)
    res = process.follow(bare, poses, free_axis=free_axis, free_range=rng,
                         free_step=math.radians(free_step),
                         max_step=math.radians(max_step), scene=sc,
                         clearance=clearance * 1e-3)
    written = _write_outputs(placed, res, folder, stem, no_plot, force, dialects,
                             speed * 1e-3, zone * 1e-3, f"{bare.name}: {path.name}",
                             sc if html else None)
    _report(res, poses.shape[0], written, fmt)
    if not res.feasible:
        raise DomainFailure(f"no feasible motion: {res.reason}")


def _check_dialects(given: list[str]) -> list[str]:
    from robokin.exceptions import InputError
    from robokin.trajectory.posts import post_names

    names = post_names()
    out = []
    for d in given:
        key = d.strip().lower().replace("-", "_")
        if key not in names:
            raise InputError("--program", f"unknown dialect {d!r}; available: {names}")
        if key not in out:
            out.append(key)
    return out


def _targets(folder: Path, stem: str, no_plot: bool, html: bool, dialects: list[str]
             ) -> list[tuple[Path, str]]:
    """Every file the command writes, with its option."""
    from robokin.io.atomic import file_stem
    from robokin.trajectory.posts import get_post

    base = file_stem(stem)
    out = [(folder / f"{base}.joints.csv", "--out")]
    if not no_plot:
        out.append((folder / f"{base}.png", "--out"))
    if html:
        out.append((folder / f"{base}.html", "--html"))
    for d in dialects:
        post = get_post(d)
        legal, _ = post.program_name(stem)
        out += [(folder / rel, "--program") for rel in post.file_names(legal)]
    return out


def _refuse_existing(targets: list[tuple[Path, str]], force: bool) -> None:
    import os

    from robokin.exceptions import InputError

    there = [p for p, _ in targets if os.path.lexists(p)]
    if there and not force:
        names = ", ".join(str(p) for p in there[:4]) + (" ..." if len(there) > 4 else "")
        raise InputError("--out", f"{names} exist(s) from an earlier run; pass --force "
                         "to replace, or --out / --name to write elsewhere")


def _write_outputs(robot: Robot, res: Any, folder: Path, stem: str, no_plot: bool,
                   force: bool, dialects: list[str], speed: float, zone: float,
                   title: str, html_scene: Any) -> list[str]:
    """The CSV, the plot and the page (all or none), then the programs (feasible only).

    ``html_scene``: the scene to draw in ``NAME.html``, or None for no page.
    """
    from robokin.exceptions import InputError
    from robokin.io.atomic import file_stem, staged_outputs
    from robokin.process import path_markers, plot_follow
    from robokin.trajectory.posts import write_program
    from robokin.viz.html import animation_html

    if not folder.is_dir():
        try:
            folder.mkdir(parents=False)
        except OSError as exc:
            raise InputError("--out", f"{folder}: cannot create: "
                             f"{exc.strerror or exc}") from None
    reachable = res.waypoints.reachable
    base = file_stem(stem)
    outputs = [(folder / f"{base}.joints.csv", "--out", force)]
    if not no_plot:
        outputs.append((folder / f"{base}.png", "--out", force))
    if html_scene is not None:
        outputs.append((folder / f"{base}.html", "--html", force))
    with staged_outputs(outputs, how="pass --force") as staged:
        staged[0].write_text(joints_csv_text(robot, res.q, res.free_angle, reachable))
        if not no_plot:
            state = "feasible" if res.feasible else res.reason
            fig = plot_follow(res, robot=robot, title=f"{title}: {state}")
            fig.savefig(staged[1], dpi=110)
        if html_scene is not None:
            staged[-1].write_text(animation_html(
                robot, _held(res.q), scene=path_markers(res, scene=html_scene),
                title=title, dt=0.05), encoding="utf-8")
    lines = [f"wrote {p}" for p, _, _ in outputs]
    if not res.feasible:
        return lines
    for d in dialects:
        prog = write_program(robot, res, d, folder, name=stem, force=force, speed=speed,
                             zone=zone)
        lines.append(f"wrote {', '.join(str(p) for p in prog.files)}: {prog.describe()}")
        lines += [f"note: {n}" for n in prog.notes]
    return lines


def _held(q: np.ndarray) -> np.ndarray:
    """The motion for the animation: a waypoint without a configuration holds the last.

    Before the first configuration found, the first one found is held.
    """
    import numpy as np

    ok = np.isfinite(q).all(axis=1)
    if not ok.any():
        return np.zeros((1, q.shape[1]))
    idx = np.maximum.accumulate(np.where(ok, np.arange(q.shape[0]), -1))
    idx[idx < 0] = int(np.argmax(ok))
    return q[idx]


def _report(res: Any, n: int, written: list[str], fmt: str) -> None:
    if fmt == "json":
        print(json_text({"feasible": bool(res.feasible), "waypoints": n,
                         "travel_rad": float(res.travel), "max_step_rad": float(res.max_step),
                         "reason": res.reason, "files": written}))
        return
    from robokin.cli.output import say

    state = "feasible" if res.feasible else "NOT feasible"
    say(f"{n} waypoints: {state}; joint travel {math.degrees(res.travel):.1f} deg, "
        f"largest step {math.degrees(res.max_step):.2f} deg", fmt)
    if not res.feasible:
        say(f"reason: {res.reason}", fmt)
    for line in written:
        say(line, fmt)
