"""MoveIt planning scenes as robokin scenes (issue 26): ``Scene.load`` of a ``.scene``
file and a PlanningScene YAML, objects of several shapes, the allowed-collision
matrix mapped onto robokin's links, and hostile files refused with their line.
Oracle for the matrix: robokin's own check of the same robot and objects, with the
pair allowed and not."""

import textwrap
from pathlib import Path

import numpy as np
import pytest

from robokin import collision
from robokin.exceptions import ModelError

pytest.importorskip("yourdfpy")
from robokin import Robot  # noqa: E402

DATA = Path(__file__).parent.parent / "data"
URDF = DATA / "urdf" / "gripper_arm.urdf"


@pytest.fixture(scope="module")
def robot():
    return Robot.from_urdf(URDF, tip_link="tcp")


def test_load_scene_text_names_shapes_and_groups():
    scene = collision.Scene.load(DATA / "moveit" / "cell.scene")
    assert scene.name == "press cell" and scene.path == DATA / "moveit" / "cell.scene"
    assert scene.names == ("table", "post with lamp/0", "post with lamp/1",
                           "post with lamp/2", "wedge")
    assert scene.groups["post with lamp"] == ("post with lamp/0", "post with lamp/1",
                                              "post with lamp/2")
    assert scene["table"].shape.kind == "box"
    assert scene.allowed is None and scene.joint_state == {}


def test_load_planning_scene_yaml(robot):
    scene = collision.Scene.load(DATA / "moveit" / "planning_scene.yaml")
    assert scene.names == ("table", "fixture/0", "fixture/1", "fixture/2", "fixture/3")
    assert scene.frame == "world"
    assert scene.joint_state == {"joint_1": 0.1, "joint_2": -0.2, "joint_3": 0.3}
    excluded = scene.excluded_pairs(robot)
    # base_link-table allowed, and base holds base_link only
    assert frozenset(("base", "table")) in excluded
    # the camera's default entry allows it with everything, but joint_2 also holds
    # link_2 and the camera mount: not excluded
    assert not any("joint_2" in p for p in excluded)
    # base_link-link_1 allowed: a self pair the placed robot no longer checks
    placed = scene.attach(robot)
    assert frozenset(("base", "joint_1")) in placed.geometry.exclude


def _scene_yaml(tmp_path, acm=""):
    """A box around link_1 at q = 0 (and a far one), with an optional matrix."""
    text = textwrap.dedent("""\
        world:
          collision_objects:
          - id: post
            header: {frame_id: world}
            primitives:
            - {type: 1, dimensions: [0.3, 0.3, 0.1]}
            primitive_poses:
            - position: {x: 0.0, y: 0.0, z: 0.3}
              orientation: {x: 0.0, y: 0.0, z: 0.0, w: 1.0}
          - id: far
            header: {frame_id: world}
            primitives:
            - {type: 2, dimensions: [0.1]}
            primitive_poses:
            - position: {x: 3.0, y: 0.0, z: 0.0}
        """) + acm
    path = tmp_path / "scene.yaml"
    path.write_text(text)
    return collision.Scene.load(path)


@pytest.mark.parametrize("acm, reported", [
    ("", True),
    ("allowed_collision_matrix:\n  entry_names: [link_1, post]\n"
     "  entry_values:\n  - enabled: [false, true]\n  - enabled: [true, false]\n", False),
    # the lower triangle alone is not read (as in MoveIt)
    ("allowed_collision_matrix:\n  entry_names: [link_1, post]\n"
     "  entry_values:\n  - enabled: [false, false]\n  - enabled: [true, false]\n", True),
    ("allowed_collision_matrix:\n  default_entry_names: [post]\n"
     "  default_entry_values: [true]\n", False),
])
def test_the_allowed_collision_matrix_decides_what_is_checked(tmp_path, robot, acm,
                                                              reported):
    scene = _scene_yaml(tmp_path, acm)
    rep = collision.check(robot, scene, np.zeros((1, 3)), subdivide=False)
    hits = {(c[2], c[3]) for c in rep.collisions}
    assert (("joint_1", "post") in hits) == reported
    assert not any("far" in h for h in hits)


def test_a_robokin_scene_may_exclude_a_urdf_link(tmp_path, robot):
    path = tmp_path / "cell.yaml"
    path.write_text("objects:\n  - {name: post, type: box, size: [0.3, 0.3, 0.1], "
                    "xyz: [0, 0, 0.3]}\nexclude: [[link_1, post]]\n")
    scene = collision.Scene.load(path)
    rep = collision.check(robot, scene, np.zeros((1, 3)), subdivide=False)
    assert not any(c[3] == "post" for c in rep.collisions)
    path.write_text(path.read_text().replace("link_1", "link_9"))
    with pytest.raises(ModelError, match="'link_9' is neither a link of the robot"):
        collision.check(robot, collision.Scene.load(path), np.zeros((1, 3)))


