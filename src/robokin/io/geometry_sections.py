"""The ``geometry:`` and ``collision:`` sections of a robot file, and shape entries.

A shape entry (robot-file geometry, scene objects, a scene's tool) is a mapping in
the file's units, e.g. ``{type: capsule, radius: 60, from: [-408, 0, 0], to: [0,
0, 0]}``; :func:`shape_from_spec` turns it into a
:class:`~robokin.model.geometry.Shape` in metres. See the module docstring of
:mod:`robokin.model.geometry` for the keys, and ``docs/collision.md``.

The robot-file reader applies the two sections through its table
(:data:`robokin.io.robot_files.SECTIONS`): :func:`apply_geometry_section` and
:func:`apply_collision_section` read them, :func:`geometry_section` and
:func:`collision_section` write them for robots built in memory.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from robokin._text import short_repr
from robokin._validation import MAX_TRANSLATION
from robokin.exceptions import InputError, ModelError
from robokin.io.validate import list_of, tagged_union, union_of, unknown_key
from robokin.model.geometry import (
    LENGTH_UNITS,
    MESH_SUFFIXES,
    SHAPE_KINDS,
    RobotGeometry,
    Shape,
    mesh_file_problem,
    segment_pose,
)

if TYPE_CHECKING:
    from robokin.model.parts import RobotParts

__all__ = [
    "apply_collision_section",
    "apply_geometry_section",
    "collision_model",
    "collision_section",
    "geometry_model",
    "geometry_section",
    "number_field",
    "sections_from_geometry",
    "shape_from_spec",
    "shape_keys",
    "shape_models",
]

@functools.cache
def shape_models() -> dict[str, Any]:
    """The pydantic models of a shape entry, one per ``type`` (built once, lazily).

    They are the schema of a shape (the keys each type accepts, and their
    types) for the JSON Schemas of robot and scene files and for the key checks of
    :func:`shape_from_spec`; numbers are in the file's units.
    """
    from typing import Annotated, Literal

    from pydantic import BaseModel, ConfigDict, Field, StrictFloat, StrictStr

    Vec3 = tuple[StrictFloat, StrictFloat, StrictFloat]
    Positive = Annotated[StrictFloat, Field(gt=0)]

    class Shape(BaseModel):
        """A shape placed in its owner's frame (``xyz`` [length], ``rpy`` [angle])."""

        model_config = ConfigDict(extra="forbid", allow_inf_nan=False,
                                  populate_by_name=True)
        name: StrictStr = ""
        xyz: Vec3 = (0.0, 0.0, 0.0)
        rpy: Vec3 = (0.0, 0.0, 0.0)

    class Box(Shape):
        """A box centred on its frame: edge lengths along x, y, z."""

        type: Literal["box"]
        size: tuple[Positive, Positive, Positive]

    class Sphere(Shape):
        """A sphere centred on its frame."""

        type: Literal["sphere"]
        radius: Positive

    class Cylinder(Shape):
        """A cylinder: along its frame's z axis (``length``), or ``from`` -> ``to``."""

        type: Literal["cylinder"]
        radius: Positive
        length: Positive | None = None
        from_: Vec3 | None = Field(default=None, alias="from")
        to: Vec3 | None = None

    class Capsule(Cylinder):
        """A capsule (a cylinder with hemispherical ends), placed as a cylinder."""

        type: Literal["capsule"]  # type: ignore[assignment]

    class Mesh(Shape):
        """A mesh file (STL, OBJ, DAE, PLY, OFF, GLB, glTF), relative to the file."""

        type: Literal["mesh"]
        file: StrictStr
        units: Literal["m", "mm", "cm"] | None = None
        scale: StrictFloat = 1.0

    models = {"box": Box, "sphere": Sphere, "cylinder": Cylinder, "capsule": Capsule,
              "mesh": Mesh}
    return models


