"""The nearest in-limit point of a held-joint self-motion (``self_motion_nearest``).

Oracles (independent of the search under test):
* dense samples: every branch of ``SelfMotion.sample`` at 5,000 values of the
  parameter over its range, the rows inside every joint limit, the smallest 2 pi
  wrapped distance to q_near; the answer is never farther than that (1e-12);
* forward kinematics of the answer reproduces the pose to 1e-12 (position [m] and
  rotation angle [rad], ``reference.pose_errors``), and it is inside the limits;
* from q0 itself (inside the limits) the answer is q0, also where q2 or q6 is 0 (an
  aligned continuum: session 23), and from q_near the answer is never farther than q0.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import robokin
from reference import iiwa14_srs, pose_errors, random_7r, ur5_on_a_track
from robokin.kinematics.arm import arm_of
from robokin.kinematics.ik.dispatch import solve
from robokin.kinematics.ik.self_motion_families import _family
from robokin.kinematics.ik.self_motion_nearest import interval_nearest
from robokin.spatial import wrap_angle
from special_values import configurations, draw_configurations

PANDA = robokin.load("panda")
DENSE = 5000


def _dense_best(sm, qn):
    Q = sm.sample(np.linspace(*sm.domain, DENSE), within_limits=True).reshape(-1, 7)
    d = np.linalg.norm(wrap_angle(Q - qn), axis=-1)
    return float(np.nanmin(d)) if np.isfinite(d).any() else np.inf


def _cases():
    """36 seeded (q0, q_near): random in-limit q0; q_near near, far, or past a limit."""
    rng = np.random.default_rng(2029)
    lo, hi = PANDA.limits[:, 0], PANDA.limits[:, 1]
    out = []
    for i in range(36):
        q0 = rng.uniform(lo, hi)
        if i % 6 == 5:  # special values users hit: 0 and +-pi/2 where in range
            q0[[0, 2, 4, 6]] = np.clip([0.0, np.pi / 2, -np.pi / 2, 0.0], lo[[0, 2, 4, 6]],
                                       hi[[0, 2, 4, 6]])
        kind = i % 3
        if kind == 0:
            qn = q0 + rng.normal(0.0, 0.3, 7)
        elif kind == 1:
            qn = rng.uniform(lo, hi)  # far: another part of the manifold may be nearer
        else:
            qn = q0.copy()
            qn[3] = hi[3] + 0.2  # past q4's upper limit: a constrained minimum
        out.append((q0, qn))
    return out


@pytest.mark.parametrize("i", range(36))
def test_ik_near_self_motion_is_as_near_as_dense_samples(i):
    q0, qn = _cases()[i]
    T = PANDA.fk(q0)
    res = PANDA.ik_near(T, qn, method="self_motion")
    assert res.success
    best = _dense_best(PANDA.self_motion(T), qn)
    got = float(np.linalg.norm(wrap_angle(res.q - qn)))
    assert got <= best + 1e-12
    assert PANDA.within_limits(res.q)
    dp, dr = pose_errors(PANDA.fk(res.q), T)
    assert dp <= 1e-12 and dr <= 1e-12


def test_from_q0_itself_the_answer_is_q0():
    rng = np.random.default_rng(11)
    for _ in range(5):
        q0 = rng.uniform(PANDA.limits[:, 0] * 0.95, PANDA.limits[:, 1] * 0.95)
        p = PANDA.self_motion(PANDA.fk(q0)).nearest(q0)
        assert p is not None and np.abs(p.q - q0).max() < 1e-7 and -p.score < 1e-7


def test_no_interval_gives_none():
    # oracle: an empty interval list has no point (the search must not invent one)
    q0 = np.zeros(7)
    fam = _family(arm_of(PANDA), PANDA.fk(q0), "auto", solve, False)
    assert interval_nearest(fam, PANDA.limits, np.zeros((0, 2)), np.zeros(0, int), q0) is None


@pytest.mark.parametrize("parameter", ["track", "j1", "j6"])
def test_joints_with_a_range_over_a_turn_come_back_without_a_full_turn(parameter):
    # Session 16: a UR5 (joints +-6.28 rad) on a linear track. With j6 as the
    # parameter, t and t - 2 pi are both in its domain and equally near q0 by the
    # wrapped distance; nearest(q0) returned q0 with j6 a full turn away. The tie now
    # goes to the unwrapped nearer value, and the other revolute joints come back at
    # their 2 pi equivalent nearest q_near (SolutionSet.nearest's rule); the track
    # (prismatic) is never wrapped. Oracles: q0 itself (1e-9), FK of the answer.
    arm = ur5_on_a_track(6.0)
    for q0 in (np.array([0.7, 0.3, -1.2, 1.1, -0.5, 0.8, 0.2]),
               np.array([4.5, -2.9, 1.0, -2.0, 2.5, -0.4, -3.0])):
        T = arm.fk(q0)
        sm = arm.self_motion(T, parameter)
        got = sm.nearest(q0)
        assert got is not None
        np.testing.assert_allclose(got.q, q0, atol=1e-9)
        assert got.t == pytest.approx(q0[arm.joint_names.index(parameter)], abs=1e-9)
        dp, dr = pose_errors(arm.fk(got.q), T)
        assert dp < 1e-12 and dr < 1e-12


@pytest.mark.parametrize("i", range(6))
def test_a_general_7r_arm_takes_its_continued_manifold(i):
    # Session 17: method="self_motion" refused every 7-joint arm without a closed form
    # (its continued manifold then cost up to ~1 s a pose; now ~10-30 ms). A general
    # 7R arm (random_7r: the general held-joint 6R solver, joint 7 continued) now
    # takes it. Oracles: the dense samples of its manifold (never nearer than the
    # answer), FK of the answer (1e-12), inside the limits; special values of q0.
    arm = random_7r()
    rng = np.random.default_rng(1700 + i)
    lo, hi = arm.limits[:, 0], arm.limits[:, 1]
    q0 = rng.uniform(lo, hi)
    if i % 2:  # joints at 0 and pi/2 where in range
        q0[[1, 3, 5]] = np.clip([0.0, np.pi / 2, 0.0], lo[[1, 3, 5]], hi[[1, 3, 5]])
    qn = q0 + rng.normal(0.0, 0.3, 7) if i < 3 else rng.uniform(lo, hi)
    T = arm.fk(q0)
    res = arm.ik_near(T, qn, method="self_motion")
    assert res.success
    got = float(np.linalg.norm(wrap_angle(res.q - qn)))
    assert got <= _dense_best(arm.self_motion(T), qn) + 1e-12
    assert arm.within_limits(res.q)
    dp, dr = pose_errors(arm.fk(res.q), T)
    assert dp <= 1e-12 and dr <= 1e-12


# Session 23: aligned continua. Where joint j puts axes j-1 and j+1 on one line (the
# Panda's and the iiwa's q2 = 0 or q6 = 0), the pose is also reached by every
# configuration turning those two joints against each other: a continuum at one
# parameter value, which the branches' rows meet in a single point. The search on
# the branches alone returned, from an in-limit configuration with q2 = 0 (Panda,
# SRS) or q6 = 0 (SRS), a configuration up to 3 rad away (SRS batch of q6 = 0 poses:
# 1 % within the generating configuration's distance).

SRS = iiwa14_srs()
#: The arms and the aligned joints forced to 0 in these tests (Panda: q6 = 0 puts
#: joints 5 and 7 on one line, the parameter's own pair: covered by the branches).
ALIGNED = {"panda": (PANDA, (1, 5)), "srs": (SRS, (1, 5))}


def _aligned_configuration(robot, q: np.ndarray, which: int) -> np.ndarray:
    """q inside the limits with the aligned joints of ``which`` (1, 2 or 3: bits) at 0."""
    q = np.clip(q, robot.limits[:, 0], robot.limits[:, 1])
    for bit, j in enumerate(ALIGNED["panda" if robot is PANDA else "srs"][1]):
        if which >> bit & 1:
            q[j] = 0.0
    return q


def _checked(robot, T, q_near, got) -> float:
    """The answer's 2 pi wrapped distance to q_near; asserts it reaches T inside the limits."""
    assert got is not None
    q = got if isinstance(got, np.ndarray) else got.q
    dp, dr = pose_errors(robot.fk(q), T)
    assert dp <= 1e-12 and dr <= 1e-12
    assert robot.within_limits(q)
    return float(np.linalg.norm(wrap_angle(q - q_near)))


