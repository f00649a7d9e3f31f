"""Configuration flags (issue 27 item 4): KUKA Status/Turn, ABB confdata, FANUC config,
Yaskawa RCONF, Staubli config.

Oracles: the vendors' documented values at their reference poses (KUKA HOME is
S 'B010', T 'B000010'; ABB's calibration and tool-down poses are [0,0,0,0]; FANUC's
tool-down home is 'N U T, 0, 0, 0'; a taught Yaskawa tool-down point is RCONF 0,...;
Staubli's park pose is lefty / epositive / wpositive), the definitions' boundary
values, and the property a controller relies on: the eight IK branches of one pose
get eight different flag sets, on spherical-wrist (KUKA-like, Puma) and offset-wrist
(UR5, AUBO-i5) arms.
"""

import numpy as np
import pytest

import robokin
from robokin.exceptions import InputError
from robokin.trajectory.io import ControllerProfile
from robokin.trajectory.posts.arm_config import (
    abb_confdata,
    abb_quadrant,
    arm_configuration,
    fanuc_config,
    fanuc_turn,
    kuka_status_turn,
    staubli_config,
    yaskawa_rconf,
)
from vendor_arms import PROFILES, kuka_like, model_q


def flags(robot, profile, controller_deg):
    cfg = arm_configuration(robot, model_q(profile, controller_deg), profile)
    np.testing.assert_allclose(cfg.joints_deg[0], controller_deg, atol=1e-9)
    return cfg.joints_deg[0], bool(cfg.behind_axis_1[0]), bool(cfg.behind_lower_arm[0])


def test_kuka_home_is_status_2_turn_2_and_the_other_areas():
    arm, prof = kuka_like(), PROFILES["kuka"]
    assert tuple(map(int, kuka_status_turn(*flags(arm, prof, [0, -90, 90, 0, 0, 0])))) == (2, 2)
    # tool down (A5 = +90): still the basic area, elbow up: S 'B010'
    assert int(kuka_status_turn(*flags(arm, prof, [0, -90, 90, 0, 90, 0]))[0]) == 2
    # A5 < 0: bit 2 -> S 'B110' = 6, the other value every KUKA program is full of
    assert int(kuka_status_turn(*flags(arm, prof, [10, -90, 90, 0, -45, 0]))[0]) == 6
    # forearm folded back over the shoulder: wrist behind A1 (bit 0) and behind the
    # A2-A3 line (bit 1 clear): S 'B001'
    s, t = kuka_status_turn(*flags(arm, prof, [-20, -90, -40, 30, 60, -10]))
    assert int(s) == 1 and int(t) == 0b100111  # A1, A2, A3, A6 negative
    # upper arm leaning back past vertical, forearm forward: the wrist point behind
    # A1 while still in front of the A2-A3 line: S 'B011'
    assert int(kuka_status_turn(*flags(arm, prof, [0, -150, 60, 0, 30, 0]))[0]) == 3


def test_kuka_bit_2_and_turn_at_their_boundaries():
    a = np.zeros((6, 6))
    a[:, 4] = [-180.0, -1e-9, 0.0, 179.9, 180.0, 359.0]
    s, t = kuka_status_turn(a, False, False)
    assert ((s >> 2) & 1).tolist() == [1, 1, 0, 0, 1, 1]
    assert t.tolist() == [16, 16, 0, 0, 0, 0]
    assert kuka_status_turn(-np.ones(6) * 1e-12, True, True)[1] == 63


def test_abb_calibration_and_home_are_zero_and_quadrants():
    arm, prof = kuka_like(), PROFILES["abb"]
    assert abb_confdata(*flags(arm, prof, [0, 0, 0, 0, 0, 0])).tolist() == [0, 0, 0, 0]
    assert abb_confdata(*flags(arm, prof, [0, 0, 0, 0, 90, 0])).tolist() == [0, 0, 0, 0]
    assert abb_confdata(*flags(arm, prof, [100, 10, 5, -45, -30, 200])).tolist() == \
        [1, -1, 2, 1]
    # the quadrant rule: [0, 90) -> 0, [90, 180) -> 1, (-90, 0) -> -1, (-180, -90] -> -2
    vals = [0.0, 89.999, 90.0, 179.0, 180.0, -1e-9, -89.9, -90.0, -179.9, -180.0, 359.0]
    assert abb_quadrant(vals).tolist() == [0, 0, 1, 1, 2, -1, -1, -2, -2, -3, 3]


def test_fanuc_tool_down_home_is_nut_and_turn_numbers():
    arm, prof = kuka_like(), PROFILES["fanuc"]
    assert fanuc_config(*flags(arm, prof, [0, 0, 0, 0, -90, 0])) == ["N U T, 0, 0, 0"]
    assert fanuc_config(*flags(arm, prof, [0, 0, 0, 0, 90, 0])) == ["F U T, 0, 0, 0"]
    assert fanuc_config(*flags(arm, prof, [0, 0, 0, 0, -90, 270])) == ["N U T, 0, 0, 1"]
    # turn k: angle - 360 k in (-180, 180]
    assert fanuc_turn([-540.0, -539.9, -181.0, -180.0, 0.0, 180.0, 180.001, 540.0]
                      ).tolist() == [-2, -1, -1, -1, 0, 0, 1, 1]
    assert fanuc_config(np.zeros(6), True, True, turn_axes=(1, 4, 6)) == ["F D B, 0, 0, 0"]


