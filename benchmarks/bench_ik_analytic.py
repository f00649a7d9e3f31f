"""Closed-form IK: robokin against eaik, ur-analytic-ik and ik-geo, in one run.

For each library: microseconds per single pose (best of several repeats, mean
call), poses per second on a batch (100,000 UR5 poses for robokin and eaik's batched
call; Python loops for the single-pose-only peers, on 10,000 poses), solutions found
per pose (on the first ``--loop`` poses, for every library), and the worst FK error
of the returned solutions (robokin's FK, after checking the peer's model agrees with
it). Then robokin's and eaik's batch throughput timed in alternation (the machine may
be shared) and their ratio. Also the Puma 560 (spherical wrist) against eaik.

Run: ``python benchmarks/bench_ik_analytic.py [--batch 100000]``.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import numpy as np

import robokin
from robokin.kinematics.ik.analytic._common import fk_error


def _best(fn: Callable[[], object], repeat: int = 5, number: int = 1) -> float:
    """Best of ``repeat`` runs of ``number`` calls, seconds per call."""
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(number):
            fn()
        best = min(best, (time.perf_counter() - t0) / number)
    return best


def _worst_error(robot, qs: list[np.ndarray], T: np.ndarray) -> tuple[float, float]:
    """(mean solutions per pose, worst FK error [m or rad]) of per-pose solution lists."""
    errs = []
    count = 0
    for q, Ti in zip(qs, T):
        q = np.asarray(q, dtype=float).reshape(-1, 6)
        count += len(q)
        if len(q):
            dp, dr = fk_error(robot.chain, q, Ti)
            errs.append(max(dp.max(), dr.max()))
    return count / len(T), float(max(errs) if errs else np.nan)


def _row(name: str, single_us: float, rate: float, nsol: float, err: float) -> None:
    print(f"{name:<38s} {single_us:9.2f} {rate / 1e6:12.3f} {nsol:8.2f} {err:12.1e}")


def _dh(robot_name: str):
    # the robot file's own document (read once, by robokin's YAML reader)
    doc = robokin.load(robot_name).meta["document"]
    L = 1e-3 if doc["units"]["length"] == "mm" else 1.0
    rows = doc["joints"]
    return (np.radians([r["alpha"] for r in rows]), np.array([r["a"] for r in rows]) * L,
            np.array([r["d"] for r in rows]) * L)


def bench_robokin(robot, T_single, T_batch, loop_n: int) -> None:
    from robokin.kinematics.ik.analytic._six_r import raw_solve

    fam = robokin.ik.family(robot)
    P = fam.solver.params
    T1 = np.ascontiguousarray(T_single[None])
    robot.ik(T_single)
    raw_solve(P, T1, packed=robot.chain.arrays.packed)
    s_api = _best(lambda: robot.ik(T_single), number=2000)
    packed = robot.chain.arrays.packed
    s_raw = _best(lambda: raw_solve(P, T1, packed=packed), number=2000)
    robot.ik(T_batch[:1000])
    tb = _best(lambda: robot.ik(T_batch), repeat=3)
    sols = robot.ik(T_batch)
    dp, dr = fk_error(robot.chain, sols.q, T_batch)
    err = float(np.max(np.where(sols.valid, np.maximum(dp, dr), 0.0)))
    n = sols.count[:loop_n].mean()  # the same poses as the peers' counts
    _row(f"robokin {robot.name} robot.ik", s_api * 1e6, len(T_batch) / tb, n, err)
    tr = _best(lambda: raw_solve(P, np.ascontiguousarray(T_batch), packed=packed), repeat=3)
    _row(f"robokin {robot.name} kernel only", s_raw * 1e6, len(T_batch) / tr, n, err)


def cpu_rate(robot, T_batch) -> None:
    """Batch throughput by wall clock and by the process's CPU time, 1 and 2 threads.

    On a shared machine the wall-clock rate measures the load as much as the code;
    poses per CPU-second (best of 5) is what one core delivers while it runs, and
    twice that is what two free cores would. The load average is printed with it.
    """
    import os

    import robokin._native as native

    before = native.num_threads()
    try:
        for k in (1, 2):
            native.set_num_threads(k)
            robot.ik(T_batch[:1000])
            wall = cpu = np.inf
            for _ in range(5):
                w0, c0 = time.perf_counter(), time.process_time()
                robot.ik(T_batch)
                wall = min(wall, time.perf_counter() - w0)
                cpu = min(cpu, time.process_time() - c0)
            n = len(T_batch)
            print(f"  {robot.name} robot.ik, {k} thread(s): {n / wall / 1e6:.3f} M poses/s "
                  f"wall, {n / cpu / 1e6:.3f} M poses per CPU-second "
                  f"(load average {os.getloadavg()[0]:.1f})")
    finally:
        native.set_num_threads(before)


def bench_eaik(robot, T_single, T_batch, loop_n: int) -> float:
    try:
        from eaik.IK_DH import DhRobot
    except ImportError:
        print("eaik: not installed")
        return np.nan
    alpha, a, d = _dh(robot.name)
    bot = DhRobot(alpha, a, d)
    # eaik's DH model has no joint offsets: check it matches ours
    q = np.random.default_rng(1).uniform(-3, 3, 6)
    if not np.allclose(bot.fwdKin(q), robot.fk(q), atol=1e-9):
        print(f"eaik {robot.name}: DH model differs from robokin's (offsets); skipped")
        return np.nan
    s = _best(lambda: bot.IK(T_single), number=2000)
    nb = len(T_batch)
    tb = _best(lambda: bot.IK_batched(T_batch, 1), repeat=2)
    res = bot.IK_batched(T_batch, 1)
    qs = [np.asarray(r.Q)[~np.asarray(r.is_LS)] for r in res[:loop_n]]
    n, err = _worst_error(robot, qs, T_batch[:loop_n])
    _row(f"eaik {robot.name} (batched, 1 thread)", s * 1e6, nb / tb, n, err)
    tb2 = _best(lambda: bot.IK_batched(T_batch, 2), repeat=2)
    _row(f"eaik {robot.name} (batched, 2 threads)", s * 1e6, nb / tb2, n, err)
    return max(nb / tb, nb / tb2)


def bench_ur_analytic(robot, T_single, T_batch) -> None:
    try:
        import ur_analytic_ik
    except ImportError:
        print("ur-analytic-ik: not installed")
        return
    ur = ur_analytic_ik.ur5
    T1 = np.ascontiguousarray(T_single)
    s = _best(lambda: ur.inverse_kinematics(T1), number=2000)
    Ts = [np.ascontiguousarray(T) for T in T_batch]
    t0 = time.perf_counter()
    qs = [np.array(ur.inverse_kinematics(T)) for T in Ts]
    tb = time.perf_counter() - t0
    n, err = _worst_error(robot, qs, T_batch)
    _row("ur-analytic-ik ur5 (Python loop)", s * 1e6, len(Ts) / tb, n, err)


def bench_ik_geo(robot, T_single, T_batch) -> None:
    try:
        import ik_geo
    except ImportError:
        print("ik-geo: not installed")
        return
    from robokin.kinematics.ik.analytic._geometry import poe_from_chain

    poe = poe_from_chain(robot.chain)
    h = poe.h
    p = np.vstack([poe.o[0], np.diff(poe.o, axis=0), poe.M[:3, 3] - poe.o[-1]])
    bot = ik_geo.Robot.three_parallel_two_intersecting(h.tolist(), p.tolist())
    RM = poe.M[:3, :3]

    def one(T):
        # ik-geo reads the rotation column by column
        return bot.get_ik((T[:3, :3] @ RM.T).T.tolist(), T[:3, 3].tolist())

    s = _best(lambda: one(T_single), number=2000)
    t0 = time.perf_counter()
    res = [one(T) for T in T_batch]
    tb = time.perf_counter() - t0
    qs = [np.array([q for q, ls in r if not ls]).reshape(-1, 6) for r in res]
    n, err = _worst_error(robot, qs, T_batch)
    _row("ik-geo ur5 (Python loop)", s * 1e6, len(T_batch) / tb, n, err)


def throughput_ratio(robot, T_batch, rounds: int = 5) -> None:
    """robokin's ``robot.ik`` against eaik's batched call (1 and 2 threads) on the
    same batch, timed in alternation so both see the same machine load (the
    machine is shared); the best round of each, and their ratio."""
    try:
        from eaik.IK_DH import DhRobot
    except ImportError:
        return
    alpha, a, d = _dh(robot.name)
    bot = DhRobot(alpha, a, d)
    best = {"robokin": np.inf, "eaik1": np.inf, "eaik2": np.inf}
    calls = {"robokin": lambda: robot.ik(T_batch),
             "eaik1": lambda: bot.IK_batched(T_batch, 1),
             "eaik2": lambda: bot.IK_batched(T_batch, 2)}
    for _ in range(rounds):
        for key, fn in calls.items():
            best[key] = min(best[key], _best(fn, repeat=1))
    rate = {k: len(T_batch) / v for k, v in best.items()}
    e = max(rate["eaik1"], rate["eaik2"])
    print(f"  alternated, best of {rounds}: robokin {rate['robokin'] / 1e6:.3f} M poses/s, "
          f"eaik {rate['eaik1'] / 1e6:.3f} (1 thread) / {rate['eaik2'] / 1e6:.3f} "
          f"(2 threads) -> robokin / eaik best: {rate['robokin'] / e:.1f}x")


def singular_targets(n: int = 2000) -> None:
    """Issue 20: targets from random configurations with q5 = 0 exactly (the wrist
    singularity of a UR arm's home pose): how many are solved and flagged singular,
    and eaik's answer on the same poses."""
    print(f"\nwrist-singular targets (q5 = 0 exactly), {n} per arm:")
    for name in ("ur5", "aubo_i5", "puma560"):
        robot = robokin.load(name)
        rng = np.random.default_rng(5)
        lim = np.clip(robot.limits, -np.pi, np.pi)
        q = rng.uniform(lim[:, 0], lim[:, 1], (n, 6))
        q[:, 4] = 0.0
        T = robot.fk(q)
        sols = robot.ik(T)
        solved = sols.valid.any(axis=-1)
        flagged = (sols.valid & sols.singular).any(axis=-1)
        ok = sols.valid
        dp, dr = fk_error(robot.chain, sols.q, T)
        worst = float(np.nanmax(np.where(ok, np.maximum(dp, dr), np.nan)))
        print(f"  {name:<10s} solved {100 * solved.mean():6.2f} %  flagged singular "
              f"{100 * flagged.mean():6.2f} %  worst FK error {worst:.1e}")


def main(batch: int = 100_000, loop_n: int = 10_000) -> None:
    """Run every comparison and print one table."""
    rng = np.random.default_rng(0)
    print(f"{'library':<38s} {'single µs':>9s} {'M poses/s':>12s} {'sols':>8s} "
          f"{'worst err':>12s}")
    for name in ("ur5", "puma560"):
        robot = robokin.load(name)
        q = rng.uniform(-np.pi, np.pi, (batch, 6))
        T = robot.fk(q)
        bench_robokin(robot, T[0], T, loop_n)
        cpu_rate(robot, T)
        eaik_rate = bench_eaik(robot, T[0], T, loop_n)
        if name == "ur5":
            bench_ur_analytic(robot, T[0], T[:loop_n])
            bench_ik_geo(robot, T[0], T[:loop_n])
            if np.isfinite(eaik_rate):
                throughput_ratio(robot, T)
    singular_targets()


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--batch", type=int, default=100_000)
    ap.add_argument("--loop", type=int, default=10_000)
    args = ap.parse_args()
    main(args.batch, args.loop)
