"""The cell's manipulability is robokin's one formula (review finding 2)."""

import numpy as np
import pytest

import robokin
from reference import random_q
from robokin.cell._evaluate import manipulability as cell_manipulability
from robokin.exceptions import InputError
from robokin.kinematics.jacobian import manipulability


@pytest.mark.parametrize("name", ["scara", "panda"])
def test_the_cell_equals_robot_manipulability_without_six_joints(name, rng):
    robot = robokin.load(name)
    assert robot.n != 6
    q = random_q(robot, rng, 2000)
    np.testing.assert_allclose(cell_manipulability(robot.chain, q),
                               robot.manipulability(q), rtol=1e-12, atol=0.0)


@pytest.mark.parametrize("name", ["ur5", "puma560", "aubo_i5"])
def test_the_determinant_equals_the_svd_product_on_a_6r_arm(name, rng):
    robot = robokin.load(name)
    q = random_q(robot, rng, 2000)
    svd = robot.manipulability(q)
    det = manipulability(robot.chain, q, method="det")
    # random configurations, some near a singularity (w down to 7e-7)
    np.testing.assert_allclose(det, svd, rtol=1e-10, atol=0.0)
    np.testing.assert_array_equal(cell_manipulability(robot.chain, q), det)
    np.testing.assert_array_equal(manipulability(robot.chain, q), svd)  # the default


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_the_cell_chunks_change_no_bit(monkeypatch, rng, name):
    import robokin.cell._evaluate as ev

    robot = robokin.load(name)
    q = random_q(robot, rng, (25, 4))
    ok = rng.random((25, 4)) < 0.7
    whole = cell_manipulability(robot.chain, q, ok)
    monkeypatch.setattr(ev, "_MANIPULABILITY_BATCH", 7)  # the SVD path's batches
    np.testing.assert_array_equal(cell_manipulability(robot.chain, q, ok), whole)
    # masked rows are 0, the others the value each row gets alone
    assert (whole[~ok] == 0).all()
    for i, j in zip(*np.nonzero(ok)):
        assert cell_manipulability(robot.chain, q[i, j][None])[0] == whole[i, j]
    assert cell_manipulability(robot.chain, q[:0, 0]).shape == (0,)


def test_an_unknown_method_is_named():
    ur5 = robokin.load("ur5")
    with pytest.raises(InputError, match="argument 'method'.*'svd' or 'det'"):
        manipulability(ur5.chain, np.zeros(6), method="lu")
