"""Pose selection: the chosen poses identify better than random poses of the same count.

Oracles: the observability index O1 of random subsets, and the hold-out error of
calibrations on the selected vs random subsets (same synthetic truth).
"""

from __future__ import annotations

import numpy as np
import pytest

from robokin import calibration
from robokin.exceptions import InputError

from .conftest import make_case


@pytest.fixture(scope="module")
def case(ur5):
    return make_case(ur5, "position", n=600, hold=1000, seed=14)


def test_selected_poses_beat_random_ones(ur5, case):
    k = 30
    idx = calibration.select_poses(ur5, case.q, k)
    assert len(set(idx.tolist())) == k
    o_sel = calibration.observability_index(ur5, case.q[idx])
    rng = np.random.default_rng(5)
    randoms = [rng.choice(len(case.q), k, replace=False) for _ in range(10)]
    o_rand = [calibration.observability_index(ur5, case.q[r]) for r in randoms]
    assert o_sel > max(o_rand)

    def holdout(sub):
        res = calibration.calibrate(ur5, case.q[sub], case.measured[sub])
        return calibration.holdout_report(res, case.q_hold, case.measured_hold).after.rms

    sel = holdout(idx)
    rand = [holdout(r) for r in randoms[:5]]
    assert sel < np.median(rand)


def test_i_optimal_selection_lowers_the_mean_prediction_variance(ur5, case):
    # oracle: trace(M A^-1) computed here from the Jacobians of every candidate
    from robokin.calibration._select import _jacobians

    J = _jacobians(ur5, case.q, "position", np.radians(10))
    p = J.shape[-1]
    # columns scaled (trace(M A^-1) does not change; inv() stays well conditioned)
    J = J / np.linalg.norm(J.reshape(-1, p), axis=0)
    M = np.einsum("cip,ciq->pq", J, J) / len(J)

    def variance(idx):
        A = np.einsum("cip,ciq->pq", J[idx], J[idx])
        return np.trace(M @ np.linalg.inv(A))

    sel = calibration.select_poses(ur5, case.q, 30, criterion="I")
    rng = np.random.default_rng(9)
    randoms = [variance(rng.choice(len(case.q), 30, replace=False)) for _ in range(10)]
    assert variance(sel) < min(randoms)
    assert p == 27
    with pytest.raises(InputError, match="argument 'criterion'"):
        calibration.select_poses(ur5, case.q, 30, criterion="A")


def test_selection_is_deterministic_and_checks_k(ur5, case):
    a = calibration.select_poses(ur5, case.q[:200], 20, kind="pose")
    b = calibration.select_poses(ur5, case.q[:200], 20, kind="pose")
    np.testing.assert_array_equal(a, b)
    for bad in (0, 201, 2.5, True):
        with pytest.raises(InputError, match="argument 'k'"):
            calibration.select_poses(ur5, case.q[:200], bad)
    with pytest.raises(InputError, match="argument 'kind'"):
        calibration.select_poses(ur5, case.q[:200], 5, kind="twist")
    with pytest.raises(InputError, match="argument 'candidate_q'"):
        calibration.select_poses(ur5, case.q[:200, :5], 5)