def shape_keys(kind: str) -> list[str]:
    """The keys a shape entry of ``type: kind`` accepts (from :func:`shape_models`)."""
    model = shape_models()[kind]
    return [f.alias or name for name, f in model.model_fields.items()]


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def number_field(
    spec: Mapping[str, Any], key: str, where: str, file: Any, count: int | None = None
):
    """``spec[key]``: a number (``count`` None) or a list of ``count`` numbers.

    Each must be a real number (text such as ``"12"`` and booleans are refused)
    of magnitude at most :data:`robokin._validation.MAX_TRANSLATION`.

    Args:
        spec: The mapping holding the field.
        key: The field.
        where: The mapping's field path, for the message.
        file: The file, for the message.
        count: How many numbers (None: one number, not a list).

    Returns:
        A float, or a float64 array of shape (count,).

    Raises:
        ModelError: naming the file and ``where.key``.
    """
    v = spec[key]

    def fine(x: Any) -> bool:
        return _is_number(x) and abs(x) <= MAX_TRANSLATION

    if count is None:
        ok = fine(v)
    else:
        ok = isinstance(v, (list, tuple)) and len(v) == count and all(map(fine, v))
    if not ok:
        what = "a number" if count is None else f"{count} numbers"
        what += f" of magnitude at most {MAX_TRANSLATION:g}"
        raise ModelError(
            f"expected {what}, got {short_repr(v)}", file=file, field=f"{where}.{key}"
        )
    return float(v) if count is None else np.array(v, dtype=float)


def shape_from_spec(
    spec: Any,
    *,
    length: float = 1.0,
    angle: float = 1.0,
    base_dir: Path | None = None,
    file: Any = None,
    where: str = "shape",
    owner: str = "",
) -> Shape:
    """Build a Shape from a file entry (a mapping in file units).

    Args:
        spec: ``{type: box|cylinder|sphere|capsule|mesh, ...}`` (see module docstring).
        length: File length unit in metres (1e-3 for mm).
        angle: File angle unit in radians.
        base_dir: Where relative mesh paths start.
        file: The file, for error messages.
        where: The field path, for error messages.
        owner: The link or object name, for error messages.

    Raises:
        ModelError: naming the file, the field path and the reason.
    """
    from robokin.spatial import pose_from_xyz_rpy

    if not isinstance(spec, Mapping):
        raise ModelError(
            f"a shape must be a mapping, got {short_repr(spec)}", file=file, field=where
        )
    kind = spec.get("type")
    if kind not in SHAPE_KINDS:
        raise ModelError(
            f"'type' must be one of {list(SHAPE_KINDS)}, got {short_repr(kind)}",
            file=file,
            field=f"{where}.type",
        )
    allowed = shape_keys(kind)
    for key in spec:
        if key not in allowed:
            raise ModelError(unknown_key(allowed), file=file, field=f"{where}.{key}")
    xyz = number_field(spec, "xyz", where, file, 3) * length if "xyz" in spec else np.zeros(3)
    rpy = number_field(spec, "rpy", where, file, 3) * angle if "rpy" in spec else np.zeros(3)
    if np.any(rpy):
        T = pose_from_xyz_rpy(xyz, rpy)
    else:  # no rotation: skip importing scipy for the common case
        T = np.eye(4)
        T[:3, 3] = xyz
    name = spec.get("name", "")
    if not isinstance(name, str):
        raise ModelError(f"expected a name (text), got {short_repr(name)}", file=file,
                         field=f"{where}.name")

    def need(key: str) -> None:
        if key not in spec:
            raise ModelError(
                "missing required field", file=file, field=f"{where}.{key}"
            )

    try:
        if kind == "box":
            need("size")
            return Shape(
                "box",
                tuple(number_field(spec, "size", where, file, 3) * length),
                T,
                name=name,
                owner=owner,
            )
        if kind == "sphere":
            need("radius")
            return Shape(
                "sphere",
                (number_field(spec, "radius", where, file) * length,),
                T,
                name=name,
                owner=owner,
            )
        if kind in ("cylinder", "capsule"):
            need("radius")
            r = number_field(spec, "radius", where, file) * length
            if "from" in spec or "to" in spec:
                need("from")
                need("to")
                if "length" in spec:
                    raise ModelError(
                        "give either 'length' or 'from'/'to', not both",
                        file=file,
                        field=f"{where}.length",
                    )
                p0 = number_field(spec, "from", where, file, 3) * length
                p1 = number_field(spec, "to", where, file, 3) * length
                S, L = segment_pose(p0, p1)
                return Shape(kind, (r, L), T @ S, name=name, owner=owner)
            need("length")
            L = number_field(spec, "length", where, file) * length
            return Shape(kind, (r, L), T, name=name, owner=owner)
        need("file")
        units = spec.get("units")
        if units is None:
            scale = length
        elif isinstance(units, str) and units in LENGTH_UNITS:
            scale = LENGTH_UNITS[units]
        else:
            raise ModelError(
                f"expected one of {list(LENGTH_UNITS)}, got {short_repr(units)}",
                file=file,
                field=f"{where}.units",
            )
        if "scale" in spec:
            scale *= number_field(spec, "scale", where, file)
        if not isinstance(spec["file"], str) or not spec["file"]:
            raise ModelError(f"expected a file name, got {short_repr(spec['file'])}",
                             file=file, field=f"{where}.file")
        path = Path(spec["file"]).expanduser()
        if not path.is_absolute() and base_dir is not None:
            path = base_dir / path
        problem = mesh_file_problem(path)
        if problem is not None:
            raise ModelError(
                ("mesh file not found: " if problem.startswith("no such file") else
                 "mesh file: ") + problem.removeprefix("no such file ")
                + (f" (link '{owner}')" if owner else ""),
                file=file,
                field=f"{where}.file",
            )
        if path.suffix.lower() not in MESH_SUFFIXES:
            raise ModelError(
                f"unsupported mesh format {short_repr(path.suffix)} "
                f"(use {list(MESH_SUFFIXES)})",
                file=file,
                field=f"{where}.file",
            )
        return Shape("mesh", (), T, name=name, file=path, scale=scale, owner=owner)
    except InputError as exc:
        raise ModelError(
            exc.reason, file=file, field=f"{where}.{exc.argument}"
        ) from None


