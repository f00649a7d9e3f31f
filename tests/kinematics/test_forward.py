"""Batch forward kinematics: shapes, batch == loop, serial == parallel, input errors."""

import numpy as np
import pytest

import robokin
from reference import random_q
from robokin._native import kernels
from robokin.kinematics.forward import link_frames


@pytest.mark.parametrize("shape", [(), (7,), (3, 5)])
@pytest.mark.parametrize("name", ["ur5", "qfmd010", "improved_dh_arm"])
def test_batch_shapes_and_batch_equals_loop(name, shape, rng):
    robot = robokin.load(name)
    q = random_q(robot, rng, shape) if shape else random_q(robot, rng)
    T = robot.fk(q)
    assert T.shape == shape + (4, 4)
    F = robot.fk_all(q)
    assert F.shape == shape + (robot.n_chain + 1, 4, 4)
    flat_q = q.reshape(-1, robot.n)
    loop = np.array([robot.fk(x) for x in flat_q]).reshape(T.shape)
    np.testing.assert_array_equal(T, loop)
    # frames and fk are one walk along the chain (chain.h's chain_walk): same bits
    np.testing.assert_array_equal(link_frames(robot.chain, q)[..., -1, :, :], T)
    np.testing.assert_allclose(
        F[..., 0, :, :], np.broadcast_to(robot.base, shape + (4, 4))
    )


@pytest.mark.parametrize("name", ["panda", "ur5", "puma560", "qfmd010"])
def test_link_frames_end_at_fk_bit_for_bit(name):
    """Oracle: fk's own tool pose. frames walked the chain a second time (F_k then
    G_k) and differed from fk by 4.4e-16 on 40 % of Panda samples; now exact."""
    robot = robokin.load(name)
    q = random_q(robot, np.random.default_rng(7), 2000)
    q[:5] = 0.0
    q[5:10] = np.pi / 2
    frames = link_frames(robot.chain, q)
    np.testing.assert_array_equal(frames[:, -1], robot.fk(q))


def test_parallel_kernel_equals_serial(rng):
    robot = robokin.load("panda")
    q = random_q(robot, rng, kernels.FK_PARALLEL_MIN + 3)
    big = robot.fk(q)
    small = np.concatenate([robot.fk(q[i : i + 100]) for i in range(0, len(q), 100)])
    np.testing.assert_array_equal(big, small)


def test_lists_are_accepted():
    robot = robokin.load("ur5")
    np.testing.assert_array_equal(robot.fk([0, 0, 0, 0, 0, 0]), robot.fk(np.zeros(6)))
    assert robot.fk([[0] * 6, [0.1] * 6]).shape == (2, 4, 4)


@pytest.mark.parametrize(
    ("q", "match"),
    [
        (np.zeros(5), r"argument 'q'.*\(\.\.\., 6\).*\(5,\)"),
        (np.zeros((2, 7)), r"argument 'q'.*\(2, 7\)"),
        (3.0, r"argument 'q'"),
        ([0, 0, 0, np.nan, 0, 0], r"argument 'q'.*non-finite.*index \(3,\)"),
        ([[0] * 6, [0, 0, 0, 0, 0, np.inf]], r"argument 'q'.*non-finite.*\(1, 5\)"),
        (["a"] * 6, r"argument 'q'.*numbers"),
    ],
)
def test_bad_q_gives_a_clear_error(q, match):
    robot = robokin.load("ur5")
    with pytest.raises(robokin.InputError, match=match):
        robot.fk(q)
    with pytest.raises(robokin.InputError, match=match):
        robot.fk_all(q)
    with pytest.raises(robokin.InputError, match=match):
        robot.jacobian(q)


def test_large_batch_nan_is_reported(rng):
    robot = robokin.load("ur5")
    q = random_q(robot, rng, 5000)
    q[4321, 2] = np.nan
    with pytest.raises(robokin.InputError, match=r"\(4321, 2\)"):
        robot.fk(q)


def test_fk_does_not_modify_its_input(rng):
    robot = robokin.load("qfmd010")
    q = random_q(robot, rng, 4)
    before = q.copy()
    robot.fk(q)
    robot.jacobian(q)
    np.testing.assert_array_equal(q, before)


@pytest.mark.parametrize("scalar", [0, 1], ids=["vsincos", "sincos1"])
def test_compiled_sincos_is_within_one_ulp_of_libm(rng, scalar):
    x = np.concatenate(
        [
            rng.uniform(-7, 7, 200_000),
            rng.uniform(-2e3, 2e3, 50_000),
            [0.0, np.pi / 2, np.pi, -np.pi, 2 * np.pi, 1e5, 3e5, np.inf, np.nan],
        ]
    )
    s, c = np.empty_like(x), np.empty_like(x)
    kernels.sincos(x, s, c, scalar)
    ok = np.isfinite(x)
    np.testing.assert_allclose(s[ok], np.sin(x[ok]), rtol=0, atol=2.3e-16)
    np.testing.assert_allclose(c[ok], np.cos(x[ok]), rtol=0, atol=2.3e-16)
    assert np.isnan(s[~ok]).all() and np.isnan(c[~ok]).all()
