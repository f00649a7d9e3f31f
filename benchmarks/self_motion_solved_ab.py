"""``robot.self_motion(T)`` on the solved-points path, two trees A/B: the same objects, the CPU.

The poses the compiled held kernel flags (the rtb-data iiwa14 URDF, every pose; the
Gen3-like arm, ~36 % of its special poses) take the solved-points path
(``self_motion_intervals``); the Panda's certified poses take the kernel
(``_compiled``) and must not get slower. Each tree runs in a fresh process
(``PYTHONPATH=<tree>/src``) on the same configurations
(``self_motion_rates.configurations(robot, 2 --n, --seed)``: ``--n`` uniform in the
limits, then ``--n`` from ``special_batch``), after untimed calls per arm up to the
first pose the kernel flags (the per-arm set-ups of both paths: reduced chains,
families); per pose the CPU
(``time.process_time``) of ``robot.self_motion(T)`` alone, the trees alternated
``--rounds`` times. Round 0 saves every public field of each ``SelfMotion``
(intervals, branches, crossings, singular points, ``method``, ``info``) and
``sample(t)`` / ``inside(t)`` at ``--values`` values over the domain and at the
generating configuration's own parameter value; the comparison is exact, field by
field (``ab_trees.same``), and the differing fields are counted.

Timing lines per tree and arm: the mean over each half (uniform, special) split by
path (``solved``: ``info["compiled"]`` not True; ``compiled``), each pose the best
of its rounds.

Run: ``python benchmarks/self_motion_solved_ab.py TREE_A TREE_B [--arms iiwa_urdf,gen3_like,panda]``.
"""

from __future__ import annotations

import argparse
import pathlib
import pickle
import tempfile

import numpy as np
from ab_trees import run_rounds, same

CHILD = """
import pathlib, pickle, sys, time
import numpy as np
ROOT = pathlib.Path({tree!r})
sys.path[:0] = [str(ROOT / p) for p in ("tests", "tests/kinematics/ik", "benchmarks")]
from self_motion_rates import build, configurations

out, cpu, path = {{}}, {{}}, {{}}
for arm in {arms!r}:
    robot = build(arm)
    q, _ = configurations(robot, 2 * {n}, {seed})
    T = robot.fk(q)
    for Tw in (robot.fk(q[0] * 0.5), *T):  # the per-arm set-ups of both paths, untimed:
        if robot.self_motion(Tw).info.get("compiled") is not True:  # to the first
            break  # pose the kernel flags (its path's reduced chains, ~0.2 s on the Panda)
    res, ts, solved = [], [], []
    for qi, Ti in zip(q, T):
        c0 = time.process_time()
        sm = robot.self_motion(Ti)
        ts.append(time.process_time() - c0)
        solved.append(sm.info.get("compiled") is not True)
        if {save}:
            tv = np.append(np.linspace(*sm.domain, {values}), qi[sm.joint])
            res.append(dict(intervals=sm.intervals, interval_branch=sm.interval_branch,
                            method=sm.method, info=dict(sm.info),
                            crossings=tuple(sm.crossings), singular=tuple(sm.singular),
                            sample=sm.sample(tv), inside=sm.inside(tv)))
    out[arm], cpu[arm], path[arm] = res, np.array(ts), np.array(solved)
    print(arm, f"{{1e3 * np.mean(ts):.1f}} ms per pose", end="; ")
with open({out!r} + ".cpu{round}", "wb") as f:
    pickle.dump((cpu, path), f)
if {save}:
    with open({out!r}, "wb") as f:
        pickle.dump(out, f)
"""


def main() -> None:
    """One line per tree and round, the best-of-rounds means by half and path, the comparison."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("trees", nargs=2)
    ap.add_argument("--arms", default="iiwa_urdf,gen3_like,panda")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--n", type=int, default=40)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--values", type=int, default=33)
    args = ap.parse_args()
    arms = args.arms.split(",")
    tmp = pathlib.Path(tempfile.mkdtemp())
    out = run_rounds(args.trees, args.rounds, tmp, lambda tree, r, o: CHILD.format(
        tree=tree, arms=arms, n=args.n, seed=args.seed, values=args.values, save=r == 0,
        out=str(o), round=r))
    for name in "AB":
        runs = [pickle.loads((tmp / f"{name}.pkl.cpu{r}").read_bytes()) for r in range(args.rounds)]
        for arm in arms:
            best = np.min([c[arm] for c, _ in runs], axis=0) * 1e3
            solved = runs[0][1][arm]
            parts = []
            for half, sl in (("uniform", slice(None, args.n)), ("special", slice(args.n, None))):
                for label, mask in (("solved", solved[sl]), ("compiled", ~solved[sl])):
                    if mask.any():
                        parts.append(f"{half} {label} {best[sl][mask].mean():.2f} ms "
                                     f"({int(mask.sum())})")
            print(f"{name} {arm}: " + ", ".join(parts) + " (best of rounds)")
    for arm in arms:
        fields: dict[str, int] = {}
        for a, b in zip(out[0][arm], out[1][arm], strict=True):
            for key in a:
                if not same(a[key], b[key]):
                    fields[key] = fields.get(key, 0) + 1
        print(f"{arm}: poses {len(out[0][arm])}; poses with a differing field: "
              f"{fields if fields else 'none (every field equal)'}")


if __name__ == "__main__":
    main()
