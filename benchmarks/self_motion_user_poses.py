"""The Panda's whole manifold at the poses users type: every joint a multiple of pi/4.

Configurations drawn (``--seed``, ``--n``, duplicates dropped) with each joint one of
its values k pi / 4 (k = -4..4) inside the Panda's limits (q2 from 5 of them: a fifth
have the shoulder aligned, q2 = 0, where q1 and q3 swing by pi). Per pose:
``robot.self_motion(fk(q))``, CPU (``time.process_time``) best of ``--repeat``, and
whether the compiled kernel certified it (``info["compiled"]``) or flagged it (which
flag: ``held_manifold.c``'s HM_FLAG_*) for the solved-points path. ``--check`` also holds
every certified pose with q2 = 0 to the tests' two oracles
(``tests/kinematics/ik/test_self_motion_intervals.py``: ``_check_dense``,
``_check_against_solved_points``) and prints each failure.

Run: ``python benchmarks/self_motion_user_poses.py [--n 1000] [--seed 0] [--repeat 3]
[--check]``; to compare two trees, run it with each tree's ``src`` first on
``PYTHONPATH`` (each built).
"""

from __future__ import annotations

import argparse
import collections
import pathlib
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / p) for p in ("tests", "tests/kinematics/ik")]

import robokin  # noqa: E402

#: held_manifold.c's flag bits, by name
FLAGS = {1: "SINGULAR", 2: "UNRESOLVED", 4: "CONVERGE", 8: "FULL", 16: "VANISH",
         32: "MEMORY", 64: "BAD"}


def poses(robot: robokin.Robot, n: int, seed: int) -> np.ndarray:
    """(m, 7) distinct configurations, every joint one of its in-limit k pi / 4 (k = -4..4)."""
    rng = np.random.default_rng(seed)
    steps = np.arange(-4, 5) * (np.pi / 4)
    cols = [rng.choice(steps[(steps >= lo) & (steps <= hi)], n) for lo, hi in robot.limits]
    return np.unique(np.stack(cols, axis=-1), axis=0)


def main(n: int, seed: int, repeat: int, check: bool) -> None:
    robot = robokin.load("panda")
    qs = poses(robot, n, seed)
    print(f"robokin from {robokin.__file__}; {len(qs)} poses (seed {seed})")
    kinds: collections.Counter[str] = collections.Counter()
    cpu = {"certified": [], "flagged": []}
    aligned = {"certified": 0, "flagged": 0}
    failures = 0
    for q in qs:
        T = robot.fk(q)
        best = np.inf
        for _ in range(repeat):
            c0 = time.process_time()
            sm = robot.self_motion(T)
            best = min(best, time.process_time() - c0)
        ok = bool(sm.info.get("compiled"))
        key = "certified" if ok else "flagged"
        cpu[key].append(best)
        flag = int(sm.info.get("flags", 0))
        kinds["certified" if ok else FLAGS.get(flag, str(flag))] += 1
        if abs(q[1]) < 1e-12:
            aligned[key] += 1
            if ok and check:
                import test_self_motion_intervals as tsi

                for name, fn in (("_check_dense", lambda: tsi._check_dense(sm)),
                                 ("_check_against_solved_points",
                                  lambda: tsi._check_against_solved_points(robot, T, sm))):
                    try:
                        fn()
                    except AssertionError as e:
                        failures += 1
                        print(f"  {name} failed: q / (pi/4) = "
                              f"{np.round(q / (np.pi / 4)).astype(int).tolist()}: {str(e)[:160]}")
    allt = np.array(cpu["certified"] + cpu["flagged"])
    print(f"certified {len(cpu['certified'])}, flagged {len(cpu['flagged'])} "
          f"({', '.join(f'{k} {v}' for k, v in sorted(kinds.items()) if k != 'certified')})")
    print(f"shoulder aligned (q2 = 0): certified {aligned['certified']}, "
          f"flagged {aligned['flagged']}")
    for key in ("certified", "flagged"):
        t = np.array(cpu[key])
        if len(t):
            print(f"  {key:9s} CPU per pose: median {1e3 * np.median(t):.2f} ms, "
                  f"mean {1e3 * t.mean():.2f} ms, largest {1e3 * t.max():.2f} ms")
    print(f"  all       CPU per pose: mean {1e3 * allt.mean():.2f} ms")
    if check:
        print(f"oracle failures on certified aligned poses: {failures}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1000, help="configurations drawn")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--check", action="store_true", help="the tests' oracles on aligned poses")
    a = ap.parse_args()
    main(a.n, a.seed, a.repeat, a.check)
