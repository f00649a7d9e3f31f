"""Held-joint IK of the Panda with q7 given: robokin against geofikpy and ssik.

Every method gets the same flange poses ``panda.fk(q)`` and the value q7 of the
configuration that made each pose, and must return every configuration with that
q7 reaching the pose:

* robokin: ``panda.ik(T, fixed={"joint7": q7})`` (the ``pieper`` closed form,
  ``analytic/pieper.py``), one pose per call; the compiled kernel alone
  (``kernels.pieper_ik1``); and a batch (one call for every pose, the held values
  an array);
* geofikpy (GeoFIK, He and Liu's closed form): ``franka_ik_q7(r, R, q7)`` on the
  pose of its frame E (the flange pose times the constant flange-to-E transform,
  read off ``franka_fk``);
* ssik: its self-motion charts of the pose (``Manipulator.from_prebuilt
  ("franka_panda_ik").self_motion(T)``, the charts parametrised by q7), each chart
  evaluated at q7 (``chart.q(q7)``): the time is charts plus evaluation.

Configurations: uniform inside the limits ("random"), and "special": every joint
drawn from {0, +-pi/2, pi, +-1e-9, +-1e-7, +-1e-6, its limits, uniform}, kept when
the remaining 6 x 6 Jacobian's smallest singular value is >= 1e-4 (non-singular:
the solutions are isolated and the generating configuration must come back).
Reported per method: generating configurations recovered (a returned row within
1e-6 rad of it, modulo 2 pi), wrong rows (pose error above 1e-9 m or rad) and the
largest error of any row, rows per pose, and microseconds per pose: the best of
``--repeat`` runs over all poses, in wall time ("call") and in CPU time ("cpu
call", ``time.process_time``), and (robokin, geofikpy) the median over poses of
each pose's best of ``--repeat`` calls, which a loaded machine inflates less; peers
timed in the same run.

Run: ``python benchmarks/bench_ik_held.py [--poses 1000] [--ssik-poses 200]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import robokin
from robokin._native import kernels as K
from robokin.kinematics.ik import fixed as fixed_ik

SPECIAL = (0.0, np.pi / 2, -np.pi / 2, np.pi, 1e-9, -1e-9, 1e-7, -1e-7, 1e-6, -1e-6)
SAME = 1e-6  # [rad]
WRONG = 1e-9  # [m, rad]


def pose_errors(T, Tt):
    """Position [m] and rotation angle [rad] between poses (..., 4, 4)."""
    dp = np.linalg.norm(T[..., :3, 3] - Tt[..., :3, 3], axis=-1)
    R = np.swapaxes(T[..., :3, :3], -1, -2) @ Tt[..., :3, :3]
    c = np.clip((np.trace(R, axis1=-2, axis2=-1) - 1) / 2, -1, 1)
    s = np.linalg.norm(np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0],
                                 R[..., 1, 0] - R[..., 0, 1]], -1), axis=-1) / 2
    return dp, np.arctan2(s, c)


def configurations(panda, rng, n, kind):
    lim = panda.limits
    if kind == "random":
        return rng.uniform(lim[:, 0], lim[:, 1], (n, 7))
    out = []
    while len(out) < n:
        q = np.empty(7)
        for j in range(7):
            k = rng.integers(0, 13)
            q[j] = (SPECIAL[k] if k < 10 else lim[j, 0] if k == 10 else lim[j, 1] if k == 11
                    else rng.uniform(*lim[j]))
        J = panda.jacobian(q)[:, :6]
        if np.linalg.svd(J, compute_uv=False)[-1] >= 1e-4:
            out.append(q)
    return np.array(out)


def score(panda, q, T, rows):
    """(recovered, wrong rows, largest error, rows) over poses; rows: list of (k, 7)."""
    rec = wrong = total = 0
    worst = 0.0
    for i, Q in enumerate(rows):
        Q = np.asarray(Q, dtype=float).reshape(-1, 7)
        Q = Q[np.isfinite(Q).all(axis=1)]  # a NaN row is no answer
        total += len(Q)
        if not len(Q):
            continue
        dp, dr = pose_errors(panda.fk(Q), T[i])
        err = np.maximum(dp, dr)
        worst = max(worst, float(err.max()))
        wrong += int((err > WRONG).sum())
        gap = np.abs((Q - q[i] + np.pi) % (2 * np.pi) - np.pi).max(axis=1)
        rec += bool(gap.min() <= SAME)
    return rec, wrong, worst, total


def best_time(fn, repeat):
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def cpu_time(fn, repeat):
    """The best of ``repeat`` runs of ``fn`` in CPU time (``time.process_time``) [s].

    A loaded machine inflates it less than wall time: time spent waiting for a core
    is not counted (cache and frequency effects of the other processes still are).
    """
    best = np.inf
    for _ in range(repeat):
        t0 = time.process_time()
        fn()
        best = min(best, time.process_time() - t0)
    return best


def median_time(fn, args, repeat):
    """The median over poses of each pose's best of ``repeat`` calls [s].

    Robust to the load of a shared machine: a pose slowed by another process in
    one repetition keeps its best, and the median ignores the slowest poses.
    """
    best = np.full(len(args), np.inf)
    for _ in range(repeat):
        for i, a in enumerate(args):
            t0 = time.perf_counter()
            fn(*a)
            best[i] = min(best[i], time.perf_counter() - t0)
    return float(np.median(best))


def run_robokin(panda, q, T, repeat):
    held = fixed_ik._held_solvers(panda.arm)["joint7"]
    v = [float(x) for x in q[:, 6]]
    Ts = list(T)
    rows = []
    for Ti, vi in zip(Ts, v, strict=True):
        s = panda.ik(Ti, fixed={"joint7": vi})
        rows.append(s.q[s.valid])

    def loop():
        for Ti, vi in zip(Ts, v, strict=True):
            panda.ik(Ti, fixed={"joint7": vi})

    def kernel():
        for Ti, vi in zip(Ts, v, strict=True):
            K.pieper_ik1(Ti, held.params, vi, None)

    Tb = np.ascontiguousarray(T)
    vb = np.ascontiguousarray(q[:, 6])
    n = len(T)
    times = {"call": best_time(loop, repeat) / n, "kernel": best_time(kernel, repeat) / n,
             "cpu call": cpu_time(loop, repeat) / n, "cpu kernel": cpu_time(kernel, repeat) / n,
             "batch": best_time(lambda: panda.ik(Tb, fixed={"joint7": vb}), repeat) / n,
             "median call": median_time(lambda t, x: panda.ik(t, fixed={"joint7": x}),
                                        list(zip(Ts, v, strict=True)), repeat),
             "median kernel": median_time(lambda t, x: K.pieper_ik1(t, held.params, x, None),
                                          list(zip(Ts, v, strict=True)), repeat)}
    return rows, times


def run_geofik(panda, q, T, repeat):
    import geofikpy

    q0 = np.array([0.1, -0.3, 0.2, -2.0, 0.3, 1.8, 0.7])
    X = np.linalg.inv(panda.fk(q0)) @ np.asarray(geofikpy.franka_fk(q0, "E"))
    TE = T @ X
    args = [(np.ascontiguousarray(t[:3, 3]), np.ascontiguousarray(t[:3, :3]).ravel(),
             float(v)) for t, v in zip(TE, q[:, 6], strict=True)]
    rows = []
    for r, R, v in args:
        sols, k = geofikpy.franka_ik_q7(r, R, v)
        rows.append(np.array(sols[:k]))

    def loop():
        for r, R, v in args:
            geofikpy.franka_ik_q7(r, R, v)

    return rows, {"call": best_time(loop, repeat) / len(T),
                  "cpu call": cpu_time(loop, repeat) / len(T),
                  "median call": median_time(geofikpy.franka_ik_q7, args, repeat)}


def run_ssik(panda, q, T, repeat):
    import ssik

    arm = ssik.Manipulator.from_prebuilt("franka_panda_ik")
    q0 = np.array([0.1, -0.3, 0.2, -2.0, 0.3, 1.8, 0.7])
    X = np.linalg.inv(panda.fk(q0)) @ np.asarray(arm.fk(q0))
    TS = T @ X

    def solve(t, v):
        out = []
        for chart in arm.self_motion(t):
            row = chart.q(v)
            if np.all(np.isfinite(row)):
                out.append(row)
        return np.array(out).reshape(-1, 7)

    rows = [solve(t, v) for t, v in zip(TS, q[:, 6], strict=True)]

    def loop():
        for t, v in zip(TS, q[:, 6], strict=True):
            solve(t, v)

    return rows, {"call": best_time(loop, repeat) / len(T)}


def main(n: int = 1000, n_ssik: int = 200, repeat: int = 3, seed: int = 0) -> None:
    panda = robokin.load("panda")
    rng = np.random.default_rng(seed)
    print(f"robokin {robokin.__version__}, kernels {K.ISA}; poses: {n} (ssik {n_ssik})")
    header = ("| configurations | method | recovered | wrong rows (> 1e-9) | largest error | "
              "rows / pose | µs / pose |")
    print(header)
    print("|---|---|---|---|---|---|---|")
    for kind in ("random", "special"):
        q = configurations(panda, rng, n, kind)
        T = panda.fk(q)
        runs = [("robokin", run_robokin, n), ("geofikpy", run_geofik, n),
                ("ssik", run_ssik, n_ssik)]
        for name, fn, m in runs:
            try:
                rows, times = fn(panda, q[:m], T[:m], repeat)
            except ImportError as exc:
                print(f"| {kind} | {name} | not installed ({exc}) | | | | |")
                continue
            rec, wrong, worst, total = score(panda, q[:m], T[:m], rows)
            t = ", ".join(f"{k} {v * 1e6:.2f}" for k, v in times.items())
            print(f"| {kind} | {name} | {rec}/{m} = {100 * rec / m:.1f} % | {wrong} | "
                  f"{worst:.1e} | {total / m:.2f} | {t} |")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--poses", type=int, default=1000)
    ap.add_argument("--ssik-poses", type=int, default=200)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()
    main(a.poses, a.ssik_poses, a.repeat, a.seed)
