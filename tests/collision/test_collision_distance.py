"""Distances between known shapes: closed forms, meshes vs primitives, the bounds."""

import math

import numpy as np
import pytest

import robokin
from robokin.collision import Scene, check
from robokin.model import geometry as geo
from robokin.model.geometry import RobotGeometry

pytest.importorskip("coal")


def T(x=0.0, y=0.0, z=0.0, R=None):
    out = np.eye(4)
    out[:3, 3] = (x, y, z)
    if R is not None:
        out[:3, :3] = R
    return out


def Rz(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


def gantry(shapes):
    """An x-y-z gantry (three prismatic joints) carrying ``shapes`` on its last link."""
    r = robokin.Robot.from_elementary(
        [
            {"op": "tx", "joint": "prismatic", "name": "x"},
            {"op": "ty", "joint": "prismatic", "name": "y"},
            {"op": "tz", "joint": "prismatic", "name": "z"},
        ]
    )
    return r.replace(geometry=RobotGeometry.from_mapping(r, {"z": shapes}))


def test_sphere_to_box_face_edge_and_corner_closed_form():
    r = gantry([geo.sphere(0.1)])
    sc = Scene()
    sc.add_box("block", size=(0.4, 0.6, 0.2), pose=T(1.0, 0.0, 0.0))  # x 0.8..1.2
    q = np.array(
        [
            [0.5, 0.0, 0.0],  # in front of the x face
            [0.5, 0.5, 0.0],  # beyond the x-y edge
            [0.5, 0.5, 0.3],  # beyond a corner
            [1.0, 0.0, 0.15],  # overlapping the top face by 0.05
        ]
    )
    want = [
        0.8 - 0.5 - 0.1,
        math.hypot(0.3, 0.2) - 0.1,
        math.sqrt(0.3**2 + 0.2**2 + 0.2**2) - 0.1,
        -0.05,
    ]
    rep = check(r, sc, q, subdivide=False)
    got = rep.distances("z", "block")
    np.testing.assert_allclose(got, want, atol=1e-9)
    assert rep.min_distance == pytest.approx(-0.05, abs=1e-9)
    assert rep.collisions == [(3, 3, "z", "block")]


def test_capsule_pairs_use_the_segment_distance():
    # a vertical capsule on the gantry against a horizontal capsule along y
    cap = geo.capsule(0.05, 0.4)  # axis z from -0.2 to 0.2
    r = gantry([cap])
    sc = Scene()
    sc.add_capsule(
        "bar",
        0.03,
        1.0,
        pose=T(0.0, 0.0, 0.5, R=np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0.0]])),
    )  # axis along y at z = 0.5
    zs = np.array([0.0, 0.1, 0.25, 0.4])
    q = np.column_stack([np.full(4, 0.3), np.zeros(4), zs])
    rep = check(r, sc, q, subdivide=False)
    # segment (0.3, 0, z-0.2..z+0.2) vs line (0, y, 0.5): dx = 0.3, dz = max(0.5 - (z+0.2), 0)
    want = [math.hypot(0.3, max(0.5 - (z + 0.2), 0.0)) - 0.08 for z in zs]
    np.testing.assert_allclose(rep.distances("z", "bar"), want, atol=1e-12)
    assert rep.queries == 0  # closed form, no coal query needed


def test_mesh_box_and_primitive_box_agree(tmp_path, rng):
    import trimesh

    stl = tmp_path / "block.stl"
    trimesh.creation.box(extents=(300.0, 200.0, 100.0)).export(stl)  # in mm
    pose = T(0.7, -0.1, 0.2, R=Rz(0.4))
    prim, mesh = Scene(), Scene()
    prim.add_box("block", size=(0.3, 0.2, 0.1), pose=pose)
    mesh.add_mesh("block", stl, pose=pose, units="mm")
    r = gantry(
        [geo.capsule(0.04, 0.3, T(R=np.array([[0, 0, 1], [0, 1, 0], [-1, 0, 0.0]])))]
    )
    q = rng.uniform([0.0, -0.6, -0.3], [1.4, 0.4, 0.6], size=(60, 3))
    a = check(r, prim, q, subdivide=False).distances("z", "block")
    b = check(r, mesh, q, subdivide=False).distances("z", "block")
    outside = a > 1e-6
    assert outside.sum() > 30
    np.testing.assert_allclose(b[outside], a[outside], atol=1e-6)
    # both agree on which samples touch (the mesh reports 0 inside, not a depth)
    np.testing.assert_array_equal(a <= 0, b <= 0)


