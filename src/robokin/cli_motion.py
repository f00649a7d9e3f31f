"""``robokin traj`` and ``robokin compare``: plan a motion from a file, check a real run.

A motion file (YAML) names a robot and its via points::

    robot: aubo_i5                    # built-in name or robot file
    units: {length: mm, angle: deg}   # of this file (default m, rad)
    dt: 0.005                         # [s]
    start: [0, 10, 80, 0, 90, 0]      # joint configuration
    limits: {velocity: 90, acceleration: 180}   # per second (scalar or per joint)
    tool_speed: 250                   # [length/s] on lines (optional)
    smooth: true                      # pass through joint via points
    segments:
      - joint: [-40, 20, 90, -20, 90, 0]
      - line: {dxyz: [0, 0, -100]}    # relative straight move (base axes)
        duration: 1.0
      - dwell: 0.5
      - line: {xyz: [400, -120, 600], rpy: [180, 0, 90]}
      - pose: {xyz: [300, 300, 500]}  # joint move to a pose (rpy kept if omitted)

Segment keys besides the target: ``duration`` [s], ``profile``, ``stop``,
``label``, ``speed_in`` / ``speed_out`` (lines, [length/s]).
"""

from __future__ import annotations

import json
import math
from contextlib import contextmanager
from pathlib import Path
from typing import Annotated, Any

import typer

from robokin.cli import DomainFailure, app

__all__ = ["load_motion_file", "plan_from_document"]

_NUMERIC_ARGS = {"ignore_unknown_options": True}


# ------------------------------------------------------------------ motion files
def _schema():
    from typing import Literal

    from pydantic import BaseModel, ConfigDict, Field

    class Units(BaseModel):
        model_config = ConfigDict(extra="forbid")
        length: Literal["m", "mm"] = "m"
        angle: Literal["rad", "deg"] = "rad"

    class Limits(BaseModel):
        model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
        velocity: float | list[float] | None = None
        acceleration: float | list[float] | None = None

    class Target(BaseModel):
        model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
        xyz: list[float] | None = Field(default=None, min_length=3, max_length=3)
        dxyz: list[float] | None = Field(default=None, min_length=3, max_length=3)
        rpy: list[float] | None = Field(default=None, min_length=3, max_length=3)

    class Step(BaseModel):
        model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
        joint: list[float] | None = None
        pose: Target | None = None
        line: Target | None = None
        dwell: float | None = Field(default=None, gt=0)
        duration: float | None = Field(default=None, gt=0)
        profile: str = "quintic"
        stop: bool = False
        label: str = ""
        speed_in: float = 0.0
        speed_out: float = 0.0

    class Motion(BaseModel):
        model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
        robot: str
        units: Units = Units()
        dt: float = Field(default=0.005, gt=0)
        start: list[float]
        limits: Limits = Limits()
        tool_speed: float | None = Field(default=None, gt=0)
        tool_acceleration: float | None = Field(default=None, gt=0)
        smooth: bool = True
        ik: Literal["follow", "analytic", "numeric"] = "follow"
        segments: list[Step] = Field(min_length=1)

    return Motion


