"""IK with joints held at given values (issue 20, item 2): the Panda's redundancy."""

import numpy as np
import pytest

import robokin
from reference import pose_errors, rtb_iiwa14
from robokin.exceptions import InputError
from robokin.kinematics.ik import fixed as fixed_ik

Q0 = np.array([0.3, -0.5, 0.2, -2.0, 0.4, 1.6, 0.7])


def test_held_last_joint_solutions_reproduce_the_pose_and_hold_the_value():
    robot = robokin.load("panda")
    T = robot.fk(Q0)
    sols = robot.ik(T, fixed={"joint7": Q0[6]})
    assert "joint7 held" in sols.method
    assert len(sols) >= 1
    for q in sols:
        assert q[6] == Q0[6]
        dp, dr = pose_errors(robot.fk(q), T)
        assert dp < 1e-9 and dr < 1e-9
    assert any(np.allclose(q, Q0, atol=1e-6) for q in sols)


def test_a_sweep_of_the_held_value_is_a_batch():
    robot = robokin.load("panda")
    T = robot.fk(Q0)
    values = Q0[6] + np.linspace(-0.3, 0.3, 7)  # the self-motion near Q0
    sweep = robot.ik(T, fixed={"joint7": values})
    assert sweep.shape == (7,)
    ok = sweep.valid
    assert ok.any(axis=-1).sum() >= 3
    dp, dr = pose_errors(robot.fk(sweep.q[ok]), T)
    assert dp.max() < 1e-9 and dr.max() < 1e-9
    held = np.broadcast_to(values[:, None], ok.shape)[ok]
    np.testing.assert_array_equal(sweep.q[ok][:, 6], held)
    # the sweep equals held-value calls one at a time
    for i in (2, 5):
        one = robot.ik(T, fixed={"joint7": values[i]})
        np.testing.assert_array_equal(one.valid, sweep[i].valid)
        np.testing.assert_allclose(one.q[one.valid], sweep[i].q[sweep[i].valid],
                                   atol=1e-12)


def test_the_end_joint_shortcut_equals_a_reduced_chain_per_value():
    robot = robokin.load("panda")
    T = robot.fk(Q0)
    v = 0.9
    moved = fixed_ik._moved_targets(robot.arm, "last", T[None], np.array([v]))[0]
    reduced0 = robokin.Robot(fixed_ik._reduced(robot.arm, [6], (0.0,)).chain)
    reduced_v = robokin.Robot(fixed_ik._reduced(robot.arm, [6], (v,)).chain)
    q6 = np.array([0.1, 0.2, -0.3, -1.5, 0.5, 1.2])
    # the chain held at v reaches T_v(q6); the chain held at 0 reaches the moved target
    T_v = reduced_v.fk(q6)
    np.testing.assert_allclose(
        fixed_ik._moved_targets(robot.arm, "last", T_v[None], np.array([v]))[0],
        reduced0.fk(q6), atol=1e-12)
    # every solution of the chain held at v for T reaches the moved target at 0
    sols = reduced_v.ik(T)
    assert len(sols) >= 1
    for q in sols:
        np.testing.assert_allclose(reduced0.fk(q), moved, atol=1e-9)


def test_a_middle_joint_held():
    robot = robokin.load("panda")
    T = robot.fk(Q0)
    sols = robot.ik(T, fixed={"joint3": Q0[2]})
    assert len(sols) >= 1
    for q in sols:
        assert q[2] == Q0[2]
        dp, dr = pose_errors(robot.fk(q), T)
        assert dp < 1e-9 and dr < 1e-9


def test_with_fixed_folds_constant_joints_and_keeps_fk(rng):
    robot = robokin.load("panda")
    chain = robot.chain.with_fixed({2: 0.4, 6: -1.1})
    assert chain.n == chain.n_chain == 5
    q = rng.uniform(-1, 1, (20, 5))
    full = np.insert(np.insert(q, 2, 0.4, axis=1), 6, -1.1, axis=1)
    reduced = robokin.Robot(chain)
    np.testing.assert_allclose(reduced.fk(q), robot.fk(full), atol=1e-12)
    qf = robokin.load("qfmd010")  # dependent joints: the held value enters the offset
    red = qf.chain.with_fixed({0: 0.3})
    q3 = rng.uniform(-0.3, 0.3, (10, 3))
    np.testing.assert_allclose(robokin.Robot(red).fk(q3),
                               qf.fk(np.insert(q3, 0, 0.3, axis=1)), atol=1e-12)


