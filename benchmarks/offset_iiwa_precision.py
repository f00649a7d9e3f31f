"""Offset iiwa, joint 7 held: IK rows that reproduce their pose to worse than 1e-12.

Issue 23 wants every valid row of ``robot.ik`` within 1e-12 (m and rad) of its
pose. Arm: ``tests/reference.py::offset_iiwa14()`` (joint 7 held goes to the general
held-joint 6R kernel). Configurations: ``bench_self_motion_general.configurations``,
2,000 special (each joint with probability 0.3 at 0, +-pi/2, pi, +-1e-9 or a limit)
and 2,000 uniform per seed (``--n``, ``--seeds``), solved in one batch call
``robot.ik(robot.fk(q), fixed={joint7: q[:, 6]})``.

Prints one line per (seed, kind): poses, poses with a valid row above 1e-12
(``tests/reference.py::pose_errors``, the larger of position [m] and angle [rad]),
such rows, the worst row error, and configurations inside the limits whose generating
q is not among the valid rows (within 1e-6 rad): the non-singular ones (joints 1-6
Jacobian's smallest singular value >= 1e-4, isolated solutions) and all; then the first
configurations with a bad row (``--show``). ``--dump FILE`` also saves every call's
q, valid and flag arrays to an .npz (for A/B runs of two trees with
``np.array_equal``).

Run: ``python benchmarks/offset_iiwa_precision.py [--seeds 0 1 2] [--n 2000]``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE), str(HERE.parent / "tests")]
from bench_self_motion_general import configurations  # noqa: E402

from reference import offset_iiwa14, pose_errors  # noqa: E402

TOL = 1e-12
NON_SINGULAR = 1e-4  # joints 1-6 Jacobian's smallest singular value: isolated solutions


def measure(robot, q: np.ndarray) -> dict:
    """Solve every configuration of q (n, 7) at its own q7; count the rows above TOL."""
    T = robot.fk(q)
    sols = robot.ik(T, fixed={robot.joint_names[6]: q[:, 6]})
    valid = sols.valid
    Tt = np.broadcast_to(T[:, None], sols.q.shape[:2] + (4, 4))
    err = np.zeros(valid.shape)
    dp, dr = pose_errors(robot.fk(sols.q[valid]), Tt[valid])
    err[valid] = np.maximum(dp, dr)
    bad = err > TOL
    gap = np.abs((sols.q - q[:, None, :] + np.pi) % (2 * np.pi) - np.pi).max(axis=-1)
    back = np.where(valid, gap, np.inf).min(axis=-1) <= 1e-6
    lim = robot.limits
    inside = np.all((q >= lim[:, 0]) & (q <= lim[:, 1]), axis=-1)
    sigma = np.linalg.svd(robot.jacobian(q)[..., :6], compute_uv=False)[:, -1]
    missed = inside & ~back
    return {"poses": len(q), "bad_poses": np.flatnonzero(bad.any(axis=-1)),
            "bad_rows": int(bad.sum()), "worst": float(err.max(initial=0.0)),
            "missed": (int((missed & (sigma >= NON_SINGULAR)).sum()), int(missed.sum())),
            "sols": sols}


def main(seeds: list[int], n: int, show: int, dump: str | None) -> None:
    """Print the counts per (seed, kind) and the first bad configurations."""
    robot = offset_iiwa14()
    arrays = {}
    print(f"offset iiwa, joint 7 held, {n} configurations per seed and kind, rows > {TOL:g}")
    print("seed kind     poses  bad poses  bad rows  worst row error  generating q missed")
    print("                                                             non-singular / all")
    for seed in seeds:
        for special in (True, False):
            q = configurations(robot, np.random.default_rng(seed), n, special)
            r = measure(robot, q)
            kind = "special" if special else "uniform"
            print(f"{seed:4d} {kind:8s} {r['poses']:5d}  {len(r['bad_poses']):9d}  "
                  f"{r['bad_rows']:8d}  {r['worst']:15.3e}  {r['missed'][0]:12d} / "
                  f"{r['missed'][1]}")
            for i in r["bad_poses"][:show]:
                print("     ", i, np.array2string(q[i], precision=17, separator=", ",
                                                  max_line_width=400))
            s = r["sols"]
            arrays[f"{seed}_{kind}_q"], arrays[f"{seed}_{kind}_valid"] = s.q, s.valid
            for name, f in s.flags.items():
                arrays[f"{seed}_{kind}_{name}"] = f
    if dump:
        np.savez(dump, **arrays)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    ap.add_argument("--n", type=int, default=2000)
    ap.add_argument("--show", type=int, default=0)
    ap.add_argument("--dump", default=None)
    a = ap.parse_args()
    main(a.seeds, a.n, a.show, a.dump)