@pytest.mark.parametrize("name", ["panda", "srs"])
@given(data=st.data())
@settings(max_examples=40, deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.too_slow])
def test_from_an_aligned_configuration_the_answer_is_itself(name, data):
    """Oracle: q0 itself, inside the limits with q2 and / or q6 at 0 (the other joints
    special or uniform): ``nearest(q0)`` and ``ik_near(fk(q0), q0, method=
    "self_motion")`` return q0 (1e-6, the issue's recovery tolerance: at a singular q0,
    e.g. q2 = q5 = pi/2 with q4 at its limit, the rows are 6.5e-8 off; before, the
    answers were 0.3 to 3 rad away), reaching the pose to 1e-12 inside the limits."""
    robot, _ = ALIGNED[name]
    q0 = _aligned_configuration(robot, data.draw(configurations(robot)),
                                data.draw(st.sampled_from([1, 2, 3])))
    T = robot.fk(q0)
    for got in (robot.self_motion(T).nearest(q0), robot.ik_near(T, q0, method="self_motion")):
        assert _checked(robot, T, q0, got) <= 1e-6


@pytest.mark.parametrize("name", ["panda", "srs"])
def test_near_an_aligned_configuration_the_answer_is_never_farther_than_it(name):
    """Oracle: q0 (inside the limits, q2 and / or q6 at 0) solves its pose, so the
    answer for q_near = q0 + noise (0.05-0.5 rad) is never farther from q_near than
    q0 (1e-6: where two joints sit at limits at q0 the branch search's point is
    7.5e-7 farther); one ``ik_near`` batch (the SRS arm's compiled path) and
    ``nearest`` per pose agree on the distance (1e-6)."""
    robot, _ = ALIGNED[name]
    rng = np.random.default_rng(2323)
    n = 24
    q0 = np.array([_aligned_configuration(robot, q, 1 + i % 3)
                   for i, q in enumerate(draw_configurations(robot, rng, n))])
    qn = q0 + rng.normal(0.0, 1.0, q0.shape) * rng.choice([0.05, 0.2, 0.5], (n, 1))
    T = robot.fk(q0)
    batch = robot.ik_near(T, qn, method="self_motion")
    for i in range(n):
        bound = float(np.linalg.norm(wrap_angle(q0[i] - qn[i])))
        d_batch = _checked(robot, T[i], qn[i], batch.q[i])
        d_one = _checked(robot, T[i], qn[i], robot.self_motion(T[i]).nearest(qn[i]))
        assert d_batch <= bound + 1e-6 and d_one <= bound + 1e-6
        assert d_batch == pytest.approx(d_one, abs=1e-6)


