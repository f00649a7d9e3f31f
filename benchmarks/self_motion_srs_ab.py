"""``robot.self_motion(T)`` on the SRS swivel, two trees A/B: the same outputs, and the CPU.

Each tree runs in a fresh process (``PYTHONPATH=<tree>/src``). Outputs: on
``--n`` configurations (``self_motion_rates.configurations``: half uniform in the
limits, half ``special_batch``, seed 29) every public field of each ``SelfMotion``
(``T``, ``parameter``, ``joint``, ``domain``, ``periodic``, ``n_branches``,
``intervals``, ``interval_branch``, ``method``, ``info``, ``limits``, ``crossings``,
``singular``, ``sample(t)`` and ``inside(t)`` at 9 values), the bare kernels'
outputs (``swivel_manifold``: intervals, counts, points; ``swivel_rows`` at 37
values per pose: rows, valid and singular flags; ``swivel_near``) are saved and
compared exactly (``np.array_equal``, NaN equal to NaN; records as tuples).

Timing (the trees alternated ``--rounds`` times; CPU, ``time.process_time``, best
of ``--repeat`` passes over the first ``--timed`` uniform poses, as
``bench_self_motion.py`` draws them, seed 0): ``robot.self_motion`` per pose; the
bare ``swivel_manifold`` one pose per call (one thread); the API alone (the kernel
replaced by a replay of its saved outputs, minus the replay's own cost); and
``sm.sample`` per (pose, value) on 64 values.

Run: ``python benchmarks/self_motion_srs_ab.py /work/wt/main-ref /work/wt/mine``.
"""

from __future__ import annotations

import argparse
import pathlib
import tempfile

from ab_trees import run_rounds, same

