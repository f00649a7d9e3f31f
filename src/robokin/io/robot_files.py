"""Robot files (YAML): load, validate field by field, save atomically.

A robot file declares its units once; everything is converted to SI here, at the
edge. The schema (pydantic, imported lazily) is below; see ``docs/robot-files.md``.

.. code-block:: yaml

    name: ur5
    source: Universal Robots' published DH parameters
    units: {length: mm, angle: deg}
    convention: standard            # standard | modified | elementary
    joints:
      - {name: shoulder_pan, joint: revolute, a: 0, alpha: 90, d: 89.159, theta: 0,
         limits: [-360, 360]}
    base: {xyz: [0, 0, 0], rpy: [0, 0, 0]}   # optional
    tool: {xyz: [0, 0, 0], rpy: [0, 0, 0]}   # optional

Sections besides the chain (``actuators``, ``geometry``, ``collision``,
``dynamics``, ``rate_limits``) are read and written by the functions of
:data:`SECTIONS`, an explicit table.

Numbers must be numbers (``a: "12"`` and ``alpha: yes`` are refused), a file holds
at most :data:`MAX_JOINTS` rows, names are at most :data:`MAX_NAME` characters and
``source`` :data:`MAX_SOURCE`. A file without ``units:`` whose lengths only make
sense in millimetres (or angles in degrees) loads, with a warning naming the
likely unit. Errors name the file, the line and the field path.
"""

from __future__ import annotations

import copy
import math
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from robokin._text import control_character
from robokin._units import ANGLE_UNITS, LENGTH_UNITS
from robokin._validation import MAX_TRANSLATION
from robokin.exceptions import ModelError
from robokin.io import (
    actuator_section,
    dynamics_section,
    geometry_sections,
    rate_limits_section,
)
from robokin.io.atomic import write_atomic
from robokin.io.text_files import MAX_TEXT_BYTES
from robokin.io.validate import list_of, union_of, validate_document
from robokin.io.yaml_reader import read_yaml_document
from robokin.model.dh import chain_from_dh, chain_from_elementary
from robokin.model.parts import RobotParts
from robokin.spatial import pose_from_xyz_rpy, rpy_from_matrix

__all__ = [
    "MAX_JOINTS",
    "MAX_NAME",
    "MAX_SOURCE",
    "SECTIONS",
    "SectionIO",
    "document_from_robot",
    "file_model",
    "load_parts",
    "parts_from_document",
    "save_robot",
]

#: Most joint rows (or elementary operations) a robot file may hold.
MAX_JOINTS = 1000
#: Longest name (robot, joint, coordinate) [characters].
MAX_NAME = 200
#: Longest ``source`` text [characters].
MAX_SOURCE = 4096
# Beyond these a length read as metres (an angle read as radians) is implausible.
_PLAUSIBLE_LENGTH = 20.0
_PLAUSIBLE_ANGLE = 2 * math.pi + 1e-9


@dataclass(frozen=True)
class SectionIO:
    """How one optional robot-file section is read and written.

    Attributes:
        read: ``read(parts, value, file, units) -> RobotParts``: a copy of the
            parts with the section applied (``units`` the file's); raises ModelError
            naming the field path.
        write: ``write(parts) -> value or None``: the section (SI units) of
            parts (a robot) built in memory, None when it has nothing to write.
        model: ``model() -> type``: the section's pydantic model (or type), for
            the robot file's JSON Schema (:func:`file_model`); None: any value.
    """

    read: Callable[[Any, Any, Any, Any], Any]
    write: Callable[[Any], Any]
    model: Callable[[], Any] | None = None


#: The optional sections, in the order they are applied.
SECTIONS: dict[str, SectionIO] = {
    "actuators": SectionIO(actuator_section.apply_actuators_section,
                           actuator_section.section_from_robot,
                           actuator_section.section_model),
    "geometry": SectionIO(geometry_sections.apply_geometry_section,
                          geometry_sections.geometry_section,
                          geometry_sections.geometry_model),
    "collision": SectionIO(geometry_sections.apply_collision_section,
                           geometry_sections.collision_section,
                           geometry_sections.collision_model),
    "dynamics": SectionIO(dynamics_section.apply_dynamics_section,
                          dynamics_section.dynamics_section),
    "rate_limits": SectionIO(rate_limits_section.apply_rate_limits_section,
                             rate_limits_section.section_from_robot),
}


