r"""Joint axes, the identification frames on them, and re-framing a chain.

The canonical chain (:mod:`robokin.model.chain`) is ``T = B L_0 J_1 C_1 J_2 C_2
\cdots J_n C_n T_{tool}`` with ``C_k = F_k G_k``. With every joint motion ``J_k``
at the identity (chain joint values ``u_k = 0``) the frame right before ``J_k`` is
the *joint frame* ``W_k``: its z axis is joint k's axis.

Identification frames ``D_k`` sit on the same axes. Between consecutive axes the
transform is one row (:class:`Row`):

* ``"dh"``: ``Rz(theta) Tz(d) Tx(a) Rx(alpha)``, the common normal (standard DH);
* ``"hayati"``: ``Rz(theta) Tz(d) Tx(a) Rx(alpha) Ry(beta)`` with ``d`` held
  fixed, for (near-)parallel axes, where the common normal's position ``d`` is
  ill-conditioned (a tilt of 0.05 deg between parallel axes 0.4 m apart moves it
  by ~460 m). Hayati and Mirmirani, "Improving the absolute positioning
  accuracy of robot manipulators", J. Robotic Systems 2(4), 1985.

Since ``J_k`` is a rotation about (or translation along) z, it commutes with any
``Rz Tz`` on the same axis; that is what lets frames slide along and turn about
their axes (:func:`reframe`) without changing the forward kinematics.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from robokin.exceptions import ModelError
from robokin.model.chain import Chain, ChainBuilder, joint_motion
from robokin.spatial import invert, rotx, roty, rotz, trans

__all__ = ["Row", "frames_at_zero", "joint_frames", "reframe", "row_matrix",
           "rows_from_axes", "zero_values"]

RowForm = Literal["dh", "hayati"]
_TINY = 1e-12


@dataclass(frozen=True)
class Row:
    """The transform from identification frame ``D_k`` to ``D_{k+1}``.

    Attributes:
        form: ``"dh"`` or ``"hayati"`` (see the module docstring).
        theta: Rotation about z_k [rad].
        d: Translation along z_k [m] (held fixed in the Hayati form).
        a: Translation along the new x [m].
        alpha: Rotation about the new x [rad].
        beta: Rotation about the new y [rad] (0 in the DH form).
    """

    form: RowForm
    theta: float
    d: float
    a: float
    alpha: float
    beta: float = 0.0


def row_matrix(row: Row) -> np.ndarray:
    """The 4x4 transform of a row."""
    T = rotz(row.theta) @ trans(0.0, 0.0, row.d) @ trans(row.a) @ rotx(row.alpha)
    return T @ roty(row.beta) if row.form == "hayati" else T


def joint_frames(chain: Chain) -> np.ndarray:
    """The joint frames ``W_k`` at zero joint motion, in the base frame.

    Returns:
        (n_chain, 4, 4): ``W_1 = L_0``, ``W_{k+1} = W_k C_k``; the base
        transform ``B`` is left out.
    """
    at_rest = np.array([-j.offset * j.sign for j in chain.joints])  # every J_k = I
    frames: np.ndarray = _without_base_and_tool(chain).frames_at(at_rest)[:-1]
    return frames


def _without_base_and_tool(chain: Chain) -> Chain:
    """The chain with identity base and tool (base frame in, flange out).

    So the model's one walk (:meth:`Chain.frames_at`) serves the frames here.
    """
    return chain.replace(base=np.eye(4), tool=np.eye(4))


def _sense(x: np.ndarray, x_prev: np.ndarray, z_prev: np.ndarray) -> np.ndarray:
    """``x`` or ``-x``: the one closer to ``x_prev`` (ties: +90 deg about z_prev)."""
    dot = float(x @ x_prev)
    if abs(dot) > 1e-9:
        return x if dot > 0 else -x
    return x if float(np.cross(x_prev, x) @ z_prev) > 0 else -x


def _theta(x_prev: np.ndarray, y_prev: np.ndarray, x: np.ndarray) -> float:
    return math.atan2(float(x @ y_prev), float(x @ x_prev))


def _dh_row(D: np.ndarray, p: np.ndarray, z: np.ndarray) -> Row:
    """The DH row from frame ``D`` to the line ``(p, z)`` (not parallel to z_D)."""
    x0, y0, z0, o0 = D[:3, 0], D[:3, 1], D[:3, 2], D[:3, 3]
    b = float(z0 @ z)
    w = o0 - p
    den = 1.0 - b * b
    t1 = (b * float(z @ w) - float(z0 @ w)) / den
    t2 = (float(z @ w) - b * float(z0 @ w)) / den
    c1, c2 = o0 + t1 * z0, p + t2 * z
    n = c2 - c1
    dist = float(np.linalg.norm(n))
    if dist > 1e-12:
        x = _sense(n / dist, x0, z0)
    else:
        cr = np.cross(z0, z)
        x = _sense(cr / np.linalg.norm(cr), x0, z0)
    a = float(n @ x)
    alpha = math.atan2(float(np.cross(z0, z) @ x), float(z0 @ z))
    return Row("dh", _theta(x0, y0, x), t1, a, alpha)


def _hayati_row(D: np.ndarray, p: np.ndarray, z: np.ndarray, d: float) -> Row:
    """The Hayati row from ``D`` to the line ``(p, z)`` (near-parallel to z_D).

    The new origin is where the line crosses the plane ``z_D . (x - o_D) = d``.
    """
    x0, y0, z0, o0 = D[:3, 0], D[:3, 1], D[:3, 2], D[:3, 3]
    s = (d - float(z0 @ (p - o0))) / float(z0 @ z)
    o = p + s * z
    v = o - o0 - d * z0
    dist = float(np.linalg.norm(v))
    x = _sense(v / dist, x0, z0) if dist > 1e-12 else x0
    theta = _theta(x0, y0, x)
    a = float(v @ x)
    # z in the frame Rz(theta): (sin b, -sin a cos b, cos a cos b)
    R = D[:3, :3] @ rotz(theta)[:3, :3]
    zl = R.T @ z
    beta = math.asin(max(-1.0, min(1.0, float(zl[0]))))
    alpha = math.atan2(-float(zl[1]), float(zl[2]))
    return Row("hayati", theta, d, a, alpha, beta)


def rows_from_axes(
    frames: np.ndarray, parallel_tol: float, d_parallel: np.ndarray | None = None
) -> tuple[list[Row], np.ndarray]:
    """Identification rows along the joint axes of ``frames`` (joint frames).

    Args:
        frames: Joint frames (n, 4, 4); each z axis is a joint axis.
        parallel_tol: Axes closer than this angle [rad] take the Hayati form.
        d_parallel: The fixed ``d`` of each Hayati row (n - 1,), default 0.

    Returns:
        The n - 1 rows and the identification frames ``D`` (n, 4, 4), ``D_1`` the
        first joint frame.

    Raises:
        ModelError: the rows do not reproduce the axes (a bug).
    """
    n = len(frames)
    D = [np.array(frames[0])]
    rows: list[Row] = []
    for k in range(n - 1):
        p, z = frames[k + 1][:3, 3], frames[k + 1][:3, 2]
        angle = math.acos(max(-1.0, min(1.0, abs(float(D[-1][:3, 2] @ z)))))
        if angle < max(parallel_tol, 1e-9):  # exactly parallel: DH has no normal
            d = 0.0 if d_parallel is None else float(d_parallel[k])
            row = _hayati_row(D[-1], p, z, d)
        else:
            row = _dh_row(D[-1], p, z)
        Dn = D[-1] @ row_matrix(row)
        off_axis = np.linalg.norm(np.cross(Dn[:3, 3] - p, z))
        if np.linalg.norm(Dn[:3, 2] - z) > 1e-9 or off_axis > 1e-9:  # pragma: no cover
            raise ModelError(f"internal: identification frame {k + 2} is off its axis")
        rows.append(row)
        D.append(Dn)
    return rows, np.array(D)


def _closest_frame(W: np.ndarray, target: np.ndarray) -> np.ndarray:
    """The frame on ``W``'s z axis (same z) nearest ``target``: ``W Rz(phi) Tz(s)``."""
    z, o = W[:3, 2], W[:3, 3]
    s = float((target[:3, 3] - o) @ z)
    x = None
    for cand in (target[:3, 0], target[:3, 1], W[:3, 0]):
        xp = cand - (cand @ z) * z
        if np.linalg.norm(xp) > 1e-6:
            x = xp / np.linalg.norm(xp)
            break
    assert x is not None  # W's own x is perpendicular to z
    phi = _theta(W[:3, 0], W[:3, 1], x)
    return W @ rotz(phi) @ trans(0.0, 0.0, s)


