"""Joint-space segments: polynomials with boundary conditions and profile motions.

Every function here works on all joints at once (``q0``, ``q1`` of shape (n,)) and
returns a :class:`~robokin.trajectory.samples.Trajectory` sampled every ``dt`` from
0 to ``duration`` (the last sample is exactly at ``duration``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from robokin._text import short_repr
from robokin.exceptions import InputError
from robokin.trajectory.profiles import Profile, get_profile, lspb_timing
from robokin.trajectory.samples import Trajectory

__all__ = [
    "MAX_SAMPLES",
    "check_max_samples",
    "check_sample_count",
    "constant_velocity",
    "cubic",
    "cubic_coefficients",
    "cycloidal",
    "evaluate_polynomial",
    "modified_sine",
    "piecewise_acceleration",
    "profile_motion",
    "quintic",
    "quintic_coefficients",
    "time_grid",
    "trapezoidal",
]

#: Most samples one time grid may hold unless ``max_samples=`` says otherwise: a
#: backstop so that an absurd ``duration`` / ``dt`` is refused before anything is
#: allocated (10 million samples of a 6-joint arm are about 1.4 GB of q, qd, qdd).
MAX_SAMPLES = 10_000_000


def time_grid(duration: float, dt: float, *, t0: float = 0.0,
              max_samples: int | None = None) -> np.ndarray:
    """Times ``t0, t0 + dt, ...`` up to ``t0 + duration``, the end always included.

    When ``duration`` is a multiple of ``dt`` (to 1e-9 of a step) the grid is
    uniform; otherwise the last step is shorter.

    Args:
        duration: Length of the grid [s], >= 0.
        dt: Step [s], > 0.
        t0: First time [s].
        max_samples: Most samples accepted (default :data:`MAX_SAMPLES`); checked
            before the grid is allocated.

    Raises:
        InputError: ``dt`` not positive, ``duration`` negative, or more than
            ``max_samples`` samples (naming both and the limit).
    """
    try:
        dt, duration = float(dt), float(duration)
    except (TypeError, ValueError):
        bad = "dt" if not isinstance(dt, (int, float, np.number)) else "duration"
        raise InputError(bad, f"expected seconds, got "
                         f"{short_repr(locals()[bad])}") from None
    if not np.isfinite(dt) or dt <= 0:
        raise InputError("dt", f"must be a positive time step [s], got {dt!r}")
    if not np.isfinite(duration) or duration < 0:
        raise InputError("duration", f"must be >= 0 [s], got {duration!r}")
    check_sample_count(duration, dt, max_samples)
    k = duration / dt
    steps = int(np.floor(k + 1e-9))
    t = np.arange(steps + 1) * dt
    if abs(k - round(k)) <= 1e-9:
        t[-1] = duration
    else:
        t = np.append(t, duration)
    return t0 + t


def check_max_samples(max_samples: Any) -> int:
    """The sample cap a ``max_samples=`` argument asks for.

    Args:
        max_samples: An integer >= 1, or None for :data:`MAX_SAMPLES`.

    Returns:
        The cap (a count of samples).

    Raises:
        InputError: not an integer (a bool, a float such as 1.5, text), or below 1
            (naming ``max_samples``).
    """
    if max_samples is None:
        return MAX_SAMPLES
    if isinstance(max_samples, bool) or not isinstance(max_samples, int | np.integer):
        raise InputError("max_samples", f"expected a whole number of samples >= 1, got "
                         f"{short_repr(max_samples)}")
    if max_samples < 1:
        raise InputError("max_samples", f"expected a count >= 1, got {int(max_samples)}")
    return int(max_samples)


def check_sample_count(duration: float, dt: float, max_samples: int | None = None,
                       *, argument: str = "duration") -> int:
    """The number of samples of a grid ``duration`` / ``dt``, refused above the cap.

    Args:
        duration: Time span [s].
        dt: Step [s].
        max_samples: The cap (default :data:`MAX_SAMPLES`).
        argument: The argument to name in the error.

    Returns:
        The sample count (end included).

    Raises:
        InputError: more than ``max_samples`` samples (naming ``argument``), or a
            ``max_samples`` that is not an integer >= 1 (naming ``max_samples``).
    """
    cap = check_max_samples(max_samples)
    count = duration / dt + 2.0
    if count > cap:
        raise InputError(argument, f"{duration:g} s at dt {dt:g} s is {count:,.0f} "
                         f"samples, more than the limit of {cap:,} (pass "
                         "max_samples= to raise it)")
    return int(count)


def _vec(x: npt.ArrayLike, n: int | None, name: str) -> np.ndarray:
    try:
        a = np.array(x, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(name, f"expected numbers, got {short_repr(x)}") from exc
    if n is not None:
        if a.ndim == 0:
            a = np.full(n, float(a))
        if a.shape != (n,):
            raise InputError(name, f"expected shape ({n},), got {a.shape}")
    elif a.ndim != 1:
        raise InputError(name, f"expected shape (n,), got {a.shape}")
    if not np.isfinite(a).all():
        raise InputError(name, "holds a non-finite value")
    return a


def _duration(duration: Any) -> float:
    try:
        T = float(duration)
    except (TypeError, ValueError):
        raise InputError("duration", f"expected seconds, got {short_repr(duration)}"
                         ) from None
    if not np.isfinite(T) or T <= 0:
        raise InputError("duration", f"must be positive [s], got {duration!r}")
    return T


def quintic_coefficients(
    q0: npt.ArrayLike, q1: npt.ArrayLike, duration: float,
    qd0: npt.ArrayLike = 0.0, qd1: npt.ArrayLike = 0.0,
    qdd0: npt.ArrayLike = 0.0, qdd1: npt.ArrayLike = 0.0,
) -> np.ndarray:
    """Coefficients ``c`` (6, n) of ``q = sum_k c_k tau^k``, ``tau = t / duration``.

    The unique quintic meeting position, velocity and acceleration at both ends
    (Biagiotti & Melchiorri 2008, eq. 2.5). Velocities are in [unit/s] and
    accelerations in [unit/s^2]; the coefficients are in the normalised time.
    """
    q0 = _vec(q0, None, "q0")
    n = q0.shape[0]
    q1 = _vec(q1, n, "q1")
    T = _duration(duration)
    v0, v1 = _vec(qd0, n, "qd0") * T, _vec(qd1, n, "qd1") * T
    a0, a1 = _vec(qdd0, n, "qdd0") * T * T, _vec(qdd1, n, "qdd1") * T * T
    h = q1 - q0
    c = np.empty((6, n))
    c[0], c[1], c[2] = q0, v0, 0.5 * a0
    c[3] = (20 * h - (8 * v1 + 12 * v0) - (3 * a0 - a1)) / 2.0
    c[4] = (-30 * h + (14 * v1 + 16 * v0) + (3 * a0 - 2 * a1)) / 2.0
    c[5] = (12 * h - 6 * (v1 + v0) + (a1 - a0)) / 2.0
    return c


def cubic_coefficients(
    q0: npt.ArrayLike, q1: npt.ArrayLike, duration: float,
    qd0: npt.ArrayLike = 0.0, qd1: npt.ArrayLike = 0.0,
) -> np.ndarray:
    """Coefficients ``c`` (4, n) of the cubic meeting positions and velocities."""
    q0 = _vec(q0, None, "q0")
    n = q0.shape[0]
    q1 = _vec(q1, n, "q1")
    T = _duration(duration)
    v0, v1 = _vec(qd0, n, "qd0") * T, _vec(qd1, n, "qd1") * T
    h = q1 - q0
    c = np.empty((4, n))
    c[0], c[1] = q0, v0
    c[2] = 3 * h - 2 * v0 - v1
    c[3] = -2 * h + v0 + v1
    return c


def evaluate_polynomial(coeffs: np.ndarray, t: npt.ArrayLike, duration: float
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Position, velocity, acceleration (m, n) of normalised-time coefficients (k, n)."""
    tau = (np.asarray(t, dtype=np.float64) / duration)[:, None]
    k = coeffs.shape[0]
    q = np.broadcast_to(coeffs[k - 1], (tau.shape[0], coeffs.shape[1])).copy()
    qd = np.zeros_like(q)
    qdd = np.zeros_like(q)
    for i in range(k - 2, -1, -1):  # Horner, carrying the derivatives along
        qdd = qdd * tau + 2.0 * qd
        qd = qd * tau + q
        q = q * tau + coeffs[i]
    return q, qd / duration, qdd / duration**2


