"""Co-simulation in MuJoCo (issue 17): agreement first, then timing.

Run: ``python benchmarks/bench_sim.py`` (needs ``pip install -e '.[sim,collision]'``).

1. MJCF FK vs robokin FK: every link frame and the tool site at 1,000 random
   configurations of every built-in arm.
2. The demo's press-loading plan (24 s, 5 ms samples) simulated with the default
   servo gains: tracking error per joint and its correlation with |qdd|; wall
   time of the stepping loop (best of 3) over simulated time.
3. A deliberately colliding plan in the press cell: MuJoCo's contact intervals
   vs ``collision.check``'s (pairs, start and end times).
4. A pendulum: simulated holding torque vs ``m g l cos(q)``.
"""

from __future__ import annotations

import math
import time

import numpy as np

import robokin
from robokin import collision, sim, trajectory
from robokin.cli.demo import plan_press_loading
from robokin.model.dynamics import LinkInertia, RobotDynamics
from robokin.model.geometry import link_names
from robokin.sim._mujoco import load_model, mujoco


def fk_agreement() -> None:
    mj = mujoco()
    rng = np.random.default_rng(17)
    print("1. MJCF FK vs robokin FK, 1,000 random configurations per arm")
    for name in robokin.robots.names():
        robot = robokin.load(name)
        export = sim.build_mjcf(robot)
        model = load_model(export.xml)
        data = mj.MjData(model)
        lo, hi = robot.limits.T
        Q = rng.uniform(np.where(np.isfinite(lo), lo, -np.pi),
                        np.where(np.isfinite(hi), hi, np.pi), size=(1000, robot.n))
        site = mj.mj_name2id(model, mj.mjtObj.mjOBJ_SITE, "tool")
        bodies = [mj.mj_name2id(model, mj.mjtObj.mjOBJ_BODY, n)
                  for n in link_names(robot)[:-1]]
        frames, tool = robot.fk_all(Q), robot.fk(Q)
        ep = er = 0.0
        for k, q in enumerate(Q):
            data.qpos[:] = export.joints.qpos(model, q)
            mj.mj_kinematics(model, data)
            ep = max(ep, np.abs(data.site_xpos[site] - tool[k, :3, 3]).max(),
                     np.abs(data.xpos[bodies] - frames[k, :, :3, 3]).max())
            er = max(er, np.abs(data.xmat[bodies].reshape(-1, 3, 3)
                                - frames[k, :, :3, :3]).max())
        print(f"   {name:18s} position {ep:.1e} m, rotation {er:.1e}")


def demo_plan() -> None:
    scene = collision.Scene.load(collision.scene_path("press"))
    bare = robokin.load("aubo_i5")
    traj, _ = plan_press_loading(scene.attach(bare), scene)
    runs = [sim.simulate(bare, traj, scene) for _ in range(3)]
    res = min(runs, key=lambda r: r.wall_time)
    print(f"2. press-loading plan: {res.duration:.1f} s, {len(res.t)} samples, "
          f"{res.steps} steps at {1 / res.export.timestep:.0f} Hz")
    cmp = res.comparison
    for j, row in enumerate(cmp.table()):
        print(f"   {row['joint']:9s} max {row['max']:.4f} deg at {row['t_max']:.2f} s, "
              f"RMS {row['rms']:.4f} deg, corr(|e|, |qdd|) {row['corr_acc']:.2f}, "
              f"peak torque {res.peak_tau[j]:.2f} N m")
    walls = sorted(r.wall_time for r in runs)
    print(f"   stepping loop {walls[0]:.3f} s (runs {', '.join(f'{w:.3f}' for w in walls)})"
          f" = {res.real_time_factor:.4f} x real time; contacts {len(res.contacts)}")
    t = time.perf_counter()
    sim.simulate(bare, traj, scene)
    print(f"   whole call (model, gains, stepping, compare) {time.perf_counter() - t:.2f} s")


def contacts() -> None:
    scene = collision.Scene.load(collision.scene_path("press"))
    robot = robokin.load("aubo_i5")
    qa, qb = scene.pose_joints["press_approach"], scene.pose_joints["press_place"]
    dive, fold = qb.copy(), qa.copy()
    dive[1] += math.radians(12)
    fold[2] += math.radians(33)
    dt = 0.005
    plan = trajectory.Trajectory.concatenate([
        trajectory.quintic(qa, dive, 2.0, dt=dt), trajectory.quintic(dive, qa, 1.0, dt=dt),
        trajectory.quintic(qa, fold, 2.0, dt=dt)])
    rep = collision.check(robot, scene, plan)
    res = sim.simulate(robot, plan, scene)
    print("3. colliding plan: robokin's intervals | MuJoCo's contacts")
    got = {(c.body_a, c.body_b): c for c in res.contacts}
    for iv in rep.intervals:
        c = got.get((iv.body_a, iv.body_b))
        if c is None:
            print(f"   {iv.body_a}-{iv.body_b}: MISSING in MuJoCo")
            continue
        print(f"   {iv.body_a}-{iv.body_b}: {iv.t_start:.3f}-{iv.t_end:.3f} s, "
              f"{-iv.min_distance * 1e3:.2f} mm | {c.t_start:.3f}-{c.t_end:.3f} s, "
              f"{c.depth * 1e3:.2f} mm")
    extra = set(got) - {(iv.body_a, iv.body_b) for iv in rep.intervals}
    print(f"   pairs only MuJoCo reports: {sorted(extra) or 'none'}")


def pendulum() -> None:
    m, length, g = 2.0, 0.5, 9.81
    robot = robokin.Robot.from_elementary(
        [{"op": "rx", "value": math.pi / 2},
         {"op": "rz", "joint": "revolute", "name": "hinge"},
         {"op": "tx", "value": length}], name="pendulum")
    robot = robot.replace(dynamics=RobotDynamics.from_mapping(
        robot, {"hinge": LinkInertia(m, [length, 0, 0], np.zeros((3, 3)))}))
    worst = 0.0
    for a in np.linspace(-1.4, 1.4, 8):
        hold = trajectory.quintic(np.array([a]), np.array([a]), 0.5, dt=0.005)
        res = sim.simulate(robot, hold)
        worst = max(worst, abs(res.tau[-1, 0] - m * g * length * math.cos(a)))
    print(f"4. pendulum holding torque vs m g l cos q: worst {worst:.1e} N m "
          f"(m g l = {m * g * length:.2f} N m)")


if __name__ == "__main__":
    fk_agreement()
    demo_plan()
    contacts()
    pendulum()
