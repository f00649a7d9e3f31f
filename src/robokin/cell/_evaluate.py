"""What one Dask task of a reachability map computes: a chunk of voxels.

Everything here is a function of the voxel numbers and the job alone (no state,
no randomness, nothing that depends on which other voxels share the chunk), so
a map is the same bit for bit whatever the chunking and wherever it runs:

* the target poses are copied, not computed, from the voxel centres and the
  orientations;
* the closed-form IK kernel and the numeric solver give each target the result
  it gets alone (``tests/native``; the numeric solver is given no random
  restarts: only its deterministic seed-table restarts);
* the manipulability is computed per solution (a determinant, or a product
  of singular values), each on its own, and the per-voxel results are maxima
  and integer sums, which do not depend on order.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from robokin.cell.grid import VoxelGrid

if TYPE_CHECKING:
    from robokin.collision.scene import Scene
    from robokin.model.chain import Chain
    from robokin.robot import Robot

__all__ = ["SOLVE_BATCH", "ReachChunk", "ReachJob", "evaluate_reach", "first_false",
           "fused_params", "manipulability", "solve_poses", "solve_task"]

NUMERIC_RESTARTS = 4  # the numeric solver's seed-table restarts (no random ones)
_MANIPULABILITY_BATCH = 16384  # Jacobians at a time (16384 x 6 x 6 x 8 B = 4.7 MB)
#: IK targets solved at a time inside a reach-map task (rounded to whole voxels):
#: the closed form's solutions of 16,384 targets are 6.3 MB. Measured on one UR5
#: task of 131,072 targets (one thread): 458 ns a target against 547 ns solved
#: at once, whose 50 MB of fresh pages cost 60-100 ns a target of system time.
SOLVE_BATCH = 16384


@dataclass(frozen=True, eq=False)
class ReachJob:
    """What every chunk of a map shares (pickled once into the Dask graph).

    Attributes:
        robot: The robot as placed in the world (IK targets are world poses).
        bare: The robot before the scene placed it (for the collision check), or
            None without a scene.
        scene: The scene whose objects make a solution invalid, or None.
        grid: The voxel grid.
        orientations: Tool orientations (K, 3, 3) in the world.
        numeric: Solve numerically (one solution per target) instead of in
            closed form (every solution).
        with_manipulability: Compute the best manipulability per voxel.
        store: Path of the Zarr store the chunk writes into, or None to return
            the arrays.
        store_token: Names the run writing the store (see
            :func:`robokin.cell._store.write_chunk`).
        sweep: With ``numeric``, the joint whose values sweep a 7R arm's
            self-motion manifold for targets the numeric sample missed
            (:mod:`robokin.cell._manifold`), or None.
    """

    robot: Robot
    bare: Robot | None
    scene: Scene | None
    grid: VoxelGrid
    orientations: np.ndarray
    numeric: bool
    with_manipulability: bool
    store: str | None = None
    store_token: str = ""
    sweep: str | None = None


@dataclass(frozen=True, eq=False)
class ReachChunk:
    """The result of one chunk of B voxels.

    Attributes:
        start: First voxel number.
        stop: One past the last.
        counts: Solutions per voxel and orientation (B, K) uint8, or None when
            written to the store.
        index: Reachability index per voxel (B,), or None (written).
        solutions: Solutions per voxel, summed over orientations (B,) int32, or
            None (written).
        manipulability: Best manipulability per voxel (B,), or None.
        reachable_voxels: Voxels with an index above 0.
    """

    start: int
    stop: int
    counts: np.ndarray | None
    index: np.ndarray | None
    solutions: np.ndarray | None
    manipulability: np.ndarray | None
    reachable_voxels: int


def manipulability(chain: Chain, q: np.ndarray, ok: np.ndarray | None = None) -> np.ndarray:
    """Yoshikawa's manipulability of configurations q (..., n) [rad, m], shape (...).

    :func:`robokin.kinematics.jacobian.manipulability` with ``method="det"``
    (``|det J|`` for a 6-joint arm, computed in compiled code with the
    Jacobian, in one call: it stores nothing but the result; the product of
    singular values otherwise, :data:`_MANIPULABILITY_BATCH` configurations at
    a time so the temporaries stay bounded), where ``ok`` (...) (default
    everywhere; 0 elsewhere, where q is not read: NaN rows of a solution set
    are fine). Each row is computed on its own, so chunking changes no bit.
    """
    from robokin.kinematics.jacobian import manipulability as yoshikawa

    lead = q.shape[:-1]
    flat = q.reshape(-1, q.shape[-1])
    mask = np.ones(flat.shape[0], dtype=bool) if ok is None else ok.reshape(-1)
    if chain.n == 6:  # compiled, no temporaries: one call
        return yoshikawa(chain, flat, method="det", where=mask).reshape(lead)
    out = np.empty(flat.shape[0])
    for a in range(0, flat.shape[0], _MANIPULABILITY_BATCH):  # bounded temporaries
        b = min(a + _MANIPULABILITY_BATCH, flat.shape[0])
        out[a:b] = yoshikawa(chain, flat[a:b], method="det", where=mask[a:b])
    return out.reshape(lead)


def solve_poses(robot: Robot, T: np.ndarray, numeric: bool, sweep: str | None = None
                ) -> tuple[np.ndarray, np.ndarray]:
    """Every IK solution of poses T (M, 4, 4) inside the joint limits.

    Args:
        robot: The robot (world frame).
        T: Target poses (M, 4, 4) [m].
        numeric: One numeric solution per target (seed-table restarts only)
            instead of every closed-form solution.
        sweep: With ``numeric`` on a 7R arm, the joint that sweeps the
            self-motion manifold of the targets the numeric sample did not
            reach (:func:`robokin.cell._manifold.reach_on_manifold`), or None.

    Returns:
        ``q`` (M, k, n) [rad, m] and ``ok`` (M, k) bool: a valid solution inside
        every joint limit (k = 1 for the numeric solver).
    """
    if numeric:
        from robokin.kinematics.ik.numeric import solve

        res = solve(robot, T, max_restarts=NUMERIC_RESTARTS)
        q = np.asarray(res.q, dtype=np.float64).reshape(T.shape[0], 1, robot.n)
        ok = np.asarray(res.success, dtype=bool).reshape(-1, 1)
        ok &= robot.within_limits(q)
        miss = np.flatnonzero(~ok[:, 0])
        if sweep is not None and miss.size:
            from robokin.cell._manifold import reach_on_manifold

            q[miss, 0], ok[miss, 0] = reach_on_manifold(robot, T[miss], sweep, q[miss, 0])
        return q, ok
    sols = robot.ik(T, method="analytic")
    return sols.q, sols.within_limits


def solve_task(robot: Robot, T: np.ndarray, numeric: bool, sweep: str | None = None
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`solve_poses` of a task's poses for C candidates, T (C, N, 4, 4).

    Returns:
        ``q`` (C, N, k, n), ``ok`` (C, N, k) and ``unreached`` (C,): the first
        pose without any solution inside the limits (-1 when every pose has one).
    """
    C, N = T.shape[:2]
    q, ok = solve_poses(robot, np.ascontiguousarray(T.reshape(C * N, 4, 4)), numeric, sweep)
    k, n = q.shape[-2:]
    ok = ok.reshape(C, N, k)
    return q.reshape(C, N, k, n), ok, first_false(np.asarray(ok.any(axis=-1)))


