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
                                                             time_limit=30.0)
    assert res.success, res.reason
    rc = plan_baseline.recheck_path(p, np.asarray(res.q), checker=checker)
    assert rc.valid, (rc.reason, rc.segment, rc.where)
    assert rc.states >= len(res.q)


@pytest.mark.parametrize("family", ["box", "bookshelf_small"])
def test_a_pose_goal_path_ends_at_the_pose_by_pinocchio(robots, family):
    p = FIRST[("ur5_gripper", family)]
    checker = plan_baseline.checker_for(p)
    res = planning.Planner(robots[p.robot], p.scene()).plan(p.start, p.goal_pose, seed=0,
                                                             time_limit=30.0)
    assert res.success, res.reason
    rc = plan_baseline.recheck_path(p, np.asarray(res.q), checker=checker, goal="pose")
    assert rc.valid, (rc.reason, rc.segment, rc.where)
    # every in-limit IK branch of the 6-axis arm (whole turns included) was a goal
    sols = robots[p.robot].ik(np.asarray(p.goal_pose)).keep_within_limits().expand_turns()
    assert res.goals.shape[0] == np.asarray(sols.solutions()).reshape(-1, 6).shape[0] > 8


# An edge a UR5 cage search step took (problem ur5_gripper/cage/065), as hex floats.
CAGE_EDGE = np.array([[float.fromhex(x) for x in row] for row in (
    ("0x1.ea7fff9b977dep-1", "-0x1.e166ef02e624fp-1", "0x1.9273023317344p-3",
     "0x1.e6d56f8998d8ap-1", "0x1.5a85bb166038fp+1", "-0x1.64a0b08094eb7p+1"),
    ("0x1.53c86186aa082p+0", "-0x1.a9ed31872c7fp-1", "-0x1.de0d36256520ep-8",
     "0x1.13f239f75f899p+0", "0x1.58fdc7803d3bep+1", "-0x1.7f8018894c526p+1"))])


def test_cylinder_distances_never_read_an_overlap_of_cores_apart(robots):
    """GJK on two cylinders (upper arm, gripper) along a free edge of the cage.

    Oracle: coal's distance of every pair at every state (``plan_baseline``'s
    pinocchio + coal checker on the URDF: the edge is free, 1.3 mm at its closest)
    and of the cylinder pair itself. Before 2026-12-02 GJK's simplex read its rounding
    on ever thinner tetrahedra as the origin inside at 12 of these 2001 states and
    returned 0 for cores 7.8 mm apart (a free state called in collision).
    """
    p = next(q for q in plan_problems.load_problems() if q.id == "ur5_gripper/cage/065")
    pl = planning.Planner(robots[p.robot], p.scene())
    q0, q1 = CAGE_EDGE
    t = np.linspace(0.0, 1.0, 2001)
    qs = q0 + t[:, None] * (q1 - q0)
    d = pl.model.distances(qs)
    checker = plan_baseline.checker_for(p)
    assert all(checker.free(q) for q in qs[::20])  # coal: free (every 0.005 of t)
    assert d.min() > 1e-3  # robokin's certified bounds: every state free
    pair = pl.model.names.index(("elbow_joint", "tool"))
    from robokin.kinematics.forward import link_frames
    for i in range(0, 2001, 100):
        ref = pl.model.problem.exact(pair, link_frames(pl.model.chain, qs[i:i + 1])[0])
        assert abs(d[i, pair] - ref) < 2e-6, (i, d[i, pair], ref)
