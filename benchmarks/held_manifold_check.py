"""The compiled held-joint manifold against its oracles on many poses of one arm.

For each of ``--n`` uniform and ``--n`` special configurations
(``self_motion_rates.configurations``, ``--seed``) of the arm (``self_motion_rates.build``;
default the Gen3-like arm, joint_3 held), ``robot.self_motion(T)``; every pose the kernel
certifies (``info["compiled"]``) is checked as ``tests/kinematics/ik/
test_self_motion_intervals.py`` checks the Panda's: its rows at 20,000 values
(``_check_dense``), the solved-points path (``_check_against_solved_points``: ends to
1e-9) and its interval ends (``_check_ends``: a joint at its limit to 1e-10, a fold, or a
slot change: the branch's rows jump by more than 1e-3 across one ulp). Prints each
failure (pose, uniform / special, check, message, q) and one summary line: poses,
compiled (uniform, special), failures, the flags of the others. The development check of
issue 29's session 9 (helper quartic29): 0 failures on seeds 0 and 1 at ``--n 200``.

Run: ``python benchmarks/held_manifold_check.py [--arm gen3_like] [--n 200] [--seed 0]``.
"""

from __future__ import annotations

import argparse
import collections
import pathlib
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / p) for p in ("tests", "tests/kinematics/ik", "benchmarks")]

import test_self_motion_intervals as tsi  # noqa: E402
from self_motion_rates import build, configurations  # noqa: E402


def main() -> None:
    """One line per failure, then the summary."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--arm", default="gen3_like")
    ap.add_argument("--n", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    robot = build(args.arm)
    lim = robot.limits
    q, special = configurations(robot, 2 * args.n, args.seed)
    T = robot.fk(q)
    compiled = np.zeros(len(q), dtype=bool)
    flags: collections.Counter[int] = collections.Counter()
    failures = 0
    for i in range(len(q)):
        sm = robot.self_motion(T[i])
        if not sm.info.get("compiled", False):
            flags[int(sm.info.get("flags", -1))] += 1
            continue
        compiled[i] = True
        checks = (("dense", lambda sm=sm: tsi._check_dense(sm)),
                  ("solved", lambda sm=sm, i=i: tsi._check_against_solved_points(
                      robot, T[i], sm, lim)),
                  ("ends", lambda sm=sm, i=i: tsi._check_ends(robot, T[i], sm, lim,
                                                              jumps=True)))
        for name, check in checks:
            try:
                check()
            except AssertionError as e:
                failures += 1
                print("FAIL", i, "special" if special[i] else "uniform", name, str(e)[:300],
                      q[i].tolist())
    print(f"{args.arm} seed {args.seed}: poses {len(q)}, compiled {compiled.sum()} (uniform "
          f"{compiled[~special].sum()}, special {compiled[special].sum()}), failures "
          f"{failures}; flags of the others {dict(flags)}")


if __name__ == "__main__":
    main()
