"""calibration/ sits on top: nothing in the core imports it; importing robokin loads none of it."""

from __future__ import annotations

import subprocess
import sys

from ..test_layers import SRC, imported_modules


def test_nothing_below_imports_calibration():
    bad = []
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC).as_posix()
        if rel.startswith("calibration/") or rel == "cli_calibrate.py":
            continue
        mods = imported_modules(path.read_text(encoding="utf-8"))
        if any(m == "robokin.calibration" or m.startswith("robokin.calibration.")
               for m in mods):
            bad.append(rel)
    assert bad == []


def test_import_robokin_does_not_load_calibration():
    code = ("import sys, robokin; robokin.load('ur5'); "
            "print(any(m.startswith('robokin.calibration') for m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "False"
