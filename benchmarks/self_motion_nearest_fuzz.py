"""`SelfMotion.nearest` at special configurations: never farther than the generating one.

Configurations q0 drawn by ``special_values.draw_configurations`` (``--seed``, ``--n``;
joints at 0, +-1e-9..1e-6, pi/2 or a limit with some probability), clipped into the
limits. Per q0: ``robot.self_motion(fk(q0))``, then ``nearest`` from q0 itself, from
q0 + N(0, 0.1) and from a uniform in-limit q_near. An answer is a failure when it is
None, leaves the pose by more than 1e-12, leaves the limits, or is farther from q_near
(2 pi wrapped) than q0 by more than 1e-6 (q0 is inside the limits and solves the pose);
a pose whose ``reachable`` is False is one too. Each failure is printed with q0
(``--save DIR``: q0 and q_near as ``<arm>_<seed>_<i>_<k>.npy``); the last line counts
them.

Arms: ``self_motion_rates.build`` names (panda, srs, iiwa_urdf, gen3_like,
offset_iiwa, random) and ``ur5track`` (a UR5 on a 2 m track).

Run: ``python benchmarks/self_motion_nearest_fuzz.py srs [--n 150] [--seed 24]
[--save DIR]``; to compare two trees, run it with each tree's ``src`` first on
``PYTHONPATH`` (each built). Session 24's figures (docs/ik.md): seeds 24-30 on the
SRS arm, 24-26 on the Panda, 24 with ``--n 30`` on the others.
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / p) for p in ("benchmarks", "tests", "tests/kinematics/ik")]

from self_motion_rates import build  # noqa: E402

from reference import pose_errors, ur5_on_a_track  # noqa: E402
from robokin.spatial import wrap_angle  # noqa: E402
from special_values import draw_configurations  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("arm")
    ap.add_argument("--n", type=int, default=150)
    ap.add_argument("--seed", type=int, default=24)
    ap.add_argument("--save", type=pathlib.Path, default=None)
    a = ap.parse_args()
    robot = ur5_on_a_track(2.0) if a.arm == "ur5track" else build(a.arm)
    lim = robot.limits
    rev = np.asarray(robot.is_revolute, dtype=bool)
    rng = np.random.default_rng(a.seed)
    Q = np.clip(draw_configurations(robot, rng, a.n), lim[:, 0], lim[:, 1])

    def dist(x: np.ndarray, y: np.ndarray) -> float:
        return float(np.linalg.norm(np.where(rev, wrap_angle(x - y), x - y)))

    bad, calls, t0 = 0, 0, time.process_time()
    for i, q in enumerate(Q):
        T = robot.fk(q)
        sm = robot.self_motion(T)
        near = (q, q + rng.normal(0.0, 0.1, len(q)), rng.uniform(lim[:, 0], lim[:, 1]))
        for k, qn in enumerate(near):
            calls += 1
            p = sm.nearest(qn)
            why = []
            if p is None:
                why.append("none")
            else:
                e = max(pose_errors(robot.fk(p.q), T))
                if e > 1e-12:
                    why.append(f"pose {e:.2e}")
                if not robot.within_limits(p.q):
                    why.append("limits")
                if dist(p.q, qn) > dist(q, qn) + 1e-6:
                    why.append(f"farther {dist(p.q, qn) - dist(q, qn):.3e}")
            if why:
                bad += 1
                print(i, k, why, "reachable", sm.reachable, "q0", q.tolist(), flush=True)
                if a.save is not None:
                    a.save.mkdir(parents=True, exist_ok=True)
                    np.save(a.save / f"{a.arm}_{a.seed}_{i}_{k}.npy", np.stack([q, qn]))
        if not sm.reachable:
            bad += 1
            print(i, "reachable False", "q0", q.tolist(), flush=True)
    print(f"{a.arm} n {a.n} seed {a.seed}: {bad} failures of {calls} calls "
          f"({time.process_time() - t0:.1f} s CPU)")


if __name__ == "__main__":
    main()