def test_a_continuum_step_is_the_brute_force_minimum():
    """Oracle: a dense scan of s (200,001 values over each in-limit stretch, the pair's
    2 pi turns included) of |wrap(q_a + s - n_a)|^2 + |wrap(q_b - sign s - n_b)|^2:
    ``_pair_step``'s point is no farther (1e-9), inside both limits, and on the
    continuum (q_a + sign q_b kept, mod 2 pi)."""
    from robokin.kinematics.ik.self_motion_continua import pair_step as _pair_step

    rng = np.random.default_rng(23)
    m = 200
    lo = np.array([-2.9, -1.8, -2.9, -3.1, -2.9, -0.1, -2.9])
    hi = np.array([2.9, 1.8, 2.9, -0.1, 2.9, 3.8, 2.9])
    q = rng.uniform(lo, hi, (m, 7))
    qn = rng.uniform(-np.pi, np.pi, (m, 7))
    wrapped = np.ones(7, dtype=bool)
    for sign in (1.0, -1.0):
        got = _pair_step(q, 0, 2, sign, lo, hi, wrapped, qn)
        assert np.all((got >= lo) & (got <= hi))
        np.testing.assert_allclose(wrap_angle(got[:, 0] + sign * got[:, 2]
                                              - q[:, 0] - sign * q[:, 2]), 0.0, atol=1e-12)
        f = wrap_angle(got[:, 0] - qn[:, 0]) ** 2 + wrap_angle(got[:, 2] - qn[:, 2]) ** 2
        s = np.linspace(-4 * np.pi, 4 * np.pi, 200_001)
        for i in range(0, m, 10):
            qa, qb = q[i, 0] + s, q[i, 2] - sign * s
            best = np.inf
            for ka in (-2, -1, 0, 1, 2):
                for kb in (-2, -1, 0, 1, 2):
                    a, b = qa + 2 * np.pi * ka, qb + 2 * np.pi * kb
                    ok = (a >= lo[0]) & (a <= hi[0]) & (b >= lo[2]) & (b <= hi[2])
                    if ok.any():
                        g = (wrap_angle(a[ok] - qn[i, 0]) ** 2
                             + wrap_angle(b[ok] - qn[i, 2]) ** 2)
                        best = min(best, float(g.min()))
            assert f[i] <= best + 1e-9


