"""Numeric IK: robokin vs roboticstoolbox-python (C++), ikpy and pinocchio, in one run.

Run: ``python benchmarks/bench_ik_numeric.py [--n 1000] [--ikpy-n 100]`` (needs
``pip install -e '.[bench]'``).

For UR5, Panda and the 8-joint patent arm (``improved_dh_arm``), draws random
reachable targets (FK of random configurations inside the limits), then solves
each target one call at a time with every solver, from a fixed seed (the middle
of the limits) and from a random seed (a random configuration inside the limits,
the same for every solver). A solve counts as a success when FK of the answer is
within the tolerance of the target (position [m] and rotation angle [rad],
checked here, not taken from the solver) and inside the joint limits. Times are
wall-clock per call, Python overhead included. robokin gets a 10 ms budget per
target; rtb's ``ik_LM/ik_NR/ik_GN`` their default search limits (30 iterations x
100 searches) with the tolerance on their residual ``E = e^T e / 2`` set to match;
pinocchio runs the damped-least-squares loop of its documentation (ignores
limits); ikpy runs on ``--ikpy-n`` targets only (it takes tens of ms each).
Also prints robokin's batch throughput against its per-target loop.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

from peers import _constants, pinocchio_model, rtb_ets  # noqa: E402

import robokin  # noqa: E402
from robokin.kinematics.ik import numeric  # noqa: E402
from robokin.kinematics.ik.restart_seeds import middle  # noqa: E402

ROBOTS = ("ur5", "panda", "improved_dh_arm")
BUDGET = 1_000_000  # restarts: the 10 ms wall-time budget is what stops robokin


def pose_errors(T, Tt):
    """Position [m] and rotation angle [rad] between poses (..., 4, 4)."""
    dp = np.linalg.norm(T[..., :3, 3] - Tt[..., :3, 3], axis=-1)
    R = np.swapaxes(T[..., :3, :3], -1, -2) @ Tt[..., :3, :3]
    c = np.clip((np.trace(R, axis1=-2, axis2=-1) - 1) / 2, -1, 1)
    s = np.linalg.norm(
        np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0],
                  R[..., 1, 0] - R[..., 0, 1]], -1), axis=-1) / 2
    return dp, np.arctan2(s, c)


def run(fn, targets, seeds):
    """Call fn(T, q0) per target; returns (q (N, n), times (N,))."""
    qs, ts = [], []
    for T, q0 in zip(targets, seeds, strict=True):
        t = time.perf_counter()
        q = fn(T, q0)
        ts.append(time.perf_counter() - t)
        qs.append(q)
    return np.array(qs, dtype=float), np.array(ts)


def score(robot, q, times, targets, tol):
    ok = np.all(np.isfinite(q), axis=-1)
    qq = np.where(ok[:, None], q, 0.0)
    dp, dr = pose_errors(robot.fk(qq), targets)
    inside = robot.within_limits(qq, tol=1e-9)
    acc = ok & (dp <= tol) & (dr <= tol)
    return {
        "success": float(np.mean(acc & inside)),
        "accurate": float(np.mean(acc)),
        "inside": float(np.mean(inside[acc])) if acc.any() else float("nan"),
        "median_ms": float(np.median(times) * 1e3),
        "p95_ms": float(np.percentile(times, 95) * 1e3),
        "n": len(times),
    }


def _rpy(P):
    """Roll, pitch, yaw (ikpy's convention: R = Rz(yaw) Ry(pitch) Rx(roll))."""
    import warnings

    from scipy.spatial.transform import Rotation

    with warnings.catch_warnings():  # gimbal lock is exact here (third angle 0)
        warnings.simplefilter("ignore", UserWarning)
        return Rotation.from_matrix(P[:3, :3]).as_euler("xyz")


def ikpy_chain(robot):
    from ikpy.chain import Chain
    from ikpy.link import OriginLink, URDFLink

    placements, last = _constants(robot)
    links = [OriginLink()]
    for P, j in zip(placements, robot.chain.joints, strict=True):
        rpy = _rpy(P)
        axis = [0.0, 0.0, j.sign]
        kw = {"rotation": axis} if j.kind == "revolute" else {
            "translation": axis, "joint_type": "prismatic"}
        links.append(URDFLink(j.name, P[:3, 3], rpy, bounds=tuple(j.limits), **kw))
    rpy = _rpy(last)
    links.append(URDFLink("tool", last[:3, 3], rpy, joint_type="fixed"))
    mask = [False] + [True] * robot.n + [False]
    return Chain(links, active_links_mask=mask)


def check_models(robot, rng, m=20):
    """The peers' FK must match robokin's to 1e-9 before anything is timed."""
    import pinocchio as pin

    box = np.clip(robot.limits, -np.pi, np.pi)
    Q = rng.uniform(box[:, 0], box[:, 1], (m, robot.n))
    ours = robot.fk(Q)
    ets = rtb_ets(robot)
    model, data, fid = pinocchio_model(robot)
    chain = ikpy_chain(robot)
    worst = {"rtb": 0.0, "pinocchio": 0.0, "ikpy": 0.0}
    for q, T in zip(Q, ours, strict=True):
        worst["rtb"] = max(worst["rtb"], np.abs(ets.fkine(q).A - T).max())
        pin.forwardKinematics(model, data, q)
        Tp = pin.updateFramePlacement(model, data, fid).homogeneous
        worst["pinocchio"] = max(worst["pinocchio"], np.abs(Tp - T).max())
        Ti = chain.forward_kinematics(np.concatenate([[0.0], q, [0.0]]))
        worst["ikpy"] = max(worst["ikpy"], np.abs(Ti - T).max())
    bad = {k: v for k, v in worst.items() if v > 1e-9}
    if bad:
        raise SystemExit(f"{robot.name}: peer FK disagrees with robokin: {bad}")


def solvers(robot, tol):
    """name -> fn(T, q0) returning q (n,) or NaNs."""
    import pinocchio as pin

    n = robot.n
    nan = np.full(n, np.nan)
    out = {}

    def rk(T, q0, _tol=tol):
        r = numeric.solve(robot, T, q0=q0, tol=_tol, max_time=0.01, max_restarts=BUDGET)
        return r.q if r.success else nan

    out["robokin"] = rk

    ets = rtb_ets(robot)
    ets.qlim = robot.limits.T.copy()
    e_tol = 0.5 * tol**2
    for meth in ("ik_LM", "ik_NR", "ik_GN"):
        f = getattr(ets, meth)

        def rtb(T, q0, _f=f):
            sol = _f(T, q0=q0, tol=e_tol, joint_limits=True)
            return np.asarray(sol.q) if sol.success else nan

        out[f"rtb {meth}"] = rtb

    model, data, fid = pinocchio_model(robot)

    def pin_dls(T, q0, eps=tol, it_max=1000, dt=1e-1, damp=1e-12):
        # the damped-least-squares loop of pinocchio's documentation (frame version)
        oMdes = pin.SE3(T[:3, :3].copy(), T[:3, 3].copy())
        q = q0.copy()
        for _ in range(it_max):
            pin.forwardKinematics(model, data, q)
            pin.updateFramePlacement(model, data, fid)
            iMd = data.oMf[fid].actInv(oMdes)
            err = pin.log(iMd).vector
            if np.linalg.norm(err) < eps:
                return q
            J = pin.computeFrameJacobian(model, data, q, fid)
            J = -pin.Jlog6(iMd.inverse()) @ J
            v = -J.T @ np.linalg.solve(J @ J.T + damp * np.eye(6), err)
            q = pin.integrate(model, q, v * dt)
        return nan

    out["pinocchio DLS"] = pin_dls

    try:
        chain = ikpy_chain(robot)

        def ikpy_fn(T, q0):
            q = chain.inverse_kinematics_frame(
                T, initial_position=np.concatenate([[0.0], q0, [0.0]]),
                orientation_mode="all")
            return np.asarray(q[1:-1])

        out["ikpy"] = ikpy_fn
    except Exception as exc:  # noqa: BLE001  (a peer that cannot model the arm)
        print(f"  ikpy unavailable for {robot.name}: {exc}")
    return out


def one_thread_kernels(robot, targets, q0) -> dict:
    """Per-target time of a one-thread batch in each copy of the compiled kernel
    this CPU runs: the AVX2 + FMA copy (when it runs here) and the baseline copy."""
    from robokin._native import _base, kernels

    copies = {kernels.ISA: kernels}
    copies.setdefault(_base.ISA, _base)
    threads = kernels.num_threads()
    times = {}
    try:
        for isa, mod in copies.items():
            numeric.K = mod
            mod.set_num_threads(1)
            numeric.solve(robot, targets, q0=q0, parallel=False)
            best = np.inf
            for _ in range(5):
                t = time.perf_counter()
                numeric.solve(robot, targets, q0=q0, parallel=False,
                              rng=np.random.default_rng(1))
                best = min(best, time.perf_counter() - t)
            times[isa] = best * 1e6 / len(targets)
    finally:
        numeric.K = kernels
        for mod in copies.values():
            mod.set_num_threads(threads)
    return times


def near_limits(runs: int = 5, n: int = 2000) -> None:
    """Issue 20: Panda targets with joints 4 and 6 within 0.05 rad of a limit (the
    others anywhere in theirs); success per run with fresh random restarts."""
    robot = robokin.load("panda")
    lim = robot.limits
    rates, median_us = [], []
    for run in range(runs):
        rng = np.random.default_rng(run)
        q = rng.uniform(lim[:, 0], lim[:, 1], (n, 7))
        q[:, 3] = lim[3, 0] + rng.uniform(0, 0.05, n)
        q[:, 5] = lim[5, 1] - rng.uniform(0, 0.05, n)
        T = robot.fk(q)
        res = numeric.solve(robot, T, rng=np.random.default_rng(run + 100))
        rates.append(res.success.mean())
        times = []
        for i in range(200):
            t = time.perf_counter()
            numeric.solve(robot, T[i], rng=np.random.default_rng(i))
            times.append(time.perf_counter() - t)
        median_us.append(np.median(times) * 1e6)
    print(f"\nPanda near its joint limits ({n} targets x {runs} runs): success "
          + ", ".join(f"{100 * r:.2f} %" for r in rates)
          + f"; single-solve median {min(median_us):.1f}-{max(median_us):.1f} us")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1000, help="targets per robot")
    ap.add_argument("--ikpy-n", type=int, default=100, help="targets for ikpy")
    ap.add_argument("--tol", type=float, default=1e-6, help="tolerance [m, rad]")
    ap.add_argument("--robots", default=",".join(ROBOTS))
    args = ap.parse_args()
    rng = np.random.default_rng(2024)
    rows = []
    batch_rows = []
    kernel_rows = []
    for name in args.robots.split(","):
        robot = robokin.load(name)
        lim = robot.limits
        box = np.clip(lim, -np.pi, np.pi)
        Q = rng.uniform(box[:, 0], box[:, 1], (args.n, robot.n))
        targets = robot.fk(Q)
        fixed = np.tile(middle(robot.chain), (args.n, 1))
        rand = rng.uniform(box[:, 0], box[:, 1], (args.n, robot.n))
        check_models(robot, rng)
        fns = solvers(robot, args.tol)
        # warm the compiled kernels and the peers
        for f in fns.values():
            f(targets[0], fixed[0])
        numeric.solve(robot, targets[:200])  # the batch (parallel) kernel too
        for seed_name, seeds in (("fixed", fixed), ("random", rand)):
            for sname, f in fns.items():
                m = args.ikpy_n if sname == "ikpy" else args.n
                q, t = run(f, targets[:m], seeds[:m])
                rows.append((name, seed_name, sname, score(robot, q, t, targets[:m],
                                                             args.tol)))
            # robokin at the strict 1e-9 as well
            def strict(T, q0, _robot=robot):
                r = numeric.solve(_robot, T, q0=q0, tol=1e-9, max_time=0.01,
                                  max_restarts=BUDGET)
                return r.q if r.success else np.full(_robot.n, np.nan)

            q, t = run(strict, targets, seeds)
            rows.append((name, seed_name, "robokin @1e-9", score(robot, q, t, targets,
                                                                 1e-9)))
        # batch vs per-target loop (strict tolerance, fixed seed), best of 7 each; the
        # full pose and position only (a workspace sweep)
        for mask in (None, "xyz"):
            t_batch = t_loop = np.inf
            for _ in range(7):
                t = time.perf_counter()
                res = numeric.solve(robot, targets, q0=fixed, mask=mask, tol=1e-9,
                                    max_time=0.01, max_restarts=BUDGET)
                t_batch = min(t_batch, time.perf_counter() - t)
                t = time.perf_counter()
                for i in range(args.n):
                    numeric.solve(robot, targets[i], q0=fixed[i], mask=mask, tol=1e-9,
                                  max_time=0.01, max_restarts=BUDGET)
                t_loop = min(t_loop, time.perf_counter() - t)
            batch_rows.append((name, mask or "pose", res.success.mean(), t_batch, t_loop))
        kernel_rows.append((name, one_thread_kernels(robot, targets, fixed)))

    print(f"\n{args.n} random reachable targets per robot (ikpy: {args.ikpy_n}); "
          f"success = FK within {args.tol:g} m / {args.tol:g} rad and inside the limits")
    hdr = (f"{'robot':16s} {'seed':7s} {'solver':14s} {'success':>8s} {'accurate':>9s} "
           f"{'in lim':>7s} {'median ms':>10s} {'p95 ms':>8s} {'vs rtb LM':>10s}")
    print(hdr)
    print("-" * len(hdr))
    ref = {(r[0], r[1]): r[3]["median_ms"] for r in rows if r[2] == "rtb ik_LM"}
    for name, seed, solver, s in rows:
        ratio = s["median_ms"] / ref[(name, seed)]
        print(f"{name:16s} {seed:7s} {solver:14s} {100 * s['success']:7.1f}% "
              f"{100 * s['accurate']:8.1f}% {100 * s['inside']:6.1f}% "
              f"{s['median_ms']:10.3f} {s['p95_ms']:8.3f} {ratio:9.2f}x")
    print("\nrobokin batch (one call, all targets) vs a per-target loop, tol 1e-9:")
    for name, task, succ, tb, tl in batch_rows:
        print(f"  {name:16s} {task:4s} success {100 * succ:5.1f}%  batch "
              f"{tb * 1e6 / args.n:7.1f} "
              f"us/target  loop {tl * 1e6 / args.n:7.1f} us/target  speed-up "
              f"{tl / tb:4.1f}x")
    near_limits()
    print("\nrobokin batch on one thread, by copy of the kernel (us/target, best of 5):")
    for name, times in kernel_rows:
        print(f"  {name:16s} " + "  ".join(f"{k} {v:6.2f}" for k, v in times.items()))


if __name__ == "__main__":
    main()
