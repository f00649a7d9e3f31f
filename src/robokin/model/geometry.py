"""Link and tool shapes: boxes, cylinders, spheres, capsules and meshes.

Every shape has a placement in the frame of the link that carries it (link k in
the frame ``robot.fk_all(q)[..., k, :, :]``, k = 0 the base link; the tool's shapes
in the tool frame). Cylinders and capsules run along their local z axis and are
centred on their placement's origin (as in coal). Meshes (STL, OBJ, DAE, PLY) are
loaded with trimesh on first use and scaled to metres from their declared units.

A robot file's ``geometry:`` section lists shapes per link, in the file's units:

.. code-block:: yaml

    geometry:
      base:
        - {type: cylinder, radius: 75, length: 120, xyz: [0, 0, 60]}
      upper_arm:
        - {type: capsule, radius: 60, from: [-408, 0, 0], to: [0, 0, 0]}
        - {type: mesh, file: meshes/upper_arm.stl, units: mm, rpy: [0, 0, 90]}
      tool:
        - {type: box, size: [80, 40, 100], xyz: [0, 0, 50]}
    collision:
      exclude: [[base, upper_arm]]      # pairs never checked for self-collision

Link keys are ``base``, the chain joint names (link k moves with joint k) and
``tool``. ``from``/``to`` give a cylinder's or capsule's axis end points instead of
``length``/``xyz``/``rpy``. Mesh files resolve relative to the robot file; a mesh's
``units`` (m, cm, mm; default: the file's length unit) and optional ``scale``
convert its vertices to metres. See ``docs/collision.md``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import numpy.typing as npt

from robokin.exceptions import InputError, MissingExtraError, ModelError

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = [
    "RobotGeometry",
    "Shape",
    "ShapeKind",
    "box",
    "capsule",
    "capsule_between",
    "cylinder",
    "cylinder_between",
    "link_names",
    "mesh",
    "shape_from_spec",
    "sphere",
]

ShapeKind = Literal["box", "cylinder", "sphere", "capsule", "mesh"]
_KINDS = ("box", "cylinder", "sphere", "capsule", "mesh")
_MESH_SUFFIXES = (".stl", ".obj", ".dae", ".ply", ".off", ".glb", ".gltf")
_LENGTH = {"m": 1.0, "mm": 1e-3, "cm": 1e-2}


def _ro(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=np.float64)
    a.setflags(write=False)
    return a


def _placement(placement: npt.ArrayLike | None, name: str = "placement") -> np.ndarray:
    if placement is None:
        return _ro(np.eye(4))
    from robokin._validation import check_transform

    T = check_transform(placement, name)
    if T.shape != (4, 4):
        raise InputError(name, f"expected one pose (4, 4), got {T.shape}")
    return _ro(T)


@dataclass(frozen=True, eq=False)
class Shape:
    """One shape in a link (or tool, or scene object) frame.

    Attributes:
        kind: ``"box"``, ``"cylinder"``, ``"sphere"``, ``"capsule"`` or ``"mesh"``.
        size: Box full sizes ``(sx, sy, sz)``; cylinder and capsule
            ``(radius, length)`` (length of the axis, capsule caps excluded);
            sphere ``(radius,)``; mesh ``()`` [m].
        placement: Pose of the shape in its parent frame, (4, 4) [m].
        name: Optional label.
        file: The mesh file (meshes only).
        scale: Factor from mesh-file units to metres (meshes only).
        owner: The link or object the shape belongs to (for error messages).
    """

    kind: ShapeKind
    size: tuple[float, ...] = ()
    placement: np.ndarray = field(default_factory=lambda: _ro(np.eye(4)))
    name: str = ""
    file: Path | None = None
    scale: float = 1.0
    owner: str = ""

    def __post_init__(self) -> None:
        if self.kind not in _KINDS:
            raise InputError(
                "kind", f"expected one of {list(_KINDS)}, got {self.kind!r}"
            )
        need = {"box": 3, "cylinder": 2, "capsule": 2, "sphere": 1, "mesh": 0}[
            self.kind
        ]
        size = tuple(float(v) for v in self.size)
        if len(size) != need:
            raise InputError(
                "size", f"a {self.kind} needs {need} sizes, got {len(size)}"
            )
        if any(not math.isfinite(v) or v < 0.0 for v in size):
            raise InputError("size", f"sizes must be finite and >= 0, got {size}")
        if self.kind in ("box", "sphere") and any(v <= 0 for v in size):
            raise InputError("size", f"a {self.kind} needs positive sizes, got {size}")
        if self.kind in ("cylinder", "capsule") and size[0] <= 0:
            raise InputError(
                "size", f"a {self.kind} needs a positive radius, got {size}"
            )
        if self.kind == "cylinder" and size[1] <= 0:
            raise InputError("size", f"a cylinder needs a positive length, got {size}")
        object.__setattr__(self, "size", size)
        object.__setattr__(self, "placement", _placement(self.placement))
        if self.kind == "mesh":
            if self.file is None:
                raise InputError("file", "a mesh shape needs a file")
            object.__setattr__(self, "file", Path(self.file))
            if not (math.isfinite(self.scale) and self.scale > 0):
                raise InputError("scale", f"must be positive, got {self.scale}")
        object.__setattr__(self, "_cache", {})

    def __repr__(self) -> str:
        extra = f", file={str(self.file)!r}" if self.file is not None else ""
        return f"Shape({self.kind!r}, size={self.size}{extra})"

    def placed(self, T: npt.ArrayLike) -> Shape:
        """The same shape with its placement pre-multiplied by ``T`` (4, 4)."""
        return replace(self, placement=np.asarray(T, dtype=float) @ self.placement)

    def with_owner(self, owner: str) -> Shape:
        """The same shape, labelled as belonging to ``owner``."""
        return replace(self, owner=owner)

    # ------------------------------------------------------------------ meshes
    def trimesh(self):
        """The shape as a ``trimesh.Trimesh`` in its own frame (metres), cached.

        Raises:
            MissingExtraError: trimesh is not installed.
            ModelError: a mesh file that is missing, unreadable or empty (the
                message names the file and the link).
        """
        cache = self._cache  # type: ignore[attr-defined]
        if "trimesh" in cache:
            return cache["trimesh"]
        try:
            import trimesh
        except ImportError:  # pragma: no cover - the extra is installed in CI
            raise MissingExtraError("trimesh", "collision") from None
        k = self.kind
        if k == "box":
            m = trimesh.creation.box(extents=self.size)
        elif k == "sphere":
            m = trimesh.creation.icosphere(subdivisions=2, radius=self.size[0])
        elif k == "cylinder":
            m = trimesh.creation.cylinder(radius=self.size[0], height=self.size[1])
        elif k == "capsule":
            m = trimesh.creation.capsule(height=self.size[1], radius=self.size[0])
        else:
            m = _load_mesh(self.file, self.scale, self.owner)
        cache["trimesh"] = m
        return m

    def check_file(self) -> None:
        """Load a mesh now (no-op for primitives); raises ModelError if it is bad."""
        if self.kind == "mesh":
            self.trimesh()

    # --------------------------------------------------------- bounding volumes
    def local_box(self) -> tuple[np.ndarray, np.ndarray]:
        """An oriented bounding box in the shape's own frame: centre (3,), half sizes (3,)."""
        cache = self._cache  # type: ignore[attr-defined]
        if "box" in cache:
            return cache["box"]
        k, s = self.kind, self.size
        c = np.zeros(3)
        if k == "box":
            h = np.array(s) / 2
        elif k == "sphere":
            h = np.full(3, s[0])
        elif k == "cylinder":
            h = np.array([s[0], s[0], s[1] / 2])
        elif k == "capsule":
            h = np.array([s[0], s[0], s[1] / 2 + s[0]])
        else:
            v = np.asarray(self.trimesh().vertices, dtype=float)
            lo, hi = v.min(axis=0), v.max(axis=0)
            c, h = (lo + hi) / 2, (hi - lo) / 2
        cache["box"] = (c, h)
        return c, h

    def bounding_spheres(self) -> tuple[np.ndarray, np.ndarray]:
        """Spheres that together cover the shape, in the parent frame.

        Returns:
            Centres (k, 3) [m] in the parent frame (placement applied) and radii (k,).
        """
        cache = self._cache  # type: ignore[attr-defined]
        if "spheres" in cache:
            return cache["spheres"]
        if self.kind == "capsule":
            r, L = self.size
            # k + 1 centres on the axis, ends included: a point within r of the
            # axis lies within hypot(r, L / 2k) of the nearest centre.
            k = int(min(8, max(1, math.ceil(L / (1.5 * r)))))
            z = np.linspace(-L / 2, L / 2, k + 1)
            centres = np.stack([np.zeros(k + 1), np.zeros(k + 1), z], axis=1)
            radii = np.full(k + 1, math.hypot(r, L / (2 * k)))
        elif self.kind == "sphere":
            centres, radii = np.zeros((1, 3)), np.array([self.size[0]])
        else:
            c, h = self.local_box()
            sub = max(h.min(), 0.3 * h.max(), 1e-9)
            counts = np.minimum(np.ceil(h / sub - 1e-9).astype(int), 6)
            counts = np.maximum(counts, 1)
            hs = h / counts
            axes = [(np.arange(n) + 0.5) / n * 2 * hh - hh for n, hh in zip(counts, h)]
            g = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
            centres = g + c
            radii = np.full(len(centres), float(np.linalg.norm(hs)))
            if self.kind == "cylinder" and counts[0] == 1 and counts[1] == 1:
                radii[:] = math.hypot(self.size[0], hs[2])
        P = self.placement
        centres = centres @ P[:3, :3].T + P[:3, 3]
        out = (_ro(centres), _ro(radii))
        cache["spheres"] = out
        return out

    # ------------------------------------------------------------------- coal
    def coal_geometry(self):
        """The coal collision geometry (cached; meshes as an OBBRSS BVH)."""
        cache = self._cache  # type: ignore[attr-defined]
        if "coal" in cache:
            return cache["coal"]
        coal = _coal()
        k, s = self.kind, self.size
        if k == "box":
            g = coal.Box(*s)
        elif k == "sphere":
            g = coal.Sphere(s[0])
        elif k == "cylinder":
            g = coal.Cylinder(s[0], s[1])
        elif k == "capsule":
            g = coal.Capsule(s[0], s[1])
        else:
            m = self.trimesh()
            g = coal.BVHModelOBBRSS()
            g.beginModel(len(m.faces), len(m.vertices))
            g.addVertices(np.ascontiguousarray(m.vertices, dtype=np.float64))
            g.addTriangles(np.ascontiguousarray(m.faces, dtype=np.int64))
            g.endModel()
        cache["coal"] = g
        return g

    def coal_convex(self):
        """A convex coal geometry containing the shape (its hull), or the primitive itself."""
        cache = self._cache  # type: ignore[attr-defined]
        if "convex" in cache:
            return cache["convex"]
        if self.kind != "mesh":
            g = self.coal_geometry()
        else:
            coal = _coal()
            hull = self.trimesh().convex_hull
            pts = coal.StdVec_Vec3s()
            for p in np.asarray(hull.vertices, dtype=np.float64):
                pts.append(p)
            tris = coal.StdVec_Triangle()
            for f in np.asarray(hull.faces):
                tris.append(coal.Triangle(int(f[0]), int(f[1]), int(f[2])))
            g = coal.Convex(pts, tris)
        cache["convex"] = g
        return g


