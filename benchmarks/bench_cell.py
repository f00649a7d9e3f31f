"""Cell design at scale: reachability-map throughput on Dask against the bare batch IK.

Run: ``python benchmarks/bench_cell.py [--voxel 0.05] [--orientations 32] [--rounds 3]
[--rss-evals 1e8] [--sweep] [--core]``.

Everything side by side in one run, on the UR5 over its default region (the
workspace bounds), after checking correctness:

1. **Correctness.** The map from the local scheduler and from a
   ``distributed.LocalCluster`` of two workers are compared array by array (bit
   for bit); random (voxel, orientation) pairs are re-solved by direct IK
   (``robot.ik`` one pose at a time) and must agree 100 %; the best
   manipulability of random voxels is compared with ``robot.manipulability``;
   the cost of one manipulability, compiled (``|det J|``, ``manipulability.c``)
   and the old way (a stored Jacobian and ``numpy.linalg.det``).
2. **Throughput, in alternating rounds** (medians; the box is shared, so each
   round measures every variant back to back):

   * bare batch IK: ``robot.ik`` on the map's poses, pre-built, in batches, the
     kernels on every core (their own thread pool);
   * the map's work without Dask: every chunk's evaluation in this process, in a
     loop, kernels on every core;
   * ``reach_map`` on a LocalCluster of 2 workers x 1 thread (one per core),
     without and with manipulability, in memory and streaming into Zarr; again
     with glibc's malloc told to keep freed memory (``MALLOC_TUNED``: Dask's
     workers otherwise get fresh pages for every array of every task);
   * the same on 1 worker (1 core): the per-core rate;
   * ``reach_map`` with ``scheduler=None`` (local threads);
   * "before": the local-threads and two-worker maps as before the fused
     kernel (the solution sets, then a second manipulability pass:
     :func:`as_before`).
3. **Projection**: the 5 mm, 200-orientation UR5 map on a 100-core cluster,
   from the measured 1-worker (per-core) rate.
4. **Memory**: a map of at least ``--rss-evals`` IK evaluations streamed into a
   Zarr store in a child process; its peak RSS from ``/usr/bin/time -v``.
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

import numpy as np

import robokin
from robokin import cell
from robokin._native import num_threads, set_num_threads
from robokin.cell._evaluate import ReachJob, evaluate_reach, poses
from robokin.cell._facts import default_region
from robokin.cell.grid import VoxelGrid, tool_orientations
from robokin.cell.reach_map import _REGION_MARGIN, _REGION_SAMPLES, _default_chunk

FIELDS = ("counts", "index", "solutions", "manipulability")
CORE = ("bare batch IK (robot.ik)", "map work, no Dask, w off", "map work, no Dask, w on",
        "local threads, w on", "local threads, w on, before",
        "LocalCluster 2x1, w off", "LocalCluster 2x1, w on", "LocalCluster 2x1, w on, before")


def as_before(on: bool) -> None:
    """Run tasks as before the fused kernel (``on``): the closed form's solution
    sets from ``robot.ik``, then the manipulability kernel in a second pass and
    the per-voxel reduction in numpy (``fused_params`` returns None); else as
    now (``_native/csrc/reach.c``). Called here and on every worker, so the same
    run times both. (Round 1's "before", one IK call per task and glibc's
    thresholds as Dask pinned them, is in docs/scale.md.)"""
    from robokin.cell import _evaluate

    saved = _evaluate.__dict__.setdefault(  # kept in the module: this runs on workers too
        "_bench_saved", _evaluate.fused_params)
    _evaluate.fused_params = (lambda job: None) if on else saved


def before(fn, clients):
    """``fn`` run as before the fix (see :func:`as_before`), then back to now."""
    def run():
        for c in clients:
            c.run(as_before, True)
        as_before(True)
        try:
            fn()
        finally:
            as_before(False)
            for c in clients:
                c.run(as_before, False)
    return run


def rate(n: int, seconds: float) -> float:
    """Million IK targets per second."""
    return n / seconds / 1e6


def cpu_seconds(pids: list[int]) -> float:
    """CPU time [s] of the given processes (this one, a cluster's nannies and
    workers; the LocalCluster scheduler runs inside this process), user + system."""
    import psutil

    total = 0.0
    for pid in pids:
        t = psutil.Process(pid).cpu_times()
        total += t.user + t.system
    return total


def measure(fn, pids: list[int]) -> tuple[float, float]:
    """(wall seconds, CPU seconds of ``pids``) of ``fn()``."""
    c, t = cpu_seconds(pids), time.perf_counter()
    fn()
    return time.perf_counter() - t, cpu_seconds(pids) - c


def cluster_pids(client) -> list[int]:
    """This process (a LocalCluster's scheduler and nannies live in it) and the
    cluster's worker processes."""
    return sorted({os.getpid(), *client.run(os.getpid).values()})


# glibc keeps freed memory for reuse unless told otherwise; Dask's nanny sets
# MALLOC_TRIM_THRESHOLD_=65536 in its workers, which also fixes the mmap threshold
# at 128 KiB, so every array of a task is fresh pages (page faults, system time).
MALLOC_TUNED = {"MALLOC_MMAP_THRESHOLD_": 2**26, "MALLOC_TRIM_THRESHOLD_": 2**28}


def local_cluster(n: int, tuned: bool = False):
    import dask
    from distributed import LocalCluster

    env = dict(dask.config.get("distributed.nanny.pre-spawn-environ"))
    if tuned:
        env.update(MALLOC_TUNED)
    with dask.config.set({"distributed.nanny.pre-spawn-environ": env}):
        return LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                            dashboard_address=None)


