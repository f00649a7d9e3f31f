"""robokin._native manipulability.c: |det J| of a 6-coordinate arm, in compiled code.

The oracle is the product of the Jacobian's singular values (``numpy.linalg.svd``
of :func:`robokin.kinematics.jacobian.jacobian`, i.e. ``method="svd"``), on every
built-in 6-coordinate arm, at random configurations, at the values users hit (0,
+-pi/2, pi, the limits), 1e-9 from a singularity, and at singular configurations
found without the kernel (sign changes of numpy's signed determinant, bisected).
"To rounding" means relative to the largest singular values: a perturbation of J
of eps |J| moves det J by about eps * s1 * (s1 s2 s3 s4 s5).
"""

from __future__ import annotations

import numpy as np
import pytest

import robokin
from reference import kernel_copies, random_q
from robokin import _native
from robokin.exceptions import InputError
from robokin.kinematics.jacobian import jacobian, manipulability

SIX = [name for name in robokin.robots.names() if robokin.load(name).n == 6]
ROUNDING = 1e-14  # times s1 * s1 s2 s3 s4 s5 (the kernel's worst seen: 5e-16)


def _svd(robot, q):
    """(product of singular values, rounding scale s1 * prod(s1..s5)) per row."""
    s = np.linalg.svd(jacobian(robot.chain, q), compute_uv=False)
    return np.prod(s, axis=-1), s[..., 0] * np.prod(s[..., :5], axis=-1)


def _assert_rounding(robot, q, w):
    ref, scale = _svd(robot, q)
    bad = np.abs(w - ref) > ROUNDING * scale
    assert not bad.any(), (q[bad][:3], w[bad][:3], ref[bad][:3])


def _special_q(robot, rng, count):
    """Random rows whose joints are often 0, +-pi/2, pi or a limit."""
    q = random_q(robot, rng, count)
    lim = robot.limits
    for j in range(robot.n):
        pick = rng.random(count)
        lo, hi = lim[j]
        values = [0.0, np.pi / 2, -np.pi / 2, np.pi, -np.pi, lo, hi]
        values = [v for v in values if lo <= v <= hi]
        take = pick < 0.4
        q[take, j] = rng.choice(values, int(take.sum()))
    return q


def _singular_q(robot, rng, count):
    """Configurations where det J = 0: numpy's signed det changes sign along one
    joint between grid points; bisected to the last bit (no kernel involved)."""
    out = []
    while len(out) < count:
        q0 = random_q(robot, rng)
        j = int(rng.integers(0, 6))
        lo, hi = np.clip(robot.limits[j], -np.pi, np.pi)
        grid = np.linspace(lo, hi, 49)
        Q = np.repeat(q0[None], grid.size, axis=0)
        Q[:, j] = grid
        d = np.linalg.det(jacobian(robot.chain, Q))
        for i in np.flatnonzero(np.sign(d[:-1]) * np.sign(d[1:]) < 0):
            a, b, da = grid[i], grid[i + 1], d[i]
            for _ in range(80):
                m = 0.5 * (a + b)
                qm = q0.copy()
                qm[j] = m
                dm = np.linalg.det(jacobian(robot.chain, qm))
                if np.sign(dm) == np.sign(da):
                    a, da = m, dm
                else:
                    b = m
            qs = q0.copy()
            qs[j] = 0.5 * (a + b)
            out.append(qs)
    return np.array(out[:count])


@pytest.mark.parametrize("name", SIX)
def test_the_determinant_is_the_svd_product_to_rounding(name, rng):
    robot = robokin.load(name)
    q = np.concatenate([random_q(robot, rng, 3000), _special_q(robot, rng, 3000)])
    w = manipulability(robot.chain, q, method="det")
    _assert_rounding(robot, q, w)
    assert (w > 0).mean() > 0.95  # not a vacuous comparison of zeros


