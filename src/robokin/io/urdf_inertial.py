"""URDF ``<inertial>`` and ``<limit effort>`` in and out.

Used by :mod:`robokin.io.urdf` and :mod:`robokin.io.urdf_export`. In: each URDF link rigidly attached to the chain contributes its ``<inertial>``
(origin, mass, inertia) to the robokin link it moves with (links joined by fixed
joints are combined into one body); a joint's ``effort`` (> 0) becomes the torque
limit of its coordinate. Out: each robokin link's data is written as the
``<inertial>`` of the URDF link that carries its frame, and torque limits as the
movable joints' ``effort``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any
from xml.etree import ElementTree as ET

import numpy as np

from robokin.exceptions import InputError, ModelError
from robokin.model.dynamics import LinkInertia, RobotDynamics

if TYPE_CHECKING:
    from robokin.model.parts import RobotParts

__all__ = ["dynamics_from_urdf", "write_inertials"]


def dynamics_from_urdf(robot: RobotParts, urdf_robot: Any, link_frames: Mapping[str, Any],
                       file: Any = None) -> RobotDynamics | None:
    """The robot's dynamics from a parsed URDF (None when it has no inertial data).

    Args:
        robot: The robot compiled from the URDF (its chain and joint names).
        urdf_robot: The ``yourdfpy`` robot model.
        link_frames: URDF link -> ``(k, T)``: the fk_all frame it moves with and
            its pose there (:attr:`robokin.io.urdf.UrdfChain.link_frames`).
        file: The URDF, for messages.

    Raises:
        ModelError: an ``<inertial>`` that is not physical (naming the link).
    """
    from robokin.model.geometry import link_names

    names = link_names(robot)
    parts: dict[int, list[LinkInertia]] = {}
    for link in urdf_robot.links:
        inertial = getattr(link, "inertial", None)
        if inertial is None or link.name not in link_frames:
            continue
        k, T = link_frames[link.name]
        origin = np.eye(4) if inertial.origin is None else np.asarray(inertial.origin)
        mass = 0.0 if inertial.mass is None else float(inertial.mass)
        tensor = (np.zeros((3, 3)) if inertial.inertia is None
                  else np.asarray(inertial.inertia, dtype=float))
        try:
            body = LinkInertia(mass, np.zeros(3), tensor).moved(T @ origin)
        except InputError as exc:
            raise ModelError(exc.reason, file=file,
                             field=f"link[{link.name}].inertial.{exc.argument}") from None
        parts.setdefault(int(k), []).append(body)
    efforts = _efforts(robot, urdf_robot)
    if not parts and efforts is None:
        return None
    links = {names[k]: LinkInertia.combine(p) for k, p in parts.items()}
    source = "URDF <inertial>" + (f" of {file}" if file is not None else "")
    return RobotDynamics.from_mapping(
        robot, {k: v for k, v in links.items() if v is not None},
        torque_limits=efforts, source=source)


def _efforts(robot: RobotParts, urdf_robot: Any) -> np.ndarray | None:
    """Per coordinate, the effort of the URDF joint of that name (> 0), else inf."""
    by_name = {j.name: j for j in urdf_robot.joints}
    out = []
    for name in robot.joint_names:
        j = by_name.get(name)
        lim = None if j is None else j.limit
        e = None if lim is None else lim.effort
        out.append(float(e) if e is not None and math.isfinite(e) and e > 0 else math.inf)
    arr = np.array(out)
    return None if np.isinf(arr).all() else arr


def write_inertials(root: ET.Element, robot: RobotParts,
                    targets: Sequence[tuple[str, np.ndarray]],
                    fmt: Any) -> None:
    """Add an ``<inertial>`` to each URDF link that carries robokin links with data.

    Args:
        root: The ``<robot>`` element (links already written).
        robot: The robot (its ``dynamics``).
        targets: Per robokin link (base, chain links, tool), the URDF link that
            carries it and the pose (4, 4) of its frame there.
        fmt: The number formatter of the writer.
    """
    dyn = robot.dynamics
    if not isinstance(dyn, RobotDynamics):
        return
    per_link: dict[str, list[LinkInertia]] = {}
    for (urdf_link, T), data in zip(targets, dyn.links):
        if data is not None:
            per_link.setdefault(urdf_link, []).append(data.moved(T))
    elements = {el.get("name"): el for el in root.findall("link")}
    for urdf_link, parts in per_link.items():
        body = LinkInertia.combine(parts)
        if body is None:
            continue
        el = ET.Element("inertial")
        ET.SubElement(el, "origin", {"xyz": " ".join(fmt(v) for v in body.com),
                                     "rpy": "0 0 0"})
        ET.SubElement(el, "mass", {"value": fmt(body.mass)})
        i = body.inertia
        ET.SubElement(el, "inertia", {
            "ixx": fmt(i[0, 0]), "ixy": fmt(i[0, 1]), "ixz": fmt(i[0, 2]),
            "iyy": fmt(i[1, 1]), "iyz": fmt(i[1, 2]), "izz": fmt(i[2, 2])})
        elements[urdf_link].insert(0, el)
