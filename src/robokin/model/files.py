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
"""

from __future__ import annotations

import copy
import math
import os
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from robokin.exceptions import ModelError

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = [
    "document_from_robot",
    "load_robot",
    "read_yaml",
    "robot_from_document",
    "save_robot",
]

_LENGTH = {"m": 1.0, "mm": 1e-3}
_ANGLE = {"rad": 1.0, "deg": math.pi / 180.0}
# Extra top-level sections other modules validate (actuators, geometry, ...).
_SECTIONS: dict[str, Any] = {}


def register_section(key: str, handler: Any) -> None:
    """Register a handler ``handler(robot, value, file, units) -> Robot`` for a section.

    The handler receives the already-built robot and returns a new one with the
    section applied; it raises ModelError naming the field path on bad input.
    """
    _SECTIONS[key] = handler


def _schema():
    from typing import Literal

    from pydantic import BaseModel, ConfigDict, Field, field_validator

    class Strict(BaseModel):
        model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    class Units(Strict):
        length: Literal["m", "mm"] = "m"
        angle: Literal["rad", "deg"] = "rad"

    class Placement(Strict):
        xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
        rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def _check_limits(v):
        if v is not None and v[0] > v[1]:
            raise ValueError(f"limits reversed: lower {v[0]} > upper {v[1]}")
        return v

    class Row(Strict):
        name: str | None = None
        joint: Literal["revolute", "prismatic", "fixed"] = "revolute"
        a: float = 0.0
        alpha: float = 0.0
        d: float = 0.0
        theta: float = 0.0
        limits: tuple[float, float] | None = None
        sign: Literal[1, -1] = 1
        depends: dict[str, float] | None = None
        depends_offset: float = 0.0

        _lim = field_validator("limits")(_check_limits)

    class Op(Strict):
        op: Literal["rx", "ry", "rz", "tx", "ty", "tz", "frame"]
        value: float = 0.0
        name: str | None = None
        joint: Literal["revolute", "prismatic", "fixed"] = "fixed"
        limits: tuple[float, float] | None = None
        sign: Literal[1, -1] = 1
        depends: dict[str, float] | None = None
        depends_offset: float = 0.0

        _lim = field_validator("limits")(_check_limits)

    class Coordinate(Strict):
        name: str
        joint: Literal["revolute", "prismatic"] = "revolute"
        limits: tuple[float, float] | None = None

        _lim = field_validator("limits")(_check_limits)

    class RobotFile(BaseModel):
        model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
        name: str
        source: str = ""
        units: Units = Field(default_factory=Units)
        convention: Literal["standard", "modified", "elementary"] = "standard"
        joints: list[dict[str, Any]] = Field(min_length=1)
        coordinates: list[Coordinate] | None = None
        base: Placement | None = None
        tool: Placement | None = None
        actuators: Any = None
        geometry: Any = None
        collision: Any = None
        controller: Any = None  # a controller profile (robokin.trajectory.io), kept raw

    return RobotFile, Row, Op


def _field_path(loc: tuple) -> str:
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out


def _validate(model, data: Any, file: Any, prefix: tuple = ()):
    from pydantic import ValidationError

    try:
        return model.model_validate(data)
    except ValidationError as exc:
        err = exc.errors()[0]
        loc = prefix + tuple(err["loc"])
        msg = err["msg"]
        if err["type"] == "missing":
            msg = "missing required field"
        elif "input" in err and err["type"] not in ("extra_forbidden",):
            msg = f"{msg} (got {err['input']!r:.60})"
        elif err["type"] == "extra_forbidden":
            msg = "unknown field"
        raise ModelError(msg, file=file, field=_field_path(loc)) from None


def _placement(p, L: float, A: float) -> np.ndarray | None:
    if p is None:
        return None
    from robokin.spatial import pose_from_xyz_rpy

    return pose_from_xyz_rpy(np.array(p.xyz) * L, np.array(p.rpy) * A)


def robot_from_document(doc: Any, file: str | Path | None = None) -> Robot:
    """Build a Robot from a parsed robot-file document (a dict in file units).

    Raises:
        ModelError: naming ``file``, the field path and the reason.
    """
    from robokin.model.dh import chain_from_dh, chain_from_elementary
    from robokin.robot import Robot

    if not isinstance(doc, Mapping):
        raise ModelError(
            f"a robot file must be a mapping of fields, got {type(doc).__name__}",
            file=file,
        )
    RobotFile, Row, Op = _schema()
    spec = _validate(RobotFile, doc, file)
    L = _LENGTH[spec.units.length]
    A = _ANGLE[spec.units.angle]
    elementary = spec.convention == "elementary"
    rows = [
        _validate(Op if elementary else Row, r, file, ("joints", i))
        for i, r in enumerate(spec.joints)
    ]
    # Kinds of the independent coordinates, for unit conversion of 'depends'.
    kind_of: dict[str, str] = {}
    if spec.coordinates is not None:
        kind_of = {c.name: c.joint for c in spec.coordinates}
    else:
        for i, r in enumerate(rows):
            if r.joint != "fixed" and r.depends is None:
                kind_of[
                    r.name
                    or f"joint{sum(1 for x in rows[:i] if x.joint != 'fixed') + 1}"
                ] = r.joint

    def scale(kind: str) -> float:
        return L if kind == "prismatic" else A

    si_rows = []
    for r in rows:
        d = r.model_dump(exclude_none=True)
        kind = r.joint
        if elementary:
            is_rot = r.op[0] == "r"
            d["value"] = r.value * (A if is_rot else L)
            if r.op == "frame":
                si_rows.append({"op": "frame"})
                continue
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
        si_rows.append(d)
    coords = None
    if spec.coordinates is not None:
        coords = []
        for c in spec.coordinates:
            cd = {"name": c.name, "joint": c.joint}
            if c.limits is not None:
                cd["limits"] = [v * scale(c.joint) for v in c.limits]
            coords.append(cd)
    base = _placement(spec.base, L, A)
    tool = _placement(spec.tool, L, A)
    try:
        if elementary:
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
    robot = Robot(chain, name=spec.name, source=spec.source, path=file, meta=meta)
    for key in ("actuators", "geometry", "collision"):
        value = getattr(spec, key)
        if value is None:
            continue
        handler = _SECTIONS.get(key)
        if handler is None:
            _load_section_module(key)
            handler = _SECTIONS.get(key)
        if handler is None:
            raise ModelError(
                f"section '{key}' is not supported yet", file=file, field=key
            )
        robot = handler(robot, value, file, spec.units)
    # The file's document describes exactly this state; a changed copy (with_tool,
    # replace(...)) no longer matches it and is written from its model instead.
    robot.meta["document_state"] = _state(robot)
    return robot


def _state(robot: Robot) -> tuple:
    """What a stored document must still describe: the same objects, by identity."""
    return (robot.chain, robot.geometry, robot.actuators, robot.name, robot.source,
            robot.actuator_names, robot.actuator_limits)


def _document_matches(robot: Robot) -> bool:
    state = robot.meta.get("document_state")
    if state is None:
        return False
    now = _state(robot)
    return all(a is b or (isinstance(a, str) and a == b) for a, b in zip(state, now))


def _load_section_module(key: str) -> None:
    import importlib

    module = {
        "actuators": "robokin.model.coupling_files",
        "geometry": "robokin.model.geometry",
        "collision": "robokin.model.geometry",
    }.get(key)
    if module is None:
        return
    try:
        importlib.import_module(module)
    except ModuleNotFoundError as exc:
        if exc.name and exc.name.startswith("robokin"):
            return
        raise


def read_yaml(path: str | Path) -> Any:
    """Read a YAML file with ``yaml.safe_load``.

    Raises:
        ModelError: the file is missing or unreadable, or not valid YAML (with the
            line and column), naming the file.
    """
    import yaml

    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ModelError("no such file", file=path) from None
    except OSError as exc:
        raise ModelError(f"cannot read: {exc.strerror}", file=path) from None
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        raise ModelError(
            f"not valid YAML{where}: {getattr(exc, 'problem', exc)}", file=path
        ) from None


def load_robot(path: str | Path) -> Robot:
    """Load and validate a robot file.

    Raises:
        ModelError: the file is missing, not YAML, or fails validation (the message
            names the file, the field path and the reason).
    """
    path = Path(path)
    return robot_from_document(read_yaml(path), file=path)


def document_from_robot(robot: Robot) -> dict[str, Any]:
    """The robot-file document of a robot.

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


