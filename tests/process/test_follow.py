"""robokin.process.follow: exact layered search over every IK branch (issue 27).

Oracles: the motion's own properties (every step at most max_step, inside the
limits, the poses reproduced by FK to 1e-9 with the free rotation applied), and the
independent slow reference of ``tests/process/reference.py`` (every configuration
with its whole turns listed, manipulability by SVD, a dense numpy DP), whose
optimum must equal the result's cost at the same sampling.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from process import reference as ref
from process.paths import Q0, circle, load, spin, with_limits
from robokin import process
from robokin._native import num_threads, set_num_threads
from robokin.exceptions import InputError
from robokin.process._graph import arm_facts
from robokin.spatial import rotz, wrap_angle


def assert_valid_motion(robot, res, poses, max_step):
    """Every property a feasible result promises."""
    assert res.feasible and res.reason == "ok" and res.failure is None
    q = res.q
    assert np.isfinite(q).all()
    steps = np.abs(np.diff(q, axis=0)).max(axis=1)
    assert (steps <= max_step + 1e-12).all()
    assert res.max_step == pytest.approx(steps.max(), abs=1e-15)
    assert res.travel == pytest.approx(steps.sum(), rel=1e-12)
    assert robot.within_limits(q, tol=1e-9).all()
    # the tool poses: the waypoints turned about the tool z by free_angle, reached
    expected = poses @ rotz(res.free_angle)
    np.testing.assert_allclose(res.tool_poses, expected, atol=1e-12)
    np.testing.assert_allclose(robot.fk(q), expected, atol=1e-9)


def reference_optimum(robot, poses, angles, max_step, q_start=None):
    mu_ref = arm_facts(robot).mu_ref
    layers, costs = [], []
    for T in poses:
        q, _ = ref.configurations(robot, T, angles, mu_ref=mu_ref)
        layers.append(q)
        costs.append(ref.node_costs(robot, q, mu_ref=mu_ref))
    return ref.shortest_path(layers, costs, max_step=max_step, q_start=q_start), mu_ref


@pytest.mark.parametrize("name", ["ur5", "aubo_i5"])
@pytest.mark.parametrize("free", [False, True])
def test_a_feasible_path_is_valid_and_equals_the_reference_optimum(name, free):
    robot = load(name)
    poses = circle(robot, n=14)
    kw = {}
    angles = np.zeros(1)
    if free:
        kw = {"free_axis": "z", "free_range": (-0.2, 0.2), "free_step": 0.2}
        angles = np.array([-0.2, 0.0, 0.2])
    res = process.follow(robot, poses, max_step=0.3, **kw)
    assert_valid_motion(robot, res, poses, 0.3)
    (best, path), mu_ref = reference_optimum(robot, poses, angles, 0.3)
    assert res.cost == pytest.approx(best, rel=1e-9, abs=1e-12)
    # the cost is the objective of the returned motion, recomputed independently
    assert ref.objective(robot, res.q, mu_ref=mu_ref) == pytest.approx(res.cost, rel=1e-9)


def test_q_start_counts_the_approach_and_matches_the_reference():
    robot = load("ur5")
    poses = circle(robot, n=10)
    q_start = Q0 + np.array([0.3, -0.2, 0.1, 0.0, 0.2, -0.4])
    res = process.follow(robot, poses, max_step=0.3, q_start=q_start)
    assert_valid_motion(robot, res, poses, 0.3)
    assert res.approach == pytest.approx(np.abs(res.q[0] - q_start).max(), abs=1e-15)
    (best, _), mu_ref = reference_optimum(robot, poses, np.zeros(1), 0.3, q_start)
    assert res.cost == pytest.approx(best, rel=1e-9)
    assert ref.objective(robot, res.q, mu_ref=mu_ref, q_start=q_start) == pytest.approx(
        res.cost, rel=1e-9)


def test_joints_spanning_two_turns_get_the_turn_that_fits_their_limits():
    # the tool turns 1.9 times in place: q6 must sweep 11.9 rad of the UR5's 4 pi;
    # on the circle that is free, so the search must pick (and certify) the turn
    robot = load("ur5")
    poses = spin(robot, 1.9, 40)
    res = process.follow(robot, poses, max_step=0.35)
    assert_valid_motion(robot, res, poses, 0.35)
    assert np.ptp(res.q[:, 5]) > 2 * np.pi + 5.0
    (best, _), _ = reference_optimum(robot, poses, np.zeros(1), 0.35)
    assert res.cost == pytest.approx(best, rel=1e-9)


def naive_tracking(robot, poses, q):
    """The nearest solution inside the limits at every pose, from q (what users do)."""
    out = []
    for T in poses:
        q = robot.ik(T).nearest(q)
        out.append(q)
    return np.array(out)


def test_a_wrist_flip_is_chosen_where_naive_tracking_jumps():
    # the tool turns 0.6 turns in place from q6 = 2.0: on the branch nearest the
    # start q6 runs into the AUBO-i5's +175 deg limit; with the wrist flipped
    # (q6 - pi) it fits, so the search starts there
    robot = load("aubo_i5")
    q = np.array([0.3, -1.2, 1.5, -1.9, -1.4, 2.0])
    poses = spin(robot, 0.6, 50, q=q)
    naive = naive_tracking(robot, poses, q)
    assert np.abs(np.diff(naive, axis=0)).max() > 3.0  # it jumps
    res = process.follow(robot, poses, max_step=0.2)
    assert_valid_motion(robot, res, poses, 0.2)
    assert res.q[0, 5] < 0.0  # the flipped wrist


# ---------------------------------------------------------------- infeasible paths


def test_out_of_reach_names_the_first_unreachable_waypoint():
    robot = load("ur5")
    poses = circle(robot, n=12)
    poses[7, :3, 3] += [3.0, 0.0, 0.0]
    poses[9, :3, 3] += [3.0, 0.0, 0.0]
    res = process.follow(robot, poses, max_step=0.3)
    assert not res.feasible
    assert res.failure.index == 7 and res.failure.kind == "out of reach"
    assert res.reason.startswith("waypoint 7: out of reach")
    assert list(res.waypoints.reachable) == [i not in (7, 9) for i in range(12)]
    assert np.isnan(res.q[7]).all() and np.isfinite(res.q[8]).all()
    assert (res.waypoints.colors()[7] == [215, 40, 40]).all()


def test_limits_names_the_waypoint_and_the_joint():
    base = load("ur5")
    robot = with_limits(base, np.stack([Q0 - 0.6, Q0 + 0.6], axis=1))
    poses = circle(robot, n=12)
    q_bad = Q0.copy()
    q_bad[0] += 0.9  # only this joint leaves its (tight) limits
    poses[5] = robot.fk(q_bad)
    res = process.follow(robot, poses, max_step=math.inf)
    assert res.failure.index == 5 and res.failure.kind == "limits"
    assert "joint 1" in res.reason and "limit" in res.reason


def test_singular_names_the_waypoint():
    base = load("ur5")
    lim = np.stack([Q0 - 0.6, Q0 + 0.6], axis=1)
    lim[4] = [-2.0, 0.3]  # q5 = 0 (the wrist singularity) inside; one branch only
    robot = with_limits(base, lim)
    poses = circle(robot, n=10)
    q_sing = Q0.copy()
    q_sing[4] = 0.0
    poses[4] = robot.fk(q_sing)
    res = process.follow(robot, poses, max_step=math.inf)
    assert res.failure.index == 4 and res.failure.kind == "singular"
    assert res.waypoints.status[4] == "singular"


def test_a_jump_names_the_layer_where_every_path_dies_and_the_limit_in_the_way():
    robot = load("aubo_i5")
    poses = spin(robot, 1.2, 120)  # q6 must pass its +-175 deg limit
    res = process.follow(robot, poses, max_step=0.1)
    assert not res.feasible and res.failure.kind == "jump"
    i = res.failure.index
    assert res.waypoints.status[i] == "jump" and res.waypoints.reachable[i]
    assert "joint 6" in res.reason and "limit" in res.reason
    # every waypoint has a configuration; the pieces before and after are valid
    assert np.isfinite(res.q).all()
    assert res.waypoints.segment[i] == res.waypoints.segment[i - 1] + 1
    steps = np.abs(np.diff(res.q, axis=0)).max(axis=1)
    assert steps[i - 1] > 0.1 and (np.delete(steps, i - 1) <= 0.1 + 1e-12).all()
    # the reference agrees: no path through the first i + 1 waypoints
    (best, _), _ = reference_optimum(robot, poses[:i + 1], np.zeros(1), 0.1)
    assert best == math.inf
    (best, _), _ = reference_optimum(robot, poses[:i], np.zeros(1), 0.1)
    assert best < math.inf


def test_collision_names_the_waypoint_inside_an_obstacle():
    pytest.importorskip("coal")
    from robokin import collision

    robot = load("ur5")
    poses = circle(robot, n=12, radius=0.15)
    scene = collision.Scene()
    scene.add_box("block", size=(0.05, 0.05, 0.05), pose=poses[6])  # around the TCP
    res = process.follow(robot, poses, max_step=0.5, scene=scene)
    assert res.failure.index == 6 and res.failure.kind == "collision"
    assert res.waypoints.status[6] == "collision" and not res.waypoints.reachable[6]


def test_a_scene_removes_the_colliding_branch_and_the_motion_is_clear():
    pytest.importorskip("coal")
    from robokin import collision

    robot = load("ur5")
    poses = circle(robot, n=16)
    free = process.follow(robot, poses, max_step=0.3)
    # a small box at the elbow of the free optimum, away from the tool path
    elbow = robot.fk_all(free.q[8])[2, :3, 3]
    scene = collision.Scene()
    scene.add_box("post", size=(0.06, 0.06, 0.06), pose=np.block(
        [[np.eye(3), elbow[:, None]], [np.zeros((1, 3)), np.ones((1, 1))]]))
    assert collision.check(robot, scene, free.q).collides
    res = process.follow(robot, poses, max_step=0.3, scene=scene, clearance=0.01)
    assert_valid_motion(robot, res, poses, 0.3)
    rep = collision.check(robot, scene, res.q, clearance=0.01)
    assert not rep.collides and rep.min_distance > 0.01
    assert res.cost >= free.cost - 1e-12
    assert np.nanmin(res.waypoints.clearance) > 0.01
    assert res.stats["collision_checks"] > 0


# ------------------------------------------------------------------ determinism


def test_the_same_input_gives_the_same_motion_whatever_the_threads():
    robot = load("ur5")
    poses = circle(robot, n=30)
    kw = {"free_axis": "z", "free_range": (-0.5, 0.5), "free_step": 0.1, "max_step": 0.2}
    a = process.follow(robot, poses, **kw)
    before = num_threads()
    try:
        set_num_threads(1)
        b = process.follow(robot, poses, **kw)
    finally:
        set_num_threads(before)
    assert np.array_equal(a.q, b.q) and np.array_equal(a.free_angle, b.free_angle)
    assert a.cost == b.cost


def test_the_free_axis_can_only_help_and_its_angles_are_sampled():
    robot = load("ur5").with_tool(np.array([[1, 0, 0, 0], [0, 0, -1, 0.05],
                                            [0, 1, 0, 0.1], [0, 0, 0, 1.0]]))
    poses = circle(robot, n=20)
    fixed = process.follow(robot, poses, max_step=0.3)
    free = process.follow(robot, poses, max_step=0.3, free_axis="z",
                          free_range=(-0.5, 0.5), free_step=0.25)
    assert free.cost <= fixed.cost + 1e-12  # angle 0 is among the samples
    assert set(np.round(free.free_angle, 12)) <= {-0.5, -0.25, 0.0, 0.25, 0.5}
    assert_valid_motion(robot, free, poses, 0.3)


# ------------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    ("kwargs", "argument"),
    [({"free_axis": "x"}, "free_axis"),
     ({"free_range": (0, 1)}, "free_range"),
     ({"free_axis": "z", "free_range": (1, 0)}, "free_range"),
     ({"free_axis": "z", "free_range": (0, 7)}, "free_range"),
     ({"free_axis": "z", "free_step": 0.0}, "free_step"),
     ({"free_axis": "z", "free_step": 1e-6}, "free_step"),
     ({"max_step": -0.1}, "max_step"),
     ({"max_step": float("nan")}, "max_step"),
     ({"q_start": [0, 0]}, "q_start"),
     ({"q_start": [9, 0, 0, 0, 0, 0]}, "q_start"),
     ({"clearance": 0.01}, "clearance"),
     ({"scene": "press"}, "scene"),
     ({"travel_weight": 0.0}, "travel_weight"),
     ({"limit_margin": -1.0}, "limit_margin")])
def test_bad_arguments_are_named(kwargs, argument):
    robot = load("ur5")
    with pytest.raises(InputError) as err:
        process.follow(robot, circle(robot, n=4), **kwargs)
    assert err.value.argument == argument


@pytest.mark.parametrize("poses", [np.eye(3), np.zeros((2, 4, 4)), [], "poses"])
def test_bad_poses_are_named(poses):
    with pytest.raises(InputError) as err:
        process.follow(load("ur5"), poses)
    assert err.value.argument == "poses"


def test_a_robot_that_is_not_one_is_named():
    with pytest.raises(InputError) as err:
        process.follow("ur5", np.eye(4))
    assert err.value.argument == "robot"


def test_too_many_sampled_poses_are_refused_before_any_work():
    with pytest.raises(InputError, match="sampled poses") as err:
        process.follow(load("ur5"), np.broadcast_to(np.eye(4), (30_000, 4, 4)),
                       free_axis="z", free_step=math.radians(5))
    assert err.value.argument == "poses"


# ------------------------------------------- the issue's paths (the benchmark's)


def _bench():
    """benchmarks/bench_process.py, whose four paths the issue measures."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).parents[2] / "benchmarks" / "bench_process.py"
    spec = importlib.util.spec_from_file_location("bench_process", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


#: What the exact search must find on each path (fixed orientation, free axis):
#: "ok", or the failure kind and the waypoint it names.
EXPECTED = {
    ("ur5", "seam"): ("ok", "ok"), ("ur5", "circle"): ("ok", "ok"),
    ("ur5", "spline"): ("ok", "ok"), ("ur5", "holes"): ("ok", "ok"),
    # the tool turns a whole turn round the tray: q6 cannot on the AUBO's +-175 deg
    ("aubo_i5", "seam"): (("jump", 216), "ok"), ("aubo_i5", "circle"): ("ok", "ok"),
    # q5 = 0 exactly at waypoint 100 with the tool as given; turning it avoids that
    ("aubo_i5", "spline"): (("singular", 100), "ok"), ("aubo_i5", "holes"): ("ok", "ok"),
}


@pytest.mark.parametrize("name", ["ur5", "aubo_i5"])
def test_the_issue_paths_get_a_valid_motion_or_the_reason(name):
    bench = _bench()
    for path, (robot, poses) in bench.paths(load(name)).items():
        step = math.inf if path == "holes" else bench.MAX_STEP
        for expect, kw in zip(EXPECTED[(name, path)], ({}, bench.FREE), strict=True):
            res = process.follow(robot, poses, max_step=step, **kw)
            if expect == "ok":
                assert_valid_motion(robot, res, poses, step)
                # naive tracking, when feasible, is one path of the same graph (the
                # fixed orientation): its objective cannot beat the optimum
                q = bench.naive(robot, poses)
                if not kw and bench.measure(robot, poses, q, max_step=step)["feasible"]:
                    mu_ref = arm_facts(robot).mu_ref
                    assert ref.objective(robot, q, mu_ref=mu_ref) >= res.cost - 1e-9
            else:
                kind, index = expect
                assert (res.failure.kind, res.failure.index) == (kind, index), res.reason


@pytest.mark.parametrize("name", ["ur5", "aubo_i5", "puma560"])
def test_the_tool_turn_by_shifting_the_last_joint_equals_ik_at_every_rotation(name):
    # oracle: the same layers built with the shortcut off (IK of every rotated
    # pose); the shortcut applies when the tool z is the last joint's axis and the
    # IK returns every solution (not the Panda's numeric IK)
    import dataclasses

    from robokin.process._graph import build_layers
    from robokin.process._inputs import tool_samples
    from robokin.process.costs import Costs
    from robokin.spatial import trans

    robot = load(name).with_tool(trans(0.0, 0.0, 0.12))
    facts = arm_facts(robot)
    off = dataclasses.replace(facts, spin=0)
    assert facts.spin != 0
    assert arm_facts(load(name).with_tool(trans(0.01, 0.0, 0.12))).spin == 0
    assert arm_facts(load("panda").with_tool(trans(0.0, 0.0, 0.12))).spin == 0
    rng = np.random.default_rng(3)
    q = rng.uniform(robot.limits[:, 0], robot.limits[:, 1], (6, robot.n))
    poses = robot.fk(q)
    samples = tool_samples("z", (-1.0, 1.0), 0.25)
    a = build_layers(facts, poses, samples, Costs())
    b = build_layers(off, poses, samples, Costs())
    assert np.array_equal(np.isfinite(a.cost), np.isfinite(b.cost))
    assert np.array_equal(a.code, b.code)
    ok = np.isfinite(a.cost)
    assert ok.sum() > 20
    np.testing.assert_allclose(a.cost[ok], b.cost[ok], rtol=1e-9, atol=1e-12)
    d = a.Q[ok] - b.Q[ok]
    np.testing.assert_allclose(np.where(facts.wraps, wrap_angle(d), d), 0.0, atol=1e-9)
