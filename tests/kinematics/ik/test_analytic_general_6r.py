"""The general 6R solver (issues 20, 23): completeness against an independent
multi-start reference, the generating configuration at special joint values
(hypothesis), FK round trips to 1e-12, batches, threads, the root finder, bad input."""

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

import robokin
from robokin import _native
from robokin.exceptions import InputError
from robokin.kinematics.ik import numeric
from robokin.kinematics.ik.analytic import general_6r
from robokin.kinematics.ik.analytic._common import fk_error
from robokin.kinematics.ik.analytic.detect import detect
from robokin.kinematics.jacobian import min_singular_value

K = _native.kernels
IRB140 = Path(__file__).parents[2] / "data" / "urdf" / "irb140.urdf"
MATCH_TOL = 1e-5  # [rad] same solution (a near-singular numeric one is this loose)


# ----------------------------------------------------------------------- arms
def random_dh_arm(rng, name="random_6r"):
    rows = [{"joint": "revolute", "a": rng.uniform(-0.5, 0.5), "d": rng.uniform(-0.5, 0.5),
             "alpha": rng.uniform(-np.pi, np.pi), "theta": rng.uniform(-np.pi, np.pi),
             "limits": [-np.pi, np.pi]} for _ in range(6)]
    return robokin.Robot.from_dh(rows, name=name)


def ur_twisted(twist=0.05, offset=0.02):
    """UR5's DH table with a twisted forearm (alpha_3 = twist) and the wrist offset
    by ``offset`` along a_5: no closed form applies."""
    rows = [{"d": 0.089159, "alpha": math.pi / 2}, {"a": -0.425},
            {"a": -0.39225, "alpha": twist}, {"d": 0.10915, "alpha": math.pi / 2},
            {"d": 0.09465, "a": offset, "alpha": -math.pi / 2}, {"d": 0.0823}]
    for r in rows:
        r.setdefault("a", 0.0)
        r.setdefault("d", 0.0)
        r.setdefault("alpha", 0.0)
        r.update(joint="revolute", theta=0.0, limits=[-2 * np.pi, 2 * np.pi])
    return robokin.Robot.from_dh(rows, name="ur5_twisted")


def irb140():
    return robokin.Robot.from_urdf(IRB140, geometry=False)


def open_limits(robot):
    """The same arm with every joint in [-pi, pi] (the reference searches all of them)."""
    chain = robot.chain
    joints = tuple(dataclasses.replace(j, limits=(-np.pi, np.pi)) for j in chain.joints)
    return robot.replace(chain=chain.replace(joints=joints, coordinates=joints))


# ------------------------------------------------------------------- helpers
def wrapped(d):
    return (d + np.pi) % (2 * np.pi) - np.pi


def not_in(a, b, tol=MATCH_TOL):
    """Rows of a (k, 6) with no row of b within tol (angles modulo 2 pi)."""
    if len(b) == 0:
        return a
    d = np.abs(wrapped(a[:, None, :] - b[None, :, :])).max(axis=-1)
    return a[(d >= tol).all(axis=1)]


def multistart_reference(robot, T, seed, n_seeds=800):
    """Distinct solutions that dense LM descents from random starts reach."""
    ref = numeric.solve_all(open_limits(robot), T, n_seeds=n_seeds,
                            rng=np.random.default_rng(seed))
    return ref.q[ref.valid]


def assert_round_trip(robot, T, sols, tol=1e-9):
    """Every valid row reproduces its pose to tol (m and rad entries of the 4x4)."""
    q = sols.q[sols.valid]
    Tb = np.broadcast_to(T[..., None, :, :], sols.q.shape[:-1] + (4, 4))[sols.valid]
    err = np.abs(robot.fk(q) - Tb).max(axis=(-2, -1)) if len(q) else np.zeros(0)
    assert (err < tol).all(), err.max()


def assert_generating_found(q, sols, tol=1e-6):
    gap = np.where(sols.valid, np.abs(wrapped(sols.q - q[:, None, :])).max(axis=-1),
                   np.inf).min(axis=-1)
    assert (gap < tol).all(), np.flatnonzero(gap >= tol)


# -------------------------------------------------------------- completeness
@pytest.mark.parametrize(
    ("arm", "seed"),
    [("random", 1), ("random", 2), ("random", 3), ("irb140", 4), ("ur_twisted", 5)],
)
def test_every_solution_of_a_dense_multistart_and_no_other(arm, seed):
    rng = np.random.default_rng(seed)
    robot = {"random": lambda: random_dh_arm(rng), "irb140": irb140,
             "ur_twisted": ur_twisted}[arm]()
    assert robokin.ik.family(robot).name == "general_6r"
    for k in range(2):
        q = rng.uniform(-np.pi, np.pi, 6)
        T = robot.fk(q)
        sols = robot.ik(T)
        assert sols.method == "general_6r"
        ours = sols.solutions()
        ref = multistart_reference(robot, T, seed=10 * seed + k)
        assert len(ref) >= 1
        assert len(not_in(ref, ours)) == 0, "missing solutions"
        assert len(not_in(ours, ref)) == 0, "solutions the reference does not have"
        assert_round_trip(robot, T, sols)


