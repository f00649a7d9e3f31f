"""URDF import: FK against pinocchio's parser, the vendor arms against their DH
models, axes, prismatic and mimic joints, tip choice, geometry and error paths."""

import math
import os
import re
from pathlib import Path

import numpy as np
import pytest

import robokin
from robokin.exceptions import ModelError
from robokin.spatial import rotz

pytest.importorskip("yourdfpy")
from reference import pin_fk  # noqa: E402
from robokin import Robot  # noqa: E402
from robokin.io.urdf import axis_frame  # noqa: E402

DATA = Path(__file__).parent.parent / "data" / "urdf"


def random_q(robot, rng, m=20):
    lim = np.clip(robot.limits, -3.0, 3.0)
    return rng.uniform(lim[:, 0], lim[:, 1], (m, robot.n))


def test_industrial_arm_matches_pinocchio(rng):
    xml = (DATA / "industrial6.urdf").read_text()
    robot = Robot.from_urdf(DATA / "industrial6.urdf")
    assert robot.meta["urdf"].tip_link == "tool0"  # not the fixed 'base' leaf
    assert robot.joint_names == tuple(f"joint_{i}" for i in range(1, 7))
    # negative axes become reversed joints; continuous joints are unlimited
    assert [j.sign for j in robot.chain.joints] == [1, 1, -1, -1, 1, -1]
    assert np.isinf(robot.limits[5]).all()
    np.testing.assert_allclose(robot.limits[2], [-2.443, 3.316])
    q = random_q(robot, rng)
    T = robot.fk(q)
    for qi, Ti in zip(q, T):
        ref = pin_fk(xml, "tool0", dict(zip(robot.joint_names, qi)))
        np.testing.assert_allclose(Ti, ref, atol=1e-12)


def test_link_frames_are_the_urdf_child_link_frames(rng):
    xml = (DATA / "industrial6.urdf").read_text()
    robot = Robot.from_urdf(xml)  # the XML string works as well as the path
    q = random_q(robot, rng, 5)
    frames = robot.fk_all(q)
    for qi, Fi in zip(q, frames):
        vals = dict(zip(robot.joint_names, qi))
        for k, link in enumerate(robot.meta["urdf"].child_links, start=1):
            np.testing.assert_allclose(Fi[k], pin_fk(xml, link, vals), atol=1e-12)
    # a fixed link between movable joints keeps its pose on the previous link
    k, T = robot.meta["urdf"].link_frames["link_3_housing"]
    assert k == 3
    ref = pin_fk(xml, "link_3_housing", dict(zip(robot.joint_names, q[0])))
    np.testing.assert_allclose(frames[0, 3] @ T, ref, atol=1e-12)


def test_tilted_axes_prismatic_and_mimic_match_pinocchio(rng):
    text = (DATA / "tilted_prismatic.urdf").read_text()
    robot = Robot.from_urdf(DATA / "tilted_prismatic.urdf")
    assert robot.n == 4 and robot.n_chain == 5
    assert robot.joint_names == ("joint_a", "joint_b", "joint_d", "joint_e")
    assert robot.chain.joints[1].kind == "prismatic"
    np.testing.assert_allclose(robot.limits[1], [-0.1, 0.4])
    # without the mimic element joint_c is free: pinocchio evaluates it there
    free = re.sub(r"<mimic[^>]*/>", "", text)
    q = random_q(robot, rng)
    for qi, Ti in zip(q, robot.fk(q)):
        vals = dict(zip(robot.joint_names, qi))
        vals["joint_c"] = -2.0 * vals["joint_a"] + 0.1
        np.testing.assert_allclose(Ti, pin_fk(free, "tip", vals), atol=1e-12)


@pytest.mark.parametrize(
    "axis", [(0, 0, 1), (0, 0, -1), (1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -2, 0),
             (0.6, 0, 0.8), (0.3, -0.4, -0.2), (1, 1, 1e-9)]
)
def test_axis_frame_rotates_about_the_axis(axis):
    A, sign = axis_frame(axis)
    u = np.array(axis, float) / np.linalg.norm(axis)
    q = 0.7
    R = (A @ rotz(sign * q) @ A.T)[:3, :3]
    K = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
    rodrigues = np.eye(3) + math.sin(q) * K + (1 - math.cos(q)) * K @ K
    np.testing.assert_allclose(R, rodrigues, atol=1e-15)
    np.testing.assert_allclose(A[:3, :3] @ A[:3, :3].T, np.eye(3), atol=1e-15)


