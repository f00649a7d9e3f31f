"""The pieces of the MJCF text: numbers, poses, joints and geoms.

Number formatting, pose attributes, the MuJoCo joint of each chain joint
(:func:`_parts`) and the geoms of shapes (:func:`_geom`).

Used by :mod:`robokin.sim.mjcf`, which writes the model.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any
from xml.etree import ElementTree as ET

import numpy as np
import numpy.typing as npt

from robokin.spatial import quaternion_from_matrix

if TYPE_CHECKING:
    from robokin.model.geometry import Shape
    from robokin.robot import Robot

F64 = npt.NDArray[np.float64]


def _fmt(v: float) -> str:
    v = float(v)
    return "0" if v == 0.0 else repr(v)


def _vec(values: Any) -> str:
    return " ".join(_fmt(v) for v in np.asarray(values, dtype=float).reshape(-1))


def _pose_attrs(T: np.ndarray) -> dict[str, str]:
    """``pos`` and ``quat`` (w x y z) attributes of a pose, identity parts left out."""
    out = {}
    if np.any(T[:3, 3] != 0.0):
        out["pos"] = _vec(T[:3, 3])
    if not np.array_equal(T[:3, :3], np.eye(3)):
        out["quat"] = _vec(quaternion_from_matrix(T))
    return out


# ----------------------------------------------------------------------- layout
@dataclass
class _Part:
    """The MuJoCo joint of one chain joint."""

    name: str
    row: F64  # its value per unit of each coordinate (n,)
    axis_sign: float  # the joint turns the body by axis_sign * value about F^-1 z
    master: int | None  # the coordinate whose joint it is, or None (dependent)


def _masters(M: np.ndarray) -> dict[int, tuple[int, float]]:
    """Per coordinate, the chain joint that is its joint (one +-1 entry), and the sign."""
    out: dict[int, tuple[int, float]] = {}
    taken: set[int] = set()
    for k in range(M.shape[0]):
        nz = np.flatnonzero(M[k])
        if len(nz) == 1 and abs(M[k, nz[0]]) == 1.0 and int(nz[0]) not in out \
                and k not in taken:
            out[int(nz[0])] = (k, float(M[k, nz[0]]))
            taken.add(k)
    return out


def _parts(robot: Robot) -> tuple[list[_Part | None], list[int]]:
    """Per chain joint its MuJoCo joint, and the coordinates that need a leaf body.

    A constant chain joint (driven by no coordinate) has no joint (None).
    """
    chain = robot.chain
    M = chain.arrays.M
    cnames = list(robot.joint_names)
    masters = _masters(M)
    master_of = {k: (i, m) for i, (k, m) in masters.items()}
    used = set(cnames)
    out: list[_Part | None] = []
    for k, joint in enumerate(chain.joints):
        if not M[k].any():
            out.append(None)
            continue
        if k in master_of:
            i, m = master_of[k]
            row = np.zeros(len(cnames))
            row[i] = 1.0
            out.append(_Part(cnames[i], row, joint.sign * m, i))
            continue
        name, j = joint.name, 2
        while name in used:
            name, j = f"{joint.name}_{j}", j + 1
        used.add(name)
        out.append(_Part(name, np.array(M[k], dtype=np.float64), joint.sign, None))
    leaves = [i for i in range(len(cnames)) if i not in masters]
    return out, leaves


# ------------------------------------------------------------------------ geoms
def _mesh_asset(asset: ET.Element, shape: Shape, name: str) -> None:
    """The convex hull of a mesh shape, inline (MuJoCo collides convex hulls)."""
    hull = shape.trimesh().convex_hull
    ET.SubElement(asset, "mesh", {
        "name": name,
        "vertex": _vec(np.asarray(hull.vertices)),
        "face": " ".join(str(int(v)) for v in np.asarray(hull.faces).reshape(-1)),
    })


def _geom(parent: ET.Element, asset: ET.Element, shape: Shape, name: str,
          rgba: str, pose: np.ndarray | None = None) -> None:
    P = np.asarray(shape.placement if pose is None else pose, dtype=float)
    attrs: dict[str, str] = {"name": name, "rgba": rgba}
    k, s = shape.kind, shape.size
    if k == "box":
        attrs.update(type="box", size=_vec(np.array(s) / 2))
    elif k == "sphere":
        attrs.update(type="sphere", size=_vec(s[:1]))
    elif k == "cylinder":
        attrs.update(type="cylinder", size=_vec([s[0], s[1] / 2]))
    elif k == "capsule":
        if s[1] > 0:
            attrs.update(type="capsule", size=_vec([s[0], s[1] / 2]))
        else:
            attrs.update(type="sphere", size=_vec(s[:1]))
    else:
        mesh_name = f"mesh_{name}"
        _mesh_asset(asset, shape, mesh_name)
        attrs.update(type="mesh", mesh=mesh_name)
    attrs.update(_pose_attrs(P))
    ET.SubElement(parent, "geom", attrs)
