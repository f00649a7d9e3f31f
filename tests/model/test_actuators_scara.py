"""The built-in SCARA in actuator (motor) space: the paper's motor angles, round trips,
FK / Jacobian / IK with ``space="actuator"`` (issue 5)."""

import numpy as np
import pytest

import robokin
from robokin.exceptions import InputError
from robokin.spatial import axis_angle_from_matrix
from robokin.trajectory.samples import Trajectory

T_PAPER = np.arange(0.0, 5.0 + 1e-9, 0.5)
# Paper parameters: c1 = 400, c2 = 325, c3 = 275, c4 = -150 mm; lead 20 mm, i = 1, j = 15.
C1, C2, C3, C4 = 0.400, 0.325, 0.275, -0.150
LEAD, I_RED, J_RED = 0.020, 1.0, 15.0


@pytest.fixture(scope="module")
def scara():
    return robokin.load("scara")


def _q_from_phi_by_hand(phi):
    """The paper's inverse map, in SI: theta3 = phi4 / j, l4 = (phi4/j - phi3/i) l / 2pi."""
    phi = np.asarray(phi)
    th3 = phi[..., 3] / J_RED
    l4 = (phi[..., 3] / J_RED - phi[..., 2] / I_RED) * LEAD / (2 * np.pi)
    return np.stack([phi[..., 0], phi[..., 1], th3, l4], axis=-1)


def _scara_fk_by_hand(q):
    """The paper's closed form: position and yaw q1 + q2 + q3."""
    q1, q2, q3, l4 = q
    T = np.eye(4)
    yaw = q1 + q2 + q3
    T[:2, :2] = [[np.cos(yaw), -np.sin(yaw)], [np.sin(yaw), np.cos(yaw)]]
    T[:3, 3] = [C2 * np.cos(q1) + C3 * np.cos(q1 + q2), C2 * np.sin(q1) + C3 * np.sin(q1 + q2),
                C1 + C4 + l4]
    return T


@pytest.mark.parametrize(
    ("lift_mm", "phi3_deg"),
    [
        (lambda t: t**2, lambda t: 36 * t - 18 * t**2),
        (lambda t: 60 * np.sin(np.pi * t / 10), lambda t: 36 * t - 1080 * np.sin(np.pi * t / 10)),
        (lambda t: 10 * t, lambda t: -144 * t),
    ],
    ids=["t2", "sine", "linear"],
)
def test_scara_motor_angles_are_the_papers_equation_17(scara, lift_mm, phi3_deg):
    t = T_PAPER
    q1, q2 = np.radians(20 * t), np.radians(-10 * t)  # motors 1 and 2 drive directly
    q = np.stack([q1, q2, np.radians(36 * t), lift_mm(t) / 1000.0], axis=-1)
    phi = scara.actuators_from_joints(q)
    assert phi.shape == (t.size, 4)
    np.testing.assert_allclose(phi[:, 0], q1, atol=1e-15)
    np.testing.assert_allclose(phi[:, 1], q2, atol=1e-15)
    np.testing.assert_allclose(np.degrees(phi[:, 2]), phi3_deg(t), atol=1e-9)
    np.testing.assert_allclose(np.degrees(phi[:, 3]), 540 * t, atol=1e-9)
    np.testing.assert_allclose(scara.joints_from_actuators(phi), q, atol=1e-12)


def test_scara_actuators_match_the_robot_file(scara):
    assert scara.actuator_names == ("motor1", "motor2", "motor3", "motor4")
    assert scara.actuators.n_in == scara.actuators.n_out == 4
    np.testing.assert_allclose(scara.actuators.matrix,
                               [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 1 / 15],
                                [0, 0, -LEAD / (2 * np.pi), LEAD / (2 * np.pi * 15)]],
                               atol=1e-15)
    assert np.isinf(scara.actuator_limits).all()


def test_phi_to_q_to_phi_round_trip_random(scara, rng):
    phi = rng.uniform(-50, 50, (3, 40, 4))  # any leading batch shape
    q = scara.joints_from_actuators(phi)
    assert q.shape == phi.shape
    np.testing.assert_allclose(q, _q_from_phi_by_hand(phi), atol=1e-12)
    np.testing.assert_allclose(scara.actuators_from_joints(q), phi, atol=1e-10)
    q = rng.uniform(scara.limits[:, 0], scara.limits[:, 1], (200, 4))
    np.testing.assert_allclose(scara.joints_from_actuators(scara.actuators_from_joints(q)),
                               q, atol=1e-12)
    # a single configuration is a batch of one
    np.testing.assert_allclose(scara.actuators_from_joints(q[0]),
                               scara.actuators_from_joints(q[:1])[0])


