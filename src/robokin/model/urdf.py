"""URDF in and out.

* :func:`robot_from_urdf` reads a URDF (file or XML string, parsed with
  ``yourdfpy``, the ``robokin[urdf]`` extra) and compiles the serial chain from a
  base link to a tip link to the canonical chain.
* :func:`urdf_from_robot` writes any robokin robot as a URDF string with the same
  forward kinematics and limits (needs no extra).
* :func:`dh_from_urdf` derives standard and modified DH tables from a URDF arm
  (see :mod:`robokin.model.dh_extract`).

Import rules (documented in ``docs/urdf.md``):

* **Chain.** From ``base_link`` (default: the tree's root) to ``tip_link``
  (default: the leaf below the base whose path has the most movable joints; on a
  tie a leaf named ``tool0`` wins, the ROS-Industrial tool frame; otherwise a
  :class:`~robokin.exceptions.ModelError` lists the candidates). The base link
  may sit below the chain's branch point (ROS-Industrial's ``base`` frame): fixed
  joints may be walked backwards, movable ones may not.
* **Frames.** Constants before the first movable joint form the chain's head
  (``robot.base`` stays the identity: the base link frame is the world frame);
  constants after the last one form ``robot.tool``. The frame that
  ``fk_all`` reports for each joint is the URDF frame of the joint's child link.
* **Joints.** ``revolute``, ``continuous`` (unlimited) and ``prismatic`` joints
  about any axis; the axis is folded into the constants (a joint about ``-z``,
  ``-x`` or ``-y`` becomes a reversed joint, ``sign = -1``). ``floating`` and
  ``planar`` joints on the chain are refused.
* **Mimic.** A ``<mimic>`` joint is a dependent chain joint
  ``value = multiplier * q[master] + offset`` (chains of mimics are resolved). Its
  master becomes an independent coordinate even when it is not on the chain (a
  gripper's finger that mimics the other finger). Independent coordinates are
  ordered by first use along the chain.
* **Errors.** Malformed XML, a missing ``name``/``parent``/``child``, a revolute or
  prismatic joint without ``<limit>``, a link with two parents, a loop, several
  roots, an unknown base or tip: :class:`~robokin.exceptions.ModelError` naming the
  file, the element and the reason.

Export rules: every chain joint becomes a URDF joint whose child link frame is the
frame just after the joint (for modified DH that is the robokin link frame; for
standard DH the link frame sits ``Tx(a) Rx(alpha)`` further). The joint zero offset
is folded into the joint origin, a reversed joint gets the axis ``0 0 -1``, virtual
frames and other constants are folded into the next origin, ``robot.base`` becomes a
fixed joint from a ``world`` link, and the tool transform a fixed joint to ``tool0``.
A dependent joint ``sum_i m_i q_i + c`` becomes ``<mimic>`` joints: one joint when a
single coordinate drives it, otherwise one coaxial joint per coordinate (rotations
about one axis add). A coordinate that is no chain joint of its own gets a
zero-length joint on a leaf link so the mimic joints have a master.
"""

from __future__ import annotations

import io
import math
import os
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal
from xml.etree import ElementTree as ET

import numpy as np

from robokin.exceptions import InputError, MissingExtraError, ModelError
from robokin.model.chain import Chain, ChainBuilder, Joint
from robokin.model.coupling import Dependency, coupling_from_dependencies, mimic

if TYPE_CHECKING:
    from robokin.model.dh_extract import DHExtraction
    from robokin.robot import Robot

__all__ = [
    "UrdfChain",
    "dh_from_robot",
    "dh_from_urdf",
    "parse_urdf",
    "robot_from_urdf",
    "urdf_from_robot",
]

MissingMesh = Literal["warn", "error", "ignore"]

_MOVABLE = ("revolute", "continuous", "prismatic")
_KNOWN = (*_MOVABLE, "fixed", "floating", "planar")
# Exact rotations that take the local z axis onto +x / +y (no cos(pi/2) residue).
_Z_TO_X = np.array([[0.0, 0, 1, 0], [0, 1, 0, 0], [-1, 0, 0, 0], [0, 0, 0, 1]])
_Z_TO_Y = np.array([[1.0, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]])
# A prismatic joint without finite limits is written with these (URDF needs numbers).
_BIG = 1.0e6


def _yourdfpy():
    try:
        import yourdfpy
    except ImportError:
        raise MissingExtraError("yourdfpy", "urdf") from None
    return yourdfpy


# ----------------------------------------------------------------------- reading
def _read_source(source: str | Path | bytes) -> tuple[bytes, Path | None]:
    """The XML bytes and the file they came from (None for a string)."""
    if isinstance(source, bytes):
        return source, None
    if isinstance(source, str) and source.lstrip().startswith("<"):
        return source.encode("utf-8"), None
    path = Path(source)
    try:
        return path.read_bytes(), path
    except FileNotFoundError:
        raise ModelError("no such file", file=path) from None
    except OSError as exc:
        raise ModelError(f"cannot read: {exc.strerror}", file=path) from None