def _traj(t, q, qd, qdd, joint_names, label, is_revolute=None) -> Trajectory:
    return Trajectory(t, q, qd, qdd, joint_names=joint_names,
                      via_times=np.array([t[0], t[-1]]), labels=(label,),
                      is_revolute=is_revolute)


def quintic(
    q0: npt.ArrayLike, q1: npt.ArrayLike, duration: float, dt: float = 0.005, *,
    qd0: npt.ArrayLike = 0.0, qd1: npt.ArrayLike = 0.0,
    qdd0: npt.ArrayLike = 0.0, qdd1: npt.ArrayLike = 0.0,
    joint_names: Sequence[str] | None = None,
) -> Trajectory:
    """Quintic polynomial from ``q0`` to ``q1`` with velocity and acceleration conditions.

    Args:
        q0: Start position (n,) [rad or m].
        q1: End position (n,).
        duration: Motion time [s].
        dt: Sampling period [s].
        qd0: Start velocity, scalar or (n,) [unit/s] (default rest).
        qd1: End velocity.
        qdd0: Start acceleration [unit/s^2].
        qdd1: End acceleration.
        joint_names: Optional column names.

    Returns:
        The sampled :class:`Trajectory`; its ends meet the conditions to rounding.

    Raises:
        InputError: mismatched shapes, non-finite values, non-positive duration or dt.
    """
    T = _duration(duration)
    c = quintic_coefficients(q0, q1, T, qd0, qd1, qdd0, qdd1)
    t = time_grid(T, dt)
    return _traj(t, *evaluate_polynomial(c, t, T), joint_names, "quintic")


