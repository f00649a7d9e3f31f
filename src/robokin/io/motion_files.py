"""Motion files (YAML): a robot, its via points and segments -> a sampled trajectory.

A motion file names a robot and its via points::

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

Bounded work: a file may ask for at most ``max_samples`` samples in all
(:data:`MAX_MOTION_SAMPLES` by default, 16 min 40 s at 5 ms); ``dt: 1e-9`` or
``duration: 1e7`` is refused before anything is allocated, naming the field and
the limit (``robokin traj --max-samples N`` raises it). Numbers must be numbers,
and at most :data:`MAX_SEGMENTS` segments.
"""

from __future__ import annotations

import math
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robokin.exceptions import InputError, ModelError
from robokin.io.text_files import MAX_TEXT_BYTES
from robokin.io.validate import validate_document
from robokin.io.yaml_reader import read_yaml_document

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = [
    "MAX_MOTION_SAMPLES",
    "MAX_SEGMENTS",
    "load_motion_file",
    "motion_limits",
    "plan_from_document",
]

#: Default cap on the samples of a motion file's whole trajectory.
MAX_MOTION_SAMPLES = 200_000
#: Most segments a motion file may hold.
MAX_SEGMENTS = 10_000
_DEFAULT_DT = 0.005


def _schema():
    from typing import Annotated, Literal

    from pydantic import (
        BaseModel,
        ConfigDict,
        Field,
        PrivateAttr,
        StrictBool,
        StrictFloat,
        StrictStr,
    )

    Text = Annotated[StrictStr, Field(max_length=200)]
    Positive = Annotated[StrictFloat, Field(gt=0)]

    class Strict(BaseModel):
        model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    class Units(Strict):
        length: Literal["m", "mm"] = "m"
        angle: Literal["rad", "deg"] = "rad"

    class Limits(Strict):  # signs are checked by the path builder, naming the joint
        velocity: StrictFloat | list[StrictFloat] | None = None
        acceleration: StrictFloat | list[StrictFloat] | None = None

    class Target(Strict):
        xyz: list[StrictFloat] | None = Field(default=None, min_length=3, max_length=3)
        dxyz: list[StrictFloat] | None = Field(default=None, min_length=3, max_length=3)
        rpy: list[StrictFloat] | None = Field(default=None, min_length=3, max_length=3)

    class Step(Strict):
        joint: list[StrictFloat] | None = None
        pose: Target | None = None
        line: Target | None = None
        dwell: Positive | None = None
        duration: Positive | None = None
        profile: Text = "quintic"
        stop: StrictBool = False
        label: Text = ""
        speed_in: StrictFloat = 0.0
        speed_out: StrictFloat = 0.0

    class Motion(Strict):
        robot: Annotated[StrictStr, Field(max_length=4096)]
        units: Units = Units()
        dt: Positive = _DEFAULT_DT
        start: list[StrictFloat]
        limits: Limits = Limits()
        tool_speed: Positive | None = None
        tool_acceleration: Positive | None = None
        smooth: StrictBool = True
        ik: Literal["follow", "analytic", "numeric"] = "follow"
        segments: list[Step] = Field(min_length=1, max_length=MAX_SEGMENTS)
        _source: Any = PrivateAttr(default=None)  # the YamlDocument, for lines

    return Motion


def load_motion_file(path: str | Path, *, max_bytes: int = MAX_TEXT_BYTES
                     ) -> tuple[Any, Path]:
    """Read and validate a motion file.

    Args:
        path: The motion file (YAML).
        max_bytes: The largest file accepted [bytes].

    Returns:
        ``(spec, path)``: the validated document and the file.

    Raises:
        ModelError: missing, too large or binary file, bad YAML, or a bad field
            (file, line and field path named).
    """
    path = Path(path)
    ydoc = read_yaml_document(path, max_bytes=max_bytes)
    try:
        if not isinstance(ydoc.data, dict):
            raise ModelError("a motion file must be a mapping of fields", file=path)
        # a union's member types appear in pydantic's locations: not fields
        spec = validate_document(_schema(), ydoc.data, file=path,
                                 drop=("float", "list[float]"))
    except ModelError as exc:
        raise ydoc.locate(exc) from None
    spec._source = ydoc
    return spec, path


def _check_budget(spec: Any, file: Path, max_samples: int) -> None:
    """Refuse explicit durations that ask for more than ``max_samples`` samples.

    The field named is the unusual one: ``dt`` when it is below the default 5 ms
    and the time itself would fit at 5 ms, else the segment's ``duration`` or
    ``dwell``.
    """
    dt = spec.dt
    total = 0.0
    for i, st in enumerate(spec.segments):
        key = "dwell" if st.dwell is not None else "duration"
        d = st.dwell if st.dwell is not None else st.duration
        if d is None:
            continue
        total += d / dt + 1.0
        if total <= max_samples:
            continue
        at_default = sum((s.dwell or s.duration or 0.0) / _DEFAULT_DT + 1.0
                         for s in spec.segments[: i + 1])
        field, what = ((("dt", f"dt {dt:g} s"))
                       if dt < _DEFAULT_DT and at_default <= max_samples
                       else (f"segments[{i}].{key}", f"{d:g} s"))
        raise ModelError(
            f"{what} makes the motion {total:,.0f} samples (by segment {i + 1}), more "
            f"than the limit of {max_samples:,} samples (raise it with "
            "--max-samples or max_samples=)", file=file, field=field)