def _check_xml(data: bytes, file: Path | None) -> None:
    """Strict XML parse (yourdfpy silently 'recovers' broken XML) and structure."""
    from lxml import etree

    try:
        root = etree.fromstring(data, parser=etree.XMLParser(remove_blank_text=True))
    except etree.XMLSyntaxError as exc:
        line = getattr(exc, "lineno", None)
        where = f" at line {line}" if line else ""
        raise ModelError(f"not valid XML{where}: {exc.msg}", file=file) from None
    if root.tag != "robot":
        raise ModelError(
            f"the root element must be <robot>, got <{root.tag}>", file=file
        )
    if "name" not in root.attrib:
        raise ModelError("<robot> has no 'name' attribute", file=file)
    for el in root.findall("link"):
        if "name" not in el.attrib:
            raise ModelError(
                f"<link> at line {el.sourceline} has no 'name' attribute", file=file
            )
    for el in root.findall("joint"):
        name = el.get("name")
        if name is None:
            raise ModelError(
                f"<joint> at line {el.sourceline} has no 'name' attribute", file=file
            )
        where = f"joint[{name}]"
        jtype = el.get("type")
        if jtype not in _KNOWN:
            raise ModelError(
                f"type must be one of {list(_KNOWN)}, got {jtype!r}", file=file,
                field=f"{where}.type",
            )
        for tag in ("parent", "child"):
            sub = el.find(tag)
            if sub is None or sub.get("link") is None:
                raise ModelError(
                    f"missing <{tag} link=...>", file=file, field=f"{where}.{tag}"
                )
        if jtype in ("revolute", "prismatic") and el.find("limit") is None:
            raise ModelError(
                f"a {jtype} joint needs <limit lower=... upper=...>",
                file=file, field=f"{where}.limit",
            )
        mim = el.find("mimic")
        if mim is not None and mim.get("joint") is None:
            raise ModelError(
                "<mimic> has no 'joint' attribute", file=file, field=f"{where}.mimic"
            )
        for geom in el.iter("geometry"):
            if len(geom) == 0:
                raise ModelError("empty <geometry>", file=file, field=where)
    _check_numbers(root, file)


def _check_numbers(root: Any, file: Path | None) -> None:
    """Vectors (xyz, rpy) hold 3 numbers and limits numbers, naming the line."""
    def field(el: Any, key: str) -> str:
        for up in el.iterancestors():
            if up.tag in ("joint", "link") and up.get("name") is not None:
                return f"{up.tag}[{up.get('name')}].{el.tag}.{key}"
        return f"{el.tag}.{key}"

    for el in root.iter():
        if not isinstance(el.tag, str):
            continue  # comments, processing instructions
        for key in ("xyz", "rpy"):
            text = el.get(key)
            if text is None:
                continue
            try:
                ok = len([float(v) for v in text.split()]) == 3
            except ValueError:
                ok = False
            if not ok:
                raise ModelError(
                    f"<{el.tag} {key}=\"{text}\"> at line {el.sourceline}: "
                    "expected 3 numbers",
                    file=file, field=field(el, key),
                )
        if el.tag == "limit":
            for key in ("lower", "upper", "effort", "velocity"):
                text = el.get(key)
                if text is None:
                    continue
                try:
                    float(text)
                except ValueError:
                    raise ModelError(
                        f"<limit {key}=\"{text}\"> at line {el.sourceline}: "
                        "expected a number",
                        file=file, field=field(el, key),
                    ) from None


def parse_urdf(source: str | Path | bytes) -> tuple[Any, Path | None]:
    """Parse a URDF file or XML string with yourdfpy, strictly.

    Returns:
        ``(yourdfpy.Robot, path or None)``.

    Raises:
        ModelError: unreadable file, malformed XML, or a structural error.
        MissingExtraError: yourdfpy is not installed.
    """
    data, file = _read_source(source)
    _check_xml(data, file)
    yourdfpy = _yourdfpy()
    try:
        urdf = yourdfpy.URDF.load(
            io.BytesIO(data),
            build_scene_graph=False,
            build_collision_scene_graph=False,
            load_meshes=False,
            load_collision_meshes=False,
        )
    except (KeyError, AttributeError, ValueError, TypeError, IndexError) as exc:
        raise ModelError(f"malformed URDF: {exc}", file=file) from None
    return urdf.robot, file


@dataclass(frozen=True)
class _Step:
    """One URDF joint on the path, walked forwards or (fixed joints only) backwards."""

    joint: Any
    reverse: bool