@pytest.mark.parametrize("name", ["ur5", "puma560"])
def test_exact_family_arms_give_the_closed_form_sets(name):
    # an independent oracle: on arms with a closed form the elimination (forced)
    # must give the closed form's solutions, away from the wrist singularity
    robot = robokin.load(name)
    rng = np.random.default_rng(8)
    q = rng.uniform(-np.pi, np.pi, (60, 6))
    q[:, 4] = rng.uniform(0.3, 2.8, 60) * rng.choice([-1, 1], 60)
    T = robot.fk(q)
    ours = general_6r.solve(robot, T)
    closed = robot.ik(T)
    assert closed.method.startswith("analytic:")
    for i in range(len(q)):
        a, b = ours.q[i][ours.valid[i]], closed.q[i][closed.valid[i]]
        assert len(not_in(a, b)) == 0 and len(not_in(b, a)) == 0, i


def test_generating_configuration_always_found_and_round_trip():
    for robot in (irb140(), ur_twisted(), random_dh_arm(np.random.default_rng(11))):
        rng = np.random.default_rng(12)
        q = rng.uniform(-np.pi, np.pi, (400, 6))
        T = robot.fk(q)
        sols = robot.ik(T)
        assert (sols.status == "ok").all()
        assert sols.q.shape == (400, 16, 6)
        assert (sols.count <= 16).all()
        assert_round_trip(robot, T, sols)
        assert_generating_found(q, sols)
        # distinct modulo 2 pi
        for i in range(0, 400, 37):
            s = sols[i].solutions()
            d = np.abs(wrapped(s[:, None] - s[None])).max(-1)
            assert (d[~np.eye(len(s), dtype=bool)] > 1e-6).all()


def test_near_family_arm_is_solved_at_least_as_completely_as_its_closed_form():
    # a calibrated UR5 (the near-family test's arm): general_6r by default; it has
    # every solution the nominal closed form + Newton finds
    rows = [{"a": 0, "alpha": math.pi / 2, "d": 0.089159},
            {"a": -0.425, "alpha": 0, "d": 0}, {"a": -0.39225, "alpha": 0, "d": 0},
            {"a": 0, "alpha": math.pi / 2, "d": 0.10915},
            {"a": 0, "alpha": -math.pi / 2, "d": 0.09465},
            {"a": 0, "alpha": 0, "d": 0.0823}]
    rng = np.random.default_rng(5)
    for row in rows:
        row["alpha"] += rng.normal(0, 1e-3)
        row["theta"] = rng.normal(0, 1e-3)
    robot = robokin.Robot.from_dh(rows, name="ur5_calibrated")
    assert robokin.ik.family(robot).name == "general_6r"
    near = detect(robot, general_6r=False)
    assert near.near and near.name == "three_parallel"
    q = rng.uniform(-np.pi, np.pi, (200, 6))
    T = robot.fk(q)
    ours, theirs = robot.ik(T), near.solver(robot, T)
    assert_generating_found(q, ours)
    for i in range(200):
        assert len(not_in(theirs.q[i][theirs.valid[i]], ours.q[i][ours.valid[i]])) == 0


# ------------------------------------------------------- batches and threads
def test_batch_equals_loop_of_single_calls():
    robot = irb140()
    rng = np.random.default_rng(21)
    q = rng.uniform(-np.pi, np.pi, (2, 20, 6))
    T = robot.fk(q)
    batch = robot.ik(T)
    assert batch.shape == (2, 20)
    for i in range(2):
        for j in range(20):
            one = robot.ik(T[i, j])
            np.testing.assert_array_equal(one.valid, batch.valid[i, j])
            np.testing.assert_array_equal(one.q, batch.q[i, j])
            np.testing.assert_array_equal(one.singular, batch.singular[i, j])


def test_thread_count_does_not_change_results():
    robot = ur_twisted()
    T = robot.fk(np.random.default_rng(22).uniform(-np.pi, np.pi, (300, 6)))
    before = _native.num_threads()
    try:
        _native.set_num_threads(1)
        one = general_6r.solve(robot, T, parallel=True)
        _native.set_num_threads(2)
        two = general_6r.solve(robot, T, parallel=True)
        serial = general_6r.solve(robot, T, parallel=False)
    finally:
        _native.set_num_threads(before)
    for other in (two, serial):
        np.testing.assert_array_equal(one.valid, other.valid)
        np.testing.assert_array_equal(one.q, other.q)


# ---------------------------------------------------------- flags and order
def test_singular_flag_is_the_jacobians_smallest_singular_value():
    robot = irb140()
    T = robot.fk(np.random.default_rng(23).uniform(-np.pi, np.pi, (100, 6)))
    tol = 0.05  # large enough that some solutions are flagged
    sols = general_6r.solve(robot, T, singular_tol=tol)
    q = sols.q[sols.valid]
    smin = np.linalg.svd(robot.jacobian(q), compute_uv=False)[:, -1]
    flagged = sols.singular[sols.valid]
    clear = np.abs(smin - tol) > 1e-6 * tol
    assert flagged.any() and not flagged.all()
    np.testing.assert_array_equal(flagged[clear], smin[clear] < tol)
    assert not sols.singular[~sols.valid].any()


