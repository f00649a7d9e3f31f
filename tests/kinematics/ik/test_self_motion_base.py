"""The base of the self-motion families (``self_motion_base``)."""

from __future__ import annotations

import numpy as np

from reference import offset_iiwa14


def test_into_limits_shifts_by_two_pi_where_that_fits_bit_for_bit():
    # the in-place shifts against the formula they replace (q + 2 pi up - 2 pi down),
    # bit for bit: -0.0 comes out 0.0 as there, NaN stays, a value shifted lands
    # inside its limits, one where no shift fits is kept
    from robokin.kinematics.ik.self_motion_base import _into_limits

    robot = offset_iiwa14().arm
    lo, hi = robot.limits[:, 0], robot.limits[:, 1]
    rng = np.random.default_rng(2)
    q = rng.uniform(-2 * np.pi, 2 * np.pi, (40, 3, 7))
    q[rng.random(q.shape) < 0.1] = np.nan
    q[0, 0] = -0.0
    up = (q < lo) & (q + 2 * np.pi <= hi)
    down = (q > hi) & (q - 2 * np.pi >= lo)
    want = q + 2 * np.pi * up - 2 * np.pi * down
    out = _into_limits(robot, q)
    np.testing.assert_array_equal(out.view(np.int64), want.view(np.int64))
    assert up.any() and down.any()
    assert np.all((out[up | down] >= lo.min()) & (out[up | down] <= hi.max()))
    assert np.all(out[0, 0].view(np.int64) == 0)  # -0.0 -> 0.0
    keep = ~(up | down) & np.isfinite(q) & (q != 0)
    np.testing.assert_array_equal(out[keep], q[keep])
    assert np.isnan(out[np.isnan(q)]).all()


def test_into_limits_quick_test_moves_nothing_it_skips():
    # Issue 29 (helper iiwapy30): _into_limits returns q + 0.0 where no angle is at or
    # past SHIFT_CAPS' bounds. Oracle: the formula (q + 2 pi up - 2 pi down), bit for
    # bit, one row set per call, on the offset iiwa (limits narrower than 2 pi: no row
    # in [-pi, pi) moves, every call the quick one) and the Panda (joint 6 in [-0.0175,
    # 3.7525]: angles below -2.53 move up), with values at the bounds, the limits and
    # hi - 2 pi, lo + 2 pi and their neighbouring floats; both branches are taken.
    import robokin
    from robokin.kinematics.ik.self_motion_base import SHIFT_CAPS, _into_limits

    rng = np.random.default_rng(5)
    taken = {True: 0, False: 0}
    for robot in (offset_iiwa14().arm, robokin.load("panda").arm):
        lo, hi = robot.limits[:, 0], robot.limits[:, 1]
        up_cap, down_cap = robot.derived(SHIFT_CAPS)
        edges = np.stack([lo, hi, hi - 2 * np.pi, lo + 2 * np.pi, up_cap, down_cap])
        edges = np.concatenate([edges, np.nextafter(edges, -np.inf), np.nextafter(edges, np.inf)])
        for k in range(300):
            q = rng.uniform(-np.pi, np.pi, (8, 7))
            if k % 3 == 0:  # some coordinates exactly at (or one float off) an edge
                pick = rng.random(q.shape) < 0.3
                q[pick] = edges[rng.integers(0, len(edges), q.shape), np.arange(7)][pick]
            q[rng.random(q.shape) < 0.05] = np.nan
            up = (q < lo) & (q + 2 * np.pi <= hi)
            down = (q > hi) & (q - 2 * np.pi >= lo)
            want = q + 2 * np.pi * up - 2 * np.pi * down
            out = _into_limits(robot, q)
            np.testing.assert_array_equal(out.view(np.int64), want.view(np.int64))
            quick = not ((q <= up_cap) | (q >= down_cap)).any()
            assert not quick or not (up | down).any()
            taken[quick] += 1
    assert taken[True] > 100 and taken[False] > 20, taken


def _bisected(f, lo, hi, steps=200):
    # Oracle: plain bisection on the sign of f (the low end's sign kept) to adjacent
    # doubles; also its step count.
    lo, hi = np.array(lo, float), np.array(hi, float)
    s_lo = np.sign(f(lo))
    n = 0
    while n < steps:
        mid = 0.5 * (lo + hi)
        go = (mid != lo) & (mid != hi)
        if not go.any():
            break
        same = np.sign(f(mid)) == s_lo
        lo, hi = np.where(go & same, mid, lo), np.where(go & ~same, mid, hi)
        n += 1
    return lo, hi, n


