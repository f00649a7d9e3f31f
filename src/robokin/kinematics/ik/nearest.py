"""One IK solution per target, the one nearest the current configuration.

:func:`solve_near` (``Robot.ik_near``) is the streaming case: a controller at
``q_near`` wants the joint target for the next pose at the lowest latency. Where
the arm has a closed form, every solution is computed and the nearest one inside
the limits is returned (the 2 pi equivalent closest to ``q_near``); otherwise one
Levenberg-Marquardt descent starts from ``q_near`` (restarting elsewhere only when
it fails). Failure is a status with a reason, never an exception.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from robokin._native import kernels
from robokin._validation import (
    check_broadcasts,
    check_finite,
    check_joints,
    check_transform,
)
from robokin.exceptions import InputError
from robokin.kinematics.arm import Arm, ArmSource, arm_of
from robokin.kinematics.ik import numeric
from robokin.kinematics.ik.analytic.detect import detect
from robokin.kinematics.ik.dispatch import solve
from robokin.kinematics.ik.numeric import IKResult
from robokin.kinematics.ik.self_motion import (
    exact_parameter,
    nearest_on_manifold,
    swivel_nearest,
)

if TYPE_CHECKING:
    from robokin.kinematics.ik.solutions import SolutionSet

__all__ = ["solve_near"]

_METHODS = ("auto", "analytic", "numeric", "self_motion")


def solve_near(
    robot: ArmSource,
    T: npt.ArrayLike,
    q_near: npt.ArrayLike,
    *,
    method: str = "auto",
    **options: Any,
) -> IKResult:
    """The solution nearest ``q_near`` for every target pose.

    Args:
        robot: The arm (a :class:`~robokin.robot.Robot` or its ``Arm``).
        T: Target tool poses (..., 4, 4) [m] in the world frame.
        q_near: Current configuration [rad, m], (n,) or (..., n) broadcasting to
            the targets.
        method: ``"auto"`` (the closed form where the arm has one, else numeric:
            on 7R arms the numeric descent from ``q_near``), ``"analytic"``,
            ``"numeric"`` or ``"self_motion"`` (7-joint arms whose whole
            self-motion is exact: the in-limit point of the manifold nearest
            ``q_near``: compiled on SRS arms, ~0.1 ms per pose; on the Panda the
            exact intervals searched in Python, ~5 ms; on a general 7R arm or a
            robot on a track the continued manifold, ~10-30 ms; see ``docs/ik.md``).
        **options: Options of the numeric solver
            (:func:`robokin.kinematics.ik.numeric.solve`, e.g. ``mask``, ``tol``,
            ``max_restarts``); giving any selects it.

    Returns:
        An :class:`~robokin.kinematics.ik.numeric.IKResult` of leading shape (...):
        ``q`` the nearest solution inside the limits where ``success``, ``reason``
        why not elsewhere (then ``q`` is the numeric solver's best configuration,
        or NaN for a closed form that has no solution).

    Raises:
        InputError: a bad pose, ``q_near``, method or option.
    """
    arm = arm_of(robot)
    if method not in _METHODS:
        raise InputError("method", f"expected one of {_METHODS}, got {method!r}")
    q_near = check_finite(check_joints(q_near, arm.n, "q_near"), "q_near")
    if method == "self_motion":
        if options:
            raise InputError("options", f"{sorted(options)} are numeric-solver options; "
                                        "method='self_motion' takes none")
        if exact_parameter(arm) is None:
            raise InputError("method", f"method='self_motion' needs a 7-joint arm whose "
                                       f"whole self-motion is exact (a closed form, or "
                                       f"every solution with a joint held); robot "
                                       f"'{arm.name}' is not one: use method='numeric'")
        return _manifold_near(arm, T, q_near)
    if method == "numeric" or options:
        if method == "analytic":
            raise InputError("options", f"{sorted(options)} are numeric-solver options; "
                                        "the closed form takes none")
        return _numeric_near(arm, T, q_near, **options)
    fam = detect(arm)
    if fam.solver is None:
        if method == "analytic":
            raise InputError("method", f"no closed form for robot '{arm.name}': "
                                       f"{fam.reason}")
        return _numeric_near(arm, T, q_near)
    sols = solve(arm, T, q_near=q_near, method="analytic")
    return _nearest(arm, sols, T, q_near)


def _manifold_near(arm: Arm, T: npt.ArrayLike, q_near: np.ndarray) -> IKResult:
    """A 7-joint arm with an exact self-motion: the in-limit point nearest ``q_near``.

    SRS arms: the compiled search on the exact swivel intervals, all poses in one
    batch (``self_motion.swivel_nearest``); other arms: per pose, the exact in-limit
    intervals searched (``self_motion.nearest_on_manifold``).
    """
    from robokin.kinematics.ik.analytic._common import fk_error

    T = check_transform(T, "T")
    lead = T.shape[:-2]
    check_broadcasts(q_near, lead + (arm.n,), "q_near")
    Tf = T.reshape(-1, 4, 4)
    qn = np.broadcast_to(q_near, lead + (arm.n,)).reshape(-1, arm.n)
    fast = swivel_nearest(arm, Tf, qn, solve)  # SRS arms: one compiled batch
    q = np.full((len(Tf), arm.n), np.nan) if fast is None else fast
    for i, (Ti, qi) in enumerate(zip(Tf, qn, strict=True)):
        # other arms per pose; on SRS arms the poses the compiled search left without
        # a row (next to a stretched elbow, where it can miss the intervals' slivers):
        # SelfMotion.nearest searches the pose's intervals themselves
        if fast is None or not np.isfinite(q[i]).all():
            p = nearest_on_manifold(arm, Ti, qi, dispatch=solve)
            if p is not None:
                q[i] = p.q
    found = np.isfinite(q).all(-1)
    dp, dr = fk_error(arm.chain, q[:, None], Tf)
    dp, dr = dp[:, 0], dr[:, 0]
    reason = np.where(found, "converged",
                      "no configuration of the self-motion inside the joint limits")
    zeros = np.zeros(lead, dtype=np.int64)
    if not lead:
        return IKResult(q=q[0], success=np.bool_(found[0]), error=float(np.hypot(dp[0], dr[0])),
                        iterations=0, restarts=0, reason=str(reason[0]),
                        position_error=float(dp[0]), rotation_error=float(dr[0]))
    return IKResult(q=q.reshape(lead + (arm.n,)), success=found.reshape(lead),
                    error=np.hypot(dp, dr).reshape(lead), iterations=zeros, restarts=zeros,
                    reason=reason.astype(object).reshape(lead),
                    position_error=dp.reshape(lead), rotation_error=dr.reshape(lead))


def _numeric_near(robot: Arm, T: npt.ArrayLike, q_near: np.ndarray,
                  **options: Any) -> IKResult:
    """The numeric solver started at ``q_near``.

    ``q_near`` is checked against the poses first, so a mismatch is reported as
    ``q_near``, the argument the caller passed.
    """
    T = check_transform(T, "T")
    check_broadcasts(q_near, T.shape[:-2] + (robot.n,), "q_near")
    return numeric.solve(robot, T, q0=q_near, **options)


def _nearest(robot: Arm, sols: SolutionSet, T: npt.ArrayLike, q_near: np.ndarray) -> IKResult:
    """The row of ``sols`` nearest ``q_near`` per pose, inside the limits, as a result."""
    lead, n = sols.shape, robot.n
    k = sols.q.shape[-2]
    if not lead and q_near.shape == (n,):  # one pose: no reshaping copies
        N = 1
        Q = sols.q[None]
        ok = (sols.valid & sols.flags["within_limits"])[None]
        qn = q_near[None]
        Tf = np.asarray(T, dtype=np.float64)[None]
        if not all(a.flags.c_contiguous and a.flags.aligned for a in (Q, qn, Tf)):
            Q, qn, Tf = (np.require(a, requirements=("C", "A")) for a in (Q, qn, Tf))
    else:
        N = int(np.prod(lead, dtype=np.int64))
        Q = np.ascontiguousarray(sols.q.reshape(N, k, n))
        ok = np.ascontiguousarray((sols.valid & sols.flags["within_limits"]).reshape(N, k))
        qn = np.ascontiguousarray(np.broadcast_to(q_near, lead + (n,)).reshape(N, n))
        Tf = np.require(np.asarray(T, dtype=np.float64).reshape(N, 4, 4),
                        requirements=("C", "A"))  # an unaligned buffer: copied
    q = np.empty((N, n))
    err = np.empty((N, 2))
    found = np.empty(N, dtype=bool)
    arrays = robot.chain.arrays
    kernels.nearest(arrays.packed, Q, ok, qn, arrays.is_revolute, Tf, q, err, found)
    if not lead:
        if found[0]:
            return IKResult(q=q[0], success=np.True_, error=float(np.hypot(*err[0])),
                            iterations=0, restarts=0, reason="converged",
                            position_error=float(err[0, 0]),
                            rotation_error=float(err[0, 1]))
        return IKResult(q=q[0], success=np.False_, error=np.nan, iterations=0,
                        restarts=0, reason=str(_why(sols).item()),
                        position_error=np.nan, rotation_error=np.nan)
    reason = np.full(N, "converged", dtype=object)
    if not found.all():  # the reasons of the poses without a solution only
        miss = np.flatnonzero(~found)
        reason[miss] = _why(sols[np.unravel_index(miss, lead)])
    zeros = np.zeros(lead, dtype=np.int64)
    return IKResult(q=q.reshape(lead + (n,)), success=found.reshape(lead),
                    error=np.hypot(err[:, 0], err[:, 1]).reshape(lead),
                    iterations=zeros, restarts=zeros, reason=reason.reshape(lead),
                    position_error=err[:, 0].reshape(lead),
                    rotation_error=err[:, 1].reshape(lead))


def _why(sols: SolutionSet) -> np.ndarray:
    """Per pose: why it has no solution inside the limits (its status)."""
    return np.asarray(sols.keep_within_limits().status, dtype=object)
