"""``check_*`` helpers: what a cast would silently change is refused (issue 15, item 4)."""

from __future__ import annotations

import numpy as np
import pytest

import robokin
from robokin._validation import (
    MAX_TRANSLATION,
    check_joints,
    check_transform,
    check_vector,
)
from robokin.exceptions import InputError


@pytest.fixture(scope="module")
def ur5():
    return robokin.load("ur5")


def test_an_overflowed_pose_is_refused_not_solved(ur5):
    # the attack: before, ik() returned NaN rows marked valid
    T = ur5.fk(np.array([0.1, -1.0, 1.2, -0.5, 0.4, 0.2])).copy()
    T[0, 3] = 1e300
    for method in ("auto", "analytic", "numeric"):
        with pytest.raises(InputError, match=r"'T'.*1e\+300 m is beyond the 1e\+06 m"):
            ur5.ik(T, method=method)
    with pytest.raises(InputError, match=r"beyond .*\(pose \(1,\)\)"):
        ur5.ik(np.stack([ur5.fk(np.zeros(6)), T]))
    with pytest.raises(InputError, match="beyond"):
        ur5.ik(T.tolist())
    with pytest.raises(InputError, match="beyond"):
        robokin.load("panda").ik(T[None])  # a numeric-only arm


def test_the_bound_is_the_documented_one_and_leaves_real_poses_alone(ur5):
    assert MAX_TRANSLATION == 1e6
    T = np.eye(4)
    T[2, 3] = MAX_TRANSLATION
    check_transform(T)  # at the bound: accepted (no solution, but a fair question)
    assert len(ur5.ik(T)) == 0
    T[2, 3] = np.nextafter(MAX_TRANSLATION, np.inf)
    with pytest.raises(InputError, match="beyond"):
        check_transform(T)
    T[2, 3] = np.inf  # non-finite values keep their own message
    with pytest.raises(InputError, match="non-finite"):
        check_transform(T)
    with pytest.raises(InputError, match="non-finite"):
        ur5.ik(T)
    q = np.array([0.1, -1.0, 1.2, -0.5, 0.4, 0.2])
    sols = ur5.ik(ur5.fk(q))
    assert np.isfinite(sols.q[sols.valid]).all() and len(sols) == 8


@pytest.mark.parametrize(("value", "message"), [
    (np.array([1 + 1j, 0, 0]), "complex values"),
    ([1 + 0j, 0, 0], "complex values"),
    (np.ma.masked_array([1.0, 2.0, 3.0], mask=[0, 1, 0]), "masked array"),
    ([True, False, True], "bool values"),
    (["1", "2", "3"], "<U1 values"),
    ([1, "2", 3], "values"),
    ([None, 1, 2], "expected numbers"),
])
def test_values_a_cast_would_change_are_refused(value, message):
    for check in (lambda v: check_joints(v, 3), lambda v: check_vector(v, 3, "q")):
        with pytest.raises(InputError, match=message):
            check(value)


def test_the_public_functions_refuse_them_too(ur5):
    with pytest.raises(InputError, match="complex"):
        ur5.fk(np.zeros(6, dtype=complex))
    with pytest.raises(InputError, match="masked"):
        ur5.jacobian(np.ma.masked_array(np.zeros(6)))
    with pytest.raises(InputError, match="complex"):
        check_transform(np.eye(4, dtype=complex))
    with pytest.raises(InputError, match="masked"):
        ur5.ik(np.ma.masked_array(np.eye(4)))
    # one configuration (the compiled fast path) and the numeric solver too
    with pytest.raises(InputError, match="masked"):
        ur5.fk(np.ma.masked_array(np.zeros(6), mask=[1, 0, 0, 0, 0, 0]))
    T = ur5.fk(np.full(6, 0.3))
    for bad, message in ((np.ma.masked_array(T), "masked"), (T.astype(complex), "complex"),
                         (np.eye(4, dtype=bool), "bool")):
        with pytest.raises(InputError, match=message):
            ur5.ik(bad, method="numeric")
    # plain integers and float32 are still numbers
    np.testing.assert_array_equal(check_joints(np.arange(3, dtype=np.int32), 3),
                                  [0.0, 1.0, 2.0])
    assert check_joints(np.zeros(3, np.float32), 3).dtype == np.float64
