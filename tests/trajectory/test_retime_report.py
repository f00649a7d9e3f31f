"""The cycle-time report (issue 18, item 2): the minimum cycle time, which joint and
which limit is active where, the same path at a slower cycle time with margins."""

import json

import numpy as np
import pytest

import robokin
from robokin import trajectory
from robokin.exceptions import InputError
from robokin.io.strict_json import strict_json

pytest.importorskip("toppra")
from robokin.trajectory.cycle_time import cycle_time_report  # noqa: E402

Q0 = np.radians([0, -60, 80, -20, 90, 0])


@pytest.fixture(scope="module")
def ur5():
    return robokin.load("ur5")


@pytest.fixture(scope="module")
def two_limits(ur5):
    """A straight move where the shoulder's speed and the elbow's acceleration limit."""
    d = np.array([1.0, 0.0, 0.2, 0.0, 0.0, 0.0])
    tr = trajectory.quintic(Q0, Q0 + d, 3.0)
    v = np.array([0.5, 10, 10, 10, 10, 10])
    a = np.array([100, 100, 0.5, 100, 100, 100])
    return cycle_time_report(ur5, tr, v_max=v, a_max=a, cycle_time=9.0)


def test_the_bottlenecks_name_the_joint_and_the_limit(two_limits):
    rep = two_limits
    kinds = [(b.joint_name, b.kind) for b in rep.bottlenecks]
    # accelerate at the elbow's limit, cruise at the shoulder's, brake at the elbow's
    assert kinds == [("elbow", "acceleration"), ("shoulder_pan", "velocity"),
                     ("elbow", "acceleration")]
    accel, cruise, brake = rep.bottlenecks
    assert accel.t_start == 0.0 and brake.t_end == pytest.approx(rep.minimum_cycle_time)
    # the closed form: path speed V = 0.5 L / 1, path acceleration A = 0.5 L / 0.2
    L = np.hypot(1.0, 0.2)
    V, A = 0.5 * L, 0.5 * L / 0.2
    assert cruise.t_start == pytest.approx(V / A, abs=0.006)  # within a sample
    assert rep.minimum_cycle_time == pytest.approx(L / V + V / A, abs=1e-6)
    (section,) = rep.sections
    assert section.limiting == "shoulder_pan velocity"
    assert section.active_share > 0.99  # some limit is active all the time


def test_the_slower_retiming_has_uniform_margins(two_limits):
    rep = two_limits
    slow = rep.slower
    assert slow.duration == pytest.approx(9.0)
    c = 9.0 / rep.minimum_cycle_time
    # the bottleneck joint has exactly the margin the stretch gives it
    assert rep.margins["velocity"][0] == pytest.approx(1 - 1 / c, abs=1e-6)
    assert rep.margins["acceleration"][2] == pytest.approx(1 - 1 / c**2, abs=1e-6)
    assert (rep.margins["velocity"] >= 1 - 1 / c - 1e-9).all()
    assert rep.sections[0].slower == pytest.approx(9.0)


def test_ratios_reach_one_only_at_the_limits(two_limits):
    r = two_limits.ratios
    assert r["velocity"].max() <= 1 + 1e-6 and r["acceleration"].max() <= 1 + 1e-6
    assert r["velocity"][:, 0].max() == pytest.approx(1.0, abs=1e-6)


def test_report_is_json_and_text(two_limits):
    doc = json.loads(strict_json(two_limits.to_dict()))
    assert doc["minimum_cycle_time_s"] == pytest.approx(two_limits.minimum_cycle_time)
    assert doc["planned_s"] == pytest.approx(3.0)
    assert doc["limits"]["sources"]["velocity"] == "argument"
    assert doc["margins"]["velocity"][0] > 0
    text = str(two_limits)
    assert "minimum cycle time" in text and "shoulder_pan velocity" in text


def test_dwells_are_reported_and_kept(ur5):
    pb = trajectory.PathBuilder(ur5, Q0, v_max=1.0, a_max=2.0)
    pb.joint(Q0 + 0.3, label="out").dwell(0.5, label="wait").joint(Q0, label="back")
    rep = cycle_time_report(ur5, pb.build(), v_max=2.0, a_max=4.0, cycle_time=10.0)
    labels = [s.label for s in rep.sections]
    assert labels == ["out", "wait", "back"]
    wait = rep.sections[1]
    assert wait.kind == "dwell" and wait.minimum == pytest.approx(0.5)
    assert wait.slower == pytest.approx(0.5) and wait.limiting == ""
    assert rep.minimum.dwell_time == pytest.approx(0.5)


def test_bad_report_arguments(ur5):
    tr = trajectory.quintic(Q0, Q0 + 0.3, 1.0)
    with pytest.raises(InputError, match="shorter than the minimum"):
        cycle_time_report(ur5, tr, v_max=1.0, a_max=2.0, cycle_time=0.01)
    with pytest.raises(InputError, match="fraction") as info:
        cycle_time_report(ur5, tr, v_max=1.0, a_max=2.0, active_tol=2.0)
    assert info.value.argument == "active_tol"
