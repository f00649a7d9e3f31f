"""Joint-space segments and time-scaling profiles: boundary conditions, peaks, limits."""

import numpy as np
import pytest

from robokin import InputError, trajectory
from robokin.trajectory import get_profile
from robokin.trajectory.profiles import PROFILES, lspb_timing


def test_quintic_meets_boundary_conditions_to_1e12(rng):
    for _ in range(20):
        q0, q1, v0, v1, a0, a1 = rng.normal(size=(6, 6))
        T = rng.uniform(0.3, 5.0)
        tr = trajectory.quintic(q0, q1, T, 0.005, qd0=v0, qd1=v1, qdd0=a0, qdd1=a1)
        assert tr.t[0] == 0.0 and tr.t[-1] == pytest.approx(T, abs=1e-15)
        for got, want in ((tr.q[0], q0), (tr.q[-1], q1), (tr.qd[0], v0),
                          (tr.qd[-1], v1), (tr.qdd[0], a0), (tr.qdd[-1], a1)):
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)


def test_quintic_rates_are_the_derivatives(rng):
    q0, q1 = rng.normal(size=(2, 3))
    tr = trajectory.quintic(q0, q1, 2.0, 0.001, qd0=[0.1, 0, -0.2])
    np.testing.assert_allclose(np.gradient(tr.q, tr.t, axis=0)[1:-1], tr.qd[1:-1],
                               atol=1e-5)
    np.testing.assert_allclose(np.gradient(tr.qd, tr.t, axis=0)[1:-1], tr.qdd[1:-1],
                               atol=1e-4)


def test_rest_quintic_matches_hand_formula():
    tr = trajectory.quintic([0.0], [2.0], 4.0, 0.5)
    tau = tr.t / 4.0
    np.testing.assert_allclose(tr.q[:, 0], 2 * (10 * tau**3 - 15 * tau**4 + 6 * tau**5),
                               atol=1e-14)
    assert tr.qd[:, 0].max() == pytest.approx(2 * 1.875 / 4.0)  # C_v D / T at mid


def test_cubic_boundary_conditions(rng):
    q0, q1, v0, v1 = rng.normal(size=(4, 4))
    tr = trajectory.cubic(q0, q1, 1.7, 0.01, qd0=v0, qd1=v1)
    np.testing.assert_allclose(tr.q[[0, -1]], [q0, q1], atol=1e-12)
    np.testing.assert_allclose(tr.qd[[0, -1]], [v0, v1], atol=1e-12)


def test_time_grid_has_fixed_dt_and_the_end():
    t = trajectory.time_grid(25.0, 0.005)
    assert t.size == 5001 and t[-1] == 25.0
    np.testing.assert_allclose(np.diff(t), 0.005, atol=1e-12)
    t = trajectory.time_grid(1.0013, 0.005)
    assert t[-1] == 1.0013 and t[-2] == pytest.approx(1.0)


@pytest.mark.parametrize("name", sorted(set(PROFILES) - {"lspb", "pca", "linear"}))
def test_profiles_rest_to_rest_and_peak_coefficients(name):
    p = get_profile(name)
    tau = np.linspace(0.0, 1.0, 200001)
    s, sd, sdd = p.evaluate(tau)
    assert s[0] == pytest.approx(0.0, abs=1e-15) and s[-1] == pytest.approx(1.0, abs=1e-14)
    assert np.abs(sd).max() == pytest.approx(p.peak_velocity, rel=1e-6)
    if np.isfinite(p.peak_acceleration):
        assert np.abs(sdd).max() == pytest.approx(p.peak_acceleration, rel=1e-4)
    h = tau[1]
    np.testing.assert_allclose(np.gradient(s, h)[1:-1], sd[1:-1], atol=2e-5)
    if name not in ("trapezoidal", "constant_velocity"):  # those have steps in s''
        np.testing.assert_allclose(np.gradient(sd, h)[2:-2], sdd[2:-2], atol=1e-3)
    if name in ("quintic", "cycloidal", "modified_sine", "piecewise_acceleration"):
        assert abs(sdd[0]) < 1e-12 and abs(sdd[-1]) < 1e-9  # no acceleration steps


def test_published_coefficients():
    # Biagiotti & Melchiorri, table 3.1: modified sine C_v = 1.76, C_a = 5.53;
    # cycloidal C_v = 2, C_a = 2 pi.
    ms = get_profile("modified_sine")
    assert ms.peak_velocity == pytest.approx(1.76, abs=5e-3)
    assert ms.peak_acceleration == pytest.approx(5.53, abs=5e-3)
    # Trapezoidal acceleration with ramps of 1/4: triangular acceleration, C_a = 8.
    assert get_profile("pca", ramp=0.25).peak_acceleration == pytest.approx(8.0)


def test_lspb_timing_hand_case():
    # D = 2, v = 1, a = 2: T = D/v + v/a = 2.5 s, blend time 0.5 s -> f = 0.2.
    dur, f = lspb_timing([1.0, 2.0], 1.0, 2.0)
    assert dur == pytest.approx(2.5, rel=1e-9) and f == pytest.approx(0.2, rel=1e-6)
    # Short move: triangular, T = 2 sqrt(D/a).
    dur, f = lspb_timing([0.5], 10.0, 2.0)
    assert dur == pytest.approx(2 * np.sqrt(0.25), rel=1e-9) and f == pytest.approx(0.5)


