"""Servo gains: how the simulated controller turns set points into torques.

Each actuator (a joint, or a motor when the robot is driven in actuator space)
is a PD position servo with velocity feed-forward, and (by default) ideal gravity
compensation at the measured configuration::

    tau = kp (q_set - q) + kv (qd_set - qd) + g(q)

``kp`` and ``kv`` default to a second-order loop of natural frequency
``bandwidth`` [Hz] and damping ratio ``damping`` on the actuator's effective
inertia ``I`` (the diagonal of the mass matrix in that actuator's coordinate: the
inertia it moves with the other joints held, averaged over the motion):
``kp = I (2 pi f)^2``, ``kv = 2 zeta I (2 pi f)``.
The tracking error that remains is then ``(M qdd + C qd) / kp`` to first order:
it grows with the joints' acceleration, as the press-loading study's
measurements did.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any

import numpy as np
import numpy.typing as npt

from robokin._text import short_repr
from robokin.exceptions import InputError

__all__ = ["ServoGains", "servo_gains"]

F64 = npt.NDArray[np.float64]


def _positive(value: Any, what: str, *, zero_ok: bool = False) -> float:
    ok = (isinstance(value, int | float) and not isinstance(value, bool)
          and math.isfinite(value) and (value >= 0 if zero_ok else value > 0))
    if not ok:
        raise InputError("gains", f"{what} must be a finite number "
                         f"{'>= 0' if zero_ok else '> 0'}, got {short_repr(value)}")
    return float(value)


def _gain_vector(value: Any, what: str, *, zero_ok: bool) -> F64 | None:
    if value is None:
        return None
    try:
        arr = np.array(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise InputError("gains", f"{what} must be numbers, got {short_repr(value)}"
                         ) from None
    bad = ~np.isfinite(arr) | ((arr < 0) if zero_ok else (arr <= 0))
    if bad.any():
        raise InputError("gains", f"{what} must be finite and "
                         f"{'>= 0' if zero_ok else '> 0'}; entry {int(np.argmax(bad))} is "
                         f"{arr[int(np.argmax(bad))]!r}")
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True, eq=False)
class ServoGains:
    """Servo gains of the simulated controller (see the module docstring).

    Attributes:
        bandwidth: Natural frequency of each position loop [Hz] (default gains).
        damping: Damping ratio of each loop (default gains).
        kp: Explicit stiffness per actuator [N m/rad, N/m], (n,) or (m,) for
            motors; overrides ``bandwidth``.
        kv: Explicit damping per actuator [N m s/rad, N s/m]; with ``kp``.
        gravity_compensation: Add the gravity torque at the measured
            configuration (counted in the actuator torques).
        velocity_feedforward: Servo on the set velocity too (``kv (qd_set - qd)``)
            rather than on zero velocity (``-kv qd``, which lags).
    """

    bandwidth: float = 10.0
    damping: float = 1.0
    kp: F64 | None = None
    kv: F64 | None = None
    gravity_compensation: bool = True
    velocity_feedforward: bool = True

    def __post_init__(self) -> None:
        """Check every gain (raises InputError naming ``gains``)."""
        object.__setattr__(self, "bandwidth", _positive(self.bandwidth, "bandwidth [Hz]"))
        object.__setattr__(self, "damping", _positive(self.damping, "damping",
                                                      zero_ok=True))
        kp = _gain_vector(self.kp, "kp", zero_ok=False)
        kv = _gain_vector(self.kv, "kv", zero_ok=True)
        if (kp is None) != (kv is None):
            raise InputError("gains", "give kp and kv together (or neither)")
        if kp is not None and kv is not None and kp.shape != kv.shape:
            raise InputError("gains", f"kp has {kp.size} entries, kv {kv.size}")
        object.__setattr__(self, "kp", kp)
        object.__setattr__(self, "kv", kv)
        for flag in ("gravity_compensation", "velocity_feedforward"):
            if not isinstance(getattr(self, flag), bool):
                raise InputError("gains", f"{flag} must be True or False, got "
                                 f"{short_repr(getattr(self, flag))}")

    def resolve(self, inertia: npt.ArrayLike) -> tuple[F64, F64]:
        """``(kp, kv)`` per actuator for effective inertias ``inertia`` (k,).

        Raises:
            InputError: explicit gains of another length than ``inertia``.
        """
        I = np.asarray(inertia, dtype=np.float64).reshape(-1)
        if self.kp is not None and self.kv is not None:
            if self.kp.shape != I.shape:
                raise InputError("gains", f"kp and kv have {self.kp.size} entries; the "
                                 f"model has {I.size} actuators")
            return np.array(self.kp), np.array(self.kv)
        w = 2.0 * math.pi * self.bandwidth
        return I * w * w, 2.0 * self.damping * I * w


def servo_gains(value: Any) -> ServoGains:
    """``gains=`` as given to :func:`robokin.sim.simulate`, as a :class:`ServoGains`.

    Args:
        value: None (the defaults), a :class:`ServoGains`, or a mapping of its
            fields (``{"bandwidth": 8.0}``, ``{"kp": [...], "kv": [...]}``).

    Raises:
        InputError: an unknown field, a non-finite or non-positive gain (the
            argument named is ``gains``).
    """
    if value is None:
        return ServoGains()
    if isinstance(value, ServoGains):
        return value
    if isinstance(value, Mapping):
        known = {f.name for f in fields(ServoGains)}
        unknown = sorted(str(k) for k in value if k not in known)
        if unknown:
            raise InputError("gains", f"unknown field {unknown[0]!r}; fields: "
                             f"{sorted(known)}")
        return ServoGains(**dict(value))
    raise InputError("gains", "expected None, a ServoGains or a mapping of its fields, "
                     f"got {short_repr(value)}")
