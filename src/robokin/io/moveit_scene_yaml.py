"""MoveIt planning scenes in: a ``moveit_msgs/PlanningScene`` message as YAML.

The message as ``ros2 topic echo`` (or ROS 1's ``rostopic echo``) prints it, and
the shorter form robowflex / MotionBenchMaker write (positions and quaternions
as lists ``[x, y, z]`` / ``[x, y, z, w]``, primitive types as ``box`` /
``sphere`` / ``cylinder`` / ``cone``, booleans as ``"true"``, a mesh as a
``resource`` file with ``dimensions`` as scale). Read through robokin's one YAML
reader (safe loading, bounded size, duplicate keys refused); every error names
the file, the field and its line.

What is read, with MoveIt's meaning:

* ``world.collision_objects``: ``id``, ``header.frame_id``, ``pose`` (the
  object's pose; its shapes' poses are relative to it), ``primitives``
  (``BOX`` = 1: x y z; ``SPHERE`` = 2: radius; ``CYLINDER`` = 3: height,
  radius; ``CONE`` = 4: height, radius) with ``primitive_poses``, ``meshes``
  (``vertices`` and ``triangles``) with ``mesh_poses``; a missing shape pose is
  the identity, more poses than shapes an error (as in MoveIt); quaternions are
  normalised (a zero one is refused); ``operation`` ``ADD`` (0), ``REMOVE``
  (1) and ``APPEND`` (2), in order; ``MOVE`` (3) is refused;
* ``allowed_collision_matrix``: ``entry_names`` / ``entry_values`` (the upper
  triangle, as MoveIt reads it) and ``default_entry_names`` /
  ``default_entry_values``;
* ``fixed_frame_transforms``: frames an object's ``header.frame_id`` may name;
  the planning frame is theirs (their ``header.frame_id``), else the frame the
  objects share; an object in another frame (a robot link) is refused;
* ``robot_state.joint_state`` (names and positions: ``MoveItScene.joint_state``);
* ``name``, ``robot_model_name``, ``is_diff``, ``object_colors``, a
  ``collision_object.type``, ``subframe_names`` / ``subframe_poses``: accepted,
  not used.

Refused, naming the field: planes, an octomap with data, attached collision
objects, a multi-DOF joint state, a non-zero ``link_padding``, a
``link_scale`` other than 1, an unknown key or shape type.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from robokin._text import short_repr
from robokin.exceptions import InputError, ModelError
from robokin.io.moveit_scene import (
    MAX_SCENE_OBJECTS,
    MAX_SCENE_SHAPES,
    AllowedCollisions,
    MoveItObject,
    MoveItScene,
    check_name,
    pose_from_quaternion,
    shape_from_moveit,
)

__all__ = ["PLANNING_SCENE_KEYS", "is_planning_scene_document",
           "planning_scene_from_document"]

#: The fields of ``moveit_msgs/PlanningScene``.
PLANNING_SCENE_KEYS = ("name", "robot_state", "robot_model_name",
                       "fixed_frame_transforms", "allowed_collision_matrix",
                       "link_padding", "link_scale", "object_colors", "world",
                       "is_diff")
_OBJECT_KEYS = ("header", "pose", "id", "type", "primitives", "primitive_poses",
                "meshes", "mesh_poses", "planes", "plane_poses", "subframe_names",
                "subframe_poses", "operation")
#: SolidPrimitive type -> (robokin kind, dimension count, (radius, length) order).
_PRIMITIVES = {1: "box", 2: "sphere", 3: "cylinder", 4: "cone"}
_OPERATIONS = {0: "add", 1: "remove", 2: "append", 3: "move"}
_BYTE = re.compile(r"^b'\\x0([0-9])'$")


class _Reader:
    """Field access with ModelErrors naming the file and the field path."""

    def __init__(self, file: Path | None) -> None:
        self.file = file

    def error(self, where: str, reason: str) -> ModelError:
        return ModelError(reason, file=self.file, field=where)

    def mapping(self, value: Any, where: str, keys: Sequence[str]) -> Mapping[str, Any]:
        if value is None:
            return {}
        if not isinstance(value, Mapping):
            raise self.error(where, f"expected a mapping, got {short_repr(value)}")
        for k in value:
            if k not in keys:
                raise self.error(f"{where}.{k}" if where else str(k),
                                 f"unknown key; expected one of {list(keys)}")
        return value

    def sequence(self, value: Any, where: str, cap: int = MAX_SCENE_SHAPES) -> list[Any]:
        if value is None:
            return []
        if not isinstance(value, list):
            raise self.error(where, f"expected a list, got {short_repr(value)}")
        if len(value) > cap:
            raise self.error(where, f"{len(value):,} entries; robokin reads at most {cap:,}")
        return value

    def number(self, value: Any, where: str) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.error(where, f"expected a number, got {short_repr(value)}")
        v = float(value)
        if not math.isfinite(v):
            raise self.error(where, f"expected a finite number, got {short_repr(value)}")
        return v

    def text(self, value: Any, where: str) -> str:
        if value is None:
            return ""
        if not isinstance(value, str):
            raise self.error(where, f"expected text, got {short_repr(value)}")
        return value

    def flag(self, value: Any, where: str) -> bool:
        if isinstance(value, bool):
            return value
        if isinstance(value, str) and value.lower() in ("true", "false"):
            return value.lower() == "true"
        if isinstance(value, int) and value in (0, 1):
            return bool(value)
        raise self.error(where, f"expected true or false, got {short_repr(value)}")

    def vector(self, value: Any, where: str, names: str) -> np.ndarray:
        """A Point / Vector3 / Quaternion: a mapping of ``names`` or a list."""
        if isinstance(value, Mapping):
            self.mapping(value, where, tuple(names))
            return np.array([self.number(value.get(c, 0.0), f"{where}.{c}") for c in names])
        if isinstance(value, list) and len(value) == len(names):
            return np.array([self.number(v, f"{where}[{i}]") for i, v in enumerate(value)])
        raise self.error(where, f"expected {{{', '.join(names)}}} or a list of "
                         f"{len(names)} numbers, got {short_repr(value)}")

    def pose(self, value: Any, where: str, keys: tuple[str, str] = ("position",
                                                                      "orientation")
             ) -> np.ndarray:
        """A geometry_msgs/Pose (or Transform: ``translation``, ``rotation``)."""
        if value is None:
            return np.eye(4)
        m = self.mapping(value, where, keys)
        xyz = self.vector(m[keys[0]], f"{where}.{keys[0]}", "xyz") if keys[0] in m \
            else np.zeros(3)
        q = self.vector(m[keys[1]], f"{where}.{keys[1]}", "xyzw") if keys[1] in m \
            else np.array([0.0, 0.0, 0.0, 1.0])
        try:
            return pose_from_quaternion(xyz, q, strict=False)
        except InputError as exc:
            raise self.error(f"{where}.{keys[1]}", exc.reason) from None

    def frame(self, header: Any, where: str) -> str:
        h = self.mapping(header, where, ("stamp", "frame_id", "seq"))
        return self.text(h.get("frame_id"), f"{where}.frame_id").lstrip("/")


def is_planning_scene_document(doc: Any) -> bool:
    """Whether a YAML document is a ``moveit_msgs/PlanningScene`` (not a robokin scene).

    It is when it has a PlanningScene field other than ``name`` (``world``,
    ``robot_state``, ``allowed_collision_matrix``, ...).
    """
    return isinstance(doc, Mapping) and any(
        k in doc for k in PLANNING_SCENE_KEYS if k != "name")


def _operation(r: _Reader, value: Any, where: str) -> str:
    if value is None:
        return "add"
    if isinstance(value, str):
        m = _BYTE.match(value)
        if m:
            value = int(m.group(1))
        elif value.lower() in _OPERATIONS.values():
            return value.lower()
    if isinstance(value, int) and not isinstance(value, bool) and value in _OPERATIONS:
        return _OPERATIONS[value]
    raise r.error(where, f"expected ADD (0), REMOVE (1), APPEND (2) or MOVE (3), got "
                  f"{short_repr(value)}")


def _primitive(r: _Reader, value: Any, where: str) -> tuple[str, list[float]]:
    m = r.mapping(value, where, ("type", "dimensions", "polygon"))
    t = m.get("type")
    kind = None
    if isinstance(t, str) and t.lower() in _PRIMITIVES.values():
        kind = t.lower()
    elif isinstance(t, int) and not isinstance(t, bool):
        kind = _PRIMITIVES.get(t)
        if t == 5:
            raise r.error(f"{where}.type", "a PRISM (5) is not supported")
    if kind is None:
        raise r.error(f"{where}.type", f"expected BOX (1), SPHERE (2), CYLINDER (3) or "
                      f"CONE (4), got {short_repr(t)}")
    dims = [r.number(v, f"{where}.dimensions[{i}]")
            for i, v in enumerate(r.sequence(m.get("dimensions"), f"{where}.dimensions", 3))]
    need = {"box": 3, "sphere": 1, "cylinder": 2, "cone": 2}[kind]
    if len(dims) != need:
        raise r.error(f"{where}.dimensions", f"a {kind.upper()} needs {need} "
                      f"dimension{'s' if need > 1 else ''}, got {len(dims)}")
    if kind in ("cylinder", "cone"):
        dims = [dims[1], dims[0]]  # message: height, radius -> robokin: radius, length
    return kind, dims


def _mesh(r: _Reader, value: Any, where: str, base: Path | None
          ) -> tuple[str, list[float], Any]:
    m = r.mapping(value, where, ("triangles", "vertices", "resource", "dimensions"))
    if "resource" in m:
        return "file", [], _mesh_resource(r, m, where, base)
    vs = r.sequence(m.get("vertices"), f"{where}.vertices", 1_000_000)
    ts = r.sequence(m.get("triangles"), f"{where}.triangles", 2_000_000)
    vertices = np.array([r.vector(v, f"{where}.vertices[{i}]", "xyz")
                         for i, v in enumerate(vs)]).reshape(-1, 3)
    faces = []
    for i, t in enumerate(ts):
        idx = t.get("vertex_indices") if isinstance(t, Mapping) else t
        w = f"{where}.triangles[{i}]"
        if isinstance(t, Mapping):
            r.mapping(t, w, ("vertex_indices",))
            w += ".vertex_indices"
        if not (isinstance(idx, list) and len(idx) == 3 and all(
                isinstance(k, int) and not isinstance(k, bool) and 0 <= k < len(vs)
                for k in idx)):
            raise r.error(w, f"expected 3 vertex indices in [0, {len(vs) - 1}], got "
                          f"{short_repr(idx)}")
        faces.append(idx)
    return "mesh", [], (vertices, np.array(faces, dtype=np.int64).reshape(-1, 3))


def _mesh_resource(r: _Reader, m: Mapping[str, Any], where: str, base: Path | None) -> Any:
    """A robowflex mesh ``resource`` (a file) with ``dimensions`` as its scale."""
    from robokin.io.ros_packages import PackageFinder
    from robokin.io.urdf_geometry import resolve_mesh

    uri = r.text(m["resource"], f"{where}.resource")
    scale = [1.0, 1.0, 1.0]
    if m.get("dimensions") is not None:
        scale = [r.number(v, f"{where}.dimensions[{i}]")
                 for i, v in enumerate(r.sequence(m["dimensions"], f"{where}.dimensions", 3))]
    if len(scale) != 3 or not (scale[0] == scale[1] == scale[2] > 0):
        raise r.error(f"{where}.dimensions", f"a mesh scale must be 3 equal positive "
                      f"numbers (robokin scales meshes uniformly), got {scale}")
    path, why = resolve_mesh(uri, base, PackageFinder(None, near=base))
    if path is None:
        raise r.error(f"{where}.resource", f"mesh {short_repr(uri, 200)}: {why}")
    return path, scale[0]


def _shapes(r: _Reader, obj: Mapping[str, Any], where: str, base: Path | None
            ) -> list[Any]:
    """Every shape of a collision object: (kind, dims, mesh, pose relative to it)."""
    out = []
    for key, pkey in (("primitives", "primitive_poses"), ("meshes", "mesh_poses")):
        items = r.sequence(obj.get(key), f"{where}.{key}")
        poses = r.sequence(obj.get(pkey), f"{where}.{pkey}")
        if len(poses) > len(items):
            raise r.error(f"{where}.{pkey}", f"{len(poses)} poses for {len(items)} {key}")
        for i, item in enumerate(items):
            w = f"{where}.{key}[{i}]"
            if key == "primitives":
                kind, dims = _primitive(r, item, w)
                mesh = None
            else:
                kind, dims, mesh = _mesh(r, item, w, base)
            pose = r.pose(poses[i], f"{where}.{pkey}[{i}]") if i < len(poses) else np.eye(4)
            out.append((kind, dims, mesh, pose, w))
    if r.sequence(obj.get("planes"), f"{where}.planes"):
        raise r.error(f"{where}.planes", "a plane is not supported (an infinite plane "
                      "has no robokin shape; use a box)")
    return out


def _build(kind: str, dims: list[float], mesh: Any, pose: np.ndarray, r: _Reader,
           where: str) -> Any:
    from robokin.model import geometry as geo

    try:
        if kind == "file":
            path, scale = mesh
            shape = geo.mesh(path, pose, scale=scale)
            shape.check_file()
            return shape
        return shape_from_moveit(kind, dims, pose, mesh)
    except InputError as exc:
        raise r.error(where, exc.reason) from None
    except ModelError as exc:
        raise r.error(where, exc.reason) from None


class _Frames:
    """The planning frame and the frames ``fixed_frame_transforms`` define."""

    def __init__(self, r: _Reader, value: Any) -> None:
        self.r = r
        self.planning: str | None = None
        self.known: dict[str, np.ndarray] = {}
        for i, tf in enumerate(r.sequence(value, "fixed_frame_transforms")):
            w = f"fixed_frame_transforms[{i}]"
            m = r.mapping(tf, w, ("header", "child_frame_id", "transform"))
            parent = r.frame(m.get("header"), f"{w}.header")
            if self.planning is None:
                self.planning = parent
            elif parent != self.planning:
                raise r.error(f"{w}.header.frame_id", f"'{parent}': the fixed frames must "
                              f"all be given in the planning frame '{self.planning}'")
            child = r.text(m.get("child_frame_id"), f"{w}.child_frame_id").lstrip("/")
            self.known[child] = r.pose(m.get("transform"), f"{w}.transform",
                                       ("translation", "rotation"))

    def placement(self, frame: str, where: str) -> np.ndarray:
        if frame in ("", self.planning):
            return np.eye(4)
        if frame in self.known:
            return self.known[frame]
        if self.planning is None:
            self.planning = frame  # the objects' shared frame
            return np.eye(4)
        raise self.r.error(where, f"'{frame}' is neither the planning frame "
                           f"'{self.planning}' nor one of fixed_frame_transforms "
                           f"{sorted(self.known)}: robokin places objects in the planning "
                           "frame (an object in a robot link's frame is not supported)")


def _objects(r: _Reader, world: Any, frames: _Frames, base: Path | None
             ) -> list[MoveItObject]:
    w = r.mapping(world, "world", ("collision_objects", "octomap"))
    octo = w.get("octomap")
    if isinstance(octo, Mapping) and isinstance(octo.get("octomap"), Mapping) and \
            octo["octomap"].get("data"):
        raise r.error("world.octomap", "an octomap is not supported")
    objects: dict[str, MoveItObject] = {}
    count = 0
    for i, value in enumerate(r.sequence(w.get("collision_objects"), "world.collision_objects",
                                         MAX_SCENE_OBJECTS)):
        where = f"world.collision_objects[{i}]"
        obj = r.mapping(value, where, _OBJECT_KEYS)
        oid = check_name(r.text(obj.get("id"), f"{where}.id"), "object id", r.file,
                         field=f"{where}.id")
        op = _operation(r, obj.get("operation"), f"{where}.operation")
        if op == "move":
            raise r.error(f"{where}.operation", "MOVE is not supported: give the object "
                          "where it is (ADD)")
        if op == "remove":
            objects.pop(oid, None)
            continue
        placed = frames.placement(r.frame(obj.get("header"), f"{where}.header"),
                                  f"{where}.header.frame_id") @ r.pose(obj.get("pose"),
                                                                       f"{where}.pose")
        shapes = [_build(kind, dims, mesh, placed @ pose, r, w).with_owner(oid)
                  for kind, dims, mesh, pose, w in _shapes(r, obj, where, base)]
        count += len(shapes)
        if count > MAX_SCENE_SHAPES:
            raise r.error(where, f"more than {MAX_SCENE_SHAPES:,} shapes")
        if op == "append" and oid in objects:
            shapes = [*objects[oid].shapes, *shapes]
        elif not shapes:
            raise r.error(where, f"object '{oid}' has no shapes")
        objects[oid] = MoveItObject(oid, tuple(shapes))
    return list(objects.values())


def _allowed(r: _Reader, value: Any) -> AllowedCollisions | None:
    where = "allowed_collision_matrix"
    m = r.mapping(value, where, ("entry_names", "entry_values", "default_entry_names",
                                 "default_entry_values"))
    if not m:
        return None
    names = [r.text(v, f"{where}.entry_names[{i}]")
             for i, v in enumerate(r.sequence(m.get("entry_names"), f"{where}.entry_names"))]
    rows = r.sequence(m.get("entry_values"), f"{where}.entry_values")
    if len(rows) != len(names):
        raise r.error(f"{where}.entry_values", f"{len(rows)} rows for {len(names)} "
                      "entry_names")
    entries: dict[frozenset[str], bool] = {}
    for i, row in enumerate(rows):
        w = f"{where}.entry_values[{i}]"
        if isinstance(row, Mapping):
            r.mapping(row, w, ("enabled",))
            row, w = row.get("enabled"), f"{w}.enabled"
        vals = r.sequence(row, w)
        if len(vals) != len(names):
            raise r.error(w, f"{len(vals)} values for {len(names)} entry_names")
        for j in range(i + 1, len(names)):  # the upper triangle, as MoveIt reads it
            entries[frozenset((names[i], names[j]))] = r.flag(vals[j], f"{w}[{j}]")
    dn = [r.text(v, f"{where}.default_entry_names[{i}]") for i, v in
          enumerate(r.sequence(m.get("default_entry_names"), f"{where}.default_entry_names"))]
    dv = r.sequence(m.get("default_entry_values"), f"{where}.default_entry_values")
    if len(dv) != len(dn):
        raise r.error(f"{where}.default_entry_values", f"{len(dv)} values for {len(dn)} "
                      "default_entry_names")
    defaults = {n: r.flag(v, f"{where}.default_entry_values[{i}]")
                for i, (n, v) in enumerate(zip(dn, dv))}
    return AllowedCollisions(entries, defaults)


def _robot_state(r: _Reader, value: Any) -> dict[str, float]:
    m = r.mapping(value, "robot_state", ("joint_state", "multi_dof_joint_state",
                                         "attached_collision_objects", "is_diff"))
    if r.sequence(m.get("attached_collision_objects"), "robot_state.attached_collision_objects"):
        raise r.error("robot_state.attached_collision_objects", "attached objects are not "
                      "supported (give a grasped part as the scene's tool)")
    multi = m.get("multi_dof_joint_state")
    if isinstance(multi, Mapping) and multi.get("joint_names"):
        raise r.error("robot_state.multi_dof_joint_state", "a multi-DOF joint state is "
                      "not supported")
    js = r.mapping(m.get("joint_state"), "robot_state.joint_state",
                   ("header", "name", "position", "velocity", "effort"))
    names = r.sequence(js.get("name"), "robot_state.joint_state.name")
    pos = r.sequence(js.get("position"), "robot_state.joint_state.position")
    if pos and len(pos) != len(names):
        raise r.error("robot_state.joint_state.position", f"{len(pos)} positions for "
                      f"{len(names)} names")
    return {r.text(n, f"robot_state.joint_state.name[{i}]"):
            r.number(p, f"robot_state.joint_state.position[{i}]")
            for i, (n, p) in enumerate(zip(names, pos))}


def _padding(r: _Reader, doc: Mapping[str, Any]) -> None:
    for key, field_, neutral in (("link_padding", "padding", 0.0),
                                 ("link_scale", "scale", 1.0)):
        for i, item in enumerate(r.sequence(doc.get(key), key)):
            m = r.mapping(item, f"{key}[{i}]", ("link_name", field_))
            v = r.number(m.get(field_, neutral), f"{key}[{i}].{field_}")
            if v != neutral:
                raise r.error(f"{key}[{i}].{field_}", f"{field_} {v:g}: robokin has no "
                              f"per-link {field_} (check with a clearance instead)")


def planning_scene_from_document(doc: Any, file: str | Path | None = None) -> MoveItScene:
    """Read a ``moveit_msgs/PlanningScene`` YAML document (see the module docstring).

    Args:
        doc: The parsed YAML (a mapping).
        file: The file, for messages and relative mesh resources.

    Returns:
        The :class:`MoveItScene`.

    Raises:
        ModelError: an unknown key, a bad value or an unsupported feature, naming
            the file and the field (``Scene.load`` adds the line).
    """
    path = None if file is None else Path(file)
    r = _Reader(path)
    m = r.mapping(doc, "", PLANNING_SCENE_KEYS)
    name = r.text(m.get("name"), "name") or (path.stem if path else "scene")
    _padding(r, m)
    frames = _Frames(r, m.get("fixed_frame_transforms"))
    objects = _objects(r, m.get("world"), frames, path)
    return MoveItScene(
        name=name, objects=tuple(objects), allowed=_allowed(r, m.get("allowed_collision_matrix")),
        joint_state=_robot_state(r, m.get("robot_state")), frame=frames.planning, file=path)
