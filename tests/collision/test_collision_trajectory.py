"""Whole trajectories: collision intervals, subdivision between samples, self-collision,
agreement with a brute-force loop of coal queries."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

import robokin
from robokin.collision import Scene, check
from robokin.exceptions import InputError
from robokin.io.robot_files import parts_from_document
from robokin.model import geometry as geo
from robokin.model.geometry import RobotGeometry

coal = pytest.importorskip("coal")


def T(x=0.0, y=0.0, z=0.0):
    out = np.eye(4)
    out[:3, 3] = (x, y, z)
    return out


def gantry(shapes):
    r = robokin.Robot.from_elementary(
        [
            {"op": "tx", "joint": "prismatic", "name": "x"},
            {"op": "ty", "joint": "prismatic", "name": "y"},
        ]
    )
    return r.replace(geometry=RobotGeometry.from_mapping(r, {"y": shapes}))


def test_passing_through_a_box_collides_in_the_right_interval():
    r = gantry([geo.sphere(0.05)])
    sc = Scene()
    sc.add_box("block", size=(0.3, 0.2, 0.2), pose=T(0.755, 0.0, 0.0))  # x 0.605..0.905
    x = np.linspace(0.0, 1.5, 151)  # 0.01 steps
    q = np.column_stack([x, np.zeros_like(x)])
    t = 0.02 * np.arange(151)
    rep = check(r, sc, q, t=t)
    # touching when x + 0.05 >= 0.605 and x - 0.05 <= 0.905: x in [0.555, 0.955]
    assert rep.collides
    assert rep.collisions == [(56, 95, "y", "block")]
    (iv,) = rep.intervals
    assert (iv.t_start, iv.t_end) == pytest.approx((1.12, 1.90))
    assert not iv.between_samples
    # deepest at x = 0.75 / 0.76: the centre is 0.1 m inside the y faces, r = 0.05
    assert iv.min_distance == pytest.approx(-0.15, abs=1e-9)
    assert rep.min_distance == pytest.approx(-0.15, abs=1e-9)


def test_a_fast_jump_over_a_thin_plate_is_caught_by_subdivision():
    r = gantry([geo.sphere(0.02)])
    sc = Scene()
    sc.add_box("plate", size=(0.002, 0.5, 0.5), pose=T(0.5, 0.0, 0.0))
    q = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.3]])  # one step straight through it
    coarse = check(r, sc, q, subdivide=False)
    assert not coarse.collides
    assert coarse.min_distance == pytest.approx(0.499 - 0.02, abs=1e-9)
    rep = check(r, sc, q)
    assert rep.collides
    assert rep.collisions == [(0, 1, "y", "plate")]
    (iv,) = rep.intervals
    assert iv.between_samples and 0.0 < iv.t_start < 1.0
    # the configuration found lies inside the plate's reach
    x_hit = iv.t_start  # t defaults to the sample index, linear in x here
    assert abs(x_hit - 0.5) <= 0.001 + 0.02
    assert rep.min_distance <= 0.0 and rep.closest.between_samples
    assert rep.sample_min_distance == pytest.approx(coarse.min_distance)


def test_a_fast_revolute_sweep_through_a_thin_plate_is_caught():
    # one revolute link 0.5 m long sweeping +-0.6 rad in a single step
    r = robokin.Robot.from_dh([{"a": 0.5, "alpha": 0.0, "d": 0.0, "theta": 0.0}])
    r = r.replace(
        geometry=RobotGeometry.from_mapping(
            r, {"joint1": [geo.capsule_between([-0.5, 0, 0], [0, 0, 0], 0.01)]}
        )
    )
    sc = Scene()
    sc.add_box("plate", size=(0.2, 0.003, 0.2), pose=T(0.4, 0.0, 0.0))  # on the x axis
    q = np.array([[-0.6], [0.6]])
    assert not check(r, sc, q, subdivide=False).collides
    rep = check(r, sc, q)
    assert rep.collisions == [(0, 1, "joint1", "plate")]


def test_clearance_violations_are_reported_and_exact():
    r = gantry([geo.sphere(0.05)])
    sc = Scene()
    sc.add_box(
        "wall", size=(0.1, 1.0, 1.0), pose=T(1.003, 0.0, 0.0)
    )  # face at x = 0.953
    x = np.linspace(0.0, 0.9, 91)
    q = np.column_stack([x, np.zeros_like(x)])
    rep = check(r, sc, q, clearance=0.004)
    assert not rep.collides
    assert rep.min_distance == pytest.approx(0.953 - 0.9 - 0.05, abs=1e-9)
    # distance <= 4 mm when x >= 0.899: sample 90 only (3 mm); sample 89 is at 13 mm
    assert [(v.first_index, v.last_index) for v in rep.violations] == [(90, 90)]


def _planar_3r(exclude=None):
    doc = {
        "name": "planar",
        "units": {"length": "m", "angle": "rad"},
        "joints": [
            {"name": "j1", "a": 0.4},
            {"name": "j2", "a": 0.4},
            {"name": "j3", "a": 0.3},
        ],
        "geometry": {
            "j1": [
                {
                    "type": "capsule",
                    "radius": 0.03,
                    "from": [-0.4, 0, 0],
                    "to": [0, 0, 0],
                }
            ],
            "j2": [
                {
                    "type": "capsule",
                    "radius": 0.03,
                    "from": [-0.4, 0, 0],
                    "to": [0, 0, 0],
                }
            ],
            "j3": [
                {
                    "type": "capsule",
                    "radius": 0.03,
                    "from": [-0.3, 0, 0],
                    "to": [0, 0, 0],
                }
            ],
        },
    }
    if exclude is not None:
        doc["collision"] = {"exclude": exclude}
    return robokin.Robot.from_parts(parts_from_document(doc))


def test_self_collision_of_non_adjacent_links_and_exclusions():
    q = np.array([[0.0, 0.0, 0.0], [0.0, 2.8, 2.8]])  # stretched, then folded back
    r = _planar_3r()
    rep = check(r, Scene(), q)
    assert rep.collisions == [(1, 1, "j1", "j3")]
    kinds = {(p.body_a, p.body_b): p.kind for p in rep.pairs}
    assert kinds == {("j1", "j3"): "self"}  # adjacent pairs are never checked
    # stretched: the closest points are the ends of links 1 and 3, 0.4 m apart
    assert rep.distances("j1", "j3")[0] == pytest.approx(0.4 - 0.06, abs=1e-12)
    excluded = _planar_3r(exclude=[["j1", "j3"]])
    rep2 = check(excluded, Scene(), q)
    assert not rep2.collides and rep2.pairs == []
    assert check(r, Scene(), q, self_collision=False).pairs == []


def test_trajectory_objects_and_times_are_accepted():
    r = gantry([geo.sphere(0.05)])
    sc = Scene()
    sc.add_sphere("ball", 0.05, pose=T(0.5, 0.3, 0.0))
    x = np.linspace(0.0, 1.0, 11)
    tr = SimpleNamespace(
        t=np.linspace(0.0, 2.0, 11), q=np.column_stack([x, np.zeros(11)])
    )
    rep = check(r, sc, tr)
    assert rep.closest.index == 5 and rep.closest.t == pytest.approx(1.0)
    assert rep.min_distance == pytest.approx(0.3 - 0.1, abs=1e-12)
    np.testing.assert_allclose(rep.t, tr.t)


def test_bad_inputs_raise_input_errors():
    r = gantry([geo.sphere(0.05)])
    sc = Scene()
    with pytest.raises(InputError, match=r"expected shape \(m, 2\)"):
        check(r, sc, np.zeros((4, 3)))
    with pytest.raises(InputError, match="non-finite"):
        check(r, sc, np.array([[0.0, np.nan]]))
    with pytest.raises(InputError, match="clearance"):
        check(r, sc, np.zeros((2, 2)), clearance=-1.0)
    with pytest.raises(InputError, match="times"):
        check(r, sc, np.zeros((2, 2)), t=[0.0])


def _brute_force(problem, q):
    """Every pair at every sample, one coal.distance call each."""
    frames = problem.frames(q)
    req = coal.DistanceRequest()
    req.gjk_tolerance = 1e-9  # as robokin's queries (coal's default is 1e-6)
    D = np.empty((problem.P, q.shape[0]))
    for i in range(q.shape[0]):
        for p in range(problem.P):
            ga, gb = problem.geoms[p]
            Wa = frames[i, problem.link[problem.pa[p]]] @ problem.place[problem.pa[p]]
            ta = coal.Transform3s(Wa[:3, :3].copy(), Wa[:3, 3].copy())
            if problem.is_self[p]:
                b = problem.pb[p]
                Wb = frames[i, problem.link[b]] @ problem.place[b]
            else:
                Wb = problem.objects[problem.pb[p]].pose
            tb = coal.Transform3s(Wb[:3, :3].copy(), Wb[:3, 3].copy())
            D[p, i] = coal.distance(ga, ta, gb, tb, req, coal.DistanceResult())
    return D


def test_agrees_with_a_brute_force_loop_on_the_aubo(rng):
    r = robokin.load("aubo_i5")
    sc = Scene()
    sc.add_box("wall", (0.05, 1.0, 1.0), T(0.55, 0.0, 0.5))
    sc.add_box("table", (0.4, 0.4, 0.05), T(0.0, 0.5, 0.3))
    sc.add_cylinder("post", 0.05, 1.0, T(-0.4, -0.3, 0.5))
    sc.set_tool([geo.box((0.06, 0.08, 0.1), T(0, 0, 0.05))], T(0, 0, 0.12))
    m = 240
    s = np.linspace(0.0, 1.0, m)[:, None]
    q0, q1 = rng.uniform(-1.5, 1.5, (2, 6))
    q = q0 + (q1 - q0) * s + 0.3 * np.sin(7 * s)
    rep = check(r, sc, q, clearance=0.01)
    D = _brute_force(rep._problem, q)
    assert rep.min_distance == pytest.approx(D.min(), abs=1e-9)
    groups = rep._problem._groups()
    for pm in rep.pairs:
        ref = D[groups[(pm.body_a, pm.body_b)]].min(axis=0)
        assert pm.distance >= ref.min() - 1e-9
        assert pm.distance <= ref.min() + max(1e-3, 0.01 * abs(ref.min())) + 1e-9
        assert ref[pm.index] == pytest.approx(pm.distance, abs=1e-9)
    # collision intervals: the runs of the brute-force per-pair minimum <= 0
    want = []
    for (a, b), plist in groups.items():
        mask = D[plist].min(axis=0) <= 0
        edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(int), [0]])))
        want += [
            (int(s0), int(e0) - 1, a, b) for s0, e0 in zip(edges[::2], edges[1::2])
        ]
    got = [
        c
        for c in rep.collisions
        if not any(
            iv.between_samples and (iv.first_index, iv.last_index) == (c[0], c[1])
            for iv in rep.intervals
        )
    ]
    assert sorted(got) == sorted(want)
    assert rep.collides == bool(want) or any(iv.between_samples for iv in rep.intervals)
    assert rep.queries < D.size / 4  # the bounds spared most of the queries
    exact = check(r, sc, q, clearance=0.01, pair_tolerance=0.0, pair_rtol=0.0)
    for pm in exact.pairs:
        ref = D[groups[(pm.body_a, pm.body_b)]].min()
        assert pm.distance == pytest.approx(ref, abs=1e-9)


@pytest.mark.parametrize("name", ["ur5", "scara", "improved_dh_arm"])
def test_motion_bounds_hold_between_samples(rng, name):
    """|d(t) - d(t_i)| never exceeds the motion bound over the interval.

    The SCARA's lift and the improved-DH arm's slides are prismatic joints (the
    SCARA's driven through its coupling), whose travel lengthens the reach.
    """
    r = robokin.load(name)
    sc = Scene()
    sc.add_box("box", (0.3, 0.3, 0.3), T(0.4, 0.2, 0.3))
    lo, hi = r.chain.arrays.seed_lower, r.chain.arrays.seed_upper
    q0 = rng.uniform(lo, hi)
    q = q0 + np.linspace(0, 1, 21)[:, None] * 0.2 * rng.uniform(-1, 1, r.n) * (hi - lo)
    rep = check(r, sc, q)
    pr = rep._problem
    M = pr.motion(q, pr.frames(q))
    fine = q[0] + np.linspace(0, 1, 401)[:, None] * (q[-1] - q[0])
    D = _brute_force(pr, fine)
    Dc = D[:, ::20]  # the samples
    for i in range(20):
        seg = D[:, 20 * i : 20 * i + 21]
        assert np.all(np.abs(seg - Dc[:, i : i + 1]) <= M[:, i : i + 1] + 1e-9)
    assert math.isfinite(rep.min_distance)


def test_motion_bounds_count_the_travel_of_a_slide_after_a_turn():
    """A slide extending 1 m while the joint before it turns: the lever of the
    turn is the slide's travel, not the arm's constant lengths (0 here)."""
    r = robokin.Robot.from_elementary(
        [
            {"op": "rz", "joint": "revolute", "name": "turn"},
            {"op": "tx", "joint": "prismatic", "name": "slide"},
        ]
    )
    r = r.replace(geometry=RobotGeometry.from_mapping(r, {"slide": [geo.sphere(0.05)]}))
    sc = Scene()
    sc.add_box("box", (0.2, 0.2, 0.2), T(0.6, 0.9, 0.0))
    q = np.column_stack([np.linspace(0.0, 0.8, 5), np.linspace(0.2, 1.0, 5)])
    rep = check(r, sc, q)
    pr = rep._problem
    M = pr.motion(q, pr.frames(q))
    fine = q[0] + np.linspace(0, 1, 401)[:, None] * (q[-1] - q[0])
    D = _brute_force(pr, fine)[0]
    for i in range(4):
        seg = D[100 * i : 100 * i + 101]
        assert np.all(np.abs(seg - seg[0]) <= M[0, i] + 1e-9)


def test_non_convex_mesh_links_are_exact_through_the_hull_bound(tmp_path, rng):
    import trimesh

    # an L-shaped part: its convex hull fills the corner the part itself leaves open
    a = trimesh.creation.box(extents=(0.4, 0.1, 0.1))
    a.apply_translation((0.15, 0.0, 0.0))
    b = trimesh.creation.box(extents=(0.1, 0.4, 0.1))
    b.apply_translation((0.0, 0.15, 0.0))
    path = tmp_path / "ell.stl"
    trimesh.util.concatenate([a, b]).export(path)
    r = gantry([geo.mesh(path, owner="y")])
    sc = Scene()
    sc.add_sphere("ball", 0.03, pose=T(0.2, 0.2, 0.0))  # sits in the L's open corner
    x = np.linspace(-0.3, 0.3, 61)
    q = np.column_stack([x, 0.5 * x])
    rep = check(r, sc, q)
    D = _brute_force(rep._problem, q)
    assert rep.min_distance == pytest.approx(D.min(), abs=1e-9)
    assert rep.collides == bool((D <= 0).any())
    hull = rep._problem.exact(0, rep._problem.frames(q)[30], hull=True)
    assert hull < D[0, 30] - 0.05  # the hull bound really is looser here


def test_subdivision_never_misses_what_dense_sampling_finds(rng):
    """Two clear samples with contact in between: subdivision always reports it."""
    r = robokin.load("ur5")
    sc = Scene()
    sc.add_box("plate", (0.01, 1.2, 1.2), T(0.35, 0.0, 0.3))
    sc.add_box("slab", (1.5, 1.5, 0.01), T(0.0, 0.0, 0.0))
    sc.add_cylinder("pole", 0.02, 1.0, T(-0.3, 0.35, 0.5))
    for link in ("base", "shoulder_pan"):
        sc.exclude_pair(link, "slab")
    between = clear = 0
    for _ in range(150):
        q0 = rng.uniform(-2.0, 2.0, 6)
        q1 = q0 + rng.uniform(-2.0, 2.0, 6)
        ends = np.stack([q0, q1])
        if check(r, sc, ends, self_collision=False, subdivide=False).collides:
            continue  # only motions whose samples are both clear
        dense = q0 + np.linspace(0.0, 1.0, 400)[:, None] * (q1 - q0)
        touched = check(r, sc, dense, self_collision=False, subdivide=False).collides
        rep = check(r, sc, ends, self_collision=False)
        if touched:
            between += 1
            assert rep.collides and all(iv.between_samples for iv in rep.intervals)
        elif not rep.collides:
            clear += 1
    assert between >= 3 and clear >= 3  # both outcomes were exercised


def test_a_robot_without_any_shapes_is_an_error_not_a_clear_report():
    r = gantry([geo.sphere(0.05)]).replace(geometry=None)
    sc = Scene()
    sc.add_box("block", size=(0.2, 0.2, 0.2))  # the robot's origin is inside it
    with pytest.raises(InputError, match="no collision geometry"):
        check(r, sc, np.zeros((2, 2)))
