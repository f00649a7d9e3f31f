"""MoveIt planning scenes in: the ``.scene`` text format (the common records).

A MoveIt planning scene reaches robokin in one of two forms, both read into a
:class:`MoveItScene` (shapes placed in the planning frame, an allowed-collision
matrix, a joint state) that :meth:`robokin.collision.Scene.from_moveit`
assembles:

* the ``.scene`` text MoveIt's ``PlanningScene::saveGeometryToStream`` writes
  (RViz's "Export" of the scene geometry; :func:`read_scene_text`, here);
* a ``moveit_msgs/PlanningScene`` message as YAML (``ros2 topic echo``, a
  MotionBenchMaker / robowflex scene file;
  :func:`robokin.io.moveit_scene_yaml.planning_scene_from_document`).

The ``.scene`` format, as MoveIt reads it (``loadGeometryFromStream``): the
scene's name on the first line; then per object a line ``* <id>``, the object's
pose (``x y z`` and the quaternion ``qx qy qz qw``; written by MoveIt since
1.1 / ROS 2, recognised as the line after the first ``*`` holding a space), the
number of shapes, each shape (its type and dimensions, its pose relative to the
object, a colour ``r g b a``), then (new format) the number of subframes and
each subframe's name and pose; a line ``.`` ends the scene. Shapes are
``box x y z``, ``cylinder radius length``, ``sphere radius``, ``cone radius
length`` (geometric_shapes' cone: base at ``-length/2``, tip at ``+length/2``;
robokin builds a mesh that contains it, :func:`robokin.model.geometry.cone`)
and ``mesh V T`` followed by V vertices and T triangles. A ``plane`` (infinite)
or an ``octree`` is refused, as is anything robokin does not know, naming the
file and the line.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from robokin._text import control_character, short_repr
from robokin.exceptions import InputError, ModelError
from robokin.model import geometry as geo
from robokin.model.geometry import MAX_MESH_VERTICES, Shape

__all__ = [
    "MAX_SCENE_OBJECTS",
    "MAX_SCENE_SHAPES",
    "AllowedCollisions",
    "MoveItObject",
    "MoveItScene",
    "is_scene_text_file",
    "read_scene_text",
]

#: Most objects a MoveIt scene may hold.
MAX_SCENE_OBJECTS = 10_000
#: Most shapes a MoveIt scene may hold (over all objects).
MAX_SCENE_SHAPES = 100_000
#: A quaternion in a ``.scene`` file is normalised when its norm is this close
#: to 1 (MoveIt writes 6 significant digits); farther, it is refused.
QUATERNION_TOLERANCE = 1e-3


@dataclass(frozen=True)
class AllowedCollisions:
    """A MoveIt allowed-collision matrix (``moveit_msgs/AllowedCollisionMatrix``).

    Attributes:
        entries: Explicit pairs: ``frozenset((a, b)) -> allowed`` (True: never
            checked).
        defaults: ``name -> allowed`` for pairs without an entry.
    """

    entries: Mapping[frozenset[str], bool] = field(default_factory=dict)
    defaults: Mapping[str, bool] = field(default_factory=dict)

    def allows(self, a: str, b: str) -> bool:
        """Whether the pair is never checked, by MoveIt's rule.

        The pair's entry, else its names' defaults (both must allow when both
        have one), else not allowed (checked).
        """
        entry = self.entries.get(frozenset((a, b)))
        if entry is not None:
            return entry
        da, db = self.defaults.get(a), self.defaults.get(b)
        if da is None and db is None:
            return False
        return bool((da if da is not None else True) and (db if db is not None else True))

    def names(self) -> set[str]:
        """Every name the matrix mentions."""
        out = set(self.defaults)
        for pair in self.entries:
            out |= pair
        return out

    def __repr__(self) -> str:
        """A deterministic summary (sorted), for fingerprints and messages."""
        allowed = sorted(sorted(p) for p, v in self.entries.items() if v)
        return f"AllowedCollisions(allowed={allowed}, defaults={sorted(self.defaults.items())})"


@dataclass(frozen=True)
class MoveItObject:
    """One collision object: its id and its shapes, placed in the planning frame.

    Attributes:
        id: The object's id.
        shapes: Its shapes; each placement is the shape's pose in the planning
            frame (4, 4) [m].
        line: Where it starts in the file (None when unknown).
    """

    id: str
    shapes: tuple[Shape, ...]
    line: int | None = None


@dataclass(frozen=True)
class MoveItScene:
    """What robokin reads of a MoveIt planning scene.

    Attributes:
        name: The scene's name.
        objects: The collision objects, in file order.
        allowed: The allowed-collision matrix, or None (a ``.scene`` file has
            none).
        joint_state: The robot state's joint positions ``{name: value}``.
        frame: The planning frame the poses are in, when the file names one.
        file: The file, or None.
    """

    name: str
    objects: tuple[MoveItObject, ...]
    allowed: AllowedCollisions | None = None
    joint_state: Mapping[str, float] = field(default_factory=dict)
    frame: str | None = None
    file: Path | None = None


def check_name(value: str, what: str, file: Path | None, line: int | None = None,
               field: str | None = None) -> str:
    """An object id: non-empty text, at most 200 characters, no control character."""
    problem = None
    if not value:
        problem = f"an empty {what}"
    elif len(value) > 200:
        problem = f"a {what} longer than 200 characters"
    else:
        problem = control_character(value)
    if problem is not None:
        raise ModelError(f"{problem} ({short_repr(value)})", file=file, line=line,
                         field=field)
    return value


def pose_from_quaternion(xyz: np.ndarray, xyzw: np.ndarray, *, strict: bool) -> np.ndarray:
    """A pose (4, 4) from a position and a quaternion (x, y, z, w).

    Args:
        xyz: Position (3,) [m].
        xyzw: Quaternion (4,), x y z w (ROS order).
        strict: Refuse a norm farther than :data:`QUATERNION_TOLERANCE` from 1
            (``.scene``); else any non-zero quaternion is normalised, as
            MoveIt does with messages.

    Raises:
        InputError: a zero (or, strict, a non-unit) quaternion (argument
            ``orientation``).
    """
    from robokin.spatial import matrix_from_quaternion

    norm = float(np.linalg.norm(xyzw))
    if not norm > 1e-9:
        raise InputError("orientation", f"a zero quaternion {xyzw.tolist()}")
    if strict and abs(norm - 1.0) > QUATERNION_TOLERANCE:
        raise InputError("orientation", f"not a unit quaternion (norm {norm:.6g}): "
                         f"{xyzw.tolist()}")
    T = matrix_from_quaternion(np.array([xyzw[3], xyzw[0], xyzw[1], xyzw[2]]) / norm)
    T = np.array(T, dtype=float)
    T[:3, 3] = xyz
    return T


def shape_from_moveit(kind: str, dims: list[float], pose: np.ndarray,
                      mesh: tuple[np.ndarray, np.ndarray] | None = None) -> Shape:
    """A robokin shape from a MoveIt shape type and dimensions (SI), placed at pose.

    ``kind``: ``box`` (x, y, z), ``cylinder`` (radius, length), ``sphere``
    (radius), ``cone`` (radius, length) or ``mesh`` (``mesh`` = vertices,
    triangles).

    Raises:
        InputError: bad dimensions, mesh data or kind.
    """
    if kind == "box":
        return geo.box(dims, pose)
    if kind == "cylinder":
        return geo.cylinder(dims[0], dims[1], pose)
    if kind == "sphere":
        return geo.sphere(dims[0], pose)
    if kind == "cone":
        return geo.cone(dims[0], dims[1], pose)
    if kind == "mesh" and mesh is not None:
        return geo.mesh_from_arrays(mesh[0], mesh[1], pose)
    raise InputError("type", f"unknown shape type {short_repr(kind)}")


# ------------------------------------------------------------------ .scene text
class _Tokens:
    """Whitespace tokens of a ``.scene`` text with their line numbers."""

    def __init__(self, lines: list[str], first: int, file: Path | None) -> None:
        self.lines, self.file = lines, file
        self.row = first  # index into lines of the next line to split
        self.queue: list[str] = []
        self.line = first  # 1-based line of the last token handed out

    def _fill(self) -> bool:
        while not self.queue:
            if self.row >= len(self.lines):
                return False
            self.queue = self.lines[self.row].split()[::-1]
            self.row += 1
        return True

    def error(self, reason: str, line: int | None = None) -> ModelError:
        return ModelError(reason, file=self.file, line=line or self.line)

    def token(self, what: str) -> str:
        if not self._fill():
            raise self.error(f"the file ends where {what} was expected "
                             "(a scene ends with a line '.')", len(self.lines))
        self.line = self.row
        return self.queue.pop()

    def rest_of_line(self) -> str:
        """What follows the last token on its line (MoveIt's getline)."""
        rest = " ".join(reversed(self.queue))
        self.queue = []
        return rest.strip()

    def numbers(self, count: int, what: str) -> np.ndarray:
        out = np.empty(count)
        for i in range(count):
            tok = self.token(what)
            try:
                v = float(tok)
            except ValueError:
                raise self.error(f"{what}: expected a number, got {short_repr(tok)}") \
                    from None
            if not math.isfinite(v):
                raise self.error(f"{what}: expected a finite number, got {short_repr(tok)}")
            out[i] = v
        return out

    def count(self, what: str, cap: int) -> int:
        tok = self.token(what)
        if not tok.isdigit():
            raise self.error(f"{what}: expected a count (a whole number >= 0), got "
                             f"{short_repr(tok)}")
        n = int(tok)
        if n > cap:
            raise self.error(f"{what} is {n:,}; robokin reads at most {cap:,}")
        return n

    def pose(self, what: str) -> np.ndarray:
        xyz = self.numbers(3, f"{what} position (x y z)")
        q = self.numbers(4, f"{what} orientation (qx qy qz qw)")
        try:
            return pose_from_quaternion(xyz, q, strict=True)
        except InputError as exc:
            raise self.error(f"{what}: {exc.reason}") from None


def _read_mesh(tok: _Tokens) -> tuple[np.ndarray, np.ndarray]:
    nv = tok.count("mesh vertex count", MAX_MESH_VERTICES)
    nt = tok.count("mesh triangle count", 2 * MAX_MESH_VERTICES)
    vertices = tok.numbers(3 * nv, "mesh vertex").reshape(nv, 3)
    faces = np.empty((nt, 3), dtype=np.int64)
    for i in range(nt):
        for j in range(3):
            t = tok.token("mesh triangle")
            if not t.isdigit() or int(t) >= nv:
                raise tok.error(f"mesh triangle {i}: expected a vertex index in [0, "
                                f"{nv - 1}], got {short_repr(t)}")
            faces[i, j] = int(t)
    return vertices, faces


def _read_shape(tok: _Tokens, where: str) -> tuple[str, list[float],
                                                   tuple[np.ndarray, np.ndarray] | None]:
    kind = tok.token(f"{where} type")
    line = tok.line
    dims: dict[str, tuple[int, str]] = {
        "box": (3, "size x y z"), "cylinder": (2, "radius length"),
        "sphere": (1, "radius"), "cone": (2, "radius length")}
    if kind in dims:
        n, what = dims[kind]
        return kind, tok.numbers(n, f"{where} {kind} {what}").tolist(), None
    if kind == "mesh":
        return kind, [], _read_mesh(tok)
    if kind in ("plane", "octree"):
        raise tok.error(f"{where}: a {kind} is not supported (an infinite plane or an "
                        "octree has no robokin shape; use a box)", line)
    raise tok.error(f"{where}: unknown shape type {short_repr(kind)}; a .scene file "
                    "holds box, cylinder, sphere, cone, mesh", line)


def _read_object(tok: _Tokens, new_format: bool, total: list[int]) -> MoveItObject:
    start = tok.line
    oid = check_name(tok.rest_of_line(), "object id", tok.file, start)
    pose = tok.pose(f"object '{oid}' pose") if new_format else np.eye(4)
    n = tok.count(f"object '{oid}' shape count", MAX_SCENE_SHAPES)
    total[0] += n
    if total[0] > MAX_SCENE_SHAPES:
        raise tok.error(f"more than {MAX_SCENE_SHAPES:,} shapes; robokin reads at most "
                        "that many (robokin.io.moveit_scene.MAX_SCENE_SHAPES)")
    shapes = []
    for i in range(n):
        where = f"object '{oid}' shape {i}"
        kind, dims, mesh = _read_shape(tok, where)
        line = tok.line
        local = tok.pose(f"{where} pose")
        tok.numbers(4, f"{where} colour (r g b a)")
        try:
            shapes.append(shape_from_moveit(kind, dims, pose @ local, mesh))
        except InputError as exc:
            raise tok.error(f"{where}: {exc.reason}", line) from None
    if new_format:
        for i in range(tok.count(f"object '{oid}' subframe count", MAX_SCENE_SHAPES)):
            tok.token(f"object '{oid}' subframe {i} name")
            tok.pose(f"object '{oid}' subframe {i} pose")
    return MoveItObject(oid, tuple(s.with_owner(oid) for s in shapes), start)


def read_scene_text(text: str, file: str | Path | None = None) -> MoveItScene:
    """Read a MoveIt ``.scene`` text (see the module docstring for the format).

    Args:
        text: The file's text.
        file: The file, for messages.

    Returns:
        The :class:`MoveItScene` (no allowed-collision matrix, no joint state).

    Raises:
        ModelError: anything malformed, unknown or unsupported, naming the file
            and the line: a missing or bad number, a count beyond the caps
            (:data:`MAX_SCENE_OBJECTS`, :data:`MAX_SCENE_SHAPES`,
            :data:`~robokin.model.geometry.MAX_MESH_VERTICES`), a plane, an
            unknown marker or shape, an object given twice, a missing final
            ``.``, text after it.
    """
    path = None if file is None else Path(file)
    lines = text.splitlines()
    if not lines:
        raise ModelError("an empty .scene file (it starts with the scene's name and "
                         "ends with a line '.')", file=path)
    name = lines[0].strip()
    # The format: the line after the first '*' holds a space (the object pose)?
    star = next((i for i in range(1, len(lines)) if lines[i].startswith("*")), None)
    new_format = star is not None and star + 1 < len(lines) and \
        " " in lines[star + 1].strip()
    tok = _Tokens(lines, 1, path)
    objects: list[MoveItObject] = []
    seen: dict[str, int] = {}
    total = [0]
    while True:
        marker = tok.token("'*' (an object) or '.' (the end)")
        if marker == ".":
            break
        if marker != "*":
            raise tok.error(f"unknown marker {short_repr(marker)}: expected '* <object "
                            "id>' or '.'")
        obj = _read_object(tok, new_format, total)
        if obj.id in seen:
            raise tok.error(f"object '{obj.id}' is given twice (lines {seen[obj.id]} "
                            f"and {obj.line})", obj.line)
        seen[obj.id] = obj.line or 0
        objects.append(obj)
        if len(objects) > MAX_SCENE_OBJECTS:
            raise tok.error(f"more than {MAX_SCENE_OBJECTS:,} objects; robokin reads at "
                            "most that many (robokin.io.moveit_scene.MAX_SCENE_OBJECTS)")
    extra = tok.line if tok.queue else next(
        (tok.row + i + 1 for i, line in enumerate(lines[tok.row:]) if line.strip()), None)
    if extra is not None:
        raise tok.error("text after the scene's closing '.'", extra)
    return MoveItScene(name or "scene", tuple(objects), file=path)


def is_scene_text_file(path: str | Path) -> bool:
    """Whether ``path`` names a MoveIt ``.scene`` file (by its suffix)."""
    return Path(path).suffix.lower() == ".scene"
