"""Issue 19, item 5: JSON Schemas of robot, scene and motion files, and their docs.

The schemas are generated from the pydantic models the readers use; they accept
every built-in robot file and the bundled scenes, reject bad files the readers
reject, and every field they hold has a line in its docs page.
"""

import copy
import json
import re
from pathlib import Path

import pytest
import yaml

import robokin
from robokin.cli import main
from robokin.exceptions import ModelError
from robokin.io.schemas import FILE_KINDS, json_schema

jsonschema = pytest.importorskip("jsonschema")

ROOT = Path(__file__).resolve().parents[2]
ROBOTS = sorted((ROOT / "src" / "robokin" / "robots").glob("*.yaml"))
SCENES = sorted((ROOT / "src" / "robokin" / "collision" / "scenes").glob("*.yaml"))
DOCS = {"robot": "robot-files.md", "scene": "scene-files.md", "motion": "motion-files.md"}


def validator(kind):
    schema = json_schema(kind)
    cls = jsonschema.validators.validator_for(schema)
    cls.check_schema(schema)
    return cls(schema)


def schema_ok(kind, doc) -> bool:
    return validator(kind).is_valid(doc)


@pytest.mark.parametrize("path", ROBOTS, ids=lambda p: p.stem)
def test_every_builtin_robot_file_is_valid(path):
    errors = list(validator("robot").iter_errors(yaml.safe_load(path.read_text())))
    assert not errors, [e.message for e in errors[:3]]


@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.stem)
def test_every_bundled_scene_is_valid(path):
    errors = list(validator("scene").iter_errors(yaml.safe_load(path.read_text())))
    assert not errors, [e.message for e in errors[:3]]


def _load_robot(doc, tmp_path):
    p = tmp_path / "r.yaml"
    p.write_text(yaml.safe_dump(doc))
    robokin.load(str(p))


def _load_scene(doc, tmp_path):
    from robokin.collision.scene import Scene

    p = tmp_path / "s.yaml"
    p.write_text(yaml.safe_dump(doc))
    Scene.load(p)


UR5 = yaml.safe_load((ROOT / "src/robokin/robots/ur5.yaml").read_text())
SCARA = yaml.safe_load((ROOT / "src/robokin/robots/scara.yaml").read_text())
PRESS = yaml.safe_load((ROOT / "src/robokin/collision/scenes/press.yaml").read_text())


def _edit(doc, path, value):
    doc = copy.deepcopy(doc)
    *head, last = path
    target = doc
    for key in head:
        target = target[key]
    target[last] = value
    return doc


BAD_ROBOTS = [
    (_edit(UR5, ["wheels"], 4), "wheels"),
    (_edit(UR5, ["units", "length"], "inch"), "units.length"),
    (_edit(UR5, ["joints", 0, "alpah"], 90), "alpah"),
    (_edit(UR5, ["joints", 0, "a"], "12"), "joints[0].a"),
    (_edit(UR5, ["joints", 0, "sign"], 2), "joints[0].sign"),
    (_edit(UR5, ["convention"], "craig"), "convention"),
    (_edit(UR5, ["base"], {"xyz": [0, 0]}), "base.xyz"),
    (_edit(SCARA, ["actuators", "drives", 0, "speed"], 1), "speed"),
    (_edit(SCARA, ["actuators", "drives", 1, "type"], "belt"), "drives[1]"),
    (_edit(UR5, ["geometry", "base", 0, "colour"], "red"), "colour"),
    (_edit(UR5, ["geometry", "base", 0, "type"], "cone"), "type"),
    (_edit(UR5, ["collision", "exclude_adjacent"], "yes"), "exclude_adjacent"),
    ({k: v for k, v in UR5.items() if k != "name"}, "name"),
]


@pytest.mark.parametrize(("doc", "where"), BAD_ROBOTS, ids=[w for _, w in BAD_ROBOTS])
def test_the_robot_schema_rejects_what_the_reader_rejects(doc, where, tmp_path):
    assert not schema_ok("robot", doc)
    with pytest.raises(ModelError, match=re.escape(where)):
        _load_robot(doc, tmp_path)


BAD_SCENES = [
    (_edit(PRESS, ["lights"], 3), "lights"),
    (_edit(PRESS, ["units", "length"], "inch"), "units.length"),
    (_edit(PRESS, ["objects", 0, "size"], [1, 1]), "objects[0].size"),
    (_edit(PRESS, ["objects", 0, "colour"], "red"), "objects[0].colour"),
    (_edit(PRESS, ["objects", 0, "type"], "cone"), "objects[0].type"),
    (_edit(PRESS, ["tool", "grip"], 1), "tool"),
    (_edit(PRESS, ["robot", "base", "z"], 1), "robot.base"),
    (_edit(PRESS, ["poses", "pick", "xyz"], [1, 2]), "poses.pick"),
    (_edit(PRESS, ["exclude"], [["base"]]), "exclude[0]"),
]


@pytest.mark.parametrize(("doc", "where"), BAD_SCENES, ids=[w for _, w in BAD_SCENES])
def test_the_scene_schema_rejects_what_the_reader_rejects(doc, where, tmp_path):
    pytest.importorskip("trimesh")
    assert not schema_ok("scene", doc)
    with pytest.raises(ModelError, match=re.escape(where)):
        _load_scene(doc, tmp_path)


MOTION = {"robot": "ur5", "units": {"length": "mm", "angle": "deg"},
          "start": [0, -90, 90, 0, 90, 0],
          "segments": [{"joint": [10, -80, 80, 0, 90, 0], "duration": 1.0}]}