def test_ur5_urdf_is_the_dh_model_turned_by_pi(rng):
    urdf = Robot.from_urdf(DATA / "ur5.urdf", missing_mesh="ignore")
    dh = robokin.load("ur5")
    q = random_q(dh, rng)
    # ROS-Industrial base_link is REP-103: the controller's 'base' turned by pi
    np.testing.assert_allclose(urdf.fk(q), rotz(math.pi) @ dh.fk(q), atol=1e-12)
    # from the 'base' frame (a fixed leaf walked backwards) the two are identical
    from_base = Robot.from_urdf(DATA / "ur5.urdf", base_link="base", geometry=False)
    np.testing.assert_allclose(from_base.fk(q), dh.fk(q), atol=1e-12)
    np.testing.assert_allclose(urdf.limits[2], [-math.pi, math.pi])


def test_panda_urdf_is_the_modified_dh_model(rng):
    arm = Robot.from_urdf(DATA / "panda.urdf", tip_link="panda_link8")
    dh = robokin.load("panda")
    q = random_q(dh, rng)
    np.testing.assert_allclose(arm.fk(q), dh.fk(q), atol=1e-12)
    np.testing.assert_allclose(arm.limits, dh.limits)
    # with the hand: the known -45 deg turn and the finger offset
    hand = Robot.from_urdf(DATA / "panda.urdf", tip_link="panda_hand")
    np.testing.assert_allclose(hand.fk(q), dh.fk(q) @ rotz(-math.pi / 4), atol=1e-12)


def test_mimic_master_off_the_chain_becomes_a_coordinate(rng):
    right = Robot.from_urdf(DATA / "panda.urdf", tip_link="panda_rightfinger")
    left = Robot.from_urdf(DATA / "panda.urdf", tip_link="panda_leftfinger")
    assert right.n == 8 and right.joint_names[-1] == "panda_finger_joint1"
    assert [j.name for j in right.chain.joints][-1] == "panda_finger_joint2"
    np.testing.assert_allclose(right.limits[-1], [0.0, 0.04])
    q = random_q(right, rng)
    # the fingers open symmetrically: they sit 2 * q8 apart along the hand's y
    gap = right.fk(q)[:, :3, 3] - left.fk(q)[:, :3, 3]
    np.testing.assert_allclose(np.linalg.norm(gap, axis=-1), 2 * q[:, 7], atol=1e-12)


def test_ambiguous_tip_lists_candidates_and_explicit_tip_works(rng):
    with pytest.raises(ModelError, match=r"ambiguous tip.*left_tool.*right_tool"):
        Robot.from_urdf(DATA / "branched.urdf")
    with pytest.raises(ModelError, match=r"ambiguous tip.*panda_leftfinger"):
        Robot.from_urdf(DATA / "panda.urdf")
    left = Robot.from_urdf(DATA / "branched.urdf", tip_link="left_tool")
    assert left.joint_names == ("waist", "left_shoulder", "left_elbow")
    q = np.array([0.3, 0.4, -0.5])
    # planar check: shoulder at (0, 0.2, 0.8) in the chest, two links of 0.3/0.25
    c, s = math.cos, math.sin
    x = -0.3 * s(0.4) - 0.25 * s(0.4 - 0.5)
    z = 0.8 - 0.3 * c(0.4) - 0.25 * c(0.4 - 0.5)
    p = rotz(0.3)[:3, :3] @ np.array([x, 0.2, z])
    np.testing.assert_allclose(left.fk(q)[:3, 3], p, atol=1e-12)
    # a base below a movable joint that is not on the way to the tip
    with pytest.raises(ModelError, match="hangs below the movable joint 'left_shoulder'"):
        Robot.from_urdf(DATA / "branched.urdf", base_link="left_1", tip_link="right_tool")
    with pytest.raises(ModelError, match="unknown tip link 'nose'; links: chest"):
        Robot.from_urdf(DATA / "branched.urdf", tip_link="nose")


