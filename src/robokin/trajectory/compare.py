"""Plan versus real run: per-joint tracking error, its peaks, and its link to acceleration.

The logged run is interpolated onto the plan's times (linear interpolation over
the overlap of the two time spans), so logs at another rate, with jitter or with
a time offset (``time_shift``) compare directly. Reported per joint: the error
over time, its maximum absolute value and RMS, and the correlation between
``|error|`` and ``|qdd|`` of the plan — a robot tracks worse where it accelerates
hard (the AUBO press-loading study: max error under 0.35 deg, growing with joint
acceleration); robokin reports both.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TypedDict

import numpy as np

from robokin.exceptions import InputError
from robokin.trajectory.samples import Trajectory

__all__ = ["Comparison", "ErrorRow", "compare"]


class ErrorRow(TypedDict):
    """One joint's line of :meth:`Comparison.table`, in display units."""

    joint: str
    unit: str  # deg, rad, mm or m
    max: float  # largest |error|
    t_max: float  # [s] when it occurs
    rms: float
    mean: float
    corr_acc: float  # correlation of |error| with the planned |acceleration|


@dataclass(frozen=True, eq=False)
class Comparison:
    """The result of :func:`compare`.

    Attributes:
        t: Plan times inside the log's time span (k,) [s].
        error: ``real - plan`` per joint (k, n) [rad or m].
        max_abs: (n,) largest ``|error|``.
        t_max: (n,) time of that largest error [s].
        rms: (n,) root mean square error.
        mean: (n,) mean error (a constant offset shows here).
        acceleration_correlation: (n,) Pearson correlation of ``|error|`` with
            the plan's ``|qdd|`` (nan where either is constant).
        joint_names: Names (n,).
        is_revolute: (n,) angle (True) or length columns.
        plan_qdd: The plan's accelerations at ``t`` (k, n).
    """

    t: np.ndarray
    error: np.ndarray
    max_abs: np.ndarray
    t_max: np.ndarray
    rms: np.ndarray
    mean: np.ndarray
    acceleration_correlation: np.ndarray
    joint_names: tuple[str, ...]
    is_revolute: np.ndarray
    plan_qdd: np.ndarray

    def table(self, *, degrees: bool = True) -> list[ErrorRow]:
        """One row per joint: name, unit, max, t_max, rms, mean, corr (display units)."""
        rows: list[ErrorRow] = []
        for j, name in enumerate(self.joint_names):
            rev = bool(self.is_revolute[j])
            s = (180.0 / np.pi if degrees else 1.0) if rev else (1000.0 if degrees else 1.0)
            unit = ("deg" if degrees else "rad") if rev else ("mm" if degrees else "m")
            rows.append({"joint": name, "unit": unit, "max": self.max_abs[j] * s,
                         "t_max": self.t_max[j], "rms": self.rms[j] * s,
                         "mean": self.mean[j] * s,
                         "corr_acc": self.acceleration_correlation[j]})
        return rows


def compare(plan: Trajectory, real: Trajectory, *, time_shift: float = 0.0
            ) -> Comparison:
    """Compare a logged run with its plan.

    Args:
        plan: The planned trajectory.
        real: The logged run (e.g. from :func:`robokin.trajectory.io.read_log`),
            same joints in the same order and units.
        time_shift: Added to the log's times before comparing [s] (a log that
            starts its clock elsewhere).

    Returns:
        A :class:`Comparison`.

    Raises:
        InputError: different joint counts, or time spans that do not overlap.
    """
    if plan.n != real.n:
        raise InputError("real", f"has {real.n} joints, the plan {plan.n}")
    tr = real.t + time_shift
    inside = (plan.t >= tr[0] - 1e-12) & (plan.t <= tr[-1] + 1e-12)
    if inside.sum() < 2:
        raise InputError("real", f"its times [{tr[0]:.4g}, {tr[-1]:.4g}] s do not "
                         f"overlap the plan's [{plan.t[0]:.4g}, {plan.t[-1]:.4g}] s")
    t = plan.t[inside]
    q_real = np.stack([np.interp(t, tr, real.q[:, j]) for j in range(plan.n)], axis=-1)
    err = q_real - plan.q[inside]
    a = np.abs(err)
    k = np.argmax(a, axis=0)
    qdd = plan.qdd[inside]
    corr = np.full(plan.n, np.nan)
    for j in range(plan.n):
        x, y = a[:, j], np.abs(qdd[:, j])
        if x.std() > 0 and y.std() > 0:
            corr[j] = float(np.corrcoef(x, y)[0, 1])
    return Comparison(
        t=t, error=err, max_abs=a.max(axis=0), t_max=t[k],
        rms=np.sqrt((err**2).mean(axis=0)), mean=err.mean(axis=0),
        acceleration_correlation=corr, joint_names=plan.names(),
        is_revolute=plan.revolute(), plan_qdd=qdd,
    )
