"""Choose the IK solver for a robot: its closed form when one applies, else numeric."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, TypeGuard

import numpy as np
import numpy.typing as npt

from robokin._validation import (
    check_broadcasts,
    check_finite,
    check_joints,
    check_poses_fast,
)
from robokin.exceptions import InputError
from robokin.kinematics.ik.fixed import solve_fixed
from robokin.kinematics.ik.solutions import SolutionSet
from robokin.kinematics.per_chain import cached

if TYPE_CHECKING:
    from robokin.kinematics.robot_like import RobotLike

__all__ = ["solve"]

_METHODS = ("auto", "analytic", "numeric")


def solve(
    robot: RobotLike,
    T: npt.ArrayLike,
    *,
    q_near: npt.ArrayLike | None = None,
    method: str = "auto",
    **options: Any,
) -> SolutionSet:
    """Every solution for target poses ``T`` (..., 4, 4); see ``Robot.ik``.

    Raises:
        InputError: bad pose or ``q_near``, unknown method, or ``method="analytic"``
            for an arm without a closed form (the message says why).
    """
    if method not in _METHODS:
        raise InputError("method", f"expected one of {_METHODS}, got {method!r}")
    if len(options) == 1 and "fixed" in options:
        # held joints, no other option: no re-packing of the keyword arguments
        return solve_fixed(robot, T, options["fixed"], q_near=q_near, method=method)
    if "fixed" in options:
        return solve_fixed(robot, T, options.pop("fixed"), q_near=q_near, method=method,
                           **options)
    qn: npt.NDArray[np.float64] | None = None
    if q_near is not None:
        qn = (q_near if _plain_joints(q_near, robot.n)
              else check_finite(check_joints(q_near, robot.n, "q_near"), "q_near"))
    if (not options and type(T) is np.ndarray and T.shape == (4, 4)
            and T.dtype == np.float64 and T.flags.aligned and method != "numeric"):
        # hot path: one pose, a 6R closed form, default options (one compiled call
        # validates the pose and solves it)
        single = _single_solver(robot)
        if single is not None and (qn is None or qn.shape == (6,)):
            out = single(T, math.nan if qn is None else float(qn[5]))
            if out is not None:
                return out
    T = check_poses_fast(T, "T")
    if qn is not None and qn.ndim > 1:
        check_broadcasts(qn, T.shape[:-2] + (robot.n,), "q_near")
    if method in ("auto", "analytic"):
        from robokin.kinematics.ik.analytic.detect import detect

        fam = detect(robot)
        if fam.solver is not None:
            try:
                return fam.solver(robot, T, q_near=qn, **options)
            except TypeError as exc:
                # an option the closed form does not take: name it, never a TypeError
                if "unexpected keyword argument" not in str(exc):
                    raise
                bad = str(exc).split("argument", 1)[1].strip()
                raise InputError(
                    "options",
                    f"the {fam.name} closed form does not take the option {bad} "
                    "(pass method='numeric' for the numeric solver's options)",
                ) from None
        if method == "analytic":
            raise InputError(
                "method", f"no closed form for robot '{robot.name}': {fam.reason}"
            )
    from robokin.kinematics.ik.numeric import solve_all

    return solve_all(robot, T, q_near=qn, **options)


def _single_solver(robot: RobotLike) -> Any:
    """The family's single-pose hot path (``_six_r.make_single``), or None.

    Cached per chain.
    """
    def build() -> Any:
        from robokin.kinematics.ik.analytic.detect import detect

        return getattr(detect(robot).solver, "single", None)

    return cached(robot.chain, "ik_single", build)


def _plain_joints(q: object, n: int) -> TypeGuard[npt.NDArray[np.float64]]:
    """True for a float64 array of shape (n,) with finite values.

    That is what the full ``check_joints`` / ``check_finite`` would return
    unchanged (a cheap test for the single-pose path; anything else gets the
    full checks).
    """
    return (type(q) is np.ndarray and q.shape == (n,) and q.dtype == np.float64
            and q.flags.aligned and math.isfinite(sum(q.tolist())))
