"""The Panda's whole self-motion from closed forms (``csrc/held_closed.c``, session 26).

Oracles: the grid kernel (``held_manifold.c``, HM_MODE_GRID) where both certify a
pose; pk_one's rows (``SelfMotion.sample``) inside every limit over each interval and
outside just past an end that is a limit crossing; the generating configuration's
own value of q7 in an interval of its slot.
"""

from __future__ import annotations

import numpy as np
import pytest

import robokin
from robokin._native import kernels as K
from robokin.kinematics.ik.self_motion_intervals import KERNEL_GRID, _aligned_values

PANDA = robokin.load("panda")
LO, HI = PANDA.limits[:, 0], PANDA.limits[:, 1]
SPECIAL = (0.0, 1e-9, -1e-9, np.pi / 2, -np.pi / 2)


def _configurations(n: int, special: bool, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    q = rng.uniform(LO, HI, (n, 7))
    if special:  # one to three joints at 0, +-1e-9, +-pi/2 or a limit
        for row in q:
            for j in rng.choice(7, rng.integers(1, 4), replace=False):
                c = rng.integers(0, 3)
                row[j] = rng.choice(SPECIAL) if c == 0 else (LO[j] if c == 1 else HI[j])
        np.clip(q, LO, HI, out=q)
    return q


def _run(robot, T: np.ndarray, mode: int) -> dict:
    """held_manifold's outputs for poses T (N, 4, 4) in ``mode``."""
    fam = robot.self_motion(T[0])._family
    params = np.ascontiguousarray(fam.params, dtype=np.float64)
    aligned = np.array([[j, v] for j, v in _aligned_values(robot.arm)],
                       dtype=np.float64).reshape(-1, 2)
    n = len(T)
    out = {"iv": np.empty((n, 8, K.HM_MAXI, 2)), "niv": np.zeros((n, 8), np.int64),
           "pts": np.empty((n, K.HM_MAXP, 4)), "npts": np.zeros(n, np.int64),
           "flags": np.zeros(n, np.int64), "evals": np.zeros(n, np.int64)}
    K.held_manifold(params, np.ascontiguousarray(T), aligned, KERNEL_GRID, out["iv"],
                    out["niv"], out["pts"], out["npts"], out["flags"], out["evals"], mode)
    return out


def _intervals(out: dict, i: int, b: int) -> np.ndarray:
    return out["iv"][i, b, :out["niv"][i, b]]


@pytest.mark.parametrize("special", [False, True])
def test_closed_forms_give_the_grids_intervals_where_both_certify(special):
    q = _configurations(300, special, 26 + special)
    T = PANDA.fk(q)
    grid, closed = _run(PANDA, T, K.HM_MODE_GRID), _run(PANDA, T, K.HM_MODE_CLOSED)
    both = (grid["flags"] == 0) & (closed["flags"] == 0)
    # uniform poses: most certified (session 27: ~99 %); special ones often left to the
    # grid (a joint at a limit: corners, isolated in-limit rows)
    assert both.sum() >= (270 if not special else 100), both.sum()
    assert np.all((closed["flags"] == 0) | (closed["flags"] == K.HM_FLAG_BAD))
    for i in np.flatnonzero(both):
        for b in range(8):
            a, c = _intervals(grid, i, b), _intervals(closed, i, b)
            assert a.shape == c.shape, (i, b, a.tolist(), c.tolist())
            # ends within 5e-10: the grid bisects branch ends on pk_one's rows (to
            # HM_FOLD_TOL), the closed forms take the margins' roots (<= 1.4e-10 apart
            # on 6,000 poses); limit crossings agree to ~3e-11
            np.testing.assert_allclose(c, a, rtol=0, atol=5e-10, err_msg=f"pose {i} slot {b}")
    # the same branch ends and aligned-axes points are listed
    for i in np.flatnonzero(both):
        for kind in (K.HM_KIND_ALIGNED, K.HM_KIND_FOLD):
            pa = grid["pts"][i, :grid["npts"][i]]
            pc = closed["pts"][i, :closed["npts"][i]]
            pa, pc = pa[pa[:, 3] == kind], pc[pc[:, 3] == kind]
            assert len(pa) == len(pc), (i, kind)
            key = np.lexsort((pa[:, 0], pa[:, 2], pa[:, 1])), np.lexsort((pc[:, 0], pc[:, 2], pc[:, 1]))
            np.testing.assert_array_equal(pa[key[0]][:, 1:], pc[key[1]][:, 1:])
            np.testing.assert_allclose(pa[key[0]][:, 0], pc[key[1]][:, 0], rtol=0, atol=5e-10)


def test_events_next_to_a_branch_end_and_a_near_aligned_shoulder_are_certified():
    # session 27: uniform poses (seed 11 of 6,000) the closed forms left to the grid
    # before and certify now, with the grid's intervals. The first five have an event
    # within 1e-6 of a branch end of its slot (HC_CORNER before, HC_FOLD_GAP 1e-10
    # now: there the rows move as the square root of the distance); on the last five
    # a branch passes within 1 - |cos q2| < 1e-6 of the aligned shoulder (HC_ALIGNED
    # 1e-6 before, 1e-8 now)
    q = _configurations(6000, False, 11)[[158, 192, 213, 215, 300, 316, 365, 392, 487, 500]]
    T = PANDA.fk(q)
    grid, closed = _run(PANDA, T, K.HM_MODE_GRID), _run(PANDA, T, K.HM_MODE_CLOSED)
    assert np.all(grid["flags"] == 0) and np.all(closed["flags"] == 0), closed["flags"]
    for i in range(len(q)):
        for b in range(8):
            a, c = _intervals(grid, i, b), _intervals(closed, i, b)
            assert a.shape == c.shape, (i, b, a.tolist(), c.tolist())
            np.testing.assert_allclose(c, a, rtol=0, atol=5e-10, err_msg=f"pose {i} slot {b}")
    for i in range(5):  # an event (limit or aligned value) next to a branch end
        pts = closed["pts"][i, :closed["npts"][i]]
        gaps = [np.abs(pts[(pts[:, 3] == K.HM_KIND_FOLD) & (pts[:, 1] == b), 0][:, None]
                       - pts[(pts[:, 3] != K.HM_KIND_FOLD) & (pts[:, 1] == b), 0][None, :])
                for b in range(8)]
        nearest = min((g[g > 0].min() for g in gaps if np.any(g > 0)), default=np.inf)
        assert 1e-10 <= nearest < 1e-6, (i, nearest)


def test_closed_forms_intervals_hold_in_limit_rows_and_the_generating_configuration():
    q = _configurations(60, False, 2026)
    T = PANDA.fk(q)
    closed = _run(PANDA, T, K.HM_MODE_CLOSED)
    checked = 0
    for i in np.flatnonzero(closed["flags"] == 0):
        sm = PANDA.self_motion(T[i])  # its sample: pk_one's rows
        found = False
        for b in range(8):
            for a, e in _intervals(closed, i, b):
                # pk_one's row at every sampled value, the ends included (a branch end
                # is where pk_one's rows end: hc_snap), inside every limit
                t = np.linspace(a, e, 7)
                rows = sm.sample(t)[:, b]
                assert np.isfinite(rows).all(), (i, b, a, e)
                assert np.all(rows >= LO - 1e-9) and np.all(rows <= HI + 1e-9), (i, b, a, e)
                for end, step in ((a, -1e-6), (e, 1e-6)):
                    out = end + step
                    if not LO[6] < out < HI[6]:
                        continue
                    row = sm.sample(np.array([out]))[0, b]
                    # past an end: no row (a branch end), or a joint outside
                    assert (not np.isfinite(row).all()) or np.any((row < LO) | (row > HI)), (
                        i, b, end)
                if a <= q[i, 6] <= e:
                    row = sm.sample(np.array([q[i, 6]]))[0, b]
                    found |= bool(np.all(np.isfinite(row))
                                  and np.abs(row - q[i]).max() < 1e-9)
        assert found, i  # the generating configuration is in an interval of its slot
        checked += 1
    assert checked >= 55


def test_an_aligned_shoulder_and_other_arms_are_left_to_the_grid():
    # q2 at 0 or 1e-9: q1 and q3 swing (the grid's deep splits); q1, q3, q4 at limits
    # with q5 = 1e-9 (self_motion_rates.py seed 0, special #1085: an isolated in-limit
    # row at an aligned wrist point, which the closed forms certified without it)
    q = np.array([[0.3, 0.0, 0.2, -1.5, 0.1, 1.2, 0.5], [0.3, 1e-9, 0.2, -1.5, 0.1, 1.2, 0.5],
                  [-2.8973, -1.6248256302915205, 2.8973, -3.0718, 1e-09, 0.2731590631920966,
                   1e-07]])
    assert np.all(_run(PANDA, PANDA.fk(q), K.HM_MODE_CLOSED)["flags"] == K.HM_FLAG_BAD)
    # robot.self_motion (the grid, then solved points) has the isolated row
    sm = PANDA.self_motion(PANDA.fk(q[2]))
    assert sm.reachable
    assert np.abs(sm.nearest(q[2]).q - q[2]).max() < 1e-6
    # the Gen3-like arm (joint_3 held, the wrist triple): not this file's kind; AUTO is
    # then the grid, bit for bit
    d = [-0.2848, -0.0118, -0.4208, -0.0128, -0.3143, 0.0, -0.1674]
    lim = [180, 128.9, 180, 147.8, 180, 120.3, 180]
    gen3 = robokin.Robot.from_dh([
        {"a": 0.0, "alpha": np.pi if i == 6 else np.pi / 2, "d": d[i],
         "theta": 0.0 if i == 0 else np.pi, "limits": [-np.radians(lim[i]), np.radians(lim[i])],
         "name": f"joint_{i + 1}"} for i in range(7)], convention="standard")
    qg = np.random.default_rng(3).uniform(gen3.limits[:, 0], gen3.limits[:, 1], (4, 7))
    Tg = gen3.fk(qg)
    assert np.all(_run(gen3, Tg, K.HM_MODE_CLOSED)["flags"] == K.HM_FLAG_BAD)
    auto, grid = _run(gen3, Tg, K.HM_MODE_AUTO), _run(gen3, Tg, K.HM_MODE_GRID)
    np.testing.assert_array_equal(auto["niv"], grid["niv"])
    for i in range(4):
        for b in range(8):
            np.testing.assert_array_equal(_intervals(auto, i, b), _intervals(grid, i, b))


def test_an_fr3_kind_arm_with_its_own_limits_gets_the_grids_intervals():
    # the FR3's kinematics (the Panda's DH) with the FR3's limits: other ranges for the
    # margins without angles (hc_margins: q4 in [-3.04, -0.15], q6 in [0.54, 4.52], q7
    # within 0.13 rad of a whole turn's half)
    a = [0, 0, 0, 0.0825, -0.0825, 0, 0.088]
    d = [0.333, 0, 0.316, 0, 0.384, 0, 0]
    alpha = [0, -np.pi / 2, np.pi / 2, np.pi / 2, -np.pi / 2, np.pi / 2, np.pi / 2]
    lim = [(-2.7437, 2.7437), (-1.7837, 1.7837), (-2.9007, 2.9007), (-3.0421, -0.1518),
           (-2.8065, 2.8065), (0.5445, 4.5169), (-3.0159, 3.0159)]
    fr3 = robokin.Robot.from_dh([
        {"a": a[i], "alpha": alpha[i], "d": d[i], "theta": 0.0, "limits": list(lim[i]),
         "name": f"fr3_joint{i + 1}"} for i in range(7)], convention="modified")
    lo, hi = fr3.limits[:, 0], fr3.limits[:, 1]
    q = np.random.default_rng(27).uniform(lo, hi, (200, 7))
    T = fr3.fk(q)
    assert fr3.self_motion(T[0]).method == "analytic:pieper (fr3_joint7 held), compiled"
    grid, closed = _run(fr3, T, K.HM_MODE_GRID), _run(fr3, T, K.HM_MODE_CLOSED)
    both = (grid["flags"] == 0) & (closed["flags"] == 0)
    assert both.sum() >= 190, both.sum()  # (1,481 of 1,500 in session 27)
    for i in np.flatnonzero(both):
        for b in range(8):
            ga, c = _intervals(grid, i, b), _intervals(closed, i, b)
            assert ga.shape == c.shape, (i, b, ga.tolist(), c.tolist())
            np.testing.assert_allclose(c, ga, rtol=0, atol=5e-10, err_msg=f"pose {i} slot {b}")
    # and the generating configuration's q7 is in an interval of some slot
    for i in np.flatnonzero(closed["flags"] == 0)[:40]:
        assert any(s <= q[i, 6] <= e for b in range(8) for s, e in _intervals(closed, i, b)), i


def test_a_tilted_panda_gets_the_grids_intervals():
    # the Panda on a tilted base (0.4 rad about y, 0.3 about x): no axis along a
    # coordinate axis, so the rows turn by Rodrigues' formula (held_row.h's hr_rot,
    # its default case) in the one-row and the W-row instantiations alike (session 29)
    c, s, c2, s2 = np.cos(0.4), np.sin(0.4), np.cos(0.3), np.sin(0.3)
    base = np.array([[c, 0, s, 0.1], [0, 1, 0, 0.2], [-s, 0, c, 0.3], [0, 0, 0, 1.0]]) @ \
        np.array([[1, 0, 0, 0], [0, c2, -s2, 0], [0, s2, c2, 0], [0, 0, 0, 1.0]])
    tilted = robokin.Robot(PANDA.chain.replace(base=base), name="tilted panda")
    q = np.random.default_rng(29).uniform(LO, HI, (200, 7))
    T = tilted.fk(q)
    fam = tilted.self_motion(T[0])._family
    axes = np.asarray(fam.params)[8:8 + 21].reshape(7, 3)  # (pieper.c's PK_AXES = 8)
    assert np.all(np.abs(axes).max(axis=1) < 0.99), axes
    grid, closed = _run(tilted, T, K.HM_MODE_GRID), _run(tilted, T, K.HM_MODE_CLOSED)
    both = (grid["flags"] == 0) & (closed["flags"] == 0)
    assert both.sum() >= 190, both.sum()  # (198 of 200 in session 29)
    for i in np.flatnonzero(both):
        for b in range(8):
            ga, cl = _intervals(grid, i, b), _intervals(closed, i, b)
            assert ga.shape == cl.shape, (i, b, ga.tolist(), cl.tolist())
            np.testing.assert_allclose(cl, ga, rtol=0, atol=5e-10, err_msg=f"pose {i} slot {b}")
    # the untilted Panda's intervals on the same configurations: the base moves nothing
    upright = _run(PANDA, PANDA.fk(q), K.HM_MODE_CLOSED)
    for i in np.flatnonzero(both & (upright["flags"] == 0)):
        for b in range(8):
            np.testing.assert_allclose(_intervals(closed, i, b), _intervals(upright, i, b),
                                       rtol=0, atol=1e-10, err_msg=f"pose {i} slot {b}")


def test_poses_in_and_out_of_reach_get_the_grids_intervals():
    # poses pushed in or out along their position (x 0.6 .. 1.6): ~40 % out of reach,
    # where no branch has a row (no piece: the wrist's events are not looked for,
    # session 29) and the manifold is empty, as the grid finds it
    q = np.random.default_rng(3).uniform(LO, HI, (400, 7))
    T = PANDA.fk(q)
    T[:, :3, 3] *= np.random.default_rng(4).uniform(0.6, 1.6, (400, 1))
    grid, closed = _run(PANDA, T, K.HM_MODE_GRID), _run(PANDA, T, K.HM_MODE_CLOSED)
    both = (grid["flags"] == 0) & (closed["flags"] == 0)
    assert both.sum() >= 380, both.sum()
    empty = both & (closed["niv"].sum(axis=1) == 0)
    assert empty.sum() >= 100, empty.sum()
    for i in np.flatnonzero(both):
        for b in range(8):
            ga, cl = _intervals(grid, i, b), _intervals(closed, i, b)
            assert ga.shape == cl.shape, (i, b, ga.tolist(), cl.tolist())
            np.testing.assert_allclose(cl, ga, rtol=0, atol=5e-10, err_msg=f"pose {i} slot {b}")


def test_an_aligned_value_at_a_branch_end_is_left_to_the_grid():
    # the generating configuration at a branch end with q3 = 0 (the other triple at q3's
    # aligned value, pi): the aligned point lies at the end itself, where the snapped
    # end's rounding moves q3 as a square root (~1e-8), so the closed forms' crossing
    # search saw no sign change and listed none (special poses of cmp seeds 23 #673 and
    # #1627, 12 #1022; the last two certified so since session 26). The grid lists it.
    q = np.array([
        [1.8910063561578663, 0.43502246887868345, 0.0, -0.2348618532075708,
         1.5707963267948966, 2.2662417106423374, 0.5833936175275154],
        [-1.0374206361272473, 0.22314174353311267, 0.0, -1.4770577300515049,
         -1.5707963267948966, 1.5707963267948966, 1.360073618176782],
        [-0.04302525185658279, -1.7481623500069061, 0.0, -1.5707963267948966,
         1.5707963267948966, 2.8621457292086676, 2.717140331395227]])
    T = PANDA.fk(q)
    closed, auto = _run(PANDA, T, K.HM_MODE_CLOSED), _run(PANDA, T, K.HM_MODE_AUTO)
    assert np.all(closed["flags"] == K.HM_FLAG_BAD), closed["flags"]
    for i in range(len(q)):
        pts = auto["pts"][i, :auto["npts"][i]]
        at = pts[(pts[:, 3] == K.HM_KIND_ALIGNED) & (pts[:, 2] == 2)
                 & (np.abs(pts[:, 0] - q[i, 6]) < 1e-9)]
        assert len(at), (i, pts.tolist())


def test_an_isolated_in_limit_point_at_a_branch_end_is_left_to_the_grid():
    # cmp special seed 25 #1189 (certified wrongly since session 26): the generating
    # configuration at a branch end with q3 at its limit and q2 = 0.011 (q1 and q3 swing
    # ~90 times faster): an isolated in-limit point [t, t] there. At the snapped end q3
    # is beta sqrt(shift) from the limit, more than HC_AT_FOLD; the rate-scaled guard
    # leaves the pose to the grid, which has the point
    q = np.array([[-0.47725033120276006, 0.011494837727267226, 2.8973, -3.022633628895515,
                   -1.5707963267948966, 1.2104713183828129, -1.7998953644568292]])
    T = PANDA.fk(q)
    assert _run(PANDA, T, K.HM_MODE_CLOSED)["flags"][0] == K.HM_FLAG_BAD
    auto = _run(PANDA, T, K.HM_MODE_AUTO)
    assert auto["flags"][0] == 0
    assert any(s - 1e-9 <= q[0, 6] <= e + 1e-9 for b in range(8)
               for s, e in _intervals(auto, 0, b))