def _printable(name: str) -> str:
    problem = control_character(name)
    if problem is not None:
        raise ValueError(problem)
    return name


def _schema():
    from typing import Annotated, Literal

    from pydantic import (
        AfterValidator,
        BaseModel,
        BeforeValidator,
        ConfigDict,
        Field,
        StrictFloat,
        StrictInt,
        StrictStr,
    )

    Name = Annotated[StrictStr, Field(max_length=MAX_NAME), AfterValidator(_printable)]
    Sign = Literal[1, -1]

    class Strict(BaseModel):
        model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    class Units(Strict):
        length: Literal["m", "mm"] = "m"
        angle: Literal["rad", "deg"] = "rad"

    class Placement(Strict):
        xyz: tuple[StrictFloat, StrictFloat, StrictFloat] = (0.0, 0.0, 0.0)
        rpy: tuple[StrictFloat, StrictFloat, StrictFloat] = (0.0, 0.0, 0.0)

    def _check_limits(v):
        if v is not None and v[0] > v[1]:
            raise ValueError(f"limits reversed: lower {v[0]} > upper {v[1]}")
        return v

    def _check_sign(v):
        if isinstance(v, bool):
            raise ValueError("sign must be 1 or -1, got a boolean")
        return v

    # the field types every joint entry shares, each with its check
    Limits = Annotated[tuple[StrictFloat, StrictFloat], AfterValidator(_check_limits)]
    JointSign = Annotated[Sign, StrictInt, BeforeValidator(_check_sign)]
    JointKind = Literal["revolute", "prismatic", "fixed"]

    class Row(Strict):
        name: Name | None = None
        joint: JointKind = "revolute"
        a: StrictFloat = 0.0
        alpha: StrictFloat = 0.0
        d: StrictFloat = 0.0
        theta: StrictFloat = 0.0
        limits: Limits | None = None
        sign: JointSign = 1
        depends: dict[Name, StrictFloat] | None = None
        depends_offset: StrictFloat = 0.0

    class Op(Strict):
        op: Literal["rx", "ry", "rz", "tx", "ty", "tz", "frame"]
        value: StrictFloat = 0.0
        name: Name | None = None
        joint: JointKind = "fixed"
        limits: Limits | None = None
        sign: JointSign = 1
        depends: dict[Name, StrictFloat] | None = None
        depends_offset: StrictFloat = 0.0

    class Coordinate(Strict):
        name: Name
        joint: Literal["revolute", "prismatic"] = "revolute"
        limits: Limits | None = None

    class RobotFile(Strict):
        name: Name
        source: Annotated[StrictStr, Field(max_length=MAX_SOURCE)] = ""
        units: Units = Field(default_factory=Units)
        convention: Literal["standard", "modified", "elementary"] = "standard"
        joints: list[dict[str, Any]] = Field(min_length=1, max_length=MAX_JOINTS)
        coordinates: list[Coordinate] | None = Field(default=None,
                                                     max_length=MAX_JOINTS)
        base: Placement | None = None
        tool: Placement | None = None
        actuators: Any = None
        geometry: Any = None
        collision: Any = None
        dynamics: Any = None  # link masses and torque limits (io/dynamics_section.py)
        rate_limits: Any = None  # per-joint speed/acceleration/jerk (io.rate_limits_section)
        controller: Any = None  # a controller profile (robokin.trajectory.io), kept raw

    return RobotFile, Row, Op


