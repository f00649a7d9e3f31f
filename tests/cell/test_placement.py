"""Placement search: the demo's base is feasible, bad bases are rejected for the
right reason, the best one gets the full check, bad input is named (issue 16)."""

import math

import numpy as np
import pytest

import robokin
from robokin import cell
from robokin.exceptions import InputError, UnreachableError

pytest.importorskip("dask")
pytest.importorskip("coal")


def assert_same(x, y, what):
    """Equal bit for bit (NaN where NaN)."""
    assert x.dtype == y.dtype and np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), what


@pytest.fixture(scope="module")
def press():
    from robokin import collision
    from robokin.cli.demo_job import placement_task, plan_press_loading

    scene = collision.Scene.load(collision.scene_path("press"))
    bare = robokin.load("aubo_i5")
    traj, _ = plan_press_loading(scene.attach(bare), scene)
    return bare, scene, placement_task(traj, every=20)


@pytest.fixture(scope="module")
def three_bases(press):
    bare, scene, task = press
    # the demo's base; far behind the robot (the press out of reach); against the
    # pick table (the base inside it)
    cand = cell.base_grid([0.0], [0.0])
    cand = np.concatenate([cand, cell.base_grid([-1.2], [0.0]), cell.base_grid([0.0], [0.3])])
    return cell.place(bare, task, cand, scene=scene, clearance=0.004)


def test_the_demos_own_placement_is_feasible(press, three_bases):
    pl = three_bases
    assert pl.feasible[0] and pl.reason[0] == "ok"
    assert pl.clearance[0] >= 0.004 and pl.score[0] == pl.manipulability[0] > 0
    assert pl.best_index == 0
    np.testing.assert_array_equal(pl.best, np.eye(4))
    # the full check: subdivision between samples, along the chosen branch
    rep = pl.best_report
    assert rep is not None and not rep.collides and rep.min_distance >= 0.004
    bare, scene, task = press
    np.testing.assert_allclose(scene.attach(bare).fk(pl.best_q), task, atol=1e-9)


def test_a_base_that_puts_the_press_out_of_reach_is_rejected(three_bases):
    pl = three_bases
    assert not pl.feasible[1] and not pl.reachable[1]
    assert pl.reason[1].startswith("out of reach: task pose")
    assert pl.score[1] == 0 and math.isnan(pl.clearance[1])


def test_a_base_in_collision_is_rejected(three_bases):
    pl = three_bases
    assert pl.reachable[2] and not pl.feasible[2]
    assert pl.reason[2].startswith("collision: base–table")
    assert pl.clearance[2] <= 0


def test_a_larger_clearance_than_the_cell_has_rejects_the_base(press):
    bare, scene, task = press
    pl = cell.place(bare, task, np.eye(4), scene=scene, clearance=0.05)
    assert not pl.feasible[0] and pl.reason[0].startswith("clearance:")
    with pytest.raises(UnreachableError, match="no feasible placement among 1"):
        _ = pl.best


def test_ranking_output_and_chunking(press, tmp_path):
    bare, scene, task = press
    cand = cell.base_grid([-0.2, -0.1, 0.0], [0.0, 0.1, 0.2])
    a = cell.place(bare, task, cand, scene=scene, clearance=0.004)
    b = cell.place(bare, task, cand, scene=scene, clearance=0.004, chunk=1,
                   scheduler="synchronous")
    for f in ("feasible", "score", "reachable", "clearance", "manipulability", "branch"):
        assert_same(getattr(a, f), getattr(b, f), f)
    r = a.ranking
    assert r.size == a.feasible.sum() >= 3 and r[0] == a.best_index
    assert (np.diff(a.score[r]) <= 0).all()
    a.write_csv(tmp_path / "p.csv")
    rows = (tmp_path / "p.csv").read_text().splitlines()
    assert len(rows) == 1 + len(cand) and rows[1].startswith("1,")
    a.plot_floor(tmp_path / "floor.png", scene=scene, mark=np.eye(4))
    assert (tmp_path / "floor.png").stat().st_size > 10_000
    s = a.summary()
    assert s["feasible"] == r.size and s["best"]["index"] == a.best_index


def test_without_a_scene_only_reach_and_manipulability_count():
    ur5 = robokin.load("ur5")
    q = np.radians([[0, -60, 80, -20, 90, 0], [5, -55, 75, -20, 90, 0],
                    [10, -50, 70, -20, 90, 0]])
    task = ur5.fk(q)
    pl = cell.place(ur5, task, cell.base_grid([0.0, 0.05], [0.0]))
    assert pl.feasible.all() and np.isinf(pl.clearance).all()
    # from the robot's own base, the branch that produced the task is among those found
    assert pl.manipulability[0] >= ur5.manipulability(q).min() - 1e-12
    strict = cell.place(ur5, task, np.eye(4), min_manipulability=10.0)
    assert strict.reason[0].startswith("manipulability:")


