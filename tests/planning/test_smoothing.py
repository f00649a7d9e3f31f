"""Shortcuts, corner cutting and checked retiming (Planner.simplify, smoothing.py).

Oracles: the ends never move; every segment of the new path is free when sampled
every 0.01 rad with coal; sharp corners (over SHARP_TURN) are cut where that is free
and kept where it is not; a retimed trajectory whose steps are not all proven free
is replaced by one that stops at every waypoint, whose samples lie on the waypoints'
segments.
"""

from __future__ import annotations

import numpy as np

import robokin
from planning_oracle import Oracle, pose
from robokin import planning
from robokin.collision import Scene
from robokin.planning.smoothing import SHARP_TURN, retime_checked

PATH = np.array([[0.0, -1.57, 0.0, -1.57, 0.0, 0.0],
                 [1.0, -1.57, 0.0, -1.57, 0.0, 0.0],
                 [1.0, -1.57, 1.0, -1.57, 0.0, 0.0],  # 90 deg corners
                 [0.0, -1.57, 1.0, -1.07, 0.0, 0.0],
                 [-0.3, -1.57, 1.0, -0.87, 0.0, 0.0]])  # a gentle turn: left alone


def _turns(q):
    u = np.diff(q, axis=0)
    u /= np.linalg.norm(u, axis=1)[:, None]
    return np.arccos(np.clip(np.einsum("ij,ij->i", u[:-1], u[1:]), -1, 1))


def _dist(p, a, b):
    d = b - a
    t = np.clip(np.dot(p - a, d) / np.dot(d, d), 0, 1)
    return np.linalg.norm(a + t * d - p)


def _on_segment(p, a, b):
    d = b - a
    t = np.clip(np.dot(p - a, d) / np.dot(d, d), 0, 1)
    return np.linalg.norm(a + t * d - p) < 1e-12


def test_sharp_corners_are_cut_in_free_space_and_the_gentle_ones_kept():
    robot = robokin.load("ur5")
    scene = Scene("far")
    scene.add_box("far", (0.1, 0.1, 0.1), pose((3.0, 0.0, 0.0)))
    pl = planning.Planner(robot, scene)
    assert pl.path_free(PATH)
    out = pl.simplify(PATH, shortcut=False)
    assert np.array_equal(out[0], PATH[0]) and np.array_equal(out[-1], PATH[-1])
    assert _turns(PATH).max() > SHARP_TURN >= _turns(out).max() - 1e-12
    assert any(np.array_equal(out[k], PATH[3]) for k in range(len(out)))  # gentle: kept
    assert Oracle(robot, scene).path_min(out) > 0.0
    short = pl.simplify(PATH)  # with shortcuts too: shorter still
    length = lambda q: np.linalg.norm(np.diff(q, axis=0), axis=1).sum()  # noqa: E731
    assert length(short) < length(out) < length(PATH)
    assert np.array_equal(short[0], PATH[0]) and np.array_equal(short[-1], PATH[-1])


def test_a_zigzag_in_free_space_shortcuts_to_its_straight_segment():
    """The vertex pass joins the start to the farthest vertex it sees: here the goal.

    Oracle: the straight segment between the ends is free (coal, every 0.01 rad) and
    the shortest joint-space path, so a shortcutter that finds it returns exactly the
    two ends; the greedy pass tries that edge first, so it is the only edge checked
    (before 2026-12-02 random vertex pairs came first: 5 edges here).
    """
    robot = robokin.load("ur5")
    scene = Scene("far")
    scene.add_box("far", (0.1, 0.1, 0.1), pose((3.0, 0.0, 0.0)))
    pl = planning.Planner(robot, scene)
    k = np.arange(9)
    zigzag = np.tile(PATH[0], (9, 1))
    zigzag[:, 0] += 0.15 * k
    zigzag[:, 2] += 0.3 * (k % 2)  # every other waypoint 0.3 rad off the line
    assert pl.path_free(zigzag)
    assert Oracle(robot, scene).segment_min(zigzag[0], zigzag[-1]) > 0.0
    for seed in range(3):
        stats: dict[str, int] = {}
        out = pl._simplify(zigzag, pl.margin(), seed, 20, False, stats)
        np.testing.assert_array_equal(out, zigzag[[0, -1]])
        assert stats["simplify_edges"] == 1


def test_a_corner_whose_cut_would_collide_stays():
    # a ball where the cut of the first corner passes, clear of the corner itself:
    # at the flange point of the cut configuration farthest from the corner path
    robot = robokin.load("ur5")
    corner = np.array([[0.0, -2.0, 1.5, -1.57, 0.0, 0.0],
                       [0.0, -0.8, 1.5, -1.57, 0.0, 0.0],  # shoulder up, then
                       [0.0, -0.8, 0.3, -1.57, 0.0, 0.0]])  # the elbow: 90 deg
    cut = planning.Planner(robot, Scene("empty")).simplify(corner, shortcut=False)
    assert len(cut) == 4  # the corner was cut in free space

    def clearance(point):
        probe = Scene("probe")
        probe.add_sphere("probe", 1e-4, pose(point))
        return Oracle(robot, probe).path_min(corner, step=0.02)

    points = [robot.fk(cut[1] + t * (cut[2] - cut[1]))[:3, 3]
              for t in np.linspace(0.2, 0.8, 7)]
    gaps = [clearance(p) for p in points]
    k = int(np.argmax(gaps))
    assert gaps[k] > 0.01
    scene = Scene("post")
    scene.add_sphere("post", gaps[k] / 2, pose(points[k]))
    pl = planning.Planner(robot, scene)
    assert pl.path_free(corner)  # the ball leaves the corner path free
    assert not pl.edges_free(cut[1], cut[2])[0]  # and blocks the cut
    out = pl.simplify(corner, shortcut=False)
    assert np.array_equal(out, corner)
    assert Oracle(robot, scene).path_min(out) > 0.0


def test_a_step_not_proven_free_makes_its_segment_run_straight():
    robot = robokin.load("ur5")
    gentle = np.array([[0.0] * 6, [1.0] + [0.0] * 5, [1.8, 0.4] + [0.0] * 4,
                       [2.4, 1.0] + [0.0] * 4])  # turns of 27 and 18 deg
    calls = []

    def free(a, b):  # the first check: every step beside segment 1 -> 2 fails
        calls.append(len(a))
        if len(calls) > 1:
            return np.ones(len(a), bool)
        mid = 0.5 * (a + b)
        return np.array([_dist(m, gentle[1], gentle[2]) > 0.05 for m in mid])

    tr, stops = retime_checked(robot, gentle, free)
    assert stops == 2 and len(calls) == 2  # both ends of that segment, once
    # stopping at waypoints 1 and 2 leaves three straight stretches: every sample
    # lies on the polyline (before, the spline cut its corners)
    for q in tr.q:
        assert any(_on_segment(q, a, b) for a, b in zip(gentle[:-1], gentle[1:]))
    smooth, none = retime_checked(robot, gentle, lambda a, b: np.ones(len(a), bool))
    assert none == 0 and smooth.duration < tr.duration  # not stopping is faster
    worst, every = retime_checked(robot, gentle, lambda a, b: np.zeros(len(a), bool))
    assert every == 2  # never proven: it stops at every waypoint (and is returned)
    for q in worst.q:
        assert any(_on_segment(q, a, b) for a, b in zip(gentle[:-1], gentle[1:]))