def file_model() -> Any:
    """The pydantic model of a whole robot file, for its JSON Schema.

    The validating model with the parts it checks in a second step typed too: a
    joint row is a DH row or (``convention: elementary``) an elementary
    operation, and each section of :data:`SECTIONS` that declares a model has
    it. Every other field is the validating model's own, so the schema follows
    the reader.
    """
    from pydantic import Field, create_model

    RobotFile, Row, Op = _schema()
    fields: dict[str, Any] = {"joints": (
        list_of(union_of(Row, Op)),
        Field(min_length=1, max_length=MAX_JOINTS,
              description="The chain, base to tool: DH rows, or elementary "
                          "operations when convention is elementary."))}
    for key, section in SECTIONS.items():
        if section.model is not None and key in RobotFile.model_fields:
            fields[key] = (union_of(section.model(), None), None)
    Row.__doc__ = "A DH row (standard or modified): one joint or a fixed frame."
    Op.__doc__ = "An elementary operation: rx ry rz tx ty tz, or a frame marker."
    return create_model("RobotFile", __base__=RobotFile,
                        __doc__="A robot file: a serial arm, in the units it declares.",
                        **fields)


def _placement(p, L: float, A: float) -> np.ndarray | None:
    if p is None:
        return None
    return pose_from_xyz_rpy(np.array(p.xyz) * L, np.array(p.rpy) * A)


def _validated(doc: Any, file: Any) -> tuple[Any, list[Any]]:
    """The validated top level and joint rows (still in file units)."""
    if not isinstance(doc, Mapping):
        hint = ""
        if isinstance(doc, str) and doc.lstrip().startswith("<"):
            hint = ("; this looks like XML (a URDF?): read it with "
                    "robokin.Robot.from_urdf(path) or 'robokin import FILE -o ROBOT.yaml'")
        raise ModelError(
            f"a robot file must be a mapping of fields, got {type(doc).__name__}{hint}",
            file=file,
        )
    RobotFile, Row, Op = _schema()
    joints = doc.get("joints")
    if isinstance(joints, list) and len(joints) > MAX_JOINTS:
        raise ModelError(f"{len(joints):,} rows; a robot file holds at most "
                         f"{MAX_JOINTS:,}", file=file, field="joints")
    spec = validate_document(RobotFile, doc, file=file)
    row_model = Op if spec.convention == "elementary" else Row
    rows = [validate_document(row_model, r, file=file, prefix=("joints", i))
            for i, r in enumerate(spec.joints)]
    return spec, rows


def _coordinate_kinds(spec: Any, rows: list[Any]) -> dict[str, str]:
    """Kinds of the independent coordinates, for unit conversion of 'depends'."""
    if spec.coordinates is not None:
        return {c.name: c.joint for c in spec.coordinates}
    kind_of: dict[str, str] = {}
    k = 0
    for r in rows:
        if r.joint == "fixed":
            continue
        k += 1
        if r.depends is None:
            kind_of[r.name or f"joint{k}"] = r.joint
    return kind_of


def _si_rows(spec: Any, rows: list[Any], L: float, A: float) -> list[dict[str, Any]]:
    """The joint rows in SI units, as the DH and elementary chain builders take them."""
    elementary = spec.convention == "elementary"
    kind_of = _coordinate_kinds(spec, rows)

    def scale(kind: str) -> float:
        return L if kind == "prismatic" else A

    out = []
    for r in rows:
        d = r.model_dump(exclude_none=True)
        kind = r.joint
        if elementary:
            if r.op == "frame":
                out.append({"op": "frame"})
                continue
            d["value"] = r.value * (A if r.op[0] == "r" else L)
        else:
            for key, s in (("a", L), ("d", L), ("alpha", A), ("theta", A)):
                d[key] = getattr(r, key) * s
        if r.limits is not None:
            d["limits"] = [v * scale(kind) for v in r.limits]
        if r.depends is not None:
            d["depends"] = {
                k: v * scale(kind) / scale(kind_of.get(k, kind))
                for k, v in r.depends.items()
            }
            d["depends_offset"] = r.depends_offset * scale(kind)
        else:
            d.pop("depends_offset", None)
        if elementary and kind == "fixed":
            for key in ("sign", "limits"):
                d.pop(key, None)
        out.append(d)
    return out


