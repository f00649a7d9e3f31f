"""Rows of a self-motion next to a joint limit, refined on the pose.

A family's row reproduces the pose to its solver's stop (the held closed form keeps
a row below ``PK_EXACT``, 1e-13; the continued family's Newton steps stop at ~5e-15).
Where the held Jacobian of the six other joints is nearly singular the joints are
off by that error over its smallest singular value: the rtb-data iiwa14 with the
elbow stretched up to 5e-10 rad (issue 29, helper corner29), the random 7R at a
range end with four joints at their limits 9e-12 (helper r7end30), more than
``MANIFOLD_SLACK``. A row within ``_POLISH_NEAR`` of a limit is in or out of its
interval by that error alone, so :class:`LimitPolish` takes one Newton step on the
pose for it, with the parameter held.

Shared by the held-joint family (:mod:`~robokin.kinematics.ik.self_motion_families`)
and the continued family (:mod:`~robokin.kinematics.ik.self_motion_continued`),
which do not import each other.
"""

from __future__ import annotations

import numpy as np

from robokin._native import kernels
from robokin.kinematics.arm import Arm
from robokin.kinematics.jacobian import jacobian_and_pose

#: Rows within this of a limit [rad] are refined: a membership decided within
#: rounding of the slack.
_POLISH_NEAR = 1e-9
#: A refining step longer than this [rad], or than ``_POLISH_GAIN`` times the pose
#: error, is not taken: a singular row (its held Jacobian's smallest singular value
#: below 1e-4, the rates script's regular threshold), whose joints the pose does not
#: fix to that; the regular rows it is for move by <= 5e-10.
_POLISH_STEP = 1e-8
_POLISH_GAIN = 1e4
#: A family without singular flags of its own (the continued family's rows) refines only
#: rows whose held 6 x 6 has its smallest singular value at least this (the regular
#: rows of issue 29's goal): next to a singular one the step amplifies the row's
#: rounding (the offset iiwa's #5257, sigma 2.9e-5: 5.2e-13 from q before the step,
#: 1.2e-12 after it, its range-end corner lost).
REGULAR_FLOOR = 1e-4


try:  # np.linalg.solve's own gufunc (private to numpy; its wrapper costs ~20 us a call)
    from numpy.linalg import _umath_linalg as _linalg_gufuncs
except ImportError:  # pragma: no cover - a numpy without it: the public wrapper
    _linalg_gufuncs = None  # type: ignore[assignment]


def _solve_stacked(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.linalg.solve(A, b)`` for float64 stacks A (m, k, k), b (m, k, 1).

    Raises ``np.linalg.LinAlgError`` where a matrix is exactly singular, as the
    public function does; the gufunc directly where numpy has it (the refinement's
    calls are ~25 us through the wrapper, ~5 us without).
    """
    if _linalg_gufuncs is None:
        return np.linalg.solve(A, b)
    with np.errstate(invalid="raise", over="ignore", divide="ignore", under="ignore"):
        try:
            out: np.ndarray = _linalg_gufuncs.solve(A, b, signature="dd->d")
        except FloatingPointError:
            raise np.linalg.LinAlgError("Singular matrix") from None
    return out


class LimitPolish:
    """One pose's refinement of rows next to a limit, the parameter joint held.

    Attributes:
        robot: The arm.
        T: The pose (4, 4).
        band: (mid, half) of every joint's limits, each (n,) [rad]; the parameter's
            half is infinite (it is never refined).
        free: The joints a refining step moves (all but the parameter), (n - 1,).
        poses: T repeated (r, 4, 4), C-contiguous, grown as needed
            (:meth:`repeated`).
        floor: Rows whose held 6 x 6's smallest singular value is below this are
            not refined (0: every row not flagged singular by the caller).
    """

    def __init__(self, robot: Arm, j: int, T: np.ndarray, floor: float = 0.0) -> None:
        """``j``: the parameter joint (0-based); ``T`` (4, 4) the pose; ``floor`` as above."""
        self.robot = robot
        self.floor = floor
        self.T = T
        lim = np.asarray(robot.limits, dtype=np.float64)
        half = 0.5 * (lim[:, 1] - lim[:, 0])
        half[j] = np.inf
        self.band = (0.5 * (lim[:, 0] + lim[:, 1]), half)
        self.free = np.delete(np.arange(robot.n), j)
        self.poses = np.zeros((0, 4, 4))

    def repeated(self, m: int) -> np.ndarray:
        """T repeated (m, 4, 4), C-contiguous (a slice of ``poses``, grown as needed)."""
        if len(self.poses) < m:
            self.poses = np.ascontiguousarray(np.broadcast_to(self.T, (max(2 * m, 64), 4, 4)))
        return self.poses[:m]

    def __call__(self, Q: np.ndarray, valid: np.ndarray, sing: np.ndarray) -> None:
        """Rows Q (m, k, n) within ``_POLISH_NEAR`` of a limit refined in place on the pose.

        One Newton step on the pose with the parameter held (the 6 x 6 Jacobian of
        the other joints), taken where it is at most ``_POLISH_STEP`` and
        ``_POLISH_GAIN`` times the error (its second-order error ~1e-16: not
        checked). Rows valid (m, k) and not flagged ``sing`` (m, k) only; the test
        costs ~10 us per call where no row is near.
        """
        mid, half = self.band
        with np.errstate(invalid="ignore"):
            d = np.subtract(Q, mid)
            np.abs(d, out=d)
            d -= half
            np.abs(d, out=d)
            near = d <= _POLISH_NEAR
        if not near.any():
            return
        pick = near.any(axis=-1)
        pick &= valid
        pick &= ~sing
        idx = np.nonzero(pick)
        if not len(idx[0]):
            return
        q = Q[idx]
        J, P = jacobian_and_pose(self.robot.chain, q)
        e = np.empty((len(q), 6))
        kernels.pose_error(P, self.repeated(len(q)), e)
        try:
            step = _solve_stacked(J[:, :, self.free], e[..., None])[..., 0]
        except np.linalg.LinAlgError:  # an exactly singular one: none is refined
            return
        size = np.abs(step).max(axis=-1)
        small = (size <= _POLISH_STEP) & (size <= _POLISH_GAIN * np.abs(e).max(axis=-1))
        if self.floor > 0.0:
            small &= np.linalg.svd(J[:, :, self.free], compute_uv=False)[:, -1] >= self.floor
        if small.all():  # (the usual case: no rows to pick)
            q[:, self.free] += step
            Q[idx] = q
            return
        trial = q[small]
        trial[:, self.free] += step[small]
        Q[tuple(x[small] for x in idx)] = trial
