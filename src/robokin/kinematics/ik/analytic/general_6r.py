"""General 6R arms: every IK solution by Raghavan-Roth elimination.

Any arm of six revolute joints without dependent joints is solved completely, up
to 16 solutions, by the compiled kernel in ``robokin/_native/csrc/general6r.c``
(its header gives the elimination step by step): the loop-closure equations of a
split of the chain into three joints and the inverse of the other three give 14
equations (Raghavan & Roth 1993); eliminating two angles leaves a 12 x 12 matrix
``Sigma(theta_a)`` whose determinant, a trigonometric polynomial of degree 8, has
the solutions' ``theta_a`` as real roots (Manocha & Canny 1994). Every root is
back-substituted, polished by Newton steps on the true chain and kept only when it
reproduces the pose to ``1e-9`` (m and rad).

This module does the per-arm set-up, once per chain (kept in its ``Arm``):

* **fit**: the left side of each split is linear in 27 pose-independent monomials;
  their coefficients are fitted by least squares from rows the kernel computes
  (``general6r_fit_rows``), no symbolic derivation;
* **variant choice**: a variant is a split ``a`` in {1, 2, 3}, the chain or its
  reversal (the IK of ``T^-1`` on the reversed chain) and the dialytic multiplier
  (``x_b`` or ``x_c``), 12 in all. Arms with special geometry make some variants
  degenerate (a UR arm: only the split with the three parallel axes on the left
  works) or miss solutions that share ``theta_a`` (a wrist flip: a 2-D null space).
  Every variant runs on ``SETUP_POSES`` deterministic poses (from random joint
  values); the union of their validated solutions plus the generating
  configurations is the reference; the chosen pair (primary, secondary) finds all
  of it, the primary alone where it reports no trouble, with the smallest DFT tail.
  Per pose, the kernel runs the secondary when the primary's determinant is
  degenerate or one of its roots has a 2-D null space, and merges.

Arms with a prismatic joint or dependent joints are not offered this family (the
elimination is written for revolute joints), nor arms no variant pair solves.

References:
    Raghavan, M. and Roth, B. "Inverse kinematics of the general 6R manipulator and
    related linkages", J. Mech. Design 115(3):502-508, 1993.
    Manocha, D. and Canny, J. "Efficient inverse kinematics for general 6R
    manipulators", IEEE Trans. Robotics and Automation 10(5):648-657, 1994.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from robokin import _native
from robokin.kinematics.arm import Arm, ArmSource, arm_of
from robokin.kinematics.ik.analytic._common import fk_error, make_set
from robokin.model.chain import Chain
from robokin.spatial import invert, wrap_angle

if TYPE_CHECKING:
    from robokin.kinematics.ik.solutions import SolutionSet

__all__ = ["NAME", "General6R", "Variant", "make_single", "raw_solve", "setup", "solve",
           "why_not"]

NAME = "general_6r"
K = _native.kernels
MAX_SOLUTIONS = 16
SETUP_POSES = 20  # deterministic poses the variant choice is measured on
SETUP_SEED = 20_241_993
FIT_SAMPLES = 64  # rows per least-squares fit (27 unknowns)
FIT_TOL = 1e-9  # largest relative residual of a fit
TAIL_TOL = 1e-6  # largest relative DFT tail above degree 8 of a usable determinant
NULL_TOL = 1e-7  # Sigma's second-smallest / largest pivot below: 2-D null space
IMAG_TOL = 5e-2  # imaginary part of theta_a [rad] still tried as a real root
SOLUTION_TOL = 1e-9  # position [m] and rotation [rad] error of a solution
DEDUPE_TOL = 1e-6  # [rad] solutions closer than this are one
NEWTON_ITERATIONS = 40  # most: singular solutions converge linearly
PAIR_GAP = 1e-2  # [rad] roots closer: both solutions from a 2-D null space
_PARALLEL_MIN = 32  # below this many poses one thread (the kernel's own threshold)
# kernel status (ok, none, degenerate, bad pose) -> _common.STATUS_TEXT code
_STATUS = np.array([0, 1, 5, 1], dtype=np.int8)


@dataclass(frozen=True)
class Variant:
    """One elimination variant.

    Attributes:
        reversed: Solve ``T^-1`` on the reversed chain.
        split: ``a``: joints a, a+1, a+2 of the (reversed) chain on the left.
        multiplier: 0: the dialytic rows are multiplied by ``x_b`` (joint a+1),
            1: by ``x_c`` (joint a+2).
    """

    reversed: bool
    split: int
    multiplier: int

    @property
    def hidden_joint(self) -> int:
        """The joint (1-based, original order) whose angle the determinant's roots give."""
        return 7 - self.split if self.reversed else self.split

    def __str__(self) -> str:
        """The split, its direction and the dialytic multiplier, e.g. "split 2, x_b"."""
        return (f"split {self.split}{' reversed' if self.reversed else ''}, "
                f"x_{'bc'[self.multiplier]}")