def _coal():
    try:
        import coal
    except ImportError:  # pragma: no cover - the extra is installed in CI
        raise MissingExtraError("coal", "collision") from None
    return coal


def _load_mesh(path: Path | None, scale: float, owner: str):
    import trimesh

    where = f" (link '{owner}')" if owner else ""
    if path is None or not Path(path).is_file():
        raise ModelError(f"mesh file not found{where}", file=path, field=owner or None)
    try:
        loaded = trimesh.load(str(path), force="mesh")
    except Exception as exc:  # trimesh raises many kinds on a bad file
        raise ModelError(
            f"cannot read mesh{where}: {type(exc).__name__}: {exc}"[:300],
            file=path,
            field=owner or None,
        ) from None
    faces = getattr(loaded, "faces", None)
    vertices = getattr(loaded, "vertices", None)
    if faces is None or vertices is None or len(faces) == 0 or len(vertices) < 4:
        raise ModelError(
            f"mesh file holds no triangles{where}", file=path, field=owner or None
        )
    if not np.isfinite(np.asarray(vertices)).all():
        raise ModelError(
            f"mesh file holds non-finite vertices{where}",
            file=path,
            field=owner or None,
        )
    m = trimesh.Trimesh(
        vertices=np.asarray(vertices, dtype=np.float64) * scale,
        faces=np.asarray(faces),
        process=False,
    )
    return m


