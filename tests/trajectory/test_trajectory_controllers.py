"""Controller programs per profile (issue 19, item 3): URScript for UR arms, a waypoint
file (round trip) for vendor SDKs such as AUBO's, ROS 2 for any arm; a profile's
programs are the only ones written."""

import json

import numpy as np
import pytest

import robokin
from robokin import trajectory
from robokin.cli import main
from robokin.exceptions import InputError, ModelError
from robokin.trajectory.controllers import (
    controller_profile,
    controller_program,
    read_waypoints,
    write_controller_program,
)


def motion(robot, dt=0.008):
    q0 = np.zeros(robot.n) + 0.1
    return trajectory.quintic(q0, q0 + 0.3, 0.4, dt).replace(joint_names=robot.joint_names)


def test_ur5_runs_urscript_servoj():
    ur5 = robokin.load("ur5")
    tr = motion(ur5)
    prog = controller_program(ur5, tr)
    assert prog.program == "urscript" and prog.suffix == ".script"
    assert "URScript" in prog.describe() and "UR5" in prog.describe()
    lines = prog.text.splitlines()
    assert lines[0] == "def robokin_ur5():" and lines[-1] == "end"
    assert lines[2].startswith("  movej([") and lines[-2] == "  stopj(2.0)"
    servo = [ln for ln in lines if ln.strip().startswith("servoj(")]
    assert len(servo) == len(tr) - 1 and all("t=0.008," in ln for ln in servo)
    vals = [float(v) for v in servo[-1][servo[-1].index("[") + 1:
                                        servo[-1].index("]")].split(",")]
    np.testing.assert_allclose(vals, tr.q[-1], atol=1e-9)  # radians, model order
    ros = controller_program(ur5, tr, "ros2")
    assert "joint_names: [shoulder_pan_joint, shoulder_lift_joint" in ros.text
    with pytest.raises(InputError, match=r"runs \['urscript', 'ros2'\], not waypoints"):
        controller_program(ur5, tr, "waypoints")


def test_aubo_i5_runs_a_waypoint_file_not_urscript(tmp_path):
    aubo = robokin.load("aubo_i5")
    tr = motion(aubo)
    prof = controller_profile(aubo)
    assert prof.programs == ("waypoints", "ros2") and prof.angle_unit == "rad"
    prog = write_controller_program(aubo, tr, tmp_path / "p.waypoints.csv")
    assert prog.program == "waypoints" and prog.path == tmp_path / "p.waypoints.csv"
    text = prog.path.read_text().splitlines()
    assert text[0].startswith("# robokin waypoints: aubo_i5, controller profile 'AUBO-i5")
    assert "every 0.008 s" in text[1] and "angles in rad" in text[1]
    assert text[3] == ("t [s],shoulder_joint [rad],upperArm_joint [rad],foreArm_joint "
                       "[rad],wrist1_joint [rad],wrist2_joint [rad],wrist3_joint [rad]")
    back = read_waypoints(prog.path, prof, aubo.joint_names)
    np.testing.assert_array_equal(back.q, tr.q)
    np.testing.assert_array_equal(back.t, tr.t)
    assert back.joint_names == aubo.joint_names
    with pytest.raises(InputError, match=r"runs \['waypoints', 'ros2'\], not urscript"):
        controller_program(aubo, tr, "urscript")
    with pytest.raises(InputError, match="expected one of"):
        controller_program(aubo, tr, "krl")


