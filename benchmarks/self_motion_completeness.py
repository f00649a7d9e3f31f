"""Every in-limit configuration of a pose inside an interval of its branch (issue 29).

``self_motion_rates.py`` asks it of one configuration per pose, the one the pose was
made from. This asks it of the whole manifold: for each pose the arm is solved with
one joint held at ``VALUES`` values drawn uniformly in its limits (``robot.ik(T,
fixed=...)``, an independent solver: the parameter joint itself on held-joint and
continued arms, the last joint on SRS arms, whose parameter is the swivel). Each
valid row inside every limit by more than 1e-9 and regular (as in
``self_motion_rates``: the Jacobian without the parameter's column, or on the swivel
the whole Jacobian and sin q2, sin q6, above 1e-5) must be a row of some branch of
``robot.self_motion(T)`` at its own parameter value (1e-6) lying in an interval of
that branch (1e-9). Misses are printed (pose, t, branch, smallest singular value).

Session 17 (``docs/ik.md``): on the offset iiwa's special poses main 37b5191 missed
whole in-limit stretches of branches other than the generating configuration's,
which ``self_motion_rates`` never looks at; ``_node_fills`` restores them.

Usage: ``python benchmarks/self_motion_completeness.py ARM POSES KIND [PICK] [SEED]``
(ARM as in ``self_motion_rates.py``; KIND ``uniform`` or ``special``; POSES of that
kind of ``configurations(robot, 10000, 0)`` drawn with seed PICK (7), as
``self_motion_interval_rows.py`` draws them; SEED (0) draws the held values).
"""

from __future__ import annotations

import pathlib
import sys
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
sys.path[:0] = [str(HERE), str(HERE.parent / "tests")]

from self_motion_rates import (  # noqa: E402
    NON_SINGULAR,
    PARAMETER,
    build,
    configurations,
    gap,
)

from robokin.kinematics.ik.self_motion import parameter_values  # noqa: E402

#: Held values per pose.
VALUES = 24
#: A row counts when it is inside every limit by more than this [rad, m].
MARGIN = 1e-9


def regularity(robot, Q: np.ndarray, swivel: bool, j: int | None) -> np.ndarray:
    """How regular the manifold is in its parameter at rows Q (m, 7): (m,) [1/m]."""
    if swivel:
        sigma = np.minimum(np.linalg.svd(robot.jacobian(Q), compute_uv=False)[:, -1],
                           np.abs(np.sin(Q[:, [1, 5]])).min(axis=-1))
    else:
        sigma = np.linalg.svd(np.delete(robot.jacobian(Q), j, axis=-1),
                              compute_uv=False)[:, -1]
    return sigma


def check_pose(robot, par: str, T: np.ndarray, rng: np.random.Generator
               ) -> tuple[int, list[tuple[float, int, float]], float]:
    """(rows checked, misses [(t, nearest branch or -1, sigma)], CPU seconds of the manifold)."""
    c0 = time.process_time()
    sm = robot.self_motion(T, par)
    cpu = time.process_time() - c0
    swivel = sm.joint is None
    held = robot.n - 1 if swivel else sm.joint
    lo, hi = robot.limits[:, 0], robot.limits[:, 1]
    v = rng.uniform(lo[held], hi[held], VALUES)
    sols = robot.ik(T, fixed={robot.joint_names[held]: v})
    Q = sols.q[sols.valid]
    room = np.minimum(Q - lo, hi - Q).min(axis=-1)  # inside every limit by this
    Q = Q[room > MARGIN]
    if not len(Q):
        return 0, [], cpu
    sigma = regularity(robot, Q, swivel, sm.joint)
    Q = Q[sigma >= NON_SINGULAR]
    sigma = sigma[sigma >= NON_SINGULAR]
    if not len(Q):
        return 0, [], cpu
    if swivel:
        _, t = parameter_values(robot, T, Q[:, None, :])
        t = t[:, 0]
    else:
        t = Q[:, sm.joint].copy()
    rows = sm.sample(t)  # (m, k, 7)
    with np.errstate(invalid="ignore"):
        g = np.where(np.isfinite(rows).all(-1), gap(rows, Q[:, None, :]), np.inf)
    shifts = (-2 * np.pi, 0.0, 2 * np.pi) if sm.periodic else (0.0,)
    misses = []
    for i in range(len(Q)):
        hits = np.flatnonzero(g[i] <= 1e-6)
        inside = False
        for b in hits:
            iv = sm.intervals[sm.interval_branch == b]
            for s in shifts:
                if np.any((iv[:, 0] - 1e-9 <= t[i] + s) & (t[i] + s <= iv[:, 1] + 1e-9)):
                    inside = True
        if not inside:
            misses.append((float(t[i]), int(hits[0]) if len(hits) else -1, float(sigma[i])))
    return len(Q), misses, cpu


def main() -> None:
    arm, m, kind = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    pick = int(sys.argv[4]) if len(sys.argv) > 4 else 7
    seed = int(sys.argv[5]) if len(sys.argv) > 5 else 0
    robot = build(arm)
    par = PARAMETER.get(arm, "auto")
    q, special = configurations(robot, 10000, 0)
    pool = np.flatnonzero(special if kind == "special" else ~special)
    idx = np.random.default_rng(pick).choice(pool, m, replace=False)
    rng = np.random.default_rng(seed)
    rows = poses_missed = n_miss = 0
    cpu = 0.0
    for i in idx.tolist():
        n, misses, c = check_pose(robot, par, robot.fk(q[i]), rng)
        rows += n
        cpu += c
        if misses:
            poses_missed += 1
            n_miss += len(misses)
            for t, b, s in misses[:3]:
                print(f"pose {i}: t {t:.9f} branch {b} sigma {s:.2g}", flush=True)
    print(f"{arm} {kind}: {len(idx)} poses, {rows} regular in-limit rows checked, "
          f"{n_miss} not in an interval of their branch ({poses_missed} poses); "
          f"manifold {1e3 * cpu / max(len(idx), 1):.1f} ms CPU a pose")


if __name__ == "__main__":
    main()
