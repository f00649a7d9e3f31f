"""The chain's screw geometry helpers (``kinematics/ik/analytic/_geometry.py``).

Oracles: numpy for ``cross3``, which must give ``np.cross``'s bits (the closed forms'
set-up packs its results into kernel parameters, so a different rounding would move
solutions), on the values set-ups meet: unit axes, zeros, signed zeros, huge and tiny
components. For the Paden-Kahan subproblems (issue 24: one Python copy, used by the
SCARA and palletizer solvers) the defining equations, evaluated with an independent
rotation (scipy's rotvec): ``p . R(h, v) q = d`` for subproblem 4, ``|a + R(h, v) b| = |d|``
for 3, and ``R(h, v) u`` parallel to ``d`` (in the plane normal to ``h``) for 1; at special
angles (0, +-pi/2, pi) and on the edge of reach (disc = 0).
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from robokin.kinematics.ik.analytic._geometry import (
    angle_between_axes,
    cross3,
    rotate_about,
    subproblem_1,
    subproblem_3,
    subproblem_4,
)

SPECIAL = [0.0, -0.0, 1.0, -1.0, 0.5, np.sqrt(0.5), 1e-9, -1e-9, 1e-150, 1e150,
           np.pi, -np.pi / 2, 2.0**-1074]
component = st.one_of(st.sampled_from(SPECIAL),
                      st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False))
vector = st.lists(component, min_size=3, max_size=3).map(np.array)


@settings(max_examples=100, deadline=None)
@given(vector, vector)
def test_cross3_gives_numpys_bits(a, b):
    got, want = cross3(a, b), np.cross(a, b)
    assert got.dtype == want.dtype and got.shape == (3,)
    assert got.tobytes() == want.tobytes()  # bit for bit, signed zeros included


def test_cross3_on_the_axes_of_every_built_in_arm():
    import robokin
    from robokin.kinematics.ik.analytic._geometry import poe_from_chain
    from robokin.robots import names

    for name in names():
        h = poe_from_chain(robokin.load(name).chain).h
        for i in range(len(h)):
            for j in range(len(h)):
                assert cross3(h[i], h[j]).tobytes() == np.cross(h[i], h[j]).tobytes()
    # and the angle it gives: x and y axes are pi/2 apart, an axis and its reverse 0
    assert angle_between_axes(np.array([1.0, 0, 0]), np.array([0, 1.0, 0])) == np.pi / 2
    assert angle_between_axes(np.array([0, 0, 1.0]), np.array([0, 0, -1.0])) == 0.0



SPECIAL_ANGLES = [0.0, np.pi / 2, -np.pi / 2, np.pi, 0.3, -2.0]


def _R(h, v):
    return Rotation.from_rotvec(np.asarray(v)[..., None] * h).as_matrix()


def _unit(x):
    return x / np.linalg.norm(x)


@pytest.mark.parametrize("v", SPECIAL_ANGLES)
def test_subproblem_4_roots_satisfy_the_equation(v):
    rng = np.random.default_rng(4)
    h = _unit(rng.normal(size=3))
    p, q = rng.normal(size=(5, 3)), rng.normal(size=3)
    d = p @ (_R(h, v) @ q)  # reachable by construction: v is a root
    roots, disc, r2 = subproblem_4(h, p, q, d)
    assert roots.shape == (5, 2) and np.all(disc >= -1e-12 * r2)
    for k in range(2):
        got = np.einsum("ni,nij,j->n", p, _R(h, roots[:, k]), q)
        np.testing.assert_allclose(got, d, atol=1e-12)
    # the generating angle is one of the two roots
    wrap = np.angle(np.exp(1j * (roots - v)))
    assert np.all(np.abs(wrap).min(axis=-1) < 1e-7)


def test_subproblem_4_reports_out_of_reach_and_the_edge():
    h, p, q = np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0]), np.array([1.0, 0.0, 0.0])
    _, disc, r2 = subproblem_4(h, p, q, 1.5)  # |p . R q| <= 1
    assert disc < 0 and r2 == 1.0
    roots, disc, _ = subproblem_4(h, p, q, 1.0)  # the edge: one double root, v = 0
    assert disc == 0.0 and np.all(roots == 0.0)


@pytest.mark.parametrize("v", SPECIAL_ANGLES)
def test_subproblem_3_roots_reach_the_distance(v):
    rng = np.random.default_rng(3)
    h = _unit(rng.normal(size=3))
    a, b = rng.normal(size=3), rng.normal(size=3)
    d = a + _R(h, v) @ b
    roots, disc, _ = subproblem_3(h, a, b, d)
    for r in roots:
        assert np.linalg.norm(a + _R(h, r) @ b) == pytest.approx(np.linalg.norm(d), abs=1e-12)
    assert min(abs(np.angle(np.exp(1j * (roots - v))))) < 1e-7


@pytest.mark.parametrize("v", SPECIAL_ANGLES)
def test_subproblem_1_and_rotate_about(v):
    rng = np.random.default_rng(1)
    h = _unit(rng.normal(size=3))
    u = rng.normal(size=3)
    np.testing.assert_allclose(rotate_about(h, np.array(v), u), _R(h, v) @ u, atol=1e-14)
    d = 2.5 * (_R(h, v) @ u)  # the same direction, scaled
    assert abs(np.angle(np.exp(1j * (subproblem_1(h, u, d) - v)))) < 1e-12
