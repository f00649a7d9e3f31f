"""Retiming refuses what it cannot do, naming the argument (issue 18): zero, negative
or missing limits, a path that needs an infinite velocity, a cycle time below the
minimum, a missing extra."""

import sys

import numpy as np
import pytest

import robokin
from robokin import trajectory
from robokin.exceptions import InputError, MissingExtraError

pytest.importorskip("toppra")

Q0 = np.radians([0, -60, 80, -20, 90, 0])


@pytest.fixture(scope="module")
def ur5():
    return robokin.load("ur5")


@pytest.fixture(scope="module")
def move(ur5):
    return trajectory.quintic(Q0, Q0 + 0.4, 2.0)


@pytest.mark.parametrize("kwargs, argument, match", [
    ({"v_max": 0.0}, "v_max", r"positive finite.*got 0\.0 for joint shoulder_pan"),
    ({"v_max": -1.0}, "v_max", "positive finite"),
    ({"v_max": [1, 1, 1, -2, 1, 1]}, "v_max", "got -2.0 for joint wrist_1"),
    ({"v_max": np.nan}, "v_max", "positive finite"),
    ({"v_max": np.inf}, "v_max", "positive finite"),
    ({"v_max": [1.0, 2.0]}, "v_max", "one number or 6"),
    ({"v_max": "fast"}, "v_max", "one number or 6"),
    ({"a_max": 0}, "a_max", "positive finite"),
    ({"a_max": -3.0}, "a_max", "positive finite"),
    ({"j_max": 0.0}, "j_max", "positive finite"),
    ({"j_max": "fast"}, "j_max", "None or 'robot'"),
    ({"tool_speed": 0.0}, "tool_speed", "positive finite speed"),
    ({"tool_speed": -0.1}, "tool_speed", "positive finite speed"),
    ({"dt": 0.0}, "dt", "positive sampling period"),
    ({"grid_points": 1}, "grid_points", "count"),
])
def test_bad_limits_name_the_argument(ur5, move, kwargs, argument, match):
    base = {"v_max": 1.0, "a_max": 2.0}
    with pytest.raises(InputError, match=match) as info:
        trajectory.retime(ur5, move, **{**base, **kwargs})
    assert info.value.argument == argument


def test_limits_neither_given_nor_in_the_robot_file():
    puma = robokin.load("puma560")  # its file has no rate_limits
    tr = trajectory.quintic(np.zeros(6), np.full(6, 0.3), 1.0)
    with pytest.raises(InputError, match=r"no velocity limits.*pass v_max=") as info:
        trajectory.retime(puma, tr)
    assert info.value.argument == "v_max"
    with pytest.raises(InputError, match="no acceleration limits") as info:
        trajectory.retime(puma, tr, v_max=1.0)
    assert info.value.argument == "a_max"
    aubo = robokin.load("aubo_i5")  # speeds and accelerations, no jerk
    with pytest.raises(InputError, match="no jerk limits") as info:
        trajectory.retime(aubo, trajectory.quintic(np.zeros(6), np.full(6, 0.3), 1.0),
                          j_max="robot")
    assert info.value.argument == "j_max"


def test_an_unknown_limit_in_the_robot_file_names_the_joint():
    from robokin.model.rate_limits import RateLimits

    arm = robokin.load("ur5").replace(rate_limits=RateLimits(
        velocity=[1.0] * 5 + [np.nan], acceleration=[2.0] * 6))
    with pytest.raises(InputError, match="no velocity limit for joint wrist_3"):
        trajectory.retime(arm, trajectory.quintic(Q0, Q0 + 0.2, 1.0))


def test_a_path_through_a_jump_needs_an_infinite_velocity(ur5):
    # two moves glued with a gap: q jumps by 0.3 rad between two samples while the
    # recorded speeds there are zero; following it would take no time at all
    a = trajectory.quintic(Q0, Q0 + 0.2, 1.0)
    b = trajectory.quintic(Q0 + 0.5, Q0 + 0.8, 1.0)
    glued = trajectory.Trajectory(
        np.concatenate([a.t, b.t[1:] + a.t[-1]]),
        np.concatenate([a.q, b.q[1:]]), np.concatenate([a.qd, b.qd[1:]]),
        np.concatenate([a.qdd, b.qdd[1:]]))
    with pytest.raises(InputError, match=r"jumps between samples 200 and 201.*"
                                         r"infinite joint velocity") as info:
        trajectory.retime(ur5, glued, v_max=1.0, a_max=2.0)
    assert info.value.argument == "traj"
    # the positions alone are a smooth path through the gap, and retime
    out = trajectory.retime(ur5, glued.q, v_max=1.0, a_max=2.0)
    assert np.isfinite(out.qd).all()


def test_positions_with_velocities_that_do_not_move_are_a_jump(ur5, move):
    still = move.replace(qd=np.zeros_like(move.qd))
    with pytest.raises(InputError, match="infinite joint velocity"):
        trajectory.retime(ur5, still, v_max=1.0, a_max=2.0)


def test_non_finite_samples_and_paths_that_do_not_move(ur5, move):
    q = move.q.copy()
    q[5, 2] = np.nan
    with pytest.raises(InputError, match="NaN or infinite"):
        trajectory.retime(ur5, q, v_max=1.0, a_max=2.0)
    with pytest.raises(InputError, match="does not move"):
        trajectory.retime(ur5, np.tile(Q0, (10, 1)), v_max=1.0, a_max=2.0)
    with pytest.raises(InputError, match="at least 2 samples"):
        trajectory.retime(ur5, Q0[None, :], v_max=1.0, a_max=2.0)


def test_wrong_joint_count(ur5):
    with pytest.raises(InputError, match="has 6 joints") as info:
        trajectory.retime(ur5, np.zeros((5, 4)), v_max=1.0, a_max=2.0)
    assert info.value.argument == "traj"


def test_a_cycle_time_below_the_minimum_is_refused(ur5, move):
    res = trajectory.retime_detailed(ur5, move, v_max=1.0, a_max=2.0)
    with pytest.raises(InputError, match="shorter than the minimum cycle time") as info:
        res.slowed(res.duration * 0.9)
    assert info.value.argument == "cycle_time"
    with pytest.raises(InputError, match="expected a duration"):
        res.slowed(float("nan"))
    assert res.slowed(res.duration).duration == pytest.approx(res.duration)


def test_too_many_samples_are_refused_before_sampling(ur5, move):
    with pytest.raises(InputError, match="more than the limit") as info:
        trajectory.retime(ur5, move, v_max=1e-3, a_max=1e-3, max_samples=1000)
    assert info.value.argument == "dt"


@pytest.mark.parametrize("max_samples", ["abc", 0, 1.5, -1, True])
def test_a_bad_max_samples_is_refused_by_its_name(ur5, move, max_samples):
    with pytest.raises(InputError, match="max_samples") as info:
        trajectory.retime(ur5, move, v_max=1.0, a_max=2.0, max_samples=max_samples)
    assert info.value.argument == "max_samples"


def test_a_missing_extra_names_it(ur5, move, monkeypatch):
    monkeypatch.setitem(sys.modules, "toppra", None)
    with pytest.raises(MissingExtraError, match=r"robokin\[retime\]"):
        trajectory.retime(ur5, move, v_max=1.0, a_max=2.0)
    monkeypatch.setitem(sys.modules, "ruckig", None)
    with pytest.raises(MissingExtraError, match="ruckig"):
        trajectory.retime(ur5, move, v_max=1.0, a_max=2.0, j_max=10.0)
