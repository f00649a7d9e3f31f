"""One configuration through the C accelerator (``_fk_single``) and its numba fallback.

The C function mirrors the numba kernel operation for operation, so both must give
the same bits; anything it does not take (lists, other dtypes, NaN) must reach the
general path and its clear errors.
"""

import shutil

import numpy as np
import pytest

import robokin
from reference import random_q
from robokin.exceptions import InputError
from robokin.kinematics import forward

SINGLE = [n for n in robokin.robots.names() if robokin.load(n).chain._single_shape]


@pytest.mark.skipif(shutil.which("cc") is None, reason="no C compiler on this machine")
def test_the_c_accelerator_was_built():
    assert forward.fk_single_c is not None, "setup.py did not build _fk_single"


needs_c = pytest.mark.skipif(forward.fk_single_c is None, reason="_fk_single not built")


@needs_c
@pytest.mark.parametrize("name", SINGLE)
def test_c_single_equals_the_batch_kernel_bit_for_bit(name, rng):
    robot = robokin.load(name)
    chain = robot.chain
    Q = random_q(robot, rng, 500)
    Q[:50] *= 40.0  # large angles: several turns of the reduction
    Q[50:55] = 3e5  # beyond the polynomial's range: libm
    batch = forward.forward_kinematics(chain, Q)  # 2-D input: never the C path
    single = np.array([forward.fk_single_c(q, chain._packed) for q in Q])
    np.testing.assert_array_equal(single, batch)
    np.testing.assert_array_equal(np.array([robot.fk(q) for q in Q]), batch)


@needs_c
def test_c_single_reads_strided_input_and_returns_a_fresh_array(rng):
    robot = robokin.load("panda")
    wide = random_q(robot, rng, 2).T.copy()  # (7, 2): a column is strided
    q = wide[:, 1]
    assert not q.flags.c_contiguous
    T1 = robot.fk(q)
    np.testing.assert_array_equal(T1, robot.fk(q.copy()))
    T2 = robot.fk(q)
    assert T1 is not T2 and T1.flags.writeable and T1.flags.owndata
    np.testing.assert_array_equal(T1[3], [0.0, 0.0, 0.0, 1.0])


@needs_c
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
def test_c_single_declines_what_it_does_not_take(q):
    chain = robokin.load("ur5").chain
    assert forward.fk_single_c(q, chain._packed) is None


@needs_c
def test_c_single_declines_a_packed_array_of_the_wrong_size():
    chain = robokin.load("ur5").chain
    assert forward.fk_single_c(np.zeros(6), chain._packed[:-1].copy()) is None
    assert forward.fk_single_c(np.zeros(6), chain._packed[::2]) is None
    with pytest.raises(TypeError, match="2 arguments"):
        forward.fk_single_c(np.zeros(6))


@pytest.mark.parametrize(
    "q", [[0.1, 0.2, 0.3, 0.4, 0.5, 0.6], np.arange(6), np.arange(6, dtype=np.float32)]
)
def test_declined_inputs_give_the_same_pose_through_the_general_path(q):
    robot = robokin.load("ur5")
    np.testing.assert_allclose(
        robot.fk(q), robot.fk(np.asarray(q, dtype=np.float64)), rtol=0, atol=1e-6
    )


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_non_finite_single_configuration_names_the_argument(bad):
    robot = robokin.load("ur5")
    q = np.zeros(6)
    q[2] = bad
    with pytest.raises(InputError, match=r"'q'.*non-finite.*\(2,\)"):
        robot.fk(q)
    with pytest.raises(InputError, match=r"'q'.*non-finite.*\(2,\)"):
        forward.forward_kinematics(robot.chain, q)


def test_without_the_c_accelerator_the_numba_kernel_gives_the_same_bits(rng, monkeypatch):
    import robokin.robot as robot_module

    robot = robokin.load("aubo_i5")
    Q = random_q(robot, rng, 50)
    with_c = np.array([robot.fk(q) for q in Q])
    monkeypatch.setattr(robot_module, "_FK_C", None)
    monkeypatch.setattr(forward, "fk_single_c", None)
    np.testing.assert_array_equal(np.array([robot.fk(q) for q in Q]), with_c)
    np.testing.assert_array_equal(
        np.array([forward.forward_kinematics(robot.chain, q) for q in Q]), with_c
    )
    q = Q[0].copy()
    q[4] = np.nan
    with pytest.raises(InputError, match="non-finite"):
        robot.fk(q)