def cubic(
    q0: npt.ArrayLike, q1: npt.ArrayLike, duration: float, dt: float = 0.005, *,
    qd0: npt.ArrayLike = 0.0, qd1: npt.ArrayLike = 0.0,
    joint_names: Sequence[str] | None = None,
) -> Trajectory:
    """Cubic polynomial from ``q0`` to ``q1`` with end velocities (see :func:`quintic`)."""
    T = _duration(duration)
    c = cubic_coefficients(q0, q1, T, qd0, qd1)
    t = time_grid(T, dt)
    return _traj(t, *evaluate_polynomial(c, t, T), joint_names, "cubic")


def profile_motion(
    q0: npt.ArrayLike, q1: npt.ArrayLike, duration: float | None = None,
    dt: float = 0.005, *, profile: str | Profile = "quintic",
    v_max: npt.ArrayLike | None = None, a_max: npt.ArrayLike | None = None,
    joint_names: Sequence[str] | None = None,
) -> Trajectory:
    """Rest-to-rest motion ``q0 + (q1 - q0) s(t / T)`` with any profile.

    All joints start and stop together. With no ``duration``, the shortest one
    that respects ``v_max`` / ``a_max`` is used (rounded up to a multiple of dt).

    Raises:
        InputError: neither a duration nor limits, or bad inputs.
    """
    prof = get_profile(profile)
    q0 = _vec(q0, None, "q0")
    q1 = _vec(q1, q0.shape[0], "q1")
    if duration is None:
        if v_max is None and a_max is None:
            raise InputError("duration", "give a duration or v_max / a_max limits")
        T = prof.min_duration(q1 - q0, v_max, a_max)
        T = max(dt, np.ceil(T / dt - 1e-9) * dt)
    else:
        T = _duration(duration)
    t = time_grid(T, dt)
    s, sd, sdd = prof.scale(t, T)
    d = q1 - q0
    return _traj(t, q0 + s[:, None] * d, sd[:, None] * d, sdd[:, None] * d,
                 joint_names, prof.name)


