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
