"""General 6R IK: robokin's general_6r against ssik, a 16-seed numeric search and
ik-geo's general solver, for completeness and speed, in one run.

Arm groups (none has a closed form in robokin; each is solved by ``general_6r``):

* random general DH arms (a, d in [-0.5, 0.5] m, alpha and theta offsets uniform);
* the rtb-data ABB IRB140 URDF (axis 6 20 mm off axis 4; a 2.8 m model);
* a UR5 with a twisted forearm (alpha_3 = 0.05 rad) and an offset wrist (a_5 = 0.02 m);
* random *sparse* DH arms (each a, d zero with probability 1/2, alpha 0, +-pi/2 or
  uniform, theta offsets 0), those whose Jacobian has full rank and that detection
  sends to general_6r;
* the Panda with joint 1, 2 or 3 held (0.4, -0.6, 0.9 rad): the reduced 6R chains
  ``robot.ik(T, fixed=...)`` solves.

Two pose sets per group: **uniform** (joint values uniform in [-pi, pi]) and
**special** (each joint at 0, +-pi/2 or pi plus 0, +-1e-9, +-1e-7 or +-1e-6, at a
limit, or uniform, as in ``tests/kinematics/ik/test_analytic_general_6r.py``).

Measured per group and set:

* robokin speed: microseconds per pose of the compiled kernel on a batch (best of 3)
  on ONE thread (CPU time of that thread, which a shared machine does not inflate, and
  wall time) and on every thread of the pool (wall), and of the full ``robot.ik`` call;
* robokin completeness at every pose of the set: a configuration whose Jacobian's
  smallest singular value is above 1e-3 (rows in m and rad per rad) has isolated
  solutions and must come back (modulo 2 pi within 1e-6 rad): the share that does;
  at the other (singular) ones the share with at least one solution; the largest FK
  error of any solution (position [m] per metre of arm scale, rotation [rad]);
* against a dense multi-start reference on a subsample of non-singular poses
  (``numeric.solve_all`` with ``--ref-seeds`` starts, every joint in [-pi, pi]):
  solutions found, missing, extra
  (two solutions are one within 1e-5 rad: a near-singular numeric one is only that
  close), for robokin, the 16-seed numeric search and ik-geo's ``gen_six_dof``;
* ssik (``--ssik N``: N poses per set on the first arm of each group, ``ssik`` 8.x
  from the package index, its ``Manipulator.from_transforms`` on the robot's canonical
  chain, ``solve(T, respect_limits=False)``): set-up time (``prepare()``: its per-arm
  symbolic derivation, cached on disk by ssik after the first run), milliseconds per
  pose (CPU time of the calling thread and wall, one Python call per pose), the
  generating configuration recovered (a row within 1e-6 rad), rows with an FK error
  above 1e-9 m / rad, and on the non-singular poses the solutions robokin has that
  ssik does not (missing) and the reverse (extra), matched within 1e-6 rad.

Every robokin solution is checked to reproduce its pose before anything is reported.
Run: ``python benchmarks/bench_ik_general_6r.py [--poses 10000] [--ssik 200]
[--groups irb140,random]`` (ssik's set-up is minutes of CPU per arm the first time).
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
from robokin.kinematics.jacobian import min_singular_value

IRB140 = Path(__file__).parents[1] / "tests" / "data" / "urdf" / "irb140.urdf"
SAME = 1e-5  # [rad] same solution against the numeric reference
GENERATING = 1e-6  # [rad] the generating configuration recovered
ISOLATED = 1e-3  # Jacobian's smallest singular value above: isolated solutions
SPECIAL = np.array([0.0, math.pi / 2, -math.pi / 2, math.pi])
TINY = np.array([0.0, 1e-9, -1e-9, 1e-7, -1e-7, 1e-6, -1e-6])
HELD = {"joint1": 0.4, "joint2": -0.6, "joint3": 0.9}


# ----------------------------------------------------------------------- arms
def random_arm(rng: np.random.Generator, k: int) -> robokin.Robot:
    rows = [{"joint": "revolute", "a": rng.uniform(-0.5, 0.5), "d": rng.uniform(-0.5, 0.5),
             "alpha": rng.uniform(-np.pi, np.pi), "theta": rng.uniform(-np.pi, np.pi),
             "limits": [-np.pi, np.pi]} for _ in range(6)]
    return robokin.Robot.from_dh(rows, name=f"random{k}")


def random_arms(count: int) -> list[robokin.Robot]:
    """``count`` random general DH arms (seed 0)."""
    rng = np.random.default_rng(0)
    return [random_arm(rng, k) for k in range(count)]


def sparse_arms(rng: np.random.Generator, count: int) -> list[robokin.Robot]:
    """Random sparse DH arms with a full-rank Jacobian that go to general_6r."""
    out: list[robokin.Robot] = []
    while len(out) < count:
        rows = []
        for _ in range(6):
            alpha = [0.0, rng.choice([-1.0, 1.0]) * np.pi / 2, rng.uniform(-np.pi, np.pi)]
            rows.append({"joint": "revolute", "theta": 0.0, "limits": [-np.pi, np.pi],
                         "a": 0.0 if rng.random() < 0.5 else rng.uniform(-0.5, 0.5),
                         "d": 0.0 if rng.random() < 0.5 else rng.uniform(-0.5, 0.5),
                         "alpha": alpha[int(rng.integers(0, 3))]})
        robot = robokin.Robot.from_dh(rows, name=f"sparse{len(out)}")
        q = rng.uniform(-np.pi, np.pi, (20, 6))
        if (np.median(min_singular_value(robot.chain, q)) > 1e-6
                and robokin.ik.family(robot).name == "general_6r"):
            out.append(robot)
    return out


def ur_twisted() -> robokin.Robot:
    rows = [{"d": 0.089159, "alpha": math.pi / 2}, {"a": -0.425},
            {"a": -0.39225, "alpha": 0.05}, {"d": 0.10915, "alpha": math.pi / 2},
            {"d": 0.09465, "a": 0.02, "alpha": -math.pi / 2}, {"d": 0.0823}]
    for r in rows:
        for key in ("a", "d", "alpha"):
            r.setdefault(key, 0.0)
        r.update(joint="revolute", theta=0.0, limits=[-2 * np.pi, 2 * np.pi])
    return robokin.Robot.from_dh(rows, name="ur5_twisted")


def panda_held() -> list[robokin.Robot]:
    """The Panda's reduced chains with joint 1, 2 or 3 held (as ``fixed=`` builds)."""
    panda = robokin.load("panda")
    return [robokin.Robot(panda.chain.with_fixed({int(j[-1]) - 1: v}),
                          name=f"panda ({j}={v:g} held)") for j, v in HELD.items()]


