"""``robokin reach`` and ``robokin place``: outputs, exit codes, one-line errors (issue 16)."""

import json

import numpy as np
import pytest

import robokin
from robokin import cell
from robokin.cli import main

pytest.importorskip("dask")


def run(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_reach_streams_a_map_and_draws_its_sections(capsys, tmp_path):
    out = tmp_path / "r"
    code, text, _ = run(capsys, "reach", "ur5", "--voxel", "250", "--orientations", "6",
                        "--out", str(out), "--region", "-500,-500,0,500,500,500")
    assert code == 0 and "reachability map" in text
    m = cell.ReachMap.load(out / "map.zarr")
    assert m.grid.shape == (4, 4, 2) and m.orientations.shape == (6, 3, 3)
    assert (out / "sections.png").stat().st_size > 10_000
    summary = json.loads((out / "reach.json").read_text())
    assert summary["voxels"] == 32 and summary["ik_evaluations"] == 192
    same = cell.reach_map(robokin.load("ur5"), region=[[-0.5, -0.5, 0], [0.5, 0.5, 0.5]],
                          voxel=0.25, orientations=6)
    np.testing.assert_array_equal(m.counts, same.counts)
    # again with --json: the finished store is recognised, nothing recomputed
    code, text, _ = run(capsys, "reach", "ur5", "--voxel", "250", "--orientations", "6",
                        "--out", str(out), "--region", "-500,-500,0,500,500,500", "--json")
    assert code == 0 and json.loads(text)["reachable_voxels"] == summary["reachable_voxels"]
    # a different map into the same folder needs --force
    code, _, err = run(capsys, "reach", "ur5", "--voxel", "200", "--out", str(out),
                       "--region", "-500,-500,0,500,500,500", "--orientations", "2")
    assert code == 2 and "holds a different map" in err and len(err.splitlines()) == 1


@pytest.mark.parametrize(("args", "match"), [
    (["--voxel", "0"], "'--voxel'"),
    (["--voxel", "-5"], "'--voxel'"),
    (["--region", "0,0,0,100,100"], "'--region'"),
    (["--region", "0,0,0,100,0,100"], "'region'.*is empty"),
    (["--orientations", "0"], "'orientations'"),
    (["--scheduler", "nowhere"], "'scheduler'"),
])
def test_reach_bad_input_is_one_line_exit_2(capsys, tmp_path, args, match):
    import re

    code, _, err = run(capsys, "reach", "ur5", "--out", str(tmp_path / "x"), *args)
    assert code == 2 and re.search(match, err) and len(err.strip().splitlines()) == 1


def test_place_scores_the_press_cell(capsys, tmp_path):
    pytest.importorskip("coal")
    out = tmp_path / "p"
    code, text, _ = run(capsys, "place", "aubo_i5", "--scene", "press", "--clearance", "4",
                        "--x=-200:0:100", "--y=0:200:100", "--out", str(out))
    assert code == 0 and "bases feasible" in text
    for f in ("placement.png", "placement.csv", "placement.json"):
        assert (out / f).stat().st_size > 100
    summary = json.loads((out / "placement.json").read_text())
    assert summary["candidates"] == 9 and summary["feasible"] >= 1
    assert summary["task_poses"] == 4  # the scene's named poses


def test_place_says_no_with_exit_1(capsys, tmp_path):
    pytest.importorskip("coal")
    code, _, err = run(capsys, "place", "aubo_i5", "--scene", "press", "--clearance", "60",
                       "--x", "0", "--y", "0", "--out", str(tmp_path / "p"))
    assert code == 1 and "no feasible placement among 1 candidates" in err


@pytest.mark.parametrize(("args", "match"), [
    (["--task", "poses"], "'poses' needs a --scene"),
    (["--scene", "press", "--x", "a:b"], "'--x'"),
    (["--scene", "press", "--x", "0:10:0"], "'--x'"),
    (["--scene", "press", "--clearance", "-1"], "'--clearance'"),
    (["--scene", "press", "--task", "missing.csv"], "missing.csv"),
])
def test_place_bad_input_is_one_line_exit_2(capsys, tmp_path, args, match):
    import re

    code, _, err = run(capsys, "place", "aubo_i5", "--out", str(tmp_path / "p"), *args)
    assert code == 2 and re.search(match, err) and len(err.strip().splitlines()) == 1