@dataclass(frozen=True, eq=False)
class General6R:
    """The per-arm set-up of the general 6R solver.

    Attributes:
        params: The kernel's parameter vector (read-only), or None when the family
            does not apply.
        primary: The variant run for every pose.
        secondary: The variant run where the primary reports trouble, or None.
        reason: Why the family does not apply ("" when it does).
        measured: What the set-up measured (for ``Family.measured``).
        tail: The primary's largest relative DFT tail on the set-up poses.
    """

    params: np.ndarray | None
    primary: Variant | None = None
    secondary: Variant | None = None
    reason: str = ""
    measured: str = ""
    tail: float = float("nan")


def why_not(chain: Chain) -> str:
    """Why the general 6R solver does not take ``chain`` ("" when it does)."""
    if chain.n_chain != 6 or chain.n != 6:
        return (f"{chain.n} joint coordinates on {chain.n_chain} chain joints: the general "
                "6R solver takes six joints")
    if (chain.arrays.kind != 0.0).any():
        return ("a prismatic joint: the general 6R elimination (Raghavan-Roth) is written "
                "for six revolute joints")
    if not chain.coupling.is_identity:
        return "dependent joints: the general 6R solver takes independent joints only"
    return ""


def setup(robot: ArmSource) -> General6R:
    """The set-up of the arm's chain (fits and variant choice), kept in its Arm."""
    arm = arm_of(robot)
    g = arm.general_6r
    if not isinstance(g, General6R):
        g = arm.general_6r = _setup(arm.chain)
    return g


# ----------------------------------------------------------------- the fit


def _direction_consts(chain: Chain, reverse: bool) -> np.ndarray:
    """C'_0 .. C'_6 of the chain (or of its reversal, C'_k = C_{6-k}^-1), (7, 4, 4)."""
    C = np.array(chain.arrays.consts, dtype=np.float64)
    return np.ascontiguousarray(invert(C[::-1]) if reverse else C)


def _fit(consts: np.ndarray, a: int, rng: np.random.Generator) -> tuple[np.ndarray, float]:
    """P_s, P_c, P_1 (3, 14, 9) of split ``a`` and the fit's relative residual."""
    angles = np.column_stack([
        rng.uniform(-np.pi, np.pi, FIT_SAMPLES),
        rng.uniform(-2.0, 2.0, (FIT_SAMPLES, 2)),  # |tan(t / 2)| < 1.6: well conditioned
    ])
    X = np.empty((FIT_SAMPLES, 27))
    Y = np.empty((FIT_SAMPLES, 14))
    K.general6r_fit_rows(consts, a, np.ascontiguousarray(angles), X, Y)
    coef = np.linalg.lstsq(X, Y, rcond=None)[0]  # (27, 14)
    resid = np.abs(X @ coef - Y).max() / max(np.abs(Y).max(), 1e-300)
    P = np.ascontiguousarray(coef.T.reshape(14, 3, 9).transpose(1, 0, 2))
    return P, float(resid)


def _header(n_variants: int) -> np.ndarray:
    h = np.zeros(K.GP_HEAD)
    h[K.GP_NVAR] = n_variants
    h[K.GP_TAIL_TOL] = TAIL_TOL
    h[K.GP_NULL_TOL] = NULL_TOL
    h[K.GP_IMAG_TOL] = IMAG_TOL
    h[K.GP_TOL] = SOLUTION_TOL
    h[K.GP_DEDUPE] = DEDUPE_TOL
    h[K.GP_MAX_ITER] = NEWTON_ITERATIONS
    h[K.GP_PAIR_GAP] = PAIR_GAP
    return h


