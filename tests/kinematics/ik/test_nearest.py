"""Robot.ik_near: one solution per target, the nearest one (issue 20, item 4)."""

import numpy as np
import pytest

import robokin
from reference import pose_errors, random_q
from robokin.exceptions import InputError
from robokin.kinematics.ik.solutions import wrap_angle


def _brute_force_nearest(sols, q_near):
    """The in-limit valid row nearest q_near (wrapped distance), by a plain loop."""
    best, best_d = None, np.inf
    for q, ok, inside in zip(sols.q, sols.valid, sols.flags["within_limits"],
                             strict=True):
        if ok and inside:
            d = np.linalg.norm(np.where(sols.is_revolute, wrap_angle(q - q_near),
                                        q - q_near))
            if d < best_d:
                best, best_d = q, d
    return best, best_d


@pytest.mark.parametrize("name", ["ur5", "aubo_i5", "puma560"])
def test_closed_form_arm_returns_the_nearest_solution_single_and_batch(name, rng):
    robot = robokin.load(name)
    q = random_q(robot, rng, 40)
    T = robot.fk(q)
    q_near = q + rng.normal(0, 0.3, q.shape)
    batch = robot.ik_near(T, q_near)
    assert batch.success.all() and (batch.reason == "converged").all()
    dp, dr = pose_errors(robot.fk(batch.q), T)
    assert dp.max() < 1e-9 and dr.max() < 1e-9
    np.testing.assert_allclose(batch.position_error, dp, atol=1e-12)
    for i in range(len(q)):
        one = robot.ik_near(T[i], q_near[i])
        np.testing.assert_allclose(one.q, batch.q[i], atol=1e-12)
        sols = robot.ik(T[i], q_near=q_near[i])
        _, d = _brute_force_nearest(sols, q_near[i])
        assert np.linalg.norm(np.where(robot.is_revolute, wrap_angle(one.q - q_near[i]),
                                       one.q - q_near[i])) == pytest.approx(d, abs=1e-9)
        assert robot.within_limits(one.q, tol=1e-9)
        # the 2 pi equivalent nearest q_near: no joint more than pi away from it
        assert np.abs(one.q - q_near[i])[robot.is_revolute].max() <= np.pi + 1e-9


def test_numeric_arm_descends_from_q_near(rng):
    robot = robokin.load("panda")  # redundant: no closed form
    q = random_q(robot, rng, 200)
    T = robot.fk(q)
    q_near = q + rng.normal(0, 0.02, q.shape)
    res = robot.ik_near(T, q_near)
    assert res.success.all()
    dp, dr = pose_errors(robot.fk(res.q), T)
    assert dp.max() < 1e-9 and dr.max() < 1e-9
    # a local descent stays near where it started (a redundant arm drifts a little
    # along its self-motion; a restart after a failed first descent may go far)
    d = np.linalg.norm(res.q - q_near, axis=1)
    assert np.percentile(d, 95) < 0.15
    assert (d[res.restarts == 0] < 0.5).all()
    one = robot.ik_near(T[0], q[0])
    assert one.success and one.q.shape == (7,) and one.reason == "converged"


def test_unreachable_targets_fail_with_a_reason_not_an_exception():
    robot = robokin.load("ur5")
    q = np.array([0.2, -1.0, 1.2, -0.3, 0.8, 0.1])
    T = robot.fk(q)
    far = T.copy()
    far[:3, 3] *= 4.0
    res = robot.ik_near(np.stack([T, far]), q)
    assert res.success.tolist() == [True, False]
    assert res.reason[1] == "out of reach"
    assert np.isnan(res.q[1]).all()
    one = robot.ik_near(far, q)
    assert not one.success and one.reason == "out of reach"


def test_options_select_the_numeric_solver():
    robot = robokin.load("ur5")
    q = np.array([0.2, -1.0, 1.2, -0.3, 0.8, 0.1])
    res = robot.ik_near(robot.fk(q), q + 0.01, mask="xyz")
    assert res.success and res.iterations > 0  # a descent ran
    res = robot.ik_near(robot.fk(q), q + 0.01, method="numeric")
    assert res.success and np.abs(res.q - q).max() < 1e-6


def test_bad_inputs_name_the_argument():
    robot = robokin.load("ur5")
    T = robot.fk(np.zeros(6))
    with pytest.raises(InputError, match="q_near"):
        robot.ik_near(T, np.zeros(5))
    with pytest.raises(InputError, match="q_near.*non-finite"):
        robot.ik_near(T, [0, 0, np.nan, 0, 0, 0])
    # the numeric path names q_near too (not the solver's q0)
    with pytest.raises(InputError, match="'q_near'.*does not broadcast"):
        robot.ik_near(np.stack([T, T]), np.zeros((3, 6)), method="numeric")
    with pytest.raises(InputError, match="method"):
        robot.ik_near(T, np.zeros(6), method="fast")
    with pytest.raises(InputError, match="options"):
        robot.ik_near(T, np.zeros(6), method="analytic", mask="xyz")
    with pytest.raises(InputError, match="no closed form"):
        robokin.load("panda").ik_near(robokin.load("panda").fk(np.full(7, 0.1)),
                                      np.full(7, 0.1), method="analytic")
