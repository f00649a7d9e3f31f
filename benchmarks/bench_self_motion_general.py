"""General 7R arms (issue 29): per (pose, value) held-joint solves and the continued manifold.

Two arms without a held-joint closed form (``tests/reference.py``): the iiwa14-type SRS
arm with a 1 cm shoulder offset (``offset_iiwa14``) and a random general 7R DH arm
(``random_7r(29)``); joint 7 is the parameter. Configurations: uniform in the limits
(``--poses``) and special (each joint with probability 0.3 at 0, +-pi/2, pi, +-1e-9 or
a limit, clipped into the limits).

Measured per arm and kind:

* ``robot.ik(T, fixed={joint7: v})``, one call per value (32 values per pose) and one
  swept call (``fixed={joint7: array}``), CPU per (pose, value);
* the generating configuration among the rows at its own q7 (within 1e-6 rad:
  recovered), and the worst pose error of every returned row (rows above 1e-12
  counted);
* ``robot.self_motion(T, parameter=joint7)``: the whole continued manifold, CPU per
  pose; ``sm.sample(t)`` at 64 values, CPU per (pose, value); the generating
  configuration on a branch at its own q7;
* ``--profile``: cProfile of the manifolds (the top entries by own time).

Run: ``python benchmarks/bench_self_motion_general.py [--poses 20] [--profile]``.
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from reference import offset_iiwa14, pose_errors, random_7r  # noqa: E402

SPECIAL = (0.0, np.pi / 2, -np.pi / 2, np.pi, 1e-9, -1e-9)
VALUES = 32
SAMPLES = 64


def configurations(robot, rng, n, special):
    lo, hi = robot.limits[:, 0], robot.limits[:, 1]
    q = rng.uniform(lo, hi, (n, robot.n))
    if special:
        pick = rng.random(q.shape) < 0.3
        choice = rng.choice(np.array(SPECIAL + (np.inf, -np.inf)), q.shape)
        vals = np.where(np.isinf(choice), np.where(choice > 0, hi, lo), choice)
        q = np.where(pick, np.clip(vals, lo, hi), q)
    return q


def wrapped(a):
    return np.abs((a + np.pi) % (2 * np.pi) - np.pi)


def cpu(fn):
    c0 = time.process_time()
    out = fn()
    return out, time.process_time() - c0


def held_solves(robot, q, T):
    """Per-value CPU (single calls, swept calls), recovered, worst error, rows > 1e-12."""
    name = robot.joint_names[-1]
    lo, hi = robot.limits[-1]
    rec, worst, wrong = 0, 0.0, 0
    single = swept = 0.0
    for qi, Ti in zip(q, T, strict=True):
        vals = np.concatenate([[qi[-1]], np.linspace(lo, hi, VALUES - 1)])
        sets, c = cpu(lambda Ti=Ti, vals=vals: [robot.ik(Ti, fixed={name: float(v)})
                                                for v in vals])
        single += c
        _, c = cpu(lambda Ti=Ti, vals=vals: robot.ik(Ti, fixed={name: vals}))
        swept += c
        rows = sets[0].q[sets[0].valid]
        rec += bool(len(rows) and wrapped(rows - qi).max(-1).min() < 1e-6)
        allq = np.concatenate([s.q[s.valid] for s in sets]).reshape(-1, robot.n)
        if len(allq):
            dp, dr = pose_errors(robot.fk(allq), Ti)
            e = np.maximum(dp, dr)
            worst = max(worst, float(e.max()))
            wrong += int((e > 1e-12).sum())
    n = len(q) * VALUES
    return single / n, swept / n, rec, worst, wrong


def manifolds(robot, q, T, profile):
    name = robot.joint_names[-1]
    sms, c = cpu(lambda: [robot.self_motion(Ti, parameter=name) for Ti in T])
    rec = 0
    for sm, qi in zip(sms, q, strict=True):
        rows = sm.sample(qi[-1])
        rec += bool(np.isfinite(rows).all(-1).any()
                    and np.nanmin(wrapped(rows - qi).max(-1)) < 1e-6)
    ts = [np.linspace(*sm.domain, SAMPLES) for sm in sms]
    _, cs = cpu(lambda: [sm.sample(t) for sm, t in zip(sms, ts, strict=True)])
    if profile:
        pr = cProfile.Profile()
        pr.enable()
        for Ti in T:
            robot.self_motion(Ti, parameter=name)
        pr.disable()
        pstats.Stats(pr).sort_stats("tottime").print_stats(12)
    solves = np.mean([sm.info.get("solves", 0) for sm in sms])
    return c / len(T), cs / (len(T) * SAMPLES), rec, solves, sms[0].method


def main(poses: int, seed: int, profile: bool) -> None:
    print(f"CPU times (time.process_time); {poses} poses per arm and kind; seed {seed}")
    for robot in (offset_iiwa14(), random_7r(29)):
        robot.ik(robot.fk(np.zeros(7)), fixed={robot.joint_names[-1]: 0.0})  # set-up
        for special in (False, True):
            rng = np.random.default_rng(seed)
            q = configurations(robot, rng, poses, special)
            T = robot.fk(q)
            kind = "special" if special else "uniform"
            one, swept, rec, worst, wrong = held_solves(robot, q, T)
            print(f"{robot.name:12s} {kind:8s} ik(T, fixed=...): {one * 1e6:7.1f} us per "
                  f"single call, {swept * 1e6:6.1f} us per swept value; recovered "
                  f"{rec}/{poses}; rows above 1e-12: {wrong} (max error {worst:.1e})")
            man, per, rec, solves, method = manifolds(robot, q, T, profile)
            print(f"{robot.name:12s} {kind:8s} self_motion [{method}]: {man * 1e3:7.1f} ms "
                  f"per pose ({solves:.0f} values solved), sample {per * 1e6:6.1f} us per "
                  f"(pose, value); generating q on a branch {rec}/{poses}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--poses", type=int, default=20)
    ap.add_argument("--seed", type=int, default=29)
    ap.add_argument("--profile", action="store_true")
    a = ap.parse_args()
    main(a.poses, a.seed, a.profile)
