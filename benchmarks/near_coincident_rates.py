"""The Panda with joint 2 held next to 0 (axes 1 and 3 nearly on one line): rates, speed.

For each held value v (q2 = +-v, random sign), ``--n`` seeded configurations inside
the limits (each joint a third of the time uniform, a third from {0, +-pi/2, pi,
+-1e-9, +-1e-7, +-1e-6} clipped into the limits, a third at a limit), one
``panda.ik(T, fixed={"joint2": q2})`` call per pose. Reported: valid rows, valid rows
whose FK is more than 1e-12 off the pose (m, rad) and in how many poses, the worst
row, generating configurations back (to 1e-6 rad) where the free joints' 6 x 6
Jacobian is regular (smallest singular value above 1e-5 of the largest), in-limit
rows at the others, and CPU microseconds per call (``time.process_time``).

Run: ``python benchmarks/near_coincident_rates.py [--n 1000] [--values 1e-9 1e-7 0.3]``.
For a before/after comparison run it with ``PYTHONPATH`` at the two trees in turn.
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import time

import numpy as np

sys.path[:0] = [str(pathlib.Path(__file__).resolve().parents[1] / "tests")]

import robokin  # noqa: E402
from reference import pose_errors  # noqa: E402

SPECIAL = (0.0, np.pi / 2, -np.pi / 2, np.pi, 1e-9, -1e-9, 1e-7, -1e-7, 1e-6, -1e-6)


def configurations(robot: robokin.Robot, n: int, v: float, seed: int) -> np.ndarray:
    """(n, 7) special-value configurations inside the limits with q2 = +-v."""
    rng = np.random.default_rng(seed)
    lim = robot.limits
    q = rng.uniform(lim[:, 0], lim[:, 1], (n, 7))
    pick = rng.integers(0, 3, (n, 7))
    special = np.array(SPECIAL)[rng.integers(0, len(SPECIAL), (n, 7))]
    limit = np.where(rng.integers(0, 2, (n, 7)) == 0, lim[:, 0], lim[:, 1])
    q = np.clip(np.where(pick == 1, special, np.where(pick == 2, limit, q)), lim[:, 0], lim[:, 1])
    q[:, 1] = v * np.where(rng.integers(0, 2, n) == 0, 1.0, -1.0)
    return q


def rates(robot: robokin.Robot, v: float, n: int, seed: int) -> dict:
    """One held value's counts and CPU time per call."""
    q = configurations(robot, n, v, seed)
    T = robot.fk(q)
    t0 = time.process_time()
    sets = [robot.ik(T[i], fixed={"joint2": float(q[i, 1])}) for i in range(n)]
    cpu = (time.process_time() - t0) / n
    sv = np.linalg.svd(np.delete(robot.jacobian(q), 1, axis=-1), compute_uv=False)
    regular = sv[:, -1] > 1e-5 * sv[:, 0]
    rows = bad = bad_poses = back = inside = 0
    worst = 0.0
    for i, s in enumerate(sets):
        Q = s.q[s.valid]
        rows += len(Q)
        if len(Q):
            dp, dr = pose_errors(robot.fk(Q), np.broadcast_to(T[i], (len(Q), 4, 4)))
            e = np.maximum(dp, dr)
            worst = max(worst, float(e.max()))
            bad += int((e > 1e-12).sum())
            bad_poses += bool((e > 1e-12).any())
        gap = np.abs((Q - q[i] + np.pi) % (2 * np.pi) - np.pi).max(axis=-1, initial=0.0)
        back += bool(regular[i] and len(Q) and gap.min() <= 1e-6)
        inside += bool(not regular[i] and (s.valid & s.within_limits).any())
    return {"rows": rows, "bad": bad, "bad_poses": bad_poses, "worst": worst,
            "back": (back, int(regular.sum())), "inside": (inside, int((~regular).sum())),
            "us": cpu * 1e6, "method": sets[0].method}


def main() -> None:
    """Print one line per held value."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=23)
    ap.add_argument("--values", type=float, nargs="+",
                    default=[1e-9, 1e-8, 1e-7, 1e-6, 1e-4, 1e-3, 0.3])
    a = ap.parse_args()
    panda = robokin.load("panda")
    print(f"{robokin.__file__}: {a.n} configurations per value, seed {a.seed}")
    print("q2 = +-v  rows  >1e-12 (poses)  worst     regular back  singular in-limit"
          "  us CPU/call  method")
    for v in a.values:
        r = rates(panda, v, a.n, a.seed)
        print(f"{v:8.0e} {r['rows']:5d} {r['bad']:6d} ({r['bad_poses']:4d})  {r['worst']:.1e}"
              f"  {r['back'][0]:4d}/{r['back'][1]:<4d}     {r['inside'][0]:4d}/{r['inside'][1]:<4d}"
              f"      {r['us']:7.0f}  {r['method']}")


if __name__ == "__main__":
    main()
