r"""Arm configuration: which IK branch a joint configuration is on, as controllers say it.

A Cartesian target alone does not say how a six-axis arm reaches it: up to eight
branches (shoulder front/back, elbow up/down, wrist flip) and, for joints that turn
more than a revolution, several turns of each. Every controller language carries
that choice next to the pose, each in its own words. This module computes them from
the joint values (in the controller's convention: order, signs and zeros of the
robot file's ``controller:`` section applied, degrees) and from two geometric facts
computed once, here, for every dialect.

Geometry (:func:`arm_configuration`), in the controller's robot root frame
(``$ROBROOT``; z up along axis 1, x where the arm reaches when axis 1 is at its
zero), evaluated with axis 1 turned to its zero (KUKA's "A1 coordinate system",
which turns with axis 1):

``behind_axis_1``
    The wrist point lies behind axis 1: its x in the A1 frame is negative (KUKA's
    "overhead area", ABB's "wrist center behind axis 1", FANUC's B, Yaskawa's
    "rear"). The wrist point is the intersection of axes 5 and 6 (the point of axis
    5 nearest axis 6 when they do not meet).
``behind_lower_arm``
    The elbow point lies behind the line through axes 2 and 3 (ABB: "wrist center
    behind the lower arm"; KUKA status bit 1 is its negation, "in front of the
    straight line through A2 and A3"; FANUC D, Yaskawa "lower arm"). The elbow point
    is the intersection of axes 4 and 5 (for a spherical wrist, the wrist point
    again). "In front" is the side the wrist reaches when the upper arm points up
    and the forearm forward: the signed angle about the A1 frame's y axis from the
    line (axis 2 to axis 3) to the elbow point is in [0, 180) degrees. For KUKA
    arms this is the manual's ``A3 >= phi`` (phi: the A3 angle at which the arm is
    stretched) within half a turn of phi.

Both are exact for spherical-wrist arms (every arm the vendor dialects are for) and
a stated convention for offset wrists (UR, AUBO): there the two points are the ones
each IK branch choice moves, so the eight branches of a pose still get eight
different flag triples (tested).

The vendor flags (each function's docstring cites its definition):

=============  =====================================================================
KUKA           Status ``S`` = bit 0 behind axis 1, bit 1 in front of the A2-A3 line,
               bit 2 ``A5 < 0``; Turn ``T`` bit ``i`` = ``A(i+1) < 0``
ABB            confdata ``[cf1, cf4, cf6, cfx]``: quadrants of axes 1, 4, 6 and
               ``cfx`` = 4 (behind axis 1) + 2 (behind lower arm) + 1 (axis 5 < 0)
FANUC          ``'F|N U|D T|B, t4, t5, t6'``: F when ``J5 >= 0``, D behind the lower
               arm, B behind axis 1, turn numbers of J4, J5, J6
Yaskawa        ``RCONF l,m,n,o,p,q,r,s``: flip (0 when ``B < 0``), lower arm, rear,
               R >= 180, T >= 180, S >= 180, 0, 0
Staubli        ``shoulder`` lefty/righty (righty behind axis 1), ``elbow``
               epositive/enegative (sign of J3), ``wrist`` wpositive/wnegative (J5)
=============  =====================================================================
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from robokin._validation import check_joints
from robokin.exceptions import InputError
from robokin.spatial import invert

if TYPE_CHECKING:
    from robokin.robot import Robot
    from robokin.trajectory.io import ControllerProfile

__all__ = [
    "ArmConfiguration",
    "abb_confdata",
    "abb_quadrant",
    "arm_configuration",
    "fanuc_config",
    "fanuc_turn",
    "kuka_status_turn",
    "staubli_config",
    "yaskawa_rconf",
]


@dataclass(frozen=True)
class ArmConfiguration:
    """The branch facts of a batch of configurations (module docstring).

    Attributes:
        joints_deg: Controller joint values (N, 6) [deg]: the profile's order, signs
            and zeros applied.
        behind_axis_1: (N,) bool, the wrist point behind axis 1.
        behind_lower_arm: (N,) bool, the elbow point behind the line through axes 2
            and 3.
        reach: (N,) x of the wrist point in the A1 frame [m] (its sign is
            ``behind_axis_1``; near 0 the flag is a shoulder singularity).
        elbow: (N,) the signed elbow angle [rad] in (-pi, pi] (negative: behind;
            near 0 or pi the arm is stretched or folded, an elbow singularity).
    """

    joints_deg: npt.NDArray[np.float64]
    behind_axis_1: npt.NDArray[np.bool_]
    behind_lower_arm: npt.NDArray[np.bool_]
    reach: npt.NDArray[np.float64]
    elbow: npt.NDArray[np.float64]


def _axes(robot: Robot, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit directions (N, n, 3) and a point (N, n, 3) of every joint axis, world frame.

    From the geometric Jacobian at the tool: column k is ``[w_k x (p - a_k); w_k]``,
    so the point of axis k nearest the tool is ``p - (v_k x w_k) / |w_k|^2``.
    """
    J = robot.jacobian(q)
    p = robot.fk(q)[..., :3, 3]
    v = np.swapaxes(J[..., :3, :], -1, -2)
    w = np.swapaxes(J[..., 3:, :], -1, -2)
    ww = np.einsum("...i,...i->...", w, w)[..., None]
    point = p[..., None, :] - np.cross(v, w) / ww
    return w / np.sqrt(ww), point