GROUPS = ("random", "irb140", "ur_twisted", "sparse", "panda_held")


def groups(n_random: int, n_sparse: int, keys: tuple[str, ...] = GROUPS
           ) -> list[tuple[str, list[robokin.Robot]]]:
    """(title, arms) of the groups named in ``keys`` (see ``GROUPS``), in that order."""
    make = {
        "random": lambda: ("random general 6R DH arms", random_arms(n_random)),
        "irb140": lambda: ("ABB IRB140 (rtb-data URDF)",
                           [robokin.Robot.from_urdf(IRB140, geometry=False)]),
        "ur_twisted": lambda: ("UR5, twisted forearm + offset wrist", [ur_twisted()]),
        "sparse": lambda: ("random sparse DH arms",
                           sparse_arms(np.random.default_rng(1), n_sparse)),
        "panda_held": lambda: ("Panda, joint 1 / 2 / 3 held", panda_held()),
    }
    return [make[k]() for k in keys]


def open_limits(robot: robokin.Robot) -> robokin.Robot:
    chain = robot.chain
    joints = tuple(dataclasses.replace(j, limits=(-np.pi, np.pi)) for j in chain.joints)
    return robot.replace(chain=chain.replace(joints=joints, coordinates=joints))


def special_configurations(rng: np.random.Generator, n: int, limits: np.ndarray
                           ) -> np.ndarray:
    """(n, 6) joint values: per joint special + tiny (1/2), a limit (1/4), uniform."""
    kind = rng.integers(0, 4, (n, 6))
    special = SPECIAL[rng.integers(0, 4, (n, 6))] + TINY[rng.integers(0, 7, (n, 6))]
    ends = np.where(rng.random((n, 6)) < 0.5, np.clip(limits[:, 0], -np.pi, np.pi),
                    np.clip(limits[:, 1], -np.pi, np.pi))
    uniform = rng.uniform(-np.pi, np.pi, (n, 6))
    return np.where(kind < 2, special, np.where(kind == 2, ends, uniform))


