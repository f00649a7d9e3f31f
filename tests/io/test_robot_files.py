"""Robot files: units, validation with field paths, atomic save, round trips."""

import os
from pathlib import Path

import numpy as np
import pytest
import yaml

import robokin
from reference import random_q
from robokin.io.robot_files import document_from_robot, load_parts, save_robot

GOOD = """\
name: two_link
source: a test arm
units: {length: mm, angle: deg}
convention: standard
joints:
  - {name: j1, joint: revolute, a: 300, alpha: 0, d: 100, theta: 0, limits: [-90, 90]}
  - {name: j2, joint: prismatic, a: 0, alpha: 0, d: 50, theta: 90, limits: [0, 200]}
tool: {xyz: [0, 0, 100], rpy: [180, 0, 0]}
"""


def _write(tmp_path: Path, text: str) -> Path:
    p = tmp_path / "robot.yaml"
    p.write_text(text)
    return p


def test_units_are_converted_once_at_the_edge(tmp_path):
    robot = robokin.load(_write(tmp_path, GOOD))
    np.testing.assert_allclose(robot.limits, [[-np.pi / 2, np.pi / 2], [0.0, 0.2]])
    T = robot.fk([0.0, 0.02])
    # j1: Rz(0) Tz(0.1) Tx(0.3); j2: Rz(90 deg) Tz(0.05 + 0.02); tool Tz(0.1) Rx(180 deg)
    np.testing.assert_allclose(T[:3, 3], [0.3, 0.0, 0.1 + 0.07 + 0.1], atol=1e-12)
    np.testing.assert_allclose(
        T[:3, :3], [[0, 1, 0], [1, 0, 0], [0, 0, -1]], atol=1e-12
    )


CASES = [
    ("name: x\njoints: []\n", r"robot\.yaml:2: joints"),
    ("joints:\n  - {a: 1}\n", r"robot\.yaml: name: missing required field"),
    (
        GOOD.replace("limits: [-90, 90]", "limits: [90, -90]"),
        r"joints\[0\]\.limits.*reversed",
    ),
    (GOOD.replace("limits: [-90, 90]", "limits: 5"), r"joints\[0\]\.limits"),
    (GOOD.replace("a: 300", "a: three"), r"joints\[0\]\.a"),
    (GOOD.replace("a: 300", "a: .nan"), r"joints\[0\]\.a"),
    (GOOD.replace("length: mm", "length: inch"), r"units\.length"),
    (GOOD.replace("angle: deg", "angle: grad"), r"units\.angle"),
    (GOOD.replace("convention: standard", "convention: craig"), r"convention"),
    (GOOD.replace("joint: prismatic", "joint: ball"), r"joints\[1\]\.joint"),
    (GOOD.replace("  - {name: j2", "  - 7\n  - {name: j2"), r"joints\[1\]"),
    (
        GOOD.replace("theta: 90,", "theta: 90, colour: red,"),
        r"joints\[1\]\.colour: unknown",
    ),
    (GOOD.replace("rpy: [180, 0, 0]", "rpy: [180, 0]"), r"tool\.rpy"),
    (GOOD + "wheels: 4\n", r"wheels: unknown key; accepted: name, source, units"),
    ("- just\n- a list\n", r"robot\.yaml: a robot file must be a mapping"),
    ("name: [unclosed\n", r"robot\.yaml:2: not valid YAML, column"),
    (GOOD.replace("name: j2", "name: j1"), r"unique"),
]


@pytest.mark.parametrize(("text", "match"), CASES)
def test_malformed_files_name_the_file_and_field(tmp_path, text, match):
    with pytest.raises(robokin.ModelError, match=match):
        load_parts(_write(tmp_path, text))


def test_missing_file_is_a_model_error(tmp_path):
    with pytest.raises(robokin.ModelError, match="no such file"):
        robokin.load(tmp_path / "nope.yaml")


def test_unknown_builtin_lists_the_names():
    with pytest.raises(robokin.ModelError, match="aubo_i5.*ur5"):
        robokin.load("ur6")


def test_save_round_trips_a_loaded_file(tmp_path):
    robot = robokin.load(_write(tmp_path, GOOD))
    out = save_robot(robot, tmp_path / "copy.yaml")
    assert yaml.safe_load(out.read_text()) == yaml.safe_load(GOOD)
    again = robokin.load(out)
    np.testing.assert_array_equal(again.fk([0.3, 0.1]), robot.fk([0.3, 0.1]))


@pytest.mark.parametrize("name", ["panda", "qfmd010", "improved_dh_arm"])
def test_code_built_robots_save_as_exact_elementary_files(tmp_path, name, rng):
    original = robokin.load(name)
    robot = original.replace(meta={})  # forget the source document
    doc = document_from_robot(robot)
    assert doc["convention"] == "elementary"
    again = robokin.load(save_robot(robot, tmp_path / f"{name}.yaml"))
    q = random_q(original, rng, 20)
    np.testing.assert_allclose(again.fk(q), original.fk(q), atol=1e-12)
    np.testing.assert_allclose(again.limits, original.limits)
    np.testing.assert_allclose(again.fk_all(q), original.fk_all(q), atol=1e-12)