def test_rounded_box_bounds_never_exceed_the_coal_distance(rng):
    import coal

    from robokin._native import kernels as _k
    from robokin.spatial import matrix_from_rpy

    kinds = [
        ("box", (0.3, 0.1, 0.2)),
        ("capsule", (0.05, 0.4)),
        ("sphere", (0.08,)),
        ("cylinder", (0.06, 0.3)),
    ]
    shapes, poses = [], []
    for _ in range(40):
        k, size = kinds[rng.integers(len(kinds))]
        P = matrix_from_rpy(rng.uniform(-np.pi, np.pi, 3))
        P[:3, 3] = rng.uniform(-0.4, 0.4, 3)
        shapes.append(geo.Shape(k, size, P))
        poses.append(P)
    # objects: the same shapes again, placed in the world
    robot_like = shapes[:20]
    objects = shapes[20:]

    def rb(sh):
        Tl = np.array(sh.placement)
        if sh.kind == "capsule":
            return Tl, np.array([0, 0, sh.size[1] / 2]), sh.size[0]
        if sh.kind == "sphere":
            return Tl, np.zeros(3), sh.size[0]
        c, h = sh.local_box()
        Tl[:3, 3] += Tl[:3, :3] @ c
        return Tl, np.array(h), 0.0

    A = [rb(s) for s in robot_like]
    B = [rb(s) for s in objects]
    frames = np.broadcast_to(np.eye(4), (1, 1, 4, 4)).copy()
    P = len(A) * len(B)
    pa = np.repeat(np.arange(len(A)), len(B))
    pb = np.tile(np.arange(len(B)), len(A))
    out = np.empty((P, 1))
    _k.rounded_box_bounds(
        frames,
        np.zeros(len(A), dtype=np.int64),
        np.array([x[0] for x in A]),
        np.array([x[1] for x in A]),
        np.array([x[2] for x in A]),
        np.array([x[0] for x in B]),
        np.array([x[1] for x in B]),
        np.array([x[2] for x in B]),
        pa.astype(np.int64),
        pb.astype(np.int64),
        np.zeros(P, bool),
        np.zeros(P, bool),
        out,
    )
    req = coal.DistanceRequest()
    for p in range(P):
        sa, sb = robot_like[pa[p]], objects[pb[p]]
        ta = coal.Transform3s(sa.placement[:3, :3].copy(), sa.placement[:3, 3].copy())
        tb = coal.Transform3s(sb.placement[:3, :3].copy(), sb.placement[:3, 3].copy())
        d = coal.distance(
            sa.coal_geometry(), ta, sb.coal_geometry(), tb, req, coal.DistanceResult()
        )
        if d > 0:
            assert out[p, 0] <= d + 1e-9, (sa, sb, out[p, 0], d)


def test_capsule_kernel_matches_coal_on_random_segments(rng):
    import coal

    from robokin._native import kernels as _k

    def seg_seg(p1, q1, p2, q2):
        out = np.empty(1)
        _k.seg_seg(np.array([[p1, q1, p2, q2]]), out)
        return out[0]

    req = coal.DistanceRequest()
    for _ in range(200):
        p1, q1, p2, q2 = rng.uniform(-1, 1, (4, 3))
        if rng.random() < 0.2:
            q1 = p1.copy()  # a point
        if rng.random() < 0.1:
            q2 = p2 + 1e-3 * (q1 - p1)  # nearly parallel, short
        a = (
            geo.capsule_between(p1, q1, 0.01)
            if np.any(p1 != q1)
            else geo.sphere(0.01, T(*p1))
        )
        b = geo.capsule_between(p2, q2, 0.01)
        ta = coal.Transform3s(a.placement[:3, :3].copy(), a.placement[:3, 3].copy())
        tb = coal.Transform3s(b.placement[:3, :3].copy(), b.placement[:3, 3].copy())
        d = coal.distance(
            a.coal_geometry(), ta, b.coal_geometry(), tb, req, coal.DistanceResult()
        )
        assert seg_seg(p1, q1, p2, q2) - 0.02 == pytest.approx(d, abs=1e-9)