def test_actuator_inputs_are_validated(scara):
    with pytest.raises(InputError, match=r"argument 'phi'.*\(\.\.\., 4\)"):
        scara.joints_from_actuators(np.zeros(3))
    with pytest.raises(InputError, match="argument 'phi': holds a non-finite"):
        scara.joints_from_actuators([0, 0, np.nan, 0])
    with pytest.raises(InputError, match="argument 'q'"):
        scara.actuators_from_joints(np.zeros(5))
    with pytest.raises(InputError, match="argument 'space'"):
        scara.fk(np.zeros(4), space="motor")


def test_motion_types_on_the_robot(scara):
    """The paper's table through the robot's map: motor 3 alone lifts, motors 3 and 4
    together (N1 = N2) rotate, motor 4 alone moves the shaft on a 20 mm-lead helix."""
    turn = 2 * np.pi
    vertical = scara.joints_from_actuators([0, 0, I_RED * turn, 0])
    np.testing.assert_allclose(vertical, [0, 0, 0, -LEAD], atol=1e-15)
    rotation = scara.joints_from_actuators([0, 0, I_RED * turn, J_RED * turn])
    np.testing.assert_allclose(rotation, [0, 0, turn, 0], atol=1e-15)
    helix = scara.joints_from_actuators(np.outer([0.25, 1.0, 3.0], [0, 0, 0, J_RED * turn]))
    np.testing.assert_allclose(helix[:, 2:], np.outer([0.25, 1.0, 3.0], [turn, LEAD]),
                               atol=1e-14)


def test_fk_in_actuator_space(scara, rng):
    phi = rng.uniform(-3, 3, (30, 4))
    T = scara.fk(phi, space="actuator")
    q = _q_from_phi_by_hand(phi)
    for k in range(len(phi)):
        np.testing.assert_allclose(T[k], _scara_fk_by_hand(q[k]), atol=1e-12)
    np.testing.assert_allclose(scara.fk_all(phi, space="actuator"), scara.fk_all(q), atol=1e-12)


def test_jacobian_in_actuator_space_against_finite_differences(scara, rng):
    h = 1e-6
    for phi in rng.uniform(-3, 3, (5, 4)):
        J = scara.jacobian(phi, space="actuator")
        assert J.shape == (6, 4)
        fd = np.zeros((6, 4))
        for c in range(4):
            d = np.zeros(4)
            d[c] = h
            Tp, Tm = scara.fk(phi + d, space="actuator"), scara.fk(phi - d, space="actuator")
            fd[:3, c] = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
            fd[3:, c] = axis_angle_from_matrix(
                np.block([[Tp[:3, :3] @ Tm[:3, :3].T, np.zeros((3, 1))],
                          [np.zeros((1, 3)), np.ones((1, 1))]]))
            fd[3:, c] /= 2 * h
        np.testing.assert_allclose(J, fd, atol=1e-7)
        # = J(q) A
        q = scara.joints_from_actuators(phi)
        np.testing.assert_allclose(J, scara.jacobian(q) @ scara.actuators.matrix, atol=1e-14)
    # motor 4 turns and lifts the tool: its column has both vz and wz
    J = scara.jacobian(np.zeros(4), space="actuator")
    assert J[2, 3] == pytest.approx(LEAD / (2 * np.pi * J_RED))
    assert J[5, 3] == pytest.approx(1 / J_RED)
    assert J[2, 2] == pytest.approx(-LEAD / (2 * np.pi))
    assert J[5, 2] == 0.0


def test_robot_without_actuators_is_the_identity():
    ur5 = robokin.load("ur5")
    assert ur5.actuators is None
    q = np.linspace(-1, 1, 6)
    np.testing.assert_array_equal(ur5.actuators_from_joints(q), q)
    np.testing.assert_array_equal(ur5.joints_from_actuators(q), q)
    np.testing.assert_array_equal(ur5.jacobian(q, space="actuator"), ur5.jacobian(q))
    np.testing.assert_array_equal(ur5.fk(q, space="actuator"), ur5.fk(q))


def test_actuator_limits_are_checked_in_motor_space(scara):
    lim = np.radians([[-150, 150], [-145, 145], [-3600, 3600], [-5400, 5400]])
    r = scara.replace(actuator_limits=lim)
    assert r.within_actuator_limits(np.radians([0, 0, 3000, 0]))
    assert not r.within_actuator_limits(np.radians([0, 0, 3700, 0]))
    np.testing.assert_array_equal(
        r.within_actuator_limits(np.radians([[0, 0, 0, 5500], [0, 0, 0, 5300]])), [False, True])


