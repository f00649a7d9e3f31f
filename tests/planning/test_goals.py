"""Goal arguments (robokin.planning.goals): configurations, sets and poses.

Oracles: a pose's candidates are exactly the in-limit IK solutions, each 2*pi
turn of a joint whose range exceeds 2*pi included (FK of every candidate is the
pose, and the generating configuration is among them); rows outside the joint
limits are dropped with the reason naming the joint.
"""

from __future__ import annotations

import numpy as np
import pytest

import robokin
from reference import random_7r, ur5_on_a_track
from robokin.exceptions import InputError
from robokin.planning import goal_configurations


def test_a_configuration_and_a_set_keep_their_rows():
    robot = robokin.load("panda")
    q = np.array([0.1, -0.5, 0.2, -2.0, 0.1, 1.5, 0.3])
    g = goal_configurations(robot, q)
    assert g.kind == "configuration" and np.array_equal(g.q, q[None])
    bad = q.copy()
    bad[3] = 0.5  # joint 4's upper limit is -0.0698
    g = goal_configurations(robot, np.stack([bad, q, q + 0.01]))
    assert g.kind == "set" and np.array_equal(g.index, [1, 2])
    assert np.array_equal(g.q[0], q)
    g = goal_configurations(robot, bad)
    assert g.q.shape == (0, 7) and "joint 4" in g.reason and "upper limit" in g.reason


def test_a_pose_gives_every_in_limit_solution_with_its_whole_turns():
    robot = robokin.load("ur5")  # +-360 deg joints: each angle twice
    q = np.array([0.3, -1.2, 1.0, -0.5, 1.2, 0.4])
    T = robot.fk(q)
    g = goal_configurations(robot, T)
    assert g.kind == "pose" and np.array_equal(g.pose, T)
    np.testing.assert_allclose(robot.fk(g.q), np.broadcast_to(T, (len(g.q), 4, 4)),
                               atol=1e-9)
    assert np.min(np.abs(g.q - q).max(axis=1)) < 1e-9  # the generating one is there
    assert np.min(np.abs(g.q - (q - [2 * np.pi, 0, 0, 0, 0, 0])).max(axis=1)) < 1e-9
    per_branch = len(robot.ik(T).keep_within_limits())
    assert len(g.q) == len(robot.ik(T).keep_within_limits().expand_turns())
    assert len(g.q) > per_branch
    assert np.all(g.q >= robot.limits[:, 0]) and np.all(g.q <= robot.limits[:, 1])


def test_an_unreachable_pose_says_so():
    robot = robokin.load("aubo_i5")
    T = np.eye(4)
    T[:3, 3] = (5.0, 0.0, 0.0)
    g = goal_configurations(robot, T)
    assert g.q.shape == (0, 6) and g.reason.startswith("the goal pose is unreachable")


def test_a_four_joint_arm_reads_a_rigid_transform_as_a_pose():
    robot = robokin.load("scara")
    q = np.array([0.3, 0.5, 0.1, 0.2])
    T = robot.fk(q)
    assert goal_configurations(robot, T).kind == "pose"
    four = np.array([q, q + 0.01, q + 0.02, q + 0.03])  # not a rigid transform
    assert goal_configurations(robot, four).kind == "set"


@pytest.mark.parametrize("bad", [np.zeros(5), np.zeros((2, 5)), np.zeros((0, 6)),
                                 np.full(6, np.nan), "home", np.zeros((3, 4, 4))])
def test_bad_goals_are_named(bad):
    with pytest.raises(InputError, match="'goal'"):
        goal_configurations(robokin.load("ur5"), bad)


def test_a_seven_joint_pose_samples_every_in_limit_interval_of_its_self_motion():
    # oracle: FK of every candidate is the pose (to 1e-9); every in-limit interval of
    # robot.self_motion(T) holds at least one first-round candidate; later rounds
    # halve the cells, so no candidate repeats and round r holds 2**r times round 0
    robot = robokin.load("panda")
    q = np.array([0.0, 0.3, 0.0, -1.8, 0.0, 2.1, 0.8])
    T = robot.fk(q)
    g = goal_configurations(robot, T)
    sm = robot.self_motion(T)
    assert g.kind == "pose" and g.manifold is not None and g.rounds == 1
    assert len(sm.intervals) >= 3
    t = g.q[:, 6]  # the parameter is q7 on the Panda
    for (a, b), br in zip(sm.intervals, sm.interval_branch, strict=True):
        inside = (t >= a) & (t <= b)
        assert inside.any()
        branch = sm.sample(t[inside])[np.arange(inside.sum()), br]
        assert np.any(np.abs(branch - g.q[inside]).max(axis=1) < 1e-12)
    first = len(g.q)
    for r in range(1, 3):
        g, rows = g.grown()
        assert len(rows) == first * 2**r and g.rounds == r + 1
    np.testing.assert_allclose(robot.fk(g.q), np.broadcast_to(T, (len(g.q), 4, 4)),
                               atol=1e-9)
    assert np.all(g.q >= robot.limits[:, 0]) and np.all(g.q <= robot.limits[:, 1])
    assert len(np.unique(np.round(g.q, 12), axis=0)) == len(g.q)


