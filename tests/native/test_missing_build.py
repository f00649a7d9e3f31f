"""``import robokin`` from a tree whose kernels were never built (issue 25).

The error says what to do: build in the source tree (which needs a C compiler and
the Python headers) or install a wheel robokin's own script builds; it suggests no
package index download that does not exist. The oracle is a real import of a copy
of the package without its compiled modules, in a fresh interpreter.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import robokin

SRC = Path(robokin.__file__).resolve().parent


def test_an_unbuilt_tree_says_how_to_build_it(tmp_path):
    shutil.copytree(SRC, tmp_path / "robokin",
                    ignore=shutil.ignore_patterns("*.so", "*.pyd", "__pycache__"))
    env = dict(os.environ, PYTHONPATH=str(tmp_path))
    proc = subprocess.run([sys.executable, "-c", "import robokin"], cwd=tmp_path,
                          env=env, capture_output=True, text=True, timeout=120,
                          check=False)
    assert proc.returncode != 0
    last = proc.stderr.strip().splitlines()[-1]
    assert last.startswith("ImportError: robokin's compiled kernels")
    assert str(tmp_path / "robokin" / "_native") in last
    for needed in ("pip install -e .", "C compiler", "Python headers", ".ci/wheel"):
        assert needed in last, needed
    assert "--no-binary" not in last and "use a wheel" not in last
