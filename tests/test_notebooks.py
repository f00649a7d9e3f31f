"""Issue 19, item 4: the example notebook runs, and each object shows itself.

The notebook in ``examples/05_notebooks`` is executed in a fresh kernel
(nbclient) and its outputs are checked: the robot's joint table, the IK
solutions with branches, a batch summarised, the line's plot, the collision
verdict and the 3D view. The ``_repr_html_`` outputs stay bounded (a batch of
10^5 solutions is a few kilobytes).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import robokin

NOTEBOOKS = sorted((Path(__file__).resolve().parents[1] / "examples").glob("*/*.ipynb"))


def _html(cell) -> str:
    return "".join(o.get("data", {}).get("text/html", "") for o in cell.outputs)


@pytest.fixture(scope="module")
def executed():
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    pytest.importorskip("ipykernel")
    pytest.importorskip("coal")
    path = NOTEBOOKS[0]
    nb = nbformat.read(path, as_version=4)
    client = nbclient.NotebookClient(
        nb, timeout=300, kernel_name="python3",
        resources={"metadata": {"path": str(path.parent)}})
    client.execute()  # raises CellExecutionError, with the cell, on any error
    return [c for c in nb.cells if c.cell_type == "code"]


def test_there_is_one_example_notebook():
    assert [p.name for p in NOTEBOOKS] == ["00_robokin_in_jupyter.ipynb"]


def test_the_notebook_runs_and_shows_each_object(executed):
    robot, ik, batch, line, report, view = (_html(c) for c in executed[1:])
    assert "aubo_i5" in robot and "upper_arm" in robot and "408" in robot
    assert "joint limits" in robot and "-175" in robot
    n = int(re.search(r"(\d+) solution\(s\)", ik).group(1))
    assert n >= 2 and ik.count("shoulder ") == n  # a branch label per solution
    assert "1,000 poses" in batch and "solutions per pose" in batch
    assert "<svg" in line and "201 samples" in line
    assert "minimum distance" in report and ": OK" in report and "<svg" in report
    assert view.startswith("<iframe srcdoc=") and 'sandbox="allow-scripts"' in view
    for html in (robot, ik, batch, line, report):
        assert len(html) < 50_000
    assert len(view) < 1_000_000


def test_outputs_stay_bounded_for_big_batches():
    """10^5 solutions, 10^5 samples: a few kilobytes, not megabytes."""
    from robokin import trajectory

    robot = robokin.load("ur5")
    Q = np.random.default_rng(1).uniform(-np.pi, np.pi, (100_000, 6))
    sols = robot.ik(robot.fk(Q))
    html = sols._repr_html_()
    assert len(html) < 5_000 and "100,000 poses" in html
    one = robot.ik(robot.fk(Q[0]))._repr_html_()
    assert len(one) < 10_000
    tr = trajectory.quintic(np.zeros(6), np.ones(6), 10.0, dt=1e-4)
    assert len(tr) == 100_001 and len(tr._repr_html_()) < 40_000


def test_a_big_robot_table_is_cut_and_says_so():
    rows = [{"a": 0.1, "joint": "revolute" if k < 30 else "fixed"} for k in range(200)]
    html = robokin.Robot.from_dh(rows)._repr_html_()
    assert "more rows not shown" in html and len(html) < 30_000


def test_names_from_files_are_escaped():
    robot = robokin.load("ur5").replace(name="<script>alert(1)</script>")
    html = robot._repr_html_()
    assert "<script>" not in html and "&lt;script&gt;" in html