def test_limits_q_near_and_the_single_pose_path():
    robot = irb140()  # joints 2, 3, 5 narrower than a turn, joints 4, 6 wider
    rng = np.random.default_rng(24)
    q = rng.uniform(-np.pi, np.pi, (40, 6))
    T = robot.fk(q)
    sols = robot.ik(T)
    lim = robot.limits
    inside = ((sols.q >= lim[:, 0] - 1e-9) & (sols.q <= lim[:, 1] + 1e-9)).all(-1)
    np.testing.assert_array_equal(sols.flags["within_limits"], inside & sols.valid)
    assert inside.any() and not inside[sols.valid].all()
    # revolute values in [-pi, pi) unless a whole turn puts them into the limits
    shifted = (sols.q < -np.pi) | (sols.q >= np.pi)
    assert not (shifted & ~inside[..., None])[sols.valid].any()
    # q_near changes nothing: the solutions are isolated (SolutionSet.nearest picks)
    near = robot.ik(T, q_near=q)
    np.testing.assert_array_equal(near.q, sols.q)
    np.testing.assert_allclose(wrapped(near.nearest(q, respect_limits=False) - q), 0.0,
                               atol=1e-7)
    # the single-pose path gives the batch's rows
    for i in range(0, 40, 7):
        one = robot.ik(T[i])
        assert one.method == "general_6r" and one.shape == ()
        np.testing.assert_array_equal(one.q, sols.q[i])
        np.testing.assert_array_equal(one.flags["within_limits"],
                                      sols.flags["within_limits"][i])
        assert one.status == sols.status[i]


def test_unreachable_pose_has_no_solution_and_says_so():
    robot = ur_twisted()
    far = np.eye(4)
    far[:3, 3] = [3.0, 0.0, 0.0]
    sols = robot.ik(np.stack([far, robot.fk(np.zeros(6))]))
    assert sols.count[0] == 0 and sols.count[1] >= 1
    assert sols.status[0] == "out of reach" and sols.status[1] == "ok"


# ------------------------------------------------------------- root finder
def _match(a, b):
    return np.abs(a[:, None] - b[None, :]).min(axis=1).max()


def test_polynomial_roots_agree_with_numpy():
    rng = np.random.default_rng(31)
    for _ in range(300):
        deg = int(rng.integers(1, 17))
        c = rng.normal(size=deg + 1)
        wr, wi = np.empty(deg), np.empty(deg)
        assert K.general6r_roots(c, wr, wi)
        ours, ref = wr + 1j * wi, np.roots(c[::-1])
        tol = 1e-7 * (1.0 + np.abs(ref).max())
        assert _match(ours, ref) < tol and _match(ref, ours) < tol
        # conjugate pairs stay pairs
        np.testing.assert_allclose(np.sort_complex(ours), np.sort_complex(ours.conj()))


def test_clustered_roots_as_accurate_as_numpy():
    # a cluster of three within 1e-4 and a complex pair: ill-conditioned roots whose
    # errors depend on rounding; over many polynomials ours are LAPACK's size
    rng = np.random.default_rng(32)
    ours_err, np_err = [], []
    for _ in range(400):
        deg = int(rng.integers(5, 17))
        r = rng.normal(size=deg).astype(complex)
        r[1:3] = r[0] + 1e-4 * rng.normal(size=2)
        r[3] = complex(rng.normal(), 2.0)
        r[4] = r[3].conjugate()
        c = np.real(np.poly(r))[::-1].copy()
        wr, wi = np.empty(deg), np.empty(deg)
        assert K.general6r_roots(c, wr, wi)
        ours, ref = wr + 1j * wi, np.roots(c[::-1])
        ours_err.append(max(_match(r, ours), _match(ours, r)))
        np_err.append(max(_match(r, ref), _match(ref, r)))
    assert np.median(ours_err) < 2 * np.median(np_err)
    assert max(ours_err) < 2 * max(np_err)


def test_polynomial_roots_of_an_even_polynomial_with_double_roots():
    # the determinant of a spherical-wrist arm's split: every root double and +-
    # paired, which stalls EISPACK's original exceptional shifts
    r = np.array([0.47, 0.55 + 0.36j, 0.55 - 0.36j, 1.14 + 0.56j, 1.14 - 0.56j, 1.8])
    r = np.concatenate([r, -r])
    c = np.real(np.poly(np.repeat(r, 2)))[::-1].copy()
    wr, wi = np.empty(24), np.empty(24)
    assert K.general6r_roots(c, wr, wi)
    assert _match(r, wr + 1j * wi) < 1e-5


# ------------------------------------------------------------------- errors
def test_prismatic_and_dependent_joints_are_not_offered():
    rows = [{"joint": "revolute", "a": 0.1, "alpha": 0.5, "d": 0.1}] * 5 + [
        {"joint": "prismatic", "a": 0.0, "alpha": 0.0, "theta": 0.3, "limits": [0, 1]}]
    robot = robokin.Robot.from_dh(rows)
    fam = robokin.ik.family(robot)
    assert fam.name == "none" and "prismatic" in fam.reason
    assert "revolute" in general_6r.why_not(robot.chain)
    with pytest.raises(InputError, match="robot.*prismatic"):
        general_6r.solve(robot, robot.fk(np.full(6, 0.2)))
    panda = robokin.load("panda")
    assert "six joints" in general_6r.why_not(panda.chain)


