"""URDF out: any robokin robot as a URDF with the same forward kinematics.

Export rules (documented in ``docs/urdf.md``): every chain joint becomes a URDF
joint whose child link frame is the frame just after the joint (for modified DH
that is the robokin link frame; for standard DH the link frame sits
``Tx(a) Rx(alpha)`` further). The joint zero offset is folded into the joint
origin, a reversed joint gets the axis ``0 0 -1``, virtual frames and other
constants are folded into the next origin, ``robot.base`` becomes a fixed joint
from a ``world`` link, and the tool transform a fixed joint to ``tool0``. A
dependent joint ``sum_i m_i q_i + c`` becomes ``<mimic>`` joints: one joint when a
single coordinate drives it, otherwise one coaxial joint per coordinate
(rotations about one axis add). A coordinate that is no chain joint of its own
gets a zero-length joint on a leaf link so the mimic joints have a master.
Link mass properties become ``<inertial>`` elements and torque limits ``effort``
(:mod:`robokin.io.urdf_inertial`); ``<limit velocity>`` carries
``robot.rate_limits.velocity`` where it is known (a placeholder elsewhere; URDF has
no acceleration or jerk limits). Needs no extra.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any
from xml.etree import ElementTree as ET

import numpy as np

from robokin._text import printable
from robokin.io.atomic import write_atomic
from robokin.io.dh_extract import identity_rows
from robokin.io.urdf_tree import UrdfChain
from robokin.model.chain import joint_motion

if TYPE_CHECKING:
    from robokin.model.parts import RobotParts

__all__ = ["rpy_of", "urdf_from_robot", "write_urdf"]

# A prismatic joint without finite limits is written with these (URDF needs numbers).
_BIG = 1.0e6


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


def urdf_from_robot(
    robot: RobotParts,
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
        velocity: The ``<limit velocity>`` [rad/s or m/s] written on joints whose
            speed limit the robot does not know (``robot.rate_limits``; URDF
            requires a value). Known limits are written as they are (a mimic
            joint's scaled by its multiplier).
        effort: The ``<limit effort>`` written on every joint [N m or N] whose
            coordinate has no torque limit in ``robot.dynamics``.
        mesh_uri: Optional ``fn(path) -> str`` rewriting mesh paths (e.g. to
            ``package://`` URIs); default: the path as stored.

    Returns:
        The URDF XML text. Link frames: see the module docstring. The root link is
        ``base_link`` (``world`` when ``robot.base`` is not the identity) and the
        tool frame is ``tool0``.
    """
    chain = robot.chain
    root = ET.Element("robot", {"name": name or robot.name})
    tl = getattr(robot.dynamics, "torque_limits", None)
    efforts = {} if tl is None else {
        j: float(v) for j, v in zip(robot.joint_names, tl) if math.isfinite(v)}
    note = (
        f"written by robokin from '{robot.name}'"
        + (f" ({robot.source})" if robot.source else "")
        + ("; an effort without a torque limit is a placeholder"
           if _known_velocities(robot) is not None
           else "; <limit velocity> and an effort without a torque limit are placeholders")
    )
    note = printable(note)  # XML cannot hold a control character, even escaped
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
                  exact: bool = False, speed: float = math.nan) -> str:
        jname = jname if exact else unique(jname, joint_names)
        el = ET.SubElement(root, "joint", {"name": jname, "type": jtype})
        ET.SubElement(el, "parent", {"link": parent})
        ET.SubElement(el, "child", {"link": child})
        _origin_el(el, T)
        if jtype != "fixed" and axis is not None:  # every moving joint has its axis
            ET.SubElement(el, "axis", {"xyz": " ".join(_fmt(_clean(v)) for v in axis)})
            lim = {"effort": _fmt(efforts.get(jname, effort)),
                   "velocity": _fmt(velocity if math.isnan(speed) else speed)}
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
    urdf = robot.meta.get("urdf")
    info = (urdf if isinstance(urdf, UrdfChain) and len(urdf.child_links) == chain.n_chain
            else None)
    base_name = info.base_link if info is not None else "base_link"
    if not np.array_equal(chain.base, np.eye(4)):
        world = add_link("world")
        base = add_link(base_name)
        add_joint("world_to_base", "fixed", world, base, chain.base)
    else:
        base = add_link(base_name)

    M, c = chain.coupling.matrix, chain.coupling.offset
    coords = chain.coordinates
    cnames = [x.name for x in coords]
    vmax = _known_velocities(robot)
    speeds = np.full(len(cnames), np.nan) if vmax is None else vmax
    # Coordinates that are a chain joint of the same name with an identity row.
    is_self = {chain.joints[kk].name: kk for kk in identity_rows(chain)}
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
        child_name = info.child_links[kk] if info is not None else f"{j.name}_link"
        kind = j.kind
        row = M[kk]
        nz = [int(i) for i in np.flatnonzero(row)]
        F = chain.frame_offsets[kk]
        # (URDF joint name, (coordinate, multiplier, offset) of a mimic or None,
        # position limits, speed limit or NaN)
        parts: list[tuple[str, tuple[int, float, float] | None,
                          tuple[float, float], float]]
        if j.name in is_self:
            i_self = cnames.index(j.name)
            parts = [(j.name, None, coords[i_self].limits, float(speeds[i_self]))]
        elif not nz:
            # A constant joint: its value folds into the constants.
            pending = pending @ joint_motion(kind, j.sign * c[kk] + j.offset) @ F
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
                parts.append((pname, (i, float(row[i]), off), lim,
                              abs(float(row[i])) * float(speeds[i])))
        # Fold F into the joint when the moved axis still passes through the child
        # origin (F^-1 Rz F is then a rotation about F^-1 z): the URDF child link
        # frame is then the robokin link frame.
        fold = kind == "prismatic" or (abs(F[0, 3]) < 1e-15 and abs(F[1, 3]) < 1e-15)
        T = pending @ joint_motion(kind, j.offset)
        for p_i, (pname, mim, lim, speed) in enumerate(parts):
            last = p_i == len(parts) - 1
            child = add_link(child_name if last else f"{child_name}_{p_i + 1}")
            jtype, lim = joint_type(kind, lim)
            mimic_of = None if mim is None else (master(mim[0]), mim[1], mim[2])
            axis = np.array([0.0, 0.0, j.sign])
            if last and fold:
                T = T @ F
                axis = F[:3, :3].T @ axis
            add_joint(pname, jtype, parent, child, T, axis=axis, limits=lim,
                      mimic_of=mimic_of, speed=float(speed))
            parent, T = child, np.eye(4)
        rest = np.eye(4) if fold else F.copy()
        targets.append((parent, rest))
        pending = rest @ chain.link_offsets[kk]
    tool_name = info.tip_link if info is not None and info.tip_link not in link_names \
        else "tool0"
    tool = add_link(tool_name)
    add_joint(f"{parent}_to_{tool}", "fixed", parent, tool, pending @ chain.tool)
    targets.append((tool, np.eye(4)))
    # Masters that are no chain joint: a zero-length joint on a leaf link.
    for i, jname in coordinate_joints:
        leaf = add_link(f"{jname}_coordinate")
        jtype, lim = joint_type(coords[i].kind, coords[i].limits)
        add_joint(jname, jtype, base, leaf, np.eye(4), axis=np.array([0.0, 0, 1]),
                  limits=lim, exact=True, speed=float(speeds[i]))
    if robot.geometry is not None and hasattr(robot.geometry, "shapes"):
        _write_shapes(root, robot.geometry, targets, mesh_uri)
    from robokin.io.urdf_inertial import write_inertials

    write_inertials(root, robot, targets, _fmt)
    ET.indent(root, space="  ")
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def _known_velocities(robot: RobotParts) -> np.ndarray | None:
    """The robot's speed limits (n,) [rad/s or m/s], NaN where unknown.

    None when the robot knows none.
    """
    lim = robot.rate_limits
    v = None if lim is None else lim.velocity
    return None if v is None or np.isnan(v).all() else v


def write_urdf(robot: RobotParts, path: str | Path, **kwargs: Any) -> Path:
    """Write :func:`urdf_from_robot` to ``path`` atomically; returns the path.

    An existing file is replaced (keeping its permissions) only once the new
    content is complete (see :func:`robokin.io.atomic.write_atomic`).

    Raises:
        InputError: the folder of ``path`` is missing or read-only, or ``path``
            is a folder.
    """
    return write_atomic(path, urdf_from_robot(robot, **kwargs))