def trapezoidal(
    q0: npt.ArrayLike, q1: npt.ArrayLike, duration: float | None = None,
    dt: float = 0.005, *, v_max: npt.ArrayLike | None = None,
    a_max: npt.ArrayLike | None = None, blend: float | None = None,
    joint_names: Sequence[str] | None = None,
) -> Trajectory:
    """Linear segment with parabolic blends (trapezoidal velocity), joints synchronised.

    Give either ``v_max`` and ``a_max`` (the shortest synchronised motion, its
    duration rounded up to a multiple of dt), or a ``duration`` (with ``blend``,
    the acceleration time fraction, default 0.25).

    Raises:
        InputError: neither a duration nor both limits, or bad inputs.
    """
    from robokin.trajectory.profiles import TrapezoidalProfile

    q0 = _vec(q0, None, "q0")
    q1 = _vec(q1, q0.shape[0], "q1")
    if duration is None:
        if v_max is None or a_max is None:
            raise InputError("duration", "give a duration, or both v_max and a_max")
        T, f = lspb_timing(q1 - q0, v_max, a_max)
        if T == 0.0:
            T = dt
        Tr = max(dt, np.ceil(T / dt - 1e-9) * dt)
        # Stretching T keeps the limits if the cruise speed is kept: re-solve f.
        f = _blend_for(q1 - q0, Tr, v_max, a_max, f)
        T = Tr
    else:
        T = _duration(duration)
        f = 0.25 if blend is None else blend
    return profile_motion(q0, q1, T, dt, profile=TrapezoidalProfile(f),
                          joint_names=joint_names)


def _blend_for(d, T, v_max, a_max, f0):
    """The blend fraction for a stretched duration T that keeps both limits."""
    d = np.abs(np.asarray(d, float))
    v = np.broadcast_to(np.asarray(v_max, float), d.shape)
    a = np.broadcast_to(np.asarray(a_max, float), d.shape)
    fs = np.linspace(1e-4, 0.5, 5001)
    ok = ((d / (T * (1 - fs[:, None])) <= v * (1 + 1e-9)) &
          (d / (T * T * fs[:, None] * (1 - fs[:, None])) <= a * (1 + 1e-9))).all(-1)
    if not ok.any():
        return f0
    good = fs[ok]
    return float(good[np.argmin(np.abs(good - f0))])


def cycloidal(q0, q1, duration=None, dt=0.005, **kw) -> Trajectory:
    """Cycloidal rest-to-rest motion (see :func:`profile_motion`)."""
    return profile_motion(q0, q1, duration, dt, profile="cycloidal", **kw)


def modified_sine(q0, q1, duration=None, dt=0.005, **kw) -> Trajectory:
    """Modified-sine rest-to-rest motion (see :func:`profile_motion`)."""
    return profile_motion(q0, q1, duration, dt, profile="modified_sine", **kw)


def piecewise_acceleration(q0, q1, duration=None, dt=0.005, *, ramp: float = 0.125,
                           **kw) -> Trajectory:
    """Trapezoidal-acceleration (piecewise-continuous) rest-to-rest motion."""
    from robokin.trajectory.profiles import PiecewiseAccelerationProfile

    return profile_motion(q0, q1, duration, dt,
                          profile=PiecewiseAccelerationProfile(ramp), **kw)


def constant_velocity(
    q0: npt.ArrayLike, velocity: npt.ArrayLike, duration: float, dt: float = 0.005,
    *, joint_names: Sequence[str] | None = None,
) -> Trajectory:
    """Every joint at its constant speed for ``duration``: ``q = q0 + velocity t``.

    Args:
        q0: Start (n,) [rad or m].
        velocity: Speeds (n,) [unit/s].
        duration: [s].
        dt: Sampling period [s].
        joint_names: Optional names.
    """
    q0 = _vec(q0, None, "q0")
    v = _vec(velocity, q0.shape[0], "velocity")
    T = _duration(duration)
    t = time_grid(T, dt)
    m = t.shape[0]
    return _traj(t, q0 + t[:, None] * v, np.broadcast_to(v, (m, v.size)),
                 np.zeros((m, v.size)), joint_names, "constant_velocity")
