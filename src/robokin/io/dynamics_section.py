"""The ``dynamics:`` section of a robot file: link mass properties and torque limits.

Optional. Lengths are in the file's length unit unless the section declares its
own; masses in kg unless declared; an inertia in mass x length^2 of those units;
torques and forces always in N m and N:

.. code-block:: yaml

    dynamics:
      source: UR's published masses and centres of mass   # where the numbers come from
      units: {length: m, mass: kg}     # optional: length m|mm|cm, mass kg|g
      density: 1000                    # optional [kg/m^3]: links without data are
                                       # estimated from their shapes at this density
      torque_limits: {shoulder_pan: 150, wrist_3: 28}   # optional, per joint [N m | N]
      links:                           # per link (base, chain joints, tool)
        shoulder_pan: {mass: 3.7, com: [0, -0.02561, 0.00193],
                       inertia: [0.0084, 0.0064, 0.0084, 0, 0, 0]}

``com`` is the centre of mass in the link frame (the frame of
``robot.fk_all``); ``inertia`` is ``[ixx, iyy, izz, ixy, ixz, iyz]`` about the
centre of mass, in the link frame's axes, or in the axes of ``rpy`` (radians or
the file's angle unit) when given, as in a URDF ``<inertial>``. Applied through the
robot-file section table (:data:`robokin.io.robot_files.SECTIONS`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from robokin._units import ANGLE_UNITS
from robokin.exceptions import InputError, ModelError
from robokin.io.validate import validate_document
from robokin.model.dynamics import LinkInertia, RobotDynamics

if TYPE_CHECKING:
    from robokin.model.parts import RobotParts

__all__ = ["apply_dynamics_section", "dynamics_section"]

_LENGTH = {"m": 1.0, "cm": 1e-2, "mm": 1e-3}  # dynamics also take centimetres
_MASS = {"kg": 1.0, "g": 1e-3}


def _schema() -> Any:
    from typing import Annotated, Literal

    from pydantic import BaseModel, ConfigDict, Field, StrictFloat, StrictStr

    # StrictFloat: numbers must be numbers ("3.7" and yes are refused)
    Vec3 = tuple[StrictFloat, StrictFloat, StrictFloat]

    class Strict(BaseModel):
        model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    class Units(Strict):
        length: Literal["m", "cm", "mm"] | None = None
        mass: Literal["kg", "g"] = "kg"

    class Link(Strict):
        mass: Annotated[StrictFloat, Field(ge=0.0)]
        com: Vec3 = (0.0, 0.0, 0.0)
        inertia: tuple[StrictFloat, StrictFloat, StrictFloat, StrictFloat, StrictFloat,
                       StrictFloat] = (0.0,) * 6
        rpy: Vec3 | None = None

    class Section(Strict):
        source: Annotated[StrictStr, Field(max_length=4096)] = ""
        units: Units = Field(default_factory=Units)
        density: Annotated[StrictFloat, Field(gt=0.0)] | None = None
        torque_limits: dict[StrictStr, Annotated[StrictFloat, Field(gt=0.0)]] | None = None
        links: dict[StrictStr, Link] = Field(default_factory=dict)

    return Section


def apply_dynamics_section(robot: RobotParts, value: Any, file: Any, units: Any) -> RobotParts:
    """The section reader: a copy of ``robot`` with its dynamics (file units).

    Args:
        robot: The robot built from the file so far.
        value: The section, a mapping in the section's (else the file's) units.
        file: The robot file, for messages.
        units: The file's units (``.length``, ``.angle``).

    Raises:
        ModelError: naming the file, the field path (``dynamics.links.elbow.inertia``
            ...) and the reason: an unknown link or joint, a negative mass, an
            inertia that is not a physical tensor.
    """
    from robokin.model.geometry import link_names
    from robokin.spatial import pose_from_xyz_rpy

    if not isinstance(value, dict):
        raise ModelError(f"must be a mapping of fields, got {type(value).__name__}",
                         file=file, field="dynamics")
    spec = validate_document(_schema(), value, file=file, prefix=("dynamics",))
    L = _LENGTH[spec.units.length or getattr(units, "length", "m")]
    M = _MASS[spec.units.mass]
    A = ANGLE_UNITS[getattr(units, "angle", "rad")]
    names = link_names(robot)
    links: dict[str, LinkInertia] = {}
    for name, lk in spec.links.items():
        where = f"dynamics.links.{name}"
        if name not in names:
            raise ModelError(f"unknown link {name!r}; the links are {list(names)}",
                             file=file, field=where)
        try:
            inertia = LinkInertia.from_moments(lk.mass * M, np.array(lk.com) * L,
                                               [v * M * L * L for v in lk.inertia])
        except InputError as exc:
            raise ModelError(exc.reason, file=file, field=f"{where}.{exc.argument}"
                             ) from None
        if lk.rpy is not None:  # the tensor's axes are rotated in the link frame
            R = pose_from_xyz_rpy(np.zeros(3), np.array(lk.rpy) * A)
            R[:3, 3] = 0.0
            turned = LinkInertia(inertia.mass, np.zeros(3), inertia.inertia).moved(R)
            inertia = LinkInertia(inertia.mass, inertia.com, turned.inertia)
        links[name] = inertia
    limits = None
    if spec.torque_limits is not None:
        joints = list(robot.joint_names)
        for key in spec.torque_limits:
            if key not in joints:
                raise ModelError(f"unknown joint {key!r}; joints: {joints}", file=file,
                                 field=f"dynamics.torque_limits.{key}")
        limits = np.array([spec.torque_limits.get(j, math.inf) for j in joints])
    dyn = RobotDynamics.from_mapping(robot, links, torque_limits=limits,
                                     source=spec.source, density=spec.density)
    return robot.replace(dynamics=dyn)


def dynamics_section(robot: RobotParts) -> dict[str, Any] | None:
    """The ``dynamics:`` section (SI units) of a robot, or None when it has none.

    For writing robots built in memory (e.g. imported from URDF); files loaded
    from disk keep their own section.
    """
    dyn = robot.dynamics
    if not isinstance(dyn, RobotDynamics):
        return None
    out: dict[str, Any] = {}
    if dyn.source:
        out["source"] = dyn.source
    out["units"] = {"length": "m", "mass": "kg"}
    if dyn.density is not None:
        out["density"] = float(dyn.density)
    if dyn.torque_limits is not None:
        out["torque_limits"] = {j: float(v) for j, v in
                                zip(robot.joint_names, dyn.torque_limits)
                                if math.isfinite(v)}
    links: dict[str, Any] = {}
    for name, lk in zip(dyn.names, dyn.links):
        if lk is not None:
            links[name] = {"mass": float(lk.mass), "com": [float(v) for v in lk.com],
                           "inertia": [float(v) for v in lk.moments]}
    out["links"] = links
    return out
