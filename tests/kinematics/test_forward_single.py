"""One configuration through the compiled single-configuration entry point (``fk1``).

It runs the batch kernel's code in one lane, so a single configuration and the same
configuration inside a batch must give the same bits; anything it does not take
(lists, other dtypes, NaN) must reach the general path and its clear errors.
"""

import numpy as np
import pytest

import robokin
from reference import random_q
from robokin.exceptions import InputError
from robokin.kinematics import forward

ALL = robokin.robots.names()


@pytest.mark.parametrize("name", ALL)
def test_single_equals_the_batch_kernel_bit_for_bit(name, rng):
    robot = robokin.load(name)
    chain = robot.chain
    Q = random_q(robot, rng, 500)
    Q[:50] *= 40.0  # large angles: several turns of the reduction
    Q[50:55] = 3e5  # beyond the polynomial's range: libm
    batch = forward.forward_kinematics(chain, Q)  # 2-D input: the batch kernel
    single = np.array([forward.fk_single(q, chain.arrays.packed) for q in Q])
    np.testing.assert_array_equal(single, batch)
    np.testing.assert_array_equal(np.array([robot.fk(q) for q in Q]), batch)


def test_single_reads_strided_input_and_returns_a_fresh_array(rng):
    robot = robokin.load("panda")
    wide = random_q(robot, rng, 2).T.copy()  # (7, 2): a column is strided
    q = wide[:, 1]
    assert not q.flags.c_contiguous
    T1 = robot.fk(q)
    np.testing.assert_array_equal(T1, robot.fk(q.copy()))
    T2 = robot.fk(q)
    assert T1 is not T2 and T1.flags.writeable and T1.flags.owndata
    np.testing.assert_array_equal(T1[3], [0.0, 0.0, 0.0, 1.0])


@pytest.mark.parametrize(
    "q",
    [
        [0.1, 0.2, 0.3, 0.4, 0.5, 0.6],  # a list
        np.arange(6, dtype=np.float32),  # another dtype
        np.arange(6),  # integers
        np.zeros((1, 6)),  # a batch
        np.zeros(5),  # the wrong length
        np.array([0, 0, np.nan, 0, 0, 0.0]),
        np.array([0, 0, 0, 0, 0, np.inf]),
        np.zeros(6).astype(">f8"),  # byte-swapped
    ],
)
def test_single_declines_what_it_does_not_take(q):
    chain = robokin.load("ur5").chain
    assert forward.fk_single(q, chain.arrays.packed) is None


def test_single_declines_a_packed_array_that_is_not_a_layout():
    packed = robokin.load("ur5").chain.arrays.packed
    assert forward.fk_single(np.zeros(6), packed[:-1].copy()) is None
    assert forward.fk_single(np.zeros(6), packed[::2]) is None
    wrong_tag = packed.copy()
    wrong_tag[0] += 1.0
    assert forward.fk_single(np.zeros(6), wrong_tag) is None
    with pytest.raises(TypeError, match="2 arguments"):
        forward.fk_single(np.zeros(6))


def test_dependent_joints_take_the_single_path_too(rng):
    robot = robokin.load("qfmd010")  # q_chain = M q + c: 5 chain joints from 4
    assert not robot.chain.arrays.identity
    q = random_q(robot, rng)
    T = forward.fk_single(q, robot.chain.arrays.packed)
    assert T is not None
    np.testing.assert_array_equal(T, robot.fk(q[None])[0])


@pytest.mark.parametrize(
    "q", [[0.1, 0.2, 0.3, 0.4, 0.5, 0.6], np.arange(6), np.arange(6, dtype=np.float32)]
)
def test_declined_inputs_give_the_same_pose_through_the_general_path(q):
    # A list, integers and float32 (exact here: small integers) are declined by the
    # single path and converted: the general path gives the same bits as the single
    # path on the float64 array (one chain walk, chain.h).
    robot = robokin.load("ur5")
    q64 = np.asarray(q, dtype=np.float64)
    assert forward.fk_single(q64, robot.chain.arrays.packed) is not None
    np.testing.assert_array_equal(robot.fk(q), robot.fk(q64))


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_non_finite_single_configuration_names_the_argument(bad):
    robot = robokin.load("ur5")
    q = np.zeros(6)
    q[2] = bad
    with pytest.raises(InputError, match=r"'q'.*non-finite.*\(2,\)"):
        robot.fk(q)
    with pytest.raises(InputError, match=r"'q'.*non-finite.*\(2,\)"):
        forward.forward_kinematics(robot.chain, q)