def _row_values(si_rows: list[dict[str, Any]], op: str, fields: tuple[str, str],
                with_limits: bool) -> list[tuple[str, float]]:
    """The chain rows' values of one quantity (field path, SI value), row by row.

    ``op`` is the first letter of the elementary ops holding it (``"t"``
    lengths, ``"r"`` angles), ``fields`` the DH fields holding it; with
    ``with_limits`` a prismatic joint's limits follow its row's values.
    """
    out: list[tuple[str, float]] = []
    for i, d in enumerate(si_rows):
        where = f"joints[{i}]"
        if "op" in d:
            if d["op"][0] == op:
                out.append((f"{where}.value", d["value"]))
        else:
            out += [(f"{where}.{f}", d[f]) for f in fields]
        if with_limits and d.get("joint") == "prismatic" and "limits" in d:
            out += [(f"{where}.limits", v) for v in d["limits"]]
    return out


def _lengths(spec: Any, si_rows: list[dict[str, Any]], L: float
             ) -> list[tuple[str, float]]:
    """Every length of the file (field path, value in metres)."""
    out = _row_values(si_rows, "t", ("a", "d"), with_limits=True)
    for key in ("base", "tool"):
        p = getattr(spec, key)
        if p is not None:
            out += [(f"{key}.xyz", v * L) for v in p.xyz]
    return out


def _angles(spec: Any, si_rows: list[dict[str, Any]]) -> list[tuple[str, float]]:
    """Every angle of the chain rows (field path, value in radians)."""
    return _row_values(si_rows, "r", ("alpha", "theta"), with_limits=False)


def _check_lengths(lengths: list[tuple[str, float]], file: Any) -> None:
    for where, v in lengths:
        if abs(v) > MAX_TRANSLATION:
            raise ModelError(f"{v:g} m is beyond the {MAX_TRANSLATION:g} m robokin "
                             "accepts for a length", file=file, field=where)


def _warn_units(doc: Mapping, lengths: list[tuple[str, float]],
                angles: list[tuple[str, float]], file: Any) -> None:
    """Warn when the numbers only make sense in mm or degrees.

    Without ``units:`` the file is read in metres and radians; with ``units:
    {angle: rad}`` (or ``length: m``) it says so itself. Either way a length
    beyond 20 m or an angle beyond 2 pi (``alpha: 90``) is named, with the unit
    it suggests.
    """
    units = doc.get("units") if isinstance(doc.get("units"), Mapping) else None
    hints = []
    # (values, units: key, SI unit, the other unit, its word; the plausible bound)
    for values, key, si, other, word, bound in (
            (lengths, "length", "m", "mm", "millimetres", _PLAUSIBLE_LENGTH),
            (angles, "angle", "rad", "deg", "degrees", _PLAUSIBLE_ANGLE)):
        if not values or (units is not None and units.get(key, si) != si):
            continue
        where, v = max(values, key=lambda wv: abs(wv[1]))
        if abs(v) > bound:
            article = "an" if key[0] in "aeiou" else "a"
            hints.append(f"{article} {key} of {v:g} {si} ({where}) suggests {word}: "
                         + (f"add 'units: {{{key}: {other}}}'" if units is None else
                            f"declare '{key}: {other}' in units:"))
    if hints:
        name = "the robot file" if file is None else str(file)
        said = ("has no 'units:', so it is read in metres and radians" if units is None
                else f"declares units: {{length: {units.get('length', 'm')}, "
                     f"angle: {units.get('angle', 'rad')}}}")
        warnings.warn(f"{name} {said}; {'; '.join(hints)}", UserWarning, stacklevel=4)