def bare_ik(robot, T: np.ndarray, batch: int) -> float:
    """Seconds of ``robot.ik`` over every pose, in batches (kernels on every core)."""
    t = time.perf_counter()
    for a in range(0, T.shape[0], batch):
        robot.ik(T[a : a + batch])
    return time.perf_counter() - t


def in_process(job: ReachJob, ranges) -> float:
    """Seconds of every chunk's evaluation in this process (no Dask)."""
    t = time.perf_counter()
    for a, b in ranges:
        evaluate_reach(job, a, b)
    return time.perf_counter() - t


def timed_map(robot, kw, **extra) -> float:
    t = time.perf_counter()
    cell.reach_map(robot, **kw, **extra)
    return time.perf_counter() - t


def check_correctness(robot, kw, client, samples: int, rng) -> None:
    local = cell.reach_map(robot, **kw)
    remote = cell.reach_map(robot, scheduler=client, **kw)
    same = all(np.array_equal(np.asarray(getattr(local, f)), np.asarray(getattr(remote, f)))
               for f in FIELDS)
    print(f"local threads == LocalCluster(2), all four arrays bit for bit: {same}")
    if not same:
        raise SystemExit("the schedulers disagree")
    V, K = remote.counts.shape
    agree = 0
    vs, ks = rng.integers(0, V, samples), rng.integers(0, K, samples)
    centers = remote.grid.centers()
    for v, k in zip(vs, ks):
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = remote.orientations[k], centers[v]
        agree += int(remote.counts[v, k] == robot.ik(T).within_limits.sum())
    print(f"random (voxel, orientation) pairs re-solved by direct IK: {agree}/{samples} "
          f"agree ({100.0 * agree / samples:.1f} %)")
    worst = 0.0
    for v in rng.choice(np.flatnonzero(remote.index > 0), 30, replace=False):
        T = np.zeros((K, 4, 4))
        T[:, :3, :3], T[:, :3, 3], T[:, 3, 3] = remote.orientations, centers[v], 1.0
        sols = robot.ik(T)
        best = robot.manipulability(sols.q[sols.within_limits]).max()
        worst = max(worst, abs(best - remote.manipulability[v]) / best)
    print(f"best manipulability of 30 voxels vs robot.manipulability (SVD): worst "
          f"relative difference {worst:.1e}")
    if agree != samples:
        raise SystemExit("the map disagrees with direct IK")