def test_every_urdf_link_of_a_robokin_link_must_be_allowed(tmp_path, robot):
    """joint_2 holds link_2 and the camera: allowing link_2 alone keeps the pair."""
    q = np.zeros(3)  # the wall cuts link_2, the camera's mount and the camera
    base = "objects:\n  - {name: wall, type: box, size: [0.02, 2, 2], xyz: [0.2, 0, 0.4]}\n"
    path = tmp_path / "cell.yaml"
    hit = []
    for exclude in ("", "exclude: [[link_2, wall]]\n",
                    "exclude: [[link_2, wall], [camera, wall], [camera_mount, wall]]\n"):
        path.write_text(base + exclude)
        rep = collision.check(robot, collision.Scene.load(path), q[None], subdivide=False)
        hit.append(any(c[2:] == ("joint_2", "wall") for c in rep.collisions))
    assert hit == [True, True, False]


@pytest.mark.parametrize("text, line, match", [
    ("world:\n  collision_objects:\n  - id: a\n    primitives:\n    - {type: 7, "
     "dimensions: [1]}\n", 5, r"primitives\[0\].type: expected BOX"),
    ("world:\n  collision_objects:\n  - id: a\n    primitives:\n    - {type: 1, "
     "dimensions: [1, 2]}\n", 5, "a BOX needs 3 dimensions, got 2"),
    ("world:\n  collision_objects:\n  - id: a\n    primitives:\n    - {type: 2, "
     "dimensions: [.nan]}\n", 5, "finite number"),
    ("world:\n  collision_objects:\n  - id: a\n    primitives:\n    - {type: 2, "
     "dimensions: [-1]}\n", 5, "finite and >= 0"),
    ("world:\n  collision_objects:\n  - id: a\n    planes:\n    - {coef: [0, 0, 1, 0]}\n",
     4, "a plane is not supported"),
    ("world:\n  collision_objects:\n  - id: a\n    primitives: [{type: 2, dimensions: [1]}]"
     "\n    primitive_poses: [{}, {}]\n", 5, "2 poses for 1 primitives"),
    ("world:\n  collision_objects:\n  - id: a\n    primitives: [{type: 2, dimensions: [1]}]"
     "\n    pose: {orientation: {x: 0, y: 0, z: 0, w: 0}}\n", 5, "a zero quaternion"),
    ("world:\n  collision_objects:\n  - id: a\n    header: {frame_id: tool0}\n"
     "    primitives: [{type: 2, dimensions: [1]}]\n  - id: b\n    header: {frame_id: world}"
     "\n    primitives: [{type: 2, dimensions: [1]}]\n", 7, "'world' is neither the planning"),
    ("world:\n  collision_objects:\n  - id: a\n    operation: 3\n", 4, "MOVE is not"),
    ("world:\n  collision_objects:\n  - id: a\n    colour: red\n", 4, "unknown key"),
    ("world:\n  collision_objects:\n  - id: a\n", 3, "object 'a' has no shapes"),
    ("robot_state:\n  attached_collision_objects:\n  - {link_name: tool0}\n", 2,
     "attached objects are not supported"),
    ("link_padding:\n- {link_name: a, padding: 0.01}\n", 2, "robokin has no per-link"),
    ("world:\n  octomap:\n    octomap: {data: [1, 2]}\n", 2, "an octomap is not supported"),
    ("world: {}\nallowed_collision_matrix:\n  entry_names: [a, b]\n  entry_values:\n"
     "  - [true]\n  - [true, false]\n", 5, "1 values for 2 entry_names"),
    ("world: {}\nallowed_collision_matrix:\n  entry_names: [a, b]\n  entry_values:\n"
     "  - [false, maybe]\n  - [true, false]\n", 5, "expected true or false"),
    ("world: {}\nobjects: []\n", 2, "unknown key"),
])
def test_bad_planning_scene_yaml_is_refused_with_its_line(tmp_path, text, line, match):
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(ModelError, match=match) as err:
        collision.Scene.load(path)
    assert err.value.file == str(path)
    assert err.value.line == line


def test_a_yaml_alias_bomb_is_refused(tmp_path):
    lines = ["a0: &a0 [1, 1, 1, 1, 1, 1, 1, 1, 1]"]
    lines += [f"a{i}: &a{i} [*a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, "
              f"*a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}]" for i in range(1, 9)]
    path = tmp_path / "bomb.yaml"
    path.write_text("\n".join(lines) + "\nworld: {collision_objects: *a8}\n")
    with pytest.raises(ModelError, match="too large once expanded|nodes"):
        collision.Scene.load(path)


def test_a_binary_scene_file_is_refused(tmp_path):
    path = tmp_path / "x.scene"
    path.write_bytes(b"name\n* a\x00\n")
    with pytest.raises(ModelError, match="binary file"):
        collision.Scene.load(path)
