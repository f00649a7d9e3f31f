"""URDF in (URDF out is :mod:`robokin.io.urdf_export`).

* :func:`parts_from_urdf` reads a URDF (file or XML string, parsed with
  ``yourdfpy``, the ``robokin[urdf]`` extra), compiles the serial chain from a
  base link to a tip link to the canonical chain and returns the robot's parts
  (:meth:`robokin.robot.Robot.from_urdf` makes them a Robot).
* :func:`dh_from_urdf` derives standard and modified DH tables from a URDF arm
  (see :mod:`robokin.io.dh_extract`).

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
* **Rate limits.** ``<limit velocity>`` of each independent joint becomes
  ``robot.rate_limits.velocity`` (a missing or zero velocity, as many vendor URDFs
  write, is unknown: NaN); URDF has no acceleration or jerk limits.
* **Mimic.** A ``<mimic>`` joint is a dependent chain joint
  ``value = multiplier * q[master] + offset`` (chains of mimics are resolved). Its
  master becomes an independent coordinate even when it is not on the chain (a
  gripper's finger that mimics the other finger). Independent coordinates are
  ordered by first use along the chain.
* **Errors.** Malformed XML, a ``<!DOCTYPE>``, a missing ``name``/``parent``/
  ``child``, a revolute or prismatic joint without ``<limit>``, a non-finite or
  malformed number, a link with two parents, a loop, several roots, an unknown
  base or tip: :class:`~robokin.exceptions.ModelError` naming the file, the line,
  the element and the reason (the XML checks are :mod:`robokin.io.urdf_xml`).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, TypedDict

import numpy as np

from robokin._text import short_repr
from robokin.exceptions import ModelError, user_stacklevel
from robokin.io.ros_packages import PackageFinder
from robokin.io.urdf_geometry import (
    Drops,
    MissingMesh,
    geometry_of,
    resolve_mesh,
    with_shapes,
)
from robokin.io.urdf_tool import (
    axis_frame,
    freeze_tool_tree,
    link_owners,
    resolve_mimic,
)
from robokin.io.urdf_tree import Step, Tree, UrdfChain
from robokin.io.urdf_xml import MAX_URDF_JOINTS, MOVABLE, parse_urdf
from robokin.model.chain import Chain, ChainBuilder, Joint, JointKind
from robokin.model.coupling import Dependency, coupling_from_dependencies, mimic
from robokin.model.parts import RobotParts
from robokin.spatial import invert

if TYPE_CHECKING:
    from robokin.io.dh_extract import DHExtraction
    from robokin.io.xacro import XacroExpansion

__all__ = [
    "MAX_URDF_JOINTS",
    "UrdfChain",
    "axis_frame",
    "dh_from_urdf",
    "parse_urdf",
    "parts_from_urdf",
    "resolve_mesh",
]


def _origin(j: Any) -> np.ndarray:
    return np.eye(4) if j.origin is None else np.asarray(j.origin, dtype=np.float64)


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


def _velocity_limits(urdf_robot: Any, chain: Chain, source: str) -> Any:
    """``<limit velocity>`` of each independent coordinate as RateLimits, or None.

    A velocity that is missing, zero (as in many vendor URDFs) or not finite is
    unknown (NaN); None when no coordinate has one.
    """
    from robokin.model.rate_limits import RateLimits

    by_name = {j.name: j for j in urdf_robot.joints}
    out = np.full(chain.n, np.nan)
    for k, c in enumerate(chain.coordinates or ()):
        j = by_name.get(c.name)
        v = None if j is None or j.limit is None else j.limit.velocity
        if v is not None and math.isfinite(float(v)) and float(v) > 0:
            out[k] = float(v)
    if np.isnan(out).all():
        return None
    return RateLimits(velocity=out, source=f"{source}: <limit velocity>")


def _kind(j: Any) -> JointKind:
    return "prismatic" if j.type == "prismatic" else "revolute"


def _path_steps(tree: Tree, base_link: str | None, tip_link: str | None,
                file: Path | None) -> tuple[str, str, list[Step], int]:
    """The base, the tip, the joints between them and the index of the last movable one.

    Raises:
        ModelError: an unknown link, base = tip, a floating or planar joint on the
            path, or no movable joint (naming the file and field).
    """
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
    movable = [i for i, s in enumerate(steps) if s.joint.type in MOVABLE]
    if not movable:
        raise ModelError(
            f"no movable joint between '{base}' and '{tip}'", file=file, field="tip_link"
        )
    return base, tip, steps, movable[-1]


def _add_hanging_links(tree: Tree, frames: dict[str, tuple[int, np.ndarray]]) -> None:
    """Add to ``frames`` the links hanging off the path by fixed joints (they move with it)."""
    stack = list(frames)
    while stack:
        link = stack.pop()
        kk, T = frames[link]
        for j in tree.children[link]:
            if j.child in frames or j.type != "fixed":
                continue
            frames[j.child] = (kk, T @ _origin(j))
            stack.append(j.child)


def chain_from_urdf_model(
    urdf_robot: Any,
    *,
    base_link: str | None = None,
    tip_link: str | None = None,
    file: Path | None = None,
    tool_joints: Mapping[str, float] | None = None,
) -> tuple[Chain, UrdfChain]:
    """Compile the chain ``base_link`` -> ``tip_link`` of a parsed URDF model.

    Args:
        urdf_robot: A ``yourdfpy.Robot`` (``yourdfpy.URDF(...).robot``).
        base_link: Base link name (default: the root).
        tip_link: Tip link name (default: see the module docstring).
        file: The file, for error messages.
        tool_joints: Positions of joints in the tool's tree (default: 0 clamped
            into their limits); see :mod:`robokin.io.urdf_tool`.

    Returns:
        The canonical chain and the :class:`UrdfChain` bookkeeping.
    """
    tree = Tree(urdf_robot, file)
    base, tip, steps, last = _path_steps(tree, base_link, tip_link, file)
    builder = ChainBuilder()
    tool = np.eye(4)
    coords: list[Joint] = []
    deps: dict[str, Dependency] = {}
    names: list[str] = []
    child_links: list[str] = []
    # Pose of every path link in its fk_all frame: (k, T).
    frames: dict[str, tuple[int, np.ndarray]] = {base: (0, np.eye(4))}
    k, T_rel = 0, np.eye(4)

    coord_names: set[str] = set()

    def add_coordinate(j: Any) -> None:
        if j.name not in coord_names:  # a set: linear in the number of joints
            coord_names.add(j.name)
            coords.append(Joint(j.name, _kind(j), _limits(j, file)))

    for i, s in enumerate(steps):
        j = s.joint
        if s.reverse:  # fixed, walked from child to parent
            C = invert(_origin(j))
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
            master, mult, off = resolve_mimic(tree.joints, j, file)
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
    _add_hanging_links(tree, frames)
    # The tool's tree: subtrees below the last link's rigid body, joints frozen.
    positions, left_out = freeze_tool_tree(
        tree, frames, len(names), set(names) | coord_names, tool_joints, file)
    for msg in left_out:
        warnings.warn(f"{file or 'URDF'}: {msg} left out: they move with the arm",
                      UserWarning, stacklevel=user_stacklevel())
    dropped = tuple(sorted(set(tree.links) - set(frames)))
    info = UrdfChain(
        base_link=base,
        tip_link=tip,
        child_links=tuple(child_links),
        link_frames=frames,
        dropped_links=dropped,
        owners=link_owners(frames, names, child_links[-1]),
        tool_joints=positions,
    )
    return chain, info


# ------------------------------------------------------------------------ public
class UrdfKeywords(TypedDict, total=False):
    """The keyword-only arguments of :func:`parts_from_urdf` (and ``Robot.from_urdf``)."""

    xacro_args: Mapping[str, str] | None
    geometry: bool
    missing_mesh: MissingMesh
    name: str | None
    srdf: str | Path | bytes | None
    tool_joints: Mapping[str, float] | None


def parts_from_urdf(
    path_or_string: str | Path | bytes,
    base_link: str | None = None,
    tip_link: str | None = None,
    package_map: Mapping[str, str | Path] | None = None,
    *,
    xacro_args: Mapping[str, str] | None = None,
    geometry: bool = True,
    missing_mesh: MissingMesh = "warn",
    name: str | None = None,
    srdf: str | Path | bytes | None = None,
    tool_joints: Mapping[str, float] | None = None,
) -> RobotParts:
    """The parts of the serial chain of a URDF or xacro (needs ``robokin[urdf]``).

    :meth:`robokin.robot.Robot.from_urdf` takes the same arguments and returns
    a Robot.

    Links hung by fixed joints anywhere on the chain move with their link, and
    the links below the tip (a gripper's tree, its fingers frozen at
    ``tool_joints``) join the tool (:mod:`robokin.io.urdf_tool`); their shapes
    become those links' geometry.

    Args:
        path_or_string: A URDF file path, or the XML itself (a string starting
            with ``<``, or bytes), or a xacro file (a name ending ``.xacro``:
            expanded first by :func:`robokin.io.xacro.expand_xacro`, which
            needs ``robokin[ros]``).
        base_link: The link the chain starts at (default: the root link).
        tip_link: The link it ends at (default: the leaf with the most movable
            joints below the base; ``tool0`` wins a tie).
        package_map: ``{package: directory}`` for ``package://`` meshes and a
            xacro's ``$(find ...)``; searched before ``ROS_PACKAGE_PATH``,
            ``AMENT_PREFIX_PATH`` and the folders above the file
            (:mod:`robokin.io.ros_packages`).
        xacro_args: ``{name: value}`` for a xacro's ``<xacro:arg>``
            declarations (refused for a plain URDF).
        geometry: Read visual and collision shapes (False: kinematics only).
        missing_mesh: A mesh that cannot be used (missing file, remote URI, a
            file that is not a mesh, a non-uniform scale): ``"warn"`` (default:
            a UserWarning naming the link and file, the shape is skipped),
            ``"error"`` (ModelError) or ``"ignore"`` (skipped silently; still
            listed in ``meta["urdf_dropped_shapes"]``). Shapes left out for the
            same reason (every mesh of a package that is not found) give one
            warning.
        name: The robot's name (default: the URDF's ``<robot name>``).
        srdf: The robot's SRDF (a path or the XML; :mod:`robokin.io.srdf`):
            its ``<disable_collisions>`` pairs become self-collision exclusions
            on robokin's links (:func:`robokin.io.srdf.excluded_link_pairs`)
            and, as in MoveIt, every other pair is checked (adjacent links are
            no longer skipped by default); without ``tip_link`` its end
            effector's parent link (or its chain's tip) is the tip.
        tool_joints: ``{joint: position}`` [rad, m] for joints of the tool's
            tree (a gripper's fingers; default: 0 clamped into the limits).

    Returns:
        :class:`~robokin.model.parts.RobotParts` (their ``dynamics`` from the links'
        ``<inertial>`` and the joints' ``effort``, see
        :mod:`robokin.io.urdf_inertial`) with ``robot.meta["urdf"]`` holding the
        :class:`UrdfChain`, ``robot.meta["urdf_shapes"]`` the shapes,
        ``robot.meta["urdf_dropped_shapes"]`` one message per shape left out,
        ``robot.meta["urdf_dropped_notes"]`` one per reason (what ``robokin
        import`` prints), ``robot.meta["srdf"]`` the
        :class:`~robokin.io.srdf.Srdf` (when given) and, for a xacro,
        ``robot.meta["xacro"]`` the
        :class:`~robokin.io.xacro.XacroExpansion` (its ``urdf`` is the
        expanded text).

    Raises:
        ModelError: a bad file (naming the file, element and reason); for a
            xacro, an error in it or a package that is not found.
        InputError: a package map folder that does not exist; ``xacro_args``
            for a file that is not a xacro, or naming an argument the xacro
            does not declare; a ``tool_joints`` entry that is not a joint of
            the tool's tree or is outside its limits.
        MissingExtraError: yourdfpy (or, for a xacro, xacro) is not installed.
    """
    from robokin.io.srdf import parse_srdf

    if missing_mesh not in ("warn", "error", "ignore"):
        raise ModelError(
            "missing_mesh must be 'warn', 'error' or 'ignore', got "
            f"{short_repr(missing_mesh)}",
            field="missing_mesh",
        )
    expansion, urdf_robot, file = _parse_source(path_or_string, package_map,
                                                xacro_args)
    semantic = None if srdf is None else parse_srdf(srdf)
    if semantic is not None:
        links = {link.name for link in urdf_robot.links}
        semantic.check_links(links, urdf_robot.name)
        if tip_link is None:
            tip_link = semantic.default_tip(links)
    chain, info = chain_from_urdf_model(
        urdf_robot, base_link=base_link, tip_link=tip_link, file=file,
        tool_joints=tool_joints,
    )
    drops = Drops(missing_mesh, file)
    packages = expansion.packages if expansion is not None else \
        PackageFinder(package_map, near=file)
    shapes = geometry_of(urdf_robot, info, file, packages, drops) if geometry \
        else []
    source = "URDF string" if file is None else \
        f"{'xacro' if expansion is not None else 'URDF'} {file}"
    meta: dict[str, Any] = {"urdf": info, "urdf_shapes": shapes}
    if expansion is not None:
        meta["xacro"] = expansion
        if expansion.args:
            source += " (" + ", ".join(f"{k}:={v}" for k, v in expansion.args.items()) + ")"
    robot = RobotParts(
        chain,
        name=name or urdf_robot.name,
        source=f"{source}, chain {info.base_link} -> {info.tip_link}",
        meta=meta,
        rate_limits=_velocity_limits(urdf_robot, chain, source),
    )
    robot = with_shapes(robot, shapes, drops, info, semantic)
    from robokin.io.urdf_inertial import dynamics_from_urdf

    robot = robot.replace(dynamics=dynamics_from_urdf(robot, urdf_robot,
                                                      info.link_frames, file))
    drops.report()
    return robot.replace(meta={**robot.meta,
                               "urdf_dropped_shapes": tuple(drops.messages),
                               "urdf_dropped_notes": drops.notes()})


def _parse_source(
    source: str | Path | bytes,
    package_map: Mapping[str, str | Path] | None,
    xacro_args: Mapping[str, str] | None,
) -> tuple[XacroExpansion | None, Any, Path | None]:
    """The xacro expansion (None for a URDF), the parsed URDF and its file."""
    from robokin.exceptions import InputError
    from robokin.io.xacro import expand_xacro, is_xacro

    if not is_xacro(source):
        if xacro_args:
            raise InputError("xacro_args", "given for a URDF that is not a xacro "
                             "file (a name ending .xacro)")
        urdf_robot, file = parse_urdf(source)
        return None, urdf_robot, file
    path = Path(source)  # type: ignore[arg-type]  # is_xacro: a path
    expansion = expand_xacro(path, args=xacro_args, package_map=package_map)
    try:
        urdf_robot, _ = parse_urdf(expansion.urdf)
    except ModelError as exc:
        where = "" if exc.line is None else \
            f" (line {exc.line} of the URDF expanded from it)"
        raise ModelError(exc.reason + where, file=path, field=exc.field) from None
    return expansion, urdf_robot, path


def dh_from_urdf(
    path_or_string: str | Path | bytes,
    base_link: str | None = None,
    tip_link: str | None = None,
    *,
    convention: Literal["standard", "modified"] = "standard",
    reference_link: str | None = None,
    virtual_frames: bool = False,
    package_map: Mapping[str, str | Path] | None = None,
    xacro_args: Mapping[str, str] | None = None,
) -> DHExtraction:
    """DH table of a URDF arm (see :func:`robokin.io.dh_extract.dh_from_robot`).

    Args:
        path_or_string: URDF file, XML string or xacro file.
        base_link: Chain start (default: the root).
        tip_link: Chain end (default as in :func:`parts_from_urdf`).
        convention: ``"standard"`` or ``"modified"``.
        reference_link: The link whose frame guides the choice of DH frame 0 (its
            x axis and origin). Default: the ROS-Industrial ``base`` link when the
            URDF has one rigidly attached to the base (it is the controller's
            base frame, which vendors' DH tables use), else the base link.
        virtual_frames: Fold the remaining base and tool transforms into fixed
            rows (virtual frames) so the table alone reproduces the robot.
        package_map: As in :func:`parts_from_urdf` (a xacro's ``$(find)``).
        xacro_args: As in :func:`parts_from_urdf`.

    Returns:
        A :class:`~robokin.io.dh_extract.DHExtraction`.
    """
    from robokin.io.dh_extract import dh_from_robot as _dh

    robot = parts_from_urdf(path_or_string, base_link, tip_link, package_map,
                            xacro_args=xacro_args, geometry=False)
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