class _Tree:
    """The link/joint tree of a parsed URDF with checks and path queries."""

    def __init__(self, robot: Any, file: Path | None) -> None:
        self.file = file
        self.links: dict[str, Any] = {}
        for link in robot.links:
            if link.name in self.links:
                raise ModelError(f"link '{link.name}' is defined twice", file=file)
            self.links[link.name] = link
        self.joints: dict[str, Any] = {}
        self.parent_joint: dict[str, Any] = {}
        self.children: dict[str, list[Any]] = {name: [] for name in self.links}
        for j in robot.joints:
            where = f"joint[{j.name}]"
            if j.name in self.joints:
                raise ModelError("joint defined twice", file=file, field=where)
            for role in ("parent", "child"):
                link = getattr(j, role)
                if link not in self.links:
                    raise ModelError(
                        f"{role} link '{link}' is not defined", file=file,
                        field=f"{where}.{role}",
                    )
            if j.child in self.parent_joint:
                raise ModelError(
                    f"link '{j.child}' has two parent joints "
                    f"('{self.parent_joint[j.child].name}' and '{j.name}'): "
                    "a URDF must be a tree",
                    file=file, field=where,
                )
            self.joints[j.name] = j
            self.parent_joint[j.child] = j
            self.children[j.parent].append(j)
        roots = [n for n in self.links if n not in self.parent_joint]
        if not roots:
            raise ModelError("the joints form a loop: no root link", file=file)
        if len(roots) > 1:
            raise ModelError(
                f"several root links {roots}: a URDF must be one connected tree",
                file=file,
            )
        self.root = roots[0]
        # Every link must be reachable from the root (no loop elsewhere).
        seen = set(self._descendants(self.root))
        if len(seen) != len(self.links):
            loop = sorted(set(self.links) - seen)
            raise ModelError(f"links {loop} form a loop", file=file)

    def _descendants(self, link: str) -> list[str]:
        out, stack = [], [link]
        while stack:
            cur = stack.pop()
            out.append(cur)
            stack.extend(j.child for j in self.children[cur])
        return out

    def ancestors(self, link: str) -> list[str]:
        """The link, its parent link, ..., the root."""
        out = [link]
        while out[-1] in self.parent_joint:
            out.append(self.parent_joint[out[-1]].parent)
        return out

    def check_link(self, name: str, role: str) -> None:
        if name not in self.links:
            names = sorted(self.links)
            shown = ", ".join(names[:30]) + (" ..." if len(names) > 30 else "")
            raise ModelError(
                f"unknown {role} link '{name}'; links: {shown}", file=self.file,
                field=f"{role}_link",
            )

    def path(self, base: str, tip: str) -> list[_Step]:
        """The joints from ``base`` to ``tip``."""
        up = self.ancestors(base)
        down = self.ancestors(tip)
        common = next((a for a in up if a in set(down)), None)
        steps = []
        for link in up[: up.index(common)]:
            j = self.parent_joint[link]
            if j.type != "fixed":
                raise ModelError(
                    f"the base link '{base}' hangs below the movable joint '{j.name}' "
                    f"that is not between it and the tip '{tip}'; choose a base link "
                    f"above it (e.g. '{self.root}')",
                    file=self.file, field="base_link",
                )
            steps.append(_Step(j, True))
        for link in reversed(down[: down.index(common)]):
            steps.append(_Step(self.parent_joint[link], False))
        return steps

    def default_tip(self, base: str) -> str:
        """The leaf below ``base`` whose path has the most movable joints."""
        top = base  # a base hanging by fixed joints (ROS-I 'base') looks from above
        while top in self.parent_joint and self.parent_joint[top].type == "fixed":
            top = self.parent_joint[top].parent
        leaves = [n for n in self._descendants(top) if not self.children[n]]
        counts = {
            leaf: sum(s.joint.type in _MOVABLE for s in self.path(base, leaf))
            for leaf in leaves
        }
        best = max(counts.values())
        if best == 0:
            raise ModelError(
                f"no movable joint below the base link '{base}'", file=self.file,
                field="tip_link",
            )
        cands = sorted(leaf for leaf, c in counts.items() if c == best)
        if len(cands) == 1:
            return cands[0]
        if "tool0" in cands:
            return "tool0"
        raise ModelError(
            f"ambiguous tip link: {len(cands)} leaves {cands} are each {best} movable "
            f"joints from '{base}'; pass tip_link= (CLI: --tip) to choose one",
            file=self.file, field="tip_link",
        )


def _origin(j: Any) -> np.ndarray:
    return np.eye(4) if j.origin is None else np.asarray(j.origin, dtype=np.float64)


def _invert(T: np.ndarray) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = T[:3, :3].T
    out[:3, 3] = -T[:3, :3].T @ T[:3, 3]
    return out


def axis_frame(axis: Sequence[float], *, where: str = "axis") -> tuple[np.ndarray, float]:
    """A rotation ``A`` (4, 4) and sign with ``A @ Rz(sign q) @ A.T`` = rotation about ``axis``.

    Axis-aligned axes give exact matrices; a negative axis (``-x``, ``-y``, ``-z``,
    or any axis with a negative z component) gives ``sign = -1``.

    Raises:
        ModelError: a zero or non-finite axis.
    """
    u = np.asarray(axis, dtype=np.float64).reshape(-1)
    norm = float(np.linalg.norm(u)) if u.shape == (3,) else 0.0
    if u.shape != (3,) or not np.isfinite(u).all() or norm < 1e-12:
        raise ModelError(f"the joint axis must be a non-zero 3-vector, got {u.tolist()}",
                         field=where)
    u = u / norm
    nz = np.flatnonzero(np.abs(u) > 1e-15)
    if len(nz) == 1:
        i = int(nz[0])
        sign = 1.0 if u[i] > 0 else -1.0
        return ((_Z_TO_X, _Z_TO_Y, np.eye(4))[i]).copy(), sign
    sign = 1.0
    if u[2] < 0:
        u, sign = -u, -1.0
    # Minimal rotation taking z onto u (Rodrigues, 1 + cos >= 1 here).
    v = np.array([-u[1], u[0], 0.0])
    c = u[2]
    K = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    A = np.eye(4)
    A[:3, :3] = np.eye(3) + K + K @ K / (1.0 + c)
    return A, sign