def test_waypoint_file_applies_order_signs_offsets_and_units(tmp_path):
    """A controller whose zero, directions, order and units differ from the model's."""
    doc = robokin.load("aubo_i5").meta["document"]
    doc = {k: v for k, v in doc.items() if k != "controller"}
    doc["controller"] = {
        "name": "vendor X", "programs": ["waypoints"], "angle_unit": "deg",
        "order": ["forearm", "shoulder", "upper_arm", "wrist_1", "wrist_2", "wrist_3"],
        "signs": [-1, 1, 1, 1, 1, -1], "offsets": [90, 0, -90, 0, 0, 180],
    }
    import yaml

    f = tmp_path / "x.yaml"
    f.write_text(yaml.safe_dump(doc, sort_keys=False))
    robot = robokin.load(f)
    tr = motion(robot)
    prog = write_controller_program(robot, tr, tmp_path / "x.waypoints.csv")
    rows = np.loadtxt(prog.path, delimiter=",", comments="#", skiprows=4)
    # controller column 0 is model joint 2 (forearm), reversed, +90 deg, in degrees
    np.testing.assert_allclose(rows[:, 1], np.degrees(-tr.q[:, 2]) + 90, atol=1e-9)
    np.testing.assert_allclose(rows[:, 2], np.degrees(tr.q[:, 0]), atol=1e-9)
    np.testing.assert_allclose(rows[:, 6], np.degrees(-tr.q[:, 5]) + 180, atol=1e-9)
    back = read_waypoints(prog.path, controller_profile(robot), robot.joint_names)
    np.testing.assert_allclose(back.q, tr.q, atol=1e-12)
    with pytest.raises(InputError, match=r"runs \['waypoints'\], not ros2"):
        controller_program(robot, tr, "ros2")


def test_default_profile_and_bad_sections(tmp_path):
    panda = robokin.load("panda")
    tr = motion(panda)
    assert controller_program(panda, tr).program == "waypoints"
    assert controller_program(panda, tr, "ros2").program == "ros2"
    with pytest.raises(InputError, match="runs"):
        controller_program(panda, tr, "urscript")
    import yaml

    doc = {k: v for k, v in panda.meta["document"].items() if k != "controller"}
    doc["controller"] = {"programs": ["urscript", "rapid"]}
    f = tmp_path / "p.yaml"
    f.write_text(yaml.safe_dump(doc))
    bad = robokin.load(f)  # the section is checked where it is used
    with pytest.raises(ModelError, match=r"p.yaml: controller.programs: programs must be"):
        controller_program(bad, tr)
    doc["controller"] = {"programs": ["urscript"]}
    f.write_text(yaml.safe_dump(doc))
    with pytest.raises(InputError, match="URScript drives six revolute joints"):
        controller_program(robokin.load(f), tr)
    with pytest.raises(InputError, match="expected a joint-space trajectory of 7"):
        controller_program(panda, motion(robokin.load("ur5")))


MOTION = """\
robot: aubo_i5
units: {length: mm, angle: deg}
dt: 0.005
start: [0, 10, 80, 0, 90, 0]
segments:
  - joint: [-40, 20, 90, -20, 90, 0]
    duration: 1.0
"""


def test_cli_traj_writes_the_profile_program_and_ros2(tmp_path, capsys):
    f = tmp_path / "m.yaml"
    f.write_text(MOTION)
    code = main(["traj", str(f), "--no-plot", "--program", str(tmp_path / "p.csv"),
                 "--ros2", str(tmp_path / "jt.yaml"), "--ros2-goal", "--ros2-stride",
                 "10"])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert "p.csv: waypoint file (CSV, every sample), controller profile 'AUBO-i5" in out
    assert "jt.yaml: ROS 2 FollowJointTrajectory goal (YAML), controller profile" in out
    from robokin.trajectory.io import read_csv
    from robokin.trajectory.ros2 import read_joint_trajectory

    aubo = robokin.load("aubo_i5")
    plan = read_csv(tmp_path / "m.csv")
    back = read_waypoints(tmp_path / "p.csv", controller_profile(aubo), aubo.joint_names)
    np.testing.assert_array_equal(back.q, plan.q)
    jt = read_joint_trajectory(tmp_path / "jt.yaml", joint_names=aubo.joint_names,
                               profile=controller_profile(aubo))
    np.testing.assert_array_equal(jt.q, plan.q[list(range(0, len(plan), 10))
                                               + ([len(plan) - 1]
                                                  if (len(plan) - 1) % 10 else [])])
    code = main(["traj", str(f), "-o", str(tmp_path / "m.csv"), "--no-plot", "--json",
                 "--program", str(tmp_path / "p.script")])
    out, err = capsys.readouterr()
    assert code == 0 and json.loads(out)["controller_files"][0].endswith(
        "waypoint file (CSV, every sample), controller profile 'AUBO-i5 (SDK waypoints; "
        "ROS aubo_driver)'")
    code = main(["traj", str(f), "-o", str(tmp_path / "m.csv"), "--no-plot",
                 "--ros2-goal"])
    _, err = capsys.readouterr()
    assert code == 2 and "needs --ros2" in err
