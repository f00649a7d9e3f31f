"""The compiled planning checks (robokin.planning._model, csrc/plan_*.c) against coal.

Oracles (tests/planning_oracle.py): coal's distance on every checked pair, the pairs
re-derived from the declared geometry and exclusions. States: robokin's certified
bounds equal coal's distance for primitives (to coal's 1e-6 GJK tolerance) and never
exceed it for meshes; a state is free exactly when coal's smallest distance exceeds
the margin. Edges (the conservative-advancement guarantee): every edge the kernel
calls free is free when sampled every 0.01 rad with coal, including fast motions
through thin plates and robots with prismatic and coupled joints.
"""

from __future__ import annotations

import numpy as np
import pytest

import robokin
from planning_oracle import Oracle, gripper, pose, shelf_scene
from robokin.collision import Scene
from robokin.planning._model import CollisionModel

TOL = 2e-6  # coal's default GJK tolerance is 1e-6 (robokin's closed forms are exact)


def _free_states(model, robot, rng, count, margin):
    q = rng.uniform(robot.limits[:, 0], robot.limits[:, 1], (20 * count, robot.n))
    return q[model.check_states(q, margin).free][:count]


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_distances_are_coals_for_primitives_and_lower_bounds_for_meshes(name, l_mesh):
    scene = shelf_scene()
    scene.add_mesh("L", l_mesh, pose((-0.3, -0.35, 0.25), (0.2, 0.3, 0.4)))
    robot = robokin.load(name)
    model = CollisionModel(robot, scene)
    oracle = Oracle(robot, scene)
    assert len(oracle.pairs) == model.P  # the same pairs are checked
    rng = np.random.default_rng(1)
    q = rng.uniform(robot.limits[:, 0], robot.limits[:, 1], (60, robot.n))
    q[0] = 0.0  # the zero configuration users start from
    mine = model.distances(q)
    mesh = np.array(["L" in names for names in model.names])
    for i in range(len(q)):
        ref = oracle.distances(q[i])
        apart = ref > 0  # coal reports penetration depths below 0; robokin bounds them
        assert np.all(mine[i][apart & ~mesh] >= ref[apart & ~mesh] - TOL)
        assert np.all(mine[i][apart & ~mesh] <= ref[apart & ~mesh] + TOL)
        assert np.all(mine[i][mesh] <= np.maximum(ref[mesh], 0) + TOL)  # hull: below
        assert np.all(mine[i][~apart] <= TOL)


@pytest.mark.parametrize("margin", [0.0, 0.03])
def test_a_state_is_free_exactly_when_coal_says_every_pair_is_beyond_the_margin(
        margin, l_mesh):
    scene = shelf_scene()
    scene.add_mesh("L", l_mesh, pose((-0.3, -0.35, 0.25), (0.2, 0.3, 0.4)))
    robot = robokin.load("ur5")
    model = CollisionModel(robot, scene)
    oracle = Oracle(robot, scene)
    rng = np.random.default_rng(2)
    q = rng.uniform(-np.pi, np.pi, (150, robot.n))
    rep = model.check_states(q, model.margins(margin, margin))
    ref = np.array([oracle.min_distance(x) for x in q])
    sure = np.abs(ref - margin) > TOL  # leave coal's own tolerance band out
    assert np.array_equal(rep.free[sure], ref[sure] > margin)
    assert 10 < rep.free.sum() < 140  # both answers occur
    # the pair named for a state that is not free really is that close
    for i in np.flatnonzero(~rep.free & sure)[:20]:
        assert oracle.distances(q[i])[rep.pair[i]] <= margin + TOL


