"""The ``rate_limits:`` section of a robot file: per-joint speed, acceleration, jerk.

Values are in the file's units per second (``units: {angle: deg, length: mm}``:
deg/s and mm/s, deg/s^2 and mm/s^2, deg/s^3 and mm/s^3), one per independent
joint coordinate in order (the ``joints`` rows, or ``coordinates`` when given),
or one number for every joint; ``null`` marks a value that is not known.

.. code-block:: yaml

    rate_limits:
      source: AUBO-i5 datasheet (speeds); AUBO's MoveIt configuration (accelerations)
      velocity: [150, 150, 150, 180, 180, 180]        # deg/s
      acceleration: [1718.873, 1718.873, 1718.873, 1432.394, 1432.394, 1432.394]
      jerk: null                                      # optional

They become :attr:`robokin.Robot.rate_limits` (SI) and are the defaults of
:func:`robokin.trajectory.retime`. The robot-file reader applies the section
through its table (:data:`robokin.io.robot_files.SECTIONS`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from robokin._text import short_repr
from robokin._units import ANGLE_UNITS, LENGTH_UNITS
from robokin.exceptions import ModelError
from robokin.io.validate import validate_document
from robokin.model.rate_limits import RATE_KINDS, RateLimits

if TYPE_CHECKING:
    from robokin.model.parts import RobotParts

__all__ = ["apply_rate_limits_section", "rate_limits_from_section",
           "section_from_robot"]



def _schema() -> Any:
    from typing import Annotated

    from pydantic import BaseModel, ConfigDict, Field, StrictStr

    class Section(BaseModel):
        model_config = ConfigDict(extra="forbid")

        source: Annotated[StrictStr, Field(max_length=4096)] = ""
        # checked by _values (a union's error would not name the entry)
        velocity: Any = None
        acceleration: Any = None
        jerk: Any = None

    return Section


def _values(v: Any, n: int, file: Any, field: str) -> list[float]:
    """One positive number per joint (NaN for ``null``) from a number or a list."""
    def number(x: Any, where: str) -> float:
        if x is None and where != field:
            return math.nan
        if isinstance(x, bool) or not isinstance(x, int | float) or not (
                math.isfinite(x) and x > 0):
            raise ModelError(f"expected a finite positive number (or null for an "
                             f"unknown value), got {short_repr(x)}", file=file,
                             field=where)
        return float(x)

    if isinstance(v, list):
        if len(v) != n:
            raise ModelError(f"expected {n} values (one per joint) or one number, "
                             f"got {len(v)}", file=file, field=field)
        return [number(x, f"{field}[{k}]") for k, x in enumerate(v)]
    return [number(v, field)] * n


def rate_limits_from_section(value: Any, is_revolute: np.ndarray, file: Any = None,
                             units: Any = None) -> RateLimits:
    """Parse a ``rate_limits:`` section into SI :class:`RateLimits`.

    Args:
        value: The section (a mapping) in the file's units.
        is_revolute: (n,) bool per independent coordinate (angles or lengths).
        file: The robot file, for error messages.
        units: The file's ``units`` (``.length``, ``.angle``); SI when None.

    Returns:
        The limits, NaN where a value is ``null``.

    Raises:
        ModelError: naming the file and the field path (``rate_limits.velocity``):
            not a mapping, a value that is not a positive number, the wrong count.
    """
    if not isinstance(value, dict):
        raise ModelError(f"must be a mapping of fields, got {type(value).__name__}",
                         file=file, field="rate_limits")
    spec = validate_document(_schema(), value, file=file, prefix=("rate_limits",))
    rev = np.asarray(is_revolute, dtype=bool).reshape(-1)
    n = rev.size
    unit = np.where(rev, ANGLE_UNITS[getattr(units, "angle", "rad")],
                    LENGTH_UNITS[getattr(units, "length", "m")])
    out: dict[str, np.ndarray | None] = {}
    for kind in RATE_KINDS:
        v = getattr(spec, kind)
        if v is None:
            out[kind] = None
            continue
        vals = _values(v, n, file, f"rate_limits.{kind}")
        out[kind] = np.array(vals) * unit
    if all(a is None for a in out.values()):
        raise ModelError("give at least one of velocity, acceleration, jerk",
                         file=file, field="rate_limits")
    return RateLimits(out["velocity"], out["acceleration"], out["jerk"],
                      source=spec.source)


def apply_rate_limits_section(robot: RobotParts, value: Any, file: Any, units: Any
                              ) -> RobotParts:
    """The section reader: a copy of ``robot`` with its rate limits (file units)."""
    limits = rate_limits_from_section(value, robot.is_revolute, file, units)
    return robot.replace(rate_limits=limits)


def section_from_robot(robot: RobotParts) -> dict[str, Any] | None:
    """The ``rate_limits:`` section (SI units) of a robot, or None.

    For writing robots built in memory; files loaded from disk keep their own
    section.
    """
    lim = robot.rate_limits
    if lim is None:
        return None
    out: dict[str, Any] = {}
    if lim.source:
        out["source"] = lim.source
    for kind in RATE_KINDS:
        arr = lim.get(kind)
        if arr is not None:
            out[kind] = [None if math.isnan(x) else float(x) for x in arr]
    return out