CHILD = """
import pathlib, pickle, sys, time
import numpy as np
root = pathlib.Path({tree!r})
sys.path[:0] = [str(root / p) for p in ("tests", "tests/kinematics/ik", "benchmarks")]
from self_motion_rates import configurations
from reference import iiwa14_srs
import robokin.kinematics.ik.swivel as swivel
from robokin._native import kernels as K
from robokin.kinematics.ik.self_motion_families import SELF_MOTION

robot = iiwa14_srs()
arm = robot.arm.derived(SELF_MOTION).swivel
if {save}:
    q, _ = configurations(robot, {n}, 29)
    T = np.ascontiguousarray(robot.fk(q))
    N = len(T)
    iv = np.full((N, 8, K.SM_MAXI, 2), np.nan)
    niv = np.empty((N, 8), np.int64)
    pts = np.full((N, K.SM_MAXP, 4), np.nan)
    npts = np.empty(N, np.int64)
    K.swivel_manifold(arm.params, T, iv, niv, pts, npts)
    kern = dict(niv=niv, npts=npts,
                iv=[iv[i][niv[i][:, None] > np.arange(K.SM_MAXI)] for i in range(N)],
                pts=[pts[i, :npts[i]] for i in range(N)])
    psi = np.tile(np.linspace(-np.pi, np.pi, 37), (N, 1)) + 0.013
    kern["rows"] = arm.rows(T, psi)
    qn = np.clip(q + 0.3, robot.limits[:, 0], robot.limits[:, 1])
    kern["near"] = arm.nearest(T, qn)
    ts = np.linspace(-np.pi, np.pi, 9) + 0.1
    api = []
    for Ti in T:
        sm = robot.self_motion(Ti)
        api.append(dict(T=sm.T, parameter=sm.parameter, joint=sm.joint, domain=sm.domain,
                        periodic=sm.periodic, n_branches=sm.n_branches,
                        intervals=sm.intervals, interval_branch=sm.interval_branch,
                        method=sm.method, info=dict(sm.info), limits=sm.limits,
                        crossings=tuple(sm.crossings), singular=tuple(sm.singular),
                        sample=sm.sample(ts), inside=sm.inside(ts)))
    with open({out!r}, "wb") as f:
        pickle.dump(dict(kern=kern, api=api), f)

rng = np.random.default_rng(0)
qt = rng.uniform(robot.limits[:, 0], robot.limits[:, 1], ({timed}, 7))
Tt = [np.ascontiguousarray(t) for t in robot.fk(qt)]
T1 = [t[None] for t in Tt]
o = (np.empty((1, 8, K.SM_MAXI, 2)), np.empty((1, 8), np.int64),
     np.empty((1, K.SM_MAXP, 4)), np.empty(1, np.int64))


def best(f, reps={repeat}):
    b = np.inf
    for _ in range(reps):
        c0 = time.process_time()
        f()
        b = min(b, time.process_time() - c0)
    return b / len(Tt) * 1e6


api = best(lambda: [robot.self_motion(t) for t in Tt])
kern1 = best(lambda: [K.swivel_manifold(arm.params, t, *o) for t in T1])
sms = [robot.self_motion(t) for t in Tt]
t64 = np.linspace(-np.pi, np.pi, 64)
samp = best(lambda: [sm.sample(t64) for sm in sms]) / 64
saved = {{}}


def replayer(name):
    kernel = getattr(K, name)

    def replay(params, T, *out):
        key = T.tobytes()
        if key not in saved:
            saved[key] = (kernel(params, T, *out), [x.copy() for x in out])
        ret, outs = saved[key]
        for x, s in zip(out, outs):
            x[...] = s
        # swivel_manifold_one returns new arrays: new copies, as the kernel makes them
        # (and since round 8d its close flag, a bool)
        return None if ret is None else tuple(
            x.copy() if isinstance(x, np.ndarray) else x for x in ret)
    return replay


# the kernel the API calls (main: swivel_manifold on (1, 4, 4); since round 8c
# swivel_manifold_one) replaced by a replay of its outputs
one = hasattr(K, "swivel_manifold_one")
name = "swivel_manifold_one" if one else "swivel_manifold"
replay = replayer(name)


class Replayed:
    def __getattr__(self, attr):
        return replay if attr == name else getattr(K, attr)


swivel.K = Replayed()
for t in Tt:
    robot.self_motion(t)
alone = best(lambda: [robot.self_motion(t) for t in Tt], 3 * {repeat})
if one:
    bare = best(lambda: [replay(arm.params, t) for t in Tt], 3 * {repeat})
else:
    bare = best(lambda: [replay(arm.params, t, *o) for t in T1], 3 * {repeat})
swivel.K = K
print(f"self_motion {{api:.2f}} us, kernel one pose per call {{kern1:.2f}} us, "
      f"API alone (kernel replayed) {{alone - bare:.2f}} us per pose; sample {{samp:.3f}} us "
      f"per (pose, value)")
"""



def main() -> None:
    """One timing line per tree and round, then the field-by-field comparison."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("trees", nargs=2)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--n", type=int, default=4000)
    ap.add_argument("--timed", type=int, default=100)
    args = ap.parse_args()
    tmp = pathlib.Path(tempfile.mkdtemp())
    out = run_rounds(args.trees, args.rounds, tmp, lambda tree, r, out: CHILD.format(
        tree=tree, n=args.n, save=r == 0, out=str(out), timed=args.timed, repeat=args.repeat))
    bad: dict[str, int] = {}
    for key in out[0]["kern"]:
        x, y = out[0]["kern"][key], out[1]["kern"][key]
        if isinstance(x, list):
            n = sum(not same(u, v) for u, v in zip(x, y, strict=True))
        else:
            n = 0 if same(x, y) else 1
        if n:
            bad[f"kernel {key}"] = n
    for a, b in zip(out[0]["api"], out[1]["api"], strict=True):
        for key in a:
            if not same(a[key], b[key]):
                bad[key] = bad.get(key, 0) + 1
    print(f"poses {len(out[0]['api'])}; differing: "
          f"{bad if bad else 'none (every field and kernel output equal)'}")


if __name__ == "__main__":
    main()
