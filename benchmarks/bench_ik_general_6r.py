"""General 6R IK: robokin's general_6r against ik-geo's general solver and a 16-seed
numeric search, for speed and completeness, in one run.

Arms: random general DH arms (a, d in [-0.5, 0.5] m, alpha and theta offsets
uniform), the rtb-data ABB IRB140 URDF (axis 6 20 mm off axis 4) and a UR5 with a
twisted forearm (alpha_3 = 0.05 rad) and an offset wrist (a_5 = 0.02 m): none has
a closed form. Poses come from uniform joint values in [-pi, pi].

Per arm group:

* speed: microseconds per pose of the compiled kernel on a batch (best of 3) on
  ONE thread (wall time, and in brackets the thread's CPU time, which a shared
  machine does not inflate) and on every thread of the pool, and of the full
  ``robot.ik`` call (checks, joint wrapping, flags); the 16-seed numeric search
  (``numeric.solve_all(robot, T, n_seeds=16)``, joints in [-pi, pi] like the
  reference) and ik-geo's general solver
  (``ik_geo.Robot.gen_six_dof``, a Python loop) on subsamples;
* completeness: on a subsample, every method's solutions against a dense
  multi-start reference (``numeric.solve_all`` with ``--ref-seeds`` starts per
  pose, every joint in [-pi, pi]): solutions found, missing (in the reference,
  not found), extra (found, not in the reference); two solutions are the same
  within 1e-5 rad (a near-singular numeric solution is only that close);
* the share of poses whose generating configuration is among the solutions
  (robokin on every pose, the 16-seed search on its subsample).

Every robokin solution is checked to reproduce its pose to 1e-9 before anything is
reported. Run: ``python benchmarks/bench_ik_general_6r.py [--poses 10000]``.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time
from pathlib import Path

import numpy as np

import robokin
from robokin import _native
from robokin.kinematics.ik import numeric
from robokin.kinematics.ik.analytic import general_6r
from robokin.kinematics.ik.analytic._common import fk_error

IRB140 = Path(__file__).parents[1] / "tests" / "data" / "urdf" / "irb140.urdf"
SAME = 1e-5  # [rad]


# ----------------------------------------------------------------------- arms
def random_arm(rng: np.random.Generator, k: int) -> robokin.Robot:
    rows = [{"joint": "revolute", "a": rng.uniform(-0.5, 0.5), "d": rng.uniform(-0.5, 0.5),
             "alpha": rng.uniform(-np.pi, np.pi), "theta": rng.uniform(-np.pi, np.pi),
             "limits": [-np.pi, np.pi]} for _ in range(6)]
    return robokin.Robot.from_dh(rows, name=f"random{k}")


def ur_twisted() -> robokin.Robot:
    rows = [{"d": 0.089159, "alpha": math.pi / 2}, {"a": -0.425},
            {"a": -0.39225, "alpha": 0.05}, {"d": 0.10915, "alpha": math.pi / 2},
            {"d": 0.09465, "a": 0.02, "alpha": -math.pi / 2}, {"d": 0.0823}]
    for r in rows:
        for key in ("a", "d", "alpha"):
            r.setdefault(key, 0.0)
        r.update(joint="revolute", theta=0.0, limits=[-2 * np.pi, 2 * np.pi])
    return robokin.Robot.from_dh(rows, name="ur5_twisted")


def open_limits(robot: robokin.Robot) -> robokin.Robot:
    chain = robot.chain
    joints = tuple(dataclasses.replace(j, limits=(-np.pi, np.pi)) for j in chain.joints)
    return robot.replace(chain=chain.replace(joints=joints, coordinates=joints))


# -------------------------------------------------------------------- helpers
def wrapped(d: np.ndarray) -> np.ndarray:
    return (d + np.pi) % (2 * np.pi) - np.pi


def not_in(a: np.ndarray, b: np.ndarray) -> int:
    """How many rows of a have no row of b within SAME (modulo 2 pi)."""
    if len(a) == 0:
        return 0
    if len(b) == 0:
        return len(a)
    d = np.abs(wrapped(a[:, None, :] - b[None, :, :])).max(axis=-1)
    return int((d >= SAME).all(axis=1).sum())


def compare(sets: list[np.ndarray], refs: list[np.ndarray]) -> tuple[int, int, int]:
    """(found, missing, extra) summed over poses."""
    return (sum(len(s) for s in sets), sum(not_in(r, s) for s, r in zip(sets, refs)),
            sum(not_in(s, r) for s, r in zip(sets, refs)))


def generating_found(q: np.ndarray, sets: list[np.ndarray]) -> float:
    hit = [len(s) > 0 and np.abs(wrapped(s - qi)).max(axis=1).min() < SAME
           for qi, s in zip(q, sets)]
    return float(np.mean(hit))


def best_time(fn, repeat: int = 3, clock=time.perf_counter) -> float:
    """Best of ``repeat`` calls [s] on ``clock`` (wall time by default; thread CPU
    time, ``time.thread_time``, is what a single-threaded call costs on a shared
    machine)."""
    best = np.inf
    for _ in range(repeat):
        t0 = clock()
        fn()
        best = min(best, clock() - t0)
    return best


# -------------------------------------------------------------------- methods
def robokin_speed(robot, T: np.ndarray) -> dict[str, float]:
    """Microseconds per pose: kernel on 1 thread (wall and CPU time), on all threads,
    robot.ik (wall)."""
    g = general_6r.setup(robot.chain)
    Tc = np.ascontiguousarray(T)
    before = _native.num_threads()
    out = {}
    try:
        for label, k in (("1 thread", 1), ("all threads", before)):
            _native.set_num_threads(k)
            general_6r.raw_solve(robot.chain, g.params, Tc[:64], parallel=True)
            out[label] = best_time(
                lambda: general_6r.raw_solve(robot.chain, g.params, Tc, parallel=True))
            if k == 1:
                out["1 thread cpu"] = best_time(
                    lambda: general_6r.raw_solve(robot.chain, g.params, Tc, parallel=True),
                    clock=time.thread_time)
    finally:
        _native.set_num_threads(before)
    out["robot.ik"] = best_time(lambda: robot.ik(T))
    return {k: v / len(T) * 1e6 for k, v in out.items()}


def robokin_sets(robot, T: np.ndarray) -> list[np.ndarray]:
    sols = robot.ik(T)
    assert sols.method == "general_6r", sols.method
    dp, dr = fk_error(robot.chain, sols.q, T)
    worst = float(np.max(np.where(sols.valid, np.maximum(dp, dr), 0.0)))
    assert worst < 1e-9, f"{robot.name}: a solution off its pose by {worst:.1e}"
    return [sols.q[i][sols.valid[i]] for i in range(len(T))]


def numeric_sets(robot, T: np.ndarray, seeds: int, rng) -> tuple[list[np.ndarray], float]:
    t0 = time.perf_counter()
    sols = numeric.solve_all(robot, T, n_seeds=seeds, rng=rng)
    dt = (time.perf_counter() - t0) / len(T) * 1e6
    return [sols.q[i][sols.valid[i]] for i in range(len(T))], dt


def ik_geo_sets(robot, T: np.ndarray) -> tuple[list[np.ndarray], float] | None:
    """ik-geo's general 6R solver (gen_six_dof) in a Python loop, solutions in joint
    coordinates; None when ik-geo is not installed."""
    try:
        import ik_geo
    except ImportError:
        return None
    from robokin.kinematics.ik.analytic._geometry import poe_from_chain

    poe = poe_from_chain(robot.chain)
    p = np.vstack([poe.o[0], np.diff(poe.o, axis=0), poe.M[:3, 3] - poe.o[-1]])
    bot = ik_geo.Robot.gen_six_dof(poe.h.tolist(), p.tolist())
    RM = poe.M[:3, :3]
    arr = robot.chain.arrays
    # its model agrees with ours (it reads rotations column by column)
    v = np.array([0.3, -0.7, 1.1, 0.4, -0.9, 0.2])
    R, t = bot.forward_kinematics(v.tolist())
    Tq = robot.fk(arr.sign * (v - arr.offset))
    assert np.allclose(np.array(R).T, Tq[:3, :3] @ RM.T, atol=1e-9)
    assert np.allclose(t, Tq[:3, 3], atol=1e-9)
    out = []
    t0 = time.perf_counter()
    for Ti in T:
        res = bot.get_ik((Ti[:3, :3] @ RM.T).T.tolist(), Ti[:3, 3].tolist())
        vals = np.array([s for s, ls in res if not ls], dtype=float).reshape(-1, 6)
        q = arr.sign * (vals - arr.offset)
        if len(q):
            dp, dr = fk_error(robot.chain, q, Ti)
            q = q[(dp < 1e-9) & (dr < 1e-9)]
        out.append(q)
    return out, (time.perf_counter() - t0) / len(T) * 1e6


# ----------------------------------------------------------------------- main
def _row(label: str, one: str, all_: str, counts: list[int], gen: str) -> None:
    print(f"  {label:<26s} {one:>20s} {all_:>12s} {counts[0]:6d} {counts[1]:8d} "
          f"{counts[2]:6d} {gen:>19s}")


def run_group(name: str, robots: list, poses: int, sub: int, ref_seeds: int,
              geo: int, rng: np.random.Generator) -> None:
    """Time and check every method on the arms of one group; print its table."""
    per = poses // len(robots)
    speed = {"1 thread": 0.0, "1 thread cpu": 0.0, "all threads": 0.0, "robot.ik": 0.0}
    counts = {"robokin": [0, 0, 0], "numeric": [0, 0, 0], "ik-geo": [0, 0, 0]}
    gen = {"robokin": [], "numeric": []}
    t_num = t_geo = 0.0
    n_ref = n_geo = 0
    for robot in robots:
        q = rng.uniform(-np.pi, np.pi, (per, 6))
        T = robot.fk(q)
        for k, v in robokin_speed(robot, T).items():
            speed[k] += v / len(robots)
        ours = robokin_sets(robot, T)
        gen["robokin"].append(generating_found(q, ours))
        ref = [numeric.solve_all(open_limits(robot), T[i], n_seeds=ref_seeds,
                                 rng=np.random.default_rng(i)).solutions()
               for i in range(sub)]
        n_ref += sum(len(r) for r in ref)
        num, dt = numeric_sets(open_limits(robot), T[:sub], 16, np.random.default_rng(1))
        t_num += dt / len(robots)
        gen["numeric"].append(generating_found(q[:sub], num))
        found = {"robokin": (ours[:sub], ref), "numeric": (num, ref)}
        g = ik_geo_sets(robot, T[:geo]) if geo else None
        if g is not None:
            t_geo += g[1] / len(robots)
            n_geo += geo
            found["ik-geo"] = (g[0], ref[:geo])
        for key, (sets, refs) in found.items():
            counts[key] = [a + b for a, b in zip(counts[key], compare(sets, refs),
                                                  strict=True)]
    print(f"\n{name}: {poses} poses ({len(robots)} arm(s)); completeness on {sub} poses "
          f"per arm against a {ref_seeds}-start reference ({n_ref} solutions)")
    print(f"  {'method':<26s} {'us/pose 1 thr (cpu)':>20s} {'us/pose all':>12s} "
          f"{'found':>6s} {'missing':>8s} {'extra':>6s} {'generating q found':>19s}")
    pct = {k: f"{100 * np.mean(v):.2f}%" for k, v in gen.items()}
    _row("robokin general_6r", f"{speed['1 thread']:.1f} ({speed['1 thread cpu']:.1f})",
         f"{speed['all threads']:.1f}", counts["robokin"], pct["robokin"])
    print(f"  {'  (robot.ik, full call)':<26s} {'':>20s} {speed['robot.ik']:12.1f}")
    _row("numeric, 16 seeds", "", f"{t_num:.1f}", counts["numeric"], pct["numeric"])
    if n_geo:
        _row("ik-geo gen_six_dof", f"{t_geo:.0f}", "", counts["ik-geo"],
             f"(first {geo} poses/arm)")


def main(poses: int = 10_000, sub: int = 20, ref_seeds: int = 2000, geo: int = 3,
         n_random: int = 5) -> None:
    """Run every comparison and print one table per arm group."""
    rng = np.random.default_rng(0)
    print(f"robokin {robokin.__version__}, kernels {_native.ISA}, "
          f"{_native.num_threads()} pool threads")
    groups = [("random general 6R DH arms", [random_arm(rng, k) for k in range(n_random)]),
              ("ABB IRB140 (rtb-data URDF)",
               [robokin.Robot.from_urdf(IRB140, geometry=False)]),
              ("UR5, twisted forearm + offset wrist", [ur_twisted()])]
    for name, robots in groups:
        for robot in robots:
            fam = robokin.ik.family(robot)
            assert fam.name == "general_6r", (robot.name, fam)
        run_group(name, robots, poses, sub, ref_seeds, geo, rng)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--poses", type=int, default=10_000, help="poses per arm group")
    ap.add_argument("--sub", type=int, default=20, help="reference poses per arm")
    ap.add_argument("--ref-seeds", type=int, default=2000, help="starts per reference pose")
    ap.add_argument("--ik-geo", type=int, default=3, help="ik-geo poses per arm (slow)")
    args = ap.parse_args()
    main(args.poses, args.sub, args.ref_seeds, args.ik_geo)
