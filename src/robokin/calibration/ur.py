"""Universal Robots' factory calibration as a robokin robot.

Every UR arm leaves the factory with its own kinematics: the controller's
``calibration.conf`` holds DH *deltas* added to the type's published standard DH
table (``[mounting]`` section: ``delta_theta``, ``delta_a``, ``delta_d``,
``delta_alpha``, six values each, metres and radians), and the primary interface
reports the summed table (``dh_theta``, ``dh_a``, ``dh_d``, ``dh_alpha``), which
``ur_calibration`` (ur_robot_driver) logs before writing its kinematics YAML.

On the parallel joints 2-4 these tables carry ``d`` values of hundreds of metres:
the calibrated axes are a fraction of a milliradian from parallel, so their
common normals lie far away. The forward kinematics is right, but a URDF that puts
those DH frames into joint origins places the links metres from the robot
(ros-industrial/universal_robot#357: an 11.7 m offset;
Universal_Robots_ROS_Driver ``ur_calibration`` "corrects" the chain for that).
Here the exact DH product is re-expressed with every joint frame on its
calibrated axis nearest the nominal robot's (:func:`~robokin.calibration._frames.reframe`):
the same forward kinematics, link origins within millimetres of the nominal
ones, so ``robot.to_urdf()`` and robot files stay physical.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from robokin.calibration._frames import frames_at_zero, reframe
from robokin.exceptions import InputError, ModelError

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["UR_DH", "load_ur_calibration", "ur_nominal"]

#: Published standard DH tables of Universal Robots arms (Universal Robots,
#: "DH parameters for calculations of kinematics and dynamics"): d1, a2, a3, d4,
#: d5, d6 [m]; alpha = (pi/2, 0, 0, pi/2, -pi/2, 0), theta = 0.
UR_DH: dict[str, tuple[float, float, float, float, float, float]] = {
    "ur3": (0.1519, -0.24365, -0.21325, 0.11235, 0.08535, 0.0819),
    "ur5": (0.089159, -0.425, -0.39225, 0.10915, 0.09465, 0.0823),
    "ur10": (0.1273, -0.612, -0.5723, 0.163941, 0.1157, 0.0922),
    "ur3e": (0.15185, -0.24355, -0.2132, 0.13105, 0.08535, 0.0921),
    "ur5e": (0.1625, -0.425, -0.3922, 0.1333, 0.0997, 0.0996),
    "ur10e": (0.1807, -0.6127, -0.57155, 0.17415, 0.11985, 0.11655),
    "ur16e": (0.1807, -0.4784, -0.36, 0.17415, 0.11985, 0.11655),
}
_NAMES = ("shoulder_pan", "shoulder_lift", "elbow", "wrist_1", "wrist_2", "wrist_3")
_KEYS = ("theta", "a", "d", "alpha")
#: Largest calibration file read [bytes].
MAX_BYTES = 1 << 20
#: How far a calibrated link origin may lie from the nominal one [m] before the
#: deltas are judged not to belong to the nominal type.
MAX_SHIFT = 0.05


def _rows(d1: float, a2: float, a3: float, d4: float, d5: float, d6: float
          ) -> list[dict[str, float]]:
    h = math.pi / 2
    return [{"theta": 0.0, "a": 0.0, "d": d1, "alpha": h},
            {"theta": 0.0, "a": a2, "d": 0.0, "alpha": 0.0},
            {"theta": 0.0, "a": a3, "d": 0.0, "alpha": 0.0},
            {"theta": 0.0, "a": 0.0, "d": d4, "alpha": h},
            {"theta": 0.0, "a": 0.0, "d": d5, "alpha": -h},
            {"theta": 0.0, "a": 0.0, "d": d6, "alpha": 0.0}]


def ur_nominal(kind: str) -> Robot:
    """The nominal robot of a UR type (``"ur3"`` ... ``"ur16e"``, :data:`UR_DH`)."""
    from robokin.robot import Robot

    if kind not in UR_DH:
        raise InputError("nominal", f"unknown UR type {kind!r}; known: {sorted(UR_DH)}")
    rows = [{**r, "name": n, "limits": [-2 * math.pi, 2 * math.pi]}
            for r, n in zip(_rows(*UR_DH[kind]), _NAMES)]
    return Robot.from_dh(rows, name=kind)


def _nominal_rows(robot: Robot) -> list[dict[str, float]]:
    """The standard DH rows of a nominal 6R robot without base or tool remainders."""
    from robokin.io.dh_extract import dh_from_robot

    if robot.n_chain != 6 or not robot.is_revolute.all():
        raise InputError("nominal", f"a UR arm has 6 revolute joints; {robot.name!r} "
                         f"has {robot.n_chain} chain joints")
    ext = dh_from_robot(robot)
    if ext.needs_virtual_frames:
        raise InputError("nominal", f"{robot.name!r} is not a plain standard DH table "
                         "(it has a base or tool transform): give the UR type name")
    return [{k: float(r[k]) for k in _KEYS} for r in ext.rows]


def _parse(text: str, file: Path) -> dict[str, list[float]]:
    """``{"delta_theta": [...], ...}`` or ``{"dh_theta": [...], ...}`` from the text."""
    found: dict[str, list[float]] = {}
    for m in re.finditer(r"\b((?:delta|dh)_(?:theta|alpha|a|d))\s*[:=]\s*\[([^\]]*)\]",
                         text):
        key, body = m.group(1), m.group(2)
        if key in found:
            raise ModelError(f"'{key}' is given twice", file=file, field=key)
        try:
            values = [float(v) for v in re.split(r"[,\s]+", body.strip()) if v]
        except ValueError:
            raise ModelError(f"'{key}' must hold numbers, got [{body.strip()[:80]}]",
                             file=file, field=key) from None
        if len(values) != 6 or not all(math.isfinite(v) for v in values):
            raise ModelError(f"'{key}' must hold 6 finite numbers (one per joint), got "
                             f"{len(values)}", file=file, field=key)
        found[key] = values
    for prefix in ("delta", "dh"):
        keys = [f"{prefix}_{k}" for k in _KEYS]
        if all(k in found for k in keys):
            return {k: found[k] for k in keys}
    have = sorted(found)
    raise ModelError("expected delta_theta, delta_a, delta_d and delta_alpha (a "
                     "calibration.conf) or dh_theta, dh_a, dh_d and dh_alpha (the "
                     f"calibrated table); found {have or 'none of them'}", file=file)


def load_ur_calibration(path: str | Path, nominal: str | Robot = "ur5") -> Robot:
    """A UR arm with its factory calibration, link frames kept physical.

    Args:
        path: The controller's ``calibration.conf`` (DH deltas in its
            ``[mounting]`` section) or a file with the calibrated table
            ``dh_theta: [...]`` etc. (metres, radians; lists of 6).
        nominal: The UR type (``"ur5"``, ``"ur5e"``, ... :data:`UR_DH`) or a
            nominal robot whose standard DH table the deltas apply to (its
            limits, geometry and names are kept).

    Returns:
        A robot whose forward kinematics is the calibrated DH product
        ``prod Rz(theta + dtheta + q) Tz(d + dd) Tx(a + da) Rx(alpha + dalpha)``
        exactly, and whose link frames lie on the calibrated axes nearest the
        nominal ones.

    Raises:
        ModelError: the file is missing, too large, or lacks the four tables
            (named).
        InputError: an unknown type, or deltas that move a link origin more than
            :data:`MAX_SHIFT` from the nominal one (the wrong type).
    """
    from robokin.io.text_files import read_text_file
    from robokin.robot import Robot

    file = Path(path)
    text = read_text_file(file, max_bytes=MAX_BYTES)
    tables = _parse(text, file)
    base_robot = ur_nominal(nominal) if isinstance(nominal, str) else nominal
    nom = _nominal_rows(base_robot)
    if "delta_theta" in tables:
        full = {k: [r[k] + dv for r, dv in zip(nom, tables[f"delta_{k}"])] for k in _KEYS}
    else:
        full = {k: tables[f"dh_{k}"] for k in _KEYS}
    rows = [{"theta": full["theta"][i], "a": full["a"][i], "d": full["d"][i],
             "alpha": full["alpha"][i], "name": j.name, "limits": list(j.limits)}
            for i, j in enumerate(base_robot.chain.joints)]
    exact = Robot.from_dh(rows, base=base_robot.base, tool=base_robot.tool)
    chain = reframe(exact.chain, base_robot.chain)
    shift = np.linalg.norm(frames_at_zero(chain)[0][:, :3, 3]
                           - frames_at_zero(base_robot.chain)[0][:, :3, 3], axis=1)
    if shift.max() > MAX_SHIFT:
        k = int(np.argmax(shift))
        raise InputError("nominal", f"the calibration moves joint {k + 1}'s axis "
                         f"{shift[k]:.3f} m from the nominal {base_robot.name!r}: the "
                         f"deltas belong to another type (known: {sorted(UR_DH)})")
    return base_robot.replace(chain=chain, name=f"{base_robot.name}_calibrated",
                              source=f"{base_robot.source} + factory calibration "
                              f"{file.name}".strip(" +"), meta={})
