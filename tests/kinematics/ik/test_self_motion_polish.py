"""The refinement of self-motion rows next to a joint limit (``self_motion_polish``)."""

from __future__ import annotations

import numpy as np
import pytest

import robokin
from robokin.kinematics.ik.self_motion_polish import _POLISH_STEP, LimitPolish
from robokin.spatial import pose_error


def _panda_at_limits() -> tuple[robokin.Robot, np.ndarray]:
    """The Panda with q2 and q4 at their limits, q7 (the parameter) inside."""
    robot = robokin.load("panda")
    lim = robot.limits
    q = np.array([0.3, lim[1, 1], -0.4, lim[3, 0], 0.5, 1.9, 0.7])
    return robot, q


def _off(robot: robokin.Robot, q: np.ndarray, size: float, seed: int) -> np.ndarray:
    """q with its six free joints (all but q7) moved by ``size`` [rad] each, random signs."""
    d = np.random.default_rng(seed).choice([-1.0, 1.0], robot.n) * size
    d[6] = 0.0
    return q + d


@pytest.mark.parametrize("size", [1e-12, 1e-11, 3e-10])
def test_a_row_next_to_a_limit_is_brought_back_to_the_pose(size):
    # One Newton step on the pose with the parameter held: a row off the pose by
    # ~size (its joints off q by size) comes back to q to rounding (the step's
    # second-order error ~size^2), the parameter untouched. Oracle: q itself, and the
    # row's pose error by FK.
    robot, q = _panda_at_limits()
    T = robot.fk(q)
    pol = LimitPolish(robot, 6, T)
    rows = np.stack([_off(robot, q, size, s) for s in range(4)])[None]  # (1, 4, 7)
    before = np.abs(rows - q).max()
    pol(rows, np.ones((1, 4), bool), np.zeros((1, 4), bool))
    assert np.all(rows[..., 6] == q[6])
    assert np.abs(rows - q).max() < 1e-14 + 1e-3 * before, np.abs(rows - q).max()
    err = pose_error(robot.fk(rows[0]), np.broadcast_to(T, (4, 4, 4)))
    assert np.abs(err).max() < 1e-14


def test_rows_it_must_not_refine_are_left_bit_for_bit():
    # Left alone: a row farther than 1e-9 from every limit (even off the pose), a row
    # flagged singular, an invalid one, and one whose step would exceed _POLISH_STEP.
    robot, q = _panda_at_limits()
    T = robot.fk(q)
    pol = LimitPolish(robot, 6, T)
    far = q.copy()
    far[1] -= 0.2
    far[3] += 0.2  # no joint within 1e-9 of a limit (and not on the pose)
    big = _off(robot, q, 10 * _POLISH_STEP, 1)
    big[1] = robot.limits[1, 1]  # next to a limit, but the step is too long
    near = _off(robot, q, 1e-11, 2)
    rows = np.stack([far, near, near, near, big])[None]
    valid = np.array([[True, True, True, False, True]])
    sing = np.array([[False, True, False, False, False]])
    want = rows.copy()
    pol(rows, valid, sing)
    for k in (0, 1, 3, 4):
        assert np.array_equal(rows[0, k], want[0, k]), k
    assert np.abs(rows[0, 2] - q).max() < 1e-14  # the one it must refine


def test_the_parameter_at_its_limit_is_never_moved_and_repeated_grows():
    # The parameter's band is infinite: a row with only q7 at its limit is not near
    # (not refined); the pose buffer is T repeated, grown to the largest call.
    robot = robokin.load("panda")
    q = np.array([0.1, 0.2, -0.3, -1.5, 0.4, 1.6, robot.limits[6, 1]])
    T = robot.fk(q)
    pol = LimitPolish(robot, 6, T)
    rows = _off(robot, q, 1e-11, 3)[None, None]
    want = rows.copy()
    pol(rows, np.ones((1, 1), bool), np.zeros((1, 1), bool))
    assert np.array_equal(rows, want)
    R = pol.repeated(100)
    assert R.shape == (100, 4, 4) and R.flags.c_contiguous and np.array_equal(R[57], T)
    assert len(pol.repeated(3)) == 3 and len(pol.poses) >= 100


def test_a_floor_leaves_rows_next_to_a_singular_configuration_alone():
    # The continued family has no singular flags: its LimitPolish takes a floor on the
    # held 6 x 6's smallest singular value (REGULAR_FLOOR, issue 29's regular rows).
    # The Panda with q2 = 1e-4 (axes 1 and 3 nearly on one line: sigma 1.4e-5) and q4
    # at its limit: a row 1e-12 off is refined without the floor and left bit for bit
    # with it; the regular row at limits (sigma 0.11) is refined either way.
    from robokin.kinematics.ik.self_motion_polish import REGULAR_FLOOR

    robot = robokin.load("panda")
    lim = robot.limits
    near = np.array([0.3, 1e-4, -0.4, lim[3, 0], 0.5, 1.9, 0.7])
    _, regular = _panda_at_limits()
    for q, singular in ((near, True), (regular, False)):
        T = robot.fk(q)
        for floor in (0.0, REGULAR_FLOOR):
            rows = _off(robot, q, 1e-12, 5)[None, None]
            want = rows.copy()
            LimitPolish(robot, 6, T, floor)(rows, np.ones((1, 1), bool),
                                            np.zeros((1, 1), bool))
            assert np.array_equal(rows, want) == (singular and floor > 0), (q[1], floor)
