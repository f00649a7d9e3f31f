"""Trajectory sampling: robokin vs roboticstoolbox-python, in one run.

Run: ``python benchmarks/bench_trajectory.py`` (roboticstoolbox is optional:
``pip install -e '.[bench]'``). Times (best of 5, warm):

* a 6-segment joint path through via points for a 6-axis arm (AUBO-i5), 25 s at
  5 ms = 5,001 samples, smooth (C2) quintic blends — the target is well under
  a second; roboticstoolbox's ``jtraj`` per segment (rest-to-rest quintics, no
  blending) and ``mstraj`` (linear segments with parabolic blends) for scale;
* a Cartesian straight line of 1,000 samples: robokin's path-following IK
  (``ik="follow"``), nearest closed-form solution (``ik="analytic"``), the
  compiled numeric ``ik_path`` (``ik="numeric"``), and roboticstoolbox's
  ``ctraj`` + ``ikine_LM`` warm-started per sample;
* the press-loading style path (joint via points, two Cartesian lines, dwells).

Also checks what it times: junction continuity and the line deviation.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

import robokin  # noqa: E402
from robokin import trajectory  # noqa: E402
from robokin.spatial import trans  # noqa: E402


def _best(fn, repeats=5):
    best, out = np.inf, None
    for _ in range(repeats):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def _line_dev(robot, q, p0, p1):
    P = robot.fk(q)[:, :3, 3]
    u = (p1 - p0) / np.linalg.norm(p1 - p0)
    d = P - p0
    return float(np.linalg.norm(d - (d @ u)[:, None] * u, axis=1).max())


def main() -> None:
    robot = robokin.load("aubo_i5")
    rng = np.random.default_rng(0)
    q_home = np.radians([0, 10, 80, 0, 90, 0])
    vias = q_home + rng.uniform(-0.6, 0.6, (6, 6))
    durations = [4.0, 4.0, 4.0, 4.0, 4.5, 4.5]
    rows = []

    def joint_path():
        pb = trajectory.PathBuilder(robot, q_home, dt=0.005)
        for q, d in zip(vias, durations):
            pb.joint(q, duration=d)
        return pb.build()

    t_rk, tr = _best(joint_path)
    rows.append(("6-segment joint path, C2 blends", len(tr), t_rk))
    peers = {}
    try:
        import roboticstoolbox as rtb

        def rtb_jtraj():
            pts = np.vstack([q_home, vias])
            parts = [rtb.jtraj(a, b, int(round(d / 0.005)) + 1).q
                     for a, b, d in zip(pts[:-1], pts[1:], durations)]
            return np.vstack([parts[0]] + [p[1:] for p in parts[1:]])

        def rtb_mstraj():
            return rtb.mstraj(vias, dt=0.005, tacc=0.5, q0=q_home,
                              tsegment=durations).q

        peers["rtb jtraj x6 (rest-to-rest)"] = _best(rtb_jtraj)
        peers["rtb mstraj (LSPB blends)"] = _best(rtb_mstraj)
    except ImportError:
        rtb = None
    for name, (t, q) in peers.items():
        rows.append((name, len(q), t))

    q0 = np.array([0.1, 0.5, 1.2, 0.4, 1.3, 0.6])
    T0 = robot.fk(q0)
    T1 = trans(0.15, 0.1, -0.2) @ T0
    line_rows = []
    for ik in ("follow", "analytic", "numeric"):
        t, ln = _best(lambda ik=ik: trajectory.cartesian_line(robot, q0, T1, 4.995,
                                                               ik=ik), repeats=3)
        dev = _line_dev(robot, ln.q, T0[:3, 3], T1[:3, 3])
        line_rows.append((f"Cartesian line, ik={ik!r}", len(ln), t, dev))
    if rtb is not None:
        from peers import rtb_ets
        from spatialmath import SE3

        ets = rtb_ets(robot)

        def rtb_line():
            Ts = rtb.ctraj(SE3(T0, check=False), SE3(T1, check=False), len(ln))
            q = q0
            out = []
            for T in Ts:
                sol = ets.ik_LM(T.A, q0=q, tol=1e-12)
                q = sol[0]
                out.append(q)
            return np.array(out)

        try:
            t, q = _best(rtb_line, repeats=1)
            line_rows.append(("rtb ctraj + ik_LM per sample", len(q), t,
                              _line_dev(robot, q, T0[:3, 3], T1[:3, 3])))
        except Exception as exc:  # a peer API drift must not hide our numbers
            print(f"(rtb line skipped: {type(exc).__name__}: {exc})")

    def press():
        pb = trajectory.PathBuilder(robot, q_home, dt=0.005, v_max=1.5, a_max=3.0)
        q_above = np.radians([-40, 20, 90, -20, 90, 0])
        pb.joint(q_above)
        Ta = robot.fk(q_above)
        pb.line(trans(0, 0, -0.1) @ Ta, duration=1.0)
        pb.dwell(0.5)
        pb.line(Ta, duration=1.0)
        pb.joint(np.radians([20, 15, 85, -10, 90, 30]))
        pb.joint(np.radians([50, 10, 70, 0, 90, 40]))
        Tf = robot.fk(np.radians([60, 10, 70, 0, 90, 40]))
        pb.pose(Tf)
        c, s = np.cos(np.radians(60)), np.sin(np.radians(60))
        pb.line(trans(0.12 * c, 0.12 * s, 0) @ Tf, duration=1.5)
        pb.dwell(1.0)
        pb.line(Tf, duration=1.5)
        pb.joint(q_home)
        return pb.build()

    t_press, trp = _best(press, repeats=3)

    def jumps(tr, arr):
        out = []
        for v in tr.via_times[1:-1]:
            i = int(np.argmin(np.abs(tr.t - v)))
            left = 3 * arr[i - 1] - 3 * arr[i - 2] + arr[i - 3]
            right = 3 * arr[i + 1] - 3 * arr[i + 2] + arr[i + 3]
            out.append(np.abs(left - right).max())
        return max(out)

    print(f"{'task':44s} {'samples':>8s} {'time [ms]':>10s}  notes")
    for name, m, t in rows:
        print(f"{name:44s} {m:8d} {t * 1e3:10.2f}")
    print(f"  joint path junction jumps: velocity {jumps(tr, tr.qd):.1e} rad/s, "
          f"acceleration {jumps(tr, tr.qdd):.1e} rad/s^2 (O(dt^3) extrapolation)")
    for name, m, t, dev in line_rows:
        print(f"{name:44s} {m:8d} {t * 1e3:10.2f}  max off-line {dev:.1e} m")
    print(f"{'press-loading path (6 joint, 4 lines, 2 dwells)':44s} {len(trp):8d} "
          f"{t_press * 1e3:10.2f}  vel/acc junction jumps {jumps(trp, trp.qd):.1e} / "
          f"{jumps(trp, trp.qdd):.1e}")


if __name__ == "__main__":
    main()
