"""MJCF export (issue 17, item 1): MuJoCo's FK of the exported model is robokin's.

MuJoCo itself compiles the text; 1,000 random configurations of every built-in arm
put every link frame and the ``tool`` site where ``robot.fk_all`` / ``robot.fk``
put them, to 1e-9 m (and 1e-9 in the rotation matrices).
"""

from __future__ import annotations

import numpy as np
import pytest

import robokin
from robokin.model.geometry import link_names

mujoco = pytest.importorskip("mujoco")

from robokin import sim  # noqa: E402
from robokin.sim._mujoco import load_model  # noqa: E402


def _random_q(robot, rng, m):
    lo, hi = robot.limits.T
    lo = np.where(np.isfinite(lo), lo, -np.pi)
    hi = np.where(np.isfinite(hi), hi, np.pi)
    return rng.uniform(lo, hi, size=(m, robot.n))


def assert_fk_equal(robot, export, Q):
    model = load_model(export.xml)
    data = mujoco.MjData(model)
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "tool")
    bodies = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, n)
              for n in link_names(robot)[:-1]]
    assert min(bodies) >= 0
    frames, tool = robot.fk_all(Q), robot.fk(Q)
    worst_p = worst_r = 0.0
    for k, q in enumerate(Q):
        data.qpos[:] = export.joints.qpos(model, q)
        mujoco.mj_kinematics(model, data)
        worst_p = max(worst_p, np.abs(data.site_xpos[site] - tool[k, :3, 3]).max(),
                      np.abs(data.xpos[bodies] - frames[k, :, :3, 3]).max())
        worst_r = max(worst_r,
                      np.abs(data.site_xmat[site].reshape(3, 3) - tool[k, :3, :3]).max(),
                      np.abs(data.xmat[bodies].reshape(-1, 3, 3)
                             - frames[k, :, :3, :3]).max())
    assert worst_p < 1e-9, worst_p
    assert worst_r < 1e-9, worst_r


@pytest.mark.parametrize("name", robokin.robots.names())
def test_mjcf_fk_equals_robokin_fk_on_every_builtin_arm(name):
    robot = robokin.load(name)
    export = sim.build_mjcf(robot)
    Q = _random_q(robot, np.random.default_rng(17), 1000)
    assert_fk_equal(robot, export, Q)
    # joints named as robot.joint_names, a site "tool"
    model = load_model(export.xml)
    for j in robot.joint_names:
        assert mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j) >= 0


def test_mjcf_keeps_the_coupling_of_dependent_joints():
    # the QFMD010's forearm = theta3 - theta2 (a tendon equality: two coordinates)
    # and its level joint is theta3's own (coefficient -1): one joint per chain joint
    robot = robokin.load("qfmd010")
    export = sim.build_mjcf(robot)
    assert "<equality>" in export.xml
    model = load_model(export.xml)
    assert model.neq == 1 and model.njnt == 5
    assert set(export.joints.masters) == set(robot.joint_names)


def test_mjcf_in_a_scene_places_the_robot_and_its_tool():
    from robokin import collision

    scene = collision.Scene.load(collision.scene_path("press"))
    robot = robokin.load("aubo_i5")
    export = sim.build_mjcf(robot, scene)
    placed = scene.attach(robot)
    Q = _random_q(placed, np.random.default_rng(3), 50)
    assert_fk_equal(placed, export, Q)
    model = load_model(export.xml)
    for obj in scene.names:
        assert mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, obj) >= 0


def test_mjcf_motor_actuators_act_through_the_actuator_map():
    robot = robokin.load("scara")
    export = sim.build_mjcf(robot, actuators="motor")
    model = load_model(export.xml)
    assert model.nu == 4 and model.ntendon == 4
    assert export.actuator_names == robot.actuator_names
    with pytest.raises(robokin.InputError, match="actuators"):
        sim.build_mjcf(robokin.load("ur5"), actuators="motor")


def test_mjcf_joint_limits_and_torque_limits():
    robot = robokin.load("scara")
    export = sim.build_mjcf(robot, torque_limits=[50.0, 40.0, 10.0, 500.0])
    model = load_model(export.xml)
    j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "lift")
    np.testing.assert_allclose(model.jnt_range[j], [0.0, 0.2])
    np.testing.assert_allclose(model.jnt_actfrcrange[j], [-500.0, 500.0])
    with pytest.raises(robokin.InputError, match="torque_limits"):
        sim.build_mjcf(robot, torque_limits=[50.0, 40.0, 10.0])


def test_mjcf_coordinate_without_a_joint_of_its_own():
    # q2 moves one chain joint at half rate: no MuJoCo joint can carry q2 itself,
    # so it gets a joint on a light leaf body, tied to the chain joint
    robot = robokin.Robot.from_elementary(
        [{"op": "rz", "joint": "revolute", "name": "q1"}, {"op": "tx", "value": 0.3},
         {"op": "rz", "joint": "revolute", "name": "b", "depends": {"q2": 0.5}},
         {"op": "tx", "value": 0.2}],
        coordinates=[{"name": "q1", "joint": "revolute", "limits": [-3, 3]},
                     {"name": "q2", "joint": "revolute", "limits": [-3, 3]}])
    export = sim.build_mjcf(robot)
    assert any("leaf" in n for n in export.notes)
    assert_fk_equal(robot, export, _random_q(robot, np.random.default_rng(5), 200))