def _nearest_on_first(p1: np.ndarray, d1: np.ndarray, p2: np.ndarray,
                      d2: np.ndarray) -> np.ndarray:
    """The point of line 1 nearest line 2 (their intersection when they meet).

    Parallel lines: ``p1`` itself.
    """
    r = p1 - p2
    a = np.einsum("...i,...i->...", d1, d2)
    b = np.einsum("...i,...i->...", d1, r)
    c = np.einsum("...i,...i->...", d2, r)
    den = 1.0 - a * a
    safe = np.where(den > 1e-12, den, 1.0)
    s = np.where(den > 1e-12, (a * c - b) / safe, 0.0)
    return p1 + s[..., None] * d1


def arm_configuration(robot: Robot, q: npt.ArrayLike, profile: ControllerProfile,
                      root: npt.ArrayLike | None = None) -> ArmConfiguration:
    """The branch facts of six-axis configurations ``q`` (module docstring).

    Args:
        robot: A six-axis arm (revolute joints 1, 4, 5, 6 at least).
        q: Joint coordinates (N, 6) or (6,) [rad], model order.
        profile: The controller profile (column order, signs, zeros).
        root: The controller's robot root frame in the model's base frame (4, 4)
            [m] (default: the model's base frame).

    Returns:
        An :class:`ArmConfiguration` for the batch (N = 1 for one configuration).

    Raises:
        InputError: not a six-coordinate arm, or a bad ``q``.
    """
    if robot.n != 6:
        raise InputError("robot", f"configuration flags need a six-axis arm; "
                         f"{robot.name} has {robot.n} coordinates")
    q = check_joints(q, 6, "q").reshape(-1, 6)
    order, signs, offsets = profile.parts(6)
    ctrl = profile.export(q)
    j1 = int(order[0])
    at_zero = q.copy()
    at_zero[:, j1] = -offsets[0] / signs[0]      # controller axis 1 at its zero
    direction, point = _axes(robot, at_zero)
    base = robot.fk_all(at_zero[:1])[0, 0]
    root_T = base if root is None else base @ np.asarray(root, float)
    to_root = invert(root_T)
    R, t = to_root[:3, :3], to_root[:3, 3]
    point = point @ R.T + t
    direction = direction @ R.T
    ax = [int(k) for k in order]
    wrist = _nearest_on_first(point[:, ax[4]], direction[:, ax[4]],
                              point[:, ax[5]], direction[:, ax[5]])
    elbow_pt = _nearest_on_first(point[:, ax[3]], direction[:, ax[3]],
                                 point[:, ax[4]], direction[:, ax[4]])
    line = point[:, ax[2]] - point[:, ax[1]]
    fore = elbow_pt - point[:, ax[2]]
    # signed angle about +y (rotation about +y takes z to x): x-z plane components
    sin_part = line[:, 2] * fore[:, 0] - line[:, 0] * fore[:, 2]
    cos_part = line[:, 0] * fore[:, 0] + line[:, 2] * fore[:, 2]
    elbow = np.arctan2(sin_part, cos_part)
    reach = wrist[:, 0]
    deg = np.where(robot.is_revolute[order], 180.0 / np.pi, 1000.0)
    return ArmConfiguration(joints_deg=ctrl * deg, behind_axis_1=reach < 0.0,
                            behind_lower_arm=elbow < 0.0, reach=reach, elbow=elbow)