# -------------------------------------------------------------------- helpers
def wrapped(d: np.ndarray) -> np.ndarray:
    return (d + np.pi) % (2 * np.pi) - np.pi


def not_in(a: np.ndarray, b: np.ndarray, tol: float = SAME) -> int:
    """How many rows of a have no row of b within tol (modulo 2 pi)."""
    if len(a) == 0:
        return 0
    if len(b) == 0:
        return len(a)
    d = np.abs(wrapped(a[:, None, :] - b[None, :, :])).max(axis=-1)
    return int((d >= tol).all(axis=1).sum())


def compare(sets: list[np.ndarray], refs: list[np.ndarray]) -> tuple[int, int, int]:
    """(found, missing, extra) summed over poses."""
    return (sum(len(s) for s in sets), sum(not_in(r, s) for s, r in zip(sets, refs)),
            sum(not_in(s, r) for s, r in zip(sets, refs)))


def found_generating(q: np.ndarray, sets: list[np.ndarray]) -> np.ndarray:
    return np.array([len(s) > 0 and np.abs(wrapped(s - qi)).max(axis=1).min() < GENERATING
                     for qi, s in zip(q, sets)])


def best_time(fn, repeat: int = 3, clock=time.perf_counter) -> float:
    """Best of ``repeat`` calls [s] on ``clock``."""
    best = np.inf
    for _ in range(repeat):
        t0 = clock()
        fn()
        best = min(best, clock() - t0)
    return best


# -------------------------------------------------------------------- robokin
def robokin_speed(robot, T: np.ndarray) -> dict[str, float]:
    """Microseconds per pose: kernel on 1 thread (CPU and wall), on all threads, robot.ik."""
    g = general_6r.setup(robot.chain)
    Tc = np.ascontiguousarray(T)
    before = _native.num_threads()

    def run() -> None:
        general_6r.raw_solve(robot.chain, g.params, Tc, parallel=True)

    out = {}
    try:
        for label, k in (("1 thread", 1), ("all threads", before)):
            _native.set_num_threads(k)
            run()
            out[label] = best_time(run)
            if k == 1:
                out["1 thread cpu"] = best_time(run, clock=time.thread_time)
    finally:
        _native.set_num_threads(before)
    out["robot.ik"] = best_time(lambda: robot.ik(T))
    return {k: v / len(T) * 1e6 for k, v in out.items()}


@dataclasses.dataclass
class Completeness:
    """Counts over the poses of a set (robokin at every pose)."""

    isolated: int = 0
    generating: int = 0
    singular: int = 0
    singular_solved: int = 0
    worst: float = 0.0

    def add(self, robot, q: np.ndarray, T: np.ndarray) -> list[np.ndarray]:
        sols = robot.ik(T)
        assert sols.method == "general_6r", sols.method
        scale = max(1.0, general_6r.setup(robot.chain).scale)
        dp, dr = fk_error(robot.chain, sols.q, T)
        self.worst = max(self.worst, float(np.max(np.where(sols.valid,
                                                           np.maximum(dp / scale, dr), 0))))
        sets = [sols.q[i][sols.valid[i]] for i in range(len(T))]
        isolated = min_singular_value(robot.chain, q) > ISOLATED
        hit = found_generating(q, sets)
        self.isolated += int(isolated.sum())
        self.generating += int((hit & isolated).sum())
        self.singular += int((~isolated).sum())
        self.singular_solved += int(((sols.count > 0) & ~isolated).sum())
        return sets


# ---------------------------------------------------------------------- peers
def ssik_manipulator(robot):
    """An ssik Manipulator with the robot's canonical chain (joint value = chain value)."""
    import ssik

    return ssik.Manipulator.from_transforms(np.array(robot.chain.arrays.consts), (0.0, 0.0, 1.0))


