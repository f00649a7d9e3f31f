"""Cold start: the README quick start and ``robokin demo`` in fresh processes.

Run: ``python benchmarks/bench_cold_start.py [--runs 5] [--python PATH]``.

Every run is a new process with empty caches: a fresh ``PYTHONPYCACHEPREFIX`` (no
byte-code from earlier runs), a fresh ``NUMBA_CACHE_DIR`` (robokin compiles nothing
at run time; the variable is set so a numba-based build, e.g. an older robokin given
with ``--python``, is measured cold as well) and, for the "fresh machine" rows, a
fresh ``MPLCONFIGDIR`` (matplotlib builds its font cache on first use). Wall time is
measured around the whole child process, interpreter start-up included.

The quick start is the README's (load, FK, Jacobian, FK of 100,000 configurations,
closed-form IK, nearest) plus one numeric IK solve on the Panda.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

QUICK_START = """
import numpy as np
import robokin

robot = robokin.load("aubo_i5")
q = np.radians([10, -20, 30, -40, 50, 60])
T = robot.fk(q)
J = robot.jacobian(q)
Q = np.random.default_rng(0).uniform(-1, 1, (100_000, 6))
poses = robot.fk(Q)
sols = robot.ik(T)
q_best = sols.nearest(q)
panda = robokin.load("panda")
from robokin.kinematics.ik import numeric
res = numeric.solve(panda, panda.fk(np.full(7, 0.3)))
assert res.success and np.allclose(robot.fk(q_best), T, atol=1e-9)
"""


def run_once(cmd: list[str], fresh_matplotlib: bool, cwd: Path) -> float:
    """Wall seconds of one run of ``cmd`` with empty caches."""
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, PYTHONPYCACHEPREFIX=f"{tmp}/pyc",
                   NUMBA_CACHE_DIR=f"{tmp}/numba", MPLBACKEND="Agg")
        if fresh_matplotlib:
            env["MPLCONFIGDIR"] = f"{tmp}/mpl"
        t = time.perf_counter()
        proc = subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, text=True,
                              check=False)
        dt = time.perf_counter() - t
    if proc.returncode != 0:
        raise RuntimeError(f"{cmd} failed:\n{proc.stdout}\n{proc.stderr}")
    return dt


def figures(cmd: list[str], runs: int, fresh_matplotlib: bool, cwd: Path) -> str:
    times = [run_once(cmd, fresh_matplotlib, cwd) for _ in range(runs)]
    return (f"median {statistics.median(times):6.2f} s  (min {min(times):.2f}, "
            f"max {max(times):.2f}, {runs} runs)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--demo-runs", type=int, default=3)
    ap.add_argument("--python", default=sys.executable,
                    help="the interpreter whose robokin is measured")
    args = ap.parse_args()
    py = args.python
    robokin_cmd = str(Path(py).with_name("robokin"))
    with tempfile.TemporaryDirectory() as work:
        cwd = Path(work)
        print(f"python: {py}")
        print("quick start + one Panda numeric solve, empty byte-code/compile caches: "
              + figures([py, "-c", QUICK_START], args.runs, False, cwd))
        print("the same on a fresh machine (no matplotlib cache either):          "
              + figures([py, "-c", QUICK_START], args.runs, True, cwd))
        demo = [robokin_cmd, "demo", "--out", str(cwd / "demo")]
        print("robokin demo, empty byte-code/compile caches:                      "
              + figures(demo, args.demo_runs, False, cwd))
        print("robokin demo on a fresh machine (no matplotlib cache either):      "
              + figures(demo, args.demo_runs, True, cwd))


if __name__ == "__main__":
    main()
