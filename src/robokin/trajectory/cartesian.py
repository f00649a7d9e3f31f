"""Cartesian straight-line segments and the path-following IK behind them.

A line moves the tool's origin linearly from ``T_start`` to ``T_goal`` and turns
its orientation by slerp (a rotation about one fixed axis), both driven by one
time scaling ``s(t)``. It is converted to joints by *path following*: each sample
is solved by Newton / damped-least-squares steps started from the previous
sample's solution, so the joint path is continuous by construction and stays on
the branch it starts on (no elbow or wrist flips). The first sample that cannot
be followed is reported with its index, time and reason: out of reach, a joint
limit, a singularity (the joints would jump), or no convergence.

Velocities come from the Jacobian, ``qd = J^+ [v; w]``, and accelerations from
``qdd = J^+ ([a; alpha] - Jdot qd)`` with ``Jdot qd`` a directional finite
difference, so both are exact to the model (not differentiated samples).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy as np
import numpy.typing as npt

from robokin._native import kernels as _k
from robokin._validation import check_finite, check_joints, check_transform
from robokin.exceptions import InputError, RobokinError
from robokin.spatial import (
    rotation_from_rotvec,
    rotvec_from_rotation,
    wrap_angle,
)
from robokin.trajectory.joint import time_grid
from robokin.trajectory.profiles import Profile, get_profile
from robokin.trajectory.samples import Trajectory

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = [
    "PathError",
    "PathFollowResult",
    "cartesian_line",
    "follow_poses",
    "line_poses",
]

IKMode = Literal["follow", "analytic", "numeric"]


class PathError(RobokinError):
    """A Cartesian path cannot be followed.

    Attributes:
        index: First sample that fails.
        time: Its time [s] (from the segment start), or None.
        reason: Why (out of reach, joint limit, singularity, not converged).
        result: The :class:`PathFollowResult` (joints up to the failure).
    """

    def __init__(self, result: PathFollowResult, what: str = "path"):
        """Carry the failing sample (index, time) and the reason of ``result``."""
        self.index = result.first_failure
        self.time = result.failure_time
        self.reason = result.reason
        self.result = result
        when = "" if self.time is None else f" at t = {self.time:.4f} s"
        super().__init__(f"{what} cannot be followed: sample {self.index}{when}: "
                         f"{self.reason}")


@dataclass(frozen=True, eq=False)
class PathFollowResult:
    """The outcome of :func:`follow_poses`.

    Attributes:
        q: Joint path (m, n); rows from ``first_failure`` on repeat the last good one.
        success: (m,) bool.
        error: (m,) residual per sample, max of position [m] and rotation [rad].
        first_failure: Index of the first failed sample, or None.
        failure_time: Its time [s] when times were given, else None.
        reason: ``"followed"`` or why the path stops.
        kind: ``"ok"``, ``"out_of_reach"``, ``"joint_limit"``, ``"singularity"``
            or ``"not_converged"``.
    """

    q: np.ndarray
    success: np.ndarray
    error: np.ndarray
    first_failure: int | None
    failure_time: float | None
    reason: str
    kind: str

    def __bool__(self) -> bool:
        """True when every sample was followed."""
        return self.first_failure is None


# ------------------------------------------------------------------ line geometry
def line_poses(T_start: npt.ArrayLike, T_goal: npt.ArrayLike, s: npt.ArrayLike
               ) -> np.ndarray:
    """Poses along a straight line: position linear in ``s``, orientation by slerp.

    Args:
        T_start: Start pose (4, 4).
        T_goal: Goal pose (4, 4).
        s: Path parameters (m,) in [0, 1].

    Returns:
        Poses (m, 4, 4).
    """
    T0 = check_transform(T_start, "T_start")
    T1 = check_transform(T_goal, "T_goal")
    s = np.asarray(s, dtype=np.float64).reshape(-1)
    w = rotvec_from_rotation(T0[:3, :3].T @ T1[:3, :3])  # body-frame rotation vector
    out = np.zeros((s.size, 4, 4))
    out[:, :3, :3] = T0[:3, :3] @ rotation_from_rotvec(s[:, None] * w)
    out[:, :3, 3] = T0[:3, 3] + s[:, None] * (T1[:3, 3] - T0[:3, 3])
    out[:, 3, 3] = 1.0
    return out


# --------------------------------------------------------------- path following
def _err(T: np.ndarray, Tt: np.ndarray, e: np.ndarray) -> float:
    """Fill ``e`` (6,) with the base-frame pose error; return its largest component.

    The error runs from the current pose to the target: the compiled residual of
    :func:`robokin.spatial.pose_error`, called directly because ``T`` and ``Tt``
    are the follower's own C-contiguous float64 (4, 4) poses (the argument checks
    ``pose_error`` makes on a user's input were ~40 % of a 1,000-sample line).
    """
    _k.pose_error(T.reshape(1, 4, 4), Tt.reshape(1, 4, 4), e.reshape(1, 6))
    return float(np.abs(e).max())


def follow_poses(
    robot: Robot,
    T_path: npt.ArrayLike,
    q_start: npt.ArrayLike,
    *,
    times: npt.ArrayLike | None = None,
    tol: float = 1e-12,
    max_iterations: int = 50,
    max_jump: float = 0.3,
    damping: float = 1e-6,
    singular_tol: float = 1e-5,
    check_limits: bool = True,
    seeds: npt.ArrayLike | None = None,
) -> PathFollowResult:
    """Follow a sequence of poses with joints, each warm-started from the last.

    Newton steps ``dq = J^T (J J^T + lambda^2 I)^-1 e`` (damped least squares;
    ``e`` from :func:`robokin.spatial.pose_error`'s convention, base frame),
    started from the previous sample's solution extrapolated linearly, iterate to
    ``tol``. Works for every arm (fewer or more than six joints too).

    Args:
        robot: The :class:`~robokin.robot.Robot`.
        T_path: Target poses (m, 4, 4) [m].
        q_start: Configuration (n,) near the first pose (the branch to keep).
        times: (m,) sample times [s], used in the failure report.
        tol: Residual [m and rad] a sample must reach.
        max_iterations: Newton iterations per sample.
        max_jump: Largest joint change between samples [rad or m] before the
            path counts as passing a singularity / flipping branch.
        damping: ``lambda`` of the damped least squares.
        singular_tol: Smallest Jacobian singular value accepted at a solution.
        check_limits: Stop where a joint leaves ``robot.limits``.
        seeds: (m, n) start points per sample (e.g. closed-form solutions)
            instead of the extrapolated previous solution.

    Returns:
        A :class:`PathFollowResult`.

    Raises:
        InputError: bad poses or ``q_start``.
    """
    from robokin.kinematics.jacobian import jacobian_and_pose

    Tp = np.ascontiguousarray(check_transform(T_path, "T_path"))
    if Tp.ndim != 3:
        raise InputError("T_path", f"expected shape (m, 4, 4), got {Tp.shape}")
    n = robot.n
    q0 = check_finite(check_joints(q_start, n, "q_start"), "q_start").reshape(-1)
    if q0.shape != (n,):
        raise InputError("q_start", f"expected shape ({n},), got {q0.shape}")
    m = Tp.shape[0]
    tt = None if times is None else np.asarray(times, dtype=np.float64).reshape(-1)
    chain = robot.chain
    lim = robot.limits
    names = robot.joint_names
    lam2 = damping * damping
    if seeds is not None:
        seeds = check_joints(seeds, n, "seeds").reshape(-1, n)
        if seeds.shape[0] != m:
            raise InputError("seeds", f"expected {m} rows, got {seeds.shape[0]}")
    Q = np.empty((m, n))
    err = np.full(m, np.inf)
    e = np.empty(6)
    q_prev = q0.copy()
    step = np.zeros(n)
    first, kind, reason = None, "ok", "followed"
    eye6 = np.eye(6)
    eyen = np.eye(n)
    for k in range(m):
        Tt = Tp[k]
        q = q_prev + step if seeds is None else seeds[k]
        best, q_best = np.inf, q
        J_best: np.ndarray | None = None
        stalled = 0
        for _ in range(max_iterations):
            J, T = jacobian_and_pose(chain, q)
            size = _err(T, Tt, e)
            if size < best:
                best, q_best, J_best = size, q, J
                stalled = 0
            else:
                stalled += 1
            if size <= tol or (size < 1e-10 and stalled) or stalled > 3:
                break
            if n >= 6:
                dq = J.T @ np.linalg.solve(J @ J.T + lam2 * eye6, e)
            else:
                dq = np.linalg.solve(J.T @ J + lam2 * eyen, J.T @ e)
            big = np.abs(dq).max()
            if big > 0.5:
                dq *= 0.5 / big
            q = q + dq
        q = q_best
        err[k] = best
        if best > max(tol, 1e-10) and best > 1e-9:
            J = jacobian_and_pose(chain, q)[0]
            sv = np.linalg.svd(J, compute_uv=False)
            if sv[-1] < 1e-3 * max(sv[0], 1e-300) or sv[-1] < singular_tol * 100:
                kind = "out_of_reach"
                reason = (f"out of reach: the arm stalls {best:.3g} from the target at a "
                          f"singular configuration (smallest singular value "
                          f"{sv[-1]:.2g}): the pose is outside the workspace")
            else:
                kind = "not_converged"
                reason = f"not converged (residual {best:.3g})"
            first = k
            break
        jump = np.abs(q - q_prev)
        if k and jump.max() > max_jump:
            j = int(np.argmax(jump))
            sv = np.linalg.svd(jacobian_and_pose(chain, q_prev)[0], compute_uv=False)
            kind = "singularity"
            reason = (f"singularity: joint {names[j]} would move {jump[j]:.3g} in one "
                      f"sample (max_jump {max_jump:g}); smallest Jacobian singular "
                      f"value {sv[-1]:.2g} at the previous sample")
            first = k
            break
        if check_limits:
            out = (q < lim[:, 0] - 1e-12) | (q > lim[:, 1] + 1e-12)
            if out.any():
                j = int(np.argmax(out))
                kind = "joint_limit"
                reason = (f"joint limit: {names[j]} would reach {q[j]:.6g} outside "
                          f"[{lim[j, 0]:.6g}, {lim[j, 1]:.6g}]")
                first = k
                break
        if singular_tol > 0 and n >= 6 and J_best is not None:
            J = J_best
            # sigma_min >= |det J| / ||J||_F^5 for a 6x6 J: skip the SVD when that
            # bound already clears the tolerance (nearly always).
            clear = n == 6 and (abs(np.linalg.det(J)) >
                                singular_tol * float((J * J).sum()) ** 2.5)
            sv_min = np.inf if clear else np.linalg.svd(J, compute_uv=False)[-1]
            if sv_min < singular_tol:
                kind = "singularity"
                reason = (f"singularity: smallest Jacobian singular value {sv_min:.2g} "
                          f"< {singular_tol:g}")
                first = k
                break
        Q[k] = q
        step = q - q_prev if k else np.zeros(n)
        q_prev = q
    success = np.zeros(m, bool)
    if first is None:
        success[:] = True
    else:
        success[:first] = True
        Q[first:] = Q[first - 1] if first else q0
    ftime = None if first is None or tt is None else float(tt[first])
    return PathFollowResult(Q, success, err, first, ftime, reason, kind)


def _follow_analytic(robot: Robot, Tp: np.ndarray, q0: np.ndarray, times, **kw
                     ) -> PathFollowResult:
    """All closed-form solutions per sample, the one nearest the previous kept.

    The chosen rows seed the follower's Newton polish; its jump, limit and
    singularity checks then apply as for ``ik="follow"``.
    """
    sols = robot.ik(Tp, q_near=q0, method="analytic")
    m, n = Tp.shape[0], robot.n
    Q = np.empty((m, n))
    prev = q0
    rev = robot.is_revolute
    for k in range(m):
        valid = sols.valid[k]
        if not valid.any():
            Q[k:] = prev
            succ = np.zeros(m, bool)
            succ[:k] = True
            ft = None if times is None else float(times[k])
            return PathFollowResult(Q, succ, np.where(succ, 0.0, np.inf), k, ft,
                                    f"out of reach: no closed-form solution "
                                    f"({sols.status[k]})", "out_of_reach")
        d = sols.q[k] - prev
        d = np.where(rev, wrap_angle(d), d)
        dn = np.where(valid, np.linalg.norm(d, axis=-1), np.inf)
        Q[k] = prev + d[int(np.argmin(dn))]
        prev = Q[k]
    return follow_poses(robot, Tp, q0, times=times, seeds=Q, **kw)


def _follow(robot, Tp, q0, times, ik: str, **kw) -> PathFollowResult:
    if ik == "follow":
        return follow_poses(robot, Tp, q0, times=times, **kw)
    if ik == "analytic":
        return _follow_analytic(robot, Tp, q0, times, **kw)
    if ik == "numeric":
        from robokin.kinematics.ik.numeric import ik_path

        r = ik_path(robot, Tp, q0, max_jump=kw.get("max_jump", 0.3),
                    tol=max(kw.get("tol", 1e-12), 1e-12))
        ft = None if r.first_failure is None or times is None else float(
            times[r.first_failure])
        return PathFollowResult(r.q, r.success, r.error, r.first_failure, ft, r.reason,
                                "ok" if r.first_failure is None else "not_converged")
    raise InputError("ik", f"expected 'follow', 'analytic' or 'numeric', got {ik!r}")


# ----------------------------------------------------------------- time scaling
def _scalar_quintic(T: float, v0: float, v1: float, t: np.ndarray):
    """s(t) from 0 to 1 in T with end rates v0, v1 [1/s], zero end accelerations."""
    from robokin.trajectory.joint import evaluate_polynomial, quintic_coefficients

    c = quintic_coefficients([0.0], [1.0], T, [v0], [v1], [0.0], [0.0])
    s, sd, sdd = evaluate_polynomial(c, t, T)
    return s[:, 0], sd[:, 0], sdd[:, 0]


def _rates(robot: Robot, q: np.ndarray, twist: np.ndarray, dtwist: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray]:
    """Joint rates ``qd = J^+ twist``, ``qdd = J^+ (dtwist - Jdot qd)`` per sample."""
    J = robot.jacobian(q)
    Jp = np.linalg.pinv(J, rcond=1e-10)
    qd = np.einsum("mij,mj->mi", Jp, twist)
    h = 1e-6
    Jf = robot.jacobian(q + h * qd)
    Jb = robot.jacobian(q - h * qd)
    jdot_qd = np.einsum("mij,mj->mi", (Jf - Jb) / (2 * h), qd)
    qdd = np.einsum("mij,mj->mi", Jp, dtwist - jdot_qd)
    return qd, qdd


def line_min_duration(
    robot: Robot, q_start: np.ndarray, T_start: np.ndarray, T_goal: np.ndarray,
    profile: Profile, *, v_max: npt.ArrayLike | None = None,
    a_max: npt.ArrayLike | None = None, tool_speed: float | None = None,
    tool_acceleration: float | None = None, samples: int = 101,
) -> float:
    """Shortest rest-to-rest duration [s] of a line within joint and tool limits.

    Joint limits act through the path derivatives ``dq/ds`` and ``d2q/ds2``
    (sampled along the line): ``|qd| = |dq/ds| sd`` and
    ``|qdd| <= |d2q/ds2| sd^2 + |dq/ds| |sdd|``.

    Raises:
        PathError: the line cannot be followed at all.
    """
    L = float(np.linalg.norm(T_goal[:3, 3] - T_start[:3, 3]))
    T = 0.0
    if tool_speed is not None and L > 0:
        T = max(T, profile.peak_velocity * L / tool_speed)
    if tool_acceleration is not None and L > 0:
        T = max(T, math.sqrt(profile.peak_acceleration * L / tool_acceleration))
    if v_max is None and a_max is None:
        return T
    s = np.linspace(0.0, 1.0, samples)
    res = follow_poses(robot, line_poses(T_start, T_goal, s), q_start, singular_tol=0)
    if not res:
        raise PathError(res, "the line")
    dqds = np.gradient(res.q, s, axis=0, edge_order=2)
    d2 = np.gradient(dqds, s, axis=0, edge_order=2)
    g1 = np.abs(dqds).max(axis=0)
    g2 = np.abs(d2).max(axis=0)
    if v_max is not None:
        T = max(T, float(np.max(profile.peak_velocity * g1 / np.asarray(v_max, float))))
    if a_max is not None:
        a = np.asarray(a_max, float)
        T = max(T, float(np.sqrt(np.max((profile.peak_velocity**2 * g2 +
                                          profile.peak_acceleration * g1) / a))))
    return T


# -------------------------------------------------------------------- the segment
def _goal_unreachable(robot: Robot, T_goal: np.ndarray) -> str | None:
    """Why the goal pose has no closed-form solution inside the limits, or None.

    Only for arms with a closed form (cheap and complete); None otherwise.
    """
    from robokin.exceptions import RobokinError
    from robokin.kinematics.ik.analytic.detect import detect

    if detect(robot).solver is None:
        return None
    try:
        sols = robot.ik(T_goal).keep_within_limits()
    except RobokinError:
        return None
    return None if int(sols.count) else str(sols.status.item())


def cartesian_line(
    robot: Robot,
    q_start: npt.ArrayLike,
    T_goal: npt.ArrayLike,
    duration: float | None = None,
    dt: float = 0.005,
    *,
    profile: str | Profile = "quintic",
    speed_in: float = 0.0,
    speed_out: float = 0.0,
    v_max: npt.ArrayLike | None = None,
    a_max: npt.ArrayLike | None = None,
    tool_speed: float | None = None,
    tool_acceleration: float | None = None,
    ik: IKMode = "follow",
    max_jump: float = 0.3,
    singular_tol: float = 1e-5,
    max_samples: int | None = None,
) -> Trajectory:
    """Straight tool line from ``robot.fk(q_start)`` to ``T_goal``.

    Args:
        robot: The :class:`~robokin.robot.Robot`.
        q_start: Start configuration (n,) [rad, m]; fixes the branch.
        T_goal: Goal pose (4, 4) [m] in the world frame.
        duration: Motion time [s]; None: the shortest within ``v_max`` /
            ``a_max`` (joints) and ``tool_speed`` / ``tool_acceleration``,
            rounded up to a multiple of dt.
        dt: Sampling period [s].
        profile: Time scaling along the line (any profile name or instance).
        speed_in: Tool speed at the start [m/s] along the line (default rest);
            non-zero end speeds use a quintic scaling with those rates.
        speed_out: Tool speed at the end [m/s].
        v_max: Joint speed limits used for the duration, scalar or (n,).
        a_max: Joint acceleration limits used for the duration.
        tool_speed: Largest tool speed [m/s] used for the duration.
        tool_acceleration: Largest tool acceleration [m/s^2].
        ik: ``"follow"`` (Newton path following, default, every arm),
            ``"analytic"`` (nearest-to-previous closed-form solution, then
            polished) or ``"numeric"`` (``robokin.kinematics.ik.numeric.ik_path``).
        max_jump: Largest joint change between samples [rad or m].
        singular_tol: Smallest Jacobian singular value allowed on the path.
        max_samples: Most samples accepted (default
            :data:`robokin.trajectory.joint.MAX_SAMPLES`), checked before sampling.

    Returns:
        The :class:`Trajectory`, with ``pose`` set to the line's poses.

    Raises:
        PathError: a sample cannot be followed (index, time and reason).
        InputError: bad arguments.
    """
    n = robot.n
    q0 = check_finite(check_joints(q_start, n, "q_start"), "q_start").reshape(-1)
    T1 = check_transform(T_goal, "T_goal")
    if T1.shape != (4, 4):
        raise InputError("T_goal", f"expected one pose (4, 4), got {T1.shape}")
    T0 = robot.fk(q0)
    prof = get_profile(profile)
    dp = T1[:3, 3] - T0[:3, 3]
    L = float(np.linalg.norm(dp))
    moving_ends = bool(speed_in or speed_out)
    if moving_ends and L == 0:
        raise InputError("speed_in", "a pure rotation has no path speed")
    if duration is None:
        Tmin = line_min_duration(robot, q0, T0, T1, prof, v_max=v_max, a_max=a_max,
                                 tool_speed=tool_speed,
                                 tool_acceleration=tool_acceleration)
        if Tmin <= 0:
            raise InputError("duration", "give a duration or limits to derive one")
        T = max(dt, math.ceil(Tmin / dt - 1e-9) * dt)
    else:
        T = float(duration)
        if not T > 0:
            raise InputError("duration", f"must be positive [s], got {duration!r}")
    t = time_grid(T, dt, max_samples=max_samples)
    if moving_ends:
        s, sd, sdd = _scalar_quintic(T, speed_in / L, speed_out / L, t)
    else:
        s, sd, sdd = prof.scale(t, T)
    Tp = line_poses(T0, T1, s)
    res = _follow(robot, Tp, q0, t, ik, max_jump=max_jump, singular_tol=singular_tol)
    if not res:
        hint = _goal_unreachable(robot, T1)
        if hint:
            import dataclasses

            res = dataclasses.replace(
                res, reason=f"{res.reason}; the goal itself is unreachable: {hint}"
            )
        raise PathError(res, "the Cartesian line")
    w_base = T0[:3, :3] @ rotvec_from_rotation(T0[:3, :3].T @ T1[:3, :3])
    axis = np.concatenate([dp, w_base])
    qd, qdd = _rates(robot, res.q, sd[:, None] * axis, sdd[:, None] * axis)
    return Trajectory(t, res.q, qd, qdd, joint_names=robot.joint_names, pose=Tp,
                      via_times=np.array([t[0], t[-1]]), labels=("line",),
                      is_revolute=robot.is_revolute)