def test_degenerate_arm_is_not_offered_and_says_why():
    # axes 3 and 4 on one line (a = 0, alpha = 0, the offset along the axis): the
    # Jacobian has rank 5 everywhere, every pose has infinitely many solutions. The
    # family is refused with that reason, and robot.ik says it fell back to numeric.
    h = math.pi / 2
    rows = [{"a": 0.0, "d": -0.285, "alpha": -h, "theta": 2.35},
            {"a": -0.368, "d": 0.445, "alpha": 0.4381, "theta": -2.228},
            {"a": 0.0, "d": 0.052, "alpha": 0.0, "theta": 2.413},
            {"a": 0.07, "d": 0.0, "alpha": -h, "theta": -1.637},
            {"a": 0.0, "d": -0.032, "alpha": -h, "theta": 1.579},
            {"a": 0.0, "d": 0.0, "alpha": 0.0, "theta": -2.369}]
    robot = robokin.Robot.from_dh(rows)
    assert robot.is_singular(np.random.default_rng(0).uniform(-3, 3, (50, 6)), tol=1e-9).all()
    fam = robokin.ik.family(robot)
    assert fam.name == "none" and fam.solver is None
    assert "general_6r: a degenerate arm: its Jacobian has rank below 6" in fam.reason
    assert general_6r.setup(robot.chain).params is None
    with pytest.raises(InputError, match="degenerate arm"):
        general_6r.solve(robot, robot.fk(np.full(6, 0.3)))
    sols = robot.ik(robot.fk(np.full(6, 0.3)))  # the numeric fallback, and it says so
    assert sols.method == "numeric" and sols.count >= 1
    with pytest.raises(InputError, match="degenerate arm"):
        robot.ik(robot.fk(np.full(6, 0.3)), method="analytic")


def test_bad_pose_and_option_raise_input_errors():
    robot = ur_twisted()
    bad = np.eye(4)
    bad[0, 0] = 2.0
    with pytest.raises(InputError, match="T"):
        robot.ik(bad)
    with pytest.raises(InputError, match="banana"):
        robot.ik(np.eye(4), banana=1)
    # the module's own entry checks what it is given too
    with pytest.raises(InputError, match="T"):
        general_6r.solve(robot, bad)
    T = robot.fk(np.zeros((3, 6)))
    with pytest.raises(InputError, match="q_near"):
        general_6r.solve(robot, T, q_near=np.zeros((2, 6)))
    with pytest.raises(InputError, match="q_near"):
        general_6r.solve(robot, T, q_near=np.full(6, np.nan))


def test_kernel_rejects_inconsistent_arguments():
    robot = ur_twisted()
    g = general_6r.setup(robot.chain)
    T = np.ascontiguousarray(robot.fk(np.zeros((2, 6))))
    with pytest.raises(ValueError, match="params"):
        general_6r.raw_solve(robot.chain, g.params[:-1], T)
    with pytest.raises(ValueError, match="chain"):
        general_6r.raw_solve(robokin.load("panda").chain, g.params, T)
    with pytest.raises(ValueError, match="degree"):
        K.general6r_roots(np.array([1.0, 0.0]), np.empty(2), np.empty(2))


# ------------------------------------------ special configurations (issue 23)
# The oracle: a configuration whose Jacobian's smallest singular value is above
# ISOLATED (rows in m and rad per rad) has isolated solutions, so the configuration
# that made the pose must come back (modulo 2 pi, within GENERATING_TOL rad); at a
# singular one (a continuum, or two solutions merging) at least one solution must.
# Every returned solution reproduces its pose to FK_TOL: position error [m] per metre
# of the arm's scale (1 for arms of about a metre) and rotation error [rad].
ISOLATED = 1e-3
GENERATING_TOL = 1e-6
FK_TOL = 1e-12
SPECIAL = (0.0, math.pi / 2, -math.pi / 2, math.pi)
TINY = (0.0, 1e-9, -1e-9, 1e-7, -1e-7, 1e-6, -1e-6)
H = math.pi / 2
# random sparse DH arms outside every closed form, (a [m], d [m], alpha [rad]) per
# joint, theta offsets 0; each exposed a failure mode (docs/ik.md, General 6R arms)
SPARSE_ROWS = {
    "sparse_a": [(0.0, 0.1395, H), (-0.3161, 0.427, -3.031215), (0.0, 0.0, -H),
                 (-0.2219, 0.0, 0.0), (0.0, 0.0, H), (0.0, 0.0, -0.437946)],
    "sparse_b": [(0.0, 0.33, H), (0.0, -0.4014, 2.462557), (0.4209, 0.0, 0.0),
                 (0.0153, -0.1615, H), (-0.0485, 0.0, 0.0), (0.0, 0.0, 0.0)],
    "sparse_c": [(0.0, 0.0, H), (0.0, -0.1897, -H), (0.0, 0.2472, 0.604968),
                 (0.0, -0.2141, H), (-0.2824, -0.1452, 0.0), (0.0, -0.1591, -0.346073)],
    "sparse_d": [(0.0, 0.127, -H), (-0.2229, -0.1015, -1.272109), (-0.3101, 0.0, 0.0),
                 (-0.0494, 0.0, 0.0), (0.0, 0.116, -H), (0.4634, 0.4652, 0.975554)],
    "sparse_e": [(0.471, -0.2789, 0.0), (0.2585, 0.4837, -0.330254), (-0.0058, 0.2051, 0.0),
                 (0.0142, 0.0, -H), (0.0233, 0.0, 0.0), (-0.1993, 0.0, -2.029053)],
    "sparse_f": [(0.2869, 0.0, 0.0), (0.0, -0.1508, H), (0.0, -0.1198, 3.072959),
                 (0.4445, 0.0, -H), (-0.0895, -0.0399, 0.0), (0.0, -0.2543, -2.289809)],
    "sparse_h": [(-0.3898, 0.0421, 0.0), (-0.019, 0.0, 0.0), (0.472, 0.0, H),
                 (0.0, 0.0, -1.218876), (-0.1349, 0.2073, -H), (0.0, 0.0, -H)],
}