# ------------------------------------------------------------------ constructors
def box(
    size: Sequence[float], placement: npt.ArrayLike | None = None, *, name: str = ""
) -> Shape:
    """A box of full sizes ``(sx, sy, sz)`` [m] centred on ``placement``."""
    return Shape("box", tuple(size), _placement(placement), name=name)


def sphere(
    radius: float, placement: npt.ArrayLike | None = None, *, name: str = ""
) -> Shape:
    """A sphere of ``radius`` [m] centred on ``placement``."""
    return Shape("sphere", (radius,), _placement(placement), name=name)


def cylinder(
    radius: float,
    length: float,
    placement: npt.ArrayLike | None = None,
    *,
    name: str = "",
) -> Shape:
    """A cylinder along local z, centred on ``placement`` [m]."""
    return Shape("cylinder", (radius, length), _placement(placement), name=name)


def capsule(
    radius: float,
    length: float,
    placement: npt.ArrayLike | None = None,
    *,
    name: str = "",
) -> Shape:
    """A capsule (sphere-swept segment of ``length`` along local z) [m]."""
    return Shape("capsule", (radius, length), _placement(placement), name=name)


def _segment_pose(p0: npt.ArrayLike, p1: npt.ArrayLike) -> tuple[np.ndarray, float]:
    p0 = np.asarray(p0, dtype=float).reshape(3)
    p1 = np.asarray(p1, dtype=float).reshape(3)
    axis = p1 - p0
    L = float(np.linalg.norm(axis))
    T = np.eye(4)
    T[:3, 3] = (p0 + p1) / 2
    if L > 1e-12:
        z = axis / L
        helper = (
            np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        )
        x = np.cross(helper, z)
        x /= np.linalg.norm(x)
        T[:3, :3] = np.stack([x, np.cross(z, x), z], axis=1)
    return T, L


