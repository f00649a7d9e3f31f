"""Motion files (YAML): a robot, its via points and segments, read and checked.

This module reads and validates the file (:func:`load_motion_file`) and gives its
limits in SI units (:func:`motion_limits`);
:func:`robokin.trajectory.motion_plan.plan_from_document` builds the trajectory
it describes.

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
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robokin.exceptions import ModelError
from robokin.io.text_files import MAX_TEXT_BYTES
from robokin.io.validate import validate_document
from robokin.io.yaml_reader import read_yaml_document

if TYPE_CHECKING:
    from robokin.model.parts import RobotParts

__all__ = [
    "MAX_MOTION_SAMPLES",
    "MAX_SEGMENTS",
    "check_budget",
    "load_motion_file",
    "motion_limits",
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

    :func:`robokin.trajectory.motion_plan.plan_from_document` builds its
    trajectory.
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


def check_budget(spec: Any, file: Path, max_samples: int) -> None:
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


def motion_limits(spec: Any, robot: RobotParts, file: Path | None = None
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