def ssik_run(robot, q: np.ndarray, T: np.ndarray, ours: list[np.ndarray]) -> dict[str, float]:
    """ssik on the poses: set-up [s], ms/pose, generating found, wrong, missing, extra.

    The generating configuration counts as found when any ssik row is within
    GENERATING of it (whatever its FK error); a row whose FK error is above 1e-9
    (m, rad) is counted wrong and left out of the set comparison. Missing / extra
    (against robokin's set, within GENERATING) are counted on the non-singular poses
    only: at a singular one both return points of a continuum, not the same points.
    """
    t0 = time.perf_counter()
    m = ssik_manipulator(robot)
    m.prepare()
    setup = time.perf_counter() - t0
    arr = robot.chain.arrays
    assert np.abs(m.fk(arr.sign * q[0] + arr.offset) - T[0]).max() < 1e-9
    rows, sets, wrong = [], [], 0
    t0, c0 = time.perf_counter(), time.thread_time()
    raw = [m.solve(Ti, respect_limits=False) for Ti in T]
    dt = (time.perf_counter() - t0) / len(T) * 1e3
    cpu = (time.thread_time() - c0) / len(T) * 1e3
    for Ti, sols in zip(T, raw):
        v = np.array([s.q for s in sols], dtype=float).reshape(-1, 6)
        qs = arr.sign * (v - arr.offset)
        rows.append(qs)
        if len(qs):
            dp, dr = fk_error(robot.chain, qs, Ti)
            bad = (dp > 1e-9) | (dr > 1e-9)
            wrong += int(bad.sum())
            qs = qs[~bad]
        sets.append(qs)
    isolated = min_singular_value(robot.chain, q) > ISOLATED
    hit = found_generating(q, rows)
    iso = np.flatnonzero(isolated)
    return {"setup": setup, "ms": dt, "cpu": cpu, "generating": float(hit[isolated].mean()),
            "isolated": int(isolated.sum()), "wrong": wrong,
            "missing": sum(not_in(ours[i], sets[i], GENERATING) for i in iso),
            "extra": sum(not_in(sets[i], ours[i], GENERATING) for i in iso),
            "ours": sum(len(ours[i]) for i in iso)}


def ik_geo_sets(robot, T: np.ndarray) -> tuple[list[np.ndarray], float] | None:
    """ik-geo's general 6R solver (gen_six_dof) in a Python loop; None without ik-geo."""
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
@dataclasses.dataclass
class Options:
    poses: int
    sub: int
    ref_seeds: int
    geo: int
    ssik: int


