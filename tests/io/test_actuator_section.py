"""The robot-file ``actuators:`` section and the ``robokin motors`` / ``robokin joints``
commands (issue 5)."""

import json
import math
import textwrap

import numpy as np
import pytest

import robokin
from robokin.exceptions import ModelError

HEAD = textwrap.dedent("""\
    name: cart
    units: {length: mm, angle: deg}
    convention: standard
    joints:
      - {name: turn, joint: revolute, a: 300, limits: [-170, 170]}
      - {name: wrist, joint: revolute, a: 100}
      - {name: z, joint: prismatic, d: 0, limits: [0, 400]}
    """)


def _write(tmp_path, section: str, head: str = HEAD):
    p = tmp_path / "cart.yaml"
    p.write_text(head + textwrap.dedent(section))
    return p


def test_matrix_section_in_file_units(tmp_path):
    p = _write(tmp_path, """\
        actuators:
          names: [m_turn, m_wrist, m_z]
          kinds: [rotary, rotary, linear]
          limits: [[-3600, 3600], [-7200, 7200], [-10, 410]]
          matrix: [[0.01, 0, 0], [0.01, 0.02, 0], [0, 0, 1]]
          offset: [5, 0, 2]
        """)
    r = robokin.load(p)
    assert r.actuator_names == ("m_turn", "m_wrist", "m_z")
    # q [deg, mm] = A phi [deg, deg, mm] + b, checked in SI
    phi_file = np.array([1000.0, -500.0, 25.0])
    q_file = np.array([[0.01, 0, 0], [0.01, 0.02, 0], [0, 0, 1]]) @ phi_file + [5, 0, 2]
    phi_si = np.array([math.radians(1000), math.radians(-500), 0.025])
    q_si = r.joints_from_actuators(phi_si)
    np.testing.assert_allclose(q_si, [math.radians(q_file[0]), math.radians(q_file[1]),
                                      q_file[2] / 1000], atol=1e-15)
    np.testing.assert_allclose(r.actuators_from_joints(q_si), phi_si, atol=1e-12)
    np.testing.assert_allclose(r.actuator_limits,
                               [[-20 * np.pi, 20 * np.pi], [-40 * np.pi, 40 * np.pi],
                                [-0.010, 0.410]], atol=1e-15)


def test_drives_section_gear_and_screw(tmp_path):
    p = _write(tmp_path, """\
        actuators:
          drives:
            - {type: gear, joint: turn, ratio: 100, offset: 10}
            - {type: direct, joints: [wrist]}
            - {type: screw, joint: z, lead: 5, ratio: 2}
        """)
    r = robokin.load(p)
    assert r.actuator_names == ("motor1", "motor2", "motor3")
    assert r.meta["actuator_kinds"] == ("rotary", "rotary", "rotary")
    # 100 motor turns -> one joint turn (+10 deg); 2 motor turns -> one 5 mm screw turn
    q = r.joints_from_actuators([2 * np.pi * 50, 0.3, 2 * np.pi * 2])
    np.testing.assert_allclose(q, [np.pi + math.radians(10), 0.3, 0.005], atol=1e-14)


def test_scara_file_section_matches_the_named_constructor():
    from robokin.model.coupling import actuator_map, ball_screw_spline, direct

    r = robokin.load("scara")
    built = actuator_map(r.joint_names, [(["shoulder", "elbow"], direct(2)),
                                         (["rotate", "lift"], ball_screw_spline(0.020, 1, 15))])
    assert built.allclose(r.actuators, atol=1e-15)


