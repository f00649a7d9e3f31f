"""The one YAML reader: lines, duplicate keys, numbers, and bounded work (issue 15).

The "billion laughs" tests are written as the attack: a few hundred bytes of YAML
whose aliases name 9**9 values, in every kind of field robokin validates, read
by a fresh interpreter whose address space is capped a few hundred MB above what
it already uses. Before the fix these files made ``robokin.load`` and ``robokin
show`` allocate gigabytes (the validation message built the repr of the whole
input before cutting it).
"""

from __future__ import annotations

import pytest
import yaml

from bounded import alias_bomb, run_bounded
from robokin.exceptions import ModelError
from robokin.io.yaml_reader import parse_yaml, read_yaml_document

ANCHORS, BOMB = alias_bomb()


def _robot_file(field_yaml: str) -> str:
    # the anchors live under an unknown key 'bombs' that validation never reaches
    return f"bombs:\n{ANCHORS}\n{field_yaml}"


ROBOT_BOMBS = {
    "joints[0].a": _robot_file(f"name: x\njoints:\n  - {{a: {BOMB}}}\n"),
    "source": _robot_file(f"name: x\nsource: {BOMB}\njoints:\n  - {{a: 1}}\n"),
    "base.xyz": _robot_file(f"name: x\nbase: {{xyz: {BOMB}}}\njoints:\n  - {{a: 1}}\n"),
    "geometry size": _robot_file(
        f"name: x\njoints:\n  - {{name: j1, a: 1}}\n"
        f"geometry:\n  j1:\n    - {{type: box, size: {BOMB}}}\n"),
}


def _leaves(node: yaml.Node, memo: dict[int, int]) -> int:
    """Scalars a composed YAML node names once every alias is expanded (memoised:
    nothing is expanded)."""
    if id(node) not in memo:
        if isinstance(node, yaml.ScalarNode):
            memo[id(node)] = 1
        elif isinstance(node, yaml.SequenceNode):
            memo[id(node)] = sum(_leaves(c, memo) for c in node.value)
        else:
            memo[id(node)] = sum(_leaves(v, memo) for _, v in node.value)
    return memo[id(node)]


def test_the_bomb_is_a_bomb():
    # the oracle: the few hundred bytes really name width**depth leaves as a tree
    assert len(ANCHORS) + len(BOMB) < 600
    node = yaml.compose(f"bombs:\n{ANCHORS}\nx: {BOMB}\n")
    x = dict((k.value, v) for k, v in node.value)["x"]
    assert _leaves(x, {}) == 9**9
    # a small one expands to the count it names
    small_anchors, small = alias_bomb(width=3, depth=4)
    doc = yaml.safe_load(f"bombs:\n{small_anchors}\nx: {small}\n")
    flat = doc["x"]
    while isinstance(flat[0], list):
        flat = [leaf for part in flat for leaf in part]
    assert flat == ["lol"] * 81


@pytest.mark.parametrize("field", sorted(ROBOT_BOMBS))
def test_alias_bomb_in_a_robot_file_is_refused_in_bounded_memory(tmp_path, field):
    path = tmp_path / "bomb.yaml"
    path.write_text(ROBOT_BOMBS[field])
    proc = run_bounded(f"""
        try:
            robokin.load({str(path)!r})
        except robokin.ModelError as exc:
            print("REFUSED", exc)
        code = robokin.cli.main(["show", {str(path)!r}])
        print("EXIT", code)
    """)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "REFUSED" in proc.stdout and "bomb.yaml:" in proc.stdout
    assert "EXIT 2" in proc.stdout
    assert "aliases" in proc.stdout


def test_alias_bomb_in_scene_and_motion_files_is_refused(tmp_path):
    scene = tmp_path / "scene.yaml"
    scene.write_text(f"bombs:\n{ANCHORS}\nname: s\nobjects:\n"
                     f"  - {{name: b, type: box, size: {BOMB}}}\n")
    motion = tmp_path / "motion.yaml"
    motion.write_text(f"bombs:\n{ANCHORS}\nrobot: ur5\nstart: {BOMB}\n"
                      "segments:\n  - dwell: 1\n")
    proc = run_bounded(f"""
        from robokin.io.motion_files import load_motion_file
        for load in (collision.Scene.load, load_motion_file):
            for p in ({str(scene)!r}, {str(motion)!r}):
                try:
                    load(p)
                except robokin.ModelError as exc:
                    print("REFUSED", exc)
        print("EXIT", robokin.cli.main(["traj", {str(motion)!r}, "--no-plot"]))
    """)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.count("REFUSED") == 4 and "EXIT 2" in proc.stdout