def parts_from_document(doc: Any, file: str | Path | None = None) -> RobotParts:
    """The robot parts of a parsed robot-file document (a dict in file units).

    :meth:`robokin.robot.Robot.from_parts` makes them a Robot.

    Raises:
        ModelError: naming ``file``, the field path and the reason.
    """
    spec, rows = _validated(doc, file)
    L = LENGTH_UNITS[spec.units.length]
    A = ANGLE_UNITS[spec.units.angle]
    si_rows = _si_rows(spec, rows, L, A)
    lengths = _lengths(spec, si_rows, L)
    _check_lengths(lengths, file)
    _warn_units(doc, lengths, _angles(spec, si_rows), file)
    coords = None
    if spec.coordinates is not None:
        coords = []
        for c in spec.coordinates:
            cd: dict[str, Any] = {"name": c.name, "joint": c.joint}
            if c.limits is not None:
                s = L if c.joint == "prismatic" else A
                cd["limits"] = [v * s for v in c.limits]
            coords.append(cd)
    base = _placement(spec.base, L, A)
    tool = _placement(spec.tool, L, A)
    try:
        if spec.convention == "elementary":
            chain = chain_from_elementary(
                si_rows, base=base, tool=tool, coordinates=coords
            )
        else:
            chain = chain_from_dh(
                si_rows, spec.convention, base=base, tool=tool, coordinates=coords
            )
    except ModelError as exc:
        field = (exc.field or "").replace("rows[", "joints[").replace("ops[", "joints[")
        raise ModelError(exc.reason, file=file, field=field or None) from None
    meta: dict[str, Any] = {"document": copy.deepcopy(dict(doc))}
    if spec.controller is not None:
        # Validated where it is used: robokin.trajectory.io.ControllerProfile.
        meta["controller"] = copy.deepcopy(spec.controller)
    parts = RobotParts(chain, name=spec.name, source=spec.source, path=file, meta=meta)
    for key, section in SECTIONS.items():
        value = getattr(spec, key)
        if value is not None:
            parts = section.read(parts, value, file, spec.units)
    # The file's document describes exactly this state; a changed copy (with_tool,
    # replace(...)) no longer matches it and is written from its model instead.
    return parts.replace(meta={**parts.meta, "document_state": _state(parts)})


def _state(robot: RobotParts) -> tuple[object, ...]:
    """What a stored document must still describe: the same objects, by identity."""
    return (robot.chain, robot.geometry, robot.actuators, robot.name, robot.source,
            robot.actuator_names, robot.actuator_limits, robot.dynamics,
            robot.rate_limits)


def _document_matches(robot: RobotParts) -> bool:
    state = robot.meta.get("document_state")
    if state is None:
        return False
    now = _state(robot)
    return all(a is b or (isinstance(a, str) and a == b) for a, b in zip(state, now))


def load_parts(path: str | Path, *, max_bytes: int = MAX_TEXT_BYTES,
               max_nodes: int | None = None) -> RobotParts:
    """Load and validate a robot file: the robot's parts.

    ``robokin.load(path)`` makes them a Robot.

    Args:
        path: The robot file (YAML).
        max_bytes: The largest file accepted [bytes].
        max_nodes: The most YAML values accepted, aliases expanded (default: see
            :func:`robokin.io.yaml_reader.parse_yaml`).

    Raises:
        ModelError: the file is missing, too large, binary, not YAML, or fails
            validation (the message names the file, the line, the field path
            and the reason).
    """
    path = Path(path)
    ydoc = read_yaml_document(path, max_bytes=max_bytes, max_nodes=max_nodes)
    try:
        return parts_from_document(ydoc.data, file=path)
    except ModelError as exc:
        raise ydoc.locate(exc) from None


def document_from_robot(robot: RobotParts) -> dict[str, Any]:
    """The robot-file document of a robot (or of robot parts).

    Robots loaded from a file, and not changed since, return that file's document
    unchanged (units kept). Others (built in code, or changed with ``with_tool``,
    ``with_base`` or ``replace``) are written as an elementary sequence in SI units
    that reproduces their canonical chain exactly, with their actuators and
    geometry.
    """
    doc = robot.meta.get("document")
    if doc is not None and _document_matches(robot):
        return copy.deepcopy(doc)
    return _elementary_document(robot)


