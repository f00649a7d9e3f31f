"""The :class:`Arm`: one object per chain, owning what computing with the chain needs.

pinocchio splits ``Model`` (what the arm is) from ``Data`` (what computing with it
needs). Here the :class:`~robokin.model.chain.Chain` (with its ``ChainArrays``) is
what the arm is, and the :class:`Arm` holds it together with everything derived from
it: the closed-form family of every detection setting, the general-6R set-up, the
numeric solver's seed table, the closed forms with one joint held and the reduced
arms of a held-joint sweep. Each kind of derived state is declared, with its type,
by the module that computes it, as a :class:`Derived` (``detect.FAMILY``,
``general_6r.SETUP``, ``restart_seeds.SEED_TABLE``, ``fixed.HELD_SOLVERS``,
``self_motion_families.SELF_MOTION``), built
on first use by :meth:`Arm.derived` and kept in the Arm, so it goes with the Arm.

A :class:`~robokin.robot.Robot` owns one Arm (``robot.arm``) and delegates its
kinematics to it; the Arm holds the chain, the chain holds nothing back, so a Robot,
its Arm and its chain are freed together by reference counting. There is no
module-level registry and no cache keyed by ``id()``.

Kinematics functions take an Arm, or anything holding one (:class:`HasArm`, e.g. a
Robot): :func:`arm_of` returns the Arm of either (a bare Chain gets a new Arm,
kept only for that call).
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Generic, Protocol, TypeAlias, TypeVar

import numpy as np
import numpy.typing as npt

from robokin.exceptions import InputError
from robokin.model.chain import Chain
from robokin.model.coupling import AffineMap

__all__ = ["Arm", "ArmSource", "Derived", "HasArm", "ReducedKey", "arm_of"]

#: A held-joint reduction: (held coordinate indices, held values).
ReducedKey: TypeAlias = tuple[tuple[int, ...], tuple[float, ...]]

V = TypeVar("V")


@dataclass(frozen=True, eq=False)
class Derived(Generic[V]):
    """One kind of derived per-arm state: its type, its name and how it is built.

    The module that computes the state declares it once, typed by what it holds,
    e.g. ``SEED_TABLE: Derived[SeedTable] = Derived("seed table", build)``;
    :meth:`Arm.derived` then returns a ``SeedTable`` (a typed key, as
    ``contextvars.ContextVar[T]``). This module names none of those types, so
    nothing, type-only imports included, runs from the Arm back to its users
    (``tests/test_layers.py``: the ``arm`` layer), and a new kind of state is a
    change to the module that computes it only.

    Attributes:
        name: What the state is (in messages and reprs).
        build: ``build(arm)``: the state of ``arm``, never None; called once per Arm,
            on first use.
    """

    name: str
    build: Callable[[Arm], V]

    def __repr__(self) -> str:
        """The name only."""
        return f"Derived({self.name!r})"


@dataclass(slots=True, eq=False, repr=False)
class Arm:
    """One serial chain and the state derived from it (built on first use).

    Attributes:
        chain: The canonical chain (immutable).
        name: The arm's name (in messages).
        actuators: ``q = A phi + b`` from motor to joint coordinates, or None.
        actuator_limits: Motor limits (m, 2), SI units, or None.
        state: The derived state built so far, by kind (:class:`Derived` -> its
            value); read it with :meth:`derived`, which types the value.
        reduced: The arms of the remaining coordinates of the last held-joint
            reductions (most recently used last; ``fixed`` bounds it).
    """

    chain: Chain
    name: str = "robot"
    actuators: AffineMap | None = None
    actuator_limits: npt.NDArray[np.float64] | None = None
    state: dict[Derived[Any], Any] = field(default_factory=dict, init=False)
    reduced: OrderedDict[ReducedKey, Arm] = field(default_factory=OrderedDict)

    def derived(self, kind: Derived[V]) -> V:
        """The arm's state of ``kind``, built by ``kind.build(self)`` on first use and kept.

        Args:
            kind: The kind of state (declared by the module that computes it).

        Returns:
            The state, typed as ``kind`` declares it.
        """
        value: V | None = self.state.get(kind)
        if value is None:
            value = self.state[kind] = kind.build(self)
        return value

    @property
    def arm(self) -> Arm:
        """The Arm itself (an Arm is a :class:`HasArm` too)."""
        return self

    @property
    def n(self) -> int:
        """Number of independent joint coordinates."""
        return self.chain.n

    @property
    def limits(self) -> npt.NDArray[np.float64]:
        """Joint limits (n, 2), SI units."""
        return self.chain.limits

    @property
    def is_revolute(self) -> npt.NDArray[np.bool_]:
        """(n,) bool: which coordinates are angles."""
        return self.chain.is_revolute

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Names of the independent joint coordinates."""
        return tuple(c.name for c in self.chain.coordinates)

    def __repr__(self) -> str:
        """The name and the number of joints (never the derived state)."""
        return f"Arm(name={self.name!r}, n={self.n})"

    def __reduce__(self) -> tuple[object, ...]:
        """Pickle the parts only: the derived state is rebuilt on first use."""
        return (Arm, (self.chain, self.name, self.actuators, self.actuator_limits))


class HasArm(Protocol):
    """Anything that holds an :class:`Arm` (a :class:`~robokin.robot.Robot`, an Arm)."""

    @property
    def arm(self) -> Arm:
        """The Arm."""


#: What kinematics functions take: an Arm, an object holding one (a Robot), or a
#: bare chain (then an Arm is made for the call: nothing derived is kept).
ArmSource: TypeAlias = Arm | HasArm | Chain


def arm_of(source: ArmSource) -> Arm:
    """The :class:`Arm` of ``source``: itself, the one it holds, or a new one of a chain.

    Raises:
        InputError: ``source`` is none of these (names the argument ``robot``).
    """
    if isinstance(source, Chain):
        return Arm(source)
    try:
        arm = source.arm
    except AttributeError:
        arm = None
    if not isinstance(arm, Arm):
        raise InputError("robot", f"expected a Robot, an Arm or a Chain, got "
                                  f"{type(source).__name__}")
    return arm
