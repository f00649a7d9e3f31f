"""URDF shapes in: the visual and collision shapes of the links robokin places.

Used by :mod:`robokin.io.urdf`: :func:`resolve_mesh` finds a mesh file
(``package://``, ``file://``, relative paths; never a remote URI, never a path
leaving its package), :func:`geometry_of` lists every shape of the placed links
in their ``fk_all`` frames, :func:`with_shapes` puts the collision shapes (visual
ones where a link has none) on robokin's links (the tool's in the tool frame) and
maps an SRDF's pairs onto them (:func:`robokin.io.srdf.excluded_link_pairs`).
"""

from __future__ import annotations

import os
import re
import warnings
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from robokin._text import short_repr
from robokin.exceptions import ModelError, user_stacklevel
from robokin.io.ros_packages import PackageFinder
from robokin.model.geometry import MESH_SUFFIXES, mesh_file_problem
from robokin.spatial import invert

if TYPE_CHECKING:
    from robokin.io.srdf import Srdf
    from robokin.io.urdf_tree import UrdfChain
    from robokin.model.parts import RobotParts

__all__ = ["Drops", "MissingMesh", "geometry_of", "resolve_mesh", "with_shapes"]

MissingMesh = Literal["warn", "error", "ignore"]
_SCHEME = re.compile(r"^([A-Za-z][A-Za-z0-9+.-]*)://")


def resolve_mesh(
    filename: str, file: Path | None, packages: PackageFinder
) -> tuple[Path | None, str]:
    """Resolve a mesh reference to a path; ``(None, reason)`` when it cannot be.

    ``package://PKG/...`` through ``packages``, ``file://``, a path relative to
    ``file``'s folder; a remote URI is never fetched, a path leaving its
    package is not read, a file that is not a mesh is named.
    """
    if filename.startswith("package://"):
        rest = filename[len("package://"):]
        pkg, _, sub = rest.partition("/")
        root = packages.find(pkg)
        if root is None:
            return None, packages.not_found(pkg)
        inside = os.path.normpath(sub)
        if os.path.isabs(sub) or inside == ".." or inside.startswith(".." + os.sep):
            return None, (f"the path leaves the package '{pkg}' (its folder {root}; "
                          f"it resolves to {os.path.normpath(root / sub)}): not read")
        return _mesh_file(root / sub)
    if filename.startswith("file://"):
        return _mesh_file(Path(filename[len("file://"):]))
    scheme = _SCHEME.match(filename)
    if scheme:
        return None, f"a remote mesh ({scheme.group(1)}://) is not fetched"
    p = Path(filename)
    if not p.is_absolute():
        if file is None:
            return None, "a relative mesh path in a URDF string has no directory"
        p = file.parent / p
    return _mesh_file(p)


def _mesh_file(p: Path) -> tuple[Path | None, str]:
    """``p`` when it names an existing mesh file robokin reads, else the reason."""
    if p.suffix.lower() not in MESH_SUFFIXES:
        return None, (f"not a mesh file (suffix {short_repr(p.suffix)}; robokin "
                      f"reads {', '.join(MESH_SUFFIXES)})")
    problem = mesh_file_problem(p)
    if problem is not None:
        return None, problem
    return p, ""


class Drops:
    """Shapes left out of the import: raised, or recorded and reported per reason.

    Shapes left out for the same reason (every mesh of one missing package) make
    one note: :meth:`notes`, warned once each in ``"warn"`` mode by :meth:`report`.
    """

    def __init__(self, mode: MissingMesh, file: Path | None) -> None:
        """Record drops for ``file`` in ``mode`` (warn, error or ignore)."""
        self.mode, self.file = mode, file
        self.messages: list[str] = []
        self._by_reason: dict[str, list[tuple[str, str, str]]] = {}

    def drop(self, link: str, role: str, uri: str, why: str) -> None:
        """Leave out one shape: raise, or record it under its reason, naming link and file."""
        msg = f"link '{link}' {role} mesh {short_repr(uri, 200)}: {why}"
        if self.mode == "error":
            raise ModelError(msg, file=self.file, field=f"link[{link}].{role}")
        self.messages.append(msg)
        self._by_reason.setdefault(why, []).append((link, role, uri))

    def notes(self) -> tuple[str, ...]:
        """One line per reason: the shape (or how many, of which links) and why."""
        out = []
        for why, shapes in self._by_reason.items():
            if len(shapes) == 1:
                link, role, uri = shapes[0]
                out.append(f"link '{link}' {role} mesh {short_repr(uri, 200)}: {why}")
                continue
            links = list(dict.fromkeys(link for link, _, _ in shapes))
            shown = ", ".join(links[:8]) + (f" and {len(links) - 8} more"
                                            if len(links) > 8 else "")
            roles = " and ".join(sorted({role for _, role, _ in shapes},
                                        reverse=True))
            out.append(f"{len(shapes)} {roles} meshes of link"
                       f"{'s' if len(links) > 1 else ''} {shown}: {why}")
        return tuple(out)

    def report(self) -> None:
        """Warn once per reason (``"warn"`` mode), naming the caller outside robokin."""
        if self.mode == "warn":
            for note in self.notes():
                warnings.warn(f"left out {note}; shapes skipped", UserWarning,
                              stacklevel=user_stacklevel())


