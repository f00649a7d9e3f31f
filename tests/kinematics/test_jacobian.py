"""Jacobians against central finite differences, tool frame, manipulability, singularity."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import robokin
from reference import random_q


def _finite_difference_jacobian(robot, q, h=1e-6):
    J = np.zeros((6, robot.n))
    T0 = robot.fk(q)
    for j in range(robot.n):
        dq = np.zeros(robot.n)
        dq[j] = h
        Tp, Tm = robot.fk(q + dq), robot.fk(q - dq)
        J[:3, j] = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
        dR = Tp[:3, :3] @ Tm[:3, :3].T  # base-frame angular displacement over 2h
        J[3:, j] = Rotation.from_matrix(dR).as_rotvec() / (2 * h)
    del T0
    return J


@pytest.mark.parametrize("name", robokin.robots.names())
def test_jacobian_matches_finite_differences(name, rng):
    robot = robokin.load(name)
    for q in random_q(robot, rng, 10):
        np.testing.assert_allclose(
            robot.jacobian(q), _finite_difference_jacobian(robot, q), atol=2e-8
        )


def test_prismatic_columns_are_pure_translation(rng):
    robot = robokin.load("scara")
    J = robot.jacobian(random_q(robot, rng, 5))
    np.testing.assert_allclose(
        J[:, :, 3], np.broadcast_to([0, 0, 1, 0, 0, 0], (5, 6)), atol=1e-15
    )


def test_tool_frame_jacobian_is_the_rotated_base_one(rng):
    robot = robokin.load("panda")
    q = random_q(robot, rng, (2, 3))
    Jb = robot.jacobian(q)
    Jt = robot.jacobian(q, frame="tool")
    R = robot.fk(q)[..., :3, :3]
    np.testing.assert_allclose(R @ Jt[..., :3, :], Jb[..., :3, :], atol=1e-14)
    np.testing.assert_allclose(R @ Jt[..., 3:, :], Jb[..., 3:, :], atol=1e-14)
    with pytest.raises(robokin.InputError, match="frame"):
        robot.jacobian(q, frame="world")


def test_batched_jacobian_equals_loop(rng):
    robot = robokin.load("improved_dh_arm")
    q = random_q(robot, rng, (3, 4))
    J = robot.jacobian(q)
    assert J.shape == (3, 4, 6, 7)
    for idx in np.ndindex(3, 4):
        np.testing.assert_array_equal(J[idx], robot.jacobian(q[idx]))


def test_ur5_singularities_and_manipulability():
    robot = robokin.load("ur5")
    generic = np.array([0.1, -1.0, 1.2, -0.5, 0.8, 0.3])
    wrist = generic.copy()
    wrist[4] = 0.0  # wrist singularity: axes 4 and 6 parallel
    elbow = generic.copy()
    elbow[2] = 0.0  # elbow stretched out
    assert not robot.is_singular(generic)
    assert robot.is_singular(wrist) and robot.is_singular(elbow)
    np.testing.assert_allclose(
        robot.manipulability(np.stack([wrist, elbow])), 0, atol=1e-12
    )
    J = robot.jacobian(generic)
    np.testing.assert_allclose(
        robot.manipulability(generic), np.sqrt(np.linalg.det(J @ J.T)), rtol=1e-9
    )
    assert robot.manipulability(generic) > 1e-3


def test_four_axis_manipulability_uses_its_own_dof(rng):
    robot = robokin.load("scara")
    q = random_q(robot, rng)
    J = robot.jacobian(q)
    np.testing.assert_allclose(robot.manipulability(q), np.sqrt(np.linalg.det(J.T @ J)))
    assert not robot.is_singular(q + np.array([0, 0.5, 0, 0]))
    q[1] = 0.0  # elbow straight
    assert robot.is_singular(q)
