"""``robokin demo --place``: the map of feasible bases, with the cell's own base feasible
(issue 16)."""

import io
import json

import pytest

pytest.importorskip("coal")
pytest.importorskip("dask")


def test_the_demo_maps_feasible_bases_and_its_own_is_one(tmp_path):
    from rich.console import Console

    from robokin.cli.demo import run_demo
    from robokin.cli.demo_job import PLACE_SPAN, PLACE_STEP

    console = Console(file=io.StringIO(), width=140)
    result = run_demo(out=tmp_path, console=console, html_animation=False, place=True)
    assert result.ok
    summary = json.loads((tmp_path / "summary.json").read_text())
    ps = summary["placement"]
    side = round(2 * PLACE_SPAN / PLACE_STEP) + 1
    assert ps["candidates"] == side * side
    assert ps["cell_base_feasible"] and ps["cell_base_reason"] == "ok"
    assert 1 <= ps["feasible"] < ps["candidates"]
    assert ps["best"]["full_check_min_distance_m"] >= 0.004
    assert (tmp_path / "placement.png").stat().st_size > 10_000
    rows = (tmp_path / "placement.csv").read_text().splitlines()
    assert len(rows) == 1 + ps["candidates"]
    assert "placement.png" in (tmp_path / "report.html").read_text()
    text = console.file.getvalue()
    assert "bases feasible; this cell's base feasible" in text
    # issue 25: the placement search is in the timing line and the total
    timings = summary["timings_s"]
    assert timings["total"] >= timings["place"] + timings["plan"]
    time_line = next(ln for ln in text.splitlines() if "│ time" in ln)
    # the line prints the unrounded time to 2 decimals, the summary keeps 3: they agree
    # to half a hundredth (9.595 in the summary may print as 9.59 or 9.60)
    printed = float(time_line.split("place ", 1)[1].split()[0].rstrip(",)"))
    assert abs(printed - timings["place"]) <= 0.0051


def test_the_cli_takes_place(tmp_path, capsys):
    from robokin.cli import main

    code = main(["demo", "--out", str(tmp_path), "--place"])
    out, _ = capsys.readouterr()
    assert code == 0 and (tmp_path / "placement.png").exists()
