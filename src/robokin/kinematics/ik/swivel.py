r"""The swivel (arm angle) closed form of an SRS arm: every configuration of a pose.

An SRS arm (KUKA iiwa type) has axes 1-3 meeting in the shoulder point S and axes
5-7 in the wrist point W. For a pose T the wrist point goes to
:math:`W_T = T M^{-1} W`; the elbow angle fixes the distance :math:`|S - W_T|`
(subproblem 3, two roots), and the shoulder rotation :math:`R_A = e_1 e_2 e_3` must
take :math:`a = e_4 W - S` to :math:`w = W_T - S`. Every such rotation is
:math:`R_A(\psi) = \mathrm{rot}(\hat w, \psi - \psi_0) R_0` with :math:`R_0` the
smallest rotation taking a to w: the swivel :math:`\psi` turns the arm about the
shoulder-wrist line (Shimizu et al. 2008; Singh and Kreutz 1989).

**The swivel angle** :math:`\psi` is measured about :math:`\hat w` (shoulder to
wrist) from the direction of axis 1 (its part perpendicular to :math:`\hat w`) to
:math:`\hat w \times R_A h_4`, the arm plane's in-plane normal to the shoulder-wrist
line (:math:`h_4`, the elbow axis, is normal to the arm plane on the iiwa): on the
iiwa14 at :math:`q_3 = 0` it is 0 or :math:`\pi`. It is undefined where the
shoulder-wrist line is along axis 1 (the base x axis' part is used there and the
pose flagged).

Each triple is split by subproblem 4 (its middle angle, two roots) and subproblem 1
(the outer ones). Slots: ``slot = 4 * elbow + 2 * shoulder + wrist`` (each 0/1:
the + / - root of that subproblem), the same for every swivel value.

**Joint limits exactly.** A shoulder or wrist joint at a value L is one condition
:math:`x \cdot \mathrm{rot}(\hat w, \pm\varphi)\, y = c` on the swivel (first joint
of the triple: its axis turned by L applied to the middle axis, and so on): one
subproblem 4, at most two swivel angles per joint and limit. The elbow is constant
over the swivel.

References:
    Shimizu, Kakuya, Yoon, Kitagaki and Kosuge, "Analytical inverse kinematic
    computation for 7-DOF redundant manipulators with joint limits and its
    application to redundancy resolution", IEEE T-RO 24(5), 2008.
    Singh and Kreutz, "Gravity compensation and an inverse kinematics-based
    description of the self-motion of 7-DOF manipulators", 1989.
    Elias and Wen, "IK-Geo", arXiv:2211.05737 (2022): subproblems 1, 3, 4.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from robokin._native import kernels as K
from robokin.kinematics.ik.analytic._geometry import poe_from_chain
from robokin.spatial import wrap_angle

__all__ = ["SwivelArm", "swivel_arm"]

#: Axes meeting within this distance [m, relative to the arm's length over 1 m].
_MEET_TOL = 1e-9
#: A subproblem-4 root whose |C| exceeds its amplitude by this (relative) is a double root.
_DOUBLE = 1e-12
#: A triple whose middle axis is this near normal to the outer ones takes its middle
#: angle from the cross product (``_triple``; self_motion.c SM_ORTHO).
_ORTHO = 1e-12
#: Outer axes this near one line (the norm of the last axis' part normal to the
#: first): the first angle set to 0 (self_motion.c SM_LINED); flagged singular below
#: 1e-9.
_LINED = 1e-15


def _rot(u: np.ndarray, ang: np.ndarray) -> np.ndarray:
    """Rotation matrices (..., 3, 3) about unit axes u (..., 3) by ang (...) [rad]."""
    u = np.asarray(u, dtype=np.float64)
    c, s = np.cos(ang)[..., None, None], np.sin(ang)[..., None, None]
    x, y, z = u[..., 0], u[..., 1], u[..., 2]
    zero = np.zeros_like(x)
    K = np.stack([np.stack([zero, -z, y], -1), np.stack([z, zero, -x], -1),
                  np.stack([-y, x, zero], -1)], -2)
    outer = u[..., :, None] * u[..., None, :]
    eye = np.broadcast_to(np.eye(3), K.shape)
    out: np.ndarray = c * eye + s * K + (1 - c) * outer
    return out


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    out: np.ndarray = np.einsum("...i,...i->...", a, b)
    return out


def _mv(R: np.ndarray, v: np.ndarray) -> np.ndarray:
    out: np.ndarray = np.einsum("...ij,...j->...i", R, v)
    return out


def _sp4(h: np.ndarray, x: np.ndarray, y: np.ndarray, c: np.ndarray
         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r"""Subproblem 4: the angles t with :math:`x \cdot \mathrm{rot}(h, t)\, y = c`.

    Returns ``(t_plus, t_minus, real)``: the two roots (...) [rad] and where they are
    real (a |C| past the amplitude by rounding, relative 1e-12, is a double root).
    """
    ypar = _dot(h, y)[..., None] * h
    yp = y - ypar
    A = _dot(x, yp)
    B = _dot(x, np.cross(h, yp))
    C = c - _dot(x, ypar)
    rho = np.hypot(A, B)
    real = np.abs(C) <= rho * (1 + _DOUBLE) + 1e-300
    with np.errstate(invalid="ignore", divide="ignore"):
        d = np.arccos(np.clip(C / rho, -1.0, 1.0))
    phi = np.arctan2(B, A)
    return phi + d, phi - d, real & (rho > 0)


def _sp1(h: np.ndarray, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Subproblem 1: the angle about h from x to y, and |x's part normal to h|."""
    xp = x - _dot(h, x)[..., None] * h
    yp = y - _dot(h, y)[..., None] * h
    return np.arctan2(_dot(h, np.cross(xp, yp)), _dot(xp, yp)), np.linalg.norm(xp, axis=-1)


