"""General 6R arms: every IK solution by Raghavan-Roth elimination.

Any arm of six revolute joints without dependent joints whose solutions are finite
(its Jacobian has full rank somewhere) is solved completely, up to 16 solutions, by
the compiled kernel in ``robokin/_native/csrc/general6r.c`` (its header gives the
elimination step by step): the loop-closure equations of a split of the chain into
three joints and the inverse of the other three give 14 equations (Raghavan & Roth
1993); eliminating two angles leaves a 12 x 12 matrix ``Sigma(theta_a)`` whose
determinant, a trigonometric polynomial of degree 8, has the solutions' ``theta_a``
as real roots (Manocha & Canny 1994). Where several solutions share ``theta_a``
(special configurations) the null space of ``Sigma`` is split by its monomial
structure; where the determinant vanishes identically at a pose (every variant), the
lowest coefficient of its expansion along a pose motion takes its place (Canny's
generalized characteristic polynomial). Every candidate is polished by Newton steps
on the true chain and kept only when it reproduces the pose to ``SOLUTION_TOL``
(rotation [rad]; position [m] per metre of arm, ``scale``).

This module does the per-arm set-up, once per chain (kept in its ``Arm``):

* **fit**: the left side of each split is linear in 27 pose-independent monomials;
  their coefficients are fitted by least squares from rows the kernel computes
  (``general6r_fit_rows``), no symbolic derivation;
* **variant choice**: a variant is a split ``a`` in {1, 2, 3}, the chain or its
  reversal (the IK of ``T^-1`` on the reversed chain) and the dialytic multiplier
  (``x_b`` or ``x_c``), 12 in all. Arms with special geometry make some variants
  degenerate at some or all poses (a UR arm: only the split with the three parallel
  axes on the left works). Every variant runs alone on ``SETUP_POSES`` deterministic
  poses from uniform joint values and as many from joint values at 0, +-pi/2, pi;
  the union of their solutions plus the generating configurations is the
  reference. The primary is the variant that finds all of it and is degenerate at
  the fewest poses (there the kernel needs the secondary, or the projection, both
  slower), then splits the fewest multiple roots, then has the smallest DFT tail;
  the secondary is the one that does best on the primary's degenerate poses.

Arms with a prismatic joint or dependent joints are not offered this family (the
elimination is written for revolute joints), nor degenerate arms (rank-deficient
Jacobian everywhere: two coincident axes, infinitely many solutions for every pose),
nor nearly degenerate ones (its smallest singular value below ``ISOLATED`` per metre
of arm at every set-up configuration: no isolated solutions to check the set-up on),
nor, should it happen, arms whose chosen variants miss a reference solution: their
``Family.reason`` says why and ``robot.ik`` falls back to the numeric solver, which
its ``method`` says.

References:
    Raghavan, M. and Roth, B. "Inverse kinematics of the general 6R manipulator and
    related linkages", J. Mech. Design 115(3):502-508, 1993.
    Manocha, D. and Canny, J. "Efficient inverse kinematics for general 6R
    manipulators", IEEE Trans. Robotics and Automation 10(5):648-657, 1994.
    Canny, J. "Generalised characteristic polynomials", J. Symbolic Computation
    9(3):241-250, 1990.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from robokin import _native
from robokin.kinematics.arm import Arm, ArmSource, Derived, arm_of
from robokin.kinematics.forward import forward_kinematics
from robokin.kinematics.ik.analytic._common import fk_error, make_set
from robokin.kinematics.ik.analytic._geometry import poe_from_chain
from robokin.kinematics.jacobian import min_singular_value
from robokin.model.chain import Chain
from robokin.spatial import invert, wrap_angle

if TYPE_CHECKING:
    from robokin.kinematics.ik.solutions import SolutionSet

__all__ = ["NAME", "SETUP", "General6R", "Variant", "make_single", "raw_solve", "setup",
           "solve", "why_not"]

NAME = "general_6r"
K = _native.kernels
MAX_SOLUTIONS = 16
SETUP_POSES = 20  # deterministic poses per kind (uniform, special) the choice is made on
SETUP_SEED = 20_241_993
FIT_SAMPLES = 64  # rows per least-squares fit (27 unknowns)
FIT_TOL = 1e-9  # largest relative residual of a fit
TAIL_TOL = 1e-6  # largest relative DFT tail above degree 8 of a usable determinant
NEAR_TAIL = 1e-12  # a tail above: near a degenerate pose, the next variant runs too
NULL_TOL = 1e-7  # pivot of Sigma below this fraction of the largest: a null direction
IMAG_TOL = 5e-2  # imaginary part of theta_a [rad] still tried as a real root
SOLUTION_TOL = 9e-13  # rotation [rad] and position [m, per metre of scale] error
DEDUPE_TOL = 1e-6  # [rad] solutions closer than this are one (more near-singular)
NEWTON_ITERATIONS = 60  # most: singular solutions converge linearly
PAIR_GAP = 1e-2  # [rad] roots closer than this form a cluster (a multiple root)
FALLBACKS = 2  # variants after the secondary, each with another split and direction
RANK_TOL = 1e-9  # Jacobian singular value [per metre of scale] below: rank deficient
ISOLATED = 1e-4  # ... above: a set-up configuration whose solutions are compared
SPECIAL_VALUES = np.array([0.0, np.pi / 2, -np.pi / 2, np.pi])
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
        secondary: The variant run where the primary is degenerate or noisy.
        reason: Why the family does not apply ("" when it does).
        measured: What the set-up measured (for ``Family.measured``).
        tail: The primary's largest relative DFT tail on the set-up poses.
        scale: The arm's length scale [m]: the largest distance of a joint axis point
            or the tool from the base at zero joint values (at least 1e-3).
        variants: Every variant in the kernel's order (primary, secondary, ...).
    """

    params: np.ndarray | None
    primary: Variant | None = None
    secondary: Variant | None = None
    reason: str = ""
    measured: str = ""
    tail: float = float("nan")
    scale: float = 1.0
    variants: tuple[Variant, ...] = ()


