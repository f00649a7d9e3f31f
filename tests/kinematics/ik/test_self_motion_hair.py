"""Branches a hair outside a limit (``self_motion_hair``): the in-limit solutions next to them.

Oracle throughout: the generating configuration q0, inside the limits, reaches its
pose (forward kinematics). With the SRS arm's elbow stretched to q4 = -1e-9 and the
shoulder pitch q2 at its limit, the swivel's closed form returns the exactly
stretched branches (q4 = 0: the pose fixes q4 only to ~1e-8), whose q2 is 4.9e-10
past the limit along their whole length: no interval. Before session 25 such a pose
was not ``reachable`` and had no ``best``; now a solution inside the limits is found
next to the branches, within 1e-6 of q0 from q0.
"""

from __future__ import annotations

import numpy as np
import pytest

from reference import iiwa14_srs, pose_errors, rtb_iiwa14
from robokin.kinematics.ik.self_motion_hair import HAIR, SAMPLES, hair_bands
from robokin.spatial import wrap_angle

SRS = iiwa14_srs()


def _solution(robot, T, q) -> np.ndarray:
    """q (n,) after asserting it reaches T (1e-12) inside the limits."""
    q = np.asarray(q.q if hasattr(q, "q") else q)
    dp, dr = pose_errors(robot.fk(q), T)
    assert dp <= 1e-12 and dr <= 1e-12
    assert robot.within_limits(q)
    return q


def _stretched(q2_sign: float, q4: float, rest: tuple[float, ...]) -> np.ndarray:
    """An SRS configuration with q2 at a limit and q4 next to 0 (rest: q1, q3, q5-q7)."""
    q1, q3, q5, q6, q7 = rest
    return np.array([q1, q2_sign * SRS.limits[1, 1], q3, q4, q5, q6, q7])


# q2 at +-limit with q4 of the sign that tilts the stretched branch outward
CASES = [
    _stretched(1.0, -1e-9, (0.3, 0.2, 0.5, 0.4, 0.1)),
    _stretched(1.0, -1e-9, (-1.5707963267948966, -1e-6, 1e-6, -1e-6, -3.0543261909900767)),
    _stretched(1.0, 1e-9, (-1e-6, 2.9670597283903604, -0.9936883666467231,
                           -0.08655780721555484, -1e-7)),
    _stretched(1.0, -1e-9, (0.8551705644345744, -1e-9, 2.6537531098441685,
                            0.40836039152259707, -0.9365768450479659)),
    _stretched(-1.0, 1e-9, (0.3, 0.2, 0.5, 0.4, 0.1)),
]


@pytest.mark.parametrize("q0", CASES, ids=range(len(CASES)))
def test_a_stretched_elbow_at_a_limit_is_reachable_with_q0_nearest(q0):
    T = SRS.fk(q0)
    sm = SRS.self_motion(T)
    assert len(sm.intervals) == 0  # (the case this is about: no branch inside)
    assert sm.reachable
    best = _solution(SRS, T, sm.best("margin"))
    assert sm.best("margin").score == pytest.approx(
        np.minimum(best - SRS.limits[:, 0], SRS.limits[:, 1] - best).min(), abs=1e-15)
    near = _solution(SRS, T, sm.nearest(q0))
    assert np.linalg.norm(wrap_angle(near - q0)) <= 1e-6
    rng = np.random.default_rng(5)
    for qn in (q0 + rng.normal(0.0, 0.1, 7), rng.uniform(SRS.limits[:, 0], SRS.limits[:, 1])):
        _solution(SRS, T, sm.nearest(qn))


def test_the_same_pose_with_q2_a_hair_further_out_is_not_reachable():
    """Oracle: every configuration of the pose has q2 >= limit + ~1e-4 (the q0 below
    with q2 1e-4 past its limit and the elbow stretched: the arm's direction fixes
    q2 up to the 1e-8 the pose leaves free), so nothing is inside: far beyond HAIR."""
    q0 = _stretched(1.0, 0.0, (0.3, 0.2, 0.5, 0.4, 0.1))
    q0[1] += 1e-4
    sm = SRS.self_motion(SRS.fk(q0))
    assert not sm.reachable
    assert sm.best("margin") is None and sm.nearest(q0) is None


def _rows_of(values):
    """rows_at for hair_bands: one branch, joint 0 = values(t), joint 1 = 0."""
    def rows_at(t):
        out = np.zeros((len(t), 1, 2))
        out[:, 0, 0] = values(t)
        return out
    return rows_at


