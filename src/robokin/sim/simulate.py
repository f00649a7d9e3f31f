"""Co-simulation of a planned motion: MuJoCo drives the plan through the servos.

:func:`simulate` builds the robot's MuJoCo model (:mod:`robokin.sim.mjcf`, the
robot placed in the scene), starts it at the plan's first sample and steps it at
``dt`` (1 kHz by default, never slower), the plan's samples interpolated
linearly as the servos' set points (position, and velocity for the
feed-forward). It records the joints' angles, velocities and actuator torques,
and every contact with its bodies and time, and compares the run with the plan
(:func:`robokin.trajectory.compare`: tracking error per joint and its
correlation with the plan's acceleration).

Contacts: with ``contacts="detect"`` (the default) they exert no force (the
robot follows its servos through an obstacle, like V-REP's collision-detection
module) and are found by MuJoCo's collision detection after every step; with
``"physical"`` they push back. Either way the pairs are robokin's: scene objects
against moving links, and the link pairs the robot's geometry checks.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import numpy.typing as npt

from robokin._text import short_repr
from robokin.exceptions import InputError
from robokin.sim.mjcf import MjcfExport, build_mjcf

if TYPE_CHECKING:
    from robokin.collision.scene import Scene
    from robokin.robot import Robot
    from robokin.trajectory.compare import Comparison
    from robokin.trajectory.samples import Trajectory

__all__ = ["Contact", "SimResult", "check_trajectory", "simulate"]

F64 = npt.NDArray[np.float64]
ContactMode = Literal["detect", "physical"]

#: Default tracking tolerance: 0.5 deg for angles, 1 mm for lengths.
DEFAULT_TOLERANCE = (math.radians(0.5), 1e-3)


@dataclass(frozen=True)
class Contact:
    """One contact interval between two bodies.

    Attributes:
        body_a: A robot link (base, a chain joint's link, or tool).
        body_b: A scene object, or another robot link.
        t_start: First time MuJoCo reported it [s].
        t_end: Last time it was reported [s].
        depth: Deepest penetration over the interval [m] (>= 0).
        point: Where the deepest penetration was, world frame (3,) [m].
    """

    body_a: str
    body_b: str
    t_start: float
    t_end: float
    depth: float
    point: tuple[float, float, float]


@dataclass(frozen=True, eq=False)
class SimResult:
    """What :func:`simulate` recorded, at the plan's sample times.

    Attributes:
        t: Sample times of the plan (m,) [s].
        q: Simulated joint coordinates (m, n) [rad, m].
        qd: Simulated joint rates (m, n) [rad/s, m/s].
        tau: Torques [N m] (forces [N]) the actuators apply at the joint
            coordinates, gravity compensation included, (m, n).
        phi: Simulated motor coordinates (m, k) [rad] for a motor-driven run,
            else None.
        motor_tau: Motor torques ``A^T tau`` (m, k) for a motor-driven run, else None.
        contacts: Every contact interval, in order of start time.
        plan: The plan in joint space.
        comparison: :func:`robokin.trajectory.compare` of the run with the plan.
        torque_limits: Per joint coordinate [N m, N] (inf: none), (n,).
        export: The MuJoCo model and its bookkeeping (gains, notes, ...).
        wall_time: Seconds spent stepping MuJoCo (contact detection included).
        steps: Physics steps taken.
        tolerance: Tracking tolerance (angles [rad], lengths [m]) of the verdict.
    """

    t: F64
    q: F64
    qd: F64
    tau: F64
    phi: F64 | None
    motor_tau: F64 | None
    contacts: tuple[Contact, ...]
    plan: Trajectory
    comparison: Comparison
    torque_limits: F64
    export: MjcfExport
    wall_time: float
    steps: int
    tolerance: tuple[float, float]

    @property
    def duration(self) -> float:
        """Simulated time [s]."""
        return float(self.t[-1] - self.t[0])

    @property
    def real_time_factor(self) -> float:
        """Wall time per simulated second (below 1: faster than real time)."""
        return self.wall_time / self.duration if self.duration > 0 else math.inf

    @property
    def peak_tau(self) -> F64:
        """Largest ``|tau|`` per joint, (n,)."""
        return np.abs(self.tau).max(axis=0)

    @property
    def torque_ratio(self) -> F64:
        """Peak torque over the limit per joint (nan where there is no limit), (n,)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(np.isfinite(self.torque_limits),
                            self.peak_tau / self.torque_limits, np.nan)

    def trajectory(self) -> Trajectory:
        """The simulated motion as a joint-space Trajectory (qdd differentiated)."""
        from robokin.trajectory.samples import Trajectory

        qdd = np.gradient(self.qd, self.t, axis=0) if len(self.t) > 1 \
            else np.zeros_like(self.qd)
        return Trajectory(self.t, self.q, self.qd, qdd, joint_names=self.plan.joint_names,
                          is_revolute=self.plan.revolute())

    @property
    def reasons(self) -> tuple[str, ...]:
        """Why the verdict fails (empty when it passes)."""
        out = []
        tol = np.where(self.plan.revolute(), self.tolerance[0], self.tolerance[1])
        bad = self.comparison.max_abs > tol
        names = self.plan.names()
        for j in np.flatnonzero(bad):
            rev = bool(self.plan.revolute()[j])
            s, u = (180 / math.pi, "deg") if rev else (1000.0, "mm")
            out.append(f"{names[j]} tracks within {self.comparison.max_abs[j] * s:.3g} {u},"
                       f" more than the {tol[j] * s:.3g} {u} allowed")
        ratio = self.torque_ratio
        for j in np.flatnonzero(np.nan_to_num(ratio) >= 1.0 - 1e-9):
            out.append(f"{names[j]} saturates at its torque limit "
                       f"{self.torque_limits[j]:.4g}")
        if self.contacts:
            c = self.contacts[0]
            out.append(f"{len(self.contacts)} contact(s), the first {c.body_a}-{c.body_b} "
                       f"at {c.t_start:.3f} s")
        return tuple(out)

    @property
    def ok(self) -> bool:
        """True when the run tracks, stays inside the torque limits and touches nothing.

        Tracking: every joint within ``tolerance`` of the plan.
        """
        return not self.reasons


def check_trajectory(robot: Robot, traj: Any) -> tuple[Trajectory, bool]:
    """The plan in joint space, and whether it came in motor coordinates.

    Raises:
        InputError: not a Trajectory, a trajectory for another robot (joint
            count or names), motor coordinates for a robot without motors,
            non-finite samples, or fewer than two samples (naming ``traj``).
    """
    from robokin.trajectory.samples import Trajectory

    if not isinstance(traj, Trajectory):
        raise InputError("traj", f"expected a robokin Trajectory, got {short_repr(traj)}")
    motors = traj.space == "actuator"
    if motors:
        if robot.actuators is None:
            raise InputError("traj", f"is in actuator (motor) space, but {robot.name} has "
                             "no actuator map")
        want, names, what = robot.actuators.n_in, robot.actuator_names, "motors"
    else:
        want, names, what = robot.n, robot.joint_names, "joints"
    if traj.n != want:
        raise InputError("traj", f"has {traj.n} columns, but {robot.name} has {want} "
                         f"{what} {list(names or ())}: a trajectory for another robot?")
    if traj.joint_names is not None and names is not None \
            and tuple(traj.joint_names) != tuple(names):
        raise InputError("traj", f"is for {what} {list(traj.joint_names)}, but "
                         f"{robot.name} has {list(names)}: a trajectory for another robot?")
    if len(traj) < 2:
        raise InputError("traj", "needs at least two samples")
    for key in ("t", "q", "qd", "qdd"):
        if not np.isfinite(getattr(traj, key)).all():
            raise InputError("traj", f"holds a non-finite value in {key}")
    plan = traj.to_joint_space(robot) if motors else traj
    if plan.joint_names is None:
        plan = plan.replace(joint_names=robot.joint_names)
    if plan.is_revolute is None:
        plan = plan.replace(is_revolute=robot.is_revolute)
    return plan, motors


def _check_dt(dt: Any) -> float:
    ok = isinstance(dt, int | float) and not isinstance(dt, bool) and math.isfinite(dt)
    if not ok or not 1e-5 <= dt <= 1e-3:
        raise InputError("dt", f"expected a physics step in [1e-5, 1e-3] s (1 kHz or "
                         f"faster), got {short_repr(dt)}")
    return float(dt)


def _check_tolerance(tolerance: Any) -> tuple[float, float]:
    try:
        a, b = (float(v) for v in tolerance)
    except (TypeError, ValueError):
        raise InputError("tolerance", "expected (angle [rad], length [m]), got "
                         f"{short_repr(tolerance)}") from None
    if not (a > 0 and b > 0 and math.isfinite(a) and math.isfinite(b)):
        raise InputError("tolerance", f"expected two finite values > 0, got {(a, b)}")
    return a, b


class _ContactLog:
    """Contact intervals from per-step contact lists."""

    def __init__(self, model: Any, robot_links: tuple[str, ...]) -> None:
        mj = _mj()
        body_names = [mj.mj_id2name(model, mj.mjtObj.mjOBJ_BODY, b) or ""
                      for b in range(model.nbody)]
        self.geom_body = [body_names[b] for b in model.geom_bodyid]
        self.rank = {nm: k for k, nm in enumerate(robot_links)}
        self.open: dict[tuple[str, str], list[Any]] = {}
        self.done: list[Contact] = []

    def _pair(self, a: str, b: str) -> tuple[str, str]:
        ra, rb = self.rank.get(a, 10**6), self.rank.get(b, 10**6)
        return (a, b) if ra <= rb else (b, a)

    def step(self, data: Any, t: float) -> None:
        seen: dict[tuple[str, str], tuple[float, np.ndarray]] = {}
        for i in range(data.ncon):
            c = data.contact[i]
            if c.dist > 0.0:
                continue
            g1, g2 = int(c.geom[0]), int(c.geom[1])
            pair = self._pair(self.geom_body[g1], self.geom_body[g2])
            depth = -float(c.dist)
            if pair not in seen or depth > seen[pair][0]:
                seen[pair] = (depth, np.array(c.pos))
        for pair, (depth, pos) in seen.items():
            cur = self.open.get(pair)
            if cur is None:
                self.open[pair] = [t, t, depth, pos]
            else:
                cur[1] = t
                if depth > cur[2]:
                    cur[2], cur[3] = depth, pos
        for pair in [p for p in self.open if p not in seen]:
            self._close(pair)

    def _close(self, pair: tuple[str, str]) -> None:
        t0, t1, depth, pos = self.open.pop(pair)
        self.done.append(Contact(pair[0], pair[1], float(t0), float(t1), float(depth),
                                 tuple(float(v) for v in pos)))  # type: ignore[arg-type]

    def contacts(self) -> tuple[Contact, ...]:
        for pair in list(self.open):
            self._close(pair)
        return tuple(sorted(self.done, key=lambda c: (c.t_start, c.body_a, c.body_b)))


def _mj() -> Any:
    from robokin.sim._mujoco import mujoco

    return mujoco()


def _set_points(plan: Trajectory, times: F64) -> tuple[F64, F64]:
    """Plan positions and rates at the step times (linear interpolation), (N, k)."""
    x = np.stack([np.interp(times, plan.t, plan.q[:, j]) for j in range(plan.n)], -1)
    v = np.stack([np.interp(times, plan.t, plan.qd[:, j]) for j in range(plan.n)], -1)
    return x, v


def _at(t_src: F64, values: F64, t: F64) -> F64:
    return np.stack([np.interp(t, t_src, values[:, j]) for j in range(values.shape[1])],
                    axis=-1)


def simulate(
    robot: Robot,
    traj: Trajectory,
    scene: Scene | None = None,
    *,
    gains: Any = None,
    dt: float = 0.001,
    contacts: ContactMode = "detect",
    strict: bool = False,
    density: float | None = None,
    torque_limits: npt.ArrayLike | None = None,
    tolerance: tuple[float, float] = DEFAULT_TOLERANCE,
    max_samples: int | None = None,
) -> SimResult:
    """Run a planned motion through the robot's servos in MuJoCo.

    Args:
        robot: The robot (mass data from its ``dynamics``, else estimated from
            its shapes; see :func:`robokin.model.dynamics.resolve_links`).
        traj: The plan: joint coordinates (a servo per joint), or motor
            coordinates (``traj.space == "actuator"``: a servo per motor acting
            through the actuator map).
        scene: The scene (robot placement, tool, objects to touch), or None.
        gains: Servo gains (:func:`robokin.sim.servo.servo_gains`); the default
            gains are tuned at 16 configurations of the plan.
        dt: Physics step [s], at most 1e-3 (1 kHz); divided when stiff servos
            need it (``res.export.timestep``).
        contacts: ``"detect"`` (contacts exert no force) or ``"physical"``.
        strict: Refuse to estimate missing link mass data.
        density: Density for estimated links [kg/m^3].
        torque_limits: Per joint [N m, N]; default the robot's.
        tolerance: Largest tracking error of the verdict ``(angle [rad], length [m])``.
        max_samples: Most physics steps the run may record (default
            :data:`robokin.trajectory.joint.MAX_SAMPLES`), checked before any
            array of the run is allocated.

    Returns:
        A :class:`SimResult` at the plan's sample times.

    Raises:
        InputError: a trajectory for another robot, non-finite or non-positive
            gains, a bad ``dt``, ``contacts``, ``tolerance``, ``max_samples`` or
            torque limits, a plan longer than ``max_samples`` physics steps
            (naming ``traj``).
        ModelError: missing mass data in strict mode (naming the field), or a
            model MuJoCo refuses.
        MissingExtraError: MuJoCo is not installed (``robokin[sim]``).
    """
    from robokin.sim._mujoco import load_model
    from robokin.trajectory.compare import compare
    from robokin.trajectory.joint import check_max_samples

    plan, motors = check_trajectory(robot, traj)
    dt = _check_dt(dt)
    tol = _check_tolerance(tolerance)
    cap = check_max_samples(max_samples)
    if contacts not in ("detect", "physical"):
        raise InputError("contacts", f"expected 'detect' or 'physical', got "
                         f"{short_repr(contacts)}")
    pick = np.linspace(0, len(plan) - 1, min(16, len(plan))).round().astype(int)
    export = build_mjcf(robot, scene, actuators="motor" if motors else "joint",
                        gains=gains, torque_limits=torque_limits, strict=strict,
                        density=density, timestep=dt,
                        contact_forces=contacts == "physical", q_ref=plan.q[pick])
    mj = _mj()
    model = load_model(export.xml)
    data = mj.MjData(model)
    run = _Run(model, data, export, plan, traj if motors else plan, contacts, cap)
    t0 = time.perf_counter()
    run.step_all()
    wall = time.perf_counter() - t0
    q = _at(run.times, run.q, plan.t)
    qd = _at(run.times, run.qd, plan.t)
    tau = _at(run.times[:-1], run.tau, plan.t)
    placed = export.robot
    phi = motor_tau = None
    if motors and placed.actuators is not None:
        phi = placed.actuators.inverse(q, what="actuator map")
        motor_tau = tau @ placed.actuators.matrix
    from robokin.trajectory.samples import Trajectory

    sim_traj = Trajectory(plan.t, q, qd, np.zeros_like(q), joint_names=plan.joint_names,
                          is_revolute=plan.revolute())
    return SimResult(
        t=np.array(plan.t), q=q, qd=qd, tau=tau, phi=phi, motor_tau=motor_tau,
        contacts=run.log.contacts(), plan=plan, comparison=compare(plan, sim_traj),
        torque_limits=export.torque_limits, export=export, wall_time=wall,
        steps=run.n_steps, tolerance=tol)


class _Run:
    """One stepping loop: set points in, states, torques and contacts out."""

    def __init__(self, model: Any, data: Any, export: MjcfExport, plan: Trajectory,
                 drive: Trajectory, contacts: ContactMode, max_samples: int) -> None:
        from robokin.trajectory.joint import check_sample_count

        mj = _mj()
        self.mj, self.model, self.data = mj, model, data
        _, dadr, S = export.joints.selection(model)
        # the servos' damping matrix over the dofs: implicitfast integrates it
        # implicitly, so the force the actuators apply is qfrc_actuator - dt D a
        G = np.zeros((export.moments.shape[0], model.nv))
        G[:, dadr] = export.moments
        self.D = G.T @ (export.kv[:, None] * G)
        self.limits = export.torque_limits
        master = export.joints.master_qpos(model)
        self.S = S
        self.qadr_master = master
        self.dadr_master = np.array([model.jnt_dofadr[np.flatnonzero(
            model.jnt_qposadr == a)[0]] for a in master], dtype=np.int64)
        dt = export.timestep  # the requested step, or a fraction of it
        check_sample_count(float(plan.t[-1] - plan.t[0]), dt, max_samples,
                           argument="traj")
        n_steps = max(1, int(round((plan.t[-1] - plan.t[0]) / dt)))
        self.n_steps = n_steps
        self.times = plan.t[0] + dt * np.arange(n_steps + 1)
        x, v = _set_points(drive, self.times[:-1])
        ff = (export.kv / export.kp) if export.velocity_feedforward else 0.0
        self.ctrl = x + ff * v + export.ctrl_offset
        # initial state: the plan's first sample
        data.qpos[:] = export.joints.qpos(model, plan.q[0])
        data.qvel[:] = S @ plan.qd[0]
        mj.mj_forward(model, data)
        self.q = np.empty((n_steps + 1, plan.n))
        self.qd = np.empty((n_steps + 1, plan.n))
        self.tau = np.empty((n_steps, plan.n))
        self.q[0] = data.qpos[master]
        self.qd[0] = data.qvel[self.dadr_master]
        from robokin.model.geometry import link_names

        self.log = _ContactLog(model, link_names(export.robot))
        self.detect = contacts == "detect"
        self.flag = int(mj.mjtDisableBit.mjDSBL_CONTACT)

    def step_all(self) -> None:
        mj, m, d = self.mj, self.model, self.data
        ctrl, S = self.ctrl, self.S
        q, qd, tau = self.q, self.qd, self.tau
        master, dmaster = self.qadr_master, self.dadr_master
        log, times = self.log, self.times
        qfrc = np.empty((self.n_steps, m.nv))
        dv = np.empty((self.n_steps, m.nv))
        for k in range(self.n_steps):
            d.ctrl[:] = ctrl[k]
            dv[k] = d.qvel
            if not self.detect:
                mj.mj_step(m, d)
                log.step(d, times[k])  # contacts of the state the step started from
            else:
                mj.mj_step(m, d)
                m.opt.disableflags &= ~self.flag
                mj.mj_kinematics(m, d)
                mj.mj_collision(m, d)
                m.opt.disableflags |= self.flag
                log.step(d, times[k + 1])
            qfrc[k] = d.qfrc_actuator
            dv[k] = d.qvel - dv[k]
            q[k + 1] = d.qpos[master]
            qd[k + 1] = d.qvel[dmaster]
        tau[:] = (qfrc - dv @ self.D.T) @ S  # dv = dt a: the implicit damping
        # A saturated servo gives its limit: MuJoCo's implicit step keeps damping it
        # (by dt kv |a|, a numerical artefact, not motor torque), so report the limit.
        lim = np.where(np.isfinite(self.limits), self.limits, np.inf)
        sat = np.abs(qfrc[:, dmaster]) >= np.where(np.isfinite(lim), lim * (1 - 1e-9),
                                                   np.inf)
        tau[sat] = (qfrc @ S)[sat]