def test_a_continuum_row_past_a_limit_is_moved_inside_along_its_continuum():
    """Oracle: forward kinematics. SRS rows with q6 = 0 (axes 5 and 7 on one line) and
    q7 = pi, past its limit (3.054): ``pair_steps`` moves q5 and q7 against each other
    into the limits, and the rows still reach their poses (1e-12). Before, a moved
    joint outside was clipped first: q7 pi -> 3.054 left the pose by 0.087 rad (the
    held rows at q2 = 0 of an aligned pose, one of them past q7's limit)."""
    from robokin.kinematics.ik.self_motion_continua import LINE_PAIRS, pair_steps

    rng = np.random.default_rng(24)
    lo, hi = SRS.limits[:, 0], SRS.limits[:, 1]
    q = rng.uniform(0.8 * lo, 0.8 * hi, (20, 7))
    q[:, 5], q[:, 6] = 0.0, np.pi
    T = SRS.fk(q)
    qn = rng.uniform(lo, hi, (20, 7))
    got = pair_steps(q, qn, SRS.arm.derived(LINE_PAIRS), lo, hi, np.ones(7, dtype=bool))
    assert np.isfinite(got).all()
    for i in range(len(q)):
        assert SRS.within_limits(got[i])
        assert max(pose_errors(SRS.fk(got[i]), T[i])) <= 1e-12


def _continuum_margin(robot, T) -> float:
    """Oracle: the largest joint-limit margin on the aligned continua of pose T, by a
    scan of 20,001 values of s per family row (the pair's 2 pi turns included); each
    row from ``robot.ik(T, fixed={joint: v})`` at every line-sharing aligned value."""
    from robokin.kinematics.ik.coincident import coincident_pair
    from robokin.kinematics.ik.self_motion_intervals import _aligned_values

    lim = robot.limits
    best = -np.inf
    s = np.linspace(-2 * np.pi, 2 * np.pi, 20_001)
    for j, v in _aligned_values(robot.arm):
        pair = coincident_pair(robot.arm, j, v)
        if pair is None:
            continue
        sols = robot.ik(T, fixed={robot.arm.joint_names[j]: v})
        for r in sols.q[sols.valid]:
            for ka in (-1, 0, 1):
                for kb in (-1, 0, 1):
                    R = np.repeat(r[None], len(s), axis=0)
                    R[:, pair.a] += s + 2 * np.pi * ka
                    R[:, pair.b] += -pair.sign * s + 2 * np.pi * kb
                    m = np.minimum(R - lim[:, 0], lim[:, 1] - R).min(axis=1)
                    best = max(best, float(m.max()))
    return best


@pytest.mark.parametrize("name,q0", [
    ("panda", [-np.pi / 2, 0.0, -np.pi / 4, -np.pi / 2, 0.0, np.pi / 2, np.pi / 4]),
    ("srs", [2.107959299690248, 0.0, 2.2344161100453483, -0.1176642923996003,
             -1.3408238534182906, 0.0, 0.8901582958581864]),
    ("srs", [0.0] * 7),  # stretched: one line of axes 1, 3, 5, 7
])
def test_best_margin_takes_the_aligned_continua(name, q0):
    """Oracle: :func:`_continuum_margin`'s scan; ``best("margin")`` is at least its
    value (1e-6) and at least q0's own margin, its score is its configuration's margin,
    and it reaches the pose to 1e-12 inside the limits. Before, the first two poses'
    best margins were 1.4391 and 1.8149 rad against 1.5010 and 1.9767 on a continuum
    (a quarter-turn Panda pose with q2 = 0; an SRS pose with q2 = q6 = 0)."""
    robot, _ = ALIGNED[name]
    q0 = np.array(q0)
    T = robot.fk(q0)
    got = robot.self_motion(T).best("margin")
    lim = robot.limits
    margin = float(np.minimum(got.q - lim[:, 0], lim[:, 1] - got.q).min())
    assert got.score == pytest.approx(margin, abs=1e-12)
    assert got.score >= _continuum_margin(robot, T) - 1e-6
    assert got.score >= float(np.minimum(q0 - lim[:, 0], lim[:, 1] - q0).min()) - 1e-9
    _checked(robot, T, q0, got)


def _with_limits(robot, new: dict[int, tuple[float, float]]):
    """The arm with some joints' limits replaced (the same chain otherwise)."""
    import dataclasses

    chain = robot.chain
    joints = list(chain.joints)
    for j, (lo, hi) in new.items():
        joints[j] = dataclasses.replace(joints[j], limits=(lo, hi))
    return robot.replace(chain=chain.replace(joints=tuple(joints), coordinates=tuple(joints)))


