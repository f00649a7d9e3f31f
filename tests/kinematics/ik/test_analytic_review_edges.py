"""Review regressions: q_near and q_current shapes, empty batches, per-pose q_near."""

import numpy as np
import pytest

import robokin
from robokin.exceptions import InputError


@pytest.mark.parametrize("name", ["ur5", "puma560", "scara", "qfmd010"])
def test_q_near_that_does_not_fit_the_batch_names_the_argument(name):
    robot = robokin.load(name)
    T = np.broadcast_to(robot.fk(np.full(robot.n, 0.1)), (3, 5, 4, 4))
    with pytest.raises(InputError, match=r"q_near.*\(4, \d\).*\(3, 5, \d\)"):
        robot.ik(T, q_near=np.zeros((4, robot.n)))
    # a batch of q_near for one pose would silently pick one of them
    with pytest.raises(InputError, match="q_near"):
        robot.ik(T[0, 0], q_near=np.zeros((3, robot.n)))
    # rows that broadcast are fine
    assert robot.ik(T, q_near=np.zeros((5, robot.n))).shape == (3, 5)


@pytest.mark.parametrize("name", ["ur5", "puma560"])
def test_batched_q_near_keeps_each_poses_own_q6_at_the_wrist_singularity(name):
    robot = robokin.load(name)
    q0 = np.array([0.3, 0.5, -1.2, 0.4, 0.0, 0.0])  # q5 = 0: wrist singular
    T = np.broadcast_to(robot.fk(q0), (2, 3, 4, 4))
    q6 = np.array([[-1.0, 0.2, 0.5], [1.5, -0.7, 2.0]])
    q_near = np.broadcast_to(q0, (2, 3, 6)).copy()
    q_near[..., 5] = q6
    sols = robot.ik(T, q_near=q_near)
    sing = sols.singular
    assert sing.any(axis=-1).all()
    np.testing.assert_allclose(np.where(sing, sols.q[..., 5], q6[..., None]),
                               np.broadcast_to(q6[..., None], sing.shape), atol=1e-12)


def test_nearest_and_distance_check_q_current_shape():
    robot = robokin.load("ur5")
    sols = robot.ik(robot.fk(np.full(6, 0.2)))
    with pytest.raises(InputError, match="q_current.*\\(2, 6\\)"):
        sols.nearest(np.zeros((2, 6)))
    with pytest.raises(InputError, match="q_current"):
        sols.distance(np.zeros(5))


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_nearest_on_an_empty_batch_is_empty(name):
    robot = robokin.load(name)
    sols = robot.ik(np.zeros((0, 4, 4)))
    assert sols.shape == (0,)
    out = sols.nearest(np.zeros(robot.n))
    assert out.shape == (0, robot.n)


@pytest.mark.parametrize("name", ["ur5", "aubo_i5", "puma560"])
def test_branch_labels_follow_the_arm_geometry(name):
    # Independent of the kernels' slot order: the elbow label is the side of the
    # forearm (elbow -> wrist centre) relative to the upper arm about the
    # shoulder-pitch axis, the wrist label the sign of sin(q5), the shoulder label
    # the side of frame 5's origin in joint 1's frame. Each must agree with its
    # geometric sign on every solution (one fixed convention per arm).
    robot = robokin.load(name)
    q = np.random.default_rng(1).uniform(-np.pi, np.pi, (400, 6))
    sols = robot.ik(robot.fk(q))
    Q = sols.q[sols.valid]
    F = robot.fk_all(Q)
    o1, o2, ow = F[:, 1, :3, 3], F[:, 2, :3, 3], F[:, 4, :3, 3]
    elbow_geo = np.sign(np.einsum("ni,ni->n", np.cross(o2 - o1, ow - o2), F[:, 1, :3, 2]))
    wrist_geo = np.sign(np.sin(Q[:, 4]))
    T1 = F[:, 1]
    o5 = F[:, 5, :3, 3]
    shoulder_geo = np.sign(np.einsum("nji,nj->ni", T1[:, :3, :3], o5 - T1[:, :3, 3])[:, 0])
    for label, geo in (("elbow", elbow_geo), ("wrist", wrist_geo),
                       ("shoulder", shoulder_geo)):
        prod = sols.branches[label][sols.valid] * geo
        assert np.unique(prod).size == 1 and abs(prod[0]) == 1, label
