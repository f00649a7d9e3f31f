"""CPU per call of the Panda with joint 2 held next to 0, two trees A/B in turn.

For each held value (q2 = +-v), ``--n`` seeded configurations from
``near_coincident_rates.configurations`` and one ``panda.ik(T, fixed={"joint2": q2})``
call per pose, timed with ``time.process_time`` in a fresh process per tree and
round, the trees alternating; ``--rounds`` rounds. Prints ms CPU per call.

Run: ``python benchmarks/near_coincident_ab.py OLD_SRC NEW_SRC [--n 200] [--rounds 3]``
(each a ``src`` directory with its kernels built).
"""

from __future__ import annotations

import argparse
import os
import pathlib
import subprocess
import sys

HERE = pathlib.Path(__file__).resolve().parent
CHILD = """
import sys, time
sys.path[:0] = [{here!r}]
import robokin
from near_coincident_rates import configurations
panda = robokin.load("panda")
out = []
for v in {values!r}:
    q = configurations(panda, {n}, v, 23)
    T = panda.fk(q)
    panda.ik(T[0], fixed={{"joint2": float(q[0, 1])}})
    t0 = time.process_time()
    for i in range({n}):
        panda.ik(T[i], fixed={{"joint2": float(q[i, 1])}})
    out.append((time.process_time() - t0) / {n} * 1e3)
print(" ".join(f"{{x:.2f}}" for x in out))
"""


def main() -> None:
    """Print one line per tree and round."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("trees", nargs=2)
    ap.add_argument("--n", type=int, default=200)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--values", type=float, nargs="+", default=[1e-9, 1e-7, 1e-4])
    a = ap.parse_args()
    code = CHILD.format(here=str(HERE), values=a.values, n=a.n)
    print("round tree  ms CPU per call at q2 = +-" + " ".join(f"{v:g}" for v in a.values))
    for r in range(a.rounds):
        for name, tree in zip("AB", a.trees):
            env = dict(os.environ, PYTHONPATH=tree)
            res = subprocess.run([sys.executable, "-c", code], env=env, check=True,
                                 capture_output=True, text=True)
            print(f"{r}     {name}     {res.stdout.strip()}", flush=True)


if __name__ == "__main__":
    main()
