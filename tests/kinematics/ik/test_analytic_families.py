"""Closed-form IK families: FK round trip, completeness, singular and unreachable poses."""

import math

import numpy as np
import pytest

import robokin
from robokin.kinematics.ik.analytic._common import fk_error
from robokin.kinematics.ik.analytic.detect import detect
from robokin.kinematics.ik.analytic.palletizer import pose_from_position_yaw
from robokin.spatial import rotx


def _random_q(robot, rng, m):
    lim = robot.limits
    lo = np.maximum(lim[:, 0], -np.pi)
    hi = np.minimum(lim[:, 1], np.pi)
    return rng.uniform(lo, hi, (m, robot.n))


def _check_round_trip(robot, q, sols, tol=1e-9):
    T = robot.fk(q)
    dp, dr = fk_error(robot.chain, sols.q, T)
    assert np.all(np.where(sols.valid, dp, 0.0) < tol)
    assert np.all(np.where(sols.valid, dr, 0.0) < tol)
    diff = sols.q - q[:, None, :]
    diff = np.where(robot.is_revolute, (diff + np.pi) % (2 * np.pi) - np.pi, diff)
    gap = np.where(sols.valid, np.abs(diff).max(axis=-1), np.inf).min(axis=-1)
    # completeness: the generating configuration is among the solutions
    assert np.all(gap < 1e-6), np.flatnonzero(gap >= 1e-6)


@pytest.mark.parametrize(
    ("name", "family", "max_count"),
    [("ur5", "three_parallel", 8), ("aubo_i5", "three_parallel", 8),
     ("puma560", "spherical_wrist", 8), ("puma560_modified", "spherical_wrist", 8),
     ("scara", "scara", 2), ("qfmd010", "palletizer", 4)],
)
def test_round_trip_and_completeness(name, family, max_count):
    robot = robokin.load(name)
    rng = np.random.default_rng(7)
    q = _random_q(robot, rng, 2000)
    sols = robot.ik(robot.fk(q), method="analytic")
    assert sols.method == f"analytic:{family}"
    assert sols.q.shape == (2000, max_count, robot.n)
    assert np.all(sols.status == "ok")
    assert np.isfinite(sols.q[sols.valid]).all()
    assert np.isnan(sols.q[~sols.valid]).all()  # rows that are not solutions
    _check_round_trip(robot, q, sols)


def test_batch_equals_single_calls():
    robot = robokin.load("ur5")
    q = _random_q(robot, np.random.default_rng(3), 6).reshape(2, 3, 6)
    T = robot.fk(q)
    batch = robot.ik(T)
    assert batch.shape == (2, 3)
    for i in range(2):
        for j in range(3):
            one = robot.ik(T[i, j])
            np.testing.assert_array_equal(one.valid, batch.valid[i, j])
            np.testing.assert_allclose(one.q[one.valid], batch.q[i, j][batch.valid[i, j]])


def test_aubo_eight_solutions_at_generic_pose():
    robot = robokin.load("aubo_i5")
    q0 = np.radians([20.0, 30.0, -60.0, 40.0, 70.0, -30.0])
    sols = robot.ik(robot.fk(q0))
    assert len(sols) == 8
    # eight distinct solutions
    Q = sols.solutions()
    d = np.abs(((Q[:, None] - Q[None]) + np.pi) % (2 * np.pi) - np.pi).max(axis=-1)
    assert (d + np.eye(8) * 10 > 1e-3).all()
    assert np.abs(robot.fk(Q) - robot.fk(q0)).max() < 1e-10
    # every (shoulder, elbow, wrist) combination appears once
    combos = {tuple(int(sols.branches[k][i]) for k in ("shoulder", "elbow", "wrist"))
              for i in np.flatnonzero(sols.valid)}
    assert len(combos) == 8


def test_puma_modified_matches_standard_twin():
    std, mod = robokin.load("puma560"), robokin.load("puma560_modified")
    q = _random_q(std, np.random.default_rng(11), 200)
    a, b = std.ik(std.fk(q)), mod.ik(mod.fk(q))
    np.testing.assert_array_equal(a.valid, b.valid)
    np.testing.assert_allclose(np.where(a.valid[..., None], a.q, 0),
                               np.where(b.valid[..., None], b.q, 0), atol=1e-9)


@pytest.mark.parametrize("name", ["ur5", "puma560"])
def test_singular_wrist_keeps_q6_and_flags(name):
    robot = robokin.load(name)
    q0 = np.array([0.3, 0.5, -1.2, 0.4, 0.0, 0.7])
    T = robot.fk(q0)
    sols = robot.ik(T, q_near=q0)
    assert len(sols) >= 1
    Q = sols.solutions()
    assert np.isfinite(Q).all()
    assert sols.singular[sols.valid].any()
    assert np.abs(robot.fk(Q) - T).max() < 1e-9
    # theta6 kept at q_near where singular
    np.testing.assert_allclose(sols.q[sols.singular][:, 5], 0.7, atol=1e-12)
    assert np.abs(sols.nearest(q0) - q0).max() < 1e-9
    # without q_near: theta6 = 0
    s0 = robot.ik(T)
    np.testing.assert_allclose(s0.q[s0.singular][:, 5], 0.0, atol=1e-12)
    assert np.abs(robot.fk(s0.solutions()) - T).max() < 1e-9


