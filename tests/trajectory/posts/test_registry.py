"""The post processor registry: built-ins, register(), the entry point group.

Oracle: a real installed distribution (a .dist-info folder with entry_points.txt on
sys.path, read by importlib.metadata) declaring a dialect in
robokin.post_processors; unknown names list the valid ones.
"""

import textwrap
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pytest

from robokin.exceptions import InputError
from robokin.trajectory.posts import (
    ENTRY_POINT_GROUP,
    KukaKrl,
    PostProcessor,
    Statement,
    get_post,
    post_names,
    register,
    render_program,
    unregister,
)
from vendor_arms import PROFILES


@dataclass(frozen=True)
class PointList(PostProcessor):
    """A user's dialect: one line per target."""

    separator: str = " "
    name: ClassVar[str] = "point_list"
    title: ClassVar[str] = "point list"

    def file_names(self, name):
        return (f"{name}.txt",)

    def header(self, job):
        return [f"# {job.name}"]

    def joint_move(self, job, move, previous):
        return Statement((self.separator.join(self.angle(v) for v in move.target.joints),))

    def linear_move(self, job, move, previous):
        return Statement((self.separator.join(self.length(v) for v in move.target.position),))

    def footer(self, job):
        return []

    def assemble(self, job, code, data):
        return {f"{job.name}.txt": "\n".join(code) + "\n"}


def test_unknown_names_and_options_list_the_valid_ones():
    with pytest.raises(InputError, match=r"unknown post processor 'krl'; available: "
                       r"\['abb_rapid', 'fanuc_tp', 'kawasaki_as', 'kuka_krl'"):
        get_post("krl")
    with pytest.raises(InputError, match=r"unknown kuka_krl option\(s\) \['cnt'\]; known: "
                       r"\['length_decimals', 'angle_decimals', 'ptp_approximation'"):
        get_post("kuka_krl", cnt=3)
    with pytest.raises(InputError, match="length_decimals"):
        get_post("kuka_krl", length_decimals=12)
    assert isinstance(get_post("KUKA-KRL"), KukaKrl)


def test_register_a_dialect(arm):
    assert "point_list" not in post_names()
    try:
        register(PointList)
        assert "point_list" in post_names()
        prog = render_program(arm, np.zeros((2, 6)) + 0.1, "point_list", name="pts",
                              profile=PROFILES["kuka"], options={"separator": ";"})
        assert prog.texts["pts.txt"].splitlines()[1].count(";") == 5
        with pytest.raises(InputError, match="exists; pass replace=True"):
            register(PointList)
        register(PointList, replace=True)
    finally:
        unregister("point_list")
    assert "point_list" not in post_names()


def test_register_refuses_what_is_not_a_post_processor():
    with pytest.raises(InputError, match="expected a PostProcessor subclass"):
        register(dict)

    @dataclass(frozen=True)
    class Half(PostProcessor):
        name: ClassVar[str] = "half"

    with pytest.raises(InputError, match="does not implement"):
        register(Half)

    @dataclass(frozen=True)
    class BadName(PointList):
        name: ClassVar[str] = "Bad Name"

    with pytest.raises(InputError, match="lower-case identifier"):
        register(BadName)
    with pytest.raises(InputError, match="exists"):
        register(KukaKrl)


def test_entry_point_of_an_installed_distribution(tmp_path, monkeypatch, arm):
    pkg = tmp_path / "rk_plugin_demo"
    pkg.mkdir()
    (pkg / "__init__.py").write_text(textwrap.dedent('''
        from dataclasses import dataclass
        from typing import ClassVar
        from robokin.trajectory.posts import PostProcessor, Statement

        @dataclass(frozen=True)
        class Lines(PostProcessor):
            name: ClassVar[str] = "demo_lines"
            title: ClassVar[str] = "demo lines"
            def file_names(self, name): return (name + ".lines",)
            def header(self, job): return []
            def joint_move(self, job, move, previous):
                return Statement(("J " + " ".join(self.angle(v) for v in move.target.joints),))
            def linear_move(self, job, move, previous): return Statement(("L",))
            def footer(self, job): return []
            def assemble(self, job, code, data): return {job.name + ".lines": "\\n".join(code)}

        class Broken:  # not a post processor
            name = "demo_broken"
    '''))
    dist = tmp_path / "rk_plugin_demo-1.0.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: rk-plugin-demo\nVersion: 1.0\n")
    (dist / "entry_points.txt").write_text(
        f"[{ENTRY_POINT_GROUP}]\ndemo_lines = rk_plugin_demo:Lines\n"
        "demo_broken = rk_plugin_demo:Broken\ndemo_missing = rk_plugin_demo.nope:X\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    assert {"demo_lines", "demo_broken", "demo_missing"} <= set(post_names())
    prog = render_program(arm, np.zeros((2, 6)), "demo_lines", name="ep",
                          profile=PROFILES["kuka"])
    assert prog.texts["ep.lines"].startswith("J 0.0000 0.0000")
    with pytest.raises(InputError, match="expected a PostProcessor subclass"):
        get_post("demo_broken")
    with pytest.raises(InputError, match=r"'demo_missing' \(rk_plugin_demo.nope:X, entry point "
                       r"group robokin.post_processors\) failed to load: ModuleNotFoundError"):
        get_post("demo_missing")
