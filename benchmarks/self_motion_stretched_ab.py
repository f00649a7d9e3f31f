"""The offset iiwa's elbow-stretched poses (q4 = q6 = 0), two trees A/B in turn (issue 29).

The continued family's costliest class: special configurations of
``self_motion_rates.configurations(robot, 10000, 0)`` with |q4| < 1e-6 and |q6| < 1e-5,
``POSES`` of them drawn with seed 18. Per tree and round, in a fresh process,
``robot.self_motion(T, "a7")`` alone, process CPU time per pose (after one warm-up
pose), the trees alternating for ``ROUNDS`` rounds. No peer library computes this
arm's manifold (ssik's general 7R path samples; geofikpy is Panda-only), so only the
trees are compared.

Run: ``python benchmarks/self_motion_stretched_ab.py A_SRC B_SRC [POSES] [ROUNDS]``
(each a ``src`` directory with its kernels built; default 24 poses, 2 rounds).
"""

from __future__ import annotations

import os
import pathlib
import subprocess
import sys

HERE = pathlib.Path(__file__).resolve().parent

CHILD = """
import sys, time
sys.path[:0] = [{bench!r}, {tests!r}]
import numpy as np
from self_motion_rates import build, configurations
robot = build("offset_iiwa")
q, special = configurations(robot, 10000, 0)
cand = np.flatnonzero(special & (np.abs(q[:, 3]) < 1e-6) & (np.abs(q[:, 5]) < 1e-5))
pick = np.random.default_rng(18).choice(cand, {poses}, replace=False)
robot.self_motion(robot.fk(q[0]), "a7")
tot = 0.0
for i in pick.tolist():
    c0 = time.process_time()
    robot.self_motion(robot.fk(q[i]), "a7")
    tot += time.process_time() - c0
print(f"{{1e3 * tot / len(pick):.0f}}")
"""


def run(src: str, poses: int) -> float:
    code = CHILD.format(bench=str(HERE), tests=str(HERE.parent / "tests"), poses=poses)
    env = dict(os.environ, PYTHONPATH=src)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                         text=True, check=True)
    return float(out.stdout.split()[-1])


def main() -> None:
    a, b = sys.argv[1], sys.argv[2]
    poses = int(sys.argv[3]) if len(sys.argv) > 3 else 24
    rounds = int(sys.argv[4]) if len(sys.argv) > 4 else 2
    for r in range(rounds):
        ta, tb = run(a, poses), run(b, poses)
        print(f"round {r + 1}: A {ta:,.0f} ms, B {tb:,.0f} ms CPU a pose ({poses} poses)",
              flush=True)


if __name__ == "__main__":
    main()
