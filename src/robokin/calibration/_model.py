r"""The identification model: a product of elementary motions with parameters.

.. math::

    T(q) = B_0 E_B(\delta_B) \, L_0 \, J_1(u_1) R_1 \, J_2(u_2) R_2 \cdots
           J_n(u_n) \, C_{flange} \, T_0 E_T(\delta_T)

``B_0`` and ``T_0`` are the registered base and the nominal tool, ``E(\delta) =
Tx Ty Tz Rz Ry Rx`` a local correction (6 parameters), ``R_k`` the identification
row from joint axis k to k+1 (:mod:`robokin.calibration._frames`: DH or Hayati,
parameters ``theta, d, a, alpha`` or ``theta, a, alpha, beta``) and
``C_{flange}`` the nominal transform from the last axis frame to the flange.
Parameters are deviations from nominal, so ``x = 0`` is the nominal robot at
the registered base.

The parameter Jacobian is exact and analytic: a rotation parameter about unit
axis ``w`` through ``o`` moves the tool point ``p`` by ``w x (p - o)`` and turns
it by ``w``; a translation along ``w`` moves it by ``w`` (the screw of the
elementary motion, in the measuring frame).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from robokin.calibration._frames import Row, joint_frames, row_matrix, rows_from_axes
from robokin.model.chain import Chain, ChainBuilder, Joint
from robokin.model.coupling import AffineMap
from robokin.spatial import invert, rotx, roty, rotz, trans

__all__ = ["Evaluation", "Model", "PoseSide"]

_AXES = {"x": 0, "y": 1, "z": 2}
_POSE_NAMES = ("x", "y", "z", "yaw", "pitch", "roll")  # order of E: Tx Ty Tz Rz Ry Rx
_POSE_OPS = ("tx", "ty", "tz", "rz", "ry", "rx")
PoseSide = tuple[str, ...]


_ROT_COLS = {"x": (1, 2), "y": (2, 0), "z": (0, 1)}


def _apply(F: np.ndarray, op: str, v: np.ndarray | float) -> None:
    """``F <- F @ E(op, v)`` in place for frames F (N, 4, 4), by column operations."""
    if op[0] == "t":
        F[:, :3, 3] += F[:, :3, _AXES[op[1]]] * np.reshape(v, (-1, 1))
        return
    i, j = _ROT_COLS[op[1]]
    c = np.reshape(np.cos(v), (-1, 1))
    s = np.reshape(np.sin(v), (-1, 1))
    fi = F[:, :3, i].copy()
    F[:, :3, i] = c * fi + s * F[:, :3, j]
    F[:, :3, j] = c * F[:, :3, j] - s * fi


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross product of (N, 3) arrays."""
    return np.stack([a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1],
                     a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
                     a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]], axis=1)


def _elementary(op: str, v: np.ndarray | float) -> np.ndarray:
    if op[0] == "r":
        return {"x": rotx, "y": roty, "z": rotz}[op[1]](v)
    vec = np.zeros(np.shape(v) + (3,))
    vec[..., _AXES[op[1]]] = v
    return trans(vec)


@dataclass(frozen=True)
class Step:
    """One factor of the product.

    Attributes:
        op: ``"const"``, ``"joint"``, an elementary ``"tx" .. "rz"``, or the
            placeholders ``"base"`` and ``"tool"`` (``B_0``, ``T_0``: given at
            evaluation).
        value: The constant (4, 4), or the nominal value of an elementary step.
        param: Index into the full parameter vector, or -1 (fixed).
        joint: The chain joint index of a ``"joint"`` step.
    """

    op: str
    value: np.ndarray | float = 0.0
    param: int = -1
    joint: int = -1


@dataclass(frozen=True)
class Evaluation:
    """Model output for N poses.

    Attributes:
        T: Tool poses (N, 4, 4) in the measuring frame.
        Jp: d position / d parameter (N, 3, p) for the active parameters.
        Jr: d rotation / d parameter (N, 3, p) (base-frame rotation vector).
    """

    T: np.ndarray
    Jp: np.ndarray | None = None
    Jr: np.ndarray | None = None