def test_mjcf_meshes_go_in_as_their_convex_hulls_and_touch_the_scene(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    from robokin import collision, trajectory
    from robokin.model.geometry import RobotGeometry, mesh

    stl = tmp_path / "blob.stl"
    trimesh.creation.icosphere(subdivisions=1, radius=0.05).export(stl)
    robot = robokin.load("scara")
    robot = robot.replace(geometry=RobotGeometry.from_mapping(
        robot, {"elbow": [mesh(stl, np.eye(4))]}))
    scene = collision.Scene("post")
    pose = np.eye(4)
    pose[:3, 3] = [0.0, 0.6, 0.4]  # on the circle the elbow sweeps
    scene.add_box("post", (0.1, 0.1, 0.8), pose)
    export = sim.build_mjcf(robot, scene)
    assert '<mesh name="mesh_elbow/0"' in export.xml
    plan = trajectory.quintic(np.array([0.0, 0.0, 0.0, 0.1]),
                              np.array([1.6, 0.0, 0.0, 0.1]), 1.0, dt=0.005)
    rep = collision.check(robot, scene, plan)
    res = sim.simulate(robot, plan, scene)
    assert [(iv.body_a, iv.body_b) for iv in rep.intervals] == \
        [(c.body_a, c.body_b) for c in res.contacts] == [("elbow", "post")]
    assert abs(rep.intervals[0].t_start - res.contacts[0].t_start) <= 0.005 + 1e-9


def test_mujoco_warnings_become_python_warnings_not_a_log_file(tmp_path, monkeypatch):
    # MuJoCo's default handler appends warnings to MUJOCO_LOG.TXT in the working
    # directory; robokin routes them to Python's warnings instead
    import warnings

    from robokin.sim._mujoco import mujoco

    monkeypatch.chdir(tmp_path)
    mj = mujoco()
    model = mj.MjModel.from_xml_string(
        '<mujoco><worldbody><body><joint type="hinge"/><geom size=".1"/></body>'
        "</worldbody></mujoco>")
    data = mj.MjData(model)
    data.qvel[0] = float("nan")  # MuJoCo warns and resets the state
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mj.mj_step(model, data)
    assert any("MuJoCo:" in str(w.message) for w in caught)
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()


# ------------------------------------------ issue 25: mass properties no body has
@pytest.mark.parametrize(("mass", "moments", "field", "match"), [
    (1e300, (1.0, 1.0, 1.0), "mass", r"a mass of 1e\+300 kg, more than the 100000 kg"),
    (3.0, (1e300, 1e300, 1e300), "inertia", r"a principal moment of 1e\+300 kg m\^2"),
    # [1, 1, 5]: C = 2.5 (A + B), no rigid body (A + B >= C for every mass layout)
    (3.0, (1.0, 1.0, 5.0), "inertia",
     r"principal moments \[1.0, 1.0, 5.0\] kg m\^2 break the triangle inequality "
     r"A \+ B >= C \(by 150%"),
])
def test_mjcf_export_refuses_mass_properties_no_body_has(tmp_path, mass, moments,
                                                         field, match):
    import yaml

    doc = yaml.safe_load(robokin.robots.path("ur5").read_text())
    doc["dynamics"]["links"]["elbow"] = {"mass": mass, "inertia": [*moments, 0, 0, 0]}
    f = tmp_path / "ur5.yaml"
    f.write_text(yaml.safe_dump(doc, sort_keys=False))
    robot = robokin.load(f)  # kinematics still load: only physics needs them
    with pytest.raises(robokin.ModelError, match=rf"ur5.yaml: dynamics.links.elbow."
                                                 rf"{field}: {match}"):
        sim.to_mjcf(robot)
    from robokin.cli import main

    assert main(["export", str(f), "-o", str(tmp_path / "ur5.xml")]) == 2
    assert not (tmp_path / "ur5.xml").exists()


def test_mjcf_export_balances_a_rounded_tensor_with_a_note():
    """Within 25 % (the Puma 560's elbow: 0.086 > 0.0125 + 0.066 by 9.6 %), the two
    smaller moments grow by half the shortfall each and the export says so."""
    export = sim.build_mjcf(robokin.load("puma560"))
    (note,) = [n for n in export.notes if n.startswith("link 'elbow'")]
    assert "violate A + B >= C" in note
    model = load_model(export.xml)
    body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "elbow")
    A, B, C = np.sort(model.body_inertia[body])
    assert A + B >= C * (1 - 1e-9)
    assert pytest.approx(0.086) == C
