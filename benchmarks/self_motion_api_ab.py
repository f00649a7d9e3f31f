"""``robot.self_motion(T)`` on the Panda, two trees A/B: the same objects, and the CPU.

Each tree runs in a fresh process (its own ``PYTHONPATH=<tree>/src``) on the same
poses (the 1,000 random + 150 special development poses of
``held_manifold_ab.py``, seeds 2029 / 4029) and saves every public field of each
``SelfMotion``: ``T``, ``parameter``, ``joint``, ``domain``, ``periodic``,
``n_branches``, ``intervals``, ``interval_branch``, ``method``, ``info``, ``limits``,
``crossings``, ``singular`` and ``sample(t)`` / ``inside(t)`` at 9 values. The
comparison is exact (``np.array_equal``, NaN equal to NaN; the records as tuples).
Timing: the trees alternated ``--rounds`` times, ``robot.self_motion`` per pose on
the first ``--timed`` poses and the bare kernel (``held_manifold`` one pose per
call) on the same poses, alternated pose by pose, per pose the best of ``--repeat``
passes, CPU (``time.process_time``), averaged over the poses; the difference is
what the API adds (also given over the poses the kernel certifies: a flagged
pose takes the solved-points path, ~13 ms). Those differences are within the
noise of the kernel's ~1.5 ms (a few %), so the API alone is also timed with the
kernel replaced by a replay of its saved outputs (best of 20 passes over the
certified poses, minus the replay's own cost; the kernel the tree's API calls:
``held_manifold`` on one pose before session 12, ``held_manifold_one`` since, whose
new arrays the replay copies, as the kernel makes them).

Run: ``python benchmarks/self_motion_api_ab.py /work/wt/main-ref /work/wt/mine``.
"""

from __future__ import annotations

import argparse
import pathlib
import tempfile

from ab_trees import run_rounds, same