def _block(v: Variant, consts: np.ndarray, P: np.ndarray) -> np.ndarray:
    b = np.zeros(K.VB_SIZE)
    b[K.VB_DIR] = float(v.reversed)
    b[K.VB_A] = v.split
    b[K.VB_MULT] = v.multiplier
    b[K.VB_C:K.VB_C + 112] = consts.ravel()
    b[K.VB_CI:K.VB_CI + 112] = invert(consts).ravel()
    b[K.VB_P:K.VB_P + 378] = P.ravel()
    return b


def _params(blocks: list[np.ndarray]) -> np.ndarray:
    P = np.concatenate([_header(len(blocks))] + blocks)
    P.setflags(write=False)
    return P


# -------------------------------------------------------------- the kernel


def raw_solve(chain: Chain, params: np.ndarray, T: np.ndarray,
              parallel: bool | None = None) -> tuple[np.ndarray, ...]:
    """The bare kernel call.

    T (N, 4, 4) C-contiguous float64 -> (q (N, 16, 6) [rad], valid (N, 16), inside (N, 16) the valid rows within the limits, sigma (N, 16) the
    Jacobian's smallest singular value, status (N,) int64 (kernel codes), diag (N,)
    int64 (kernel flags; >> G6_DIAG_CAND_SHIFT the roots tried), stats (N, 3): the
    primary's relative DFT tail, null-space margin and roots taken as close pairs).
    Revolute values are in [-pi, pi), or moved by whole turns into their limits
    where that is possible; rows that are not solutions are 0. No input checks.
    """
    N = T.shape[0]
    Q = np.empty((N, MAX_SOLUTIONS, 6))
    valid = np.empty((N, MAX_SOLUTIONS), np.bool_)
    inside = np.empty((N, MAX_SOLUTIONS), np.bool_)
    sigma = np.empty((N, MAX_SOLUTIONS))
    status = np.empty(N, np.int64)
    diag = np.empty(N, np.int64)
    stats = np.empty((N, 3))
    par = N >= _PARALLEL_MIN if parallel is None else bool(parallel)
    K.general6r_solve(chain.arrays.packed, params, T, Q, valid, inside, sigma, status, diag,
                      stats, par)
    return Q, valid, inside, sigma, status, diag, stats


# -------------------------------------------------------- variant choice


