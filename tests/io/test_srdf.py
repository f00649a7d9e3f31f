"""SRDF in (issue 26): parsing (safe, strict, errors with file and line), MoveIt's
collision rules, the default tip, and the mapping of URDF pairs onto robokin's merged
links. Oracle for the self-collision effect: robokin's own check with and without the
SRDF, on a configuration found to collide in the pair."""

import warnings
from pathlib import Path

import numpy as np
import pytest

from robokin import collision
from robokin.exceptions import ModelError
from robokin.io import srdf as srdf_mod
from robokin.io.srdf import excluded_link_pairs, parse_srdf

pytest.importorskip("yourdfpy")
from robokin import Robot  # noqa: E402

DATA = Path(__file__).parent.parent / "data" / "urdf"
URDF = DATA / "gripper_arm.urdf"
SRDF = DATA / "gripper_arm.srdf"


def srdf_text(*pairs, extra=""):
    rules = "".join(f'<disable_collisions link1="{a}" link2="{b}" reason="Never"/>\n'
                    for a, b in pairs)
    return f'<?xml version="1.0"?>\n<robot name="gripper_arm">\n{rules}{extra}</robot>\n'


def test_parse_reads_groups_end_effectors_and_pairs():
    s = parse_srdf(SRDF)
    assert s.name == "gripper_arm" and s.file == SRDF
    assert [(c.group, c.base_link, c.tip_link) for c in s.chains] == \
        [("arm", "base_link", "tcp")]
    assert [(e.name, e.parent_link, e.group) for e in s.end_effectors] == \
        [("hand", "flange", "hand")]
    assert len(s.disabled) == 10
    assert s.disabled[0].reason == "Adjacent" and s.disabled[0].line == 9
    assert s.default_tip({"flange", "tcp"}) == "flange"  # the end effector's parent


def test_moveit_rules_disable_wins_then_enable_then_defaults():
    text = srdf_text(("a", "b"), ("c", "d"), extra=(
        '<enable_collisions link1="a" link2="b"/>\n'
        '<enable_collisions link1="e" link2="f"/>\n'
        '<disable_default_collisions link="e"/>\n'))
    allows = parse_srdf(text).allowed()
    assert allows("a", "b") and allows("b", "a")  # disabled, though also enabled
    assert allows("d", "c")
    assert not allows("e", "f")  # re-enabled after the default
    assert allows("e", "g")  # the default for e
    assert not allows("a", "c")  # nothing said: checked


def test_default_tip_from_the_chain_and_ambiguity():
    chain = '<group name="arm"><chain base_link="b" tip_link="t1"/></group>\n'
    assert parse_srdf(srdf_text(extra=chain)).default_tip({"t1"}) == "t1"
    two = chain + '<group name="arm2"><chain base_link="b" tip_link="t2"/></group>\n'
    with pytest.raises(ModelError, match=r"ambiguous tip link.*\['t1', 't2'\].*tip_link="):
        parse_srdf(srdf_text(extra=two)).default_tip({"t1", "t2"})
    with pytest.raises(ModelError, match="names no tip"):
        parse_srdf(srdf_text()).default_tip({"t1"})
    with pytest.raises(ModelError, match=r"line 3: tip_link: the group chain tip_link 't1' is "
                                         "not a link of the URDF"):
        parse_srdf(srdf_text(extra=chain)).default_tip({"x"})


def test_merged_links_rule():
    """A pair inside one robokin link vanishes; a pair across two is excluded only
    when every URDF pair between their shaped links is allowed."""
    parts = {"base": ("b",), "j1": ("l1",), "j2": ("l2", "cam"), "tool": ("hand", "f1")}
    allowed = {frozenset(p) for p in [("b", "l1"), ("l2", "cam"), ("l1", "l2"),
                                      ("hand", "f1"), ("b", "hand")]}
    out = excluded_link_pairs(parts, lambda a, b: frozenset((a, b)) in allowed)
    assert out == {frozenset(("base", "j1"))}
    allowed |= {frozenset(("l1", "cam")), frozenset(("b", "f1"))}
    out = excluded_link_pairs(parts, lambda a, b: frozenset((a, b)) in allowed)
    assert out == {frozenset(("base", "j1")), frozenset(("j1", "j2")),
                   frozenset(("base", "tool"))}
    # links without URDF shapes never appear
    assert excluded_link_pairs({"a": (), "b": ("x",)}, lambda a, b: True) == set()


def test_robot_from_urdf_with_srdf_maps_the_pairs():
    robot = Robot.from_urdf(URDF, srdf=SRDF)
    assert robot.meta["urdf"].tip_link == "flange"  # the end effector's parent link
    assert robot.meta["srdf"].name == "gripper_arm"
    geo = robot.geometry
    assert not geo.exclude_adjacent  # as in MoveIt: only the SRDF's pairs are skipped
    # base-joint_1: the one URDF pair is disabled. joint_1-joint_2: link_1 against
    # the camera is not. joint_3-tool: wrist_cam against link_3 is not.
    assert geo.exclude == {frozenset(("base", "joint_1"))}
    assert (1, 2) in geo.self_pairs() and (3, 4) in geo.self_pairs()
    assert (0, 1) not in geo.self_pairs()