@dataclass(frozen=True)
class UrdfChain:
    """What :func:`robot_from_urdf` made of the URDF, besides the chain.

    Attributes:
        base_link: The chosen base link.
        tip_link: The chosen tip link.
        child_links: The URDF child link of every chain joint (n_chain).
        link_frames: Every URDF link rigidly attached to the chain:
            ``name -> (k, T)``, the link's pose ``T`` (4, 4) in the frame ``k`` of
            ``fk_all`` (0: the base link; k: chain joint k's child link).
        dropped_links: Links not rigidly attached to the chain (they move with
            joints off the chain), sorted.
    """

    base_link: str
    tip_link: str
    child_links: tuple[str, ...]
    link_frames: Mapping[str, tuple[int, np.ndarray]]
    dropped_links: tuple[str, ...]


def _limits(j: Any, file: Path | None) -> tuple[float, float]:
    if j.type == "continuous":
        return (-math.inf, math.inf)
    lim = j.limit
    lo = 0.0 if lim is None or lim.lower is None else float(lim.lower)
    hi = 0.0 if lim is None or lim.upper is None else float(lim.upper)
    if not (math.isfinite(lo) and math.isfinite(hi)) or lo > hi:
        raise ModelError(
            f"limits must be finite with lower <= upper, got [{lo}, {hi}]",
            file=file, field=f"joint[{j.name}].limit",
        )
    return (lo, hi)


def _kind(j: Any) -> str:
    return "prismatic" if j.type == "prismatic" else "revolute"


def _resolve_mimic(tree: _Tree, j: Any) -> tuple[Any, float, float]:
    """The independent master of a mimic joint, with the composed multiplier/offset."""
    mult, off, seen = 1.0, 0.0, {j.name}
    cur = j
    while cur.mimic is not None:
        name = cur.mimic.joint
        master = tree.joints.get(name)
        where = f"joint[{cur.name}].mimic"
        if master is None:
            raise ModelError(f"mimics unknown joint '{name}'", file=tree.file, field=where)
        if master.type not in _MOVABLE:
            raise ModelError(
                f"mimics the {master.type} joint '{name}'", file=tree.file, field=where
            )
        if name in seen:
            raise ModelError("mimic joints form a loop", file=tree.file, field=where)
        seen.add(name)
        m = 1.0 if cur.mimic.multiplier is None else float(cur.mimic.multiplier)
        o = 0.0 if cur.mimic.offset is None else float(cur.mimic.offset)
        mult, off = mult * m, mult * o + off
        cur = master
    return cur, mult, off


def chain_from_urdf_model(
    robot: Any,
    *,
    base_link: str | None = None,
    tip_link: str | None = None,
    file: Path | None = None,
) -> tuple[Chain, UrdfChain]:
    """Compile the chain ``base_link`` -> ``tip_link`` of a parsed URDF model.

    Args:
        robot: A ``yourdfpy.Robot`` (``yourdfpy.URDF(...).robot``).
        base_link: Base link name (default: the root).
        tip_link: Tip link name (default: see the module docstring).
        file: The file, for error messages.

    Returns:
        The canonical chain and the :class:`UrdfChain` bookkeeping.
    """
    tree = _Tree(robot, file)
    base = tree.root if base_link is None else str(base_link)
    tree.check_link(base, "base")
    if tip_link is None:
        tip = tree.default_tip(base)
    else:
        tip = str(tip_link)
        tree.check_link(tip, "tip")
    if tip == base:
        raise ModelError("the base and tip links are the same", file=file,
                         field="tip_link")
    steps = tree.path(base, tip)
    for s in steps:
        if s.joint.type in ("floating", "planar"):
            raise ModelError(
                f"{s.joint.type} joints are not supported on a serial chain",
                file=file, field=f"joint[{s.joint.name}].type",
            )
    movable = [i for i, s in enumerate(steps) if s.joint.type in _MOVABLE]
    if not movable:
        raise ModelError(
            f"no movable joint between '{base}' and '{tip}'", file=file, field="tip_link"
        )
    last = movable[-1]
    builder = ChainBuilder()
    tool = np.eye(4)
    coords: list[Joint] = []
    deps: dict[str, Dependency] = {}
    names: list[str] = []
    child_links: list[str] = []
    # Pose of every path link in its fk_all frame: (k, T).
    frames: dict[str, tuple[int, np.ndarray]] = {base: (0, np.eye(4))}
    k, T_rel = 0, np.eye(4)

    def add_coordinate(j: Any) -> None:
        if all(c.name != j.name for c in coords):
            coords.append(Joint(j.name, _kind(j), _limits(j, file)))

    for i, s in enumerate(steps):
        j = s.joint
        if s.reverse:  # fixed, walked from child to parent
            C = _invert(_origin(j))
            builder.constant(C)
            T_rel = T_rel @ C
            frames[j.parent] = (k, T_rel.copy())
            continue
        O = _origin(j)
        if j.type == "fixed":
            if i > last:
                tool = tool @ O
            else:
                builder.constant(O)
            T_rel = T_rel @ O
            frames[j.child] = (k, T_rel.copy())
            continue
        try:
            A, sign = axis_frame(j.axis, where=f"joint[{j.name}].axis")
        except ModelError as exc:
            raise ModelError(exc.reason, file=file, field=exc.field) from None
        kind = _kind(j)
        if j.mimic is None:
            add_coordinate(j)
            joint = Joint(j.name, kind, _limits(j, file), sign)
        else:
            master, mult, off = _resolve_mimic(tree, j)
            add_coordinate(master)
            deps[j.name] = mimic(master.name, mult, off)
            lim = (-math.inf, math.inf) if j.limit is None else _limits(j, file)
            joint = Joint(j.name, kind, lim, sign)
        builder.constant(O @ A).joint(joint).constant(A.T.copy()).frame()
        names.append(j.name)
        child_links.append(j.child)
        k, T_rel = k + 1, np.eye(4)
        frames[j.child] = (k, T_rel.copy())
    coupling = coordinates = None
    if deps:
        coupling = coupling_from_dependencies(names, [c.name for c in coords], deps)
        coordinates = tuple(coords)
    chain = builder.build(tool=tool, coordinates=coordinates, coupling=coupling)
    # Links hanging off the path by fixed joints move with it.
    on_path = set(frames)
    stack = list(on_path)
    while stack:
        link = stack.pop()
        kk, T = frames[link]
        for j in tree.children[link]:
            if j.child in frames or j.type != "fixed":
                continue
            frames[j.child] = (kk, T @ _origin(j))
            stack.append(j.child)
    dropped = tuple(sorted(set(tree.links) - set(frames)))
    info = UrdfChain(
        base_link=base,
        tip_link=tip,
        child_links=tuple(child_links),
        link_frames=frames,
        dropped_links=dropped,
    )
    return chain, info