def load_motion_file(path: str | Path) -> tuple[Any, Path]:
    """Read and validate a motion file.

    Raises:
        ModelError: missing file, bad YAML, or a bad field (file and field path named).
    """
    import yaml
    from pydantic import ValidationError

    from robokin.exceptions import ModelError

    path = Path(path)
    try:
        doc = yaml.safe_load(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ModelError("no such file", file=path) from None
    except yaml.YAMLError as exc:
        raise ModelError(f"not valid YAML: {exc}", file=path) from None
    try:
        return _schema().model_validate(doc), path
    except ValidationError as exc:
        err = exc.errors()[0]
        field = ".".join(str(p) if not isinstance(p, int) else f"[{p}]"
                         for p in err["loc"]).replace(".[", "[")
        raise ModelError(err["msg"], file=path, field=field) from None


def plan_from_document(spec: Any, file: Path, progress: Any = None) -> tuple[Any, Any]:
    """Build the trajectory a validated motion file describes: ``(robot, traj)``.

    Raises:
        ModelError: a field that does not fit the robot (file and field named).
        PathError: a line that cannot be followed.
    """
    import numpy as np

    import robokin
    from robokin.exceptions import InputError, ModelError
    from robokin.spatial import matrix_from_rpy
    from robokin.trajectory import PathBuilder

    # the builder's argument names -> the motion file's fields
    top = {"v_max": "limits.velocity", "a_max": "limits.acceleration",
           "tool_speed": "tool_speed", "tool_acceleration": "tool_acceleration",
           "dt": "dt", "ik": "ik", "q_start": "start"}

    @contextmanager
    def fields(where: str | None):
        """Re-raise a builder's InputError as a ModelError naming the file's field."""
        try:
            yield
        except InputError as exc:
            field = top.get(exc.argument) or (
                f"{where}.{exc.argument}" if where else exc.argument)
            raise ModelError(exc.reason, file=file, field=field) from None

    name = spec.robot
    candidate = file.parent / name
    try:
        robot = robokin.load(candidate if candidate.suffix in (".yaml", ".yml")
                             and candidate.exists() else name)
    except ModelError as exc:
        if exc.file is not None:
            raise
        raise ModelError(exc.reason, file=file, field="robot") from None
    L = 1e-3 if spec.units.length == "mm" else 1.0
    A = math.pi / 180.0 if spec.units.angle == "deg" else 1.0
    rev = robot.is_revolute
    jscale = np.where(rev, A, L)

    def joints(values, field):
        if len(values) != robot.n:
            raise ModelError(f"{robot.name} has {robot.n} joints, got {len(values)} "
                             "values", file=file, field=field)
        return np.asarray(values, float) * jscale

    def per_joint(v, field):
        if v is None:
            return None
        arr = np.broadcast_to(np.asarray(v, float), (robot.n,)) if np.ndim(v) == 0 \
            else np.asarray(v, float)
        if arr.shape != (robot.n,):
            raise ModelError(f"expected one value or {robot.n}", file=file, field=field)
        return arr * jscale

    with fields(None):
        pb = PathBuilder(robot, joints(spec.start, "start"), dt=spec.dt,
                         v_max=per_joint(spec.limits.velocity, "limits.velocity"),
                         a_max=per_joint(spec.limits.acceleration, "limits.acceleration"),
                         tool_speed=None if spec.tool_speed is None else spec.tool_speed * L,
                         tool_acceleration=None if spec.tool_acceleration is None
                         else spec.tool_acceleration * L,
                         smooth=spec.smooth, ik=spec.ik)

    def pose(target, field):
        T = robot.fk(pb.q_end).copy()
        if target.xyz is not None and target.dxyz is not None:
            raise ModelError("give xyz or dxyz, not both", file=file, field=field)
        if target.rpy is not None:
            T[:3, :3] = matrix_from_rpy(np.asarray(target.rpy) * A)[:3, :3]
        if target.xyz is not None:
            T[:3, 3] = np.asarray(target.xyz) * L
        elif target.dxyz is not None:
            T[:3, 3] += np.asarray(target.dxyz) * L
        return T

    total = len(spec.segments)
    for i, st in enumerate(spec.segments):
        field = f"segments[{i}]"
        kinds = [k for k in ("joint", "pose", "line", "dwell") if getattr(st, k) is not None]
        if len(kinds) != 1:
            raise ModelError("needs exactly one of joint, pose, line, dwell", file=file,
                             field=field)
        common = {"label": st.label or f"{kinds[0]} {i + 1}"}
        with fields(field):
            _add_step(pb, st, joints, pose, field, L, common)
        if progress is not None:
            progress(i + 1, total + 1)
    with fields("segments"):
        traj = pb.build()
    if progress is not None:
        progress(total + 1, total + 1)
    return robot, traj


def _add_step(pb: Any, st: Any, joints: Any, pose: Any, field: str, L: float,
              common: dict[str, Any]) -> None:
    """Add one validated motion-file step to the path builder."""
    if st.joint is not None:
        pb.joint(joints(st.joint, f"{field}.joint"), st.duration,
                 profile=st.profile, stop=st.stop, **common)
    elif st.pose is not None:
        pb.pose(pose(st.pose, f"{field}.pose"), st.duration, profile=st.profile,
                stop=st.stop, **common)
    elif st.line is not None:
        pb.line(pose(st.line, f"{field}.line"), st.duration, profile=st.profile,
                speed_in=st.speed_in * L, speed_out=st.speed_out * L, **common)
    else:
        pb.dwell(st.dwell, **common)


def _default_out(path: Path | None, fallback: Path, explicit: bool) -> tuple[Path, bool]:
    """The output path and whether overwriting it is allowed (only when explicit)."""
    if path is not None:
        return path, explicit
    return fallback, False


@app.command(context_settings=_NUMERIC_ARGS)
def traj(
    file: Annotated[Path, typer.Argument(help="Motion file (YAML).")],
    output: Annotated[Path | None, typer.Option(
        "-o", "--output", help="CSV to write (replaced if it exists).")] = None,
    plot: Annotated[Path | None, typer.Option(
        "--plot", help="Joint plot to write (PNG/SVG/PDF; replaced if it exists).")] = None,
    no_plot: Annotated[bool, typer.Option("--no-plot", help="Write no plot.")] = False,
    rates: Annotated[bool, typer.Option(
        "--rates", help="Also write velocity and acceleration columns.")] = False,
    as_json: Annotated[bool, typer.Option("--json", help="Machine-readable summary.")
                       ] = False,
) -> None:
    """Plan a motion through via points: write the samples (CSV) and a plot, print a summary.

    Without -o the CSV goes next to the motion file as FILE.csv (never replacing
    an existing file); the plot likewise as FILE.png. Exit code 1 when the
    motion violates a joint limit (the files are still written).
    """
    import numpy as np
    from rich.progress import Progress

    from robokin.exceptions import InputError
    from robokin.trajectory import PathError
    from robokin.trajectory.io import write_csv

    spec, path = load_motion_file(file)
    try:
        if as_json:
            robot, tr = plan_from_document(spec, path)
        else:
            with Progress(transient=True) as bar:
                task = bar.add_task("planning", total=len(spec.segments) + 1)
                robot, tr = plan_from_document(
                    spec, path, lambda d, t: bar.update(task, completed=d))
    except PathError as exc:
        raise DomainFailure(str(exc)) from None
    csv_path, csv_over = _default_out(output, path.with_suffix(".csv"), True)
    try:
        write_csv(tr, csv_path, robot.joint_names, rates=rates, overwrite=csv_over)
        png = None
        if not no_plot:
            from robokin.viz.plots import plot_joints

            png, png_over = _default_out(plot, path.with_suffix(".png"), True)
            plot_joints(tr, path=png, overwrite=png_over,
                        title=f"{robot.name}: {path.name}")
    except InputError as exc:
        raise InputError(exc.argument, exc.reason + " (or give -o / --plot)") from None
    L = 1e-3 if spec.units.length == "mm" else 1.0
    A = math.pi / 180.0 if spec.units.angle == "deg" else 1.0
    jscale = np.where(robot.is_revolute, A, L)
    vel = None if spec.limits.velocity is None else np.broadcast_to(
        np.asarray(spec.limits.velocity, float), (robot.n,)) * jscale
    acc = None if spec.limits.acceleration is None else np.broadcast_to(
        np.asarray(spec.limits.acceleration, float), (robot.n,)) * jscale
    report = tr.check_limits(robot, velocity=vel, acceleration=acc)
    peaks = tr.peaks()
    su = np.where(robot.is_revolute, 180 / math.pi, 1000.0)
    if as_json:
        print(json.dumps({
            "robot": robot.name, "duration": tr.duration, "samples": len(tr),
            "dt": spec.dt, "csv": str(csv_path), "plot": None if png is None else str(png),
            "joints": list(robot.joint_names),
            "peak_velocity": peaks["velocity"].tolist(),
            "peak_acceleration": peaks["acceleration"].tolist(),
            "violations": [v.__dict__ for v in report],
        }))
    else:
        from rich.console import Console
        from rich.table import Table

        con = Console()
        con.print(f"{robot.name}: {len(tr.labels)} segments, {tr.duration:.3f} s, "
                  f"{len(tr)} samples at {spec.dt * 1000:g} ms", markup=False)
        table = Table(title="peaks per joint")
        for col in ("joint", "unit", "min", "max", "peak |vel| /s", "peak |acc| /s²"):
            table.add_column(col)
        for j, name in enumerate(robot.joint_names):
            table.add_row(name, "deg" if robot.is_revolute[j] else "mm",
                          f"{peaks['min'][j] * su[j]:.3f}", f"{peaks['max'][j] * su[j]:.3f}",
                          f"{peaks['velocity'][j] * su[j]:.3f}",
                          f"{peaks['acceleration'][j] * su[j]:.3f}")
        con.print(table)
        con.print(f"wrote {csv_path}" + ("" if png is None else f" and {png}"),
                  markup=False)
        if report.ok:
            con.print("limits: no violation")
        else:
            for v in report:
                con.print(f"limit violated: {v}", markup=False)
    if not report.ok:
        raise DomainFailure(f"{len(report)} limit violation(s); first: {report.first()}")


@app.command(context_settings=_NUMERIC_ARGS)
def compare(
    plan: Annotated[Path, typer.Argument(help="Planned trajectory CSV.")],
    log: Annotated[Path, typer.Argument(help="Logged run CSV (time + joints).")],
    plot: Annotated[Path | None, typer.Option(
        "--plot", help="Error plot to write (replaced if it exists).")] = None,
    no_plot: Annotated[bool, typer.Option("--no-plot", help="Write no plot.")] = False,
    time_shift: Annotated[float, typer.Option(
        "--time-shift", help="Added to the log's times [s].")] = 0.0,
    radians: Annotated[bool, typer.Option(
        "--rad", help="Report radians and metres (default degrees and mm).")] = False,
    as_json: Annotated[bool, typer.Option("--json", help="Machine-readable output.")
                       ] = False,
) -> None:
    """Compare a logged real run with its plan: per-joint max and RMS error, a plot.

    The plot goes to LOG_vs_plan.png next to the log unless --plot is given
    (an existing file is replaced only when named with --plot).
    """
    from robokin.trajectory.compare import compare as run_compare
    from robokin.trajectory.io import read_csv, read_log

    p = read_csv(plan)
    r = read_log(log)
    cmp = run_compare(p, r, time_shift=time_shift)
    rows = cmp.table(degrees=not radians)
    png = None
    if not no_plot:
        from robokin.viz.plots import plot_comparison

        png, over = _default_out(plot, log.with_name(log.stem + "_vs_plan.png"), True)
        plot_comparison(cmp, path=png, overwrite=over, degrees=not radians)
    if as_json:
        print(json.dumps({"joints": rows, "plot": None if png is None else str(png)},
                         default=float))
        return
    from rich.console import Console
    from rich.table import Table

    table = Table(title=f"{log.name} vs {plan.name}: {len(cmp.t)} samples compared")
    for col in ("joint", "unit", "max |error|", "at t [s]", "RMS", "mean",
                "corr(|error|, |acc|)"):
        table.add_column(col)
    for row in rows:
        table.add_row(row["joint"], row["unit"], f"{row['max']:.4f}",
                      f"{row['t_max']:.3f}", f"{row['rms']:.4f}", f"{row['mean']:.4f}",
                      f"{row['corr_acc']:.2f}")
    con = Console()
    con.print(table)
    if png is not None:
        con.print(f"wrote {png}", markup=False)