def test_failed_save_keeps_the_old_file(tmp_path, monkeypatch):
    target = tmp_path / "robot.yaml"
    target.write_text(GOOD)
    robot = robokin.load(target)

    def boom(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(os, "fsync", boom)
    with pytest.raises(robokin.InputError, match=r"robot\.yaml: cannot write: disk full"):
        save_robot(robot, target)
    assert target.read_text() == GOOD
    assert sorted(p.name for p in tmp_path.iterdir()) == ["robot.yaml"]  # no temp left


def test_dependent_joint_units_are_converted(tmp_path):
    text = """\
name: dep
units: {length: mm, angle: deg}
convention: elementary
joints:
  - {op: rz, joint: revolute, name: a, limits: [-90, 90]}
  - {op: tx, value: 1000}
  - {op: rz, joint: revolute, name: b, depends: {a: -1}, depends_offset: 90}
"""
    robot = robokin.load(_write(tmp_path, text))
    assert robot.n == 1
    T = robot.fk([0.25])
    np.testing.assert_allclose(T[:3, 3], [np.cos(0.25), np.sin(0.25), 0], atol=1e-12)
    # total rotation 0.25 - 0.25 + 90 deg
    np.testing.assert_allclose(T[:3, 0], [0, 1, 0], atol=1e-12)
    bad = text.replace("depends: {a: -1}", "depends: {zz: -1}")
    with pytest.raises(
        robokin.ModelError, match=r"joints\[2\]\.depends.*unknown coordinate 'zz'"
    ):
        load_parts(_write(tmp_path, bad))


def test_code_built_robot_keeps_its_actuators_when_saved(tmp_path, rng):
    scara = robokin.load("scara")
    robot = scara.replace(meta={})
    again = robokin.load(save_robot(robot, tmp_path / "scara.yaml"))
    q = random_q(scara, rng, 10)
    np.testing.assert_allclose(
        again.actuators_from_joints(q), scara.actuators_from_joints(q), atol=1e-12
    )


@pytest.mark.parametrize("name", ["aubo_i5", "scara"])
def test_code_built_robot_keeps_its_geometry_when_saved(tmp_path, name):
    original = robokin.load(name)
    robot = original.replace(meta={})
    again = robokin.load(save_robot(robot, tmp_path / f"{name}.yaml"))
    geo, ref = again.geometry, original.geometry
    assert geo.names == ref.names
    assert geo.exclude == ref.exclude and geo.exclude_adjacent == ref.exclude_adjacent
    for a_shapes, b_shapes in zip(geo.shapes, ref.shapes):
        assert [s.kind for s in a_shapes] == [s.kind for s in b_shapes]
        for a, b in zip(a_shapes, b_shapes):
            np.testing.assert_allclose(a.size, b.size)
            np.testing.assert_allclose(a.placement, b.placement, atol=1e-12)


def test_a_changed_loaded_robot_saves_its_changes(tmp_path, rng):
    from robokin.spatial import trans

    ur5 = robokin.load("ur5")
    tooled = ur5.with_tool(trans(0, 0, 0.2))
    again = robokin.load(save_robot(tooled, tmp_path / "tooled.yaml"))
    q = random_q(ur5, rng, 10)
    np.testing.assert_allclose(again.fk(q), tooled.fk(q), atol=1e-12)
    bare = robokin.load(save_robot(ur5.replace(geometry=None), tmp_path / "bare.yaml"))
    assert bare.geometry is None
    renamed = robokin.load(save_robot(ur5.replace(name="ur5_cell_3"), tmp_path / "r.yaml"))
    assert renamed.name == "ur5_cell_3"
    # an unchanged robot keeps its file's own document (units and DH rows)
    same = yaml.safe_load(save_robot(ur5, tmp_path / "same.yaml").read_text())
    assert same["convention"] == "standard" and same["units"]["length"] == "mm"


def test_save_gives_normal_permissions_and_keeps_existing_ones(tmp_path):
    robot = robokin.load("scara")
    new = save_robot(robot, tmp_path / "new.yaml")
    mask = os.umask(0)
    os.umask(mask)
    assert new.stat().st_mode & 0o777 == 0o666 & ~mask
    existing = tmp_path / "existing.yaml"
    existing.write_text("x")
    existing.chmod(0o640)
    save_robot(robot, existing)
    assert existing.stat().st_mode & 0o777 == 0o640


# ------------------------------------------------------- issue 15: strict numbers
@pytest.mark.parametrize(("old", "new", "message"), [
    ("a: 300", 'a: "300"', r"robot\.yaml:6: joints\[0\]\.a: Input should be a valid "
                           r"number \(got '300'\)"),
    ("alpha: 0, d: 100", "alpha: yes, d: 100", r":6: joints\[0\]\.alpha: .*got True"),
    ("limits: [-90, 90]", "limits: [-90, '90']", r":6: joints\[0\]\.limits\[1\]: .*got '90'"),
    ("xyz: [0, 0, 100]", "xyz: [0, 0, '100']", r":8: tool\.xyz\[2\]: .*got '100'"),
    ("a: 300, alpha: 0", "a: 300, alpha: 0, a: 301", r":6: duplicate key 'a'"),
    ("a: 300", "a: 3.0e10", r":6: joints\[0\]\.a: 3e\+07 m is beyond the 1e\+06 m"),
    ("name: j1,", "name: " + "n" * 201 + ",", r"joints\[0\]\.name: String should have "
                                                "at most 200 characters"),
])
def test_numbers_must_be_numbers_and_errors_name_the_line(tmp_path, old, new, message):
    assert old in GOOD
    with pytest.raises(robokin.ModelError, match=message):
        load_parts(_write(tmp_path, GOOD.replace(old, new, 1)))


def test_too_many_joint_rows_are_refused_before_validation(tmp_path):
    rows = "".join("  - {a: 0.1}\n" for _ in range(1001))
    with pytest.raises(robokin.ModelError, match=r"joints: 1,001 rows; a robot file "
                                                 r"holds at most 1,000"):
        load_parts(_write(tmp_path, "name: long\njoints:\n" + rows))


def test_a_file_without_units_that_reads_as_an_89_m_arm_warns(tmp_path):
    ur5_mm = "name: ur5\njoints:\n  - {a: 0, alpha: 1.5707963, d: 89.159}\n" \
             "  - {a: -425, alpha: 0, d: 0}\n"
    with pytest.warns(UserWarning, match=r"no 'units:'.*-425 m \(joints\[1\]\.a\) "
                                         r"suggests millimetres"):
        robot = robokin.load(_write(tmp_path, ur5_mm))
    assert robot.fk(np.zeros(2))[2, 3] == pytest.approx(89.159)  # read as asked
    deg = "name: d\njoints:\n  - {a: 0.4, alpha: 90}\n"
    with pytest.warns(UserWarning, match=r"90 rad \(joints\[0\]\.alpha\) suggests "
                                         "degrees"):
        load_parts(_write(tmp_path, deg))
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        load_parts(_write(tmp_path, GOOD))  # units given: no warning
        load_parts(_write(tmp_path, "name: m\njoints:\n  - {a: 0.425, alpha: 1.57}\n"))
        for name in robokin.robots.names():
            robokin.load(name)


@pytest.mark.parametrize(
    ("units", "row", "match"),
    [
        ("{angle: rad}", "{a: 0.4, alpha: 90}",
         r"declares units: \{length: m, angle: rad\}; an angle of 90 rad "
         r"\(joints\[0\]\.alpha\) suggests degrees: declare 'angle: deg'"),
        ("{length: mm, angle: rad}", "{a: 400, alpha: -180, theta: 0}",
         r"angle: rad\}; an angle of -180 rad \(joints\[0\]\.alpha\) suggests degrees"),
        ("{length: m}", "{a: 425, alpha: 0}",
         r"a length of 425 m \(joints\[0\]\.a\) suggests millimetres: declare "
         r"'length: mm'"),
    ],
)
def test_declared_units_whose_numbers_suggest_others_warn(tmp_path, units, row, match):
    """Issue 25: ``units: {angle: rad}`` with ``alpha: 90`` loaded without a note."""
    with pytest.warns(UserWarning, match=match):
        load_parts(_write(tmp_path, f"name: a\nunits: {units}\njoints:\n  - {row}\n"))
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the same numbers in the unit they suggest
        load_parts(_write(tmp_path, "name: a\nunits: {length: mm, angle: deg}\n"
                                    "joints:\n  - {a: 425, alpha: 90}\n"))


@pytest.mark.parametrize("name", ["arm.urdf", "arm.urdf.xacro", "arm.xacro"])
def test_load_of_a_urdf_points_to_urdf_import(tmp_path, monkeypatch, name):
    """Issue 25: load('x.urdf') said "must be a mapping of fields"."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / name).write_text('<robot name="r"><link name="a"/></robot>\n')
    for given in (name, tmp_path / name):
        with pytest.raises(robokin.ModelError, match=r"a URDF or xacro, not a robokin "
                           r"robot file: read it with robokin.Robot.from_urdf\(.*\) or "
                           r"convert it once with 'robokin import "):
            robokin.load(given)
    # the same XML under a robot-file name: the content gives it away
    f = _write(tmp_path, '<robot name="r"><link name="a"/></robot>\n')
    with pytest.raises(robokin.ModelError, match=r"robot.yaml: a robot file must be a "
                       r"mapping of fields, got str; this looks like XML \(a URDF\?\)"):
        robokin.load(f)


def test_sections_are_an_explicit_table():
    from robokin.io import robot_files

    assert set(robot_files.SECTIONS) == {"actuators", "geometry", "collision", "dynamics",
                                         "rate_limits"}
    assert not hasattr(robot_files, "register_section")
    for section in robot_files.SECTIONS.values():
        assert callable(section.read) and callable(section.write)
