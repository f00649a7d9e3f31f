"""robokin.process.order: visiting order of a point set with the IK branch per point.

Oracles: an exact generalised-TSP optimum computed independently (Held-Karp over
subsets of poses, with every configuration of ``tests/process/reference.py`` as a
state: every IK solution, every whole turn inside the limits listed explicitly,
numpy only) on small sets; on 60 holes the result's own Held-Karp lower bound
(checked to be a true lower bound on the small sets) and the motion's properties
(a permutation, FK reproduces each pose, inside the limits).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from process import reference as ref
from process.paths import Q0, panel_holes, with_limits
from robokin import process
from robokin.exceptions import InputError
from robokin.process._graph import arm_facts
from robokin.spatial import rotz


def exact_gtsp(robot, poses, angles, q_start=None):
    """The least objective over every order and every configuration (Held-Karp)."""
    mu_ref = arm_facts(robot).mu_ref
    Q = [ref.configurations(robot, T, angles, mu_ref=mu_ref)[0] for T in poses]
    C = [ref.node_costs(robot, q, mu_ref=mu_ref) for q in Q]
    P = len(Q)
    D = {(a, b): np.abs(Q[a][:, None, :] - Q[b][None, :, :]).max(axis=2)
         for a in range(P) for b in range(P) if a != b}
    V: dict[tuple[int, int], np.ndarray] = {}
    for c in range(P):
        start = 0.0 if q_start is None else np.abs(Q[c] - q_start).max(axis=1)
        V[(1 << c, c)] = C[c] + start
    for S in range(1, 1 << P):
        for c in range(P):
            if (S, c) not in V:
                continue
            for d in range(P):
                if S & (1 << d):
                    continue
                new = (V[(S, c)][:, None] + D[(c, d)]).min(axis=0) + C[d]
                key = (S | (1 << d), d)
                V[key] = new if key not in V else np.minimum(V[key], new)
    full = (1 << P) - 1
    return min(float(V[(full, c)].min()) for c in range(P))


def assert_valid_visit(robot, res, poses):
    """A permutation; each configuration reaches its pose (turned by free_angle)."""
    P = poses.shape[0]
    assert res.feasible and res.reason == "ok" and res.skipped.size == 0
    assert sorted(res.order.tolist()) == list(range(P))
    expected = poses[res.order] @ rotz(res.free_angle)
    np.testing.assert_allclose(robot.fk(res.q), expected, atol=1e-9)
    assert robot.within_limits(res.q, tol=1e-9).all()
    steps = np.abs(np.diff(res.q, axis=0)).max(axis=1)
    assert res.travel == pytest.approx(steps.sum(), rel=1e-12)


@pytest.mark.parametrize(("name", "count", "seed"), [("aubo_i5", 7, 3), ("ur5", 5, 4)])
def test_small_sets_are_within_20_percent_of_the_exact_optimum(name, count, seed):
    robot = process_robot(name)
    poses = panel_holes(name, count, seed)
    res = process.order(robot, poses)
    assert_valid_visit(robot, res, poses)
    best = exact_gtsp(robot, poses, [0.0])
    assert res.cost >= best - 1e-9  # nothing beats the exact optimum
    assert res.cost <= 1.2 * best
    assert res.lower_bound <= best + 1e-9  # the bound is a bound
    assert res.gap == pytest.approx(max((res.cost - res.lower_bound) / res.lower_bound, 0))


def process_robot(name):
    """The arm as built in; the UR5's +-2 turn joints cut to one turn (the exact
    reference lists every whole turn: 512 configurations a pose otherwise)."""
    import robokin

    robot = robokin.load(name)
    if name == "ur5":
        robot = with_limits(robot, np.tile([-3.0, 3.0], (6, 1)))
    return robot


def test_q_start_is_where_the_visit_begins_and_matches_the_exact_optimum():
    robot = process_robot("aubo_i5")
    poses = panel_holes("aubo_i5", 6, 11)
    res = process.order(robot, poses, q_start=Q0)
    assert_valid_visit(robot, res, poses)
    assert res.approach == pytest.approx(np.abs(res.q[0] - Q0).max(), abs=1e-15)
    best = exact_gtsp(robot, poses, [0.0], q_start=Q0)
    assert best - 1e-9 <= res.cost <= 1.2 * best
    assert res.lower_bound <= best + 1e-9


def test_a_free_axis_is_searched_with_the_order():
    robot = process_robot("aubo_i5")
    poses = panel_holes("aubo_i5", 5, 21)
    angles = np.array([-0.4, -0.2, 0.0, 0.2, 0.4])
    res = process.order(robot, poses, free_axis="z", free_range=(-0.4, 0.4),
                        free_step=0.2)
    assert_valid_visit(robot, res, poses)
    assert set(np.round(res.free_angle, 12)) <= set(angles)
    best = exact_gtsp(robot, poses, angles)
    assert best - 1e-9 <= res.cost <= 1.2 * best
    assert res.cost <= process.order(robot, poses).cost + 1e-12  # 0 is a sample


@pytest.mark.parametrize("name", ["ur5", "aubo_i5"])
def test_sixty_holes_are_within_20_percent_of_the_lower_bound(name):
    import robokin

    robot = robokin.load(name)
    poses = panel_holes(name, 60, 7)
    res = process.order(robot, poses)
    assert_valid_visit(robot, res, poses)
    assert 0.0 < res.lower_bound <= res.cost
    assert res.gap <= 0.2
    # the given order, followed with the best branches, travels several times more
    given = process.follow(robot, poses, max_step=math.inf)
    assert given.feasible and res.travel < 0.5 * given.travel


def test_the_same_input_gives_the_same_order():
    import robokin

    robot = robokin.load("aubo_i5")
    poses = panel_holes("aubo_i5", 20, 5)
    a, b = process.order(robot, poses), process.order(robot, poses)
    assert np.array_equal(a.order, b.order) and np.array_equal(a.q, b.q)


def test_an_unreachable_pose_is_skipped_and_named():
    import robokin

    robot = robokin.load("aubo_i5")
    poses = panel_holes("aubo_i5", 8, 2)
    poses[3, :3, 3] += [4.0, 0.0, 0.0]
    res = process.order(robot, poses)
    assert not res.feasible and res.skipped.tolist() == [3]
    assert res.reason.startswith("pose 3: out of reach")
    assert sorted(res.order.tolist()) == [0, 1, 2, 4, 5, 6, 7]
    np.testing.assert_allclose(robot.fk(res.q), poses[res.order], atol=1e-9)


def test_one_pose_and_bad_input():
    import robokin

    robot = robokin.load("ur5")
    one = process.order(robot, panel_holes("ur5", 1, 0))
    assert one.order.tolist() == [0] and one.travel == 0.0
    with pytest.raises(InputError) as err:
        process.order(robot, np.zeros((3, 4, 4)))
    assert err.value.argument == "poses"
    with pytest.raises(InputError) as err:
        process.order(robot, panel_holes("ur5", 3, 0), free_axis="y")
    assert err.value.argument == "free_axis"
