"""The layers point one way (issue 14 item 4, issue 24 item 3): checked on the source.

Every robokin import of every module counts: at module level, inside functions and
methods, under ``if TYPE_CHECKING:``, and the module names given to
``importlib.import_module`` / ``__import__`` as text. Each module belongs to one
layer (:data:`LAYERS`, the picture of ``docs/conventions.md``, "Layers"), and an
import must stay inside its layer or follow an arrow of :data:`ALLOWED`. Apart from
that, no module may reach itself through imports (no cycle, inside a layer too).

The oracle is the parsed source, not a run: a forbidden import that only happens in
a rarely called function is found all the same. The checker itself is checked on
planted code (it must find what it is there to find).
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

import pytest

import robokin

SRC = Path(robokin.__file__).parent

#: Layer -> the modules (dotted prefixes) it holds. ``robokin`` is the package root
#: (``robokin/__init__.py``): the public face, with the command line.
LAYERS: dict[str, tuple[str, ...]] = {
    "native": ("robokin._native",),
    "spatial": ("robokin.spatial", "robokin._validation", "robokin._text",
                "robokin.exceptions", "robokin._html", "robokin._units"),
    "model": ("robokin.model",),
    "arm": ("robokin.kinematics.arm",),
    "kinematics": ("robokin.kinematics",),
    "io": ("robokin.io",),
    "robot": ("robokin.robot", "robokin.robots"),
    "trajectory": ("robokin.trajectory",),
    "collision": ("robokin.collision",),
    "planning": ("robokin.planning",),
    "process": ("robokin.process",),
    "calibration": ("robokin.calibration",),
    "viz": ("robokin.viz",),
    "cell": ("robokin.cell",),
    "sim": ("robokin.sim",),
    "face": ("robokin.cli", "robokin.__main__", "robokin"),
}

_CORE = ("native", "spatial", "model", "arm", "kinematics", "io", "robot")
#: Layer -> the other layers it may import. The core (native, spatial, model,
#: kinematics, io, robot) imports nothing above it; io never imports robot.py.
#: The per-arm state (``kinematics.arm``) sits under the rest of kinematics: the
#: modules that fill it import it, it imports none of them (not even for types).
ALLOWED: dict[str, frozenset[str]] = {
    "native": frozenset(),
    "spatial": frozenset({"native"}),
    "model": frozenset({"spatial", "native"}),
    "arm": frozenset({"model", "spatial", "native"}),
    "kinematics": frozenset({"arm", "model", "spatial", "native"}),
    "io": frozenset({"model", "spatial", "native"}),
    "robot": frozenset({"io", "arm", "kinematics", "model", "spatial", "native"}),
    "trajectory": frozenset(_CORE),
    "collision": frozenset(_CORE),
    "planning": frozenset({*_CORE, "trajectory", "collision"}),
    "process": frozenset({*_CORE, "trajectory", "collision", "viz"}),
    "calibration": frozenset({*_CORE, "trajectory"}),
    "viz": frozenset({*_CORE, "trajectory", "collision"}),
    "cell": frozenset({*_CORE, "trajectory", "collision", "viz"}),
    "sim": frozenset({*_CORE, "trajectory", "collision", "viz"}),
    "face": frozenset(set(LAYERS) - {"face"}),
}


def layer_of(module: str) -> str:
    """The layer of a dotted module name (the longest matching prefix)."""
    best, size = "", -1
    for layer, prefixes in LAYERS.items():
        for p in prefixes:
            if (module == p or module.startswith(p + ".")) and len(p) > size:
                best, size = layer, len(p)
    if not best:
        raise AssertionError(f"{module} is in no layer: add it to LAYERS")
    return best


def _module_name(path: Path, root: Path) -> str:
    parts = list(path.relative_to(root.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def source_modules(root: Path = SRC) -> dict[str, Path]:
    """Every module of the package: dotted name -> file."""
    return {_module_name(p, root): p for p in sorted(root.rglob("*.py"))}


def imports_of(module: str, source: str, known: set[str], *, is_package: bool = False
               ) -> list[tuple[str, int]]:
    """``(imported robokin module, line)`` for every import anywhere in ``source``.

    ``from a import b`` names the module ``a.b`` when that is a module, else ``a``;
    relative imports are resolved against ``module``; the text given to
    ``importlib.import_module`` and ``__import__`` counts as an import. A name
    that is not a module is reduced to the longest module it starts with.
    """
    found: list[tuple[str, int]] = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found += [(a.name, node.lineno) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                package = module.split(".") if is_package else module.split(".")[:-1]
                package = package[: len(package) - (node.level - 1)]
                base = ".".join(package + ([base] if base else []))
            for a in node.names:
                full = f"{base}.{a.name}"
                found.append((full if full in known else base, node.lineno))
        elif isinstance(node, ast.Call) and node.args:
            func = node.func
            name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
            arg = node.args[0]
            if name in ("import_module", "__import__") and isinstance(arg, ast.Constant) \
                    and isinstance(arg.value, str):
                found.append((arg.value, node.lineno))
    out = []
    for name, line in found:
        if name != "robokin" and not name.startswith("robokin."):
            continue
        parts = name.split(".")
        while parts and ".".join(parts) not in known:
            parts.pop()
        target = ".".join(parts)
        if target and target != module and (target, line) not in out:
            out.append((target, line))
    return out


def import_graph(root: Path = SRC) -> dict[str, list[tuple[str, int]]]:
    """Module -> the robokin modules it imports, with the line of each import."""
    modules = source_modules(root)
    known = set(modules)
    return {m: imports_of(m, p.read_text(encoding="utf-8"), known,
                          is_package=p.name == "__init__.py")
            for m, p in modules.items()}


def layer_violations(graph: dict[str, list[tuple[str, int]]]) -> list[str]:
    """Every import that leaves its layer against the arrows of :data:`ALLOWED`."""
    bad = []
    for module, targets in sorted(graph.items()):
        here = layer_of(module)
        for target, line in targets:
            there = layer_of(target)
            if there != here and there not in ALLOWED[here]:
                bad.append(f"{module}:{line} imports {target} ({here} -> {there})")
    return bad


def cycles(graph: dict[str, list[tuple[str, int]]]) -> list[list[str]]:
    """The import cycles: strongly connected groups of two or more modules."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w, _ in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                found.append(sorted(group))

    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(max(limit, 10 * len(graph) + 100))
    try:
        for v in sorted(graph):
            if v not in index:
                visit(v)
    finally:
        sys.setrecursionlimit(limit)
    return found


