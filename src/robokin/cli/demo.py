"""The main job: the AUBO-i5 loads a press (``robokin demo``).

It reproduces, on the built-in AUBO-i5 with a parallel gripper, the press-loading
study that motivated robokin: from its zero configuration the arm prepares to
grasp, grasps a workpiece from a fixture, moves to the press opening and places
the workpiece between the dies along a straight final approach, then retracts.

* Via points: zero -> pick approach -> pick -> (lift) pick approach -> press
  approach -> press place; quintic blends between joint via points, Cartesian
  straight lines where the gripper approaches, lifts, enters and retracts.
* Every via pose is solved in closed form (all solutions); the branch taken is the
  solution nearest the scene's taught configuration for that pose (as a
  controller stores a configuration flag with each waypoint), and lines follow
  the nearest closed-form solution sample by sample, so there are no branch flips.
* Sampled every 5 ms (about 25 s, about 5,000 samples), checked against the
  joint position, speed and acceleration limits and, link by link, against the
  press scene (collision and minimum distance, with subdivision between samples).
* The shortest cycle of the same path (:func:`robokin.trajectory.retime`, needs
  ``robokin[retime]``): under the AUBO-i5's limits from its robot file and under
  the demo's own caps, side by side with the planned 24 s; the retimed motion is
  checked against the press again.

Outputs in ``--out`` (default ``./robokin-demo``): ``trajectory.csv`` (time and
joints), ``waypoints.csv`` (the via points in degrees, for reading), the program
the AUBO-i5's controller profile names (``program.waypoints.csv``: every sample in
the controller's joint order and units, for AUBO's SDK waypoint calls; see
:mod:`robokin.trajectory.controllers`), ``joints.png``,
``tool_path.png`` (3D with projections), ``press_views.png`` (the tool path inside
the press, side and top views), ``distance.csv`` and ``distance.png`` (the closest
body pairs over time), ``animation.html`` (the
motion, self-contained), ``report.html`` (one page with all of it) and
``summary.json``. With ``sim=True`` (``robokin demo --sim``) the plan also runs in
MuJoCo: ``sim_*`` files and a "simulated run" section in the report. The command
exits 0 only when the plan is collision-free with at least the required clearance.

With ``place=True`` (``robokin demo --place``) it also asks where else the arm
could stand: robot bases on a 100 mm floor grid within 400 mm of the cell's base are
scored for the same motion (:func:`robokin.cell.place`: one continuous IK branch,
joint limits, clearance, manipulability) and ``placement.png`` maps the feasible
ones (``placement.csv`` lists them all); the cell's own base comes out feasible.

With ``plan=True`` (``robokin demo --plan``) robokin also plans the free moves
itself (:mod:`robokin.cli.demo_plan`: the collision-free planner between the same
configurations, process lines and dwells kept, every move time-optimal under the
robot file's limits) and reports that cycle time next to the hand-made path's
(``planned_trajectory.csv``, a "planned by robokin" row and report section).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import numpy as np
import typer

from robokin import collision
from robokin._validation import check_nonnegative
from robokin.cli.common import DomainFailure, console
from robokin.cli.demo_job import (
    A_MAX,
    DT,
    PLAN,
    V_MAX,
    cycle_times,
    placement_summary,
    plan_press_loading,
    search_placement,
)
from robokin.cli.demo_report import (
    MARKER,
    check_out_dir,
    closest_pair_distances,
    cycle_text,
    demo_summary,
    plot_press_views,
    report_html,
    timing_text,
    write_distance_csv,
)
from robokin.io.atomic import write_atomic
from robokin.io.strict_json import strict_json
from robokin.robots import load as load_robot
from robokin.trajectory import io
from robokin.trajectory.controllers import ControllerProgram, controller_program
from robokin.trajectory.samples import Trajectory
from robokin.viz import plots

if TYPE_CHECKING:
    from rich.progress import Progress

    from robokin.cell.placement import Placement
    from robokin.collision.report import CollisionReport
    from robokin.collision.scene import Scene
    from robokin.robot import Robot
    from robokin.trajectory.samples import LimitReport

__all__ = ["A_MAX", "DT", "PLAN", "V_MAX", "DemoResult", "commands", "plan_press_loading",
           "run_demo"]

commands = typer.Typer()


@dataclass
class DemoResult:
    """What the demo computed (also written to ``summary.json``)."""

    ok: bool
    summary: dict[str, Any]
    files: dict[str, Path] = field(default_factory=dict)
    trajectory: Any = None
    report: CollisionReport | None = None


def _clearance(clearance_mm: float) -> float:
    """The required clearance [m] of the ``--clearance`` value [mm], checked."""
    return check_nonnegative(clearance_mm, "clearance", "a distance >= 0 [mm]") / 1000.0


@dataclass
class _Run:
    """One run's output folder, progress bar, phase timings [s] and files written."""

    out: Path
    bar: Progress
    timings: dict[str, float] = field(default_factory=dict)
    files: dict[str, Path] = field(default_factory=dict)
    started: float = field(default_factory=time.perf_counter)


