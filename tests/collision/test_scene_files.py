"""Scenes: building in code, scene files, the bundled press cell and its key poses."""

import math

import numpy as np
import pytest
import yaml

import robokin
from robokin import ModelError
from robokin.collision import Scene, check, scene_path
from robokin.exceptions import InputError
from robokin.model import geometry as geo
from robokin.spatial import pose_from_xyz_rpy

pytest.importorskip("coal")


def test_add_objects_and_errors():
    sc = Scene("cell")
    T = np.eye(4)
    T[:3, 3] = (1.0, 2.0, 3.0)
    sc.add_box("plate", size=(0.1, 0.2, 0.3), pose=T)
    sc.add_cylinder("post", 0.05, 1.0)
    sc.add_sphere("ball", 0.1)
    assert sc.names == ("plate", "post", "ball")
    np.testing.assert_allclose(sc["plate"].pose, T)
    assert sc["plate"].shape.size == (0.1, 0.2, 0.3)
    with pytest.raises(InputError, match="already has an object 'plate'"):
        sc.add_box("plate", size=(1, 1, 1))
    with pytest.raises(
        InputError, match=r"no object 'nope'.*objects: \['plate', 'post', 'ball'\]"
    ):
        sc["nope"]
    bad = np.eye(4)
    bad[0, 0] = 2.0
    with pytest.raises(InputError, match="orthonormal"):
        sc.add_box("skewed", size=(1, 1, 1), pose=bad)
    with pytest.raises(ModelError, match="not found"):
        sc.add_mesh("part", "/nonexistent/part.stl")


def test_scene_file_units_placement_and_errors(tmp_path):
    doc = {
        "units": {"length": "mm", "angle": "deg"},
        "robot": {"name": "ur5", "base": {"xyz": [100, 0, 500], "rpy": [0, 0, 90]}},
        "objects": [
            {
                "name": "plate",
                "type": "box",
                "size": [400, 300, 10],
                "xyz": [500, 0, 200],
                "rpy": [0, 0, 30],
            }
        ],
        "poses": {
            "home": {
                "xyz": [400, 0, 300],
                "rpy": [180, 0, 0],
                "q": [0, -90, 0, 0, 0, 0],
            }
        },
    }
    path = tmp_path / "cell.yaml"
    path.write_text(yaml.safe_dump(doc))
    sc = Scene.load(path)
    assert sc.robot_name == "ur5"
    np.testing.assert_allclose(
        sc.base, pose_from_xyz_rpy([0.1, 0, 0.5], [0, 0, math.pi / 2])
    )
    plate = sc["plate"]
    assert plate.shape.size == pytest.approx((0.4, 0.3, 0.01))
    np.testing.assert_allclose(
        plate.pose, pose_from_xyz_rpy([0.5, 0, 0.2], [0, 0, math.pi / 6])
    )
    np.testing.assert_allclose(sc.pose_joints["home"], [0, -math.pi / 2, 0, 0, 0, 0])
    for bad, match in [
        ({**doc, "lights": 3}, "lights: unknown key; accepted: name, source, units"),
        (
            {**doc, "objects": [{"type": "box", "size": [1, 1, 1]}]},
            r"objects\[0\]: an object needs a 'name'",
        ),
        (
            {**doc, "objects": [{"name": "a", "type": "box", "size": [1, 1]}]},
            r"objects\[0\]\.size",
        ),
        ({**doc, "units": {"length": "inch"}}, "units.length"),
        ({**doc, "poses": {"p": {"xyz": [1, 2]}}}, r"poses\.p\.xyz: expected 3 numbers"),
        (
            {**doc, "objects": [{"name": "m", "type": "mesh", "file": "gone.stl"}]},
            r"objects\[0\]\.file: mesh file not found",
        ),
    ]:
        path.write_text(yaml.safe_dump(bad))
        with pytest.raises(ModelError, match=match) as exc:
            Scene.load(path)
        assert str(path) in str(exc.value)
    with pytest.raises(ModelError, match="no such file"):
        Scene.load(tmp_path / "missing.yaml")