def _triple(ha: np.ndarray, hb: np.ndarray, hc: np.ndarray, R: np.ndarray,
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r"""Every split of a rotation R (..., 3, 3) into :math:`e_a e_b e_c` (axes meet).

    Returns ``(v (..., 2, 3) chain angles, real (..., 2), singular (..., 2))``; the
    second axis is the middle angle's +/- root. Where the outer axes line up (a
    singular triple) only their sum is fixed: the first angle is set to 0. The rows
    within 1e-9 of that are flagged singular (their outer angles are fixed by the
    rotation only to ~1e-16 over the distance).

    Where the middle axis is normal to both others (the SRS arms' shoulders and
    wrists) the middle angle is ``phi +- atan2(|ha x R hc|, C)`` where |C| > 0.99: the
    cosine C alone (``_sp4``'s arccos) loses half the digits next to 0 or pi, where a
    middle joint at 1e-9 came out 0 and the row 1e-9 off the pose.
    """
    Rhc = _mv(R, hc)
    vb_p, vb_m, real = _sp4(hb, ha, hc, _dot(ha, Rhc))
    if abs(float(ha @ hb)) <= _ORTHO and abs(float(hb @ hc)) <= _ORTHO:
        ypar = _dot(hb, hc)[..., None] * hb
        yp = hc - ypar
        phi = np.arctan2(_dot(ha, np.cross(hb, yp)), _dot(ha, yp))
        C = _dot(ha, Rhc) - _dot(ha, ypar)
        d = np.arctan2(np.linalg.norm(np.cross(ha, Rhc), axis=-1), C)
        near = ~(np.abs(np.clip(C / np.hypot(_dot(ha, yp), _dot(ha, np.cross(hb, yp))),
                                -1.0, 1.0)) <= 0.99)  # (elsewhere arccos is as exact)
        vb_p, vb_m = np.where(near, phi + d, vb_p), np.where(near, phi - d, vb_m)
    vb = np.stack([vb_p, vb_m], -1)  # (..., 2)
    Rb = _rot(hb, vb)  # (..., 2, 3, 3)
    Rx = R[..., None, :, :]
    va, spread = _sp1(ha, _mv(Rb, hc), _mv(Rx, hc)[..., :] + 0 * vb[..., None])
    singular = spread < 1e-9
    va = np.where(spread < _LINED, 0.0, va)
    B = _rot(ha, va) @ Rb
    e = _perp(hc)
    vc, _ = _sp1(hc, e + 0 * vb[..., None], _mv(np.swapaxes(B, -1, -2) @ Rx, e))
    v = np.stack([va, vb, vc], -1)
    return v, np.broadcast_to(real[..., None], vb.shape), singular


def _perp(h: np.ndarray) -> np.ndarray:
    e = np.eye(3)[int(np.argmin(np.abs(h)))]
    v = e - np.dot(e, h) * h
    out: np.ndarray = v / np.linalg.norm(v)
    return out


def _meet(h: np.ndarray, o: np.ndarray) -> tuple[float, np.ndarray]:
    from robokin.kinematics.ik.analytic.pieper import _meet as meet

    return meet(h, o)


@dataclass(frozen=True, eq=False)
class SwivelArm:
    """An SRS arm's constants for the swivel closed form (:func:`swivel_arm`).

    Attributes:
        h: Unit joint axes (7, 3) at zero chain values, base frame.
        o4: A point on the elbow axis (3,) [m].
        S: The shoulder point (3,) [m]; W: the wrist point at zero (3,) [m].
        M: The tool pose at zero chain values (4, 4).
        sign: Joint signs (7,); offset: joint offsets (7,) [rad].
        limits: Joint limits (7, 2) [rad].
        ref: The swivel's reference direction (axis 1) (3,).
        params: The compiled twin's parameter vector (``csrc/self_motion.c``).
    """

    h: np.ndarray
    o4: np.ndarray
    S: np.ndarray
    W: np.ndarray
    M: np.ndarray
    sign: np.ndarray
    offset: np.ndarray
    limits: np.ndarray
    ref: np.ndarray
    params: np.ndarray

    # ------------------------------------------------------------- the frame
    def frame(self, T: np.ndarray) -> dict[str, Any]:
        r"""Per-pose constants: the elbow roots and :math:`R_0, \psi_0` per elbow.

        Args:
            T: One pose (4, 4).

        Returns:
            A dict: ``u`` (3,) shoulder-wrist unit vector, ``v4`` (2,) elbow chain
            angles, ``elbow_real`` (2,), ``R0`` (2, 3, 3), ``psi0`` (2,), ``TR``
            (3, 3) the wrist triple's target before the swivel, ``ref_ok`` bool.
        """
        Minv = np.linalg.inv(self.M)
        Wt = (T @ Minv @ np.append(self.W, 1.0))[:3]
        w = Wt - self.S
        d = float(np.linalg.norm(w))
        u = w / d if d > 0 else np.array([0.0, 0.0, 1.0])
        h4 = self.h[3]
        p, q = self.W - self.o4, self.S - self.o4
        # |rot(h4, v) p - q| = d  <=>  q . rot(h4, v) p = (|p|^2 + |q|^2 - d^2) / 2
        vp, vm, real = _sp4(h4, q, p, np.array((p @ p + q @ q - d * d) / 2))
        v4 = np.array([vp, vm], dtype=np.float64)
        a = (self.o4 + _mv(_rot(h4, v4), p)) - self.S  # (2, 3)
        R0 = np.stack([_smallest_rotation(ai, w) for ai in a])
        r = self.ref - (self.ref @ u) * u
        ref_ok = bool(np.linalg.norm(r) > 1e-9)
        if not ref_ok:
            x = np.array([1.0, 0.0, 0.0])
            r = x - (x @ u) * u
        r = r / np.linalg.norm(r)
        psi0 = np.array([_angle_of(u, r, _mv(R0[i], h4)) for i in range(2)])
        TR = T[:3, :3] @ Minv[:3, :3]
        return {"u": u, "r": r, "v4": v4, "elbow_real": np.broadcast_to(real, (2,)).copy(),
                "R0": R0, "psi0": psi0, "TR": TR, "ref_ok": ref_ok}

    def configurations(self, fr: dict[str, Any], psi: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Every configuration at swivel angles psi (m,): q (m, 8, 7), valid, singular.

        Joint values are wrapped into (-pi, pi], then shifted by 2 pi into the limits
        where that puts them inside.
        """
        psi = np.atleast_1d(np.asarray(psi, dtype=np.float64))
        m = psi.shape[0]
        h = self.h
        v = np.full((m, 2, 2, 2, 7), np.nan)
        real = np.zeros((m, 2, 2, 2), bool)
        sing = np.zeros((m, 2, 2, 2), bool)
        for e in range(2):
            RA = _rot(fr["u"], psi - fr["psi0"][e]) @ fr["R0"][e]  # (m, 3, 3)
            sA, rA, gA = _triple(h[0], h[1], h[2], RA)  # (m, 2, 3)
            R4 = _rot(h[3], fr["v4"][e])
            RB = np.swapaxes(RA @ R4, -1, -2) @ fr["TR"]
            sB, rB, gB = _triple(h[4], h[5], h[6], RB)
            v[:, e, :, :, 0:3] = sA[:, :, None, :]
            v[:, e, :, :, 3] = fr["v4"][e]
            v[:, e, :, :, 4:7] = sB[:, None, :, :]
            real[:, e] = fr["elbow_real"][e] & rA[:, :, None] & rB[:, None, :]
            sing[:, e] = gA[:, :, None] | gB[:, None, :]
        q: np.ndarray = self.wrap((v.reshape(m, 8, 7) - self.offset) * self.sign)
        ok = real.reshape(m, 8)
        q[~ok] = np.nan
        return q, ok, sing.reshape(m, 8)

    def rows(self, T: np.ndarray, psi: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The compiled twin of :meth:`configurations` with the polish, batched.

        Args:
            T: Poses (N, 4, 4).
            psi: Swivel angles (N, m) [rad].

        Returns:
            ``(Q (N, m, 8, 7), valid (N, m, 8), singular (N, m, 8))``: every slot at
            every angle, rows whose pose error exceeds 1e-13 Newton-polished (up to 3
            minimum-norm steps, each kept where it lowers the error), rows still above
            5e-13 dropped (NaN, not valid).
        """
        T = np.ascontiguousarray(T, dtype=np.float64)
        psi = np.ascontiguousarray(psi, dtype=np.float64)
        N, m = psi.shape
        Q = np.empty((N, m, 8, 7))
        valid = np.empty((N, m, 8), bool)
        sing = np.empty((N, m, 8), bool)
        K.swivel_rows(self.params, T, psi, Q, valid, sing)
        return Q, valid, sing

    def manifold(self, T: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The exact in-limit swivel intervals of poses T (N, 4, 4), compiled.

        Returns:
            ``(iv (N, 8, SM_MAXI, 2), counts (N, 8), points (N, SM_MAXP, 4), npoints
            (N,))``: per branch its intervals (an interval across pi ends past pi);
            points as ``[psi, branch, joint, kind]`` with kind ``SM_KIND_LOWER``,
            ``_UPPER`` (a joint at that limit), ``_ALIGNED`` (a triple's outer axes
            in line) or ``_FOLD`` (a triple's middle angle at an end of its range).
        """
        T = np.ascontiguousarray(T, dtype=np.float64)
        N = len(T)
        iv = np.empty((N, 8, K.SM_MAXI, 2))
        niv = np.empty((N, 8), np.int64)
        pts = np.empty((N, K.SM_MAXP, 4))
        npts = np.empty(N, np.int64)
        K.swivel_manifold(self.params, T, iv, niv, pts, npts)
        return iv, niv, pts, npts

    def manifold_one(self, T: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
        """:meth:`manifold` of one pose T (4, 4, contiguous float64), packed.

        Returns:
            ``(intervals (m, 2), branch (m,), points (p, 4), close)``, new arrays: the
            intervals branch by branch (each branch's sorted), then the points, as
            :meth:`manifold` gives them (``robot.self_motion``'s call: no batch axes,
            no per-call output arrays or masking); ``close``: the decision of
            ``self_motion_intervals._points_refined``'s cheap test (two limit crossings
            of a branch within ``K.SM_PAIR`` in psi, one within it of +-pi, or an interval
            at most ``K.SM_POINT`` long), computed in the kernel.
        """
        return K.swivel_manifold_one(self.params, T)

    def nearest(self, T: np.ndarray, q_near: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The in-limit configuration of each pose nearest ``q_near``, compiled.

        On the exact intervals (:meth:`manifold`): per branch and interval the
        distance sampled at its ends and a 48-value swivel grid, the four smallest
        local minima refined by Brent's method, the best point Newton-polished and
        clamped into the limits (it is within 1e-12 of them).

        Args:
            T: Poses (N, 4, 4).
            q_near: Configurations (N, 7) [rad]; the distance is 2 pi wrapped.

        Returns:
            ``(q (N, 7), psi (N,), slot (N,), distance (N,), found (N,))``: NaN, -1,
            inf and False where no part of a pose's manifold is inside the limits.
        """
        T = np.ascontiguousarray(T, dtype=np.float64)
        qn = np.ascontiguousarray(q_near, dtype=np.float64)
        N = len(T)
        q = np.empty((N, 7))
        psi = np.empty(N)
        slot = np.empty(N, np.int64)
        dist = np.empty(N)
        found = np.empty(N, bool)
        K.swivel_near(self.params, T, qn, q, psi, slot, dist, found)
        return q, psi, slot, dist, found

    def wrap(self, q: np.ndarray) -> np.ndarray:
        """Angles into (-pi, pi], then by 2 pi into the limits where that fits."""
        q = wrap_angle(q)
        lo, hi = self.limits[:, 0], self.limits[:, 1]
        up = (q < lo) & (q + 2 * np.pi <= hi)
        down = (q > hi) & (q - 2 * np.pi >= lo)
        out: np.ndarray = q + 2 * np.pi * up - 2 * np.pi * down
        return out

    def swivel_of(self, fr: dict[str, Any], q: np.ndarray) -> np.ndarray:
        """The swivel angle [rad] of configurations q (..., 7) of the pose."""
        v = self.sign * np.asarray(q) + self.offset
        RA = _rot(self.h[0], v[..., 0]) @ _rot(self.h[1], v[..., 1]) @ _rot(self.h[2], v[..., 2])
        return _angle_of(fr["u"], fr["r"], _mv(RA, self.h[3]))

    def limit_swivels(self, fr: dict[str, Any], j: int, q_value: float
                      ) -> list[tuple[float, int]]:
        """Swivel angles where joint j (0-based, not the elbow) is at ``q_value``.

        Returns ``[(psi, elbow), ...]``: at most two per elbow root (subproblem 4).
        """
        L = self.sign[j] * q_value + self.offset[j]
        h = self.h
        u = fr["u"]
        out = []
        for e in range(2):
            if not fr["elbow_real"][e]:
                continue
            R0, TR = fr["R0"][e], fr["TR"]
            R4 = _rot(h[3], fr["v4"][e])
            if j < 3:
                a, b, c = h[0], h[1], h[2]
                if j == 0:
                    x, y, k = _mv(_rot(a, L), b), R0 @ c, b @ c
                elif j == 1:
                    x, y, k = a, R0 @ c, a @ _mv(_rot(b, L), c)
                else:
                    x, y, k = a, R0 @ _mv(_rot(c, -L), b), a @ b
                sgn = 1.0
            else:
                a, b, c = h[4], h[5], h[6]
                base = R0 @ R4
                if j == 4:
                    x, y, k = base @ _mv(_rot(a, L), b), TR @ c, b @ c
                elif j == 5:
                    x, y, k = base @ a, TR @ c, a @ _mv(_rot(b, L), c)
                else:
                    x, y, k = base @ a, TR @ _mv(_rot(c, -L), b), a @ b
                sgn = -1.0  # R_B holds rot(u, -phi)
            tp, tm, real = _sp4(u, x, y, np.array(k))
            if not bool(real):
                continue
            for phi in {float(tp), float(tm)}:
                psi = sgn * phi + fr["psi0"][e]
                out.append((float(wrap_angle(psi)), e))
        return out


def _angle_of(u: np.ndarray, r: np.ndarray, h4: np.ndarray) -> np.ndarray:
    """Swivel angle: about u from r to u x h4 (normalised)."""
    d = np.cross(u, h4)
    out: np.ndarray = np.arctan2(_dot(u, np.cross(r, d)), _dot(r, d))
    return out


def _smallest_rotation(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The smallest rotation taking the direction of a to that of b (3, 3)."""
    na, nb = np.linalg.norm(a), np.linalg.norm(b)
    if na == 0 or nb == 0:
        return np.eye(3)
    a, b = a / na, b / nb
    axis = np.cross(a, b)
    s, c = np.linalg.norm(axis), float(a @ b)
    if s < 1e-15:
        if c > 0:
            return np.eye(3)
        return _rot(_perp(a), np.array(np.pi))
    return _rot(axis / s, np.array(np.arctan2(s, c)))


def swivel_arm(chain: Any) -> SwivelArm | None:
    """The swivel constants of a 7R chain whose axes 1-3 and 5-7 meet, else None."""
    if chain.n_chain != 7 or not chain.coupling.is_identity:
        return None
    poe = poe_from_chain(chain)
    if poe.prismatic.any():
        return None
    pts = np.vstack([poe.o, poe.M[:3, 3]])
    scale = float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())
    lim = _MEET_TOL * max(1.0, scale)
    dS, S = _meet(poe.h[0:3], poe.o[0:3])
    dW, W = _meet(poe.h[4:7], poe.o[4:7])
    if dS > lim or dW > lim:
        return None
    # the elbow axis must be off the shoulder-wrist plane's degenerate cases
    if np.linalg.norm(np.cross(poe.h[3], S - poe.o[3])) < lim:
        return None
    lims = np.asarray(chain.limits, dtype=np.float64)
    sign = np.asarray(chain.arrays.sign, dtype=np.float64).copy()
    offset = np.asarray(chain.arrays.offset, dtype=np.float64).copy()
    return SwivelArm(poe.h.copy(), poe.o[3].copy(), S, W, poe.M.copy(), sign, offset,
                     lims, poe.h[0].copy(), _pack(poe.h, poe.o, S, W, poe.M, sign, offset,
                                                  lims))


def _pack(h: np.ndarray, o: np.ndarray, S: np.ndarray, W: np.ndarray, M: np.ndarray,
          sign: np.ndarray, offset: np.ndarray, limits: np.ndarray) -> np.ndarray:
    """The parameter vector of ``csrc/self_motion.c`` (its SM_ layout)."""
    P = np.zeros(K.SM_N_PARAMS)
    P[K.SM_H:K.SM_H + 21] = h.ravel()
    P[K.SM_O:K.SM_O + 21] = o.ravel()
    P[K.SM_S:K.SM_S + 3] = S
    P[K.SM_W:K.SM_W + 3] = W
    P[K.SM_MR:K.SM_MR + 9] = M[:3, :3].ravel()
    P[K.SM_MT:K.SM_MT + 3] = M[:3, 3]
    for at, v in ((K.SM_SIGN, sign), (K.SM_OFFSET, offset), (K.SM_LO, limits[:, 0]),
                  (K.SM_HI, limits[:, 1])):
        P[at:at + 7] = v
    P[K.SM_REF:K.SM_REF + 3] = h[0]
    P[K.SM_TAG] = K.SM_TAG_VALUE
    _pack_quick(P, h, sign, offset, limits)
    return P


#: The quick tests' margin [rad] and pad (``csrc/self_motion.c`` SM_QUICK_M, _PAD).
_QUICK_M, _QUICK_PAD = 1e-6, 5e-8


def _pack_quick(P: np.ndarray, h: np.ndarray, sign: np.ndarray, offset: np.ndarray,
                limits: np.ndarray) -> None:
    """The quick tests' constants (SM_ARC, SM_LIMCS, SM_FOLDCS; self_motion.c says how).

    Rounding here does not matter: each test is certain by a margin of ~5e-8 or more.
    """
    for j in (0, 1, 2, 4, 5, 6):
        lo, hi = float(limits[j, 0]), float(limits[j, 1])
        for s, lim in enumerate((lo, hi)):
            L = sign[j] * lim + offset[j]
            P[K.SM_LIMCS + 4 * j + 2 * s:K.SM_LIMCS + 4 * j + 2 * s + 2] = np.cos(L), np.sin(L)
        arc = (0.0, 0.0, 2.0, -2.0)  # never certain: the exact test
        w = 0.5 * (hi - lo)
        if -np.pi <= lo < hi <= np.pi and _QUICK_M < w < np.pi - _QUICK_M:
            vc = offset[j] + sign[j] * 0.5 * (lo + hi)
            arc = (np.cos(vc), np.sin(vc), np.cos(w - _QUICK_M) + _QUICK_PAD,
                   np.cos(w + _QUICK_M) - _QUICK_PAD)
        P[K.SM_ARC + 4 * j:K.SM_ARC + 4 * j + 4] = arc
    for t in range(2):  # the middle angle where a triple's outer axes are nearest
        ha, hb, hc = h[4 * t], h[4 * t + 1], h[4 * t + 2]
        hp = hc - hb * (hb @ hc)
        A, B = ha @ hp, ha @ np.cross(hb, hp)
        P[K.SM_FOLDCS + 2 * t:K.SM_FOLDCS + 2 * t + 2] = np.array([A, B]) / np.hypot(A, B)
