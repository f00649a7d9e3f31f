"""Planning queries (robokin.planning.planner): paths re-checked independently.

Oracle: every returned path is sampled every 0.01 rad (largest joint step) and each
sample checked with coal on every checked pair (tests/planning_oracle.py); the path
starts at the start and ends at a goal (for a pose: FK of the end is the pose, and
it is one of the IK solutions). Determinism: the same seed gives the same bits.
Failures carry the reason the brief names (start in collision with the pair, goals
unreachable or in collision, time limit).
"""

from __future__ import annotations

import numpy as np
import pytest

import robokin
from planning_oracle import Oracle, gripper, pose, shelf_scene
from robokin import planning
from robokin.collision import Scene
from robokin.exceptions import InputError

# UR5 configurations around the shelf (tests/planning_oracle.py: shelf_scene): HOME
# upright, INSIDE and INSIDE_2 two IK branches with the gripper in the middle cell
# (TCP at (0.72, 0, 0.57), tool along +x), BAD the arm through the lowest board
HOME = np.array([0.0, -1.57, 0.0, -1.57, 0.0, 0.0])
INSIDE = np.array([2.92, -1.253, 0.799, 0.453, 1.35, -1.571])
INSIDE_2 = np.array([2.92, -1.347, 1.419, 3.07, -1.35, 1.571])
BAD = np.array([np.pi, 0.0, 0.0, 0.0, 0.0, 0.0])
# The time limit of a query that must succeed: far above what it takes (well under a
# second here), so a slow or loaded machine cannot fail it. The planner stops as soon
# as it has a path, so this costs nothing; the default (1 s) failed on a CI machine.
AMPLE = 30.0


@pytest.fixture(scope="module")
def ur5_shelf():
    robot = robokin.load("ur5")
    scene = shelf_scene()
    return planning.Planner(robot, scene), Oracle(robot, scene)


