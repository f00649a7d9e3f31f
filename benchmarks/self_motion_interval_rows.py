"""Intervals against their own rows: false inclusions of ``robot.self_motion`` (issue 29).

For special configurations of ``self_motion_rates.configurations`` (seed, n) the
manifold of each pose is built and every interval is sampled at 21 values strictly
inside it (``sm.sample``); an interval whose branch row is out of the joint limits by
more than 1e-9 at one of them is printed with the smallest singular value of the held
Jacobian there (regular above 1e-5). Session 15 (``docs/ik.md``): on 60 special offset
iiwa poses main 73f3f77 had 25 such intervals (up to 0.45 rad out); after
``_node_cuts`` none.

Usage: ``python benchmarks/self_motion_interval_rows.py ARM N POSES SEED [PICK_SEED]``
(e.g. ``offset_iiwa 10000 60 0``; ARM as in ``self_motion_rates.py``; PICK_SEED, 7 by
default, chooses which special poses).
"""

from __future__ import annotations

import pathlib
import sys

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
sys.path[:0] = [str(HERE), str(HERE.parent / "tests")]

from self_motion_rates import PARAMETER, build, configurations  # noqa: E402


def main() -> None:
    arm, n, m, seed = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
    pick_seed = int(sys.argv[5]) if len(sys.argv) > 5 else 7
    robot = build(arm)
    lim = robot.limits
    par = PARAMETER.get(arm, "auto")
    Q, special = configurations(robot, n, seed)
    idx = np.random.default_rng(pick_seed).choice(np.flatnonzero(special), m, replace=False)
    bad_reg = bad_sing = total = 0
    for i in idx.tolist():
        sm = robot.self_motion(robot.fk(Q[i]), par)
        j = sm.joint if sm.joint is not None else robot.n - 1
        for (x, y), o in zip(sm.intervals, sm.interval_branch, strict=True):
            total += 1
            ts = np.linspace(x, y, 23)[1:-1]
            rows = sm.sample(ts)[:, o]
            with np.errstate(invalid="ignore"):
                ex = np.maximum(lim[:, 0] - rows, rows - lim[:, 1]).max(-1)
            k = int(np.nanargmax(ex)) if np.isfinite(ex).any() else 0
            if not ex[k] > 1e-9:
                continue
            sv = np.linalg.svd(np.delete(robot.jacobian(rows[k]), j, axis=-1),
                               compute_uv=False)[-1]
            reg = bool(sv > 1e-5)
            bad_reg += reg
            bad_sing += not reg
            print(f"pose {i} branch {o} [{x:.9f}, {y:.9f}] excess {ex[k]:.3g} at t "
                  f"{ts[k]:.9f} sigma {sv:.2g} {'REGULAR' if reg else 'singular'}", flush=True)
    print(f"{arm}: {m} special poses, {total} intervals, out by > 1e-9 inside: "
          f"regular {bad_reg}, singular {bad_sing}")


if __name__ == "__main__":
    main()
