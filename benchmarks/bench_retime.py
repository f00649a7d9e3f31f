"""Time-optimal retiming: robokin's ``trajectory.retime`` vs ``toppra`` used directly.

Run: ``python benchmarks/bench_retime.py`` (needs ``pip install -e '.[retime,collision]'``).

For each path both compute the shortest time along the same geometric path under
the same joint speed and acceleration limits:

* **robokin**: ``trajectory.retime_detailed(robot, traj, v_max=, a_max=)``;
* **toppra directly**, the way its documentation uses it: the path cut at the
  source's stops (samples where every joint speed is below 1e-9 of the largest;
  dwells keep their duration), each stretch a ``toppra.SplineInterpolator``
  through its samples in the chord-length parameter (toppra's time parameterisation of these paths fails as
  "not controllable": the speed at rest is unbounded), ``JointVelocityConstraint``
  and ``JointAccelerationConstraint``, ``TOPPRA(..., solver_wrapper="seidel")``,
  ``compute_trajectory(0, 0)``; on toppra's own grid (``propose_gridpoints``) and on
  a fine one (4,000 intervals per stretch).

Paths: the demo's press loading (AUBO-i5, its robot-file limits and the demo's
caps), 20 random via-point paths (UR5: blended joint via points, a Cartesian line
down and up with a dwell, random limits), and a single-joint rest-to-rest move
against its closed form. Printed per path: both cycle times and their difference
(target: within 1 %), the worst limit excess on any sample of each (robokin's
target: below 1e-6 relative; toppra's is sampled every 5 ms from its output), the
line deviation (target 1e-6 m), and, for the demo, the collision check of the
retimed motion.
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


def stretches(traj):
    """(first, last, kind) per rest-to-rest stretch and dwell of a trajectory."""
    speed = np.abs(traj.qd).max(axis=1)
    still = np.linalg.norm(np.diff(traj.q, axis=0), axis=1) == 0
    rest = speed <= 1e-9 * speed.max()  # a quintic's end speed is ~1e-17, not 0
    stop = np.flatnonzero(rest | np.concatenate([[True], still])
                          | np.concatenate([still, [True]]))
    stop = np.union1d(stop, [0, len(traj.t) - 1])
    out = []
    for a, b in zip(stop[:-1], stop[1:]):
        out.append((a, b, "dwell" if still[a:b].all() else "move"))
    return out


def toppra_reference(traj, v, a, n_grid=None, dt=0.005):
    """toppra used directly: total time, its worst sampled limit excess, run time."""
    import toppra
    import toppra.algorithm as ta
    import toppra.constraint as tc

    total, excess, t0 = 0.0, 0.0, time.perf_counter()
    for first, last, kind in stretches(traj):
        if kind == "dwell":
            total += traj.t[last] - traj.t[first]
            continue
        q = traj.q[first:last + 1]
        step = np.linalg.norm(np.diff(q, axis=0), axis=1)
        keep = np.concatenate([[True], step > 0])
        ss = np.concatenate([[0.0], np.cumsum(step)])[keep]
        path = toppra.SplineInterpolator(ss, q[keep])
        grid = None if n_grid is None else np.linspace(0, ss[-1], n_grid + 1)
        algo = ta.TOPPRA([tc.JointVelocityConstraint(v),
                          tc.JointAccelerationConstraint(a)], path, gridpoints=grid,
                         solver_wrapper="seidel", parametrizer="ParametrizeConstAccel")
        out = algo.compute_trajectory(0, 0)
        if out is None:
            raise RuntimeError(f"toppra failed: {algo.problem_data.return_code}")
        total += out.duration
        ts = np.linspace(0, out.duration, max(2, int(out.duration / dt) + 1))
        excess = max(excess, float((np.abs(out(ts, 1)) / v).max() - 1),
                     float((np.abs(out(ts, 2)) / a).max() - 1))
    return total, excess, time.perf_counter() - t0


def robokin_retime(robot, traj, v, a):
    t0 = time.perf_counter()
    res = trajectory.retime_detailed(robot, traj, v_max=v, a_max=a)
    run = time.perf_counter() - t0
    out = res.trajectory
    excess = max(float((np.abs(out.qd) / v).max() - 1),
                 float((np.abs(out.qdd) / a).max() - 1))
    return res, excess, run


def line_deviation(res, traj, labels=None):
    """Largest distance [m] of the tool from the source's straight lines."""
    worst = 0.0
    out = res.trajectory
    for s in res.sections:
        if s.kind != "move":
            continue
        i0 = int(np.argmin(np.abs(traj.t - s.source_start)))
        i1 = int(np.argmin(np.abs(traj.t - s.source_end)))
        if labels is not None and s.label not in labels:
            continue
        src = traj.pose[i0:i1 + 1, :3, 3]
        a, b = src[0], src[-1]
        u = (b - a) / np.linalg.norm(b - a)
        d0 = src - a
        if np.linalg.norm(d0 - np.outer(d0 @ u, u), axis=1).max() > 1e-9:
            continue  # not a straight line in the source
        inside = (out.t >= s.t_start) & (out.t <= s.t_end)
        d = out.pose[inside, :3, 3] - a
        worst = max(worst, float(np.linalg.norm(d - np.outer(d @ u, u), axis=1).max()))
    return worst