@pytest.mark.parametrize(
    ("section", "field", "reason"),
    [
        ("actuators:\n  matrix: [[1, 1, 0], [1, 1, 0], [0, 0, 1]]\n",
         "actuators.matrix", r"rank 2 < 3 motors: it cannot be inverted"),
        ("actuators:\n  matrix: [[1, 0], [0, 0], [0, 0]]\n",
         "actuators.matrix", r"rank 1 < 2 motors"),
        ("actuators:\n  matrix: [[1, 0, 0], [0, 1, 0]]\n",
         "actuators.matrix", r"expected 3 rows"),
        ("actuators:\n  matrix: [[1, 0, 0], [0, 1], [0, 0, 1]]\n",
         r"actuators.matrix\[1\]", r"row 1 has 2 entries"),
        ("actuators:\n  matrix: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\n  offset: [1]\n",
         "actuators.offset", "expected 3 entries"),
        ("actuators:\n  matrix: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\n  names: [a, b]\n",
         "actuators.names", "expected 3 names"),
        ("actuators:\n  matrix: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\n  limits: [[1, 0], [0, 1], [0, 1]]\n",
         r"actuators.limits\[0\]", "limits reversed"),
        ("actuators:\n  drives:\n    - {type: direct, joints: [turn, wrist]}\n",
         "actuators.drives", r"\['z'\] are driven by no actuator"),
        ("actuators:\n  drives:\n    - {type: direct, joints: [turn, wrist, zz]}\n",
         r"actuators.drives\[0\].joints", "unknown joint 'zz'"),
        ("actuators:\n  drives:\n    - {type: gear, joint: z, ratio: 3}\n",
         r"actuators.drives\[0\].joint", "a gear drives a revolute joint"),
        ("actuators:\n  drives:\n    - {type: ball_screw_spline, joints: [turn, wrist], lead: 20}\n",
         r"actuators.drives\[0\].joints", "a revolute then a prismatic joint"),
        ("actuators:\n  drives:\n    - {type: gear, joint: turn, ratio: 0}\n",
         r"actuators.drives\[0\]", "ratio must not be zero"),
        ("actuators:\n  drives:\n    - {type: belt, joint: turn}\n",
         r"actuators.drives\[0\]", "does not match any of the expected tags|tag"),
        ("actuators:\n  drives:\n    - {type: gear, joint: turn, ratio: 2, speed: 3}\n",
         r"actuators.drives\[0\].speed", "unknown key; accepted: type, joint, ratio, offset"),
        ("actuators: [1, 2]\n", "actuators", "must be a mapping"),
        ("actuators: {}\n", "actuators", "either 'matrix'"),
    ],
)
def test_bad_actuator_sections_name_the_file_and_field(tmp_path, section, field, reason):
    p = _write(tmp_path, section)
    with pytest.raises(ModelError, match=reason) as info:
        robokin.load(p)
    err = info.value
    assert err.file == str(p)
    assert str(p) in str(err)
    assert err.field is not None and __import__("re").fullmatch(field, err.field), err.field


def test_section_from_robot_round_trips_through_a_file(tmp_path):
    import yaml

    from robokin.io.actuator_section import section_from_robot

    r = robokin.load("scara")
    sec = section_from_robot(r)
    doc = {"name": "s2", "units": {"length": "m", "angle": "rad"},
           "joints": [{"name": "shoulder", "d": 0.4, "a": 0.325},
                      {"name": "elbow", "a": 0.275},
                      {"name": "rotate"},
                      {"name": "lift", "joint": "prismatic", "d": -0.15}],
           "actuators": sec}
    p = tmp_path / "s2.yaml"
    p.write_text(yaml.safe_dump(doc))
    r2 = robokin.load(p)
    assert r2.actuators.allclose(r.actuators, atol=1e-15)
    assert section_from_robot(robokin.load("ur5")) is None


# ------------------------------------------------------------------------------ CLI
def _cli(capsys, *args):
    from robokin.cli import main

    code = main(list(args))
    out = capsys.readouterr()
    return code, out.out, out.err


def test_cli_motors_gives_the_papers_motor_angles(capsys):
    # t = 2 s of the paper's first motion: theta3 = 72 deg, l4 = 4 mm
    code, out, _ = _cli(capsys, "motors", "scara", "10", "-20", "72", "4",
                        "--deg", "--mm", "--json")
    assert code == 0
    res = json.loads(out)
    np.testing.assert_allclose(res["phi"], [10, -20, 72 - 18 * 4, 540 * 2], atol=1e-9)
    assert res["names"] == ["motor1", "motor2", "motor3", "motor4"]
    assert res["units"] == ["deg"] * 4


def test_cli_joints_inverts_motors(capsys):
    code, out, _ = _cli(capsys, "joints", "scara", "0", "0", "-144", "540", "--deg", "--mm",
                        "--json")
    assert code == 0
    res = json.loads(out)
    # the paper's third motion at t = 1 s: theta3 = 36 deg, l4 = 10 mm
    np.testing.assert_allclose(res["q"], [0, 0, 36, 10], atol=1e-9)
    assert res["units"] == ["deg", "deg", "deg", "mm"]
    code, out, _ = _cli(capsys, "joints", "scara", "0", "0", "0", "0.5")
    assert code == 0 and "lift" in out and "rotate" in out


def test_cli_usage_errors(capsys):
    code, _, err = _cli(capsys, "motors", "scara", "1", "2")
    assert code == 2 and "scara has 4 joints, got 2 values" in err
    code, _, err = _cli(capsys, "joints", "scara", "1")
    assert code == 2 and "scara has 4 motors, got 1 values" in err