def _offending(folder: Path, forbidden: tuple[str, ...]) -> list[str]:
    """The imports, anywhere in the modules under ``folder`` (a file or a folder of
    ``SRC``), of a module under one of the ``forbidden`` dotted prefixes.

    Used by the per-package layer tests (``tests/sim``, ``tests/cell``, ...).
    """
    modules = source_modules()
    graph = import_graph()
    inside = {m for m, p in modules.items()
              if p == folder or folder in p.parents}
    return [f"{m}:{line} imports {t}" for m in sorted(inside) for t, line in graph[m]
            if any(t == f or t.startswith(f + ".") for f in forbidden)]


# ----------------------------------------------------------------- the checker
PLANTED = {
    "robokin/__init__.py": "",
    "robokin/model/__init__.py": "",
    "robokin/model/chain.py": (
        "from typing import TYPE_CHECKING\n"
        "if TYPE_CHECKING:\n    from robokin.robot import Robot\n"      # model -> robot
    ),
    "robokin/model/dh.py": "from . import chain\n",
    "robokin/io/__init__.py": "",
    "robokin/io/files.py": (
        "def f():\n    import robokin.viz.plots as p\n"                   # io -> viz
        "class C:\n    def g(self):\n        from ..trajectory import path\n"
        "def h():\n    import importlib\n"
        "    return importlib.import_module('robokin.robot')\n"            # io -> robot
    ),
    "robokin/io/a.py": "from robokin.io import b\n",
    "robokin/io/b.py": "def f():\n    from robokin.io.a import x\n",     # a <-> b
    "robokin/robot.py": "from robokin.io import files\nimport robokin\n",  # -> root
    "robokin/viz/__init__.py": "",
    "robokin/viz/plots.py": "",
    "robokin/trajectory/__init__.py": "",
    "robokin/trajectory/path.py": "",
}


@pytest.fixture
def planted(tmp_path: Path) -> Path:
    for rel, text in PLANTED.items():
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text(text)
    return tmp_path / "robokin"


def test_the_checker_finds_imports_anywhere_in_a_module(planted):
    # a checker that cannot fail proves nothing: plant each kind of import
    graph = import_graph(planted)
    assert graph["robokin.model.chain"] == [("robokin.robot", 3)]
    assert graph["robokin.model.dh"] == [("robokin.model.chain", 1)]
    assert sorted(graph["robokin.io.files"]) == [
        ("robokin.robot", 8), ("robokin.trajectory.path", 5), ("robokin.viz.plots", 2)]
    assert sorted(graph["robokin.robot"]) == [("robokin", 2), ("robokin.io.files", 1)]


def test_the_checker_names_every_forbidden_arrow_and_cycle(planted):
    graph = import_graph(planted)
    assert layer_violations(graph) == [
        "robokin.io.files:2 imports robokin.viz.plots (io -> viz)",
        "robokin.io.files:5 imports robokin.trajectory.path (io -> trajectory)",
        "robokin.io.files:8 imports robokin.robot (io -> robot)",
        "robokin.model.chain:3 imports robokin.robot (model -> robot)",
        "robokin.robot:2 imports robokin (robot -> face)",
    ]
    assert cycles(graph) == [["robokin.io.a", "robokin.io.b"],
                             ["robokin.io.files", "robokin.robot"]]


# ------------------------------------------------------------------- the tree
def test_every_module_is_in_a_layer():
    for module in source_modules():
        layer_of(module)  # raises naming the module


def test_every_import_follows_the_arrows_of_the_layers():
    assert layer_violations(import_graph()) == []


def test_no_module_reaches_itself_through_imports():
    assert cycles(import_graph()) == []


def test_the_core_imports_nothing_from_the_layers_on_top():
    # the same rule as above, said once more as DESIGN.md says it
    top = ("robokin.viz", "robokin.trajectory", "robokin.cli", "robokin.collision",
           "robokin.cell", "robokin.sim", "robokin.planning", "robokin.process",
           "robokin.calibration")
    graph = import_graph()
    bad = [f"{m}:{line} imports {t}" for m, targets in graph.items()
           if layer_of(m) in _CORE for t, line in targets
           if t == "robokin" or t.startswith(top)]
    assert bad == []
