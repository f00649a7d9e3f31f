"""MoveIt planning scenes in (issue 26): the ``.scene`` text (both versions of
MoveIt's format) and ``moveit_msgs/PlanningScene`` YAML (ROS 2 echo and robowflex
forms), read into shapes placed in the planning frame. Oracle: poses written out by
hand from the hand-written files (quaternions turned into matrices by hand)."""

import math
from pathlib import Path

import numpy as np
import pytest

from robokin.exceptions import ModelError
from robokin.io import moveit_scene as ms
from robokin.io.moveit_scene import read_scene_text
from robokin.io.moveit_scene_yaml import planning_scene_from_document
from robokin.io.yaml_reader import read_yaml

DATA = Path(__file__).parent.parent / "data" / "moveit"
S = math.sqrt(0.5)


def pose(xyz, R=None):
    T = np.eye(4)
    T[:3, 3] = xyz
    if R is not None:
        T[:3, :3] = R
    return T


RZ90 = np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])
RY90 = np.array([[0.0, 0, 1], [0, 1, 0], [-1, 0, 0]])
RZ180 = np.diag([-1.0, -1, 1])


def shapes_of(scene):
    return {o.id: o.shapes for o in scene.objects}


def test_scene_text_new_format_shapes_and_poses():
    scene = read_scene_text((DATA / "cell.scene").read_text(), DATA / "cell.scene")
    assert scene.name == "press cell"
    assert [o.id for o in scene.objects] == ["table", "post with lamp", "wedge"]
    assert [o.line for o in scene.objects] == [2, 12, 35]
    (table,) = shapes_of(scene)["table"]
    assert table.kind == "box" and table.size == (0.8, 1.2, 0.04)
    np.testing.assert_allclose(table.placement, pose([0.6, 0, 0.3], RZ90), atol=1e-6)
    cyl, ball, cone = shapes_of(scene)["post with lamp"]
    assert (cyl.kind, cyl.size) == ("cylinder", (0.05, 0.6))
    np.testing.assert_allclose(cyl.placement, pose([0.5, -0.4, 0.3]), atol=1e-12)
    assert (ball.kind, ball.size) == ("sphere", (0.08,))
    np.testing.assert_allclose(ball.placement, pose([0.5, -0.4, 0.68]), atol=1e-12)
    # a cone is a mesh containing it: tip at +length/2 along its z (here world +x)
    assert cone.kind == "mesh" and cone.vertices is not None
    np.testing.assert_allclose(cone.placement, pose([0.6, -0.4, 0.5], RY90), atol=1e-6)
    world = cone.vertices @ cone.placement[:3, :3].T + cone.placement[:3, 3]
    np.testing.assert_allclose(world.max(axis=0)[0], 0.7, atol=1e-6)  # the tip
    ring = np.linalg.norm(cone.vertices[:-2, :2], axis=1)
    np.testing.assert_allclose(ring, 0.1 / math.cos(math.pi / 32), rtol=1e-12)
    assert cone.trimesh().is_watertight
    (wedge,) = shapes_of(scene)["wedge"]
    assert wedge.kind == "mesh" and wedge.faces.tolist()[0] == [0, 2, 1]
    np.testing.assert_allclose(wedge.placement, pose([-0.2, 0.5, 0.1]), atol=1e-12)
    np.testing.assert_allclose(wedge.trimesh().volume, 0.1**3 / 6, rtol=1e-12)


def test_scene_text_old_format_has_world_shape_poses():
    scene = read_scene_text((DATA / "cell_old.scene").read_text())
    (table,) = shapes_of(scene)["table"]
    np.testing.assert_allclose(table.placement, pose([0.6, 0, 0.3], RZ90), atol=1e-6)
    (ball,) = shapes_of(scene)["ball"]
    np.testing.assert_allclose(ball.placement, pose([0.3, 0.2, 0.9]), atol=1e-12)


