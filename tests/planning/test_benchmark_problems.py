"""Planning on the benchmark's problems (robots from URDF + SRDF with their grippers).

Oracle: ``benchmarks/plan_baseline.recheck_path``, the benchmark's independent
check: pinocchio's forward kinematics and coal's collision tests on the URDF (the
SRDF's pairs removed, the fingers locked as the problem set has them), coal's
cached GJK guess off, every 0.01 rad of every segment; the path begins at the
start and ends at the goal configuration, or for a pose goal at a configuration
whose tip pinocchio puts at the pose (1e-6 m and rad). One problem of each family
and robot (the first of the committed set).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("yourdfpy")
pytest.importorskip("pinocchio")
coal = pytest.importorskip("coal")
BENCH = Path(__file__).resolve().parents[2] / "benchmarks"
sys.path.insert(0, str(BENCH))
import plan_baseline  # noqa: E402
import plan_problems  # noqa: E402

from robokin import planning  # noqa: E402

FIRST = {}
for _p in plan_problems.load_problems():
    FIRST.setdefault((_p.robot, _p.family), _p)


@pytest.fixture(scope="module")
def robots():
    return {name: spec.robot() for name, spec in plan_problems.ROBOTS.items()}


@pytest.mark.parametrize("key", sorted(FIRST), ids="/".join)
def test_the_path_passes_the_uncached_pinocchio_coal_recheck(robots, key):
    p = FIRST[key]
    checker = plan_baseline.checker_for(p)
    # the checker really has coal's cached guess off (it is what the re-check relies on)
    assert all(r.gjk_initial_guess == coal.GJKInitialGuess.DefaultGuess
               for r in checker.gdata.collisionRequests)
    res = planning.Planner(robots[p.robot], p.scene()).plan(p.start, p.goal, seed=0,
                                                             time_limit=5.0)
    assert res.success, res.reason
    rc = plan_baseline.recheck_path(p, np.asarray(res.q), checker=checker)
    assert rc.valid, (rc.reason, rc.segment, rc.where)
    assert rc.states >= len(res.q)


@pytest.mark.parametrize("family", ["box", "bookshelf_small"])
def test_a_pose_goal_path_ends_at_the_pose_by_pinocchio(robots, family):
    p = FIRST[("ur5_gripper", family)]
    checker = plan_baseline.checker_for(p)
    res = planning.Planner(robots[p.robot], p.scene()).plan(p.start, p.goal_pose, seed=0,
                                                             time_limit=5.0)
    assert res.success, res.reason
    rc = plan_baseline.recheck_path(p, np.asarray(res.q), checker=checker, goal="pose")
    assert rc.valid, (rc.reason, rc.segment, rc.where)
    # every in-limit IK branch of the 6-axis arm (whole turns included) was a goal
    sols = robots[p.robot].ik(np.asarray(p.goal_pose)).keep_within_limits().expand_turns()
    assert res.goals.shape[0] == np.asarray(sols.solutions()).reshape(-1, 6).shape[0] > 8