def test_yaskawa_taught_tool_down_is_rconf_zero():
    arm, prof = kuka_like(), PROFILES["yaskawa"]
    assert yaskawa_rconf(*flags(arm, prof, [0, 0, 0, 0, -90, 0])).tolist() == [0] * 8
    assert yaskawa_rconf(*flags(arm, prof, [200, 0, 0, 190, 30, 185])).tolist() == \
        [1, 0, 0, 1, 1, 1, 0, 0]


def test_staubli_park_is_lefty_epositive_wpositive():
    arm, prof = kuka_like(), PROFILES["staubli"]
    q, back, _ = flags(arm, prof, [0, 0, 90, 0, 90, 0])
    assert staubli_config(q, back) == [("lefty", "epositive", "wpositive")]
    q, back, _ = flags(arm, prof, [0, 0, -30, 0, -20, 0])
    assert staubli_config(q, back) == [("righty", "enegative", "wnegative")]


ARMS = {"kuka_like": lambda: (kuka_like(), PROFILES["kuka"]),
        "ur5": lambda: (robokin.load("ur5"), ControllerProfile()),
        "aubo_i5": lambda: (robokin.load("aubo_i5"), ControllerProfile()),
        "puma560": lambda: (robokin.load("puma560"), ControllerProfile())}


@pytest.mark.parametrize("arm", sorted(ARMS))
def test_the_branches_of_a_pose_get_different_flags(arm):
    """The eight IK branches of a pose: eight shoulder / elbow / wrist triples, and
    eight different KUKA statuses, ABB cfx, FANUC and Yaskawa strings."""
    robot, prof = ARMS[arm]()
    rng = np.random.default_rng(7)
    lo, hi = robot.limits[:, 0], robot.limits[:, 1]
    checked = 0
    for _ in range(40):
        q = rng.uniform(np.maximum(lo, -2.8), np.minimum(hi, 2.8))
        sols = robot.ik(robot.fk(q))
        Q = sols.q[sols.valid & ~sols.flags.get("singular", np.zeros_like(sols.valid))]
        if len(Q) < 2:
            continue
        cfg = arm_configuration(robot, Q, prof)
        if (np.abs(cfg.reach) < 1e-6).any():
            continue
        triples = set(zip(cfg.behind_axis_1, cfg.behind_lower_arm, cfg.joints_deg[:, 4] < 0))
        assert len(triples) == len(Q)
        s, _ = kuka_status_turn(cfg.joints_deg, cfg.behind_axis_1, cfg.behind_lower_arm)
        cf = abb_confdata(cfg.joints_deg, cfg.behind_axis_1, cfg.behind_lower_arm)
        fan = fanuc_config(cfg.joints_deg, cfg.behind_axis_1, cfg.behind_lower_arm)
        ry = yaskawa_rconf(cfg.joints_deg, cfg.behind_axis_1, cfg.behind_lower_arm)
        assert len(set(s.tolist())) == len(set(cf[:, 3].tolist())) == len(Q)
        assert len({f.split(",")[0] for f in fan}) == len({tuple(r[:3]) for r in ry}) == len(Q)
        checked += 1
    assert checked >= 20


def test_batch_equals_one_at_a_time_and_bad_input():
    robot, prof = kuka_like(), PROFILES["kuka"]
    Q = np.radians([[0, -90, 90, 0, 30, 0], [10, -60, 100, 20, -40, 50], [-30, -120, 20, 0, 10, 0]])
    batch = arm_configuration(robot, Q, prof)
    for k, q in enumerate(Q):
        one = arm_configuration(robot, q, prof)
        assert one.behind_axis_1[0] == batch.behind_axis_1[k]
        assert one.behind_lower_arm[0] == batch.behind_lower_arm[k]
        np.testing.assert_allclose(one.elbow[0], batch.elbow[k])
    with pytest.raises(InputError, match="six-axis arm; panda has 7"):
        arm_configuration(robokin.load("panda"), np.zeros(7), prof)
    with pytest.raises(InputError, match="expected"):
        kuka_status_turn(np.zeros(5), False, False)


def test_root_frame_turns_the_front():
    """The UR5 reaches along -x at q1 = 0: its default root calls that 'behind axis 1';
    a root turned 180 deg about z (x where the arm reaches) calls it front."""
    ur5 = robokin.load("ur5")
    q = np.array([0.0, -1.0, 1.2, -1.5, -1.5, 0.0])
    plain = arm_configuration(ur5, q, ControllerProfile())
    turned = arm_configuration(ur5, q, ControllerProfile(root=(0, 0, 0, 0, 0, np.pi)),
                               ControllerProfile(root=(0, 0, 0, 0, 0, np.pi)).frame("root"))
    assert plain.behind_axis_1[0] and not turned.behind_axis_1[0]
    np.testing.assert_allclose(plain.reach, -turned.reach, atol=1e-12)