def manipulability_cost(robot, rng, count: int = 500_000, rounds: int = 5) -> None:
    """ns per configuration, one thread: the compiled |det J| (manipulability.c)
    against a stored Jacobian and numpy.linalg.det (the map's path before issue 25)."""
    from robokin.kinematics.jacobian import jacobian, manipulability

    q = robot.limits[:, 0] + rng.random((count, robot.n)) * np.ptp(robot.limits, axis=1)
    ok = rng.random(count) < 0.5  # an IK solution set's valid rows
    before = num_threads()
    set_num_threads(1)
    try:
        fused, stored = [], []
        for _ in range(rounds):
            t = time.perf_counter()
            w = manipulability(robot.chain, q, method="det", where=ok)
            fused.append((time.perf_counter() - t) / ok.sum() * 1e9)
            t = time.perf_counter()
            ref = np.abs(np.linalg.det(jacobian(robot.chain, q[ok])))
            stored.append((time.perf_counter() - t) / ok.sum() * 1e9)
    finally:
        set_num_threads(before)
    worst = float(np.max(np.abs(w[ok] - ref)) / ref.max())
    print(f"manipulability per solution, one thread ({rounds} rounds, min-max): compiled "
          f"|det J| {min(fused):.0f}-{max(fused):.0f} ns, stored Jacobian + numpy det "
          f"{min(stored):.0f}-{max(stored):.0f} ns; largest difference / largest w "
          f"{worst:.1e}")


def projection(robot, per_core: dict[str, float]) -> None:
    region = default_region(robot, _REGION_SAMPLES, _REGION_MARGIN)
    g = VoxelGrid.from_region(region, 0.005)
    n = g.size * 200
    print(f"\nprojection: UR5 at 5 mm over its default region {np.round(region, 3).tolist()} m:"
          f" {g.size:,} voxels x 200 orientations = {n:.3e} IK targets")
    for label, r in per_core.items():
        core_h = n / (r * 1e6) / 3600
        print(f"  {label:<28} {r:.3f} M/s per core -> {core_h:,.1f} core-hours = "
              f"{core_h * 60 / 100:.1f} min on 100 cores")


RSS_CHILD = """
import sys, time
import robokin
from robokin import cell
robot = robokin.load("ur5")
voxel, K, store = float(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
t = time.perf_counter()
m = cell.reach_map(robot, voxel=voxel, orientations=K, store=store)
dt = time.perf_counter() - t
print(m.size * K, dt, m.summary()["reachable_voxels"])
"""