def test_unreachable_pose_gives_empty_set_with_reason():
    robot = robokin.load("ur5")
    T = np.eye(4)
    T[0, 3] = 3.0  # the UR5 reaches about 0.85 m
    sols = robot.ik(T)
    assert len(sols) == 0
    assert sols.status.item() == "out of reach"
    with pytest.raises(robokin.exceptions.UnreachableError, match="out of reach"):
        sols.nearest(np.zeros(6))


def test_scara_two_elbows_hand_formula():
    robot = robokin.load("scara")
    c1, c2, c3, c4 = 0.400, 0.325, 0.275, -0.150
    q1, q2, q3, l4 = math.radians(20), math.radians(50), math.radians(-30), 0.08
    x = c2 * math.cos(q1) + c3 * math.cos(q1 + q2)
    y = c2 * math.sin(q1) + c3 * math.sin(q1 + q2)
    z = c1 + c4 + l4
    yaw = q1 + q2 + q3
    T = np.eye(4)
    T[:3, :3] = [[math.cos(yaw), -math.sin(yaw), 0], [math.sin(yaw), math.cos(yaw), 0],
                 [0, 0, 1]]
    T[:3, 3] = [x, y, z]
    sols = robot.ik(T)
    assert len(sols) == 2
    Q = sols.solutions()
    # law of cosines: the two elbows are +-q2
    np.testing.assert_allclose(sorted(Q[:, 1]), [-q2, q2], atol=1e-12)
    np.testing.assert_allclose(Q[:, 3], l4, atol=1e-12)
    labels = sols.branches["elbow"][sols.valid]
    assert sorted(labels.tolist()) == [-1, 1]
    assert labels[np.argmax(Q[:, 1])] == 1  # forearm counter-clockwise about +z
    # a tilted target cannot be reached
    assert robot.ik(T @ rotx(0.1)).status.item() == "orientation not achievable"


def test_palletizer_joint_ranges_remove_extra_solutions():
    robot = robokin.load("qfmd010")
    q0 = np.radians([30.0, 10.0, -5.0, 20.0])
    # the paper's forward model (mm): r = 700 c2 + 650 c3
    q1, q2, q3, q4 = q0
    r = 700 * math.cos(q2) + 650 * math.cos(q3)
    P3 = np.array([-math.sin(q1) * r, math.cos(q1) * r,
                   -900 + 700 * math.sin(q2) + 650 * math.sin(q3)])
    P4 = P3 + 250 * np.array([-math.sin(q1 + q4), math.cos(q1 + q4), 0.0])
    T = pose_from_position_yaw(robot, P4 / 1000.0, q1 + q4)
    sols = robot.ik(T)
    assert len(sols) == 4  # two waist branches x two elbows
    assert np.abs(robot.fk(sols.solutions()) - T).max() < 1e-12
    inside = sols.keep_within_limits()
    assert len(inside) == 1
    np.testing.assert_allclose(inside.solutions()[0], q0, atol=1e-12)
    # a pose only the out-of-range candidates reach names the joint and limit
    q_bad = np.radians([30.0, 40.0, -5.0, 20.0])
    rep = robot.ik(robot.fk(q_bad)).keep_within_limits()
    assert len(rep) == 0
    assert "joint 2" in rep.status.item() and "upper limit 0.436332" in rep.status.item()


def test_palletizer_tool_cannot_tilt():
    robot = robokin.load("qfmd010")
    T = robot.fk(np.radians([30.0, 10.0, -5.0, 20.0])) @ rotx(0.05)
    sols = robot.ik(T)
    assert len(sols) == 0
    assert sols.status.item() == "not reachable: tool cannot tilt"


def test_near_family_calibrated_ur5_polished():
    rows = [
        {"a": 0, "alpha": math.pi / 2, "d": 0.089159, "theta": 0},
        {"a": -0.425, "alpha": 0, "d": 0, "theta": 0},
        {"a": -0.39225, "alpha": 0, "d": 0, "theta": 0},
        {"a": 0, "alpha": math.pi / 2, "d": 0.10915, "theta": 0},
        {"a": 0, "alpha": -math.pi / 2, "d": 0.09465, "theta": 0},
        {"a": 0, "alpha": 0, "d": 0.0823, "theta": 0},
    ]
    rng = np.random.default_rng(5)
    for row in rows:
        row["alpha"] += rng.normal(0, 1e-4)
        row["theta"] += rng.normal(0, 1e-4)
    robot = robokin.Robot.from_dh(rows, name="ur5_calibrated")
    # by default a near-family arm goes to the complete general 6R solver (docs/ik.md);
    # its nominal closed form + Newton polish stays available
    assert robokin.ik.family(robot).name == "general_6r"
    fam = detect(robot, general_6r=False)
    assert fam.name == "three_parallel" and fam.near
    assert "axes 2-4 parallel within" in fam.measured
    q = rng.uniform(-np.pi, np.pi, (300, 6))
    q[:, 2] = rng.uniform(0.2, 2.9, 300) * rng.choice([-1, 1], 300)  # away from folded/stretched elbow
    T = robot.fk(q)
    sols = fam.solver(robot, T)
    assert sols.method == "analytic:three_parallel+newton"
    assert sols.info["polished"]
    assert sols.flags["polished"][sols.valid].all()
    _check_round_trip(robot, q, sols)
