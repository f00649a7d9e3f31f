"""Choose the IK solver for a robot: its closed form when one applies, else numeric."""

from __future__ import annotations

import math
from typing import Any, TypeGuard

import numpy as np
import numpy.typing as npt

from robokin._validation import (
    check_broadcasts,
    check_finite,
    check_joints,
    check_poses_fast,
)
from robokin.exceptions import InputError
from robokin.kinematics.arm import Arm, ArmSource, arm_of
from robokin.kinematics.ik.analytic.detect import FAMILY, Family, detect
from robokin.kinematics.ik.fixed import solve_fixed
from robokin.kinematics.ik.solutions import SolutionSet

__all__ = ["solve"]

_METHODS = ("auto", "analytic", "numeric")


def solve(
    robot: ArmSource,
    T: npt.ArrayLike,
    *,
    q_near: npt.ArrayLike | None = None,
    method: str = "auto",
    **options: Any,
) -> SolutionSet:
    """Every solution for target poses ``T`` (..., 4, 4); see ``Robot.ik``.

    Args:
        robot: The arm (an :class:`~robokin.kinematics.arm.Arm` or a Robot).
        T: Target poses (..., 4, 4) [m].
        q_near: Current configuration (..., n) [rad, m], optional.
        method: ``"auto"``, ``"analytic"`` or ``"numeric"``.
        **options: The solver's options; a closed form's are checked against the
            names its family declares (``Family.options``) before it is called.

    Raises:
        InputError: bad pose or ``q_near``, unknown method, an option the closed
            form does not take, or ``method="analytic"`` for an arm without a
            closed form (the message says why).
    """
    arm = robot if type(robot) is Arm else arm_of(robot)
    if method not in _METHODS:
        raise InputError("method", f"expected one of {_METHODS}, got {method!r}")
    if len(options) == 1 and "fixed" in options:
        # held joints, no other option: no re-packing of the keyword arguments
        return solve_fixed(arm, T, options["fixed"], dispatch=solve, q_near=q_near,
                           method=method)
    if "fixed" in options:
        return solve_fixed(arm, T, options.pop("fixed"), dispatch=solve, q_near=q_near,
                           method=method, **options)
    qn: npt.NDArray[np.float64] | None = None
    if q_near is not None:
        qn = (q_near if _plain_joints(q_near, arm.n)
              else check_finite(check_joints(q_near, arm.n, "q_near"), "q_near"))
    if (not options and type(T) is np.ndarray and T.shape == (4, 4)
            and T.dtype == np.float64 and T.flags.aligned and method != "numeric"):
        # hot path: one pose, a 6R closed form, default options (one compiled call
        # validates the pose and solves it)
        single = arm.derived(FAMILY).single
        if single is not None and (qn is None or qn.shape == (6,)):
            out = single(T, math.nan if qn is None else float(qn[5]))
            if out is not None:
                return out
    T = check_poses_fast(T, "T")
    if qn is not None and qn.ndim > 1:
        check_broadcasts(qn, T.shape[:-2] + (arm.n,), "q_near")
    if method in ("auto", "analytic"):
        fam = detect(arm)
        if fam.solver is not None:
            _check_options(fam, options)
            return fam.solver(arm, T, q_near=qn, **options)
        if method == "analytic":
            raise InputError(
                "method", f"no closed form for robot '{arm.name}': {fam.reason}"
            )
    from robokin.kinematics.ik.numeric import solve_all

    sols = solve_all(arm, T, q_near=qn, **options)
    chain = arm.chain
    if arm.n == 7 and chain.n_chain == 7 and chain.coupling.is_identity:
        sols = _say_sample(arm, T, sols)
    return sols


def _say_sample(arm: Arm, T: npt.NDArray[np.float64], sols: SolutionSet) -> SolutionSet:
    """A 7R arm's numeric set says it is a sample of the self-motion, with parameters.

    ``info["self_motion"]`` says what the rows are; ``info["parameter"]`` names the
    self-motion parameter (the swivel on SRS arms, else a joint) and
    ``info["parameter_values"]`` (..., k) gives each row's value (NaN rows: NaN).
    """
    from dataclasses import replace

    from robokin.kinematics.ik.self_motion import parameter_values

    name, values = parameter_values(arm, T, sols.q)
    info = dict(sols.info)
    info["self_motion"] = ("a sample of a one-parameter family (7 joints, 6 pose "
                           "components): robot.self_motion(T) gives every branch "
                           "with its exact in-limit intervals")
    info["parameter"] = name
    info["parameter_values"] = np.where(sols.valid, values, np.nan)
    return replace(sols, info=info)


def _check_options(fam: Family, options: dict[str, Any]) -> None:
    """Refuse an option the family's closed form does not declare (naming them all)."""
    unknown = sorted(set(options) - fam.options)
    if unknown:
        accepted = ", ".join(sorted(fam.options)) or "none"
        raise InputError(
            "options",
            f"the {fam.name} closed form does not take the option(s) {unknown} "
            f"(it takes: {accepted}; pass method='numeric' for the numeric solver's "
            "options)",
        )


def _plain_joints(q: object, n: int) -> TypeGuard[npt.NDArray[np.float64]]:
    """True for a float64 array of shape (n,) with finite values.

    That is what the full ``check_joints`` / ``check_finite`` would return
    unchanged (a cheap test for the single-pose path; anything else gets the
    full checks).
    """
    return (type(q) is np.ndarray and q.shape == (n,) and q.dtype == np.float64
            and q.flags.aligned and math.isfinite(sum(q.tolist())))
