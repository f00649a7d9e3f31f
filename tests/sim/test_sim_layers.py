"""``robokin.sim`` sits on top: nothing below it imports it (issue 17)."""

from __future__ import annotations

import pytest

from test_layers import SRC, _offending


@pytest.mark.parametrize("below", ["model", "kinematics", "io", "trajectory",
                                   "collision", "robot.py", "spatial.py", "viz"])
def test_nothing_below_sim_imports_it(below):
    assert _offending(SRC / below, ("robokin.sim",)) == []


def test_sim_is_lazy_and_needs_no_mujoco_to_import_robokin():
    import subprocess
    import sys

    code = ("import sys, robokin; robokin.load('ur5'); "
            "print('mujoco' in sys.modules, 'robokin.sim' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split()
    assert out == ["False", "False"]
