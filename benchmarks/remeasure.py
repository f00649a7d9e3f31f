"""The quiet re-measure: every quick figure of the re-measure table, one after another.

Run from the repository root on free cores (the lead's end-of-session run)::

    python benchmarks/remeasure.py OUT_DIR [--long] [--only NAME,...] [--list]

Each step runs the script (or command) named in the first column of the table
"Re-measured on free cores" at the end of ``docs/benchmarks.md``, with the options
named there, as many times as the table says, one process after another (nothing
runs beside it). Each run's output (stdout and stderr) goes to
``OUT_DIR/<step>.<run>.txt``; ``OUT_DIR/summary.tsv`` gets one line per run: wall
time, CPU time of the run's processes (user + system of the waited children, from
``getrusage``) and the load average before and after, so a busy machine shows in
the record. A step that fails is recorded (exit code) and the next one runs; the
driver exits 1 when any failed.

The quick set used 250 s of CPU time in its trial (24.8 min wall at load 5-17):
about 5-8 minutes on a quiet 2-core machine (``docs/benchmarks.md``, the end). ``--long`` adds the figures that take
minutes each: ssik's side-by-side table of ``bench_ik_general_6r.py`` (ssik's
per-arm set-up must be cached in ``~/.cache/ssik``, or it takes up to 15 minutes an
arm), ``bench_ik_held.py`` at full size with its ssik rows, and the 10^8-evaluation
reach map's peak memory (``bench_cell.py``'s memory run alone).

Not run at all (too long for this driver; each has its own section and owner):
``bench_cell.py``'s throughput rounds and ``bench_plan.py`` (tens of minutes), and
the planning problem set (``plan_baseline.py``).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PY = sys.executable
CLI = str(Path(PY).with_name("robokin"))  # the console script of this environment

MEMORY = ("import sys; sys.path.insert(0, 'benchmarks'); import robokin, bench_cell; "
          "bench_cell.peak_rss(robokin.load('ur5'), 1e8, 200)")


@dataclasses.dataclass(frozen=True)
class Step:
    """One row (or rows) of the re-measure table: a command run ``runs`` times."""

    name: str
    argv: tuple[str, ...]
    runs: int = 1
    long: bool = False


def bench(script: str, *options: str) -> tuple[str, ...]:
    """The argv running ``benchmarks/<script>`` with ``options``."""
    return (PY, f"benchmarks/{script}", *options)


STEPS = (
    Step("cold_start", bench("bench_cold_start.py", "--runs", "3", "--demo-runs", "2")),
    Step("import_robokin", (PY, "-c", "import robokin"), runs=5),
    Step("cli_fk", (CLI, "fk", "ur5", "0", "0", "0", "0", "0", "0"), runs=3),
    Step("fk", bench("bench_fk.py"), runs=3),
    Step("ik_analytic", bench("bench_ik_analytic.py", "--batch", "100000"), runs=2),
    Step("ik_general_6r", bench("bench_ik_general_6r.py", "--poses", "300", "--sub", "0")),
    Step("ik_held", bench("bench_ik_held.py", "--ssik-poses", "20"), runs=2),
    Step("self_motion", bench("bench_self_motion.py", "--poses", "30")),
    Step("self_motion_general", bench("bench_self_motion_general.py", "--poses", "10")),
    Step("ik_numeric", bench("bench_ik_numeric.py", "--n", "300", "--ikpy-n", "20"), runs=4),
    Step("trajectory", bench("bench_trajectory.py"), runs=5),
    Step("collision", bench("bench_collision.py"), runs=5),
    Step("retime", bench("bench_retime.py")),
    Step("process", bench("bench_process.py", "--quick", "--runs", "3")),
    Step("calibration", bench("bench_calibration.py", "--quick", "--runs", "1")),
    Step("posts", bench("bench_posts.py")),
    Step("sim", bench("bench_sim.py")),
    Step("xacro", bench("bench_xacro.py", "--rounds", "5")),
    # The demo warm: the first run fills the caches, the second is the figure.
    Step("demo_warm", (CLI, "demo", "--force", "--out", "{out}/demo"), runs=2),
    Step("ik_general_6r_ssik", bench("bench_ik_general_6r.py", "--ssik", "100", "--poses",
                                     "800", "--sub", "0"), long=True),
    Step("ik_held_full", bench("bench_ik_held.py", "--poses", "1000", "--ssik-poses", "200"),
         long=True),
    Step("cell_memory", (PY, "-c", MEMORY), long=True),
)


def children_cpu() -> float:
    """User + system CPU time [s] of every waited child process so far."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_once(step: Step, i: int, out: Path) -> tuple[int, float, float]:
    """Run ``step`` once, its output into ``out``; (exit code, wall [s], CPU [s])."""
    argv = [a.replace("{out}", str(out)) for a in step.argv]
    log = out / f"{step.name}.{i}.txt"
    c0, t0 = children_cpu(), time.perf_counter()
    with log.open("w") as f:
        f.write(f"$ {' '.join(argv)}\n")
        f.flush()
        rc = subprocess.run(argv, cwd=ROOT, stdout=f, stderr=subprocess.STDOUT,
                            check=False).returncode
    return rc, time.perf_counter() - t0, children_cpu() - c0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", type=Path, help="directory for the outputs (created)")
    ap.add_argument("--long", action="store_true", help="also the steps of minutes each")
    ap.add_argument("--only", default="", help="comma-separated step names")
    ap.add_argument("--list", action="store_true", help="print the steps and exit")
    a = ap.parse_args()
    names = {s.name for s in STEPS}
    only = {n.strip() for n in a.only.split(",") if n.strip()}
    if only - names:
        ap.error(f"--only: unknown {', '.join(sorted(only - names))}; "
                 f"choose from {', '.join(s.name for s in STEPS)}")
    steps = [s for s in STEPS if s.name in only] if only else [
        s for s in STEPS if a.long or not s.long]
    if a.list:
        for s in steps:
            print(f"{s.name:<20} x{s.runs}  {' '.join(s.argv[1:])}")
        return 0
    a.out.mkdir(parents=True, exist_ok=True)
    os.environ.setdefault("MPLBACKEND", "Agg")
    summary = a.out / "summary.tsv"
    failed = []
    start = time.perf_counter()
    with summary.open("w") as tsv:
        tsv.write("step\trun\texit\twall_s\tcpu_s\tload_before\tload_after\n")
        for s in steps:
            for i in range(1, s.runs + 1):
                load0 = os.getloadavg()[0]
                rc, wall, cpu = run_once(s, i, a.out)
                load1 = os.getloadavg()[0]
                tsv.write(f"{s.name}\t{i}\t{rc}\t{wall:.2f}\t{cpu:.2f}\t{load0:.2f}\t"
                          f"{load1:.2f}\n")
                tsv.flush()
                print(f"{s.name:<20} run {i}/{s.runs}: exit {rc}, wall {wall:6.1f} s, "
                      f"CPU {cpu:6.1f} s, load {load0:.1f} -> {load1:.1f}", flush=True)
                if rc != 0:
                    failed.append(f"{s.name}.{i}")
    total = time.perf_counter() - start
    print(f"total {total / 60:.1f} min; outputs in {a.out}; summary {summary}")
    if failed:
        print(f"FAILED: {', '.join(failed)} (see their .txt files)")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
