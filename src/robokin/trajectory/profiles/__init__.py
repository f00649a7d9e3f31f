"""Time-scaling profiles: one module per profile, behind :class:`Profile`.

``get_profile("quintic")`` (or an instance) returns the profile object; names:
``cubic``, ``quintic``, ``trapezoidal`` (alias ``lspb``), ``cycloidal``,
``piecewise_acceleration`` (alias ``pca``), ``modified_sine``,
``constant_velocity`` (alias ``linear``).
"""

from __future__ import annotations

from typing import Any

from robokin._text import short_repr
from robokin.exceptions import InputError
from robokin.trajectory.profiles._constant_velocity import ConstantVelocityProfile
from robokin.trajectory.profiles._cycloidal import CycloidalProfile
from robokin.trajectory.profiles._modified_sine import ModifiedSineProfile
from robokin.trajectory.profiles._piecewise_acceleration import (
    PiecewiseAccelerationProfile,
)
from robokin.trajectory.profiles._polynomials import CubicProfile, QuinticProfile
from robokin.trajectory.profiles._trapezoidal import TrapezoidalProfile, lspb_timing
from robokin.trajectory.profiles.base import Profile

__all__ = [
    "ConstantVelocityProfile",
    "CubicProfile",
    "CycloidalProfile",
    "ModifiedSineProfile",
    "PROFILES",
    "PiecewiseAccelerationProfile",
    "Profile",
    "QuinticProfile",
    "TrapezoidalProfile",
    "get_profile",
    "lspb_timing",
]

PROFILES: dict[str, type[Profile]] = {
    "cubic": CubicProfile,
    "quintic": QuinticProfile,
    "trapezoidal": TrapezoidalProfile,
    "lspb": TrapezoidalProfile,
    "cycloidal": CycloidalProfile,
    "piecewise_acceleration": PiecewiseAccelerationProfile,
    "pca": PiecewiseAccelerationProfile,
    "modified_sine": ModifiedSineProfile,
    "constant_velocity": ConstantVelocityProfile,
    "linear": ConstantVelocityProfile,
}


def get_profile(profile: str | Profile, **params: Any) -> Profile:
    """The profile named ``profile`` (with ``params``), or ``profile`` itself.

    Raises:
        InputError: unknown name (the message lists the names) or bad parameters.
    """
    if isinstance(profile, Profile):
        return profile
    cls = PROFILES.get(str(profile).lower().replace("-", "_").replace(" ", "_"))
    if cls is None:
        raise InputError("profile", f"unknown profile {short_repr(profile)}; known: "
                         f"{sorted(PROFILES)}")
    try:
        return cls(**params)
    except TypeError as exc:
        raise InputError("profile", f"{short_repr(profile)}: {exc}") from None