def test_geometry_meshes_package_map_and_missing_mesh():
    pytest.importorskip("trimesh")
    with pytest.warns(UserWarning, match=r"link 'arm' collision mesh 'meshes/not_there.stl'"):
        robot = Robot.from_urdf(DATA / "meshes_arm.urdf",
                                package_map={"meshy_description": str(DATA)})
    geo = robot.geometry
    assert geo.names == ("base", "j1", "tool")
    (base_mesh,) = geo.link("base")
    assert base_mesh.kind == "mesh" and base_mesh.scale == 0.5
    assert base_mesh.file == DATA / "meshes" / "cube.stl"
    np.testing.assert_allclose(base_mesh.placement[:3, 3], [0, 0, 0.05])
    (arm_box,) = geo.link("j1")  # collision shapes win over visual ones
    assert arm_box.kind == "box" and arm_box.size == (0.2, 0.05, 0.05)
    np.testing.assert_allclose(base_mesh.trimesh().extents, [0.05] * 3, atol=1e-12)
    with pytest.raises(ModelError, match=r"not_there.stl.*no such file"):
        Robot.from_urdf(DATA / "meshes_arm.urdf", missing_mesh="error",
                        package_map={"meshy_description": DATA})
    # the package map resolves package:// (here: the visual mesh)
    shapes = Robot.from_urdf(
        DATA / "meshes_arm.urdf", missing_mesh="ignore",
        package_map={"meshy_description": DATA},
    ).meta["urdf_shapes"]
    visual = [s for s in shapes if s["role"] == "visual"]
    assert visual[0]["filename"] == str(DATA / "meshes" / "cube.stl")
    with pytest.raises(ModelError, match="package .meshy_description. not found; searched the package map"):
        Robot.from_urdf(DATA / "meshes_arm.urdf", missing_mesh="error",
                        package_map={})
    # kinematics only: no geometry read, no warning
    assert Robot.from_urdf(DATA / "meshes_arm.urdf", geometry=False).geometry is None


@pytest.mark.parametrize(
    ("xml", "match"),
    [
        ("<robot name='r'><link name='a'/>", "line 1: not valid XML"),
        ("<robt name='r'/>", "root element must be <robot>"),
        ("<robot name='r'><link name='a'/><link name='b'/><joint name='j' type='revolute'>"
         "<parent link='a'/><child link='b'/></joint></robot>", r"joint\[j\].limit"),
        ("<robot name='r'><link name='a'/><link name='b'/><joint name='j' type='fixed'>"
         "<parent link='a'/><child link='c'/></joint></robot>",
         r"child link 'c' is not defined"),
        ("<robot name='r'><link name='a'/><link name='b'/><joint name='j' type='hinge'>"
         "<parent link='a'/><child link='b'/></joint></robot>", "type must be one of"),
        ("<robot name='r'><link name='a'/><link name='b'/></robot>", "several root links"),
        ("<robot name='r'><link name='a'/><link name='b'/><link name='c'/>"
         "<joint name='j' type='floating'><parent link='a'/><child link='b'/></joint>"
         "<joint name='k' type='continuous'><parent link='b'/><child link='c'/></joint>"
         "</robot>",
         "floating joints are not supported"),
        ("<robot name='r'><link name='a'/><link name='b'/><joint name='j' type='revolute'>"
         "<parent link='a'/><child link='b'/><axis xyz='0 0 0'/>"
         "<limit lower='0' upper='1' effort='1' velocity='1'/></joint></robot>",
         "non-zero 3-vector"),
        ("<robot name='r'><link name='a'/><link name='b'/><joint name='j' type='revolute'>"
         "<parent link='a'/><child link='b'/>"
         "<limit lower='1' upper='0' effort='1' velocity='1'/></joint></robot>",
         "lower <= upper"),
        ("<robot name='r'><link name='a'/><link name='b'/><joint name='j' type='revolute'>"
         "<parent link='a'/><child link='b'/><mimic joint='zz'/>"
         "<limit lower='0' upper='1' effort='1' velocity='1'/></joint></robot>",
         "mimics unknown joint 'zz'"),
    ],
)
def test_bad_urdf_raises_model_error(xml, match):
    with pytest.raises(ModelError, match=match):
        Robot.from_urdf(xml)


def test_malformed_file_and_missing_file_name_the_file():
    with pytest.raises(ModelError, match=r"malformed.urdf:\d+: not valid XML"):
        Robot.from_urdf(DATA / "malformed.urdf")
    with pytest.raises(ModelError, match="nope.urdf: no such file"):
        Robot.from_urdf(DATA / "nope.urdf")