#: The files of "writing the outputs", in the order they are written.
_OUTPUTS = ("trajectory.csv", "waypoints.csv", "program", "joints.png", "tool_path.png",
            "press_views.png", "distance.csv", "distance.png", "animation.html",
            "report.html")


def _plan_and_check(run: _Run, robot: Robot, bare: Robot, scene: Scene, clearance: float
                    ) -> tuple[Trajectory, list[dict[str, Any]], LimitReport,
                               CollisionReport]:
    """Plan the motion, then check its joint limits and its clearance to the press."""
    bar = run.bar
    t = time.perf_counter()
    task = bar.add_task("planning the motion", total=len(PLAN))
    traj, via = plan_press_loading(
        robot, scene, progress=lambda done, total: bar.update(task, completed=done)
    )
    run.timings["plan"] = time.perf_counter() - t

    t = time.perf_counter()
    task = bar.add_task("checking limits and clearance", total=2)
    limits = traj.check_limits(robot, velocity=V_MAX, acceleration=A_MAX)
    bar.update(task, advance=1)
    report = collision.check(bare, scene, traj, clearance=clearance)  # attaches itself
    bar.update(task, advance=1)
    run.timings["check"] = time.perf_counter() - t
    return traj, via, limits, report


def _place(run: _Run, bare: Robot, scene: Scene, traj: Trajectory, clearance: float,
           scheduler: Any) -> Placement:
    """Score robot bases around the cell's for the motion; the floor map and its CSV."""
    t = time.perf_counter()
    bar = run.bar
    task = bar.add_task("scoring robot placements", total=None)
    placement = search_placement(
        bare, scene, traj, clearance=clearance, scheduler=scheduler,
        progress=lambda d, n: bar.update(task, completed=d, total=n))
    placement.plot_floor(run.out / "placement.png", scene=scene, mark=scene.base)
    run.files["placement.png"] = run.out / "placement.png"
    run.files["placement.csv"] = placement.write_csv(run.out / "placement.csv")
    run.timings["place"] = time.perf_counter() - t
    return placement


def _plan_free_moves(run: _Run, bare: Robot, scene: Scene, traj: Trajectory,
                     clearance: float) -> tuple[Trajectory, dict[str, Any]]:
    """The cycle with its free moves planned by robokin (``--plan``), and its summary."""
    from robokin.cli.demo_plan import planned_cycle

    t = time.perf_counter()
    task = run.bar.add_task("planning the free moves", total=None)
    planned = planned_cycle(bare, scene, traj, PLAN, clearance=clearance, dt=DT)
    run.bar.update(task, completed=1, total=1)
    run.timings["robokin_plan"] = time.perf_counter() - t
    return planned


