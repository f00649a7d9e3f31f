"""MJCF export: any robokin robot (and scene) as a MuJoCo model with the same FK.

The canonical chain ``T = C0 J1 C1 ... Jn Cn`` becomes a tree of bodies (see
``docs/simulation.md``):

* **Bodies.** One per link: ``base`` (at ``robot.base``, welded to the world),
  one per chain joint (its frame is the link frame of ``robot.fk_all``, so link
  shapes, centres of mass and inertias go in unchanged) and ``tool`` (at the tool
  frame, welded to the last link, carrying the site ``tool``). A body's pose in
  its parent is ``G_{k-1} J_k(constant part) F_k``: virtual frames, zero offsets
  and the constant part of a coupled joint fold in there.
* **Joints.** A chain joint is one hinge or slide through the origin of
  ``F_k^-1`` along ``sign * F_k^-1 z`` (a reversed joint points its axis the
  other way). A chain joint that follows one coordinate with coefficient +-1 (the
  first such for that coordinate) is that coordinate's joint, named as in
  ``robot.joint_names``. Every other (dependent) chain joint keeps its own name
  and is tied to the coordinates' joints by an equality constraint
  ``x_k = sum_i M_ki q_i``: a joint equality for one coordinate, a fixed-tendon
  equality for several (the QFMD010's forearm, ``theta3 - theta2``). A coordinate
  that moves no chain joint with coefficient +-1 gets its own joint on a light
  leaf body.
* **Actuators.** Position servos (:mod:`robokin.sim.servo`) per joint, or per
  motor: a motor acts through a fixed tendon whose length is its coordinate
  ``phi = A^+ (q - b)`` (the robot's actuator map, e.g. the SCARA's ball-screw /
  ball-spline pair), so its force is the motor torque and ``tau_q = A^-T tau_phi``.
  Torque limits clamp each joint's actuator torque (``actuatorfrcrange``).
* **Collision.** Every link shape and scene object is a geom (a capsule, box,
  sphere or cylinder as such; a mesh as its convex hull, inline). Contacts are
  only those robokin's own check looks at: scene objects against moving links,
  and the link pairs :meth:`~robokin.model.geometry.RobotGeometry.self_pairs`
  lists; every other pair is excluded.
* **Mass.** Each link's :class:`~robokin.model.dynamics.LinkInertia` (data, or
  estimated from its shapes; see :func:`~robokin.model.dynamics.resolve_links`).

MJCF text is written directly (ElementTree) rather than through ``MjSpec``: the
text is the product (``robokin export NAME -o robot.xml``), it needs no MuJoCo to
write it, and it stays readable and diffable; MuJoCo compiles it when simulating.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal
from xml.etree import ElementTree as ET

import numpy as np
import numpy.typing as npt

from robokin._text import short_repr
from robokin.exceptions import InputError, ModelError
from robokin.model.chain import joint_motion
from robokin.model.dynamics import LinkInertia, ResolvedLinks, resolve_links
from robokin.sim._mjcf_elements import _fmt, _geom, _parts, _pose_attrs, _vec
from robokin.sim._mjcf_tuning import (
    JointMap,
    _check_q_ref,
    _effective_inertia,
    _stable_step,
)
from robokin.sim.servo import servo_gains
from robokin.spatial import invert

if TYPE_CHECKING:
    from robokin.collision.scene import Scene
    from robokin.robot import Robot

__all__ = ["MAX_LINK_INERTIA", "MAX_LINK_MASS", "MJCF_TIMESTEP", "TRIANGLE_SLACK",
           "JointMap", "MjcfExport", "build_mjcf", "to_mjcf", "write_mjcf"]

F64 = npt.NDArray[np.float64]
ActuatorSpace = Literal["joint", "motor"]

#: Default physics time step [s] (1 kHz).
MJCF_TIMESTEP = 0.001
# Mass [kg] and principal moment [kg m^2] given to a moving body without any mass
# (MuJoCo refuses massless moving bodies); reported in the export's notes.
_TINY_MASS = 1e-9
_TINY_INERTIA = 1e-12
# Rotor inertia [kg m^2 or kg] of the joint of a coordinate on a massless leaf
# body (without it the mass matrix is singular there).
_ARMATURE = 1e-6
#: Largest link mass [kg] the export accepts (a 100 t link is a typo, not an arm).
MAX_LINK_MASS = 1e5
#: Largest principal moment of inertia [kg m^2] the export accepts (1e5 kg at a
#: radius of gyration of 3 m).
MAX_LINK_INERTIA = 1e6
#: How far a tensor's principal moments may break ``A + B >= C`` and still be
#: balanced with a note (``C <= (1 + slack) (A + B)``): published tables round
#: (the Puma 560's elbow breaks it by 9.6 %); beyond, no rigid body has them.
TRIANGLE_SLACK = 0.25
_ROBOT_RGBA = "0.95 0.55 0.15 1"
_SCENE_RGBA = "0.6 0.6 0.65 0.6"


@dataclass(frozen=True, eq=False)
class MjcfExport:
    """The MJCF text and what a simulation needs to drive and read it.

    Attributes:
        xml: The MJCF text.
        robot: The robot as modelled (placed in the scene when one was given).
        joints: The :class:`JointMap`.
        links: Every link's mass properties and where they come from.
        actuators: ``"joint"`` (one servo per joint coordinate) or ``"motor"``
            (one per motor, through the actuator map).
        actuator_names: The actuators, in ``ctrl`` order.
        kp: Servo stiffness per actuator.
        kv: Servo damping per actuator.
        ctrl_offset: Added to a set point to make the actuator's ``ctrl``,
            (n_actuators,) (a motor tendon's ``A^+ b``).
        gravity_compensation: Whether the servos compensate gravity.
        velocity_feedforward: Whether the servos follow the set velocity.
        torque_limits: Per joint coordinate [N m or N] (inf: none), (n,).
        notes: What the export had to decide (estimated links, adjusted
            inertias), one sentence each.
        timestep: The physics time step [s].
        moments: Each actuator's moment arm over the MuJoCo joints of
            ``joints.names``, (n_actuators, J) (a motor's row: ``A^+ W``).
    """

    xml: str
    robot: Robot
    joints: JointMap
    links: ResolvedLinks
    actuators: ActuatorSpace
    actuator_names: tuple[str, ...]
    kp: F64
    kv: F64
    ctrl_offset: F64
    gravity_compensation: bool
    velocity_feedforward: bool
    torque_limits: F64
    notes: tuple[str, ...]
    timestep: float
    moments: F64


# ------------------------------------------------------------------------ mass
def _consistent(link: LinkInertia) -> tuple[LinkInertia, str]:
    """The link with principal moments that satisfy ``A + B >= C`` (MuJoCo's rule).

    The smaller moments grow by half the shortfall each, which keeps the largest
    (a link turning about one axis keeps its inertia about it). Returns the link
    and a note ("" when nothing changed).
    """
    w, V = np.linalg.eigh(link.inertia)
    w = np.maximum(w, 0.0)
    order = np.argsort(w)
    a, b, c = w[order]
    if a + b >= c * (1 - 1e-12):
        return link, ""
    gap = (c - a - b) / 2.0
    w2 = w.copy()
    w2[order[0]] += gap
    w2[order[1]] += gap
    fixed = LinkInertia(link.mass, link.com, V @ np.diag(w2) @ V.T)
    return fixed, (f"principal moments {np.round(w, 9).tolist()} kg m^2 violate "
                   f"A + B >= C; raised to {np.round(w2, 9).tolist()}")


def check_link_inertia(link: LinkInertia, name: str, file: object = None) -> None:
    """Refuse mass properties no rigid body has, before MuJoCo sees them.

    Args:
        link: The link's mass properties.
        name: The link (as in ``dynamics.links``), for the message.
        file: The robot file, for the message.

    Raises:
        ModelError: a mass above :data:`MAX_LINK_MASS`, a principal moment above
            :data:`MAX_LINK_INERTIA`, or (for a link with mass) principal moments
            that break ``A + B >= C`` by more than :data:`TRIANGLE_SLACK`, naming
            the file and ``dynamics.links.<link>.mass`` / ``.inertia``.
    """
    field = f"dynamics.links.{name}"
    if link.mass > MAX_LINK_MASS:
        raise ModelError(f"a mass of {link.mass:g} kg, more than the {MAX_LINK_MASS:g} kg "
                         "the MJCF export accepts (robokin.sim.mjcf.MAX_LINK_MASS)",
                         file=file, field=f"{field}.mass")
    w = np.sort(np.maximum(np.linalg.eigvalsh(link.inertia), 0.0))
    if w[2] > MAX_LINK_INERTIA:
        raise ModelError(f"a principal moment of {w[2]:g} kg m^2, more than the "
                         f"{MAX_LINK_INERTIA:g} kg m^2 the MJCF export accepts "
                         "(robokin.sim.mjcf.MAX_LINK_INERTIA)", file=file,
                         field=f"{field}.inertia")
    if link.mass > 0.0 and w[2] > (1.0 + TRIANGLE_SLACK) * (w[0] + w[1]):
        over = f"{w[2] / (w[0] + w[1]) - 1:.0%}" if w[0] + w[1] > 0 else "all of C"
        raise ModelError(f"principal moments {np.round(w, 9).tolist()} kg m^2 break the "
                         f"triangle inequality A + B >= C (by {over}; up to "
                         f"{TRIANGLE_SLACK:.0%} is balanced with a note): no rigid body "
                         "has them; check the tensor's entries and units",
                         file=file, field=f"{field}.inertia")


def _inertial(body: ET.Element, name: str, link: LinkInertia | None, has_joint: bool,
              notes: list[str], file: object = None) -> None:
    if link is not None:
        check_link_inertia(link, name, file)
    if link is None or link.mass <= 0.0:
        if not has_joint:  # a welded body may be massless
            return
        had = "" if link is None else f" (its data: mass {link.mass:g} kg)"
        notes.append(f"link {name!r} has no mass{had}: modelled with "
                     f"{_TINY_MASS:g} kg so MuJoCo accepts it")
        com = np.zeros(3) if link is None else link.com
        tensor = np.eye(3) * _TINY_INERTIA if link is None else link.inertia
        link = LinkInertia(_TINY_MASS, com, tensor + np.eye(3) * _TINY_INERTIA)
    fixed, note = _consistent(link)
    if note:
        notes.append(f"link {name!r}: {note}")
    I = fixed.moments
    if np.all(I[:3] <= 0.0):
        I = np.array([_TINY_INERTIA] * 3 + [0.0] * 3)
    ET.SubElement(body, "inertial", {"pos": _vec(fixed.com), "mass": _fmt(fixed.mass),
                                     "fullinertia": _vec(I)})


# ----------------------------------------------------------------------- export
def _check_space(actuators: Any, robot: Robot) -> ActuatorSpace:
    if actuators not in ("joint", "motor"):
        raise InputError("actuators", f"expected 'joint' or 'motor', got "
                         f"{short_repr(actuators)}")
    if actuators == "motor" and robot.actuators is None:
        raise InputError("actuators", f"{robot.name} has no actuator map (motors); "
                         "use actuators='joint'")
    return "motor" if actuators == "motor" else "joint"


def _torque_limits(robot: Robot, torque_limits: npt.ArrayLike | None) -> F64:
    n = robot.n
    if torque_limits is None:
        dyn_lim = getattr(robot.dynamics, "torque_limits", None)
        return (np.full(n, math.inf) if dyn_lim is None
                else np.array(dyn_lim, dtype=float))
    try:
        lim = np.array(torque_limits, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise InputError("torque_limits", f"expected {n} numbers, got "
                         f"{short_repr(torque_limits)}") from None
    if lim.shape != (n,) or np.isnan(lim).any() or (lim <= 0).any():
        raise InputError("torque_limits", f"expected {n} values > 0 [N m or N] (inf: "
                         f"none), got {lim.tolist()}")
    return lim


class _Writer:
    """Builds the MJCF tree of one robot (and scene)."""

    def __init__(self, robot: Robot, scene: Scene | None, links: ResolvedLinks,
                 timestep: float, gravity_compensation: bool,
                 torque_limits: F64, contact_forces: bool) -> None:
        self.robot, self.scene, self.links = robot, scene, links
        self.notes: list[str] = []
        self.root = ET.Element("mujoco", {"model": robot.name})
        self.root.append(ET.Comment(
            f" written by robokin from '{robot.name}': bodies are the link frames of "
            "robot.fk_all; see docs/simulation.md ".replace("--", "-")))
        ET.SubElement(self.root, "compiler", {"angle": "radian", "autolimits": "true",
                                              "inertiafromgeom": "false"})
        # implicit in the servos' damping: stable for stiff, coupled servos (the
        # force it applies is qfrc_actuator - dt D a, see robokin.sim.simulate)
        opt = ET.SubElement(self.root, "option", {"timestep": _fmt(timestep),
                                                  "integrator": "implicitfast"})
        flags = {"filterparent": "disable"}
        if not contact_forces:
            flags["contact"] = "disable"
        ET.SubElement(opt, "flag", flags)
        self.asset = ET.SubElement(self.root, "asset")
        self.world = ET.SubElement(self.root, "worldbody")
        self.gravcomp = gravity_compensation
        self.torque_limits = torque_limits
        self.joint_names: list[str] = []
        self.joint_rows: list[F64] = []
        self.dependent: list[tuple[str, F64]] = []  # (joint, its row)

    @classmethod
    def bodies(cls, robot: Robot, scene: Scene | None, links: ResolvedLinks,
               timestep: float, gravity_compensation: bool, torque_limits: F64,
               contact_forces: bool) -> _Writer:
        """A writer with the robot's and the scene's bodies, contacts and equalities."""
        writer = cls(robot, scene, links, timestep, gravity_compensation, torque_limits,
                     contact_forces)
        writer.robot_tree()
        writer.scene_bodies()
        writer.contact_filter()
        writer.equality(timestep)
        return writer

    # -- bodies
    def _body(self, parent: ET.Element, name: str, T: np.ndarray, k: int,
              moving: bool, has_joint: bool) -> ET.Element:
        attrs = {"name": name, **_pose_attrs(T)}
        if moving and self.gravcomp:
            attrs["gravcomp"] = "1"
        body = ET.SubElement(parent, "body", attrs)
        _inertial(body, name, self.links.links[k], has_joint, self.notes,
                  self.robot.path)
        geo = self.robot.geometry
        if geo is not None and hasattr(geo, "shapes"):
            for s_i, shape in enumerate(geo.shapes[k]):
                _geom(body, self.asset, shape, f"{name}/{s_i}", _ROBOT_RGBA)
        return body

    def _joint(self, body: ET.Element, name: str, kind: str, F: np.ndarray,
               axis_sign: float, row: F64, master: int | None,
               armature: float = 0.0) -> None:
        inv = invert(F)  # the joint's axis and origin in its body: F^-1 z, F^-1 origin
        attrs = {"name": name, "type": "hinge" if kind == "revolute" else "slide",
                 "axis": _vec(axis_sign * inv[:3, 2])}
        if armature:
            attrs["armature"] = _fmt(armature)
        pos = inv[:3, 3]
        if kind == "revolute" and np.any(pos != 0.0):
            attrs["pos"] = _vec(pos)
        if master is not None:
            lo, hi = self.robot.limits[master]
            if math.isfinite(lo) and math.isfinite(hi):
                attrs["range"] = _vec([lo, hi])
            lim = self.torque_limits[master]
            if math.isfinite(lim):
                attrs["actuatorfrcrange"] = _vec([-lim, lim])
        if self.gravcomp:
            attrs["actuatorgravcomp"] = "true"
        ET.SubElement(body, "joint", attrs)
        self.joint_names.append(name)
        self.joint_rows.append(row)
        if master is None:
            self.dependent.append((name, row))

    def robot_tree(self) -> None:
        robot = self.robot
        chain = robot.chain
        parts, leaves = _parts(robot)
        c = chain.arrays.c
        base = self._body(self.world, "base", np.asarray(chain.base), 0, moving=False,
                          has_joint=False)
        parent, pending = base, np.asarray(chain.head)
        names = [j.name for j in chain.joints]
        for k, joint in enumerate(chain.joints):
            F = np.asarray(chain.frame_offsets[k])
            const = joint.sign * c[k] + joint.offset
            T = pending @ joint_motion(joint.kind, const) @ F
            part = parts[k]
            body = self._body(parent, names[k], T, k + 1, moving=True,
                              has_joint=part is not None)
            if part is not None:
                self._joint(body, part.name, joint.kind, F, part.axis_sign, part.row,
                            part.master)
            parent, pending = body, np.asarray(chain.link_offsets[k])
        tool = self._body(parent, "tool", pending @ np.asarray(chain.tool),
                          chain.n_chain + 1, moving=True, has_joint=False)
        ET.SubElement(tool, "site", {"name": "tool", "size": "0.005"})
        for i in leaves:
            self._leaf(base, i)

    def _leaf(self, base: ET.Element, i: int) -> None:
        """A coordinate with no joint of its own: a joint on a light leaf body."""
        name = self.robot.joint_names[i]
        kind = "revolute" if self.robot.is_revolute[i] else "prismatic"
        body = ET.SubElement(base, "body", {"name": f"{name}_coordinate"})
        ET.SubElement(body, "inertial", {"pos": "0 0 0", "mass": _fmt(_TINY_MASS),
                                         "diaginertia": _vec([_TINY_INERTIA] * 3)})
        row = np.zeros(self.robot.n)
        row[i] = 1.0
        self._joint(body, name, kind, np.eye(4), 1.0, row, i, armature=_ARMATURE)
        self.notes.append(f"coordinate {name!r} drives no chain joint with "
                          "coefficient +-1: it has its own joint on a massless leaf body")

    def scene_bodies(self) -> None:
        scene = self.scene
        if scene is None:
            return
        taken = set(self.robot_link_names())
        for obj in scene.objects:
            if obj.name in taken:
                raise ModelError(f"scene object {obj.name!r} has the name of a robot "
                                 "link; rename it", field="scene.objects")
            body = ET.SubElement(self.world, "body", {"name": obj.name})
            _geom(body, self.asset, obj.shape, obj.name, _SCENE_RGBA)

    def robot_link_names(self) -> tuple[str, ...]:
        from robokin.model.geometry import link_names

        return link_names(self.robot)

    # -- contacts, constraints, actuators
    def contact_filter(self) -> None:
        from robokin.model.geometry import RobotGeometry

        geo = self.robot.geometry
        names = self.robot_link_names()
        if not isinstance(geo, RobotGeometry):
            geo = RobotGeometry.empty(self.robot)
        with_shapes = [k for k, ss in enumerate(geo.shapes) if ss]
        checked = set(geo.self_pairs())
        contact = ET.SubElement(self.root, "contact")
        for a_i, a in enumerate(with_shapes):
            for b in with_shapes[a_i + 1:]:
                if (a, b) not in checked:
                    ET.SubElement(contact, "exclude", {"body1": names[a],
                                                       "body2": names[b]})
        if self.scene is not None:
            for pair in sorted(sorted(p) for p in self.scene.excluded_pairs(self.robot)):
                link = [x for x in pair if x in names]
                obj = [x for x in pair if x in self.scene.names]
                if link and obj:
                    ET.SubElement(contact, "exclude", {"body1": link[0],
                                                       "body2": obj[0]})

    def equality(self, timestep: float) -> None:
        """Tie every dependent joint to the coordinates' joints: ``x_k = M_k q``."""
        if not self.dependent:
            return
        masters = self.robot.joint_names
        soft = {"solref": _vec([2 * timestep, 1.0]), "solimp": "0.99 0.999 0.001"}
        tendons: list[tuple[str, list[tuple[str, float]]]] = []
        eq = ET.Element("equality")
        for name, row in self.dependent:
            nz = np.flatnonzero(row)
            if len(nz) == 1:
                ET.SubElement(eq, "joint", {
                    "joint1": name, "joint2": masters[nz[0]],
                    "polycoef": _vec([0, row[nz[0]], 0, 0, 0]), **soft})
                continue
            tname = f"{name}_coupling"
            tendons.append((tname, [(name, 1.0)]
                            + [(masters[i], -float(row[i])) for i in nz]))
            ET.SubElement(eq, "tendon", {"tendon1": tname, **soft})
        if tendons:
            tendon = ET.SubElement(self.root, "tendon")
            for tname, terms in tendons:
                fixed = ET.SubElement(tendon, "fixed", {"name": tname})
                for jname, coef in terms:
                    ET.SubElement(fixed, "joint", {"joint": jname, "coef": _fmt(coef)})
        self.root.append(eq)

    def actuators(self, space: ActuatorSpace, kp: F64, kv: F64, weights: F64) -> F64:
        """Servos on the coordinates (or motors), through tendons where needed.

        ``weights`` (n, J): the tendon of coordinate i is ``sum_j weights[i, j] x_j``
        (its length is q_i). A coordinate that moves one joint acts on it directly.
        Returns each actuator's moment arms over the joints, (n_actuators, J).
        """
        robot = self.robot
        if space == "motor":
            amap = robot.actuators
            assert amap is not None
            coefs = amap.pseudo_inverse(what="actuator") @ weights  # (m, J)
            names = list(robot.actuator_names or ())
        else:
            coefs = weights
            names = list(robot.joint_names)
        direct = [space == "joint" and np.count_nonzero(row) == 1 for row in coefs]
        if not all(direct):
            found = self.root.find("tendon")
            tendon = found if found is not None else ET.SubElement(self.root, "tendon")
            for r, name in enumerate(names):
                if direct[r]:
                    continue
                fixed = ET.SubElement(tendon, "fixed", {"name": name})
                for j, jname in enumerate(self.joint_names):
                    if coefs[r, j] != 0.0:
                        ET.SubElement(fixed, "joint", {"joint": jname,
                                                       "coef": _fmt(coefs[r, j])})
        act = ET.SubElement(self.root, "actuator")
        for r, name in enumerate(names):
            target = ({"joint": self.joint_names[int(np.flatnonzero(coefs[r])[0])]}
                      if direct[r] else {"tendon": name})
            attrs = {"name": name, **target,
                     "gaintype": "fixed", "biastype": "affine",
                     "gainprm": _fmt(kp[r]), "biasprm": _vec([0.0, -kp[r], -kv[r]])}
            ET.SubElement(act, "general", attrs)
        return np.array(coefs, dtype=np.float64)

    def text(self) -> str:
        if not len(self.asset):
            self.root.remove(self.asset)
        ET.indent(self.root, space="  ")
        return ET.tostring(self.root, encoding="unicode") + "\n"


def default_reference(robot: Robot) -> F64:
    """The configuration default gains are tuned at: zero, clipped into the limits."""
    lo, hi = robot.limits[:, 0], robot.limits[:, 1]
    return np.clip(np.zeros(robot.n), lo, hi)


def build_mjcf(
    robot: Robot,
    scene: Scene | None = None,
    *,
    actuators: ActuatorSpace = "joint",
    gains: Any = None,
    torque_limits: npt.ArrayLike | None = None,
    strict: bool = False,
    density: float | None = None,
    timestep: float = MJCF_TIMESTEP,
    contact_forces: bool = True,
    q_ref: npt.ArrayLike | None = None,
) -> MjcfExport:
    """Build the MuJoCo model of a robot (and scene): the text and its bookkeeping.

    Args:
        robot: Any robokin robot.
        scene: A :class:`~robokin.collision.Scene`: the robot is placed in it
            (base, tool, tool shapes) and its objects become static bodies.
        actuators: ``"joint"``: a servo per joint coordinate; ``"motor"``: a
            servo per motor of the robot's actuator map.
        gains: Servo gains (:func:`~robokin.sim.servo.servo_gains`: None, a
            :class:`~robokin.sim.servo.ServoGains` or a mapping of its fields).
        torque_limits: Per joint coordinate [N m or N] (inf: none); default the
            robot's ``dynamics.torque_limits``.
        strict: Refuse to estimate missing link mass data (ModelError).
        density: Density for estimated links [kg/m^3] (default: the robot's, else
            :data:`~robokin.model.dynamics.DEFAULT_DENSITY`).
        timestep: Physics step [s], > 0; divided (at most
            :data:`~robokin.sim._mjcf_tuning.MAX_SUBSTEPS` times) when stiff servos need it (the export's
            ``timestep`` and notes say so).
        contact_forces: False: contacts exert no force (MuJoCo's contact
            detection is off in the model; :func:`robokin.sim.simulate` then
            detects them separately).
        q_ref: Configuration(s) (n,) or (k, n) the default gains are tuned at
            (the effective inertia is averaged over them); default
            :func:`default_reference`.

    Returns:
        An :class:`MjcfExport`.

    Raises:
        InputError: a bad ``actuators``, ``gains``, ``torque_limits``, ``timestep``
            or ``q_ref``.
        ModelError: missing mass data in strict mode (naming
            ``dynamics.links.<link>``), a scene object named like a robot link,
            or a model MuJoCo refuses.
        MissingExtraError: MuJoCo (``robokin[sim]``) or trimesh is not installed.
    """
    space = _check_space(actuators, robot)
    servo = servo_gains(gains)
    if not (isinstance(timestep, int | float) and math.isfinite(timestep)
            and 0 < timestep <= 0.01):
        raise InputError("timestep", f"expected a step in (0, 0.01] s, got "
                         f"{short_repr(timestep)}")
    placed = scene.attach(robot) if scene is not None else robot
    limits = _torque_limits(placed, torque_limits)
    links = resolve_links(placed, strict=strict, density=density)
    writer = _Writer.bodies(placed, scene, links, float(timestep),
                            servo.gravity_compensation, limits, contact_forces)
    joints = JointMap(tuple(writer.joint_names), np.array(writer.joint_rows),
                      tuple(placed.joint_names))
    A = placed.actuators.matrix if space == "motor" and placed.actuators else None
    ref = default_reference(placed) if q_ref is None else _check_q_ref(q_ref, placed.n)
    inertia, weights, mats = _effective_inertia(writer.text(), joints, ref, A)
    kp, kv = servo.resolve(inertia)
    step, note = _stable_step(kp, mats, float(timestep), names_for(placed, space))
    ctrl_offset = np.zeros(placed.n)
    names = names_for(placed, space)
    if space == "motor" and placed.actuators is not None:
        P = placed.actuators.pseudo_inverse(what="actuator")
        ctrl_offset = P @ placed.actuators.offset
    # the text is rebuilt with actuators (ElementTree elements are not reusable
    # after text(): a fresh writer keeps the two passes independent)
    writer = _Writer.bodies(placed, scene, links, step, servo.gravity_compensation,
                            limits, contact_forces)
    moments = writer.actuators(space, kp, kv, weights)
    xml = writer.text()
    notes = [f"mass properties: {links.describe()}"] + writer.notes + ([note] if note
                                                                        else [])
    return MjcfExport(xml, placed, joints, links, space, names, kp, kv, ctrl_offset,
                      servo.gravity_compensation, servo.velocity_feedforward, limits,
                      tuple(notes), step, moments)


def names_for(robot: Robot, space: ActuatorSpace) -> tuple[str, ...]:
    """The actuators' names: the joint names, or the motor names."""
    return tuple(robot.actuator_names or ()) if space == "motor" \
        else tuple(robot.joint_names)


def to_mjcf(robot: Robot, scene: Scene | None = None, **options: Any) -> str:
    """The MJCF text of a robot (and scene): same FK, joints named as ``robot.joint_names``.

    Bodies are the link frames of ``robot.fk_all``; the site ``tool`` sits at
    the tool frame. See :func:`build_mjcf` for the options and the module
    docstring for the rules.

    Args:
        robot: Any robokin robot.
        scene: Optional scene (robot placement, tool, static objects).
        **options: Keyword options of :func:`build_mjcf`.

    Returns:
        MJCF XML text.
    """
    return build_mjcf(robot, scene, **options).xml


def write_mjcf(robot: Robot, path: Any, scene: Scene | None = None,
               **options: Any) -> Any:
    """Write :func:`to_mjcf` atomically to ``path``; returns the path.

    Raises:
        InputError: the folder is missing or read-only, or ``path`` is a folder.
    """
    from robokin.io.atomic import write_atomic

    return write_atomic(path, to_mjcf(robot, scene, **options))