def zero_values(chain: Chain) -> np.ndarray:
    """Each chain joint's motion value ``u_k`` at zero joint coordinates, (n_chain,)."""
    c = np.asarray(chain.coupling.offset, dtype=float).reshape(-1)
    return np.array([j.sign * ck + j.offset for j, ck in zip(chain.joints, c)])


def frames_at_zero(chain: Chain) -> tuple[np.ndarray, np.ndarray]:
    """Joint frames at zero joint coordinates (n_chain, 4, 4), and the flange (4, 4).

    The frame right before ``J_k`` with every earlier joint at its ``q = 0``
    value; the flange is the end of the chain (before the tool), base left out.
    """
    c = np.asarray(chain.coupling.offset, dtype=float).reshape(-1)  # q = 0: q_chain = c
    frames = _without_base_and_tool(chain).frames_at(c)
    return frames[:-1], frames[-1]


def reframe(chain: Chain, like: Chain) -> Chain:
    r"""``chain`` re-expressed with its link frames as close as possible to ``like``'s.

    Both chains need the same joints (kinds). The result has exactly
    ``chain``'s forward kinematics, its joints (offsets included), coupling,
    base and tool. Its joint frames at ``q = 0`` are the frames on ``chain``'s
    axes nearest ``like``'s (each only slides along and turns about its own
    axis, which commutes with the joint's motion), and its link frames sit
    relative to them as ``like``'s do at equal joint coordinates. A robot file
    or URDF written from it therefore has link origins near the physical links,
    not metres away as a DH table of near-parallel axes puts them
    (ros-industrial/universal_robot#357).

    .. math:: T(q) = \prod_k V_k J_k(u_k - e_k) V_k^{-1} \cdot P

    with ``V_k`` the new joint frames at ``q = 0``, ``e_k`` the joint values there
    and ``P`` the flange at ``q = 0``; each factor is written as joint ``k``
    followed by ``F'_k = J(e'_k - e_k) F'_{like}`` and ``G'_k``.

    Raises:
        ModelError: the chains differ in joint count or kinds.
    """
    if like.n_chain != chain.n_chain or any(
            a.kind != b.kind for a, b in zip(chain.joints, like.joints)):
        raise ModelError("reframe: the chains must have the same joints")
    W, tip = frames_at_zero(chain)
    Wl, _ = frames_at_zero(like)
    e, el = zero_values(chain), zero_values(like)
    n = chain.n_chain
    V = [_closest_frame(W[k], Wl[k]) for k in range(n)] + [tip]
    builder = ChainBuilder().constant(V[0])
    for k, j in enumerate(chain.joints):
        F = joint_motion(j.kind, el[k] - e[k]) @ like.frame_offsets[k]
        C = joint_motion(j.kind, -e[k]) @ invert(V[k]) @ V[k + 1]
        builder.joint(j).constant(F).frame().constant(invert(F) @ C)
    return builder.build(base=chain.base, tool=chain.tool,
                         coordinates=chain.coordinates, coupling=chain.coupling)
