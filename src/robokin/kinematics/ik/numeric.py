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
from the whole range) until the target is reached or the budget (restarts, wall
time) is spent. The random seeds come from the inputs, not from a generator's
state: each target's from a counter-based stream keyed by a hash of its pose and
start configuration (:mod:`~robokin.kinematics.ik.restart_seeds`; an explicit
``rng`` changes the key), so the same call gives the same bits whatever the batch
around a target and the thread count (see ``docs/conventions.md``,
Repeatability). Results are always inside the limits;
a target that is not reached comes back with ``success=False``, the best
configuration found and the error it leaves, never an exception.

Convergence means the norm of the selected position rows is at most ``tol`` [m]
and that of the selected rotation rows at most ``tol_rotation`` [rad] (default
``tol``), both 1e-9 by default.

The descents run compiled (``robokin/_native/csrc/lm.c``), four targets per vector,
on every thread for batches; a single target runs the same code in one lane. The
option vector and the input checks are :mod:`~robokin.kinematics.ik.lm_options`',
the result records :mod:`~robokin.kinematics.ik.numeric_result`'s.

References:
    Sugihara, T. "Solvability-unconcerned inverse kinematics by the
    Levenberg-Marquardt method", IEEE Trans. Robotics 27(5), 2011 (the
    error-scaled damping ``lambda = E + ...``, eq. 20).
    Nocedal, J. and Wright, S. "Numerical Optimization", 2nd ed., ch. 10.3
    (Levenberg-Marquardt) and 16.7 (active sets for bounds).
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from robokin import _native
from robokin._validation import check_broadcasts, check_finite, check_joints
from robokin.exceptions import InputError
from robokin.kinematics.arm import Arm, ArmSource, arm_of
from robokin.kinematics.ik import lm_options, restart_seeds
from robokin.kinematics.ik.lm_options import parse_mask
from robokin.kinematics.ik.numeric_result import IKPathResult, IKResult, ik_result
from robokin.model.chain import Chain

if TYPE_CHECKING:
    from robokin.kinematics.ik.solutions import SolutionSet

__all__ = ["IKPathResult", "IKResult", "ik_path", "parse_mask", "solve", "solve_all"]

# below this many targets one thread beats the parallel launch (~3 us; a first
# descent costs ~5 us, a round of 16 restarts ~100 us)
_PARALLEL_MIN = 8
_PARALLEL_MIN_RESTARTS = 2
_FIRST_ROUND_RESTARTS = 4
_ROUND_RESTARTS = 16

K = _native.kernels  # the compiled solver, its option indices and result columns
_clock = time.perf_counter  # the clock max_time is measured on (tests replace it)



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
    options = lm_options.option_vector(mask, weights, tol, tol_rotation,
                                       max_iterations, max_step)
    return _solve(arm_of(robot), T, q0, options, max_restarts, max_time, parallel,
                  restart_seeds.seed_key(rng))


def _solve(arm: Arm, T: npt.ArrayLike, q0: npt.ArrayLike | None, opts: np.ndarray,
           max_restarts: int, max_time: float | None, parallel: bool | None,
           key: int) -> IKResult:
    """:func:`solve` with its option vector and the restart streams' key.

    ``opts`` comes from ``lm_options.option_vector`` (this writes to it), ``key``
    from ``restart_seeds.seed_key``.
    """
    chain = arm.chain
    n = chain.n
    Tf, lead = lm_options.flat_targets(T)
    N = Tf.shape[0]
    max_restarts = lm_options.check_count(max_restarts, "max_restarts")
    if max_time is not None:
        max_time = lm_options.check_positive(max_time, "max_time")
    t_start = _clock()
    Q0 = _start(chain, q0, lead, N)
    out = np.empty((N, n + K.N_RES))
    if N == 0:
        return ik_result(out, lead, n, None)
    # the first round: a descent from Q0, then up to 4 restarts (seed table first)
    use_par = N >= _PARALLEL_MIN if parallel is None else bool(parallel)
    R = min(max_restarts, _FIRST_ROUND_RESTARTS)
    opts[K.O_USE_Q0] = 1.0
    opts[K.O_N_SEEDS] = R
    if R and opts[K.O_TABLE_ROT] >= 0.0:
        opts[K.O_N_TABLE] = restart_seeds.TABLE_SEEDS
        tab = restart_seeds.seed_table(arm).kernel_args()
    else:
        tab = restart_seeds.NO_TABLE
    # random numbers only when some restart of this round is not a table one (the
    # table always has more rows than TABLE_SEEDS)
    seeds = (restart_seeds.uniforms(Tf, Q0, key, 0, R) if opts[K.O_N_TABLE] < R
             else np.zeros((N, max(R, 1), n)))
    fails, bad = K.lm_solve(chain.arrays.packed, Tf, Q0, seeds, opts, out, *tab, use_par)
    if bad >= 0:
        raise lm_options.bad_input(out, n, Tf, Q0, lead, bad)
    if fails == 0:
        return ik_result(out, lead, n, None)
    timed_out = np.zeros(N, dtype=bool)
    used = out[:, n + K.R_RESTARTS].copy()
    if max_restarts > R:
        deadline = None if max_time is None else t_start + max_time * N
        _restart_rounds(chain, Tf, Q0, opts, out, used, timed_out,
                        max_restarts=max_restarts, deadline=deadline,
                        parallel=parallel, key=key)
    out[:, n + K.R_RESTARTS] = used
    return ik_result(out, lead, n, timed_out)