def test_planning_scene_yaml_frames_shapes_acm_and_state():
    path = DATA / "planning_scene.yaml"
    scene = planning_scene_from_document(read_yaml(path), path)
    assert scene.frame == "world" and scene.name == "press cell"
    assert scene.joint_state == {"joint_1": 0.1, "joint_2": -0.2, "joint_3": 0.3}
    (table,) = shapes_of(scene)["table"]
    np.testing.assert_allclose(table.placement, pose([0.6, 0, 0.3], RZ90), atol=1e-7)
    cyl, ball, cone, mesh = shapes_of(scene)["fixture"]
    fixture = pose([0.5, 0, 0.2], RZ180)  # fixed_frame_transforms: half a turn about z
    # CYLINDER dimensions are [height, radius]; w = 2 is normalised
    assert (cyl.kind, cyl.size) == ("cylinder", (0.05, 0.4))
    np.testing.assert_allclose(cyl.placement, fixture @ pose([0.1, 0, 0.2]), atol=1e-12)
    np.testing.assert_allclose(ball.placement[:3, 3], [0.4, 0, 0.65], atol=1e-12)
    assert cone.kind == "mesh"  # CONE [height 0.2, radius 0.1], no pose: the identity
    np.testing.assert_allclose(np.ptp(cone.vertices, axis=0)[2], 0.2, atol=1e-12)
    np.testing.assert_allclose(cone.placement, fixture, atol=1e-12)
    np.testing.assert_allclose(mesh.placement, fixture @ pose([-0.3, 0, 0]), atol=1e-12)
    acm = scene.allowed
    assert acm.allows("base_link", "link_1") and acm.allows("table", "base_link")
    assert not acm.allows("link_1", "table") and not acm.allows("fixture", "base_link")
    assert acm.allows("camera", "anything")  # a default entry
    assert not acm.allows("nobody", "else")


def test_robowflex_form_with_append_and_remove():
    path = DATA / "robowflex_scene.yaml"
    scene = planning_scene_from_document(read_yaml(path), path)
    assert [o.id for o in scene.objects] == ["Box"]  # Can removed
    box, ball = shapes_of(scene)["Box"]  # the sphere appended
    assert box.size == (0.2, 0.3, 0.4) and ball.size == (0.05,)
    np.testing.assert_allclose(box.placement, pose([0.5, 0.1, 0.2]), atol=1e-12)
    assert scene.allowed.allows("link_3", "Box")


# ------------------------------------------------------------------ hostile input
GOOD = (DATA / "cell.scene").read_text()


@pytest.mark.parametrize("old, new, line, match", [
    ("0.8 1.2 0.04", "0.8 nan 0.04", 7, "finite number"),
    ("0.8 1.2 0.04", "0.8 1.2e999 0.04", 7, "finite number"),
    ("0.8 1.2 0.04", "0.8 abc 0.04", 7, "expected a number, got 'abc'"),
    ("* wedge\n-0.2 0.5 0.1\n0 0 0 1\n1", "* wedge\n-0.2 0.5 0.1\n0 0 0 1\n999999999",
     38, r"shape count is 999,999,999; robokin reads at most 100,000"),
    ("mesh\n4 4", "mesh\n4000000000 4", 40, r"vertex count is 4,000,000,000"),
    ("mesh\n4 4", "mesh\n4 -4", 40, "expected a count"),
    ("1 2 3\n0 0 0\n0 0 0 1\n0 0 0 0\n0\n.", "1 2 7\n0 0 0\n0 0 0 1\n0 0 0 0\n0\n.", 48,
     r"vertex index in \[0, 3\], got '7'"),
    ("box\n0.8", "plane\n0.8", 6, "a plane is not supported"),
    ("box\n0.8", "capsule\n0.8", 6, "unknown shape type 'capsule'"),
    ("* wedge", "# wedge", 35, "unknown marker '#'"),
    ("0 0 0.707107 0.707107", "0 0 0 2", 4, r"not a unit quaternion \(norm 2\)"),
    ("0 0 0.707107 0.707107", "0 0 0 0", 4, "a zero quaternion"),
    ("* wedge", "* table", 35, r"object 'table' is given twice \(lines 2 and 35\)"),
    ("0\n.\n", "0\n", 52, "the file ends where"),
    ("0\n.\n", "0\n.\n* more\n", 54, "text after the scene's closing '.'"),
    ("* wedge", "*", 35, "an empty object id"),
])
def test_bad_scene_text_is_refused_with_its_line(old, new, line, match):
    assert old in GOOD
    with pytest.raises(ModelError, match=match) as err:
        read_scene_text(GOOD.replace(old, new, 1), "cell.scene")
    assert err.value.file == "cell.scene"
    assert err.value.line == line