# ---------------------------------------------------------------------- geometry
def _resolve_mesh(
    filename: str, file: Path | None, package_map: Mapping[str, str | Path] | None
) -> tuple[Path | None, str]:
    """Resolve a mesh reference to a path; ``(None, reason)`` when it cannot be."""
    if filename.startswith("package://"):
        rest = filename[len("package://"):]
        pkg, _, sub = rest.partition("/")
        root = (package_map or {}).get(pkg)
        if root is None:
            return None, (
                f"package '{pkg}' is not in the package map "
                f"(pass package_map={{'{pkg}': '/path/to/{pkg}'}})"
            )
        return Path(root) / sub, ""
    if filename.startswith("file://"):
        return Path(filename[len("file://"):]), ""
    p = Path(filename)
    if not p.is_absolute():
        if file is None:
            return None, "a relative mesh path in a URDF string has no directory"
        p = file.parent / p
    return p, ""


def _geometry_of(
    urdf_robot: Any,
    info: UrdfChain,
    file: Path | None,
    package_map: Mapping[str, str | Path] | None,
    missing_mesh: MissingMesh,
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
                    path, why = _resolve_mesh(g.mesh.filename, file, package_map)
                    if path is not None and not path.is_file():
                        why = f"no such file {path}"
                    if why:
                        msg = (f"link '{link.name}' {role} mesh "
                               f"'{g.mesh.filename}': {why}")
                        if missing_mesh == "error":
                            raise ModelError(msg, file=file,
                                             field=f"link[{link.name}].{role}")
                        if missing_mesh == "warn":
                            warnings.warn(f"{msg}; shape skipped", UserWarning,
                                          stacklevel=4)
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


def _attach_geometry(
    robot: Robot, shapes: list[dict[str, Any]], file: Path | None,
    missing_mesh: MissingMesh,
) -> Robot:
    """Put the collision shapes on the geometry layer (visual ones where a link has
    no collision shape)."""
    from robokin.model import geometry as geo

    names = geo.link_names(robot)
    with_collision = {e["link"] for e in shapes if e["role"] == "collision"}
    per_link: dict[str, list[Any]] = {}
    for e in shapes:
        if e["role"] == "visual" and e["link"] in with_collision:
            continue
        pose, label = e["pose"], e.get("name") or ""
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
                msg = (f"link '{e['link']}' mesh '{e['uri']}': non-uniform scale "
                       f"{list(sc)} is not supported")
                if missing_mesh == "error":
                    raise ModelError(msg, file=file, field=f"link[{e['link']}]")
                if missing_mesh == "warn":
                    warnings.warn(f"{msg}; shape skipped", UserWarning, stacklevel=4)
                continue
            shape = geo.mesh(e["filename"], pose, scale=sc[0], name=label,
                             owner=e["link"])
        per_link.setdefault(names[e["frame"]], []).append(shape)
    return robot.replace(geometry=geo.RobotGeometry.from_mapping(robot, per_link))


# ------------------------------------------------------------------------ public
def robot_from_urdf(
    path_or_string: str | Path | bytes,
    base_link: str | None = None,
    tip_link: str | None = None,
    package_map: Mapping[str, str | Path] | None = None,
    *,
    geometry: bool = True,
    missing_mesh: MissingMesh = "warn",
    name: str | None = None,
) -> Robot:
    """Load the serial chain of a URDF as a robot (needs ``robokin[urdf]``).

    Args:
        path_or_string: A URDF file path, or the XML itself (a string starting
            with ``<``, or bytes).
        base_link: The link the chain starts at (default: the root link).
        tip_link: The link it ends at (default: the leaf with the most movable
            joints below the base; ``tool0`` wins a tie).
        package_map: ``{package: directory}`` to resolve ``package://`` meshes.
        geometry: Read visual and collision shapes (False: kinematics only).
        missing_mesh: A mesh file that cannot be found: ``"warn"`` (default: a
            UserWarning naming the link and file, the shape is skipped),
            ``"error"`` (ModelError) or ``"ignore"``.
        name: The robot's name (default: the URDF's ``<robot name>``).

    Returns:
        A :class:`~robokin.robot.Robot` with ``robot.meta["urdf"]`` holding the
        :class:`UrdfChain` and ``robot.meta["urdf_shapes"]`` the shapes.

    Raises:
        ModelError: a bad file (naming the file, element and reason).
        MissingExtraError: yourdfpy is not installed.
    """
    from robokin.robot import Robot

    if missing_mesh not in ("warn", "error", "ignore"):
        raise ModelError(
            f"missing_mesh must be 'warn', 'error' or 'ignore', got {missing_mesh!r}",
            field="missing_mesh",
        )
    urdf_robot, file = parse_urdf(path_or_string)
    chain, info = chain_from_urdf_model(
        urdf_robot, base_link=base_link, tip_link=tip_link, file=file
    )
    shapes = (
        _geometry_of(urdf_robot, info, file, package_map, missing_mesh)
        if geometry else []
    )
    source = f"URDF {file}" if file is not None else "URDF string"
    robot = Robot(
        chain,
        name=name or urdf_robot.name,
        source=f"{source}, chain {info.base_link} -> {info.tip_link}",
        meta={"urdf": info, "urdf_shapes": shapes},
    )
    if shapes:
        robot = _attach_geometry(robot, shapes, file, missing_mesh)
    return robot


def dh_from_urdf(
    path_or_string: str | Path | bytes,
    base_link: str | None = None,
    tip_link: str | None = None,
    *,
    convention: Literal["standard", "modified"] = "standard",
    reference_link: str | None = None,
    virtual_frames: bool = False,
) -> DHExtraction:
    """DH table of a URDF arm (see :func:`robokin.model.dh_extract.dh_from_robot`).

    Args:
        path_or_string: URDF file or XML string.
        base_link: Chain start (default: the root).
        tip_link: Chain end (default as in :func:`robot_from_urdf`).
        convention: ``"standard"`` or ``"modified"``.
        reference_link: The link whose frame guides the choice of DH frame 0 (its
            x axis and origin). Default: the ROS-Industrial ``base`` link when the
            URDF has one rigidly attached to the base (it is the controller's
            base frame, which vendors' DH tables use), else the base link.
        virtual_frames: Fold the remaining base and tool transforms into fixed
            rows (virtual frames) so the table alone reproduces the robot.

    Returns:
        A :class:`~robokin.model.dh_extract.DHExtraction`.
    """
    from robokin.model.dh_extract import dh_from_robot as _dh

    robot = robot_from_urdf(path_or_string, base_link, tip_link, geometry=False)
    info: UrdfChain = robot.meta["urdf"]
    ref = reference_link
    if ref is None and "base" in info.link_frames and info.link_frames["base"][0] == 0:
        ref = "base"
    reference = None
    if ref is not None:
        if ref not in info.link_frames or info.link_frames[ref][0] != 0:
            raise ModelError(
                f"reference link '{ref}' is not rigidly attached to the base link "
                f"'{info.base_link}'", field="reference_link",
            )
        reference = info.link_frames[ref][1]
    return _dh(robot, convention=convention, reference=reference,
               virtual_frames=virtual_frames)


def dh_from_robot(robot: Robot, convention: str = "standard", **kwargs: Any) -> DHExtraction:
    """See :func:`robokin.model.dh_extract.dh_from_robot`."""
    from robokin.model.dh_extract import dh_from_robot as _dh

    return _dh(robot, convention=convention, **kwargs)


# ----------------------------------------------------------------------- writing
def _fmt(v: float) -> str:
    v = float(v)
    if v == 0.0:
        return "0"
    return repr(v)


def rpy_of(R: np.ndarray) -> tuple[float, float, float]:
    """URDF roll, pitch, yaw of a rotation (``R = Rz(y) Ry(p) Rx(r)``), gimbal-safe."""
    sp = -R[2, 0]
    cp = math.hypot(R[0, 0], R[1, 0])
    p = math.atan2(sp, cp)
    if cp > 1e-9:
        r = math.atan2(R[2, 1], R[2, 2])
        y = math.atan2(R[1, 0], R[0, 0])
    else:  # pitch = +-pi/2: only r - y (or r + y) is defined; put it in roll
        y = 0.0
        r = math.atan2(math.copysign(1.0, sp) * R[0, 1], R[1, 1])
    return r, p, y


def _clean(v: float) -> float:
    return 0.0 if abs(v) < 1e-15 else float(v)


def _shape_geometry(parent: ET.Element, shape: Any, mesh_uri: Any) -> None:
    g = ET.SubElement(parent, "geometry")
    k, size = shape.kind, shape.size
    if k == "box":
        ET.SubElement(g, "box", {"size": " ".join(_fmt(v) for v in size)})
    elif k == "sphere":
        ET.SubElement(g, "sphere", {"radius": _fmt(size[0])})
    elif k == "cylinder":
        ET.SubElement(g, "cylinder", {"radius": _fmt(size[0]), "length": _fmt(size[1])})
    else:
        path = str(shape.file)
        uri = mesh_uri(path) if mesh_uri is not None else path
        ET.SubElement(g, "mesh", {"filename": uri,
                                  "scale": " ".join([_fmt(shape.scale)] * 3)})


def _write_shapes(root: ET.Element, geometry: Any, targets: list, mesh_uri: Any) -> None:
    """Visual and collision elements; a capsule is a cylinder and two spheres."""
    links = {el.get("name"): el for el in root.findall("link")}
    for (link, T), shapes in zip(targets, geometry.shapes):
        el = links[link]
        for shape in shapes:
            pieces = [(shape, shape.placement)]
            if shape.kind == "capsule":
                from robokin.model.geometry import cylinder, sphere

                r, L = shape.size
                P = np.asarray(shape.placement)
                pieces = [(cylinder(r, L) if L > 0 else sphere(r), P)]
                for z in (-L / 2, L / 2):
                    Tz = np.eye(4)
                    Tz[2, 3] = z
                    pieces.append((sphere(r), P @ Tz))
            for piece, pose in pieces:
                for role in ("visual", "collision"):
                    attrib = {"name": shape.name} if shape.name else {}
                    item = ET.SubElement(el, role, attrib)
                    _origin_el(item, T @ pose)
                    _shape_geometry(item, piece, mesh_uri)


def _origin_el(parent: ET.Element, T: np.ndarray) -> None:
    if np.array_equal(T, np.eye(4)):
        return
    r, p, y = rpy_of(T[:3, :3])
    ET.SubElement(parent, "origin", {
        "xyz": " ".join(_fmt(v) for v in T[:3, 3]),
        "rpy": " ".join(_fmt(v) for v in (r, p, y)),
    })


def _rz_or_tz(kind: str, value: float) -> np.ndarray:
    T = np.eye(4)
    if value == 0.0:
        return T
    if kind == "revolute":
        c, s = math.cos(value), math.sin(value)
        T[:2, :2] = [[c, -s], [s, c]]
    else:
        T[2, 3] = value
    return T


def urdf_from_robot(
    robot: Robot,
    *,
    name: str | None = None,
    velocity: float = 1.0,
    effort: float = 100.0,
    mesh_uri: Any = None,
) -> str:
    """Write a robot as a URDF string with the same FK and limits.

    Args:
        robot: Any robokin robot (standard / modified DH, virtual frames,
            prismatic and dependent joints).
        name: The ``<robot name>`` (default: ``robot.name``).
        velocity: The ``<limit velocity>`` written on every joint [rad/s or m/s]
            (robokin does not model it; URDF requires it).
        effort: The ``<limit effort>`` written on every joint [N m or N].
        mesh_uri: Optional ``fn(path) -> str`` rewriting mesh paths (e.g. to
            ``package://`` URIs); default: the path as stored.

    Returns:
        The URDF XML text. Link frames: see the module docstring. The root link is
        ``base_link`` (``world`` when ``robot.base`` is not the identity) and the
        tool frame is ``tool0``.
    """
    chain = robot.chain
    root = ET.Element("robot", {"name": name or robot.name})
    note = (
        f"written by robokin from '{robot.name}'"
        + (f" ({robot.source})" if robot.source else "")
        + "; <limit velocity/effort> are placeholders"
    )
    while "--" in note:
        note = note.replace("--", "-")
    root.append(ET.Comment(f" {note} "))
    link_names: set[str] = set()
    joint_names: set[str] = set()

    def unique(base: str, used: set[str]) -> str:
        out, i = base, 2
        while out in used:
            out, i = f"{base}_{i}", i + 1
        used.add(out)
        return out

    def add_link(lname: str) -> str:
        lname = unique(lname, link_names)
        ET.SubElement(root, "link", {"name": lname})
        return lname

    def add_joint(jname: str, jtype: str, parent: str, child: str, T: np.ndarray,
                  *, axis: np.ndarray | None = None,
                  limits: tuple[float, float] | None = None,
                  mimic_of: tuple[str, float, float] | None = None,
                  exact: bool = False) -> str:
        jname = jname if exact else unique(jname, joint_names)
        el = ET.SubElement(root, "joint", {"name": jname, "type": jtype})
        ET.SubElement(el, "parent", {"link": parent})
        ET.SubElement(el, "child", {"link": child})
        _origin_el(el, T)
        if jtype != "fixed":
            ET.SubElement(el, "axis", {"xyz": " ".join(_fmt(_clean(v)) for v in axis)})
            lim = {"effort": _fmt(effort), "velocity": _fmt(velocity)}
            if limits is not None and jtype != "continuous":
                lim["lower"], lim["upper"] = _fmt(limits[0]), _fmt(limits[1])
            ET.SubElement(el, "limit", lim)
        if mimic_of is not None:
            ET.SubElement(el, "mimic", {"joint": mimic_of[0],
                                        "multiplier": _fmt(mimic_of[1]),
                                        "offset": _fmt(mimic_of[2])})
        return jname

    def joint_type(kind: str, limits: tuple[float, float]) -> tuple[str, tuple]:
        finite = all(math.isfinite(v) for v in limits)
        if kind == "revolute":
            return ("revolute", limits) if finite else ("continuous", limits)
        if finite:
            return "prismatic", limits
        return "prismatic", tuple(
            v if math.isfinite(v) else math.copysign(_BIG, v) for v in limits
        )

    # Link names from an imported URDF, when the chain still matches.
    info = robot.meta.get("urdf")
    imported = (
        isinstance(info, UrdfChain) and len(info.child_links) == chain.n_chain
    )
    base_name = info.base_link if imported else "base_link"
    if not np.array_equal(chain.base, np.eye(4)):
        world = add_link("world")
        base = add_link(base_name)
        add_joint("world_to_base", "fixed", world, base, chain.base)
    else:
        base = add_link(base_name)

    M, c = chain.coupling.matrix, chain.coupling.offset
    coords = chain.coordinates
    cnames = [x.name for x in coords]
    # Coordinates that are a chain joint of the same name with an identity row.
    is_self = {}
    for kk, j in enumerate(chain.joints):
        if j.name in cnames:
            i = cnames.index(j.name)
            e = np.zeros(len(cnames))
            e[i] = 1.0
            if np.array_equal(M[kk], e) and c[kk] == 0.0:
                is_self[j.name] = kk
    master_of: dict[int, str] = {}
    for i, cn in enumerate(cnames):
        if cn in is_self:
            master_of[i] = cn
    coordinate_joints: list[tuple[int, str]] = []

    # Coordinates without a chain joint of their own keep their name for the
    # zero-length master joint written at the end.
    joint_names.update(cn for cn in cnames if cn not in is_self)

    def master(i: int) -> str:
        if i not in master_of:
            master_of[i] = cnames[i]
            coordinate_joints.append((i, cnames[i]))
        return master_of[i]

    parent = base
    pending = chain.head.copy()
    # Where each fk_all frame's shapes go: (URDF link, pose of the frame in it).
    targets: list[tuple[str, np.ndarray]] = [(base, np.eye(4))]
    for kk, j in enumerate(chain.joints):
        child_name = info.child_links[kk] if imported else f"{j.name}_link"
        kind = j.kind
        row = M[kk]
        nz = [int(i) for i in np.flatnonzero(row)]
        F = chain.frame_offsets[kk]
        if j.name in is_self:
            parts = [(j.name, None, coords[cnames.index(j.name)].limits)]
        elif not nz:
            # A constant joint: its value folds into the constants.
            pending = pending @ _rz_or_tz(kind, j.sign * c[kk] + j.offset) @ F
            targets.append((parent, pending.copy()))
            pending = pending @ chain.link_offsets[kk]
            continue
        else:
            parts = []
            for p_i, i in enumerate(nz):
                lo, hi = (row[i] * v for v in coords[i].limits)
                off = float(c[kk]) if p_i == 0 else 0.0
                lim = (min(lo, hi) + off, max(lo, hi) + off) if all(
                    math.isfinite(v) for v in (lo, hi)) else (-math.inf, math.inf)
                pname = j.name if len(nz) == 1 else f"{j.name}_{cnames[i]}"
                parts.append((pname, (i, float(row[i]), off), lim))
        # Fold F into the joint when the moved axis still passes through the child
        # origin (F^-1 Rz F is then a rotation about F^-1 z): the URDF child link
        # frame is then the robokin link frame.
        fold = kind == "prismatic" or (abs(F[0, 3]) < 1e-15 and abs(F[1, 3]) < 1e-15)
        T = pending @ _rz_or_tz(kind, j.offset)
        for p_i, (pname, mim, lim) in enumerate(parts):
            last = p_i == len(parts) - 1
            child = add_link(child_name if last else f"{child_name}_{p_i + 1}")
            jtype, lim = joint_type(kind, lim)
            mimic_of = None if mim is None else (master(mim[0]), mim[1], mim[2])
            axis = np.array([0.0, 0.0, j.sign])
            if last and fold:
                T = T @ F
                axis = F[:3, :3].T @ axis
            add_joint(pname, jtype, parent, child, T, axis=axis, limits=lim,
                      mimic_of=mimic_of)
            parent, T = child, np.eye(4)
        rest = np.eye(4) if fold else F.copy()
        targets.append((parent, rest))
        pending = rest @ chain.link_offsets[kk]
    tool_name = info.tip_link if imported and info.tip_link not in link_names \
        else "tool0"
    tool = add_link(tool_name)
    add_joint(f"{parent}_to_{tool}", "fixed", parent, tool, pending @ chain.tool)
    targets.append((tool, np.eye(4)))
    # Masters that are no chain joint: a zero-length joint on a leaf link.
    for i, jname in coordinate_joints:
        leaf = add_link(f"{jname}_coordinate")
        jtype, lim = joint_type(coords[i].kind, coords[i].limits)
        add_joint(jname, jtype, base, leaf, np.eye(4), axis=np.array([0.0, 0, 1]),
                  limits=lim, exact=True)
    if robot.geometry is not None and hasattr(robot.geometry, "shapes"):
        _write_shapes(root, robot.geometry, targets, mesh_uri)
    ET.indent(root, space="  ")
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def write_urdf(robot: Robot, path: str | Path, **kwargs: Any) -> Path:
    """Write :func:`urdf_from_robot` to ``path`` atomically; returns the path.

    An existing file is replaced (keeping its permissions) only once the new
    content is complete; a new file gets the usual permissions (0666 less the
    umask).

    Raises:
        InputError: the folder of ``path`` does not exist, or ``path`` is a folder.
    """
    import tempfile

    path = Path(path)
    text = urdf_from_robot(robot, **kwargs)
    directory = path.parent if str(path.parent) else Path(".")
    if not directory.is_dir():
        raise InputError("path", f"{path}: the folder {directory} does not exist")
    if path.is_dir():
        raise InputError("path", f"{path} is a folder, expected a file name")
    if path.exists():
        mode = path.stat().st_mode & 0o7777
    else:
        umask = os.umask(0)
        os.umask(umask)
        mode = 0o666 & ~umask
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=directory)
    try:
        os.chmod(tmp, mode)
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path
