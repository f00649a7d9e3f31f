"""Paden subproblem 4: the lane form (six_r.c ``lsp4``) and the scalar form
(subproblems.h ``sp4_roots``) share one formula and must agree.

Oracle: each other (same root count, same roots to 1e-14), and the equation
itself: A cos t + B sin t = rhs at every returned root where disc >= 0.
"""

from __future__ import annotations

import numpy as np

from robokin._native import kernels as K


def _rows(rng: np.random.Generator) -> np.ndarray:
    """Rows [A, B, rhs, disc, phi, cos phi, sin phi]: random and special values."""
    special = np.array([0.0, 1.0, -1.0, 0.5, -0.5, 1e-9, -1e-9, 2.0])
    A = np.concatenate([rng.normal(size=300), rng.choice(special, 200)])
    B = np.concatenate([rng.normal(size=300), rng.choice(special, 200)])
    r = np.hypot(A, B)
    # rhs: inside, at (double root), 1e-12 beyond, and well beyond the circle
    scale = np.concatenate([rng.uniform(-1, 1, 300),
                            rng.choice([1.0, -1.0, 1 + 1e-12, -1 - 1e-12, 1.5, 0.0], 200)])
    rhs = scale * r
    disc = A * A + B * B - rhs * rhs
    phi = np.arctan2(B, A)
    return np.column_stack([A, B, rhs, disc, phi, np.cos(phi), np.sin(phi)])


def test_lane_and_scalar_subproblem_4_agree():
    rng = np.random.default_rng(4)
    x = _rows(rng)
    for tol in (0.0, 1e-13, 1e-9):
        for mirror in (False, True):
            lane, one = np.empty((len(x), 8)), np.empty((len(x), 8))
            K.sp4_pair(x, tol, mirror, lane, one)
            np.testing.assert_array_equal(lane[:, 6:], one[:, 6:])  # root counts
            has = one[:, 6] == 1.0
            assert has.any() and (~has).any()  # both cases drawn
            np.testing.assert_allclose(lane[has, 0], one[has, 0], atol=1e-14, rtol=0)
            two = one[:, 7] == 1.0
            np.testing.assert_allclose(lane[two, :6], one[two, :6], atol=1e-14, rtol=0)
            np.testing.assert_allclose(lane[has][:, [2, 4]], one[has][:, [2, 4]], atol=1e-14,
                                       rtol=0)
            real = has & (x[:, 3] >= 0.0)
            for i in (0, 1):
                t = one[real, i]
                A, B, rhs = x[real, 0], x[real, 1], x[real, 2]
                scale = np.maximum(np.hypot(A, B), 1.0)
                assert np.all(np.abs(A * np.cos(t) + B * np.sin(t) - rhs) <= 1e-12 * scale)
                # A = B = 0 (every t solves 0 = 0) aside, (c, s) is (cos t, sin t)
                ok = np.hypot(A, B) > 0.0
                np.testing.assert_allclose(one[real, 2 + i][ok], np.cos(t[ok]), atol=1e-14)
                np.testing.assert_allclose(one[real, 4 + i][ok], np.sin(t[ok]), atol=1e-14)
