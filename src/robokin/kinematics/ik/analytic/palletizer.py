"""4-axis parallelogram palletizers (QFMD010): the tool always stays level.

The chain has five revolute joints for four coordinates: the waist ``1``, three
parallel pitch joints ``2, 3, 4`` whose (signed) angle sum the parallelogram holds
constant (``theta_c``), and the tool yaw ``5`` whose axis is parallel to the waist's
once the constant pitch ``R_c = rot(h2, theta_c)`` is applied. So the tool
orientation is ``rot(h1, v1 + s5 v5) R_c R_M`` (a yaw only) and:

* a target whose roll/pitch is not level (within ``level_tol``) gives the status
  'not reachable: tool cannot tilt';
* ``h2 . R1^T p' = h2 . (o5 - o1)``: subproblem 4 for the waist (two roots, about
  ``theta1`` and ``theta1 + pi``);
* the planar two-link problem: subproblem 3 for the forearm (two roots), subproblem 1
  for the upper arm. That gives the paper's four candidate (theta2, theta3) pairs
  over the two waist branches; the joint ranges then keep the real ones
  (``SolutionSet.keep_within_limits``).
* the yaw joint from the target yaw.

The coordinates are recovered from the chain values through the coupling
(``q = M^+ (q_chain - c)``).

Use :func:`pose_from_position_yaw` to build the level target from a position and a
yaw.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from robokin.kinematics.arm import Arm, ArmSource, arm_of
from robokin.kinematics.ik.analytic._common import fit_turns, fk_error, make_set
from robokin.kinematics.ik.analytic._geometry import (
    Poe,
    angle_between_axes,
    rotate_about,
    subproblem_1,
    subproblem_3,
    subproblem_4,
    unit_perpendicular,
)

if TYPE_CHECKING:
    from robokin.kinematics.ik.solutions import SolutionSet
    from robokin.model.chain import Chain

__all__ = ["measure", "pose_from_position_yaw"]

NAME = "palletizer"


@dataclass(frozen=True, eq=False)
class PalletizerGeometry:
    """The nominal palletizer read from a chain (base frame, zero chain values)."""

    h: np.ndarray  # (5, 3) axes, 3 and 4 snapped onto 2
    o: np.ndarray
    s3: float
    s4: float
    s5: float
    theta_c: float
    Rc: np.ndarray
    M: np.ndarray
    e1: np.ndarray
    back: np.ndarray  # (n, n_chain) pseudo-inverse of the coupling matrix


def _analyse(chain: Chain, poe: Poe) -> tuple[PalletizerGeometry, float, str, str]:
    h, o = poe.h, poe.o
    sign, off = chain.arrays.sign, chain.arrays.offset
    Mc, c = chain.coupling.matrix, chain.coupling.offset
    s3 = 1.0 if h[1] @ h[2] >= 0 else -1.0
    s4 = 1.0 if h[1] @ h[3] >= 0 else -1.0
    sv = np.array([0.0, 1.0, s3, s4, 0.0])
    # the parallelogram holds s2 v2 + s3 v3 + s4 v4 constant in q
    drift = float(np.abs((sv * sign) @ Mc).max())
    theta_c = float(sv @ (sign * c + off))
    h2 = h[1] + s3 * h[2] + s4 * h[3]
    h2 /= np.linalg.norm(h2)
    Rc = rotate_about(h2, np.array(theta_c), np.eye(3)).T  # columns rot(h2, theta_c) e_i
    h5c = Rc @ h[4]
    ang = max(angle_between_axes(h[1], h[2]), angle_between_axes(h[1], h[3]),
              angle_between_axes(h[0], h5c))
    text = (f"axes 2-4 parallel within {angle_between_axes(h[1], h[2]):.1e} rad; "
            f"pitch sum held constant (drift {drift:.1e}); tool axis parallel to the "
            f"waist within {angle_between_axes(h[0], h5c):.1e} rad")
    why = []
    if drift > 1e-9:
        why.append("the pitch joints' angle sum is not held constant (tool not level)")
    if np.linalg.matrix_rank(Mc) < chain.n:
        why.append("the coupling does not determine the coordinates")
    if angle_between_axes(h[0], h[1]) < 0.1:
        why.append("axis 1 is parallel to axis 2")
    hs = h.copy()
    hs[1], hs[2], hs[3] = h2, s3 * h2, s4 * h2
    g = PalletizerGeometry(
        hs, o, s3, s4, 1.0 if h[0] @ h5c >= 0 else -1.0, theta_c, Rc, poe.M,
        unit_perpendicular(h[0]), np.linalg.pinv(Mc),
    )
    return g, ang, text, "; ".join(why)


def measure(chain: Chain, poe: Poe) -> tuple[float, float, str, str]:
    """Deviation from the family: (angle [rad], 0, text, why-not)."""
    _, ang, text, why = _analyse(chain, poe)
    return ang, 0.0, text, why


def geometry(chain: Chain, poe: Poe) -> PalletizerGeometry:
    """The nominal palletizer geometry of a chain."""
    return _analyse(chain, poe)[0]


def level_rotation(g: PalletizerGeometry) -> np.ndarray:
    """The tool rotation (3, 3) at yaw 0."""
    R: np.ndarray = g.Rc @ g.M[:3, :3]
    return R


def pose_from_position_yaw(robot: ArmSource, xyz: Any, yaw: Any) -> np.ndarray:
    """The level target pose(s) (..., 4, 4) at a position with a yaw.

    The tool sits at ``xyz`` (..., 3) [m], turned by ``yaw`` (...) [rad] about
    the waist axis from its zero-yaw orientation.
    """
    from robokin.kinematics.ik.analytic._geometry import poe_from_chain

    chain = arm_of(robot).chain
    g = geometry(chain, poe_from_chain(chain))
    xyz = np.asarray(xyz, dtype=np.float64)
    yaw = np.asarray(yaw, dtype=np.float64)
    lead = np.broadcast_shapes(xyz.shape[:-1], yaw.shape)
    R0 = level_rotation(g)
    Rz = np.moveaxis(rotate_about(g.h[0], yaw[..., None], np.eye(3)), -1, -2)
    T = np.zeros(lead + (4, 4))
    T[..., :3, :3] = Rz @ R0
    T[..., :3, 3] = xyz
    T[..., 3, 3] = 1.0
    return T


def solve_geometry(robot: Arm, g: PalletizerGeometry, T: np.ndarray, *,
                   level_tol: float = 1e-9, compute_error: bool = False,
                   method: str = "analytic:palletizer",
                   info: dict[str, Any] | None = None) -> SolutionSet:
    """Every solution (up to 4) for poses T (..., 4, 4)."""
    chain = robot.chain
    T = np.asarray(T, dtype=np.float64)
    lead = T.shape[:-2]
    h, o = g.h, g.o
    h1, h2 = h[0], h[1]
    Rrel = T[..., :3, :3] @ level_rotation(g).T
    hr = Rrel @ h1
    tilt = np.arctan2(np.linalg.norm(np.cross(hr, h1), axis=-1), hr @ h1)
    f = Rrel @ g.e1
    psi = np.arctan2(np.cross(g.e1, f) @ h1, f @ g.e1)
    p = T[..., :3, 3]
    RTM = T[..., :3, :3] @ g.M[:3, :3].T
    pp = p - o[0] - RTM @ (g.M[:3, 3] - o[4])
    # waist: pp . rot(h1, v1) h2 = h2 . (o5 - o1)
    v1, disc, r2 = subproblem_4(h1, pp, h2, h2 @ (o[4] - o[0]))  # (..., 2)
    reach1 = disc >= -1e-12 * r2
    d = (rotate_about(h1, -v1, pp[..., None, :]) - (o[1] - o[0])
         - g.Rc @ (o[4] - o[3]))  # (..., 2, 3)
    a = o[2] - o[1]
    b = o[3] - o[2]
    h3 = h[2]
    v3, disc3, r3 = subproblem_3(h3, a, b, d)  # (..., 2, 2): [waist, elbow]
    reach3 = disc3 >= -1e-12 * r3
    u = a + rotate_about(h3, v3, b)  # (..., 2, 2, 3)
    v2 = subproblem_1(h2, u, d[..., :, None, :])
    v1b = np.broadcast_to(v1[..., :, None], v2.shape)
    v4 = g.s4 * (g.theta_c - v2 - g.s3 * v3)
    v5 = g.s5 * (psi[..., None, None] - v1b)
    v = np.stack([v1b, v2, v3, v4, v5], axis=-1).reshape(lead + (4, 5))
    qc = chain.arrays.sign * (v - chain.arrays.offset)
    q = (qc - chain.coupling.offset) @ g.back.T
    q = fit_turns(q, chain.is_revolute, chain.limits)
    level = tilt <= level_tol
    ok = np.broadcast_to(
        reach1[..., None, None] & reach3[..., :, None] & level[..., None, None],
        lead + (2, 2)).copy()  # (..., waist, elbow)
    ok[..., 1, :] &= (disc > 1e-12 * r2)[..., None]
    ok[..., :, 1] &= (disc3 > 1e-12 * r3)
    valid = ok.reshape(lead + (4,))
    sing = ((np.abs(disc) <= 1e-12 * r2)[..., None, None]
            | (np.abs(disc3) <= 1e-12 * r3)[..., :, None])
    sing = np.broadcast_to(sing, lead + (2, 2)).reshape(lead + (4,)) & valid
    status = np.where(valid.any(axis=-1), 0, np.where(level, 1, 3)).astype(np.int8)
    error = None
    if compute_error:
        dp, dr = fk_error(chain, q, T)
        error = np.where(valid, np.hypot(dp, dr), np.inf)
    labels = {"shoulder": np.broadcast_to(np.array([1, 1, -1, -1], np.int8), lead + (4,)),
              "elbow": np.broadcast_to(np.array([1, -1, 1, -1], np.int8), lead + (4,))}
    return make_set(robot, q, valid, inside=None, singular=sing, branches=labels,
                    status_codes=status, method=method,
                    info=dict(info or {}, level_tolerance=level_tol), error=error)