def _add_planned(run: _Run, summary: dict[str, Any], cycle: dict[str, Any],
                 clearance: float, planned: Trajectory, planned_summary: dict[str, Any]
                 ) -> None:
    """Write ``planned_trajectory.csv``; its summary entry; ``ok`` only if it clears."""
    run.files["planned_trajectory.csv"] = io.write_csv(
        planned, run.out / "planned_trajectory.csv", precision=9, overwrite=True)
    summary["planned_by_robokin"] = {
        **planned_summary, "hand_made_planned_s": cycle.get("planned_s"),
        "hand_made_minimum_s": cycle.get("minimum_s")}
    summary["ok"] = bool(summary["ok"] and not planned_summary["collides"]
                         and planned_summary["min_clearance_mm"] >= clearance * 1000.0)


def _waypoints(traj: Trajectory) -> Trajectory:
    """The samples at the via points (for ``waypoints.csv``)."""
    idx = np.unique(
        np.clip(np.rint((traj.via_times - traj.t[0]) / DT).astype(int), 0, len(traj.t) - 1)
    )
    return Trajectory(traj.t[idx], traj.q[idx], traj.qd[idx], traj.qdd[idx],
                      joint_names=traj.joint_names, is_revolute=traj.is_revolute)


def _write_outputs(run: _Run, robot: Robot, bare: Robot, scene: Scene, traj: Trajectory,
                   report: CollisionReport, clearance: float, html_animation: bool
                   ) -> tuple[ControllerProgram, Callable[[str, Path], None]]:
    """Write the trajectory files, the controller program, the figures, the animation.

    Returns:
        The controller program and ``done(name, path)``, which records a file and
        advances the "writing the outputs" bar (``report.html`` comes last).
    """
    out, bar = run.out, run.bar
    t = time.perf_counter()
    program = controller_program(bare, traj)  # what the robot's controller runs
    program_name = "program" + program.suffix
    task = bar.add_task("writing the outputs", total=len(_OUTPUTS))

    def done(name: str, path: Path) -> None:
        run.files[name] = path
        bar.update(task, advance=1)

    done("trajectory.csv",
         io.write_csv(traj, out / "trajectory.csv", precision=9, overwrite=True))
    deg = io.ControllerProfile(name="aubo_i5 (degrees)", angle_unit="deg")
    done("waypoints.csv", io.write_csv(_waypoints(traj), out / "waypoints.csv",
                                       profile=deg, precision=10, overwrite=True))
    done(program_name, write_atomic(out / program_name, program.text))
    plots.plot_joints(traj, path=out / "joints.png", overwrite=True,
                      title="AUBO-i5 press loading: joints")
    done("joints.png", out / "joints.png")
    plots.plot_tool_path(traj, robot, path=out / "tool_path.png", overwrite=True,
                         title="tool path with projections")
    done("tool_path.png", out / "tool_path.png")
    done("press_views.png", plot_press_views(traj, scene, report, out / "press_views.png"))
    dist = closest_pair_distances(report)
    done("distance.csv", write_distance_csv(traj, dist, out / "distance.csv"))
    from robokin.collision.plots import plot_distance

    pairs = [(p.body_a, p.body_b) for p in report.pairs[: len(dist)]]
    plot_distance(report, pairs, clearance=clearance, out=out / "distance.png")
    done("distance.png", out / "distance.png")
    if html_animation:
        from robokin.viz.html import write_html

        done("animation.html", write_html(out / "animation.html", robot, traj, scene=scene,
                                          report=report, title="AUBO-i5 loads a press"))
    else:
        bar.update(task, advance=1)
    run.timings["write"] = time.perf_counter() - t
    return program, done