def test_a_pose_inside_the_limits_only_on_a_continuum_is_reachable():
    """Oracle: q0, inside the limits and reaching the pose by construction. The SRS
    arm with q1, q2 and q3 held to narrow ranges around q0 (q2 = 0: axes 1 and 3 on
    one line) has no branch inside its limits at q0's pose (every branch row at q0's
    swivel splits q1 + q3 = 0.7 otherwise, 2.914 / -2.214 and -0.228 / 0.928), only the
    continuum through q0: ``reachable`` is True (it was False, while ``best`` and
    ``nearest`` now find the continuum), ``best`` and ``nearest`` return in-limit
    configurations of the pose (``nearest(q0)``: q0), and a planning goal at the pose
    samples that continuum (session 24; before, one configuration): every goal reaches
    the pose inside the limits with q2 = 0 and q1 + q3 = 0.7, spread over q1's range."""
    from robokin.planning.goals import goal_configurations

    q0 = np.array([0.4, 0.0, 0.3, -1.2, 0.5, 0.8, 0.2])
    arm = _with_limits(SRS, {0: (0.35, 0.45), 1: (-1e-3, 1e-3), 2: (0.25, 0.35)})
    T = arm.fk(q0)
    sm = arm.self_motion(T)
    assert len(sm.intervals) == 0 and sm.reachable
    _checked(arm, T, q0, sm.best("margin"))
    assert _checked(arm, T, q0, sm.nearest(q0)) <= 1e-9
    goals = goal_configurations(arm, T)
    assert goals.q.shape[0] >= 4 and goals.manifold is not None
    for q in goals.q:
        _checked(arm, T, q0, q)
    assert np.abs(goals.q[:, 1]).max() <= 1e-12
    np.testing.assert_allclose(goals.q[:, 0] + goals.q[:, 2], 0.7, atol=1e-12)
    assert goals.q[:, 0].max() - goals.q[:, 0].min() >= 0.08  # (cell centres of 0.1)
    assert len(np.unique(goals.q.round(12), axis=0)) == len(goals.q)


def test_next_to_a_stretched_elbow_the_nearest_is_found_on_the_intervals():
    """Oracle: q0 (q2 = q4 = q5 = -1e-7, q6 at its upper limit) reaches its pose inside the
    limits, and the manifold has 12 intervals. The compiled swivel search found no
    point there (``nearest`` gave None for q0 itself and every q_near, ``ik_near``
    failed); now its intervals are searched instead: an in-limit configuration of the
    pose for every q_near, q0 itself from q0, one ``ik_near`` batch the same. (From
    q0 + 0.1, q6 past its limit, the answer is 0.015 rad farther than q0: q0 is on no
    sampled row, the numeric solve from there leaves the limits, and no aligned joint
    is exactly at its value: docs/ik.md, session 23.)"""
    lim = SRS.limits
    q0 = np.array([-1.135, -1e-7, -1.42, -1e-7, -1e-7, lim[5, 1], 1.07])
    T = SRS.fk(q0)
    sm = SRS.self_motion(T)
    assert len(sm.intervals) == 12
    near = [q0, q0 + np.array([-0.08, 0.3, 0.05, -0.08, -0.13, 0.2, 0.17]), q0 + 0.1,
            q0 - 0.1]
    got = [_checked(SRS, T, qn, sm.nearest(qn)) for qn in near]
    assert got[0] <= 1e-9
    batch = SRS.ik_near(np.stack([T] * len(near)), np.stack(near), method="self_motion")
    assert batch.success.all()
    for qn, q, d in zip(near, batch.q, got, strict=True):
        assert _checked(SRS, T, qn, q) == pytest.approx(d, abs=1e-9)


def test_a_continued_manifold_of_continuum_rows_gives_q0_back():
    """Oracle: q0 itself. A UR5 on a 2 m track with its wrist's joint at 0 (q6 = 0:
    axes 5 and 7 parallel to the shoulder's; with the track held the six joints have a
    continuum of solutions, so the continued manifold's rows are its members): from
    q0 the search on the branches returned a configuration 0.48 rad away; the numeric
    solve from q_near now runs for every pose of such families and finds q0."""
    arm = ur5_on_a_track(2.0)
    q0 = np.array([1.0, -1.686, -2.8636, -1.7201, -2.1824, 0.0, -1.8646])
    T = arm.fk(q0)
    got = arm.self_motion(T).nearest(q0)
    assert _checked(arm, T, q0, got) <= 1e-9


