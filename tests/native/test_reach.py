"""The fused reach-map kernel (csrc/reach.c, ``six_r_reach``): counts and best w per voxel.

Oracles: the solution set of ``robot.ik`` (its within-limits rows counted per
target) and ``|det J|`` of ``robot.jacobian`` by LAPACK (numpy.linalg.det) on
those rows, maximised per voxel; and, bit for bit, the path the map took before
(``robot.ik`` then ``cell._evaluate.manipulability``).
"""

import numpy as np
import pytest

import robokin
from robokin._native import kernels
from robokin.cell._evaluate import manipulability
from robokin.kinematics.ik.analytic.detect import SixRSolver, detect

SPECIAL = np.array([0.0, np.pi / 2, -np.pi / 2, np.pi, -np.pi, 1e-9, np.pi / 2 + 1e-9])


def targets(robot, rng, G, K):
    """FK of random and special configurations (0, +-pi/2, pi, 1e-9 from singular),
    plus random poses mostly out of reach, grouped (G, K, 4, 4)."""
    n = G * K
    q = rng.uniform(-np.pi, np.pi, (n, 6))
    special = rng.random((n, 6)) < 0.5
    q[special] = rng.choice(SPECIAL, special.sum())
    T = np.array(robot.fk(q))
    far = rng.random(n) < 0.25
    T[far, :3, 3] = rng.uniform(-1.2, 1.2, (far.sum(), 3))
    return np.ascontiguousarray(T.reshape(G, K, 4, 4))


@pytest.mark.parametrize("name", ["ur5", "puma560", "aubo_i5"])
def test_counts_and_best_w_match_the_solution_set_and_lapack(name):
    robot = robokin.load(name)
    solver = detect(robot.arm).solver
    assert isinstance(solver, SixRSolver) and not solver.near
    rng = np.random.default_rng(7)
    G, K = 300, 5
    T = targets(robot, rng, G, K)
    counts = np.empty((G, K), np.uint8)
    best = np.full(G, np.nan)
    kernels.six_r_reach(solver.params, T, robot.chain.arrays.packed, True, counts, best)

    sols = robot.ik(T.reshape(-1, 4, 4), method="analytic")
    ok = sols.within_limits
    assert np.array_equal(counts.ravel(), ok.sum(axis=-1))
    # independent w: LAPACK's determinant of the geometric Jacobian
    w = np.zeros(ok.shape)
    w[ok] = np.abs(np.linalg.det(robot.jacobian(sols.q[ok])))
    expect = w.reshape(G, -1).max(axis=-1)
    assert np.allclose(best, expect, rtol=1e-9, atol=1e-12)
    assert (best[counts.sum(axis=1) == 0] == 0).all()
    # and bit for bit what the map computed before (ik, then the manipulability kernel)
    before = manipulability(robot.chain, sols.q, ok).reshape(G, -1).max(axis=-1)
    assert np.array_equal(best, before)
    # the count is the same without w
    again = np.empty((G, K), np.uint8)
    kernels.six_r_reach(solver.params, T, robot.chain.arrays.packed, False, again,
                        np.empty(G))
    assert np.array_equal(again, counts)


def test_a_chain_that_is_not_6r_is_refused():
    ur5 = robokin.load("ur5")
    panda = robokin.load("panda")
    params = detect(ur5.arm).solver.params
    with pytest.raises(ValueError, match="packed is not a 6R chain"):
        kernels.six_r_reach(params, np.zeros((1, 1, 4, 4)), panda.chain.arrays.packed,
                            True, np.empty((1, 1), np.uint8), np.empty(1))
