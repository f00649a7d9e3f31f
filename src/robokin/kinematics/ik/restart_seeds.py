"""Where the numeric solver's descents restart from: the seed table and the seed streams.

A descent that stalls restarts (:mod:`robokin.kinematics.ik.numeric`): first from
the configurations of the arm's :class:`SeedTable` whose tool poses are nearest the
target, then from random configurations inside the limits. Those random numbers do
not come from a generator's state: each target's are numbers of a counter-based
stream keyed by a hash of its pose, its start configuration and a key
(:func:`seed_key`; compiled: ``csrc/lm.c``, ``seed_uniforms``), so a target's
answer does not depend on its place in a batch, the other targets, the thread
count or earlier calls (``docs/conventions.md``, Repeatability).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robokin import _native
from robokin.exceptions import InputError
from robokin.kinematics.arm import ArmSource, Derived, arm_of
from robokin.kinematics.forward import forward_kinematics
from robokin.model.chain import Chain

__all__ = [
    "NO_TABLE", "SEED_SHRINK", "SEED_TABLE", "TABLE_ROT", "TABLE_SEEDS", "TABLE_SIZE", "SeedTable",
    "build_seed_table", "grid_cells", "middle", "seed_key", "seed_table", "uniforms",
]

SEED_SHRINK = 0.1  # restarts and the table sample the central 80 % of each range
TABLE_SIZE = 2048  # seed-table configurations per chain
TABLE_SEEDS = 4  # first-round restarts from the table rows nearest the target
TABLE_ROT = 0.15**2  # [m^2] per unit squared Frobenius rotation distance
_TABLE_PER_CELL = 2.5  # mean rows per occupied grid cell

K = _native.kernels

@dataclass(frozen=True, eq=False)
class SeedTable:
    """Restart seeds of one chain, bucketed by the position of their tool pose.

    ``TABLE_SIZE`` configurations drawn once (a fixed seed: the same table every
    time) from the central 80 % of the seed ranges, with their tool poses, sorted
    into a grid of G^3 cells (G chosen for about ``_TABLE_PER_CELL`` rows per
    occupied cell) so a target's nearest rows are found by scanning the cells
    around it.

    Attributes:
        rows: (M, 12 + n): tool position (3), rotation row-major (9), q (n),
            sorted by cell.
        cell_start: (G^3 + 1,) int64: first row of each cell.
        grid: (7,): grid origin (3) [m], inverse cell size (3) [1/m], G.
    """

    rows: np.ndarray
    cell_start: np.ndarray
    grid: np.ndarray

    def kernel_args(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(rows, cell_start, grid)`` as the compiled solver takes them."""
        return self.rows, self.cell_start, self.grid


def seed_table(robot: ArmSource) -> SeedTable:
    """The arm's :class:`SeedTable` (built on first use, kept in its ``Arm``)."""
    return arm_of(robot).derived(SEED_TABLE)


def build_seed_table(chain: Chain) -> SeedTable:
    """A new :class:`SeedTable` of ``chain`` (the same rows every time: a fixed seed)."""
    arr = chain.arrays
    span = arr.seed_upper - arr.seed_lower
    lo = arr.seed_lower + SEED_SHRINK * span
    hi = arr.seed_upper - SEED_SHRINK * span
    Q = lo + np.random.default_rng(0).random((TABLE_SIZE, chain.n)) * (hi - lo)
    T = forward_kinematics(chain, Q)
    poses = np.concatenate([T[:, :3, 3], T[:, :3, :3].reshape(-1, 9)], axis=1)
    p = poses[:, :3]
    origin = p.min(axis=0) - 1e-9
    extent = np.maximum(p.max(axis=0) + 1e-9 - origin, 1e-6)
    G = 1
    while G < 64:
        cells = grid_cells(p, origin, G / extent, G)
        if len(p) <= _TABLE_PER_CELL * len(np.unique(cells)):
            break
        G += 1
    cells = grid_cells(p, origin, G / extent, G)
    order = np.argsort(cells, kind="stable")
    rows = np.ascontiguousarray(np.concatenate([poses, Q], axis=1)[order])
    cstart = np.zeros(G**3 + 1, dtype=np.int64)
    cstart[1:] = np.cumsum(np.bincount(cells, minlength=G**3))
    grid = np.concatenate([origin, G / extent, [G]]).astype(np.float64)
    for a in (rows, cstart, grid):
        a.setflags(write=False)
    return SeedTable(rows, cstart, grid)


def grid_cells(p: np.ndarray, origin: np.ndarray, inv: np.ndarray, G: int) -> np.ndarray:
    """The grid cell (int64, (M,)) of each position p (M, 3) [m].

    ``origin`` (3,) [m], inverse cell size ``inv`` (3,) [1/m], ``G`` cells per axis;
    a position outside the grid gets the border cell.
    """
    c = np.clip(np.floor((p - origin) * inv).astype(np.int64), 0, G - 1)
    cells: np.ndarray = (c[:, 0] * G + c[:, 1]) * G + c[:, 2]
    return cells


#: The arm's seed table, kept in its ``Arm`` (``arm.derived(SEED_TABLE)``).
SEED_TABLE: Derived[SeedTable] = Derived(
    "numeric IK seed table", lambda arm: build_seed_table(arm.chain))

#: The kernel arguments for "no seed table" (a 0-row table).
NO_TABLE = (np.empty((0, 12)), np.zeros(1, dtype=np.int64), np.zeros(7))
for _a in NO_TABLE:
    _a.setflags(write=False)
del _a


def middle(chain: Chain) -> np.ndarray:
    """The default first guess: the middle of the seed ranges, (n,)."""
    arr = chain.arrays
    return 0.5 * (arr.seed_lower + arr.seed_upper)


def seed_key(rng: np.random.Generator | None) -> int:
    """The key of the restart streams: 0, or one number drawn from ``rng``.

    Restart seeds are not drawn from a generator's state: each target's come from
    a counter-based stream keyed by a hash of its pose, its start configuration
    and this key (``csrc/lm.c``, ``seed_uniforms``), so a target's answer does not
    depend on its place in a batch, the other targets, the thread count or earlier
    calls. An explicit ``rng`` changes the key (one draw per call).
    """
    if rng is None:
        return 0
    if not isinstance(rng, np.random.Generator):
        raise InputError("rng", f"expected a numpy.random.Generator, got {rng!r:.60}")
    # one raw 64-bit draw of its bit generator (0.4 us; rng.integers took 2.7 us,
    # ~15 % of a single solve)
    return int(rng.bit_generator.random_raw())


def uniforms(Tf: np.ndarray, Q0: np.ndarray, key: int, base: int, R: int) -> np.ndarray:
    """Restart numbers (N, R, n) in [0, 1) of targets Tf (N, 4, 4) started at Q0 (N, n).

    Numbers ``base .. base + R - 1`` of each target's stream (``seed_key``).
    """
    out = np.empty((Tf.shape[0], R, Q0.shape[1]))
    K.seed_uniforms(np.ascontiguousarray(Tf), np.ascontiguousarray(Q0), key, base, out)
    return out