def test_at_a_corner_of_two_limits_the_answer_is_on_the_pose():
    """Oracle: forward kinematics of the answer. q0 has q4 and q6 at their limits
    (with q5 = 1e-7): the branch search's point at that corner was clamped into the
    limits, 1.00008e-12 off the pose (over the issue's 1e-12); it is now polished with
    the joints at their limits kept there: within 5e-13 from any q_near, inside the
    limits, and from q_near near q0 no farther than q0."""
    q0 = np.array([-2.0627886086769855, -0.39673422769784961, -0.37572944873058534,
                   -3.0718, 1e-7, -0.0175, 0.75444574412352639])
    T = PANDA.fk(q0)
    sm = PANDA.self_motion(T)
    rng = np.random.default_rng(0)
    near = [q0 + 0.1, q0 - 0.1, q0 + 0.05, *rng.uniform(PANDA.limits[:, 0],
                                                        PANDA.limits[:, 1], (4, 7))]
    for i, qn in enumerate(near):
        got = sm.nearest(qn)
        d = _checked(PANDA, T, qn, got)
        assert max(pose_errors(PANDA.fk(got.q), T)) <= 5e-13
        if i < 3:
            assert d <= float(np.linalg.norm(wrap_angle(q0 - qn))) + 1e-9


#: (arm, q0, q_near) of a fuzz of special configurations (``special_values``, seeds
#: 24-26: q_near = q0 + N(0, 0.1) or uniform) where the answer was up to 3.6 rad
#: farther than q0, or None: a branch 1e-9..1e-6 from an aligned continuum (q2, q4 or
#: q6 at 1e-9..1e-6, its pair swinging by ~pi next to it), often with joints at limits.
SWINGS = [
    ('srs', [-1.5707963267948966, 1.768417534149179, -1e-06, 0.08084048099307095, 0.8036876461384939, -1e-09, 1e-07],
     [-1.633896105647421, 1.9283947973057662, -0.03381477914398409, 0.22543356089946365, 0.868261694156566, -0.01735571783688044, -0.11605366078152254]),
    ('srs', [1e-06, 2.0943951023931953, 1.706461847740937, 0.0, 0.0, -1e-07, -3.0543261909900767],
     [-0.002326129040900309, 2.092511750774872, 1.657645031337585, 0.0066849544387060315, 0.12110597737631129, 0.02426487891919681, -3.1115595232424806]),
    ('srs', [2.9670597283903604, -1e-06, -2.9670597283903604, 1.240404452703424, -2.9670597283903604, -1e-06, 0.9593410329519809],
     [2.8981179178977694, -0.06576626263814779, -2.9824800601071084, 1.2384107107425473, -2.900465836133214, -0.03408208603132786, 0.984161619997657]),
    ('srs', [2.9670597283903604, 2.0943951023931953, 2.5621541151938603, -1e-06, 1e-06, 0.0, -1e-06],
     [2.8391748404281314, 1.9145894019271625, 2.5651013785225447, 0.2551582626456178, -0.1362332643253934, -0.04531784227550669, -0.2285158053378507]),
    ('srs', [2.9670597283903604, 1e-09, -1e-06, 1e-07, 0.0, -1e-07, -1e-06],
     [2.8681106392191507, 0.03149050996541042, -0.0829228821013876, -0.016556050495934338, -0.02186099936113932, -0.08261960325905736, 0.09400756640569155]),
    ('srs', [1e-07, -1e-06, 0.4485713315456876, -1e-09, 0.7574717055218612, 0.13377098477627225, 1e-09],
     [1.6664219338101294, 1.2233586607289904, 0.5957586321166222, 0.06338344712305144, -1.653564052988086, -0.21270834234607006, 2.307920850039019]),
    ('srs', [-2.0839190403478214, 0.0, 2.2041577587308963, -2.0943951023931953, -1.9769605063231281, 1e-09, -1e-06],
     [-2.1995152560260416, 0.009117622995188956, 2.2449554657436233, -2.257193186871075, -1.8681998833687758, 0.11686538628941284, 0.05028785823258457]),
    ('srs', [-2.9670597283903604, -1e-06, 1e-09, -2.0943951023931953, -0.7777858962021122, -1e-09, 1.1982300797795427],
     [-2.9706134195621425, -0.021020898382716757, -0.07863996947673654, -2.058189005130989, -0.7712935220403104, -0.05151630280296142, 1.2819489627672565]),
    ('srs', [1.5707963267948966, -2.0943951023931953, 1e-09, 1e-06, 1e-06, 1.3615835734608837, -0.8747439136934774],
     [2.809104356850681, -1.2228517833453614, 2.8551489097964424, 1.159110874240441, 2.050547510610614, 0.15750589402126103, 2.898008408063772]),
    ('srs', [1.970491193255306, -1e-09, -1e-09, 1.5707963267948966, -0.9005393983774703, -0.5547907277151485, -3.0543261909900767],
     [2.086818551190948, 0.08634940686752243, 0.12171412405291819, 1.6498744986934184, -0.9766664823781377, -0.5162232169345209, -3.012107094171209]),
    ('panda', [-1e-09, 1e-06, 1e-06, -1.3163024847285558, -1.3888599389947565, 0.8312723426070328, 1.2933827749508962],
     [-0.31529870770455704, 0.5818412696614286, 0.7994246269563838, -2.1541706748945044, -1.9701863233451304, 3.453468335671027, 0.23400421732190058]),
    ('panda', [1.8564001504935939, -0.28789285673654086, 0.6216208516843893, -0.0698, -2.8973, -1e-06, 1e-07],
     [1.9689770417723036, -0.2780509920948742, 0.6940222005243905, -0.033815584245919995, -2.991527881779192, 0.2027533940953347, 0.0884816230820874]),
    # session 25: the swivel kernel's answer with q6 clamped onto its limit, 1.0002e-12
    # off the pose (a corner's row taken with its error before the clamp)
    ('srs', [-1.5707963267948966, -1e-06, 1e-06, -1.7513213822701155, -1.8788305363411641, 2.0943951023931953, -2.215194710999195],
     [-1.6343384198467297, -0.024314898051286254, -0.11520987081139458, -1.7079491340119946, -1.7303457237872761, 2.054039873775296, -2.2170169472299457]),
    # a branch passing the continuum 1e-9 off without crossing it (no
    # aligned point; q0 1e-9 after an interval end of its swing: 0.069 rad farther)
    ('panda', [0.2718112341103085, -1e-09, -2.2466308734536136, -1.040651343624745, 1.0533945803167022, 1e-07, -1e-07],
     [-0.40334901609802465, 0.09189379175233459, -2.4588977241732946, -2.5928331908794076, 2.663902281023955, 3.4244821555027287, 0.33004063967476016]),
    # a moved aligned row nearest q_near with q6 0.6 outside hid an in-limit one (0.18)
    ('panda', [-2.057285607905913, -1e-07, 0.6528206373068586, -1.091668462767552, -1.0123724693311402, -1e-09, -1e-06],
     [-0.47912400037246616, -1.709547708871876, 1.4700219972746527, -0.34004776473966425, 2.765187650695092, 0.44284314553185516, 1.1307662678711732]),
    # q0 at an interval's end where q1 crosses its limit steeply (4e-11 past: 0.36)
    ('panda', [-2.8973, -1e-06, -1e-09, -0.0698, -1e-06, 3.141592653589793, 2.895610808741878],
     [-2.926028799194581, -0.04251852787705909, 0.05909833800964482, 0.016781865321228495, 0.23733625239089184, 2.903725333930055, 2.857465629890354]),
    # a swing 9.8e-7..1e-6 off the shoulder's continuum (0.42 rad farther)
    ('panda', [1e-07, 1e-06, 1e-09, -2.8643460970567363, -0.21976607190717523, -1e-09, -1e-07],
     [0.5458720288719126, 0.6089057278143621, 0.29061494828594725, -1.9569999946357806, 0.49987564196786316, 2.580756878699669, -1.5063480431374354]),
]


