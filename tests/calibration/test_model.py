"""The identification model: nominal FK, its exact Jacobian, the rows it chooses.

Oracles: the robot's own FK (the model at zero errors is the robot), central
finite differences of the model (the analytic Jacobian), and the geometry of
the arms (which consecutive axes are parallel).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import robokin
from robokin.calibration._fit import Problem
from robokin.calibration._model import Model
from robokin.calibration.synthetic import random_configurations

from .conftest import TOOL, TRACKER, irb140

TOL = math.radians(10)
ROBOTS = ["ur5", "aubo_i5", "puma560", "puma560_modified", "panda", "scara",
          "qfmd010", "improved_dh_arm"]


def _robot(name: str) -> robokin.Robot:
    return irb140() if name == "irb140" else robokin.load(name)


@pytest.mark.parametrize("name", ROBOTS + ["irb140"])
def test_model_at_zero_errors_is_the_robot(name):
    robot = _robot(name).with_base(TRACKER).with_tool(TOOL)
    model = Model.from_chain(robot.chain, parallel_tol=TOL)
    q = random_configurations(robot, np.random.default_rng(3), 40)
    q[0] = 0.0
    T = model.evaluate(q, np.zeros(model.size), robot.base, robot.tool).T
    np.testing.assert_allclose(T, robot.fk(q), atol=1e-12)
    # and the chain it builds (in its identification frames) too
    chain = model.chain_at(np.zeros(model.size), robot.base, robot.tool)
    np.testing.assert_allclose(robot.replace(chain=chain).fk(q), robot.fk(q), atol=1e-12)


@pytest.mark.parametrize("name", ["ur5", "aubo_i5", "scara", "panda", "irb140"])
@pytest.mark.parametrize("kind", ["position", "pose"])
def test_jacobian_matches_finite_differences(name, kind):
    robot = _robot(name)
    rng = np.random.default_rng(7)
    model = Model.from_chain(robot.chain, parallel_tol=TOL, extras=("scale",))
    q = random_configurations(robot, rng, 12)
    x = rng.normal(0, 1e-3, model.size)  # away from nominal: exact, not linearised
    T = model.evaluate(q, x, TRACKER, TOOL).T
    # measured poses rotated by up to ~0.3 rad from the model: J_l^-1 matters
    from robokin.spatial import matrix_from_axis_angle
    meas = T.copy()
    meas[:, :3, :3] = matrix_from_axis_angle(rng.normal(0, 0.2, (12, 3)))[:, :3, :3] \
        @ T[:, :3, :3]
    meas = meas if kind == "pose" else meas[:, :3, 3] + 1e-3
    prob = Problem(model, q, meas, kind == "pose", TRACKER, TOOL, None, 0.3)
    active = np.arange(model.size)
    r, J = prob.residual_and_jacobian(x, active)
    h = 1e-7
    Jfd = np.empty_like(J)
    for i in active:
        xp, xm = x.copy(), x.copy()
        xp[i] += h
        xm[i] -= h
        Jfd[:, i] = (prob.residual_and_jacobian(xp, active)[0]
                     - prob.residual_and_jacobian(xm, active)[0]) / (2 * h)
    np.testing.assert_allclose(J, Jfd, atol=2e-7)


def test_compliance_jacobian_matches_finite_differences(ur5):
    rng = np.random.default_rng(8)
    model = Model.from_chain(ur5.chain, parallel_tol=TOL, extras=("compliance",))
    q = random_configurations(ur5, rng, 10)
    tau = rng.normal(0, 50, (10, 6))
    x = rng.normal(0, 1e-4, model.size)
    prob = Problem(model, q, np.zeros((10, 3)), False, TRACKER, TOOL, tau)
    active = np.array([model.index(f"j{k}.compliance") for k in range(1, 7)])
    _, J = prob.residual_and_jacobian(x, active)
    for c, i in enumerate(active):
        xp, xm = x.copy(), x.copy()
        xp[i] += 1e-7
        xm[i] -= 1e-7
        fd = (prob.residual_and_jacobian(xp, active)[0]
              - prob.residual_and_jacobian(xm, active)[0]) / 2e-7
        np.testing.assert_allclose(J[:, c], fd, atol=1e-6)


@pytest.mark.parametrize(("name", "hayati"), [
    ("ur5", [2, 3]),            # joints 2-3-4 parallel: rows 2 and 3
    ("aubo_i5", [2, 3]),
    ("puma560", [2]),           # shoulder and elbow parallel
    ("irb140", [2]),            # joints 2-3 parallel
    ("panda", []),
    ("scara", [1, 2, 3]),       # every axis vertical
])
def test_hayati_beta_exactly_on_parallel_axes(name, hayati):
    model = Model.from_chain(_robot(name).chain, parallel_tol=TOL)
    got = [k + 1 for k, r in enumerate(model.rows) if r.form == "hayati"]
    assert got == hayati
    for k in hayati:
        assert f"j{k}.beta" in model.names and f"j{k}.d" not in model.names


def test_exactly_parallel_axes_never_take_dh(ur5):
    # parallel_tol=0 asks for DH everywhere; exactly parallel axes have no
    # common normal, so they still get the Hayati row (no division by zero)
    model = Model.from_chain(ur5.chain, parallel_tol=0.0)
    assert [r.form for r in model.rows] == ["dh", "hayati", "hayati", "dh", "dh"]
    assert all(np.isfinite([r.theta, r.d, r.a, r.alpha, r.beta]).all()
               for r in model.rows)


def test_near_parallel_axes_take_beta_with_short_lengths():
    # axis 3 tilted 0.5 deg about y towards axis 2 (0.45 m away): standard DH
    # puts the common normal ~50 m away (d = a / tan 0.5 deg); the Hayati row
    # keeps every length at arm scale
    h = math.pi / 2
    ops = [dict(op="rz", joint="revolute"), dict(op="tz", value=0.4),
           dict(op="rx", value=h), dict(op="rz", joint="revolute"),
           dict(op="tx", value=0.45), dict(op="ry", value=math.radians(0.5)),
           dict(op="rz", joint="revolute"), dict(op="tx", value=0.4),
           dict(op="rx", value=h), dict(op="rz", joint="revolute"),
           dict(op="tz", value=0.4), dict(op="rx", value=-h),
           dict(op="rz", joint="revolute"), dict(op="rx", value=h),
           dict(op="rz", joint="revolute"), dict(op="tz", value=0.1)]
    robot = robokin.Robot.from_elementary(ops)
    model = Model.from_chain(robot.chain, parallel_tol=TOL)
    assert model.rows[1].form == "hayati"
    lengths = [abs(v) for r in model.rows for v in (r.a, r.d)]
    assert max(lengths) < 1.0
    strict = Model.from_chain(robot.chain, parallel_tol=0.0)  # DH everywhere
    assert max(abs(r.d) for r in strict.rows) > 40.0
