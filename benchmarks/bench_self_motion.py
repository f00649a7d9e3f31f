"""The self-motion manifold of one pose: robokin against ssik (charts) and geofikpy.

Every method gets the same poses ``robot.fk(q)``:

* robokin ``robot.self_motion(T)``: every branch and the exact in-limit intervals
  of the pose (q7 on the Panda through the held-joint ``pieper`` kernel; the
  swivel on the exact iiwa14-type SRS arm, ``tests/reference.py``). Timed: the
  whole manifold per pose, and ``sm.sample(t)`` per (pose, value) on 64 values;
* ssik 8.2 (Panda): ``Manipulator.from_prebuilt("franka_panda_ik").self_motion(T)``,
  its charts q(q7) (He and Liu on the reversed chain); timed: the charts per pose
  (without interval ends: ssik gives chart domains, not joint-limit intervals);
* geofikpy (Panda): ``franka_ik_q7(r, R, q7)``, per (pose, value).

Scored (``bench_ik_held.score``): the generating configuration among the rows at its
own q7 / swivel (within 1e-6 rad), rows with a pose error above 1e-9 (wrong) and
the largest error. Configurations uniform in the limits. Times: best of
``--repeat`` runs, peers in the same run.

Run: ``python benchmarks/bench_self_motion.py [--poses 200]``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from bench_ik_held import best_time, run_geofik, run_ssik, score

import robokin

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from reference import iiwa14_srs  # noqa: E402


def parameter_of(sm, q):
    if sm.joint is not None:
        return float(q[sm.joint])
    return float(sm._family.arm.swivel_of(sm._family.fr, q))


def run_robokin(robot, q, T, repeat):
    sms = [robot.self_motion(t) for t in T]
    rows = [sm.sample(parameter_of(sm, qi)) for sm, qi in zip(sms, q, strict=True)]
    # every sampled row of every pose (64 values) for the wrong-row count
    grid = [sm.sample(np.linspace(*sm.domain, 64)).reshape(-1, 7) for sm in sms]
    whole = best_time(lambda: [robot.self_motion(t) for t in T], repeat) / len(T)
    t64 = np.linspace(-1.0, 1.0, 64)
    per_value = best_time(lambda: [sm.sample(t64) for sm in sms], repeat) / (64 * len(T))
    return rows, grid, {"manifold": whole, "per value": per_value}


def main(n: int = 200, repeat: int = 3, seed: int = 0) -> None:
    rng = np.random.default_rng(seed)
    print(f"robokin {robokin.__version__}; poses per arm: {n}; best of {repeat}")
    for name, robot in (("panda", robokin.load("panda")), ("iiwa14 SRS", iiwa14_srs())):
        q = rng.uniform(robot.limits[:, 0], robot.limits[:, 1], (n, 7))
        T = robot.fk(q)
        robot.self_motion(T[0])  # set-up (held-joint solvers, reduced chains)
        rows, grid, times = run_robokin(robot, q, T, repeat)
        rec, _, _, _ = score(robot, q, T, rows)
        _, wrong, worst, total = score(robot, q, T, grid)
        print(f"{name:11s} robokin self_motion: recovered {rec}/{n}, wrong {wrong} of {total}"
              f" sampled rows (max error {worst:.1e}); whole manifold "
              f"{times['manifold'] * 1e3:.1f} ms/pose, sample {times['per value'] * 1e6:.1f}"
              " us per (pose, value)")
        if name != "panda":
            continue
        for peer, fn in (("ssik charts", run_ssik), ("geofikpy q7", run_geofik)):
            try:
                prow, ptimes = fn(robot, q, T, repeat)
            except ImportError as exc:
                print(f"{name:11s} {peer}: not installed ({exc})")
                continue
            rec, wrong, worst, total = score(robot, q, T, prow)
            what = "per pose (charts)" if peer.startswith("ssik") else "per (pose, value)"
            print(f"{name:11s} {peer}: recovered {rec}/{n}, wrong {wrong} of {total} rows "
                  f"(max error {worst:.1e}); {ptimes['call'] * 1e6:.1f} us {what}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--poses", type=int, default=200)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()
    main(a.poses, a.repeat, a.seed)
