"""``cell/`` sits on top, beside ``collision/`` and ``viz/``: nothing below imports it,
and ``import robokin.cell`` needs no Dask until a map or a placement runs (issue 16)."""

import subprocess
import sys

from test_layers import SRC, _offending


def test_nothing_below_imports_cell():
    for below in ("model", "kinematics", "io", "collision", "trajectory", "robot.py",
                  "spatial.py", "viz"):
        assert _offending(SRC / below, ("robokin.cell",)) == [], below


def test_importing_cell_loads_neither_dask_nor_zarr():
    code = ("import sys, robokin.cell; "
            "print(sorted(m for m in ('dask', 'distributed', 'zarr') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.strip() == "[]"


def test_a_missing_extra_names_it():
    # an interpreter where dask cannot be imported (sys.modules entry None)
    code = ("import sys; sys.modules['dask'] = None\n"
            "import robokin\nfrom robokin import cell\n"
            "try:\n    cell.reach_map(robokin.load('ur5'), voxel=0.5)\n"
            "except robokin.MissingExtraError as e:\n    print(e)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert "pip install 'robokin[scale]'" in out and "'dask'" in out