def test_trapezoidal_respects_limits(rng):
    q0, q1 = rng.normal(size=(2, 6))
    v, a = np.full(6, 0.8), np.full(6, 1.5)
    tr = trajectory.trapezoidal(q0, q1, v_max=v, a_max=a)
    assert np.all(np.abs(tr.qd) <= v + 1e-9)
    assert np.all(np.abs(tr.qdd) <= a + 1e-9)
    np.testing.assert_allclose(tr.q[-1], q1, atol=1e-12)
    assert np.isclose(tr.duration / 0.005, round(tr.duration / 0.005))


@pytest.mark.parametrize("fn", [trajectory.cycloidal, trajectory.modified_sine,
                                trajectory.piecewise_acceleration])
def test_profile_motion_durations_from_limits(fn, rng):
    q0, q1 = rng.normal(size=(2, 4))
    tr = fn(q0, q1, v_max=1.0, a_max=2.0)
    peak_v, peak_a = np.abs(tr.qd).max(), np.abs(tr.qdd).max()
    assert peak_v <= 1.0 + 1e-9 and peak_a <= 2.0 + 1e-9
    assert max(peak_v / 1.0, peak_a / 2.0) > 0.95  # no more than rounding to dt slack
    np.testing.assert_allclose(tr.q[[0, -1]], [q0, q1], atol=1e-12)


def test_constant_velocity_palletizer_sweep():
    v = np.array([0.1, -0.05, 0.02, 0.3])
    tr = trajectory.constant_velocity(np.zeros(4), v, 10.0, 0.01)
    np.testing.assert_allclose(tr.q[-1], 10.0 * v, atol=1e-12)
    assert np.all(tr.qd == v) and not tr.qdd.any()


def test_bad_inputs_name_the_argument():
    with pytest.raises(InputError, match="duration"):
        trajectory.quintic([0.0], [1.0], -1.0)
    with pytest.raises(InputError, match="q1"):
        trajectory.quintic([0.0, 1.0], [1.0], 1.0)
    with pytest.raises(InputError, match="dt"):
        trajectory.quintic([0.0], [1.0], 1.0, dt=0.0)
    with pytest.raises(InputError, match="unknown profile"):
        get_profile("bogus")
    with pytest.raises(InputError, match="blend"):
        get_profile("trapezoidal", blend=0.7)
    with pytest.raises(InputError, match="duration"):
        trajectory.cycloidal([0.0], [1.0])


@pytest.mark.parametrize("fn", [trajectory.quintic, trajectory.cycloidal,
                                trajectory.trapezoidal])
@pytest.mark.parametrize(("kw", "match"), [
    ({"v_max": -1.0, "a_max": 2.0}, "v_max.*positive"),
    ({"v_max": 1.0, "a_max": 0.0}, "a_max.*positive"),
    ({"v_max": float("nan"), "a_max": 2.0}, "v_max.*positive"),
    ({"v_max": [1.0, 2.0, 3.0], "a_max": 2.0}, r"v_max.*shape \(2,\)"),
    ({"v_max": "fast", "a_max": 2.0}, "v_max"),
])
def test_bad_limits_are_rejected_not_turned_into_a_one_step_jump(fn, kw, match):
    # A negative v_max used to give a "minimum duration" of 0: the whole move in
    # one dt with zero velocity at both samples.
    if fn is trajectory.quintic:
        fn = lambda q0, q1, **k: trajectory.profile_motion(q0, q1, profile="quintic", **k)  # noqa: E731
    with pytest.raises(InputError, match=match):
        fn([0.0, 0.0], [1.0, 2.0], **kw)


def test_time_grid_rejects_non_numbers_by_name():
    with pytest.raises(InputError, match="dt"):
        trajectory.quintic([0.0], [1.0], 1.0, dt="fast")
    with pytest.raises(InputError, match="duration"):
        trajectory.time_grid("long", 0.01)


@pytest.mark.parametrize(("max_samples", "match"), [
    ("abc", "whole number"), (1.5, "whole number"), (True, "whole number"),
    (0, ">= 1"), (-5, ">= 1"),
])
def test_a_bad_max_samples_is_refused_by_its_name(max_samples, match):
    # "abc" used to raise a bare ValueError, 0 an error naming 'duration', 1.5 to be
    # truncated to a cap of 1
    with pytest.raises(InputError, match=match) as info:
        trajectory.time_grid(1.0, 0.5, max_samples=max_samples)
    assert info.value.argument == "max_samples"


def test_max_samples_caps_a_grid_and_takes_numpy_integers():
    assert trajectory.time_grid(1.0, 0.5, max_samples=np.int64(4)).tolist() == [0.0, 0.5, 1.0]
    with pytest.raises(InputError, match="more than the limit of 3") as info:
        trajectory.time_grid(1.0, 0.5, max_samples=3)
    assert info.value.argument == "duration"