def _sides(f, s_lo, calls):
    # _shrunk's side(t, a) for brackets whose low ends have signs s_lo: f's value, the
    # low end's side where the sign is the same, every value ok; each call's size logged.
    def side(t, a):
        calls.append(len(a))
        v = f(t, a)
        return v, np.sign(v) == s_lo[a], np.ones(len(a), bool)
    return side


def _noisy_brackets(seed):
    # 40 brackets around roots c of a smooth cubic with rounding noise of 1e-13 (the
    # rows' own next to a singularity): the side changes many times within ~1e-13.
    rng = np.random.default_rng(seed)
    c = rng.uniform(-3.0, 3.0, 40)
    lo, hi = c - rng.uniform(1e-3, 0.5, 40), c + rng.uniform(1e-3, 0.5, 40)

    def f(t, a=slice(None)):
        return (t - c[a]) * (1.0 + (t - c[a]) ** 2) + 1e-13 * np.sin(1e15 * t)

    return c, lo, hi, f


def test_shrunk_brackets_are_bisections_in_half_the_steps():
    # Monotone smooth functions with roots at special places (0, a limit value, a root
    # next to an end, 1e-9): the bracket is bisection's own pair of adjacent doubles (a
    # single sign change), in at most half of bisection's steps.
    from robokin.kinematics.ik.self_motion_base import _shrunk

    c = np.array([0.0, 2.9670597283903604, -1.7453292519943295, 0.3, 1e-9])
    lo = np.array([-0.3, 2.9, -1.8, -1.0, -0.02])
    hi = np.array([0.25, 3.1, -1.7453292519943, 2.0, 0.03])
    k = np.array([1.0, -3.0, 0.5, 1.0, 2.0])

    def f(t, a=slice(None)):
        x = t - c[a]
        return k[a] * (x + x ** 3)

    calls = []
    side = _sides(f, np.sign(f(lo)), calls)
    out_lo, out_hi, found = _shrunk(side, lo, hi, f(lo), f(hi), 240)
    ref_lo, ref_hi, _ = _bisected(f, lo, hi)
    assert found.all()
    # away from 0: bisection's adjacent doubles exactly
    assert np.array_equal(out_lo[1:], ref_lo[1:]) and np.array_equal(out_hi[1:], ref_hi[1:])
    assert (np.nextafter(out_lo[1:], out_hi[1:]) == out_hi[1:]).all()
    # a root at 0 (doubles down to 5e-324 there): straddled within 1e-20, as bisection's
    # 60 steps leave it within 5e-19
    assert out_lo[0] < 0.0 <= out_hi[0] and out_hi[0] - out_lo[0] < 1e-20
    # the steps: the others alone (the root at 0 goes on into the subnormals), at most
    # half of bisection's (55 here)
    calls.clear()
    a = np.arange(1, 5)
    _shrunk(lambda t, i: side(t, a[i]), lo[a], hi[a], f(lo)[a], f(hi)[a], 240)
    assert len(calls) <= _bisected(lambda t: f(t, a), lo[a], hi[a])[2] // 2
    # the inputs are not changed in place
    assert lo[0] == -0.3 and hi[1] == 3.1


def test_shrunk_without_end_values_and_a_bracket_given_up():
    # NaN at an end (no row: a state change's outer end) still reaches adjacent doubles
    # by midpoints; a bracket whose side() is not ok at a step is given up (found False).
    from robokin.kinematics.ik.self_motion_base import _shrunk

    c = np.array([0.125, 1.0])
    lo, hi = np.array([0.0, 0.0]), np.array([1.0, 2.0])

    def side(t, a):
        v = t - c[a]
        ok = ~((a == 1) & (t > 0.9) & (t < 1.1))  # bracket 1 loses its row next to its root
        return np.where(ok, v, np.nan), v < 0, ok

    out_lo, out_hi, found = _shrunk(side, lo, hi, np.array([np.nan, -1.0]),
                                    np.array([0.875, np.nan]), 240)
    assert found.tolist() == [True, False]
    assert out_lo[0] < 0.125 <= out_hi[0] and np.nextafter(out_lo[0], 1.0) == out_hi[0]


