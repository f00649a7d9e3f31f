"""Process paths over every IK branch (issue 27): ``robokin.process`` vs what users do today.

Run: ``python benchmarks/bench_process.py [--runs 5] [--quick]`` (needs
``roboticstoolbox-python`` for the ``ikine_LM`` peer; skipped without it).

Four tool paths, built here, on the UR5 and the AUBO-i5 (the same paths in each
arm's frame, around a comfortable configuration of it):

* **seam**: a fillet seam round the inside of a 240 x 160 mm tray, the torch
  tilted 30 deg into the wall and its x axis along the seam, so the tool turns
  90 deg about the vertical at each corner (in place, 5 deg a waypoint); 5 mm
  spacing. Four corners turn the tool a whole turn: tracked naively the wrist
  runs into a limit or flips.
* **circle**: a glue bead, a 100 mm circle in a plane tilted 30 deg, the nozzle
  normal to the plane, 2.5 deg spacing.
* **spline**: a deburring spline generated in joint space so that it passes
  the wrist singularity (q5 = 0) on the nominal orientation, with a deburring
  tool whose axis is 90 deg off the flange axis; the free axis lets the tool
  turn away from the singularity.
* **holes**: 60 unordered holes on a curved panel in front of the arm (the drill
  may turn about its axis).

Methods, on each path:

* **naive**: the IK solution nearest the previous configuration at every
  waypoint (``robot.ik(T).nearest(q)``, inside the limits), from the solution
  nearest a home configuration;
* **ikine_LM**: roboticstoolbox's ``Robot.ikine_LM`` seeded with the previous
  waypoint (its defaults: tol 1e-6, joint limits on; ``seed=0``), the model built
  from the same chain (``peers.rtb_ets``; FK checked to agree to 1e-9);
* **follow**: ``robokin.process.follow`` with the fixed orientation, and with the
  tool free about z (+-90 deg at 5 deg), ``max_step`` 0.2 rad;
* holes only: **order**: ``robokin.process.order`` (the visit order chosen, the
  drill fixed), against the holes in the given order (naive, ikine_LM, follow).

Reported: feasible (every waypoint reached to 1e-6 m and 1e-6 rad, inside the
limits, every step at most ``max_step``; order: every hole reached), the largest
joint step [rad], the joint travel (sum of the per-step largest joint change)
[rad], the worst pose error [m] and the time [ms] (best of the runs).

Throughput: ``follow`` on a 5,000-waypoint circle on each arm, fixed orientation
and free axis every 5 deg over +-90 deg (37 rotations: 185,000 sampled poses),
``--runs`` times: wall-clock waypoints/s (min-max over the runs) and the same
per CPU-second of this process (the machine is shared; two CPU-seconds per
wall second is what two free cores give), with the load average at the time.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import robokin  # noqa: E402
from process.paths import panel_holes  # noqa: E402  (the tests' panel of holes)
from robokin import process  # noqa: E402
from robokin.spatial import rotx, roty, rotz, trans  # noqa: E402

#: The home configuration the paths are built around [rad] (both arms).
Q0 = np.array([0.3, -1.2, 1.5, -1.9, -1.4, 0.2])
MAX_STEP = 0.2
FREE = {"free_axis": "z", "free_range": (-math.pi / 2, math.pi / 2),
        "free_step": math.radians(5.0)}


# ------------------------------------------------------------------------ paths


def _frame(x, z, p):
    """A pose with tool x along ``x``, z along ``z`` (made orthogonal), at p."""
    z = z / np.linalg.norm(z)
    x = x - z * (x @ z)
    x = x / np.linalg.norm(x)
    T = np.eye(4)
    T[:3, :3] = np.stack([x, np.cross(z, x), z], axis=1)
    T[:3, 3] = p
    return T


#: Where the tray's floor centre is, in each arm's base frame [m].
TRAY = np.array([0.40, -0.10, 0.10])


def seam(robot, spacing=0.005, corner_deg=5.0):
    """The fillet seam round the inside of a 240 x 160 mm tray (clockwise seen from
    above), the torch tilted 30 deg into the wall; turning in place at corners."""
    c = TRAY
    corner_step = math.radians(corner_deg)
    hx, hy = 0.12, 0.08
    corners = c + np.array([[-hx, hy, 0], [hx, hy, 0], [hx, -hy, 0], [-hx, -hy, 0]])
    out = []
    for k in range(4):
        a, b = corners[k], corners[(k + 1) % 4]
        d = (b - a) / np.linalg.norm(b - a)
        wall = np.cross(d, [0.0, 0.0, 1.0])  # outward: the wall on the right
        z = -np.array([0.0, 0.0, 1.0]) + math.tan(math.radians(30.0)) * wall
        m = int(round(np.linalg.norm(b - a) / spacing))
        for s in np.linspace(0.0, 1.0, m, endpoint=False):
            out.append(_frame(d, z, a + s * (b - a)))
        # turn in place at corner b towards the next side (-90 deg about z)
        T = _frame(d, z, b)
        turns = int(round(math.pi / 2 / corner_step))
        for t in range(1, turns):
            out.append(_turn_about_vertical(T, b, -t * corner_step))
    return np.array(out)


def _turn_about_vertical(T, p, angle):
    """T turned by ``angle`` about the world vertical through p."""
    R = rotz(angle)
    out = T.copy()
    out[:3, :3] = R[:3, :3] @ T[:3, :3]
    out[:3, 3] = p + R[:3, :3] @ (T[:3, 3] - p)
    return out


def circle(robot, n=144, radius=0.1, tilt_deg=30.0):
    """A glue circle in a plane tilted by ``tilt_deg`` about x, nozzle normal to it."""
    tilt = math.radians(tilt_deg)
    T0 = robot.fk(Q0)
    s = np.linspace(0.0, 2.0 * np.pi, n)
    plane = T0 @ rotx(tilt)
    return plane @ trans(radius * np.cos(s) - radius, radius * np.sin(s), 0.0) @ rotx(-tilt)


#: The deburring tool: 120 mm out, its axis 90 deg off the flange axis.
DEBURR_TOOL = trans(0.0, 0.0, 0.12) @ roty(math.pi / 2)


def spline(robot, n=201):
    """A joint-space spline through the wrist singularity (q5 = 0 at its middle
    waypoint, exactly), as tool poses."""
    s = np.linspace(0.0, 1.0, n)[:, None]
    qa = Q0 + np.array([-0.3, 0.1, -0.2, 0.3, 1.4 - 0.5, -0.4])  # q5 = -0.5
    qb = Q0 + np.array([0.35, -0.1, 0.25, -0.2, 1.4 + 0.5, 0.5])  # q5 = +0.5
    bow = np.array([0.1, 0.15, -0.1, 0.2, 0.0, 0.3])
    q = qa + s * (qb - qa) + 4.0 * s * (1.0 - s) * bow
    return robot.fk(q)


def holes(robot, count=60, seed=7):
    """``count`` hole poses on a curved panel in front of the arm (drill z into it):
    the panel of the process tests (``tests/process/paths.py``)."""
    return panel_holes(robot.name, count, seed)


def paths(robot):
    """name -> (the robot to use, its poses)."""
    deburr = robot.with_tool(DEBURR_TOOL)
    return {"seam": (robot, seam(robot)), "circle": (robot, circle(robot)),
            "spline": (deburr, spline(deburr)), "holes": (robot, holes(robot))}


# ---------------------------------------------------------------------- methods


def naive(robot, poses):
    """Nearest solution inside the limits at every waypoint, from the home one."""
    q = Q0
    out = []
    for T in poses:
        sols = robot.ik(T).keep_within_limits()
        if sols.count == 0:
            out.append(np.full(robot.n, np.nan))
            continue
        q = sols.nearest(q)
        out.append(q)
    return np.array(out)


def rtb_model(robot):
    """roboticstoolbox's Robot of the same chain (tool included), with limits."""
    import roboticstoolbox as rtb
    from peers import rtb_ets

    ets = rtb_ets(robot)
    ets.qlim = robot.limits.T
    model = rtb.Robot(ets)
    q = np.random.default_rng(0).uniform(-1, 1, (5, robot.n))
    for qi in q:
        assert np.allclose(model.fkine(qi).A, robot.fk(qi), atol=1e-9)
    return model


