"""The self-motion manifold of one pose: robokin against ssik (charts) and geofikpy.

Every method gets the same poses ``robot.fk(q)``:

* robokin ``robot.self_motion(T)``: every branch and the exact in-limit intervals
  of the pose (q7 on the Panda through the held-joint ``pieper`` kernel; the
  swivel on the exact iiwa14-type SRS arm, ``tests/reference.py``). Timed: the
  whole manifold per pose, and ``sm.sample(t)`` per (pose, value) on 64 values;
* ssik 8.2 (Panda): ``Manipulator.from_prebuilt("franka_panda_ik").self_motion(T)``,
  its charts q(q7) (He and Liu on the reversed chain); timed: the charts per pose
  (without interval ends: ssik gives chart domains, not joint-limit intervals);
* geofikpy (Panda): ``franka_ik_q7(r, R, q7)``, per (pose, value).

Scored (``bench_ik_held.score``): the generating configuration among the rows at its
own q7 / swivel (within 1e-6 rad), rows with a pose error above 1e-9 (wrong) and
the largest error. Configurations uniform in the limits. Times: best of
``--repeat`` runs, peers in the same run.

Arms: the Panda; the exact iiwa14-type SRS arm (the compiled swivel,
``csrc/self_motion.c``: also timed as bare kernel batches); the rtb-data
``lbr_iiwa_14_r820.urdf`` (shoulder offset 0.44 mm: not exactly SRS, so the held
joint path: ``auto`` picks joint_a4 with the Pieper closed form, continuation-free)
and a Gen3-like arm (Kinova Gen3 7-DoF, the classic DH table of the Kinova Gen3 user
guide: d = -0.2848, -0.0118, -0.4208, -0.0128, -0.3143, 0, -0.1674 m, alpha = pi/2
(pi for joint 7), theta offsets 0, pi, ..., pi; limits +-128.9, 147.8, 120.3 deg on
joints 2, 4, 6, the continuous joints 1, 3, 5, 7 taken as +-180 deg; its 11.8 and
12.8 mm offsets leave no held-joint closed form: the general held-joint 6R solver,
continued). The last two take ``--slow-poses`` poses (seconds per pose). Every time
is given as wall time and as process CPU time (the machine is shared).

Peers on the last two arms: ssik 8.2 built from the same URDF (``from_urdf``) and
from the same DH table (``from_dh``; its joint angles are ours plus the theta
offsets); both dispatch to ``seven_r.srs_polished`` (an approximate class: no
charts), so its ``solve(T)`` sample is scored (set-up time printed: ssik caches its
per-arm preparation under ``~/.cache/ssik`` itself). geofikpy is Panda-only.

Run: ``python benchmarks/bench_self_motion.py [--poses 200] [--slow-poses 5]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from bench_ik_held import run_geofik, run_ssik, score

import robokin
from robokin.kinematics.ik.self_motion_families import SELF_MOTION

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from reference import iiwa14_srs  # noqa: E402

IIWA_URDF = "xacro/kuka_description/kuka_lbr_iiwa/urdf/lbr_iiwa_14_r820.urdf"


def gen3_like() -> robokin.Robot:
    """Kinova Gen3 7-DoF from the classic DH table of its user guide (module docstring)."""
    d = [-0.2848, -0.0118, -0.4208, -0.0128, -0.3143, 0.0, -0.1674]
    lim = [180, 128.9, 180, 147.8, 180, 120.3, 180]
    rows = [{"a": 0.0, "alpha": np.pi if i == 6 else np.pi / 2, "d": d[i],
             "theta": 0.0 if i == 0 else np.pi, "limits": [-np.radians(lim[i]),
                                                         np.radians(lim[i])],
             "name": f"joint_{i + 1}"} for i in range(7)]
    return robokin.Robot.from_dh(rows, convention="standard", name="gen3_like")


def arms(slow: int) -> list[tuple[str, robokin.Robot, int | None]]:
    """(name, robot, poses or None for --poses) of the arms that can be built here."""
    out: list[tuple[str, robokin.Robot, int | None]] = [
        ("panda", robokin.load("panda"), None), ("iiwa14 SRS", iiwa14_srs(), None)]
    try:
        import rtbdata

        urdf = Path(rtbdata.__file__).parent / IIWA_URDF
        out.append(("iiwa14 URDF", robokin.Robot.from_urdf(str(urdf), geometry=False), slow))
    except ImportError:
        print("iiwa14 URDF: rtb-data not installed")
    out.append(("gen3-like", gen3_like(), slow))
    return out


#: The Gen3-like arm's DH theta offsets (ssik's from_dh has none: its q = ours + these).
GEN3_THETA = np.array([0.0] + [np.pi] * 6)


def ssik_arm(name: str, robot: robokin.Robot):
    """(ssik Manipulator, q offset ours -> ssik, base/tool correction X, build seconds)."""
    import ssik

    t0 = time.perf_counter()
    if name == "iiwa14 URDF":
        import rtbdata

        arm = ssik.Manipulator.from_urdf(str(Path(rtbdata.__file__).parent / IIWA_URDF))
        off = np.zeros(7)
    else:
        d = [-0.2848, -0.0118, -0.4208, -0.0128, -0.3143, 0.0, -0.1674]
        arm = ssik.Manipulator.from_dh([np.pi / 2] * 6 + [np.pi], [0.0] * 7, d,
                                       limits=robot.limits + GEN3_THETA[:, None])
        off = GEN3_THETA
    arm.prepare()  # the per-arm set-up (cached by ssik on disk where it has one)
    built = time.perf_counter() - t0
    q0 = np.array([0.1, -0.3, 0.2, -1.0, 0.3, 0.8, 0.7])
    X = np.linalg.inv(robot.fk(q0)) @ np.asarray(arm.fk(q0 + off))
    return arm, off, X, built


def run_ssik_peer(name, robot, q, T, repeat):
    """ssik on a non-Panda arm: its charts where it has them, else its solve(T) sample."""
    arm, off, X, built = ssik_arm(name, robot)
    TS = T @ X
    try:
        arm.self_motion(TS[0])
        charts = "charts available"
    except NotImplementedError as exc:
        charts = f"no charts ({str(exc).split('. ')[0]})"

    def solve_all():
        return [np.array([np.asarray(s.q, dtype=float) for s in arm.solve(t)]).reshape(-1, 7)
                for t in TS]

    rows = [r - off for r in solve_all()]
    wall, cpu = cpu_and_wall(solve_all, repeat)
    return rows, {"solver": arm.solver_name, "charts": charts, "setup": built,
                  "solve": (wall / len(T), cpu / len(T))}


def parameter_of(sm, q):
    if sm.joint is not None:
        return float(q[sm.joint])
    return float(sm._family.arm.swivel_of(sm._family.fr, q))


def cpu_and_wall(fn, repeat):
    """(best wall [s], best process CPU [s]) over repeat calls."""
    wall = cpu = np.inf
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        fn()
        wall, cpu = min(wall, time.perf_counter() - t0), min(cpu, time.process_time() - c0)
    return wall, cpu


def run_robokin(robot, q, T, repeat):
    sms = [robot.self_motion(t) for t in T]
    rows = [sm.sample(parameter_of(sm, qi)) for sm, qi in zip(sms, q, strict=True)]
    # every sampled row of every pose (64 values) for the wrong-row count
    grid = [sm.sample(np.linspace(*sm.domain, 64)).reshape(-1, 7) for sm in sms]
    whole = cpu_and_wall(lambda: [robot.self_motion(t) for t in T], repeat)
    t64 = [np.linspace(*sm.domain, 64) for sm in sms]
    per_value = cpu_and_wall(lambda: [sm.sample(t) for sm, t in zip(sms, t64, strict=True)],
                             repeat)
    return rows, grid, {"manifold": [x / len(T) for x in whole],
                        "per value": [x / (64 * len(T)) for x in per_value],
                        "method": sms[0].method}


def run_kernels(robot, T, repeat):
    """The SRS swivel kernels on the whole batch: rows at 64 angles, the manifolds."""
    arm = robot.arm.derived(SELF_MOTION).swivel
    psi = np.tile(np.linspace(-np.pi, np.pi, 64), (len(T), 1))
    rows = cpu_and_wall(lambda: arm.rows(T, psi), repeat)
    man = cpu_and_wall(lambda: arm.manifold(T), repeat)
    return [x / psi.size for x in rows], [x / len(T) for x in man]


def us(pair):
    return f"{pair[0] * 1e6:.1f} (CPU {pair[1] * 1e6:.1f})"


def main(n: int = 200, repeat: int = 3, seed: int = 0, slow: int = 5) -> None:
    rng = np.random.default_rng(seed)
    print(f"robokin {robokin.__version__}; poses per arm: {n} ({slow} on the held-joint "
          f"arms); best of {repeat}; times in us, wall (process CPU)")
    for name, robot, m in arms(slow):
        count = n if m is None else m
        if count == 0:  # --slow-poses 0: the held-joint arms left out
            continue
        q = rng.uniform(robot.limits[:, 0], robot.limits[:, 1], (count, 7))
        T = robot.fk(q)
        robot.self_motion(T[0])  # set-up (held-joint solvers, reduced chains)
        rows, grid, times = run_robokin(robot, q, T, repeat if m is None else 1)
        rec, _, _, _ = score(robot, q, T, rows)
        _, wrong, worst, total = score(robot, q, T, grid)
        print(f"{name:11s} robokin self_motion [{times['method']}]: recovered {rec}/{count}, "
              f"wrong {wrong} of {total} sampled rows (max error {worst:.1e}); whole "
              f"manifold {us(times['manifold'])} per pose, sample {us(times['per value'])}"
              " per (pose, value)")
        if name == "iiwa14 SRS":
            krows, kman = run_kernels(robot, T, repeat)
            print(f"{name:11s} kernels, one batch: swivel_rows {us(krows)} per (pose, value),"
                  f" swivel_manifold {us(kman)} per pose")
            qn = np.clip(q + 0.3, robot.limits[:, 0], robot.limits[:, 1])
            near = cpu_and_wall(lambda: robot.ik_near(T, qn, method="self_motion"), repeat)
            one = cpu_and_wall(lambda: [robot.ik_near(t, v, method="self_motion")
                                        for t, v in zip(T, qn, strict=True)], repeat)
            print(f"{name:11s} ik_near(method='self_motion'), q_near = q0 + 0.3: one batch "
                  f"{us([x / len(T) for x in near])}, one pose per call "
                  f"{us([x / len(T) for x in one])} per pose")
        if name in ("iiwa14 URDF", "gen3-like"):
            try:
                prow, info = run_ssik_peer(name, robot, q, T, 1)
            except ImportError as exc:
                print(f"{name:11s} ssik: not installed ({exc})")
            else:
                rec, wrong, worst, total = score(robot, q, T, prow)
                print(f"{name:11s} ssik [{info['solver']}, {info['charts']}; set-up "
                      f"{info['setup']:.1f} s]: solve(T) recovered {rec}/{count}, wrong {wrong} "
                      f"of {total} rows (max error {worst:.1e}); {us(info['solve'])} per pose")
            print(f"{name:11s} geofikpy: not applicable (its closed forms are the Panda's only)")
        if name != "panda":
            continue
        held_kernel_rows(robot, T, repeat)
        for peer, fn in (("ssik charts", run_ssik), ("geofikpy q7", run_geofik)):
            try:
                prow, ptimes = fn(robot, q, T, repeat)
            except ImportError as exc:
                print(f"{name:11s} {peer}: not installed ({exc})")
                continue
            rec, wrong, worst, total = score(robot, q, T, prow)
            what = "per pose (charts)" if peer.startswith("ssik") else "per (pose, value)"
            print(f"{name:11s} {peer}: recovered {rec}/{n}, wrong {wrong} of {total} rows "
                  f"(max error {worst:.1e}); {ptimes['call'] * 1e6:.1f} us {what}")


def held_kernel_rows(robot, T, repeat):
    """The Panda's compiled held-joint manifold (issue 29): bare kernel and solved points.

    Prints ``held_manifold`` on the whole batch (per pose, both cores for 8+ poses),
    and ``self_motion(..., reference=True)`` (the solved-points path, what
    ``robot.self_motion`` did before the kernel) on the same poses.
    """
    from robokin._native import kernels as K
    from robokin.kinematics.ik.dispatch import solve
    from robokin.kinematics.ik.self_motion import self_motion
    from robokin.kinematics.ik.self_motion_families import _family
    from robokin.kinematics.ik.self_motion_intervals import KERNEL_GRID, _aligned_values

    T = np.ascontiguousarray(T)
    N = len(T)
    params = _family(robot.arm, T[0], "auto", solve).params
    al = np.array(_aligned_values(robot.arm), dtype=np.float64).reshape(-1, 2)
    out = (np.empty((N, 8, K.HM_MAXI, 2)), np.zeros((N, 8), np.int64),
           np.empty((N, K.HM_MAXP, 4)), np.zeros(N, np.int64), np.zeros(N, np.int64),
           np.zeros(N, np.int64))
    grid = cpu_and_wall(lambda: K.held_manifold(params, T, al, KERNEL_GRID, *out,
                                                K.HM_MODE_GRID), repeat)
    kern = cpu_and_wall(lambda: K.held_manifold(params, T, al, KERNEL_GRID, *out,
                                                K.HM_MODE_AUTO), repeat)
    flagged, solves = int((out[4] != 0).sum()), float(out[5].mean())
    ref = cpu_and_wall(lambda: [self_motion(robot.arm, t, dispatch=solve, reference=True)
                                for t in T], 1)
    print(f"{'panda':11s} held_manifold kernel, one batch: {us([x / N for x in kern])} per pose "
          f"(closed forms, else the grid: {solves:.1f} pk_one solves per pose, {flagged} of {N} "
          f"flagged to the solved-points path); the grid alone {us([x / N for x in grid])}; "
          f"solved points (reference=True) {us([x / N for x in ref])}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--poses", type=int, default=200)
    ap.add_argument("--slow-poses", type=int, default=5)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()
    main(a.poses, a.repeat, a.seed, a.slow_poses)