def geometry_of(
    urdf_robot: Any,
    info: UrdfChain,
    file: Path | None,
    packages: PackageFinder,
    drops: Drops,
) -> list[dict[str, Any]]:
    """Every visual and collision shape of the chain's links, placed in fk_all frames.

    Each entry: ``{"link": URDF link, "frame": k, "role": "visual"|"collision",
    "pose": (4, 4) in frame k, "type": "box"|"cylinder"|"sphere"|"mesh",
    "size"|"radius"|"length"|"filename"|"scale": ...}``.
    """
    out: list[dict[str, Any]] = []
    for link in urdf_robot.links:
        if link.name not in info.link_frames:
            continue
        k, T = info.link_frames[link.name]
        for role, items in (("visual", link.visuals), ("collision", link.collisions)):
            for item in items:
                g = item.geometry
                pose = T @ (np.eye(4) if item.origin is None else item.origin)
                entry: dict[str, Any] = {
                    "link": link.name, "frame": k, "role": role, "pose": pose,
                    "name": item.name,
                }
                if g.box is not None:
                    entry.update(type="box", size=tuple(float(v) for v in g.box.size))
                elif g.cylinder is not None:
                    entry.update(type="cylinder", radius=float(g.cylinder.radius),
                                 length=float(g.cylinder.length))
                elif g.sphere is not None:
                    entry.update(type="sphere", radius=float(g.sphere.radius))
                elif g.mesh is not None:
                    path, why = resolve_mesh(g.mesh.filename, file, packages)
                    if path is None:
                        drops.drop(link.name, role, g.mesh.filename, why)
                        continue
                    scale = g.mesh.scale
                    scale = (1.0, 1.0, 1.0) if scale is None else tuple(
                        float(v) for v in np.broadcast_to(scale, (3,))
                    )
                    entry.update(type="mesh", filename=str(path), scale=scale,
                                 uri=g.mesh.filename)
                else:  # pragma: no cover - _check_xml refuses empty geometry
                    continue
                out.append(entry)
    return out


def _attach_geometry(robot: RobotParts, shapes: list[dict[str, Any]], drops: Drops,
                     owners: Mapping[str, str]) -> tuple[RobotParts, frozenset[str]]:
    """Put the collision shapes on the geometry layer; the URDF links that gave some.

    Visual shapes stand in where a link has no collision shape. A shape goes to
    the robokin link its URDF link belongs to (``owners``); the tool's shapes
    are placed in the tool frame.
    """
    from robokin.model import geometry as geo

    tool_from_last = invert(robot.chain.tool)
    with_collision = {e["link"] for e in shapes if e["role"] == "collision"}
    per_link: dict[str, list[Any]] = {}
    shaped: set[str] = set()
    for e in shapes:
        if e["role"] == "visual" and e["link"] in with_collision:
            continue
        owner = owners[e["link"]]
        pose, label = e["pose"], e.get("name") or ""
        if owner == "tool":
            pose = tool_from_last @ pose
        t = e["type"]
        if t == "box":
            shape = geo.box(e["size"], pose, name=label)
        elif t == "cylinder":
            shape = geo.cylinder(e["radius"], e["length"], pose, name=label)
        elif t == "sphere":
            shape = geo.sphere(e["radius"], pose, name=label)
        else:
            sc = e["scale"]
            if not (sc[0] == sc[1] == sc[2]):
                drops.drop(e["link"], e["role"], e["uri"],
                           f"non-uniform scale {list(sc)} is not supported")
                continue
            shape = geo.mesh(e["filename"], pose, scale=sc[0], name=label,
                             owner=e["link"])
        per_link.setdefault(owner, []).append(shape)
        shaped.add(e["link"])
    geometry = geo.RobotGeometry.from_mapping(robot, per_link)
    return robot.replace(geometry=geometry), frozenset(shaped)



def with_shapes(robot: RobotParts, shapes: list[dict[str, Any]], drops: Drops,
                 info: UrdfChain, semantic: Srdf | None) -> RobotParts:
    """The robot with its geometry, the SRDF's exclusions and the final bookkeeping."""
    from robokin.io.srdf import excluded_link_pairs

    shaped: frozenset[str] = frozenset()
    if shapes:
        robot, shaped = _attach_geometry(robot, shapes, drops, info.owners)
    info = replace(info, shaped_links=shaped)
    meta = {**robot.meta, "urdf": info}
    if semantic is not None:
        meta["srdf"] = semantic
        if robot.geometry is not None:
            pairs = excluded_link_pairs(info.parts(), semantic.allowed())
            robot = robot.replace(geometry=replace(
                robot.geometry, exclude=frozenset(pairs), exclude_adjacent=False))
    return robot.replace(meta=meta)
