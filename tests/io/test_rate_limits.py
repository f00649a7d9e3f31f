"""Per-joint rate limits (issue 18): the robot-file section, its units and errors,
the built-in values and their sources, URDF ``<limit velocity>`` in and out."""

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

import robokin
from robokin.exceptions import InputError, ModelError
from robokin.io.robot_files import document_from_robot, load_parts, save_robot
from robokin.model.rate_limits import RateLimits

ARM = """\
name: two_link
units: {length: mm, angle: deg}
convention: standard
joints:
  - {name: j1, joint: revolute, a: 300, alpha: 0, d: 100, theta: 0, limits: [-90, 90]}
  - {name: j2, joint: prismatic, a: 0, alpha: 0, d: 50, theta: 90, limits: [0, 200]}
rate_limits:
  source: a test arm's manual
  velocity: [90, 250]          # deg/s, mm/s
  acceleration: [180, 1000]    # deg/s^2, mm/s^2
  jerk: [null, 5000]           # the first is not known
"""


def _write(tmp_path: Path, text: str) -> Path:
    p = tmp_path / "robot.yaml"
    p.write_text(text)
    return p


def test_values_are_in_the_file_units_per_second(tmp_path):
    lim = load_parts(_write(tmp_path, ARM)).rate_limits
    np.testing.assert_allclose(lim.velocity, [math.radians(90), 0.25])
    np.testing.assert_allclose(lim.acceleration, [math.radians(180), 1.0])
    assert math.isnan(lim.jerk[0]) and lim.jerk[1] == pytest.approx(5.0)
    assert lim.source == "a test arm's manual"
    assert not lim.velocity.flags.writeable


def test_one_number_applies_to_every_joint(tmp_path):
    text = ARM.replace("velocity: [90, 250]", "velocity: 90")
    # one number in the file's units: 90 deg/s for the revolute joint, 90 mm/s for
    # the prismatic one
    lim = load_parts(_write(tmp_path, text)).rate_limits
    np.testing.assert_allclose(lim.velocity, [math.radians(90), 0.09])


@pytest.mark.parametrize("replace, match", [
    (("velocity: [90, 250]", "velocity: [90, -1]"), r"rate_limits\.velocity\[1\]: "
                                                     r"expected a finite positive"),
    (("velocity: [90, 250]", "velocity: [90]"), r"rate_limits\.velocity: expected 2"),
    (("velocity: [90, 250]", "velocity: fast"), r"rate_limits\.velocity: expected a"),
    (("velocity: [90, 250]", "velocity: 0"), r"rate_limits\.velocity: .*got 0"),
    (("velocity: [90, 250]", "velocity: .inf"), r"rate_limits\.velocity"),
    (("velocity: [90, 250]", "velocity: [true, 1]"), r"velocity\[0\]"),
    (("velocity: [90, 250]", "speed: [90, 250]"), r"rate_limits\.speed: unknown key; accepted: source, velocity, acceleration, jerk"),
])
def test_bad_values_name_the_field_and_line(tmp_path, replace, match):
    with pytest.raises(ModelError, match=match) as info:
        load_parts(_write(tmp_path, ARM.replace(*replace)))
    assert info.value.line is not None  # the editor can jump there


def test_a_section_with_no_limit_is_refused(tmp_path):
    text = ARM.split("rate_limits:")[0] + "rate_limits: {source: nothing}\n"
    with pytest.raises(ModelError, match="at least one of velocity"):
        load_parts(_write(tmp_path, text))


def test_loaded_file_round_trips_unchanged(tmp_path):
    robot = load_parts(_write(tmp_path, ARM))
    back = load_parts(save_robot(robot, tmp_path / "copy.yaml"))
    assert back.rate_limits == robot.rate_limits
    # the file's own units are kept
    assert yaml.safe_load((tmp_path / "copy.yaml").read_text())["rate_limits"][
        "velocity"] == [90, 250]


def test_robot_built_in_memory_writes_si_limits(tmp_path):
    robot = robokin.load("ur5").with_tool(np.eye(4))  # no longer the file's state
    lim = RateLimits(velocity=[1, 2, 3, 4, 5, 6], jerk=[np.nan] * 5 + [9.0],
                     source="made up")
    robot = robot.replace(rate_limits=lim)
    doc = document_from_robot(robot)
    assert doc["units"] == {"length": "m", "angle": "rad"}
    assert doc["rate_limits"]["jerk"][:5] == [None] * 5
    back = load_parts(save_robot(robot, tmp_path / "mem.yaml"))
    assert back.rate_limits == lim


