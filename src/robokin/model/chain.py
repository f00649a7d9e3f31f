r"""The canonical kinematic chain every robot model compiles to.

.. math::

    T(q) = B \cdot L_0 \cdot J_1 F_1 G_1 \cdot J_2 F_2 G_2 \cdots J_n F_n G_n \cdot T_{tool}

``J_k`` is a rotation about (revolute) or translation along (prismatic) the local z
axis by ``sign_k * q_chain_k + offset_k``. ``F_k`` places the frame of link k
after joint k (the frame that ``fk_all`` reports); ``G_k`` carries on to just
before the next joint (virtual frames and the next row's leading constants).
``q_chain = M q + c`` (:class:`~robokin.model.coupling.AffineMap`) derives every
chain joint from the robot's independent coordinates ``q``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from robokin._validation import check_finite, check_joints
from robokin.exceptions import InputError, ModelError
from robokin.model.chain_arrays import MAX_JOINTS, ChainArrays, chain_arrays
from robokin.model.coupling import AffineMap

__all__ = ["Chain", "ChainBuilder", "Joint", "JointKind", "joint_motion"]

JointKind = Literal["revolute", "prismatic"]


@dataclass(frozen=True)
class Joint:
    """One joint (or independent coordinate) of a chain.

    Attributes:
        name: Unique name.
        kind: ``"revolute"`` (value in rad) or ``"prismatic"`` (value in m).
        limits: ``(lower, upper)`` in SI units; ``(-inf, inf)`` when unlimited.
        sign: +1, or -1 for a reversed axis.
        offset: The chain value at zero joint coordinate [rad or m].
    """

    name: str
    kind: JointKind = "revolute"
    limits: tuple[float, float] = (-math.inf, math.inf)
    sign: float = 1.0
    offset: float = 0.0

    def __post_init__(self) -> None:
        """Check the kind, sign and limits; store them as floats."""
        if self.kind not in ("revolute", "prismatic"):
            raise ModelError(
                f"joint '{self.name}': kind must be 'revolute' or 'prismatic', got {self.kind!r}"
            )
        if self.sign not in (1.0, -1.0):
            raise ModelError(
                f"joint '{self.name}': sign must be +1 or -1, got {self.sign}"
            )
        lo, hi = (float(v) for v in self.limits)
        if math.isnan(lo) or math.isnan(hi) or lo > hi:
            raise ModelError(
                f"joint '{self.name}': limits must be [lower, upper] with lower <= upper, "
                f"got {list(self.limits)}"
            )
        object.__setattr__(self, "limits", (lo, hi))
        object.__setattr__(self, "sign", float(self.sign))
        object.__setattr__(self, "offset", float(self.offset))


def _ro(a: npt.ArrayLike) -> npt.NDArray[np.float64]:
    out = np.ascontiguousarray(a, dtype=np.float64)
    out.setflags(write=False)
    return out


def joint_motion(kind: JointKind, value: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """The joint's own transform ``J(v)``: a rotation about or translation along z.

    Args:
        kind: ``"revolute"`` or ``"prismatic"``.
        value: Chain joint values ``v`` [rad or m], shape (...).

    Returns:
        Transforms (..., 4, 4).
    """
    v = np.asarray(value, dtype=np.float64)
    out = np.zeros(v.shape + (4, 4))
    out[..., 0, 0] = out[..., 1, 1] = out[..., 2, 2] = out[..., 3, 3] = 1.0
    if kind == "revolute":
        c, s = np.cos(v), np.sin(v)
        out[..., 0, 0], out[..., 0, 1], out[..., 1, 0], out[..., 1, 1] = c, -s, s, c
    else:
        out[..., 2, 3] = v
    return out


@dataclass(frozen=True, eq=False, init=False)
class Chain:
    """An immutable canonical chain (see the module docstring).

    Attributes:
        joints: The chain joints, in order (n_chain).
        head: ``L_0``, (4, 4).
        frame_offsets: ``F_k``, (n_chain, 4, 4).
        link_offsets: ``G_k``, (n_chain, 4, 4).
        base: The base transform ``B``, (4, 4).
        tool: The tool transform, (4, 4).
        coordinates: The independent coordinates (n) with their limits.
        coupling: ``q_chain = M q + c``, an AffineMap (n_chain x n).
        arrays: What the compiled kernels read (built here, see
            :mod:`robokin.model.chain_arrays`).
    """

    joints: tuple[Joint, ...]
    head: npt.NDArray[np.float64]
    frame_offsets: npt.NDArray[np.float64]
    link_offsets: npt.NDArray[np.float64]
    base: npt.NDArray[np.float64]
    tool: npt.NDArray[np.float64]
    coordinates: tuple[Joint, ...]
    coupling: AffineMap
    arrays: ChainArrays = field(init=False, repr=False)

    def __init__(
        self,
        joints: tuple[Joint, ...],
        head: npt.ArrayLike,
        frame_offsets: npt.ArrayLike,
        link_offsets: npt.ArrayLike,
        base: npt.ArrayLike | None = None,
        tool: npt.ArrayLike | None = None,
        coordinates: tuple[Joint, ...] | None = None,
        coupling: AffineMap | None = None,
    ) -> None:
        """Check and freeze the parts; build the kernels' arrays.

        Args:
            joints: The chain joints, in order (n_chain).
            head: ``L_0`` [m], shape (4, 4).
            frame_offsets: ``F_k`` [m], shape (n_chain, 4, 4).
            link_offsets: ``G_k`` [m], shape (n_chain, 4, 4).
            base: The base transform [m], shape (4, 4); the identity if None.
            tool: The tool transform [m], shape (4, 4); the identity if None.
            coordinates: The independent coordinates (n); the joints if None.
            coupling: ``q_chain = M q + c`` (n_chain x n); the identity if None
                (then the coordinates must be as many as the joints).

        Raises:
            ModelError: no joints, repeated joint names, a part of the wrong shape or not
                finite, a coupling that does not fit, more than
                :data:`~robokin.model.chain_arrays.MAX_JOINTS` joints.
        """
        init = object.__setattr__
        init(self, "joints", joints)
        nc = len(joints)
        if nc == 0:
            raise ModelError("a robot needs at least one joint")
        names = [j.name for j in joints]
        if len(set(names)) != nc:
            dup = sorted({x for x in names if names.count(x) > 1})
            raise ModelError(f"joint names must be unique, repeated: {dup}")
        for attr, value, shape in (
            ("head", head, (4, 4)),
            ("frame_offsets", frame_offsets, (nc, 4, 4)),
            ("link_offsets", link_offsets, (nc, 4, 4)),
            ("base", np.eye(4) if base is None else base, (4, 4)),
            ("tool", np.eye(4) if tool is None else tool, (4, 4)),
        ):
            arr = np.asarray(value, dtype=np.float64)
            if arr.shape != shape:
                raise ModelError(f"{attr} must have shape {shape}, got {arr.shape}")
            if not np.isfinite(arr).all():
                raise ModelError(f"{attr} holds a non-finite value")
            init(self, attr, _ro(arr))
        if coordinates is None:
            coordinates = tuple(joints)
        init(self, "coordinates", coordinates)
        n = len(coordinates)
        if coupling is None:
            if n != nc:
                raise ModelError(
                    "a chain whose coordinates differ from its joints needs a coupling"
                )
            coupling = AffineMap.identity(nc)
        init(self, "coupling", coupling)
        if coupling.matrix.shape != (nc, n):
            raise ModelError(
                f"coupling matrix must have shape ({nc}, {n}), got {coupling.matrix.shape}"
            )
        if nc > MAX_JOINTS or n > MAX_JOINTS:
            raise ModelError(
                f"a chain of {nc} joints and {n} coordinates: robokin takes at most "
                f"{MAX_JOINTS} of each"
            )
        init(self, "arrays", chain_arrays(
            head=self.head, frame_offsets=self.frame_offsets,
            link_offsets=self.link_offsets, base=self.base, tool=self.tool,
            kind=np.array([j.kind == "prismatic" for j in self.joints], dtype=np.float64),
            sign=np.array([j.sign for j in self.joints], dtype=np.float64),
            offset=np.array([j.offset for j in self.joints], dtype=np.float64),
            M=np.asarray(self.coupling.matrix, dtype=np.float64).reshape(nc, n),
            c=np.asarray(self.coupling.offset, dtype=np.float64).reshape(nc),
            limits=np.array([co.limits for co in self.coordinates], dtype=np.float64),
            is_revolute=np.array([co.kind == "revolute" for co in self.coordinates]),
            identity=bool(self.coupling.is_identity)))

    @property
    def n(self) -> int:
        """Number of independent joint coordinates."""
        return len(self.coordinates)

    @property
    def n_chain(self) -> int:
        """Number of chain joints (independent plus dependent)."""
        return len(self.joints)

    @property
    def limits(self) -> np.ndarray:
        """Limits of the independent coordinates, (n, 2), SI units (read-only)."""
        return self.arrays.limits

    @property
    def is_revolute(self) -> np.ndarray:
        """Boolean (n,): which independent coordinates are angles."""
        return np.array([c.kind == "revolute" for c in self.coordinates])

    def frames_at(self, q_chain: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Where each chain joint acts, and the tool pose, for one set of joint values.

        The model's one walk along the chain, for questions about its geometry
        (joint axes, DH tables, file export); forward kinematics, link frames and
        Jacobians of configurations are the compiled kernels' (``chain.h``).

        Args:
            q_chain: Chain joint coordinates ``q_chain = M q + c`` (the coupling
                applied, before each joint's sign and offset) [rad, m], shape
                (n_chain,). Zeros put every joint at its zero offset.

        Returns:
            (n_chain + 1, 4, 4): entry k < n_chain is the frame joint k turns
            about (revolute) or slides along (prismatic), its z axis, in the
            world frame, ``C_0 J_1 C_1 ... J_k C_k`` (0-based: the base and head
            for k = 0); the last entry is the tool pose ``T``.

        Raises:
            InputError: ``q_chain`` does not hold n_chain finite values.
        """
        qc = check_finite(check_joints(q_chain, self.n_chain, "q_chain"), "q_chain")
        if qc.shape != (self.n_chain,):
            raise InputError("q_chain", f"expected one configuration ({self.n_chain},), "
                             f"got shape {qc.shape}")
        consts = self.arrays.consts
        out = np.empty((self.n_chain + 1, 4, 4))
        out[0] = consts[0]
        for k, joint in enumerate(self.joints):
            move = joint_motion(joint.kind, joint.sign * qc[k] + joint.offset)
            out[k + 1] = out[k] @ move @ consts[k + 1]
        return out

    def with_fixed(self, values: Mapping[int, float]) -> Chain:
        """The chain with some independent coordinates held at given values.

        Args:
            values: Coordinate index -> value [rad or m].

        Returns:
            A chain of the remaining coordinates (their order kept): each fixed
            value folds into the coupling offset, and a chain joint left driven by
            fixed coordinates alone becomes a constant transform (its link frame
            goes with it). Base and tool are unchanged.

        Raises:
            ModelError: an index out of range, a non-finite value, or no coordinate
                left.
        """
        n = self.n
        fixed = {}
        for j, v in values.items():
            if not 0 <= int(j) < n:
                raise ModelError(f"coordinate index {j} out of range for {n} coordinates")
            if not math.isfinite(float(v)):
                raise ModelError(f"fixed value of coordinate {j} is not finite: {v!r}")
            fixed[int(j)] = float(v)
        keep = [j for j in range(n) if j not in fixed]
        if not keep:
            raise ModelError("every coordinate is fixed: nothing left to solve for")
        M = self.coupling.matrix
        c = self.coupling.offset + sum(M[:, j] * v for j, v in fixed.items())
        Mk = M[:, keep]
        builder = ChainBuilder()
        builder.constant(self.head)
        rows = []
        for k, joint in enumerate(self.joints):
            if Mk[k].any():
                builder.joint(joint)
                builder.constant(self.frame_offsets[k])
                builder.frame()
                builder.constant(self.link_offsets[k])
                rows.append(k)
                continue
            move = joint_motion(joint.kind, joint.sign * c[k] + joint.offset)
            builder.constant(move @ self.frame_offsets[k] @ self.link_offsets[k])
        coordinates = tuple(self.coordinates[j] for j in keep)
        coupling = AffineMap(Mk[rows], c[rows])
        return builder.build(base=self.base, tool=self.tool, coordinates=coordinates,
                             coupling=None if coupling.is_identity else coupling)

    def replace(self, **changes: Any) -> Chain:
        """A copy with some fields replaced (e.g. ``base=`` or ``tool=``)."""
        kw: dict[str, Any] = {
            "joints": self.joints,
            "head": self.head,
            "frame_offsets": self.frame_offsets,
            "link_offsets": self.link_offsets,
            "base": self.base,
            "tool": self.tool,
            "coordinates": self.coordinates,
            "coupling": self.coupling,
        }
        kw.update(changes)
        return Chain(**kw)


