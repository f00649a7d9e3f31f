"""A KUKA-like six-axis arm and the joint conventions of five controller vendors (tests).

The arm has the KR 6 R900 (KR AGILUS) dimensions from KUKA's data sheet: A2 400 mm
above the floor and 25 mm ahead of A1, upper arm 455 mm, a 35 mm offset to the
forearm, forearm 420 mm, flange 80 mm beyond the wrist point. Its model coordinates
are KUKA's A1..A6 except axis 1's direction (KUKA's A1 turns clockwise seen from
above): at ``(0, -90, 90, 0, 0, 0)`` deg (KUKA's HOME) the upper arm points up, the
forearm forward and the flange forward along +x.

The profiles map it to each vendor's published joint zero and directions:

- KUKA: A1 reversed, the rest as modelled. The other vendors turn axis 1
  counterclockwise seen from above (as modelled).
- ABB: axis 2 = A2 + 90 (0 with the lower arm vertical, + leaning forward), axis 3 =
  A3 - 90 (0 with the upper arm horizontal, + downward), axis 5 + tilting the tool
  down ([0, 0, 0, 0, 90, 0] is the tool-down pose of ABB's examples).
- FANUC and Yaskawa: J2 / L = A2 + 90, J3 / U = 90 - A3 (0 with the forearm
  horizontal, + raising it; J2 = 0 poses only, FANUC's J2/J3 interaction aside), J5 /
  B reversed (-90 is tool down, the usual home).
- Staubli: J2 = A2 + 90, J3 = A3 (0 stretched, + forward), J5 + tilting down (the
  park pose (0, 0, 90, 0, 90, 0) of Staubli's examples is tool down).
"""

from __future__ import annotations

from dataclasses import dataclass
from datetime import datetime
from math import pi, radians

import numpy as np

import robokin
from robokin.trajectory.io import ControllerProfile

LIMITS_DEG = [(-170, 170), (-190, 45), (-120, 156), (-185, 185), (-120, 120), (-350, 350)]


def kuka_like(limits_deg=LIMITS_DEG) -> robokin.Robot:
    rows = [dict(a=0.025, alpha=-pi / 2, d=0.4, theta=0.0),
            dict(a=0.455, alpha=0.0, d=0.0, theta=0.0),
            dict(a=0.035, alpha=-pi / 2, d=0.0, theta=-pi / 2),
            dict(a=0.0, alpha=pi / 2, d=0.42, theta=0.0),
            dict(a=0.0, alpha=-pi / 2, d=0.0, theta=0.0),
            dict(a=0.0, alpha=0.0, d=0.08, theta=0.0)]
    for row, (lo, hi), k in zip(rows, limits_deg, range(1, 7)):
        row.update(joint="revolute", limits=[radians(lo), radians(hi)], name=f"a{k}")
    return robokin.Robot.from_dh(rows)


def _profile(name, signs, offsets_deg):
    return ControllerProfile(name=name, signs=tuple(signs),
                             offsets=tuple(radians(o) for o in offsets_deg))


PROFILES = {
    "kuka": _profile("KUKA", [-1, 1, 1, 1, 1, 1], [0, 0, 0, 0, 0, 0]),
    "abb": _profile("ABB", [1, 1, 1, 1, 1, 1], [0, 90, -90, 0, 0, 0]),
    "fanuc": _profile("FANUC", [1, 1, -1, 1, -1, 1], [0, 90, 90, 0, 0, 0]),
    "yaskawa": _profile("Yaskawa", [1, 1, -1, 1, -1, 1], [0, 90, 90, 0, 0, 0]),
    "staubli": _profile("Staubli", [1, 1, 1, 1, 1, 1], [0, 90, 0, 0, 0, 0]),
}


def model_q(profile: ControllerProfile, controller_deg) -> np.ndarray:
    """Model joint values [rad] of controller values [deg] (the profile undone)."""
    return profile.undo(np.radians(np.asarray(controller_deg, dtype=float)))


#: The date written into dated program files by the tests.
CREATED = datetime(2024, 5, 6, 7, 8, 9)


@dataclass(frozen=True)
class PathResult:
    """The shape of robokin.process.follow's result the writers read (input data)."""

    q: np.ndarray
    feasible: bool = True
    free_angle: np.ndarray | None = None
    reason: str = ""


@dataclass(frozen=True)
class PointSet:
    """The shape of robokin.process.order's result."""

    q: np.ndarray
    order: np.ndarray
    travel: float = 0.0
