"""The Robot: the parts of an arm (:mod:`robokin.model.parts`) and what it computes.

A Robot is assembled from parts (a canonical chain plus its name, source,
actuators, geometry, dynamics and limits) and delegates the computing to
:mod:`robokin.kinematics`. The files it is read from and written to are
:mod:`robokin.io`'s, which read and write parts and know nothing of Robots.

A Robot is immutable: assigning or deleting an attribute raises
:class:`~robokin.exceptions.FrozenError`, its arrays are read-only and ``meta`` is
a read-only mapping; ``with_tool`` / ``with_base`` / ``replace`` return new ones.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace as _replace
from functools import cache
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import numpy.typing as npt

from robokin._validation import check_finite, check_joints, check_transform
from robokin.exceptions import InputError
from robokin.kinematics import forward
from robokin.kinematics import jacobian as _jac
from robokin.kinematics.arm import Arm
from robokin.model.parts import RobotParts

if TYPE_CHECKING:
    from typing_extensions import Unpack

    from robokin.io.urdf import UrdfKeywords
    from robokin.kinematics.ik.fixed import Dispatch
    from robokin.kinematics.ik.numeric import IKResult
    from robokin.kinematics.ik.self_motion import SelfMotion
    from robokin.kinematics.ik.solutions import SolutionSet

__all__ = ["Robot"]

Space = Literal["joint", "actuator"]
_FK_SINGLE = forward.fk_single  # one configuration, or None for the general path


# The IK entry points and the file readers are imported on first use, not by
# ``import robokin``: they pull in every closed-form family, the numeric solver, the
# self-motion code and PyYAML (``import robokin`` took 0.22-0.26 s with them, 0.10-0.12
# s before they were added). A cached loader costs ~20 ns a call where a
# function-level ``from ... import`` costs 0.3-0.6 us.
@cache
def _ik_solve() -> Dispatch:
    """:func:`robokin.kinematics.ik.dispatch.solve`, imported on the first solve."""
    from robokin.kinematics.ik.dispatch import solve

    return solve


@cache
def _self_motion() -> Callable[..., SelfMotion]:
    """:func:`robokin.kinematics.ik.self_motion.self_motion`, imported on first use."""
    from robokin.kinematics.ik.self_motion import self_motion

    return self_motion


@cache
def _held_single() -> Callable[[Arm, object, object], SolutionSet | None]:
    """:func:`robokin.kinematics.ik.fixed.solve_held_single`, imported on first use."""
    from robokin.kinematics.ik.fixed import solve_held_single

    return solve_held_single


@cache
def _solve_near() -> Callable[..., IKResult]:
    """:func:`robokin.kinematics.ik.nearest.solve_near`, imported on first use."""
    from robokin.kinematics.ik.nearest import solve_near

    return solve_near


class _Moved:
    """A method a Robot no longer has: reading it raises AttributeError naming the replacement.

    A descriptor rather than ``Robot.__getattr__``: a class with ``__getattr__`` takes
    CPython's slow attribute path for *every* attribute (no specialised lookups), which
    cost ``robot.fk(q)`` about 0.07 us a call (0.30 against 0.23 us).
    """

    def __init__(self, instead: str) -> None:
        self.instead = instead
        self.name = ""

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    def __get__(self, obj: object, owner: type | None = None) -> Any:
        raise AttributeError(f"'Robot' object has no attribute {self.name!r}: {self.instead}")


class Robot(RobotParts):
    """A serial manipulator: its parts and what it computes (FK, Jacobians, IK).

    The parts (:class:`~robokin.model.parts.RobotParts`) are the attributes
    (``chain``, ``name``, ``source``, ``actuators``, ``actuator_names``,
    ``actuator_limits``, ``geometry``, ``dynamics``, ``path``, ``meta``,
    ``rate_limits``), checked and frozen when the Robot is made; a Robot is accepted
    wherever parts are, and :meth:`from_parts` makes one from parts read by
    :mod:`robokin.io`.

    Attributes:
        arm: The :class:`~robokin.kinematics.arm.Arm` the kinematics run on (the
            chain and the state derived from it, made on first use and freed with
            the Robot; a changed copy gets a new one).
    """

    __slots__ = ("_arm",)
    _arm: Arm
    #: Removed in issue 24 (the facade does not draw).
    plot = _Moved("the facade does not draw; use robokin.viz.plot_robot(robot, q)")

    @property
    def arm(self) -> Arm:
        """The Robot's :class:`~robokin.kinematics.arm.Arm` (made on first use)."""
        try:
            return self._arm
        except AttributeError:  # first use: the parts were checked by __init__
            arm = Arm(self.chain, self.name, self.actuators, self.actuator_limits)
            object.__setattr__(self, "_arm", arm)
            return arm

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
    def from_parts(cls, parts: RobotParts) -> Robot:
        """The Robot of parts read by :mod:`robokin.io` (the same objects, not copies)."""
        if isinstance(parts, cls):
            return parts
        return cls(parts.chain, **parts._fields())

    @classmethod
    def from_urdf(
        cls,
        path: str | Path | bytes,
        base_link: str | None = None,
        tip_link: str | None = None,
        package_map: Mapping[str, str | Path] | None = None,
        **options: Unpack[UrdfKeywords],
    ) -> Robot:
        """Load the serial chain of a URDF or xacro file (needs ``robokin[urdf]``).

        A ``.xacro`` / ``.urdf.xacro`` file is expanded first (needs
        ``robokin[ros]``): ``Robot.from_urdf("arm.urdf.xacro",
        package_map={"pkg": "dir"}, xacro_args={"name": "value"}, tip_link=...)``.
        The arguments are those of :func:`robokin.io.urdf.parts_from_urdf`, which
        reads the parts.
        """
        from robokin.io.urdf import parts_from_urdf

        return cls.from_parts(parts_from_urdf(path, base_link, tip_link, package_map,
                                              **options))

    def to_urdf(
        self,
        *,
        name: str | None = None,
        velocity: float = 1.0,
        effort: float = 100.0,
        mesh_uri: Callable[[Path], str] | None = None,
    ) -> str:
        """A URDF string with the same FK, limits and geometry.

        The arguments are those of :func:`robokin.io.urdf_export.urdf_from_robot`.
        """
        from robokin.io.urdf_export import urdf_from_robot

        return urdf_from_robot(self, name=name, velocity=velocity, effort=effort,
                               mesh_uri=mesh_uri)

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
        fixed: Mapping[str, npt.ArrayLike] | None = None,
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
            fixed: Joints held at given values, ``{name: value}`` [rad, m]: a
                number, or an array broadcasting with the poses (a 7R arm with one
                joint held: the remaining 6R chain solved completely; see
                :func:`robokin.kinematics.ik.fixed.solve_fixed`). None: no joint
                held.
            space: ``"actuator"`` returns motor coordinates (and takes ``q_near``
                in motor coordinates).
            **options: Passed to the solver.

        Returns:
            A :class:`~robokin.kinematics.ik.solutions.SolutionSet`.
        """
        if fixed is not None:
            if (q_near is None and not options and space == "joint"
                    and (method == "auto" or method == "analytic")):
                # hot path: one pose, one joint at a number, a closed form for it
                # (None where that is not so: the general path below checks and
                # raises)
                out = _held_single()(self.arm, T, fixed)
                if out is not None:
                    return out
            options["fixed"] = fixed
        if space == "joint":
            return _ik_solve()(self.arm, T, q_near=q_near, method=method, **options)
        if space != "actuator":
            raise InputError("space", f"expected 'joint' or 'actuator', got {space!r}")
        if q_near is not None:
            q_near = self.joints_from_actuators(q_near)
        arm = self.arm
        sols = _ik_solve()(arm, T, q_near=q_near, method=method, **options)
        out = sols.to_actuator_space(arm)
        if self.actuators is not None and out.is_revolute.any():
            # Motor angles never wrap: a motor turn through a reduction is not a
            # whole joint turn, so 2*pi-shifted motor values are other poses.
            out = _replace(out, is_revolute=np.zeros(out.n, bool))
        return out

    def ik_near(
        self,
        T: npt.ArrayLike,
        q_near: npt.ArrayLike,
        *,
        method: Literal["auto", "analytic", "numeric", "self_motion"] = "auto",
        **options: Any,
    ) -> IKResult:
        """One solution per target: the one nearest ``q_near`` (streaming to a controller).

        The closed form's nearest solution inside the limits where the arm has one,
        else one numeric descent from ``q_near`` (see
        :func:`robokin.kinematics.ik.nearest.solve_near`).

        Args:
            T: Target poses (..., 4, 4) in the world frame [m].
            q_near: Current configuration (n,) or (..., n) [rad, m].
            method: ``"auto"``, ``"analytic"``, ``"numeric"`` or ``"self_motion"``
                (7-joint arms whose whole self-motion is exact: the in-limit point
                of the manifold nearest ``q_near``: compiled on SRS arms, about
                0.1-0.2 ms per pose; on held-joint arms such as the Panda a search
                of the exact in-limit intervals, 4-5 ms; on a general 7R arm or a
                robot on a track the continued manifold, ~10-30 ms; ``docs/ik.md``;
                ``"auto"`` on a 7R arm is the numeric descent, ~0.03 ms).
            **options: Numeric-solver options (``mask``, ``tol``, ...).

        Returns:
            An :class:`~robokin.kinematics.ik.numeric.IKResult`: ``.q`` (..., n),
            ``.success`` (...), ``.reason``.
        """
        return _solve_near()(self.arm, T, q_near, method=method, **options)

    def self_motion(self, T: npt.ArrayLike, parameter: str = "auto") -> SelfMotion:
        """The self-motion manifold of one pose of a 7R arm: every branch, exact limits.

        Args:
            T: The tool pose (4, 4) [m] in the world frame.
            parameter: ``"auto"`` (the swivel on SRS arms, else the last joint with
                a held-joint closed form: q7 on the Panda / FR3; on other arms the
                one prismatic joint, a track, or else the last joint), ``"swivel"``
                or a joint name.

        Returns:
            A :class:`~robokin.kinematics.ik.self_motion.SelfMotion`: ``.sample(t)``
            (..., k, n), ``.intervals`` (m, 2) inside every limit with
            ``.interval_branch``, ``.crossings``, ``.singular``, ``.best(criterion)``,
            ``.nearest(q)``; ``.method`` says what solved each parameter value
            (``"continued numeric"``: an arm with neither a closed form nor the
            general 6R solver for the held chain, whose branches can be missed).
        """
        return _self_motion()(self.arm, T, parameter, dispatch=_ik_solve())

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
        q = check_finite(check_joints(q, self.n, "q"), "q")
        if self.actuators is None:
            result: np.ndarray = q.copy()
            return result
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
        m = self.n if self.actuators is None else self.actuators.n_in
        phi = check_finite(check_joints(phi, m, "phi"), "phi")
        if self.actuators is None:
            result: np.ndarray = phi.copy()
            return result
        return self.actuators.apply(phi)

    def within_actuator_limits(
        self, phi: npt.ArrayLike, tol: float = 1e-9
    ) -> npt.NDArray[np.bool_] | np.bool_:
        """(...) bool: every motor coordinate (..., m) inside its limits (tolerance ``tol``)."""
        m = self.n if self.actuators is None else self.actuators.n_in
        phi = check_joints(phi, m, "phi")
        lim = self.limits if self.actuator_limits is None else self.actuator_limits
        return ((phi >= lim[:, 0] - tol) & (phi <= lim[:, 1] + tol)).all(axis=-1)

    # ------------------------------------------------------------------- checks
    def within_limits(
        self, q: npt.ArrayLike, tol: float = 1e-9
    ) -> npt.NDArray[np.bool_] | np.bool_:
        """(...) bool: every coordinate inside its limits (with tolerance ``tol``)."""
        q = check_joints(q, self.n, "q")
        lim = self.limits
        return ((q >= lim[:, 0] - tol) & (q <= lim[:, 1] + tol)).all(axis=-1)
