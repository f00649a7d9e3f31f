"""``robokin traj`` and ``robokin compare``: plan a motion from a file, check a real run.

The motion-file format is described in :mod:`robokin.io.motion_files`.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from robokin.cli.common import NUMERIC_ARGS, DomainFailure, json_text
from robokin.cli.options import JsonFlag, NoPlotFlag
from robokin.cli.output import FormatOption, resolve_format
from robokin.io.motion_files import MAX_MOTION_SAMPLES, load_motion_file, motion_limits
from robokin.trajectory.motion_plan import plan_from_document

if TYPE_CHECKING:
    from robokin.robot import Robot
    from robokin.trajectory.samples import Trajectory

__all__ = ["commands", "compare", "traj"]

commands = typer.Typer()



def _default_out(path: Path | None, fallback: Path, explicit: bool) -> tuple[Path, bool]:
    """The output path and whether overwriting it is allowed (only when explicit)."""
    if path is not None:
        return path, explicit
    return fallback, False


@commands.command(context_settings=NUMERIC_ARGS)
def traj(
    file: Annotated[Path, typer.Argument(help="Motion file (YAML).")],
    output: Annotated[Path | None, typer.Option(
        "-o", "--output", help="CSV to write (replaced if it exists).")] = None,
    plot: Annotated[Path | None, typer.Option(
        "--plot", help="Joint plot to write (PNG/SVG/PDF; replaced if it exists).")] = None,
    no_plot: NoPlotFlag = False,
    rates: Annotated[bool, typer.Option(
        "--rates", help="Also write velocity and acceleration columns.")] = False,
    as_json: JsonFlag = False,
    max_samples: Annotated[int, typer.Option(
        "--max-samples", help="Most samples the motion may hold (refused above).")
    ] = MAX_MOTION_SAMPLES,
    ros2: Annotated[Path | None, typer.Option(
        "--ros2", help="Also write a ROS 2 trajectory_msgs/JointTrajectory (YAML; "
        "replaced if it exists).")] = None,
    ros2_goal: Annotated[bool, typer.Option(
        "--ros2-goal", help="Write --ros2 as a FollowJointTrajectory action goal.")
    ] = False,
    ros2_stride: Annotated[int, typer.Option(
        "--ros2-stride", help="Keep every N-th sample (and the last) in --ros2.")] = 1,
    program: Annotated[Path | None, typer.Option(
        "--program", help="Also write a controller program. A dialect name (kuka_krl, "
        "abb_rapid, fanuc_tp, yaskawa_inform, staubli_val3, kawasaki_as, or a "
        "registered one): its files, named after the motion file, in --program-dir "
        "(an existing one is replaced only with --force). A file path: the program "
        "the robot's controller profile names (URScript, ROS 2 or waypoint file; "
        "replaced if it exists).")] = None,
    program_dir: Annotated[Path | None, typer.Option(
        "--program-dir", help="Folder of a --program DIALECT's files (default: the "
        "motion file's folder).")] = None,
    program_tolerance: Annotated[float | None, typer.Option(
        "--program-tolerance", help="--program DIALECT: keep the samples within this "
        "joint-space deviation [deg] (default 0.057 deg = 1 mrad).")] = None,
    program_stride: Annotated[int | None, typer.Option(
        "--program-stride", help="--program DIALECT: keep every N-th sample (and the "
        "last) instead.")] = None,
    force: Annotated[bool, typer.Option(
        "--force", help="Replace FILE.csv / FILE.png left by an earlier run.")] = False,
    output_format: FormatOption = None,
) -> None:
    """Plan a motion through via points: write the samples (CSV) and a plot, print a summary.

    Without -o the CSV goes next to the motion file as FILE.csv (an existing one
    is replaced only with --force); the plot likewise as FILE.png. The CSV and the
    plot are written all or none: nothing is written when either cannot be.
    --ros2 and --program use the robot file's controller: section (joint names,
    order, signs, offsets; docs/controllers.md, docs/ros2.md). --program DIALECT
    writes joint moves through the samples (decimated: --program-tolerance,
    --program-stride) in that controller's language. Exit code 1 when the motion
    violates a joint limit (the files are still written).
    """
    import numpy as np
    from rich.progress import Progress

    from robokin.exceptions import InputError
    from robokin.io.atomic import check_distinct, staged_outputs
    from robokin.trajectory import PathError
    from robokin.trajectory.io import write_csv

    fmt = resolve_format(output_format, as_json)
    if max_samples < 1:
        raise InputError("--max-samples", f"expected a count >= 1, got {max_samples}")
    spec, path = load_motion_file(file)
    try:
        if fmt != "table":
            robot, tr = plan_from_document(spec, path, max_samples=max_samples)
        else:
            with Progress(transient=True) as bar:
                task = bar.add_task("planning", total=len(spec.segments) + 1)
                robot, tr = plan_from_document(
                    spec, path, lambda d, t: bar.update(task, completed=d),
                    max_samples=max_samples)
    except PathError as exc:
        raise DomainFailure(str(exc)) from None
    csv_path, csv_over = _default_out(output, path.with_suffix(".csv"), True)
    outputs = [(csv_path, "-o", csv_over or force)]
    png = None
    if not no_plot:
        png, png_over = _default_out(plot, path.with_suffix(".png"), True)
        outputs.append((png, "--plot", png_over or force))
    dialect = _program_dialect(program, program_dir, program_tolerance, program_stride)
    program_files = [] if dialect is None else _dialect_files(
        robot, dialect, program_dir or path.parent, path.stem)
    check_distinct([(p, arg) for p, arg, _ in outputs]
                   + [(p, arg) for p, arg in ((ros2, "--ros2"),
                                              (None if dialect else program, "--program"))
                      if p is not None] + [(p, "--program") for p in program_files],
                   [(path, "FILE"), (robot.path, "(the motion file's robot)")])
    if not force:
        _refuse_earlier_run([(p, opt) for (p, opt, _), given in
                             zip(outputs, (output, plot)) if given is None]
                            + [(p, "--program-dir") for p in program_files], path)
    with staged_outputs(outputs, how="pass --force") as staged:
        write_csv(tr, staged[0], robot.joint_names, rates=rates)
        if png is not None:
            from robokin.viz.plots import plot_joints

            plot_joints(tr, path=staged[1], title=f"{robot.name}: {path.name}"[:200])
    extra = _controller_outputs(robot, tr, ros2, ros2_goal, ros2_stride,
                                None if dialect else program)
    if dialect is not None:
        extra += _dialect_program(robot, tr, dialect, program_dir or path.parent,
                                  path.stem, force, program_tolerance, program_stride)
    vel, acc = motion_limits(spec, robot, path)
    report = tr.check_limits(robot, velocity=vel, acceleration=acc)
    peaks = tr.peaks()
    su = np.where(robot.is_revolute, 180 / math.pi, 1000.0)
    if fmt == "json":
        print(json_text({
            "robot": robot.name, "duration": tr.duration, "samples": len(tr),
            "dt": spec.dt, "csv": str(csv_path), "plot": None if png is None else str(png),
            "controller_files": extra,
            "joints": list(robot.joint_names),
            "peak_velocity": peaks["velocity"].tolist(),
            "peak_acceleration": peaks["acceleration"].tolist(),
            "violations": [v.__dict__ for v in report],
        }))
    else:
        from robokin.cli.output import Column, OutputTable, emit, fixed, say

        say(f"{robot.name}: {len(tr.labels)} segments, {tr.duration:.3f} s, "
            f"{len(tr)} samples at {spec.dt * 1000:g} ms", fmt)
        f3 = fixed(3)
        table = OutputTable("peaks per joint", [
            Column("joint"), Column("unit"), Column("min", f3, True),
            Column("max", f3, True), Column("peak |vel| /s", f3, True),
            Column("peak |acc| /s²", f3, True)])
        for j, name in enumerate(robot.joint_names):
            table.add_row(name, "deg" if robot.is_revolute[j] else "mm",
                          *(float(peaks[k][j] * su[j])
                            for k in ("min", "max", "velocity", "acceleration")))
        emit(table, fmt)
        say(f"wrote {csv_path}" + ("" if png is None else f" and {png}"), fmt)
        for line in extra:
            say(line, fmt)
        if report.ok:
            say("limits: no violation", fmt)
        else:
            for v in report:
                say(f"limit violated: {v}", fmt)
    if not report.ok:
        raise DomainFailure(f"{len(report)} limit violation(s); first: {report.first()}")


def _refuse_earlier_run(defaults: list[tuple[Path, str]], motion: Path) -> None:
    """Outputs named after the motion file (no -o / --plot) need --force to be replaced.

    The error names the files and the motion file, not an option the user did not
    give.
    """
    import os

    from robokin.exceptions import InputError

    there = [(p, opt) for p, opt in defaults if os.path.lexists(p)]
    if not there:
        return
    many = len(there) > 1
    names = " and ".join(str(p) for p, _ in there)
    options = " / ".join(dict.fromkeys(opt for _, opt in there))
    raise InputError("FILE", f"{names} {'exist' if many else 'exists'} (written next "
                     f"to {motion.name} by an earlier run); pass --force to replace "
                     f"{'them' if many else 'it'}, or {options} to write elsewhere")


def _controller_outputs(robot: Robot, tr: Trajectory, ros2: Path | None, goal: bool,
                        stride: int, program: Path | None) -> list[str]:
    """Write --ros2 and --program; one line per file saying what it holds."""
    from robokin.exceptions import InputError
    from robokin.trajectory.controllers import (
        controller_profile,
        write_controller_program,
    )
    from robokin.trajectory.ros2 import write_joint_trajectory

    if (goal or stride != 1) and ros2 is None:
        raise InputError("--ros2-goal" if goal else "--ros2-stride", "needs --ros2 OUT.yaml")
    lines = []
    if ros2 is not None:
        prof = controller_profile(robot)
        write_joint_trajectory(tr, ros2, robot.joint_names, profile=prof, stride=stride,
                               action_goal=goal, overwrite=True)
        kind = "FollowJointTrajectory goal" if goal else "trajectory_msgs/JointTrajectory"
        lines.append(f"wrote {ros2}: ROS 2 {kind} (YAML), controller profile "
                     f"'{prof.name}'")
    if program is not None:
        prog = write_controller_program(robot, tr, program, overwrite=True)
        lines.append(f"wrote {program}: {prog.describe()}")
    return lines


def _program_dialect(program: Path | None, program_dir: Path | None,
                     tolerance: float | None, stride: int | None) -> str | None:
    """The dialect named by --program (None: a file path, or no --program)."""
    from robokin.exceptions import InputError
    from robokin.trajectory.posts import post_names

    text = "" if program is None else str(program)
    bare = bool(text) and "/" not in text and "\\" not in text and "." not in text
    dialect = text if bare and text.lower().replace("-", "_") in post_names() else None
    if bare and dialect is None:
        raise InputError("--program", f"{text!r} is neither a dialect ({post_names()}) "
                         "nor a file name with a suffix (move.script, move.ros2.yaml, "
                         "move.waypoints.csv)")
    for value, opt in ((program_dir, "--program-dir"), (tolerance, "--program-tolerance"),
                       (stride, "--program-stride")):
        if value is not None and dialect is None:
            raise InputError(opt, "applies to --program DIALECT (one of "
                             f"{post_names()})")
    return dialect


def _dialect_files(robot: Robot, dialect: str, folder: Path, stem: str) -> list[Path]:
    """The files --program DIALECT will write (for the distinct-output check)."""
    from robokin.trajectory.posts import get_post

    post = get_post(dialect)
    name, _ = post.program_name(stem)
    return [folder / rel for rel in post.file_names(name)]


def _dialect_program(robot: Robot, tr: Trajectory, dialect: str, folder: Path, stem: str,
                     force: bool, tolerance_deg: float | None, stride: int | None
                     ) -> list[str]:
    """Write --program DIALECT; lines saying what was written (and its notes)."""
    from robokin.trajectory.posts import write_program

    tol = None if tolerance_deg is None else math.radians(tolerance_deg)
    prog = write_program(robot, tr, dialect, folder, name=stem, force=force,
                         tolerance=tol, stride=stride)
    files = ", ".join(str(p) for p in prog.files)
    return [f"wrote {files}: {prog.describe()}"] + [f"note: {n}" for n in prog.notes]


def _is_bag(path: Path) -> bool:
    """A ROS 2 bag: a folder with metadata.yaml, an .mcap or a .db3 file."""
    return path.suffix.lower() in (".mcap", ".db3") or (path / "metadata.yaml").is_file()


def _read_run(log: Path, plan: Trajectory, topic: str | None, stamp: str
              ) -> Trajectory:
    """The logged run, joints matched by name to the plan's (a CSV or a bag)."""
    from robokin.exceptions import InputError
    from robokin.trajectory.io import read_log

    if not _is_bag(log):
        if topic is not None:
            raise InputError("--topic", f"applies to ROS 2 bags (.mcap, .db3 or a bag "
                             f"folder); {log} is read as CSV")
        return read_log(log, joint_names=plan.joint_names, is_revolute=plan.revolute())
    from robokin.trajectory.ros2 import read_bag_log

    if stamp not in ("header", "receive"):
        raise InputError("--stamp", f"expected header or receive, got {stamp!r}")
    return read_bag_log(log, topic=topic or "/joint_states",
                        joint_names=plan.joint_names, is_revolute=plan.revolute(),
                        stamp="header" if stamp == "header" else "receive")


