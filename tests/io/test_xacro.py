"""xacro import (issue 19, item 1): rtb-data's vendor xacros against pinocchio on the
expanded URDF, xacro arguments, package resolution (package map, ROS_PACKAGE_PATH,
AMENT_PREFIX_PATH, package.xml above the file) and the error messages."""

import os
from pathlib import Path

import numpy as np
import pytest

import robokin
from robokin.exceptions import InputError, ModelError

pytest.importorskip("yourdfpy")
pytest.importorskip("xacro")
from reference import pin_fk  # noqa: E402
from robokin import Robot  # noqa: E402
from robokin.io.ros_packages import PackageFinder  # noqa: E402
from robokin.io.xacro import expand_xacro, is_xacro  # noqa: E402

DEMO = Path(__file__).parent.parent / "data" / "xacro" / "demo_description"
ARM = DEMO / "urdf" / "arm.urdf.xacro"


def rtb_xacro() -> Path:
    rtbdata = pytest.importorskip("rtbdata")
    return Path(rtbdata.__file__).parent / "xacro"


def assert_fk_matches_pinocchio(robot, rng, m=25):
    xml = robot.meta["xacro"].urdf
    lim = np.clip(robot.limits, -3.0, 3.0)
    q = rng.uniform(lim[:, 0], lim[:, 1], (m, robot.n))
    T = robot.fk(q)
    tip = robot.meta["urdf"].tip_link
    for qi, Ti in zip(q, T):
        ref = pin_fk(xml, tip, dict(zip(robot.joint_names, qi)))
        np.testing.assert_allclose(Ti, ref, atol=1e-12)


@pytest.mark.parametrize(
    ("xacro", "packages", "n_meshes"),
    [
        ("abb_irb140_description/urdf/irb140.xacro",
         {"abb_irb140": "abb_irb140_description"}, 14),
        ("kuka_description/kuka_kr6/urdf/kr6r700sixx.xacro",
         {"kuka_kr6_support": "kuka_description/kuka_kr6",
          "kuka_resources": "kuka_description/kuka_resources"}, 14),
    ],
)
def test_vendor_xacro_fk_matches_pinocchio_on_the_expanded_urdf(xacro, packages,
                                                                 n_meshes, rng):
    root = rtb_xacro()
    pmap = {k: root / v for k, v in packages.items()}
    robot = robokin.Robot.from_urdf(root / xacro, package_map=pmap, tip_link="tool0")
    assert robot.n == 6 and robot.meta["urdf"].tip_link == "tool0"
    assert robot.source.startswith("xacro ")
    assert_fk_matches_pinocchio(robot, rng)
    # every package:// mesh resolved through the package map: nothing dropped
    assert robot.meta["urdf_dropped_shapes"] == ()
    meshes = [s for s in robot.meta["urdf_shapes"] if s["type"] == "mesh"]
    assert len(meshes) == n_meshes
    assert all(Path(s["filename"]).is_file() for s in meshes)


def ros_tree(tmp_path: Path, name: str, target: Path) -> Path:
    """A ROS workspace folder holding package ``name`` (a package.xml, links inside)."""
    pkg = tmp_path / "ws" / "src" / name
    pkg.mkdir(parents=True)
    (pkg / "package.xml").write_text(f"<package format='3'><name>{name}</name></package>")
    for child in target.iterdir():
        (pkg / child.name).symlink_to(child)
    return tmp_path / "ws"


def test_ros_package_path_finds_find_and_package_uris(tmp_path, monkeypatch, rng):
    root = rtb_xacro() / "abb_irb140_description"
    ws = ros_tree(tmp_path, "abb_irb140", root)
    (tmp_path / "ws" / "ignored").mkdir()
    (tmp_path / "ws" / "ignored" / "CATKIN_IGNORE").write_text("")
    monkeypatch.setenv("ROS_PACKAGE_PATH", f"{tmp_path / 'empty'}{os.pathsep}{ws}")
    robot = robokin.Robot.from_urdf(root / "urdf" / "irb140.xacro")
    assert robot.meta["urdf_dropped_shapes"] == ()
    assert robot.meta["xacro"].packages.find("abb_irb140") == ws / "src" / "abb_irb140"
    assert_fk_matches_pinocchio(robot, rng, m=5)
    # the package map wins over ROS_PACKAGE_PATH
    finder = PackageFinder({"abb_irb140": root}, near=None)
    assert finder.find("abb_irb140") == root