def test_replacing_the_limits_rewrites_the_document():
    robot = robokin.load("aubo_i5")
    faster = robot.replace(rate_limits=RateLimits(velocity=[9.0] * 6))
    assert document_from_robot(faster)["rate_limits"]["velocity"] == [9.0] * 6


def test_robot_refuses_limits_for_another_joint_count():
    with pytest.raises(InputError, match="rate_limits"):
        robokin.load("ur5").replace(rate_limits=RateLimits(velocity=[1.0, 2.0]))


def test_rate_limits_refuse_zero_and_negative_values():
    with pytest.raises(ModelError, match=r"velocity\[1\]"):
        RateLimits(velocity=[1.0, 0.0])
    with pytest.raises(ModelError, match="expected 2 values"):
        RateLimits(velocity=[1.0, 2.0], acceleration=[1.0])
    with pytest.raises(ModelError, match="at least one"):
        RateLimits()


# ----------------------------------------------------------------- built-in arms
def test_builtin_limits_with_their_sources():
    aubo = robokin.load("aubo_i5").rate_limits
    np.testing.assert_allclose(np.degrees(aubo.velocity), [150] * 3 + [180] * 3)
    np.testing.assert_allclose(aubo.acceleration, [30] * 3 + [25] * 3, rtol=1e-6)
    assert aubo.jerk is None and "datasheet" in aubo.source
    ur5 = robokin.load("ur5").rate_limits
    np.testing.assert_allclose(np.degrees(ur5.velocity), [180] * 6)
    assert "ESTIMATED" in ur5.source  # no published joint acceleration limit
    panda = robokin.load("panda").rate_limits
    np.testing.assert_allclose(panda.velocity, [2.175] * 4 + [2.61] * 3)
    np.testing.assert_allclose(panda.acceleration, [15, 7.5, 10, 12.5, 15, 20, 20])
    np.testing.assert_allclose(panda.jerk, [7500, 3750, 5000, 6250, 7500, 10000,
                                            10000])


# ------------------------------------------------------------------------- URDF
pytest.importorskip("yourdfpy")
from robokin import Robot  # noqa: E402

URDF = """<robot name="two">
  <link name="a"/><link name="b"/><link name="c"/>
  <joint name="j1" type="revolute"><parent link="a"/><child link="b"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="5" velocity="2.5"/></joint>
  <joint name="j2" type="prismatic"><parent link="b"/><child link="c"/>
    <origin xyz="0.3 0 0"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="0.2" effort="5" velocity="0"/></joint>
</robot>"""


def test_urdf_velocity_is_imported_and_zero_means_unknown():
    lim = Robot.from_urdf(URDF).rate_limits
    assert lim.velocity[0] == 2.5 and math.isnan(lim.velocity[1])
    assert lim.acceleration is None and "<limit velocity>" in lim.source


def test_urdf_without_velocities_gives_no_limits():
    assert Robot.from_urdf(URDF.replace('velocity="2.5"', 'velocity="0"')
                           ).rate_limits is None


@pytest.mark.parametrize("name", ["aubo_i5", "ur5", "panda"])
def test_urdf_round_trip_keeps_the_speed_limits(name):
    robot = robokin.load(name)
    back = Robot.from_urdf(robot.to_urdf())
    np.testing.assert_allclose(back.rate_limits.velocity, robot.rate_limits.velocity,
                               rtol=1e-15)


def test_mimic_joints_are_written_with_their_scaled_speed():
    robot = robokin.load("qfmd010").replace(
        rate_limits=RateLimits(velocity=[1.0, 2.0, 3.0, 4.0]))
    text = robot.to_urdf()
    back = Robot.from_urdf(text)
    np.testing.assert_allclose(back.rate_limits.velocity, [1, 2, 3, 4])
    # the forearm joint is theta3 - theta2: both drive it, each at its own speed
    assert 'velocity="2.0"' in text and 'velocity="3.0"' in text


def test_unknown_speeds_get_the_placeholder():
    text = robokin.load("puma560").to_urdf(velocity=0.0)
    assert "<limit velocity> and an effort without a torque limit are placeholders" in text
    assert Robot.from_urdf(text).rate_limits is None  # 0 reads back as unknown