class ChainBuilder:
    """Assemble a Chain from constants and joints in order.

    Call :meth:`constant` for fixed transforms, :meth:`joint` for a joint, and
    :meth:`frame` to mark where the link frame of the last joint sits (by default it
    is marked right before the next joint, or at the end).
    """

    def __init__(self) -> None:
        """An empty builder: no joint yet, the head the identity."""
        self._head = np.eye(4)
        self._joints: list[Joint] = []
        self._F: list[np.ndarray] = []
        self._G: list[np.ndarray] = []
        self._marked = True  # no joint yet: constants go to the head

    def constant(self, T: np.ndarray) -> ChainBuilder:
        """Append a constant transform (4, 4)."""
        T = np.asarray(T, dtype=np.float64)
        if not self._joints:
            self._head = self._head @ T
        elif not self._marked:
            self._F[-1] = self._F[-1] @ T
        else:
            self._G[-1] = self._G[-1] @ T
        return self

    def joint(self, joint: Joint) -> ChainBuilder:
        """Append a joint moving about / along the current local z axis."""
        self._marked = False
        self._joints.append(joint)
        self._F.append(np.eye(4))
        self._G.append(np.eye(4))
        return self

    def frame(self) -> ChainBuilder:
        """Mark the current position as the link frame of the last joint."""
        self._marked = True
        return self

    def build(
        self,
        *,
        base: np.ndarray | None = None,
        tool: np.ndarray | None = None,
        coordinates: tuple[Joint, ...] | None = None,
        coupling: AffineMap | None = None,
    ) -> Chain:
        """The finished chain."""
        if not self._joints:
            raise ModelError("a robot needs at least one joint")
        return Chain(
            joints=tuple(self._joints),
            head=self._head,
            frame_offsets=np.array(self._F),
            link_offsets=np.array(self._G),
            base=np.eye(4) if base is None else base,
            tool=np.eye(4) if tool is None else tool,
            coordinates=coordinates,
            coupling=coupling,
        )
