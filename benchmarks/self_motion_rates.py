"""Issue 29's goal measured: every branch at every parameter value on N configurations per arm.

Arms: the Panda (q7, the held closed form; the compiled held manifold), the exact SRS
iiwa14 (``tests/reference.py``, the swivel), the rtb-data iiwa14 URDF (shoulder offset
0.44 mm; ``auto``'s held joint), the Gen3-like arm (``bench_self_motion.gen3_like``), the
offset iiwa (``tests/reference.py::offset_iiwa14``, joint 7, general 6R) and
``random_7r(29)`` (joint 7, general 6R). Configurations: ``--n`` per arm (default
10,000), half uniform in the limits, half from
``tests/kinematics/ik/test_fixed_properties.special_batch`` (each joint a third of the
time uniform, a third at 0, +-pi/2, pi, +-1e-9, +-1e-7, +-1e-6, a third at a limit).
The parameter t is the arm's self-motion parameter (``self_motion.parameter_values``).

(a) per value, one batch call per arm: ``robot.ik(T, fixed={param: q[param]})`` (the
    swivel: ``SwivelArm.rows`` at the generating swivel, what ``sm.sample`` runs).
    Counted: configurations whose held 6 x 6 Jacobian (the swivel: the 6 x 7 Jacobian)
    has a smallest singular value >= 1e-4 (regular) with the generating q among the
    valid rows (1e-6 rad, 2 pi wrapped); singular in-limit ones with some valid
    in-limit row; the worst pose error of every valid row and the rows above 1e-12
    (m per row, rad).
(b) whole manifold, on the first ``--nb`` configurations of each half (all of them
    by default; ``--nb-slow`` (250) on the two general arms, 20-45 ms per pose):
    ``robot.self_motion(T)``; ``sm.sample(t_gen)`` must hold q (1e-6 rad) on some
    branch b, and for in-limit q (1e-9 slack) ``t_gen`` must lie in an interval of
    ``sm.intervals`` owned by b (1e-9 slack in t; the swivel modulo 2 pi). Counted
    separately for regular and singular configurations.

Prints one line per arm and part, then the first three misses of each kind (q as a
list). Takes ~6.5 min CPU at the defaults (17 min wall at load 8 on the 2 shared
cores): the Panda's (b) 2.1 min (12.8 ms per pose; special poses leave the compiled
kernel), the Gen3-like arm's and the offset iiwa's 1.5 min each.

Run: ``python benchmarks/self_motion_rates.py [--n 10000] [--nb 0] [--nb-mid 300]
[--nb-slow 250] [--seed 0] [--arms panda,srs,...] [--dump PREFIX]`` (``--dump``: each
arm's configurations and part (b) results to ``PREFIX_<arm>.npz``, to re-run its
misses on another tree: the session-8 A/B, ``docs/benchmarks.md``).
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / p) for p in ("tests", "tests/kinematics/ik", "benchmarks")]

from bench_self_motion import IIWA_URDF, gen3_like  # noqa: E402
from test_fixed_properties import NON_SINGULAR, special_batch  # noqa: E402

import robokin  # noqa: E402
from reference import iiwa14_srs, offset_iiwa14, pose_errors, random_7r  # noqa: E402
from robokin.kinematics.ik.self_motion import parameter_values  # noqa: E402
from robokin.kinematics.ik.self_motion_families import _setup  # noqa: E402

SLOW = ("offset_iiwa", "random_7r")
MID = ("iiwa_urdf", "gen3_like")  # held closed form, manifold not compiled: 40-95 ms
#: the parameter per arm where it is not ``auto``'s (the offset iiwa: its general path)
PARAMETER = {"offset_iiwa": "a7"}


def build(name: str) -> robokin.Robot:
    """The arm called name (module docstring)."""
    if name == "panda":
        return robokin.load("panda")
    if name == "srs":
        return iiwa14_srs()
    if name == "iiwa_urdf":
        import rtbdata

        urdf = pathlib.Path(rtbdata.__file__).parent / IIWA_URDF
        return robokin.Robot.from_urdf(str(urdf), geometry=False)
    if name == "gen3_like":
        return gen3_like()
    if name == "offset_iiwa":
        return offset_iiwa14()
    return random_7r(29)


def configurations(robot: robokin.Robot, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(q (n, 7), special (n,) bool): half uniform in the limits, half special_batch."""
    rng = np.random.default_rng(seed)
    lim = robot.limits
    half = n // 2
    q = np.concatenate([rng.uniform(lim[:, 0], lim[:, 1], (n - half, 7)),
                        special_batch(robot, half, rng)])
    return q, np.arange(n) >= n - half


