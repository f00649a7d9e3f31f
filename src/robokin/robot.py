"""The Robot: a canonical chain plus its name, source, actuators, geometry, limits.

A Robot is immutable: assigning or deleting an attribute raises
:class:`~robokin.exceptions.FrozenError`, its arrays are read-only and ``meta`` is
a read-only mapping; ``with_tool`` / ``with_base`` / ``replace`` return new ones.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, Literal, TypeGuard

import numpy as np
import numpy.typing as npt

from robokin._validation import check_transform
from robokin.exceptions import FrozenError, InputError
from robokin.kinematics import forward
from robokin.kinematics import jacobian as _jac
from robokin.kinematics.ik.dispatch import solve as _ik_solve
from robokin.kinematics.ik.nearest import solve_near as _solve_near
from robokin.kinematics.ik.self_motion import SelfMotion
from robokin.kinematics.ik.self_motion import self_motion as _self_motion
from robokin.model.chain import Chain
from robokin.model.coupling import AffineMap
from robokin.model.rate_limits import RateLimits

if TYPE_CHECKING:
    from robokin.kinematics.ik.numeric import IKResult
    from robokin.kinematics.ik.solutions import SolutionSet
    from robokin.model.dynamics import RobotDynamics
    from robokin.model.geometry import RobotGeometry

__all__ = ["Robot"]

Space = Literal["joint", "actuator"]
_FK_SINGLE = forward.fk_single  # one configuration, or None for the general path
_HOW_TO_CHANGE = ("make a changed copy with robot.replace(...), robot.with_tool(T) or "
                  "robot.with_base(T)")


def _is_frozen_limits(lim: object, m: int) -> TypeGuard[npt.NDArray[np.float64]]:
    """True for limits a Robot already checked and froze (kept, not copied)."""
    return (type(lim) is np.ndarray and lim.dtype == np.float64 and not lim.flags.writeable
            and lim.shape == (m, 2) and not np.isnan(lim).any())


def _actuator_fields(
    actuators: AffineMap | None,
    names: Sequence[str] | None,
    limits: npt.ArrayLike | None,
) -> tuple[tuple[str, ...] | None, npt.NDArray[np.float64] | None]:
    """The motor names and frozen motor limits (m, 2) of an actuator map, or Nones."""
    if actuators is None:
        if limits is not None:
            raise InputError("actuator_limits", "given without an actuator map")
        return None, None
    m = actuators.n_in
    names = tuple(names or (f"motor{i + 1}" for i in range(m)))
    if limits is None:
        lim = np.tile([-np.inf, np.inf], (m, 1))
    elif _is_frozen_limits(limits, m):
        return names, limits
    else:
        lim = np.array(limits, dtype=float)
        if lim.shape != (m, 2) or np.isnan(lim).any():
            raise InputError(
                "actuator_limits",
                f"expected shape ({m}, 2) without NaN for {m} motors, got {lim.shape}",
            )
    lim.setflags(write=False)
    return names, lim


class Robot:
    """A serial manipulator.

    Attributes:
        chain: The canonical chain (:class:`robokin.model.chain.Chain`).
        name: The robot's name.
        source: Where its parameters come from (citation), may be empty.
        actuators: ``q = A phi + b`` from motor to joint coordinates, or None.
        actuator_names: Names of the motor coordinates (m), or None.
        actuator_limits: Motor limits (m, 2), SI units, or None.
        geometry: Link and tool shapes (see ``robokin.model.geometry``), or None.
        dynamics: Link masses, centres of mass, inertias and joint torque limits
            (:class:`~robokin.model.dynamics.RobotDynamics`), or None.
        path: The robot file it was loaded from, or None.
        meta: Free-form extra fields from the robot file (a read-only mapping).
        rate_limits: Per-joint velocity / acceleration / jerk limits
            (:class:`~robokin.model.rate_limits.RateLimits`, SI), or None.
    """

    __slots__ = ("actuator_limits", "actuator_names", "actuators", "chain", "dynamics",
                 "geometry", "meta", "name", "path", "rate_limits", "source",
                 "__weakref__")
    chain: Chain
    name: str
    source: str
    actuators: AffineMap | None
    actuator_names: tuple[str, ...] | None
    actuator_limits: npt.NDArray[np.float64] | None
    geometry: RobotGeometry | None
    dynamics: RobotDynamics | None
    path: Path | None
    meta: Mapping[str, Any]
    rate_limits: RateLimits | None

    def __setattr__(self, name: str, value: Any) -> None:
        """Refuse: a Robot is immutable (raises FrozenError)."""
        raise FrozenError("Robot", name, _HOW_TO_CHANGE)

    def __delattr__(self, name: str) -> None:
        """Refuse: a Robot is immutable (raises FrozenError)."""
        raise FrozenError("Robot", name, _HOW_TO_CHANGE)

    def __reduce__(self) -> tuple:
        # pickle and copy rebuild through __init__ (slots cannot be set directly)
        """Pickle and copy rebuild through __init__ (slots cannot be set directly)."""
        return (_rebuild, (self.chain, self._fields()))

    def _fields(self) -> dict[str, Any]:
        return {"name": self.name, "source": self.source, "actuators": self.actuators,
                "actuator_names": self.actuator_names,
                "actuator_limits": self.actuator_limits, "geometry": self.geometry,
                "dynamics": self.dynamics, "path": self.path, "meta": dict(self.meta),
                "rate_limits": self.rate_limits}

    def __init__(
        self,
        chain: Chain,
        *,
        name: str = "robot",
        source: str = "",
        actuators: AffineMap | None = None,
        actuator_names: Sequence[str] | None = None,
        actuator_limits: npt.ArrayLike | None = None,
        geometry: RobotGeometry | None = None,
        dynamics: RobotDynamics | None = None,
        path: str | Path | None = None,
        meta: Mapping[str, Any] | None = None,
        rate_limits: RateLimits | None = None,
    ) -> None:
        """Check and freeze the parts (see the class docstring for each)."""
        init = object.__setattr__
        init(self, "chain", chain)
        init(self, "name", name)
        init(self, "source", source)
        if actuators is not None and actuators.n_out != chain.n:
            raise InputError(
                "actuators",
                f"maps {actuators.n_in} motors to {actuators.n_out} joints, "
                f"but the robot has {chain.n} joints",
            )
        init(self, "actuators", actuators)
        names, limits = _actuator_fields(actuators, actuator_names, actuator_limits)
        init(self, "actuator_names", names)
        init(self, "actuator_limits", limits)
        init(self, "geometry", geometry)
        if dynamics is not None and len(getattr(dynamics, "names", ())) != chain.n_chain + 2:
            raise InputError("dynamics", f"expected data for {chain.n_chain + 2} links "
                             "(base, the chain joints, tool); see "
                             "robokin.model.dynamics.RobotDynamics.from_mapping")
        init(self, "dynamics", dynamics)
        init(self, "path", None if path is None else Path(path))
        init(self, "meta", MappingProxyType(dict(meta or {})))
        if rate_limits is not None and (not isinstance(rate_limits, RateLimits)
                                        or rate_limits.n != chain.n):
            raise InputError(
                "rate_limits",
                f"expected RateLimits for {chain.n} joints, got {rate_limits!r}")
        init(self, "rate_limits", rate_limits)

    # ------------------------------------------------------------------ building
    @classmethod
    def from_dh(
        cls,
        rows: Sequence[Mapping[str, Any]],
        convention: Literal["standard", "modified"] = "standard",
        *,
        base: npt.ArrayLike | None = None,
        tool: npt.ArrayLike | None = None,
        name: str = "robot",
        coordinates: Sequence[Mapping[str, Any]] | None = None,
    ) -> Robot:
        """Build from a DH table in SI units (see :mod:`robokin.model.dh`).

        A row may leave out ``a``, ``alpha``, ``d`` and ``theta``: a missing one is
        0 (a joint offset or length the arm does not have). This is safe because
        a row with any other key is refused, so a misspelt key (``alpah``) is an
        error, never a silent zero. ``joint`` defaults to ``"revolute"``.

        Raises:
            ModelError: a row that is not a mapping, an unknown key, a value that
                is not a finite number, reversed limits (naming ``rows[i].key``).
        """
        from robokin.model.dh import chain_from_dh

        base = None if base is None else check_transform(base, "base")
        tool = None if tool is None else check_transform(tool, "tool")
        chain = chain_from_dh(rows, convention, base=base, tool=tool, coordinates=coordinates)
        return cls(chain, name=name)

    @classmethod
    def from_elementary(
        cls,
        ops: Sequence[Mapping[str, Any]],
        *,
        base: npt.ArrayLike | None = None,
        tool: npt.ArrayLike | None = None,
        name: str = "robot",
        coordinates: Sequence[Mapping[str, Any]] | None = None,
    ) -> Robot:
        """Build from elementary Rot/Trans operators (see :mod:`robokin.model.dh`)."""
        from robokin.model.dh import chain_from_elementary

        base = None if base is None else check_transform(base, "base")
        tool = None if tool is None else check_transform(tool, "tool")
        chain = chain_from_elementary(ops, base=base, tool=tool, coordinates=coordinates)
        return cls(chain, name=name)

    @classmethod
    def from_urdf(
        cls, path: str | Path, base_link: str | None = None, tip_link: str | None = None,
        **kwargs: Any,
    ) -> Robot:
        """Load the serial chain of a URDF or xacro file (needs ``robokin[urdf]``).

        A ``.xacro`` / ``.urdf.xacro`` file is expanded first (needs
        ``robokin[ros]``): ``Robot.from_urdf("arm.urdf.xacro",
        package_map={"pkg": "dir"}, xacro_args={"name": "value"}, tip_link=...)``.
        Keywords as :func:`robokin.io.urdf.robot_from_urdf`.
        """
        from robokin.io.urdf import robot_from_urdf

        return robot_from_urdf(path, base_link=base_link, tip_link=tip_link, **kwargs)

    def to_urdf(self, **kwargs: Any) -> str:
        """A URDF string with the same FK, limits and geometry."""
        from robokin.io.urdf_export import urdf_from_robot

        return urdf_from_robot(self, **kwargs)

    def replace(self, **changes: Any) -> Robot:
        """A copy with some attributes replaced (``chain``, ``name``, ``geometry``, ...)."""
        kw = {"chain": self.chain, **self._fields()}
        unknown = sorted(set(changes) - set(kw))
        if unknown:
            raise InputError(unknown[0], f"not a Robot attribute; replace() takes "
                             f"{sorted(kw)}")
        kw.update(changes)
        chain = kw.pop("chain")
        return Robot(chain, **kw)

    def with_tool(self, tool: npt.ArrayLike) -> Robot:
        """A copy with the tool transform (4, 4) [m] replaced."""
        return self.replace(chain=self.chain.replace(tool=check_transform(tool, "tool")))

    def with_base(self, base: npt.ArrayLike) -> Robot:
        """A copy with the base transform (4, 4) [m] replaced."""
        return self.replace(chain=self.chain.replace(base=check_transform(base, "base")))

    # ---------------------------------------------------------------- properties
    @property
    def n(self) -> int:
        """Number of independent joint coordinates."""
        return self.chain.n

    @property
    def n_chain(self) -> int:
        """Number of chain joints, dependent ones included."""
        return self.chain.n_chain

    @property
    def limits(self) -> np.ndarray:
        """Joint limits (n, 2) in SI units."""
        return self.chain.limits

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Names of the independent joint coordinates."""
        return tuple(c.name for c in self.chain.coordinates)

    @property
    def is_revolute(self) -> np.ndarray:
        """(n,) bool: which coordinates are angles (wrap) rather than lengths."""
        return self.chain.is_revolute

    @property
    def base(self) -> np.ndarray:
        """Base transform (4, 4)."""
        return self.chain.base

    @property
    def tool(self) -> np.ndarray:
        """Tool transform (4, 4)."""
        return self.chain.tool

    def __repr__(self) -> str:
        """A short summary: the name and the number of joints."""
        return f"Robot(name={self.name!r}, n={self.n})"

    def _repr_html_(self) -> str:
        """Jupyter: the joint rows (mm, degrees), the limits and the tool pose at zero.

        Bounded: at most :data:`robokin._html.MAX_ROWS` rows per table.
        """
        from robokin import _html
        from robokin.io.robot_files import document_from_robot
        from robokin.io.robot_tables import MM_PER_M, joint_rows_mm_deg

        doc = document_from_robot(self)
        keys, rows = joint_rows_mm_deg(doc)
        scale = np.where(self.is_revolute, 180.0 / np.pi, MM_PER_M)
        limits = [(c.name, c.kind, lo * k, hi * k) for c, (lo, hi), k
                  in zip(self.chain.coordinates, self.limits, scale)]
        tool = self.fk(np.zeros(self.n))[:3, 3] * MM_PER_M
        return _html.box(
            f"Robot {self.name!r}: {self.n} joints, {doc.get('convention', '?')}",
            _html.note("joint rows (lengths mm, angles deg)"),
            _html.table(keys, [["" if v is None else v for v in r] for r in rows]),
            _html.note("joint limits (deg / mm)"),
            _html.table(["joint", "kind", "lower", "upper"], limits),
            _html.note("tool at q = 0 [mm]: " + ", ".join(f"{v:.3f}" for v in tool)),
            _html.note(f"source: {self.source[:300]}") if self.source else "")

    # --------------------------------------------------------------- kinematics
    def _to_joints(self, q: npt.ArrayLike, space: Space, name: str) -> npt.ArrayLike:
        if space == "joint":
            return q
        if space != "actuator":
            raise InputError("space", f"expected 'joint' or 'actuator', got {space!r}")
        return self.joints_from_actuators(q)

    def fk(self, q: npt.ArrayLike, *, space: Space = "joint") -> np.ndarray:
        """Tool pose in the world frame.

        Args:
            q: Joint coordinates [rad, m], shape (..., n); motor coordinates
                (..., m) when ``space="actuator"``.
            space: ``"joint"`` or ``"actuator"``.

        Returns:
            Poses (..., 4, 4).
        """
        chain = self.chain
        if space == "joint":
            # One configuration: None unless q is a finite float64 (n,) array.
            T = _FK_SINGLE(q, chain.arrays.packed)
            if T is not None:
                return T
            return forward.forward_kinematics(chain, q)
        return forward.forward_kinematics(chain, self._to_joints(q, space, "phi"))

    def fk_all(self, q: npt.ArrayLike, *, space: Space = "joint") -> np.ndarray:
        """Base frame then every link frame, (..., n_chain + 1, 4, 4)."""
        return forward.forward_kinematics_all(self.chain, self._to_joints(q, space, "phi"))

    def jacobian(
        self, q: npt.ArrayLike, *, frame: Literal["base", "tool"] = "base",
        space: Space = "joint",
    ) -> np.ndarray:
        """Geometric Jacobian (..., 6, n) ``[v; w]``; (..., 6, m) in actuator space.

        In actuator space ``q`` holds motor coordinates (..., m) and the result is
        ``J(A phi + b) @ A``: tool twist per unit motor rate.
        """
        if space == "actuator":
            J = _jac.jacobian(self.chain, self.joints_from_actuators(q), frame=frame)
            if self.actuators is None:
                return J
            return J @ self.actuators.matrix
        return _jac.jacobian(self.chain, self._to_joints(q, space, "q"), frame=frame)

    def manipulability(self, q: npt.ArrayLike) -> np.ndarray:
        """Yoshikawa manipulability, (...)."""
        return _jac.manipulability(self.chain, q)

    def is_singular(self, q: npt.ArrayLike, tol: float = 1e-6) -> np.ndarray:
        """True where the smallest Jacobian singular value is below ``tol``, (...)."""
        return _jac.is_singular(self.chain, q, tol)

    def ik(
        self,
        T: npt.ArrayLike,
        q_near: npt.ArrayLike | None = None,
        method: Literal["auto", "analytic", "numeric"] = "auto",
        *,
        space: Space = "joint",
        **options: Any,
    ) -> SolutionSet:
        """Every joint solution that puts the tool at ``T``.

        Args:
            T: Target poses (..., 4, 4) in the world frame.
            q_near: The current configuration (..., n), used for the wrist
                singularity and by ``.nearest``; optional.
            method: ``"auto"`` (closed form when the arm has one, else numeric),
                ``"analytic"`` or ``"numeric"``.
            space: ``"actuator"`` returns motor coordinates (and takes ``q_near``
                in motor coordinates).
            **options: Passed to the solver.

        Returns:
            A :class:`~robokin.kinematics.ik.solutions.SolutionSet`.
        """
        if space == "actuator":
            if q_near is not None:
                q_near = self.joints_from_actuators(q_near)
            sols = _ik_solve(self, T, q_near=q_near, method=method, **options)
            out = sols.to_actuator_space(self)
            if self.actuators is not None and out.is_revolute.any():
                # Motor angles never wrap: a motor turn through a reduction is not a
                # whole joint turn, so 2*pi-shifted motor values are other poses.
                from dataclasses import replace as _replace

                out = _replace(out, is_revolute=np.zeros(out.n, bool))
            return out
        if space != "joint":
            raise InputError("space", f"expected 'joint' or 'actuator', got {space!r}")
        return _ik_solve(self, T, q_near=q_near, method=method, **options)

    def ik_near(
        self,
        T: npt.ArrayLike,
        q_near: npt.ArrayLike,
        *,
        method: Literal["auto", "analytic", "numeric"] = "auto",
        **options: Any,
    ) -> IKResult:
        """One solution per target: the one nearest ``q_near`` (streaming to a controller).

        The closed form's nearest solution inside the limits where the arm has one,
        else one numeric descent from ``q_near`` (see
        :func:`robokin.kinematics.ik.nearest.solve_near`).

        Args:
            T: Target poses (..., 4, 4) in the world frame [m].
            q_near: Current configuration (n,) or (..., n) [rad, m].
            method: ``"auto"``, ``"analytic"`` or ``"numeric"``.
            **options: Numeric-solver options (``mask``, ``tol``, ...).

        Returns:
            An :class:`~robokin.kinematics.ik.numeric.IKResult`: ``.q`` (..., n),
            ``.success`` (...), ``.reason``.
        """
        return _solve_near(self, T, q_near, method=method, **options)

    def self_motion(self, T: npt.ArrayLike, parameter: str = "auto") -> SelfMotion:
        """The self-motion manifold of one pose of a 7R arm: every branch, exact limits.

        Args:
            T: The tool pose (4, 4) [m] in the world frame.
            parameter: ``"auto"`` (the swivel on SRS arms, else the last joint with
                a held-joint closed form: q7 on the Panda / FR3), ``"swivel"`` or a
                joint name.

        Returns:
            A :class:`~robokin.kinematics.ik.self_motion.SelfMotion`: ``.sample(t)``
            (..., k, n), ``.intervals`` (m, 2) inside every limit with
            ``.interval_branch``, ``.crossings``, ``.singular``, ``.best(criterion)``,
            ``.nearest(q)``.
        """
        return _self_motion(self, T, parameter)

    # ---------------------------------------------------------------- actuators
    def actuators_from_joints(self, q: npt.ArrayLike) -> np.ndarray:
        """Motor coordinates ``phi = A^+ (q - b)``: (..., n) -> (..., m).

        The identity when the robot has no actuator map. When there are fewer
        motors than joints (passive joints driven through ``A``), ``q`` must be a
        configuration the motors can produce.

        Raises:
            InputError: ``q`` has the wrong shape, is not finite, or (fewer motors
                than joints) is not reachable through the actuator map.
            ModelError: the actuator matrix cannot be inverted.
        """
        from robokin._validation import check_finite, check_joints

        q = check_finite(check_joints(q, self.n, "q"), "q")
        if self.actuators is None:
            return q.copy()
        what = f"actuator map of '{self.name}'"
        phi = self.actuators.inverse(q, what=what)
        if self.actuators.n_in < self.actuators.n_out:
            back = self.actuators.apply(phi)
            err = np.abs(back - q)
            tol = 1e-9 * (1.0 + np.abs(q))
            if (err > tol).any():
                first = tuple(np.argwhere((err > tol).any(axis=-1))[0]) if q.ndim > 1 else ()
                idx = first + (int(np.argmax(err[first])),)
                raise InputError(
                    "q",
                    f"not reachable through the {what}: joint "
                    f"{self.joint_names[idx[-1]]!r} would be {back[tuple(idx)]:.9g}, "
                    f"got {q[tuple(idx)]:.9g} (passive joints follow the motors)",
                )
        return phi

    def joints_from_actuators(self, phi: npt.ArrayLike) -> np.ndarray:
        """Joint coordinates ``q = A phi + b``: (..., m) -> (..., n)."""
        from robokin._validation import check_finite, check_joints

        m = self.n if self.actuators is None else self.actuators.n_in
        phi = check_finite(check_joints(phi, m, "phi"), "phi")
        if self.actuators is None:
            return phi.copy()
        return self.actuators.apply(phi)

    def within_actuator_limits(
        self, phi: npt.ArrayLike, tol: float = 1e-9
    ) -> npt.NDArray[np.bool_] | np.bool_:
        """(...) bool: every motor coordinate (..., m) inside its limits (tolerance ``tol``)."""
        from robokin._validation import check_joints

        m = self.n if self.actuators is None else self.actuators.n_in
        phi = check_joints(phi, m, "phi")
        lim = self.limits if self.actuator_limits is None else self.actuator_limits
        return ((phi >= lim[:, 0] - tol) & (phi <= lim[:, 1] + tol)).all(axis=-1)

    # ------------------------------------------------------------------- checks
    def within_limits(
        self, q: npt.ArrayLike, tol: float = 1e-9
    ) -> npt.NDArray[np.bool_] | np.bool_:
        """(...) bool: every coordinate inside its limits (with tolerance ``tol``)."""
        from robokin._validation import check_joints

        q = check_joints(q, self.n, "q")
        lim = self.limits
        return ((q >= lim[:, 0] - tol) & (q <= lim[:, 1] + tol)).all(axis=-1)

    def plot(self, q: npt.ArrayLike, **kwargs: Any):
        """Draw the arm at ``q`` as a 3D stick-and-frame figure (matplotlib)."""
        from robokin.viz.plots import plot_robot

        return plot_robot(self, q, **kwargs)


def _rebuild(chain: Chain, fields: dict[str, Any]) -> Robot:
    """Unpickle a Robot (see ``Robot.__reduce__``)."""
    return Robot(chain, **fields)
