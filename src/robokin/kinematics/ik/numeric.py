r"""Numeric inverse kinematics for any chain: damped least squares with limits and restarts.

The solver works on the canonical chain (:mod:`robokin.model.chain`), so every arm
gets it: revolute and prismatic joints, reversed axes, dependent joints
(``q_chain = M q + c``). One descent is Levenberg-Marquardt on the task error

.. math::

    e = \begin{bmatrix} p_t - p(q) \\ \log(R_t R(q)^T)^\vee \end{bmatrix},
    \qquad
    \Delta q = J_w^T (J_w J_w^T + \lambda I)^{-1} W^{1/2} e

(or the joint-space form when fewer joints than task rows), with
``J_w = W^{1/2} J`` restricted to the selected task rows, ``lambda = mu * E``
(``E = e^T W e``) and ``mu`` adapted by accepting steps that lower ``E`` and
rejecting the others. Joint limits are kept during the iteration: every trial
point is projected into the limits (2*pi-periodic joints are first shifted by whole
turns), and joints pressed against a limit by the gradient leave the active set.
A descent that stalls (the cost has not fallen to 0.3 times its value of 3
iterations before: a local minimum, or pinned at limits) or runs out of iterations
restarts: first from the configurations of a per-chain seed table (2,048 fixed
samples of the central 80 % of the joint ranges with their tool poses) whose poses
are nearest the target, then from random seeds inside the limits (alternately from
the central 80 % of each joint range, where descents meet limits less often, and
from the whole range) until the target is reached or
the budget (restarts, wall time) is spent. The random seeds come from the inputs,
not from a generator's state: each target's from a counter-based stream keyed by a
hash of its pose and start configuration (``_seed_key``; an explicit ``rng`` changes
the key), so the same call gives the same bits whatever the batch around a target
and the thread count (see ``docs/conventions.md``, Repeatability). Results are always inside the limits;
a target that is not reached comes back with ``success=False``, the best
configuration found and the error it leaves, never an exception.

Convergence means the norm of the selected position rows is at most ``tol`` [m]
and that of the selected rotation rows at most ``tol_rotation`` [rad] (default
``tol``), both 1e-9 by default.

The descents run compiled (``robokin/_native/csrc/lm.c``), four targets per vector,
on every thread for batches; a single target runs the same code in one lane.

References:
    Sugihara, T. "Solvability-unconcerned inverse kinematics by the
    Levenberg-Marquardt method", IEEE Trans. Robotics 27(5), 2011 (the
    error-scaled damping ``lambda = E + ...``, eq. 20).
    Nocedal, J. and Wright, S. "Numerical Optimization", 2nd ed., ch. 10.3
    (Levenberg-Marquardt) and 16.7 (active sets for bounds).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from robokin import _native
from robokin._validation import (
    _real_array,
    check_broadcasts,
    check_finite,
    check_joints,
    check_transform,
)
from robokin.exceptions import InputError
from robokin.kinematics.arm import Arm, ArmSource, arm_of
from robokin.model.chain import Chain

if TYPE_CHECKING:
    from robokin.kinematics.ik.solutions import SolutionSet

__all__ = ["IKPathResult", "IKResult", "ik_path", "parse_mask", "solve", "solve_all"]

_AXES = ("x", "y", "z", "rx", "ry", "rz")
# below this many targets one thread beats the parallel launch (~3 us; a first
# descent costs ~5 us, a round of 16 restarts ~100 us)
_PARALLEL_MIN = 8
_PARALLEL_MIN_RESTARTS = 2
_FIRST_ROUND_RESTARTS = 4
_ROUND_RESTARTS = 16
_STALL_EVERY = 3
_STALL_RATIO = 0.3
_MU0 = 1e-2  # initial damping, lambda = mu * E
_MU_DOWN = 0.7
_MU_UP = 16.0
_SEED_SHRINK = 0.1
_TABLE_SIZE = 2048  # seed-table configurations per chain
_TABLE_SEEDS = 4  # first-round restarts from the table rows nearest the target
_TABLE_ROT = 0.15**2  # [m^2] per unit squared Frobenius rotation distance
_TABLE_PER_CELL = 2.5  # mean rows per occupied grid cell


K = _native.kernels  # the compiled solver, its option indices and result columns
_clock = time.perf_counter  # the clock max_time is measured on (tests replace it)

# --------------------------------------------------------------------------- records
@dataclass(frozen=True, eq=False)
class IKResult:
    """The outcome of :func:`solve` for a batch of targets of leading shape (...).

    Attributes:
        q: Joint coordinates [rad, m], shape (..., n): the solution where
            ``success``, else the best configuration found (always within limits).
        success: (...) bool, converged to the tolerance.
        error: (...) final residual [m, rad]: the norm of the selected task error
            rows (position and rotation together).
        position_error: (...) norm of the selected position rows [m].
        rotation_error: (...) norm of the selected rotation rows [rad].
        iterations: (...) int, iterations used over all attempts.
        restarts: (...) int, restarts used (seed-table and random).
        reason: (...) str, ``"converged"`` or why not (with the error reached).

    For a single target (``T`` of shape (4, 4)) the fields are scalars (``q`` is
    (n,), ``reason`` a str, ``iterations`` an int).
    """

    q: npt.NDArray[np.float64]
    success: npt.NDArray[np.bool_] | np.bool_
    error: npt.NDArray[np.float64] | float
    iterations: npt.NDArray[np.int64] | int
    restarts: npt.NDArray[np.int64] | int
    reason: npt.NDArray[np.object_] | str
    position_error: npt.NDArray[np.float64] | float
    rotation_error: npt.NDArray[np.float64] | float

    def __bool__(self) -> bool:
        """True when every target converged."""
        return bool(np.all(self.success))


@dataclass(frozen=True, eq=False)
class IKPathResult:
    """The outcome of :func:`ik_path` for a path of m poses.

    Attributes:
        q: Joint path (m, n) [rad, m]; after ``first_failure`` the rows repeat the
            last good configuration.
        success: (m,) bool.
        error: (m,) residual reached per sample [m, rad] (inf where not run).
        first_failure: Index of the first failed sample, or None.
        reason: ``"converged"`` or why the path stops.
    """

    q: np.ndarray
    success: np.ndarray
    error: np.ndarray
    first_failure: int | None
    reason: str

    def __bool__(self) -> bool:
        """True when every sample converged."""
        return self.first_failure is None


# ------------------------------------------------------------------ per-chain data
@dataclass(frozen=True, eq=False)
class SeedTable:
    """Restart seeds of one chain, bucketed by the position of their tool pose.

    ``_TABLE_SIZE`` configurations drawn once (a fixed seed: the same table every
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
    arm = arm_of(robot)
    tab = arm.seed_table
    if not isinstance(tab, SeedTable):
        tab = arm.seed_table = _build_seed_table(arm.chain)
    return tab


def _build_seed_table(chain: Chain) -> SeedTable:
    from robokin.kinematics.forward import forward_kinematics

    arr = chain.arrays
    span = arr.seed_upper - arr.seed_lower
    lo = arr.seed_lower + _SEED_SHRINK * span
    hi = arr.seed_upper - _SEED_SHRINK * span
    Q = lo + np.random.default_rng(0).random((_TABLE_SIZE, chain.n)) * (hi - lo)
    T = forward_kinematics(chain, Q)
    poses = np.concatenate([T[:, :3, 3], T[:, :3, :3].reshape(-1, 9)], axis=1)
    p = poses[:, :3]
    origin = p.min(axis=0) - 1e-9
    extent = np.maximum(p.max(axis=0) + 1e-9 - origin, 1e-6)
    G = 1
    while G < 64:
        cells = _grid_cells(p, origin, G / extent, G)
        if len(p) <= _TABLE_PER_CELL * len(np.unique(cells)):
            break
        G += 1
    cells = _grid_cells(p, origin, G / extent, G)
    order = np.argsort(cells, kind="stable")
    rows = np.ascontiguousarray(np.concatenate([poses, Q], axis=1)[order])
    cstart = np.zeros(G**3 + 1, dtype=np.int64)
    cstart[1:] = np.cumsum(np.bincount(cells, minlength=G**3))
    grid = np.concatenate([origin, G / extent, [G]]).astype(np.float64)
    for a in (rows, cstart, grid):
        a.setflags(write=False)
    return SeedTable(rows, cstart, grid)


def _grid_cells(p: np.ndarray, origin: np.ndarray, inv: np.ndarray, G: int) -> np.ndarray:
    c = np.clip(np.floor((p - origin) * inv).astype(np.int64), 0, G - 1)
    cells: np.ndarray = (c[:, 0] * G + c[:, 1]) * G + c[:, 2]
    return cells


# kernel arguments for "no seed table" (a 0-row table)
_NO_TABLE = (np.empty((0, 12)), np.zeros(1, dtype=np.int64), np.zeros(7))
for _a in _NO_TABLE:
    _a.setflags(write=False)
del _a


def _middle(chain: Chain) -> np.ndarray:
    """The default first guess: the middle of the seed ranges, (n,)."""
    arr = chain.arrays
    return 0.5 * (arr.seed_lower + arr.seed_upper)


def _seed_key(rng: np.random.Generator | None) -> int:
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
    return int(rng.integers(0, 2**63, dtype=np.uint64))


def _uniforms(Tf: np.ndarray, Q0: np.ndarray, key: int, base: int, R: int) -> np.ndarray:
    """Restart numbers (N, R, n) in [0, 1) of targets Tf (N, 4, 4) started at Q0 (N, n).

    Numbers ``base .. base + R - 1`` of each target's stream (``_seed_key``).
    """
    out = np.empty((Tf.shape[0], R, Q0.shape[1]))
    K.seed_uniforms(np.ascontiguousarray(Tf), np.ascontiguousarray(Q0), key, base, out)
    return out


# --------------------------------------------------------------------- the options
_MASK_CACHE: dict[Any, np.ndarray] = {}


def parse_mask(mask: Any) -> np.ndarray:
    """The task mask as a (6,) bool array over ``(x, y, z, rx, ry, rz)``.

    Args:
        mask: None (the full pose); a sequence of 6 booleans; a string or sequence of
            axis names (``"xyz"``, ``"x y z rz"``, ``["x", "y", "z", "rz"]``); or the
            shorthands ``"pose"``, ``"position"``. Rotation rows are the components
            of the rotation error vector in the base frame, so ``"rz"`` is the yaw
            about the base z axis (a SCARA's or palletizer's tool angle).

    Raises:
        InputError: an unknown axis name, a wrong length, or no axis selected.
    """
    if mask is None:
        return np.ones(6, dtype=bool)
    key = mask if isinstance(mask, str) else None
    if key is not None and key in _MASK_CACHE:
        return _MASK_CACHE[key]
    if isinstance(mask, str):
        s = mask.strip().lower()
        if s in ("pose", "full", "all"):
            out = np.ones(6, dtype=bool)
        elif s in ("position", "pos"):
            out = np.array([1, 1, 1, 0, 0, 0], dtype=bool)
        else:
            names = s.replace(",", " ").split()
            tokens: list[str] = []
            for word in names:  # "xyzrz" -> x y z rz
                i = 0
                while i < len(word):
                    if word[i] == "r" and i + 1 < len(word):
                        tokens.append(word[i:i + 2])
                        i += 2
                    else:
                        tokens.append(word[i])
                        i += 1
            out = _mask_from_names(tokens, mask)
        _MASK_CACHE[key] = out
        return out
    arr = np.asarray(mask)
    if arr.dtype.kind in "US" or (arr.dtype == object and arr.size and isinstance(
            arr.flat[0], str)):
        return _mask_from_names([str(a).lower() for a in arr.ravel()], mask)
    if arr.shape != (6,) or arr.dtype.kind not in "biuf":
        raise InputError(
            "mask", f"expected 6 booleans over (x, y, z, rx, ry, rz) or axis names, "
            f"got {mask!r:.80}"
        )
    out = arr.astype(bool)
    if not out.any():
        raise InputError("mask", "selects no task axis")
    return out


def _mask_from_names(tokens: Sequence[str], original: Any) -> np.ndarray:
    out = np.zeros(6, dtype=bool)
    for t in tokens:
        if t not in _AXES:
            raise InputError(
                "mask", f"unknown axis {t!r} in {original!r:.60}; expected names from "
                f"{list(_AXES)}, 'pose' or 'position'"
            )
        out[_AXES.index(t)] = True
    if not out.any():
        raise InputError("mask", "selects no task axis")
    return out


_OPTS_CACHE: dict[Any, np.ndarray] = {}


def _opts(mask: Any, weights: Any, tol: Any, tol_rotation: Any, max_iterations: Any,
          max_step: Any) -> np.ndarray:
    """The kernel option vector (a fresh copy; cached for hashable arguments)."""
    key = None
    if weights is None and (mask is None or isinstance(mask, str)):
        key = (mask, tol, tol_rotation, max_iterations, max_step)
        try:
            hit = _OPTS_CACHE.get(key)
        except TypeError:
            key = hit = None
        if hit is not None:
            again: np.ndarray = hit.copy()
            return again
    opts = _make_opts(mask, weights, tol, tol_rotation, max_iterations, max_step)
    if key is not None and len(_OPTS_CACHE) < 256:
        _OPTS_CACHE[key] = opts.copy()
    return opts


def _make_opts(mask: Any, weights: Any, tol: Any, tol_rotation: Any,
               max_iterations: Any, max_step: Any) -> np.ndarray:
    m = parse_mask(mask)
    if weights is None:
        w = np.ones(6)
    else:
        w = np.asarray(weights, dtype=np.float64)
        if w.shape == (2,):
            w = np.repeat(w, 3)
        if w.shape != (6,) or not np.all(np.isfinite(w)) or np.any(w <= 0):
            raise InputError(
                "weights", "expected 6 positive weights over (x, y, z, rx, ry, rz) "
                f"or 2 (position [1/m^2], rotation [1/rad^2]), got {weights!r:.80}"
            )
    tol_p = _positive(tol, "tol")
    tol_r = tol_p if tol_rotation is None else _positive(tol_rotation, "tol_rotation")
    opts = np.zeros(K.N_OPTS)
    opts[K.O_W:K.O_W + 6] = np.where(m, w, 0.0)
    opts[K.O_TOL_P] = tol_p
    opts[K.O_TOL_R] = tol_r
    opts[K.O_MAX_ITER] = _count(max_iterations, "max_iterations", minimum=1)
    opts[K.O_MAX_STEP] = _positive(max_step, "max_step")
    opts[K.O_PATH_MAX_JUMP] = np.inf
    opts[K.O_STALL_EVERY] = _STALL_EVERY
    opts[K.O_STALL_RATIO] = _STALL_RATIO
    opts[K.O_MU0] = _MU0
    opts[K.O_MU_DOWN] = _MU_DOWN
    opts[K.O_MU_UP] = _MU_UP
    opts[K.O_SEED_SHRINK] = _SEED_SHRINK
    # the seed table is searched by position (and rotation when all of it is asked)
    opts[K.O_TABLE_ROT] = -1.0 if not m[:3].all() else (_TABLE_ROT if m[3:].all() else 0.0)
    opts[K.O_N_TABLE] = 0
    return opts


def _positive(x: Any, name: str) -> float:
    try:
        v = float(x)
    except (TypeError, ValueError) as exc:
        raise InputError(name, f"expected a positive number, got {x!r:.60}") from exc
    if not v > 0.0:
        raise InputError(name, f"expected a positive number, got {x!r:.60}")
    return v


def _count(x: Any, name: str, minimum: int = 0) -> int:
    if isinstance(x, bool | np.bool_) or not isinstance(x, int | np.integer):
        raise InputError(name, f"expected an integer >= {minimum}, got {x!r:.60}")
    if x < minimum:
        raise InputError(name, f"expected an integer >= {minimum}, got {x}")
    return int(x)


def _targets(T: npt.ArrayLike) -> tuple[np.ndarray, tuple[int, ...]]:
    if type(T) is not np.ndarray or T.dtype != np.float64:
        T = _real_array(T, "T", "a 4x4 matrix")
    if T.ndim < 2 or T.shape[-2:] != (4, 4):
        raise InputError("T", f"expected shape (..., 4, 4), got {T.shape}")
    lead = T.shape[:-2]
    return np.ascontiguousarray(T.reshape(-1, 4, 4)), lead


def _bad_input(out: np.ndarray, n: int, Tf: np.ndarray, Q0: np.ndarray,
               lead: tuple[int, ...], i: int, per: int = 1) -> InputError:
    if out[i, n + K.R_CODE] == K.CODE_BAD_Q0:
        check_finite(Q0, "q0")  # raises, naming the index
    return _bad_target(Tf, lead, i // per)


def _bad_target(Tf: np.ndarray, lead: tuple[int, ...], i: int) -> InputError:
    """The error naming target ``i`` (flat) the compiled solver refused."""
    try:
        check_transform(Tf.reshape(lead + (4, 4)) if lead else Tf[0], "T")
    except InputError as exc:
        return exc
    return InputError("T", f"target {i} is not a rigid transform")  # pragma: no cover


# ------------------------------------------------------------------------- solve
def solve(
    robot: ArmSource,
    T: npt.ArrayLike,
    *,
    q0: npt.ArrayLike | None = None,
    mask: Any = None,
    weights: npt.ArrayLike | None = None,
    tol: float = 1e-9,
    tol_rotation: float | None = None,
    max_iterations: int = 100,
    max_restarts: int = 200,
    max_time: float | None = None,
    max_step: float = 1.0,
    parallel: bool | None = None,
    rng: np.random.Generator | None = None,
) -> IKResult:
    """One joint solution per target pose, by damped least squares with restarts.

    Args:
        robot: The arm (a :class:`~robokin.robot.Robot` or its ``Arm``).
        T: Target tool poses in the world frame, shape (..., 4, 4) [m].
        q0: Initial guess (..., n) or (n,) [rad, m]; default the middle of the
            limits (angles clipped to [-pi, pi]).
        mask: Which task rows to meet, see :func:`parse_mask` (e.g. ``"xyz"`` for
            position only, ``"xyz rz"`` for position + yaw); default the full pose.
        weights: Task weights, 6 values over (x, y, z, rx, ry, rz) or 2 (position,
            rotation): the exchange rate between metres and radians in the cost
            ``e^T W e``. Default all ones.
        tol: Convergence tolerance on the position error norm [m] (and on the
            rotation error norm [rad] unless ``tol_rotation`` is given).
        tol_rotation: Tolerance on the rotation error norm [rad].
        max_iterations: Iterations per descent (restarts get their own).
        max_restarts: Restarts per target after the first descent (the first 4
            from the seed-table configurations nearest the target when the mask
            selects all of x, y, z; then random seeds).
        max_time: Wall-time budget per target [s] (a batch gets ``N * max_time``);
            None for no limit. Checked between rounds of restarts.
        max_step: Largest joint change per iteration [rad or m].
        parallel: Use all threads (default: for 8 targets or more, and for rounds
            of restarts of 2 targets or more). Results do not depend on it.
        rng: Random generator keying the restart seeds (one number drawn per call).
            Default None: each target's restarts come from its own pose and start
            configuration only, so the same inputs give the same bits, whatever
            the batch around a target and the thread count (``max_time`` aside: a
            search stopped by the clock depends on the machine's speed).

    Returns:
        An :class:`IKResult` with leading shape (...). Failure is reported, never
        raised: ``success`` False, the best ``q`` found and the error reached.

    Raises:
        InputError: a bad pose (wrong shape, non-finite, not a rigid transform), a
            bad ``q0`` or option.
    """
    return _solve(arm_of(robot), T, q0=q0, mask=mask, weights=weights, tol=tol,
                  tol_rotation=tol_rotation, max_iterations=max_iterations,
                  max_restarts=max_restarts, max_time=max_time, max_step=max_step,
                  parallel=parallel, key=_seed_key(rng))


def _solve(
    arm: Arm,
    T: npt.ArrayLike,
    *,
    q0: npt.ArrayLike | None,
    mask: Any,
    weights: npt.ArrayLike | None,
    tol: float,
    tol_rotation: float | None,
    max_iterations: int,
    max_restarts: int,
    max_time: float | None,
    max_step: float,
    parallel: bool | None,
    key: int,
) -> IKResult:
    """:func:`solve` with the restart streams' key (``_seed_key``)."""
    chain = arm.chain
    packed = chain.arrays.packed
    n = chain.n
    Tf, lead = _targets(T)
    N = Tf.shape[0]
    opts = _opts(mask, weights, tol, tol_rotation, max_iterations, max_step)
    max_restarts = _count(max_restarts, "max_restarts")
    if max_time is not None:
        max_time = _positive(max_time, "max_time")
    t_start = _clock()
    if q0 is None:
        Q0 = np.broadcast_to(_middle(chain), (N, n))
    else:
        q0 = check_joints(q0, n, "q0")  # finiteness: checked by the kernel
        if q0.shape == (n,) and N == 1:
            Q0 = q0.reshape(1, n)
        else:
            Q0 = np.broadcast_to(check_broadcasts(q0, lead + (n,), "q0"),
                                 lead + (n,)).reshape(N, n)
    if not Q0.flags.c_contiguous:
        Q0 = np.ascontiguousarray(Q0)
    out = np.empty((N, n + K.N_RES))
    if N == 0:
        return _result(out, lead, n, None)
    use_par = N >= _PARALLEL_MIN if parallel is None else bool(parallel)
    R = min(max_restarts, _FIRST_ROUND_RESTARTS)
    opts[K.O_USE_Q0] = 1.0
    opts[K.O_N_SEEDS] = R
    if R and opts[K.O_TABLE_ROT] >= 0.0:
        opts[K.O_N_TABLE] = _TABLE_SEEDS
        tab = seed_table(arm).kernel_args()
    else:
        tab = _NO_TABLE
    # random numbers only when some restart of this round is not a table one (the
    # table always has more rows than _TABLE_SEEDS)
    seeds = (_uniforms(Tf, Q0, key, 0, R) if opts[K.O_N_TABLE] < R
             else np.zeros((N, max(R, 1), n)))
    fails, bad = K.lm_solve(packed, Tf, Q0, seeds, opts, out, *tab, use_par)
    if bad >= 0:
        raise _bad_input(out, n, Tf, Q0, lead, bad)
    if fails == 0:
        return _result(out, lead, n, None)
    timed_out = np.zeros(N, dtype=bool)
    used = out[:, n + K.R_RESTARTS].copy()
    todo = np.flatnonzero(out[:, n + K.R_CODE] != K.CODE_OK)
    if todo.size and max_restarts > R:
        deadline = None if max_time is None else t_start + max_time * N
        opts[K.O_USE_Q0] = 0.0
        opts[K.O_N_TABLE] = 0
        while todo.size:
            if deadline is not None and _clock() >= deadline:
                timed_out[todo] = True
                break
            left = max_restarts - int(used[todo[0]])
            if left <= 0:
                break
            R = min(left, _ROUND_RESTARTS)
            opts[K.O_N_SEEDS] = R
            sub = np.empty((todo.size, n + K.N_RES))
            par = bool((parallel is None and todo.size >= _PARALLEL_MIN_RESTARTS)
                       or parallel)
            # each target continues its own stream: numbers used[i] on (a target
            # left here has spent every restart it was given, the same count)
            seeds = np.empty((todo.size, R, n))
            for base in np.unique(used[todo]):
                rows = used[todo] == base
                seeds[rows] = _uniforms(Tf[todo[rows]], Q0[todo[rows]], key, int(base), R)
            K.lm_solve(packed, Tf[todo], Q0[todo], seeds, opts, sub, *_NO_TABLE, par)
            attempts = sub[:, n + K.R_RESTARTS] + 1
            used[todo] += attempts
            out[todo, n + K.R_ITERS] += sub[:, n + K.R_ITERS]
            better = (sub[:, n + K.R_CODE] == K.CODE_OK) | (
                sub[:, n + K.R_ERR] < out[todo, n + K.R_ERR])
            rows = todo[better]
            keep_iters = out[rows, n + K.R_ITERS].copy()
            out[rows] = sub[better]
            out[rows, n + K.R_ITERS] = keep_iters
            todo = todo[out[todo, n + K.R_CODE] != K.CODE_OK]
    out[:, n + K.R_RESTARTS] = used
    return _result(out, lead, n, timed_out)


def _result(out: np.ndarray, lead: tuple[int, ...], n: int,
            timed_out: np.ndarray | None) -> IKResult:
    if not lead and out[0, n + K.R_CODE] == K.CODE_OK:
        row = out[0, n:].tolist()
        return IKResult(
            q=out[0, :n], success=np.True_, error=row[K.R_ERR],
            iterations=int(row[K.R_ITERS]), restarts=int(row[K.R_RESTARTS]),
            reason="converged", position_error=row[K.R_EP], rotation_error=row[K.R_ER],
        )
    code = out[:, n + K.R_CODE]
    success = code == K.CODE_OK
    reason = np.empty(out.shape[0], dtype=object)
    reason[:] = "converged"
    for i in np.flatnonzero(~success):
        why = ("time budget exhausted" if timed_out is not None and timed_out[i] else
               "restart budget exhausted")
        last = "stalled in a local minimum or at joint limits" \
            if code[i] == K.CODE_STALL else "iteration budget of the last descent spent"
        reason[i] = (
            f"not converged: error {out[i, n + K.R_ERR]:.3g} (position "
            f"{out[i, n + K.R_EP]:.3g} m, rotation {out[i, n + K.R_ER]:.3g} rad) after "
            f"{int(out[i, n + K.R_RESTARTS])} restart(s); {why} ({last})"
        )
    if not lead:
        row = out[0, n:].tolist()
        return IKResult(
            q=out[0, :n], success=np.bool_(success[0]), error=row[K.R_ERR],
            iterations=int(row[K.R_ITERS]), restarts=int(row[K.R_RESTARTS]),
            reason=reason[0], position_error=row[K.R_EP], rotation_error=row[K.R_ER],
        )
    return IKResult(
        q=out[:, :n].reshape(lead + (n,)),
        success=success.reshape(lead),
        error=out[:, n + K.R_ERR].reshape(lead),
        iterations=out[:, n + K.R_ITERS].astype(np.int64).reshape(lead),
        restarts=out[:, n + K.R_RESTARTS].astype(np.int64).reshape(lead),
        reason=reason.reshape(lead),
        position_error=out[:, n + K.R_EP].reshape(lead),
        rotation_error=out[:, n + K.R_ER].reshape(lead),
    )


# --------------------------------------------------------------------- solve_all
_SOLVE_ALL_OPTIONS = frozenset(
    {"mask", "weights", "tol", "tol_rotation", "max_iterations", "max_restarts",
     "max_time", "max_step", "parallel", "rng", "dedupe_tol"}
)


def solve_all(
    robot: ArmSource,
    T: npt.ArrayLike,
    *,
    q_near: npt.ArrayLike | None = None,
    n_seeds: int = 16,
    **options: Any,
) -> SolutionSet:
    """The distinct solutions that descents from many seeds find, as a SolutionSet.

    Every target gets ``n_seeds`` independent descents (from ``q_near`` first when
    given, then random seeds inside the limits); converged results are
    deduplicated with revolute angles compared modulo 2*pi (``dedupe_tol``,
    default 1e-6). A target none of them reaches gets up to ``max_restarts`` more
    random restarts. Solutions are ordered by distance to ``q_near`` when given.
    Periodic angles are reported in [-pi, pi) when that stays inside the limits.

    For a redundant arm (more joints than task rows) the solutions form a
    continuum: the set is a sample of it.

    Args:
        robot: The arm (a :class:`~robokin.robot.Robot` or its ``Arm``).
        T: Target poses (..., 4, 4) [m].
        q_near: Current configuration (..., n) or (n,), the first seed.
        n_seeds: Descents per target.
        **options: ``mask``, ``weights``, ``tol``, ``tol_rotation``,
            ``max_iterations``, ``max_restarts`` (default 200), ``max_time``,
            ``max_step``, ``parallel``, ``rng`` as in :func:`solve`, and
            ``dedupe_tol`` [rad, m].

    Returns:
        The solution set (:class:`~robokin.kinematics.ik.solutions.SolutionSet`),
        ``method="numeric"``; per-pose ``status`` says why a pose has none.

    Raises:
        InputError: an unknown option (the message lists the accepted ones), a bad
            pose, ``q_near`` or option value.
    """
    from robokin.kinematics.ik.solutions import SolutionSet, wrap_angle

    unknown = sorted(set(options) - _SOLVE_ALL_OPTIONS)
    if unknown:
        raise InputError(
            "options", f"unknown option(s) {unknown} for the numeric IK solver; accepted: "
            f"n_seeds, q_near, {', '.join(sorted(_SOLVE_ALL_OPTIONS))}"
        )
    arm = arm_of(robot)
    chain = arm.chain
    arr = chain.arrays
    n = chain.n
    wrap = arr.wrap == 1.0
    n_seeds = _count(n_seeds, "n_seeds", minimum=1)
    dedupe_tol = _positive(options.pop("dedupe_tol", 1e-6), "dedupe_tol")
    max_restarts = _count(options.get("max_restarts", 200), "max_restarts")
    Tf, lead = _targets(T)
    N = Tf.shape[0]
    key = _seed_key(options.get("rng"))
    opts = _opts(options.get("mask"), options.get("weights"), options.get("tol", 1e-9),
                 options.get("tol_rotation"), options.get("max_iterations", 100),
                 options.get("max_step", 1.0))
    lim = arr.limits
    is_rev = np.asarray(chain.is_revolute, dtype=bool)
    if N == 0:
        return SolutionSet.empty(lead, n, is_rev, lim, "no solution", method="numeric")
    S = n_seeds
    # each target's seeds from its own stream, keyed by its pose and q_near
    start = np.broadcast_to(_middle(chain), (N, n))
    if q_near is not None:
        qn = check_finite(check_joints(q_near, n, "q_near"), "q_near")
        check_broadcasts(qn, lead + (n,), "q_near")
        start = np.broadcast_to(qn, lead + (n,)).reshape(N, n)
    seeds = arr.seed_lower + _uniforms(Tf, start, key, 0, S) * (arr.seed_upper
                                                                - arr.seed_lower)
    if q_near is not None:
        seeds[:, 0] = start
    flatT = np.ascontiguousarray(np.repeat(Tf, S, axis=0))
    flatQ = np.ascontiguousarray(seeds.reshape(N * S, n))
    opts[K.O_USE_Q0] = 1.0
    opts[K.O_N_SEEDS] = 0
    out = np.empty((N * S, n + K.N_RES))
    par = options.get("parallel")
    use_par = N * S >= _PARALLEL_MIN if par is None else bool(par)
    _, bad = K.lm_solve(arr.packed, flatT, flatQ, np.empty((N * S, 1, n)), opts, out,
                        *_NO_TABLE, use_par)
    if bad >= 0:
        raise _bad_input(out, n, Tf, flatQ, lead, bad, per=S)
    out = out.reshape(N, S, n + K.N_RES)
    q = out[..., :n].copy()
    ok = out[..., n + K.R_CODE] == K.CODE_OK
    err = out[..., n + K.R_ERR].copy()
    # rescue targets no seed reached with the restarting solver
    none = np.flatnonzero(~ok.any(axis=1))
    best_err = err.min(axis=1)
    if none.size and max_restarts > 0:
        res = _solve(arm, Tf[none], q0=q[none, np.argmin(err[none], axis=1)],
                     mask=options.get("mask"), weights=options.get("weights"),
                     tol=options.get("tol", 1e-9), tol_rotation=options.get("tol_rotation"),
                     max_iterations=options.get("max_iterations", 100),
                     max_restarts=max_restarts, max_time=options.get("max_time"),
                     max_step=options.get("max_step", 1.0), parallel=par, key=key)
        q[none, 0] = res.q
        ok[none, 0] = res.success
        err[none, 0] = res.error
        best_err[none] = np.minimum(best_err[none], res.error)
    # report periodic angles in [-pi, pi) where that stays inside the limits
    wrapped = wrap_angle(q)
    inside = (wrapped >= lim[:, 0]) & (wrapped <= lim[:, 1])
    q = np.where(wrap & inside, wrapped, q)
    # deduplicate: row j is a copy if an earlier valid row is within dedupe_tol
    # (one seed at a time: memory O(N S n), not O(N S^2 n))
    dup = np.zeros((N, S), dtype=bool)
    for j in range(1, S):
        diff = q[:, :j] - q[:, j:j + 1]
        diff = np.where(wrap, wrap_angle(diff), diff)
        dup[:, j] = ((np.abs(diff).max(axis=-1) <= dedupe_tol) & ok[:, :j]).any(axis=1)
    keep = ok & ~dup
    if q_near is not None:
        d = q - seeds[:, :1]
        d = np.where(wrap, wrap_angle(d), d)
        rank = np.where(keep, np.linalg.norm(d, axis=-1), np.inf)
    else:
        rank = np.where(keep, np.arange(S, dtype=np.float64), np.inf)
    order = np.argsort(rank, axis=1, kind="stable")
    k = max(int(keep.sum(axis=1).max()), 1)
    order = order[:, :k]
    q = np.take_along_axis(q, order[..., None], axis=1)
    valid = np.take_along_axis(keep, order, axis=1)
    err = np.take_along_axis(err, order, axis=1)
    q = np.where(valid[..., None], q, 0.0)
    status = np.empty(N, dtype=object)
    status[:] = "ok"
    for i in np.flatnonzero(~valid.any(axis=1)):
        status[i] = (f"no solution found from {S} seeds and {max_restarts} restarts "
                     f"(best error {best_err[i]:.3g})")
    info = {"n_seeds": S, "mask": _mask_names(opts), "tol": float(opts[K.O_TOL_P])}
    return SolutionSet(
        q.reshape(lead + (k, n)), valid.reshape(lead + (k,)), is_rev, lim,
        status=status.reshape(lead), method="numeric", error=err.reshape(lead + (k,)),
        info=info,
    )


def _mask_names(opts: np.ndarray) -> str:
    return " ".join(a for a, w in zip(_AXES, opts[:6], strict=True) if w > 0)


# -------------------------------------------------------------------------- ik_path
def ik_path(
    robot: ArmSource,
    T_path: npt.ArrayLike,
    q_start: npt.ArrayLike,
    *,
    mask: Any = None,
    weights: npt.ArrayLike | None = None,
    tol: float = 1e-9,
    tol_rotation: float | None = None,
    max_iterations: int = 200,
    max_step: float = 0.2,
    max_jump: float = 0.5,
) -> IKPathResult:
    """Joint path through a sequence of poses, each solve warm-started from the last.

    No random restarts: every sample starts from the previous solution (the first
    from ``q_start``) with a small step cap, so the solver stays on the branch it
    started on and a Cartesian line becomes a continuous joint motion. The path
    stops at the first sample that does not converge or whose joints move more
    than ``max_jump`` from the previous sample (a branch jump, or a path sampled
    too coarsely near a singularity).

    Args:
        robot: The arm (a :class:`~robokin.robot.Robot` or its ``Arm``).
        T_path: Poses (m, 4, 4) [m].
        q_start: Configuration (n,) the path starts from [rad, m].
        mask: Task rows, see :func:`parse_mask`.
        weights: Task weights, as in :func:`solve`.
        tol: Position tolerance [m] (and rotation [rad] unless ``tol_rotation``).
        tol_rotation: Rotation tolerance [rad].
        max_iterations: Iterations per sample.
        max_step: Largest joint change per iteration [rad or m].
        max_jump: Largest joint change between consecutive samples [rad or m].

    Returns:
        An :class:`IKPathResult`.

    Raises:
        InputError: bad poses (shape (m, 4, 4), rigid), ``q_start`` or options.
    """
    arm = arm_of(robot)
    chain = arm.chain
    n = chain.n
    Tf, lead = _targets(T_path)
    if len(lead) != 1:
        raise InputError("T_path", f"expected shape (m, 4, 4), got {lead + (4, 4)}")
    q_start = check_finite(check_joints(q_start, n, "q_start"), "q_start")
    if q_start.shape != (n,):
        raise InputError("q_start", f"expected shape ({n},), got {q_start.shape}")
    opts = _opts(mask, weights, tol, tol_rotation, max_iterations, max_step)
    opts[K.O_USE_Q0] = 1.0
    opts[K.O_N_SEEDS] = 0
    opts[K.O_PATH_MAX_JUMP] = _positive(max_jump, "max_jump")
    m = Tf.shape[0]
    out = np.empty((m, n + K.N_RES))
    first = int(K.lm_path(chain.arrays.packed, Tf, np.ascontiguousarray(q_start), opts,
                          out)) if m else -1
    code = out[:, n + K.R_CODE]
    if first >= 0 and code[first] == K.CODE_BAD_TARGET:
        raise _bad_target(Tf, lead, first)
    success = code == K.CODE_OK
    if first < 0:
        reason = "converged"
    elif code[first] == K.CODE_JUMP:
        prev = q_start if first == 0 else out[first - 1, :n]
        d = np.abs(out[first, :n] - prev)
        j = int(np.argmax(d))
        reason = (f"sample {first}: joint {j + 1} would move {d[j]:.3g} "
                  f"(max_jump {max_jump:g}): a branch jump or a path sampled too "
                  "coarsely; sample it more finely or raise max_jump")
    else:
        reason = (f"sample {first}: not converged (error {out[first, n + K.R_ERR]:.3g}) "
                  f"warm-started from sample {first - 1}" if first else
                  f"sample 0: not converged from q_start (error "
                  f"{out[first, n + K.R_ERR]:.3g})")
    return IKPathResult(
        q=out[:, :n].copy(),
        success=success,
        error=out[:, n + K.R_ERR].copy(),
        first_failure=None if first < 0 else first,
        reason=reason,
    )