@commands.command(context_settings=NUMERIC_ARGS)
def compare(
    plan: Annotated[Path, typer.Argument(help="Planned trajectory CSV.")],
    log: Annotated[Path, typer.Argument(
        help="Logged run: CSV (time + joints), or a ROS 2 bag (folder, .mcap or .db3).")],
    plot: Annotated[Path | None, typer.Option(
        "--plot", help="Error plot to write (replaced if it exists).")] = None,
    no_plot: NoPlotFlag = False,
    time_shift: Annotated[float, typer.Option(
        "--time-shift", help="Added to the log's times [s].")] = 0.0,
    radians: Annotated[bool, typer.Option(
        "--rad", help="Report radians and metres (default degrees and mm).")] = False,
    as_json: JsonFlag = False,
    topic: Annotated[str | None, typer.Option(
        "--topic", help="JointState topic of a ROS 2 bag log (default /joint_states).")
    ] = None,
    stamp: Annotated[str, typer.Option(
        "--stamp", help="Bag log time: header (stamps) or receive (bag times).")
    ] = "header",
    output_format: FormatOption = None,
) -> None:
    """Compare a logged real run with its plan: per-joint max and RMS error, a plot.

    The log is a CSV or a ROS 2 bag's sensor_msgs/JointState topic (robokin[ros]);
    its joints are matched to the plan's by name. The plot goes to
    LOG_vs_plan.png next to the log unless --plot is given (an existing file is
    replaced only when named with --plot).
    """
    from robokin.io.atomic import check_distinct
    from robokin.trajectory.compare import compare as run_compare
    from robokin.trajectory.io import read_csv

    fmt = resolve_format(output_format, as_json)
    if not no_plot:
        check_distinct([(plot or log.with_name(log.stem + "_vs_plan.png"), "--plot")],
                       [(plan, "PLAN"), (log, "LOG")])
    p = read_csv(plan)
    r = _read_run(log, p, topic, stamp)
    cmp = run_compare(p, r, time_shift=time_shift)
    rows = cmp.table(degrees=not radians)
    png = None
    if not no_plot:
        from robokin.viz.plots import plot_comparison

        png, over = _default_out(plot, log.with_name(log.stem + "_vs_plan.png"), True)
        plot_comparison(cmp, path=png, overwrite=over, degrees=not radians)
    if fmt == "json":
        print(json_text({"joints": rows, "plot": None if png is None else str(png)}))
        return
    from robokin.cli.output import Column, OutputTable, emit, fixed, say

    table = OutputTable(f"{log.name} vs {plan.name}: {len(cmp.t)} samples compared", [
        Column("joint"), Column("unit"), Column("max |error|", fixed(4), True),
        Column("at t [s]", fixed(3), True), Column("RMS", fixed(4), True),
        Column("mean", fixed(4), True), Column("corr(|error|, |acc|)", fixed(2), True)])
    for row in rows:
        table.add_row(row["joint"], row["unit"], row["max"], row["t_max"], row["rms"],
                      row["mean"], row["corr_acc"])
    emit(table, fmt)
    if png is not None:
        say(f"wrote {png}", fmt)