def _elementary_document(robot: RobotParts) -> dict[str, Any]:
    """Write any chain as elementary ops (translation xyz then rpy for each constant)."""
    chain = robot.chain

    def const_ops(T: np.ndarray) -> list[dict[str, Any]]:
        ops: list[dict[str, Any]] = []
        if np.allclose(T, np.eye(4), atol=1e-15):
            return ops
        for ax, v in zip("xyz", T[:3, 3]):
            if abs(v) > 1e-15:
                ops.append({"op": f"t{ax}", "value": float(v)})
        r, p, y = (float(v) for v in rpy_from_matrix(T))
        for ax, v in (("z", y), ("y", p), ("x", r)):
            if abs(v) > 1e-15:
                ops.append({"op": f"r{ax}", "value": v})
        return ops

    ops: list[dict[str, Any]] = const_ops(chain.head)
    M, c = chain.coupling.matrix, chain.coupling.offset
    coord_names = [x.name for x in chain.coordinates]
    explicit = not chain.coupling.is_identity
    for k, j in enumerate(chain.joints):
        op: dict[str, Any] = {
            "op": "rz" if j.kind == "revolute" else "tz",
            "joint": j.kind,
            "name": j.name,
            "value": j.offset,
        }
        if j.sign != 1.0:
            op["sign"] = -1
        if explicit:
            row = M[k]
            is_self = (
                j.name in coord_names
                and row[coord_names.index(j.name)] == 1.0
                and (np.count_nonzero(row) == 1 and c[k] == 0.0)
            )
            if not is_self:
                op["depends"] = {
                    coord_names[i]: float(row[i]) for i in np.flatnonzero(row)
                }
                op["depends_offset"] = float(c[k])
        elif all(np.isfinite(j.limits)):
            op["limits"] = list(j.limits)
        ops.append(op)
        F = chain.frame_offsets[k]
        if np.allclose(F, np.eye(4), atol=1e-15):
            ops += const_ops(chain.link_offsets[k])
        else:
            ops += const_ops(F) + [{"op": "frame"}] + const_ops(chain.link_offsets[k])
    doc: dict[str, Any] = {
        "name": robot.name,
        "source": robot.source,
        "units": {"length": "m", "angle": "rad"},
        "convention": "elementary",
        "joints": ops,
    }
    if explicit:
        doc["coordinates"] = [
            {
                "name": x.name,
                "joint": x.kind,
                **({"limits": list(x.limits)} if all(np.isfinite(x.limits)) else {}),
            }
            for x in chain.coordinates
        ]
    for key, section in SECTIONS.items():
        value = section.write(robot)
        if value is not None:
            doc[key] = value
    for key, T in (("base", chain.base), ("tool", chain.tool)):
        if not np.allclose(T, np.eye(4), atol=1e-15):
            doc[key] = {
                "xyz": [float(v) for v in T[:3, 3]],
                "rpy": [float(v) for v in rpy_from_matrix(T)],
            }
    return doc


def save_robot(robot: RobotParts, path: str | Path) -> Path:
    """Write the robot file atomically (see :func:`robokin.io.atomic.write_atomic`).

    A failure never leaves a half-written file, and an existing file is replaced
    only once the new content is complete on disk.

    The document is read back (in memory, as :func:`load_parts` would read the
    file) before anything is written: a robot whose file robokin would refuse
    to load (a length beyond :data:`~robokin._validation.MAX_TRANSLATION`, a
    name it cannot hold) is refused here, naming the field, and no file is
    written.

    Raises:
        InputError: the folder is missing or read-only, or ``path`` is a folder.
        ModelError: the file would not load back (naming ``path``, the field and
            the reason).
    """
    import yaml

    text = yaml.safe_dump(
        document_from_robot(robot), sort_keys=False, default_flow_style=None
    )
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the loader's unit hints: not a refusal
            parts_from_document(yaml.safe_load(text), file=path)
    except ModelError as exc:
        raise ModelError(f"{exc.reason}; robokin would refuse this robot file, so it "
                         "is not written", file=path, field=exc.field) from None
    return write_atomic(path, text)