def _simulate(run: _Run, summary: dict[str, Any], bare: Robot, scene: Scene,
              traj: Trajectory, report: CollisionReport) -> str:
    """Run the plan in MuJoCo; its summary entry and files; the report's HTML section."""
    from robokin.sim.demo_run import simulated_run

    t = time.perf_counter()
    summary["simulated_run"], sim_files, sim_html = simulated_run(
        bare, scene, traj, run.out, report.min_distance)
    run.files.update({f"sim_{k}": v for k, v in sim_files.items()})
    run.timings["sim"] = time.perf_counter() - t
    return sim_html


def _terminal_table(summary: dict[str, Any], timings: dict[str, float],
                    program_name: str, program: ControllerProgram, report_path: Path,
                    ) -> Any:
    """The rich table printed at the end of the run."""
    from rich.table import Table

    table = Table(title="robokin demo: AUBO-i5 loads a press", show_header=False)
    table.add_column(style="bold", overflow="fold")
    table.add_column(overflow="fold")  # never cut a value
    c = summary["closest"] or {}
    table.add_row(
        "duration",
        f"{summary['duration_s']:.2f} s, {summary['samples']} samples "
        f"at {DT * 1000:.0f} ms",
    )
    table.add_row(
        "peak joint speed",
        "  ".join(f"{v:.1f}" for v in summary["peak_joint_speed_deg_s"]) + " deg/s",
    )
    table.add_row(
        "peak joint acceleration",
        "  ".join(f"{v:.1f}" for v in summary["peak_joint_acceleration_deg_s2"])
        + " deg/s²",
    )
    table.add_row("shortest cycle", cycle_text(summary["cycle_time"]))
    if "planned_by_robokin" in summary:
        from robokin.cli.demo_plan import planned_text

        table.add_row("planned by robokin", planned_text(summary["planned_by_robokin"]))
    table.add_row("joint limit violations", str(len(summary["limit_violations"])))
    table.add_row(
        "minimum clearance",
        f"{summary['min_clearance_mm']:.1f} mm ({c.get('robot_body')} – "
        f"{c.get('scene_body')}, t = {c.get('time_s', float('nan')):.2f} s)",
    )
    table.add_row("required clearance", f"{summary['required_clearance_mm']:.1f} mm")
    table.add_row(
        "collisions",
        "none" if not summary["collisions"] else str(len(summary["collisions"])),
    )
    table.add_row("time", timing_text(timings))
    table.add_row("controller program", f"{program_name}: {program.describe()}")
    if "simulated_run" in summary:
        from robokin.sim.report import speed_text

        sr = summary["simulated_run"]
        table.add_row("simulated run", (
            "max error " + "  ".join(f"{j['max_error']:.3f}" for j in sr["joints"])
            + f" deg; {speed_text(sr['timing']['real_time_factor'])}; "
            + ("PASS" if sr["ok"] else "FAIL")))
    if "placement" in summary:
        ps = summary["placement"]
        table.add_row(
            "placement",
            f"{ps['feasible']} of {ps['candidates']} bases feasible; this cell's base "
            + ("feasible" if ps["cell_base_feasible"] else f"not: {ps['cell_base_reason']}"),
        )
    table.add_row("report", str(report_path))
    return table


