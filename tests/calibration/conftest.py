"""Shared synthetic set-ups for the calibration tests (seeded: same data every run)."""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

import robokin
from robokin.calibration import synthetic
from robokin.spatial import pose_from_xyz_rpy

DATA = Path(__file__).parents[1] / "data"

#: A tracker 2 m away at an arbitrary rotation; a tool offset (10, 20, 150) mm.
TRACKER = pose_from_xyz_rpy([2.0, 0.5, 0.3], [0.3, -2.0, 1.0])
TOOL = pose_from_xyz_rpy([0.010, 0.020, 0.150], [0.1, 0.2, 0.3])


def irb140() -> robokin.Robot:
    """The ABB IRB140 of tests/data/urdf (its meshes are not shipped: no warnings)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        return robokin.Robot.from_urdf(DATA / "urdf" / "irb140.urdf")


@dataclass
class Case:
    """A synthetic calibration problem with its truth."""

    nominal: robokin.Robot
    true: synthetic.SyntheticRobot
    q: np.ndarray
    measured: np.ndarray
    clean: np.ndarray
    q_hold: np.ndarray
    measured_hold: np.ndarray
    clean_hold: np.ndarray


def make_case(robot: robokin.Robot, kind: str, *, seed: int = 1, n: int = 200,
              hold: int = 1000, noise: float = 2e-5, outliers: float = 0.0) -> Case:
    """True errors ~0.5 mm / 0.05 deg, tracker and tool as above, 0.02 mm noise."""
    rng = np.random.default_rng(seed)
    true = synthetic.perturb(robot, rng, base=TRACKER, tool=TOOL)
    q = synthetic.random_configurations(robot, rng, n + hold)
    m, c = synthetic.measure(true.robot, q[:n], rng, kind=kind, noise=noise,
                             outliers=outliers)
    mh, ch = synthetic.measure(true.robot, q[n:], rng, kind=kind, noise=noise)
    return Case(robot, true, q[:n], m, c, q[n:], mh, ch)


@pytest.fixture(scope="session")
def ur5() -> robokin.Robot:
    """The built-in UR5 (joints 2-3-4 parallel)."""
    return robokin.load("ur5")


@pytest.fixture(scope="session")
def irb() -> robokin.Robot:
    """The IRB140 from its URDF (joints 2-3 parallel, a1 = 70 mm)."""
    return irb140()
