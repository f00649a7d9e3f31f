"""The :class:`Arm`: one object per chain, owning what computing with the chain needs.

pinocchio splits ``Model`` (what the arm is) from ``Data`` (what computing with it
needs). Here the :class:`~robokin.model.chain.Chain` (with its ``ChainArrays``) is
what the arm is, and the :class:`Arm` holds it together with everything derived from
it: the closed-form family of every detection setting, the general-6R set-up, the
numeric solver's seed table, the closed forms with one joint held and the reduced
arms of a held-joint sweep. Each field is filled on first use by the module that
computes it (``detect``, ``general_6r``, ``numeric``, ``fixed``) and goes with the
Arm.

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
from dataclasses import dataclass, field
from typing import Protocol, TypeAlias

import numpy as np
import numpy.typing as npt

from robokin.exceptions import InputError
from robokin.model.chain import Chain
from robokin.model.coupling import AffineMap

__all__ = ["Arm", "ArmSource", "FamilyKey", "HasArm", "ReducedKey", "arm_of"]

#: ``detect``'s settings: (tol, near_angle, near_distance, general_6r).
FamilyKey: TypeAlias = tuple[float, float, float, bool]
#: A held-joint reduction: (held coordinate indices, held values).
ReducedKey: TypeAlias = tuple[tuple[int, ...], tuple[float, ...]]


@dataclass(slots=True, eq=False, repr=False)
class Arm:
    """One serial chain and the state derived from it (built on first use).

    Attributes:
        chain: The canonical chain (immutable).
        name: The arm's name (in messages).
        actuators: ``q = A phi + b`` from motor to joint coordinates, or None.
        actuator_limits: Motor limits (m, 2), SI units, or None.
        family: The closed-form family at ``detect``'s default settings (a
            ``detect.Family``), or None until detected (the single-pose IK path
            reads it on every call).
        families: The families (``detect.Family``) detected at other settings.
        general_6r: The general-6R set-up (a ``general_6r.General6R``: fits and
            elimination variants), or None until first needed.
        seed_table: The numeric solver's restart seeds (a ``numeric.SeedTable``),
            or None until first needed.
        held_solvers: Joint name -> the closed form with that joint held (a
            ``fixed.HeldSolver``; 7R arms), or None until first needed.
        reduced: The arms of the remaining coordinates of the last held-joint
            reductions (most recently used last; ``fixed`` bounds it).

    The derived fields are typed ``object`` here and narrowed by the module that
    fills them (``isinstance`` on its own record type): this module imports
    nothing else of ``kinematics``, so no import (type-only ones included) runs
    from the Arm back to its users (``tests/test_layers.py``: the ``arm`` layer).
    """

    chain: Chain
    name: str = "robot"
    actuators: AffineMap | None = None
    actuator_limits: npt.NDArray[np.float64] | None = None
    family: object | None = None
    families: dict[FamilyKey, object] = field(default_factory=dict)
    general_6r: object | None = None
    seed_table: object | None = None
    held_solvers: dict[str, object] | None = None
    reduced: OrderedDict[ReducedKey, Arm] = field(default_factory=OrderedDict)

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