def run_demo(
    out: str | Path = "robokin-demo",
    *,
    clearance_mm: float = 4.0,
    view: bool = False,
    force: bool = False,
    console: Any = None,
    html_animation: bool = True,
    sim: bool = False,
    place: bool = False,
    scheduler: Any = None,
    plan: bool = False,
) -> DemoResult:
    """Run the press-loading demo end to end and write its outputs.

    Args:
        out: Output folder (created; a folder with files the demo did not write is
            refused unless ``force``).
        clearance_mm: Required minimum distance to the press cell [mm].
        view: Open the live 3D viewer on the result afterwards (blocks).
        force: Write into a folder that holds other files.
        console: A rich Console for the terminal summary (default: a new one).
        html_animation: Also write ``animation.html``.
        sim: Also run the plan in MuJoCo (``robokin[sim]``): ``sim_*`` files and
            a "simulated run" report section (:mod:`robokin.sim.demo_run`).
        place: Also search the floor around the cell's base for robot placements
            that run the same task (``placement.png``: the map of feasible bases,
            ``placement.csv``; needs ``robokin[scale]``).
        scheduler: Where the placement search runs (None: this machine; a Dask
            scheduler address or client).
        plan: Also plan the free moves with robokin's planner and report that
            cycle time next to the hand-made one (:mod:`robokin.cli.demo_plan`).

    Returns:
        A :class:`DemoResult`; ``ok`` is True only when the plan is collision-free
        with at least the required clearance and inside the joint limits.
    """
    from rich.console import Console
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    clearance = _clearance(clearance_mm)
    out = Path(out)
    check_out_dir(out, force)
    con = console or Console(emoji=False)
    scene = collision.Scene.load(collision.scene_path("press"))
    bare = load_robot("aubo_i5")
    robot = scene.attach(bare)  # base placement, gripper TCP and gripper shapes
    columns = (TextColumn("{task.description:<28}"), BarColumn(),
               TextColumn("{task.completed}/{task.total}"), TimeElapsedColumn())
    with Progress(*columns, console=con, transient=False) as bar:
        run = _Run(out, bar)
        traj, via, limits, report = _plan_and_check(run, robot, bare, scene, clearance)
        t = time.perf_counter()
        cycle = cycle_times(robot, bare, scene, traj, clearance)
        run.timings["retime"] = time.perf_counter() - t
        planned = _plan_free_moves(run, bare, scene, traj, clearance) if plan else None
        placement = _place(run, bare, scene, traj, clearance, scheduler) if place else None
        program, done = _write_outputs(run, robot, bare, scene, traj, report, clearance,
                                       html_animation)
        timings = run.timings
        timings["total"] = time.perf_counter() - run.started
        summary = demo_summary(robot, traj, report, limits, via, clearance, timings)
        if placement is not None:
            summary["placement"] = placement_summary(placement, scene)
        summary["cycle_time"] = cycle
        if planned is not None:
            _add_planned(run, summary, cycle, clearance, *planned)
        program_name = "program" + program.suffix
        summary["controller"] = {"program": program.program, "file": program_name,
                                 "profile": program.profile.name,
                                 "description": program.describe()}
        shown = ("joints.png", "press_views.png", "distance.png", "tool_path.png",
                 "placement.png")
        images = {k: run.files[k] for k in shown if k in run.files}
        sim_html = _simulate(run, summary, bare, scene, traj, report) if sim else ""
        if "planned_by_robokin" in summary:
            from robokin.cli.demo_plan import planned_html

            sim_html = planned_html(summary["planned_by_robokin"]) + sim_html
        timings["total"] = time.perf_counter() - run.started
        summary["timings_s"] = {k: round(v, 3) for k, v in timings.items()}
        report_path = out / "report.html"
        write_atomic(report_path, report_html(summary, images, sim_html))
        done("report.html", report_path)
    write_atomic(out / MARKER, strict_json(summary, indent=2) + "\n")
    run.files["summary.json"] = out / MARKER
    con.print(_terminal_table(summary, timings, program_name, program, report_path))
    con.print(
        ("[bold green]PASS[/]" if summary["ok"] else "[bold red]FAIL[/]")
        + f": outputs in {out}"
    )
    if view:
        from robokin.viz.viewer import view as open_viewer

        con.print("viewer on http://127.0.0.1:8080 (Ctrl-C to stop)")
        open_viewer(robot, traj, scene=scene, report=report)
    return DemoResult(summary["ok"], summary, run.files, traj, report)


@commands.command()
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
    result = run_demo(out=out, clearance_mm=clearance, view=view, force=force,
                      console=console(), sim=sim, place=place, scheduler=scheduler,
                      plan=plan)
    if not result.ok:
        raise DomainFailure("the plan is not collision-free with the required clearance "
                            "(see the report)")