def _edges_sound(robot, scene, margin, count, step, seed):
    """Edges the kernel calls free are free at 0.01 rad; returns (free, hit) counts."""
    model = CollisionModel(robot, scene)
    oracle = Oracle(robot, scene)
    m = model.margins(margin, 0.0)
    rng = np.random.default_rng(seed)
    a = _free_states(model, model.robot, rng, count, m)
    d = rng.normal(size=a.shape)
    b = np.clip(a + step * d / np.linalg.norm(d, axis=1)[:, None],
                model.robot.limits[:, 0], model.robot.limits[:, 1])
    rep = model.check_edges(a, b, m)
    for i in np.flatnonzero(rep.free):
        # self pairs keep 0; scene pairs the margin: the oracle's smallest of all
        dmin = oracle.segment_min(a[i], b[i])
        assert dmin > -TOL, (i, dmin)
        if margin > 0:
            scene_pairs = [p for p, (_, j, _) in enumerate(oracle.pairs) if j is not None]
            k = max(int(np.ceil(np.abs(b[i] - a[i]).max() / 0.01)), 1)
            worst = min(oracle.distances(a[i] + t * (b[i] - a[i]))[scene_pairs].min()
                        for t in np.linspace(0, 1, k + 1))
            assert worst > margin - TOL, (i, worst)
    return int(rep.free.sum()), int((~rep.free).sum())


def test_edges_called_free_are_free_when_sampled_densely():
    free, hit = _edges_sound(robokin.load("panda"), shelf_scene(), 0.0, 40, 0.8, 3)
    assert free > 10 and hit > 3


def test_edges_keep_the_clearance_between_samples():
    free, hit = _edges_sound(robokin.load("ur5"), shelf_scene(), 0.05, 30, 0.6, 4)
    assert free > 5 and hit > 3


def test_mesh_edges_are_sound_and_the_hull_alone_never_decides(l_mesh):
    scene = Scene("mesh")
    gripper(scene)
    scene.add_mesh("L", l_mesh, pose((0.45, 0.0, 0.35), (0.1, 0.2, 0.3)))
    free, hit = _edges_sound(robokin.load("ur5"), scene, 0.0, 30, 0.7, 5)
    assert free > 5 and hit > 0


@pytest.mark.parametrize("name", ["scara", "qfmd010", "improved_dh_arm"])
def test_prismatic_and_coupled_joints_keep_the_bound(name):
    # the SCARA's lift and the 8-joint arm's slides are prismatic (|dq| moves every
    # point by |dq|); the QFMD010's parallelogram joints depend on the others
    robot = robokin.load(name)
    scene = Scene("posts")
    reach = float(np.abs(robot.fk(np.zeros(robot.n))[:3, 3]).max()) + 0.3
    for k, ang in enumerate(np.linspace(0, 2 * np.pi, 7)[:-1]):
        c = 0.6 * reach * np.array([np.cos(ang), np.sin(ang)])
        scene.add_box(f"post_{k}", (0.06, 0.06, 3.0), pose((c[0], c[1], 0.0)))
    free, hit = _edges_sound(robot, scene, 0.0, 25, 0.8, 6)
    assert free > 3 and hit > 0


def test_a_fast_motion_through_a_thin_plate_is_caught():
    # both ends are clear of a 2 mm plate; the stretched arm sweeps through it
    robot = robokin.load("ur5")
    scene = Scene("plate")
    scene.add_box("plate", (0.7, 0.002, 1.0), pose((-0.65, 0.0, 0.0)))
    model = CollisionModel(robot, scene)
    m = model.margins(0.0, 0.0)
    a = np.zeros(6)  # q = 0: the UR5 stretched out along -x
    a[0] = -1.4
    b = a.copy()
    b[0] = 1.4  # joint 1 swings the arm across the plate (y = 0, x < -0.3)
    assert model.check_states(np.stack([a, b]), m).free.all()
    assert not model.check_edges(a, b, m).free[0]
    oracle = Oracle(robot, scene)
    assert oracle.segment_min(a, b) <= 0.0  # it really does collide


def test_a_zero_length_edge_is_the_state_check():
    robot = robokin.load("panda")
    model = CollisionModel(robot, shelf_scene())
    m = model.margins(0.0, 0.0)
    rng = np.random.default_rng(8)
    q = rng.uniform(robot.limits[:, 0], robot.limits[:, 1], (200, robot.n))
    assert np.array_equal(model.check_edges(q, q, m).free, model.check_states(q, m).free)


