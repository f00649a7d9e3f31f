"""``robot.self_motion(T)`` on the near-SRS arms, two trees A/B: the same objects, and the CPU.

The arms whose ``auto`` parameter is a held joint with a closed form but whose
manifold the compiled held kernel does not certify (the rtb-data iiwa14 URDF,
joint_a3 held; the Gen3-like arm, joint_3 held: ``self_motion_rates.py``'s ``MID``
arms). Each tree runs in a fresh process (``PYTHONPATH=<tree>/src``) on the same
configurations (``self_motion_rates.configurations(robot, 2 --n, --seed)``: ``--n``
uniform in the limits, then ``--n`` from ``special_batch``) and saves every public
field of each ``SelfMotion`` (as ``self_motion_api_ab.py``: intervals, branches,
crossings, singular points, ``info``, ``sample(t)`` / ``inside(t)`` at 9 values); the
comparison is exact, field by field, and the ``info`` keys that differ are named.
Timing: per pose the CPU (``time.process_time``) of one call, the trees alternated
``--rounds`` times; per tree the mean over uniform and over special poses, each the
best of its rounds.

Run: ``python benchmarks/self_motion_near_srs_ab.py TREE_A TREE_B [--arms iiwa_urdf,gen3_like]``.
"""

from __future__ import annotations

import argparse
import pathlib
import tempfile

import numpy as np
from ab_trees import run_rounds, same

CHILD = """
import pathlib, pickle, sys, time
import numpy as np
ROOT = pathlib.Path({tree!r})
sys.path[:0] = [str(ROOT / p) for p in ("tests", "tests/kinematics/ik", "benchmarks")]
from self_motion_rates import build, configurations

out, cpu = {{}}, {{}}
for arm in {arms!r}:
    robot = build(arm)
    q, _ = configurations(robot, 2 * {n}, {seed})
    T = robot.fk(q)
    res, ts = [], []
    for Ti in T:
        c0 = time.process_time()
        sm = robot.self_motion(Ti)
        ts.append(time.process_time() - c0)
        if {save}:
            t9 = np.linspace(*sm.domain, 9)
            res.append(dict(intervals=sm.intervals, interval_branch=sm.interval_branch,
                            method=sm.method, info=dict(sm.info),
                            crossings=tuple(sm.crossings), singular=tuple(sm.singular),
                            sample=sm.sample(t9), inside=sm.inside(t9)))
    out[arm], cpu[arm] = res, np.array(ts)
    print(arm, f"uniform {{1e3 * np.mean(ts[:{n}]):.1f}} ms, special "
               f"{{1e3 * np.mean(ts[{n}:]):.1f}} ms per pose", end="; ")
with open({out!r} + (".cpu{round}"), "wb") as f:
    pickle.dump(cpu, f)
if {save}:
    with open({out!r}, "wb") as f:
        pickle.dump(out, f)
"""


def main() -> None:
    """One timing line per tree and round, the best-of-rounds means, then the comparison."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("trees", nargs=2)
    ap.add_argument("--arms", default="iiwa_urdf,gen3_like")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--n", type=int, default=40)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    arms = args.arms.split(",")
    tmp = pathlib.Path(tempfile.mkdtemp())
    out = run_rounds(args.trees, args.rounds, tmp, lambda tree, r, o: CHILD.format(
        tree=tree, arms=arms, n=args.n, seed=args.seed, save=r == 0, out=str(o), round=r))
    import pickle

    for name in "AB":
        cpu = [pickle.loads((tmp / f"{name}.pkl.cpu{r}").read_bytes()) for r in range(args.rounds)]
        for arm in arms:
            best = np.min([c[arm] for c in cpu], axis=0) * 1e3
            print(f"{name} {arm}: uniform {best[:args.n].mean():.2f} ms, "
                  f"special {best[args.n:].mean():.2f} ms per pose (best of rounds)")
    for arm in arms:
        fields: dict[str, int] = {}
        info: dict[str, int] = {}
        for a, b in zip(out[0][arm], out[1][arm], strict=True):
            for key in a:
                if not same(a[key], b[key]):
                    fields[key] = fields.get(key, 0) + 1
            for key in a["info"].keys() | b["info"].keys():
                if not same(a["info"].get(key), b["info"].get(key)):
                    info[key] = info.get(key, 0) + 1
        print(f"{arm}: poses {len(out[0][arm])}; poses with a differing field: "
              f"{fields if fields else 'none (every field equal)'}; info keys: {info}")


if __name__ == "__main__":
    main()