def plan_from_document(
    spec: Any, file: Path, progress: Any = None, *,
    max_samples: int = MAX_MOTION_SAMPLES,
) -> tuple[Any, Any]:
    """Build the trajectory a validated motion file describes: ``(robot, traj)``.

    Args:
        spec: The validated document (:func:`load_motion_file`).
        file: The motion file (robot files resolve relative to its folder).
        progress: Optional ``progress(done, total)`` per segment.
        max_samples: Most samples the trajectory may hold; checked before any
            sampling.

    Raises:
        ModelError: a field that does not fit the robot, or a motion of more than
            ``max_samples`` samples (file and field named).
        PathError: a line that cannot be followed.
        UnreachableError: a pose with no IK solution.
    """
    source = getattr(spec, "_source", None)
    try:
        return _plan(spec, file, progress, max_samples)
    except ModelError as exc:
        raise (exc if source is None else source.locate(exc)) from None


def _plan(spec: Any, file: Path, progress: Any, max_samples: int) -> tuple[Any, Any]:
    import numpy as np

    from robokin.trajectory import PathBuilder

    _check_budget(spec, file, max_samples)
    # the builder's argument names -> the motion file's fields
    top = {"v_max": "limits.velocity", "a_max": "limits.acceleration",
           "tool_speed": "tool_speed", "tool_acceleration": "tool_acceleration",
           "dt": "dt", "ik": "ik", "q_start": "start", "max_samples": "dt"}

    @contextmanager
    def fields(where: str | None):
        """Re-raise a builder's InputError as a ModelError naming the file's field."""
        try:
            yield
        except InputError as exc:
            field = top.get(exc.argument) or (
                f"{where}.{exc.argument}" if where else exc.argument)
            raise ModelError(exc.reason, file=file, field=field) from None

    robot = _robot(spec, file)
    L = 1e-3 if spec.units.length == "mm" else 1.0
    A = math.pi / 180.0 if spec.units.angle == "deg" else 1.0
    jscale = np.where(robot.is_revolute, A, L)

    def joints(values, field):
        if len(values) != robot.n:
            raise ModelError(f"{robot.name} has {robot.n} joints, got {len(values)} "
                             "values", file=file, field=field)
        return np.asarray(values, float) * jscale

    v_max, a_max = motion_limits(spec, robot, file)
    with fields(None):
        pb = PathBuilder(robot, joints(spec.start, "start"), dt=spec.dt,
                         v_max=v_max, a_max=a_max,
                         tool_speed=None if spec.tool_speed is None else spec.tool_speed * L,
                         tool_acceleration=None if spec.tool_acceleration is None
                         else spec.tool_acceleration * L,
                         smooth=spec.smooth, ik=spec.ik, max_samples=max_samples)

    def pose(target, field):
        return _target_pose(robot, pb.q_end, target, L, A, file, field)

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


def motion_limits(spec: Any, robot: Robot, file: Path | None = None
                  ) -> tuple[Any, Any]:
    """A motion file's ``limits:`` in SI units, one value per joint.

    Args:
        spec: The validated document (:func:`load_motion_file`).
        robot: Its robot (for the joint count and kinds).
        file: The motion file, for error messages.

    Returns:
        ``(velocity, acceleration)``: each (n,) [rad/s or m/s; rad/s^2 or m/s^2],
        or None where the file gives none.

    Raises:
        ModelError: a list that is not one value per joint (file and field named).
    """
    import numpy as np

    L = 1e-3 if spec.units.length == "mm" else 1.0
    A = math.pi / 180.0 if spec.units.angle == "deg" else 1.0
    scale = np.where(robot.is_revolute, A, L)
    out: list[Any] = []
    for kind in ("velocity", "acceleration"):
        value = getattr(spec.limits, kind)
        if value is None:
            out.append(None)
            continue
        arr = np.asarray(value, float)
        if arr.ndim == 0:
            arr = np.broadcast_to(arr, (robot.n,))
        if arr.shape != (robot.n,):
            raise ModelError(f"expected one value or {robot.n}", file=file,
                             field=f"limits.{kind}")
        out.append(arr * scale)
    return out[0], out[1]


def _robot(spec: Any, file: Path) -> Any:
    """The motion file's robot: a robot file next to it, or a built-in name."""
    import robokin

    name = spec.robot
    candidate = file.parent / name
    try:
        return robokin.load(candidate if candidate.suffix in (".yaml", ".yml")
                            and candidate.exists() else name)
    except ModelError as exc:
        if exc.file is not None:
            raise
        raise ModelError(exc.reason, file=file, field="robot") from None


def _target_pose(robot: Robot, q_end: Any, target: Any, L: float, A: float,
                 file: Path, field: str) -> Any:
    """The pose a ``pose:`` / ``line:`` target names (rpy kept when omitted)."""
    import numpy as np

    from robokin.spatial import matrix_from_rpy

    T = robot.fk(q_end).copy()
    if target.xyz is not None and target.dxyz is not None:
        raise ModelError("give xyz or dxyz, not both", file=file, field=field)
    if target.rpy is not None:
        T[:3, :3] = matrix_from_rpy(np.asarray(target.rpy) * A)[:3, :3]
    if target.xyz is not None:
        T[:3, 3] = np.asarray(target.xyz) * L
    elif target.dxyz is not None:
        T[:3, 3] += np.asarray(target.dxyz) * L
    return T


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
