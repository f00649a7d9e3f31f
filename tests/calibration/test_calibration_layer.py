"""calibration/ sits on top: nothing below imports it; importing robokin loads none of it.

Oracle: the parsed source (tests/test_layers.py's import graph, every import of every
module counted) and a fresh interpreter's ``sys.modules``.
"""

from __future__ import annotations

import subprocess
import sys

from test_layers import import_graph, layer_of


def test_only_the_face_imports_calibration():
    # the package root and cli/ may; nothing in any other layer
    bad = [f"{m}:{line} imports {t}" for m, targets in import_graph().items()
           if layer_of(m) not in ("calibration", "face") for t, line in targets
           if layer_of(t) == "calibration"]
    assert bad == []


def test_the_command_is_the_one_face_module_that_imports_it():
    users = {m for m, targets in import_graph().items() if layer_of(m) == "face"
             and any(layer_of(t) == "calibration" for t, _ in targets)}
    assert users == {"robokin.cli.calibrate"}


def test_import_robokin_does_not_load_calibration():
    code = ("import sys, robokin; robokin.load('ur5'); "
            "print(any(m.startswith('robokin.calibration') for m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "False"