def ikine_lm(model, robot, poses):
    """ikine_LM seeded with the previous waypoint (from the home configuration)."""
    q = Q0
    out = []
    for T in poses:
        sol = model.ikine_LM(T, q0=q, seed=0)
        if sol.success:
            q = np.asarray(sol.q, dtype=float)
            out.append(q)
        else:
            out.append(np.full(robot.n, np.nan))
    return np.array(out)


def measure(robot, poses, q, tool_poses=None, max_step=MAX_STEP):
    """Feasibility, largest step, travel and worst pose error of a motion q."""
    expected = poses if tool_poses is None else tool_poses
    ok = np.isfinite(q).all(axis=1)
    err = np.full(q.shape[0], np.inf)
    if ok.any():
        T = robot.fk(q[ok])
        pos = np.linalg.norm(T[:, :3, 3] - expected[ok, :3, 3], axis=1)
        rot = np.abs(T[:, :3, :3] - expected[ok, :3, :3]).max(axis=(1, 2))
        err[ok] = np.maximum(pos, rot)
    steps = np.abs(np.diff(q, axis=0)).max(axis=1)
    inside = ok.all() and bool(robot.within_limits(q[ok], tol=1e-9).all())
    feasible = bool(ok.all() and inside and (err <= 1e-6).all()
                    and np.nanmax(steps) <= max_step + 1e-12)
    return {"feasible": feasible, "max_step": float(np.nanmax(steps)),
            "travel": float(np.nansum(steps)), "err": float(err[ok].max()) if ok.any()
            else math.inf, "reached": int((err <= 1e-6).sum())}