def test_bad_held_joints_are_named():
    robot = robokin.load("panda")
    T = robot.fk(Q0)
    with pytest.raises(InputError, match="unknown joint 'j7'; joints: joint1"):
        robot.ik(T, fixed={"j7": 0.0})
    with pytest.raises(InputError, match="every joint is held"):
        robot.ik(T, fixed={n: 0.0 for n in robot.joint_names})
    with pytest.raises(InputError, match="fixed.*non-finite"):
        robot.ik(T, fixed={"joint7": np.nan})
    with pytest.raises(InputError, match="do not broadcast"):
        robot.ik(np.stack([T, T, T]), fixed={"joint7": [0.1, 0.2]})
    with pytest.raises(InputError, match="mapping"):
        robot.ik(T, fixed=["joint7"])
    with pytest.raises(InputError, match=r"fixed\['joint7'\].*expected a number"):
        robot.ik(T, fixed={"joint7": "a"})
    with pytest.raises(InputError, match=r"q_near.*\(3,\)"):
        robot.ik(T, fixed={"joint7": 0.7}, q_near=np.zeros(3))
    with pytest.raises(InputError, match=r"q_near.*does not broadcast"):
        robot.ik(T, fixed={"joint7": 0.7}, q_near=np.zeros((2, 7)))


def test_a_sweep_keeps_only_the_last_reduced_chains():
    robot = robokin.load("panda")
    T = robot.fk(Q0)
    values = Q0[2] + np.linspace(-0.2, 0.2, fixed_ik._REDUCED_KEPT + 4)
    sols = robot.ik(np.broadcast_to(T, (len(values), 4, 4)), fixed={"joint3": values})
    np.testing.assert_array_equal(sols.q[..., 2][sols.valid],
                                  np.broadcast_to(values[:, None], sols.valid.shape)[sols.valid])
    # a sweep of a middle joint builds one reduced arm per value; a bounded few stay
    kept = robot.arm.reduced
    assert len(kept) == fixed_ik._REDUCED_KEPT
    assert list(kept)[-1] == ((2,), (float(values[-1]),))


def test_panda_with_joint7_held_is_complete_against_a_numeric_reference():
    # every in-limit solution a dense multi-start finds on the remaining 6R chain is
    # among ours (general_6r), and the generating configuration always is
    from robokin.kinematics.ik import numeric

    robot = robokin.load("panda")
    rng = np.random.default_rng(3)
    lim = robot.limits
    reduced = fixed_ik._reduced(robot.arm, [6], (0.0,))
    for _ in range(3):
        q = rng.uniform(lim[:, 0], lim[:, 1])
        T = robot.fk(q)
        sols = robot.ik(T, fixed={"joint7": q[6]})
        assert sols.method == "analytic:pieper (joint7 held)"
        assert any(np.allclose(x, q, atol=1e-6) for x in sols)
        moved = fixed_ik._moved_targets(robot.arm, "last", T[None], np.array([q[6]]))[0]
        ref = numeric.solve_all(reduced, moved, n_seeds=1500,
                                rng=np.random.default_rng(0))
        ours = sols.q[sols.valid & sols.within_limits][:, :6]
        for r in ref.q[ref.valid]:
            assert np.abs(ours - r).max(axis=1).min() < 1e-6
        assert len(ours) == len(ref.q[ref.valid])


def test_readme_example_gives_back_the_configuration():
    # issue 23: the README's example returned 4 rows, none of them qp, all outside
    # the limits; the closed form must return qp and held.nearest(qp) must be qp
    panda = robokin.load("panda")
    qp = np.array([0.0, -0.3, 0.0, -2.0, 0.0, 1.8, 0.7])
    held = panda.ik(panda.fk(qp), fixed={"joint7": 0.7})
    assert held.method == "analytic:pieper (joint7 held)"
    assert held.info["held"] == {"joint7": 0.7}
    near = held.nearest(qp)
    np.testing.assert_allclose(near, qp, atol=1e-12)
    inside = held.q[held.valid & held.within_limits]
    assert np.abs(inside - qp).max(axis=1).min() <= 1e-12