CHILD = """
import pickle, sys, time
import numpy as np
import robokin
from robokin._native import kernels as K
from robokin.kinematics.ik.self_motion_intervals import KERNEL_GRID, _aligned_values

panda = robokin.load("panda")
lo, hi = panda.limits[:, 0], panda.limits[:, 1]
SPECIAL = (0.0, np.pi / 2, -np.pi / 2, np.pi, 1e-9)


def configurations(n, special, seed):
    rng = np.random.default_rng(seed)
    q = rng.uniform(lo, hi, (n, 7))
    if special:
        pick = rng.random((n, 7)) < 0.3
        kind = rng.integers(0, len(SPECIAL) + 2, (n, 7))
        table = np.concatenate([np.broadcast_to(SPECIAL, (7, len(SPECIAL))),
                                lo[:, None], hi[:, None]], axis=1)
        q = np.where(pick, table[np.arange(7), kind], q)
        q = np.clip(q, lo, hi)
    return q


q = np.concatenate([configurations({n}, False, 2029), configurations({ns}, True, 4029)])
T = np.ascontiguousarray(panda.fk(q))
ts = np.linspace(lo[6], hi[6], 9)
if {save}:
    out = []
    for Ti in T:
        sm = panda.self_motion(Ti)
        out.append(dict(T=sm.T, parameter=sm.parameter, joint=sm.joint, domain=sm.domain,
                        periodic=sm.periodic, n_branches=sm.n_branches,
                        intervals=sm.intervals, interval_branch=sm.interval_branch,
                        method=sm.method, info=dict(sm.info), limits=sm.limits,
                        crossings=tuple(sm.crossings), singular=tuple(sm.singular),
                        sample=sm.sample(ts), inside=sm.inside(ts)))
    with open({out!r}, "wb") as f:
        pickle.dump(out, f)
Tt = T[:{timed}]
params = np.ascontiguousarray(panda.self_motion(T[0])._family.params, dtype=np.float64)
aligned = np.array([[j, v] for j, v in _aligned_values(panda.arm)],
                   dtype=np.float64).reshape(-1, 2)
iv = np.empty((1, 8, K.HM_MAXI, 2))
niv = np.zeros((1, 8), dtype=np.int64)
pts = np.empty((1, K.HM_MAXP, 4))
npts, flags, evals = (np.zeros(1, dtype=np.int64) for _ in range(3))


def kernel(Ti):
    K.held_manifold(params, Ti[None], aligned, KERNEL_GRID, iv, niv, pts, npts, flags, evals,
                    K.HM_MODE_GRID)


def api(Ti):
    panda.self_motion(Ti)


def clock(f, Ti):
    c0 = time.process_time()
    f(Ti)
    return time.process_time() - c0


# per pose the best of {repeat} passes of each (the two alternated pose by pose)
best = np.full((2, len(Tt)), np.inf)
certified = np.zeros(len(Tt), dtype=bool)
for _ in range({repeat} + 1):
    for i, Ti in enumerate(Tt):
        best[:, i] = np.minimum(best[:, i], [clock(kernel, Ti), clock(api, Ti)])
        certified[i] = flags[0] == 0
# the API alone: the kernel the API calls (main: held_manifold on (1, 4, 4); since
# session 12 held_manifold_one) replaced by a replay of its outputs (saved per pose)
import robokin.kinematics.ik.self_motion_intervals as smi
saved = {{}}
one = hasattr(K, "held_manifold_one")
name = "held_manifold_one" if one else "held_manifold"


def replay(params, T1, aligned, grid, *out):
    key = T1.tobytes()
    if key not in saved:
        saved[key] = (getattr(K, name)(params, T1, aligned, grid, *out),
                      [o.copy() for o in out if isinstance(o, np.ndarray)])
    ret, kept = saved[key]
    for o, s in zip([o for o in out if isinstance(o, np.ndarray)], kept):  # (not exact)
        o[...] = s
    # held_manifold_one returns new arrays: new copies, as the kernel makes them
    return None if ret is None else tuple(
        x.copy() if isinstance(x, np.ndarray) else x for x in ret)


class Replayed:
    def __getattr__(self, attr):
        return replay if attr == name else getattr(K, attr)


Tc = Tt[certified]
bare = np.empty((2, len(Tc)))
args = (np.empty((1, 8, K.HM_MAXI, 2)), np.zeros((1, 8), dtype=np.int64),
        np.empty((1, K.HM_MAXP, 4)), *np.zeros((3, 1, 1), dtype=np.int64))
smi.K = Replayed()
for Ti in Tc:
    panda.self_motion(Ti)
if one:
    def bare_call(Ti):
        replay(params, Ti, aligned, KERNEL_GRID, 2e-15)
else:
    def bare_call(Ti):
        replay(params, Ti[None], aligned, KERNEL_GRID, *args)
for i, f in enumerate((bare_call, api)):
    b = np.inf
    for _ in range(20):
        c0 = time.process_time()
        for Ti in Tc:
            f(Ti)
        b = min(b, time.process_time() - c0)
    bare[i] = b / len(Tc) * 1e6
smi.K = K
k, a = best.mean(axis=1) * 1e6
kc, ac = best[:, certified].mean(axis=1) * 1e6
print(f"kernel {{k:.1f}} us, self_motion {{a:.1f}} us, API adds {{a - k:.1f}} us per pose; "
      f"on the {{certified.sum()}} certified poses: kernel {{kc:.1f}}, self_motion {{ac:.1f}}, "
      f"API adds {{ac - kc:.1f}} us; the API alone (kernel replayed) {{bare[1, 0] - bare[0, 0]:.1f}} us")
"""



def main() -> None:
    """One timing line per tree and round, then the field-by-field comparison."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("trees", nargs=2)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--n", type=int, default=1000)
    ap.add_argument("--special", type=int, default=150)
    ap.add_argument("--timed", type=int, default=100)
    args = ap.parse_args()
    tmp = pathlib.Path(tempfile.mkdtemp())
    out = run_rounds(args.trees, args.rounds, tmp, lambda tree, r, out: CHILD.format(
        n=args.n, ns=args.special, save=r == 0, out=str(out), timed=args.timed,
        repeat=args.repeat))
    fields: dict[str, int] = {}
    for a, b in zip(*out, strict=True):
        for key in a:
            if not same(a[key], b[key]):
                fields[key] = fields.get(key, 0) + 1
    print(f"poses {len(out[0])}; poses with a differing field: "
          f"{fields if fields else 'none (every field equal)'}")


if __name__ == "__main__":
    main()