@pytest.mark.parametrize("name", SIX)
def test_singular_configurations_give_zero_to_rounding(name, rng):
    robot = robokin.load(name)
    q = _singular_q(robot, rng, 40)
    ref, scale = _svd(robot, q)
    assert (ref <= 1e-12 * scale).all()  # the oracle agrees they are singular
    w = manipulability(robot.chain, q, method="det")
    _assert_rounding(robot, q, w)
    assert (w <= 2 * ROUNDING * scale).all()
    # 1e-9 away (along the joint that crossed): w grows linearly, to rounding still
    q_near = q + 1e-9 * np.eye(6)[rng.integers(0, 6, len(q))]
    _assert_rounding(robot, q_near, manipulability(robot.chain, q_near, method="det"))


@pytest.mark.parametrize("name", SIX)
def test_the_wrist_singularity_and_a_hair_from_it(name, rng):
    robot = robokin.load(name)
    q = random_q(robot, rng, 200)
    q[:, 4] = 0.0  # joint 5 at 0: axes 4 and 6 line up on every built-in 6R arm
    _assert_rounding(robot, q, manipulability(robot.chain, q, method="det"))
    for eps in (1e-9, -1e-9, 1e-6):
        q[:, 4] = eps
        w = manipulability(robot.chain, q, method="det")
        _assert_rounding(robot, q, w)
        assert (w > 0).all()


def test_unmasked_rows_are_zero_and_never_read(rng):
    ur5 = robokin.load("ur5")
    q = random_q(ur5, rng, (50, 8))
    ok = rng.random((50, 8)) < 0.6
    q[~ok] = np.nan  # an IK solution set's filler rows
    w = manipulability(ur5.chain, q, method="det", where=ok)
    assert w.shape == (50, 8) and (w[~ok] == 0).all() and (w[ok] > 0).all()
    np.testing.assert_array_equal(w[ok], manipulability(ur5.chain, q[ok], method="det"))
    q[ok.nonzero()[0][0], ok.nonzero()[1][0], 2] = np.inf
    with pytest.raises(InputError, match="argument 'q'.*non-finite"):
        manipulability(ur5.chain, q, method="det", where=ok)
    with pytest.raises(InputError, match="argument 'where'"):
        manipulability(ur5.chain, q, method="det", where=ok[:, :4])


def test_each_row_gets_the_bits_it_gets_alone_whatever_the_threads(rng):
    ur5 = robokin.load("ur5")
    q = random_q(ur5, rng, 5003)  # above the parallel threshold, not a multiple of W
    mask = rng.random(5003) < 0.7
    whole = manipulability(ur5.chain, q, method="det", where=mask)
    alone = np.array([manipulability(ur5.chain, q[i], method="det") for i in range(40)])
    np.testing.assert_array_equal(alone[mask[:40]], whole[:40][mask[:40]])
    before = _native.num_threads()
    try:
        for k in (1, 2, 3):
            _native.set_num_threads(k)
            np.testing.assert_array_equal(
                manipulability(ur5.chain, q, method="det", where=mask), whole)
    finally:
        _native.set_num_threads(before)


@pytest.mark.parametrize("name", SIX)
def test_every_compiled_copy_agrees_to_rounding(name, rng):
    robot = robokin.load(name)
    q = np.ascontiguousarray(random_q(robot, rng, 257))
    mask = np.ones(257, dtype=bool)
    for copy in kernel_copies().values():
        out = np.empty(257)
        assert copy.abs_det_jacobian(robot.chain.arrays.packed, q, mask, out)
        _assert_rounding(robot, q, out)


def test_the_kernel_refuses_a_chain_without_six_coordinates():
    panda = robokin.load("panda")
    with pytest.raises(ValueError, match="6-coordinate"):
        _native.kernels.abs_det_jacobian(panda.chain.arrays.packed, np.zeros((1, 7)),
                                         np.ones(1, dtype=bool), np.empty(1))
    # the Python layer takes the SVD product for such arms instead
    q = random_q(panda, np.random.default_rng(1), 20)
    np.testing.assert_array_equal(manipulability(panda.chain, q, method="det"),
                                  manipulability(panda.chain, q))
