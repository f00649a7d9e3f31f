"""The Panda's compiled self-motion kernel (``held_manifold``), two trees A/B in turn.

The development set of issue 29: 1,000 configurations uniform in the limits (seed
2029) and 150 special-value ones (seed 4029: each joint with probability 0.3 at 0,
+-pi/2, pi, 1e-9 or a limit), built as ``tests/kinematics/ik/test_self_motion_intervals.py``
builds them. Per tree and round, in a fresh process: the bare kernel one pose per
call on the 1,150 poses (``time.process_time``, the best of ``--repeat`` passes),
the trees alternating for ``--rounds`` rounds. Then the outputs of the trees are
compared: the same poses flagged, and on the others the same intervals per branch
(ends to ``--tol``) and the same points; printed: CPU per pose, full pk_one solves
per pose (the kernel's ``evals``; a tree built with ``-DHM_COUNT_CHEAP`` counts
every row evaluation instead; one built with ``-DHM_VERIFY`` has its row mismatches
against pk_one counted), the flags and the largest interval-end differences, with the
poses (at most 20 of each kind; indices into the uniform poses, then the special ones)
flagged by one tree only, with another interval count, or with an end moved.

Run: ``python benchmarks/held_manifold_ab.py A_SRC B_SRC [--rounds 2] [--repeat 2]``
(each a ``src`` directory with its kernels built).
"""

from __future__ import annotations

import argparse
import os
import pathlib
import subprocess
import sys
import tempfile

import numpy as np

CHILD = """
import sys, time
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
params = np.ascontiguousarray(panda.self_motion(T[0])._family.params, dtype=np.float64)
aligned = np.array([[j, v] for j, v in _aligned_values(panda.arm)],
                   dtype=np.float64).reshape(-1, 2)
N = len(T)
# (trees before session 26 have no mode argument; {mode}: HM_MODE_* by name)
MODE = (getattr(K, "HM_MODE_{mode}"),) if hasattr(K, "HM_MODE_AUTO") else ()
iv = np.empty((N, 8, K.HM_MAXI, 2))
niv = np.zeros((N, 8), dtype=np.int64)
pts = np.empty((N, K.HM_MAXP, 4))
npts, flags, evals = (np.zeros(N, dtype=np.int64) for _ in range(3))


def one_pass():
    for i in range(N):
        K.held_manifold(params, T[i:i + 1], aligned, KERNEL_GRID, iv[i:i + 1], niv[i:i + 1],
                        pts[i:i + 1], npts[i:i + 1], flags[i:i + 1], evals[i:i + 1], *MODE)


one_pass()
best = np.inf
for _ in range({repeat}):
    c0 = time.process_time()
    one_pass()
    best = min(best, time.process_time() - c0)
np.savez({out!r}, iv=iv, niv=niv, pts=pts, npts=npts, flags=flags, evals=evals)
print(f"{{best / N * 1e3:.3f}} {{evals.mean():.1f}}")
"""


def pieces(iv: np.ndarray) -> np.ndarray:
    """A branch's intervals (k, 2) with touching points merged: a zero-width interval
    within 1e-9 of another interval's end dropped, gaps below 1e-12 closed."""
    out: list[list[float]] = []
    wide = iv[iv[:, 1] - iv[:, 0] > 1e-12]
    for a, e in iv.tolist():
        if e - a <= 1e-12 and wide.size and np.min(np.abs(wide - a)) < 1e-9:
            continue
        if out and a - out[-1][1] < 1e-12:
            out[-1][1] = max(out[-1][1], e)
        else:
            out.append([a, e])
    return np.array(out).reshape(-1, 2)


def compare_pieces(a: dict, b: dict, tol: float) -> str:
    """Poses whose merged intervals (``pieces``) differ in count or by more than tol."""
    both = (a["flags"] == 0) & (b["flags"] == 0)
    count, off, worst = 0, 0, 0.0
    for i in np.flatnonzero(both):
        d = 0.0
        for br in range(8):
            pa = pieces(a["iv"][i, br, :a["niv"][i, br]])
            pb = pieces(b["iv"][i, br, :b["niv"][i, br]])
            if pa.shape != pb.shape:
                count += 1
                d = -1.0
                break
            if pa.size:
                d = max(d, float(np.max(np.abs(pa - pb))))
        if d >= 0.0:
            worst = max(worst, d)
            off += d > tol
    return (f"touching points merged: poses with a different count {count}, with an end "
            f"more than {tol:g} off {off} (largest {worst:.2e})")


