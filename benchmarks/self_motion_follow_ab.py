"""A/B of ``sm.sample(t)`` on general 7R arms: followed branches against the full solve.

Issue 29, round 7: the continued family's ``sample`` follows each branch from its
nodes (Hermite prediction, Newton on the held 6 x 6, certified) where it can, and
solves the pose by the general 6R kernel elsewhere. This script builds the manifolds
of ``bench_self_motion_general.py``'s poses (offset iiwa and random 7R, uniform and
special, ``--seeds`` x ``--poses`` each; joint 7 the parameter), samples each at
``--values`` values (the domain's linspace and the generating q7) and checks:

* every row of the reference is returned (within 1e-10 rad, 2 pi wrapped, same
  branch slot; rows equal only 2 pi wrapped, a joint 2 pi apart, counted); the
  reference is this tree's full solve (``_family.rows``, the code main's ``sample``
  runs) or, with ``--against FILE``, the rows another tree saved with ``--save
  FILE`` (run main with ``--save``, this tree with ``--against``);
* rows returned with a pose error above 1e-12 (position [m] or rotation [rad]);
* rows returned where the reference has none (a branch the kernel missed at t);
* how many values took the followed path.

``--aligned N`` adds, per seed, N offset-iiwa poses with axes 3, 5 and 7 on one line
(q4 and q6 each 0 or +-1e-9, some of q1-q3 at 0, +-pi/2 or q1's limit): every one
is ``degenerate`` (a near-continuum at every value; issue 29, round 7c). To compare
against main, run this file with main's ``src`` on ``PYTHONPATH`` and ``--save``.

Run: ``python benchmarks/self_motion_follow_ab.py [--seeds 1 2 3 4 29] [--poses 20]
[--values 64] [--aligned N] [--save FILE | --against FILE]``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_self_motion_general import configurations  # noqa: E402

from reference import offset_iiwa14, pose_errors, random_7r  # noqa: E402


def wrapped(a: np.ndarray) -> np.ndarray:
    return np.abs((a + np.pi) % (2 * np.pi) - np.pi)


def aligned_configurations(robot, rng: np.random.Generator, n: int) -> np.ndarray:
    """n offset-iiwa configurations with axes 3, 5 and 7 on one line (q4, q6 ~ 0)."""
    lo, hi = robot.limits[:, 0], robot.limits[:, 1]
    q = rng.uniform(0.95 * lo, 0.95 * hi, (n, robot.n))
    q[:, 3] = rng.choice([0.0, 1e-9, -1e-9], n)
    q[:, 5] = rng.choice([0.0, 1e-9, -1e-9], n)
    pick = rng.random(n) < 0.3
    q[pick, rng.integers(0, 3, pick.sum())] = rng.choice(
        [0.0, np.pi / 2, -np.pi / 2, lo[0], hi[0]], pick.sum())
    return np.clip(q, lo, hi)


def main(seeds: list[int], poses: int, values: int, save: str | None,
         against: str | None, aligned: int = 0) -> None:
    saved: dict[str, np.ndarray] = {}
    ref = dict(np.load(against)) if against else None
    print(f"{len(seeds)} seeds x {poses} poses x 2 kinds x 2 arms; {values} values each"
          + (f"; {aligned} aligned offset-iiwa poses per seed" if aligned else ""))
    for robot in (offset_iiwa14(), random_7r(29)):
        name = robot.joint_names[-1]
        kinds = ["uniform", "special"] + (["aligned"] if aligned and robot.name == "offset_iiwa"
                                          else [])
        for kind in kinds:
            tally = dict(manifolds=0, values=0, followed=0, rows=0, missing=0,
                         wrong=0, extra=0, returned=0, shifted=0)
            for seed in seeds:
                rng = np.random.default_rng(seed)
                q = (aligned_configurations(robot, rng, aligned) if kind == "aligned"
                     else configurations(robot, rng, poses, kind == "special"))
                T = robot.fk(q)
                for i, (qi, Ti) in enumerate(zip(q, T, strict=True)):
                    sm = robot.self_motion(Ti, parameter=name)
                    fam = sm._family
                    t = np.concatenate([np.linspace(*sm.domain, values - 1), [qi[-1]]])
                    before = getattr(fam, "followed", 0)
                    rows = sm.sample(t)
                    key = f"{robot.name}/{kind}/{seed}/{i}"
                    saved[key] = rows
                    base = ref[key] if ref is not None else fam.rows(t)[0]
                    tally["manifolds"] += 1
                    tally["values"] += len(t)
                    tally["followed"] += getattr(fam, "followed", 0) - before
                    if base.shape[1] != rows.shape[1]:
                        raise SystemExit(f"{key}: {base.shape} branches against {rows.shape}")
                    fb = np.isfinite(base).all(-1)
                    fr = np.isfinite(rows).all(-1)
                    d = wrapped(np.where(fb & fr, 1, np.nan)[..., None] * (rows - base)).max(-1)
                    tally["rows"] += int(fb.sum())
                    tally["missing"] += int((fb & ~(d < 1e-10)).sum())
                    raw = np.abs(np.where(fb & fr, 1, np.nan)[..., None] * (rows - base))
                    tally["shifted"] += int(((d < 1e-10) & ~(raw.max(-1) < 1e-10)).sum())
                    tally["extra"] += int((fr & ~fb).sum())
                    tally["returned"] += int(fr.sum())
                    if fr.any():
                        dp, dr = pose_errors(robot.fk(rows[fr]), Ti)
                        tally["wrong"] += int((np.maximum(dp, dr) > 1e-12).sum())
            print(f"{robot.name:12s} {kind:8s} {tally['manifolds']} manifolds, "
                  f"{tally['values']} values ({tally['followed']} followed): reference rows "
                  f"{tally['rows']}, missing {tally['missing']} (2 pi apart "
                  f"{tally['shifted']}); returned {tally['returned']} "
                  f"(not in the reference {tally['extra']}), pose error > 1e-12: "
                  f"{tally['wrong']}")
    if save:
        np.savez_compressed(save, **saved)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4, 29])
    ap.add_argument("--poses", type=int, default=20)
    ap.add_argument("--values", type=int, default=64)
    ap.add_argument("--save")
    ap.add_argument("--against")
    ap.add_argument("--aligned", type=int, default=0)
    a = ap.parse_args()
    main(a.seeds, a.poses, a.values, a.save, a.against, a.aligned)