def _start(chain: Chain, q0: npt.ArrayLike | None, lead: tuple[int, ...],
           N: int) -> np.ndarray:
    """The start configurations (N, n), C-contiguous.

    ``q0`` broadcast to the targets' leading shape ``lead``, or the middle of the
    seed ranges.
    """
    n = chain.n
    if q0 is None:
        Q0 = np.broadcast_to(restart_seeds.middle(chain), (N, n))
    else:
        q0 = check_joints(q0, n, "q0")  # finiteness: checked by the kernel
        if q0.shape == (n,) and N == 1:
            Q0 = q0.reshape(1, n)
        else:
            Q0 = np.broadcast_to(check_broadcasts(q0, lead + (n,), "q0"),
                                 lead + (n,)).reshape(N, n)
    if not Q0.flags.c_contiguous:
        Q0 = np.ascontiguousarray(Q0)
    return Q0


def _restart_rounds(chain: Chain, Tf: np.ndarray, Q0: np.ndarray, opts: np.ndarray,
                    out: np.ndarray, used: np.ndarray, timed_out: np.ndarray, *,
                    max_restarts: int, deadline: float | None, parallel: bool | None,
                    key: int) -> None:
    """Rounds of up to 16 random restarts for the targets the first round missed.

    Updates in place ``out`` (the best row of each target, iterations summed),
    ``used`` (restarts per target) and ``timed_out`` (targets stopped by the clock).
    Each target continues its own seed stream: numbers ``used[i]`` on.
    """
    n = chain.n
    packed = chain.arrays.packed
    todo = np.flatnonzero(out[:, n + K.R_CODE] != K.CODE_OK)
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
        # (a target left here has spent every restart it was given, the same count:
        # one call for all, without np.unique's cost per round of a single solve)
        Tt, Qt, base = Tf[todo], Q0[todo], used[todo]
        if todo.size == 1 or (base == base[0]).all():
            seeds = restart_seeds.uniforms(Tt, Qt, key, int(base[0]), R)
        else:
            seeds = np.empty((todo.size, R, n))
            for b in np.unique(base):
                rows = base == b
                seeds[rows] = restart_seeds.uniforms(Tt[rows], Qt[rows], key, int(b), R)
        K.lm_solve(packed, Tt, Qt, seeds, opts, sub, *restart_seeds.NO_TABLE, par)
        used[todo] += sub[:, n + K.R_RESTARTS] + 1
        out[todo, n + K.R_ITERS] += sub[:, n + K.R_ITERS]
        better = (sub[:, n + K.R_CODE] == K.CODE_OK) | (
            sub[:, n + K.R_ERR] < out[todo, n + K.R_ERR])
        rows = todo[better]
        keep_iters = out[rows, n + K.R_ITERS].copy()
        out[rows] = sub[better]
        out[rows, n + K.R_ITERS] = keep_iters
        todo = todo[out[todo, n + K.R_CODE] != K.CODE_OK]


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
    from robokin.kinematics.ik.solutions import SolutionSet

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
    S = lm_options.check_count(n_seeds, "n_seeds", minimum=1)
    dedupe_tol = lm_options.check_positive(options.pop("dedupe_tol", 1e-6), "dedupe_tol")
    max_restarts = lm_options.check_count(options.get("max_restarts", 200), "max_restarts")
    Tf, lead = lm_options.flat_targets(T)
    N = Tf.shape[0]
    is_rev = np.asarray(chain.is_revolute, dtype=bool)
    key = restart_seeds.seed_key(options.get("rng"))
    opts = lm_options.option_vector(
        options.get("mask"), options.get("weights"), options.get("tol", 1e-9),
        options.get("tol_rotation"), options.get("max_iterations", 100),
        options.get("max_step", 1.0))
    if N == 0:
        return SolutionSet.empty(lead, n, is_rev, arr.limits, "no solution",
                                 method="numeric")
    # each target's seeds from its own stream, keyed by its pose and q_near
    start = np.broadcast_to(restart_seeds.middle(chain), (N, n))
    if q_near is not None:
        qn = check_finite(check_joints(q_near, n, "q_near"), "q_near")
        check_broadcasts(qn, lead + (n,), "q_near")
        start = np.broadcast_to(qn, lead + (n,)).reshape(N, n)
    seeds = arr.seed_lower + restart_seeds.uniforms(Tf, start, key, 0, S) * (
        arr.seed_upper - arr.seed_lower)
    if q_near is not None:
        seeds[:, 0] = start
    par = options.get("parallel")
    q, ok, err = _descents(chain, Tf, seeds, opts.copy(), lead, par)
    # rescue targets no seed reached with the restarting solver
    none = np.flatnonzero(~ok.any(axis=1))
    best_err = err.min(axis=1)
    if none.size and max_restarts > 0:
        res = _solve(arm, Tf[none], q[none, np.argmin(err[none], axis=1)], opts.copy(),
                     max_restarts, options.get("max_time"), par, key)
        q[none, 0] = res.q
        ok[none, 0] = res.success
        err[none, 0] = res.error
        best_err[none] = np.minimum(best_err[none], res.error)
    q, valid, err = _distinct(chain, q, ok, err, seeds[:, 0] if q_near is not None else None,
                              dedupe_tol)
    status = np.empty(N, dtype=object)
    status[:] = "ok"
    for i in np.flatnonzero(~valid.any(axis=1)):
        status[i] = (f"no solution found from {S} seeds and {max_restarts} restarts "
                     f"(best error {best_err[i]:.3g})")
    info = {"n_seeds": S, "mask": lm_options.mask_names(opts),
            "tol": float(opts[K.O_TOL_P])}
    k = q.shape[1]
    return SolutionSet(
        q.reshape(lead + (k, n)), valid.reshape(lead + (k,)), is_rev, arr.limits,
        status=status.reshape(lead), method="numeric",
        error=err.reshape(lead + (k,)), info=info,
    )


