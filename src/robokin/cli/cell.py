"""``robokin reach`` and ``robokin place``: cell design on Dask (needs ``robokin[scale]``).

``reach`` streams a reachability map into a Zarr store and draws its sections;
``place`` scores candidate robot bases for a task in a scene and maps them on the
floor. Both run on this machine unless ``--scheduler`` names a Dask scheduler
(``tcp://host:8786``; see docs/scale.md). Lengths on the command line are in
millimetres, angles in degrees.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from robokin.cli import output
from robokin.cli.common import DomainFailure, json_text, load_scene
from robokin.cli.options import JsonFlag, RobotName
from robokin.exceptions import InputError
from robokin.io.atomic import check_distinct

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["commands", "MAX_AXIS_VALUES", "MAX_CANDIDATES", "parse_axis", "place_command", "reach_command"]

commands = typer.Typer()

#: ``--connect-timeout``: seconds to reach a ``--scheduler`` address.
ConnectTimeout = Annotated[float | None, typer.Option(
    "--connect-timeout", help="Seconds to reach the --scheduler address and hear it "
    "answer (default 10; a closed port or an address nothing answers from ends "
    "then, exit 2).")]

#: What ``robokin place`` writes into ``--out``.
PLACE_FILES = ("placement.png", "placement.csv", "placement.json")


#: Most values one ``--x``/``--y``/``--z``/``--yaw`` range may give.
MAX_AXIS_VALUES = 10_000
#: Most candidate bases (the product of the four axes) one ``robokin place`` scores.
MAX_CANDIDATES = 1_000_000


def parse_axis(text: str, option: str, scale: float) -> list[float]:
    """Values from ``"a:b:step"`` (inclusive range), ``"a,b,c"`` or ``"a"``, times ``scale``.

    Raises:
        InputError: naming ``option`` and the real problem: not numbers, a step
            <= 0, a range that runs backwards, more than :data:`MAX_AXIS_VALUES`
            values (how many it would give), or a value that is not finite.
    """
    if ":" in text:
        values = _axis_range(text, option)
    else:
        try:
            values = [float(v) for v in text.split(",")]
        except ValueError:
            raise InputError(
                option, f"expected 'from:to:step', 'a,b,c' or a number, got {text!r}"
            ) from None
        if len(values) > MAX_AXIS_VALUES:
            raise InputError(option, f"{len(values):,} values; at most "
                             f"{MAX_AXIS_VALUES:,}")
    if not values or not all(math.isfinite(v) for v in values):
        raise InputError(option, f"expected finite numbers, got {text!r}")
    return [round(v * scale, 12) for v in values]


def _axis_range(text: str, option: str) -> list[float]:
    """The values of ``"from:to:step"``, or an InputError saying what is wrong."""
    parts = text.split(":")
    try:
        if len(parts) != 3:
            raise ValueError
        a, b, step = (float(v) for v in parts)
    except ValueError:
        raise InputError(option, f"expected 'from:to:step' (three numbers), got "
                         f"{text!r}") from None
    if not all(math.isfinite(v) for v in (a, b, step)):
        raise InputError(option, f"expected finite numbers, got {text!r}")
    if step <= 0:
        raise InputError(option, f"{text!r}: the step must be > 0, got {step:g}")
    if b < a:
        raise InputError(option, f"{text!r} runs backwards: from {a:g} is above to "
                         f"{b:g} (write '{b:g}:{a:g}:{step:g}')")
    span = (b - a) / step  # finite: a, b finite and step > 0, or inf for a tiny step
    if not span + 1 <= MAX_AXIS_VALUES:
        many = f"{math.floor(span + 1e-9) + 1:,}" if math.isfinite(span) else "too many"
        raise InputError(option, f"{text!r} gives {many} values, more than the "
                         f"{MAX_AXIS_VALUES:,} a range may hold: use a larger step "
                         "or a shorter range")
    count = math.floor(span + 1e-9) + 1
    return [a + i * step for i in range(count)]


def _probe(scheduler: str | None, timeout: float | None) -> None:
    """Up front: a --scheduler address that does not answer is exit 2 in seconds."""
    from robokin.cell._scheduler import CONNECT_TIMEOUT, probe_scheduler

    if timeout is not None and not (math.isfinite(timeout) and timeout > 0):
        raise InputError("--connect-timeout", f"expected seconds > 0, got {timeout:g}")
    probe_scheduler(scheduler, CONNECT_TIMEOUT if timeout is None else timeout,
                    argument="--scheduler")


def _scene(name: str | None) -> Any:
    return None if name is None else load_scene(name)


def _out_dir(out: Path) -> Path:
    if out.exists() and not out.is_dir():
        raise InputError("--out", f"{out} is a file, expected a folder")
    if not out.parent.is_dir():
        raise InputError("--out", f"{out}: the folder {out.parent} does not exist")
    out.mkdir(exist_ok=True)
    return out


@commands.command("reach")
def reach_command(
    name: RobotName,
    voxel: Annotated[float, typer.Option("--voxel", help="Voxel edge [mm].")] = 50.0,
    out: Annotated[
        Path, typer.Option("--out", help="Output folder (map.zarr, sections.png, reach.json).")
    ] = Path("robokin-reach"),
    orientations: Annotated[
        int, typer.Option(help="Approach directions per voxel (Fibonacci sphere).")
    ] = 32,
    rolls: Annotated[int, typer.Option(help="Rolls about each approach direction.")] = 1,
    region: Annotated[
        str | None,
        typer.Option(help="x0,y0,z0,x1,y1,z1 [mm] (default: the workspace bounds)."),
    ] = None,
    scene: Annotated[
        str | None, typer.Option(help="Scene (file or bundled name): count collision-free "
                                      "solutions only, robot placed by it.")
    ] = None,
    scheduler: Annotated[
        str | None, typer.Option(help="Dask scheduler address, e.g. tcp://host:8786 "
                                      "(default: this machine).")
    ] = None,
    chunk: Annotated[int | None, typer.Option(help="Voxels per Dask task.")] = None,
    connect_timeout: ConnectTimeout = None,
    manipulability: Annotated[
        bool, typer.Option(help="Compute the best manipulability per voxel.")
    ] = True,
    force: Annotated[
        bool, typer.Option("--force", help="Replace a map.zarr holding another map.")
    ] = False,
    as_json: JsonFlag = False,
    output_format: output.FormatOption = None,
) -> None:
    """Reachability map: which positions the tool reaches, in how many orientations.

    The map streams into OUT/map.zarr (memory stays bounded; running the same
    command again finishes an interrupted map) and OUT/sections.png shows it.
    """
    import robokin
    from robokin.cell import reach_map
    from robokin.cell.grid import check_orientation_count
    from robokin.io.atomic import write_atomic

    fmt = output.resolve_format(output_format, as_json)
    if not (math.isfinite(voxel) and voxel > 0):
        raise InputError("--voxel", f"expected an edge length > 0 [mm], got {voxel:g}")
    check_orientation_count(orientations, rolls, names=("--orientations", "--rolls"))
    _probe(scheduler, connect_timeout)
    box = None
    if region is not None:
        values = parse_axis(region, "--region", 1e-3)
        if len(values) != 6:
            raise InputError("--region", f"expected x0,y0,z0,x1,y1,z1 [mm], got {region!r}")
        box = [values[:3], values[3:]]
    robot = robokin.load(name)
    sc = _scene(scene)
    check_distinct([(out / f, "--out") for f in ("map.zarr", "sections.png", "reach.json")],
                   [(robot.path, "NAME"), (None if sc is None else sc.path, "--scene")])
    folder = _out_dir(out)
    m = reach_map(robot, region=box, voxel=voxel * 1e-3, orientations=orientations,
                  rolls=rolls, scene=sc, scheduler=scheduler, store=folder / "map.zarr",
                  chunk=chunk, manipulability=manipulability, progress=True,
                  overwrite=force)
    png = folder / "sections.png"
    m.plot_sections(path=png)
    summary = {**m.summary(), "store": str(folder / "map.zarr"), "sections": str(png)}
    write_atomic(folder / "reach.json", json_text(summary) + "\n", argument="--out")
    if fmt == "json":
        print(json_text(summary))
        return
    nx, ny, nz = m.grid.shape
    table = output.OutputTable(f"{robot.name}: reachability map ({m.method})",
                               [output.Column(""), output.Column("value")])
    table.add_row("voxels", f"{m.size:,} ({nx} x {ny} x {nz} of {voxel:g} mm)")
    table.add_row("orientations", f"{summary['orientations']} per voxel "
                  f"({summary['ik_evaluations']:,} IK targets)")
    table.add_row("reachable", f"{summary['reachable_voxels']:,} voxels, "
                  f"{summary['reachable_volume_m3']:.4f} m³ (voxel centres reached in "
                  "any orientation tried)")
    table.add_row("every orientation", f"{summary['dexterous_voxels']:,} voxels")
    if summary["manipulability_max"] is not None:
        table.add_row("best manipulability", f"{summary['manipulability_max']:.4g}")
    table.notes += [f"wrote {p}" for p in (folder / "map.zarr", png, folder / "reach.json")]
    output.emit(table, fmt)


@commands.command("place")
def place_command(
    name: RobotName,
    scene: Annotated[
        str | None, typer.Option(help="Scene (file or bundled name); its base is "
                                      "replaced by each candidate.")
    ] = None,
    task: Annotated[
        str, typer.Option(help="'poses' (the scene's named poses, in any order), 'demo' "
                               "(the press-loading motion) or a trajectory CSV "
                               "(joints at the scene's current base).")
    ] = "poses",
    x: Annotated[str | None, typer.Option(help="Base x [mm]: from:to:step or a,b,c "
                                               "(default: the scene's base ± 400 by 100).")] = None,
    y: Annotated[str | None, typer.Option(help="Base y [mm], as --x.")] = None,
    z: Annotated[str | None, typer.Option(help="Base z [mm] (default: the scene's).")] = None,
    yaw: Annotated[str | None, typer.Option(help="Base yaw [deg] (default: the scene's).")] = None,
    clearance: Annotated[float, typer.Option(help="Required clearance [mm].")] = 0.0,
    max_step: Annotated[
        float | None, typer.Option(help="Largest joint step between task poses on one "
                                        "branch [deg] (default 30; none for 'poses').")
    ] = None,
    every: Annotated[int, typer.Option(help="Use every N-th sample of a motion.")] = 10,
    out: Annotated[
        Path, typer.Option("--out", help="Output folder (placement.png, .csv, .json).")
    ] = Path("robokin-place"),
    scheduler: Annotated[
        str | None, typer.Option(help="Dask scheduler address (default: this machine).")
    ] = None,
    connect_timeout: ConnectTimeout = None,
    as_json: JsonFlag = False,
    output_format: output.FormatOption = None,
) -> None:
    """Score candidate robot bases for a task: reach on one branch, clearance, manipulability.

    Exits 1 when no candidate is feasible.
    """
    import numpy as np

    import robokin
    from robokin.cell import base_grid, place
    from robokin.cell.placement import DEFAULT_MAX_STEP
    from robokin.io.atomic import write_atomic

    fmt = output.resolve_format(output_format, as_json)
    if not (math.isfinite(clearance) and clearance >= 0):
        raise InputError("--clearance", f"expected a distance >= 0 [mm], got {clearance:g}")
    if every < 1:
        raise InputError("--every", f"expected a count >= 1, got {every}")
    given = {opt: parse_axis(text, opt, unit) for opt, text, unit in (
        ("--x", x, 1e-3), ("--y", y, 1e-3), ("--z", z, 1e-3), ("--yaw", yaw, math.pi / 180))
        if text}  # up front: a bad range is said before anything is loaded
    _probe(scheduler, connect_timeout)
    robot = robokin.load(name)
    sc = _scene(scene)
    poses, is_set = _task_poses(task, robot, sc, every)
    step = (math.inf if is_set else DEFAULT_MAX_STEP) if max_step is None else \
        math.radians(max_step)
    if not step > 0:
        raise InputError("--max-step", f"expected an angle > 0 [deg], got {max_step}")
    base = np.eye(4) if sc is None else sc.base
    around = [v * 1e-3 for v in range(-400, 401, 100)]
    xs = given.get("--x") or [base[0, 3] + d for d in around]
    ys = given.get("--y") or [base[1, 3] + d for d in around]
    zs = given.get("--z") or [base[2, 3]]
    yaws = given.get("--yaw") or [math.atan2(base[1, 0], base[0, 0])]
    count = len(xs) * len(ys) * len(zs) * len(yaws)
    if count > MAX_CANDIDATES:
        raise InputError("--x", f"--x, --y, --z and --yaw give {len(xs):,} x {len(ys):,} "
                         f"x {len(zs):,} x {len(yaws):,} = {count:,} candidate bases, more "
                         f"than the {MAX_CANDIDATES:,} robokin place scores in one run")
    check_distinct([(out / f, "--out") for f in PLACE_FILES],
                   [(robot.path, "NAME"), (None if sc is None else sc.path, "--scene"),
                    (task if task not in ("poses", "demo") else None, "--task")])
    folder = _out_dir(out)
    pl = place(robot, poses, base_grid(xs, ys, zs, yaws), scene=sc,
               clearance=clearance * 1e-3, scheduler=scheduler, max_step=step,
               progress=True)
    pl.plot_floor(folder / "placement.png", scene=sc, mark=None if sc is None else sc.base)
    pl.write_csv(folder / "placement.csv")
    summary = {**pl.summary(), "files": [str(folder / f) for f in
                                         ("placement.png", "placement.csv", "placement.json")]}
    write_atomic(folder / "placement.json", json_text(summary) + "\n", argument="--out")
    if fmt == "json":
        print(json_text(summary))
    else:
        output.emit(_ranking_table(pl, robot.name, folder), fmt)
    if pl.best_index is None:
        raise DomainFailure(f"no feasible placement among {len(pl.feasible)} candidates: "
                            f"{pl.reasons_text()}")


def _task_poses(task: str, robot: Robot, scene: Any, every: int) -> tuple[Any, bool]:
    """Task poses (N, 4, 4) and whether they are a set (no order) rather than a motion."""
    import numpy as np

    if task == "poses":
        if scene is None or not scene.poses:
            raise InputError("--task", "'poses' needs a --scene with named poses")
        return np.array(list(scene.poses.values())), True
    if task == "demo":
        if scene is None:
            raise InputError("--task", "'demo' needs --scene press")
        from robokin.cli.demo_job import placement_task, plan_press_loading

        traj, _ = plan_press_loading(scene.attach(robot), scene)
        return placement_task(traj, every), False
    from robokin.cli.collision import read_trajectory_csv

    _, q = read_trajectory_csv(Path(task), robot)
    placed = robot if scene is None else scene.attach(robot)
    return placed.fk(q[::every]), False


def _ranking_table(pl: Any, robot_name: str, folder: Path,
                   top: int = 10) -> output.OutputTable:
    """The best ``top`` feasible candidates, then why the others fail and the files."""
    numbers = [output.Column(head, output.general(digits), True) for head, digits in (
        ("x [mm]", 6), ("y [mm]", 6), ("z [mm]", 6), ("yaw [deg]", 6), ("score", 4),
        ("clearance [mm]", 4))]
    table = output.OutputTable(
        f"{robot_name}: {int(pl.feasible.sum())} of {len(pl.feasible)} bases feasible",
        [output.Column("rank", right=True), *numbers])
    for r, c in enumerate(pl.ranking[:top], start=1):
        T = pl.candidates[c]
        table.add_row(r, float(T[0, 3] * 1e3), float(T[1, 3] * 1e3), float(T[2, 3] * 1e3),
                      math.degrees(math.atan2(T[1, 0], T[0, 0])), float(pl.score[c]),
                      float(pl.clearance[c] * 1e3))
    table.notes.append(f"infeasible: {pl.reasons_text()}")
    table.notes += [f"wrote {folder / f}" for f in
                    ("placement.png", "placement.csv", "placement.json")]
    return table