def why_not(chain: Chain) -> str:
    """Why the general 6R solver does not take ``chain`` ("" when it does).

    The structural reasons only (joint kinds and count, dependent joints); the
    set-up adds its own (a degenerate arm), see :func:`setup`.
    """
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
    return arm_of(robot).derived(SETUP)


#: The arm's general-6R set-up, kept in its ``Arm`` (``arm.derived(SETUP)``).
SETUP: Derived[General6R] = Derived("general 6R set-up", lambda arm: _setup(arm.chain))


def _scale(chain: Chain) -> float:
    """The arm's length scale [m] (see :class:`General6R`)."""
    poe = poe_from_chain(chain)
    far = max(float(np.linalg.norm(poe.o, axis=1).max()),
              float(np.linalg.norm(poe.M[:3, 3])))
    return max(far, 1e-3)


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


def _header(n_variants: int, scale: float = 1.0, fallback: bool = True) -> np.ndarray:
    h = np.zeros(K.GP_HEAD)
    h[K.GP_NVAR] = n_variants
    h[K.GP_TAIL_TOL] = TAIL_TOL
    h[K.GP_NULL_TOL] = NULL_TOL
    h[K.GP_IMAG_TOL] = IMAG_TOL
    h[K.GP_TOL] = SOLUTION_TOL
    h[K.GP_DEDUPE] = DEDUPE_TOL
    h[K.GP_MAX_ITER] = NEWTON_ITERATIONS
    h[K.GP_PAIR_GAP] = PAIR_GAP
    h[K.GP_SCALE] = scale
    h[K.GP_FALLBACK] = float(fallback)
    h[K.GP_NEAR_TAIL] = NEAR_TAIL
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


def _params(blocks: list[np.ndarray], scale: float, fallback: bool = True) -> np.ndarray:
    P = np.concatenate([_header(len(blocks), scale, fallback)] + blocks)
    P.setflags(write=False)
    return P


