"""Every example script compiles, has the documented shape, and runs headless.

An example that imports a robokin name that does not exist fails; one that needs an
optional third-party package that is not installed is skipped, naming it.
"""

from __future__ import annotations

import ast
import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SCRIPTS = sorted(EXAMPLES.glob("[0-9][0-9]_*/[0-9][0-9]_*.py"))


def _missing_imports(tree: ast.Module) -> list[str]:
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module)
            for a in node.names:  # ``from robokin import collision`` imports a module
                if node.module.startswith("robokin"):
                    names.add(f"{node.module}.{a.name}")
    missing = []
    for name in sorted(names):
        try:
            found = importlib.util.find_spec(name) is not None
        except (ImportError, ValueError):
            found = False
        if not found and not (name.startswith("robokin.") and _is_attribute(name)):
            missing.append(name)
    return missing


def _is_attribute(name: str) -> bool:
    """``robokin.x.y`` where y is a name defined in module robokin.x, not a module."""
    parent, _, attr = name.rpartition(".")
    try:
        mod = importlib.import_module(parent)
    except ImportError:
        return False
    return hasattr(mod, attr)


def test_there_are_examples():
    assert len(SCRIPTS) >= 6
    folders = {p.parent.name for p in SCRIPTS}
    assert {"00_modelling", "01_kinematics", "02_motion", "03_collision"} <= folders


def test_example_folders_are_numbered_uniquely():
    """Issue 25: two folders were numbered 05_."""
    folders = sorted(p.name for p in EXAMPLES.iterdir() if p.is_dir()
                     and not p.name.startswith((".", "__")))
    numbers = [name.split("_", 1)[0] for name in folders]
    assert all(n.isdigit() and len(n) == 2 for n in numbers), folders
    assert len(set(numbers)) == len(numbers), folders


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_example_shape(script):
    source = script.read_text()
    tree = ast.parse(source, filename=str(script))
    compile(tree, str(script), "exec")
    assert ast.get_docstring(tree), f"{script.name} needs a module docstring"
    mains = [
        n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == "main"
    ]
    assert mains, f"{script.name} needs a main()"
    main = mains[0]
    assert ast.get_docstring(main)
    assert isinstance(main.returns, ast.Constant) and main.returns.value is None, (
        f"{script.name}: main() must be typed '-> None'"
    )
    assert 'if __name__ == "__main__":' in source
    assert "# /// script" in source


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_example_runs(script, tmp_path):
    missing = _missing_imports(ast.parse(script.read_text()))
    ours = [m for m in missing if m.split(".")[0] == "robokin"]
    assert not ours, f"{script.name} imports robokin names that do not exist: {ours}"
    if missing:
        pytest.skip(f"{script.name} needs {', '.join(missing)} (not installed)")
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONHASHSEED="0")
    proc = subprocess.run(
        [sys.executable, str(script)],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert proc.returncode == 0, f"{script.name} failed:\n{proc.stdout}\n{proc.stderr}"
    assert proc.stdout.strip(), f"{script.name} printed nothing"
    assert "Traceback" not in proc.stderr
    if "out_dir" in script.read_text():  # examples that write files write them here
        written = [p for p in (tmp_path / "robokin-examples").rglob("*") if p.is_file()]
        assert written and all(p.stat().st_size > 1000 for p in written), written