def test_an_aligned_pose_samples_its_continua_too():
    """Oracle: the Panda's home configuration q0 = (0, 0, 0, -pi/2, 0, pi/2, pi/4): q2 =
    0 puts axes 1 and 3 on one line, so every (q1 + s, q3 - s) inside the limits
    reaches the same pose, a continuum of configurations no branch sample holds
    (session 24; before, the goals were the branches' samples only). From the second
    round on the goals hold samples of it (q2 = 0, q7 = q0's, q1 + q3 = 0 mod 2 pi,
    q1 over most of its range; the first round is the branches' alone), every goal
    reaches the pose inside the limits, and none repeats (a continuum sample on its
    branch's aligned point is that branch sample, once) to the last round."""
    robot = robokin.load("panda")
    q0 = np.array([0.0, 0.0, 0.0, -np.pi / 2, 0.0, np.pi / 2, np.pi / 4])
    T = robot.fk(q0)
    g = goal_configurations(robot, T)
    sm = robot.self_motion(T)
    lines = sm.continua()
    assert lines is not None and len(lines.base) >= 1

    def on_line(q):
        return (np.abs(q[:, 1]) <= 1e-12) & (np.abs(q[:, 6] - q0[6]) <= 1e-12)

    assert on_line(g.q).sum() <= 2  # (the branches' own samples there)
    first = len(g.q)
    g2, rows = g.grown()
    on = on_line(g2.q)
    assert on.sum() >= 16
    q1q3 = np.angle(np.exp(1j * (g2.q[on, 0] + g2.q[on, 2])))
    np.testing.assert_allclose(q1q3, 0.0, atol=1e-12)
    assert np.ptp(g2.q[on, 0]) > 0.8 * np.ptp(robot.limits[0])
    assert len(rows) >= 2 * first + 16
    np.testing.assert_allclose(robot.fk(g2.q), np.broadcast_to(T, (len(g2.q), 4, 4)),
                               atol=1e-12)
    assert np.all(g2.q >= robot.limits[:, 0]) and np.all(g2.q <= robot.limits[:, 1])
    assert len(np.unique(np.round(g2.q, 12), axis=0)) == len(g2.q)
    while g2.can_grow:  # to the last round: thousands of samples, still none repeated
        g2, _ = g2.grown()
    assert len(g2.q) > 200 * first
    assert len(np.unique(np.round(g2.q, 12), axis=0)) == len(g2.q)
    np.testing.assert_allclose(robot.fk(g2.q), np.broadcast_to(T, (len(g2.q), 4, 4)),
                               atol=1e-12)


def test_a_pose_written_to_twelve_digits_keeps_its_self_motion():
    # a rotation orthonormal only to ~1e-12 (a pose read back from a file) made the
    # held-q7 closed form reject every branch (it accepts a solution within 1e-12):
    # the goal is projected onto SE(3) first. Oracle: FK of the candidates is the
    # written pose to 1e-9 and the generating q7's branch is reached.
    robot = robokin.load("panda")
    q = np.array([-1.005, 1.7246, 0.98118, -2.46426, 2.5477, 1.62304, -0.55742])
    T = robot.fk(q)
    T[:3, :3] *= 1.0 - 1e-12  # as a pose rounded to 12 digits may be
    # (robokin's self_motion(T) of this T had no in-limit interval on 2026-12-02)
    g = goal_configurations(robot, T)
    assert g.manifold is not None and len(g.q) > 0
    np.testing.assert_allclose(robot.fk(g.q), np.broadcast_to(T, (len(g.q), 4, 4)),
                               atol=1e-9)


def test_a_placed_robot_solves_its_pose_on_the_unplaced_one():
    # oracle: the placed robot's own FK of every candidate is the world pose; the
    # candidates equal those of the placed robot solved directly
    robot = robokin.load("panda")
    placed = robot.with_base(robot.base @ np.array(
        [[0, -1, 0, 0.3], [1, 0, 0, -0.2], [0, 0, 1, 0.1], [0, 0, 0, 1.0]]))
    placed = placed.with_tool(placed.tool @ np.array(
        [[1, 0, 0, 0], [0, 0, -1, 0.01], [0, 1, 0, 0.1], [0, 0, 0, 1.0]]))
    T = placed.fk(np.array([0.2, 0.4, -0.3, -1.9, 0.2, 2.0, 0.5]))
    g = goal_configurations(placed, T, solver=robot)
    direct = goal_configurations(placed, T)
    np.testing.assert_allclose(placed.fk(g.q), np.broadcast_to(T, (len(g.q), 4, 4)),
                               atol=1e-9)
    assert g.q.shape == direct.q.shape
    np.testing.assert_allclose(g.q, direct.q, atol=1e-8)