def peak_rss(robot, evals: float, K: int) -> None:
    region = default_region(robot, _REGION_SAMPLES, _REGION_MARGIN)
    vol = float(np.prod(region[1] - region[0]))
    voxel = (vol * K / evals) ** (1 / 3)
    while VoxelGrid.from_region(region, voxel).size * K < evals:
        voxel *= 0.995
    voxel = float(f"{voxel:.5f}")
    while VoxelGrid.from_region(region, voxel).size * K < evals:
        voxel -= 1e-5
    with tempfile.TemporaryDirectory() as tmp:
        cmd = ["/usr/bin/time", "-v", sys.executable, "-c", RSS_CHILD, str(voxel), str(K),
               f"{tmp}/map.zarr"]
        proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
        if proc.returncode != 0:
            raise SystemExit(f"the memory run failed:\n{proc.stderr[-2000:]}")
        n, dt, reach = proc.stdout.split()
        rss_kb = next(int(line.split()[-1]) for line in proc.stderr.splitlines()
                      if "Maximum resident set size" in line)
        size = sum(f.stat().st_size for f in Path(tmp).rglob("*") if f.is_file())
    print(f"\nmemory: a {int(n):.3e}-evaluation map ({voxel * 1e3:.2f} mm voxels, {K} "
          f"orientations, manipulability on) streamed into Zarr by the local scheduler: "
          f"peak RSS {rss_kb / 1024:.0f} MiB (/usr/bin/time -v), {float(dt):.0f} s "
          f"({rate(int(n), float(dt)):.3f} M/s), store {size / 2**20:.0f} MiB on disk, "
          f"{int(reach):,} voxels reachable")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--voxel", type=float, default=0.05, help="[m] of the timed map")
    ap.add_argument("--orientations", type=int, default=32)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--samples", type=int, default=1000, help="direct-IK re-checks")
    ap.add_argument("--rss-evals", type=float, default=1e8, help="0 to skip")
    ap.add_argument("--rss-orientations", type=int, default=200)
    ap.add_argument("--sweep", action="store_true", help="also time chunk sizes")
    ap.add_argument("--core", action="store_true",
                    help="only bare IK, the work without Dask and LocalCluster 2x1 (w off, "
                         "w on): more rounds in a quiet window")
    args = ap.parse_args()

    from distributed import Client

    robot = robokin.load("ur5")
    cores = len(os.sched_getaffinity(0))
    rng = np.random.default_rng(0)
    region = default_region(robot, _REGION_SAMPLES, _REGION_MARGIN)
    kw = dict(region=region, voxel=args.voxel, orientations=args.orientations)
    grid = VoxelGrid.from_region(region, args.voxel)
    R = tool_orientations(args.orientations)
    V, K = grid.size, R.shape[0]
    N = V * K
    B = _default_chunk(V, K)
    ranges = [(a, min(a + B, V)) for a in range(0, V, B)]
    print(f"robokin {robokin.__version__}, {cores} cores, kernels {robokin._native.ISA}; "
          f"UR5 map: {V:,} voxels of {args.voxel * 1e3:g} mm x {K} orientations = "
          f"{N:,} IK targets, {len(ranges)} tasks of {B * K:,}")
    job = {w: ReachJob(robot, None, None, grid, R, False, w) for w in (False, True)}
    T = np.concatenate([poses(job[False], a, b) for a, b in ranges])
    all_threads = num_threads()

    with local_cluster(2) as lc2, Client(lc2) as c2, \
            local_cluster(2, tuned=True) as lc2t, Client(lc2t) as c2t, \
            local_cluster(1) as lc1, Client(lc1) as c1, \
            tempfile.TemporaryDirectory() as tmp:
        check_correctness(robot, {**kw, "voxel": args.voxel * 2}, c2, args.samples, rng)
        manipulability_cost(robot, rng)
        wall: dict[str, list[float]] = {}
        cpu: dict[str, list[float]] = {}
        here, pids2, pids1 = [os.getpid()], cluster_pids(c2), cluster_pids(c1)
        pids2t = cluster_pids(c2t)
        runs = iter(range(10**6))

        def fresh_store() -> str:
            return f"{tmp}/m{next(runs)}.zarr"

        variants = {  # label: (run, processes whose CPU time it uses)
            "bare batch IK (robot.ik)": (lambda: bare_ik(robot, T, B * K), here),
            "map work, no Dask, w off": (lambda: in_process(job[False], ranges), here),
            "map work, no Dask, w on": (lambda: in_process(job[True], ranges), here),
            "local threads, w off": (lambda: cell.reach_map(
                robot, **kw, manipulability=False), here),
            "local threads, w on": (lambda: cell.reach_map(robot, **kw), here),
            "local threads, w on, before": (before(lambda: cell.reach_map(robot, **kw), []),
                                            here),
            "LocalCluster 2x1, w off": (lambda: cell.reach_map(
                robot, **kw, scheduler=c2, manipulability=False), pids2),
            "LocalCluster 2x1, w on": (lambda: cell.reach_map(
                robot, **kw, scheduler=c2), pids2),
            "LocalCluster 2x1, w on, before": (before(lambda: cell.reach_map(
                robot, **kw, scheduler=c2), [c2]), pids2),
            "LocalCluster 2x1, w on, Zarr": (lambda: cell.reach_map(
                robot, **kw, scheduler=c2, store=fresh_store()), pids2),
            "LocalCluster 2x1 tuned, w off": (lambda: cell.reach_map(
                robot, **kw, scheduler=c2t, manipulability=False), pids2t),
            "LocalCluster 2x1 tuned, w on": (lambda: cell.reach_map(
                robot, **kw, scheduler=c2t), pids2t),
            "LocalCluster 1x1, w off": (lambda: cell.reach_map(
                robot, **kw, scheduler=c1, manipulability=False), pids1),
            "LocalCluster 1x1, w on": (lambda: cell.reach_map(
                robot, **kw, scheduler=c1), pids1),
        }
        if args.core:
            variants = {k: v for k, v in variants.items() if k in CORE}
        for r in range(args.rounds):
            for label, (fn, pids) in variants.items():
                set_num_threads(all_threads)
                w, c = measure(fn, pids)
                wall.setdefault(label, []).append(rate(N, w))
                cpu.setdefault(label, []).append(rate(N, c))
            print(f"round {r + 1}/{args.rounds} done")
        best = {k: max(v) for k, v in wall.items()}
        med = {k: statistics.median(v) for k, v in wall.items()}
        medc = {k: statistics.median(v) for k, v in cpu.items()}
        ref = "bare batch IK (robot.ik)"
        print(f"\nthroughput, M IK targets/s over {args.rounds} rounds ('w' = best "
              "manipulability per voxel). Wall: per second elapsed on the "
              f"{cores} cores (best round, median round); CPU: per CPU-second of the "
              "processes doing the work (this one; the cluster's workers and nannies), "
              "median, which other users of a shared machine disturb less:")
        print(f"  {'':<30} {'best':>7} {'%':>6} {'median':>7} {'%':>6}   {'CPU':>6} "
              f"{'%':>6}   wall by round")
        for label in variants:
            print(f"  {label:<30} {best[label]:7.3f} {100 * best[label] / best[ref]:5.1f}% "
                  f"{med[label]:7.3f} {100 * med[label] / med[ref]:5.1f}%   "
                  f"{medc[label]:6.3f} {100 * medc[label] / medc[ref]:5.1f}%   "
                  + ", ".join(f"{x:.3f}" for x in wall[label]))
        for label in ("LocalCluster 2x1, w off", "LocalCluster 2x1, w on",
                      "LocalCluster 2x1, w on, before", "local threads, w on",
                      "local threads, w on, before"):
            ratio = [100 * a / b for a, b in zip(wall[label], wall[ref])]
            print(f"  {label} / bare batch IK, round by round (back to back): "
                  f"{min(ratio):.0f}-{max(ratio):.0f} %, median "
                  f"{statistics.median(ratio):.0f} %")
        for kind, m in (("wall, best", best), ("wall, median", med), ("CPU, median", medc)):
            if args.core:
                break
            print(f"  {kind}: LocalCluster 2 vs 1 worker "
                  f"{m['LocalCluster 2x1, w off'] / m['LocalCluster 1x1, w off']:.2f}x (w off), "
                  f"{m['LocalCluster 2x1, w on'] / m['LocalCluster 1x1, w on']:.2f}x (w on); "
                  "LocalCluster 2x1 / the same work without Dask "
                  f"{100 * m['LocalCluster 2x1, w off'] / m['map work, no Dask, w off']:.0f} % "
                  f"(w off), "
                  f"{100 * m['LocalCluster 2x1, w on'] / m['map work, no Dask, w on']:.0f} % "
                  "(w on)")
        if args.sweep:
            print("\nchunk size on LocalCluster 2x1 (w on):")
            for poses_per_task in (8192, 32768, 131072, 524288):
                b = max(1, poses_per_task // K)
                t = min(timed_map(robot, kw, scheduler=c2, chunk=b) for _ in range(2))
                print(f"  {b * K:>8,} targets per task ({-(-V // b)} tasks): "
                      f"{rate(N, t):.3f} M/s")
    if args.core:
        return
    projection(robot, {"1 worker, w off, best": best["LocalCluster 1x1, w off"],
                       "1 worker, w on, best": best["LocalCluster 1x1, w on"],
                       "2 workers / 2, w off, best": best["LocalCluster 2x1, w off"] / 2,
                       "2 workers / 2, w on, best": best["LocalCluster 2x1, w on"] / 2,
                       "per CPU-second, w on (2x1)": medc["LocalCluster 2x1, w on"]})
    if args.rss_evals > 0:
        peak_rss(robot, args.rss_evals, args.rss_orientations)


if __name__ == "__main__":
    main()
