"""Trajectory collision check: robokin vs the naive loop of coal distance calls.

Run: ``python benchmarks/bench_collision.py [--samples 5000] [--meshes]``.

The AUBO-i5 with the parallel gripper in the bundled press scene follows a
press-loading cycle of ``--samples`` joint samples (pick approach, pick, lift,
press approach, a straight Cartesian line into the die opening, and back). The
naive reference calls ``coal.distance`` on every (link shape, object) and every
checked self pair at every sample, with coal objects built once (FK for all
samples is vectorised for it too, so only the query loop differs). Both must
agree on the minimum distance to 1e-6 m; the script prints both times, the
speed-up, and the query counts, and exits 1 if the targets (< 2 s, >= 20x) miss.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

import robokin
from robokin.collision import Scene, check, scene_path


def _smooth(q0: np.ndarray, q1: np.ndarray, m: int) -> np.ndarray:
    s = np.linspace(0.0, 1.0, m)[:, None]
    s = 10 * s**3 - 15 * s**4 + 6 * s**5  # quintic time scaling, rest to rest
    return q0 + s * (q1 - q0)


def press_cycle(robot: robokin.Robot, scene: Scene, samples: int) -> np.ndarray:
    """A press-loading cycle of ``samples`` joint configurations (m, 6) [rad]."""
    placed = scene.attach(robot)
    pj = scene.pose_joints
    line_T0, line_T1 = scene.poses["press_approach"], scene.poses["press_place"]
    # segment lengths as fractions of the whole cycle
    parts = [
        ("pick_approach", "pick", 0.12),
        ("pick", "pick_approach", 0.12),
        ("pick_approach", "press_approach", 0.26),
        ("line", None, 0.15),
        ("line_back", None, 0.15),
        ("press_approach", "pick_approach", 0.20),
    ]
    counts = [int(round(f * samples)) for *_, f in parts]
    counts[-1] = samples - sum(counts[:-1])
    out = []
    for (a, b, _), m in zip(parts, counts):
        if a in ("line", "line_back"):
            s = np.linspace(0.0, 1.0, m)
            s = 10 * s**3 - 15 * s**4 + 6 * s**5
            if a == "line_back":
                s = s[::-1]
            q = pj["press_approach"] if a == "line" else pj["press_place"]
            seg = []
            for si in s:
                T = line_T0.copy()
                T[:3, 3] = (1 - si) * line_T0[:3, 3] + si * line_T1[:3, 3]
                sols = placed.ik(T)
                Q = sols.q[sols.valid]
                q = Q[np.argmin(np.linalg.norm(Q - q, axis=1))]
                seg.append(q)
            out.append(np.array(seg))
        else:
            out.append(_smooth(pj[a], pj[b], m))
    return np.concatenate(out)


def naive(problem, q: np.ndarray) -> float:
    """Minimum distance by coal.distance on every pair at every sample."""
    import coal

    frames = problem.frames(q)
    req = coal.DistanceRequest()
    pairs = []
    for p in range(problem.P):
        ga, gb = problem.geoms[p]
        a = problem.pa[p]
        b = problem.pb[p]
        if problem.is_self[p]:
            pairs.append(
                (
                    ga,
                    gb,
                    problem.link[a],
                    problem.place[a],
                    problem.link[b],
                    problem.place[b],
                    None,
                )
            )
        else:
            pairs.append(
                (
                    ga,
                    gb,
                    problem.link[a],
                    problem.place[a],
                    None,
                    None,
                    problem.ob_T3[b],
                )
            )
    best = np.inf
    for i in range(q.shape[0]):
        F = frames[i]
        for ga, gb, la, Pa, lb, Pb, Tb in pairs:
            Wa = F[la] @ Pa
            Ta = coal.Transform3s(np.ascontiguousarray(Wa[:3, :3]), Wa[:3, 3].copy())
            if Tb is None:
                Wb = F[lb] @ Pb
                Tb_ = coal.Transform3s(
                    np.ascontiguousarray(Wb[:3, :3]), Wb[:3, 3].copy()
                )
            else:
                Tb_ = Tb
            res = coal.DistanceResult()
            d = coal.distance(ga, Ta, gb, Tb_, req, res)
            best = min(best, d)
    return best


def pinocchio_min_distance(robot, problem, q: np.ndarray) -> tuple[float, float]:
    """Minimum distance with pinocchio's computeDistances at every sample (peer).

    The same coal geometries and pairs, attached to a pinocchio model with the
    robot's kinematics (``peers.pinocchio_model``); returns (minimum, seconds).
    """
    import pinocchio as pin

    sys.path.insert(0, str(__import__("pathlib").Path(__file__).parent))
    from peers import pinocchio_model

    placed = problem.robot
    chain = placed.chain
    model, data, _ = pinocchio_model(placed)
    gmodel = pin.GeometryModel()
    nc = chain.n_chain
    last = chain.arrays.consts[-1]
    ids = []
    for s, shape in enumerate(problem.shapes):
        k = int(problem.link[s])
        if k == 0:
            parent, P = 0, chain.base @ shape.placement
        elif k <= nc:
            parent, P = k, chain.frame_offsets[k - 1] @ shape.placement
        else:
            parent, P = nc, last @ shape.placement
        geom = (
            problem.geoms[[p for p in range(problem.P) if problem.pa[p] == s][0]][0]
            if (problem.pa == s).any()
            else shape.coal_geometry()
        )
        obj = pin.GeometryObject(
            f"s{s}", parent, pin.SE3(P[:3, :3].copy(), P[:3, 3].copy()), geom
        )
        ids.append(gmodel.addGeometryObject(obj))
    oids = []
    for j, ob in enumerate(problem.objects):
        P = ob.pose
        obj = pin.GeometryObject(
            f"o{j}",
            0,
            pin.SE3(P[:3, :3].copy(), P[:3, 3].copy()),
            ob.shape.coal_geometry(),
        )
        oids.append(gmodel.addGeometryObject(obj))
    for p in range(problem.P):
        a = ids[problem.pa[p]]
        b = ids[problem.pb[p]] if problem.is_self[p] else oids[problem.pb[p]]
        gmodel.addCollisionPair(pin.CollisionPair(a, b))
    gdata = pin.GeometryData(gmodel)
    qc = chain.coupling.apply(q)  # the signs are in the joint axes
    t0 = time.perf_counter()
    best = np.inf
    for i in range(q.shape[0]):
        pin.computeDistances(model, data, gmodel, gdata, qc[i])
        best = min(best, min(r.min_distance for r in gdata.distanceResults))
    return best, time.perf_counter() - t0


def with_mesh_links(robot: robokin.Robot, folder) -> robokin.Robot:
    """The robot with every capsule replaced by a ~3,800-triangle mesh of it (STL)."""
    import trimesh

    from robokin.model import geometry as geo

    g = robot.geometry
    shapes = {}
    for name, ss in zip(g.names, g.shapes):
        out = []
        for k, s in enumerate(ss):
            if s.kind != "capsule":
                out.append(s)
                continue
            path = folder / f"{name}_{k}.stl"
            trimesh.creation.capsule(
                height=s.size[1], radius=s.size[0], count=[48, 40]
            ).export(path)
            out.append(geo.mesh(path, s.placement, owner=name))
        shapes[name] = out
    new = geo.RobotGeometry.from_mapping(
        robot, shapes, exclude=[tuple(p) for p in g.exclude]
    )
    return robot.replace(geometry=new)


def main(samples: int = 5000, meshes: bool = False) -> int:
    robot = robokin.load("aubo_i5")
    if meshes:
        import tempfile
        from pathlib import Path

        robot = with_mesh_links(robot, Path(tempfile.mkdtemp()))
    scene = Scene.load(scene_path("press"))
    q = press_cycle(robot, scene, samples)
    t = np.linspace(0.0, 12.0, samples)

    t0 = time.perf_counter()
    rep = check(robot, scene, q, t=t, clearance=0.004)
    cold = time.perf_counter() - t0
    warm = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        rep = check(robot, scene, q, t=t, clearance=0.004)
        warm = min(warm, time.perf_counter() - t0)
    problem = rep._problem
    t0 = time.perf_counter()
    ref = naive(problem, q)
    t_naive = time.perf_counter() - t0

    try:
        pin_min, t_pin = pinocchio_min_distance(robot, problem, q)
    except ImportError:
        pin_min, t_pin = None, None

    c = rep.closest
    what = "mesh links, 3,840 triangles each" if meshes else "capsule links"
    print(
        f"AUBO-i5 ({what}) + gripper, press scene: {samples} samples, {problem.P} "
        f"shape pairs ({int((~problem.is_self).sum())} link-object, {len(problem.self_pairs)} self)"
    )
    print(
        f"  closest: {c.body_a} - {c.body_b} {c.distance * 1e3:.3f} mm at t = {c.t:.3f} s "
        f"(sample {c.index}); collides: {rep.collides}"
    )
    print(f"  exact coal queries: robokin {rep.queries}, naive {problem.P * samples}")
    print(f"  naive coal loop     {t_naive:8.3f} s   min {ref:.9f} m")
    if pin_min is not None:
        print(f"  pinocchio computeDistances loop {t_pin:8.3f} s   min {pin_min:.9f} m")
    print(f"  robokin check cold  {cold:8.3f} s   (includes building coal objects)")
    print(f"  robokin check warm  {warm:8.3f} s   min {rep.min_distance:.9f} m")
    print(f"  speed-up (warm / cold): {t_naive / warm:.1f}x / {t_naive / cold:.1f}x")
    diff = abs(ref - rep.min_distance)
    print(
        f"  |min difference| vs naive = {diff:.2e} m (coal's default GJK tolerance 1e-6;"
        " robokin queries with 1e-9)"
    )
    if pin_min is not None:
        print(
            f"  |min difference| vs pinocchio = {abs(pin_min - rep.min_distance):.2e} m"
        )
    ok = diff <= 1e-6 and warm < 2.0 and t_naive / warm >= 20.0
    print(
        "  targets (< 2 s, >= 20x, same minimum to 1e-6 m):", "met" if ok else "MISSED"
    )
    return 0 if ok else 1


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=5000)
    parser.add_argument(
        "--meshes",
        action="store_true",
        help="replace the link capsules by triangle meshes of them",
    )
    args = parser.parse_args()
    sys.exit(main(args.samples, args.meshes))
