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