# -------------------------------------------------------------- the kernel


def raw_solve(chain: Chain, params: np.ndarray, T: np.ndarray,
              parallel: bool | None = None) -> tuple[np.ndarray, ...]:
    """The bare kernel call.

    T (N, 4, 4) C-contiguous float64 -> (q (N, 16, 6) [rad], valid (N, 16), inside
    (N, 16) the valid rows within the limits, sigma (N, 16) the Jacobian's smallest
    singular value, status (N,) int64 (kernel codes), diag (N,) int64 (kernel flags
    ``G6F_*``; ``>> G6_DIAG_CAND_SHIFT`` the candidates polished), stats (N, 12): the
    primary's relative DFT tail, null-space margin and clusters split, the
    smallest error [m, rad] a candidate's polish reached, then the primary's four
    non-real root pairs nearest the real axis as (imaginary part, real part) of the
    split joint's angle [rad], nearest first, inf where there are fewer).
    Revolute values are in [-pi, pi), or moved by whole turns into their limits
    where that is possible; rows that are not solutions are NaN. No input checks.
    """
    N = T.shape[0]
    Q = np.empty((N, MAX_SOLUTIONS, 6))
    valid = np.empty((N, MAX_SOLUTIONS), np.bool_)
    inside = np.empty((N, MAX_SOLUTIONS), np.bool_)
    sigma = np.empty((N, MAX_SOLUTIONS))
    status = np.empty(N, np.int64)
    diag = np.empty(N, np.int64)
    stats = np.empty((N, 12))
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


def _union(sets: list[np.ndarray]) -> np.ndarray:
    """The distinct rows (modulo 2 pi) of the (k_i, 6) sets, first occurrence kept.

    Each set's rows are distinct already (the kernel's).
    """
    out = sets[0]
    for q in sets[1:]:
        if len(q):
            out = np.concatenate([out, q[~_close(q, out).any(axis=1)]])
    return out


def _setup_configurations(chain: Chain, rng: np.random.Generator, scale: float
                          ) -> np.ndarray:
    """Set-up configurations, (<= 2 SETUP_POSES, 6) joint values.

    Uniform ones, then ones with about half of the joints at 0, +-pi/2, pi and the
    others uniform; non-singular ones only (Jacobian singular values above
    ``ISOLATED * scale``: the solutions are isolated, a finite set to compare).
    """
    q = rng.uniform(-np.pi, np.pi, (8 * SETUP_POSES, 6))
    special = SPECIAL_VALUES[rng.integers(0, len(SPECIAL_VALUES), q.shape)]
    half = 4 * SETUP_POSES
    q[half:] = np.where(rng.random((half, 6)) < 0.5, special[half:], q[half:])
    ok = min_singular_value(chain, q) > ISOLATED * scale
    uniform, special_q = q[:half][ok[:half]], q[half:][ok[half:]]
    return np.concatenate([uniform[:SETUP_POSES], special_q[:SETUP_POSES]])


@dataclass(frozen=True, eq=False)
class _Trial:
    """One variant run alone on the set-up poses.

    Attributes:
        covered: Per pose, which reference solutions it found, (k_i,) bool each.
        degenerate: (poses,) bool: where it is degenerate (the kernel then runs the
            secondary, or the projection).
        clusters: Multiple roots it split.
        tail: Its largest relative DFT tail.
    """

    covered: list[np.ndarray]
    degenerate: np.ndarray
    noisy: np.ndarray
    clusters: int
    tail: float
    missed: int

    def key(self) -> tuple[int, int, int, int, float]:
        """How good a primary it is (smaller is better).

        Misses, then degenerate and noisy poses (where the kernel needs the
        secondary), clusters, tail.
        """
        return (self.missed, int(self.degenerate.sum()), int(self.noisy.sum()),
                self.clusters, self.tail)


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


