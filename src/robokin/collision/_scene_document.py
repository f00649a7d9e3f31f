"""The fields of a scene document (YAML or JSON), read and checked one by one.

:class:`SceneDocument` reads the units, the robot's placement, the tool, the
objects, the exclusions and the named poses of a parsed scene file, converting
lengths and angles to SI; :meth:`robokin.collision.Scene.from_document` assembles
the scene from them. Every error names the file and the field.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from robokin._text import control_character, short_repr
from robokin._units import ANGLE_UNITS, LENGTH_UNITS
from robokin.exceptions import ModelError
from robokin.io.geometry_sections import number_field, shape_from_spec
from robokin.io.scene_files import scene_section_keys
from robokin.io.validate import unknown_key
from robokin.model.geometry import Shape
from robokin.spatial import pose_from_xyz_rpy

_LENGTH = {**LENGTH_UNITS, "cm": 1e-2}  # scenes also take centimetres

def _text(value: Any, file: Any, field: str) -> str:
    """A name from a scene file: text of at most 200 characters."""
    if not isinstance(value, str) or len(value) > 200:
        raise ModelError(f"expected a name (text, at most 200 characters), got "
                         f"{short_repr(value)}", file=file, field=field)
    problem = control_character(value)
    if problem is not None:
        raise ModelError(f"{problem} ({short_repr(value)})", file=file, field=field)
    return value


def _check_pair(objects: Sequence[str], pair: Sequence[str], file: Any, field: str
                ) -> None:
    """An exclusion is [robot link, object]: the object must be one of ``objects``.

    The link is checked when the scene meets a robot (:meth:`Scene.attach`).
    """
    link, obj = pair
    if obj not in objects and link in objects:
        link, obj = obj, link  # [object, link]: the order does not matter
    if obj not in objects:
        raise ModelError(f"no object {short_repr(obj)} in this scene; a pair is "
                         f"[robot link, object], the objects are {list(objects)}",
                         file=file, field=field)
    if link in objects:
        raise ModelError(f"{short_repr(link)} and {short_repr(obj)} are both objects; "
                         "objects are never checked against each other, a pair is "
                         "[robot link, object]", file=file, field=field)


def _robot_file(name: str, file: Any) -> str:
    """A scene's robot: a robot file next to the scene file (as a path), or ``name``.

    A relative ``.yaml`` / ``.yml`` name is read relative to the scene file, as a
    motion file's ``robot:`` is; anything else (a built-in name, an absolute path)
    is kept as written.
    """
    candidate = Path(name)
    if (file is None or candidate.is_absolute()
            or candidate.suffix.lower() not in (".yaml", ".yml")):
        return name
    beside = Path(file).parent / candidate
    return str(beside) if beside.is_file() else name


class SceneDocument:
    """A parsed scene document, its top-level keys and units checked.

    Args:
        doc: The parsed document (a mapping).
        file: The file it came from (for messages and relative mesh paths).

    Raises:
        ModelError: not a mapping, an unknown key, or bad units.
    """

    def __init__(self, doc: Any, file: str | Path | None) -> None:
        if not isinstance(doc, Mapping):
            raise ModelError("a scene file must be a mapping of fields", file=file)
        allowed = scene_section_keys()
        for key in doc:
            if key not in allowed:
                raise ModelError(unknown_key(allowed), file=file, field=str(key))
        self.doc, self.file = doc, file
        self.base_dir = Path(file).parent if file is not None else None
        self.L, self.A = self._units()

    def _units(self) -> tuple[float, float]:
        file = self.file
        units = self.doc.get("units") or {}
        if not isinstance(units, Mapping):
            raise ModelError(
                "expected {length: m|mm, angle: rad|deg}", file=file, field="units"
            )
        lu, au = units.get("length", "m"), units.get("angle", "rad")
        if not isinstance(lu, str) or lu not in _LENGTH:
            raise ModelError(f"expected one of {list(_LENGTH)}, got {short_repr(lu)}",
                             file=file, field="units.length")
        if not isinstance(au, str) or au not in ANGLE_UNITS:
            raise ModelError(f"expected one of {list(ANGLE_UNITS)}, got {short_repr(au)}",
                             file=file, field="units.angle")
        return _LENGTH[lu], ANGLE_UNITS[au]

    def placement(self, p: Any, where: str) -> np.ndarray:
        """A ``{xyz, rpy}`` placement in SI (identity when absent)."""
        if p is None:
            return np.eye(4)
        keys = scene_section_keys("placement")
        if not isinstance(p, Mapping) or set(p) - set(keys):
            raise ModelError("expected {xyz: [x, y, z], rpy: [r, p, y]}; "
                             + unknown_key(keys), file=self.file, field=where)
        xyz = number_field(p, "xyz", where, self.file, 3) if "xyz" in p else np.zeros(3)
        rpy = number_field(p, "rpy", where, self.file, 3) if "rpy" in p else np.zeros(3)
        return pose_from_xyz_rpy(xyz * self.L, rpy * self.A)

    def _shape(self, spec: Mapping[str, Any], where: str, owner: str) -> Shape:
        return shape_from_spec(spec, length=self.L, angle=self.A, base_dir=self.base_dir,
                               file=self.file, where=where, owner=owner)

    def robot(self) -> tuple[str | None, np.ndarray] | None:
        """``robot:``: the robot's name or file (or None) and its base placement."""
        rob = self.doc.get("robot")
        if rob is None:
            return None
        keys = scene_section_keys("robot")
        if not isinstance(rob, Mapping) or set(rob) - set(keys):
            raise ModelError("expected {name: ..., base: {xyz, rpy}}; "
                             + unknown_key(keys), file=self.file, field="robot")
        name = (None if rob.get("name") is None
                else _robot_file(_text(rob["name"], self.file, "robot.name"), self.file))
        return name, self.placement(rob.get("base"), "robot.base")

    def tool(self) -> tuple[list[Shape], np.ndarray, str] | None:
        """``tool:``: its shapes, its TCP placement and its name."""
        tool = self.doc.get("tool")
        if tool is None:
            return None
        keys = scene_section_keys("tool")
        if not isinstance(tool, Mapping) or set(tool) - set(keys):
            raise ModelError("expected {name, tcp: {xyz, rpy}, shapes: [...]}; "
                             + unknown_key(keys), file=self.file, field="tool")
        shapes = tool.get("shapes") or []
        if not isinstance(shapes, list):
            raise ModelError("expected a list of shapes", file=self.file,
                             field="tool.shapes")
        return ([self._shape(s, f"tool.shapes[{i}]", "tool") for i, s in enumerate(shapes)],
                self.placement(tool.get("tcp"), "tool.tcp"),
                _text(tool.get("name", "tool"), self.file, "tool.name"))

    def objects(self) -> list[tuple[str, Shape]]:
        """``objects:``: each object's name and shape (a mesh's file checked)."""
        file = self.file
        objects = self.doc.get("objects") or []
        if not isinstance(objects, list):
            raise ModelError("expected a list of objects", file=file, field="objects")
        out: list[tuple[str, Shape]] = []
        for i, spec in enumerate(objects):
            where = f"objects[{i}]"
            if not isinstance(spec, Mapping) or "name" not in spec:
                raise ModelError("an object needs a 'name'", file=file, field=where)
            name = _text(spec["name"], file, f"{where}.name")
            if any(name == seen for seen, _ in out):
                raise ModelError(f"duplicate object name {short_repr(name)}", file=file,
                                 field=f"{where}.name")
            shape = self._shape({k: v for k, v in spec.items() if k != "name"}, where,
                                name)
            if shape.kind == "mesh":
                try:
                    shape.check_file()
                except ModelError as exc:
                    raise ModelError(exc.reason, file=file, field=f"{where}.file"
                                     ) from None
            out.append((name, shape))
        return out

    def exclusions(self, objects: Sequence[str]) -> set[frozenset[str]]:
        """``exclude:``: the [link, object] pairs, each naming one of ``objects``."""
        file = self.file
        excl = self.doc.get("exclude") or []
        if not isinstance(excl, list):
            raise ModelError("expected a list of [link, object] pairs", file=file,
                             field="exclude")
        out: set[frozenset[str]] = set()
        for i, p in enumerate(excl):
            if not (isinstance(p, list | tuple) and len(p) == 2):
                raise ModelError("expected a pair [link, object]", file=file,
                                 field=f"exclude[{i}]")
            pair = [_text(x, file, f"exclude[{i}]") for x in p]
            _check_pair(objects, pair, file, f"exclude[{i}]")
            out.add(frozenset(pair))
        return out

    def poses(self) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
        """``poses:``: the named TCP poses, and the joint values given with some."""
        file = self.file
        poses = self.doc.get("poses") or {}
        if not isinstance(poses, Mapping):
            raise ModelError("expected {name: {xyz, rpy, q}}", file=file, field="poses")
        out: dict[str, np.ndarray] = {}
        joints: dict[str, np.ndarray] = {}
        for pname, spec in poses.items():
            pname = _text(pname, file, "poses")
            where = f"poses.{pname}"
            if not isinstance(spec, Mapping):
                raise ModelError("expected {xyz, rpy, q}", file=file, field=where)
            out[pname] = self.placement({k: v for k, v in spec.items() if k != "q"}, where)
            if "q" in spec:
                q = spec["q"]
                count = len(q) if isinstance(q, list) and q else 1
                joints[pname] = number_field(spec, "q", where, file, count) * self.A
        return out, joints