@pytest.mark.parametrize("name,q0,q_near", SWINGS)
def test_next_to_a_swing_the_answer_is_never_farther_than_q0(name, q0, q_near):
    """Oracle: q0 (inside the limits) solves its pose, so the answer for q_near is never
    farther from q_near than q0 (1e-6), reaches the pose to 1e-12 inside the limits.
    Before: the SRS arm's answers 0.07-3.6 rad farther (one None: the manifold's only
    in-limit rows were two refined corners the searches skipped), the Panda's 0.015 and
    0.17 rad. What finds them (``nearer_points``): numeric solutions stalled 1e-11..1e-9
    off the pose finished by Newton's steps; rows past a limit slid back to it along
    the self-motion; the pose solved with an end joint held at q_near's value where no
    row at the aligned value was taken; the branches' aligned-axes rows moved along
    their continua; a row Newton cannot finish next to a swing replaced by an end
    joint's held closed form; the refined corners as candidates. Session 25: an
    interval's end row up to 1e-9 past a limit taken (clamped, then back onto the pose
    inside the limits); branch rows within 1e-4 of an aligned value moved along its
    continuum (``_SWING_ON``), the moved rows with another joint outside its limits
    left out before the nearest is picked, the intervals' end rows within
    ``_SWING_ON`` of an aligned value moved too."""
    robot = PANDA if name == "panda" else SRS
    q0, qn = np.array(q0), np.array(q_near)
    T = robot.fk(q0)
    bound = float(np.linalg.norm(wrap_angle(q0 - qn)))
    assert _checked(robot, T, qn, robot.self_motion(T).nearest(qn)) <= bound + 1e-6


