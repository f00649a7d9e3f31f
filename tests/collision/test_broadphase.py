"""The compiled broad phase (robokin._native, broadphase.c) on its own: the
separating-axis bound against coal's exact distance, the segment distance against
a brute-force minimum, and results that do not depend on the thread count."""

import numpy as np
import pytest

import robokin
import robokin._native as native
from robokin._native import kernels as _k
from robokin.collision import Scene, check

coal = pytest.importorskip("coal")


def _rotations(rng, n):
    """Uniformly random rotation matrices (n, 3, 3)."""
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    return np.stack(
        [
            np.stack(
                [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1
            ),
            np.stack(
                [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1
            ),
            np.stack(
                [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1
            ),
        ],
        axis=1,
    )


def _about(axis, angle):
    """Rotation by ``angle`` about the unit ``axis`` (Rodrigues)."""
    K = np.array(
        [[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]]
    )
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def _shape(rng, kind):
    """(half sizes, radius, coal geometry) of a random shape of ``kind``."""
    if kind == "box":
        h = rng.uniform(0.01, 0.3, 3)
        return h, 0.0, coal.Box(*(2 * h))
    if kind == "capsule":
        r, L = rng.uniform(0.01, 0.1), rng.uniform(0.05, 0.6)
        return np.array([0.0, 0.0, L / 2]), r, coal.Capsule(r, L)
    r = rng.uniform(0.01, 0.2)
    return np.zeros(3), r, coal.Sphere(r)


def _pose(R, c):
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, c
    return T


def _bounds_and_distances(cases):
    """rounded_box_bounds of (pose_a, h_a, r_a, g_a, pose_b, h_b, r_b, g_b) cases as
    object pairs (identity frame), and coal's distances."""
    n = len(cases)
    col = list(zip(*cases))
    local, ha, ra = np.array(col[0]), np.array(col[1]), np.array(col[2], dtype=float)
    obp, hb, rb = np.array(col[4]), np.array(col[5]), np.array(col[6], dtype=float)
    idx = np.arange(n, dtype=np.int64)
    no = np.zeros(n, bool)
    out = np.full((n, 1), np.nan)
    frames = np.eye(4)[None, None].copy()
    _k.rounded_box_bounds(
        frames, np.zeros(n, np.int64), local, ha, ra, obp, hb, rb, idx, idx, no, no, out
    )
    req = coal.DistanceRequest()
    req.gjk_tolerance = 1e-10
    dist = np.empty(n)
    for i, (Ta, _, _, ga, Tb, _, _, gb) in enumerate(cases):
        ta = coal.Transform3s(Ta[:3, :3].copy(), Ta[:3, 3].copy())
        tb = coal.Transform3s(Tb[:3, :3].copy(), Tb[:3, 3].copy())
        dist[i] = coal.distance(ga, ta, gb, tb, req, coal.DistanceResult())
    return out[:, 0], dist


def test_separating_axis_bound_is_never_above_the_coal_distance(rng):
    kinds = ["box", "capsule", "sphere"]
    cases = []
    Rs = _rotations(rng, 1200)
    for i in range(1200):
        family = i % 4
        Ra = Rs[i]
        if family == 0:  # random
            Rb = _rotations(rng, 1)[0]
        elif family == 1:  # parallel, or antiparallel (turned by pi about an axis)
            Rb = Ra if i % 8 == 1 else Ra @ np.diag([-1.0, -1.0, 1.0])
        elif family == 2:  # nearly parallel: the edge-edge axes are short
            Rb = Ra @ _about(_rotations(rng, 1)[0][:, 0], 10.0 ** rng.uniform(-7, -3))
        else:  # one shared axis direction
            Rb = Ra @ _about(np.array([0.0, 0.0, 1.0]), rng.uniform(0, 2 * np.pi))
        ca = rng.uniform(-0.5, 0.5, 3)
        cb = (
            ca if i % 50 == 0 else ca + rng.normal(size=3) * rng.choice([0.1, 0.4, 1.0])
        )
        ha, ra, ga = _shape(rng, kinds[rng.integers(3)])
        hb, rb, gb = _shape(rng, kinds[rng.integers(3)])
        cases.append((_pose(Ra, ca), ha, ra, ga, _pose(Rb, cb), hb, rb, gb))
    # Segments 2e-6..1e-5 rad from parallel, side by side: here an edge-edge axis
    # decides, and its length from 1 - R_ij^2 (cancelling) overstated the gap.
    for i in range(300):
        R = Rs[i]
        tilt = _about(
            R @ np.array([np.cos(i), np.sin(i), 0.0]), 10.0 ** rng.uniform(-5.7, -5)
        )
        side = R @ np.array([np.cos(2.0 * i), np.sin(2.0 * i), 0.0])
        h, r, g = _shape(rng, "capsule")
        h2, r2, g2 = _shape(rng, "box" if i % 2 else "capsule")
        c = rng.uniform(-0.5, 0.5, 3)
        gap = rng.uniform(0.0, 0.5) + r + r2 + h2.max()
        cases.append(
            (_pose(R, c), h, r, g, _pose(tilt @ R, c + gap * side), h2, r2, g2)
        )
    bound, dist = _bounds_and_distances(cases)
    apart = dist > 0
    assert apart.sum() > 1000
    excess = bound[apart] - dist[apart]
    assert excess.max() <= 1e-9, cases[int(np.flatnonzero(apart)[np.argmax(excess)])]
    # and it is a useful bound: exact for two spheres, and mostly close
    assert np.median(dist[apart] - bound[apart]) < 0.05


def test_separating_axis_bound_of_self_pairs_places_shapes_by_their_link_frames(rng):
    # the same shapes as self pairs under random link frames: same bounds
    S = 40
    frames = np.tile(np.eye(4), (2, 3, 1, 1))
    frames[:, 1:, :3, :3] = _rotations(rng, 4).reshape(2, 2, 3, 3)
    frames[:, 1:, :3, 3] = rng.uniform(-1, 1, (2, 2, 3))
    link = rng.integers(0, 3, S).astype(np.int64)
    local = np.array([_pose(R, rng.uniform(-0.3, 0.3, 3)) for R in _rotations(rng, S)])
    h = rng.uniform(0, 0.2, (S, 3))
    r = rng.uniform(0, 0.05, S)
    pa, pb = (x.ravel().astype(np.int64) for x in np.triu_indices(S, 1))
    P = len(pa)
    out = np.full((P, 2), np.nan)
    yes, no = np.ones(P, bool), np.zeros(P, bool)
    empty = np.zeros((0, 4, 4))
    _k.rounded_box_bounds(
        frames,
        link,
        local,
        h,
        r,
        empty,
        np.zeros((0, 3)),
        np.zeros(0),
        pa,
        pb,
        yes,
        no,
        out,
    )
    world = np.ascontiguousarray(np.einsum("msab,sbc->msac", frames[:, link], local))
    for i in range(2):
        want = np.full((P, 1), np.nan)
        _k.rounded_box_bounds(
            np.eye(4)[None, None].copy(),
            np.zeros(S, np.int64),
            world[i],
            h,
            r,
            world[i],
            h,
            r,
            pa,
            pb,
            no,
            no,
            want,
        )
        np.testing.assert_allclose(out[:, i], want[:, 0], rtol=0, atol=1e-12)
    # skipped pairs are left as they were
    skip = np.arange(P) % 3 == 0
    out2 = np.full((P, 2), -7.0)
    _k.rounded_box_bounds(
        frames,
        link,
        local,
        h,
        r,
        empty,
        np.zeros((0, 3)),
        np.zeros(0),
        pa,
        pb,
        yes,
        skip,
        out2,
    )
    assert (out2[skip] == -7.0).all()
    np.testing.assert_array_equal(out2[~skip], out[~skip])


def _seg_seg(pts):
    out = np.empty(len(pts))
    _k.seg_seg(np.ascontiguousarray(pts, dtype=np.float64), out)
    return out


def test_segment_distance_matches_a_brute_force_minimum(rng):
    n = 400
    pts = rng.uniform(-1, 1, (n, 4, 3))
    d1 = pts[:, 1] - pts[:, 0]
    kind = np.arange(n) % 8
    k = kind == 1  # parallel
    pts[k, 3] = pts[k, 2] + d1[k] * rng.uniform(0.2, 2, (k.sum(), 1))
    k = kind == 2  # antiparallel
    pts[k, 3] = pts[k, 2] - d1[k] * rng.uniform(0.2, 2, (k.sum(), 1))
    k = kind == 3  # on one line, overlapping or not
    t = rng.uniform(-1.5, 1.5, (k.sum(), 2, 1))
    pts[k, 2:] = pts[k, 0][:, None] + t * d1[k][:, None]
    pts[kind == 4, 1] = pts[kind == 4, 0]  # a point and a segment
    pts[kind == 5, 3] = pts[kind == 5, 2]  # a segment and a point
    k = kind == 6  # two points
    pts[k, 1], pts[k, 3] = pts[k, 0], pts[k, 2]
    pts[kind == 7, 2:] = pts[kind == 7, 1::-1]  # the same segment, reversed
    got = _seg_seg(pts)
    K = 201
    s = np.linspace(0.0, 1.0, K)
    for i in range(n):
        p1, q1, p2, q2 = pts[i]
        a = p1 + s[:, None] * (q1 - p1)  # (K, 3)
        b = p2 + s[:, None] * (q2 - p2)
        brute = np.sqrt(((a[:, None] - b[None]) ** 2).sum(-1)).min()
        # never above a distance the segments really have; below the sampled
        # minimum by at most the grid's resolution
        res = (np.linalg.norm(q1 - p1) + np.linalg.norm(q2 - p2)) / (2 * (K - 1))
        assert got[i] <= brute + 1e-12, (kind[i], pts[i])
        assert got[i] >= brute - res - 1e-12, (kind[i], pts[i])
    np.testing.assert_array_equal(got[kind == 7], 0.0)
    k = kind == 6
    np.testing.assert_allclose(
        got[k], np.linalg.norm(pts[k, 0] - pts[k, 2], axis=1), atol=1e-15
    )


def test_segment_distance_closed_forms():
    z = [0.0, 0.0, 0.0]
    cases = [
        ([z, [1, 0, 0], [0, 1, 0], [1, 1, 0]], 1.0),  # parallel, side by side
        ([z, [1, 0, 0], [1, 1, 0], [0, 1, 0]], 1.0),  # antiparallel
        ([z, [1, 0, 0], [2, 0, 0], [3, 0, 0]], 1.0),  # collinear, apart
        ([z, [1, 0, 0], [0.5, 0, 0], [3, 0, 0]], 0.0),  # collinear, overlapping
        ([z, [2, 0, 0], [1, -1, 0], [1, 1, 0]], 0.0),  # crossing
        ([z, [2, 0, 0], [1, -1, 1], [1, 1, 1]], 1.0),  # skew, over each other
        ([z, [1, 0, 0], [2, 0, 0], [2, 3, 0]], 1.0),  # end to end, perpendicular
        ([z, z, [3, 4, 0], [3, 4, 0]], 5.0),  # two points
        ([[1, 1, 0], [1, 1, 0], [0, 0, 0], [2, 0, 0]], 1.0),  # a point over a segment
        ([z, [1, 0, 0], [1 + 3e-9, 2, 0], [1 + 1e-9, -2, 0]], 2e-9),  # nearly touching
    ]
    got = _seg_seg(np.array([c for c, _ in cases]))
    np.testing.assert_allclose(got, [d for _, d in cases], rtol=1e-6, atol=1e-15)


def test_results_do_not_depend_on_the_thread_count(rng):
    r = robokin.load("aubo_i5")
    sc = Scene()
    sc.add_box("wall", (0.05, 1.0, 1.0), _pose(np.eye(3), (0.55, 0.0, 0.5)))
    sc.add_cylinder("post", 0.05, 1.0, _pose(np.eye(3), (-0.3, 0.4, 0.5)))
    sc.add_sphere("ball", 0.1, _pose(np.eye(3), (0.2, -0.5, 0.3)))
    q0, q1 = rng.uniform(-2, 2, (2, 6))
    q = q0 + np.linspace(0, 1, 3000)[:, None] * (q1 - q0)
    before = native.num_threads()
    runs = []
    try:
        for k in (1, 2):
            native.set_num_threads(k)
            rep = check(r, sc, q, clearance=0.01)
            pr = rep._problem
            fr = pr.frames(q)
            an = np.flatnonzero(pr.analytic)
            runs.append(
                (
                    pr.lower_bounds(fr),
                    pr.motion(q, fr),
                    pr.analytic_distances(fr, an),
                    rep.min_distance,
                    rep.queries,
                    rep.collisions,
                )
            )
    finally:
        native.set_num_threads(before)
    assert native.num_threads() == before
    (b1, m1, c1, *rest1), (b2, m2, c2, *rest2) = runs
    assert len(an) and b1.shape[1] == 3000
    np.testing.assert_array_equal(b1, b2)
    np.testing.assert_array_equal(m1, m2)
    np.testing.assert_array_equal(c1, c2)
    assert rest1 == rest2


def test_kernels_reject_inconsistent_arguments():
    frames = np.tile(np.eye(4), (2, 3, 1, 1))
    link = np.array([0, 3], dtype=np.int64)  # frame 3 does not exist
    pair = np.array([0], dtype=np.int64)
    out = np.zeros((1, 2))
    args = (
        frames,
        link,
        np.tile(np.eye(4), (2, 1, 1)),
        np.zeros((2, 3)),
        np.zeros(2),
        np.zeros((0, 4, 4)),
        np.zeros((0, 3)),
        np.zeros(0),
        pair,
        pair + 1,
        np.ones(1, bool),
        np.zeros(1, bool),
        out,
    )
    with pytest.raises(ValueError, match="rounded_box_bounds"):
        _k.rounded_box_bounds(*args)
    with pytest.raises(ValueError, match="is_self"):
        _k.rounded_box_bounds(*args[:10], np.ones(1, np.int64), *args[11:])
    with pytest.raises(ValueError, match="seg_seg"):
        _k.seg_seg(np.zeros((3, 4, 2)), np.zeros(3))