def test_passive_joint_driven_through_the_matrix(scara):
    # Three motors for four joints: joint 2 follows motor 1 at half speed (a passive joint).
    A = np.array([[1.0, 0, 0], [0.5, 0, 0], [0, 1.0, 0], [0, 0, 1.0]])
    r = scara.replace(actuators=robokin.model.coupling.AffineMap(A, np.zeros(4)),
                      actuator_names=None, actuator_limits=None)
    phi = np.array([0.4, 0.1, 0.02])
    q = r.joints_from_actuators(phi)
    np.testing.assert_allclose(q, [0.4, 0.2, 0.1, 0.02])
    np.testing.assert_allclose(r.actuators_from_joints(q), phi, atol=1e-14)
    with pytest.raises(InputError, match="not reachable through the actuator map.*'elbow'"):
        r.actuators_from_joints([0.4, 0.3, 0.1, 0.02])
    assert r.jacobian(phi, space="actuator").shape == (6, 3)
    assert r.actuator_names == ("motor1", "motor2", "motor3")


def test_numeric_ik_in_actuator_space_nearest_does_not_wrap_motor_angles(scara):
    phi = scara.actuators_from_joints(np.array([[0.3, 0.8, 0.5, 0.05]]))
    T = scara.fk(phi, space="actuator")
    sols = scara.ik(T, space="actuator", method="numeric")
    assert sols.valid.any()
    rows = sols.q[0][sols.valid[0]]
    np.testing.assert_allclose(scara.fk(rows, space="actuator"),
                               np.broadcast_to(T[0], (len(rows), 4, 4)), atol=1e-7)
    # A current motor position several radians away: a 2*pi shift of a geared motor
    # is not a joint turn, so the nearest solution must still reach T.
    near = sols.nearest(phi + np.array([0.0, 0.0, 3.0, 3.0]))
    np.testing.assert_allclose(scara.fk(near, space="actuator"), T, atol=1e-7)
    assert not sols.is_revolute.any()


def test_ik_in_actuator_space(scara, rng):
    q = rng.uniform(scara.limits[:, 0] * 0.8, scara.limits[:, 1] * 0.8, (6, 4))
    q[:, 1] = np.where(np.abs(q[:, 1]) < 0.2, 0.5, q[:, 1])  # away from the elbow singularity
    phi = scara.actuators_from_joints(q)
    T = scara.fk(phi, space="actuator")
    sols = scara.ik(T, space="actuator")
    assert sols.q.shape[-1] == 4
    assert sols.valid.any(axis=-1).all()
    for k in range(len(q)):
        rows = sols.q[k][sols.valid[k]]
        np.testing.assert_allclose(scara.fk(rows, space="actuator"),
                                   np.broadcast_to(T[k], (len(rows), 4, 4)), atol=1e-7)
        # joint-space solutions converted through the map: phi = A^+ (q - b)
        q_rows = scara.joints_from_actuators(rows)
        np.testing.assert_allclose(scara.actuators_from_joints(q_rows), rows, atol=1e-9)
    # the original motor angles are among them (up to whole turns of the joints)
    near = sols.nearest(phi)
    np.testing.assert_allclose(scara.fk(near, space="actuator"), T, atol=1e-7)
    # limits are checked in both spaces
    tight = scara.replace(actuator_limits=np.tile([-1e-3, 1e-3], (4, 1)))
    s2 = tight.ik(T[:1], space="actuator")
    assert not s2.flags["within_limits"][0][s2.valid[0]].any()
    assert "joint_within_limits" in s2.flags


def test_paper_motion_as_a_trajectory_in_motor_space(scara):
    """Motor positions, velocities and accelerations of the paper's first test motion
    (theta3 = 36 t deg, l4 = t^2 mm): phi3 = 36t - 18t^2, phi3' = 36 - 36t, phi3'' = -36,
    phi4 = 540 t, phi4' = 540, phi4'' = 0 (deg, s)."""
    t = T_PAPER
    z = np.zeros_like(t)
    d = np.radians
    q = np.stack([z, z, d(36 * t), t**2 / 1000], axis=-1)
    qd = np.stack([z, z, d(36 + z), 2 * t / 1000], axis=-1)
    qdd = np.stack([z, z, z, 2 / 1000 + z], axis=-1)
    tr = Trajectory(t, q, qd, qdd).to_actuator_space(scara)
    assert tr.space == "actuator"
    np.testing.assert_allclose(np.degrees(tr.q[:, 2]), 36 * t - 18 * t**2, atol=1e-9)
    np.testing.assert_allclose(np.degrees(tr.qd[:, 2]), 36 - 36 * t, atol=1e-9)
    np.testing.assert_allclose(np.degrees(tr.qdd[:, 2]), -36 + z, atol=1e-9)
    np.testing.assert_allclose(np.degrees(tr.q[:, 3]), 540 * t, atol=1e-9)
    np.testing.assert_allclose(np.degrees(tr.qd[:, 3]), 540 + z, atol=1e-9)
    np.testing.assert_allclose(np.degrees(tr.qdd[:, 3]), z, atol=1e-9)
    back = tr.to_joint_space(scara)
    np.testing.assert_allclose(back.q, q, atol=1e-12)
    np.testing.assert_allclose(back.qd, qd, atol=1e-12)
