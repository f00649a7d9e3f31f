"""The ``pieper`` closed form on 6R chains (issue 23, item 6).

Oracles: forward kinematics of every returned row against the pose (1e-12), the
generating configuration among the rows, numpy's companion-matrix roots for the
quartic solver, and a dense numeric multi-start for completeness.
"""

from __future__ import annotations

import numpy as np
import pytest

import robokin
from reference import pose_errors, rtb_iiwa14
from robokin._native import kernels as K
from robokin.kinematics.ik import numeric
from robokin.kinematics.ik.analytic import pieper


def shoulder_arm() -> robokin.Robot:
    """A 6R arm whose axes 1-3 meet (the Panda's first six joints, joint 7 at 0.4)."""
    panda = robokin.load("panda")
    return robokin.Robot(panda.chain.with_fixed({6: 0.4}), name="panda-6")


def wrist_arm() -> robokin.Robot:
    """A 6R arm with a spherical wrist and skew axes 2, 3 (not ``spherical_wrist``)."""
    rows = [{"a": 0.05, "alpha": np.pi / 2, "d": 0.4, "theta": 0.0},
            {"a": 0.45, "alpha": 0.3, "d": 0.05, "theta": 0.2},
            {"a": 0.03, "alpha": np.pi / 2, "d": 0.02, "theta": 0.0},
            {"a": 0.0, "alpha": -np.pi / 2, "d": 0.42, "theta": 0.0},
            {"a": 0.0, "alpha": np.pi / 2, "d": 0.0, "theta": 0.0},
            {"a": 0.0, "alpha": 0.0, "d": 0.08, "theta": 0.0}]
    for r in rows:
        r["limits"] = [-np.pi, np.pi]
    return robokin.Robot.from_dh(rows, convention="standard", name="skew-wrist")


@pytest.mark.parametrize("make", [shoulder_arm, wrist_arm])
def test_detected_and_complete_on_6r_arms(make, rng):
    robot = make()
    fam = robokin.ik.family(robot)
    assert fam.name == "pieper", str(fam)
    q = rng.uniform(-np.pi, np.pi, (200, 6))
    T = robot.fk(q)
    sols = robot.ik(T)
    assert sols.method == "analytic:pieper"
    Q = sols.q[sols.valid]
    dp, dr = pose_errors(robot.fk(Q), np.broadcast_to(T[:, None], sols.q.shape[:2] + (4, 4))
                         [sols.valid])
    assert dp.max() <= 1e-12 and dr.max() <= 1e-12
    gap = np.abs((sols.q - q[:, None] + np.pi) % (2 * np.pi) - np.pi).max(axis=-1)
    assert np.where(sols.valid, gap, np.inf).min(axis=-1).max() <= 1e-6
    # the single-pose hot path equals the batch
    one = robot.ik(T[3])
    np.testing.assert_array_equal(one.q, sols[3].q)


def test_every_solution_a_dense_numeric_search_finds_is_returned():
    robot = wrist_arm()
    rng = np.random.default_rng(5)
    for _ in range(3):
        q = rng.uniform(-np.pi, np.pi, 6)
        T = robot.fk(q)
        ours = robot.ik(T)
        ref = numeric.solve_all(robot, T, n_seeds=800, rng=np.random.default_rng(0))
        mine = ours.q[ours.valid]
        for r in ref.q[ref.valid]:
            gap = np.abs((mine - r + np.pi) % (2 * np.pi) - np.pi).max(axis=1)
            assert gap.min() < 1e-6


def test_quartic_roots_match_numpy(rng):
    # random quartics, biquadratics, double roots and a root at zero
    cases = [rng.normal(size=5) for _ in range(200)]
    cases += [np.array([4.0, 0.0, -5.0, 0.0, 1.0]), np.array([1.0, -2.0, 1.0, 0.0, 0.0])[::-1]
              + np.array([0, 0, 0, 0, 1.0]), np.poly([1.0, 1.0, -2.0, 3.0])[::-1],
              np.poly([0.0, 0.5, -0.5, 2.0])[::-1]]
    for c in cases:
        c = np.ascontiguousarray(c, dtype=float)
        if c[4] == 0.0:
            continue
        re, im = np.zeros(4), np.zeros(4)
        K.pieper_roots(c, re, im)
        ours = np.sort_complex(re + 1j * im)
        ref = np.sort_complex(np.roots(c[::-1]))
        scale = 1.0 + np.abs(ref).max()
        # each reference root has one of ours nearby (double roots: to sqrt(eps))
        for r in ref:
            assert np.abs(ours - r).min() <= 1e-6 * scale


