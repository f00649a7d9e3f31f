"""``robokin sim``: run a planned trajectory through the robot's servos in MuJoCo.

Writes the MJCF model, the simulated run, the tracking-error and torque plots,
the contacts and a summary into ``--out``; prints the tracking error per joint
(and its correlation with the plan's acceleration), the peak torques against
the limits, the contacts and the real-time ratio. Exits 1 when the verdict
fails (a joint off its plan by more than the tolerance, a torque over its limit,
or a contact), 2 on bad input.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from robokin.cli.common import DomainFailure, cell, json_text, load_scene
from robokin.cli.options import RobotName

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["commands", "sim_command"]

commands = typer.Typer()


def _read_plan(path: Path, robot: Robot, motors: bool) -> Any:
    from robokin.exceptions import InputError
    from robokin.trajectory.io import read_csv

    if not motors:
        return read_csv(path, joint_names=robot.joint_names,
                        is_revolute=robot.is_revolute)
    if robot.actuators is None:
        raise InputError("--motors", f"{robot.name} has no actuator map (motors)")
    kinds = robot.meta.get("actuator_kinds", ("rotary",) * robot.actuators.n_in)
    tr = read_csv(path, joint_names=robot.actuator_names,
                  is_revolute=[k == "rotary" for k in kinds])
    return tr.replace(space="actuator")


@commands.command("sim", context_settings={"ignore_unknown_options": True})
def sim_command(
    name: RobotName,
    trajectory: Annotated[Path, typer.Argument(
        help="Planned trajectory CSV: t \\[s],<joint> \\[rad|m]... (robokin's format).")],
    out: Annotated[Path, typer.Option("--out", help="Output folder (created).")],
    scene: Annotated[str | None, typer.Option(
        "--scene", help="Scene file or bundled name (robot placement, tool, objects)."
    )] = None,
    motors: Annotated[bool, typer.Option(
        "--motors", help="The CSV holds motor coordinates: drive the motors.")] = False,
    bandwidth: Annotated[float, typer.Option(
        help="Servo bandwidth \\[Hz] of the default gains.")] = 10.0,
    contacts: Annotated[str, typer.Option(
        help="detect (contacts exert no force) or physical.")] = "detect",
    dt: Annotated[float, typer.Option(help="Physics step \\[s] (<= 0.001).")] = 0.001,
    tolerance_deg: Annotated[float, typer.Option(
        "--tolerance-deg", help="Largest tracking error of an angle \\[deg].")] = 0.5,
    tolerance_mm: Annotated[float, typer.Option(
        "--tolerance-mm", help="Largest tracking error of a length \\[mm].")] = 1.0,
    strict: Annotated[bool, typer.Option(
        "--strict", help="Refuse to estimate missing link mass data.")] = False,
    as_json: Annotated[bool, typer.Option("--json", help="Machine-readable output.")
                       ] = False,
) -> None:
    """Co-simulate a plan in MuJoCo: tracking error, torques, contacts, a verdict."""
    import robokin
    from robokin import sim
    from robokin.exceptions import InputError
    from robokin.sim.report import run_summary, write_run

    for label, v in (("--tolerance-deg", tolerance_deg), ("--tolerance-mm", tolerance_mm)):
        if not (math.isfinite(v) and v > 0):
            raise InputError(label, f"expected a number > 0, got {v}")
    robot = robokin.load(name)
    sc = None if scene is None else load_scene(scene)
    from robokin.io.atomic import check_distinct
    from robokin.sim.report import RUN_FILES

    check_distinct([(out / f, "--out") for f in RUN_FILES],
                   [(trajectory, "TRAJECTORY"), (robot.path, "NAME"),
                    (None if sc is None else sc.path, "--scene")])
    plan = _read_plan(trajectory, robot, motors)
    tol = (math.radians(tolerance_deg), tolerance_mm / 1000.0)
    res = sim.simulate(robot, plan, sc, gains={"bandwidth": bandwidth}, dt=dt,
                       contacts=contacts, strict=strict, tolerance=tol)  # type: ignore[arg-type]
    inv = sim.inverse_dynamics(robot, plan, sc, strict=strict)
    files = write_run(res, inv, out, title=f"{robot.name}: ")
    summary = run_summary(res, inv)
    summary["files"] = {k: str(v) for k, v in files.items()}
    if as_json:
        print(json_text(summary))
    else:
        _print_summary(robot, summary, out)
    if not res.ok:
        raise DomainFailure("the simulated run fails its verdict: "
                            + "; ".join(res.reasons))


def _print_summary(robot: Robot, summary: dict[str, Any], out: Path) -> None:
    from rich.table import Table

    from robokin.cli.output import console
    from robokin.sim.report import speed_text

    con = console()
    table = Table(title=f"{cell(robot.name)} in MuJoCo: simulated run vs plan")
    for col in ("joint", "max |error|", "RMS", "corr(|error|, |acc|)", "peak torque",
                "limit", "required (ID)"):
        table.add_column(col)
    for row in summary["joints"]:
        u = row["unit"]
        tu = "N m" if u == "deg" else "N"
        corr = row["corr_error_acceleration"]
        table.add_row(
            cell(row["joint"]), f"{row['max_error']:.4f} {u}", f"{row['rms_error']:.4f} {u}",
            "-" if corr is None else f"{corr:.2f}", f"{row['peak_torque']:.3g} {tu}",
            "-" if row["torque_limit"] is None else f"{row['torque_limit']:.4g}",
            f"{row.get('required_peak_torque', float('nan')):.3g}")
    con.print(table)
    timing = summary["timing"]
    con.print(f"{timing['simulated_s']:.2f} s simulated at {timing['physics_rate_hz']:.0f} Hz"
              f" in {timing['wall_s']:.2f} s: {speed_text(timing['real_time_factor'])}; "
              f"{len(summary['contacts'])} contact(s)", markup=False)
    con.print(f"mass properties: {summary['mass_properties']}", markup=False)
    verdict = "PASS" if summary["ok"] else "FAIL: " + "; ".join(summary["reasons"])
    con.print(("[bold green]" if summary["ok"] else "[bold red]") + cell(verdict, 400)
              + f"[/]; files in {cell(str(out))}")
