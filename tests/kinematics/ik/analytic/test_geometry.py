"""The chain's screw geometry helpers (``kinematics/ik/analytic/_geometry.py``).

Oracle: numpy. ``cross3`` must give ``np.cross``'s bits (the closed forms' set-up
packs its results into kernel parameters, so a different rounding would move
solutions), on the values set-ups meet: unit axes, zeros, signed zeros, huge and
tiny components.
"""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from robokin.kinematics.ik.analytic._geometry import angle_between_axes, cross3

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