def first_false(mask: np.ndarray) -> np.ndarray:
    """(C,) index of the first False along the last axis of (C, N), -1 if none."""
    bad = ~mask
    return np.where(bad.any(axis=-1), np.argmax(bad, axis=-1), -1)


def collision_free(bare: Robot, scene: Scene, q: np.ndarray) -> np.ndarray:
    """Which configurations touch nothing in the scene (nor the robot itself).

    Each of q (P, n) [rad, m] is judged on its own (no motion between them);
    returns (P,) bool.
    """
    from robokin.collision import check

    free = np.ones(q.shape[0], dtype=bool)
    if q.shape[0] == 0:
        return free
    rep = check(bare, scene, q, subdivide=False)
    for c in rep.collisions:
        free[c.first_index : c.last_index + 1] = False
    return free


def poses(job: ReachJob, start: int, stop: int) -> np.ndarray:
    """Target poses of voxels ``start .. stop - 1`` (B * K, 4, 4): voxel-major."""
    c = job.grid.centers(start, stop)
    R = job.orientations
    B, K = c.shape[0], R.shape[0]
    T = np.zeros((B, K, 4, 4))
    T[:, :, :3, :3] = R[None]
    T[:, :, :3, 3] = c[:, None]
    T[:, :, 3, 3] = 1.0
    return T.reshape(B * K, 4, 4)