def _colliding_pair_q(robot, pair):
    """A configuration where robokin's check reports the robokin pair colliding."""
    rng = np.random.default_rng(7)
    q = rng.uniform(robot.limits[:, 0], robot.limits[:, 1], (600, robot.n))
    rep = collision.check(robot, collision.Scene(), q, subdivide=False)
    hits = [c for c in rep.collisions if {c[2], c[3]} == set(pair)]
    assert hits, f"no configuration found where {pair} collide"
    return q[hits[0][0]]


@pytest.mark.parametrize("pair, urdf_pairs", [
    (("base", "joint_3"), [("base_link", "link_3")]),
    (("base", "tool"), [("base_link", "hand"), ("base_link", "finger_left"),
                        ("base_link", "finger_right"), ("base_link", "wrist_cam")]),
])
def test_a_disabled_pair_is_not_reported_and_is_otherwise(pair, urdf_pairs):
    plain = Robot.from_urdf(URDF, tip_link="tcp")
    q = _colliding_pair_q(plain, pair)
    adjacent = [("base_link", "link_1"), ("link_1", "link_2"), ("link_2", "link_3"),
                ("link_2", "camera_mount"), ("link_2", "camera"), ("link_3", "hand"),
                ("link_3", "finger_left"), ("link_3", "finger_right"),
                ("link_3", "wrist_cam")]

    def reported(pairs):
        robot = Robot.from_urdf(URDF, tip_link="tcp", srdf=srdf_text(*adjacent, *pairs))
        rep = collision.check(robot, collision.Scene(), q[None], subdivide=False)
        return any({c[2], c[3]} == set(pair) for c in rep.collisions)

    assert not reported(urdf_pairs)  # every URDF pair disabled: never checked
    assert reported(urdf_pairs[:-1])  # one left checked: the robokin pair is checked
    assert reported([])


# ------------------------------------------------------------------ hostile input
@pytest.mark.parametrize("text, match", [
    ('<robot name="x"><disable_collisions link1="a"/></robot>',
     r":1: disable_collisions.link2: <disable_collisions> needs a 'link2' attribute"),
    ('<robot name="x">\n<group name="g"><chain tip_link="t"/></group></robot>',
     r":2: chain.base_link: .*needs a 'base_link'"),
    ('<robot name="x"><end_effector name="e" group="g"/></robot>', "parent_link"),
    ('<robot name="x"><disable_collisions link1="a&#127;" link2="b"/></robot>',
     "control character"),
    ('<srdf name="x"/>', "root element must be <robot>"),
    ('<robot name="x"><disable_collisions', "not valid XML"),
    ('<?xml version="1.0"?>\n<!DOCTYPE r [<!ENTITY a "aaaa"><!ENTITY b "&a;&a;&a;">]>\n'
     '<robot name="x"><disable_collisions link1="&b;" link2="b"/></robot>',
     r"<!DOCTYPE> \(a DTD, entity declarations\) is not allowed in an SRDF"),
    ('<!DOCTYPE r SYSTEM "file:///etc/passwd"><robot name="x"/>', "DOCTYPE"),
])
def test_bad_srdf_is_refused_with_file_line_and_element(tmp_path, text, match):
    path = tmp_path / "bad.srdf"
    path.write_text(text)
    with pytest.raises(ModelError, match=match) as err:
        parse_srdf(path)
    assert err.value.file == str(path)
    assert err.value.line is not None


def test_too_many_elements_are_refused(monkeypatch):
    monkeypatch.setattr(srdf_mod, "MAX_SRDF_ELEMENTS", 50)
    with pytest.raises(ModelError, match=r"more than 50 elements.*MAX_SRDF_ELEMENTS"):
        parse_srdf(srdf_text(*[("a", f"b{i}") for i in range(60)]))


def test_a_huge_file_is_refused_before_parsing(tmp_path):
    path = tmp_path / "huge.srdf"
    with open(path, "wb") as fh:
        fh.truncate(17 * 2**20)
    with pytest.raises(ModelError, match="more than the 16,777,216 bytes"):
        parse_srdf(path)


def test_unknown_links_and_elements_are_warned_about_and_skipped():
    text = srdf_text(("base_link", "nope"), extra='<my_extension value="1"/>\n')
    with pytest.warns(UserWarning) as record:
        robot = Robot.from_urdf(URDF, tip_link="tcp", srdf=text)
    messages = [str(w.message) for w in record]
    assert any("unknown SRDF element <my_extension>" in m for m in messages)
    assert any(":3: <disable_collisions> names link 'nope', which the URDF does not "
               "define" in m for m in messages)
    assert robot.geometry.exclude == frozenset()


def test_a_srdf_for_another_robot_is_warned_about():
    text = srdf_text().replace('name="gripper_arm"', 'name="other"')
    with pytest.warns(UserWarning, match="the SRDF is for robot 'other'"):
        Robot.from_urdf(URDF, tip_link="tcp", srdf=text)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        Robot.from_urdf(URDF, tip_link="tcp", srdf=srdf_text())