def test_attach_places_base_tool_and_gripper():
    r = robokin.load("ur5")
    sc = Scene()
    base = pose_from_xyz_rpy([0.2, 0.1, 0.7], [0.0, 0.0, 0.5])
    tcp = pose_from_xyz_rpy([0.0, 0.0, 0.15], [0.0, 0.0, 0.0])
    sc.set_base(base)
    sc.set_tool(
        [geo.box((0.05, 0.05, 0.1), pose_from_xyz_rpy([0, 0, 0.05], [0, 0, 0]))], tcp
    )
    placed = sc.attach(r)
    q = np.array([0.3, -1.0, 1.2, -0.5, 1.1, 0.2])
    np.testing.assert_allclose(placed.fk(q), base @ r.fk(q) @ tcp, atol=1e-12)
    (box,) = placed.geometry.tool
    np.testing.assert_allclose(box.placement[:3, 3], [0, 0, -0.10], atol=1e-12)
    # the robot's own link shapes are unchanged
    for a, b in zip(
        placed.geometry.link("elbow"), r.geometry.link("elbow"), strict=True
    ):
        assert a.size == b.size
        np.testing.assert_array_equal(a.placement, b.placement)
    # placing an already placed robot again does not stack base and tool twice
    again = sc.attach(placed)
    np.testing.assert_allclose(again.fk(q), base @ r.fk(q) @ tcp, atol=1e-12)
    assert len(again.geometry.tool) == 1
    # ... and the scene's current base is used when it changed in between
    sc.set_base(np.eye(4))
    np.testing.assert_allclose(sc.attach(placed).fk(q), r.fk(q) @ tcp, atol=1e-12)
    sc.set_base(base)
    # a placed robot changed afterwards is a new robot: placed on top of it
    moved = placed.with_tool(placed.chain.tool @ tcp)
    np.testing.assert_allclose(
        sc.attach(moved).fk(q), base @ base @ r.fk(q) @ tcp @ tcp @ tcp, atol=1e-12
    )
    # check() gives the same answer for the robot and the placed robot
    qs = np.stack([q, q + 0.1])
    sc.add_box("block", (0.2, 0.2, 0.2), pose_from_xyz_rpy([0.5, 0, 0.5], [0, 0, 0]))
    assert check(placed, sc, qs).min_distance == check(r, sc, qs).min_distance


@pytest.fixture(scope="module")
def press():
    return Scene.load(scene_path("press")), robokin.load("aubo_i5")