def test_ament_prefix_path_and_package_xml_above_the_file(tmp_path, monkeypatch):
    share = tmp_path / "install" / "share" / "demo_meshes"
    (share / "meshes").mkdir(parents=True)
    (share / "package.xml").write_text("<package><name>demo_meshes</name></package>")
    (share / "meshes" / "link_3.stl").write_bytes((DEMO / "meshes" / "cube.stl").read_bytes())
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(tmp_path / "install"))
    # $(find demo_description): the package.xml above arm.urdf.xacro names it
    robot = Robot.from_urdf(ARM, missing_mesh="error")
    files = {Path(s["filename"]) for s in robot.meta["urdf_shapes"] if s["type"] == "mesh"}
    assert files == {DEMO / "meshes" / "cube.stl", share / "meshes" / "link_3.stl"}


def test_xacro_args_change_the_model_and_unknown_ones_are_refused(rng):
    with pytest.warns(UserWarning, match="package 'demo_meshes' not found"):
        short = Robot.from_urdf(ARM)
    long = Robot.from_urdf(ARM, xacro_args={"upper_length": "0.6", "prefix": "left_"},
                           missing_mesh="ignore")
    assert long.joint_names == ("left_joint_1", "left_joint_2", "left_joint_3")
    assert "upper_length:=0.6" in long.source
    # q = 0: the tool hangs 0.2 m higher with the longer upper arm
    np.testing.assert_allclose(long.fk(np.zeros(3))[:3, 3] - short.fk(np.zeros(3))[:3, 3],
                               [0, 0, 0.2], atol=1e-12)
    np.testing.assert_allclose(long.limits, np.radians([[-170, 170]] * 3), atol=1e-12)
    assert_fk_matches_pinocchio(long, rng, m=10)
    with pytest.raises(InputError, match=r"declares no argument 'lenght'; it declares "
                                         r"\['prefix', 'upper_length'\]"):
        Robot.from_urdf(ARM, xacro_args={"lenght": "1"})
    with pytest.raises(InputError, match="not a xacro file"):
        Robot.from_urdf(DEMO.parent.parent / "urdf" / "ur5.urdf", xacro_args={"a": "1"})


def test_missing_package_names_it_and_lists_the_search_path(tmp_path, monkeypatch):
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path))
    root = rtb_xacro() / "abb_irb140_description"
    with pytest.raises(ModelError) as err:
        Robot.from_urdf(root / "urdf" / "irb140.xacro", package_map={"other": tmp_path})
    msg = str(err.value)
    assert msg.startswith(f"{root / 'urdf' / 'irb140.xacro'}: $(find abb_irb140): "
                          "package 'abb_irb140' not found; searched the package map "
                          "(other); ROS_PACKAGE_PATH=" + str(tmp_path))
    assert f"package.xml files in {root / 'urdf'} and the folders above it" in msg
    assert "--package abb_irb140=DIR" in msg
    with pytest.raises(InputError, match="package 'abb_irb140': no such folder"):
        Robot.from_urdf(root / "urdf" / "irb140.xacro",
                        package_map={"abb_irb140": tmp_path / "nowhere"})


def write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


HEAD = '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'


@pytest.mark.parametrize(
    ("body", "where", "match"),
    [
        ('  <link name="a"/>\n  <link name="${undefined_length}"/>\n</robot>\n', ":4:",
         "name 'undefined_length' is not defined"),
        ('  <xacro:macro name="m" params="a">\n    <link name="${a * b}"/>\n'
         '  </xacro:macro>\n  <xacro:m a="1"/>\n</robot>\n', ":4:",
         r"name 'b' is not defined .* \(in macro m\)"),
        ('  <link name="$(arg nope)"/>\n</robot>\n', ":3:",
         "Undefined substitution argument nope"),
        ('  <link name="a">\n</robot>\n', ":4:", "not valid XML"),
        ('  <xacro:include filename="gone.xacro"/>\n</robot>\n', ": xacro",
         r"cannot include .*gone.xacro: No such file"),
    ],
)
def test_xacro_errors_name_the_file_and_line(tmp_path, body, where, match):
    f = write(tmp_path / "bad.urdf.xacro", HEAD + body)
    with pytest.raises(ModelError, match=match) as err:
        expand_xacro(f)
    assert str(err.value).startswith(f"{f}{where}")


def test_an_error_inside_an_included_file_names_that_file(tmp_path):
    write(tmp_path / "inc.xacro", '<?xml version="1.0"?>\n<robot>\n  <link name="x">\n'
          '</robot>\n')
    f = write(tmp_path / "top.xacro",
              HEAD + '  <xacro:include filename="inc.xacro"/>\n</robot>\n')
    with pytest.raises(ModelError, match=r"inc.xacro:4: not valid XML"):
        expand_xacro(f)