def test_a_branch_flip_is_not_a_continuous_branch():
    ur5 = robokin.load("ur5")
    up = np.radians([0, -60, 80, -20, 90, 0])
    down = ur5.ik(ur5.fk(up)).q  # every branch of the same pose
    flip = next(qb for qb in down if np.abs(qb - up).max() > 1.0)
    T = ur5.fk(np.array([up, up, flip]))  # the same pose three times
    pl = cell.place(ur5, T, np.eye(4))
    assert pl.feasible[0]  # one branch holds still: no flip needed
    far = ur5.fk(np.radians([[0, -60, 80, -20, 90, 0], [120, -100, 30, 60, 10, 90]]))
    jump = cell.place(ur5, far, np.eye(4), max_step=math.radians(5))
    assert not jump.feasible[0] and jump.reason[0].startswith("no continuous branch")
    assert cell.place(ur5, far, np.eye(4), max_step=math.inf).feasible[0]  # a set of poses
    # in a set, a pose out of reach from one base is out of reach, whatever the step
    moved = cell.base_grid([0.0, 0.6], [0.0])
    pl = cell.place(ur5, far, moved, max_step=math.inf)
    assert pl.feasible[0] and not pl.reachable[1]
    assert pl.reason[1].startswith("out of reach: task pose")


def test_an_unreachable_task_names_the_task(press):
    bare, scene, task = press
    far = task.copy()
    far[-1, 2, 3] += 5.0  # one pose 5 m up: no base spans it
    with pytest.raises(InputError, match="argument 'task'.*more than twice the arm's reach"):
        cell.place(bare, far, np.eye(4), scene=scene)
    high = task[:3].copy()
    high[:, 2, 3] += 1.2  # within the span, but from none of these bases
    with pytest.raises(InputError, match="argument 'task'.*no candidate base reaches every.*pose 0"):
        cell.place(bare, high, cell.base_grid([0.0, 0.1], [0.0]), scene=scene)


@pytest.mark.parametrize(("kwargs", "argument"), [
    ({"candidates": np.zeros((0, 4, 4))}, "candidates"),
    ({"candidates": np.ones((2, 3))}, "candidates"),
    ({"clearance": -0.001}, "clearance"),
    ({"clearance": math.nan}, "clearance"),
    ({"max_step": 0.0}, "max_step"),
    ({"min_manipulability": -1.0}, "min_manipulability"),
    ({"task": np.zeros((0, 4, 4))}, "task"),
    ({"task": np.ones((2, 4, 4))}, "task"),
    ({"scheduler": 42}, "scheduler"),
])
def test_bad_input_names_the_argument(kwargs, argument):
    ur5 = robokin.load("ur5")
    args = {"task": ur5.fk(np.zeros(6)), "candidates": np.eye(4), **kwargs}
    with pytest.raises(InputError, match=f"argument '{argument}'"):
        cell.place(ur5, **args)


