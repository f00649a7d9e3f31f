"""``benchmarks/remeasure.py``, the driver of the end-of-session quiet re-measure.

Oracles: the scripts' own argument parsers (their source) for the options each step
passes; the re-measure table in ``docs/benchmarks.md`` for the scripts that must be
covered; the files a real (short) run leaves behind.
"""

from __future__ import annotations

import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DRIVER = ROOT / "benchmarks" / "remeasure.py"


@pytest.fixture(scope="module")
def driver():
    spec = importlib.util.spec_from_file_location("remeasure", DRIVER)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["remeasure"] = module  # dataclasses look their module up there
    try:
        spec.loader.exec_module(module)
        yield module
    finally:
        del sys.modules["remeasure"]


def test_every_option_a_step_passes_is_one_its_script_declares(driver) -> None:
    checked = 0
    for step in driver.STEPS:
        scripts = [a for a in step.argv if a.startswith("benchmarks/")]
        if not scripts:
            continue
        source = (ROOT / scripts[0]).read_text()
        for option in (a for a in step.argv if a.startswith("--")):
            assert f'"{option}"' in source, (step.name, option)
            checked += 1
    assert checked >= 15


def test_every_script_of_the_re_measure_table_is_run_or_named_as_skipped(driver) -> None:
    text = (ROOT / "docs" / "benchmarks.md").read_text()
    table = text[text.index("## Re-measured on free cores"):]
    first_column = [line.split("|")[1] for line in table.splitlines()
                    if line.startswith("| ")]
    named = {m for cell in first_column for m in re.findall(r"\w+\.py", cell)}
    assert len(named) >= 10
    run = {m for s in driver.STEPS for a in s.argv for m in re.findall(r"\w+\.py", a)}
    skipped = set(re.findall(r"``(\w+\.py)``", driver.__doc__.split("Not run at all")[1]))
    assert named - {"remeasure.py"} <= run | skipped, named - run - skipped


def test_an_unknown_step_is_refused_with_the_valid_names(tmp_path: Path) -> None:
    proc = subprocess.run([sys.executable, str(DRIVER), str(tmp_path), "--only", "fkk"],
                          capture_output=True, text=True, check=False)
    assert proc.returncode == 2
    assert "--only: unknown fkk" in proc.stderr and "cold_start" in proc.stderr
    assert not any(tmp_path.iterdir())


def test_a_short_run_leaves_each_run_output_and_the_summary(tmp_path: Path) -> None:
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, str(DRIVER), str(out), "--only", "import_robokin"],
                          capture_output=True, text=True, check=False, cwd=tmp_path)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    rows = (out / "summary.tsv").read_text().splitlines()
    assert rows[0].split("\t")[:3] == ["step", "run", "exit"]
    assert [r.split("\t")[:3] for r in rows[1:]] == [
        ["import_robokin", str(i), "0"] for i in range(1, 6)]
    assert all(float(r.split("\t")[4]) > 0 for r in rows[1:])  # CPU time of the child
    assert (out / "import_robokin.5.txt").read_text().startswith("$ ")
