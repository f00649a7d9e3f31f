"""Link and tool shapes: construction, bounding volumes, meshes, retooling."""

import math

import numpy as np
import pytest

import robokin
from robokin.exceptions import InputError
from robokin.model import geometry as geo


def _surface_points(shape, rng, n=400):
    """Random points on the shape's surface, in its parent frame."""
    m = shape.trimesh()
    pts, _ = __import__("trimesh").sample.sample_surface(
        m, n, seed=int(rng.integers(1 << 30))
    )
    P = shape.placement
    return np.asarray(pts) @ P[:3, :3].T + P[:3, 3]


def test_capsule_between_places_the_axis_on_the_end_points():
    s = geo.capsule_between([0.1, 0.2, 0.3], [0.5, -0.1, 0.3], 0.05)
    half = s.size[1] / 2
    P = s.placement
    ends = [P[:3, 3] - half * P[:3, 2], P[:3, 3] + half * P[:3, 2]]
    assert s.size[1] == pytest.approx(0.5)  # |(0.4, -0.3, 0)|
    np.testing.assert_allclose(ends[0], [0.1, 0.2, 0.3], atol=1e-12)
    np.testing.assert_allclose(ends[1], [0.5, -0.1, 0.3], atol=1e-12)
    np.testing.assert_allclose(P[:3, :3] @ P[:3, :3].T, np.eye(3), atol=1e-12)


@pytest.mark.parametrize(
    "shape",
    [
        geo.box((0.3, 0.05, 0.1)),
        geo.capsule(0.04, 0.5),
        geo.cylinder(0.06, 0.2),
        geo.sphere(0.07),
        geo.capsule_between([0, 0, 0], [0.2, 0.1, 0.0], 0.03),
    ],
    ids=["box", "capsule", "cylinder", "sphere", "capsule_between"],
)
def test_bounding_spheres_cover_the_surface(shape, rng):
    pts = _surface_points(shape, rng)
    c, r = shape.bounding_spheres()
    # every surface point lies in at least one sphere
    d = np.linalg.norm(pts[:, None, :] - c[None], axis=-1) - r[None]
    assert d.min(axis=1).max() <= 1e-9


def test_shape_validation_names_the_argument():
    with pytest.raises(InputError, match="needs 3 sizes"):
        geo.Shape("box", (1.0, 2.0))
    with pytest.raises(InputError, match="positive radius"):
        geo.capsule(0.0, 1.0)
    with pytest.raises(InputError, match="expected one of"):
        geo.Shape("cone", ())


@pytest.mark.parametrize("name", robokin.robots.names())
def test_every_builtin_arm_carries_geometry_clear_of_itself_at_a_safe_pose(name):
    from robokin.collision import Scene, check

    r = robokin.load(name)
    g = r.geometry
    assert isinstance(g, geo.RobotGeometry)
    assert (
        sum(len(s) for s in g.shapes) >= r.n_chain
    )  # something on (nearly) every link
    for pair in g.exclude:
        assert all(n in g.names for n in pair)
    q = np.clip(np.zeros(r.n), r.limits[:, 0], r.limits[:, 1])
    rep = check(r, Scene(), q[None])
    assert not rep.collides, rep.collisions


def test_retool_reexpresses_shapes_in_the_new_tool_frame():
    r = robokin.load("ur5")
    tcp = np.eye(4)
    tcp[2, 3] = 0.15
    g = r.geometry.retool(tcp, [geo.box((0.05, 0.05, 0.1), _t(0, 0, 0.05))])
    (b,) = g.tool
    # the box centred 5 cm beyond the mount is 10 cm behind the new TCP
    np.testing.assert_allclose(b.placement[:3, 3], [0, 0, -0.10], atol=1e-12)
    assert math.isclose(b.size[2], 0.1)


def _t(x, y, z):
    T = np.eye(4)
    T[:3, 3] = (x, y, z)
    return T