def sparse_arm(name):
    rows = [{"joint": "revolute", "a": a, "d": d, "alpha": al, "theta": 0.0,
             "limits": [-math.pi, math.pi]} for a, d, al in SPARSE_ROWS[name]]
    return robokin.Robot.from_dh(rows, name=name)


def general_arm(seed):
    return random_dh_arm(np.random.default_rng(seed), name=f"general_{seed}")


def six_r_arm(name):
    if name == "irb140":
        return irb140()
    if name.startswith("general_"):
        return general_arm(int(name.split("_")[1]))
    return sparse_arm(name)


# Panda joints held (the reduced chains are general 6R on this branch; another solver
# may take some, hence the method is only required not to be the numeric fallback)
HELD = {"joint1": 0.4, "joint2": -0.6, "joint3": 0.9, "joint4": -1.2, "joint5": 0.7,
        "joint6": 1.2, "joint7": 0.7}


def check_special(robot, q, sols, T, scale, smin):
    """The oracle above for configurations q (m, n), their poses T, the SolutionSet,
    the arm's scale [m] and the Jacobian's smallest singular values smin (m,)."""
    dp, dr = fk_error(robot.chain, sols.q, T)
    err = np.where(sols.valid, np.maximum(dp / max(1.0, scale), dr), 0.0)
    assert err.max() <= FK_TOL, err.max()
    gap = np.where(sols.valid, np.abs(wrapped(sols.q - q[:, None, :])).max(axis=-1),
                   np.inf).min(axis=-1)
    isolated = smin > ISOLATED
    lost = isolated & (gap >= GENERATING_TOL)
    assert not lost.any(), q[lost].tolist()
    assert (sols.count[~isolated] >= 1).all(), q[~isolated & (sols.count == 0)].tolist()


def check_6r(robot, q):
    """check_special on a 6R arm solved by robot.ik: the general 6R solver, or the
    pieper closed form that ``method="auto"`` prefers where it applies (the Panda
    with joint 7 held); never the numeric sample."""
    T = robot.fk(q)
    sols = robot.ik(T)
    assert sols.method in ("general_6r", "analytic:pieper"), sols.method
    check_special(robot, q, sols, T, general_6r.setup(robot.chain).scale,
                  min_singular_value(robot.chain, q))


def special_configurations(limits, size=12):
    """Hypothesis strategy: (size, n) joint values, each joint at 0, +-pi/2 or pi plus
    0, +-1e-9, +-1e-7 or +-1e-6, at a limit, or uniform."""
    st = pytest.importorskip("hypothesis.strategies")
    special = st.builds(lambda b, t: b + t, st.sampled_from(SPECIAL), st.sampled_from(TINY))

    def joint(lo, hi):
        ends = st.sampled_from([max(lo, -math.pi), min(hi, math.pi)])
        return st.one_of(special, special, ends, st.floats(-math.pi, math.pi))

    row = st.tuples(*(joint(lo, hi) for lo, hi in limits))
    return st.lists(row, min_size=size, max_size=size).map(np.array)


@pytest.mark.parametrize("name", ["irb140", "general_31", "general_32", "general_33",
                                  *SPARSE_ROWS])
def test_generating_configuration_at_special_joint_values(name):
    hyp = pytest.importorskip("hypothesis")
    robot = six_r_arm(name)
    assert robokin.ik.family(robot).name == "general_6r"

    @hyp.settings(max_examples=25, deadline=None, derandomize=True, database=None)
    @hyp.given(special_configurations(robot.limits))
    def check(q):
        check_6r(robot, q)

    check()


@pytest.mark.parametrize("joint", list(HELD))
def test_panda_with_a_joint_held_at_special_joint_values(joint):
    # the reduced chain (any one joint held) is solved without the numeric fallback;
    # the oracle on the Panda's own configuration, through the public held-joint call
    hyp = pytest.importorskip("hypothesis")
    panda = robokin.load("panda")
    k = int(joint[-1]) - 1
    keep = [j for j in range(7) if j != k]
    scale = general_6r.setup(panda.chain.with_fixed({k: HELD[joint]})).scale
    free = np.delete(panda.limits, k, axis=0)

    @hyp.settings(max_examples=25, deadline=None, derandomize=True, database=None)
    @hyp.given(special_configurations(free))
    def check(q6):
        q = np.insert(q6, k, HELD[joint], axis=1)
        T = panda.fk(q)
        sols = panda.ik(T, fixed={joint: HELD[joint]})
        assert not sols.method.startswith("numeric"), sols.method
        smin = np.linalg.svd(panda.jacobian(q)[..., keep], compute_uv=False)[..., -1]
        check_special(panda, q, sols, T, scale, smin)

    check()