def capsule_between(
    p0: npt.ArrayLike, p1: npt.ArrayLike, radius: float, *, name: str = ""
) -> Shape:
    """A capsule whose axis runs from ``p0`` to ``p1`` (3,) [m]."""
    T, L = _segment_pose(p0, p1)
    return Shape("capsule", (radius, L), T, name=name)


def cylinder_between(
    p0: npt.ArrayLike, p1: npt.ArrayLike, radius: float, *, name: str = ""
) -> Shape:
    """A cylinder whose axis runs from ``p0`` to ``p1`` (3,) [m]."""
    T, L = _segment_pose(p0, p1)
    if L <= 0:
        raise InputError("p1", "a cylinder's end points must differ")
    return Shape("cylinder", (radius, L), T, name=name)


def mesh(
    file: str | Path,
    placement: npt.ArrayLike | None = None,
    *,
    units: Literal["m", "mm", "cm"] = "m",
    scale: float = 1.0,
    name: str = "",
    owner: str = "",
) -> Shape:
    """A mesh file (loaded on first use), in ``units`` times ``scale``."""
    if units not in _LENGTH:
        raise InputError("units", f"expected one of {list(_LENGTH)}, got {units!r}")
    return Shape(
        "mesh",
        (),
        _placement(placement),
        name=name,
        file=Path(file),
        scale=_LENGTH[units] * float(scale),
        owner=owner,
    )