def best_time(fn, runs):
    """(best seconds, last result) over ``runs`` calls."""
    times, out = [], None
    for _ in range(runs):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return min(times), out


# ------------------------------------------------------------------------- main


def compare(arm, runs, quick):
    robot0 = robokin.load(arm)
    rows = []
    for name, (robot, poses) in paths(robot0).items():
        N = poses.shape[0]
        model = None
        if not quick:
            with contextlib.suppress(ImportError):
                model = rtb_model(robot)
        t, q = best_time(lambda robot=robot, poses=poses: naive(robot, poses), 1)
        rows.append((name, "naive nearest", N, measure(robot, poses, q, max_step=_ms(name)), t))
        if model is not None:
            t, q = best_time(lambda r=robot, p=poses, m=model: ikine_lm(m, r, p), 1)
            rows.append((name, "rtb ikine_LM", N,
                         measure(robot, poses, q, max_step=_ms(name)), t))
        for label, kw in (("follow fixed", {}), ("follow free z", FREE)):
            t, res = best_time(lambda robot=robot, poses=poses, kw=kw: process.follow(
                robot, poses, max_step=_ms(name), q_start=Q0 if name != "spline" else None,
                **kw), runs)
            m = measure(robot, poses, res.q, res.tool_poses, max_step=_ms(name))
            m["reason"] = res.reason
            rows.append((name, label, N, m, t))
        if name == "holes":
            t, res = best_time(lambda robot=robot, poses=poses: process.order(
                robot, poses, q_start=Q0), runs)
            m = measure(robot, poses[res.order], res.q, max_step=math.inf)
            m["reason"] = f"gap to the lower bound {res.gap:.1%}"
            rows.append((name, "order", N, m, t))
    return rows


def _ms(name):
    return math.inf if name == "holes" else MAX_STEP


def throughput(arm, runs, n=5000):
    robot = robokin.load(arm)
    T0 = robot.fk(Q0)
    s = np.linspace(0.0, 2.0 * np.pi, n)
    poses = T0 @ trans(0.1 * np.cos(s) - 0.1, 0.1 * np.sin(s), 0.0)
    out = []
    for label, kw in (("fixed", {}), ("free z +-90 deg / 5 deg", FREE)):
        process.follow(robot, poses[:50], max_step=0.1, **kw)  # warm
        wall, cpu = [], []
        for _ in range(runs):
            t, c = time.perf_counter(), time.process_time()
            res = process.follow(robot, poses, max_step=0.1, **kw)
            wall.append(n / (time.perf_counter() - t))
            cpu.append(n / (time.process_time() - c))
        assert res.feasible, res.reason
        out.append((label, min(wall), max(wall), min(cpu), max(cpu)))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="no roboticstoolbox peer")
    args = ap.parse_args()
    print(f"load average at start: {os.getloadavg()[0]:.1f} (2 cores)")
    for arm in ("ur5", "aubo_i5"):
        print(f"\n## {arm}: paths (max_step {MAX_STEP} rad; holes: no step limit)")
        print(f"{'path':7s} {'method':15s} {'N':>4s} {'feasible':>8s} {'reached':>7s} "
              f"{'max step':>8s} {'travel':>8s} {'pose err':>9s} {'ms':>9s}  note")
        for name, label, N, m, t in compare(arm, args.runs, args.quick):
            print(f"{name:7s} {label:15s} {N:4d} {str(m['feasible']):>8s} "
                  f"{m['reached']:7d} {m['max_step']:8.3f} {m['travel']:8.3f} "
                  f"{m['err']:9.1e} {1e3 * t:9.1f}  {m.get('reason', '')[:90]}")
    for arm in ("ur5", "aubo_i5"):
        print(f"\n## {arm}: throughput, 5,000-waypoint circle, {args.runs} runs")
        for label, w0, w1, c0, c1 in throughput(arm, args.runs):
            print(f"{label:24s} wall {w0:9,.0f}-{w1:9,.0f} waypoints/s   "
                  f"per CPU-second {c0:9,.0f}-{c1:9,.0f}")
    print(f"\nload average at end: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