def _units(units: Any) -> tuple[float, float]:
    length = getattr(units, "length", None) or (units or {}).get("length", "m")
    angle = getattr(units, "angle", None) or (units or {}).get("angle", "rad")
    return LENGTH_UNITS[length], (1.0 if angle == "rad" else np.pi / 180.0)


def _link_index(geo: RobotGeometry, name: Any, file: Any, field: str) -> int:
    """The index of a link by name; a ModelError listing the links if unknown."""
    try:
        return geo.index(name)
    except (InputError, TypeError):
        raise ModelError(f"unknown link {short_repr(name)}; the links are "
                         f"{list(geo.names)}", file=file, field=field) from None


def apply_geometry_section(robot: RobotParts, value: Any, file: Any, units: Any) -> RobotParts:
    """The ``geometry:`` section reader: a copy of ``robot`` with its link shapes.

    Args:
        robot: The robot built from the file so far.
        value: ``{link name: [shape entries]}`` in the file's units.
        file: The robot file (mesh paths resolve relative to its folder).
        units: The file's units (``.length``, ``.angle``).

    Raises:
        ModelError: naming the file, the field path and the reason.
    """
    L, A = _units(units)
    if not isinstance(value, Mapping):
        raise ModelError(
            "expected a mapping {link name: [shapes]}", file=file, field="geometry"
        )
    old = robot.geometry if isinstance(robot.geometry, RobotGeometry) else None
    empty = RobotGeometry.empty(robot)
    base_dir = Path(file).parent if file is not None else None
    per_link: dict[str, list[Shape]] = {}
    for key, items in value.items():
        _link_index(empty, key, file, f"geometry.{key}")
        if isinstance(items, Mapping):
            items = [items]
        if not isinstance(items, list):
            raise ModelError(
                "expected a list of shapes", file=file, field=f"geometry.{key}"
            )
        per_link[key] = [
            shape_from_spec(s, length=L, angle=A, base_dir=base_dir, file=file,
                            where=f"geometry.{key}[{i}]", owner=key)
            for i, s in enumerate(items)
        ]
    geo = RobotGeometry.from_mapping(robot, per_link)
    if old is not None:
        geo = replace(geo, exclude=old.exclude, exclude_adjacent=old.exclude_adjacent)
    return robot.replace(geometry=geo)