def run_set(name: str, kind: str, robots: list, opt: Options, rng: np.random.Generator
            ) -> None:
    """Time and check every method on one pose set of one arm group; print its rows."""
    per = max(1, opt.poses // len(robots))
    speed = dict.fromkeys(("1 thread", "1 thread cpu", "all threads", "robot.ik"), 0.0)
    done = Completeness()
    counts = {"robokin": [0, 0, 0], "numeric": [0, 0, 0], "ik-geo": [0, 0, 0]}
    t_num = t_geo = 0.0
    n_ref = 0
    ssik_rows = []
    for r_i, robot in enumerate(robots):
        q = (rng.uniform(-np.pi, np.pi, (per, 6)) if kind == "uniform"
             else special_configurations(rng, per, robot.limits))
        T = robot.fk(q)
        for k, v in robokin_speed(robot, T).items():
            speed[k] += v / len(robots)
        ours = done.add(robot, q, T)
        if opt.sub:  # on non-singular poses: a finite set of solutions to compare
            idx = np.flatnonzero(min_singular_value(robot.chain, q) > ISOLATED)[:opt.sub]
            ref = [numeric.solve_all(open_limits(robot), T[i], n_seeds=opt.ref_seeds,
                                     rng=np.random.default_rng(i)).solutions() for i in idx]
            n_ref += sum(len(r) for r in ref)
            t0 = time.perf_counter()
            num = numeric.solve_all(open_limits(robot), T[idx], n_seeds=16,
                                    rng=np.random.default_rng(1))
            t_num += (time.perf_counter() - t0) / len(idx) * 1e6 / len(robots)
            sets = [num.q[i][num.valid[i]] for i in range(len(idx))]
            found = {"robokin": ([ours[i] for i in idx], ref), "numeric": (sets, ref)}
            g = ik_geo_sets(robot, T[idx[:opt.geo]]) if opt.geo else None
            if g is not None:
                t_geo += g[1] / len(robots)
                found["ik-geo"] = (g[0], ref[:opt.geo])
            for key, (s, refs) in found.items():
                counts[key] = [a + b for a, b in zip(counts[key], compare(s, refs),
                                                      strict=True)]
        if opt.ssik and r_i == 0:
            ssik_rows.append(ssik_run(robot, q[:opt.ssik], T[:opt.ssik], ours[:opt.ssik]))
    print(f"\n{name}, {kind} poses: {per * len(robots)} poses ({len(robots)} arm(s))",
          flush=True)
    print(f"  robokin µs/pose: kernel 1 thread {speed['1 thread cpu']:.1f} CPU "
          f"({speed['1 thread']:.1f} wall), all threads {speed['all threads']:.1f}, "
          f"robot.ik {speed['robot.ik']:.1f}")
    print(f"  robokin generating configuration: {done.generating} / {done.isolated} "
          f"non-singular ({100 * done.generating / max(done.isolated, 1):.3f} %); "
          f"singular with a solution {done.singular_solved} / {done.singular}; worst FK "
          f"error {done.worst:.1e}")
    if opt.sub:
        print(f"  against a {opt.ref_seeds}-start reference on {opt.sub} non-singular "
              f"poses per arm ({n_ref} solutions): found / missing / extra")
        for key, (f, m, e) in counts.items():
            if key != "ik-geo" or opt.geo:
                extra = f", {t_num:.0f} µs/pose" if key == "numeric" else (
                    f", {t_geo:.0f} µs/pose" if key == "ik-geo" else "")
                print(f"    {key:<10s} {f:5d} {m:5d} {e:5d}{extra}")
    for s in ssik_rows:
        print(f"  ssik (first arm, {opt.ssik} poses): set-up {s['setup']:.1f} s, "
              f"{s['cpu']:.2f} ms/pose CPU ({s['ms']:.2f} wall), generating {100 * s['generating']:.1f} % of "
              f"{s['isolated']} non-singular, rows with FK error > 1e-9: {s['wrong']}; "
              f"on the non-singular poses, of robokin's {s['ours']} solutions not found "
              f"{s['missing']}, ssik's not robokin's {s['extra']}", flush=True)


def main(opt: Options, n_random: int = 5, n_sparse: int = 8,
         keys: tuple[str, ...] = GROUPS) -> None:
    """Run every comparison and print one block per arm group and pose set."""
    print(f"robokin {robokin.__version__}, kernels {_native.ISA}, "
          f"{_native.num_threads()} pool threads", flush=True)
    rng = np.random.default_rng(2)
    for name, robots in groups(n_random, n_sparse, keys):
        for robot in robots:
            fam = robokin.ik.family(robot)
            assert fam.name == "general_6r", (robot.name, fam)
        for kind in ("uniform", "special"):
            run_set(name, kind, robots, opt, rng)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--poses", type=int, default=10_000, help="poses per group and set")
    ap.add_argument("--sub", type=int, default=20, help="reference poses per arm (0: none)")
    ap.add_argument("--ref-seeds", type=int, default=2000, help="starts per reference pose")
    ap.add_argument("--ik-geo", type=int, default=0, help="ik-geo poses per arm (slow)")
    ap.add_argument("--ssik", type=int, default=0,
                    help="ssik poses per set on each group's first arm (set-up: minutes)")
    ap.add_argument("--random", type=int, default=5, help="random general arms")
    ap.add_argument("--sparse", type=int, default=8, help="random sparse arms")
    ap.add_argument("--groups", default=",".join(GROUPS),
                    help=f"comma-separated arm groups, of {', '.join(GROUPS)}")
    a = ap.parse_args()
    keys = tuple(k.strip() for k in a.groups.split(",") if k.strip())
    bad = [k for k in keys if k not in GROUPS]
    if bad:
        ap.error(f"--groups: unknown {', '.join(bad)}; choose from {', '.join(GROUPS)}")
    main(Options(a.poses, a.sub, a.ref_seeds, a.ik_geo, a.ssik), a.random, a.sparse, keys)
