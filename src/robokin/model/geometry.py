"""Link and tool shapes: boxes, cylinders, spheres, capsules and meshes.

Every shape has a placement in the frame of the link that carries it (link k in
the frame ``robot.fk_all(q)[..., k, :, :]``, k = 0 the base link; the tool's shapes
in the tool frame). Cylinders and capsules run along their local z axis and are
centred on their placement's origin (as in coal). Meshes (STL, OBJ, DAE, PLY) are
loaded with trimesh on first use and scaled to metres from their declared units.

A robot file's ``geometry:`` section lists shapes per link, in the file's units
(read and written by :mod:`robokin.io.geometry_sections`):

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

This module holds the shape data only; it builds no robot and reads no file but
the meshes themselves.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, Protocol

import numpy as np
import numpy.typing as npt

from robokin._text import short_repr
from robokin.exceptions import InputError, MissingExtraError
from robokin.model.mesh_files import load_mesh, mesh_file_problem

if TYPE_CHECKING:
    from trimesh import Trimesh

    from robokin.model.chain import Chain


__all__ = [
    "LENGTH_UNITS",
    "MAX_MESH_BYTES",
    "MAX_MESH_VERTICES",
    "MESH_SUFFIXES",
    "SHAPE_KINDS",
    "HasChain",
    "RobotGeometry",
    "Shape",
    "ShapeKind",
    "box",
    "capsule",
    "capsule_between",
    "cone",
    "cylinder",
    "cylinder_between",
    "link_names",
    "mesh",
    "mesh_file_problem",
    "mesh_from_arrays",
    "segment_pose",
    "sphere",
]

ShapeKind = Literal["box", "cylinder", "sphere", "capsule", "mesh"]
SHAPE_KINDS = ("box", "cylinder", "sphere", "capsule", "mesh")
MESH_SUFFIXES = (".stl", ".obj", ".dae", ".ply", ".off", ".glb", ".gltf")
LENGTH_UNITS = {"m": 1.0, "mm": 1e-3, "cm": 1e-2}
#: Largest mesh file loaded [bytes] (256 MiB).
MAX_MESH_BYTES = 256 * 2**20
#: Most vertices of a mesh given in memory (a MoveIt scene's mesh).
MAX_MESH_VERTICES = 1_000_000


class HasChain(Protocol):
    """Anything with a canonical chain (a :class:`~robokin.robot.Robot`)."""

    @property
    def chain(self) -> Chain:
        """The canonical chain."""
        ...


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
        file: The mesh file (meshes only; None for a mesh given in memory).
        scale: Factor from mesh-file units to metres (meshes only).
        owner: The link or object the shape belongs to (for error messages).
        vertices: A mesh given in memory (a MoveIt scene's mesh, a cone):
            vertices (V, 3) [m] in the shape's frame; None for a mesh file.
        faces: Its triangles (F, 3), indices into ``vertices``.
    """

    kind: ShapeKind
    size: tuple[float, ...] = ()
    placement: np.ndarray = field(default_factory=lambda: _ro(np.eye(4)))
    name: str = ""
    file: Path | None = None
    scale: float = 1.0
    owner: str = ""
    vertices: np.ndarray | None = None
    faces: np.ndarray | None = None
    # derived data (bounds, coal and trimesh objects), built on first use
    _cache: dict[str, Any] = field(init=False, repr=False, default_factory=dict)

    def __post_init__(self) -> None:
        """Check the kind, size, placement and mesh file; normalise them."""
        if self.kind not in SHAPE_KINDS:
            raise InputError(
                "kind", f"expected one of {list(SHAPE_KINDS)}, got {short_repr(self.kind)}"
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
            if (self.vertices is None) != (self.faces is None):
                raise InputError("vertices", "a mesh in memory needs both vertices "
                                 "and faces")
            if self.vertices is not None:
                self._check_memory_mesh()
            elif self.file is None:
                raise InputError("file", "a mesh shape needs a file (or vertices "
                                 "and faces)")
            else:
                object.__setattr__(self, "file", Path(self.file))
            if not (math.isfinite(self.scale) and self.scale > 0):
                raise InputError("scale", f"must be positive, got {self.scale}")
        elif self.vertices is not None or self.faces is not None:
            raise InputError("vertices", f"only a mesh has vertices, not a {self.kind}")

    def _check_memory_mesh(self) -> None:
        """Check and freeze a mesh given in memory (vertices in metres, scale 1)."""
        if self.file is not None or self.scale != 1.0:
            raise InputError("vertices", "a mesh in memory has no file and scale 1 "
                             "(its vertices are in metres)")
        v = np.array(self.vertices, dtype=np.float64)
        try:
            f = np.array(self.faces, dtype=np.int64)
        except (TypeError, ValueError, OverflowError):
            raise InputError("faces", "expected integer vertex indices") from None
        if v.ndim != 2 or v.shape[1] != 3 or len(v) < 3:
            raise InputError("vertices", f"expected (V >= 3, 3) points, got {v.shape}")
        if f.ndim != 2 or f.shape[1] != 3 or len(f) < 1:
            raise InputError("faces", f"expected (F >= 1, 3) triangles, got {f.shape}")
        if len(v) > MAX_MESH_VERTICES or len(f) > 2 * MAX_MESH_VERTICES:
            raise InputError("vertices", f"{len(v):,} vertices and {len(f):,} "
                             f"triangles: robokin takes at most {MAX_MESH_VERTICES:,} "
                             "vertices (robokin.model.geometry.MAX_MESH_VERTICES)")
        if not np.isfinite(v).all():
            raise InputError("vertices", "not finite (NaN or infinity)")
        if f.min() < 0 or f.max() >= len(v):
            raise InputError("faces", f"vertex indices must be in [0, {len(v) - 1}], "
                             f"got {int(f.min())}..{int(f.max())}")
        v.setflags(write=False)
        f.setflags(write=False)
        object.__setattr__(self, "vertices", v)
        object.__setattr__(self, "faces", f)

    def __repr__(self) -> str:
        """A short summary: kind, size, and the file of a mesh."""
        extra = f", file={str(self.file)!r}" if self.file is not None else ""
        if self.vertices is not None and self.faces is not None:
            extra = f", vertices={len(self.vertices)}, faces={len(self.faces)}"
        return f"Shape({self.kind!r}, size={self.size}{extra})"

    def placed(self, T: npt.ArrayLike) -> Shape:
        """The same shape with its placement pre-multiplied by ``T`` (4, 4)."""
        return replace(self, placement=np.asarray(T, dtype=float) @ self.placement)

    def with_owner(self, owner: str) -> Shape:
        """The same shape, labelled as belonging to ``owner``."""
        return replace(self, owner=owner)

    # ------------------------------------------------------------------ meshes
    def trimesh(self) -> Trimesh:
        """The shape as a ``trimesh.Trimesh`` in its own frame (metres), cached.

        Raises:
            MissingExtraError: trimesh is not installed.
            ModelError: a mesh file that is missing, unreadable or empty (the
                message names the file and the link).
        """
        cache = self._cache
        if "trimesh" in cache:
            cached: Trimesh = cache["trimesh"]
            return cached
        try:
            import trimesh
        except ImportError:  # pragma: no cover - the extra is installed in CI
            raise MissingExtraError("trimesh", "collision") from None
        k = self.kind
        m: Trimesh
        if k == "box":
            m = trimesh.creation.box(extents=self.size)
        elif k == "sphere":
            m = trimesh.creation.icosphere(subdivisions=2, radius=self.size[0])
        elif k == "cylinder":
            m = trimesh.creation.cylinder(radius=self.size[0], height=self.size[1])
        elif k == "capsule":
            m = trimesh.creation.capsule(height=self.size[1], radius=self.size[0])
        elif self.vertices is not None:
            m = trimesh.Trimesh(vertices=self.vertices, faces=self.faces, process=False)
        else:
            m = load_mesh(self.file, self.scale, self.owner, MAX_MESH_BYTES)
        cache["trimesh"] = m
        return m

    def check_file(self) -> None:
        """Load a mesh now (no-op for primitives); raises ModelError if it is bad."""
        if self.kind == "mesh":
            self.trimesh()

    # --------------------------------------------------------- bounding volumes
    def local_box(self) -> tuple[np.ndarray, np.ndarray]:
        """An oriented bounding box in the shape's own frame: centre (3,), half sizes (3,)."""
        cache = self._cache
        if "box" in cache:
            box: tuple[np.ndarray, np.ndarray] = cache["box"]
            return box
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
            v = np.asarray(self.trimesh().vertices, dtype=np.float64)
            lo, hi = v.min(axis=0), v.max(axis=0)
            c, h = (lo + hi) / 2, (hi - lo) / 2
        cache["box"] = (c, h)
        return c, h

    def bounding_spheres(self) -> tuple[np.ndarray, np.ndarray]:
        """Spheres that together cover the shape, in the parent frame.

        Returns:
            Centres (k, 3) [m] in the parent frame (placement applied) and radii (k,).
        """
        cache = self._cache
        if "spheres" in cache:
            spheres: tuple[np.ndarray, np.ndarray] = cache["spheres"]
            return spheres
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
    def coal_geometry(self) -> Any:
        """The coal collision geometry (cached; meshes as an OBBRSS BVH; coal is untyped)."""
        cache = self._cache
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

    def coal_convex(self) -> Any:
        """A convex coal geometry containing the shape (its hull), or the primitive itself."""
        cache = self._cache
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


def _coal() -> Any:
    """The coal module (untyped), or MissingExtraError naming ``robokin[collision]``."""
    try:
        import coal
    except ImportError:  # pragma: no cover - the extra is installed in CI
        raise MissingExtraError("coal", "collision") from None
    return coal


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


def segment_pose(p0: npt.ArrayLike, p1: npt.ArrayLike) -> tuple[np.ndarray, float]:
    """The pose (4, 4) of a segment's midpoint with z along it, and its length [m]."""
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
    T, L = segment_pose(p0, p1)
    return Shape("capsule", (radius, L), T, name=name)


def cylinder_between(
    p0: npt.ArrayLike, p1: npt.ArrayLike, radius: float, *, name: str = ""
) -> Shape:
    """A cylinder whose axis runs from ``p0`` to ``p1`` (3,) [m]."""
    T, L = segment_pose(p0, p1)
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
    if units not in LENGTH_UNITS:
        raise InputError("units", f"expected one of {list(LENGTH_UNITS)}, got {short_repr(units)}")
    return Shape(
        "mesh",
        (),
        _placement(placement),
        name=name,
        file=Path(file),
        scale=LENGTH_UNITS[units] * float(scale),
        owner=owner,
    )


def mesh_from_arrays(
    vertices: npt.ArrayLike,
    faces: npt.ArrayLike,
    placement: npt.ArrayLike | None = None,
    *,
    name: str = "",
    owner: str = "",
) -> Shape:
    """A mesh given in memory: ``vertices`` (V, 3) [m] and triangles ``faces`` (F, 3).

    Raises:
        InputError: bad shapes, non-finite vertices, indices out of range, or more
            than :data:`MAX_MESH_VERTICES` vertices.
    """
    return Shape("mesh", (), _placement(placement), name=name, owner=owner,
                 vertices=np.asarray(vertices), faces=np.asarray(faces))


def cone(
    radius: float,
    length: float,
    placement: npt.ArrayLike | None = None,
    *,
    segments: int = 32,
    name: str = "",
) -> Shape:
    """A cone along local z as a mesh that contains it (robokin has no cone primitive).

    As MoveIt's (``geometric_shapes``) cone: the base circle of ``radius`` at
    ``z = -length / 2``, the tip at ``z = +length / 2``. The base is a regular
    polygon of ``segments`` sides *around* the circle (its corners at
    ``radius / cos(pi / segments)``), so the mesh contains the cone and a check
    against it is never optimistic (it is at most 0.5 % wider with 32 sides).

    Raises:
        InputError: a radius or length that is not positive and finite.
    """
    r, L = float(radius), float(length)
    if not (math.isfinite(r) and r > 0 and math.isfinite(L) and L > 0):
        raise InputError("size", f"a cone needs a positive radius and length, got "
                         f"({radius}, {length})")
    k = int(segments)
    if k < 3:
        raise InputError("segments", f"at least 3, got {segments}")
    a = 2 * math.pi * np.arange(k) / k
    R = r / math.cos(math.pi / k)
    ring = np.stack([R * np.cos(a), R * np.sin(a), np.full(k, -L / 2)], axis=1)
    vertices = np.vstack([ring, [[0.0, 0.0, L / 2], [0.0, 0.0, -L / 2]]])
    i = np.arange(k)
    side = np.stack([i, (i + 1) % k, np.full(k, k)], axis=1)
    bottom = np.stack([(i + 1) % k, i, np.full(k, k + 1)], axis=1)
    return mesh_from_arrays(vertices, np.vstack([side, bottom]), placement, name=name)


# ---------------------------------------------------------------- robot geometry
def link_names(robot: HasChain) -> tuple[str, ...]:
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
        """Check one name per link shape list; freeze the shapes."""
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
    def empty(cls, robot: HasChain) -> RobotGeometry:
        """No shapes on any link."""
        names = link_names(robot)
        return cls(names, tuple(() for _ in names))

    @classmethod
    def from_mapping(
        cls,
        robot: HasChain,
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