# ---------------------------------------------------------------- robot geometry
def link_names(robot: Robot) -> tuple[str, ...]:
    """Names of the links that carry shapes: ``base``, the chain joints, ``tool``."""
    return ("base", *(j.name for j in robot.chain.joints), "tool")


@dataclass(frozen=True, eq=False)
class RobotGeometry:
    """The shapes of a robot, per link.

    Attributes:
        names: Link names (n_chain + 2): ``base``, each chain joint's link, ``tool``.
        shapes: Per link, a tuple of :class:`Shape` placed in that link's frame
            (the tool's in the tool frame).
        exclude: Link-name pairs never checked for self-collision (besides the
            adjacent ones when ``exclude_adjacent``).
        exclude_adjacent: Skip adjacent links (k, k + 1), the tool counting as the
            link after the last one.
    """

    names: tuple[str, ...]
    shapes: tuple[tuple[Shape, ...], ...]
    exclude: frozenset[frozenset[str]] = frozenset()
    exclude_adjacent: bool = True

    def __post_init__(self) -> None:
        if len(self.shapes) != len(self.names):
            raise InputError(
                "shapes",
                f"expected one entry per link ({len(self.names)}), got {len(self.shapes)}",
            )
        object.__setattr__(
            self,
            "shapes",
            tuple(
                tuple(s.with_owner(n) for s in ss)
                for n, ss in zip(self.names, self.shapes)
            ),
        )
        for pair in self.exclude:
            for n in pair:
                if n not in self.names:
                    raise InputError("exclude", _unknown_link(n, self.names))

    @classmethod
    def empty(cls, robot: Robot) -> RobotGeometry:
        """No shapes on any link."""
        names = link_names(robot)
        return cls(names, tuple(() for _ in names))

    @classmethod
    def from_mapping(
        cls,
        robot: Robot,
        shapes: Mapping[str, Iterable[Shape]],
        *,
        exclude: Iterable[Sequence[str]] = (),
        exclude_adjacent: bool = True,
    ) -> RobotGeometry:
        """Build from ``{link name: [Shape, ...]}`` (missing links carry nothing)."""
        names = link_names(robot)
        for key in shapes:
            if key not in names:
                raise InputError("shapes", _unknown_link(key, names))
        return cls(
            names,
            tuple(tuple(shapes.get(n, ())) for n in names),
            frozenset(frozenset(p) for p in exclude),
            exclude_adjacent,
        )

    def index(self, name: str) -> int:
        """Index of a link by name (0 = base, n_chain + 1 = tool)."""
        try:
            return self.names.index(name)
        except ValueError:
            raise InputError("link", _unknown_link(name, self.names)) from None

    def link(self, name: str) -> tuple[Shape, ...]:
        """The shapes of one link."""
        return self.shapes[self.index(name)]

    @property
    def tool(self) -> tuple[Shape, ...]:
        """The tool's shapes (in the tool frame)."""
        return self.shapes[-1]

    def with_link(self, name: str, shapes: Iterable[Shape]) -> RobotGeometry:
        """A copy with one link's shapes replaced."""
        i = self.index(name)
        new = list(self.shapes)
        new[i] = tuple(shapes)
        return replace(self, shapes=tuple(new))

    def with_exclusions(self, pairs: Iterable[Sequence[str]]) -> RobotGeometry:
        """A copy with more link pairs excluded from self-collision."""
        more = frozenset(frozenset(p) for p in pairs)
        return replace(self, exclude=self.exclude | more)

    def is_excluded(self, a: str, b: str) -> bool:
        """True when the pair (a, b) is not checked for self-collision."""
        if a == b:
            return True
        if frozenset((a, b)) in self.exclude:
            return True
        if self.exclude_adjacent:
            i, j = self.index(a), self.index(b)
            if abs(i - j) == 1:
                return True
        return False

    def self_pairs(self) -> list[tuple[int, int]]:
        """Link index pairs (i < j) checked for self-collision (both carry shapes)."""
        out = []
        for i in range(len(self.names)):
            for j in range(i + 1, len(self.names)):
                if (
                    self.shapes[i]
                    and self.shapes[j]
                    and not self.is_excluded(self.names[i], self.names[j])
                ):
                    out.append((i, j))
        return out

    def retool(
        self, tcp: npt.ArrayLike, tool_shapes: Iterable[Shape] = ()
    ) -> RobotGeometry:
        """Geometry after appending ``tcp`` to the tool transform.

        The current tool shapes and ``tool_shapes`` are both given in the old tool
        frame (the mount); they are re-expressed in the new one.
        """
        inv = np.linalg.inv(np.asarray(tcp, dtype=float))
        shapes = tuple(s.placed(inv) for s in (*self.tool, *tool_shapes))
        return self.with_link("tool", shapes)

    def check_files(self) -> None:
        """Load every mesh now; raises ModelError naming a bad file and its link."""
        for ss in self.shapes:
            for s in ss:
                s.check_file()