def _deg(joints_deg: npt.ArrayLike) -> np.ndarray:
    a = np.asarray(joints_deg, dtype=np.float64)
    if a.shape[-1] != 6:
        raise InputError("joints_deg", f"expected (..., 6) joint values, got {a.shape}")
    return a


def kuka_status_turn(joints_deg: npt.ArrayLike, behind_axis_1: npt.ArrayLike,
                     behind_lower_arm: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """KUKA Status and Turn of E6POS targets.

    Status: bit 0 = 1 when the wrist point is in the overhead area (behind axis 1),
    bit 1 = 1 when it is in front of the straight line through A2 and A3, bit 2 = 1
    when ``-180 <= A5 < 0`` or ``180 <= A5 < 360``. Turn: bit ``i`` = 1 when axis
    ``i + 1`` is negative.

    References:
        KUKA System Software 8, Operating and Programming Instructions for System
        Integrators, "Status" and "Turn"; restated in Beckhoff TF5200
        "Status & Turn (IS, IT)" (criteria 1-3, turn bits).

    Returns:
        ``S`` and ``T``, integer arrays (...).
    """
    a = _deg(joints_deg)
    a5 = a[..., 4]
    bit2 = ((a5 >= -180.0) & (a5 < 0.0)) | ((a5 >= 180.0) & (a5 < 360.0))
    status = (np.asarray(behind_axis_1, bool).astype(int)
              + 2 * (~np.asarray(behind_lower_arm, bool)).astype(int)
              + 4 * bit2.astype(int))
    turn = ((a < 0.0).astype(int) << np.arange(6)).sum(-1)
    return status, turn


def abb_quadrant(angle_deg: npt.ArrayLike) -> np.ndarray:
    """ABB's quadrant number of an axis angle: 0 for [0, 90), 1 for [90, 180), ...

    -1 for (-90, 0), -2 for (-180, -90], ... ("quadrant 0 is the first quarter
    revolution, 0 to 90 degrees, in a positive direction from the zero position;
    quadrant -1 is 0 to -90 degrees").

    References:
        ABB, Technical reference manual RAPID Instructions, Functions and Data types,
        "confdata - Robot configuration data".
    """
    a = np.asarray(angle_deg, dtype=np.float64)
    return np.where(a >= 0.0, np.floor(a / 90.0), -np.floor(-a / 90.0) - 1).astype(int)


def abb_confdata(joints_deg: npt.ArrayLike, behind_axis_1: npt.ArrayLike,
                 behind_lower_arm: npt.ArrayLike) -> np.ndarray:
    """ABB ``confdata [cf1, cf4, cf6, cfx]`` of robtargets, (..., 4) integers.

    ``cf1, cf4, cf6``: :func:`abb_quadrant` of axes 1, 4 and 6. ``cfx`` (0-7): the
    manual's table, 4 when the wrist center is behind axis 1, + 2 when it is behind
    the lower arm, + 1 when axis 5 is negative.

    References:
        ABB, Technical reference manual RAPID Instructions, Functions and Data types,
        "confdata", the cfx table for six-axis robots.
    """
    a = _deg(joints_deg)
    cfx = (4 * np.asarray(behind_axis_1, bool).astype(int)
           + 2 * np.asarray(behind_lower_arm, bool).astype(int)
           + (a[..., 4] < 0.0).astype(int))
    return np.stack([abb_quadrant(a[..., 0]), abb_quadrant(a[..., 3]),
                     abb_quadrant(a[..., 5]), cfx], axis=-1)


def fanuc_turn(angle_deg: npt.ArrayLike) -> np.ndarray:
    """FANUC turn number: ``k`` with ``angle - 360 k`` in (-180, 180]."""
    a = np.asarray(angle_deg, dtype=np.float64)
    return np.ceil((a - 180.0) / 360.0).astype(int)


def fanuc_config(joints_deg: npt.ArrayLike, behind_axis_1: npt.ArrayLike,
                 behind_lower_arm: npt.ArrayLike,
                 turn_axes: tuple[int, int, int] = (4, 5, 6)) -> list[str]:
    """FANUC configuration strings ``'N U T, 0, 0, 0'`` of Cartesian positions.

    Wrist F (flip) when ``J5 >= 0``, N otherwise; elbow D (down) when the elbow
    point is behind the lower arm, U otherwise; arm B (back) when the wrist point
    is behind axis 1, T (front) otherwise; then the turn numbers
    (:func:`fanuc_turn`) of ``turn_axes`` (the controller's
    ``$SCR_GRP[1].$TURN_AXIS``, J4, J5, J6 on six-axis arms, as FANUC's Remote
    Motion Interface names its Turn4, Turn5, Turn6).

    References:
        FANUC R-30iB HandlingTool Operator's Manual, "Configuration" (joint
        placement F/N, U/D, T/B and turn numbers); the F/N sign as in RoboDK's
        open-source FANUC post processor (``F`` for ``J5 >= 0``) and as FANUC's
        usual tool-down pose ``J5 = -90`` is written ``N U T``.

    Returns:
        One string per configuration, e.g. ``"N U T, 0, 0, 0"``.
    """
    a = _deg(joints_deg).reshape(-1, 6)
    back = np.broadcast_to(np.asarray(behind_axis_1, bool), a.shape[:1])
    down = np.broadcast_to(np.asarray(behind_lower_arm, bool), a.shape[:1])
    turns = fanuc_turn(a[:, [k - 1 for k in turn_axes]])
    return [f"{'F' if row[4] >= 0.0 else 'N'} {'D' if d else 'U'} {'B' if b else 'T'}, "
            f"{t[0]}, {t[1]}, {t[2]}" for row, d, b, t in zip(a, down, back, turns)]


def yaskawa_rconf(joints_deg: npt.ArrayLike, behind_axis_1: npt.ArrayLike,
                  behind_lower_arm: npt.ArrayLike) -> np.ndarray:
    """Yaskawa ``///RCONF l,m,n,o,p,q,r,s`` of Cartesian position variables, (..., 8).

    ``l`` 0 flip / 1 no-flip (flip: ``B < 0``), ``m`` 0 upper arm / 1 lower arm
    (behind the lower-arm line), ``n`` 0 front / 1 rear (behind axis 1), ``o``, ``p``,
    ``q``: 1 when R, T, S (axes 4, 6, 1) are ``>= 180`` degrees, ``r``, ``s`` 0.

    References:
        Yaskawa Motoman NX100 / DX100 "Job Data Format" (``RCONF``: 0 flip, 1
        no-flip; 0 upper arm, 1 lower arm; 0 front, 1 rear; 0 R < 180, 1 R >= 180;
        likewise T and S); the flip sign as in RoboDK's open-source Motoman post
        processor (``l = 1`` for ``B >= 0``), which writes the common tool-down
        pose (``B = -90``) as ``RCONF 0,...``, as taught jobs do.
    """
    a = _deg(joints_deg)
    shape = a.shape[:-1]
    cols = [(a[..., 4] >= 0.0), np.broadcast_to(np.asarray(behind_lower_arm, bool), shape),
            np.broadcast_to(np.asarray(behind_axis_1, bool), shape),
            a[..., 3] >= 180.0, a[..., 5] >= 180.0, a[..., 0] >= 180.0,
            np.zeros(shape, bool), np.zeros(shape, bool)]
    return np.stack([c.astype(int) for c in cols], axis=-1)


def staubli_config(joints_deg: npt.ArrayLike, behind_axis_1: npt.ArrayLike
                   ) -> list[tuple[str, str, str]]:
    """Staubli VAL3 ``config`` of pointRx targets: (shoulder, elbow, wrist) per row.

    ``righty`` when the wrist point is behind axis 1, else ``lefty``;
    ``epositive`` when J3 >= 0, else ``enegative``; ``wpositive`` when J5 >= 0,
    else ``wnegative``.

    References:
        Staubli VAL3 Reference Manual, "config" type (shoulder lefty / righty, elbow
        epositive / enegative, wrist wpositive / wnegative); the lefty / righty side
        as RoboDK's open-source VAL3 post processor maps its front / rear flag.
    """
    a = _deg(joints_deg).reshape(-1, 6)
    back = np.broadcast_to(np.asarray(behind_axis_1, bool), a.shape[:1])
    return [("righty" if b else "lefty", "epositive" if row[2] >= 0.0 else "enegative",
             "wpositive" if row[4] >= 0.0 else "wnegative") for row, b in zip(a, back)]
