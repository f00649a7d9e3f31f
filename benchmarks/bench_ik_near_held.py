"""CPU per pose of ``panda.ik_near(T, q_near, method="self_motion")`` (issue 29, held q7).

30 seeded random in-limit poses, q_near = q0 + N(0, 0.3) per joint, one pose per
call, ``time.process_time`` over ``--repeat`` runs; also the distance of each
answer to q_near against the best of 5,000 values through ``SelfMotion.sample``
(inside the limits). Run it with PYTHONPATH on the tree to measure (before/after).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import robokin
from robokin.spatial import wrap_angle


def main(n: int = 30, repeat: int = 3, seed: int = 0) -> None:
    robot = robokin.load("panda")
    rng = np.random.default_rng(seed)
    lo, hi = robot.limits[:, 0], robot.limits[:, 1]
    q0 = rng.uniform(lo, hi, size=(n, 7))
    qn = q0 + rng.normal(0.0, 0.3, size=(n, 7))
    T = robot.fk(q0)
    for r in range(repeat):
        t0 = time.process_time()
        res = [robot.ik_near(T[i], qn[i], method="self_motion") for i in range(n)]
        cpu = (time.process_time() - t0) / n
        print(f"run {r}: {cpu * 1e3:.3f} ms CPU per pose")
    worse, gap = 0, 0.0
    for i in range(n):
        sm = robot.self_motion(T[i])
        Q = sm.sample(np.linspace(*sm.domain, 5000), within_limits=True).reshape(-1, 7)
        d = np.linalg.norm(wrap_angle(Q - qn[i]), axis=-1)
        best = np.nanmin(d) if np.isfinite(d).any() else np.inf
        got = np.linalg.norm(wrap_angle(res[i].q - qn[i])) if res[i].success else np.inf
        worse += got > best + 1e-12
        gap = max(gap, got - best)
    print(f"farther than the best of 5,000 samples: {worse}/{n} (largest excess {gap:.2e} rad)")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=30)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()
    main(a.n, a.repeat, a.seed)