def _elementary_document(robot: Robot) -> dict[str, Any]:
    """Write any chain as elementary ops (translation xyz then rpy for each constant)."""
    from robokin.spatial import rpy_from_matrix

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
    if robot.actuators is not None:
        from robokin.model.coupling_files import section_from_robot

        doc["actuators"] = section_from_robot(robot)
    if robot.geometry is not None:
        from robokin.model.geometry import RobotGeometry, sections_from_geometry

        if isinstance(robot.geometry, RobotGeometry):
            doc.update(sections_from_geometry(robot.geometry))
    for key, T in (("base", chain.base), ("tool", chain.tool)):
        if not np.allclose(T, np.eye(4), atol=1e-15):
            doc[key] = {
                "xyz": [float(v) for v in T[:3, 3]],
                "rpy": [float(v) for v in rpy_from_matrix(T)],
            }
    return doc


def save_robot(robot: Robot, path: str | Path) -> Path:
    """Write the robot file atomically (temporary file, then rename).

    A failure never leaves a half-written file, and an existing file is replaced
    only once the new content is complete on disk.
    """
    import yaml

    path = Path(path)
    text = yaml.safe_dump(
        document_from_robot(robot), sort_keys=False, default_flow_style=None
    )
    directory = path.parent if str(path.parent) else Path(".")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=directory)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        # mkstemp makes 0600: keep an existing file's mode, else the umask's default
        if path.exists():
            mode = path.stat().st_mode & 0o7777
        else:
            mask = os.umask(0)
            os.umask(mask)
            mode = 0o666 & ~mask
        os.chmod(tmp, mode)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path
