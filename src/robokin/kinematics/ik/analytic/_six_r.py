"""Shared driver of the two 6R closed forms (three parallel axes, spherical wrist).

The geometry is read from the canonical chain (product of exponentials, see
``_geometry``), nearly-parallel / nearly-meeting axes are snapped to the nominal
family, and the result is packed into the flat parameter vector the compiled
kernels read (``robokin._native``, ``csrc/six_r.c``: the layout, and the indices
this module reads from the extension).
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np

from robokin._native import kernels as K
from robokin._native import single as single_copy
from robokin.kinematics.arm import Arm
from robokin.kinematics.ik.analytic._common import (
    STATUS_TEXT,
    branch_labels,
    fk_error,
    make_set,
    q_near_rows,
    read_only_joint_data,
)
from robokin.kinematics.ik.analytic._geometry import (
    Poe,
    closest_point,
    cross3,
    poe_from_chain,
    unit_perpendicular,
)
from robokin.kinematics.ik.solutions import SolutionSet
from robokin.model.chain import Chain

__all__ = ["POSE_TOL", "SINGULAR_TOL", "make_single", "pack", "raw_solve", "solve_six_r"]

Kind = Literal["three_parallel", "spherical_wrist"]

# slot = 4 * shoulder + 2 * elbow + wrist; 0 -> +1 ('+' root), 1 -> -1
_LABELS: dict[str, tuple[int, ...]] = {
    "shoulder": (1, 1, 1, 1, -1, -1, -1, -1),
    "elbow": (1, 1, -1, -1, 1, 1, -1, -1),
    "wrist": (1, -1, 1, -1, 1, -1, 1, -1),
}
# Below this many poses the kernel runs on one thread (the pool's launch costs more).
_PARALLEL_MIN = K.SIX_R_PARALLEL_MIN
# A solution is flagged singular within this (a sine) of a singularity, as
# robot.is_singular's default on the smallest singular value.
SINGULAR_TOL = 1e-6
# The pose error [m] (times the arm's size when above 1 m) and [rad] every solution
# meets (checked and polished in the kernel where the closed form may not).
POSE_TOL = 1e-12
# The wrist split's orientation budget [rad] (csrc/six_r.c, 'the wrist split'):
# below the kernel's polish target (half of POSE_TOL), so a split is not undone.
SPLIT_TOL = 0.4 * POSE_TOL


def pack(chain: Chain, kind: Kind, *, singular_tol: float = SINGULAR_TOL,
         disc_tol: float = 1e-10, mirror: bool = False, check_all: bool = False,
         poe: Poe | None = None) -> np.ndarray:
    """The kernel parameter vector of a 6R chain (layout in ``csrc/six_r.c``).

    Args:
        chain: The canonical 6R chain.
        kind: The family.
        singular_tol: A solution is flagged ``singular`` within this (a sine) of a
            singularity (wrist, elbow or shoulder; ``csrc/six_r.c``).
        disc_tol: Subproblem 4 discriminant tolerance (relative).
        mirror: Near-family seeds: mirrored past a boundary, no check against the
            chain (``near.polish`` does it on the true chain).
        check_all: Check (and polish) every solution against the chain, not only
            those near a boundary or singularity (for tests and measurements).
        poe: The chain's product-of-exponentials description, if at hand.
    """
    poe = poe_from_chain(chain) if poe is None else poe
    h = poe.h.copy()
    o = poe.o.copy()
    s3 = 1.0 if h[1] @ h[2] >= 0 else -1.0
    s4 = 1.0 if h[1] @ h[3] >= 0 else -1.0
    three = kind == "three_parallel"
    if three:
        h2 = h[1] + s3 * h[2] + s4 * h[3]
        h2 /= np.linalg.norm(h2)
        h[1], h[2], h[3] = h2, s3 * h2, s4 * h2
        ow = closest_point(o[4:6], h[4:6])
        e = unit_perpendicular(h2)
    else:
        h2 = h[1] + s3 * h[2]
        h2 /= np.linalg.norm(h2)
        h[1], h[2] = h2, s3 * h2
        ow = closest_point(o[3:6], h[3:6])
        e = unit_perpendicular(h[3])
    P = np.zeros(K.N_PARAMS)

    def put(index: int, value: Any) -> None:
        v = np.ravel(value)
        P[index:index + v.size] = v

    put(K.AXES, h)
    put(K.POINTS, o[0:4])
    put(K.WRIST, ow)
    put(K.TOOL_T, poe.M[:3, 3])
    put(K.TOOL_R, poe.M[:3, :3])
    put(K.PERP, e)
    hw = h[1] if three else h[3]
    put(K.PERP2, cross3(hw, e))
    put(K.SIGN, chain.arrays.sign)
    put(K.OFFSET, chain.arrays.offset)
    lim = chain.limits
    put(K.LO, lim[:, 0])
    put(K.HI, lim[:, 1])
    P[K.S3], P[K.S4] = s3, s4
    P[K.SING_TOL] = singular_tol
    P[K.DISC_TOL] = disc_tol
    P[K.MIRROR] = 1.0 if mirror else 0.0
    P[K.FAMILY] = K.THREE_PARALLEL if three else K.SPHERICAL_WRIST
    # pose-independent subproblem coefficients (theta3: |a + rot(h3, t) b|,
    # theta5: h . rot(h5, t) h6 with h = h2 (three parallel) or h4 (spherical))
    a = o[2] - o[1]
    b = (o[3] if three else ow) - o[2]
    hw = h[1] if three else h[3]
    for (ia, ib, ic, iphi), (hh, kk, pp) in (
        ((K.A3, K.B3, K.C3, K.PHI3), (a, h[2], b)),
        ((K.A5, K.B5, K.C5, K.PHI5), (hw, h[4], h[5])),
    ):
        kp = kk @ pp
        hk = hh @ kk
        A, B, C = hh @ pp - hk * kp, hh @ cross3(kk, pp), hk * kp
        r = np.hypot(A, B)
        P[ia], P[ib], P[ic] = A, B, C
        P[iphi] = np.arctan2(B, A)
        P[iphi + 1], P[iphi + 2] = (A / r, B / r) if r > 0 else (1.0, 0.0)
    P[K.AA] = a @ a
    P[K.BB] = b @ b
    # theta5's discriminant for unit vectors: |x_perp|^2 + E5 + 2 d C5 (exact)
    P[K.E5] = -((hw @ h[4]) ** 2 + (h[4] @ h[5]) ** 2)
    if three:  # the planar part in the basis (e, e2) of the plane normal to h2
        e2 = cross3(h[1], e)
        w4 = ow - o[3]
        put(K.PLANE, [a @ e, a @ e2, b @ e, b @ e2, w4 @ e, w4 @ e2, w4 @ h[1]])
    P[K.SPLIT_TOL] = SPLIT_TOL
    # the pose error every solution meets: POSE_TOL times the arm's size L (at
    # least 1 m) and POSE_TOL [rad]; the kernel aims at half of it, so the
    # guarantee holds under any other rounding of the same measure (robot.fk and
    # spatial.pose_error)
    size = float(np.linalg.norm(o[1] - o[0]) + np.linalg.norm(o[2] - o[1])
                 + np.linalg.norm(ow - o[2]) + np.linalg.norm(poe.M[:3, 3] - ow))
    P[K.SIZE] = size
    P[K.TOL_P] = 0.5 * POSE_TOL * max(1.0, size)
    P[K.TOL_R] = 0.5 * POSE_TOL
    P[K.CHECK] = -1.0 if mirror else (1.0 if check_all else 0.0)
    P.setflags(write=False)
    return P


def raw_solve(params: np.ndarray, T: np.ndarray, qn: np.ndarray | None = None,
              *, packed: np.ndarray) -> tuple[np.ndarray, ...]:
    """The bare kernel call, without input checks.

    T (N, 4, 4) contiguous float64 -> (Q (N, 8, 6), valid, singular, within_limits
    (N, 8), status (N,) int8).

    ``singular`` and ``within_limits`` are False on rows that are not valid.
    Batches of ``_PARALLEL_MIN`` poses or more run on the kernels' thread pool.
    The family is recorded in ``params`` (``pack``); ``packed`` is the chain's
    ``ChainArrays.packed`` (solutions are checked and polished on it).
    """
    return K.six_r_ik(params, T, _NO_Q_NEAR if qn is None else qn, packed)


_NO_Q_NEAR = np.full((1, 6), np.nan)  # no preference at the wrist singularity
_NO_Q_NEAR.setflags(write=False)


def make_single(chain: Chain, params: np.ndarray, *, method: str,
                info: dict[str, Any]) -> Any:
    """The single-pose hot path of an exact (not near-family) 6R arm.

    Returns ``single(T, q6) -> SolutionSet | None`` for one pose ``T`` (4, 4)
    float64 and the preferred joint-6 value ``q6`` at the wrist singularity (NaN: none,
    q6 = 0 there). The pose is
    validated inside the same compiled call (``six_r_ik1``); ``None`` means it is
    not a rigid transform (the caller re-checks it to raise the detailed error).
    Every call returns freshly allocated arrays; only the read-only joint kinds,
    limits and branch labels are shared between results.
    """
    # the copy for one pose (AVX2 on an AVX-512 CPU: 4 lanes cost less than 8 for
    # a lone pose; both copies give the same bits, tested)
    solve1 = single_copy.six_r_ik1
    packed = chain.arrays.packed
    is_rev, limits = read_only_joint_data(chain)
    labels = branch_labels((), _LABELS)
    bad = K.BAD_POSE
    texts = tuple(STATUS_TEXT)
    obj = object
    array = np.array
    trusted = SolutionSet._trusted

    def single(T: np.ndarray, q6: float) -> SolutionSet | None:
        code, Q, valid, sing, inside = solve1(T, params, q6, packed)
        if code >= bad or Q is None or valid is None or sing is None or inside is None:
            return None
        return trusted(Q, valid, is_rev, limits,
                       {"within_limits": inside, "singular": sing}, dict(labels),
                       array(texts[code], dtype=obj), method, None, dict(info))

    return single


def solve_six_r(
    robot: Arm,
    T: np.ndarray,
    q_near: np.ndarray | None,
    *,
    params: np.ndarray,
    method: str,
    info: dict[str, Any],
    near: bool = False,
    compute_error: bool = False,
    polish_iterations: int = 8,
    tol: float = 1e-9,
) -> SolutionSet:
    """Every solution of a 6R family for poses T (..., 4, 4)."""
    T = np.asarray(T, dtype=np.float64)
    lead = T.shape[:-2]
    Tf = np.ascontiguousarray(T.reshape(-1, 4, 4))
    qn = q_near_rows(q_near, lead, 6)
    Q, valid, sing, inside, status = raw_solve(params, Tf, qn,
                                               packed=robot.chain.arrays.packed)
    Q = Q.reshape(lead + (8, 6))
    valid = valid.reshape(lead + (8,))
    sing = sing.reshape(lead + (8,))
    inside = inside.reshape(lead + (8,))
    status = status.reshape(lead)
    error = None
    info = dict(info)
    if near:
        from robokin.kinematics.ik.analytic.near import polish

        Q, valid, inside, error, status, pinfo = polish(
            robot, T, Q, valid, status, iterations=polish_iterations, tol=tol
        )
        info.update(pinfo)
    elif compute_error:
        dp, dr = fk_error(robot.chain, Q, T)
        error = np.where(valid, np.hypot(dp, dr), np.inf)
    if near:
        out = make_set(
            robot, Q, valid, inside=inside, singular=sing,
            branches=branch_labels(lead, _LABELS), status_codes=status,
            method=method, info=info, error=error,
        )
        out.flags["polished"] = valid.copy()
        return out
    # the kernel leaves 'singular' and 'within_limits' False on invalid rows
    st = np.asarray(STATUS_TEXT[status], dtype=object)
    return SolutionSet._trusted(
        Q, valid, np.array(robot.is_revolute, dtype=bool), robot.limits,
        {"within_limits": inside, "singular": sing}, branch_labels(lead, _LABELS),
        st, method, error, info)
