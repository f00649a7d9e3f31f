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