def test_nearest_points_are_on_the_bodies_and_as_far_apart_as_the_minimum():
    r = gantry([geo.box((0.1, 0.1, 0.1))])
    sc = Scene()
    sc.add_cylinder("post", radius=0.05, length=1.0, pose=T(0.5, 0.0, 0.0))
    q = np.array([[0.0, 0.0, 0.0], [0.2, 0.0, 0.0], [0.1, 0.0, 0.0]])
    rep = check(r, sc, q, subdivide=False)
    c = rep.closest
    assert (c.index, c.body_a, c.body_b) == (1, "z", "post")
    assert c.distance == pytest.approx(0.5 - 0.05 - 0.25, abs=1e-9)
    np.testing.assert_allclose(c.point_a, [0.25, c.point_a[1], c.point_a[2]], atol=1e-9)
    assert np.linalg.norm(c.point_b - c.point_a) == pytest.approx(c.distance, abs=1e-9)


def test_closest_at_gives_the_closest_pair_and_its_points_in_closed_form():
    # sphere r = 0.1 on the gantry; a box (x 0.8..1.2, y -0.3..0.3, z -0.1..0.1)
    # and a ball r = 0.2 at (0, 1, 0): the closest body changes with the sample.
    r = gantry([geo.sphere(0.1)])
    sc = Scene()
    sc.add_box("block", size=(0.4, 0.6, 0.2), pose=T(1.0, 0.0, 0.0))
    sc.add_sphere("ball", 0.2, pose=T(0.0, 1.0, 0.0))
    p = np.array([[0.5, 0.0, 0.0], [0.0, 0.6, 0.0], [0.5, 0.5, 0.3]])
    rep = check(r, sc, p, subdivide=False)
    corner = np.array([0.8, 0.3, 0.1])
    u = (corner - p[2]) / np.linalg.norm(corner - p[2])
    want_d = [0.8 - 0.5 - 0.1, 0.4 - 0.1 - 0.2, math.sqrt(0.17) - 0.1]
    want_a = [[0.6, 0.0, 0.0], [0.0, 0.7, 0.0], p[2] + 0.1 * u]
    want_b = [[0.8, 0.0, 0.0], [0.0, 0.8, 0.0], corner]
    d, pa, pb = rep.closest_at([0, 1, 2])
    assert d.shape == (3,) and pa.shape == (3, 3) and pb.shape == (3, 3)
    np.testing.assert_allclose(d, want_d, atol=1e-9)
    np.testing.assert_allclose(pa, want_a, atol=1e-7)
    np.testing.assert_allclose(pb, want_b, atol=1e-7)
    # any order, repeats and negative indices
    d2, pa2, _ = rep.closest_at(np.array([-1, 1, 1]))
    np.testing.assert_allclose(d2, [want_d[2], want_d[1], want_d[1]], atol=1e-9)
    np.testing.assert_allclose(pa2[0], want_a[2], atol=1e-7)
    with pytest.raises(robokin.InputError, match="indices"):
        rep.closest_at([3])
    with pytest.raises(robokin.InputError, match="integer"):
        rep.closest_at([0.5])


def test_closest_at_with_nothing_to_check_is_inf_and_nan():
    rep = check(gantry([geo.sphere(0.1)]), Scene(), np.zeros((2, 3)))
    d, pa, pb = rep.closest_at([0, 1])
    assert np.isinf(d).all() and np.isnan(pa).all() and np.isnan(pb).all()