def gap(Q: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Largest 2 pi wrapped joint difference [rad]."""
    return np.abs((Q - q + np.pi) % (2 * np.pi) - np.pi).max(axis=-1)


def per_value(robot, name, q, T):
    """Part (a): (back (n,), in-limit row (n,), regular (n,), worst error, rows > 1e-12)."""
    if name == "swivel":
        arm = _setup(robot.arm).swivel
        _, psi = parameter_values(robot, T, q[:, None, :])
        Q, valid, _ = arm.rows(T, psi)
        Q, valid = Q[:, 0], valid[:, 0]
        # the swivel's rows are a smooth parametrisation where the arm is regular and
        # no triple is at its aligned-axes point (q2, q6 at 0 or pi; q4 at 0 is in J)
        sigma = np.minimum(np.linalg.svd(robot.jacobian(q), compute_uv=False)[:, -1],
                           np.abs(np.sin(q[:, [1, 5]])).min(axis=-1))
    else:
        j = robot.joint_names.index(name)
        sols = robot.ik(T, fixed={name: q[:, j]})
        Q, valid = sols.q, sols.valid
        sigma = np.linalg.svd(np.delete(robot.jacobian(q), j, axis=-1), compute_uv=False)[:, -1]
    dp, dr = pose_errors(robot.fk(Q[valid]),
                         np.broadcast_to(T[:, None], Q.shape[:2] + (4, 4))[valid])
    e = np.maximum(dp, dr)
    back = np.where(valid, gap(Q, q[:, None]), np.inf).min(axis=-1) <= 1e-6
    lo, hi = robot.limits[:, 0], robot.limits[:, 1]
    with np.errstate(invalid="ignore"):
        row_in = np.all((lo - 1e-9 <= Q) & (hi + 1e-9 >= Q), axis=-1)
    ok = (valid & row_in).any(axis=-1)
    return back, ok, sigma >= NON_SINGULAR, float(e.max(initial=0.0)), int((e > 1e-12).sum())


def on_manifold(robot, name, q, T, t_gen):
    """Part (b) for one pose: (sampled back, in an interval of its branch, seconds CPU)."""
    c0 = time.process_time()
    sm = robot.self_motion(T, "auto" if name == "swivel" else name)
    rows = sm.sample(t_gen)
    cpu = time.process_time() - c0
    with np.errstate(invalid="ignore"):
        g = np.where(np.isfinite(rows).all(axis=-1), gap(rows, q), np.inf)
    hits = np.flatnonzero(g <= 1e-6)
    shifts = (-2 * np.pi, 0.0, 2 * np.pi) if sm.periodic else (0.0,)
    inside = False
    for b in hits:
        iv = sm.intervals[sm.interval_branch == b]
        for s in shifts:
            if np.any((iv[:, 0] - 1e-9 <= t_gen + s) & (t_gen + s <= iv[:, 1] + 1e-9)):
                inside = True
    kind = 0  # a miss: 1 an isolated in-limit point, 2 a sliver, 0 neither
    if len(hits) and not inside:
        kind = touch_kind(sm, hits[0], q, t_gen)
    return bool(len(hits)), inside, cpu, kind


def touch_kind(sm, b: int, q: np.ndarray, t_gen: float) -> int:
    """How a miss lies: 1 branch b is outside (1e-12 slack) at t_gen +- 1e-10, q is an
    isolated in-limit point; 2 it is outside at t_gen +- 1e-4 (a sliver: in limits
    over less than 2e-4 of t, e.g. a graze from outside or two limits met at once);
    0 neither (the domain's end counts as outside)."""
    lim = sm.limits

    def out(d):
        td = t_gen + d
        if not sm.periodic and not sm.domain[0] <= td <= sm.domain[1]:
            return True
        r = sm.sample(td)[b]
        return not np.all((r >= lim[:, 0] - 1e-12) & (r <= lim[:, 1] + 1e-12))

    if out(-1e-10) and out(1e-10):
        return 1
    return 2 if out(-1e-4) and out(1e-4) else 0


def run_arm(arm: str, n: int, nb: int, seed: int, dump: str = "") -> None:
    robot = build(arm)
    q, special = configurations(robot, n, seed)
    T = robot.fk(q)
    name, t = parameter_values(robot, T, q[:, None, :])
    t = t[:, 0]
    if arm in PARAMETER:
        name = PARAMETER[arm]
        t = q[:, robot.joint_names.index(name)]
    lo, hi = robot.limits[:, 0], robot.limits[:, 1]
    inside = np.all((q >= lo - 1e-9) & (q <= hi + 1e-9), axis=-1)
    c0 = time.process_time()
    back, ok, regular, worst, wrong = per_value(robot, name, q, T)
    cpu = time.process_time() - c0
    sing = ~regular & inside
    print(f"{arm} ({name}), n {n}: (a) {cpu:.1f} s CPU")
    for label, sel in (("uniform", ~special), ("special", special)):
        r, s = regular & sel, sing & sel
        print(f"  (a) {label:8s} regular back {back[r].sum()}/{r.sum()}, singular in-limit "
              f"row {ok[s].sum()}/{s.sum()}")
    print(f"  (a) worst row error {worst:.2e}, rows > 1e-12: {wrong}")
    for m in q[regular & ~back][:3]:
        print("    (a) regular missed", m.tolist())
    for m in q[sing & ~ok][:3]:
        print("    (a) singular no in-limit row", m.tolist())
    pick = np.concatenate([np.flatnonzero(~special)[:nb], np.flatnonzero(special)[:nb]])
    # sample(t) outside a joint parameter's range is not asked for (q is then outside)
    dom = robot.limits[robot.joint_names.index(name)] if name != "swivel" else (-4.0, 4.0)
    pick = pick[(t[pick] >= dom[0]) & (t[pick] <= dom[1])]
    res = np.array([on_manifold(robot, name, q[i], T[i], float(t[i])) for i in pick])
    got, within, cpu_b = res[:, 0] > 0, res[:, 1] > 0, res[:, 2].sum()
    alone, sliver = res[:, 3] == 1, res[:, 3] == 2
    print(f"  (b) {len(pick)} poses, {1e3 * cpu_b / len(pick):.2f} ms CPU per pose "
          "(self_motion + sample)")
    for label, sel in (("uniform", ~special[pick]), ("special", special[pick])):
        for kind, rr in (("regular", regular[pick]), ("singular", ~regular[pick])):
            s = sel & rr
            si = s & inside[pick]
            print(f"  (b) {label:8s} {kind:8s} sampled back {got[s].sum()}/{s.sum()}, "
                  f"in-limit in an interval {within[si].sum()}/{si.sum()} (misses: isolated "
                  f"point {alone[si].sum()}, sliver {sliver[si].sum()}, other "
                  f"{(si & got & ~within & ~alone & ~sliver).sum()}, not sampled "
                  f"{(si & ~got).sum()})")
    if dump:
        np.savez(f"{dump}_{arm}.npz", q=q, pick=pick, res=res, regular=regular,
                 special=special, inside=inside, t=t, back=back, ok=ok)
    for m in pick[regular[pick] & ~got][:3]:
        print("    (b) regular not sampled", q[m].tolist())
    for m in pick[inside[pick] & got & ~within & ~alone & ~sliver][:6]:
        print(f"    (b) not in an interval ({'regular' if regular[m] else 'singular'})",
              q[m].tolist())
    for m in pick[inside[pick] & got & ~within & sliver][:3]:
        print(f"    (b) sliver not in an interval ({'regular' if regular[m] else 'singular'})",
              q[m].tolist())
    for m in pick[~regular[pick] & ~got][:3]:
        print("    (b) singular not sampled", q[m].tolist())
    sys.stdout.flush()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10000)
    ap.add_argument("--nb", type=int, default=0, help="(b) poses per half; 0: all")
    ap.add_argument("--nb-mid", type=int, default=300, help="(b) per half, URDF iiwa, Gen3")
    ap.add_argument("--nb-slow", type=int, default=250, help="(b) per half, general arms")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--arms", default="panda,srs,iiwa_urdf,gen3_like,offset_iiwa,random_7r")
    ap.add_argument("--dump", default="", help="save each arm's configurations and "
                    "results to DUMP_<arm>.npz")
    a = ap.parse_args()
    load = pathlib.Path("/proc/loadavg").read_text().split()[:3]
    print(f"seed {a.seed}; load {load}")
    for arm in a.arms.split(","):
        nb = (a.nb_slow if arm in SLOW else a.nb_mid if arm in MID else a.nb) or a.n
        run_arm(arm, a.n, nb, a.seed, a.dump)


if __name__ == "__main__":
    main()
