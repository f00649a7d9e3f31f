"""calibrate(): accuracy against a synthetic truth, what it reports, what it refuses.

Oracles: the true robot that generated the data (its parameters, and its
hold-out measurement noise: the noise floor no model can beat), random SE(3)
errors on every constant of the chain (a truth outside the model's own
parametrisation: the model must still reach the floor, so it is complete), and
a Monte-Carlo repeat of the noise for the covariance.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import robokin
from robokin import calibration
from robokin.calibration import synthetic
from robokin.exceptions import InputError
from robokin.spatial import matrix_from_axis_angle, trans

from .conftest import TOOL, TRACKER, make_case


def _floor(case) -> float:
    if case.measured_hold.ndim == 3:
        d = case.measured_hold[:, :3, 3] - case.clean_hold[:, :3, 3]
    else:
        d = case.measured_hold - case.clean_hold
    return float(np.sqrt((d**2).sum(1).mean()))


@pytest.fixture(scope="module", params=[("ur5", "position"), ("ur5", "pose"),
                                        ("irb", "position"), ("irb", "pose")],
                ids=lambda p: "-".join(p))
def solved(request, ur5, irb):
    name, kind = request.param
    case = make_case(ur5 if name == "ur5" else irb, kind)
    return case, calibration.calibrate(case.nominal, case.q, case.measured, kind=kind)


def test_holdout_rms_reaches_the_noise_floor(solved):
    case, res = solved
    rep = calibration.holdout_report(res, case.q_hold, case.measured_hold)
    floor = _floor(case)
    assert rep.after.rms <= 1.1 * floor
    assert rep.before.rms > 20 * floor  # the nominal model (base and tool fitted)
    assert res.residual_rms < 1.1 * floor


def test_every_parameter_within_3_sigma_of_truth(solved):
    case, res = solved
    truth = case.true.truth
    compared = 0
    for p in res.parameters:
        if p.name in truth:
            assert abs(p.identified - truth[p.name]) < 3 * p.std, p
            compared += 1
    assert compared == len(truth)  # every true joint error was identified
    # base and tool against the true tracker and tool poses
    from robokin.calibration._model import pose_values
    for side, T in (("base", TRACKER), ("tool", TOOL)):
        for v, c in zip(pose_values(T), ("x", "y", "z", "roll", "pitch", "yaw")):
            if side == "tool" and c in ("roll", "pitch", "yaw") and res.kind == "position":
                continue
            p = res.parameter(f"{side}.{c}")
            assert abs(p.identified - v) < 3 * p.std + 1e-12, p


def test_no_length_moves_more_than_a_few_mm(solved):
    _, res = solved
    moved = [abs(p.error) for p in res.parameters
             if p.unit == "m" and p.name.startswith("j")]
    assert max(moved) < 3e-3


def test_identifiability_report(solved):
    case, res = solved
    names = {p.name for p in res.parameters}
    why = dict(res.unidentifiable)
    tool_rot = {"tool.roll", "tool.pitch", "tool.yaw"}
    if res.kind == "position":
        assert tool_rot.isdisjoint(names)
        assert all("positions only" in why[n] for n in tool_rot)
        assert len(res.parameters) == 27  # 4R + 6 - 3 for a 6R arm
    else:
        assert tool_rot <= names and tool_rot.isdisjoint(why)
        assert len(res.parameters) == 30
    assert "absorbed by the base" in why["j1.theta"]
    assert "absorbed by the tool" in why["j6.theta"]
    # Hayati's beta on the parallel axes, no d there
    beta = {p for p in names if p.endswith(".beta")}
    assert beta == ({"j2.beta", "j3.beta"} if "j4.d" in names and
                    case.nominal.name == "ur5" else beta)
    assert "j2.d" not in names


def test_same_inputs_same_result(ur5):
    case = make_case(ur5, "position", n=60, hold=0, seed=4)
    a = calibration.calibrate(ur5, case.q, case.measured)
    b = calibration.calibrate(ur5, case.q, case.measured)
    assert [p.identified for p in a.parameters] == [p.identified for p in b.parameters]


def test_complete_against_errors_outside_the_model(ur5):
    # every constant of the canonical chain moved by a random rigid motion
    # (0.5 mm, 0.05 deg): a truth not drawn in the model's own parameters
    rng = np.random.default_rng(11)
    c = ur5.chain

    def wobble(T):
        E = matrix_from_axis_angle(rng.normal(0, math.radians(0.05), 3))
        return T @ trans(rng.normal(0, 5e-4, 3)) @ E

    true_chain = c.replace(head=wobble(c.head),
                           link_offsets=np.array([wobble(G) for G in c.link_offsets]),
                           base=TRACKER, tool=TOOL)
    true = ur5.replace(chain=true_chain)
    q = synthetic.random_configurations(ur5, rng, 1200)
    m, clean = synthetic.measure(true, q, rng, kind="pose")
    res = calibration.calibrate(ur5, q[:200], m[:200], kind="pose")
    pos, rot = calibration.evaluate(res.robot, q[200:], m[200:], rotation=True)
    floor = np.sqrt(((m[200:, :3, 3] - clean[200:, :3, 3])**2).sum(1).mean())
    assert np.sqrt((pos**2).mean()) < 1.1 * floor
    # the rotation floor: the noise's own angle, sqrt(3) * 0.005 deg RMS
    assert np.sqrt((rot**2).mean()) < 1.1 * math.sqrt(3) * math.radians(0.005)


def test_outliers_are_set_aside(ur5):
    case = make_case(ur5, "position", outliers=0.05, seed=5)
    res = calibration.calibrate(ur5, case.q, case.measured)
    bad = np.flatnonzero(np.linalg.norm(case.measured - case.clean, axis=1) > 1e-3)
    assert set(bad) <= set(res.outliers)
    assert len(res.outliers) <= len(bad) + 2
    rep = calibration.holdout_report(res, case.q_hold, case.measured_hold)
    assert rep.after.rms <= 1.1 * _floor(case)
    # a plain least-squares fit of the same data does worse
    assert res.residual_rms < 1.1 * _floor(case)


def test_covariance_matches_a_monte_carlo_repeat(ur5):
    rng = np.random.default_rng(21)
    true = synthetic.perturb(ur5, rng, base=TRACKER, tool=TOOL)
    q = synthetic.random_configurations(ur5, rng, 60)
    clean = true.robot.fk(q)[:, :3, 3]
    names = ["j2.beta", "j3.a", "j4.d", "j5.alpha", "tool.z"]
    runs, predicted = [], None
    for _ in range(30):
        m = clean + rng.normal(0, 2e-5, clean.shape)
        res = calibration.calibrate(ur5, q, m)
        runs.append([res.parameter(n).identified for n in names])
        if predicted is None:
            predicted = np.array([res.parameter(n).std for n in names])
    empirical = np.std(np.array(runs), axis=0, ddof=1)
    # 30 repeats: the sample std is within ~+-27 % of the true one (2 sigma)
    np.testing.assert_allclose(empirical, predicted, rtol=0.35)


def test_base_tool_only_and_named_models(ur5):
    case = make_case(ur5, "position", n=80, hold=200, seed=6)
    bt = calibration.calibrate(ur5, case.q, case.measured, model="base_tool")
    assert {p.name.split(".")[0] for p in bt.parameters} == {"base", "tool"}
    rep = calibration.holdout_report(bt, case.q_hold, case.measured_hold)
    if not bt.outliers:  # both least-squares fits of base and tool on the same poses
        np.testing.assert_allclose(rep.after.rms, rep.before.rms, rtol=1e-6)
    some = calibration.calibrate(ur5, case.q, case.measured,
                                 model=["base.x", "base.y", "base.z", "base.roll",
                                        "base.pitch", "base.yaw", "tool.x", "tool.y",
                                        "tool.z", "j2.a", "j3.a"])
    assert {p.name for p in some.parameters} >= {"j2.a", "j3.a"}
    fixed = calibration.calibrate(ur5, case.q, case.measured, fixed=["j5.theta"])
    assert "j5.theta" not in {p.name for p in fixed.parameters}


def test_gear_ratio_extra(ur5):
    rng = np.random.default_rng(31)
    true = synthetic.perturb(ur5, rng, base=TRACKER, tool=TOOL)
    scale = np.array([0, 2e-3, -1e-3, 0, 0, 0])  # joints 2 and 3 turn 0.2 % more/less
    q = synthetic.random_configurations(ur5, rng, 300)
    m, _ = synthetic.measure(true.robot, q * (1 + scale), rng)
    plain = calibration.calibrate(ur5, q, m)
    res = calibration.calibrate(ur5, q, m, extras=("scale",))
    assert res.residual_rms < 0.2 * plain.residual_rms
    for k in (2, 3):
        p = res.parameter(f"j{k}.scale")
        assert abs(p.identified - scale[k - 1]) < 3 * p.std
    # the calibrated robot carries it (a coupling): its FK fits the data
    e = calibration.evaluate(res.robot, q, m)
    assert np.sqrt((e**2).mean()) < 1.1 * res.residual_rms


def test_compliance_extra(ur5):
    rng = np.random.default_rng(41)
    true = synthetic.perturb(ur5, rng, base=TRACKER, tool=TOOL)
    q = synthetic.random_configurations(ur5, rng, 300)
    tau = 60 * np.cos(q[:, [1]] + np.zeros((1, 6)))  # a gravity-like load
    c = np.array([0, 2e-6, 3e-6, 0, 0, 0])  # rad / (N m)
    m, _ = synthetic.measure(true.robot, q + c * tau, rng)
    res = calibration.calibrate(ur5, q, m, extras=["compliance"], torque=tau)
    for k in (2, 3):
        p = res.parameter(f"j{k}.compliance")
        assert abs(p.identified - c[k - 1]) < 3 * p.std
    assert p.unit == "rad/(N m)"


# ------------------------------------------------------------------ refusals
def test_too_few_poses_is_refused_naming_the_count(ur5):
    case = make_case(ur5, "position", n=8, hold=0)
    with pytest.raises(InputError, match=r"too few poses: 8 give 24 equations for 27"):
        calibration.calibrate(ur5, case.q, case.measured)


def test_a_joint_that_never_moves_is_refused_naming_its_parameters(ur5):
    case = make_case(ur5, "position", n=100, hold=0, seed=9)
    q = case.q.copy()
    q[:, 4] = 0.3  # wrist 2 parked: its link cannot be told from the tool
    m = case.true.robot.fk(q)[:, :3, 3]
    with pytest.raises(InputError, match=r"cannot identify .*j5\.") as err:
        calibration.calibrate(ur5, q, m)
    assert "fixed=" in str(err.value)


def test_unidentifiable_names_asked_for_are_refused(ur5):
    case = make_case(ur5, "position", n=60, hold=0)
    with pytest.raises(InputError, match=r"'tool.roll' cannot be identified: .*positions"):
        calibration.calibrate(ur5, case.q, case.measured, model=["tool.x", "tool.roll"])
    with pytest.raises(InputError, match=r"'j1.theta' cannot be identified: .*base"):
        calibration.calibrate(ur5, case.q, case.measured, model=["j1.theta"])
    with pytest.raises(InputError, match=r"unknown parameter 'j9.a'"):
        calibration.calibrate(ur5, case.q, case.measured, model=["j9.a"])
    with pytest.raises(InputError, match=r"argument 'fixed'.*'nope'"):
        calibration.calibrate(ur5, case.q, case.measured, fixed=["nope"])
    with pytest.raises(InputError, match=r"argument 'model'"):
        calibration.calibrate(ur5, case.q, case.measured, model="everything")


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"measured": np.zeros((60, 2))}, r"'measured'.*\(N, 3\)"),
    ({"measured": np.zeros((59, 3))}, r"'measured'.*59 measurements for 60"),
    ({"q": np.zeros((60, 5))}, r"argument 'q'"),
    ({"kind": "twist"}, r"'kind'.*'position' or 'pose'"),
    ({"kind": "pose"}, r"'measured'.*needs poses"),
    ({"extras": ["backlash"]}, r"'extras'.*unknown extra 'backlash'"),
    ({"extras": ["compliance"]}, r"'torque'.*compliance"),
    ({"torque": np.zeros((60, 6))}, r"'torque'.*without extras"),
    ({"rotation_weight": -1.0}, r"'rotation_weight'"),
    ({"parallel_tol": float("nan")}, r"'parallel_tol'"),
    ({"parallel_tol": 2.0}, r"'parallel_tol'"),
])
def test_bad_input_names_the_argument(ur5, kwargs, match):
    case = make_case(ur5, "position", n=60, hold=0)
    args = {"q": case.q, "measured": case.measured, **kwargs}
    with pytest.raises(InputError, match=match):
        calibration.calibrate(ur5, **args)


def test_nan_measurement_is_refused(ur5):
    case = make_case(ur5, "position", n=60, hold=0)
    m = case.measured.copy()
    m[3, 1] = np.nan
    with pytest.raises(InputError, match=r"'measured'.*non-finite"):
        calibration.calibrate(ur5, case.q, m)


def test_an_explicit_redundant_parameter_is_refused():
    # on the SCARA (all axes vertical) j3.theta trades with the base and tool
    scara = robokin.load("scara")
    case = make_case(scara, "pose", n=80, hold=0, seed=12)
    auto = calibration.calibrate(scara, case.q, case.measured, kind="pose")
    assert "redundant with" in dict(auto.unidentifiable)["j3.theta"]
    asked = [p.name for p in auto.parameters] + ["j3.theta"]
    with pytest.raises(InputError, match=r"cannot identify .*'j3.theta': redundant with"):
        calibration.calibrate(scara, case.q, case.measured, kind="pose", model=asked)
    # without its partners it is identifiable: asked alone with a few, it is fitted
    few = calibration.calibrate(scara, case.q, case.measured, kind="pose",
                                model=["base.x", "base.y", "j3.theta", "j2.a"])
    assert "j3.theta" in {p.name for p in few.parameters}


def test_a_prismatic_arm_reports_its_redundancies():
    # the SCARA: every axis vertical, a prismatic shaft; the fit must still
    # reach the floor with only identifiable parameters (no rank-deficient fit)
    scara = robokin.load("scara")
    case = make_case(scara, "pose", n=150, hold=300, seed=12)
    res = calibration.calibrate(scara, case.q, case.measured, kind="pose")
    rep = calibration.holdout_report(res, case.q_hold, case.measured_hold)
    assert rep.after.rms < 1.1 * _floor(case)
    assert all(p.std < 1e-3 for p in res.parameters)
