"""Closed-form registration: exact for exact data, any tracker rotation.

Oracle: the base and tool that generated the data.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import robokin
from robokin.calibration._model import Model
from robokin.calibration._register import register_points, register_poses
from robokin.calibration.synthetic import random_configurations
from robokin.spatial import pose_from_xyz_rpy, rotx, roty, rotz

ROTATIONS = [rotx(math.pi), roty(math.pi), rotz(math.pi), rotx(math.pi / 2),
             pose_from_xyz_rpy([0, 0, 0], [0.3, -2.0, 1.0]),
             pose_from_xyz_rpy([0, 0, 0], [0, math.pi / 2, 0])]


@pytest.mark.parametrize("R", ROTATIONS, ids=range(len(ROTATIONS)))
def test_points_and_poses_register_exactly(R):
    robot = robokin.load("ur5")
    model = Model.from_chain(robot.chain, parallel_tol=math.radians(10))
    q = random_configurations(robot, np.random.default_rng(0), 30)
    flange = model.evaluate(q, np.zeros(model.size), np.eye(4), np.eye(4)).T
    B = R.copy()
    B[:3, 3] = [2.0, -1.5, 0.7]
    X = pose_from_xyz_rpy([0.01, 0.02, 0.15], [0.1, 0.2, 0.3])
    M = B @ flange @ X
    Bp, t = register_points(flange, M[:, :3, 3], np.zeros(3))
    np.testing.assert_allclose(Bp, B, atol=1e-9)
    np.testing.assert_allclose(t, X[:3, 3], atol=1e-9)
    Bq, Xq = register_poses(flange, M)
    np.testing.assert_allclose(Bq, B, atol=1e-9)
    np.testing.assert_allclose(Xq, X, atol=1e-9)