@pytest.mark.parametrize("name", ["panda", "srs"])
def test_next_to_a_swing_one_ik_near_batch_is_never_farther_than_q0(name):
    """Oracle: q0, as above, for one ``ik_near(method="self_motion")`` batch of the
    arm's cases (the SRS arm's compiled path: its kernel's answers, then
    ``nearer_points`` without the branches' records)."""
    robot = PANDA if name == "panda" else SRS
    q0 = np.array([q for n, q, _ in SWINGS if n == name])
    qn = np.array([q for n, _, q in SWINGS if n == name])
    T = robot.fk(q0)
    got = robot.ik_near(T, qn, method="self_motion")
    assert got.success.all()
    for i in range(len(q0)):
        bound = float(np.linalg.norm(wrap_angle(q0[i] - qn[i])))
        assert _checked(robot, T[i], qn[i], got.q[i]) <= bound + 1e-6


def test_a_manifold_of_two_corner_points_gives_them_to_nearest_and_best():
    """Oracle: the refined corners. q0 (q2 at its limit, q4 = q5 = 1e-6 next to a
    stretched elbow) has two in-limit intervals, each a single point where two limits
    meet; the family's rows there are a hair outside a limit, so the searches on the
    intervals skipped them: ``nearest`` gave None from a uniform q_near and ``best``
    None while ``reachable`` was True. Now both return a corner's row (or a nearer
    solution), exact and inside the limits."""
    q0 = np.array([1.5707963267948966, -2.0943951023931953, 1e-09, 1e-06, 1e-06,
                   1.3615835734608837, -0.8747439136934774])
    T = SRS.fk(q0)
    sm = SRS.self_motion(T)
    assert len(sm.intervals) == 2 and (sm.intervals[:, 0] == sm.intervals[:, 1]).all()
    assert len(sm._corners) == 2 and sm.reachable
    corners = [row for _, _, row in sm._corners]
    qn = np.array([2.809104356850681, -1.2228517833453614, 2.8551489097964424,
                   1.159110874240441, 2.050547510610614, 0.15750589402126103,
                   2.898008408063772])
    d = _checked(SRS, T, qn, sm.nearest(qn))
    assert d <= min(float(np.linalg.norm(wrap_angle(c - qn))) for c in corners) + 1e-9
    best = sm.best("margin")
    _checked(SRS, T, q0, best)
    margin = [float(np.minimum(c - SRS.limits[:, 0], SRS.limits[:, 1] - c).min())
              for c in corners]
    assert best.score >= max(margin) - 1e-12


@pytest.mark.parametrize(("a", "b"), [(3, 5), (1, 3), (1, 5)])
def test_a_q_near_that_solves_the_pose_is_the_answer(a, b):
    """Oracle: q0 itself (inside the limits, FK(q0) = T): nothing is nearer.

    With two of q2, q4, q6 at 1e-5 (next to a swing: a branch's outer joints move
    ~1e5 times as fast as the swivel) the branch search stopped 1.4e-6..5.6e-6 from q0
    on 9 and 15 of 20 SRS poses (q4, q6 and q2, q4 at 1e-5; session 25's tables in
    docs/ik.md) and no nearer solution was looked for (q0's distance to
    the aligned values was above the answer's); now a q_near on its pose inside the
    limits is returned as it is, by ``nearest`` and by one ``ik_near`` batch.
    """
    rng = np.random.default_rng(3)
    Q = rng.uniform(0.8 * SRS.limits[:, 0], 0.8 * SRS.limits[:, 1], (8, 7))
    Q[:, a] = Q[:, b] = 1e-5
    T = SRS.fk(Q)
    for q0, Ti in zip(Q, T, strict=True):
        p = SRS.self_motion(Ti).nearest(q0)
        assert p is not None and np.array_equal(p.q, q0)
    got = SRS.ik_near(T, Q, method="self_motion")
    assert got.success.all() and np.array_equal(got.q, Q)
