"""The ADAMS check of a coupled drive in MuJoCo: motor commands against the joint plan.

The SCARA's shaft is driven by two motors through a ball screw and a ball
spline: turning the spline nut turns the shaft *and*, relative to the screw nut,
lifts it. Its motor commands must therefore be decoupled:
``phi = A^+ (q - b)`` (:meth:`robokin.trajectory.Trajectory.to_actuator_space`).
:func:`check_decoupling` drives the model's motors (tendons through the actuator
map, :mod:`robokin.sim.mjcf`) with those commands and shows the shaft's rotation
and height follow the joint plan; then with the *naive* commands, which give each
joint its own motor and ignore the coupling (for the SCARA: motor 4 turns the
shaft at ``j : 1``, motor 3 lifts it as a plain screw), and shows they do not:
the shaft then rises by one lead per turn it makes.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from robokin.exceptions import InputError
from robokin.sim.simulate import (
    DEFAULT_TOLERANCE,
    SimResult,
    check_trajectory,
    simulate,
)

if TYPE_CHECKING:
    from robokin.robot import Robot
    from robokin.trajectory.samples import Trajectory

__all__ = ["DecouplingCheck", "check_decoupling", "naive_actuator_map"]

F64 = npt.NDArray[np.float64]


def naive_actuator_map(matrix: npt.ArrayLike) -> F64:
    """The actuator matrix with every coupling dropped.

    Each joint keeps the entry of one motor (a one-to-one assignment of motors to
    joints that keeps the largest entries), every other entry is zeroed: what a
    controller that knew only the ratios, not the coupling, would use.

    Args:
        matrix: ``A`` of ``q = A phi + b``, (n, n).

    Raises:
        InputError: ``A`` is not square.
    """
    from scipy.optimize import linear_sum_assignment

    A = np.asarray(matrix, dtype=np.float64)
    if A.ndim != 2 or A.shape[0] != A.shape[1]:
        raise InputError("matrix", f"expected a square actuator matrix, got {A.shape}")
    rows, cols = linear_sum_assignment(-np.abs(A))
    out = np.zeros_like(A)
    out[rows, cols] = A[rows, cols]
    return out


@dataclass(frozen=True, eq=False)
class DecouplingCheck:
    """Decoupled versus naive motor commands of one joint plan, simulated.

    Attributes:
        decoupled: The run driven by ``phi = A^+ (q - b)``.
        naive: The run driven by the naive commands (:func:`naive_actuator_map`).
        joints: Indices of the coupled joints (for the SCARA: rotation, lift).
        decoupled_error: Largest ``|q_sim - q_plan|`` of those joints, decoupled
            commands [rad, m].
        naive_error: The same with the naive commands.
        tolerance: ``(angle [rad], length [m])`` a joint that follows must stay within.
    """

    decoupled: SimResult
    naive: SimResult
    joints: tuple[int, ...]
    decoupled_error: F64
    naive_error: F64
    tolerance: tuple[float, float]

    @property
    def passed(self) -> bool:
        """The decoupled commands follow the plan and the naive ones do not."""
        rev = self.decoupled.plan.revolute()[list(self.joints)]
        tol = np.where(rev, self.tolerance[0], self.tolerance[1])
        return bool(np.all(self.decoupled_error <= tol)
                    and np.any(self.naive_error > tol))


def _coupled_joints(A: np.ndarray) -> tuple[int, ...]:
    nz = np.abs(A) > 0
    coupled = set()
    for r in range(A.shape[0]):
        if nz[r].sum() > 1:
            coupled.add(r)
    for c in range(A.shape[1]):
        rows = np.flatnonzero(nz[:, c])
        if len(rows) > 1:
            coupled.update(int(r) for r in rows)
    return tuple(sorted(coupled))


def check_decoupling(
    robot: Robot,
    traj: Trajectory,
    *,
    gains: Any = None,
    dt: float = 0.001,
    tolerance: tuple[float, float] = DEFAULT_TOLERANCE,
) -> DecouplingCheck:
    """Simulate a joint plan through the motors, decoupled and naively.

    Args:
        robot: A robot whose actuator map couples joints (the SCARA).
        traj: A joint-space plan.
        gains: Motor servo gains (:func:`robokin.sim.servo.servo_gains`).
        dt: Physics step [s] (<= 1e-3).
        tolerance: ``(angle [rad], length [m])`` of "follows the plan".

    Returns:
        A :class:`DecouplingCheck`.

    Raises:
        InputError: a robot without a coupled actuator map, or a plan in motor
            coordinates or for another robot.
    """
    from robokin.trajectory.compare import compare
    from robokin.trajectory.samples import Trajectory

    if robot.actuators is None:
        raise InputError("robot", f"{robot.name} has no actuator map (motors)")
    A, b = robot.actuators.matrix, robot.actuators.offset
    joints = _coupled_joints(A)
    if not joints:
        raise InputError("robot", f"{robot.name}'s motors drive one joint each: "
                         "there is no coupling to check")
    if traj.space != "joint":
        raise InputError("traj", "expected a joint-space plan")
    plan, _ = check_trajectory(robot, traj)
    motors = plan.to_actuator_space(robot)
    decoupled = simulate(robot, motors, gains=gains, dt=dt, tolerance=tolerance)
    Ainv = np.linalg.inv(naive_actuator_map(A))
    naive_cmd = Trajectory(
        plan.t, (plan.q - b) @ Ainv.T, plan.qd @ Ainv.T, plan.qdd @ Ainv.T,
        joint_names=robot.actuator_names, space="actuator",
        is_revolute=np.ones(A.shape[1], bool))
    naive = simulate(robot, naive_cmd, gains=gains, dt=dt, tolerance=tolerance)
    j = list(joints)
    err_dec = np.abs(compare(plan, decoupled.trajectory()).error[:, j]).max(axis=0)
    err_naive = np.abs(compare(plan, naive.trajectory()).error[:, j]).max(axis=0)
    return DecouplingCheck(decoupled, naive, joints, err_dec, err_naive,
                           (float(tolerance[0]), float(tolerance[1])))