def test_missing_yourdfpy_names_the_extra(monkeypatch):
    import builtins

    real = builtins.__import__

    def fake(name, *args, **kwargs):
        if name == "yourdfpy":
            raise ImportError("no yourdfpy")
        return real(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", fake)
    with pytest.raises(ImportError, match=r"robokin\[urdf\]"):
        Robot.from_urdf(DATA / "ur5.urdf")


@pytest.mark.parametrize(
    ("joint_xml", "message"),
    [
        ('<axis xyz="0 0 x"/>', r"arm\.urdf:1: joint\[j\]\.axis\.xyz.*3 numbers"),
        ('<origin xyz="1 2"/>', r"joint\[j\]\.origin\.xyz.*3 numbers"),
        ('<axis xyz="0 0 0"/>', r"arm\.urdf: joint\[j\]\.axis: .*non-zero"),
    ],
)
def test_malformed_numbers_name_the_file_joint_and_attribute(
    tmp_path, joint_xml, message
):
    path = tmp_path / "arm.urdf"
    path.write_text(
        '<robot name="r"><link name="a"/><link name="b"/>'
        '<joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
        f'{joint_xml}<limit lower="0" upper="1"/></joint></robot>'
    )
    with pytest.raises(robokin.ModelError, match=message):
        robokin.Robot.from_urdf(path)


def test_a_non_numeric_limit_names_the_attribute(tmp_path):
    path = tmp_path / "arm.urdf"
    path.write_text(
        '<robot name="r"><link name="a"/><link name="b"/>'
        '<joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
        '<limit lower="zero" upper="1"/></joint></robot>'
    )
    with pytest.raises(robokin.ModelError, match=r"joint\[j\]\.limit\.lower"):
        robokin.Robot.from_urdf(path)


# ------------------------------------------------------ issue 15: hostile URDFs
ARM = ('<robot name="r"><link name="a"/><link name="b">{link}</link>'
       '<joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
       '{joint}<limit lower="0" upper="1"/></joint></robot>')


@pytest.mark.parametrize("dtd", [
    # the XML billion laughs: entities of entities
    '<!DOCTYPE robot [<!ENTITY a "lol"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;">'
    '<!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;">]>',
    # an external entity: a local file, and one on the network
    '<!DOCTYPE robot [<!ENTITY x SYSTEM "file:///etc/passwd">]>',
    '<!DOCTYPE robot [<!ENTITY x SYSTEM "http://127.0.0.1:9/robot.dtd">]>',
    '<!DOCTYPE robot SYSTEM "http://127.0.0.1:9/robot.dtd">',
])
def test_dtds_and_entities_are_refused(tmp_path, dtd):
    path = tmp_path / "evil.urdf"
    path.write_text('<?xml version="1.0"?>' + dtd
                    + ARM.format(link="", joint='<origin xyz="0 0 0"/>')
                    .replace('name="r"', 'name="&c;"' if "&b;" in dtd else 'name="r"'))
    with pytest.raises(ModelError, match=r"evil\.urdf:1: a <!DOCTYPE>"):
        Robot.from_urdf(path)


@pytest.mark.parametrize(("link", "joint", "message"), [
    ("", '<origin xyz="0 nan 0"/>',
     r"arm\.urdf:1: joint\[j\]\.origin\.xyz: .*finite"),
    ("", '<origin rpy="0 0 inf"/>', r"joint\[j\]\.origin\.rpy: .*finite"),
    ("", '<axis xyz="0 0 NaN"/>', r"joint\[j\]\.axis\.xyz: .*finite"),
    ('<collision><geometry><box size="1 -2 1"/></geometry></collision>', "",
     r"arm\.urdf:1: link\[b\]\.box\.size: .*positive"),
    ('<visual><geometry><cylinder radius="0.1"/></geometry></visual>', "",
     r"link\[b\]\.cylinder\.length: <cylinder> needs a 'length'"),
    ('<visual><geometry><sphere radius="nan"/></geometry></visual>', "",
     r"link\[b\]\.sphere\.radius"),
])
def test_non_finite_origins_and_bad_shapes_name_file_element_and_line(
        tmp_path, link, joint, message):
    path = tmp_path / "arm.urdf"
    path.write_text(ARM.format(link=link, joint=joint))
    with pytest.raises(ModelError, match=message):
        Robot.from_urdf(path)


def test_lines_are_those_of_the_element(tmp_path):
    path = tmp_path / "arm.urdf"
    path.write_text(ARM.format(link="", joint='\n\n<origin xyz="1 2 x"/>')
                    .replace("><", ">\n<"))
    with pytest.raises(ModelError) as exc:
        Robot.from_urdf(path)
    line = exc.value.line
    assert 'xyz="1 2 x"' in path.read_text().splitlines()[line - 1]


def test_every_left_out_shape_is_listed_and_no_non_mesh_path_is_kept(tmp_path):
    (tmp_path / "notes.txt").write_text("not a mesh")
    (tmp_path / "folder.stl").mkdir()
    shapes = "".join(
        f'<collision><geometry><mesh filename="{f}"/></geometry></collision>'
        for f in ("gone.stl", "http://example.com/arm.stl", "notes.txt",
                  "package://nopkg/arm.stl", "folder.stl"))
    path = tmp_path / "arm.urdf"
    path.write_text(ARM.format(link=shapes + '<collision><geometry><box size="1 1 1"/>'
                                             '</geometry></collision>', joint=""))
    robot = Robot.from_urdf(path, missing_mesh="ignore")
    dropped = robot.meta["urdf_dropped_shapes"]
    assert len(dropped) == 5
    for word in ("no such file", "remote mesh (http://)", "not a mesh file",
                 "package 'nopkg'", "folder.stl"):
        assert any(word in d for d in dropped), word
    kinds = [s.kind for ss in robot.geometry.shapes for s in ss]
    assert kinds == ["box"]
    with pytest.warns(UserWarning) as record:
        Robot.from_urdf(path)
    assert len(record) == 5
    with pytest.raises(ModelError, match="gone.stl"):
        Robot.from_urdf(path, missing_mesh="error")


def _chain_urdf(n: int) -> str:
    parts = ['<robot name="r">'] + [f'<link name="l{i}"/>' for i in range(n + 1)]
    parts += [f'<joint name="j{i}" type="continuous"><parent link="l{i}"/>'
              f'<child link="l{i + 1}"/><origin xyz="0 0 0.01"/></joint>'
              for i in range(n)]
    return "\n".join(parts) + "</robot>"


def test_a_urdf_of_thousands_of_joints_is_refused_before_it_is_built(tmp_path):
    from robokin.io.urdf import MAX_URDF_JOINTS
    from robokin.model.chain_arrays import MAX_JOINTS

    path = tmp_path / "long.urdf"
    path.write_text(_chain_urdf(MAX_URDF_JOINTS + 1))
    with pytest.raises(ModelError, match=r"long\.urdf:1: 1,001 <joint> elements; "
                                         r"robokin reads at most 1,000"):
        Robot.from_urdf(path)
    path.write_text(_chain_urdf(MAX_URDF_JOINTS))  # at the cap: read, but a serial
    with pytest.raises(ModelError, match="1000 joints.*at most 32"):  # chain that long
        Robot.from_urdf(path, geometry=False)  # is more than the kernels take
    path.write_text(_chain_urdf(MAX_JOINTS))
    robot = Robot.from_urdf(path, geometry=False)
    assert robot.n == MAX_JOINTS
    assert robot.fk(np.zeros(robot.n))[2, 3] == pytest.approx(10.0 * MAX_JOINTS / 1000)


# ------------------------------------------------------ issue 25: hostile URDFs
@pytest.mark.parametrize(("link", "joint", "message"), [
    # a length beyond MAX_TRANSLATION (1e6 m) made a robot file load refused
    ("", '<origin xyz="1e308 0 0"/>',
     r"arm\.urdf:1: joint\[j\]\.origin\.xyz: <origin xyz='1e308 0 0'>: a length beyond "
     r"the 1e\+06 m robokin accepts"),
    ('<collision><origin xyz="0 -2e6 0"/><geometry><box size="1 1 1"/></geometry>'
     '</collision>', "", r"link\[b\]\.origin\.xyz: .*a length beyond"),
    ('<visual><geometry><sphere radius="1e7"/></geometry></visual>', "",
     r"link\[b\]\.sphere\.radius: .*a length beyond"),
    ('<inertial><mass value="nan"/></inertial>', "", r"link\[b\]\.mass\.value: .*finite"),
])
def test_absurd_lengths_are_refused_at_import_naming_the_field(tmp_path, link, joint,
                                                               message):
    path = tmp_path / "arm.urdf"
    path.write_text(ARM.format(link=link, joint=joint))
    with pytest.raises(ModelError, match=message):
        Robot.from_urdf(path)


def test_a_prismatic_limit_is_a_length_a_revolute_one_an_angle(tmp_path):
    path = tmp_path / "arm.urdf"
    text = ARM.format(link="", joint="").replace('lower="0" upper="1"',
                                                 'lower="-1e7" upper="1"')
    path.write_text(text.replace('type="revolute"', 'type="prismatic"'))
    with pytest.raises(ModelError, match=r"joint\[j\]\.limit\.lower: .*a length beyond"):
        Robot.from_urdf(path)
    path.write_text(text)
    assert Robot.from_urdf(path).limits[0, 0] == -1e7  # radians: not a length


def test_cli_import_of_a_1e308_origin_writes_nothing(tmp_path, capsys):
    from robokin.cli import main

    urdf = tmp_path / "arm.urdf"
    urdf.write_text(ARM.format(link="", joint='<origin xyz="1e308 0 0"/>'))
    out = tmp_path / "arm.yaml"
    code = main(["import", str(urdf), "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and not out.exists()
    assert f"{urdf}:1: joint[j].origin.xyz" in err


def test_save_refuses_a_robot_file_that_would_not_load_back(tmp_path, capsys):
    """The safety net under every writer: a 300-character URDF joint name imports,
    but a robot file holds names of at most 200 characters."""
    from robokin.cli import main

    urdf = tmp_path / "arm.urdf"
    urdf.write_text(ARM.format(link="", joint="").replace('name="j"', f'name="{"j" * 300}"'))
    out = tmp_path / "arm.yaml"
    code = main(["import", str(urdf), "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and not out.exists()
    assert "String should have at most 200 characters" in err
    assert "robokin would refuse this robot file, so it is not written" in err


def _mesh_urdf(tmp_path: Path, filename: str) -> Path:
    path = tmp_path / "desc" / "arm.urdf"
    path.parent.mkdir(exist_ok=True)
    path.write_text(ARM.format(
        link=f'<collision><geometry><mesh filename="{filename}"/></geometry></collision>'
             '<collision><geometry><box size="1 1 1"/></geometry></collision>',
        joint=""))
    return path


@pytest.mark.parametrize("uri", [
    "package://pkg/../../secret.stl",      # climbs out of the package
    "package://pkg/meshes/../../secret.stl",
    "package://pkg//abs/secret.stl",       # an absolute path after the package
])
def test_package_uris_that_leave_the_package_are_not_read(tmp_path, uri):
    """Issue 25: they resolved outside the package root with no note."""
    pkg = tmp_path / "pkg"
    (pkg / "meshes").mkdir(parents=True)
    (tmp_path / "secret.stl").write_bytes((DATA / "meshes" / "cube.stl").read_bytes())
    path = _mesh_urdf(tmp_path, uri)
    robot = Robot.from_urdf(path, package_map={"pkg": pkg}, missing_mesh="ignore")
    (dropped,) = robot.meta["urdf_dropped_shapes"]
    assert f"the path leaves the package 'pkg' (its folder {pkg}" in dropped
    assert "not read" in dropped
    assert [s.kind for ss in robot.geometry.shapes for s in ss] == ["box"]
    with pytest.raises(ModelError, match="leaves the package"):
        Robot.from_urdf(path, package_map={"pkg": pkg}, missing_mesh="error")
    # inside the package, '..' that stays inside is fine
    (pkg / "meshes" / "ok.stl").write_bytes((DATA / "meshes" / "cube.stl").read_bytes())
    fine = Robot.from_urdf(_mesh_urdf(tmp_path, "package://pkg/meshes/../meshes/ok.stl"),
                           package_map={"pkg": pkg}, missing_mesh="error")
    assert fine.meta["urdf_dropped_shapes"] == ()


@pytest.mark.parametrize("kind", ["fifo", "dev_zero_link", "dev_zero_uri", "folder"])
def test_a_mesh_that_is_not_a_regular_file_is_never_read(tmp_path, kind):
    """Issue 25: /dev/zero, a FIFO or a symlink to one was 'no such file' (and a FIFO
    opened for reading blocks forever, /dev/zero never ends)."""
    target = tmp_path / "desc" / "m.stl"
    target.parent.mkdir()
    uri = "m.stl"
    if kind == "fifo":
        os.mkfifo(target)
        what = "a FIFO (named pipe)"
    elif kind == "dev_zero_link":
        target.symlink_to("/dev/zero")
        what = "a character device (through a symlink)"
    elif kind == "dev_zero_uri":
        (tmp_path / "desc" / "zero.stl").symlink_to("/dev/zero")
        uri = f"file://{tmp_path / 'desc' / 'zero.stl'}"
        what = "a character device"
    else:
        target.mkdir()
        what = "a folder"
    path = _mesh_urdf(tmp_path, uri)
    with pytest.raises(ModelError, match=r"is not a regular file: " + re.escape(what)):
        Robot.from_urdf(path, missing_mesh="error")
