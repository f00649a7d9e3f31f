"""The general 6R kernel next to a near-continuum, two trees A/B (issue 29, session 19).

The offset iiwa's elbow-stretched poses (q4 = q6 = 0, as in
``self_motion_stretched_ab.py``) make the continued family solve thousands of held
values a pose where the six free joints are 1e-9 from a continuum; each costs ~1-4 ms
of ``general6r_solve`` (most of it the polish: Levenberg-Marquardt steps and
``g6_refine``'s halvings). This script records every ``general6r_solve`` input of
``robot.self_motion(T, "a7")`` on ``POSES`` such poses and ``UNIFORM`` uniform ones
(tree A's Python, seed 18 as there), then replays the same inputs through each tree's
kernel alone (one thread, process CPU), the trees alternating for ``ROUNDS`` rounds,
and compares the outputs: arrays equal to the bit, and per held value the valid rows'
count, status and each row's distance to the other tree's nearest row (the polish's
rounding moves a continuum member along the continuum; a regular row moves by ulps),
and the regular rows one tree returns and the other does not (next to the
near-continuum the kernel loses some regular rows at some values, session 18: which
ones depends on the polish's rounding).

Run: ``python benchmarks/general6r_near_continuum_ab.py A_SRC B_SRC [POSES] [UNIFORM]
[ROUNDS]`` (each a ``src`` directory with its kernels built; default 3, 5, 2).
"""

from __future__ import annotations

import os
import pathlib
import pickle
import subprocess
import sys
import tempfile

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
#: A row whose six free joints' smallest singular value is at least this: regular.
REGULAR = 1e-5

CAPTURE = """
import pickle, sys
sys.path[:0] = [{bench!r}, {tests!r}]
import numpy as np
from self_motion_rates import build, configurations
from robokin.kinematics.ik.analytic import general_6r as g6
robot = build("offset_iiwa")
q, special = configurations(robot, 10000, 0)
cand = np.flatnonzero(special & (np.abs(q[:, 3]) < 1e-6) & (np.abs(q[:, 5]) < 1e-5))
pick = np.random.default_rng(18).choice(cand, 24, replace=False)[:{poses}]
uniform = np.flatnonzero(~special)[:{uniform}]
rec = []
solve = g6.raw_solve
def recorded(chain, params, T, parallel=None):
    rec.append((chain.arrays.packed.copy(), params.copy(), T.copy()))
    return solve(chain, params, T, parallel)
g6.raw_solve = recorded
for i in pick.tolist() + uniform.tolist():
    robot.self_motion(robot.fk(q[i]), "a7")
pickle.dump(rec, open({out!r}, "wb"))
"""

REPLAY = """
import pickle, time
import numpy as np
from robokin._native import kernels as K
rec = pickle.load(open({inp!r}, "rb"))
outs, cpu = [], 0.0
for packed, params, T in rec:
    n = len(T)
    o = (np.empty((n, 16, 6)), np.empty((n, 16), np.bool_), np.empty((n, 16), np.bool_),
         np.empty((n, 16)), np.empty(n, np.int64), np.empty(n, np.int64), np.empty((n, 12)))
    c0 = time.process_time()
    K.general6r_solve(packed, params, T, *o, False)
    cpu += time.process_time() - c0
    outs.append(o)
pickle.dump(outs, open({out!r}, "wb"))
print(cpu)
"""


def child(src: str, code: str) -> str:
    env = dict(os.environ, PYTHONPATH=src)
    return subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                          text=True, check=True).stdout


def load(path: str) -> list:
    with open(path, "rb") as f:
        out: list = pickle.load(f)
    return out


def compare(a: list, b: list) -> str:
    """Bit-equal arrays, then per held value: status, row count, nearest-row distance,
    and the regular rows (``REGULAR``) of each tree that the other has not (1e-9)."""
    arrays = sum(x.tobytes() == y.tobytes() for xa, ya in zip(a, b) for x, y in zip(xa, ya))
    total = sum(len(xa) for xa in a)
    values = status = count = moved = regular = 0
    only = [0, 0]
    worst = 0.0
    for (qa, va, _, sa, ta, _, _), (qb, vb, _, sb, tb, _, _) in zip(a, b):
        for i in range(len(qa)):
            values += 1
            status += ta[i] != tb[i]
            ra, rb = qa[i][va[i]], qb[i][vb[i]]
            count += len(ra) != len(rb)
            if not (len(ra) and len(rb)):
                continue
            d = np.abs((ra[:, None] - rb[None] + np.pi) % (2 * np.pi) - np.pi).max(-1)
            w = max(d.min(1).max(), d.min(0).max())
            worst = max(worst, w)
            moved += w > 1e-9
            for k, (near, sig) in enumerate(((d.min(1), sa[i][va[i]]), (d.min(0), sb[i][vb[i]]))):
                regular += int((sig >= REGULAR).sum())
                only[k] += int(((sig >= REGULAR) & (near > 1e-9)).sum())
    return (f"arrays equal to the bit {arrays} / {total}; held values {values}: status "
            f"differs {status}, valid row count differs {count}, a row > 1e-9 rad from "
            f"the other tree's nearest {moved} (largest {worst:.3g}); regular rows "
            f"(sigma >= {REGULAR:g}) {regular}: only A's {only[0]}, only B's {only[1]}")


def main() -> None:
    a, b = sys.argv[1], sys.argv[2]
    poses = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    uniform = int(sys.argv[4]) if len(sys.argv) > 4 else 5
    rounds = int(sys.argv[5]) if len(sys.argv) > 5 else 2
    with tempfile.TemporaryDirectory() as tmp:
        inp = str(pathlib.Path(tmp) / "inputs.pkl")
        child(a, CAPTURE.format(bench=str(HERE), tests=str(HERE.parent / "tests"),
                                poses=poses, uniform=uniform, out=inp))
        n = sum(len(T) for _, _, T in load(inp))
        print(f"{n:,} held values recorded ({poses} stretched + {uniform} uniform poses)",
              flush=True)
        outs = {}
        for r in range(rounds):
            line = []
            for name, src in (("A", a), ("B", b)):
                out = str(pathlib.Path(tmp) / f"{name}.pkl")
                cpu = float(child(src, REPLAY.format(inp=inp, out=out)).split()[-1])
                outs[name] = out
                line.append(f"{name} {cpu:.2f} s")
            print(f"round {r + 1}: kernel CPU " + ", ".join(line), flush=True)
        print(compare(load(outs["A"]), load(outs["B"])))


if __name__ == "__main__":
    main()
