"""The layers point one way (issue 14, item 4): checked on the parsed source.

``model/`` describes arms and imports nothing from the layers above it; ``robot.py``
imports ``io/`` only inside methods (``Robot.from_urdf``); ``io/`` imports nothing
from the layers that sit on top of it. Every ``import`` statement counts,
including those inside functions and ``if TYPE_CHECKING:`` blocks.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import robokin

SRC = Path(robokin.__file__).parent


def imported_modules(source: str, *, top_level_only: bool = False) -> set[str]:
    """Every robokin module an ``import`` in ``source`` names (relative ones too)."""
    tree = ast.parse(source)
    nodes = tree.body if top_level_only else list(ast.walk(tree))
    out: set[str] = set()
    for node in nodes:
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = "robokin.<relative>." + base
            out.add(base)
            out.update(f"{base}.{a.name}" for a in node.names)
    return {m for m in out if m.startswith("robokin")}


def _offending(folder: Path, forbidden: tuple[str, ...], *, top_level_only=False):
    bad = []
    files = [folder] if folder.is_file() else sorted(folder.rglob("*.py"))
    for path in files:
        for mod in imported_modules(path.read_text(encoding="utf-8"),
                                    top_level_only=top_level_only):
            if mod.startswith("robokin.<relative>") or any(
                    mod == f or mod.startswith(f + ".") for f in forbidden):
                bad.append(f"{path.relative_to(SRC)} imports {mod}")
    return bad


def test_the_checker_finds_imports_anywhere_in_a_module():
    # a checker that cannot fail proves nothing: plant each kind of import
    planted = (
        "from typing import TYPE_CHECKING\n"
        "if TYPE_CHECKING:\n    from robokin.robot import Robot\n"
        "def f():\n    import robokin.io.robot_files as rf\n"
        "    from robokin import viz\n"
        "class C:\n    def g(self):\n        from robokin.kinematics.forward import x\n"
    )
    found = imported_modules(planted)
    assert {"robokin.robot", "robokin.io.robot_files", "robokin.viz",
            "robokin.kinematics.forward"} <= found
    assert imported_modules(planted, top_level_only=True) == set()


def test_model_imports_nothing_above_it():
    forbidden = ("robokin.robot", "robokin.io", "robokin.kinematics", "robokin.viz",
                 "robokin.collision", "robokin.trajectory", "robokin.cli",
                 "robokin.robots", "robokin.demo")
    assert _offending(SRC / "model", forbidden) == []


@pytest.mark.parametrize("module", ["robot.py", "kinematics", "model", "spatial.py",
                                    "_validation.py", "exceptions.py"])
def test_modules_below_io_do_not_import_it_at_module_level(module):
    assert _offending(SRC / module, ("robokin.io",), top_level_only=True) == []


def test_io_imports_nothing_from_the_layers_on_top():
    forbidden = ("robokin.viz", "robokin.collision", "robokin.cli", "robokin.demo")
    assert _offending(SRC / "io", forbidden) == []
