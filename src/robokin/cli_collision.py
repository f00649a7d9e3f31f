"""``robokin check``: a joint trajectory against a scene (collision, clearance).

Prints the closest pairs and every collision with its times, optionally writes a
distance-over-time plot, and exits 1 when the trajectory collides or comes closer
than ``--clearance`` (useful in scripts and CI).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from robokin.cli import DomainFailure, app, cell, json_text

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["read_trajectory_csv"]


def read_trajectory_csv(path: str | Path, robot: Robot | None = None) -> tuple[Any, Any]:
    """Times (m,) [s] and joints (m, n) [SI] from a trajectory CSV.

    With ``robot`` the joint columns are matched to its joint names by header
    (any order; see :func:`robokin.trajectory.io.read_csv`).

    Raises:
        ModelError: missing or malformed file, or joint columns that do not match
            the robot (names the file, the line and the expected names).
    """
    from robokin.trajectory.io import read_csv

    if robot is None:
        tr = read_csv(path)
    else:
        tr = read_csv(path, joint_names=robot.joint_names,
                      is_revolute=robot.is_revolute)
    return tr.t, tr.q


@app.command("check", context_settings={"ignore_unknown_options": True})
def check_command(
    scene: Annotated[
        Path, typer.Argument(help="Scene file (YAML), or a bundled name.")
    ],
    trajectory: Annotated[
        Path, typer.Argument(help="Trajectory CSV: t \\[s],<joint> \\[rad]...")
    ],
    robot: Annotated[
        str | None,
        typer.Option(
            "--robot", help="Built-in name or robot file (default: the scene's)."
        ),
    ] = None,
    clearance: Annotated[float, typer.Option(help="Required clearance \\[mm].")] = 0.0,
    plot: Annotated[
        Path | None,
        typer.Option("--plot", help="Write a distance-over-time plot here."),
    ] = None,
    top: Annotated[int, typer.Option(help="How many closest pairs to list.")] = 8,
    as_json: Annotated[
        bool, typer.Option("--json", help="Machine-readable output.")
    ] = False,
) -> None:
    """Check a joint trajectory against a scene: minimum distances and collisions."""
    import robokin
    from robokin import collision
    from robokin.exceptions import InputError

    if top < 0:
        raise InputError("--top", f"expected a count >= 0, got {top}")
    if not math.isfinite(clearance) or clearance < 0:
        raise InputError("--clearance", f"expected a number >= 0 [mm], got {clearance}")
    if not scene.exists() and scene.suffix == "":
        scene = collision.scene_path(str(scene))
    sc = collision.Scene.load(scene)
    name = robot or sc.robot_name
    if name is None:
        raise InputError("--robot", "the scene names no robot; pass --robot")
    rob = robokin.load(name)
    t, q = read_trajectory_csv(trajectory, rob)
    # the report lists pair minima: make them exact too (the default settles them
    # to 1 mm / 1 %, which is all the global minimum needs)
    rep = collision.check(
        rob, sc, q, t=t, clearance=clearance * 1e-3, pair_tolerance=0.0, pair_rtol=0.0
    )
    violated = rep.collides or rep.min_distance <= clearance * 1e-3
    if plot is not None:
        from robokin.collision.plots import plot_distance

        plot_distance(rep, out=plot)
    if as_json:
        c = rep.closest
        print(
            json_text(
                {
                    "min_distance_m": None if c is None else rep.min_distance,
                    "closest": None
                    if c is None
                    else {
                        "body_a": c.body_a,
                        "body_b": c.body_b,
                        "t": c.t,
                        "index": c.index,
                        "point_a": list(map(float, c.point_a)),
                        "point_b": list(map(float, c.point_b)),
                        "between_samples": c.between_samples,
                    },
                    "collides": rep.collides,
                    "clearance_m": rep.clearance,
                    "violated": violated,
                    "collisions": [iv._asdict() for iv in rep.intervals],
                    "pairs": [p._asdict() for p in rep.pairs[:top]],
                },
            )
        )
    else:
        _print_report(rep, clearance, violated, q.shape[0], plot, top)
    if violated:
        what = (
            "collides"
            if rep.collides
            else (
                f"comes within {rep.min_distance * 1e3:.2f} mm (clearance {clearance:g} mm)"
            )
        )
        raise DomainFailure(f"the trajectory {what}")


def _print_report(
    rep, clearance_mm: float, violated: bool, m: int, plot, top: int = 8
) -> None:
    from rich.console import Console
    from rich.markup import escape
    from rich.table import Table

    con = Console()
    table = Table(title=f"closest pairs ({m} samples)")
    for col in ("body", "body", "min distance [mm]", "t [s]", "sample"):
        table.add_column(
            escape(col), justify="right" if "[" in col or col == "sample" else "left"
        )
    for p in rep.pairs[:top]:
        style = "red" if p.distance <= max(clearance_mm * 1e-3, 0.0) else None
        table.add_row(
            cell(p.body_a),
            cell(p.body_b),
            f"{p.distance * 1e3:.2f}",
            f"{p.t:.3f}",
            str(p.index),
            style=style,
        )
    con.print(table)
    if rep.intervals:
        ct = Table(title="collisions")
        for col in (
            "body",
            "body",
            "first",
            "last",
            "t start [s]",
            "t end [s]",
            "depth [mm]",
        ):
            ct.add_column(escape(col))
        for iv in rep.intervals:
            ct.add_row(
                cell(iv.body_a),
                cell(iv.body_b),
                str(iv.first_index),
                str(iv.last_index),
                f"{iv.t_start:.3f}",
                f"{iv.t_end:.3f}",
                f"{-iv.min_distance * 1e3:.2f}"
                + (" (between samples)" if iv.between_samples else ""),
                style="red",
            )
        con.print(ct)
    c = rep.closest
    if c is not None:
        pa = ", ".join(f"{v * 1e3:.1f}" for v in c.point_a)
        pb = ", ".join(f"{v * 1e3:.1f}" for v in c.point_b)
        con.print(
            f"minimum {c.distance * 1e3:.2f} mm between {c.body_a} and {c.body_b} "
            f"at t = {c.t:.3f} s (sample {c.index}); nearest points [mm] "
            f"({pa}) and ({pb})",
            markup=False,
        )
    verdict = "[red]VIOLATED[/red]" if violated else "[green]OK[/green]"
    con.print(f"clearance {clearance_mm:g} mm: {verdict}")
    if plot is not None:
        con.print(f"plot: {plot}", markup=False)
