"""Targets at the wrist singularity are solved, never 'out of reach' (issue 20, item 3).

With q5 = 0 exactly (a UR arm's home pose) one combination of joints is free. The
closed forms return finite, valid solutions flagged ``singular``; q6 is q_near's when
the rest of the arm can follow it (else the nearest value that lets it), so with
q_near at the generating configuration that configuration itself comes back.
"""

import numpy as np
import pytest

import robokin
from reference import pose_errors


def _singular_targets(robot, n, seed):
    rng = np.random.default_rng(seed)
    lim = np.clip(robot.limits, -np.pi, np.pi)
    q = rng.uniform(lim[:, 0], lim[:, 1], (n, robot.n))
    q[:, 4] = 0.0
    return q, robot.fk(q)


@pytest.mark.parametrize("name", ["ur5", "aubo_i5", "puma560", "puma560_modified"])
def test_every_singular_target_is_solved_and_flagged(name):
    robot = robokin.load(name)
    q, T = _singular_targets(robot, 2000, 0)
    sols = robot.ik(T)
    assert (sols.status == "ok").all()
    # the branch that generated the pose is at the singularity (other shoulder /
    # wrist branches of the same pose need not be)
    assert (sols.singular & sols.valid).any(axis=-1).all()
    assert not (sols.singular & ~sols.valid).any()
    ok = sols.valid
    F = robot.fk(np.where(ok[..., None], sols.q, 0.0))
    dp, dr = pose_errors(F, np.broadcast_to(T[:, None], F.shape))
    assert dp[ok].max() < 1e-9 and dr[ok].max() < 1e-9


@pytest.mark.parametrize("name", ["ur5", "aubo_i5"])
def test_q_near_at_the_generating_configuration_gets_it_back(name):
    robot = robokin.load(name)
    q, T = _singular_targets(robot, 500, 1)
    sols = robot.ik(T, q_near=q)
    near = sols.nearest(q, respect_limits=False)
    d = np.abs((near - q + np.pi) % (2 * np.pi) - np.pi)
    assert d.max() < 1e-6
    one = robot.ik(T[7], q_near=q[7])  # the single-pose path too
    assert np.abs((one.nearest(q[7], respect_limits=False) - q[7] + np.pi)
                  % (2 * np.pi) - np.pi).max() < 1e-6


def test_without_q_near_q6_is_zero_where_the_arm_can_follow():
    robot = robokin.load("ur5")
    q, T = _singular_targets(robot, 300, 2)
    sols = robot.ik(T)
    q6 = sols.q[..., 5][sols.valid & sols.singular]
    # the documented default: q6 = 0 unless the elbow cannot reach with it
    assert (np.abs(q6) < 1e-12).mean() > 0.75  # 87 % on this seed


def test_the_singular_tolerance_is_scale_free():
    # the same arm in millimetres (lengths x 1000): still solved, still flagged
    rows = [{"a": a * 1000, "alpha": al, "d": d * 1000, "joint": "revolute",
             "limits": [-2 * np.pi, 2 * np.pi]}
            for a, al, d in [(0, np.pi / 2, 0.089159), (-0.425, 0, 0), (-0.39225, 0, 0),
                             (0, np.pi / 2, 0.10915), (0, -np.pi / 2, 0.09465),
                             (0, 0, 0.0823)]]
    robot = robokin.Robot.from_dh(rows)
    q, T = _singular_targets(robot, 500, 3)
    sols = robot.ik(T)
    assert sols.method == "analytic:three_parallel"
    assert (sols.valid & sols.singular).any(axis=-1).all()