def _assert_goals_sample_every_interval(robot, T, g, sm):
    """A pose goal g sampled on the manifold sm: every in-limit interval holds a round-0
    candidate that is its branch's row there (1e-12); FK of every candidate is T
    (1e-9), inside the limits."""
    assert g.kind == "pose" and g.manifold is not None and len(g.q) >= len(sm.intervals)
    t = g.q[:, sm.joint]
    for (a, b), br in zip(sm.intervals, sm.interval_branch, strict=True):
        inside = (t >= a) & (t <= b)
        assert inside.any()
        branch = sm.sample(t[inside])[np.arange(inside.sum()), br]
        assert np.any(np.abs(branch - g.q[inside]).max(axis=1) < 1e-12)
    np.testing.assert_allclose(robot.fk(g.q), np.broadcast_to(T, (len(g.q), 4, 4)),
                               atol=1e-9)
    assert np.all(g.q >= robot.limits[:, 0]) and np.all(g.q <= robot.limits[:, 1])


def test_a_robot_on_a_track_samples_its_manifold_over_the_track():
    # Session 16: a UR5 on a 2 m rail (no held-joint closed form of the Panda's kind)
    # took the numeric sample as its pose goal; now the manifold over the track.
    # Oracles: FK of every candidate is the pose (1e-9), inside the limits; every
    # in-limit interval of robot.self_motion(T) (the track its parameter) holds a
    # candidate of round 0 that is its branch's row there.
    robot = ur5_on_a_track(2.0)
    T = robot.fk(np.array([0.7, 0.3, -1.2, 1.1, -0.5, 0.8, 0.2]))
    g = goal_configurations(robot, T)
    sm = robot.self_motion(T)
    assert sm.parameter == "track"
    _assert_goals_sample_every_interval(robot, T, g, sm)


def test_a_general_7r_arm_samples_its_continued_manifold():
    # Session 17: a 7R arm without a closed form (random_7r: the general held-joint
    # 6R solver, joint 7 continued) took robot.ik's numeric sample as its pose goal;
    # now the whole continued manifold. Oracles: FK of every candidate is the pose
    # (1e-9), inside the limits; every in-limit interval of robot.self_motion(T)
    # holds a round-0 candidate that is its branch's row there; the generating
    # configuration's interval among them.
    robot = random_7r()
    q0 = np.clip(np.array([0.4, np.pi / 2, -0.3, 0.0, 0.8, -1.1, 0.5]),
                 robot.limits[:, 0], robot.limits[:, 1])
    T = robot.fk(q0)
    g = goal_configurations(robot, T)
    sm = robot.self_motion(T)
    assert sm.method.startswith("continued general 6R")
    _assert_goals_sample_every_interval(robot, T, g, sm)
    row = sm.sample(q0[sm.joint])
    assert np.nanmin(np.abs(row - q0).max(axis=1)) < 1e-9


def test_an_arm_whose_held_chain_is_sampled_keeps_the_ik_solutions():
    # improved_dh_arm (two prismatic joints): its held rows would be numeric samples,
    # so the pose goal is robot.ik's solutions (oracle: FK of each is the pose)
    robot = robokin.load("improved_dh_arm")
    q0 = np.clip(np.full(7, 0.3), robot.limits[:, 0], robot.limits[:, 1])
    T = robot.fk(q0)
    g = goal_configurations(robot, T)
    assert g.kind == "pose" and g.manifold is None and len(g.q) >= 1
    np.testing.assert_allclose(robot.fk(g.q), np.broadcast_to(T, (len(g.q), 4, 4)),
                               atol=1e-9)


@pytest.mark.parametrize("piece,u,field", [
    (np.array([5]), np.array([0.5]), "piece"),     # no such piece
    (np.array([0.5]), np.array([0.5]), "piece"),   # not an index
    (np.array([0]), np.array([1.5]), "u"),         # past the stretch
    (np.array([0, 0]), np.array([0.5]), "u"),      # one fraction for two pieces
])
def test_a_continuum_piece_asked_for_wrongly_is_named(piece, u, field):
    robot = robokin.load("panda")
    q0 = np.array([0.0, 0.0, 0.0, -np.pi / 2, 0.0, np.pi / 2, np.pi / 4])
    lines = robot.self_motion(robot.fk(q0)).continua()
    assert lines is not None and len(lines.base) == 1
    with pytest.raises(InputError, match=field):
        lines.at(piece, u)
