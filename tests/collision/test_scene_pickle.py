"""A scene travels to other processes (Dask workers): it pickles, even after a check
compiled coal objects into it, and rebuilds from its declared shapes (issue 16)."""

import pickle

import numpy as np
import pytest

import robokin
from robokin.collision import Scene, check, scene_path

pytest.importorskip("coal")


@pytest.fixture
def press():
    return Scene.load(scene_path("press"))


def test_a_checked_scene_pickles_and_checks_the_same(press):
    robot = robokin.load("aubo_i5")
    q = np.radians([[0, -10, 80, 0, 90, 0], [20, 0, 100, 10, 60, 0]])
    before = check(robot, press, q)
    assert "_check_cache" in press.__dict__  # coal objects compiled into it
    copy = pickle.loads(pickle.dumps(press))
    assert "_check_cache" not in copy.__dict__
    assert copy.names == press.names
    assert copy.tool is not None and press.tool is not None
    assert len(copy.tool.shapes) == len(press.tool.shapes)
    for a, b in zip(copy.objects, press.objects):
        assert a.shape is not b.shape and not a.shape._cache  # rebuilt, caches left behind
        np.testing.assert_array_equal(a.pose, b.pose)
    np.testing.assert_array_equal(copy.base, press.base)
    assert copy.poses.keys() == press.poses.keys()
    after = check(robot, copy, q)
    assert after.min_distance == before.min_distance
    assert after.collides == before.collides


def test_a_placed_robot_pickles_with_its_scene(press):
    placed = press.attach(robokin.load("aubo_i5"))
    check(placed, press, np.zeros((2, 6)))
    robot2, scene2 = pickle.loads(pickle.dumps((placed, press)))
    assert scene2.unplaced(robot2) is not robot2  # still recognised as placed by it
    np.testing.assert_array_equal(scene2.attach(robot2).base, placed.base)


def test_with_base_moves_only_the_robot(press):
    T = np.eye(4)
    T[:3, 3] = (0.1, -0.2, 0.0)
    moved = press.with_base(T)
    np.testing.assert_array_equal(moved.base, T)
    np.testing.assert_array_equal(press.base, np.eye(4))
    assert moved.objects == press.objects and moved.tool is press.tool
    robot = robokin.load("aubo_i5")
    q = np.radians([[0, -10, 80, 0, 90, 0]])
    a = check(robot, moved, q).min_distance
    b = check(robot.with_base(T), press, q).min_distance
    assert a == pytest.approx(b, abs=1e-12)


def test_unplaced_returns_the_original(press):
    bare = robokin.load("aubo_i5")
    placed = press.attach(bare)
    assert press.unplaced(placed) is bare
    assert press.unplaced(bare) is bare
    assert Scene("other").unplaced(placed) is placed  # another scene did not place it
