"""The planning benchmark's problem set (issue 26, item 6): the committed file holds
100 problems per family and robot whose starts and goals are in the limits and
collision-free, the goal reaching the grasp pose; the robots load from URDF + SRDF
with the gripper's tree in the tool; each scene survives MoveIt's ``.scene`` text.
Oracles: pinocchio + coal (the baseline's checker, no robokin geometry code) and
robokin's forward kinematics against the stored grasp pose."""

import sys
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("yourdfpy")
pytest.importorskip("pinocchio")
BENCH = Path(__file__).resolve().parent.parent / "benchmarks"
sys.path.insert(0, str(BENCH))
import plan_baseline  # noqa: E402
import plan_problems  # noqa: E402

from robokin import collision  # noqa: E402


@pytest.fixture(scope="module")
def problems():
    return plan_problems.load_problems()


@pytest.fixture(scope="module")
def robots():
    return {name: spec.robot() for name, spec in plan_problems.ROBOTS.items()}


def test_the_set_has_100_problems_per_family_and_robot(problems):
    counts = Counter((p.robot, p.family) for p in problems)
    assert set(counts) == {(r, f) for r in plan_problems.ROBOTS
                           for f in plan_problems.FAMILIES}
    assert set(counts.values()) == {100}
    assert len({p.id for p in problems}) == len(problems)


def test_the_robots_carry_their_gripper_in_the_tool(robots):
    ur5 = robots["ur5_gripper"]
    assert ur5.meta["urdf"].parts()["tool"] == (
        "gripper_base_link", "left_fingertip", "left_knuckle", "right_fingertip",
        "right_knuckle")
    assert not ur5.geometry.exclude_adjacent  # the SRDF decides
    panda = robots["panda"]
    assert panda.meta["urdf"].tool_joints == {"panda_finger_joint1": 0.04,
                                              "panda_finger_joint2": 0.04}


def test_starts_and_goals_are_valid(problems, robots):
    """One problem per family and robot: limits, both checkers, the grasp pose."""
    seen = set()
    for p in problems:
        if (p.robot, p.family) in seen:
            continue
        seen.add((p.robot, p.family))
        robot = robots[p.robot]
        lim = robot.limits
        for q in (p.start, p.goal):
            assert np.all(q >= lim[:, 0]) and np.all(q <= lim[:, 1])
        np.testing.assert_allclose(robot.fk(p.goal), p.goal_pose, atol=1e-9)
        base = plan_baseline.checker_for(p)
        assert base.free(p.start) and base.free(p.goal), p.id
        np.testing.assert_allclose(base.tip_pose(p.goal), p.goal_pose, atol=1e-9)
        rep = collision.check(robot, p.scene(), np.stack([p.start, p.goal]),
                              subdivide=False)
        assert not rep.collides and rep.min_distance >= plan_problems.CLEARANCE, p.id
        # the re-check of a path that goes nowhere: valid, and it must end at the goal
        assert plan_baseline.recheck_path(p, p.start[None], checker=base).reason == \
            "the path does not end at the goal"


def test_a_scene_survives_moveit_text(problems, tmp_path):
    p = next(x for x in problems if x.family == "cage")
    path = tmp_path / "cage.scene"
    path.write_text(p.moveit_scene())
    scene = collision.Scene.load(path)
    ours = p.scene()
    assert scene.names == ours.names
    for name in ours.names:
        a, b = scene[name].shape, ours[name].shape
        assert a.kind == b.kind
        np.testing.assert_allclose(a.size, b.size, rtol=1e-8)
        np.testing.assert_allclose(a.placement, b.placement, atol=1e-8)


@pytest.mark.parametrize("angle, scale, valid", [
    (0.0, 0.0, True), (5e-7, 0.0, True), (2e-6, 0.0, False), (np.pi / 2, 0.0, False),
    (np.pi, 0.0, False), (0.0, 1e-12, True), (5e-7, 1e-12, True), (2e-6, 1e-12, False)])
def test_the_pose_recheck_reads_small_rotations_exactly(problems, angle, scale, valid):
    # oracle: a rotation of the goal pose by a known angle about x (scipy), its matrix
    # shrunk by ``scale`` as round-off in forward kinematics leaves it; the re-check
    # allows 1e-6 rad. acos of the trace reads a 1e-12 shrink as 1.7e-6 rad (it
    # refused planned Panda paths whose end was 4.6e-13 off); atan2 of the sine and
    # cosine parts does not
    from dataclasses import replace

    from scipy.spatial.transform import Rotation

    p = next(x for x in problems if x.robot == "panda" and x.family == "bookshelf_thin")
    G = np.array(p.goal_pose)
    G[:3, :3] = G[:3, :3] @ Rotation.from_rotvec([angle, 0.0, 0.0]).as_matrix()
    G[:3, :3] *= 1.0 - scale
    at_goal = replace(p, start=p.goal, goal_pose=G)
    rc = plan_baseline.recheck_path(at_goal, p.goal[None], goal="pose")
    assert rc.valid is valid, rc.reason
