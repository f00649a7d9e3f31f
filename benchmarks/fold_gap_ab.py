"""Issue 29 (helper foldx29): in-limit stretches next to folds, counted and A/B'd.

For each uniform configuration (seed, ``self_motion_rates.configurations``' uniform
half) of an arm, ``robot.self_motion(T)`` is computed and every fold end
(``sm.singular``, kind "fold") of a branch is checked: its row (``fam.rows``) inside
the limits (``MANIFOLD_SLACK``) while no interval of the branch holds it (1e-9 in t)
is a *gap* (a crossing next to the fold missed). Writes the intervals of every pose to
``--out`` (npz) and, with ``--ref`` (another run's npz, e.g. main's), compares: poses
bit-identical, poses that only gain (every reference interval inside one of the same
branch), others.

Run: ``python benchmarks/fold_gap_ab.py --arm random_7r --n 300 --out a.npz [--ref b.npz]``
(the PYTHONPATH chooses the tree).
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / p) for p in ("tests", "tests/kinematics/ik", "benchmarks")]

from self_motion_rates import PARAMETER, build  # noqa: E402

from robokin.kinematics.ik.self_motion_intervals import MANIFOLD_SLACK  # noqa: E402


def gaps(sm) -> int:
    """Fold ends whose row is inside while no interval of their branch holds them."""
    folds = [(p.t, p.branch) for p in sm.singular if p.kind == "fold"]
    if not folds:
        return 0
    q, valid, _ = sm._family.rows(np.array([t for t, _ in folds]))
    lim = sm.limits
    count = 0
    for i, (t, b) in enumerate(folds):
        r = q[i, b]
        if not valid[i, b] or not np.all((r >= lim[:, 0] - MANIFOLD_SLACK)
                                         & (r <= lim[:, 1] + MANIFOLD_SLACK)):
            continue
        iv = sm.intervals[sm.interval_branch == b]
        if not np.any((iv[:, 0] - 1e-9 <= t) & (t <= iv[:, 1] + 1e-9)):
            count += 1
    return count


def gains(ref: tuple[np.ndarray, np.ndarray], new: tuple[np.ndarray, np.ndarray]) -> bool:
    """Every interval of ref inside one of new's of the same branch."""
    for (a, e), b in zip(*ref, strict=True):
        iv = new[0][new[1] == b]
        if not np.any((iv[:, 0] <= a) & (e <= iv[:, 1])):
            return False
    return True


def diff_rows(sm, ref: tuple[np.ndarray, np.ndarray], new: tuple[np.ndarray, np.ndarray]
              ) -> tuple[int, int, int, int]:
    """The oracle on a changed pose: 201 values over each interval of one run, the ones
    in no interval of the same branch in the other run solved in full (``fam.rows``).

    Returns (lost values, lost ones inside the limits, gained values, gained ones inside).
    """
    counts = []
    for a_run, b_run in ((ref, new), (new, ref)):
        ts, bs = [], []
        for (a, e), b in zip(*a_run, strict=True):
            iv = b_run[0][b_run[1] == b]
            for t in np.linspace(a, e, 201):
                if not np.any((iv[:, 0] <= t) & (t <= iv[:, 1])):
                    ts.append(t)
                    bs.append(b)
        if not ts:
            counts += [0, 0]
            continue
        q, valid, _ = sm._family.rows(np.array(ts))
        r = q[np.arange(len(ts)), bs]
        lim = sm.limits
        with np.errstate(invalid="ignore"):
            ok = valid[np.arange(len(ts)), bs] & np.all(
                (r >= lim[:, 0] - MANIFOLD_SLACK) & (r <= lim[:, 1] + MANIFOLD_SLACK), axis=-1)
        counts += [len(ts), int(ok.sum())]
    return counts[0], counts[1], counts[2], counts[3]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--arm", default="random_7r")
    ap.add_argument("--n", type=int, default=300)
    ap.add_argument("--seed", type=int, default=29)
    ap.add_argument("--out", required=True)
    ap.add_argument("--ref")
    args = ap.parse_args()
    robot = build(args.arm)
    rng = np.random.default_rng(args.seed)
    lim = robot.limits
    Q = rng.uniform(lim[:, 0], lim[:, 1], (args.n, 7))
    T = robot.fk(Q)
    param = PARAMETER.get(args.arm, "auto")
    store: dict[str, np.ndarray] = {}
    found, cpu, sms = [], 0.0, []
    for i in range(args.n):
        c0 = time.process_time()
        sm = robot.self_motion(T[i], param)
        cpu += time.process_time() - c0
        found.append(gaps(sm))
        store[f"iv{i}"], store[f"b{i}"] = sm.intervals, sm.interval_branch
        sms.append(sm)
    found_a = np.array(found)
    np.savez(args.out, gaps=found_a, **store)
    print(f"{args.arm}: {args.n} poses, {int((found_a > 0).sum())} with a fold gap "
          f"({int(found_a.sum())} fold ends); CPU {cpu / args.n * 1e3:.1f} ms per pose")
    if args.ref:
        ref = np.load(args.ref)
        same = gain = other = 0
        tally = np.zeros(4, dtype=int)
        for i in range(args.n):
            r = (ref[f"iv{i}"], ref[f"b{i}"])
            n = (store[f"iv{i}"], store[f"b{i}"])
            if np.array_equal(r[0], n[0]) and np.array_equal(r[1], n[1]):
                same += 1
                continue
            if gains(r, n):
                gain += 1
            else:
                other += 1
            tally += diff_rows(sms[i], r, n)
        print(f"  vs {args.ref}: {same} bit-identical, {gain} only gain, {other} other")
        print(f"  oracle on the changed poses (201 values per interval): {tally[0]} values "
              f"lost ({tally[1]} of them inside), {tally[2]} gained ({tally[3]} inside)")


if __name__ == "__main__":
    main()
