"""The Pieper kernel (``csrc/pieper.c``) in two trees: every raw output equal, bit for bit.

For several arms with a meeting triple (6R: the KUKA-like KR 6, the PUMA 560, the
Panda's first six joints, a skew-wrist arm; 7R with each joint held where a triple is
left: the Panda, the SRS iiwa14, the rtb-data iiwa14 when installed) the child program
solves ``--n`` random in-limit configurations per arm and held joint plus special ones
(every joint at 0, joints at 0 or +-pi/2, at their limits, the wrist aligned), each at
its own held value and at a random one, with random preferred coordinates, through
``pieper_ik`` (every output array), ``pieper_ik1`` (a subset) and ``pieper_limit_rows``
(the batch's rows), and ``robot.ik(T, fixed=...)`` on the 7R arms. Both trees' outputs
are compared with ``np.array_equal`` (NaN equal to NaN; the dtype and shape too) and
each difference is counted. ``--isa-a`` / ``--isa-b`` choose each tree's copy (ROBOKIN_ISA;
default the CPU's best): ``--isa-a baseline --isa-b baseline`` compares the baseline
copies; ``--isa-b baseline`` alone, tree B's baseline copy (no FMA) against tree A's
AVX2 one, checks that the comparison sees last-bit differences.

    python benchmarks/pieper_ab.py /work/wt/ref/src /work/wt/ptrip32/src --n 2000
"""

from __future__ import annotations

import argparse
import pathlib
import pickle
import subprocess
import sys
import tempfile

CHILD = r'''
import pickle, sys
from math import pi
import numpy as np
sys.path.insert(0, {tests!r})
import robokin
from robokin._native import kernels as K
from robokin.kinematics.ik.analytic import pieper
from reference import iiwa14_srs
from vendor_arms import kuka_like

n = {n}
rng = np.random.default_rng({seed})


def wrist_arm():
    rows = [dict(a=0.05, alpha=pi / 2, d=0.4, theta=0.0), dict(a=0.45, alpha=0.3, d=0.05, theta=0.2),
            dict(a=0.03, alpha=pi / 2, d=0.02, theta=0.0), dict(a=0.0, alpha=-pi / 2, d=0.42, theta=0.0),
            dict(a=0.0, alpha=pi / 2, d=0.0, theta=0.0), dict(a=0.0, alpha=0.0, d=0.08, theta=0.0)]
    for r in rows:
        r["limits"] = [-pi, pi]
    return robokin.Robot.from_dh(rows, convention="standard", name="skew-wrist")


panda = robokin.load("panda")
arms = {{"kuka_kr6": kuka_like(), "puma560": robokin.load("puma560"), "skew_wrist": wrist_arm(),
        "panda6": robokin.Robot(panda.chain.with_fixed({{6: 0.4}}), name="panda-6"),
        "panda": panda, "iiwa14_srs": iiwa14_srs()}}
try:
    import rtbdata, pathlib
    urdf = (pathlib.Path(rtbdata.__file__).parent
            / "xacro/kuka_description/kuka_lbr_iiwa/urdf/lbr_iiwa_14_r820.urdf")
    arms["rtb_iiwa14"] = robokin.Robot.from_urdf(str(urdf), geometry=False)
except ImportError:
    pass


def configurations(robot):
    lo, hi = robot.limits[:, 0], robot.limits[:, 1]
    q = rng.uniform(lo, hi, (n, robot.n))
    special = [np.zeros(robot.n)]
    for vals in ([0.0, pi / 2, -pi / 2], [0.0]):
        s = rng.choice(vals, (n // 4, robot.n))
        special.append(np.where(rng.random((n // 4, robot.n)) < 0.5, s,
                                rng.uniform(lo, hi, (n // 4, robot.n))))
    special.append(np.where(rng.random((n // 8, robot.n)) < 0.5, lo, hi))  # at limits
    for j in range(robot.n):  # one joint at 0 (aligned wrists and shoulders)
        s = rng.uniform(lo, hi, (n // 16, robot.n))
        s[:, j] = 0.0
        special.append(s)
    q = np.vstack([q] + special)
    return np.clip(q, lo, hi)


out = {{}}
for name, robot in arms.items():
    helds = [None] if robot.n == 6 else list(range(robot.n))
    for held in helds:
        st = pieper.setup(robot.chain, held)
        if st.params is None:
            continue
        P = np.ascontiguousarray(st.params)
        q = configurations(robot)
        T = np.ascontiguousarray(robot.fk(q))
        qn = np.ascontiguousarray(rng.uniform(-pi, pi, (len(q), robot.n)))
        xs = [None] if held is None else [
            np.ascontiguousarray(q[:, held]),
            np.ascontiguousarray(rng.uniform(*robot.limits[held], len(q)))]
        for v, x in enumerate(xs):
            key = (name, held, v)
            res = pieper.raw_solve(P, T, x, qn)
            out[key + ("ik",)] = res
            one = []
            for i in range(0, len(q), 7):
                one.append(K.pieper_ik1(T[i], P, 0.0 if x is None else float(x[i]), qn[i]))
            out[key + ("ik1",)] = one
            if held is not None:
                Lp = pieper.limit_params(robot.chain, held)
                if Lp is not None:
                    Q, valid, sing, inside, _ = (np.array(a) for a in res)
                    K.pieper_limit_rows(Lp, T, x, Q, valid, sing, inside)
                    out[key + ("limit_rows",)] = (Q, inside)
                jn = robot.joint_names[held]
                sols = robot.ik(T[:300], fixed={{jn: x[:300]}})
                out[key + ("fixed",)] = (np.asarray(sols.q), np.asarray(sols.valid),
                                         np.asarray(sols.within_limits), np.asarray(sols.singular))
with open({out!r}, "wb") as f:
    pickle.dump(out, f)
print(K.__file__, len(out), "outputs")
'''


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("tree_a", help="a tree's src folder (main's)")
    ap.add_argument("tree_b", help="another tree's src folder")
    ap.add_argument("--n", type=int, default=2000, help="random configurations per case")
    ap.add_argument("--seed", type=int, default=13)
    ap.add_argument("--isa-a", default=None, help="ROBOKIN_ISA for tree A (e.g. baseline)")
    ap.add_argument("--isa-b", default=None, help="ROBOKIN_ISA for tree B")
    args = ap.parse_args()
    tests = str(pathlib.Path(__file__).resolve().parent.parent / "tests")
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
    from ab_trees import same

    outs = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, src in zip("AB", (args.tree_a, args.tree_b), strict=True):
            path = str(pathlib.Path(tmp) / f"{name}.pkl")
            code = CHILD.format(n=args.n, seed=args.seed, tests=tests, out=path)
            env = {"PYTHONPATH": str(pathlib.Path(src).resolve())}
            isa = args.isa_a if name == "A" else args.isa_b
            if isa is not None:
                env["ROBOKIN_ISA"] = isa
            res = subprocess.run([sys.executable, "-c", code], env=env, check=True,
                                 capture_output=True, text=True)
            print(name, src, res.stdout.strip())
            with open(path, "rb") as f:
                outs.append(pickle.load(f))
    a, b = outs
    assert a.keys() == b.keys(), "different cases"
    differ = [k for k in a if not same(a[k], b[k])]
    arrays = sum(len(v) if isinstance(v, tuple | list) else 1 for v in a.values())
    print(f"{len(a)} outputs ({arrays} arrays / tuples), {len(differ)} differ")
    for k in differ:
        print("  differs:", k)
    sys.exit(1 if differ else 0)


if __name__ == "__main__":
    main()
