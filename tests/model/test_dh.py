"""DH tables, virtual frames and elementary sequences compile to the right chain."""

import numpy as np
import pytest

import robokin
from reference import dh_modified, dh_standard, random_q
from robokin import Robot
from robokin.spatial import rotx, roty, rotz, trans

PI = np.pi


def test_standard_rows_match_hand_product(rng):
    rows = [
        {"a": 0.1, "alpha": PI / 2, "d": 0.3, "theta": 0.2},
        {"a": 0.4, "alpha": 0.0, "d": 0.0, "theta": -0.1},
        {"a": 0.0, "alpha": -PI / 2, "d": 0.05, "theta": 0.0, "joint": "prismatic"},
        {"a": 0.0, "alpha": 0.3, "d": 0.1, "theta": 0.0},
    ]
    robot = Robot.from_dh(rows)
    ref = [
        (
            r["theta"],
            r["d"],
            r["a"],
            r["alpha"],
            "p" if r.get("joint") == "prismatic" else "r",
        )
        for r in rows
    ]
    for _ in range(20):
        q = rng.uniform(-2, 2, 4)
        np.testing.assert_allclose(robot.fk(q), dh_standard(ref, q), atol=1e-14)


def test_modified_rows_match_hand_product(rng):
    rows = [
        {"alpha": 0.0, "a": 0.0, "theta": 0.0, "d": 0.333},
        {"alpha": -PI / 2, "a": 0.0, "theta": 0.1, "d": 0.0},
        {"alpha": PI / 2, "a": 0.08, "theta": 0.0, "d": 0.2, "joint": "prismatic"},
        {"alpha": 0.4, "a": -0.08, "theta": 0.0, "d": 0.1, "joint": "fixed"},
        {"alpha": PI / 2, "a": 0.088, "theta": 0.3, "d": 0.0},
    ]
    robot = Robot.from_dh(rows, convention="modified")
    ref = [
        (
            r["alpha"],
            r["a"],
            r["theta"],
            r["d"],
            {"prismatic": "p", "fixed": "f"}.get(r.get("joint"), "r"),
        )
        for r in rows
    ]
    assert robot.n == 4
    for _ in range(20):
        q = rng.uniform(-2, 2, 4)
        np.testing.assert_allclose(robot.fk(q), dh_modified(ref, q), atol=1e-14)


def test_sign_reverses_the_joint(rng):
    row = {"a": 0.3, "alpha": 0.2, "d": 0.1, "theta": 0.4}
    fwd = Robot.from_dh([row])
    rev = Robot.from_dh([{**row, "sign": -1}])
    q = rng.uniform(-2, 2, (10, 1))
    np.testing.assert_allclose(rev.fk(q), fwd.fk(-q), atol=1e-14)


def test_base_and_tool_wrap_the_chain(rng):
    base = trans(0.1, 0.2, 0.3) @ rotz(0.5)
    tool = trans(0, 0, 0.15) @ rotx(PI)
    plain = robokin.load("ur5")
    robot = Robot.from_dh(
        [
            {"a": 0, "alpha": PI / 2, "d": 0.089159},
            {"a": -0.425},
            {"a": -0.39225},
            {"d": 0.10915, "alpha": PI / 2},
            {"d": 0.09465, "alpha": -PI / 2},
            {"d": 0.0823},
        ],
        base=base,
        tool=tool,
    )
    q = random_q(plain, rng, 5)
    np.testing.assert_allclose(robot.fk(q), base @ plain.fk(q) @ tool, atol=1e-13)
    np.testing.assert_allclose(
        plain.with_tool(tool).with_base(base).fk(q), robot.fk(q), atol=1e-13
    )


def test_puma_standard_and_modified_agree(rng):
    std, mod = robokin.load("puma560"), robokin.load("puma560_modified")
    q = rng.uniform(-np.pi, np.pi, (200, 6))
    np.testing.assert_allclose(std.fk(q), mod.fk(q), atol=1e-12)
    # the link frames differ (modified frames sit on the joint axes), the tool does not
    assert not np.allclose(std.fk_all(q)[:, 3], mod.fk_all(q)[:, 3])


def _patent_composition(q):
    """The improved-DH patent's direct composition of Rot/Trans operators (frames 0..8)."""
    t1, t2, d3, t4, t5, d6, t7 = q
    l1, d2, d5, l5, l7, d8 = 0.150, 0.300, -0.120, 0.080, 0.150, -0.040
    steps = [
        rotz(t1),
        trans(l1, 0, d2) @ roty(-PI / 2) @ rotx(-PI / 2) @ rotz(t2),
        roty(-PI / 2) @ rotx(-PI / 2) @ trans(0, 0, d3),
        rotx(-PI / 2) @ rotz(t4),
        trans(0, 0, d5) @ roty(PI / 2) @ rotx(PI / 2) @ rotz(t5),
        trans(l5, 0, 0) @ trans(0, 0, d6),
        roty(-PI / 2) @ rotx(-PI / 2) @ rotz(t7),
        trans(l7, -d8, 0) @ rotx(PI / 2),
    ]
    frames = [np.eye(4)]
    for S in steps:
        frames.append(frames[-1] @ S)
    return np.array(frames)


