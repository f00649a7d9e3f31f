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

from robokin.cli.common import DomainFailure, json_text, load_scene, scene_robot
from robokin.cli.options import JsonFlag
from robokin.cli.output import FormatOption, resolve_format

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["commands", "read_trajectory_csv"]

commands = typer.Typer()


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


@commands.command("check", context_settings={"ignore_unknown_options": True})
def check_command(
    scene: Annotated[
        Path, typer.Argument(help="Scene file (YAML), or a bundled name.")
    ],
    trajectory: Annotated[
        Path, typer.Argument(help="Trajectory CSV: t [s],<joint> [rad]...")
    ],
    robot: Annotated[
        str | None,
        typer.Option(
            "--robot", help="Built-in name or robot file (default: the scene's)."
        ),
    ] = None,
    clearance: Annotated[float, typer.Option(help="Required clearance [mm].")] = 0.0,
    plot: Annotated[
        Path | None,
        typer.Option("--plot", help="Write a distance-over-time plot here."),
    ] = None,
    top: Annotated[int, typer.Option(help="How many closest pairs to list.")] = 8,
    as_json: JsonFlag = False,
    output_format: FormatOption = None,
) -> None:
    """Check a joint trajectory against a scene: minimum distances and collisions."""
    import robokin
    from robokin import collision
    from robokin.exceptions import InputError

    fmt = resolve_format(output_format, as_json)
    if top < 0:
        raise InputError("--top", f"expected a count >= 0, got {top}")
    if not math.isfinite(clearance) or clearance < 0:
        raise InputError("--clearance", f"expected a number >= 0 [mm], got {clearance}")
    sc = load_scene(scene)
    rob = robokin.load(scene_robot(sc, robot))
    if plot is not None:
        from robokin.io.atomic import check_distinct

        check_distinct([(plot, "--plot")], [(scene, "SCENE"), (trajectory, "TRAJECTORY"),
                                           (rob.path, "--robot")])
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
    if fmt == "json":
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
        _print_report(rep, clearance, violated, q.shape[0], plot, top, fmt)
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
    rep, clearance_mm: float, violated: bool, m: int, plot, top: int, fmt: str
) -> None:
    from robokin.cli.output import Column, OutputTable, emit, fixed, say

    limit = max(clearance_mm * 1e-3, 0.0)
    pairs = OutputTable(f"closest pairs ({m} samples)", [
        Column("body"), Column("body"), Column("min distance [mm]", fixed(2), True),
        Column("t [s]", fixed(3), True), Column("sample", right=True)])
    for p in rep.pairs[:top]:
        pairs.add_row(p.body_a, p.body_b, p.distance * 1e3, p.t, p.index,
                      style="red" if p.distance <= limit else None)
    tables = [pairs]
    if rep.intervals:
        hits = OutputTable("collisions", [
            Column("body"), Column("body"), Column("first", right=True),
            Column("last", right=True), Column("t start [s]", fixed(3), True),
            Column("t end [s]", fixed(3), True), Column("depth [mm]", fixed(2), True),
            Column("between samples")])
        for iv in rep.intervals:
            hits.add_row(iv.body_a, iv.body_b, iv.first_index, iv.last_index,
                         iv.t_start, iv.t_end, -iv.min_distance * 1e3,
                         "yes" if iv.between_samples else "no", style="red")
        tables.append(hits)
    emit(tables, fmt)
    c = rep.closest
    if c is not None:
        pa = ", ".join(f"{v * 1e3:.1f}" for v in c.point_a)
        pb = ", ".join(f"{v * 1e3:.1f}" for v in c.point_b)
        say(f"minimum {c.distance * 1e3:.2f} mm between {c.body_a} and {c.body_b} "
            f"at t = {c.t:.3f} s (sample {c.index}); nearest points [mm] "
            f"({pa}) and ({pb})", fmt)
    say(f"clearance {clearance_mm:g} mm: {'VIOLATED' if violated else 'OK'}", fmt)
    if plot is not None:
        say(f"plot: {plot}", fmt)
