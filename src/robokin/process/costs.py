r"""What a process path costs: joint travel, nearness to singularity and to limits.

The objective both :func:`~robokin.process.follow` and :func:`~robokin.process.order`
minimise, over the joint configurations ``q_0 .. q_{N-1}`` they choose:

.. math::

    J = w_t \sum_{i} \max_j |q_{i+1,j} - q_{i,j}|
        + \sum_i \Big[ w_s\, r\big(\mu(q_i) / \mu_{ref}, m_s\big)
        + w_l \sum_j r\big(d_j(q_i), m_l\big) \Big]
        \;(+\, w_t \max_j |q_{0,j} - q_{start,j}| \text{ with } q_{start})

where ``r(x, m) = ((m - x) / m)^2`` for ``x < m`` and 0 beyond (a ramp from 1 at
``x = 0`` to 0 at the margin), ``mu`` is Yoshikawa's manipulability
(:func:`robokin.kinematics.jacobian.manipulability`), ``mu_ref`` the largest the
arm reaches on 4,096 fixed random configurations within its limits, and ``d_j``
the distance of joint j to its nearest limit. The first sum is the *travel* (the
contract's measure: per step the largest joint change [rad; m for a prismatic
joint]). Node terms are per waypoint and are zero outside their margins, so on a
path that keeps away from singularities and limits the objective is the travel
alone.

Hard rules (a configuration breaking one is never used): inside the joint limits
(to 1e-9), relative manipulability at or above ``singular_tol`` and not flagged
singular by the IK, and (with a scene) clear of it by more than the clearance.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from robokin import _native
from robokin._validation import check_finite_number
from robokin.exceptions import InputError

__all__ = ["Costs"]


@dataclass(frozen=True)
class Costs:
    """Weights and margins of the process objective (see the module docstring).

    Attributes:
        travel_weight: ``w_t``, cost per radian (metre) of joint travel.
        singularity_weight: ``w_s``, cost of one waypoint at zero manipulability.
        singularity_margin: ``m_s``, relative manipulability below which a
            waypoint starts to cost (0.05: 5 % of the arm's best).
        singular_tol: Relative manipulability below which a configuration is
            singular and never used.
        limit_weight: ``w_l``, cost of one joint of one waypoint at its limit.
        limit_margin: ``m_l``, distance to a limit [rad, m] below which a joint
            starts to cost.
    """

    travel_weight: float = 1.0
    singularity_weight: float = 0.1
    singularity_margin: float = 0.05
    singular_tol: float = 1e-3
    limit_weight: float = 0.1
    limit_margin: float = math.radians(5.0)

    def __post_init__(self) -> None:
        """Check every field: a finite number >= 0 (``travel_weight`` > 0)."""
        for name in ("travel_weight", "singularity_weight", "singularity_margin",
                     "singular_tol", "limit_weight", "limit_margin"):
            v = check_finite_number(getattr(self, name), name)
            if v < 0.0 or (name == "travel_weight" and v == 0.0):
                bound = "> 0" if name == "travel_weight" else ">= 0"
                raise InputError(name, f"expected a finite number {bound}, got {v}")
            object.__setattr__(self, name, v)

    def node_weights(self, mu_ref: float) -> np.ndarray:
        """The weights vector of the compiled node kernel (``process_nodes``)."""
        k = _native.kernels
        w = np.zeros(k.PW_N)
        w[k.PW_SING_W] = self.singularity_weight
        w[k.PW_SING_MARGIN] = self.singularity_margin
        w[k.PW_SING_TOL] = self.singular_tol
        w[k.PW_MU_REF] = mu_ref
        w[k.PW_LIM_W] = self.limit_weight
        w[k.PW_LIM_MARGIN] = self.limit_margin
        return w
