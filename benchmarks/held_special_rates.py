"""Held-joint IK of 7R arms on special-value configurations: completeness rates.

For the Panda (every joint held: joints 1-3 through the general 6R path,
``coincident`` and ``near_coincident``; joints 4-7 the held closed form) and the exact
SRS arm of the property tests (every joint held), ``--n`` configurations per held joint, each joint a third of the time
uniform in its limits, a third from {0, +-pi/2, pi, +-1e-9, +-1e-7, +-1e-6}, a
third at a limit (``tests/kinematics/ik/test_fixed_properties.special_batch``).
Reported per case: non-singular configurations (remaining 6 x 6 Jacobian's smallest
singular value >= 1e-4) whose generating configuration came back (to 1e-6 rad),
singular in-limit configurations that got a valid in-limit row, the worst pose
error of any returned row, and the configurations missed (first three).

Run: ``python benchmarks/held_special_rates.py [--n 3000] [--seed 0] [--cases
panda-joint2,srs-joint6]`` (``--cases``: only those cases, named as printed; default
every case).
"""

from __future__ import annotations

import argparse
import pathlib
import sys

import numpy as np

sys.path[:0] = [str(pathlib.Path(__file__).resolve().parents[1] / p)
                for p in ("tests", "tests/kinematics/ik")]

from test_fixed_properties import CASES as HELD_CASES  # noqa: E402
from test_fixed_properties import NON_SINGULAR, ROBOTS, special_batch  # noqa: E402

from reference import pose_errors  # noqa: E402

#: The property tests' cases and the Panda with joint 1, 2 or 3 held (~1 min of the
#: run at n 3000: joints 2 and 3 take a reduced chain per held value)
CASES = [("panda", j) for j in (0, 1, 2)] + HELD_CASES


def rates(arm: str, j: int, n: int, seed: int) -> dict:
    """Completeness of one (arm, held joint) case on n special-value configurations."""
    robot = ROBOTS[arm]
    lim = robot.limits
    q = special_batch(robot, n, np.random.default_rng(seed + 10 * j + (arm == "srs")))
    T = robot.fk(q)
    sols = robot.ik(T, fixed={robot.joint_names[j]: q[:, j]})
    valid = sols.valid
    dp, dr = pose_errors(robot.fk(sols.q[valid]),
                         np.broadcast_to(T[:, None], sols.q.shape[:2] + (4, 4))[valid])
    sigma = np.linalg.svd(np.delete(robot.jacobian(q), j, axis=-1), compute_uv=False)[:, -1]
    regular = sigma >= NON_SINGULAR
    gap = np.abs((sols.q - q[:, None, :] + np.pi) % (2 * np.pi) - np.pi).max(axis=-1)
    back = np.where(valid, gap, np.inf).min(axis=-1) <= 1e-6
    inside = np.all((q >= lim[:, 0] - 1e-9) & (q <= lim[:, 1] + 1e-9), axis=-1)
    ok = (valid & sols.within_limits).any(axis=-1)
    sing = ~regular & inside
    return {"regular": (int(back[regular].sum()), int(regular.sum())),
            "singular": (int(ok[sing].sum()), int(sing.sum())),
            "err": float(max(dp.max(initial=0.0), dr.max(initial=0.0))),
            "missed": q[sing & ~ok][:3].tolist() + q[regular & ~back][:3].tolist()}


def label(arm: str, j: int) -> str:
    """The case's name as printed and as ``--cases`` takes it: ``panda-joint2``."""
    return f"{arm}-joint{j + 1}"


def main(n: int = 3000, seed: int = 0, cases: list[str] | None = None) -> None:
    """Print one line per (arm, held joint), for the named cases (default all)."""
    known = [label(arm, j) for arm, j in CASES]
    unknown = sorted(set(cases or ()) - set(known))
    if unknown:
        raise SystemExit(f"unknown case(s) {', '.join(unknown)}; cases: {', '.join(known)}")
    print(f"{n} special-value configurations per held joint, seed {seed}")
    print("case          non-singular back     singular in-limit    worst row error")
    for arm, j in CASES:
        if cases and label(arm, j) not in cases:
            continue
        r = rates(arm, j, n, seed)
        (a, b), (c, d) = r["regular"], r["singular"]
        print(f"{label(arm, j):<13} {a:5d}/{b:<5d} {100 * a / max(b, 1):7.2f} %  "
              f"{c:5d}/{d:<5d} {100 * c / max(d, 1):7.2f} %  {r['err']:.1e}")
        for m in r["missed"]:
            print("    missed", m)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=3000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--cases", default="",
                    help="comma-separated case names as printed, e.g. panda-joint2")
    a = ap.parse_args()
    main(a.n, a.seed, [c for c in a.cases.split(",") if c])
