"""``robokin workspace``: Monte-Carlo workspace of a robot, with plots."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from robokin.cli import app, json_text
from robokin.cli_output import (
    Column,
    FormatOption,
    OutputTable,
    emit,
    fixed,
    resolve_format,
)

__all__ = ["workspace"]


def _refuse_earlier_run(targets: list[Path], out: Path) -> None:
    """Files an earlier run left in ``out`` are replaced only with --force."""
    import os

    from robokin.exceptions import InputError

    there = [p.name for p in targets if os.path.lexists(p)]
    if there:
        raise InputError("--out", f"{out} holds an earlier run's {', '.join(there)}; "
                         "pass --force to replace them, or --out to write elsewhere")


@app.command()
def workspace(
    name: Annotated[str, typer.Argument(help="Built-in name or robot file.")],
    samples: Annotated[
        int, typer.Option("--samples", "-n", help="Joint samples.")
    ] = 1_000_000,
    out: Annotated[
        Path, typer.Option("--out", help="Output folder for the plots.")
    ] = Path("robokin-workspace"),
    voxel_mm: Annotated[
        float, typer.Option("--voxel", help="Voxel edge [mm] (0: the longest extent / 100).")
    ] = 0.0,
    seed: Annotated[int, typer.Option(help="Random seed.")] = 0,
    force: Annotated[bool, typer.Option(
        "--force", help="Replace the files of an earlier run in --out.")] = False,
    as_json: Annotated[
        bool, typer.Option("--json", help="Same as --format json.")
    ] = False,
    output_format: FormatOption = None,
) -> None:
    """Sample the reachable workspace: bounds, volume, XY/XZ sections, manipulability.

    The plots and the summary go into --out; the files of an earlier run there are
    replaced only with --force.
    """
    import numpy as np
    from rich.console import Console
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    import robokin
    from robokin.io.atomic import check_distinct, file_stem, write_atomic
    from robokin.kinematics.workspace import sample_workspace
    from robokin.viz.plots import save_workspace_plots, workspace_plot_paths

    fmt = resolve_format(output_format, as_json)
    as_json = fmt == "json"
    if samples < 1:
        raise typer.BadParameter(f"--samples must be >= 1, got {samples}")
    if not (voxel_mm >= 0 and np.isfinite(voxel_mm)):
        raise typer.BadParameter(f"--voxel must be >= 0 [mm] (0: auto), got {voxel_mm}")
    if out.exists() and not out.is_dir():
        raise typer.BadParameter(f"--out {out} is a file, expected a folder")
    if not out.parent.is_dir():
        raise typer.BadParameter(f"--out {out}: the folder {out.parent} does not exist")
    robot = robokin.load(name)
    check_distinct([(out / f"{file_stem(robot.name)}_workspace{end}", "--out")
                    for end in ("_xy.png", "_xz.png", ".json")], [(robot.path, "NAME")])
    summary_path = Path(out) / f"{file_stem(robot.name)}_workspace.json"
    if not force:
        _refuse_earlier_run([*workspace_plot_paths(robot.name, out), summary_path], out)
    con = Console(stderr=fmt != "table")
    with Progress(
        TextColumn("[bold]sampling[/bold] {task.completed:,.0f}/{task.total:,.0f}"),
        BarColumn(),
        TimeRemainingColumn(),
        console=con,
        transient=fmt != "table",
    ) as bar:
        task = bar.add_task("fk", total=samples)
        ws = sample_workspace(
            robot,
            samples,
            rng=np.random.default_rng(seed),
            voxel_size=voxel_mm / 1000.0 if voxel_mm > 0 else None,
            progress=lambda done, total: bar.update(task, completed=done),
        )
    out.mkdir(exist_ok=True)
    paths = save_workspace_plots(ws, out)
    summary = ws.summary()
    summary["plots"] = [str(p) for p in paths]
    write_atomic(summary_path, json_text(summary) + "\n", argument="--out")
    if as_json:
        print(json_text(summary))
        return
    f1 = fixed(1)
    table = OutputTable(
        f"{robot.name}: workspace of the tool point ({ws.n_samples:,} samples)",
        [Column(""), Column("x [mm]", f1, True), Column("y [mm]", f1, True),
         Column("z [mm]", f1, True)])
    for label, row in (
        ("min", ws.bounds[0]),
        ("max", ws.bounds[1]),
        ("extent", ws.extent),
    ):
        table.add_row(label, *(float(v * 1000) for v in row))
    table.notes.append(
        f"volume ≈ {ws.volume:.4f} m³ ({ws.occupied_voxels:,} voxels of "
        f"{ws.voxel_size * 1000:.1f} mm)")
    table.notes += [f"wrote {p}" for p in [*paths, summary_path]]
    emit(table, fmt)