def test_the_single_pose_path_equals_the_batch_and_a_sweep_equals_single_values():
    # the hot path (one pose, a number held) and the batch kernel give the same
    # rows, flags and slots; a sweep of a middle joint (joint 5, a new remaining
    # chain per value) equals one call per value
    panda = robokin.load("panda")
    rng = np.random.default_rng(11)
    lim = panda.limits
    q = rng.uniform(lim[:, 0], lim[:, 1], (40, 7))
    T = panda.fk(q)
    for j in (3, 4, 6):
        name = panda.joint_names[j]
        batch = panda.ik(T, fixed={name: q[:, j]})
        for i in range(0, 40, 7):
            one = panda.ik(T[i], fixed={name: float(q[i, j])})
            np.testing.assert_array_equal(one.valid, batch[i].valid)
            np.testing.assert_array_equal(one.q, batch[i].q)
            np.testing.assert_array_equal(one.singular, batch[i].singular)
    values = q[0, 4] + np.linspace(-0.2, 0.2, 9)
    sweep = panda.ik(T[0], fixed={"joint5": values})
    assert sweep.shape == (9,)
    for i, v in enumerate(values):
        one = panda.ik(T[0], fixed={"joint5": float(v)})
        np.testing.assert_array_equal(one.q, sweep[i].q)


def test_held_closed_form_passes_q_near_and_compute_error():
    panda = robokin.load("panda")
    T = panda.fk(Q0)
    sols = panda.ik(T, fixed={"joint7": Q0[6]}, q_near=Q0, compute_error=True)
    assert sols.method == "analytic:pieper (joint7 held)"
    assert np.all(sols.error[sols.valid] <= 1e-12)
    np.testing.assert_allclose(sols.nearest(Q0), Q0, atol=1e-12)
    # the numeric method still goes the reduced-chain way
    num = panda.ik(T, fixed={"joint7": Q0[6]}, method="numeric")
    assert "held" in num.method and "pieper" not in num.method


@pytest.mark.parametrize("eps", [1e-12, 1e-9])
def test_held_closed_form_solves_a_pose_rounded_off_so3(eps):
    """A rotation orthonormal to ~eps only (a pose read to 12 digits) is solved.

    Oracle: Q0 (whose FK the pose is, before the rounding) among the solutions,
    every solution's FK within ~eps of the pose. The held closed form accepts 4e-13
    pose error only, so before check_rigid it returned no solution.
    """
    robot = robokin.load("panda")
    T = robot.fk(Q0)
    T[:3, :3] *= 1 - eps
    sols = robot.ik(T, fixed={"joint7": Q0[6]})
    assert "joint7 held" in sols.method and len(sols) >= 1
    for q in sols:
        dp, dr = pose_errors(robot.fk(q), T)
        assert dp < 1e-11 and dr < 2 * eps + 1e-11
    assert any(np.allclose(q, Q0, atol=1e-8) for q in sols)


def test_the_one_pose_hot_path_equals_the_general_path_at_special_values():
    """``robot.ik(T, fixed={name: x})`` (the hot path) == the checked batch path.

    Oracle: the same pose solved as a batch of one with the value as an array (the
    general path: ``check_rigid``, the batch kernel) gives the same rows, flags,
    slots, status and method, bit for bit, on configurations drawn from the special
    values (0, +-pi/2, pi, 1e-9..1e-6, the limits) and uniform ones; and the
    generating configuration is among the rows wherever the 6 x 6 Jacobian is
    non-singular.
    """
    from special_values import draw_configurations

    panda = robokin.load("panda")
    q = draw_configurations(panda, np.random.default_rng(23), 60)
    T = panda.fk(q)
    for j in (3, 5, 6):
        name = panda.joint_names[j]
        for i in range(len(q)):
            one = panda.ik(T[i], fixed={name: float(q[i, j])})
            ref = panda.ik(T[i][None], fixed={name: q[i:i + 1, j]})[0]
            for a, b in [(one.q, ref.q), (one.valid, ref.valid),
                         (one.within_limits, ref.within_limits),
                         (one.singular, ref.singular), *((one.branches[k], ref.branches[k])
                                                         for k in ref.branches)]:
                np.testing.assert_array_equal(a, b)
            assert one.status == ref.status and one.method == ref.method
            assert one.info["held"] == {name: float(q[i, j])}
            J = np.delete(panda.jacobian(q[i]), j, axis=1)
            if np.linalg.svd(J, compute_uv=False)[-1] > 1e-4:
                gap = np.abs((one.q[one.valid] - q[i] + np.pi) % (2 * np.pi) - np.pi)
                assert gap.max(axis=1).min() < 1e-8, (name, q[i])


