"""What the kinematics layer needs of a robot: :class:`RobotLike`.

``robokin.robot.Robot`` sits above ``kinematics/`` (it calls FK, Jacobians and IK),
so the kinematics code does not import it, not even for type hints: it takes any
object with these members, and :class:`~robokin.robot.Robot` is one.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
import numpy.typing as npt

from robokin.model.chain import Chain
from robokin.model.coupling import AffineMap

if TYPE_CHECKING:
    from robokin.kinematics.ik.solutions import SolutionSet

__all__ = ["RobotLike"]


class RobotLike(Protocol):
    """A serial arm as the kinematics layer uses it (``robokin.Robot`` is one)."""

    @property
    def chain(self) -> Chain:
        """The canonical chain."""

    @property
    def name(self) -> str:
        """The robot's name (in messages)."""

    @property
    def actuators(self) -> AffineMap | None:
        """``q = A phi + b`` from motor to joint coordinates, or None."""

    @property
    def actuator_limits(self) -> npt.NDArray[np.float64] | None:
        """Motor limits (m, 2), SI units, or None."""

    @property
    def n(self) -> int:
        """Number of independent joint coordinates."""

    @property
    def limits(self) -> npt.NDArray[np.float64]:
        """Joint limits (n, 2), SI units."""

    @property
    def is_revolute(self) -> npt.NDArray[np.bool_]:
        """(n,) bool: which coordinates are angles."""

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Names of the independent joint coordinates."""

    def ik(self, T: npt.ArrayLike, q_near: npt.ArrayLike | None = None,
           method: Any = "auto", **options: Any) -> SolutionSet:
        """Every IK solution for poses T (..., 4, 4)."""