# configurations the elimination lost before issue 23 (on the arms above; found by
# the special-value sweeps): each must now come back
LOST = [
    # four solutions share joint 6: a 4-dimensional null space (split by the shifts)
    ("irb140", [math.pi, 1.441969420022903, 0.27410390540137985, -math.pi, -2.0944, -math.pi]),
    ("irb140", [-0.08899906526957402, 2.447224238106835, 1.1345, -math.pi,
                -1.5707962267948965, 1e-07]),
    ("irb140", [H, 2.0900648210551056, 0.0, -math.pi, -H, -math.pi]),
    # the Panda with joint 1 held at 0 / 0.7, joint 3 at 0 and joint 7 at 0.7:
    # clusters, a degenerate primary, a pose 1e-7 from a degenerate one, a noisy
    # cluster where every other variant is degenerate (the primary's sibling)
    ("panda_joint7_0.7", [2.8973, 1.5707962267948965, H, -3.0718, 3.141592753589793,
                          3.1415936535897933]),
    ("panda_joint1_0", [-1.5707963277948966, math.pi, -1.4694468369271578, -H, -H,
                        3.141592652589793]),
    ("panda_joint1_0", [-1.7628, math.pi, 1.5707963257948965, -1.5707964267948966,
                        1.5707973267948965, -2.8973]),
    ("panda_joint1_0.7", [1.7628, math.pi, -1.0567443151570002, H, -1.5707963257948965,
                          math.pi]),
    ("panda_joint3_0", [-2.8973, 1.7628, -1.5707963257948965, 0.0, -1.5707963277948966,
                        1.8200234741852706]),
    ("panda_joint3_0", [-1.4216889866622433, 1.5707953267948966, -3.0718, 0.0,
                        -1.6216714595150272, H]),
    # sparse arms: solutions sharing angles, a nearly rank-deficient right side,
    # every variant degenerate (the projection), a wide multiple root
    ("sparse_a", [0.7249860371262926, H, -math.pi, 1.5707963277948966, -1e-09,
                  0.9453635139748178]),
    ("sparse_a", [2.8207963021201756, -0.2510437936434946, math.pi, -0.016193681844320018,
                  -1.5707953267948966, math.pi]),
    ("sparse_b", [2.788486605067879, H, H, -math.pi, 1.5707963257948965, -0.44124258698566]),
    ("sparse_b", [-H, H, H, math.pi, -math.pi, -math.pi]),
    ("sparse_c", [math.pi, H, 0.0, -H, 1.998813010710128, -1.5707953267948966]),
    ("sparse_c", [0.0, H, 0.0, -H, 0.4425330513975929, math.pi]),
    ("sparse_d", [-1e-07, H, math.pi, H, math.pi, 0.31291939267913005]),
    ("sparse_e", [-1.2396648034037674, math.pi, -1.5707962267948965, -1.4435457642274057,
                  -1e-09, -1.5707964267948966]),
    # singular targets (a continuum): one valid solution
    ("sparse_a", [H, -1.5707963277948966, -1e-09, math.pi, -H, 0.21721860372141277]),
    ("sparse_c", [-H, math.pi, 0.0, -math.pi, H, 1.5707973267948965]),
    ("sparse_e", [0.28006822694827394, -1.5707962267948965, H, -H, -H, math.pi]),
    ("sparse_f", [3.141592652589793, 2.447224238106835, 1.5707973267948965, -H, math.pi,
                  3.141592654589793]),
    ("sparse_h", [-H, -1e-07, -math.pi, -1.5707963277948966, -1.5707953267948966, -1e-06]),
]


def lost_arm(name):
    if name.startswith("panda_joint"):
        joint, value = name[len("panda_"):].split("_")
        panda = robokin.load("panda")
        k = int(joint[-1]) - 1
        return robokin.Robot(panda.chain.with_fixed({k: float(value)}), name=name)
    return six_r_arm(name)


def test_configurations_lost_before_now_come_back():
    for name, q in LOST:
        check_6r(lost_arm(name), np.array([q]))


def test_special_poses_against_a_dense_multistart():
    # the whole solution set, not only the generating configuration: a pose where four
    # solutions share joint 6 (IRB140), one where every variant is degenerate
    # (sparse_c: the projection), one near a degenerate pose (sparse_a)
    for name, q in (LOST[0], LOST[13], LOST[9]):
        robot = six_r_arm(name)
        T = robot.fk(np.array(q))
        ours = robot.ik(T).solutions()
        ref = multistart_reference(robot, T, seed=7, n_seeds=1500)
        assert len(ref) >= 1
        assert len(not_in(ref, ours)) == 0, (name, "missing solutions")
        assert len(not_in(ours, ref)) == 0, (name, "solutions the reference does not have")


def test_kernel_candidates_and_flags_on_a_degenerate_pose():
    # sparse_c at LOST[13]: det Sigma vanishes for every theta in every variant, the
    # projection (c_d) gives candidates near the generating configuration
    robot = sparse_arm("sparse_c")
    g = general_6r.setup(robot.chain)
    q = np.array(LOST[13][1])
    out = np.empty((K.G6_MAXCAND, 6))
    n, flags = K.general6r_candidates(g.params, np.ascontiguousarray(robot.fk(q)), out)
    assert flags & K.G6F_DEGENERATE and flags & K.G6F_PROJECTED
    assert not flags & K.G6F_PROJ_DEGENERATE
    assert np.abs(wrapped(out[:n] - q)).max(axis=1).min() < 1e-4
    with pytest.raises(ValueError, match="candidates"):
        K.general6r_candidates(g.params, np.eye(3), out)


def test_setup_ranks_fallback_variants_with_their_own_right_side():
    g = general_6r.setup(irb140().chain)
    p = g.primary
    sibling = general_6r.Variant(p.reversed, p.split, 1 - p.multiplier)
    assert g.variants[:2] == (g.primary, g.secondary)
    assert g.variants[-1] == sibling or (g.secondary == sibling
                                         and len(g.variants) == 2 + general_6r.FALLBACKS)
    fallbacks = g.variants[2:2 + general_6r.FALLBACKS]
    sides = {(v.split, v.reversed) for v in fallbacks}
    assert len(sides) == general_6r.FALLBACKS
    assert not sides & {(v.split, v.reversed) for v in g.variants[:2]}
    assert int(g.params[K.GP_NVAR]) == len(g.variants)
    assert 2.5 < g.scale < 3.5  # the rtb-data IRB140 file is a 2.8 m model


