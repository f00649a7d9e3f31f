"""Re-framing keeps the forward kinematics exactly and the link frames near nominal.

Oracles: the input chain's own FK; the nominal chain's link frames.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import robokin
from robokin.calibration import synthetic
from robokin.calibration._frames import frames_at_zero, reframe
from robokin.exceptions import ModelError

from .conftest import TOOL, TRACKER, irb140


@pytest.mark.parametrize("name", ["ur5", "aubo_i5", "puma560_modified", "panda",
                                  "scara", "qfmd010", "improved_dh_arm", "irb140"])
def test_reframe_onto_itself_is_the_same_chain(name):
    robot = irb140() if name == "irb140" else robokin.load(name)
    c = reframe(robot.chain, robot.chain)
    q = synthetic.random_configurations(robot, np.random.default_rng(1), 30)
    np.testing.assert_allclose(robot.replace(chain=c).fk(q), robot.fk(q), atol=1e-12)
    np.testing.assert_allclose(robot.replace(chain=c).fk_all(q), robot.fk_all(q),
                               atol=1e-12)


@pytest.mark.parametrize("name", ["ur5", "aubo_i5", "panda", "scara", "qfmd010"])
def test_perturbed_robot_keeps_link_frames_near_nominal(name):
    robot = robokin.load(name)
    true = synthetic.perturb(robot, np.random.default_rng(2)).robot
    q = synthetic.random_configurations(robot, np.random.default_rng(3), 30)
    # 0.5 mm / 0.05 deg errors: link frames within a few mm of the nominal ones
    d = np.abs(true.fk_all(q)[..., :3, 3] - robot.fk_all(q)[..., :3, 3]).max()
    assert d < 5e-3
    W, _ = frames_at_zero(true.chain)
    Wn, _ = frames_at_zero(robot.chain)
    assert np.abs(W[:, :3, 3] - Wn[:, :3, 3]).max() < 5e-3


def test_reframe_refuses_different_joints():
    with pytest.raises(ModelError, match="same joints"):
        reframe(robokin.load("ur5").chain, robokin.load("panda").chain)


def test_calibrated_robot_keeps_names_geometry_and_limits(ur5):
    from robokin import calibration

    from .conftest import make_case
    case = make_case(ur5, "position", n=80, hold=0, seed=3)
    res = calibration.calibrate(ur5, case.q, case.measured)
    r = res.robot
    assert r.joint_names == ur5.joint_names
    np.testing.assert_array_equal(r.limits, ur5.limits)
    assert r.geometry is ur5.geometry and r.dynamics is ur5.dynamics
    # base = measuring frame -> robot base, tool = flange -> TCP
    np.testing.assert_allclose(r.base[:3, 3], TRACKER[:3, 3], atol=1e-4)
    np.testing.assert_allclose(r.tool[:3, 3], TOOL[:3, 3], atol=1e-4)
    assert math.isfinite(res.residual_rms)
