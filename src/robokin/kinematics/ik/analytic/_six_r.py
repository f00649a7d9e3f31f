"""Shared driver of the two 6R closed forms (three parallel axes, spherical wrist).

The geometry is read from the canonical chain (product of exponentials, see
``_geometry``), nearly-parallel / nearly-meeting axes are snapped to the nominal
family, and the result is packed into the flat parameter vector the compiled
kernels read (``_kernels6r``).
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np

from robokin.kinematics.ik.analytic._common import (
    STATUS_TEXT,
    branch_labels,
    fk_error,
    make_set,
    q_near_rows,
)
from robokin.kinematics.ik.analytic._geometry import (
    Poe,
    closest_point,
    poe_from_chain,
    unit_perpendicular,
)
from robokin.kinematics.ik.solutions import SolutionSet

__all__ = ["make_single", "pack", "raw_solve", "solve_six_r"]

Kind = Literal["three_parallel", "spherical_wrist"]

# slot = 4 * shoulder + 2 * elbow + wrist; 0 -> +1 ('+' root), 1 -> -1
_LABELS = {
    "shoulder": [1, 1, 1, 1, -1, -1, -1, -1],
    "elbow": [1, 1, -1, -1, 1, 1, -1, -1],
    "wrist": [1, -1, 1, -1, 1, -1, 1, -1],
}
# Below this many poses one thread beats the parallel launch.
_PARALLEL_MIN = 512


def pack(chain: Any, kind: Kind, *, singular_tol: float = 1e-9,
         disc_tol: float = 1e-12, mirror: bool = False,
         poe: Poe | None = None) -> np.ndarray:
    """The kernel parameter vector of a 6R chain (layout in ``_kernels6r``)."""
    from robokin.kinematics.ik.analytic import _kernels6r as K

    poe = poe_from_chain(chain) if poe is None else poe
    h = poe.h.copy()
    o = poe.o.copy()
    s3 = 1.0 if h[1] @ h[2] >= 0 else -1.0
    s4 = 1.0 if h[1] @ h[3] >= 0 else -1.0
    if kind == "three_parallel":
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
    V = P[:51].reshape(17, 3)
    V[0:6] = h
    V[6:10] = o[0:4]
    V[10] = ow
    V[12] = poe.M[:3, 3]
    V[13:16] = poe.M[:3, :3]
    V[16] = e
    P[K.SIGN:K.SIGN + 6] = chain.arrays.sign
    P[K.OFFSET:K.OFFSET + 6] = chain.arrays.offset
    lim = chain.limits
    P[K.LO:K.LO + 6] = lim[:, 0]
    P[K.HI:K.HI + 6] = lim[:, 1]
    P[K.S3], P[K.S4] = s3, s4
    P[K.SING_TOL] = singular_tol
    P[K.DISC_TOL] = disc_tol
    P[K.MIRROR] = 1.0 if mirror else 0.0
    # pose-independent subproblem coefficients (theta3: |a + rot(h3, t) b|,
    # theta5: h . rot(h5, t) h6 with h = h2 (three parallel) or h4 (spherical))
    a = V[8] - V[7]
    b = (V[9] if kind == "three_parallel" else V[10]) - V[8]
    hw = V[1] if kind == "three_parallel" else V[3]
    for (ia, ib, ic, iphi), (hh, kk, pp) in (
        ((K.A3, K.B3, K.C3, K.PHI3), (a, V[2], b)),
        ((K.A5, K.B5, K.C5, K.PHI5), (hw, V[4], V[5])),
    ):
        kp = kk @ pp
        hk = hh @ kk
        A, B, C = hh @ pp - hk * kp, hh @ np.cross(kk, pp), hk * kp
        r = np.hypot(A, B)
        P[ia], P[ib], P[ic] = A, B, C
        P[iphi] = np.arctan2(B, A)
        P[iphi + 1], P[iphi + 2] = (A / r, B / r) if r > 0 else (1.0, 0.0)
    P[K.AA] = a @ a
    P[K.BB] = b @ b
    P.setflags(write=False)
    return P


def raw_solve(kind: Kind, params: np.ndarray, T: np.ndarray,
              qn: np.ndarray | None = None) -> tuple[np.ndarray, ...]:
    """The bare kernel call: T (N, 4, 4) contiguous float64 -> (Q (N, 8, 6), valid,
    singular, within_limits (N, 8), status (N,) int8). No input checks.

    ``singular`` and ``within_limits`` are False on rows that are not valid.
    Batches of ``_PARALLEL_MIN`` poses or more run on every thread.
    """
    from robokin.kinematics.ik.analytic import _kernels6r as K

    N = T.shape[0]
    Q = np.empty((N, 8, 6))
    valid = np.empty((N, 8), np.bool_)
    sing = np.empty((N, 8), np.bool_)
    inside = np.empty((N, 8), np.bool_)
    status = np.empty(N, np.int8)
    if qn is None:
        qn = _NO_Q_NEAR
    if kind == "three_parallel":
        fn = K.three_parallel_parallel if N >= _PARALLEL_MIN else K.three_parallel_serial
    else:
        fn = K.spherical_parallel if N >= _PARALLEL_MIN else K.spherical_serial
    fn(T, params, qn, Q, valid, sing, inside, status)
    return Q, valid, sing, inside, status


_NO_Q_NEAR = np.zeros((1, 6))
_NO_Q_NEAR.setflags(write=False)


def _entry_point(kern: Any, args: tuple) -> Any:
    """The compiled overload of ``kern`` for exactly the types of ``args``, called
    without numba's per-call type dispatch (a third of a microsecond); ``kern``
    itself if that overload cannot be found. Callers must pass arguments of the
    same types (C-contiguous arrays of the same dtypes and dimensions)."""
    import numba

    kern(*args)  # compile or load from the cache
    try:
        sig = tuple(numba.typeof(a) for a in args)
        return kern.overloads[sig].entry_point
    except (AttributeError, KeyError, TypeError):
        return kern


def make_single(chain: Any, kind: Kind, params: np.ndarray, *, method: str,
                info: dict[str, Any]) -> Any:
    """The single-pose hot path of an exact (not near-family) 6R arm.

    Returns ``single(T, q6) -> SolutionSet | None`` for one pose ``T`` (4, 4)
    float64 and the joint-6 value ``q6`` kept at the wrist singularity. The pose is
    validated inside the same compiled call; ``None`` means it is not a rigid
    transform (the caller re-checks it to raise the detailed error). Every call
    returns freshly allocated arrays; only the read-only joint kinds, limits and
    branch labels are shared between results.
    """
    from robokin.kinematics.ik.analytic import _kernels6r as K

    kern = K.three_parallel_checked if kind == "three_parallel" else K.spherical_checked
    direct = _entry_point(kern, (np.eye(4), params, 0.0, np.empty((8, 6)),
                                 np.empty(8, np.bool_), np.empty(8, np.bool_),
                                 np.empty(8, np.bool_)))
    is_rev = np.array(chain.is_revolute, dtype=bool)
    is_rev.setflags(write=False)
    limits = np.asarray(chain.limits, dtype=np.float64)
    if limits.flags.writeable:
        limits = limits.copy()
        limits.setflags(write=False)
    labels = branch_labels((), _LABELS)
    bad = K.BAD_POSE
    texts = tuple(STATUS_TEXT)
    empty = np.empty
    b1 = np.bool_
    obj = object
    array = np.array
    trusted = SolutionSet._trusted

    def single(T: np.ndarray, q6: float) -> SolutionSet | None:
        Q = empty((8, 6))
        valid = empty(8, b1)
        sing = empty(8, b1)
        inside = empty(8, b1)
        if T.flags.c_contiguous:
            code = direct(T, params, q6, Q, valid, sing, inside)
        else:
            code = kern(T, params, q6, Q, valid, sing, inside)
        if code >= bad:
            return None
        return trusted(Q, valid, is_rev, limits,
                       {"within_limits": inside, "singular": sing}, dict(labels),
                       array(texts[code], dtype=obj), method, None, dict(info))

    return single


def solve_six_r(
    robot: Any,
    T: np.ndarray,
    q_near: np.ndarray | None,
    *,
    kind: Kind,
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
    Q, valid, sing, inside, status = raw_solve(kind, params, Tf, qn)
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