def _solutions(run: tuple[np.ndarray, ...]) -> list[np.ndarray]:
    """Per pose, the valid rows of a raw_solve result."""
    return [run[0][i][run[1][i]] for i in range(len(run[0]))]


def _trials(chain: Chain, blocks: dict[Variant, np.ndarray], q: np.ndarray, scale: float
            ) -> tuple[dict[Variant, _Trial], list[np.ndarray]]:
    """Each variant alone on the poses of q, against the reference.

    The reference is the union of every variant's validated solutions and the
    generating configurations.
    """
    T = np.ascontiguousarray(forward_kinematics(chain, q))
    # (the kernel's threads: each pose's rows are the same on one thread or two)
    runs = {v: raw_solve(chain, _params([b], scale, fallback=False), T, parallel=True)
            for v, b in blocks.items()}
    found = {v: _solutions(r) for v, r in runs.items()}
    ref = [_union([q[i:i + 1]] + [f[i] for f in found.values()]) for i in range(len(q))]
    # compare isolated solutions only (a singular one is a point of a continuum, or two
    # merging, where variants may return different points)
    ref = [r[min_singular_value(chain, r) > ISOLATED * scale] if len(r) else r for r in ref]
    covers: dict[Variant, list[np.ndarray]] = {v: [] for v in runs}
    for i in range(len(q)):  # every variant's rows of pose i against its reference at once
        rows = [found[v][i] for v in runs]
        close = _close(ref[i], np.concatenate(rows))
        for v, part in zip(runs, np.split(close, np.cumsum([len(r) for r in rows])[:-1],
                                          axis=1), strict=True):
            covers[v].append(np.asarray(part.any(axis=1)))
    trials = {}
    for v, (_, _, _, _, _, diag, stats) in runs.items():
        tail = stats[:, 0]
        covered = covers[v]
        trials[v] = _Trial(
            covered=covered, degenerate=(diag & K.G6F_DEGENERATE) != 0,
            noisy=(diag & K.G6F_NOISY) != 0,
            clusters=int(stats[:, 2].sum()),
            tail=float(np.max(np.where(np.isfinite(tail), tail, 1.0))),
            missed=sum(int((~c).sum()) for c in covered))
    return trials, ref


def _ranked_pairs(trials: dict[Variant, _Trial]) -> list[tuple[Variant, Variant]]:
    """(primary, secondary) pairs, best first.

    Primaries by :meth:`_Trial.key`; for each, the secondaries by what they miss and
    how often they are degenerate where the primary is degenerate (a secondary with
    the primary's hidden joint meets the same multiple roots: last), then their key.
    """
    pairs = []
    for p in sorted(trials, key=lambda v: trials[v].key()):
        deg = trials[p].degenerate | trials[p].noisy

        def rank(s: Variant, p: Variant = p, deg: np.ndarray = deg) -> tuple[Any, ...]:
            t = trials[s]
            missed = sum(int((~c).sum()) for c, d in zip(t.covered, deg, strict=True) if d)
            return (missed, int(((t.degenerate | t.noisy) & deg).sum()),
                    p.hidden_joint == s.hidden_joint, t.key())

        pairs += [(p, s) for s in sorted((s for s in trials if s != p), key=rank)[:2]]
    return pairs


def _degenerate_arm(chain: Chain, q: np.ndarray, scale: float) -> str:
    """Why the arm has no finite solution sets ("" when its Jacobian has full rank)."""
    smin = min_singular_value(chain, q)
    if (smin > RANK_TOL * scale).any():
        return ""
    return (f"a degenerate arm: its Jacobian has rank below 6 at every one of {len(q)} "
            f"test configurations (smallest singular value at most {smin.max():.1e}; "
            "e.g. two joint axes on one line), so every pose it reaches has infinitely "
            "many solutions and there is no finite set to find")


