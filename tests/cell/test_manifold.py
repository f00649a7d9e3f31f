"""A 7-axis arm's pose is reachable when any part of its self-motion manifold is
inside the joint limits (issue 29 item 4): maps and placement on the Panda.

Oracles: the configuration that generated a pose (inside the limits, so the pose
is reachable whatever the numeric sample does), ``SelfMotion.reachable`` (the
manifold's exact in-limit intervals), and FK of every configuration returned.
"""

import math

import numpy as np
import pytest

import robokin
from robokin import cell
from robokin.cell._evaluate import solve_poses
from robokin.cell._manifold import reach_on_manifold, sweep_joint
from robokin.exceptions import InputError

pytest.importorskip("dask")
pytest.importorskip("zarr")


@pytest.fixture(scope="module")
def panda():
    return robokin.load("panda")


def in_limit_configurations(panda, count, seed):
    lo, hi = panda.limits[:, 0], panda.limits[:, 1]
    return lo + np.random.default_rng(seed).random((count, 7)) * (hi - lo)


def pushed_configurations(panda, count, seed, push=0.5):
    """Configurations with two joints up to ``push`` outside their limits: poses
    at the edge of the reachable set, some reachable through another part of
    their manifold, some not."""
    rng = np.random.default_rng(seed)
    lo, hi = panda.limits[:, 0], panda.limits[:, 1]
    q = in_limit_configurations(panda, count, seed)
    for i in range(count):
        for j in rng.choice(7, 2, replace=False):
            q[i, j] = hi[j] + push * rng.random() if rng.random() < 0.5 else \
                lo[j] - push * rng.random()
    return q


def assert_reaches(panda, q, T):
    assert panda.within_limits(q).all()
    np.testing.assert_allclose(panda.fk(q), T, atol=1e-8)


def test_the_panda_sweeps_q7(panda):
    assert sweep_joint(panda) == "joint7"
    assert sweep_joint(robokin.load("ur5")) is None


def test_poses_whose_numeric_sample_misses_are_reachable(panda):
    # 400 FK poses of in-limit configurations: every one is reachable (oracle:
    # the generating configuration); the numeric sample alone misses some
    q = in_limit_configurations(panda, 400, 2)
    T = panda.fk(q)
    _, numeric = solve_poses(panda, T, True)
    missed = np.flatnonzero(~numeric[:, 0])
    assert missed.size >= 3  # the case this is about (7 with this seed)
    qm, ok = solve_poses(panda, T, True, "joint7")
    assert ok.all()
    assert_reaches(panda, qm[:, 0], T)
    for i in missed[:3]:
        assert panda.self_motion(T[i]).reachable


def test_reachability_agrees_with_the_exact_manifold(panda):
    # 200 poses at the edge of the reachable set against SelfMotion.reachable
    # (each a whole manifold with its exact intervals; ~20 ms a pose)
    T = panda.fk(pushed_configurations(panda, 200, 3))
    exact = np.array([panda.self_motion(t).reachable for t in T])
    assert 0 < exact.sum() < len(T)
    q, ok = solve_poses(panda, T, True, "joint7")
    np.testing.assert_array_equal(ok[:, 0], exact)
    assert_reaches(panda, q[ok[:, 0], 0], T[ok[:, 0]])
    _, numeric = solve_poses(panda, T, True)
    assert (exact & ~numeric[:, 0]).sum() >= 5  # the numeric sample alone misses these


def test_the_exact_limit_points_decide_what_the_sweep_misses(panda, monkeypatch):
    # with a sweep of 3 values most in-limit parts fall between them: the
    # limit-point test must find those (oracle: the generating configuration)
    import robokin.cell._manifold as mf

    q = in_limit_configurations(panda, 60, 5)
    T = panda.fk(q)
    monkeypatch.setattr(mf, "SWEEP_VALUES", 3)
    monkeypatch.setattr(mf, "WINDOW_VALUES", 1)
    monkeypatch.setattr(mf, "CLOSE", math.inf)
    _, found, _ = mf._sweep(panda, T, "joint7", mf._values(panda, "joint7", len(T), None))
    assert (~found).sum() >= 10
    qm, ok = reach_on_manifold(panda, T, "joint7")
    assert ok.all()
    assert_reaches(panda, qm, T)


def test_a_panda_map_counts_the_manifold(panda):
    region = [[0.3, -0.2, 0.3], [0.8, 0.2, 0.7]]
    m = cell.reach_map(panda, region=region, voxel=0.1, orientations=16, chunk=3)
    numeric = cell.reach_map(panda, region=region, voxel=0.1, orientations=16,
                             method="numeric")
    assert m.method == "numeric + self-motion (joint7 swept)"
    assert numeric.method == "numeric" and m.counts.max() <= 1
    assert (m.reachable >= numeric.reachable).all()
    gained = np.argwhere(m.reachable & ~numeric.reachable)
    assert len(gained) >= 1
    for v, k in gained[:4]:
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = m.orientations[k], m.centers[v]
        assert panda.self_motion(T).reachable
    assert (m.manipulability >= numeric.manipulability).all()
    again = cell.reach_map(panda, region=region, voxel=0.1, orientations=16, chunk=7)
    np.testing.assert_array_equal(m.counts, again.counts)
    np.testing.assert_array_equal(m.manipulability, again.manipulability)


def test_a_set_of_poses_is_placed_through_the_manifold(panda):
    q = in_limit_configurations(panda, 400, 2)
    T = panda.fk(q)
    _, numeric = solve_poses(panda, T, True)
    task = T[np.flatnonzero(~numeric[:, 0])[:3]]
    pl = cell.place(panda, task, np.eye(4), max_step=math.inf)
    assert pl.feasible[0]
    assert_reaches(panda, pl.best_q, task)
    with pytest.raises(InputError, match="task"):  # out of reach from every candidate
        cell.place(panda, task[:1], np.eye(4), max_step=math.inf, method="numeric")


def test_a_robot_on_a_track_sweeps_the_track():
    # Session 16: a UR5 on a 2 m linear track has no held-joint closed form of the
    # Panda's kind, so maps took the numeric sample alone; its track held leaves the
    # UR5's closed form, which robot.ik(T, fixed=...) solves completely. Oracles:
    # SelfMotion.reachable (the manifold over the track, its exact intervals) for
    # every pose the map gains over the numeric sample and for every pose it leaves
    # unreachable; FK of the map's configurations through solve_poses.
    from reference import ur5_on_a_track

    arm = ur5_on_a_track(2.0)
    assert sweep_joint(arm) == "track"
    region = [[0.3, -0.5, 0.2], [0.9, 0.5, 1.8]]
    m = cell.reach_map(arm, region=region, voxel=0.2, orientations=16, chunk=3)
    numeric = cell.reach_map(arm, region=region, voxel=0.2, orientations=16,
                             method="numeric")
    assert m.method == "numeric + self-motion (track swept)"
    assert (m.reachable >= numeric.reachable).all()

    def pose(v, k):
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = m.orientations[k], m.centers[v]
        return T

    gained = np.argwhere(m.reachable & ~numeric.reachable)
    assert len(gained) >= 3  # 6 with this grid
    assert all(arm.self_motion(pose(v, k)).reachable for v, k in gained)
    left = np.argwhere(~m.reachable)
    assert len(left) >= 100
    assert not any(arm.self_motion(pose(v, k)).reachable for v, k in left)
    T = np.stack([pose(v, k) for v, k in gained])
    q, ok = solve_poses(arm, T, True, "track")
    assert ok.all()
    assert_reaches(arm, q[:, 0], T)
