"""MuJoCo's contacts are robokin's collisions (issue 17, targets).

A deliberately colliding plan in the press cell: the same body pairs as
``collision.check``, starting and ending within one sample (5 ms); a clear plan:
no contact at all.
"""

from __future__ import annotations

import math

import pytest

import robokin
from robokin import trajectory

pytest.importorskip("mujoco")
pytest.importorskip("coal")

from robokin import collision, sim  # noqa: E402

DT = 0.005


@pytest.fixture(scope="module")
def cell():
    scene = collision.Scene.load(collision.scene_path("press"))
    return robokin.load("aubo_i5"), scene


def _plans(scene):
    qa = scene.pose_joints["press_approach"]
    qb = scene.pose_joints["press_place"]
    dive = qb.copy()
    dive[1] += math.radians(12)  # the gripper into the upper die
    fold = qa.copy()
    fold[2] += math.radians(33)  # the elbow folds the arm onto itself (174.7 deg)
    colliding = trajectory.Trajectory.concatenate([
        trajectory.quintic(qa, dive, 2.0, dt=DT), trajectory.quintic(dive, qa, 1.0, dt=DT),
        trajectory.quintic(qa, fold, 2.0, dt=DT)])
    clear = trajectory.quintic(qa, qb, 2.0, dt=DT)
    return colliding, clear


def _intervals(report):
    return sorted((iv.body_a, iv.body_b, iv.t_start, iv.t_end) for iv in report.intervals)


def test_contacts_agree_with_collision_check_on_a_colliding_plan(cell):
    robot, scene = cell
    colliding, _ = _plans(scene)
    rep = collision.check(robot, scene, colliding)
    assert rep.collides and len(rep.intervals) >= 4  # a scene pair and self pairs
    res = sim.simulate(robot, colliding, scene)
    want = _intervals(rep)
    got = sorted((c.body_a, c.body_b, c.t_start, c.t_end) for c in res.contacts)
    assert [w[:2] for w in want] == [g[:2] for g in got]
    for (_, _, w0, w1), (_, _, g0, g1) in zip(want, got):
        assert abs(w0 - g0) <= DT + 1e-9 and abs(w1 - g1) <= DT + 1e-9
    depth = {(iv.body_a, iv.body_b): -iv.min_distance for iv in rep.intervals}
    for c in res.contacts:
        assert c.depth == pytest.approx(depth[(c.body_a, c.body_b)], abs=5e-4)
    assert not res.ok and any("contact" in r for r in res.reasons)


def test_no_contact_on_a_clear_plan(cell):
    robot, scene = cell
    _, clear = _plans(scene)
    assert not collision.check(robot, scene, clear).collides
    res = sim.simulate(robot, clear, scene)
    assert res.contacts == ()
    assert res.ok, res.reasons


def test_physical_contacts_push_back(cell):
    robot, scene = cell
    colliding, _ = _plans(scene)
    first = collision.check(robot, scene, colliding).intervals[0]
    res = sim.simulate(robot, colliding, scene, contacts="physical")
    c = res.contacts[0]
    assert (c.body_a, c.body_b) == (first.body_a, first.body_b)
    assert abs(c.t_start - first.t_start) <= DT + 1e-9
    assert c.depth < 0.01  # blocked, not driven 46 mm through the die
    assert res.comparison.max_abs.max() > math.radians(1.0)