def test_too_many_objects_are_refused(monkeypatch):
    monkeypatch.setattr(ms, "MAX_SCENE_OBJECTS", 2)
    with pytest.raises(ModelError, match="more than 2 objects"):
        read_scene_text(GOOD)


def test_an_empty_scene_text_is_refused_and_a_scene_of_nothing_is_read():
    with pytest.raises(ModelError, match="an empty .scene file"):
        read_scene_text("")
    assert read_scene_text("empty\n.\n").objects == ()


# ------------------------------------------------------------- round trips
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402
from scipy.spatial.transform import Rotation  # noqa: E402

ANGLES = st.sampled_from([0.0, math.pi / 2, -math.pi / 2, math.pi, 1e-9, 0.3, -2.1])
SIZES = st.floats(0.001, 5.0)
OBJECT = st.tuples(
    st.sampled_from(["box", "cylinder", "sphere"]),
    st.lists(SIZES, min_size=3, max_size=3),
    st.lists(st.floats(-3, 3), min_size=3, max_size=3),
    st.lists(ANGLES, min_size=3, max_size=3),
    st.lists(st.floats(-1, 1), min_size=3, max_size=3),
)
DIMS = {"box": 3, "cylinder": 2, "sphere": 1}


def _quat(rotvec):
    return Rotation.from_rotvec(rotvec).as_quat()  # x y z w


@settings(max_examples=40, deadline=None)
@given(st.lists(OBJECT, min_size=1, max_size=4), st.booleans())
def test_scene_text_round_trip(objects, yaml_form):
    """Objects written as MoveIt would (17 digits) come back at the same poses.

    Oracle: scipy's rotation of the same rotation vector; the object pose composed
    with a shape pose by hand.
    """
    import yaml

    lines, docs, expect = ["round trip"], [], []
    for i, (kind, size, xyz, euler, local) in enumerate(objects):
        dims = size[: DIMS[kind]]
        q_obj = _quat(np.array(euler))
        q_shape = _quat(np.array(local))
        T_obj = pose(xyz, Rotation.from_quat(q_obj).as_matrix())
        T_shape = pose([0.1 * i, 0.0, -0.2], Rotation.from_quat(q_shape).as_matrix())
        expect.append((kind, tuple(dims), T_obj @ T_shape))
        fmt = " ".join
        lines += [f"* obj {i}", fmt(f"{v:.17g}" for v in xyz), fmt(f"{v:.17g}" for v in q_obj),
                  "1", kind, fmt(f"{v:.17g}" for v in dims), f"{0.1 * i:.17g} 0 -0.2",
                  fmt(f"{v:.17g}" for v in q_shape), "0 0 0 0", "0"]
        msg_dims = dims if kind != "cylinder" else [dims[1], dims[0]]  # height, radius
        docs.append({
            "id": f"obj {i}", "header": {"frame_id": "world"},
            "pose": {"position": dict(zip("xyz", map(float, xyz))),
                     "orientation": dict(zip("xyzw", map(float, q_obj)))},
            "primitives": [{"type": {"box": 1, "sphere": 2, "cylinder": 3}[kind],
                            "dimensions": [float(v) for v in msg_dims]}],
            "primitive_poses": [{"position": {"x": 0.1 * i, "y": 0.0, "z": -0.2},
                                 "orientation": dict(zip("xyzw", map(float, q_shape)))}]})
    if yaml_form:
        doc = yaml.safe_load(yaml.safe_dump({"world": {"collision_objects": docs}}))
        scene = planning_scene_from_document(doc)
    else:
        scene = read_scene_text("\n".join(lines + ["."]) + "\n")
    assert [o.id for o in scene.objects] == [f"obj {i}" for i in range(len(objects))]
    for obj, (kind, dims, T) in zip(scene.objects, expect):
        (shape,) = obj.shapes
        assert shape.kind == kind
        np.testing.assert_allclose(shape.size, dims, rtol=1e-15)
        np.testing.assert_allclose(shape.placement, T, atol=1e-12)