def test_shrunk_on_a_noisy_sign_change_ends_on_one():
    # Rounding noise of 1e-13 around a root (the rows' own, next to a singularity):
    # the side changes many times within ~1e-13; the bracket is two adjacent doubles
    # whose sides differ.
    from robokin.kinematics.ik.self_motion_base import _shrunk

    c, lo, hi, f = _noisy_brackets(7)
    s_lo = np.sign(f(lo))
    out_lo, out_hi, found = _shrunk(_sides(f, s_lo, []), lo, hi, f(lo), f(hi), 240)
    assert found.all()
    assert (np.nextafter(out_lo, out_hi) == out_hi).all()
    assert (np.sign(f(out_lo)) == s_lo).all() and (np.sign(f(out_hi)) != s_lo).all()
    assert (np.abs(out_lo - c) < 1e-12).all()


def test_shrunk_stops_where_both_ends_are_within_the_noise():
    # With tol, a noisy bracket stops once both ends' own values are within tol of 0
    # (not at adjacent doubles), in fewer steps than without; the ends keep their sides
    # (the low end's side at lo, the other at hi) and the root lies between them.
    from robokin.kinematics.ik.self_motion_base import _shrunk

    c, lo, hi, f = _noisy_brackets(11)
    s_lo = np.sign(f(lo))
    calls = []
    side = _sides(f, s_lo, calls)
    _shrunk(side, lo, hi, f(lo), f(hi), 240)
    exact = sum(calls)
    calls.clear()
    out_lo, out_hi, found = _shrunk(side, lo, hi, f(lo), f(hi), 240, tol=1e-12)
    assert found.all() and sum(calls) < exact
    assert (np.sign(f(out_lo)) == s_lo).all() and (np.sign(f(out_hi)) != s_lo).all()
    adjacent = np.nextafter(out_lo, out_hi) == out_hi
    near = (np.abs(f(out_lo)) <= 1e-12) & (np.abs(f(out_hi)) <= 1e-12)
    assert (adjacent | near).all() and near.any()
    assert (np.abs(out_lo - c) < 2e-12).all() and (np.abs(out_hi - c) < 2e-12).all()


def test_shrunk_takes_a_bracket_from_either_end():
    # lo above hi (a run's start bracketed from its in-limit node back): a pair of
    # adjacent doubles at the same sign change as the bracket the other way round, in as
    # few steps (_node_fills brackets a run's start so: such a bracket must not be only halved).
    from robokin.kinematics.ik.self_motion_base import _shrunk

    c = np.array([0.08835, -1.2])
    up_lo, up_hi = c - np.array([0.02, 0.3]), c + np.array([0.013, 0.1])

    def f(t, a=slice(None)):
        return np.tanh(3.0 * (t - c[a])) + 0.1 * (t - c[a]) ** 2

    calls = []
    lo1, hi1, ok1 = _shrunk(_sides(f, np.sign(f(up_lo)), calls), up_lo, up_hi, f(up_lo),
                            f(up_hi), 240)
    n_up = len(calls)
    calls.clear()
    lo2, hi2, ok2 = _shrunk(_sides(f, np.sign(f(up_hi)), calls), up_hi, up_lo, f(up_hi),
                            f(up_lo), 240)
    assert ok1.all() and ok2.all()
    assert (np.nextafter(lo1, hi1) == hi1).all() and (lo1 < hi1).all()
    assert (np.nextafter(lo2, hi2) == hi2).all() and (lo2 > hi2).all()
    # the same sign change (f's sides at the pair: the low end's, then the other)
    assert (np.sign(f(lo2)) != np.sign(f(hi2))).all()
    assert (np.abs(hi2 - lo1) <= 2 * np.spacing(np.abs(c))).all()
    assert len(calls) <= n_up + 2 and n_up <= 20


def test_shrunk_halves_a_run_of_exact_zeros():
    # f exactly 0 on [0.2, 0.6] (a joint held at its value to the bit): the neighbouring
    # double of a zero end is probed, but the pace's midpoints still halve the bracket,
    # so it ends at adjacent doubles within bisection's reach, not an ulp at a time.
    from robokin.kinematics.ik.self_motion_base import _shrunk

    lo, hi = np.array([0.0]), np.array([1.0])

    def f(t):
        return np.where(t < 0.2, t - 0.2, np.where(t > 0.6, t - 0.6, 0.0))

    calls = []

    def side(t, a):
        calls.append(len(a))
        v = f(t)
        return v, v < 0.0, np.ones(len(a), bool)

    out_lo, out_hi, found = _shrunk(side, lo, hi, f(lo), f(hi), 240)
    assert found.all() and np.nextafter(out_lo, out_hi) == out_hi
    assert f(out_lo)[0] < 0.0 and f(out_hi)[0] == 0.0 and 0.19 < out_lo[0] < 0.21
    assert len(calls) <= 120