def test_the_robots_own_links_are_checked_and_the_exclusions_respected():
    robot = robokin.load("ur5")
    scene = Scene("empty")
    gripper(scene)
    model = CollisionModel(robot, scene)
    pairs = {frozenset(p) for p in model.names}
    assert frozenset(("base", "shoulder_lift")) not in pairs  # excluded in ur5.yaml
    assert frozenset(("shoulder_lift", "tool")) in pairs  # tool against the arm
    # folded onto itself: the gripper in the upper arm
    q = np.array([0.0, -1.0, 2.9, 0.0, 0.0, 0.0])
    oracle = Oracle(robot, scene)
    m = model.margins(0.0, 0.0)
    assert bool(model.check_states(q, m).free[0]) == (oracle.min_distance(q) > 0)
    assert not model.check_states(q, m).free[0]


def test_a_chain_of_edges_reuses_the_shared_ends_without_changing_a_verdict():
    """Edges q[i] -> q[i+1] checked in one call start from the last edge's far end.

    Oracles: each edge checked alone (its own call: nothing to reuse) gives the same
    verdict; every chained edge called free is free when sampled every 0.01 rad with
    coal; and the chained call computes fewer cheap bounds than the edges alone (the
    shared ends are not bounded again: equal counts before 2026-12-02).
    """
    robot, scene = robokin.load("panda"), shelf_scene()
    model, oracle = CollisionModel(robot, scene), Oracle(robot, scene)
    m = model.margins(0.0, 0.0)
    rng = np.random.default_rng(5)
    lo, hi = model.robot.limits[:, 0], model.robot.limits[:, 1]
    q = [_free_states(model, model.robot, rng, 1, m)[0]]
    for _ in range(24):
        d = rng.normal(size=robot.n)
        q.append(np.clip(q[-1] + 0.3 * d / np.linalg.norm(d), lo, hi))
    q = np.array(q)
    chained = model.check_edges(q[:-1], q[1:], m)
    alone = [model.check_edges(q[i:i + 1], q[i + 1:i + 2], m) for i in range(len(q) - 1)]
    np.testing.assert_array_equal(chained.free, [a.free[0] for a in alone])
    assert chained.free.sum() >= 5
    for i in np.flatnonzero(chained.free):
        assert oracle.segment_min(q[i], q[i + 1]) > -TOL, i
    assert chained.stats["bounds"] < sum(a.stats["bounds"] for a in alone)


def test_an_edge_in_collision_is_found_by_its_probes_before_its_ends_are_proven():
    """Long edges are probed coarse to fine (t = 1, 1/2, 1/4, 3/4, ...) before the proof.

    Oracles: every edge called in collision collides (coal) at the state the check
    names; every edge called free is free sampled every 0.01 rad with coal; and the
    colliding edges cost few exact distances (at most 30 each on average; 68 before
    2026-12-02, when both ends of every pair were refined before the first halving).
    """
    robot, scene = robokin.load("panda"), shelf_scene()
    model, oracle = CollisionModel(robot, scene), Oracle(robot, scene)
    m = model.margins(0.0, 0.0)
    rng = np.random.default_rng(7)
    q = _free_states(model, model.robot, rng, 120, m)
    a, b = q[0::2], q[1::2]
    rep = model.check_edges(a, b, m)
    hit = np.flatnonzero(~rep.free)
    assert 10 <= hit.size <= len(a) - 10  # both verdicts occur
    for i in hit:
        assert oracle.min_distance(a[i] + rep.where[i] * (b[i] - a[i])) <= TOL, i
    for i in np.flatnonzero(rep.free)[:4]:
        assert oracle.segment_min(a[i], b[i]) > -TOL, i
    alone = model.check_edges(a[hit], b[hit], m)
    np.testing.assert_array_equal(alone.free, False)
    assert alone.stats["exact"] <= 30 * hit.size, alone.stats