LIMITS = np.array([[-1.0, 1.0], [-1.0, 1.0]])
DOMAIN = np.array([-np.pi, np.pi])
STEP = 2 * np.pi / (SAMPLES - 1)


def test_hair_bands_a_branch_on_its_limit_all_along():
    bands, branch = hair_bands(_rows_of(lambda t: np.full_like(t, 1.0 + 5e-10)), DOMAIN,
                               LIMITS)
    np.testing.assert_array_equal(bands, [DOMAIN])
    np.testing.assert_array_equal(branch, [0])


def test_hair_bands_a_run_is_widened_by_one_step_each_side():
    # inside the hair only for t in [0.5, 1.0] (grid values there), 0.1 out elsewhere
    def values(t):
        return np.where((t >= 0.5) & (t <= 1.0), 1.0 + HAIR / 2, 1.1)
    bands, branch = hair_bands(_rows_of(values), DOMAIN, LIMITS)
    t = np.linspace(-np.pi, np.pi, SAMPLES)
    inside = t[(t >= 0.5) & (t <= 1.0)]
    np.testing.assert_allclose(bands, [[inside[0] - STEP, inside[-1] + STEP]], atol=1e-15)
    np.testing.assert_array_equal(branch, [0])


def test_hair_bands_none_beyond_the_hair_or_where_no_branch_is():
    for values in (lambda t: np.full_like(t, 1.0 + 2 * HAIR),
                   lambda t: np.full_like(t, np.nan)):
        bands, branch = hair_bands(_rows_of(values), DOMAIN, LIMITS)
        assert bands.shape == (0, 2) and branch.shape == (0,)


# q2 at its limit with the elbow 2.7e-4 from stretched: branch 7 is tangent to the
# limit, q2 = limit - 6.5e-5 psi^2, inside at psi = 0 only; the swivel kernel gives
# intervals of +-0.17 whose other rows are up to 2e-6 outside (its widened point)
TANGENT = np.array([-2.088187845485972, -2.0943951023931953, 1e-09, 0.00026640684586087815,
                    -1e-06, -1.297527775817982, 1.5707963267948966])


@pytest.mark.parametrize("q_near", [
    [-1.9622788823136055, -2.090858157897023, 0.03863750414916595, -0.0624729597525322,
     -0.12256130067117213, -1.2791917194937314, 1.614247697499108],
    [0.023852928654097827, 1.6032203996325611, 2.8004696294666305, -1.9112009062297013,
     2.193427086676577, -0.47436844765578146, -0.05711852497751968]])
def test_a_branch_tangent_to_a_limit_gives_its_point_to_best_and_nearest(q_near):
    """Oracle: TANGENT (inside the limits, on its pose). Its intervals' sampled rows are
    all outside but the tangent point, so ``best`` and ``nearest`` gave None (session
    25's fuzz, SRS seed 48 #142); now the hair bands' search finds the tangent point:
    both in-limit solutions of the pose, ``nearest`` no farther than TANGENT."""
    T = SRS.fk(TANGENT)
    sm = SRS.self_motion(T)
    assert len(sm.intervals) and sm.reachable
    _solution(SRS, T, sm.best("margin"))
    qn = np.array(q_near)
    near = _solution(SRS, T, sm.nearest(qn))
    bound = np.linalg.norm(wrap_angle(TANGENT - qn))
    assert np.linalg.norm(wrap_angle(near - qn)) <= bound + 1e-6


def test_a_branch_at_isolated_values_gives_its_row():
    """Oracle: q0 (inside the limits, on its pose). The rtb-data iiwa14 (not exactly
    SRS: held at joint_a3) with q2 and q4 within 1e-7 of 0 and q6 at its limit has
    branch rows at isolated grid values only (one, at t = 0, 4.3e-11 past the limit):
    ``reachable`` was False, ``best`` and ``nearest`` None (session 25's fuzz, seed 25
    #5). The hair bands' own grid rows are now candidates: an in-limit solution of the
    pose for ``best`` and ``nearest``."""
    robot = rtb_iiwa14()
    q0 = np.array([0.0, -1e-09, 1e-07, 1e-07, -2.7317217623578154, 2.0942, 1e-06])
    T = robot.fk(q0)
    sm = robot.self_motion(T)
    assert len(sm.intervals) == 0 and sm.reachable
    _solution(robot, T, sm.best("margin"))
    near = _solution(robot, T, sm.nearest(q0 + 0.05))
    assert np.linalg.norm(wrap_angle(near - q0)) <= 1e-4