def random_path(robot, rng):
    q0 = np.radians([0, -70, 90, -20, 90, 0]) + rng.uniform(-0.2, 0.2, 6)
    pb = trajectory.PathBuilder(robot, q0, dt=0.005, v_max=1.0, a_max=2.0)
    for _ in range(rng.integers(2, 5)):
        pb.joint(q0 + rng.uniform(-0.6, 0.6, 6))
    T = robot.fk(pb.q_end)
    pb.line(trans(0, 0, -0.08) @ T, duration=1.0)
    pb.dwell(0.3)
    pb.line(T, duration=1.0)
    pb.joint(q0)
    return pb.build()


def row(name, ours, ref, fine, extra=""):
    """One table row; returns robokin's difference to the fine reference and its
    worst excess."""
    res, exc, run = ours
    T, rexc, rrun = ref
    Tf, _, frun = fine
    rel = (res.duration - Tf) / Tf
    print(f"| {name} | {res.duration:.4f} s ({run * 1e3:.0f} ms) | {T:.4f} s "
          f"({rrun * 1e3:.0f} ms) | {Tf:.4f} s ({frun * 1e3:.0f} ms) | "
          f"{(res.duration - T) / T:+.3%} / {rel:+.3%} | "
          f"{max(exc, 0):.1e} | {max(rexc, 0):.1e} |{extra}")
    return rel, exc


def main() -> None:
    from robokin import collision
    from robokin.cli.demo import A_MAX, V_MAX, plan_press_loading

    print("| path | robokin | toppra, its grid | toppra, 4,000 intervals | robokin vs "
          "toppra / vs fine | robokin worst excess | toppra worst excess |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    scene = collision.Scene.load(collision.scene_path("press"))
    bare = robokin.load("aubo_i5")
    robot = scene.attach(bare)
    traj, _ = plan_press_loading(robot, scene)
    lim = robot.rate_limits
    lines = ("approach the part", "lift the part", "enter the press", "retract")
    for name, v, a in (("demo, AUBO-i5 robot-file limits", lim.velocity,
                        lim.acceleration),
                       ("demo, the demo's caps", np.full(6, V_MAX), np.full(6, A_MAX))):
        ours = robokin_retime(robot, traj, v, a)
        row(name, ours, toppra_reference(traj, v, a), toppra_reference(traj, v, a, 4000))
        rep = collision.check(bare, scene, ours[0].trajectory, clearance=0.004)
        print(f"|   ({name}: planned {traj.duration:.1f} s; lines within "
              f"{line_deviation(ours[0], traj, lines):.1e} m; retimed motion "
              f"{'collides' if rep.collides else 'collision-free'}, "
              f"{rep.min_distance * 1e3:.1f} mm) | | | | | | |")
    ur5 = robokin.load("ur5")
    rng = np.random.default_rng(2026)
    rels, excs, devs, stretch = [], [], [], []
    for k in range(20):
        tr = random_path(ur5, rng)
        v = rng.uniform(1.0, 3.0, 6)
        a = rng.uniform(2.0, 12.0, 6)
        ours = robokin_retime(ur5, tr, v, a)
        rel, exc = row(f"random via path {k + 1}", ours, toppra_reference(tr, v, a),
                       toppra_reference(tr, v, a, 4000))
        rels.append(rel)
        excs.append(exc)
        devs.append(line_deviation(ours[0], tr))
        stretch.append(max(s.stretch for s in ours[0].sections) - 1)
    print(f"\nrandom paths: robokin vs fine toppra {min(rels):+.3%} .. {max(rels):+.3%};"
          f" worst limit excess {max(max(excs), 0):.1e}; lines within {max(devs):.1e} m;"
          f" final-check slow-down 0 .. {max(stretch):.1e}")
    q0 = np.radians([0, -70, 90, -20, 90, 0])
    D, v1, a1 = 1.3, 1.1, 2.3
    tr = trajectory.quintic(q0, q0 + np.array([0, 0, D, 0, 0, 0]), 2.0)
    res = trajectory.retime_detailed(ur5, tr, v_max=v1, a_max=a1)
    closed = D / v1 + v1 / a1
    ref = toppra_reference(tr, np.full(6, v1), np.full(6, a1))[0]
    fine = toppra_reference(tr, np.full(6, v1), np.full(6, a1), 4000)[0]
    print(f"single joint, D {D} rad, v {v1} rad/s, a {a1} rad/s^2: closed form "
          f"{closed:.9f} s; robokin {res.duration:.9f} s ({res.duration - closed:+.1e});"
          f" toppra {ref:.9f} s ({ref - closed:+.1e}), fine {fine:.9f} s "
          f"({fine - closed:+.1e})")


if __name__ == "__main__":
    main()