def test_press_scene_key_poses_are_reached_by_their_joint_configurations(press):
    sc, r = press
    placed = sc.attach(r)
    assert set(sc.poses) == {"pick_approach", "pick", "press_approach", "press_place"}
    for name, T in sc.poses.items():
        q = sc.pose_joints[name]
        assert r.within_limits(q)
        Tq = placed.fk(q)
        np.testing.assert_allclose(Tq[:3, 3], T[:3, 3], atol=1e-4)
        np.testing.assert_allclose(Tq[:3, :3], T[:3, :3], atol=1e-4)
    # the gripper points horizontally (+x) into the press and down at the pick
    np.testing.assert_allclose(sc.poses["press_place"][:3, 2], [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(sc.poses["pick"][:3, 2], [0, 0, -1], atol=1e-12)
    # the line into the press is straight along +x, inside the reach (0.88 m)
    d = sc.poses["press_place"][:3, 3] - sc.poses["press_approach"][:3, 3]
    np.testing.assert_allclose(d / np.linalg.norm(d), [1, 0, 0], atol=1e-12)
    assert 0.55 <= sc.poses["press_place"][0, 3] <= 0.65


def test_press_place_fits_the_die_opening_with_a_few_cm(press):
    sc, r = press
    rep = check(r, sc, sc.pose_joints["press_place"][None])
    assert not rep.collides
    dist = {(p.body_a, p.body_b): p.distance for p in rep.pairs}
    # palm 60 mm high in a 120 mm opening: 30 mm above and below (q rounded to 1e-3 deg)
    assert dist[("tool", "upper_die")] == pytest.approx(0.030, abs=1e-4)
    assert dist[("tool", "lower_die")] == pytest.approx(0.030, abs=1e-4)
    # the gripper is really inside the opening (its tip is past the die front at x = 0.5)
    tip = sc.poses["press_place"][0, 3]
    assert tip > 0.5 + 0.1
    assert rep.closest.body_a == "tool" and rep.closest.distance == pytest.approx(
        0.03, abs=1e-4
    )
    pick = check(r, sc, sc.pose_joints["pick"][None])
    assert not pick.collides
    assert pick.closest.body_b == "fixture"
    assert pick.closest.distance == pytest.approx(0.020, abs=1e-4)


def test_changing_the_scene_after_a_check_is_seen_by_the_next_check():
    r = robokin.load("ur5")
    sc = Scene()
    sc.add_box("block", size=(0.2, 0.2, 0.2))  # around the robot's base
    q = np.zeros((1, 6))
    first = check(r, sc, q)
    assert first.distances("base", "block")[0] < 0
    sc.base = pose_from_xyz_rpy([0.0, 0.0, 1.0], [0, 0, 0])  # plain assignment
    lifted = check(r, sc, q)
    # the base capsule (r 75 mm, axis z -100..5 mm) now ends 0.825 m up; block top 0.1
    assert lifted.distances("base", "block")[0] == pytest.approx(0.725, abs=1e-9)
    sc.exclude.add(frozenset(("base", "block")))
    sc.exclude.add(frozenset(("shoulder_pan", "block")))
    pairs = {(p.body_a, p.body_b) for p in check(r, sc, q).pairs}
    assert ("base", "block") not in pairs and ("shoulder_pan", "block") not in pairs
    assert ("elbow", "block") in pairs


# ------------------------------------------- issue 25: exclusions naming nothing
SCENE = """\
name: cell
units: {length: mm, angle: deg}
objects:
  - {name: table, type: box, size: [600, 800, 20], xyz: [0, 500, 390]}
  - {name: post, type: cylinder, radius: 50, length: 400, xyz: [700, 0, 200]}
exclude: EXCLUDE
"""


@pytest.mark.parametrize(("exclude", "match"), [
    ("[[base, nothere]]",
     r"cell.yaml:6: exclude\[0\]: no object 'nothere' in this scene; a pair is "
     r"\[robot link, object\], the objects are \['table', 'post'\]"),
    ("[[base, table], [wrist_1, tabel]]", r"exclude\[1\]: no object 'tabel'"),
    ("[[table, post]]", r"exclude\[0\]: 'table' and 'post' are both objects"),
])
def test_an_exclusion_naming_no_object_is_refused_at_load(tmp_path, exclude, match):
    """Issue 25: ``exclude: [[base, nothere]]`` was ignored silently."""
    f = tmp_path / "cell.yaml"
    f.write_text(SCENE.replace("EXCLUDE", exclude))
    with pytest.raises(ModelError, match=match):
        Scene.load(f)


def test_an_exclusion_naming_no_link_is_refused_when_it_meets_the_robot(tmp_path):
    f = tmp_path / "cell.yaml"
    f.write_text(SCENE.replace("EXCLUDE", "[[table, shoulder_pann]]"))  # [object, link]
    scene = Scene.load(f)
    ur5 = robokin.load("ur5")
    with pytest.raises(ModelError, match=r"cell.yaml: exclude: exclude \['shoulder_pann', "
                       r"'table'\]: 'shoulder_pann' is neither a link of the robot "
                       r"\(links: \['base', 'shoulder_pan', 'shoulder_lift', 'elbow', "
                       r"'wrist_1', 'wrist_2', 'wrist_3', 'tool'\]\) nor an object"):
        check(ur5, scene, np.zeros((2, 6)))
    # spelt right (in either order) the pair is kept and the robot attaches
    f.write_text(SCENE.replace("EXCLUDE", "[[table, shoulder_pan]]"))
    kept = Scene.load(f)
    assert kept.exclude == {frozenset(("table", "shoulder_pan"))}
    kept.attach(ur5)
    with pytest.raises(InputError, match="'post' is an object"):
        kept.exclude_pair("post", "table")


def test_a_scene_names_a_robot_file_relative_to_itself(tmp_path, monkeypatch, capsys):
    """Issue 25: `robokin check cell/scene.yaml plan.csv` looked for the scene's
    `robot: arm.yaml` in the current folder. Oracle: the same robot file loaded by
    its full path; a built-in name stays a name."""
    from robokin.cli import main
    from robokin.trajectory import io, quintic

    folder = tmp_path / "cell"
    folder.mkdir()
    ur5 = robokin.load("ur5")
    robokin.save(ur5.replace(name="my_arm"), folder / "arm.yaml")
    (folder / "scene.yaml").write_text(
        "robot: {name: arm.yaml}\n"
        "objects: [{name: post, type: box, size: [0.1, 0.1, 0.1], xyz: [2, 0, 0]}]\n")
    sc = Scene.load(folder / "scene.yaml")
    assert sc.robot_name == str(folder / "arm.yaml")
    assert robokin.load(sc.robot_name).name == "my_arm"
    plan = quintic(np.zeros(6), np.full(6, 0.2), 0.5).replace(joint_names=ur5.joint_names)
    csv = io.write_csv(plan, tmp_path / "plan.csv")
    monkeypatch.chdir(tmp_path)  # not the scene's folder
    assert main(["check", "cell/scene.yaml", str(csv)]) == 0, capsys.readouterr().err
    (folder / "named.yaml").write_text("robot: {name: ur5}\n")
    assert Scene.load(folder / "named.yaml").robot_name == "ur5"