def _ends(pl, rng, k):
    """k (start, goal) pairs of free configurations whose straight edge collides."""
    lo, hi = np.maximum(pl.limits[:, 0], -np.pi), np.minimum(pl.limits[:, 1], np.pi)
    q = rng.uniform(lo, hi, (3000, pl.n))
    q = q[pl.is_free(q)]
    a, b = q[: len(q) // 2], q[len(q) // 2: 2 * (len(q) // 2)]
    blocked = ~pl.edges_free(a, b)
    return list(zip(a[blocked][:k], b[blocked][:k]))


def test_the_problem_ends_are_as_described(ur5_shelf):
    pl, oracle = ur5_shelf
    for q in (HOME, INSIDE, INSIDE_2):
        assert oracle.min_distance(q) > 0.02
    assert oracle.min_distance(BAD) < 0.0
    tcp = pl.robot.fk(INSIDE)[:3, 3]
    np.testing.assert_allclose(tcp, [0.72, 0.0, 0.57], atol=2e-3)
    assert not pl.edges_free(HOME, INSIDE)[0]  # the straight move hits the shelf


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_every_returned_path_is_free_when_sampled_densely(name):
    robot = robokin.load(name)
    scene = shelf_scene()
    pl = planning.Planner(robot, scene)
    oracle = Oracle(robot, scene)
    rng = np.random.default_rng(11)
    problems = _ends(pl, rng, 4)
    assert len(problems) == 4
    for i, (a, b) in enumerate(problems):
        res = pl.plan(a, b, seed=i, time_limit=AMPLE)
        assert res.success, res.reason
        assert np.array_equal(res.q[0], a) and np.array_equal(res.q[-1], b)
        assert oracle.path_min(res.q) > 0.0
        # the planner's own path, too
        assert oracle.path_min(res.raw, step=0.02) > 0.0
        assert res.length <= np.linalg.norm(np.diff(res.raw, axis=0), axis=1).sum() + 1e-9


def test_the_same_seed_gives_the_same_bits_and_another_seed_may_not(ur5_shelf):
    pl, _ = ur5_shelf
    a = pl.plan(HOME, INSIDE, seed=7, time_limit=AMPLE)
    b = pl.plan(HOME.copy(), INSIDE.copy(), seed=7, time_limit=AMPLE)
    assert a.success and np.array_equal(a.q, b.q) and np.array_equal(a.raw, b.raw)
    others = [pl.plan(HOME, INSIDE, seed=s, time_limit=AMPLE).raw for s in range(8, 12)]
    assert any(o.shape != a.raw.shape or not np.array_equal(o, a.raw) for o in others)
    # a fresh planner (built again from the same inputs) agrees too
    again = planning.plan(robokin.load("ur5"), shelf_scene(), HOME, INSIDE, seed=7,
                          time_limit=AMPLE)
    assert np.array_equal(again.q, a.q)


def test_a_goal_set_ends_at_one_of_its_free_goals(ur5_shelf):
    pl, oracle = ur5_shelf
    goals = np.stack([BAD, INSIDE, INSIDE_2])
    res = pl.plan(HOME, goals, seed=3, time_limit=AMPLE)
    assert res.success
    assert res.goal_index in (1, 2)  # never the colliding one
    assert np.array_equal(res.q[-1], goals[res.goal_index])
    assert np.array_equal(res.goal, goals[res.goal_index])
    assert oracle.path_min(res.q) > 0.0


def test_a_pose_goal_ends_at_an_ik_solution_and_uses_every_branch(ur5_shelf):
    pl, oracle = ur5_shelf
    T = pl.robot.fk(INSIDE)
    res = pl.plan(HOME, T, seed=1, time_limit=AMPLE)
    assert res.success, res.reason
    np.testing.assert_allclose(pl.robot.fk(res.q[-1]), T, atol=1e-9)
    sols = pl.robot.ik(T).keep_within_limits()
    # every in-limit IK solution, each 2*pi-equivalent of the UR5's +-360 deg joints
    assert res.goals.shape[0] == len(sols.expand_turns())
    assert res.goals.shape[0] > 8
    assert any(np.allclose(res.q[-1], g) for g in res.goals)
    assert oracle.path_min(res.q) > 0.0


def test_a_start_in_collision_names_the_pair(ur5_shelf):
    pl, _ = ur5_shelf
    bad = BAD
    res = pl.plan(bad, INSIDE)
    assert not res.success and res.q.shape == (0, 6)
    assert res.reason.startswith("the start is in collision: ")
    a, b = res.reason.split(": ", 1)[1].split(" collides with ")
    oracle = Oracle(robokin.load("ur5"), shelf_scene())
    d = oracle.distances(bad)
    named = [p for p, (i, j, o) in enumerate(oracle.pairs)
             if {pl.model.robot.geometry.names[oracle.shapes[i][0]],
                 oracle.objects[j].name if j is not None
                 else pl.model.robot.geometry.names[oracle.shapes[o][0]]}
             == {a.strip("'"), b.strip("'")}]
    assert named and min(d[named]) <= 0.0  # that pair really collides


def test_goals_in_collision_unreachable_poses_and_limits_are_reasons(ur5_shelf):
    pl, _ = ur5_shelf
    bad = BAD
    res = pl.plan(HOME, bad)
    assert not res.success and res.reason.startswith("the goal is in collision: '")
    res = pl.plan(HOME, np.stack([bad, bad]))
    assert res.reason.startswith("every goal (2) is in collision")
    far = pose((3.0, 0.0, 0.5))
    res = pl.plan(HOME, far)
    assert not res.success and "unreachable" in res.reason
    outside = HOME.copy()
    outside[0] = 7.0
    res = pl.plan(outside, INSIDE)
    assert not res.success and "joint 1" in res.reason and "limit" in res.reason
    res = pl.plan(HOME, outside)
    assert not res.success and "outside the joint limits" in res.reason
    res = pl.plan(HOME, INSIDE, clearance=0.5)  # no configuration keeps 0.5 m
    assert not res.success and "within the clearance" in res.reason


def test_an_enclosed_goal_ends_at_the_time_limit():
    # the gripper sits in a closed box; only the wrist passes through a hole in its
    # floor, too small for the gripper: the goal is free and no path leads to it
    robot = robokin.load("ur5")
    scene = Scene("box with a hole")
    gripper(scene)
    goal = np.array([0.5, -1.2, 1.2, -1.57, -1.57, 0.0])
    F = robot.fk(goal)  # the flange, before the scene's tool
    walls = [((0.24, 0.01, 0.23), (0.0, 0.115, 0.085)),
             ((0.24, 0.01, 0.23), (0.0, -0.115, 0.085)),
             ((0.01, 0.24, 0.23), (0.115, 0.0, 0.085)),
             ((0.01, 0.24, 0.23), (-0.115, 0.0, 0.085)),
             ((0.24, 0.24, 0.01), (0.0, 0.0, 0.195)),
             # the floor at z = -0.025 around a 0.095 m square hole
             ((0.24, 0.0725, 0.01), (0.0, 0.08375, -0.025)),
             ((0.24, 0.0725, 0.01), (0.0, -0.08375, -0.025)),
             ((0.0725, 0.095, 0.01), (0.08375, 0.0, -0.025)),
             ((0.0725, 0.095, 0.01), (-0.08375, 0.0, -0.025))]
    for k, (size, xyz) in enumerate(walls):
        scene.add_box(f"wall_{k}", size, F @ pose(xyz))
    pl = planning.Planner(robot, scene)
    assert pl.is_free(goal) and pl.is_free(HOME)
    res = pl.plan(HOME, goal, time_limit=0.2)
    assert not res.success
    assert res.reason.startswith("no path found before the time limit (0.2 s)")
    assert 0.2 <= res.time < 5.0  # it stopped at the limit (loaded machines: slack)


def test_the_time_limit_counts_the_goals_ik_and_checks(ur5_shelf):
    # a pose goal a small step from HOME (the straight edge to its own branch is
    # free, so a search would solve it at once): with a 1e-7 s limit the IK and the
    # checks of every goal alone take longer, and the query says so instead of
    # searching on a fresh clock; with an ample limit it is solved
    pl, oracle = ur5_shelf
    near = HOME + np.array([0.05, 0.05, -0.05, 0.05, 0.05, 0.05])
    assert pl.edges_free(HOME[None], near[None])[0]
    T = pl.robot.fk(near)
    res = pl.plan(HOME, T, time_limit=1e-7)
    assert not res.success
    assert res.reason == ("no path found before the time limit (1e-07 s): the goals "
                          "and their checks took it")
    assert res.goals.shape[0] > 8  # every branch was still computed
    res = pl.plan(HOME, T, time_limit=AMPLE)
    assert res.success, res.reason
    np.testing.assert_allclose(pl.robot.fk(res.q[-1]), T, atol=1e-9)
    assert oracle.path_min(res.q) > 0.0


def test_the_clearance_is_kept_along_the_whole_path(ur5_shelf):
    pl, oracle = ur5_shelf
    front = pose((0.4, 0.0, 0.57), (0.0, np.pi / 2, 0.0))  # in front of the cell
    res = pl.plan(HOME, front, clearance=0.03, seed=2, time_limit=AMPLE)
    assert res.success, res.reason
    scene_pairs = [p for p, (_, j, _) in enumerate(oracle.pairs) if j is not None]
    for a, b in zip(res.q[:-1], res.q[1:]):
        for t in np.linspace(0, 1, 25):
            assert oracle.distances(a + t * (b - a))[scene_pairs].min() > 0.03 - 2e-6


def test_bad_arguments_are_named(ur5_shelf):
    pl, _ = ur5_shelf
    with pytest.raises(InputError, match="planner.*planners: .*ompl:RRTstar"):
        pl.plan(HOME, INSIDE, planner="rrtstar")
    with pytest.raises(InputError, match="'start'"):
        pl.plan(HOME[:5], INSIDE)
    with pytest.raises(InputError, match="'goal'.*shape"):
        pl.plan(HOME, INSIDE[:4])
    with pytest.raises(InputError, match="'start'.*non-finite"):
        pl.plan(np.full(6, np.nan), INSIDE)
    with pytest.raises(InputError, match="'time_limit'"):
        pl.plan(HOME, INSIDE, time_limit=0.0)
    with pytest.raises(InputError, match="'clearance'"):
        pl.plan(HOME, INSIDE, clearance=-0.01)
    with pytest.raises(InputError, match="'seed'"):
        pl.plan(HOME, INSIDE, seed=-1)
    with pytest.raises(InputError, match="'goal'"):
        pl.plan(HOME, np.eye(4) * 2)  # not a rigid transform


@pytest.mark.parametrize("name", ["ompl:RRTConnect", "ompl:RRTstar"])
def test_ompl_planners_run_on_the_same_checks(ur5_shelf, name):
    pytest.importorskip("ompl")
    pl, oracle = ur5_shelf
    if name.endswith("Connect"):  # into the shelf; it stops at its first path
        goal, limit = INSIDE, AMPLE
    else:  # RRT* (one tree, anytime: it runs its whole time) to a pose in front of it
        T = pose((0.4, 0.0, 0.57), (0.0, np.pi / 2, 0.0))
        g = planning.goal_configurations(pl.robot, T).q
        goal, limit = g[np.argmin(np.linalg.norm(g - HOME, axis=1))], 2.0
    res = pl.plan(HOME, goal, planner=name, time_limit=limit)
    assert res.success, res.reason
    assert res.planner == name
    assert np.array_equal(res.q[0], HOME) and np.array_equal(res.q[-1], goal)
    assert oracle.path_min(res.q) > 0.0
    assert res.stats["edges"] > 0


def test_planning_around_a_mesh_asks_coal(l_mesh):
    robot = robokin.load("panda")
    scene = Scene("mesh")
    gripper(scene)
    scene.add_mesh("L", l_mesh, pose((0.45, 0.0, 0.35), (0.1, 0.2, 0.3)))
    pl = planning.Planner(robot, scene)
    oracle = Oracle(robot, scene)
    rng = np.random.default_rng(5)
    (a, b), = _ends(pl, rng, 1)
    res = pl.plan(a, b, seed=0, time_limit=AMPLE)
    assert res.success, res.reason
    assert res.stats["coal_calls"] > 0  # the hull did not clear it: coal decided
    assert oracle.path_min(res.q) > 0.0


def test_the_trajectory_is_time_optimal_checked_and_within_the_limits(ur5_shelf):
    pl, oracle = ur5_shelf
    res = pl.plan(HOME, INSIDE, seed=4, retime=True, time_limit=AMPLE)
    tr = res.trajectory
    assert tr is not None
    np.testing.assert_allclose(tr.q[0], HOME, atol=1e-9)
    np.testing.assert_allclose(tr.q[-1], INSIDE, atol=1e-9)
    assert pl.edges_free(tr.q[:-1], tr.q[1:]).all()
    assert tr.check_limits(pl.robot).ok
    for q in tr.q[::5]:
        assert oracle.min_distance(q) > 0.0
    # at least one joint runs at a limit somewhere (time-optimal)
    v = pl.robot.rate_limits.get("velocity")
    a = pl.robot.rate_limits.get("acceleration")
    peak = max((np.abs(tr.qd) / v).max(), (np.abs(tr.qdd) / a).max())
    assert peak > 0.95
    with pytest.raises(InputError, match="nothing to retime"):
        pl.trajectory(pl.plan(HOME, BAD))


def test_result_arrays_are_read_only_and_the_summary_reads(ur5_shelf):
    pl, _ = ur5_shelf
    res = pl.plan(HOME, INSIDE, seed=4, time_limit=AMPLE)
    assert bool(res) and "success=True" in repr(res)
    with pytest.raises(ValueError):
        res.q[0, 0] = 1.0
    assert res.stats["edges"] >= 1 and res.stats["states"] >= 2
    fail = pl.plan(HOME, BAD)
    assert not fail and "success=False" in repr(fail) and fail.length == 0.0


def _elbow_ring(robot, T):
    """Balls along the elbow's circle of the pose's self-motion but for one free arc.

    The held-q7 IK at five q7 values (closed form: the same on every kernel copy) puts
    the elbow (frame 4's origin) on a ball; the manifold sample farthest from all of
    those keeps its elbow 0.16 m from every ball. Returns the scene, those
    configurations, the free one and ``robot.ik``'s own in-limit solutions (numeric:
    where its LM lands differs between the kernels' copies at the rounding floor; on
    the AVX2 copy all six collide, on the baseline copy one of seven lies in the free
    arc).
    """
    from robokin.kinematics.forward import link_frames

    sm = robot.self_motion(T)
    q = sm.sample(np.linspace(*sm.domain, 2001), within_limits=True).reshape(-1, robot.n)
    q = q[np.isfinite(q).all(axis=1)]
    elbow = link_frames(robot.chain, q)[:, 4, :3, 3]
    held = np.vstack([np.asarray(robot.ik(T, fixed={"joint7": v}).keep_within_limits()
                                 .solutions()).reshape(-1, robot.n)
                      for v in np.linspace(0.15, 1.45, 5)])
    own = np.asarray(robot.ik(T).keep_within_limits().solutions()).reshape(-1, robot.n)
    near = link_frames(robot.chain, held)[:, 4, :3, 3]
    w = int(np.argmax(np.linalg.norm(elbow[:, None] - near[None], axis=-1).min(axis=1)))
    scene = Scene("elbow ring")
    balls: list[np.ndarray] = []
    for e in elbow[np.linalg.norm(elbow - elbow[w], axis=1) > 0.16]:
        if not balls or np.linalg.norm(np.array(balls) - e, axis=1).min() > 0.02:
            balls.append(e)
            scene.add_sphere(f"ball_{len(balls)}", 0.02, pose(e))
    return scene, held, q[w], own


def test_a_seven_joint_pose_goal_reaches_the_free_part_of_its_self_motion():
    # the Panda's pose T: the elbow's circle of its self-motion is lined with balls
    # but for one arc; every configuration of the held-q7 IK at five q7 values
    # collides, and so does every solution robot.ik returns on the AVX2 copy (so the
    # old goals, robot.ik's, were all in collision and the query failed; the baseline
    # copy's LM lands one of them in the free arc: _elbow_ring). Oracle: coal
    # (tests/planning_oracle.py) says those collide and the free arc's sample is free;
    # the path ends at a configuration whose FK is T (to 1e-9), none of the colliding
    # ones, and is free sampled every 0.01 rad.
    robot = robokin.load("panda")
    T = robot.fk(np.array([0.0, 0.3, 0.0, -1.8, 0.0, 2.1, 0.8]))
    scene, held, free, own = _elbow_ring(robot, T)
    oracle = Oracle(robot, scene)
    assert len(held) >= 5 and all(oracle.min_distance(b) < 0.0 for b in held)
    hit = [b for b in own if oracle.min_distance(b) < 0.0]
    assert len(hit) >= len(own) - 1  # (every one on the AVX2 copy)
    blocked = np.vstack([held] + hit)
    assert oracle.min_distance(free) > 0.05
    start = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])
    pl = planning.Planner(robot, scene)
    res = pl.plan(start, T, time_limit=AMPLE)
    assert res.success, res.reason
    np.testing.assert_allclose(robot.fk(res.q[-1]), T, atol=1e-9)
    assert np.array_equal(res.q[-1], res.goals[res.goal_index])
    assert np.abs(blocked - res.q[-1]).max(axis=1).min() > 1e-3  # none of the old goals
    assert oracle.path_min(res.q) > 0.0