def test_panda_with_joint2_held_at_zero_is_degenerate_and_says_so():
    # joint 2 at 0 puts axes 1 and 3 on one line: every pose has a continuum of
    # solutions; the reduced chain is refused by the general 6R set-up, and the
    # held-joint call solves the families instead (kinematics/ik/coincident.py,
    # tests/kinematics/ik/test_coincident.py) and says so
    panda = robokin.load("panda")
    q = np.array([0.3, 0.0, 0.2, -2.0, 0.4, 1.6, 0.7])
    sols = panda.ik(panda.fk(q), fixed={"joint2": 0.0})
    assert sols.method == ("general_6r (joint1 held) + coincident axes split "
                           "(joint2 held)")
    assert sols.singular[sols.valid].all()
    reduced = robokin.Robot(panda.chain.with_fixed({1: 0.0}))
    assert "a degenerate arm" in robokin.ik.family(reduced).reason


def test_nearly_degenerate_arm_is_refused_with_a_reason_not_a_traceback():
    # a random sparse arm (found by the sparse sweep): axes 1, 2 parallel, axis 3
    # 2.9e-4 rad from them and a spherical wrist, 2.9e-4 rad from rank 5 everywhere
    # (Jacobian's smallest singular value 1e-8..9e-5): no set-up configuration has
    # isolated solutions. The general 6R set-up refuses it with that reason (it raised
    # a bare ValueError from numpy before); the spherical wrist makes it a pieper arm,
    # which robot.ik takes: every generating configuration back, rows to 1e-12.
    rows = [(-0.1498, -0.4836, 0.0), (-0.3551, 0.0, 0.000287), (-0.1308, 0.0, H),
            (0.0, -0.3423, H), (0.0, 0.0, -H), (0.0, 0.0, -H)]
    robot = robokin.Robot.from_dh([{"joint": "revolute", "a": a, "d": d, "alpha": al,
                                    "theta": 0.0, "limits": [-math.pi, math.pi]}
                                   for a, d, al in rows])
    fam = robokin.ik.family(robot)
    assert fam.name == "pieper"
    assert "a nearly degenerate arm" in general_6r.setup(robot.chain).reason
    q = np.random.default_rng(3).uniform(-math.pi, math.pi, (50, 6))
    T = robot.fk(q)
    sols = robot.ik(T)
    assert sols.method == "analytic:pieper"
    dp, dr = fk_error(robot.chain, sols.q, T)
    assert np.where(sols.valid, np.maximum(dp, dr), 0.0).max() <= FK_TOL
    gap = np.where(sols.valid, np.abs(wrapped(sols.q - q[:, None, :])).max(axis=-1),
                   np.inf).min(axis=-1)
    assert (gap < GENERATING_TOL).all()


# ---------------------------------------------- joints on one line (issue 23/29)
#: offset iiwa (``reference.offset_iiwa14``, joint 7 held) with q4 = 0 or -+1e-9: axes 3
#: and 5 on one line, a continuum of solutions (only q3 + q5 fixed). The elimination's
#: rows all had their split outside the limits (q5 = 3.138 > 2.967 ...) before g6_coaxial_rows;
#: found by the bench's special configurations (seeds 1-3, 2,000 each).
COAXIAL_CONFIGURATIONS = [
    [-2.471454358744042, 0.6027801163963504, 0.37707511632294066, 0.0,
     2.6341037804751837, -1.1036562002505197, -0.1062655505895913],
    [2.6182162119585577, -1.8327473837870458, -1.84533652098516, 0.0,
     -1.199485959525064, -2.025531858393053, -1.2751884446179098],
    [2.9670597283903604, 2.0943951023931953, 2.9670597283903604, 1e-09,
     0.10047329125569382, 0.16822811187809217, 1e-09],
    [-1.388481267968898, -1.7405540789125409, 1e-09, 1e-09, 2.9670597283903604,
     -2.0943951023931953, 3.0543261909900767],
]


#: offset iiwa, q4 = -1e-9 (axes 3 and 5 1e-9 from one line), q1 and q2 at their limits:
#: every variant degenerate and noisy, 3 regular rows, the near-continuum's rows (and
#: with them every in-limit row) missing until g6_sampled runs there too
NEAR_CONTINUUM_CONFIGURATIONS = [
    [2.9670597283903604, 2.0943951023931953, -0.700430588521217, -1e-09,
     2.604076854653221, -1.7418752591336184, 1e-09],
]


@pytest.mark.parametrize("q0", NEAR_CONTINUUM_CONFIGURATIONS)
def test_near_continuum_rows_come_back_when_every_variant_is_noisy(q0):
    # ... and an in-limit row with q3 + q5 = q0's to 1e-6 (the near-continuum's invariant)
    q0 = np.asarray(q0)
    q = _in_limit_singular_rows(q0)
    inv = (q[:, 2] + q[:, 4] - q0[2] - q0[4] + np.pi) % (2 * np.pi) - np.pi
    assert (np.abs(inv) < 1e-6).any()


#: offset iiwa, q3 = -1e-9, q2 and q6 at their limits (sigma 6e-12 of the largest): the
#: elimination's row next to q0 was 1.7e-7 past q6's limit (g6_slide_row brings it in)
SLIDE_CONFIGURATIONS = [
    [-2.433386118264293, 2.0943951023931953, -1e-09, -1.971112604991673,
     1.5707963267948966, 2.0943951023931953, 0.6457688213085984],
]