def test_setup_says_why_not():
    ur5 = robokin.load("ur5")
    s = pieper.setup(ur5.chain)
    assert s.params is None and "no three consecutive axes meet" in s.reason
    panda = robokin.load("panda")
    assert pieper.setup(panda.chain).params is None  # 7 joints, none held
    s = pieper.setup(panda.chain, 0)  # joint 1 held: no triple left
    assert s.params is None and "no three consecutive axes meet" in s.reason
    s = pieper.setup(panda.chain, 6)
    assert s.params is not None and s.measured.startswith("axes 1-3 meet")


def test_bad_poses_and_values_take_the_checked_path():
    from robokin.exceptions import InputError

    panda = robokin.load("panda")
    T = panda.fk(np.array([0.1, -0.3, 0.2, -2.0, 0.3, 1.8, 0.7]))
    bad = T.copy()
    bad[0, 0] += 0.1
    with pytest.raises(InputError):
        panda.ik(bad, fixed={"joint7": 0.7})
    with pytest.raises(InputError, match="non-finite"):
        panda.ik(T, fixed={"joint7": float("nan")})
    with pytest.raises(InputError):
        panda.ik(T.astype(np.float32), fixed={"joint7": True})


def test_held_slots_continue_through_an_incidental_coplanar_value():
    # Issue 29 (helper slots29): with joint_a3 held, axes 2 and 4 of the rtb-data
    # iiwa14 are parallel at joint_a3 = 0 only (mutual moment 0.32 * joint_a3), where
    # the front took the coplanar solver, which numbers its roots otherwise than the
    # quartic at every other value: at 0 each slot held another configuration.
    # benchmarks/self_motion_rates.py seed 0, #5180. Oracles: FK, and the rows either
    # side (the quartic's), slot for slot.
    robot = rtb_iiwa14()
    q0 = np.array([0.9189737939132052, 1.5707963267948966, 1e-09, -1.3206728674132546,
                   -1.4343752253433877, -1.5707963267948966, -3.0541])
    T = robot.fk(q0)
    x = np.array([-1e-12, 0.0, 1e-12])
    sols = robot.ik(np.broadcast_to(T, (3, 4, 4)), fixed={"joint_a3": x})
    assert sols.valid.all()
    dp, dr = pose_errors(robot.fk(sols.q), np.broadcast_to(T, (3, 8, 4, 4)))
    assert dp.max() <= 1e-12 and dr.max() <= 1e-12
    assert np.abs(sols.q[1] - sols.q[0]).max() < 1e-9
    assert np.abs(sols.q[1] - sols.q[2]).max() < 1e-9
    q_at = q0.copy()
    q_at[2] = 0.0  # q0 moved along its branch by 1e-9 of joint_a3: within 1e-8
    assert np.abs(sols.q[1] - q_at).max(axis=-1).min() < 1e-8


def test_held_slots_keep_a_root_at_the_quartics_shift():
    # Issue 29 (helper slots29): the elbow stretched (q4 = 0, a near-double root of
    # the quartic in q4) sits at the shift the roots were numbered from; rounding put
    # it at +-1e-11 and its rows changed slots from one value of joint_a3 to the next
    # (1e-9 apart). Numbered from the shift + pi (where |f| is the largest sample) the
    # slot of q0's branch is the same at every value. Seed 0, #5113.
    robot = rtb_iiwa14()
    q0 = np.array([2.5356556953167813, -2.0942, -1e-07, 0.0, -1.160102486027724, -2.0942,
                   -3.0398026574264643])
    T = robot.fk(q0)
    x = q0[2] + 1e-9 * np.arange(-5, 6)
    sols = robot.ik(np.broadcast_to(T, (len(x), 4, 4)), fixed={"joint_a3": x})
    gap = np.where(sols.valid, np.abs(sols.q - q0).max(axis=-1), np.inf)
    assert gap.min(axis=-1).max() < 1e-7
    assert len(set(np.argmin(gap, axis=-1).tolist())) == 1
    ok = sols.valid
    dp, dr = pose_errors(robot.fk(sols.q[ok]), np.broadcast_to(T, (int(ok.sum()), 4, 4)))
    assert dp.max() <= 1e-12 and dr.max() <= 1e-12
