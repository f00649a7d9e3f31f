"""Corner cutting and checked retiming (robokin.planning.smoothing).

Oracles: the ends never move; every segment of the cut path lies on an old segment
or is a segment the check was asked about and passed; sharp corners shrink; a
retimed trajectory whose steps are not all proven free is replaced by one that
stops at every waypoint, whose samples lie on the waypoints' segments.
"""

from __future__ import annotations

import numpy as np

import robokin
from robokin.planning.smoothing import SHARP_TURN, _turns, cut_corners, retime_checked

PATH = np.array([[0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                 [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                 [1.0, 1.0, 0.0, 0.0, 0.0, 0.0],  # 90 deg corners
                 [0.0, 1.0, 0.5, 0.0, 0.0, 0.0],
                 [0.0, 1.0, 0.6, 0.0, 0.0, 0.0]])  # a gentle turn: left alone


def _on_segment(p, a, b):
    d = b - a
    t = np.clip(np.dot(p - a, d) / np.dot(d, d), 0, 1)
    return np.linalg.norm(a + t * d - p) < 1e-12


def test_every_new_segment_was_checked_or_lies_on_an_old_one():
    asked = []

    def free(a, b):
        asked.extend(zip(a, b))
        return np.ones(len(a), bool)

    out = cut_corners(PATH, free, rounds=3)
    assert np.array_equal(out[0], PATH[0]) and np.array_equal(out[-1], PATH[-1])
    proven = list(zip(PATH[:-1], PATH[1:])) + asked  # the old segments, the checked
    for a, b in zip(out[:-1], out[1:]):
        assert any(_on_segment(a, p, q) and _on_segment(b, p, q) for p, q in proven)
    assert _turns(out).max() <= SHARP_TURN + 1e-12  # no corner left that stops the arm
    assert _turns(PATH).max() > SHARP_TURN


def test_a_corner_whose_cut_is_not_free_stays():
    out = cut_corners(PATH, lambda a, b: np.zeros(len(a), bool), rounds=3)
    assert np.array_equal(out, PATH)


def test_a_failed_check_of_the_retimed_steps_stops_at_every_waypoint():
    robot = robokin.load("ur5")
    calls = []

    def free(a, b):
        calls.append(len(a))
        return np.ones(len(a), bool) if len(calls) > 1 else np.zeros(len(a), bool)

    gentle = np.array([[0.0] * 6, [1.0] + [0.0] * 5, [1.8, 0.4] + [0.0] * 4])  # 27 deg
    tr, smooth = retime_checked(robot, gentle, free)
    assert not smooth
    for q in tr.q:  # every sample on one of the two straight segments
        assert _on_segment(q, gentle[0], gentle[1]) or _on_segment(q, gentle[1], gentle[2])
    tr2, smooth2 = retime_checked(robot, gentle, lambda a, b: np.ones(len(a), bool))
    assert smooth2 and tr2.duration < tr.duration  # not stopping is faster