def test_base_grid_combines_every_axis():
    g = cell.base_grid([0.0, 1.0], [2.0, 3.0, 4.0], z=0.5, yaw=[0.0, math.pi / 2])
    assert g.shape == (12, 4, 4)
    np.testing.assert_allclose(g[1, :3, 3], [0.0, 2.0, 0.5])
    np.testing.assert_allclose(g[1, :3, :3], [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-15)
    np.testing.assert_allclose(g[-1, :3, 3], [1.0, 4.0, 0.5])
    with pytest.raises(InputError, match="argument 'y'"):
        cell.base_grid([0.0], [])
    rows = cell.place(robokin.load("ur5"), robokin.load("ur5").fk(np.zeros(6)),
                      [[0.0, 0.0, 0.0, 0.0]])
    assert rows.feasible[0]


def test_a_plan_in_actuator_space_places_like_the_plan():
    from robokin import trajectory

    scara = robokin.load("scara")
    plan = trajectory.quintic(np.array([0.0, 0.3, 0.0, 0.05]),
                              np.array([0.4, 0.9, 1.5, 0.12]), 1.0, dt=0.05)
    motors = plan.to_actuator_space(scara)
    assert motors.space == "actuator" and np.abs(motors.q - plan.q).max() > 1.0
    cand = cell.base_grid([0.0, 0.05], [0.0, 0.05])
    a = cell.place(scara, plan, cand)
    b = cell.place(scara, motors, cand)
    np.testing.assert_allclose(a.task, scara.fk(plan.q), atol=1e-15)
    np.testing.assert_allclose(b.task, a.task, atol=1e-12)
    assert a.feasible.all() and b.feasible.all()
    assert b.best_index == a.best_index == 3
    np.testing.assert_array_equal(b.branch, a.branch)
    np.testing.assert_allclose(b.score, a.score, rtol=1e-9)
    np.testing.assert_allclose(b.best_q, a.best_q, atol=1e-9)


# ---------------------------------------------------------- a set of poses (issue 25)
def _best_per_pose(robot, task):
    """Oracle: per pose, the largest manipulability (SVD) over its closed-form
    solutions inside the limits (robot.ik one pose at a time)."""
    best = []
    for T in task:
        sols = robot.ik(T)
        q = sols.q[sols.within_limits]
        best.append(robot.manipulability(q).max() if len(q) else -1.0)
    return np.array(best)


def test_a_set_of_poses_accepts_the_base_it_was_made_at():
    # The reported case: 40 FK poses of in-limit UR5 configurations (the whole
    # +-360 deg travel) as a set. Following a branch across them carried unwrapped
    # angles out of the limits ("no continuous branch ... task pose 16 of 40");
    # each pose only needs an in-limit solution of its own.
    ur5 = robokin.load("ur5")
    rng = np.random.default_rng(25)
    q = rng.uniform(ur5.limits[:, 0], ur5.limits[:, 1], (40, 6))
    task = ur5.fk(q)
    pl = cell.place(ur5, task, np.eye(4), max_step=math.inf)
    assert pl.feasible[0] and pl.reason[0] == "ok" and pl.best_index == 0
    # one in-limit solution per pose, reaching it
    assert pl.best_q.shape == (40, 6) and ur5.within_limits(pl.best_q).all()
    np.testing.assert_allclose(ur5.fk(pl.best_q), task, atol=1e-9)
    # the score: the smallest over the poses of each pose's best manipulability,
    # at least that of the configurations the poses were made from
    best = _best_per_pose(ur5, task)
    assert pl.score[0] == pytest.approx(best.min(), rel=1e-9)
    assert pl.score[0] >= ur5.manipulability(q).min() - 1e-12
    np.testing.assert_allclose(ur5.manipulability(pl.best_q), best, rtol=1e-9)
    # a set has no order: shuffled, the same verdict, score and solutions
    perm = rng.permutation(40)
    shuffled = cell.place(ur5, task[perm], np.eye(4), max_step=math.inf)
    assert shuffled.feasible[0] and shuffled.score[0] == pl.score[0]
    np.testing.assert_array_equal(shuffled.best_q, pl.best_q[perm])
    # as a motion (the default max_step) the same poses are not one branch
    motion = cell.place(ur5, task, np.eye(4))
    assert not motion.feasible[0] and motion.reason[0].startswith("no continuous branch")
    # manipulability asked for: the pose that limits it is named
    strict = cell.place(ur5, task, np.eye(4), max_step=math.inf,
                        min_manipulability=best.min() * 1.01)
    assert strict.reason[0] == (
        f"manipulability: {best.min():.3g} < {best.min() * 1.01:.3g} required at task "
        f"pose {int(np.argmin(best))} (its best solution inside the limits)")


def test_a_set_of_poses_in_a_scene_takes_per_pose_the_best_clear_solution(press):
    bare, scene, task = press
    base = cell.base_grid([0.0], [0.1])
    pl = cell.place(bare, task, base, scene=scene, clearance=0.004, max_step=math.inf)
    assert pl.feasible[0] and pl.clearance[0] >= 0.004
    tooled = scene.with_base(np.eye(4)).attach(bare)
    local = np.linalg.inv(base[0]) @ task
    np.testing.assert_allclose(tooled.fk(pl.best_q), local, atol=1e-9)
    # Oracle, brute force: every in-limit solution of every pose checked on its
    # own; the chosen one must be clear, and none with a larger manipulability.
    from robokin.collision import check

    sols = tooled.ik(local)
    ok = sols.within_limits
    rows = sols.q[ok]
    rep = check(bare, scene.with_base(base[0]), rows, clearance=0.004, subdivide=False)
    dist = np.full(ok.shape, np.nan)
    dist[ok] = rep.closest_at(np.arange(len(rows)))[0]
    w = np.where(ok, 0.0, np.nan)
    w[ok] = tooled.manipulability(rows)
    chosen = np.array([np.flatnonzero(ok[i] & (np.abs(sols.q[i] - pl.best_q[i]).max(
        axis=-1) < 1e-9))[0] for i in range(len(task))])
    idx = np.arange(len(task))
    assert (dist[idx, chosen] > 0.004).all()
    better = ok & (w > w[idx, chosen][:, None] * (1 + 1e-12))
    assert not (better & (dist > 0.004)).any()
    top = np.nanargmax(w, axis=-1)
    assert (chosen != top).sum() >= 10  # the scene really changes the choice
    assert pl.score[0] == pytest.approx(w[idx, chosen].min(), rel=1e-9)


def test_a_set_of_poses_on_an_arm_without_a_closed_form():
    panda = robokin.load("panda")
    rng = np.random.default_rng(7)
    q = rng.uniform(panda.limits[:, 0], panda.limits[:, 1], (6, 7))
    task = panda.fk(q)
    pl = cell.place(panda, task, np.eye(4), max_step=math.inf)
    assert pl.feasible[0] and panda.within_limits(pl.best_q).all()
    np.testing.assert_allclose(panda.fk(pl.best_q), task, atol=1e-8)
    assert pl.score[0] == pytest.approx(panda.manipulability(pl.best_q).min(), rel=1e-9)