def test_the_one_pose_hot_path_takes_no_detour():
    """One pose, one joint held at a number: six Python frames, no re-dispatch.

    Oracle: the Python functions entered during the call (``sys.setprofile``). The
    path went robot.ik -> dispatch.solve -> solve_fixed -> arm_of -> ... (10 frames,
    2.5 us of the 5.3-5.6 us call on the developers' machine); now robot.ik goes to
    ``solve_held_single`` directly. A bad argument still takes the checked path
    (``test_bad_held_joints_are_named``).
    """
    import sys

    panda = robokin.load("panda")
    T = panda.fk(Q0)
    panda.ik(T, fixed={"joint7": Q0[6]})  # set-up on first use
    entered: list[str] = []

    def profile(frame, event, arg):
        if event == "call":
            entered.append(frame.f_code.co_name)

    sys.setprofile(profile)
    try:
        sols = panda.ik(T, fixed={"joint7": Q0[6]})
    finally:
        sys.setprofile(None)
    assert sols.method == "analytic:pieper (joint7 held)" and len(sols) >= 1
    assert "solve" not in entered and "solve_fixed" not in entered, entered
    assert len(entered) <= 6, entered


def test_held_joint_at_a_stretched_elbow_near_srs_arm():
    # Issue 29's 10,000-configuration measurement (benchmarks/self_motion_rates.py,
    # seed 0): the rtb-data iiwa14 (shoulder offset 0.44 mm), joint_a3 held, q4 =
    # -1e-9 (the elbow stretched) and q2 = pi: 'out of reach', no row, although the
    # six free joints' Jacobian is regular (smallest singular value 1.7e-4 >= 1e-4:
    # q is an isolated solution). 5 of 3,401 regular special configurations miss
    # this way. Both conditions are needed (q2 = pi with a bent elbow, or the elbow
    # stretched with q2 = 1 or 3, return q): the wrist centre at the held chain's
    # reach boundary and within the 0.44 mm offset of axis 1. Oracle: q reproduces the pose (it generated it) and is isolated, so
    # it must be among the rows (1e-6 rad), each of which reproduces the pose to 1e-12.
    # Cause (pieper.c pk_general): elimination determinant 2.5e-10, |u_y| - 1 = 1.2e-5
    # at both quartic roots, dropped by a fixed 1e-6 unit check (now scale-aware).
    robot = rtb_iiwa14()
    q = np.array([-np.pi / 2, np.pi, -1e-07, -1e-09, -2.9668, -0.47755672126856075,
                  2.4839344482487373])
    sigma = np.linalg.svd(np.delete(robot.jacobian(q), 2, axis=1), compute_uv=False)[-1]
    assert sigma >= 1e-4
    T = robot.fk(q)
    sols = robot.ik(T, fixed={"joint_a3": q[2]})
    Q = sols.q[sols.valid]
    if len(Q):
        dp, dr = pose_errors(robot.fk(Q), T)
        assert dp.max() <= 1e-12 and dr.max() <= 1e-12
    assert len(Q) and np.abs((Q - q + np.pi) % (2 * np.pi) - np.pi).max(-1).min() <= 1e-6


