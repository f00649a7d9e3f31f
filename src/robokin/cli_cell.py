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
from typing import Annotated, Any

import typer

from robokin.cli import DomainFailure, app, json_text
from robokin.cli_output import (
    Column,
    FormatOption,
    OutputTable,
    emit,
    general,
    resolve_format,
)
from robokin.exceptions import InputError

__all__ = ["parse_axis", "place_command", "reach_command"]


def parse_axis(text: str, option: str, scale: float) -> list[float]:
    """Values from ``"a:b:step"`` (inclusive range), ``"a,b,c"`` or ``"a"``, times ``scale``.

    Raises:
        InputError: not numbers, a step <= 0, or more than 10,000 values (naming
            ``option``).
    """
    try:
        if ":" in text:
            a, b, step = (float(v) for v in text.split(":"))
            if not (step > 0 and math.isfinite(a + b + step)):
                raise ValueError
            count = math.floor((b - a) / step + 1e-9) + 1
            if count < 1 or count > 10_000:
                raise InputError(option, f"{text!r} gives {count} values (1 to 10,000)")
            values = [a + i * step for i in range(count)]
        else:
            values = [float(v) for v in text.split(",")]
    except ValueError:
        raise InputError(
            option, f"expected 'from:to:step', 'a,b,c' or a number, got {text!r}"
        ) from None
    if not values or not all(math.isfinite(v) for v in values):
        raise InputError(option, f"expected finite numbers, got {text!r}")
    return [round(v * scale, 12) for v in values]


def _scene(name: str | None) -> Any:
    if name is None:
        return None
    from robokin import collision

    path = Path(name)
    if not path.exists() and path.suffix == "":
        path = collision.scene_path(name)
    return collision.Scene.load(path)


def _out_dir(out: Path) -> Path:
    if out.exists() and not out.is_dir():
        raise InputError("--out", f"{out} is a file, expected a folder")
    if not out.parent.is_dir():
        raise InputError("--out", f"{out}: the folder {out.parent} does not exist")
    out.mkdir(exist_ok=True)
    return out


@app.command("reach")
def reach_command(
    name: Annotated[str, typer.Argument(help="Built-in name or robot file.")],
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
    manipulability: Annotated[
        bool, typer.Option(help="Compute the best manipulability per voxel.")
    ] = True,
    force: Annotated[
        bool, typer.Option("--force", help="Replace a map.zarr holding another map.")
    ] = False,
    as_json: Annotated[bool, typer.Option("--json", help="Same as --format json.")] = False,
    output_format: FormatOption = None,
) -> None:
    """Reachability map: which positions the tool reaches, in how many orientations.

    The map streams into OUT/map.zarr (memory stays bounded; running the same
    command again finishes an interrupted map) and OUT/sections.png shows it.
    """
    import robokin
    from robokin.cell import reach_map
    from robokin.io.atomic import write_atomic

    fmt = resolve_format(output_format, as_json)
    if not (math.isfinite(voxel) and voxel > 0):
        raise InputError("--voxel", f"expected an edge length > 0 [mm], got {voxel:g}")
    box = None
    if region is not None:
        values = parse_axis(region, "--region", 1e-3)
        if len(values) != 6:
            raise InputError("--region", f"expected x0,y0,z0,x1,y1,z1 [mm], got {region!r}")
        box = [values[:3], values[3:]]
    robot = robokin.load(name)
    sc = _scene(scene)
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
    table = OutputTable(f"{robot.name}: reachability map ({m.method})",
                        [Column(""), Column("value")])
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
    emit(table, fmt)


@app.command("place")
def place_command(
    name: Annotated[str, typer.Argument(help="Built-in name or robot file.")],
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
    as_json: Annotated[bool, typer.Option("--json", help="Same as --format json.")] = False,
    output_format: FormatOption = None,
) -> None:
    """Score candidate robot bases for a task: reach on one branch, clearance, manipulability.

    Exits 1 when no candidate is feasible.
    """
    import numpy as np

    import robokin
    from robokin.cell import base_grid, place
    from robokin.cell.placement import DEFAULT_MAX_STEP
    from robokin.io.atomic import write_atomic

    fmt = resolve_format(output_format, as_json)
    if not (math.isfinite(clearance) and clearance >= 0):
        raise InputError("--clearance", f"expected a distance >= 0 [mm], got {clearance:g}")
    if every < 1:
        raise InputError("--every", f"expected a count >= 1, got {every}")
    robot = robokin.load(name)
    sc = _scene(scene)
    poses, is_set = _task_poses(task, robot, sc, every)
    step = (math.inf if is_set else DEFAULT_MAX_STEP) if max_step is None else \
        math.radians(max_step)
    if not step > 0:
        raise InputError("--max-step", f"expected an angle > 0 [deg], got {max_step}")
    base = np.eye(4) if sc is None else sc.base
    around = [v * 1e-3 for v in range(-400, 401, 100)]
    xs = parse_axis(x, "--x", 1e-3) if x else [base[0, 3] + d for d in around]
    ys = parse_axis(y, "--y", 1e-3) if y else [base[1, 3] + d for d in around]
    zs = parse_axis(z, "--z", 1e-3) if z else [base[2, 3]]
    yaws = parse_axis(yaw, "--yaw", math.pi / 180) if yaw else \
        [math.atan2(base[1, 0], base[0, 0])]
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
        emit(_ranking_table(pl, robot.name, folder), fmt)
    if pl.best_index is None:
        raise DomainFailure(f"no feasible placement among {len(pl.feasible)} candidates: "
                            f"{pl.reasons_text()}")


def _task_poses(task: str, robot: Any, scene: Any, every: int) -> tuple[Any, bool]:
    """Task poses (N, 4, 4) and whether they are a set (no order) rather than a motion."""
    import numpy as np

    if task == "poses":
        if scene is None or not scene.poses:
            raise InputError("--task", "'poses' needs a --scene with named poses")
        return np.array(list(scene.poses.values())), True
    if task == "demo":
        if scene is None:
            raise InputError("--task", "'demo' needs --scene press")
        from robokin.demo import placement_task, plan_press_loading

        traj, _ = plan_press_loading(scene.attach(robot), scene)
        return placement_task(traj, every), False
    from robokin.cli_collision import read_trajectory_csv

    _, q = read_trajectory_csv(Path(task), robot)
    placed = robot if scene is None else scene.attach(robot)
    return placed.fk(q[::every]), False


def _ranking_table(pl: Any, robot_name: str, folder: Path, top: int = 10) -> OutputTable:
    """The best ``top`` feasible candidates, then why the others fail and the files."""
    table = OutputTable(
        f"{robot_name}: {int(pl.feasible.sum())} of {len(pl.feasible)} bases feasible",
        [Column("rank", right=True), Column("x [mm]", general(6), True),
         Column("y [mm]", general(6), True), Column("z [mm]", general(6), True),
         Column("yaw [deg]", general(6), True), Column("score", general(4), True),
         Column("clearance [mm]", general(4), True)])
    for r, c in enumerate(pl.ranking[:top], start=1):
        T = pl.candidates[c]
        table.add_row(r, float(T[0, 3] * 1e3), float(T[1, 3] * 1e3), float(T[2, 3] * 1e3),
                      math.degrees(math.atan2(T[1, 0], T[0, 0])), float(pl.score[c]),
                      float(pl.clearance[c] * 1e3))
    table.notes.append(f"infeasible: {pl.reasons_text()}")
    table.notes += [f"wrote {folder / f}" for f in
                    ("placement.png", "placement.csv", "placement.json")]
    return table