def _unknown_link(name: str, names: Sequence[str]) -> str:
    return f"unknown link {name!r}; the links are {list(names)}"


# ----------------------------------------------------------------- file section
_COMMON = {"type", "name", "xyz", "rpy"}
_FIELDS = {
    "box": {"size"},
    "sphere": {"radius"},
    "cylinder": {"radius", "length", "from", "to"},
    "capsule": {"radius", "length", "from", "to"},
    "mesh": {"file", "units", "scale"},
}


def _num(
    spec: Mapping[str, Any], key: str, where: str, file: Any, count: int | None = None
):
    v = spec[key]
    try:
        if count is None:
            if isinstance(v, bool):
                raise TypeError
            out = float(v)
            if not math.isfinite(out):
                raise ValueError
            return out
        arr = np.asarray(v, dtype=float)
        if arr.shape != (count,) or not np.isfinite(arr).all():
            raise ValueError
        return arr
    except (TypeError, ValueError):
        what = "a finite number" if count is None else f"{count} finite numbers"
        raise ModelError(
            f"expected {what}, got {v!r:.60}", file=file, field=f"{where}.{key}"
        ) from None


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
            f"a shape must be a mapping, got {spec!r:.60}", file=file, field=where
        )
    kind = spec.get("type")
    if kind not in _KINDS:
        raise ModelError(
            f"'type' must be one of {list(_KINDS)}, got {kind!r}",
            file=file,
            field=f"{where}.type",
        )
    allowed = _COMMON | _FIELDS[kind]
    for key in spec:
        if key not in allowed:
            raise ModelError(
                f"unknown field for a {kind} (allowed: {sorted(allowed)})",
                file=file,
                field=f"{where}.{key}",
            )
    xyz = _num(spec, "xyz", where, file, 3) * length if "xyz" in spec else np.zeros(3)
    rpy = _num(spec, "rpy", where, file, 3) * angle if "rpy" in spec else np.zeros(3)
    if np.any(rpy):
        T = pose_from_xyz_rpy(xyz, rpy)
    else:  # no rotation: skip importing scipy for the common case
        T = np.eye(4)
        T[:3, 3] = xyz
    name = str(spec.get("name", ""))

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
                tuple(_num(spec, "size", where, file, 3) * length),
                T,
                name=name,
                owner=owner,
            )
        if kind == "sphere":
            need("radius")
            return Shape(
                "sphere",
                (_num(spec, "radius", where, file) * length,),
                T,
                name=name,
                owner=owner,
            )
        if kind in ("cylinder", "capsule"):
            need("radius")
            r = _num(spec, "radius", where, file) * length
            if "from" in spec or "to" in spec:
                need("from")
                need("to")
                if "length" in spec:
                    raise ModelError(
                        "give either 'length' or 'from'/'to', not both",
                        file=file,
                        field=f"{where}.length",
                    )
                p0 = _num(spec, "from", where, file, 3) * length
                p1 = _num(spec, "to", where, file, 3) * length
                S, L = _segment_pose(p0, p1)
                return Shape(kind, (r, L), T @ S, name=name, owner=owner)
            need("length")
            L = _num(spec, "length", where, file) * length
            return Shape(kind, (r, L), T, name=name, owner=owner)
        need("file")
        units = spec.get("units")
        if units is None:
            scale = length
        elif units in _LENGTH:
            scale = _LENGTH[units]
        else:
            raise ModelError(
                f"expected one of {list(_LENGTH)}, got {units!r}",
                file=file,
                field=f"{where}.units",
            )
        if "scale" in spec:
            scale *= _num(spec, "scale", where, file)
        path = Path(str(spec["file"])).expanduser()
        if not path.is_absolute() and base_dir is not None:
            path = base_dir / path
        if not path.is_file():
            raise ModelError(
                f"mesh file not found: {path}"
                + (f" (link '{owner}')" if owner else ""),
                file=file,
                field=f"{where}.file",
            )
        if path.suffix.lower() not in _MESH_SUFFIXES:
            raise ModelError(
                f"unsupported mesh format {path.suffix!r} (use {list(_MESH_SUFFIXES)})",
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
    return _LENGTH[length], (1.0 if angle == "rad" else math.pi / 180.0)


def _geometry_section(robot: Robot, value: Any, file: Any, units: Any) -> Robot:
    L, A = _units(units)
    names = link_names(robot)
    if not isinstance(value, Mapping):
        raise ModelError(
            "expected a mapping {link name: [shapes]}", file=file, field="geometry"
        )
    base_dir = Path(file).parent if file is not None else None
    per_link: dict[str, list[Shape]] = {}
    for key, items in value.items():
        if key not in names:
            raise ModelError(
                _unknown_link(key, names), file=file, field=f"geometry.{key}"
            )
        if isinstance(items, Mapping):
            items = [items]
        if not isinstance(items, list):
            raise ModelError(
                "expected a list of shapes", file=file, field=f"geometry.{key}"
            )
        per_link[key] = [
            shape_from_spec(
                s,
                length=L,
                angle=A,
                base_dir=base_dir,
                file=file,
                where=f"geometry.{key}[{i}]",
                owner=key,
            )
            for i, s in enumerate(items)
        ]
    old = robot.geometry if isinstance(robot.geometry, RobotGeometry) else None
    geo = RobotGeometry.from_mapping(robot, per_link)
    if old is not None:
        geo = replace(geo, exclude=old.exclude, exclude_adjacent=old.exclude_adjacent)
    return robot.replace(geometry=geo)


def _collision_section(robot: Robot, value: Any, file: Any, units: Any) -> Robot:
    names = link_names(robot)
    if not isinstance(value, Mapping):
        raise ModelError(
            "expected a mapping with 'exclude'", file=file, field="collision"
        )
    for key in value:
        if key not in ("exclude", "exclude_adjacent"):
            raise ModelError(
                "unknown field (allowed: exclude, exclude_adjacent)",
                file=file,
                field=f"collision.{key}",
            )
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
                f"expected a pair [link, link], got {p!r:.60}",
                file=file,
                field=f"collision.exclude[{i}]",
            )
        for n in p:
            if n not in names:
                raise ModelError(
                    _unknown_link(n, names), file=file, field=f"collision.exclude[{i}]"
                )
        out.append(tuple(p))
    adjacent = value.get("exclude_adjacent", True)
    if not isinstance(adjacent, bool):
        raise ModelError(
            f"expected true or false, got {adjacent!r}",
            file=file,
            field="collision.exclude_adjacent",
        )
    geo = robot.geometry if isinstance(robot.geometry, RobotGeometry) else None
    if geo is None:
        geo = RobotGeometry.empty(robot)
    geo = replace(geo.with_exclusions(out), exclude_adjacent=adjacent)
    return robot.replace(geometry=geo)


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
            else:
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


def _register() -> None:
    from robokin.model.files import register_section

    register_section("geometry", _geometry_section)
    register_section("collision", _collision_section)


_register()
