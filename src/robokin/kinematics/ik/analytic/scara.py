"""SCARA arms: three revolute joints and one prismatic joint, all axes parallel.

Translations along the common axis ``h`` commute with rotations about lines
parallel to it, so the prismatic joint may sit anywhere in the chain:

* the tool yaw ``psi`` (rotation about ``h`` of ``R_T R_M^T``) is the signed sum of
  the three angles; a target that tilts the tool is 'orientation not achievable';
* the height along ``h`` gives the stroke directly;
* the planar two-link problem gives both elbows (subproblem 3), then the shoulder
  (subproblem 1), and the last angle from the yaw.

Branch label ``elbow``: +1 when the forearm turns counter-clockwise about ``h``
from the upper arm (a right-handed arm seen along ``-h``), -1 otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from robokin.kinematics.ik.analytic._common import fit_turns, fk_error, make_set
from robokin.kinematics.ik.analytic._geometry import (
    Poe,
    angle_between_axes,
    rotate_about,
    subproblem_1,
    subproblem_3,
    unit_perpendicular,
)

if TYPE_CHECKING:
    from robokin.kinematics.arm import Arm
    from robokin.kinematics.ik.solutions import SolutionSet

__all__ = ["measure"]

NAME = "scara"


def measure(poe: Poe) -> tuple[float, float, str, str]:
    """Deviation from the family: (angle [rad], 0, text, why-not)."""
    h = poe.h
    ang = max(angle_between_axes(h[0], h[k]) for k in range(1, 4))
    text = f"all 4 axes parallel within {ang:.1e} rad"
    why = ""
    if int(poe.prismatic.sum()) != 1:
        why = f"needs 3 revolute joints and 1 prismatic, got {int(poe.prismatic.sum())} prismatic"
    return ang, 0.0, text, why


@dataclass(frozen=True, eq=False)
class ScaraGeometry:
    """The nominal SCARA read from a chain (base frame, zero chain values)."""

    h: np.ndarray
    e: np.ndarray
    rev: tuple[int, ...]  # the three revolute coordinates
    pri: int
    s: np.ndarray
    o: np.ndarray
    M: np.ndarray


def geometry(poe: Poe) -> ScaraGeometry:
    """Snap every axis onto the first one's direction."""
    h = poe.h[0]
    s = np.sign(poe.h @ h)
    rev = tuple(int(i) for i in np.flatnonzero(~poe.prismatic))
    pri = int(np.flatnonzero(poe.prismatic)[0])
    return ScaraGeometry(h, unit_perpendicular(h), rev, pri, s, poe.o, poe.M)


def solve_geometry(robot: Arm, g: ScaraGeometry, T: np.ndarray, *,
                   orientation_tol: float = 1e-9, compute_error: bool = False,
                   method: str = "analytic:scara",
                   info: dict[str, Any] | None = None) -> SolutionSet:
    """Every solution (up to 2) for poses T (..., 4, 4)."""
    chain = robot.chain
    T = np.asarray(T, dtype=np.float64)
    lead = T.shape[:-2]
    h, e = g.h, g.e
    Rrel = T[..., :3, :3] @ g.M[:3, :3].T
    hr = Rrel @ h
    tilt = np.arctan2(np.linalg.norm(np.cross(hr, h), axis=-1), hr @ h)
    f = Rrel @ e
    psi = np.arctan2(np.cross(e, f) @ h, f @ e)
    a_, b_, c_ = g.rev
    o, s = g.o, g.s
    t = g.M[:3, 3]
    p = T[..., :3, 3]
    w = p - o[a_] - rotate_about(h, psi, t - o[c_])
    hp = s[g.pri] * h
    vp = (w @ h - h @ (o[c_] - o[a_])) / (h @ hp)
    d = w - vp[..., None] * hp
    a = o[b_] - o[a_]
    b = o[c_] - o[b_]
    # subproblem 3 -> 4: a . rot(h, vb) b = (|d|^2 - |a|^2 - |b|^2) / 2
    vb, disc, r2 = subproblem_3(h, a, b, d)  # (..., 2)
    reach = disc >= -1e-12 * r2
    u = a + rotate_about(h, vb, b)  # (..., 2, 3)
    va = subproblem_1(h, u, d[..., None, :])
    vc = s[c_] * (psi[..., None] - s[a_] * va - s[b_] * vb)
    v = np.empty(lead + (2, 4))
    v[..., a_] = va
    v[..., b_] = vb
    v[..., c_] = vc
    v[..., g.pri] = vp[..., None]
    q = chain.arrays.sign * (v - chain.arrays.offset)
    q = fit_turns(q, chain.is_revolute, chain.limits)
    ok_orient = tilt <= orientation_tol
    valid = (reach & ok_orient)[..., None] & np.array([True, True])
    valid[..., 1] &= disc > 1e-12 * r2  # a double root at full stretch counts once
    sing = (np.abs(disc) <= 1e-12 * r2)[..., None] & valid
    elbow = np.where(np.einsum("...i,...i", np.cross(a, rotate_about(h, vb, b)), h) >= 0, 1, -1)
    status = np.where(valid.any(axis=-1), 0, np.where(ok_orient, 1, 2)).astype(np.int8)
    error = None
    if compute_error:
        dp, dr = fk_error(chain, q, T)
        error = np.where(valid, np.hypot(dp, dr), np.inf)
    return make_set(robot, q, valid, inside=None, singular=sing,
                    branches={"elbow": elbow.astype(np.int8)}, status_codes=status,
                    method=method, info=dict(info or {}, tilt_tolerance=orientation_tol),
                    error=error)