@pytest.mark.parametrize(("doc", "where"), [
    (_edit(MOTION, ["segments", 0, "foo"], 1), "segments[0].foo"),
    (_edit(MOTION, ["dt"], -1), "dt"),
    (_edit(MOTION, ["ik"], "guess"), "ik"),
    ({k: v for k, v in MOTION.items() if k != "start"}, "start"),
])
def test_the_motion_schema_rejects_what_the_reader_rejects(doc, where, tmp_path):
    from robokin.io.motion_files import load_motion_file

    assert schema_ok("motion", MOTION) and not schema_ok("motion", doc)
    p = tmp_path / "m.yaml"
    p.write_text(yaml.safe_dump(doc))
    with pytest.raises(ModelError, match=re.escape(where)):
        load_motion_file(p)


def test_an_unknown_key_lists_the_accepted_ones(tmp_path):
    """The issue's example: segments[0].foo names the keys a segment takes."""
    from robokin.io.motion_files import load_motion_file

    p = tmp_path / "m.yaml"
    p.write_text(yaml.safe_dump(_edit(MOTION, ["segments", 0, "foo"], 1)))
    with pytest.raises(ModelError) as exc:
        load_motion_file(p)
    assert ("segments[0].foo: unknown key; accepted: joint, pose, line, dwell, "
            "duration, profile, stop, label, speed_in, speed_out") in str(exc.value)
    p.write_text(yaml.safe_dump(_edit(SCARA, ["actuators", "drives", 1, "speed"], 1)))
    with pytest.raises(ModelError, match=r"actuators\.drives\[1\]\.speed: unknown key; "
                                         r"accepted: type, joints, lead, i, j, lift_sign"):
        robokin.load(str(p))


def _properties(node, out):
    """Every property name in a JSON Schema (nested definitions included)."""
    if isinstance(node, dict):
        for name, sub in node.get("properties", {}).items():
            out.add(name)
            _properties(sub, out)
        for key, sub in node.items():
            if key != "properties":
                _properties(sub, out)
    elif isinstance(node, list):
        for sub in node:
            _properties(sub, out)
    return out


@pytest.mark.parametrize("kind", FILE_KINDS)
def test_every_schema_field_is_documented(kind):
    page = (ROOT / "docs" / DOCS[kind]).read_text()
    missing = sorted(p for p in _properties(json_schema(kind), set())
                     if f"`{p}`" not in page)
    assert not missing, f"docs/{DOCS[kind]} does not mention {missing}"


@pytest.mark.parametrize("kind", FILE_KINDS)
def test_the_docs_example_is_valid(kind, tmp_path):
    page = (ROOT / "docs" / DOCS[kind]).read_text()
    block = re.search(r"```yaml\n(# yaml-language-server[^\n]*\n.*?)```", page, re.S)
    doc = yaml.safe_load(block.group(1))
    errors = list(validator(kind).iter_errors(doc))
    assert not errors, [e.message for e in errors[:3]]
    if kind == "robot":
        _load_robot(doc, tmp_path)
    elif kind == "scene":
        pytest.importorskip("trimesh")
        doc["objects"] = [o for o in doc["objects"] if o["type"] != "mesh"]
        _load_scene(doc, tmp_path)
    else:
        from robokin.io.motion_files import load_motion_file

        p = tmp_path / "m.yaml"
        p.write_text(yaml.safe_dump(doc))
        load_motion_file(p)


def test_schema_command_prints_and_writes(capsys, tmp_path):
    assert main(["schema", "motion"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed == json_schema("motion")
    assert printed["title"] == "robokin motion file"
    out = tmp_path / "robot.schema.json"
    assert main(["schema", "robot", "--out", str(out)]) == 0
    assert json.loads(out.read_text()) == json_schema("robot")
    assert main(["schema", "robot", "--out", str(tmp_path / "no" / "r.json")]) == 2
    assert "--out" in capsys.readouterr().err
    assert main(["schema", "trajectory"]) == 2
    err = capsys.readouterr().err
    assert "accepted: robot, scene, motion" in err and err.count("\n") == 1


def test_the_schema_follows_the_model():
    """Generated, not written: a field of the reader's model is in the schema."""
    from robokin.io.robot_files import _schema

    RobotFile, Row, Op = _schema()
    props = json_schema("robot")["properties"]
    assert set(RobotFile.model_fields) == set(props)
    row = json_schema("robot")["$defs"]["Row"]["properties"]
    assert set(Row.model_fields) == set(row)


def test_joint_entries_keep_their_field_order_and_checks():
    """Oracle: the field order ``robokin schema robot`` printed before the joint
    fields were shared (docs/robot-files.md lists them in this order), and the
    reader's refusals of reversed limits and a boolean sign on every entry kind."""
    from pydantic import ValidationError

    from robokin.io.robot_files import _schema

    defs = json_schema("robot")["$defs"]
    assert list(defs["Row"]["properties"]) == [
        "name", "joint", "a", "alpha", "d", "theta", "limits", "sign", "depends",
        "depends_offset"]
    assert list(defs["Op"]["properties"]) == [
        "op", "value", "name", "joint", "limits", "sign", "depends", "depends_offset"]
    assert list(defs["Coordinate"]["properties"]) == ["name", "joint", "limits"]
    _, Row, Op = _schema()
    for model, base in ((Row, {}), (Op, {"op": "rz"})):
        assert model(**base, limits=(-1.0, 1.0), sign=-1).sign == -1
        with pytest.raises(ValidationError, match="limits reversed"):
            model(**base, limits=(1.0, -1.0))
        with pytest.raises(ValidationError, match="got a boolean"):
            model(**base, sign=True)