def test_a_bomb_built_in_memory_gets_a_short_message_not_its_repr():
    # the second defence: a document that never went through the YAML budget
    # (built in code) still gets a message cut before it is formatted
    proc = run_bounded("""
        from robokin.io.robot_files import parts_from_document
        bomb = ["lol"] * 9
        for _ in range(8):
            bomb = [bomb] * 9
        for doc in ({"name": "x", "source": bomb, "joints": [{}]},
                    {"name": "x", "joints": [{"a": bomb}]},
                    {"name": "x", "joints": [{}], "geometry": {"joint1": [
                        {"type": "box", "size": bomb}]}}):
            try:
                parts_from_document(doc, file="mem.yaml")
            except robokin.ModelError as exc:
                assert len(str(exc)) < 300, len(str(exc))
                print("REFUSED", exc)
    """)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.count("REFUSED") == 3


def test_a_plain_large_document_is_refused_by_the_node_cap():
    text = "x: [" + ", ".join(["1"] * 150_000) + "]\n"
    with pytest.raises(ModelError, match=r"more than 100,000 values.*max_nodes"):
        parse_yaml(text)
    assert len(parse_yaml(text, max_nodes=200_000).data["x"]) == 150_000


def test_duplicate_keys_are_refused_with_both_lines():
    with pytest.raises(ModelError, match=r"f\.yaml:3: duplicate key 'a' \(first given "
                                         r"at line 2\)"):
        parse_yaml("name: x\na: 1\na: 2\n", file="f.yaml")
    with pytest.raises(ModelError, match=r":2: duplicate key 'theta'"):
        parse_yaml("joints:\n  - {theta: 1, d: 0, theta: 2}\n", file="f.yaml")
    # merged keys may be overridden, as YAML's merge key says
    doc = parse_yaml("base: &b {a: 1, b: 2}\nc:\n  <<: *b\n  b: 3\n").data
    assert doc["c"] == {"a": 1, "b": 3}


def test_numbers_are_read_as_yaml_1_2_reads_them():
    doc = parse_yaml("a: 1e3\nb: -2.5E-3\nc: '1e3'\nd: 12\ne: 1_000\n").data
    assert doc == {"a": 1000.0, "b": -0.0025, "c": "1e3", "d": 12, "e": 1000}


def test_nesting_and_recursion_are_refused():
    with pytest.raises(ModelError, match="nested deeper than 64"):
        parse_yaml("[" * 65 + "]" * 65)
    parse_yaml("[" * 64 + "]" * 64)
    with pytest.raises(ModelError, match="recursive"):
        parse_yaml("a: &a [1, *a]\n")


def test_lines_of_fields_follow_the_document():
    doc = parse_yaml("name: x\njoints:\n  - a: 1\n    d: 2\n  - {a: 3}\n")
    assert doc.line_of("joints") == 2
    assert doc.line_of("joints[0].d") == 4
    assert doc.line_of("joints[1].a") == 5
    assert doc.line_of("joints[7].a") == 2  # the deepest part that exists
    assert doc.line_of("nosuch") is None


@pytest.mark.parametrize(("content", "message"), [
    (b"name: x\n\x00\x01\x02", r"bad\.yaml:2: is a binary file"),
    (b"name: \xff\xfe\n", r"bad\.yaml:1: is not UTF-8"),
])
def test_binary_files_are_refused(tmp_path, content, message):
    p = tmp_path / "bad.yaml"
    p.write_bytes(content)
    with pytest.raises(ModelError, match=message):
        read_yaml_document(p)


def test_folders_missing_and_oversized_files_are_refused(tmp_path):
    with pytest.raises(ModelError, match="is a folder"):
        read_yaml_document(tmp_path)
    with pytest.raises(ModelError, match="no such file"):
        read_yaml_document(tmp_path / "gone.yaml")
    p = tmp_path / "big.yaml"
    p.write_text("a: " + "x" * 2000 + "\n")
    with pytest.raises(ModelError, match=r"2,004 bytes, more than the 1,000"):
        read_yaml_document(p, max_bytes=1000)


def test_only_safe_tags():
    with pytest.raises(ModelError, match="not valid YAML"):
        parse_yaml("a: !!python/object/apply:os.system ['echo hi']\n")