def evaluate_reach(job: ReachJob, start: int, stop: int) -> ReachChunk:
    """Reachability of voxels ``start .. stop - 1`` in every orientation.

    The voxels are solved :data:`SOLVE_BATCH` targets (whole voxels) at a time,
    so a task's temporaries stay a few MB whatever its size and the solutions
    are still in cache when their manipulability is computed.

    Returns:
        A :class:`ReachChunk`; with ``job.store`` its arrays are written into
        the store (one Zarr chunk each) and left out of the result.
    """
    K = job.orientations.shape[0]
    B = stop - start
    counts = np.empty((B, K), dtype=np.uint8)
    best = np.empty(B) if job.with_manipulability else None
    step = max(1, SOLVE_BATCH // K)
    params = fused_params(job)
    for a in range(start, stop, step):
        b = min(a + step, stop)
        _evaluate_batch(job, a, b, counts[a - start : b - start],
                        None if best is None else best[a - start : b - start], params)
    solutions = counts.sum(axis=-1, dtype=np.int32)
    index = (counts > 0).sum(axis=-1) / K
    reachable = int(np.count_nonzero(index))
    if job.store is None:
        return ReachChunk(start, stop, counts, index, solutions, best, reachable)
    from robokin.cell._store import write_chunk

    write_chunk(job.store, start, stop, {"counts": counts, "index": index,
                                         "solutions": solutions, "manipulability": best},
                job.store_token)
    return ReachChunk(start, stop, None, None, None, None, reachable)


def fused_params(job: ReachJob) -> np.ndarray | None:
    """The 6R closed form's parameters when a job can take the fused kernel, else None.

    The fused kernel (``_native/csrc/reach.c``, ``six_r_reach``) solves and
    reduces in one compiled pass: it serves the closed form of a three-parallel
    or spherical-wrist arm (not a near-family one, which is polished in Python)
    without a scene (the collision check needs every solution).
    """
    if job.numeric or job.scene is not None:
        return None
    from robokin.kinematics.ik.analytic.detect import SixRSolver, detect

    solver = detect(job.robot.arm).solver
    if isinstance(solver, SixRSolver) and not solver.near:
        return solver.params
    return None


def _evaluate_batch(job: ReachJob, start: int, stop: int, counts: np.ndarray,
                    best: np.ndarray | None, params: np.ndarray | None = None) -> None:
    """Evaluate voxels ``start .. stop - 1`` into ``counts`` and ``best``.

    ``counts`` (B, K) gets the solutions per target; ``best`` (B,), unless None,
    the best manipulability per voxel. With ``params`` (:func:`fused_params`)
    one compiled call does both: the solutions are counted and their
    manipulability reduced per voxel while they are in cache, nothing of size
    (B, K, 8, 6) is returned (the same numbers, bit for bit, as the solution set
    and :func:`manipulability`: ``tests/cell/test_evaluate.py``).
    """
    B, K = counts.shape
    if params is not None:
        from robokin._native import kernels

        T = poses(job, start, stop).reshape(B, K, 4, 4)
        out = np.empty(B) if best is None else best
        kernels.six_r_reach(params, T, job.robot.chain.arrays.packed, best is not None,
                            counts, out)
        return
    q, ok = solve_poses(job.robot, poses(job, start, stop), job.numeric, job.sweep)
    if job.scene is not None and job.bare is not None and ok.any():
        ok[ok] = collision_free(job.bare, job.scene, q[ok])
    counts[:] = ok.sum(axis=-1).reshape(B, K)
    if best is not None:
        best[:] = manipulability(job.robot.chain, q, ok).reshape(B, -1).max(axis=-1)
