"""Inverse dynamics along a plan: the joint torques and motor power it needs.

For every sample of the plan, MuJoCo's ``mj_inverse`` (constraints off: the
rigid-body equation ``tau = M(q) qdd + c(q, qd) + g(q)``) gives the generalised
force at every MuJoCo joint; the virtual work of the robot's coordinates turns
them into one torque (force) per joint coordinate, ``tau_q = S^T tau``
(``x = S q`` the joint map of :mod:`robokin.sim.mjcf`), and per motor
``tau_phi = A^T tau_q``. Power is ``tau * qd`` per joint (per motor
``tau_phi * phid``: the same total). The feasibility check compares the peak
torques with the robot's torque limits.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from robokin.model.dynamics import ResolvedLinks
from robokin.sim.mjcf import build_mjcf
from robokin.sim.simulate import check_trajectory

if TYPE_CHECKING:
    from robokin.collision.scene import Scene
    from robokin.robot import Robot
    from robokin.trajectory.samples import Trajectory

__all__ = ["InverseDynamics", "inverse_dynamics"]

F64 = npt.NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class InverseDynamics:
    """The torques and power a plan needs (:func:`inverse_dynamics`).

    Attributes:
        t: Sample times (m,) [s].
        tau: Joint torques [N m] (forces [N]), (m, n).
        power: Joint power ``tau * qd`` [W], (m, n).
        motor_tau: Motor torques ``A^T tau`` (m, k), or None without motors.
        motor_power: Motor power (m, k) [W], or None.
        torque_limits: Per joint [N m, N] (inf: none), (n,).
        joint_names: Names (n,).
        motor_names: Names (k,), or None.
        links: The mass properties used, and where they come from.
    """

    t: F64
    tau: F64
    power: F64
    motor_tau: F64 | None
    motor_power: F64 | None
    torque_limits: F64
    joint_names: tuple[str, ...]
    motor_names: tuple[str, ...] | None
    links: ResolvedLinks

    @property
    def peak(self) -> F64:
        """Largest ``|tau|`` per joint, (n,)."""
        return np.abs(self.tau).max(axis=0)

    @property
    def ratio(self) -> F64:
        """Peak torque over the limit per joint (nan without a limit), (n,)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(np.isfinite(self.torque_limits),
                            self.peak / self.torque_limits, np.nan)

    @property
    def feasible(self) -> bool:
        """True when no joint needs more than its limit (joints without one pass)."""
        return bool(np.all(np.nan_to_num(self.ratio) <= 1.0 + 1e-12))

    @property
    def violations(self) -> tuple[str, ...]:
        """One sentence per joint over its limit: when first, and by how much."""
        out = []
        over = np.abs(self.tau) > self.torque_limits
        for j in np.flatnonzero(over.any(axis=0)):
            k = int(np.argmax(over[:, j]))
            out.append(f"{self.joint_names[j]} needs {self.peak[j]:.4g} (limit "
                       f"{self.torque_limits[j]:.4g}), first over at t = "
                       f"{self.t[k]:.3f} s")
        return tuple(out)

    @property
    def peak_power(self) -> F64:
        """Largest ``|power|`` per joint [W], (n,)."""
        return np.abs(self.power).max(axis=0)

    @property
    def energy(self) -> F64:
        """Positive mechanical work per joint over the plan [J], (n,).

        Regenerated (negative) power is not counted.
        """
        p = np.maximum(self.power, 0.0)
        return (0.5 * (p[1:] + p[:-1]) * np.diff(self.t)[:, None]).sum(axis=0)


def inverse_dynamics(
    robot: Robot,
    traj: Trajectory,
    scene: Scene | None = None,
    *,
    strict: bool = False,
    density: float | None = None,
    torque_limits: npt.ArrayLike | None = None,
) -> InverseDynamics:
    """Joint torques, motor torques and power along a plan (MuJoCo ``mj_inverse``).

    Args:
        robot: The robot (mass data from its ``dynamics``, else estimated).
        traj: The plan, in joint or motor coordinates (positions, rates and
            accelerations are used as given).
        scene: The scene (the robot's placement and tool), or None.
        strict: Refuse to estimate missing link mass data.
        density: Density for estimated links [kg/m^3].
        torque_limits: Per joint [N m, N]; default the robot's.

    Returns:
        An :class:`InverseDynamics`.

    Raises:
        InputError: a trajectory for another robot or with non-finite samples.
        ModelError: missing mass data in strict mode.
        MissingExtraError: MuJoCo is not installed (``robokin[sim]``).
    """
    from robokin.sim._mujoco import load_model, mujoco

    plan, _ = check_trajectory(robot, traj)
    export = build_mjcf(robot, scene, gains={"gravity_compensation": False},
                        torque_limits=torque_limits, strict=strict, density=density)
    mj = mujoco()
    model = load_model(export.xml)
    model.opt.disableflags |= int(mj.mjtDisableBit.mjDSBL_CONSTRAINT)
    data = mj.MjData(model)
    qadr, _, S = export.joints.selection(model)
    X = export.joints.matrix
    m = len(plan)
    qfrc = np.empty((m, model.nv))
    vel, acc = plan.qd @ S.T, plan.qdd @ S.T
    for k in range(m):
        data.qpos[:] = model.qpos0
        data.qpos[qadr] = X @ plan.q[k]
        data.qvel[:] = vel[k]
        data.qacc[:] = acc[k]
        mj.mj_inverse(model, data)
        qfrc[k] = data.qfrc_inverse
    tau = qfrc @ S
    power = tau * plan.qd
    placed = export.robot
    motor_tau = motor_power = None
    if placed.actuators is not None:
        motor_tau = tau @ placed.actuators.matrix
        phid = placed.actuators.inverse_rate(plan.qd, what="actuator map")
        motor_power = motor_tau * phid
    return InverseDynamics(
        t=np.array(plan.t), tau=tau, power=power, motor_tau=motor_tau,
        motor_power=motor_power, torque_limits=export.torque_limits,
        joint_names=tuple(placed.joint_names),
        motor_names=None if placed.actuators is None else placed.actuator_names,
        links=export.links)
