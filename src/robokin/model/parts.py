"""The parts of a robot: what the files hold and what a Robot is built from.

:class:`RobotParts` is the description of an arm as data: its canonical chain, its
name and source, the actuator map with the motors' names and limits, link shapes,
mass properties, rate limits, the file it came from and free-form ``meta``. The
readers of :mod:`robokin.io` return one, the writers take one, and
:class:`robokin.robot.Robot` is one that also computes (FK, Jacobians, IK): a
Robot can be passed wherever parts are taken, and
:meth:`robokin.robot.Robot.from_parts` turns parts into a Robot without copying
them. Nothing here imports a layer above ``model/``.

Parts are immutable: assigning or deleting an attribute raises
:class:`~robokin.exceptions.FrozenError`, arrays are read-only and ``meta`` is a
read-only mapping; :meth:`RobotParts.replace`, :meth:`RobotParts.with_tool` and
:meth:`RobotParts.with_base` return changed copies of the same class.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, TypeGuard, TypeVar

import numpy as np
import numpy.typing as npt

from robokin._validation import check_transform
from robokin.exceptions import FrozenError, InputError
from robokin.model.chain import Chain
from robokin.model.coupling import AffineMap
from robokin.model.rate_limits import RateLimits

if TYPE_CHECKING:
    from robokin.model.dynamics import RobotDynamics
    from robokin.model.geometry import RobotGeometry

__all__ = ["RobotParts"]

_P = TypeVar("_P", bound="RobotParts")
_HOW_TO_CHANGE = ("make a changed copy with robot.replace(...), robot.with_tool(T) or "
                  "robot.with_base(T)")


def _is_frozen_limits(lim: object, m: int) -> TypeGuard[npt.NDArray[np.float64]]:
    """True for limits already checked and frozen (kept, not copied)."""
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


class RobotParts:
    """A serial manipulator described as data (see the module docstring).

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
        """Check and freeze the parts (see the class docstring for each).

        Raises:
            InputError: an actuator map, dynamics or rate limits that do not fit
                the chain (naming the argument), motor limits of the wrong shape.
        """
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

    def __setattr__(self, name: str, value: Any) -> None:
        """Refuse: parts are immutable (raises FrozenError)."""
        raise FrozenError(type(self).__name__, name, _HOW_TO_CHANGE)

    def __delattr__(self, name: str) -> None:
        """Refuse: parts are immutable (raises FrozenError)."""
        raise FrozenError(type(self).__name__, name, _HOW_TO_CHANGE)

    def __reduce__(self) -> tuple[Any, ...]:
        """Pickle and copy rebuild through ``__init__`` (slots cannot be set directly)."""
        return (_rebuild, (type(self), self.chain, self._fields()))

    def _fields(self) -> dict[str, Any]:
        """Every keyword of ``__init__`` but the chain, as this object holds it."""
        return {"name": self.name, "source": self.source, "actuators": self.actuators,
                "actuator_names": self.actuator_names,
                "actuator_limits": self.actuator_limits, "geometry": self.geometry,
                "dynamics": self.dynamics, "path": self.path, "meta": dict(self.meta),
                "rate_limits": self.rate_limits}

    def replace(self: _P, **changes: Any) -> _P:
        """A copy with some attributes replaced (``chain``, ``name``, ``geometry``, ...).

        Raises:
            InputError: a keyword that is not an attribute (the valid ones listed).
        """
        kw = {"chain": self.chain, **self._fields()}
        unknown = sorted(set(changes) - set(kw))
        if unknown:
            raise InputError(unknown[0], f"not a {type(self).__name__} attribute; "
                             f"replace() takes {sorted(kw)}")
        kw.update(changes)
        chain = kw.pop("chain")
        return type(self)(chain, **kw)

    def with_tool(self: _P, tool: npt.ArrayLike) -> _P:
        """A copy with the tool transform (4, 4) [m] replaced."""
        return self.replace(chain=self.chain.replace(tool=check_transform(tool, "tool")))

    def with_base(self: _P, base: npt.ArrayLike) -> _P:
        """A copy with the base transform (4, 4) [m] replaced."""
        return self.replace(chain=self.chain.replace(base=check_transform(base, "base")))

    @property
    def n(self) -> int:
        """Number of independent joint coordinates."""
        return self.chain.n

    @property
    def n_chain(self) -> int:
        """Number of chain joints, dependent ones included."""
        return self.chain.n_chain

    @property
    def limits(self) -> npt.NDArray[np.float64]:
        """Joint limits (n, 2) in SI units."""
        return self.chain.limits

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Names of the independent joint coordinates."""
        return tuple(c.name for c in self.chain.coordinates)

    @property
    def is_revolute(self) -> npt.NDArray[np.bool_]:
        """(n,) bool: which coordinates are angles (wrap) rather than lengths."""
        return self.chain.is_revolute

    @property
    def base(self) -> npt.NDArray[np.float64]:
        """Base transform (4, 4)."""
        return self.chain.base

    @property
    def tool(self) -> npt.NDArray[np.float64]:
        """Tool transform (4, 4)."""
        return self.chain.tool

    def __repr__(self) -> str:
        """A short summary: the name and the number of joints."""
        return f"{type(self).__name__}(name={self.name!r}, n={self.n})"


def _rebuild(cls: type[_P], chain: Chain, fields: dict[str, Any]) -> _P:
    """Unpickle parts or a Robot (see ``RobotParts.__reduce__``)."""
    return cls(chain, **fields)