def _descents(chain: Chain, Tf: np.ndarray, seeds: np.ndarray, opts: np.ndarray,
              lead: tuple[int, ...], parallel: bool | None
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One descent (no restart) from each seed (N, S, n) towards its target Tf (N, 4, 4).

    Returns:
        q (N, S, n), converged (N, S) bool and the error reached (N, S).
    """
    N, S, n = seeds.shape
    flatT = np.ascontiguousarray(np.repeat(Tf, S, axis=0))
    flatQ = np.ascontiguousarray(seeds.reshape(N * S, n))
    opts[K.O_USE_Q0] = 1.0
    opts[K.O_N_SEEDS] = 0
    out = np.empty((N * S, n + K.N_RES))
    use_par = N * S >= _PARALLEL_MIN if parallel is None else bool(parallel)
    _, bad = K.lm_solve(chain.arrays.packed, flatT, flatQ, np.empty((N * S, 1, n)), opts,
                        out, *restart_seeds.NO_TABLE, use_par)
    if bad >= 0:
        raise lm_options.bad_input(out, n, Tf, flatQ, lead, bad, per=S)
    out = out.reshape(N, S, n + K.N_RES)
    return (out[..., :n].copy(), out[..., n + K.R_CODE] == K.CODE_OK,
            out[..., n + K.R_ERR].copy())


def _distinct(chain: Chain, q: np.ndarray, ok: np.ndarray, err: np.ndarray,
              near: np.ndarray | None, dedupe_tol: float
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The distinct converged rows of q (N, S, n), first, in order.

    Periodic angles are reported in [-pi, pi) where that stays inside the limits;
    a row within ``dedupe_tol`` of an earlier converged one (angles modulo 2*pi) is
    a copy. The rows are ordered by distance to ``near`` (N, n) when given, else
    kept in seed order, and cut to the largest count of any target.

    Returns:
        q (N, k, n) (zero where not valid), valid (N, k) bool, error (N, k).
    """
    from robokin.kinematics.ik.solutions import wrap_angle

    wrap = chain.arrays.wrap == 1.0
    lim = chain.arrays.limits
    S = q.shape[1]
    wrapped = wrap_angle(q)
    inside = (wrapped >= lim[:, 0]) & (wrapped <= lim[:, 1])
    q = np.where(wrap & inside, wrapped, q)
    # row j is a copy if an earlier valid row is within dedupe_tol (one seed at a
    # time: memory O(N S n), not O(N S^2 n))
    dup = np.zeros(ok.shape, dtype=bool)
    for j in range(1, S):
        diff = q[:, :j] - q[:, j:j + 1]
        diff = np.where(wrap, wrap_angle(diff), diff)
        dup[:, j] = ((np.abs(diff).max(axis=-1) <= dedupe_tol) & ok[:, :j]).any(axis=1)
    keep = ok & ~dup
    if near is not None:
        d = q - near[:, None]
        d = np.where(wrap, wrap_angle(d), d)
        rank = np.where(keep, np.linalg.norm(d, axis=-1), np.inf)
    else:
        rank = np.where(keep, np.arange(S, dtype=np.float64), np.inf)
    k = max(int(keep.sum(axis=1).max()), 1)
    order = np.argsort(rank, axis=1, kind="stable")[:, :k]
    q = np.take_along_axis(q, order[..., None], axis=1)
    valid = np.take_along_axis(keep, order, axis=1)
    err = np.take_along_axis(err, order, axis=1)
    return np.where(valid[..., None], q, 0.0), valid, err


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
    Tf, lead = lm_options.flat_targets(T_path)
    if len(lead) != 1:
        raise InputError("T_path", f"expected shape (m, 4, 4), got {lead + (4, 4)}")
    q_start = check_finite(check_joints(q_start, n, "q_start"), "q_start")
    if q_start.shape != (n,):
        raise InputError("q_start", f"expected shape ({n},), got {q_start.shape}")
    opts = lm_options.option_vector(mask, weights, tol, tol_rotation, max_iterations,
                                    max_step)
    opts[K.O_USE_Q0] = 1.0
    opts[K.O_N_SEEDS] = 0
    opts[K.O_PATH_MAX_JUMP] = lm_options.check_positive(max_jump, "max_jump")
    m = Tf.shape[0]
    out = np.empty((m, n + K.N_RES))
    first = int(K.lm_path(chain.arrays.packed, Tf, np.ascontiguousarray(q_start), opts,
                          out)) if m else -1
    code = out[:, n + K.R_CODE]
    if first >= 0 and code[first] == K.CODE_BAD_TARGET:
        raise lm_options.bad_target(Tf, lead, first)
    reason = _path_reason(out, n, first, q_start, max_jump)
    return IKPathResult(
        q=out[:, :n].copy(),
        success=code == K.CODE_OK,
        error=out[:, n + K.R_ERR].copy(),
        first_failure=None if first < 0 else first,
        reason=reason,
    )


def _path_reason(out: np.ndarray, n: int, first: int, q_start: np.ndarray,
                 max_jump: float) -> str:
    """Why the path of solver rows ``out`` stops at sample ``first`` (-1: it does not)."""
    if first < 0:
        return "converged"
    if out[first, n + K.R_CODE] == K.CODE_JUMP:
        prev = q_start if first == 0 else out[first - 1, :n]
        d = np.abs(out[first, :n] - prev)
        j = int(np.argmax(d))
        return (f"sample {first}: joint {j + 1} would move {d[j]:.3g} "
                f"(max_jump {max_jump:g}): a branch jump or a path sampled too "
                "coarsely; sample it more finely or raise max_jump")
    return (f"sample {first}: not converged (error {out[first, n + K.R_ERR]:.3g}) "
            f"warm-started from sample {first - 1}" if first else
            f"sample 0: not converged from q_start (error "
            f"{out[first, n + K.R_ERR]:.3g})")
