"""Plan vs a synthetic 'real' run: the known offset, noise and lag are recovered."""

import numpy as np
import pytest

from robokin import InputError, trajectory
from robokin.trajectory import io
from robokin.trajectory.compare import compare


@pytest.fixture
def plan():
    q0 = np.zeros(6)
    q1 = np.radians([40, -30, 60, 20, -45, 90])
    return trajectory.quintic(q0, q1, 4.0, 0.005)


def test_recovers_known_offset_and_noise(plan, rng, tmp_path):
    offset = np.radians([0.1, -0.2, 0.05, 0.0, 0.3, -0.1])
    sigma = np.radians(0.01)
    # the 'real' log: another rate (8 ms), starts later, offset plus noise
    t_log = np.arange(0.0, 4.0, 0.008) + 0.001
    q_log = plan.at(t_log) + offset + rng.normal(0, sigma, (t_log.size, 6))
    p = tmp_path / "log.csv"
    lines = ["t [s]," + ",".join(f"j{i + 1} [deg]" for i in range(6))]
    lines += [",".join([repr(float(t))] + [repr(float(v)) for v in np.degrees(row)])
              for t, row in zip(t_log, q_log)]
    p.write_text("\n".join(lines) + "\n")
    cmp = compare(plan, io.read_log(p))
    np.testing.assert_allclose(cmp.mean, offset, atol=4 * sigma / np.sqrt(400))
    expected_rms = np.sqrt(offset**2 + sigma**2)
    np.testing.assert_allclose(cmp.rms, expected_rms, rtol=0.05, atol=2e-5)
    # the max error is the offset plus at most a few sigma of noise
    assert np.all(cmp.max_abs >= np.abs(offset))
    assert np.all(cmp.max_abs <= np.abs(offset) + 5 * sigma + 1e-4)
    rows = cmp.table()
    assert rows[1]["unit"] == "deg" and rows[1]["mean"] == pytest.approx(-0.2, abs=0.01)


def test_error_growing_with_acceleration_is_reported(plan):
    # a controller that lags in proportion to the acceleration
    real = plan.replace(q=plan.q + 0.002 * plan.qdd)
    cmp = compare(plan, real)
    moving = np.abs(plan.q[-1] - plan.q[0]) > 0
    assert np.all(cmp.acceleration_correlation[moving] > 0.99)
    np.testing.assert_allclose(cmp.max_abs, 0.002 * np.abs(plan.qdd).max(axis=0),
                               rtol=1e-9)
    j = int(np.argmax(cmp.max_abs))
    k = int(np.argmin(np.abs(plan.t - cmp.t_max[j])))
    assert abs(plan.qdd[k, j]) == pytest.approx(np.abs(plan.qdd[:, j]).max(), rel=1e-12)


def test_time_shift_and_errors(plan):
    late = plan.shifted(10.0)
    cmp = compare(plan, late, time_shift=-10.0)
    assert cmp.max_abs.max() < 1e-12
    with pytest.raises(InputError, match="do not overlap"):
        compare(plan, late)
    with pytest.raises(InputError, match="joints"):
        compare(plan, trajectory.quintic([0.0], [1.0], 1.0))