def _setup(chain: Chain) -> General6R:
    reason = why_not(chain)
    if reason:
        return General6R(None, reason=reason)
    rng = np.random.default_rng(SETUP_SEED)
    scale = _scale(chain)
    reason = _degenerate_arm(chain, rng.uniform(-np.pi, np.pi, (2 * SETUP_POSES, 6)), scale)
    if reason:
        return General6R(None, reason=reason, scale=scale)
    q = _setup_configurations(chain, rng, scale)
    if len(q) == 0:
        return General6R(None, scale=scale, reason=(
            "a nearly degenerate arm: its Jacobian's smallest singular value is below "
            f"{ISOLATED:g} per metre of arm at all of {8 * SETUP_POSES} test "
            "configurations (e.g. axes within a fraction of a milliradian of a "
            "rank-deficient geometry), so the set-up cannot check the elimination on "
            "isolated solutions"))
    blocks = _fits(chain, rng)
    if isinstance(blocks, str):  # pragma: no cover
        return General6R(None, reason=blocks, scale=scale)
    trials, ref = _trials(chain, blocks, q, scale)
    n_ref = sum(len(r) for r in ref)
    T = np.ascontiguousarray(forward_kinematics(chain, q))
    best = None
    for p, s in _ranked_pairs(trials)[:6]:
        params = _params([blocks[p], blocks[s]], scale)
        got = _solutions(raw_solve(chain, params, T, parallel=True))
        missed = sum(int((~_close(r, g).any(axis=1)).sum()) for r, g in zip(ref, got,
                                                                          strict=True))
        if best is None or missed < best[0]:
            best = (missed, p, s, params)
        if missed == 0:
            break
    assert best is not None
    missed, p, s, _ = best
    if missed:
        return General6R(None, scale=scale, reason=(
            f"the general 6R elimination missed {missed} of {n_ref} solutions of its "
            f"{len(q)} test poses (best variants: {p}, then {s})"))
    order = _fallbacks(trials, p, s)
    params = _params([blocks[v] for v in order], scale)
    tp = trials[p]
    measured = (f"Raghavan-Roth elimination, {p} (then {', '.join(map(str, order[1:]))} "
                f"where it is degenerate or noisy: at {int((tp.degenerate | tp.noisy).sum())}"
                f" of {len(q)} test poses, half at 0, +-pi/2, pi); all {n_ref} solutions "
                f"of the test poses found; DFT tail {tp.tail:.1e}")
    return General6R(params, p, s, measured=measured, tail=tp.tail, scale=scale,
                     variants=tuple(order))


def _fallbacks(trials: dict[Variant, _Trial], p: Variant, s: Variant) -> list[Variant]:
    """The variants the kernel tries in turn.

    p, s, then up to FALLBACKS more, each with another split and direction (its own
    right side, which a pose can make rank deficient where the others' is not), best
    key first; last the primary's other dialytic multiplier (its sibling), unless
    already there. The sibling runs only where every variant before it was
    degenerate or noisy: where the others are degenerate and the primary splits a
    noisy cluster (the Panda with joint 7 held at 0.7, q2 = q3 = pi/2, q5 = q6 = pi:
    four solutions share q5), the split is sensitive to rounding in the fit (a
    6.7e-15 change lost the generating configuration) and the sibling's multiplier
    gives an independent set of candidates.
    """
    order = [p, s]
    for v in sorted(trials, key=lambda v: trials[v].key()):
        if len(order) == 2 + FALLBACKS:
            break
        if all((v.split, v.reversed) != (u.split, u.reversed) for u in order):
            order.append(v)
    sibling = Variant(p.reversed, p.split, 1 - p.multiplier)
    if sibling not in order:
        order.append(sibling)
    return order


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
        kern(packed, params, T1, Q, valid, inside, sigma, status, diag, empty((1, 12)), False)
        runs = int(diag[0] & secondary != 0)
        return trusted(Q[0], valid[0], is_rev, limits,
                       {"within_limits": inside[0], "singular": sigma[0] < 1e-6}, {},
                       texts[status[0]].copy(), NAME, None, dict(info, secondary_runs=runs))

    return single
