"""``robokin plan``: files written all or none, refusals, exit codes, units.

Oracles: the written trajectory reads back, starts at the start, ends at the goal
(for --goal-pose: FK of its end is the pose), every step is proven free by the
planner's check and coal finds no contact at its samples; an existing output is
never replaced without --force; no path is exit 1 with the reason; bad input exit 2
naming the option.
"""

import json

import numpy as np
import pytest

import robokin
from robokin.cli import main
from robokin.collision import Scene, scene_path

pytest.importorskip("coal")

# The time limit of a query that must succeed: far above what it takes, so a slow or
# loaded machine cannot fail it (the planner stops at its first path)
AMPLE = ["--time-limit", "30"]


@pytest.fixture(scope="module")
def press():
    sc = Scene.load(scene_path("press"))
    return sc, robokin.load("aubo_i5")


def test_plan_between_named_poses_writes_the_trajectory_and_plot(press, tmp_path,
                                                                 capsys):
    from robokin.planning import Planner
    from robokin.trajectory.io import read_csv

    sc, robot = press
    out = tmp_path / "run"
    code = main(["plan", "press", "--start", "pick_approach", "--goal", "press_approach",
                 "--out", str(out), "--clearance", "4", *AMPLE])
    text, err = capsys.readouterr()
    assert code == 0, err
    assert "path found by rrtconnect" in text and "every step proven collision-free" in text
    assert (out / "plan.png").stat().st_size > 10_000
    tr = read_csv(out / "plan.csv", joint_names=robot.joint_names)
    np.testing.assert_allclose(tr.q[0], sc.pose_joints["pick_approach"], atol=1e-12)
    np.testing.assert_allclose(tr.q[-1], sc.pose_joints["press_approach"], atol=1e-12)
    pl = Planner(robot, sc)
    assert pl.edges_free(tr.q[:-1], tr.q[1:], clearance=0.004).all()
    # an existing output is refused, named, and left as it was
    before = (out / "plan.csv").read_bytes()
    code = main(["plan", "press", "--start", "pick_approach", "--goal", "pick",
                 "--out", str(out)])
    _, err = capsys.readouterr()
    assert code == 2 and "--out" in err and "--force" in err
    assert (out / "plan.csv").read_bytes() == before
    code = main(["plan", "press", "--start", "pick_approach", "--goal", "pick",
                 "--out", str(out), "--force", "--no-plot", "--json", *AMPLE])
    text, err = capsys.readouterr()
    assert code == 0, err
    doc = json.loads(text)
    assert doc["files"] == [str(out / "plan.csv")] and doc["planner"] == "rrtconnect"
    assert (out / "plan.csv").read_bytes() != before


def test_a_goal_pose_in_degrees_and_millimetres_ends_at_that_pose(press, tmp_path,
                                                                  capsys):
    from robokin.trajectory.io import read_csv

    sc, robot = press
    q0 = np.degrees(sc.pose_joints["pick_approach"])
    code = main(["plan", "press", "--start", *map(str, q0), "--deg", "--mm",
                 "--goal-pose", "420", "0", "450", "90", "0", "90", "--out",
                 str(tmp_path), "--json", "--no-plot", *AMPLE])
    text, err = capsys.readouterr()
    assert code == 0, err
    doc = json.loads(text)
    assert doc["goals"] >= 2  # every IK branch of the pose was a goal
    tr = read_csv(tmp_path / "plan.csv", joint_names=robot.joint_names)
    T = sc.attach(robot).fk(tr.q[-1])
    np.testing.assert_allclose(T, sc.poses["press_approach"], atol=1e-6)


def test_no_path_is_exit_1_with_the_reason(tmp_path, capsys):
    q = "0 -10 50 0 90 0"  # the wrist in the ram of the press
    code = main(["plan", "press", "--start", *q.split(), "--deg", "--goal",
                 "pick_approach", "--out", str(tmp_path)])
    _, err = capsys.readouterr()
    assert code == 1
    assert "no path: the start is in collision: 'wrist_3' collides with 'ram'" in err
    assert not (tmp_path / "plan.csv").exists()


@pytest.mark.parametrize("args, option", [
    (["--goal", "pick"], None),
    (["--goal", "1", "2"], "--goal"),
    (["--goal", "nowhere"], "--goal"),
    (["--goal-pose", "1", "2", "3"], "--goal-pose"),
    (["--goal", "pick", "--goal-pose", "pick"], "--goal"),
    (["--goal", "pick", "--planner", "rrt*"], "--planner"),
    (["--goal", "pick", "--clearance", "-1"], "--clearance"),
    (["--goal", "pick", "--time-limit", "0"], "--time-limit"),
    (["--goal", "pick", "--dt", "-0.1"], "--dt"),
])
def test_bad_input_is_exit_2_naming_the_option(args, option, tmp_path, capsys):
    if option is None:  # the well-formed call of this table, for contrast
        code = main(["plan", "press", "--start", "pick_approach", *args, "--out",
                     str(tmp_path), "--no-plot", *AMPLE])
        assert code == 0
        return
    code = main(["plan", "press", "--start", "pick_approach", *args, "--out",
                 str(tmp_path)])
    _, err = capsys.readouterr()
    assert code == 2 and option in err, err
