"""Motions the post processor tests write: a sampled trajectory and a process path."""

import numpy as np
import pytest

from robokin import trajectory
from robokin.spatial import pose_from_xyz_rpy
from vendor_arms import PROFILES, PathResult, kuka_like


@pytest.fixture(scope="session")
def arm():
    return kuka_like()


@pytest.fixture(scope="session")
def sampled(arm):
    """A joint trajectory of the KUKA-like arm through a bend (0.8 s, 4 ms samples)."""
    q0 = np.radians([10, -80, 100, 20, 40, -30])
    q1 = np.radians([-35, -60, 80, -40, 70, 120])
    return trajectory.quintic(q0, q1, 0.8, 0.004)


@pytest.fixture(scope="session")
def seam(arm):
    """A process path: a 200 mm line with the tool tilted, every 10 mm (21 poses),
    tracked from a tool-down start; plus the world pose of a work object."""
    start = np.radians([5, -70, 95, 10, 60, -20])
    T0 = arm.fk(start)
    T1 = T0.copy()
    T1[:3, 3] += [0.05, 0.18, -0.06]
    tr = trajectory.cartesian_line(arm, start, T1, 2.0, dt=0.1)
    wobj = pose_from_xyz_rpy([0.3, -0.1, 0.2], np.radians([5, -3, 30]))
    return PathResult(tr.q, free_angle=np.zeros(len(tr.q))), wobj


@pytest.fixture(scope="session")
def profiles():
    return {"kuka_krl": PROFILES["kuka"], "abb_rapid": PROFILES["abb"],
            "fanuc_tp": PROFILES["fanuc"], "yaskawa_inform": PROFILES["yaskawa"],
            "staubli_val3": PROFILES["staubli"], "kawasaki_as": PROFILES["kuka"]}