def _in_limit_singular_rows(q0):
    # Oracle: q0 is inside the limits and reproduces T, and its six free joints'
    # Jacobian is singular (smallest / largest singular value < 1e-10), so the
    # requirement is a valid row inside the limits (one flagged singular); every
    # in-limit row reproduces T to 1e-12; every valid row once (1e-6 rad apart).
    from reference import offset_iiwa14, pose_errors

    robot = offset_iiwa14()
    sv = np.linalg.svd(robot.jacobian(q0)[:, :6], compute_uv=False)
    assert sv[-1] < 1e-10 * sv[0]
    T = robot.fk(q0)
    s = robot.ik(T, fixed={"a7": float(q0[6])})
    rows = s.valid & s.flags["within_limits"]
    assert rows.any()
    q = s.q[rows]
    dp, dr = pose_errors(robot.fk(q), T)
    assert np.maximum(dp, dr).max() <= 1e-12
    assert s.flags["singular"][rows].any()  # (regular in-limit rows may come too)
    lo, hi = robot.limits[:, 0], robot.limits[:, 1]
    assert ((q >= lo - 1e-9) & (q <= hi + 1e-9)).all()
    v = s.q[s.valid]
    d = np.abs((v[:, None] - v[None] + np.pi) % (2 * np.pi) - np.pi).max(-1)
    assert (d + np.eye(len(v)) * 1.0 >= 1e-6).all()
    return q


@pytest.mark.parametrize("q0", COAXIAL_CONFIGURATIONS)
def test_joints_on_one_line_get_an_in_limit_split(q0):
    # ... and one in-limit row has q3 + q5 = q0's (the continuum's invariant)
    q0 = np.asarray(q0)
    q = _in_limit_singular_rows(q0)
    inv = (q[:, 2] + q[:, 4] - q0[2] - q0[4] + np.pi) % (2 * np.pi) - np.pi
    assert (np.abs(inv) < 1e-6).any()


@pytest.mark.parametrize("q0", SLIDE_CONFIGURATIONS)
def test_row_just_past_a_limit_next_to_a_singularity_slides_inside(q0):
    # ... and one in-limit row lies within 1e-5 rad of q0 (the thin exact set there)
    q0 = np.asarray(q0)
    q = _in_limit_singular_rows(q0)
    d = np.abs((q - q0 + np.pi) % (2 * np.pi) - np.pi).max(-1)
    assert d.min() < 1e-5


#: offset iiwa at the stretched elbow, q4 = -+1e-9 (axes 3 and 5 1e-9 from one line):
#: rows taken from the q4 = 0 near-continuum reproduced T to 1.0-1.16e-12 m only (the
#: continuum's poses pass that far from T; in 40-digit arithmetic the nearest exact
#: solutions are 0.1-2.6 rad away along it) until g6_polish took every row above half
#: the kernel's tolerance to half of it or dropped it. From
#: ``benchmarks/offset_iiwa_precision.py`` (special configurations; seed, index).
STRETCHED_ELBOW_CONFIGURATIONS = [
    # seed 1, configuration 607 (q5 = 1e-9 too: the arm straight from joint 3 to 6)
    [0.2393754177378331, 1.542605515018454, 1.8107820456143386, -1e-09, 1e-09,
     0.5170866154310381, 2.541354368625953],
    # seed 1, configuration 1455
    [1.1494693121383897, -1.6800710715494818, 2.105744908695251, -1e-09,
     2.9670597283903604, 1.5707963267948966, 1.1660128001992476],
    # seed 2, configuration 166
    [2.758807838564308, -0.34420376656893814, -1.5707963267948966, -1e-09,
     0.17231126914044426, 0.4780076756183047, 1.838894172327156],
    # seed 4, configuration 1097
    [1.5707963267948966, -1.2980597157891682, -1.397648727326551, 1e-09,
     0.04919196572254192, 1.5707963267948966, 0.9620029004754516],
    # seed 5, configuration 415
    [-2.9670597283903604, 2.0943951023931953, 1.636735344021237, 1e-09,
     0.13928678035723863, 0.008760155498856115, -0.5995029766793798],
]


@pytest.mark.parametrize("q0", STRETCHED_ELBOW_CONFIGURATIONS)
def test_stretched_elbow_rows_reproduce_the_pose_to_1e_12(q0):
    # Oracle: FK of every valid row against T (issue 23: <= 1e-12 m and rad), and q0
    # (which reproduces T) among the rows: q1, q2, q4, q6 and q3 + q5 (the
    # near-continuum's invariant) within 1e-9 rad, q3 within 1e-3 rad (q0's
    # Jacobian's smallest singular value is 5e-12 - 2e-10: along the near-continuum
    # T's rounding moves the exact solution by up to 1e-16 / sigma, 8e-5 rad here).
    from reference import offset_iiwa14, pose_errors

    robot = offset_iiwa14()
    q0 = np.asarray(q0)
    T = robot.fk(q0)
    s = robot.ik(T, fixed={"a7": float(q0[6])})
    q = s.q[s.valid]
    dp, dr = pose_errors(robot.fk(q), T)
    assert np.maximum(dp, dr).max() <= 1e-12
    d = wrapped(q - q0)
    inv = np.abs(np.column_stack([d[:, [0, 1, 3, 5]], wrapped(d[:, 2] + d[:, 4])])).max(-1)
    assert ((inv < 1e-9) & (np.abs(d[:, 2]) < 1e-3)).any()