def compare(a: dict, b: dict, tol: float) -> str:
    """The flags, interval and point differences between two trees' outputs.

    Interval ends are compared per kind: an end at one of A's fold points of that
    branch (a branch end, located to the kernel's HM_FOLD_TOL = 1e-11 relative) is
    counted apart from the others (limit crossings, the range's ends).
    """
    fa, fb = a["flags"] != 0, b["flags"] != 0
    both = ~fa & ~fb
    worst = {"fold": 0.0, "other": 0.0}
    poses = {"fold": 0, "other": 0}
    diff_n, diff_pts, shown, moved = 0, 0, [], []
    for i in np.flatnonzero(both):
        if not np.array_equal(a["niv"][i], b["niv"][i]):
            diff_n += 1
            shown.append(int(i))
            continue
        p = a["pts"][i, :a["npts"][i]]
        d = {"fold": 0.0, "other": 0.0}
        for br in range(8):
            k = a["niv"][i, br]
            if not k:
                continue
            ea, eb = a["iv"][i, br, :k].ravel(), b["iv"][i, br, :k].ravel()
            folds = p[(p[:, 1] == br) & (p[:, 3] == 3), 0]
            for x, y in zip(ea, eb, strict=True):
                kind = "fold" if folds.size and np.min(np.abs(folds - x)) < 1e-9 else "other"
                d[kind] = max(d[kind], abs(x - y))
        for kind in d:
            worst[kind] = max(worst[kind], d[kind])
            poses[kind] += d[kind] > tol
        if max(d.values()) > tol:
            moved.append(int(i))
        diff_pts += a["npts"][i] != b["npts"][i]
    changed = np.flatnonzero(fa != fb)
    return (f"flagged A {int(fa.sum())} B {int(fb.sum())} (same poses: "
            f"{bool(np.array_equal(fa, fb))}; flagged in A only {changed[fa[changed]][:20].tolist()}, "
            f"in B only {changed[fb[changed]][:20].tolist()}); poses with a different interval count "
            f"{diff_n} {shown[:20]}; poses with an end more than {tol:g} off: at a fold {poses['fold']} "
            f"(largest {worst['fold']:.2e}), elsewhere {poses['other']} (largest "
            f"{worst['other']:.2e}) {moved[:20]}; different point counts {diff_pts}")


def compare_points(a: dict, b: dict, tol: float) -> str:
    """The points of poses neither tree flagged, per kind (folds, aligned points, limit
    crossings): poses whose points of a (branch, joint, kind) differ in count, and the
    largest move of a point where the counts agree."""
    both = (a["flags"] == 0) & (b["flags"] == 0)
    names = {3: "folds", 2: "aligned", 0: "crossings", 1: "crossings"}
    count = dict.fromkeys(names.values(), 0)
    moved = dict.fromkeys(names.values(), 0)
    worst = dict.fromkeys(names.values(), 0.0)
    for i in np.flatnonzero(both):
        pa, pb = a["pts"][i, :a["npts"][i]], b["pts"][i, :b["npts"][i]]
        keys = {tuple(r) for r in pa[:, 1:]} | {tuple(r) for r in pb[:, 1:]}
        off = dict.fromkeys(names.values(), 0.0)
        bad = dict.fromkeys(names.values(), False)
        for key in keys:
            name = names[int(key[2])]
            ta = np.sort(pa[np.all(pa[:, 1:] == key, axis=1), 0])
            tb = np.sort(pb[np.all(pb[:, 1:] == key, axis=1), 0])
            if ta.shape != tb.shape:
                bad[name] = True
            elif ta.size:
                off[name] = max(off[name], float(np.max(np.abs(ta - tb))))
        for name in count:
            count[name] += bad[name]
            moved[name] += off[name] > tol
            worst[name] = max(worst[name], off[name])
    return "points: " + "; ".join(
        f"{n}: poses with another count {count[n]}, moved more than {tol:g} {moved[n]} "
        f"(largest {worst[n]:.2e})" for n in count)


def identical(a: dict, b: dict) -> str:
    """Whether the two trees' outputs are bit for bit the same (every pose)."""
    same = {k: bool(np.array_equal(a[k], b[k])) for k in ("niv", "npts", "flags", "evals")}
    same["intervals"] = same["niv"] and all(
        np.array_equal(a["iv"][i, br, :k], b["iv"][i, br, :k])
        for (i, br), k in np.ndenumerate(a["niv"]))
    same["points"] = same["npts"] and all(
        np.array_equal(a["pts"][i, :k], b["pts"][i, :k]) for i, k in enumerate(a["npts"]))
    return "bit for bit the same: " + ", ".join(f"{k} {v}" for k, v in same.items())


def main() -> None:
    """Print one line per tree and round, then the comparison of the outputs."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("trees", nargs=2)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--n", type=int, default=1000)
    ap.add_argument("--special", type=int, default=150)
    ap.add_argument("--tol", type=float, default=1e-12)
    ap.add_argument("--modes", nargs=2, default=("AUTO", "AUTO"),
                    help="HM_MODE_* of each tree (AUTO, GRID, CLOSED; trees before session 26 "
                         "have none): the same tree twice with GRID CLOSED compares the paths")
    a = ap.parse_args()
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="hm_ab_"))
    print("load", pathlib.Path("/proc/loadavg").read_text().split()[:3])
    print("round tree  ms CPU per pose  evals per pose")
    for r in range(a.rounds):
        for name, tree, mode in zip("AB", a.trees, a.modes):
            code = CHILD.format(n=a.n, ns=a.special, repeat=a.repeat, mode=mode.upper(),
                                out=str(tmp / f"{name}.npz"))
            env = dict(os.environ, PYTHONPATH=tree)  # the tree's src folder
            res = subprocess.run([sys.executable, "-c", code], env=env, check=True,
                                 capture_output=True, text=True)
            bad = res.stderr.count("mismatch")  # a -DHM_VERIFY build's row differences
            print(f"{r}     {name}     {res.stdout.strip()}"
                  + (f"  HM_VERIFY mismatches {bad}" if bad else ""), flush=True)
    print("load", pathlib.Path("/proc/loadavg").read_text().split()[:3])
    out = [dict(np.load(tmp / f"{name}.npz")) for name in "AB"]
    print(compare(out[0], out[1], a.tol))
    print(compare_points(out[0], out[1], a.tol))
    print(compare_pieces(out[0], out[1], a.tol))
    print(identical(out[0], out[1]))


if __name__ == "__main__":
    main()
