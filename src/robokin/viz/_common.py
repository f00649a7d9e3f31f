"""What the viewers draw, independent of how.

The robot's shapes over time, the scene's bodies, and the per-sample facts of a
collision report.

Both the live viewer (:mod:`robokin.viz.viewer`) and the standalone HTML file
(:mod:`robokin.viz.html`) build on these plain arrays.

The robot is drawn from its geometry when it has one; otherwise every link is a
capsule along the chain's path: from each joint's axis frame (the frame the
joint turns or slides in) to the link frame that follows it (an L through the
foot of the common normal, so a DH row's ``d`` runs along the joint axis and its
``a`` along the link), on to the next joint, and finally to the tool frame.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from robokin._validation import check_joints
from robokin.exceptions import InputError, RobokinError
from robokin.kinematics.forward import link_frames

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = [
    "COLORS",
    "Colors",
    "Drawing",
    "Motion",
    "ReportArrays",
    "SceneShape",
    "Skeleton",
    "motion_from",
    "report_arrays",
    "robot_shapes",
    "has_link_shapes",
    "scene_shapes",
    "drawing",
    "shape_from",
    "skeleton",
]



@dataclass(frozen=True)
class Colors:
    """The drawing colours (RGB, 0-255) both views use.

    Attributes:
        link: Robot links.
        joint: Joint axes, base and flange.
        collision: Bodies in collision.
        distance: The closest-points segment.
    """

    link: tuple[int, int, int] = (232, 142, 48)
    joint: tuple[int, int, int] = (58, 62, 74)
    collision: tuple[int, int, int] = (225, 30, 30)
    distance: tuple[int, int, int] = (20, 160, 230)


#: The colours of the HTML page and the live viewer.
COLORS = Colors()
SCENE_COLOR = (150, 170, 195)


@dataclass(frozen=True)
class Motion:
    """Joint samples over time.

    Attributes:
        t: Times [s], shape (m,).
        q: Joint coordinates [rad, m], shape (m, n).
    """

    t: np.ndarray
    q: np.ndarray


def motion_from(robot: Robot, trajectory: Any = None, *, dt: float = 0.005) -> Motion:
    """Normalise a trajectory argument.

    Args:
        robot: The robot (for n and the default configuration).
        trajectory: None (one sample at zero, clipped into the limits), a
            configuration (n,), joint samples (m, n), or an object with ``.t``
            (m,) and ``.q`` (m, n) (e.g. ``robokin.trajectory.Trajectory``).
        dt: Sample period [s] used when ``trajectory`` carries no times.

    Returns:
        The :class:`Motion`.

    Raises:
        InputError: wrong shapes or non-increasing times.
    """
    if trajectory is None:
        lim = robot.limits
        q = np.clip(np.zeros(robot.n), lim[:, 0], lim[:, 1])[None, :]
        return Motion(np.zeros(1), q)
    if hasattr(trajectory, "q"):
        q = check_joints(trajectory.q, robot.n, "trajectory.q")
        t = getattr(trajectory, "t", None)
    else:
        q = check_joints(trajectory, robot.n, "trajectory")
        t = None
    q = np.atleast_2d(q)
    if q.ndim != 2:
        raise InputError(
            "trajectory", f"expected joint samples (m, {robot.n}), got {q.shape}"
        )
    if not np.isfinite(q).all():
        raise InputError("trajectory", "holds a non-finite joint value")
    if t is None:
        t = np.arange(q.shape[0]) * float(dt)
    t = np.asarray(t, dtype=float).reshape(-1)
    if t.shape[0] != q.shape[0]:
        raise InputError(
            "trajectory.t", f"has {t.shape[0]} times for {q.shape[0]} samples"
        )
    if t.shape[0] > 1 and not np.all(np.diff(t) > 0):
        raise InputError("trajectory.t", "times must increase strictly")
    return Motion(t, q)


@dataclass(frozen=True)
class Skeleton:
    """The chain-path drawing of a robot over m samples.

    Attributes:
        points: Key points [m], shape (m, P, 3).
        links: Capsules as index pairs into ``points``, shape (L, 2).
        radius: Capsule radius [m].
        joint_frames: Joint axis frames, shape (m, n_chain, 4, 4): each
            joint turns about / slides along the local z axis at the origin.
        joint_kinds: ``"revolute"`` / ``"prismatic"`` per chain joint.
        base: Base frames, shape (m, 4, 4).
        tool: Tool poses, shape (m, 4, 4).
    """

    points: np.ndarray
    links: np.ndarray
    radius: float
    joint_frames: np.ndarray
    joint_kinds: tuple[str, ...]
    base: np.ndarray
    tool: np.ndarray

    @property
    def scale(self) -> float:
        """A length typical of the robot [m] (its chain path at the first sample)."""
        p = self.points[0]
        return float(
            np.linalg.norm(p[self.links[:, 1]] - p[self.links[:, 0]], axis=1).sum()
        )


def skeleton(robot: Robot, q: npt.ArrayLike) -> Skeleton:
    """The chain path of ``robot`` at joint samples ``q`` (m, n)."""
    chain = robot.chain
    q = np.atleast_2d(check_joints(q, robot.n, "q"))
    F = link_frames(chain, q)  # (m, nc + 2, 4, 4): base, link frames, tool
    m, nc = q.shape[0], chain.n_chain
    # Joint k's axis frame: base·head for the first, then link frame·G for the rest.
    P = np.empty((m, nc, 4, 4))
    if nc:
        P[:, 0] = chain.base @ chain.head
        if nc > 1:
            P[:, 1:] = F[:, 1:nc] @ chain.link_offsets[: nc - 1]
    pts = [F[:, 0, :3, 3]]
    for k in range(nc):
        o, z = P[:, k, :3, 3], P[:, k, :3, 2]
        nxt = F[:, k + 1, :3, 3]
        foot = o + np.sum((nxt - o) * z, axis=-1, keepdims=True) * z
        pts += [o, foot, nxt]
    pts.append(F[:, -1, :3, 3])
    points = np.stack(pts, axis=1)
    seg = np.linalg.norm(np.diff(points, axis=1), axis=-1).max(axis=0)
    links = np.array(
        [(i, i + 1) for i in range(points.shape[1] - 1) if seg[i] > 1e-6],
        dtype=np.int64,
    ).reshape(-1, 2)
    length = float(np.linalg.norm(np.diff(points[0], axis=0), axis=-1).sum())
    radius = float(np.clip(0.03 * length, 0.006, 0.06))
    return Skeleton(
        points=points,
        links=links,
        radius=radius,
        joint_frames=P,
        joint_kinds=tuple(j.kind for j in chain.joints),
        base=F[:, 0],
        tool=F[:, -1],
    )


@dataclass(frozen=True)
class SceneShape:
    """One primitive body, placed in the world.

    Attributes:
        name: Body name.
        kind: ``"box"``, ``"cylinder"`` (axis z), ``"capsule"`` (axis z),
            ``"sphere"`` or ``"mesh"``.
        size: Box edges (3,), or ``(radius, length)`` for cylinders and
            capsules, ``(radius,)`` for spheres [m].
        pose: Pose in the world (4, 4).
        color: RGB 0-255.
        vertices: Mesh vertices (V, 3) in the body frame, for meshes.
        faces: Mesh triangles (F, 3), for meshes.
    """

    name: str
    kind: str
    size: tuple[float, ...]
    pose: np.ndarray
    color: tuple[int, int, int] = SCENE_COLOR
    vertices: np.ndarray | None = None
    faces: np.ndarray | None = None


def _first_attr(obj: Any, names: Iterable[str]) -> Any:
    for name in names:
        if isinstance(obj, Mapping) and name in obj:
            return obj[name]
        if not isinstance(obj, Mapping) and hasattr(obj, name):
            return getattr(obj, name)
    return None


def shape_from(
    name: str,
    shape: Any,
    pose: npt.ArrayLike | None = None,
    color: tuple[int, int, int] = SCENE_COLOR,
) -> SceneShape | None:
    """A :class:`SceneShape` from a ``robokin.model.geometry.Shape`` (or a dict like one).

    Args:
        name: Label.
        shape: Has ``kind``, ``size`` and ``placement`` (or ``pose``); meshes are
            read through ``shape.trimesh()`` (or carry ``vertices``/``faces``).
        pose: Placement to use instead of the shape's own (4, 4).
        color: RGB 0-255.

    Returns:
        The primitive, or None when the record cannot be read.
    """
    if isinstance(shape, SceneShape):
        return shape
    kind = _first_attr(shape, ("kind", "type"))
    if kind is None:
        return None
    kind = str(kind).lower()
    if pose is None:
        pose = _first_attr(shape, ("placement", "pose"))
    pose = np.eye(4) if pose is None else np.asarray(pose, dtype=float).reshape(4, 4)
    if kind == "mesh":
        verts = _first_attr(shape, ("vertices",))
        faces = _first_attr(shape, ("faces",))
        if verts is None and callable(getattr(shape, "trimesh", None)):
            m = shape.trimesh()
            verts, faces = m.vertices, m.faces
        if verts is None or faces is None:
            return None
        return SceneShape(
            name,
            "mesh",
            (),
            pose,
            color,
            np.asarray(verts, dtype=float),
            np.asarray(faces, dtype=np.int64),
        )
    size = _first_attr(shape, ("size",))
    if size is None:
        return None
    return SceneShape(name, kind, tuple(float(v) for v in np.ravel(size)), pose, color)


def scene_shapes(scene: Any) -> list[SceneShape]:
    """The objects of a ``robokin.collision.Scene`` (or None) as primitives.

    Each scene object has a ``name`` and a ``shape`` whose placement is its
    pose in the world; objects this reader cannot draw are skipped.
    """
    if scene is None:
        return []
    objects = getattr(scene, "objects", scene)
    if isinstance(objects, Mapping):
        objects = [{"name": k, "shape": v} for k, v in objects.items()]
    out = []
    for i, obj in enumerate(objects):
        name = str(_first_attr(obj, ("name",)) or f"object{i}")
        shape = _first_attr(obj, ("shape",))
        s = shape_from(name, shape if shape is not None else obj)
        if s is not None:
            out.append(s)
    return out


def robot_shapes(robot: Robot) -> list[tuple[int, SceneShape]]:
    """The robot's own geometry as ``(frame index, shape in that frame)`` pairs.

    Frame index ``i`` follows :func:`robokin.kinematics.forward.link_frames`
    (and ``robot.geometry.names``): 0 the base, ``k`` the link of chain joint
    k, ``n_chain + 1`` the tool frame. Empty when the robot has no geometry.
    """
    geo = getattr(robot, "geometry", None)
    per_link = getattr(geo, "shapes", None)
    if geo is None or per_link is None:
        return []
    nc = robot.chain.n_chain
    out = []
    for i, shapes in enumerate(per_link):
        if i > nc + 1:
            break
        color = COLORS.joint if i in (0, nc + 1) else COLORS.link
        for j, shape in enumerate(shapes):
            s = shape_from(f"{geo.names[i]}_{j}", shape, color=color)
            if s is not None:
                out.append((i, s))
    return out


def has_link_shapes(shapes: list[tuple[int, SceneShape]], robot: Robot) -> bool:
    """True when some shape sits on a moving link (not only base and tool)."""
    nc = robot.chain.n_chain
    return any(0 < i <= nc for i, _ in shapes)


@dataclass(frozen=True)
class ReportArrays:
    """Per-sample facts of a collision report, aligned with the motion.

    Attributes:
        distance: Minimum distance per sample [m], shape (m,), or None.
        closest: Closest point pairs per sample [m], shape (m, 2, 3), or None.
        colliding: Per-sample collision flag, shape (m,).
        bodies: Names of the bodies in collision per interval.
        min_distance: The report's minimum distance [m], or None.
    """

    distance: np.ndarray | None
    closest: np.ndarray | None
    colliding: np.ndarray
    bodies: list[tuple[int, int, str, str]] = field(default_factory=list)
    min_distance: float | None = None
    track: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]] | None = None

    def closest_at(self, idx: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray] | None:
        """Distance (k,) [m] and closest point pairs (k, 2, 3) at samples ``idx``.

        None when the report cannot tell.
        """
        idx = np.asarray(idx, dtype=np.int64).reshape(-1)
        if self.closest is not None:
            d = (
                self.distance[idx]
                if self.distance is not None
                else np.linalg.norm(
                    self.closest[idx, 1] - self.closest[idx, 0], axis=-1
                )
            )
            return d, self.closest[idx]
        if self.track is not None:
            try:
                return self.track(idx)
            except RobokinError:  # a report that cannot tell: draw no segment
                return None
        return None


def report_arrays(report: Any, m: int) -> ReportArrays:
    """Read a collision report (``robokin.collision.check``'s) duck-typed.

    Uses ``collisions`` [(first, last, body_a, body_b), ...] for the flags, and
    the first of ``distances`` / ``distance`` / ``min_distances`` (m,) and
    ``closest_points`` / ``witness_points`` / ``points`` (m, 2, 3) found.
    """
    colliding = np.zeros(m, dtype=bool)
    if report is None:
        return ReportArrays(None, None, colliding)
    t = getattr(report, "t", None)
    if isinstance(t, np.ndarray) and t.ndim == 1 and t.shape[0] != m:
        raise InputError(
            "report",
            f"checks {t.shape[0]} samples but the trajectory has {m}: "
            "pass the report of this trajectory",
        )
    bodies: list[tuple[int, int, str, str]] = []
    for item in getattr(report, "collisions", None) or []:
        try:
            first, last = int(item[0]), int(item[1])
        except (TypeError, ValueError, IndexError):
            continue
        colliding[max(first, 0) : min(last, m - 1) + 1] = True
        body_a, body_b = (str(item[2]), str(item[3])) if len(item) >= 4 else ("", "")
        bodies.append((first, last, body_a, body_b))
    mask = getattr(report, "colliding", None)
    if mask is not None and np.shape(mask) == (m,):
        colliding |= np.asarray(mask, dtype=bool)
    dist = None
    for name in ("distances", "distance", "min_distances", "clearance"):
        d = getattr(report, name, None)
        if d is not None and np.shape(d) == (m,):
            dist = np.asarray(d, dtype=float)
            break
    closest = None
    for name in ("closest_points", "witness_points", "nearest_points", "points"):
        c = getattr(report, name, None)
        if c is not None and np.shape(c) == (m, 2, 3):
            closest = np.asarray(c, dtype=float)
            break
    md = getattr(report, "min_distance", None)
    md = None if md is None else float(md)
    track = None if closest is not None else _pair_tracker(report)
    return ReportArrays(dist, closest, colliding, bodies, md, track)


def _pair_tracker(
    report: Any,
) -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]] | None:
    """Closest points per sample from the report's public ``closest_at(idx)``.

    ``closest_at`` returns ``(distance (k,), point_a (k, 3), point_b (k, 3))``
    (:meth:`robokin.collision.CollisionReport.closest_at`); None when the report
    has no such method.
    """
    fn = getattr(report, "closest_at", None)
    if not callable(fn):
        return None

    def public(idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d, pa, pb = fn(idx)[:3]
        return np.asarray(d, dtype=float), np.stack([pa, pb], axis=-2)

    return public


@dataclass(frozen=True)
class Drawing:
    """What both views draw of a robot's motion, read once from the arguments.

    Attributes:
        motion: The joint samples (:func:`motion_from`).
        report: The collision report's arrays over the samples (:func:`report_arrays`).
        shapes: The robot's own shapes (:func:`robot_shapes`).
        skeleton_only: No shape on a moving link: draw the skeleton instead.
    """

    motion: Motion
    report: ReportArrays
    shapes: list[tuple[int, SceneShape]]
    skeleton_only: bool


def drawing(robot: Robot, trajectory: Any = None, report: Any = None, *,
            dt: float = 0.005) -> Drawing:
    """The :class:`Drawing` of ``robot`` following ``trajectory`` with ``report``."""
    motion = motion_from(robot, trajectory, dt=dt)
    shapes = robot_shapes(robot)
    return Drawing(motion, report_arrays(report, motion.q.shape[0]), shapes,
                   not has_link_shapes(shapes, robot))