def test_virtual_frames_equal_the_patent_composition(rng):
    robot = robokin.load("improved_dh_arm")
    assert robot.n == 7
    assert [j.kind for j in robot.chain.joints].count("prismatic") == 2
    for _ in range(50):
        q = random_q(robot, rng)
        ref = _patent_composition(q)
        np.testing.assert_allclose(robot.fk_all(q), ref[:8], atol=1e-12)  # {0}..{7}
        np.testing.assert_allclose(robot.fk(q), ref[8], atol=1e-12)  # {8}


def test_dropping_the_virtual_frames_gives_a_wrong_pose(rng):
    from robokin.io.robot_files import parts_from_document

    robot = robokin.load("improved_dh_arm")
    doc = robot.meta["document"]
    without = dict(
        doc, joints=[r for r in doc["joints"] if not r["name"].startswith("frame_")]
    )
    wrong = robokin.Robot.from_parts(parts_from_document(without))
    q = random_q(robot, rng, 20)
    err = np.abs(wrong.fk(q)[..., :3, 3] - robot.fk(q)[..., :3, 3]).max(axis=-1)
    assert (err > 0.05).all()  # d2 = 300 mm and d5 = -120 mm are lost


def test_elementary_sequence_with_joints_about_x_and_y(rng):
    ops = [
        {"op": "tz", "value": 0.2},
        {"op": "rx", "joint": "revolute", "name": "a"},
        {"op": "ty", "value": 0.3},
        {"op": "ry", "joint": "revolute", "name": "b", "value": 0.1},
        {"op": "tx", "joint": "prismatic", "name": "c"},
        {"op": "rz", "value": 0.4},
    ]
    robot = Robot.from_elementary(ops)
    for _ in range(10):
        a, b, c = rng.uniform(-1, 1, 3)
        ref = (
            trans(0, 0, 0.2)
            @ rotx(a)
            @ trans(0, 0.3, 0)
            @ roty(b + 0.1)
            @ trans(c, 0, 0)
            @ rotz(0.4)
        )
        np.testing.assert_allclose(robot.fk([a, b, c]), ref, atol=1e-14)
        frames = robot.fk_all([a, b, c])
        np.testing.assert_allclose(frames[1], trans(0, 0, 0.2) @ rotx(a), atol=1e-14)


def test_dependent_joints_follow_the_coordinates(rng):
    ops = [
        {"op": "rz", "joint": "revolute", "name": "a"},
        {"op": "tx", "value": 1.0},
        {
            "op": "rz",
            "joint": "revolute",
            "name": "b",
            "depends": {"a": -2.0},
            "depends_offset": 0.1,
        },
    ]
    robot = Robot.from_elementary(ops)
    assert robot.n == 1 and robot.n_chain == 2
    a = 0.3
    np.testing.assert_allclose(
        robot.fk([a]), rotz(a) @ trans(1, 0, 0) @ rotz(-2 * a + 0.1), atol=1e-14
    )
    assert robot.fk_all(np.zeros((4, 1))).shape == (4, 3, 4, 4)


@pytest.mark.parametrize(
    ("rows", "match"),
    [
        ([{"a": "x"}], r"rows\[0\]\.a.*number"),
        ([{"a": float("nan")}], r"rows\[0\]\.a.*finite"),
        ([{"a": 0, "limits": [1, -1]}], r"rows\[0\]\.limits.*reversed"),
        ([{"a": 0, "limits": [1]}], r"rows\[0\]\.limits"),
        ([{"a": 0, "joint": "spherical"}], r"rows\[0\]\.joint"),
        ([{"a": 0, "sign": 2}], r"rows\[0\]\.sign"),
        ([{"a": 0, "bogus": 1}], r"rows\[0\].*unknown field"),
        ([[0, 0, 0, 0]], r"rows\[0\].*mapping"),
        ([], r"at least one joint"),
        ([{"name": "j"}, {"name": "j"}], r"unique"),
    ],
)
def test_bad_rows_name_the_field(rows, match):
    with pytest.raises(robokin.ModelError, match=match):
        Robot.from_dh(rows)


def test_bad_convention_is_rejected():
    with pytest.raises(robokin.ModelError, match="convention"):
        Robot.from_dh([{"a": 0}], convention="craig")


def test_missing_dh_keys_default_to_zero_and_misspelt_ones_are_refused():
    # decided in issue 15: a, alpha, d, theta default to 0 (documented in
    # Robot.from_dh); safe because any other key is refused
    rows = [{"a": 0.3}, {"d": 0.2, "joint": "prismatic"}, {"alpha": 0.5, "theta": 0.1}]
    full = [{"a": 0.0, "alpha": 0.0, "d": 0.0, "theta": 0.0, **r} for r in rows]
    q = np.array([0.4, 0.05, -0.3])
    np.testing.assert_array_equal(robokin.Robot.from_dh(rows).fk(q),
                                  robokin.Robot.from_dh(full).fk(q))
    with pytest.raises(robokin.ModelError, match=r"rows\[0\].*unknown field.*'alpah'"):
        robokin.Robot.from_dh([{"a": 0.3, "alpah": 0.5}])
    with pytest.raises(robokin.ModelError, match=r"rows\[0\]\.limits.*numbers"):
        robokin.Robot.from_dh([{"a": 0.3, "limits": ["0", "1"]}])


def test_a_chain_built_directly_needs_a_joint_too():
    from robokin.model.chain import Chain

    with pytest.raises(robokin.ModelError, match="at least one joint"):
        Chain((), np.eye(4), np.zeros((0, 4, 4)), np.zeros((0, 4, 4)))
