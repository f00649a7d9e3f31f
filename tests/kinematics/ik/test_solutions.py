"""The SolutionSet: limits, nearest with wrapping, turn expansion, reasons."""

import numpy as np
import pytest

import robokin
from robokin.exceptions import UnreachableError
from robokin.kinematics.ik.solutions import SolutionSet


def _set(q, valid, limits, is_rev=None):
    q = np.asarray(q, float)
    n = q.shape[-1]
    return SolutionSet(q, valid, np.ones(n, bool) if is_rev is None else is_rev,
                       np.asarray(limits, float))


def test_nearest_wraps_revolute_but_not_prismatic():
    s = _set([[3.1, 0.5], [-3.0, 0.0]], [True, True], [[-4, 4], [-1, 1]],
             is_rev=np.array([True, False]))
    # -3.1 is 0.083 from 3.1 across the wrap: row 0 wins despite the prismatic gap
    np.testing.assert_allclose(s.distance([-3.1, 0.5]), [2 * np.pi - 6.2, np.hypot(0.1, 0.5)])
    best = s.nearest([-3.1, 0.5])
    np.testing.assert_allclose(best, [3.1 - 2 * np.pi, 0.5])  # equivalent nearest q_current


def test_nearest_respects_limits_and_names_them():
    s = _set([[0.0, 2.0], [1.0, 0.5]], [True, True], [[-1, 1], [-1, 1]])
    np.testing.assert_allclose(s.nearest([0.0, 2.0]), [1.0, 0.5])
    np.testing.assert_allclose(s.nearest([0.0, 2.0], respect_limits=False), [0.0, 2.0])
    out = _set([[0.0, 2.0]], [True], [[-1, 1], [-1, 1]])
    with pytest.raises(UnreachableError, match="joint 2 at 2 > upper limit 1"):
        out.nearest([0.0, 0.0])


def test_within_limits_reason_names_every_candidate():
    s = _set([[0.0, 2.0], [-3.0, 0.0]], [True, True], [[-1, 1], [-1, 1]]).keep_within_limits()
    st = s.status.item()
    assert st.startswith("outside joint limits")
    assert "solution 1: joint 2 at 2 > upper limit 1" in st
    assert "solution 2: joint 1 at -3 < lower limit -1" in st


def test_expand_turns_ur_360():
    robot = robokin.load("ur5")
    q0 = np.array([0.1, -1.0, 1.0, -1.0, 1.0, 2.0])
    s = robot.ik(robot.fk(q0))
    e = s.expand_turns()
    # every joint has two equivalents inside +-360 deg: 2**6 per solution
    assert int(e.count) == 64 * int(s.count)
    Q = e.q[e.valid]
    assert (np.abs(Q) <= 2 * np.pi + 1e-9).all()
    assert np.abs(robot.fk(Q) - robot.fk(q0)).max() < 1e-9
    assert np.any(np.all(np.abs(Q - (q0 - [0, 0, 0, 0, 0, 2 * np.pi])) < 1e-9, axis=1))
    # branch labels follow their source rows
    assert set(e.branches) == {"shoulder", "elbow", "wrist"}


def test_empty_and_batched_repr():
    e = SolutionSet.empty((2,), 6, np.ones(6, bool), np.tile([-1, 1], (6, 1)), "out of reach")
    assert e.count.tolist() == [0, 0]
    assert "shape=(2,)" in repr(e)
    one = e[0]
    assert "out of reach" in repr(one)


def test_limits_choose_turn_inside_range():
    # Puma's shoulder limit [-45, 225] deg: a solution at 200 deg must not wrap to -160
    robot = robokin.load("puma560")
    q0 = np.radians([10.0, 200.0, -100.0, 20.0, 30.0, 40.0])
    s = robot.ik(robot.fk(q0))
    assert np.any(np.all(np.abs(s.q[s.valid] - q0) < 1e-9, axis=1))
    assert s.within_limits[s.valid][np.argmin(s.distance(q0)[s.valid])]


@pytest.mark.parametrize("lead", [(), (2,), (0,)])
def test_expand_turns_of_a_set_without_rows(lead):
    # the numeric solver returns sets with k = 0 rows for unreachable poses
    e = SolutionSet.empty(lead, 2, np.ones(2, bool), np.tile([-7.0, 7.0], (2, 1)),
                          "out of reach")
    x = e.expand_turns()
    assert x.q.shape == lead + (0, 2) and x.count.shape == lead
    assert (np.asarray(x.status) == "out of reach").all()


def test_an_unknown_option_is_named_not_a_type_error():
    import numpy as np
    import pytest

    import robokin

    for name in ("ur5", "scara", "qfmd010"):
        robot = robokin.load(name)
        T = robot.fk(np.full(robot.n, 0.1))
        with pytest.raises(robokin.InputError, match=r"options.*'foo'"):
            robot.ik(T, foo=1)


# ------------------------------------------------------------ a collection (issue 20)
def test_one_pose_iterates_lists_and_counts_its_valid_solutions(rng):
    robot = robokin.load("ur5")
    q0 = np.array([0.3, -1.1, 1.4, -0.6, 0.9, 0.2])
    sols = robot.ik(robot.fk(q0))
    rows = sols.q[sols.valid]
    assert len(sols) == len(rows) == int(sols.count) == 8
    listed = list(sols)
    assert len(listed) == 8
    np.testing.assert_array_equal(np.array(listed), rows)
    for q in sols:
        assert q.shape == (6,)
        np.testing.assert_allclose(robot.fk(q), robot.fk(q0), atol=1e-9)
    assert any(np.allclose(q, q0, atol=1e-9) for q in sols)


def test_rows_that_are_not_solutions_are_nan_not_a_configuration():
    robot = robokin.load("ur5")
    T = robot.fk(np.array([0.1, -0.3, 0.2, 0.4, 0.0, 0.5]))
    T[:3, 3] *= 3.0  # beyond the reach: no solution at all
    far = robot.ik(np.stack([T, robot.fk(np.full(6, 0.2))]))
    assert not far.valid[0].any() and far.valid[1].any()
    assert np.isnan(far.q[~far.valid]).all()
    assert np.isfinite(far.q[far.valid]).all()
    assert list(far[0]) == [] and len(far[0]) == 0
    # filtering by the limits makes the dropped rows NaN as well
    s = _set([[0.0, 2.0], [0.5, 0.5]], [True, True], [[-1, 1], [-1, 1]])
    kept = s.keep_within_limits()
    assert kept.valid.tolist() == [False, True]
    assert np.isnan(kept.q[0]).all()
    np.testing.assert_array_equal(kept.q[1], [0.5, 0.5])


def test_a_batch_iterates_and_counts_its_poses():
    robot = robokin.load("ur5")
    q = np.array([[0.1, -1.0, 1.0, 0.2, 0.7, 0.1], [0.4, -0.8, 0.6, -0.3, 1.1, 0.9]])
    sols = robot.ik(robot.fk(q))
    assert len(sols) == 2
    per_pose = list(sols)
    assert [len(s) for s in per_pose] == sols.count.tolist()
    for s, qi in zip(per_pose, q, strict=True):
        assert s.shape == ()
        assert any(np.allclose(x, qi, atol=1e-9) for x in s)


def test_within_limits_is_a_mask_like_valid_and_singular():
    s = _set([[0.0, 2.0], [0.5, 0.5], [0.1, 0.1]], [True, True, False],
             [[-1, 1], [-1, 1]])
    assert s.within_limits.tolist() == [False, True, False]  # invalid rows: False
    assert s.singular.tolist() == [False, False, False]
    assert s.valid.tolist() == [True, True, False]