def _close(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(len(a), len(b)) bool: configurations equal modulo 2 pi within DEDUPE_TOL."""
    d = wrap_angle(a[:, None, :] - b[None, :, :])
    close: np.ndarray = np.abs(d).max(axis=-1) < 10 * DEDUPE_TOL
    return close


def _distinct(q: np.ndarray) -> np.ndarray:
    """The rows of q (k, 6) without repeats (modulo 2 pi), in order."""
    same = _close(q, q) & np.tri(len(q), k=-1, dtype=bool)
    rows: np.ndarray = q[~same.any(axis=1)]
    return rows


@dataclass(frozen=True, eq=False)
class _Trial:
    """One variant run alone on the set-up poses.

    Attributes:
        covered: Per pose, which reference solutions it found, (k_i,) bool each.
        trouble: (poses,) bool, where it would hand the pose to the secondary
            (degenerate determinant or a 2-D null space).
        degenerate: Poses with a degenerate determinant.
        tail: Its largest relative DFT tail.
        pairs: Roots it took as close pairs (from a 2-D null space).
    """

    covered: list[np.ndarray]
    trouble: np.ndarray
    degenerate: int
    tail: float
    pairs: int

    @property
    def missed(self) -> int:
        """Reference solutions it does not find alone."""
        return sum(int((~c).sum()) for c in self.covered)

    @property
    def cost(self) -> int:
        """Expected work and fragility of a variant as the primary.

        A pose sent to the secondary costs about one variant (8 roots), each root
        taken from a 2-D null space one.
        """
        return 8 * int(self.trouble.sum()) + self.pairs


def _fits(chain: Chain, rng: np.random.Generator) -> dict[Variant, np.ndarray] | str:
    """Every variant's kernel block, or why the fit failed."""
    blocks = {}
    for rev in (False, True):
        consts = _direction_consts(chain, rev)
        for a in (1, 2, 3):
            P, resid = _fit(consts, a, rng)
            if resid > FIT_TOL:  # pragma: no cover - linear by construction
                return f"the left-side fit of split {a} failed (residual {resid:.1e})"
            for m in (0, 1):
                v = Variant(rev, a, m)
                blocks[v] = _block(v, consts, P)
    return blocks


def _trials(chain: Chain, blocks: dict[Variant, np.ndarray], q: np.ndarray
            ) -> tuple[dict[Variant, _Trial], int]:
    """Each variant alone on the poses of q, against the reference.

    The reference is the union of every variant's validated solutions and the
    generating configurations.
    """
    from robokin.kinematics.forward import forward_kinematics

    T = np.ascontiguousarray(forward_kinematics(chain, q))
    runs = {v: raw_solve(chain, _params([b]), T, parallel=False) for v, b in blocks.items()}
    found = {v: [r[0][i][r[1][i]] for i in range(len(q))] for v, r in runs.items()}
    ref = [_distinct(np.concatenate([q[i:i + 1]] + [f[i] for f in found.values()]))
           for i in range(len(q))]
    trials = {}
    for v, (_, _, _, _, _, diag, stats) in runs.items():
        tail = stats[:, 0]
        trials[v] = _Trial(
            covered=[np.asarray(_close(ref[i], found[v][i]).any(axis=1))
                     for i in range(len(q))],
            trouble=(diag & (K.G6F_DEGENERATE | K.G6F_AMBIGUOUS)) != 0,
            degenerate=int(((diag & K.G6F_DEGENERATE) != 0).sum()),
            tail=float(np.max(np.where(np.isfinite(tail), tail, 1.0))),
            pairs=int(stats[:, 2].sum()))
    return trials, sum(len(r) for r in ref)


def _choose(trials: dict[Variant, _Trial], poses: int) -> tuple[Variant, Variant] | None:
    """The (primary, secondary) pair that finds every reference solution.

    The secondary runs where the primary reports trouble; among the pairs that
    work, the least primary cost wins, then the smaller tail. None when no pair does.
    """
    best = None
    for p, tp in trials.items():
        if 2 * tp.degenerate > poses:  # it would merely hand poses on
            continue
        for s, ts in trials.items():
            if s == p or not all((cp | (tp.trouble[i] & cs)).all() for i, (cp, cs)
                                 in enumerate(zip(tp.covered, ts.covered, strict=True))):
                continue
            # a secondary with the primary's hidden joint meets the same double roots
            key = (tp.cost, tp.tail, p.hidden_joint == s.hidden_joint, ts.missed, ts.cost,
                   ts.tail)
            if best is None or key < best[0]:
                best = (key, p, s)
    return None if best is None else (best[1], best[2])


def _setup(chain: Chain) -> General6R:
    reason = why_not(chain)
    if reason:
        return General6R(None, reason=reason)
    rng = np.random.default_rng(SETUP_SEED)
    blocks = _fits(chain, rng)
    if isinstance(blocks, str):  # pragma: no cover
        return General6R(None, reason=blocks)
    trials, n_ref = _trials(chain, blocks, rng.uniform(-np.pi, np.pi, (SETUP_POSES, 6)))
    pair = _choose(trials, SETUP_POSES)
    if pair is None:
        alone = min(trials, key=lambda v: trials[v].missed)
        return General6R(None, reason=(
            f"no elimination variant finds every solution on {SETUP_POSES} test poses "
            f"(best: {alone}, {n_ref - trials[alone].missed} of {n_ref})"))
    p, s = pair
    tail = trials[p].tail
    measured = (f"Raghavan-Roth elimination, {p} (secondary {s} on "
                f"{int(trials[p].trouble.sum())} of {SETUP_POSES} test poses); all "
                f"{n_ref} solutions of the test poses found; DFT tail {tail:.1e}")
    return General6R(_params([blocks[p], blocks[s]]), p, s, measured=measured, tail=tail)


# -------------------------------------------------------------- the solver


def solve(robot: ArmSource, T: np.ndarray, q_near: np.ndarray | None = None, *,
          singular_tol: float = 1e-6, compute_error: bool = False,
          parallel: bool | None = None) -> SolutionSet:
    """Every solution of a general 6R arm for poses T (..., 4, 4).

    Args:
        robot: The arm (six revolute joints, no dependent joints).
        T: Target poses (..., 4, 4) [m], rigid transforms.
        q_near: Accepted for the solvers' common signature and checked; the
            solutions are isolated, so it changes nothing (pick with
            ``SolutionSet.nearest``).
        singular_tol: A solution is flagged ``singular`` when the smallest singular
            value of its Jacobian is below this.
        compute_error: Fill ``error`` with each solution's FK error.
        parallel: Use every thread of the pool (default: for 32 poses or more).

    Returns:
        A :class:`~robokin.kinematics.ik.solutions.SolutionSet` with
        ``method="general_6r"``, at most 16 solutions per pose (rows that are not
        solutions hold zeros); revolute values in [-pi, pi), or moved by whole turns
        into their limits where that is possible.

    Raises:
        InputError: ``robot`` is not solved by this family (the message says why),
            a pose is not a rigid transform, or ``q_near`` is not finite joint
            values (n,) or (..., n) that broadcast to the poses.
    """
    from robokin._validation import (
        check_broadcasts,
        check_finite,
        check_joints,
        check_poses_fast,
    )
    from robokin.exceptions import InputError

    arm = arm_of(robot)
    chain = arm.chain
    g = setup(arm)
    if g.params is None:
        raise InputError("robot", f"'{arm.name}' is not solved by {NAME}: {g.reason}")
    T = check_poses_fast(T, "T")
    lead = T.shape[:-2]
    if q_near is not None:
        qn = check_finite(check_joints(q_near, 6, "q_near"), "q_near")
        check_broadcasts(qn, lead + (6,), "q_near")
    Q, valid, inside, sigma, status, diag, _ = raw_solve(
        chain, g.params, np.ascontiguousarray(T.reshape(-1, 4, 4)), parallel)
    shape = lead + (MAX_SOLUTIONS,)
    Q = Q.reshape(shape + (6,))
    valid = valid.reshape(shape)
    error = None
    if compute_error:
        dp, dr = fk_error(chain, Q, T)
        error = np.where(valid, np.hypot(dp, dr), np.inf)
    info = {"family": NAME, "variant": str(g.primary), "secondary": str(g.secondary),
            "secondary_runs": int(((diag & K.G6F_SECONDARY) != 0).sum())}
    return make_set(arm, Q, valid, inside=inside.reshape(shape),
                    singular=(sigma < singular_tol).reshape(shape), branches={},
                    status_codes=_STATUS[status].reshape(lead), method=NAME, info=info,
                    error=error)


def make_single(arm: Arm) -> Any:
    """The single-pose hot path: ``single(T, q6) -> SolutionSet | None``.

    For one pose ``T`` (4, 4) float64 with default options (``q6``, the closed forms' joint-6
    value at a wrist singularity, is unused). None when ``T`` is not a rigid
    transform (the caller re-checks it to raise the detailed error). Every call
    returns fresh arrays; only the read-only joint kinds and limits are shared.
    """
    from robokin.kinematics.ik.analytic._common import STATUS_TEXT
    from robokin.kinematics.ik.solutions import SolutionSet

    g = setup(arm)
    chain = arm.chain
    packed, params = chain.arrays.packed, g.params
    if params is None:
        raise ValueError(f"general_6r is not offered for this chain: {g.reason}")
    is_rev = np.ones(6, dtype=bool)
    is_rev.setflags(write=False)
    limits = chain.limits
    info = {"family": NAME, "variant": str(g.primary), "secondary": str(g.secondary)}
    texts = [np.array(STATUS_TEXT[c], dtype=object) for c in _STATUS]
    check, kern, empty = K.check_poses, K.general6r_solve, np.empty
    trusted = SolutionSet._trusted
    b1 = np.bool_
    secondary = K.G6F_SECONDARY

    def single(T: np.ndarray, q6: float) -> Any:
        T1 = np.ascontiguousarray(T).reshape(1, 4, 4)
        if check(T1, 1e-6)[0]:
            return None
        Q = empty((1, MAX_SOLUTIONS, 6))
        valid, inside = empty((1, MAX_SOLUTIONS), b1), empty((1, MAX_SOLUTIONS), b1)
        sigma, status, diag = empty((1, MAX_SOLUTIONS)), empty(1, np.int64), empty(1, np.int64)
        kern(packed, params, T1, Q, valid, inside, sigma, status, diag, empty((1, 3)), False)
        runs = int(diag[0] & secondary != 0)
        return trusted(Q[0], valid[0], is_rev, limits,
                       {"within_limits": inside[0], "singular": sigma[0] < 1e-6}, {},
                       texts[status[0]].copy(), NAME, None, dict(info, secondary_runs=runs))

    return single