def apply_collision_section(robot: RobotParts, value: Any, file: Any, units: Any) -> RobotParts:
    """The ``collision:`` section reader: link pairs excluded from self-collision.

    Args:
        robot: The robot built from the file so far.
        value: ``{exclude: [[link, link], ...], exclude_adjacent: bool}``.
        file: The robot file, for messages.
        units: The file's units (unused: the section holds no quantities).

    Raises:
        ModelError: naming the file, the field path and the reason.
    """
    if not isinstance(value, Mapping):
        raise ModelError(
            "expected a mapping with 'exclude'", file=file, field="collision"
        )
    accepted = list(collision_model().model_fields)
    for key in value:
        if key not in accepted:
            raise ModelError(unknown_key(accepted), file=file, field=f"collision.{key}")
    geo = robot.geometry if isinstance(robot.geometry, RobotGeometry) else None
    if geo is None:
        geo = RobotGeometry.empty(robot)
    pairs = value.get("exclude", []) or []
    if not isinstance(pairs, list):
        raise ModelError(
            "expected a list of [link, link] pairs",
            file=file,
            field="collision.exclude",
        )
    out = []
    for i, p in enumerate(pairs):
        if not (isinstance(p, list | tuple) and len(p) == 2):
            raise ModelError(
                f"expected a pair [link, link], got {short_repr(p)}",
                file=file,
                field=f"collision.exclude[{i}]",
            )
        for n in p:
            _link_index(geo, n, file, f"collision.exclude[{i}]")
        out.append(tuple(p))
    adjacent = value.get("exclude_adjacent", True)
    if not isinstance(adjacent, bool):
        raise ModelError(
            f"expected true or false, got {short_repr(adjacent)}",
            file=file,
            field="collision.exclude_adjacent",
        )
    geo = replace(geo.with_exclusions(out), exclude_adjacent=adjacent)
    return robot.replace(geometry=geo)


@functools.cache
def collision_model() -> Any:
    """The pydantic model of the ``collision:`` section (its keys and types)."""
    from pydantic import BaseModel, ConfigDict, StrictBool, StrictStr

    class Collision(BaseModel):
        """Link pairs never checked against each other (self-collision)."""

        model_config = ConfigDict(extra="forbid")
        exclude: list[tuple[StrictStr, StrictStr]] = []
        exclude_adjacent: StrictBool = True

    return Collision


def geometry_model() -> Any:
    """The type of the ``geometry:`` section: ``{link name: [shape, ...] | shape}``."""
    from pydantic import StrictStr

    one = tagged_union(*shape_models().values())
    return dict.__class_getitem__((StrictStr, union_of(list_of(one), one)))


def geometry_section(robot: RobotParts) -> dict[str, Any] | None:
    """The ``geometry:`` section (SI units) of a robot, or None when it has none."""
    if not isinstance(robot.geometry, RobotGeometry):
        return None
    return sections_from_geometry(robot.geometry).get("geometry")


def collision_section(robot: RobotParts) -> dict[str, Any] | None:
    """The ``collision:`` section of a robot, or None when it has nothing to say."""
    if not isinstance(robot.geometry, RobotGeometry):
        return None
    return sections_from_geometry(robot.geometry).get("collision")


def sections_from_geometry(geometry: RobotGeometry) -> dict[str, Any]:
    """The ``geometry:`` and ``collision:`` robot-file sections (SI units).

    The inverse of the section parsers, for writing robots built in memory (e.g.
    imported from URDF): shapes as ``{type, name, xyz, rpy, size | radius + length
    | file + scale}`` per link, mesh paths absolute.
    """
    from robokin.spatial import rpy_from_matrix

    out: dict[str, Any] = {}
    per_link: dict[str, list[dict[str, Any]]] = {}
    for name, shapes in zip(geometry.names, geometry.shapes):
        specs = []
        for sh in shapes:
            spec: dict[str, Any] = {"type": sh.kind}
            if sh.name:
                spec["name"] = sh.name
            P = sh.placement
            if np.any(P[:3, 3]):
                spec["xyz"] = [float(v) for v in P[:3, 3]]
            if not np.allclose(P[:3, :3], np.eye(3), atol=1e-15):
                spec["rpy"] = [float(v) for v in rpy_from_matrix(P)]
            if sh.kind == "box":
                spec["size"] = list(sh.size)
            elif sh.kind == "sphere":
                spec["radius"] = sh.size[0]
            elif sh.kind in ("cylinder", "capsule"):
                spec["radius"], spec["length"] = sh.size
            elif sh.file is not None:  # a mesh (the one kind with a file)
                spec["file"] = str(Path(sh.file).resolve())
                spec["units"] = "m"
                if sh.scale != 1.0:
                    spec["scale"] = float(sh.scale)
            specs.append(spec)
        if specs:
            per_link[name] = specs
    if per_link:
        out["geometry"] = per_link
    collision: dict[str, Any] = {}
    if geometry.exclude:
        collision["exclude"] = sorted(sorted(p) for p in geometry.exclude if len(p) == 2)
    if not geometry.exclude_adjacent:
        collision["exclude_adjacent"] = False
    if collision:
        out["collision"] = collision
    return out