def test_held_wrist_joint_at_a_stretched_elbow_keeps_every_cluster_member():
    # Found in the A/B of helper srs29 (2,000 uniform + 2,000 special configurations
    # per held joint of the rtb-data iiwa14): joint_a5 held, q1 and q4 = 1e-9 (the
    # elbow stretched), the six free joints' Jacobian regular (smallest singular
    # value 1.7e-4 >= 1e-4: q is isolated), 1 of 3,688 regular configurations. The
    # general 6R solver returned 7 exact rows, three of them within 2.1e-3 rad of q
    # (q4 = 1e-9 or -2.08e-3): q's own root of the elimination was lost in that
    # cluster; general6r.c's g6_reseed (mirrored starts) brings it back. Oracle: q generated the pose and is isolated, so it is among the rows
    # (1e-6 rad), each of which reproduces the pose to 1e-12.
    robot = rtb_iiwa14()
    q = np.array([1e-09, 1.6343262323207903, 1.5648106360498533, 1e-09,
                  -np.pi / 2, np.pi / 2, -1e-07])
    sigma = np.linalg.svd(np.delete(robot.jacobian(q), 4, axis=1), compute_uv=False)[-1]
    assert sigma >= 1e-4
    T = robot.fk(q)
    sols = robot.ik(T, fixed={"joint_a5": q[4]})
    Q = sols.q[sols.valid]
    dp, dr = pose_errors(robot.fk(Q), T)
    assert len(Q) and dp.max() <= 1e-12 and dr.max() <= 1e-12
    assert np.abs((Q - q + np.pi) % (2 * np.pi) - np.pi).max(-1).min() <= 1e-6


def test_the_short_axis_all_equals_numpys():
    # fixed._all_last (the end sweep's limit flags, issue 29) against bool.all(-1)
    rng = np.random.default_rng(4)
    for shape in ((6, 8, 7), (13, 7), (3, 1)):
        b = rng.random(shape) < 0.9
        np.testing.assert_array_equal(fixed_ik._all_last(b), b.all(-1))
    b = np.ones((4, 5, 7), bool)
    b[1, 2, 6] = False
    out = fixed_ik._all_last(b)
    assert out.sum() == 19 and not out[1, 2]


def test_solve_held_one_gives_solve_fixeds_rows_bit_for_bit():
    # Issue 29 (helper iiwapy30): the self-motion's exact points solve the pose with
    # each joint at its limits; a middle joint without a held closed form (the offset
    # iiwa's a5 and a6) is solved by its reduced chain's general 6R kernel directly
    # (fixed.MidHeld). Oracle: solve_fixed's whole path, q, valid, singular and
    # within_limits bit for bit; every valid row reproduces T (1e-10) with the joint
    # at its value, and the generating configuration is a row at its own value.
    from reference import offset_iiwa14
    from robokin._validation import check_rigid
    from robokin.kinematics.ik import dispatch

    robot = offset_iiwa14()
    arm = robot.arm
    rng = np.random.default_rng(7)
    lim = arm.limits
    lean = 0
    for q0 in rng.uniform(lim[:, 0], lim[:, 1], (4, 7)):
        T = check_rigid(robot.fk(q0), "T")
        for j in (4, 5, 6, 1):  # 6: an end joint; 1: a held closed form (a2)
            name = arm.joint_names[j]
            for v in (float(lim[j, 0]), float(lim[j, 1]), float(q0[j])):
                got = fixed_ik.solve_held_one(arm, T, j, v, dispatch=dispatch.solve)
                want = fixed_ik.solve_fixed(arm, T, {name: v}, dispatch=dispatch.solve)
                np.testing.assert_array_equal(got.q.view(np.int64), want.q.view(np.int64))
                for key in ("valid", "singular", "within_limits"):
                    np.testing.assert_array_equal(getattr(got, key), getattr(want, key))
                lean += arm.derived(fixed_ik.MID_HELD).get((j, v)) is not None
                rows = got.q[got.valid]
                assert np.all(rows[:, j] == v)
                dp, dr = pose_errors(robot.fk(rows), T)
                assert max(dp.max(initial=0.0), dr.max(initial=0.0)) <= 1e-10
                if v == q0[j]:  # (at a limit the pose may have no row)
                    gap = np.abs((rows - q0 + np.pi) % (2 * np.pi) - np.pi).max(axis=-1)
                    assert gap.min() < 1e-8
    assert lean == 4 * 2 * 3  # a5 and a6 took the lean path at every value
