"""The ``actuators:`` section of a robot file: motor coordinates ``q = A phi + b``.

Values are in the file's units (``units: {length: mm, angle: deg}``): a rotary
motor's coordinate is an angle, a linear motor's a length; joint values follow
their joint's kind. Either a matrix with an optional offset:

.. code-block:: yaml

    actuators:
      names: [m1, m2]                # optional, default motor1..motorM
      kinds: [rotary, rotary]        # optional, default rotary
      limits: [[-3600, 3600], ...]   # optional, motor units
      matrix: [[1, 0], [0, 0.5]]     # q = A phi + b: joint units per motor unit
      offset: [0, 0]                 # optional, joint units

or named drives, motors numbered in drive order:

.. code-block:: yaml

    actuators:
      drives:
        - {type: direct, joints: [shoulder, elbow]}           # one motor per joint
        - {type: gear, joint: wrist, ratio: 100, offset: 0}     # q = phi / ratio + offset
        - {type: screw, joint: z, lead: 5, ratio: 1}            # lead in length units/rev
        - {type: ball_screw_spline, joints: [rotate, lift], lead: 20, i: 1, j: 15}

See :mod:`robokin.model.coupling` for the maps. The robot-file reader applies the
section through its table (:data:`robokin.io.robot_files.SECTIONS`). Numbers must
be numbers (``ratio: "100"`` is refused).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from robokin._units import ANGLE_UNITS, LENGTH_UNITS
from robokin.exceptions import ModelError
from robokin.io.validate import validate_document
from robokin.model.coupling import (
    AffineMap,
    actuator_map,
    ball_screw_spline,
    direct,
    gear,
    screw,
)

if TYPE_CHECKING:
    from robokin.model.parts import RobotParts

__all__ = [
    "actuators_from_section",
    "apply_actuators_section",
    "section_from_robot",
    "section_model",
]



def _schema():
    from typing import Annotated, Literal

    from pydantic import BaseModel, ConfigDict, Field, StrictFloat, StrictStr

    # StrictFloat and StrictStr: numbers must be numbers ("100" and yes are refused)

    class Strict(BaseModel):
        model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    class Direct(Strict):
        type: Literal["direct"]
        joints: list[StrictStr] = Field(min_length=1)

    class Gear(Strict):
        type: Literal["gear"]
        joint: StrictStr
        ratio: StrictFloat
        offset: StrictFloat = 0.0

    class Screw(Strict):
        type: Literal["screw"]
        joint: StrictStr
        lead: StrictFloat
        ratio: StrictFloat = 1.0
        offset: StrictFloat = 0.0

    class BallScrewSpline(Strict):
        type: Literal["ball_screw_spline"]
        joints: tuple[StrictStr, StrictStr]
        lead: StrictFloat
        i: StrictFloat = 1.0
        j: StrictFloat = 1.0
        lift_sign: Literal[1, -1] = 1

    Drive = Annotated[Direct | Gear | Screw | BallScrewSpline,
                      Field(discriminator="type")]

    class Section(Strict):
        names: list[StrictStr] | None = None
        kinds: list[Literal["rotary", "linear"]] | None = None
        limits: list[tuple[StrictFloat, StrictFloat]] | None = None
        matrix: list[list[StrictFloat]] | None = None
        offset: list[StrictFloat] | None = None
        drives: list[Drive] | None = None

    return Section


def section_model() -> Any:
    """The pydantic model of the ``actuators:`` section (for its JSON Schema)."""
    return _schema()


def _validate(value: Any, file: Any):
    Section = _schema()
    if not isinstance(value, dict):
        raise ModelError(f"must be a mapping of fields, got {type(value).__name__}",
                         file=file, field="actuators")
    # A discriminated union adds the tag to the location: dropped.
    return validate_document(Section, value, file=file, prefix=("actuators",),
                             drop=("direct", "gear", "screw", "ball_screw_spline"))


def actuators_from_section(
    value: Any, joint_names: list[str], joint_kinds: list[str], file: Any = None,
    units: Any = None,
) -> tuple[AffineMap, tuple[str, ...] | None, np.ndarray | None, tuple[str, ...]]:
    """Parse an ``actuators:`` section into SI units.

    Args:
        value: The section (a mapping) in the file's units.
        joint_names: The robot's coordinate names (n).
        joint_kinds: ``"revolute"`` / ``"prismatic"`` per coordinate (n).
        file: The robot file, for error messages.
        units: The file's ``units`` (``.length`` ``"m"|"mm"``, ``.angle``
            ``"rad"|"deg"``); SI when None.

    Returns:
        ``(map, names or None, limits (m, 2) or None, kinds)`` with ``map`` the
        n x m :class:`AffineMap` ``q = A phi + b`` in SI units.

    Raises:
        ModelError: naming the file, the field path (``actuators.matrix``,
            ``actuators.drives[1].joints`` ...) and the reason; in particular a
            matrix that cannot be inverted (rank below the number of motors).
    """
    spec = _validate(value, file)
    L = LENGTH_UNITS[getattr(units, "length", "m")]
    A = ANGLE_UNITS[getattr(units, "angle", "rad")]
    n = len(joint_names)
    q_scale = np.array([A if k == "revolute" else L for k in joint_kinds])

    def fail(reason: str, field: str) -> ModelError:
        return ModelError(reason, file=file, field=field)

    if (spec.matrix is None) == (spec.drives is None):
        raise fail("give either 'matrix' (with an optional 'offset') or 'drives'",
                   "actuators")
    if spec.drives is not None:
        if spec.offset is not None:
            raise fail("'offset' goes with 'matrix'; drives carry their own offsets",
                       "actuators.offset")
        index = {nm: k for k, nm in enumerate(joint_names)}
        drives = []
        kinds: list[str] = []
        for d, drive in enumerate(spec.drives):
            where = f"actuators.drives[{d}]"
            joints = list(drive.joints) if hasattr(drive, "joints") else [drive.joint]
            key = "joints" if hasattr(drive, "joints") else "joint"
            for nm in joints:
                if nm not in index:
                    raise fail(f"unknown joint {nm!r}; joints: {list(joint_names)}",
                               f"{where}.{key}")
            jk = [joint_kinds[index[nm]] for nm in joints]
            try:
                if drive.type == "direct":
                    amap = direct(len(joints))
                    kinds += ["rotary" if k == "revolute" else "linear" for k in jk]
                elif drive.type == "gear":
                    if jk[0] != "revolute":
                        raise fail(f"a gear drives a revolute joint; {joints[0]!r} is "
                                   f"{jk[0]} (use 'screw')", f"{where}.joint")
                    amap = gear(drive.ratio, offset=drive.offset * A)
                    kinds.append("rotary")
                elif drive.type == "screw":
                    if jk[0] != "prismatic":
                        raise fail(f"a screw drives a prismatic joint; {joints[0]!r} is "
                                   f"{jk[0]} (use 'gear')", f"{where}.joint")
                    amap = screw(drive.lead * L, ratio=drive.ratio, offset=drive.offset * L)
                    kinds.append("rotary")
                else:
                    if jk != ["revolute", "prismatic"]:
                        raise fail(
                            "a ball-screw / ball-spline drives [rotation, lift]: a revolute "
                            f"then a prismatic joint; got {joints} ({jk[0]}, {jk[1]})",
                            f"{where}.joints")
                    amap = ball_screw_spline(drive.lead * L, drive.i, drive.j,
                                             lift_sign=drive.lift_sign)
                    kinds += ["rotary", "rotary"]
            except ModelError as exc:
                if exc.file is not None:
                    raise
                raise fail(exc.reason, where) from None
            drives.append((joints, amap))
        try:
            amap = actuator_map(joint_names, drives)
        except ModelError as exc:
            raise fail(exc.reason, "actuators.drives") from None
        m = amap.n_in
        if spec.kinds is not None and list(spec.kinds) != kinds:
            raise fail(f"the drives give motor kinds {kinds}, the section says "
                       f"{list(spec.kinds)}", "actuators.kinds")
    else:
        mat = spec.matrix
        if len(mat) != n:
            raise fail(f"expected {n} rows (one per joint: {list(joint_names)}), "
                       f"got {len(mat)}", "actuators.matrix")
        m = len(mat[0]) if mat else 0
        for r, row in enumerate(mat):
            if len(row) != m or m == 0:
                raise fail(f"row {r} has {len(row)} entries, expected {m or 'at least 1'}",
                           f"actuators.matrix[{r}]")
        if spec.kinds is not None and len(spec.kinds) != m:
            raise fail(f"expected {m} entries (one per motor), got {len(spec.kinds)}",
                       "actuators.kinds")
        kinds = list(spec.kinds) if spec.kinds is not None else ["rotary"] * m
        if spec.offset is not None and len(spec.offset) != n:
            raise fail(f"expected {n} entries (one per joint), got {len(spec.offset)}",
                       "actuators.offset")
        phi_scale = np.array([A if k == "rotary" else L for k in kinds])
        Af = np.array(mat, dtype=float)
        bf = np.zeros(n) if spec.offset is None else np.array(spec.offset, dtype=float)
        amap = AffineMap(q_scale[:, None] * Af / phi_scale[None, :], q_scale * bf)
        rank = int(np.linalg.matrix_rank(Af))
        if rank < m:
            raise fail(
                f"the actuator matrix ({n} x {m}) has rank {rank} < {m} motors: it "
                "cannot be inverted (two motors act alike, or a motor drives nothing), "
                "so motor values cannot be recovered from joint values",
                "actuators.matrix")
    if not amap.is_invertible:
        raise fail(f"the actuator map ({n} x {m}) cannot be inverted",
                   "actuators.drives" if spec.drives is not None else "actuators.matrix")
    phi_scale = np.array([A if k == "rotary" else L for k in kinds])
    names = None
    if spec.names is not None:
        if len(spec.names) != m:
            raise fail(f"expected {m} names (one per motor), got {len(spec.names)}",
                       "actuators.names")
        if len(set(spec.names)) != m:
            raise fail("motor names must be unique", "actuators.names")
        names = tuple(spec.names)
    limits = None
    if spec.limits is not None:
        if len(spec.limits) != m:
            raise fail(f"expected {m} [lower, upper] pairs (one per motor), "
                       f"got {len(spec.limits)}", "actuators.limits")
        for k, (lo, hi) in enumerate(spec.limits):
            if lo > hi:
                raise fail(f"limits reversed: lower {lo} > upper {hi}",
                           f"actuators.limits[{k}]")
        limits = np.array(spec.limits, dtype=float) * phi_scale[:, None]
    return amap, names, limits, tuple(kinds)


def apply_actuators_section(robot: RobotParts, value: Any, file: Any, units: Any) -> RobotParts:
    """The section reader: a copy of ``robot`` with its actuators (file units)."""
    chain = robot.chain
    amap, names, limits, kinds = actuators_from_section(
        value, list(robot.joint_names), [c.kind for c in chain.coordinates], file, units)
    return robot.replace(actuators=amap, actuator_names=names, actuator_limits=limits,
                         meta={**robot.meta, "actuator_kinds": kinds})


def section_from_robot(robot: RobotParts) -> dict[str, Any] | None:
    """The ``actuators:`` section (matrix form, SI units) of a robot, or None.

    For writing robots built in memory; files loaded from disk keep their own
    section.
    """
    if robot.actuators is None or robot.actuator_names is None:  # both or neither
        return None
    out: dict[str, Any] = {
        "names": list(robot.actuator_names),
        "kinds": list(robot.meta.get("actuator_kinds", ["rotary"] * robot.actuators.n_in)),
        "matrix": robot.actuators.matrix.tolist(),
    }
    if robot.actuators.offset.any():
        out["offset"] = robot.actuators.offset.tolist()
    lim = robot.actuator_limits
    if lim is not None and np.isfinite(lim).all():
        out["limits"] = lim.tolist()
    return out

