"""spatial.py against scipy and against closed-form values."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robokin import spatial as sp
from robokin.exceptions import InputError


def test_elementary_rotations_match_closed_form():
    a = 0.3
    c, s = np.cos(a), np.sin(a)
    np.testing.assert_allclose(sp.rotz(a)[:3, :3], [[c, -s, 0], [s, c, 0], [0, 0, 1]])
    np.testing.assert_allclose(sp.rotx(a)[:3, :3], [[1, 0, 0], [0, c, -s], [0, s, c]])
    np.testing.assert_allclose(sp.roty(a)[:3, :3], [[c, 0, s], [0, 1, 0], [-s, 0, c]])


@pytest.mark.parametrize("shape", [(), (7,), (3, 5)])
def test_batch_shapes(shape, rng):
    a = rng.uniform(-3, 3, shape)
    assert sp.rotx(a).shape == shape + (4, 4)
    xyz = rng.normal(size=shape + (3,))
    T = sp.trans(xyz)
    assert T.shape == shape + (4, 4)
    np.testing.assert_array_equal(T[..., :3, 3], xyz)
    rpy = rng.uniform(-1, 1, shape + (3,))
    P = sp.pose_from_xyz_rpy(xyz, rpy)
    assert P.shape == shape + (4, 4)
    Pi = sp.invert(P)
    np.testing.assert_allclose(
        P @ Pi, np.broadcast_to(np.eye(4), shape + (4, 4)), atol=1e-12
    )


def test_rpy_is_fixed_axis_xyz(rng):
    rpy = rng.uniform(-1, 1, (20, 3))
    T = sp.matrix_from_rpy(rpy)
    expected = sp.rotz(rpy[:, 2]) @ sp.roty(rpy[:, 1]) @ sp.rotx(rpy[:, 0])
    np.testing.assert_allclose(T, expected, atol=1e-12)
    np.testing.assert_allclose(sp.rpy_from_matrix(T), rpy, atol=1e-12)


def test_quaternion_is_wxyz_and_round_trips(rng):
    q = rng.normal(size=(10, 4))
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    q[q[:, 0] < 0] *= -1
    T = sp.matrix_from_quaternion(q)
    R = Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_matrix()
    np.testing.assert_allclose(T[:, :3, :3], R, atol=1e-12)
    np.testing.assert_allclose(sp.quaternion_from_matrix(T), q, atol=1e-12)
    np.testing.assert_allclose(sp.quaternion_from_matrix(np.eye(4)), [1, 0, 0, 0])


def test_axis_angle_round_trip(rng):
    v = rng.normal(size=(10, 3))
    v *= (rng.uniform(0, np.pi - 1e-3, 10) / np.linalg.norm(v, axis=-1))[:, None]
    np.testing.assert_allclose(
        sp.axis_angle_from_matrix(sp.matrix_from_axis_angle(v)), v, atol=1e-12
    )
    np.testing.assert_allclose(
        sp.matrix_from_axis_angle([0, 0, 0.5]), sp.rotz(0.5), atol=1e-15
    )


@pytest.mark.parametrize("angle", [0.0, 1e-12, 1e-9, 9.99e-5, 1.0001e-4, 0.5, np.pi / 2,
                                   np.pi - 1e-9, np.pi, 7.0])
def test_rotation_from_rotvec_matches_scipy_at_special_angles(angle, rng):
    """Rodrigues' formula (numpy, no scipy) against scipy's quaternion route, at the
    series switch (1e-4), near zero and near pi; batched with a leading shape."""
    axis = rng.normal(size=(3, 4, 3))
    w = axis / np.linalg.norm(axis, axis=-1, keepdims=True) * angle
    R = sp.rotation_from_rotvec(w)
    assert R.shape == (3, 4, 3, 3)
    ref = Rotation.from_rotvec(w.reshape(-1, 3)).as_matrix().reshape(3, 4, 3, 3)
    np.testing.assert_allclose(R, ref, rtol=0, atol=4e-15)
    np.testing.assert_allclose(sp.matrix_from_axis_angle(w)[..., :3, :3], R, rtol=0, atol=0)


def test_pose_error_known_values():
    A = sp.trans(1.0, 2.0, 3.0)
    B = sp.trans(1.5, 2.0, 2.0) @ sp.rotz(0.25)
    e = sp.pose_error(A, B)
    np.testing.assert_allclose(e, [0.5, 0.0, -1.0, 0.0, 0.0, 0.25], atol=1e-15)
    # the rotation part is in the base frame: rotate both by a base rotation
    R = sp.rotx(0.7)
    e2 = sp.pose_error(R @ A, R @ B)
    np.testing.assert_allclose(e2[3:], R[:3, :3] @ [0, 0, 0.25], atol=1e-12)
    assert sp.pose_error(np.stack([A, B]), B).shape == (2, 6)


@pytest.mark.parametrize(
    "angle", [0.0, 1e-9, 1e-5, 0.3, 2.0, np.pi - 1e-2, np.pi - 1e-5, np.pi]
)
def test_pose_error_rotation_matches_scipy_across_angles(angle, rng):
    axes = rng.normal(size=(20, 3))
    axes /= np.linalg.norm(axes, axis=-1, keepdims=True)
    R = Rotation.from_rotvec(axes * angle)
    T = np.zeros((20, 4, 4))
    T[:, :3, :3] = R.as_matrix()
    T[:, 3, 3] = 1.0
    e = sp.pose_error(np.eye(4), T)[:, 3:]
    ref = Rotation.from_matrix(T[:, :3, :3]).as_rotvec()
    # at exactly pi the sign of the axis is ambiguous: compare up to sign there
    if angle == np.pi:
        e = np.where((e * ref).sum(-1, keepdims=True) < 0, -e, e)
    np.testing.assert_allclose(e, ref, atol=1e-12)


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: sp.pose_error(np.eye(3), np.eye(4)), "current"),
        (lambda: sp.pose_error(np.eye(4), np.zeros((2, 4))), "target"),
        (lambda: sp.pose_error(np.zeros((2, 4, 4)), np.zeros((3, 4, 4))), "target"),
        (lambda: sp.rotvec_from_rotation(np.eye(4)), "R"),
        (lambda: sp.rotation_from_rotvec([1.0, 2.0]), "w"),
        (lambda: sp.matrix_from_rpy([0.1, 0.2]), "rpy"),
        (lambda: sp.matrix_from_quaternion([1.0, 0.0, 0.0]), "wxyz"),
        (lambda: sp.matrix_from_axis_angle(np.zeros(4)), "rotvec"),
        (lambda: sp.rpy_from_matrix(np.eye(3)), "T"),
        (lambda: sp.quaternion_from_matrix([[1, 0], [0, 1]]), "T"),
        (lambda: sp.rpy_from_matrix(np.eye(4, dtype=complex)), "T"),
    ],
)
def test_wrong_shapes_and_types_name_the_argument(call, name):
    with pytest.raises(InputError, match=rf"'{name}'"):
        call()