def test_an_expanded_urdf_error_names_the_xacro(tmp_path):
    f = write(tmp_path / "bad.urdf.xacro", HEAD + '  <link name="a"/><link name="b"/>\n'
              '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
              '</joint>\n</robot>\n')
    with pytest.raises(ModelError, match=r"bad.urdf.xacro: joint\[j\].limit: .*"
                                         r"\(line \d+ of the URDF expanded from it\)"):
        Robot.from_urdf(f)


def test_is_xacro_and_xacro_warnings(tmp_path):
    assert is_xacro("arm.urdf.xacro") and is_xacro(Path("a.XACRO"))
    assert not is_xacro("<robot name='x.xacro'/>") and not is_xacro(b"x.xacro")
    assert not is_xacro("arm.urdf")
    f = write(tmp_path / "w.xacro", HEAD + '  <xacro:property name="len" value="1"/>\n'
              '  <link name="a"/>\n</robot>\n')
    with pytest.warns(UserWarning, match="xacro: redefining global symbol: len"):
        expand_xacro(f)


def test_cli_import_xacro_notes_each_dropped_mesh(tmp_path, capsys, monkeypatch):
    from robokin.cli import main

    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("AMENT_PREFIX_PATH", raising=False)
    out = tmp_path / "arm.yaml"
    code = main(["import", str(ARM), "--arg", "upper_length=0.6", "--arg", "prefix=r_",
                 "--package", f"demo_description={DEMO}", "-o", str(out)])
    text, err = capsys.readouterr()
    assert code == 0, err
    notes = err.splitlines()
    assert len(notes) == 1 and notes[0].startswith(
        "robokin: note: left out link 'r_link_3' collision mesh "
        "'package://demo_meshes/meshes/link_3.stl': package 'demo_meshes' not found")
    assert "r_base_link -> r_tool0" in text
    loaded = robokin.load(out)
    direct = Robot.from_urdf(ARM, xacro_args={"upper_length": "0.6", "prefix": "r_"},
                             missing_mesh="ignore")
    q = np.random.default_rng(3).uniform(-2, 2, (10, 3))
    np.testing.assert_allclose(loaded.fk(q), direct.fk(q), atol=1e-12)
    # a missing package: one line, exit code 2
    code = main(["import", str(rtb_xacro() / "abb_irb140_description" / "urdf" /
                                "irb140.xacro")])
    _, err = capsys.readouterr()
    assert code == 2 and len(err.splitlines()) == 1
    assert "package 'abb_irb140' not found; searched" in err
    code = main(["import", str(ARM), "--arg", "upper_length"])
    _, err = capsys.readouterr()
    assert code == 2 and "--arg expects NAME=VALUE" in err


