"""Scenes: named static objects in the world, the robot's base placement and its tool.

A scene file (YAML) declares its units once; everything is SI inside:

.. code-block:: yaml

    name: press cell
    units: {length: mm, angle: deg}
    robot: {name: aubo_i5, base: {xyz: [0, 0, 0], rpy: [0, 0, 0]}}
    tool:                              # mounted on the robot's tool frame (flange)
      name: gripper
      tcp: {xyz: [0, 0, 150]}          # flange -> TCP: the new tool transform
      shapes:                          # in the flange frame
        - {type: box, size: [60, 110, 40], xyz: [0, 0, 20]}
    objects:
      - {name: table, type: box, size: [600, 800, 20], xyz: [0, 500, 390]}
      - {name: post, type: cylinder, radius: 50, length: 400, xyz: [1, 0, 200]}
      - {name: housing, type: mesh, file: housing.stl, units: mm, xyz: [0, 0, 0]}
    exclude: [[base, table]]           # robot link / object pairs never checked
    poses:                             # named TCP poses in the world
      pick: {xyz: [0, 500, 450], rpy: [180, 0, 0], q: [0, 10, 90, 0, 90, 0]}

Object shapes use the keys of robot-file geometry (``type``, ``size``,
``radius``, ``length``, ``from``/``to``, ``file``, ``units``, ``xyz``, ``rpy``);
their ``xyz``/``rpy`` place them in the world. ``q`` in a pose is an optional
joint configuration (file angle units) that reaches it, a seed for IK.

:meth:`Scene.load` also reads a MoveIt planning scene: a ``.scene`` file
(:mod:`robokin.io.moveit_scene`) or a ``moveit_msgs/PlanningScene`` YAML
(:mod:`robokin.io.moveit_scene_yaml`). A MoveIt object of several shapes becomes
one robokin object per shape (``id/0``, ``id/1``, ...; ``Scene.groups`` maps
the id to them); its allowed-collision matrix (``Scene.allowed``) and exclusions
naming URDF links are mapped onto robokin's links when the scene meets a robot
from a URDF (:meth:`Scene.excluded_pairs`).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import numpy.typing as npt

from robokin._text import short_repr
from robokin._validation import check_transform
from robokin.collision._scene_document import SceneDocument, _text
from robokin.exceptions import InputError, ModelError
from robokin.io.moveit_scene import AllowedCollisions, MoveItScene
from robokin.model import geometry as _geo
from robokin.model.geometry import Shape

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["Scene", "SceneObject", "Tool"]

_PLACED = "_robokin_scene_placement"  # meta key: (scene, chain, geometry, unplaced robot)


def _parts(robot: Robot) -> dict[str, tuple[str, ...]]:
    """The URDF links with shapes each robokin link holds (a robot from a URDF)."""
    info = robot.meta.get("urdf")
    parts = getattr(info, "parts", None)
    return parts() if callable(parts) else {}


def _fresh(shape: Shape) -> Shape:
    """The same declared shape without its caches (coal objects stay behind)."""
    return replace(shape)


def _pose(T: npt.ArrayLike | None, name: str) -> np.ndarray:
    if T is None:
        return np.eye(4)
    T = check_transform(T, name)
    if T.shape != (4, 4):
        raise InputError(name, f"expected one pose (4, 4), got {T.shape}")
    out = np.array(T)
    out.setflags(write=False)
    return out


@dataclass(frozen=True, eq=False)
class SceneObject:
    """A named static object: one shape placed in the world.

    Attributes:
        name: Unique name in the scene.
        shape: The shape; its placement is its pose in the world (4, 4) [m].
    """

    name: str
    shape: Shape

    @property
    def pose(self) -> np.ndarray:
        """Pose in the world, (4, 4) [m]."""
        return self.shape.placement


@dataclass(frozen=True, eq=False)
class Tool:
    """A tool (gripper) mounted on the robot's tool frame.

    Attributes:
        name: The tool's name.
        tcp: Mount (robot tool frame) to TCP, (4, 4) [m]; appended to the robot's
            tool transform.
        shapes: Shapes placed in the mount frame.
    """

    name: str = "tool"
    tcp: np.ndarray = field(default_factory=lambda: np.eye(4))
    shapes: tuple[Shape, ...] = ()


class Scene:
    """Static objects in the world, where the robot stands and what it holds.

    Attributes:
        name: The scene's name.
        objects: The static objects, in insertion order.
        base: Pose of the robot's base frame in the world (4, 4) [m].
        tool: The tool (gripper), or None.
        exclude: (robot link, object) name pairs never checked.
        poses: Named TCP poses in the world, ``{name: (4, 4)}``.
        pose_joints: Joint configurations reaching ``poses`` (when given), ``{name: (n,)}``.
        robot_name: The robot the scene was built for (built-in name or file; a
            relative robot file is given relative to the scene file), or None.
        path: The scene file, or None.
        groups: A MoveIt object's id -> the robokin objects of its shapes.
        allowed: A MoveIt scene's allowed-collision matrix, or None.
        joint_state: A MoveIt scene's robot state ``{joint: position}``.
        frame: The planning frame a MoveIt scene's poses are in (when it names
            one); robokin takes it as the world frame.
    """

    def __init__(self, name: str = "scene") -> None:
        """An empty scene called ``name``."""
        self.name = name
        self._objects: dict[str, SceneObject] = {}
        self.base = np.eye(4)
        self.tool: Tool | None = None
        self.exclude: set[frozenset[str]] = set()
        self.poses: dict[str, np.ndarray] = {}
        self.pose_joints: dict[str, np.ndarray] = {}
        self.robot_name: str | None = None
        self.path: Path | None = None
        self.groups: dict[str, tuple[str, ...]] = {}
        self.allowed: AllowedCollisions | None = None
        self.joint_state: dict[str, float] = {}
        self.frame: str | None = None
        self._version = 0

    def __repr__(self) -> str:
        """A short summary: the name and the object names."""
        return f"Scene(name={self.name!r}, objects={list(self._objects)})"

    def __getstate__(self) -> dict[str, Any]:
        """Pickle state: the declared fields, rebuilt from the shapes' declarations.

        The compiled check (coal objects) and the shapes' caches stay behind, so a
        scene travels to another process (a Dask worker) and compiles afresh there.
        """
        state = {k: v for k, v in self.__dict__.items() if k != "_check_cache"}
        state["_objects"] = {
            name: SceneObject(obj.name, _fresh(obj.shape))
            for name, obj in self._objects.items()
        }
        if self.tool is not None:
            state["tool"] = Tool(
                self.tool.name, self.tool.tcp, tuple(_fresh(s) for s in self.tool.shapes)
            )
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        """Restore a pickled scene (see :meth:`__getstate__`)."""
        self.__dict__.update(state)

    def with_base(self, pose: npt.ArrayLike) -> Scene:
        """A copy of the scene with the robot's base frame placed at ``pose`` (4, 4) [m].

        The objects, tool, exclusions and poses are shared (they are immutable);
        the compiled check is not.
        """
        out = Scene.__new__(Scene)
        out.__dict__.update(
            {k: v for k, v in self.__dict__.items() if k != "_check_cache"}
        )
        out._objects = dict(self._objects)
        out.exclude = set(self.exclude)
        out.poses = dict(self.poses)
        out.pose_joints = dict(self.pose_joints)
        out.groups = dict(self.groups)
        out.joint_state = dict(self.joint_state)
        out.base = _pose(pose, "pose")
        return out

    def unplaced(self, robot: Robot) -> Robot:
        """The robot as it was before this scene placed it (itself if it was not)."""
        placed = robot.meta.get(_PLACED)
        if (
            placed is not None
            and placed[0] is self
            and placed[1] is robot.chain
            and placed[2] is robot.geometry
        ):
            return placed[3]
        return robot

    # ---------------------------------------------------------------- objects
    @property
    def objects(self) -> tuple[SceneObject, ...]:
        """The static objects."""
        return tuple(self._objects.values())

    @property
    def names(self) -> tuple[str, ...]:
        """Names of the static objects."""
        return tuple(self._objects)

    def __getitem__(self, name: str) -> SceneObject:
        """The object called ``name``."""
        try:
            return self._objects[name]
        except KeyError:
            raise InputError(
                "name",
                f"no object {short_repr(name)} in the scene; objects: {list(self._objects)}",
            ) from None

    def __len__(self) -> int:
        """The number of objects."""
        return len(self._objects)

    def add(self, name: str, shape: Shape) -> SceneObject:
        """Add a shape whose placement is its world pose; returns the object."""
        if not isinstance(name, str) or not name:
            raise InputError("name", f"expected a non-empty string, got {short_repr(name)}")
        if name in self._objects:
            raise InputError("name", f"the scene already has an object {short_repr(name)}")
        obj = SceneObject(name, shape.with_owner(name))
        self._objects[name] = obj
        self._version += 1
        return obj

    def remove(self, name: str) -> None:
        """Remove an object."""
        self[name]
        del self._objects[name]
        self._version += 1

    def add_box(
        self, name: str, size: Sequence[float], pose: npt.ArrayLike | None = None
    ) -> SceneObject:
        """Add a box of full sizes ``(sx, sy, sz)`` [m] centred at ``pose`` (4, 4)."""
        return self.add(name, _geo.box(size, _pose(pose, "pose")))

    def add_cylinder(
        self, name: str, radius: float, length: float, pose: npt.ArrayLike | None = None
    ) -> SceneObject:
        """Add a cylinder [m] along the local z axis of ``pose``, centred there."""
        return self.add(name, _geo.cylinder(radius, length, _pose(pose, "pose")))

    def add_sphere(
        self, name: str, radius: float, pose: npt.ArrayLike | None = None
    ) -> SceneObject:
        """Add a sphere of ``radius`` [m] centred at ``pose``."""
        return self.add(name, _geo.sphere(radius, _pose(pose, "pose")))

    def add_capsule(
        self, name: str, radius: float, length: float, pose: npt.ArrayLike | None = None
    ) -> SceneObject:
        """Add a capsule [m] along the local z axis of ``pose``, centred there."""
        return self.add(name, _geo.capsule(radius, length, _pose(pose, "pose")))

    def add_mesh(
        self,
        name: str,
        file: str | Path,
        pose: npt.ArrayLike | None = None,
        *,
        units: Literal["m", "mm", "cm"] = "m",
        scale: float = 1.0,
    ) -> SceneObject:
        """Add a mesh file (STL, OBJ, DAE, PLY) in ``units``, placed at ``pose``.

        Raises:
            ModelError: the file is missing or unreadable (names file and object).
        """
        shape = _geo.mesh(
            file, _pose(pose, "pose"), units=units, scale=scale, owner=name
        )
        shape.check_file()
        return self.add(name, shape)

    # ------------------------------------------------------------ robot side
    def set_base(self, pose: npt.ArrayLike) -> None:
        """Place the robot's base frame in the world (4, 4) [m]."""
        self.base = _pose(pose, "pose")
        self._version += 1

    def set_tool(
        self,
        shapes: Iterable[Shape] = (),
        tcp: npt.ArrayLike | None = None,
        *,
        name: str = "tool",
    ) -> None:
        """Mount a tool: ``shapes`` in the mount frame, ``tcp`` mount -> TCP (4, 4)."""
        self.tool = Tool(
            name, _pose(tcp, "tcp"), tuple(s.with_owner("tool") for s in shapes)
        )
        self._version += 1

    def exclude_pair(self, link: str, obj: str) -> None:
        """Never check robot link ``link`` against object ``obj``.

        Raises:
            InputError: ``obj`` is not an object of the scene (listing them);
                ``link`` is checked against the robot's links when the scene
                meets a robot (:meth:`attach`).
        """
        self[obj]
        if link in self.names:
            raise InputError("link", f"{short_repr(link)} is an object; objects are "
                             "never checked against each other")
        self.exclude.add(frozenset((link, obj)))
        self._version += 1

    def check_exclusions(self, links: Sequence[str], urdf_links: Iterable[str] = ()
                         ) -> None:
        """Raise unless every excluded pair names one of ``links`` and an object.

        Args:
            links: The robot's link names (``RobotGeometry.names``: ``base``, the
                joints, ``tool``).
            urdf_links: The URDF links of a robot imported from a URDF (a pair
                may name one; :meth:`excluded_pairs` maps it onto ``links``).

        Raises:
            ModelError: a pair whose link is not one of ``links`` (naming the
                scene file, the pair and listing the links).
        """
        objects = set(self.names) | set(self.groups)
        known = set(links) | set(urdf_links)
        for pair in sorted(sorted(p) for p in self.exclude):
            others = [x for x in pair if x not in objects] or pair[:1]
            bad = [x for x in others if x not in known]
            if bad:
                raise ModelError(
                    f"exclude {pair}: {short_repr(bad[0])} is neither a link of the "
                    f"robot (links: {list(links)}) nor an object of the scene "
                    f"(objects: {sorted(objects)})", file=self.path, field="exclude")

    def attach(self, robot: Robot) -> Robot:
        """The robot as placed in this scene: base, tool transform and tool shapes.

        The robot's base becomes ``scene.base @ robot.base``; its tool transform
        ``robot.tool @ tool.tcp``; the tool's shapes join the robot's tool link.
        A robot this scene already placed (and not changed since) is placed
        afresh from its unplaced original, never twice, so ``check`` and the
        viewers accept either.
        """
        from robokin.model.geometry import RobotGeometry

        robot = self.unplaced(robot)
        bare = robot
        geo = robot.geometry if isinstance(robot.geometry, RobotGeometry) else None
        if geo is None:
            geo = RobotGeometry.empty(robot)
        info = robot.meta.get("urdf")
        self.check_exclusions(geo.names, getattr(info, "owners", {}))
        if self.allowed is not None:
            pairs = self._allowed_self_pairs(geo.names, _parts(robot))
            geo = geo.with_exclusions(tuple(p) for p in pairs)
        out = robot
        if not np.array_equal(self.base, np.eye(4)):
            out = out.with_base(self.base @ robot.base)
        if self.tool is not None:
            out = out.with_tool(robot.tool @ self.tool.tcp)
            geo = geo.retool(self.tool.tcp, self.tool.shapes)
        out = out.replace(geometry=geo)
        return out.replace(meta={**out.meta,
                                 _PLACED: (self, out.chain, out.geometry, bare)})

    def _allowed_self_pairs(self, links: Sequence[str],
                            parts: Mapping[str, tuple[str, ...]]) -> set[frozenset[str]]:
        """The robokin link pairs the allowed-collision matrix never checks.

        The rule of :func:`robokin.io.srdf.excluded_link_pairs` (every URDF pair
        between two robokin links allowed), or the robokin names themselves.
        """
        from robokin.io.srdf import excluded_link_pairs

        acm = self.allowed
        if acm is None:
            return set()
        out = excluded_link_pairs(parts, acm.allows)
        for i, a in enumerate(links):
            out |= {frozenset((a, b)) for b in links[i + 1:] if acm.allows(a, b)}
        return out

    def excluded_pairs(self, robot: Robot) -> frozenset[frozenset[str]]:
        """The (robot link, object) pairs never checked, on robokin's names.

        A pair is excluded when ``exclude`` (or the allowed-collision matrix)
        names the robokin link, or names **every** URDF link with shapes that
        the robokin link holds (a robot from a URDF), against the object or the
        MoveIt object it is a shape of. Names the robot or scene does not have
        never match (a MoveIt matrix lists every link of its robot).

        Args:
            robot: The robot (placed by :meth:`attach` or not).
        """
        from robokin.model.geometry import RobotGeometry, link_names

        geo = robot.geometry
        links = geo.names if isinstance(geo, RobotGeometry) else link_names(robot)
        parts = _parts(robot)
        group_of = {name: gid for gid, names in self.groups.items() for name in names}
        acm = self.allowed

        def allowed(a: str, b: str) -> bool:
            return frozenset((a, b)) in self.exclude or (acm is not None and acm.allows(a, b))

        out = set()
        for obj in self.names:
            targets = (obj, group_of[obj]) if obj in group_of else (obj,)
            for link in links:
                if any(allowed(link, o) for o in targets) or (parts.get(link) and all(
                        any(allowed(a, o) for o in targets) for a in parts[link])):
                    out.add(frozenset((link, obj)))
        return frozenset(out)

    def _fingerprint(self) -> tuple:
        """What the compiled check depends on (attributes may be assigned directly)."""
        base = np.asarray(self.base, dtype=float)
        return (
            self._version,
            base.tobytes(),
            id(self.tool),
            frozenset(self.exclude),
            id(self.allowed),
            tuple(self.groups.items()),
            tuple(id(o) for o in self._objects.values()),
        )

    def tcp_pose(self, name: str) -> np.ndarray:
        """A named pose (4, 4) [m] of the TCP in the world."""
        try:
            return self.poses[name]
        except KeyError:
            raise InputError(
                "name", f"no pose {short_repr(name)} in the scene; poses: {list(self.poses)}"
            ) from None

    # ------------------------------------------------------------------ files
    @classmethod
    def load(cls, path: str | Path) -> Scene:
        """Load a scene file: robokin's YAML, or a MoveIt planning scene.

        A file ending ``.scene`` is MoveIt's text format; a YAML file holding
        ``moveit_msgs/PlanningScene`` fields (``world``, ``robot_state``,
        ``allowed_collision_matrix``, ...) is a PlanningScene message; any other
        YAML is a robokin scene file.

        Raises:
            ModelError: missing file, bad YAML or text, a bad field (names the
                file, the field path or line and the reason), an unsupported
                MoveIt entry, or a bad mesh.
        """
        from robokin.io.moveit_scene import is_scene_text_file, read_scene_text
        from robokin.io.moveit_scene_yaml import (
            is_planning_scene_document,
            planning_scene_from_document,
        )
        from robokin.io.text_files import read_text_file
        from robokin.io.yaml_reader import read_yaml_document

        path = Path(path)
        if is_scene_text_file(path):
            return cls.from_moveit(read_scene_text(read_text_file(path), path))
        ydoc = read_yaml_document(path)
        try:
            if is_planning_scene_document(ydoc.data):
                return cls.from_moveit(planning_scene_from_document(ydoc.data, path))
            return cls.from_document(ydoc.data, file=path)
        except ModelError as exc:
            raise ydoc.locate(exc) from None

    @classmethod
    def from_moveit(cls, moveit: MoveItScene) -> Scene:
        """A scene from a MoveIt planning scene read by :mod:`robokin.io.moveit_scene`.

        An object of one shape keeps its id; an object of several shapes becomes
        ``id/0``, ``id/1``, ... (``scene.groups[id]`` lists them). Its
        allowed-collision matrix, joint state and planning frame are kept
        (``allowed``, ``joint_state``, ``frame``).

        Raises:
            ModelError: a name robokin cannot use, or two objects whose shapes'
                names clash (naming the file and line).
        """
        file = moveit.file
        scene = cls(_text(moveit.name, file, "name"))
        scene.path = file
        for obj in moveit.objects:
            names = [obj.id] if len(obj.shapes) == 1 else \
                [f"{obj.id}/{i}" for i in range(len(obj.shapes))]
            for name, shape in zip(names, obj.shapes):
                if name in scene._objects:
                    raise ModelError(f"object name '{name}' is given twice (an object's "
                                     "shapes are named id/0, id/1, ...)", file=file,
                                     line=obj.line)
                scene.add(_text(name, file, "id"), shape)
            scene.groups[obj.id] = tuple(names)
        scene.allowed = moveit.allowed
        scene.joint_state = dict(moveit.joint_state)
        scene.frame = moveit.frame
        return scene

    @classmethod
    def from_document(cls, doc: Any, file: str | Path | None = None) -> Scene:
        """Build a scene from a parsed scene document (see the module docstring)."""
        fields = SceneDocument(doc, file)
        scene = cls(_text(doc.get("name", Path(file).stem if file else "scene"),
                          file, "name"))
        scene.path = None if file is None else Path(file)
        robot = fields.robot()
        if robot is not None:
            scene.robot_name, scene.base = robot
        tool = fields.tool()
        if tool is not None:
            shapes, tcp, name = tool
            scene.set_tool(shapes, tcp, name=name)
        for name, shape in fields.objects():
            scene.add(name, shape)
        scene.exclude.update(fields.exclusions(scene.names))
        scene.poses, scene.pose_joints = fields.poses()
        return scene