@dataclass(frozen=True)
class Model:
    """The parametric model of one nominal chain (built by :meth:`from_chain`).

    Attributes:
        chain: The nominal canonical chain.
        names: Full parameter names (P,): ``base.*``, ``jK.theta`` ..., extras,
            ``tool.*``.
        kinds: ``"length"``, ``"angle"``, ``"scale"`` or ``"compliance"`` per name.
        nominal: Nominal parameter values (P,) (0 for base and tool corrections).
        rows: The identification rows (n_chain - 1).
        frames: Identification frames ``D_k`` at zero joint motion (base frame).
        flange: ``D_n^{-1}`` times the nominal last joint frame times ``C_n``.
        scale: Per chain joint, the index of its gear-ratio parameter or -1.
        compliance: Per chain joint, the index of its compliance parameter or -1.
    """

    chain: Chain
    names: tuple[str, ...]
    kinds: tuple[str, ...]
    nominal: np.ndarray
    rows: tuple[Row, ...]
    frames: np.ndarray
    flange: np.ndarray
    scale: tuple[int, ...]
    compliance: tuple[int, ...]
    steps: tuple[Step, ...] = field(repr=False, default=())

    @classmethod
    def from_chain(cls, chain: Chain, *, parallel_tol: float,
                   extras: tuple[str, ...] = ()) -> Model:
        """Build the model of a chain (see the module docstring)."""
        W = joint_frames(chain)
        rows, D = rows_from_axes(W, parallel_tol)
        n = chain.n_chain
        names: list[str] = []
        kinds: list[str] = []
        nominal: list[float] = []

        def add(name: str, kind: str, value: float) -> int:
            names.append(name)
            kinds.append(kind)
            nominal.append(value)
            return len(names) - 1

        steps: list[Step] = [Step("base")]  # B0: supplied at evaluation
        for nm, op in zip(_POSE_NAMES, _POSE_OPS):
            steps.append(Step(op, 0.0, add(f"base.{nm}", "length" if op[0] == "t"
                                           else "angle", 0.0)))
        steps.append(Step("const", np.array(chain.head)))
        scale = [-1] * n
        comp = [-1] * n
        for k in range(n):
            j = k + 1
            if "scale" in extras:
                scale[k] = add(f"j{j}.scale", "scale", 0.0)
            if "compliance" in extras:
                comp[k] = add(f"j{j}.compliance", "compliance", 0.0)
            steps.append(Step("joint", joint=k))
            if k == n - 1:
                break
            r = rows[k]
            offset = chain.joints[k].offset
            theta0 = r.theta + (offset if chain.joints[k].kind == "revolute" else 0.0)
            steps.append(Step("rz", r.theta, add(f"j{j}.theta", "angle", theta0)))
            d0 = r.d + (offset if chain.joints[k].kind == "prismatic" else 0.0)
            if r.form == "dh":
                steps.append(Step("tz", r.d, add(f"j{j}.d", "length", d0)))
            else:
                steps.append(Step("tz", r.d))
            steps.append(Step("tx", r.a, add(f"j{j}.a", "length", r.a)))
            steps.append(Step("rx", r.alpha, add(f"j{j}.alpha", "angle", r.alpha)))
            if r.form == "hayati":
                steps.append(Step("ry", r.beta, add(f"j{j}.beta", "angle", r.beta)))
        flange = invert(D[-1]) @ W[-1] @ chain.frame_offsets[-1] @ chain.link_offsets[-1]
        steps.append(Step("const", flange))
        steps.append(Step("tool"))  # T0: supplied at evaluation
        for nm, op in zip(_POSE_NAMES, _POSE_OPS):
            steps.append(Step(op, 0.0, add(f"tool.{nm}", "length" if op[0] == "t"
                                           else "angle", 0.0)))
        return cls(chain=chain, names=tuple(names), kinds=tuple(kinds),
                   nominal=np.array(nominal), rows=tuple(rows), frames=D,
                   flange=flange, scale=tuple(scale), compliance=tuple(comp),
                   steps=tuple(steps))

    @property
    def size(self) -> int:
        """Number of candidate parameters."""
        return len(self.names)

    def index(self, name: str) -> int:
        """The position of a parameter name (ValueError if unknown)."""
        return self.names.index(name)

    # ------------------------------------------------------------------ evaluation
    def joint_values(self, q: np.ndarray, x: np.ndarray,
                     torque: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
        """Chain joint values ``u`` (N, n_chain) and the chain values ``v`` (N, n_chain)."""
        chain = self.chain
        v = chain.coupling.apply(q)
        sign = np.array([j.sign for j in chain.joints])
        off = np.array([j.offset for j in chain.joints])
        u = sign * v + off
        for k in range(chain.n_chain):
            if self.scale[k] >= 0:
                u[:, k] += sign[k] * v[:, k] * x[self.scale[k]]
            if self.compliance[k] >= 0 and torque is not None:
                u[:, k] += torque[:, k] * x[self.compliance[k]]
        return u, v

    def evaluate(self, q: np.ndarray, x: np.ndarray, base: np.ndarray,
                 tool: np.ndarray, active: np.ndarray | None = None, *,
                 torque: np.ndarray | None = None) -> Evaluation:
        """Tool poses, and the Jacobian for the ``active`` parameters if given.

        Args:
            q: Joint coordinates (N, n).
            x: Full parameter vector (P,) (deviations from nominal).
            base: Registered base ``B_0`` (4, 4).
            tool: Nominal tool ``T_0`` (4, 4).
            active: Indices of the parameters to differentiate, or None.
            torque: Joint torques (N, n_chain) for compliance parameters.
        """
        N = q.shape[0]
        u, v = self.joint_values(q, x, torque)
        col = {} if active is None else {int(i): c for c, i in enumerate(active)}
        screws: list[tuple[int, str, np.ndarray, float | np.ndarray]] = []
        F = np.array(base, dtype=float)[None]  # (1, 4, 4) until the first joint
        for st in self.steps:
            if st.op == "base":
                continue  # F starts at the base
            if st.op in ("const", "tool"):
                F = F @ (tool if st.op == "tool" else st.value)
                continue
            if st.op == "joint":
                k = st.joint
                if F.shape[0] != N:
                    F = np.repeat(F, N, axis=0)
                kind = self.chain.joints[k].kind
                op = "rz" if kind == "revolute" else "tz"
                for idx, scale in ((self.scale[k], self.chain.joints[k].sign * v[:, k]),
                                   (self.compliance[k],
                                    None if torque is None else torque[:, k])):
                    if idx in col and scale is not None:
                        screws.append((col[idx], op, F.copy(), scale))
                _apply(F, op, u[:, k])
                continue
            value = st.value if st.param < 0 else st.value + x[st.param]
            if st.param in col:
                screws.append((col[st.param], st.op, F.copy(), 1.0))
            _apply(F, st.op, value)
        if F.shape[0] != N:
            F = np.repeat(F, N, axis=0)
        if active is None:
            return Evaluation(F)
        return Evaluation(F, *self._jacobian(F, screws, len(col)))

    @staticmethod
    def _jacobian(T: np.ndarray, screws: list, p: int) -> tuple[np.ndarray, np.ndarray]:
        N = T.shape[0]
        Jp = np.zeros((N, 3, p))
        Jr = np.zeros((N, 3, p))
        P = T[:, :3, 3]
        for c, op, F, scale in screws:
            w = F[:, :3, _AXES[op[1]]]
            if op[0] == "r":
                Jp[:, :, c] += _cross(w, P - F[:, :3, 3]) * np.reshape(scale, (-1, 1))
                Jr[:, :, c] += w * np.reshape(scale, (-1, 1))
            else:
                Jp[:, :, c] += w * np.reshape(scale, (-1, 1))
        return Jp, Jr

    # ------------------------------------------------------------------ building
    def pose_correction(self, x: np.ndarray, side: str) -> np.ndarray:
        """``E(delta)`` of ``side`` (``"base"`` or ``"tool"``) for parameters ``x``."""
        start = self.index(f"{side}.x")
        E = np.eye(4)
        for i, op in enumerate(_POSE_OPS):
            E = E @ _elementary(op, x[start + i])
        return E

    def chain_at(self, x: np.ndarray, base: np.ndarray, tool: np.ndarray) -> Chain:
        """The canonical chain of parameters ``x``, in the identification frames.

        Same joints (joint-offset corrections go into the joints' offsets), the
        coupling scaled by gear-ratio corrections, base ``base E_B`` and tool
        ``tool E_T``.
        """
        chain = self.chain
        n = chain.n_chain
        b = ChainBuilder().constant(chain.head)
        joints = list(chain.joints)
        for k in range(n):
            j = joints[k]
            if k < n - 1:
                r = self.rows[k]
                t_i = self.index(f"j{k + 1}.theta")
                dth = x[t_i]
                dd = x[self.index(f"j{k + 1}.d")] if r.form == "dh" else 0.0
                da = x[self.index(f"j{k + 1}.a")]
                dal = x[self.index(f"j{k + 1}.alpha")]
                dbe = x[self.index(f"j{k + 1}.beta")] if r.form == "hayati" else 0.0
                # the joint's own offset error goes into the joint (it commutes)
                if j.kind == "revolute":
                    off, dth = j.offset + dth, 0.0
                else:
                    off, dd = j.offset + dd, 0.0
                j = Joint(j.name, j.kind, j.limits, j.sign, off)
                new = Row(r.form, r.theta + dth, r.d + dd, r.a + da, r.alpha + dal,
                          r.beta + dbe)
                C = row_matrix(new)
            else:
                C = self.flange
            joints[k] = j
            b.joint(j).constant(C).frame()
        coupling = chain.coupling
        sc = np.array([x[i] if i >= 0 else 0.0 for i in self.scale])
        if sc.any():
            coupling = AffineMap(coupling.matrix * (1.0 + sc)[:, None],
                                 coupling.offset * (1.0 + sc))
        coordinates = chain.coordinates
        if chain.coupling.is_identity:
            coordinates = tuple(joints)
        T_base = base @ self.pose_correction(x, "base")
        T_tool = tool @ self.pose_correction(x, "tool")
        return b.build(base=T_base, tool=T_tool, coordinates=coordinates,
                       coupling=None if coupling.is_identity else coupling)


def pose_values(T: np.ndarray) -> np.ndarray:
    """``x, y, z, roll, pitch, yaw`` of a pose [m, rad] (RPY as robot files use)."""
    from robokin.spatial import rpy_from_matrix

    return np.concatenate([T[:3, 3], rpy_from_matrix(T)])


def angle_between(a: np.ndarray, b: np.ndarray) -> float:
    """Angle [rad] between two unit vectors."""
    return math.atan2(float(np.linalg.norm(np.cross(a, b))), float(a @ b))