def test_cli_dh_reads_a_xacro(capsys, tmp_path):
    import json

    from robokin.cli import main

    root = rtb_xacro() / "abb_irb140_description"
    xacro = root / "urdf" / "irb140.xacro"
    code = main(["dh", str(xacro), "--package", f"abb_irb140={root}", "--mm", "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    expanded = tmp_path / "irb140.urdf"
    expanded.write_text(expand_xacro(xacro, package_map={"abb_irb140": root}).urdf)
    code = main(["dh", str(expanded), "--mm", "--json"])
    same, _ = capsys.readouterr()
    assert code == 0 and json.loads(out)["rows"] == json.loads(same)["rows"]
    assert len(json.loads(out)["rows"]) == 6


# ------------------------------------------- issue 25: xacro is a program, bounded
BOMBS = {
    # 9**387420489: computed until killed (CPU)
    "power": HEAD + '  <link name="${9**9**9}"/>\n</robot>\n',
    # a 200 MB string from a 126-byte file (it took 625 MB)
    "repeat": HEAD + "  <link name=\"${'a'*(2*10**8)}\"/>\n</robot>\n",
    # 1.6 KB of properties, each twice the one before: 16 B x 2**28 = 4 GiB
    "chain": HEAD + '  <xacro:property name="p0" value="aaaaaaaaaaaaaaaa"/>\n'
    + "".join(f'  <xacro:property name="p{i}" value="${{p{i - 1}}}${{p{i - 1}}}"/>\n'
              for i in range(1, 29)) + '  <link name="${p28}"/>\n</robot>\n',
}

BOMB_RUN = """
import json, resource, sys, time
from robokin.io.xacro import expand_xacro
t = time.monotonic()
try:
    expand_xacro(sys.argv[1])
    error = None
except Exception as exc:
    error = f"{type(exc).__name__}: {exc}"
print(json.dumps({"seconds": time.monotonic() - t, "error": error,
                  "child_peak_mb": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
                  / 1024}))
"""


@pytest.mark.parametrize("bomb", sorted(BOMBS))
def test_xacro_bombs_end_in_seconds_and_megabytes_with_an_error(tmp_path, bomb):
    """Issue 25: these ran until killed, took 625 MB, or 20 s and 3 GB. Each now ends
    with one ModelError naming the file and the limit it hit, the expansion call in
    under 5 s (its wall-clock limit is 3 s) and the expanding child's peak RSS under
    300 MB (it may add 192 MiB to the ~35 MB it starts with). Measured in a fresh
    interpreter: RUSAGE_CHILDREN is the expanding child alone."""
    import json
    import subprocess
    import sys

    f = write(tmp_path / f"{bomb}.urdf.xacro", BOMBS[bomb])
    assert f.stat().st_size < 2000
    res = subprocess.run([sys.executable, "-c", BOMB_RUN, str(f)], capture_output=True,
                         text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    out = json.loads(res.stdout)
    assert out["error"] is not None and out["error"].startswith(
        f"ModelError: {f}: xacro: expanding this file ")
    assert any(limit in out["error"] for limit in (
        "of CPU time, its limit", "MiB of memory, its limit", "(wall clock), its limit"))
    assert "robokin.io.xacro.LIMITS" in out["error"]
    assert out["seconds"] < 5.0
    assert 0 < out["child_peak_mb"] < 300


def test_each_limit_is_named(tmp_path):
    """CPU time (a limit of 1 s CPU, 60 s wall), memory (a 2 GB string) and the wall
    clock (an include of a FIFO nothing writes: the child waits forever)."""
    from robokin.io.xacro import XacroLimits

    power = write(tmp_path / "power.xacro", BOMBS["power"])
    with pytest.raises(ModelError, match=r"power.xacro: xacro: expanding this file used "
                                         r"more than 1 s of CPU time, its limit"):
        expand_xacro(power, limits=XacroLimits(cpu_seconds=1, wall_seconds=60))
    big = write(tmp_path / "big.xacro",
                HEAD + "  <link name=\"${'a'*(2*10**9)}\"/>\n</robot>\n")
    with pytest.raises(ModelError, match=r"needed more than 64 MiB of memory, its limit"):
        expand_xacro(big, limits=XacroLimits(memory_mb=64))
    fifo = tmp_path / "part.xacro"
    os.mkfifo(fifo)
    waits = write(tmp_path / "waits.xacro",
                  HEAD + '  <xacro:include filename="part.xacro"/>\n</robot>\n')
    with pytest.raises(ModelError, match=r"waits.xacro: xacro: expanding this file took "
                                         r"more than 0.5 s \(wall clock\), its limit"):
        expand_xacro(waits, limits=XacroLimits(wall_seconds=0.5))


def test_an_include_of_dev_zero_is_bounded(tmp_path):
    """/dev/zero never ends: expat refuses its first byte (inside the limits)."""
    (tmp_path / "zero.xacro").symlink_to("/dev/zero")
    f = write(tmp_path / "z.xacro", HEAD + '  <xacro:include filename="zero.xacro"/>\n'
              '</robot>\n')
    with pytest.raises(ModelError, match=r"zero.xacro:1: not valid XML"):
        expand_xacro(f)


def test_limits_are_checked():
    from robokin.io.xacro import XacroLimits

    for bad in ({"cpu_seconds": 0}, {"cpu_seconds": 1.5}, {"wall_seconds": 0},
                {"wall_seconds": float("nan")}, {"memory_mb": 1}):
        with pytest.raises(InputError, match="argument 'limits'"):
            XacroLimits(**bad)
    with pytest.raises(InputError, match="expected an XacroLimits"):
        expand_xacro(ARM, limits={"cpu_seconds": 1})


def test_the_child_answers_as_the_expansion_in_this_process(rng):
    """Oracle: the URDF expanded in this process by the same code (robokin's
    _expand), character for character; the packages the child found are known to
    the finder the caller keeps."""
    from robokin.io.xacro import _expand

    pmap = {"demo_description": DEMO}
    child = expand_xacro(ARM, package_map=pmap, args={"prefix": "x_"})
    here = _expand(ARM, {"prefix": "x_"}, PackageFinder(pmap, near=ARM))
    assert child.urdf == here[0] and child.includes == here[1]
    assert child.packages.lookups()["demo_description"] == str(DEMO)
    assert {p.name for p in child.includes} == {"parts.xacro", "limits.xacro"}


def test_a_relative_path_and_package_map_expand(monkeypatch):
    """A relative package folder made $(find) return a relative path, which xacro
    read against the including file's folder (the path twice)."""
    monkeypatch.chdir(DEMO.parent)
    out = expand_xacro(Path("demo_description/urdf/arm.urdf.xacro"),
                       package_map={"demo_description": "demo_description"})
    assert "joint_1" in out.urdf
