"""Compiled (numba) inner loops of the numeric IK solver.

Imported lazily by :mod:`robokin.kinematics.ik.numeric` (numba is slow to import).
The FK / Jacobian evaluation is a private copy of the ideas in
``robokin.kinematics._kernels`` (numba's cache does not track functions inlined
from another module, so sharing them would risk stale caches).

Packed inputs (built once per chain by ``numeric._ChainData``):

* ``consts`` (n_chain + 1, 4, 4): the chain's constant transforms.
* ``jdat`` (9, n_chain): rows kind (1.0 = prismatic), sign, offset, then
  ``[1, cos a, sin a, tx, ty, tz]`` when ``consts[k + 1]`` is ``Trans(t) Rx(a)``
  (zeros otherwise).
* ``Mc`` (n_chain, n + 1): the coupling ``q_chain = M q + c`` as ``[M | c]``.
* ``cdat`` (5, n): rows lower limit, upper limit, seed lower, seed upper bound,
  and 1.0 where a coordinate may be shifted by 2*pi without changing the pose.
* ``opts`` (N_OPTS,): see the ``O_*`` indices below.

Outputs per target (``out`` rows): q (n), then ``R_*`` columns.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

# opts indices
O_W = 0  # 6 task weights, 0 = masked out
O_TOL_P = 6
O_TOL_R = 7
O_MAX_ITER = 8  # iterations per attempt
O_IDENT = 9  # 1.0 when the coupling is the identity
O_USE_Q0 = 10  # 1.0: first attempt from q0
O_MAX_STEP = 11  # largest joint step per iteration [rad or m]
O_MU0 = 12
O_N_SEEDS = 13  # random restarts available (<= seeds.shape[1])
O_PATH_MAX_JUMP = 14  # ik_path: largest accepted joint change per sample
O_STALL_EVERY = 15  # check progress every this many iterations ...
O_STALL_RATIO = 16  # ... and give up unless the cost fell below ratio * before
O_MU_DOWN = 17  # damping factor after an accepted step
O_MU_UP = 18  # damping factor after a rejected step
O_SEED_SHRINK = 19  # odd restarts seed in [lo + f span, hi - f span]
O_N_TABLE = 20  # the first restarts start from this many seed-table entries
O_TABLE_ROT = 21  # squared length [m^2] per unit squared rotation distance, 0: position only
N_OPTS = 22

# seed table (built once per chain by ``numeric._ChainData.seed_table``): ``tab`` (M,
# 12 + n) rows [p (3), R row-major (9), q (n)] sorted by grid cell of p; ``cstart``
# (G^3 + 1) first row of each cell; ``gdat`` (7,) grid origin (3), inverse cell size
# (3) and G.
TAB_K_MAX = 8  # most table seeds per target

# result columns after q
R_ERR = 0  # combined residual norm (masked, unweighted) [m, rad]
R_EP = 1  # position residual norm [m]
R_ER = 2  # rotation residual norm [rad]
R_ITERS = 3
R_RESTARTS = 4
R_CODE = 5
N_RES = 6

CODE_OK = 0
CODE_ITER = 1  # iteration budget of the last attempt ran out
CODE_STALL = 2  # stuck in a local minimum / at a joint limit
CODE_BAD_TARGET = 3  # non-finite or not a rigid transform
CODE_JUMP = 4  # ik_path: joint jump larger than allowed
CODE_NOT_RUN = 5  # ik_path: after an earlier failure
CODE_BAD_Q0 = 6  # the initial guess holds NaN / inf

_MU_MAX = 1e9
_MU_MIN = 1e-9


# sincos: a private copy of ``robokin.kinematics._kernels.sincos`` (numba's cache does
# not track functions inlined from another module). Cody-Waite reduction by pi/2 and
# the fdlibm kernel polynomials, < 1 ulp; one reduction for both values.
_INV_PIO2 = 6.36619772367581382433e-01
_PIO2_1 = 1.57079632673412561417e00
_PIO2_2 = 6.07710050630396597660e-11
_PIO2_3 = 2.02226624871116645580e-21
_S1, _S2, _S3 = (
    -1.66666666666666324348e-01,
    8.33333333332248946124e-03,
    -1.98412698298579493134e-04,
)
_S4, _S5, _S6 = (
    2.75573137070700676789e-06,
    -2.50507602534068634195e-08,
    1.58969099521155010221e-10,
)
_C1, _C2, _C3 = (
    4.16666666666666019037e-02,
    -1.38888888888741095749e-03,
    2.48015872894767294178e-05,
)
_C4, _C5, _C6 = (
    -2.75573143513906633035e-07,
    2.08757232129817482790e-09,
    -1.13596475577881948265e-11,
)


@njit(cache=True, inline="always")
def _sincos(x):
    """(sin x, cos x) for float x; libm beyond |x| = 1e5 and for NaN / inf."""
    if not abs(x) < 1e5:
        return math.sin(x), math.cos(x)
    n = math.floor(x * _INV_PIO2 + 0.5)
    y = ((x - n * _PIO2_1) - n * _PIO2_2) - n * _PIO2_3
    z = y * y
    r = _S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))
    sy = y + z * y * (_S1 + z * r)
    rc = z * (_C1 + z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * _C6)))))
    hz = 0.5 * z
    w = 1.0 - hz
    cy = w + (((1.0 - w) - hz) + z * rc)
    k = int(n) & 3
    if k == 0:
        return sy, cy
    if k == 1:
        return cy, -sy
    if k == 2:
        return -sy, -cy
    return -cy, sy


@njit(cache=True, inline="always")
def _joint_right(T, kind, v):
    """T <- T @ J(v): rotation about / translation along local z."""
    if kind == 0.0:
        s, c = _sincos(v)
        for r in range(3):
            x0 = T[r, 0]
            x1 = T[r, 1]
            T[r, 0] = c * x0 + s * x1
            T[r, 1] = c * x1 - s * x0
    else:
        for r in range(3):
            T[r, 3] += T[r, 2] * v


@njit(cache=True, inline="always")
def _const_right(T, C):
    """T <- T @ C for an affine C (last row 0 0 0 1)."""
    for r in range(3):
        a0 = T[r, 0]
        a1 = T[r, 1]
        a2 = T[r, 2]
        a3 = T[r, 3]
        T[r, 0] = a0 * C[0, 0] + a1 * C[1, 0] + a2 * C[2, 0]
        T[r, 1] = a0 * C[0, 1] + a1 * C[1, 1] + a2 * C[2, 1]
        T[r, 2] = a0 * C[0, 2] + a1 * C[1, 2] + a2 * C[2, 2]
        T[r, 3] = a0 * C[0, 3] + a1 * C[1, 3] + a2 * C[2, 3] + a3


@njit(cache=True, inline="always")
def _pose_jac(q, Mc, ident, consts, jdat, qc, Jc, J, T):
    """Pose (top 3x4 of T) and Jacobian J (6, n) w.r.t. the independent q."""
    nc = jdat.shape[1]
    n = q.shape[0]
    if ident:
        for i in range(nc):
            qc[i] = q[i]
    else:
        for i in range(nc):
            s = Mc[i, n]
            for j in range(n):
                s += Mc[i, j] * q[j]
            qc[i] = s
    # sines and cosines first, in a loop of independent iterations (the polynomials of
    # all joints overlap instead of each waiting for the transform before it); parked
    # in rows 0 and 1 of Jc, which the loop below reads before it overwrites them
    for k in range(nc):
        if jdat[0, k] == 0.0:
            sk, ck = _sincos(jdat[1, k] * qc[k] + jdat[2, k])
            Jc[0, k] = sk
            Jc[1, k] = ck
    # the running transform in scalars (no aliasing with the arrays written below)
    C0 = consts[0]
    t00 = C0[0, 0]
    t01 = C0[0, 1]
    t02 = C0[0, 2]
    t03 = C0[0, 3]
    t10 = C0[1, 0]
    t11 = C0[1, 1]
    t12 = C0[1, 2]
    t13 = C0[1, 3]
    t20 = C0[2, 0]
    t21 = C0[2, 1]
    t22 = C0[2, 2]
    t23 = C0[2, 3]
    for k in range(nc):
        if jdat[0, k] == 0.0:
            sk = Jc[0, k]
            ck = Jc[1, k]
            x0 = t00
            t00 = ck * x0 + sk * t01
            t01 = ck * t01 - sk * x0
            x0 = t10
            t10 = ck * x0 + sk * t11
            t11 = ck * t11 - sk * x0
            x0 = t20
            t20 = ck * x0 + sk * t21
            t21 = ck * t21 - sk * x0
        else:
            v = jdat[1, k] * qc[k] + jdat[2, k]
            t03 += t02 * v
            t13 += t12 * v
            t23 += t22 * v
        Jc[0, k] = t03
        Jc[1, k] = t13
        Jc[2, k] = t23
        Jc[3, k] = t02
        Jc[4, k] = t12
        Jc[5, k] = t22
        if jdat[3, k] == 1.0:
            # consts[k + 1] is Trans(tx, ty, tz) Rx(a) (every DH row): fewer products
            ca = jdat[4, k]
            sa = jdat[5, k]
            tx = jdat[6, k]
            ty = jdat[7, k]
            tz = jdat[8, k]
            t03 += t00 * tx + t01 * ty + t02 * tz
            t13 += t10 * tx + t11 * ty + t12 * tz
            t23 += t20 * tx + t21 * ty + t22 * tz
            a1 = t01
            t01 = ca * a1 + sa * t02
            t02 = ca * t02 - sa * a1
            a1 = t11
            t11 = ca * a1 + sa * t12
            t12 = ca * t12 - sa * a1
            a1 = t21
            t21 = ca * a1 + sa * t22
            t22 = ca * t22 - sa * a1
        else:
            C = consts[k + 1]
            c00 = C[0, 0]
            c01 = C[0, 1]
            c02 = C[0, 2]
            c10 = C[1, 0]
            c11 = C[1, 1]
            c12 = C[1, 2]
            c20 = C[2, 0]
            c21 = C[2, 1]
            c22 = C[2, 2]
            c03 = C[0, 3]
            c13 = C[1, 3]
            c23 = C[2, 3]
            a0 = t00
            a1 = t01
            a2 = t02
            t00 = a0 * c00 + a1 * c10 + a2 * c20
            t01 = a0 * c01 + a1 * c11 + a2 * c21
            t02 = a0 * c02 + a1 * c12 + a2 * c22
            t03 += a0 * c03 + a1 * c13 + a2 * c23
            a0 = t10
            a1 = t11
            a2 = t12
            t10 = a0 * c00 + a1 * c10 + a2 * c20
            t11 = a0 * c01 + a1 * c11 + a2 * c21
            t12 = a0 * c02 + a1 * c12 + a2 * c22
            t13 += a0 * c03 + a1 * c13 + a2 * c23
            a0 = t20
            a1 = t21
            a2 = t22
            t20 = a0 * c00 + a1 * c10 + a2 * c20
            t21 = a0 * c01 + a1 * c11 + a2 * c21
            t22 = a0 * c02 + a1 * c12 + a2 * c22
            t23 += a0 * c03 + a1 * c13 + a2 * c23
    T[0, 0] = t00
    T[0, 1] = t01
    T[0, 2] = t02
    T[0, 3] = t03
    T[1, 0] = t10
    T[1, 1] = t11
    T[1, 2] = t12
    T[1, 3] = t13
    T[2, 0] = t20
    T[2, 1] = t21
    T[2, 2] = t22
    T[2, 3] = t23
    px = t03
    py = t13
    pz = t23
    for k in range(nc):
        zx = Jc[3, k]
        zy = Jc[4, k]
        zz = Jc[5, k]
        s = jdat[1, k]
        if jdat[0, k] == 0.0:
            dx = px - Jc[0, k]
            dy = py - Jc[1, k]
            dz = pz - Jc[2, k]
            Jc[0, k] = s * (zy * dz - zz * dy)
            Jc[1, k] = s * (zz * dx - zx * dz)
            Jc[2, k] = s * (zx * dy - zy * dx)
            Jc[3, k] = s * zx
            Jc[4, k] = s * zy
            Jc[5, k] = s * zz
        else:
            Jc[0, k] = s * zx
            Jc[1, k] = s * zy
            Jc[2, k] = s * zz
            Jc[3, k] = 0.0
            Jc[4, k] = 0.0
            Jc[5, k] = 0.0
    if ident:
        for r in range(6):
            for j in range(n):
                J[r, j] = Jc[r, j]
    else:
        for r in range(6):
            for j in range(n):
                s = 0.0
                for i in range(nc):
                    s += Jc[r, i] * Mc[i, j]
                J[r, j] = s


@njit(cache=True, inline="always")
def _residual(T, Tt, e):
    """Task error e (6,) = [p_t - p; log(R_t R^T)] in the base frame."""
    for r in range(3):
        e[r] = Tt[r, 3] - T[r, 3]
    # Re = Rt @ R^T
    r00 = Tt[0, 0] * T[0, 0] + Tt[0, 1] * T[0, 1] + Tt[0, 2] * T[0, 2]
    r01 = Tt[0, 0] * T[1, 0] + Tt[0, 1] * T[1, 1] + Tt[0, 2] * T[1, 2]
    r02 = Tt[0, 0] * T[2, 0] + Tt[0, 1] * T[2, 1] + Tt[0, 2] * T[2, 2]
    r10 = Tt[1, 0] * T[0, 0] + Tt[1, 1] * T[0, 1] + Tt[1, 2] * T[0, 2]
    r11 = Tt[1, 0] * T[1, 0] + Tt[1, 1] * T[1, 1] + Tt[1, 2] * T[1, 2]
    r12 = Tt[1, 0] * T[2, 0] + Tt[1, 1] * T[2, 1] + Tt[1, 2] * T[2, 2]
    r20 = Tt[2, 0] * T[0, 0] + Tt[2, 1] * T[0, 1] + Tt[2, 2] * T[0, 2]
    r21 = Tt[2, 0] * T[1, 0] + Tt[2, 1] * T[1, 1] + Tt[2, 2] * T[1, 2]
    r22 = Tt[2, 0] * T[2, 0] + Tt[2, 1] * T[2, 1] + Tt[2, 2] * T[2, 2]
    vx = 0.5 * (r21 - r12)
    vy = 0.5 * (r02 - r20)
    vz = 0.5 * (r10 - r01)
    s = math.sqrt(vx * vx + vy * vy + vz * vz)
    c = 0.5 * (r00 + r11 + r22 - 1.0)
    if c > 0.0 and s < 0.1 * c:
        # small angles (every descent's last iterations): th / s = atan(x) / (x c) with
        # x = s / c < 0.1, by its Maclaurin series to x^14 (next term < 1e-17): no atan2
        ic = 1.0 / c
        x = s * ic
        z = x * x
        f = ic * (1.0 + z * (-1.0 / 3.0 + z * (1.0 / 5.0 + z * (-1.0 / 7.0 + z * (
            1.0 / 9.0 + z * (-1.0 / 11.0 + z * (1.0 / 13.0 + z * (-1.0 / 15.0))))))))
        e[3] = f * vx
        e[4] = f * vy
        e[5] = f * vz
    elif c > -0.9:
        th = math.atan2(s, c)
        f = th / s if s > 1e-10 else 1.0 + s * s / 6.0
        e[3] = f * vx
        e[4] = f * vy
        e[5] = f * vz
    else:
        # near pi: axis from the symmetric part B = (1 - c) a a^T
        th = math.atan2(s, c)
        omc = 1.0 - c
        b00 = r00 - c
        b11 = r11 - c
        b22 = r22 - c
        if b00 >= b11 and b00 >= b22:
            d = math.sqrt(max(b00 * omc, 1e-300))
            ax = b00 / d
            ay = 0.5 * (r01 + r10) / d
            az = 0.5 * (r02 + r20) / d
        elif b11 >= b22:
            d = math.sqrt(max(b11 * omc, 1e-300))
            ax = 0.5 * (r01 + r10) / d
            ay = b11 / d
            az = 0.5 * (r12 + r21) / d
        else:
            d = math.sqrt(max(b22 * omc, 1e-300))
            ax = 0.5 * (r02 + r20) / d
            ay = 0.5 * (r12 + r21) / d
            az = b22 / d
        if ax * vx + ay * vy + az * vz < 0.0:
            ax = -ax
            ay = -ay
            az = -az
        e[3] = th * ax
        e[4] = th * ay
        e[5] = th * az


@njit(cache=True, inline="always")
def _errors(e, w):
    """(weighted cost, position norm, rotation norm) over the unmasked rows."""
    cost = 0.0
    ep = 0.0
    er = 0.0
    for i in range(3):
        if w[i] > 0.0:
            cost += w[i] * e[i] * e[i]
            ep += e[i] * e[i]
    for i in range(3, 6):
        if w[i] > 0.0:
            cost += w[i] * e[i] * e[i]
            er += e[i] * e[i]
    return cost, math.sqrt(ep), math.sqrt(er)


@njit(cache=True, inline="always")
def _chol_solve(A, b, m):
    """Solve A x = b in place (x into b) for SPD A (m x m); False if not SPD."""
    for j in range(m):
        s = A[j, j]
        for k in range(j):
            s -= A[j, k] * A[j, k]
        if not s > 0.0:
            return False
        d = math.sqrt(s)
        A[j, j] = d
        for i in range(j + 1, m):
            t = A[i, j]
            for k in range(j):
                t -= A[i, k] * A[j, k]
            A[i, j] = t / d
    for i in range(m):
        t = b[i]
        for k in range(i):
            t -= A[i, k] * b[k]
        b[i] = t / A[i, i]
    for i in range(m - 1, -1, -1):
        t = b[i]
        for k in range(i + 1, m):
            t -= A[k, i] * b[k]
        b[i] = t / A[i, i]
    return True

@njit(cache=True, inline="always")
def _ldl_solve6(A, b, dinv):
    """Solve A x = b in place (x into b) for SPD A (6 x 6) by A = L D L^T.

    Reads only the lower triangle of A and overwrites it with ``L D`` (no square
    roots, one reciprocal per column: the substitutions multiply, they do not
    divide, which shortens the dependency chain). False if A is not SPD.
    """
    for j in range(6):
        s = A[j, j]
        for k in range(j):
            a = A[j, k]
            s -= a * a * dinv[k]
        if not s > 0.0:
            return False
        dinv[j] = 1.0 / s
        for i in range(j + 1, 6):
            t = A[i, j]
            for k in range(j):
                t -= A[i, k] * A[j, k] * dinv[k]
            A[i, j] = t
    for i in range(6):
        t = b[i]
        for k in range(i):
            t -= A[i, k] * dinv[k] * b[k]
        b[i] = t
    for i in range(5, -1, -1):
        di = dinv[i]
        t = b[i] * di
        for k in range(i + 1, 6):
            t -= A[k, i] * di * b[k]
        b[i] = t
    return True


@njit(cache=True, inline="always")
def _project(q, cdat):
    """Shift 2*pi-periodic coordinates into their limits where possible, then clamp."""
    tp = 2.0 * math.pi
    for j in range(q.shape[0]):
        lo = cdat[0, j]
        hi = cdat[1, j]
        v = q[j]
        if cdat[4, j] == 1.0:
            if v > hi:
                k = math.ceil((v - hi) / tp)
                if v - k * tp >= lo:
                    v -= k * tp
            elif v < lo:
                k = math.ceil((lo - v) / tp)
                if v + k * tp <= hi:
                    v += k * tp
        if v > hi:
            v = hi
        elif v < lo:
            v = lo
        q[j] = v


# _nrt=False: no reference counting in the two per-target functions. They allocate
# nothing (every buffer is a view into the caller's work array), and the
# atomic increments and decrements for the ~30 views per target cost ~0.3 us.
# fastmath={"contract"} only: a * b + c may become one fused multiply-add (one
# rounding instead of two, shorter dependency chains: ~7% per iteration); no other
# fast-math licence (NaN / inf checks and the order of sums stay as written).
@njit(cache=True, _nrt=False, fastmath={"contract"})
def _attempt(q, Tt, consts, jdat, Mc, cdat, opts, rows, sw, max_iter,
             qc, Jc, J, T, e, qn, Jn, Tn, en, Jw, A, g, y, dq, free, A6, y6, d6):
    """One damped least-squares (Levenberg-Marquardt) descent from q (updated in place).

    Returns (code, iterations, ep, er, cost).
    """
    n = q.shape[0]
    m = rows.shape[0]
    ident = opts[O_IDENT] == 1.0
    tol_p = opts[O_TOL_P]
    tol_r = opts[O_TOL_R]
    max_step = opts[O_MAX_STEP]
    w = opts[O_W:O_W + 6]
    _project(q, cdat)
    _pose_jac(q, Mc, ident, consts, jdat, qc, Jc, J, T)
    _residual(T, Tt, e)
    cost, ep, er = _errors(e, w)
    if not math.isfinite(cost):
        return CODE_STALL, 0, ep, er, cost
    mu = opts[O_MU0]
    mu_down = opts[O_MU_DOWN]
    mu_up = opts[O_MU_UP]
    it = 0
    check_every = int(opts[O_STALL_EVERY])
    stall_ratio = opts[O_STALL_RATIO]
    next_check = check_every
    cost_ref = cost
    while True:
        if ep <= tol_p and er <= tol_r:
            return CODE_OK, it, ep, er, cost
        if it >= max_iter:
            return CODE_ITER, it, ep, er, cost
        if it >= next_check:
            # too little progress: a (limit-constrained) local minimum; restart
            if cost > stall_ratio * cost_ref:
                return CODE_STALL, it, ep, er, cost
            cost_ref = cost
            next_check = it + check_every
        # weighted task rows; freeze joints that the gradient J^T W e pushes into a
        # limit (only joints at a limit need their gradient component)
        for a in range(m):
            r = rows[a]
            for j in range(n):
                Jw[a, j] = sw[a] * J[r, j]
        nfree = 0
        for j in range(n):
            f = True
            if cdat[4, j] == 0.0:
                hi = q[j] >= cdat[1, j]
                lo = q[j] <= cdat[0, j]
                if hi or lo:
                    gj = 0.0
                    for a in range(m):
                        gj += Jw[a, j] * sw[a] * e[rows[a]]
                    f = not ((hi and gj > 0.0) or (lo and gj < 0.0))
            free[j] = 1.0 if f else 0.0
            if f:
                nfree += 1
            else:
                for a in range(m):
                    Jw[a, j] = 0.0
        if nfree == 0:
            return CODE_STALL, it, ep, er, cost
        if m > nfree:
            # the joint-space form needs the gradient of the free joints
            for j in range(n):
                gj = 0.0
                if free[j] == 1.0:
                    for a in range(m):
                        gj += Jw[a, j] * sw[a] * e[rows[a]]
                g[j] = gj
        accepted = False
        while not accepted:
            it += 1
            lam = mu * cost + 1e-14
            if m == 6 and nfree >= 6:
                # full pose, task space, fixed size 6 (unrolled by the compiler)
                for a in range(6):
                    for b in range(a + 1):
                        s = 0.0
                        for j in range(n):
                            s += Jw[a, j] * Jw[b, j]
                        A6[a, b] = s
                    A6[a, a] += lam
                    y6[a] = sw[a] * e[a]
                okc = _ldl_solve6(A6, y6, d6)
                for j in range(n):
                    s = 0.0
                    for a in range(6):
                        s += Jw[a, j] * y6[a]
                    dq[j] = s
            elif m <= nfree:
                # task space: (Jw Jw^T + lam I) y = W^1/2 e ; dq = Jw^T y
                for a in range(m):
                    for b in range(a + 1):
                        s = 0.0
                        for j in range(n):
                            s += Jw[a, j] * Jw[b, j]
                        A[a, b] = s
                        A[b, a] = s
                    A[a, a] += lam
                    y[a] = sw[a] * e[rows[a]]
                okc = _chol_solve(A, y, m)
                for j in range(n):
                    s = 0.0
                    for a in range(m):
                        s += Jw[a, j] * y[a]
                    dq[j] = s
            else:
                # joint space: (Jw^T Jw + lam I) dq = g
                for i in range(n):
                    for k in range(i + 1):
                        s = 0.0
                        for a in range(m):
                            s += Jw[a, i] * Jw[a, k]
                        A[i, k] = s
                        A[k, i] = s
                    A[i, i] += lam
                    dq[i] = g[i]
                okc = _chol_solve(A, dq, n)
            if okc:
                big = 0.0
                for j in range(n):
                    if abs(dq[j]) > big:
                        big = abs(dq[j])
                scale = max_step / big if big > max_step else 1.0
                for j in range(n):
                    qn[j] = q[j] + scale * dq[j]
                _project(qn, cdat)
                _pose_jac(qn, Mc, ident, consts, jdat, qc, Jc, Jn, Tn)
                _residual(Tn, Tt, en)
                cost_n, epn, ern = _errors(en, w)
                if cost_n < cost:
                    accepted = True
                    for j in range(n):
                        q[j] = qn[j]
                    # a copy, not a swap: reassigning array variables costs
                    # reference-count calls on every iteration
                    for r in range(6):
                        for j in range(n):
                            J[r, j] = Jn[r, j]
                    for r in range(6):
                        e[r] = en[r]
                    cost = cost_n
                    ep = epn
                    er = ern
                    mu = max(mu * mu_down, _MU_MIN)
                    break
            mu *= mu_up
            if mu > _MU_MAX:
                return CODE_STALL, it, ep, er, cost
            if it >= max_iter:
                return CODE_ITER, it, ep, er, cost
    return CODE_ITER, it, ep, er, cost  # pragma: no cover


@njit(cache=True)
def _check_target(Tt):
    """True when Tt is finite, has last row 0 0 0 1 and an orthonormal rotation."""
    for r in range(4):
        for c in range(4):
            if not math.isfinite(Tt[r, c]):
                return False
    if Tt[3, 0] != 0.0 or Tt[3, 1] != 0.0 or Tt[3, 2] != 0.0 or Tt[3, 3] != 1.0:
        return False
    for a in range(3):
        for b in range(3):
            s = Tt[0, a] * Tt[0, b] + Tt[1, a] * Tt[1, b] + Tt[2, a] * Tt[2, b]
            if abs(s - (1.0 if a == b else 0.0)) > 1e-6:
                return False
    det = (Tt[0, 0] * (Tt[1, 1] * Tt[2, 2] - Tt[1, 2] * Tt[2, 1])
           - Tt[0, 1] * (Tt[1, 0] * Tt[2, 2] - Tt[1, 2] * Tt[2, 0])
           + Tt[0, 2] * (Tt[1, 0] * Tt[2, 1] - Tt[1, 1] * Tt[2, 0]))
    return det > 0.0


@njit(cache=True, inline="always")
def _table_nearest(Tt, tab, cstart, gdat, k, rot_w, idx, dist):
    """Indices (into idx) of the k table rows nearest the target pose; returns the count.

    Distance ``|p - p_t|^2 + rot_w |R - R_t|_F^2``, searched over the grid cells within
    Chebyshev radius 1 of the target's cell (wider until k rows are found).
    """
    G = int(gdat[6])
    cx = int(math.floor((Tt[0, 3] - gdat[0]) * gdat[3]))
    cy = int(math.floor((Tt[1, 3] - gdat[1]) * gdat[4]))
    cz = int(math.floor((Tt[2, 3] - gdat[2]) * gdat[5]))
    cx = min(max(cx, 0), G - 1)
    cy = min(max(cy, 0), G - 1)
    cz = min(max(cz, 0), G - 1)
    found = 0
    r = 1
    r_prev = -1
    while True:
        for ix in range(max(cx - r, 0), min(cx + r, G - 1) + 1):
            for iy in range(max(cy - r, 0), min(cy + r, G - 1) + 1):
                for iz in range(max(cz - r, 0), min(cz + r, G - 1) + 1):
                    if (abs(ix - cx) <= r_prev and abs(iy - cy) <= r_prev
                            and abs(iz - cz) <= r_prev):
                        continue  # scanned at the smaller radius
                    cell = (ix * G + iy) * G + iz
                    for row in range(cstart[cell], cstart[cell + 1]):
                        dx = tab[row, 0] - Tt[0, 3]
                        dy = tab[row, 1] - Tt[1, 3]
                        dz = tab[row, 2] - Tt[2, 3]
                        d = dx * dx + dy * dy + dz * dz
                        if rot_w > 0.0:
                            sr = 0.0
                            for a in range(3):
                                for b in range(3):
                                    t = tab[row, 3 + 3 * a + b] - Tt[a, b]
                                    sr += t * t
                            d += rot_w * sr
                        # insert into the sorted best-k list
                        if found < k:
                            pos = found
                            found += 1
                        elif d < dist[k - 1]:
                            pos = k - 1
                        else:
                            continue
                        while pos > 0 and dist[pos - 1] > d:
                            dist[pos] = dist[pos - 1]
                            idx[pos] = idx[pos - 1]
                            pos -= 1
                        dist[pos] = d
                        idx[pos] = row
        if found >= k or r >= G:
            return found
        r_prev = r
        r += 1


@njit(cache=True)
def table_poses(Q, consts, jdat, Mc, ident, out):
    """Poses of the configurations Q (M, n) as rows [p (3), R row-major (9)] of out."""
    n = Q.shape[1]
    nc = jdat.shape[1]
    qc = np.empty(nc)
    Jc = np.empty((6, nc))
    J = np.empty((6, n))
    T = np.zeros((4, 4))
    for i in range(Q.shape[0]):
        _pose_jac(Q[i], Mc, ident, consts, jdat, qc, Jc, J, T)
        for a in range(3):
            out[i, a] = T[a, 3]
            for b in range(3):
                out[i, 3 + 3 * a + b] = T[a, b]


@njit(cache=True)
def work_size(n, nc):
    """Length of the float work buffer of :func:`_solve_target`."""
    nd = max(6, n)
    return 6 + 7 * nc + 18 * n + 44 + nd * nd + nd + 6 * n + 48 + TAB_K_MAX


@njit(cache=True, _nrt=False, fastmath={"contract"})
def _solve_target(Tt, q0, seeds, consts, jdat, Mc, cdat, opts, out, work, iwork, tab,
                  cstart, gdat):
    """Attempt from q0 (if asked) then from each seed until converged.

    The first ``opts[O_N_TABLE]`` restarts start from the seed-table configurations
    whose poses are nearest the target (searched only once q0 has failed), the
    others from ``seeds`` (R, n): uniform [0, 1) numbers mapped into the seed
    ranges. ``out`` gets the best q, then the result columns. ``iwork`` holds
    6 + TAB_K_MAX integers.
    """
    n = q0.shape[0]
    nc = jdat.shape[1]
    bad = 0
    if not _check_target(Tt):
        bad = CODE_BAD_TARGET
    elif opts[O_USE_Q0] == 1.0:
        for j in range(n):
            if not math.isfinite(q0[j]):
                bad = CODE_BAD_Q0
    if bad:
        for j in range(n):
            out[j] = 0.0
        out[n + R_ERR] = np.inf
        out[n + R_EP] = np.inf
        out[n + R_ER] = np.inf
        out[n + R_ITERS] = 0
        out[n + R_RESTARTS] = 0
        out[n + R_CODE] = bad
        return
    w = opts[O_W:O_W + 6]
    m = 0
    for i in range(6):
        if w[i] > 0.0:
            m += 1
    rows = iwork[:m]
    sw = work[:m]
    m = 0
    for i in range(6):
        if w[i] > 0.0:
            rows[m] = i
            sw[m] = math.sqrt(w[i])
            m += 1
    nd = max(m, n)
    # views into the one work buffer (see work_size)
    o = 6
    qc = work[o:o + nc]
    o += nc
    Jc = work[o:o + 6 * nc].reshape((6, nc))
    o += 6 * nc
    J = work[o:o + 6 * n].reshape((6, n))
    o += 6 * n
    Jn = work[o:o + 6 * n].reshape((6, n))
    o += 6 * n
    Jw = work[o:o + m * n].reshape((m, n))
    o += 6 * n
    T = work[o:o + 16].reshape((4, 4))
    o += 16
    Tn = work[o:o + 16].reshape((4, 4))
    o += 16
    e = work[o:o + 6]
    o += 6
    en = work[o:o + 6]
    o += 6
    A = work[o:o + nd * nd].reshape((nd, nd))
    o += nd * nd
    y = work[o:o + nd]
    o += nd
    qn = work[o:o + n]
    o += n
    g = work[o:o + n]
    o += n
    dq = work[o:o + n]
    o += n
    free = work[o:o + n]
    o += n
    q = work[o:o + n]
    o += n
    best = work[o:o + n]
    o += n
    A6 = work[o:o + 36].reshape((6, 6))
    o += 36
    y6 = work[o:o + 6]
    o += 6
    d6 = work[o:o + 6]
    o += 6
    tdist = work[o:o + TAB_K_MAX]
    tidx = iwork[6:6 + TAB_K_MAX]
    n_tab = min(int(opts[O_N_TABLE]), TAB_K_MAX) if tab.shape[0] > 0 else 0
    tab_found = -1
    best_cost = np.inf
    bep = np.inf
    ber = np.inf
    max_iter = int(opts[O_MAX_ITER])
    n_seeds = min(int(opts[O_N_SEEDS]), seeds.shape[0])
    total = 0
    restarts = 0
    code = CODE_STALL
    start = 0 if opts[O_USE_Q0] == 1.0 else 1
    for a in range(start, n_seeds + 1):
        if a == 0:
            for j in range(n):
                q[j] = q0[j]
        elif a <= n_tab and tab_found != 0:
            if tab_found < 0:
                tab_found = _table_nearest(Tt, tab, cstart, gdat, n_tab, opts[O_TABLE_ROT],
                                           tidx, tdist)
            if a > tab_found:
                # fewer table rows than asked for: this restart is a random one
                for j in range(n):
                    q[j] = cdat[2, j] + seeds[a - 1, j] * (cdat[3, j] - cdat[2, j])
            else:
                row = tidx[a - 1]
                for j in range(n):
                    q[j] = tab[row, 12 + j]
            if a > 1 or start == 0:
                restarts += 1
        else:
            # alternate seeds from the central part of the range (descents from
            # there meet limits less often) with seeds from the whole range
            lo_f = 0.0
            span_f = 1.0
            if a % 2 == 1:
                lo_f = opts[O_SEED_SHRINK]
                span_f = 1.0 - 2.0 * lo_f
            for j in range(n):
                u = lo_f + span_f * seeds[a - 1, j]
                q[j] = cdat[2, j] + u * (cdat[3, j] - cdat[2, j])
            if a > 1 or start == 0:
                restarts += 1
        code, it, ep, er, cost = _attempt(q, Tt, consts, jdat, Mc, cdat, opts, rows, sw,
                                       max_iter, qc, Jc, J, T, e, qn, Jn, Tn, en, Jw, A,
                                       g, y, dq, free, A6, y6, d6)
        total += it
        if cost < best_cost or code == CODE_OK or a == start:
            best_cost = cost
            bep = ep
            ber = er
            for j in range(n):
                best[j] = q[j]
        if code == CODE_OK:
            break
    for j in range(n):
        out[j] = best[j]
    out[n + R_ERR] = math.sqrt(bep * bep + ber * ber)
    out[n + R_EP] = bep
    out[n + R_ER] = ber
    out[n + R_ITERS] = total
    out[n + R_RESTARTS] = restarts
    out[n + R_CODE] = code


@njit(cache=True)
def _summary(out, n):
    """(number not converged, index of the first bad input or -1)."""
    fails = 0
    first_bad = -1
    for i in range(out.shape[0]):
        c = out[i, n + R_CODE]
        if c != CODE_OK:
            fails += 1
            if first_bad < 0 and c in (CODE_BAD_TARGET, CODE_BAD_Q0):
                first_bad = i
    return fails, first_bad


@njit(cache=True)
def solve_serial(targets, q0, seeds, consts, jdat, Mc, cdat, opts, out, tab, cstart,
                 gdat):
    """Solve a batch: targets (N, 4, 4), q0 (N, n), seeds (N, R, n) -> out (N, n + N_RES).

    Returns (number not converged, index of the first bad target / q0 or -1).
    """
    n = q0.shape[1]
    work = np.empty(work_size(n, jdat.shape[1]))
    iwork = np.empty(6 + TAB_K_MAX, np.int64)
    for i in range(targets.shape[0]):
        _solve_target(targets[i], q0[i], seeds[i], consts, jdat, Mc, cdat, opts, out[i],
                      work, iwork, tab, cstart, gdat)
    return _summary(out, n)


@njit(cache=True, parallel=True)
def solve_parallel(targets, q0, seeds, consts, jdat, Mc, cdat, opts, out, tab, cstart,
                   gdat):
    """As :func:`solve_serial`, over all threads (one work buffer per chunk)."""
    N = targets.shape[0]
    n = q0.shape[1]
    size = work_size(n, jdat.shape[1])
    chunks = min(N, 64)
    for c in prange(chunks):
        work = np.empty(size)
        iwork = np.empty(6 + TAB_K_MAX, np.int64)
        for i in range(c * N // chunks, (c + 1) * N // chunks):
            _solve_target(targets[i], q0[i], seeds[i], consts, jdat, Mc, cdat, opts,
                          out[i], work, iwork, tab, cstart, gdat)
    return _summary(out, n)


@njit(cache=True)
def solve_path(targets, q_start, consts, jdat, Mc, cdat, opts, out):
    """Warm-started path: target i starts from the solution of i - 1.

    Stops at the first failure (non-convergence, or a joint change larger than
    ``opts[O_PATH_MAX_JUMP]`` from the previous sample); later rows get the last good
    q and ``CODE_NOT_RUN``. Returns the index of the first failure, or -1.
    """
    N = targets.shape[0]
    n = q_start.shape[0]
    prev = q_start.copy()
    no_seeds = np.empty((0, n))
    no_tab = np.empty((0, 12 + n))
    no_cstart = np.zeros(1, np.int64)
    no_gdat = np.zeros(7)
    max_jump = opts[O_PATH_MAX_JUMP]
    work = np.empty(work_size(n, jdat.shape[1]))
    iwork = np.empty(6 + TAB_K_MAX, np.int64)
    first = -1
    for i in range(N):
        if first >= 0:
            for j in range(n):
                out[i, j] = prev[j]
            out[i, n + R_ERR] = np.inf
            out[i, n + R_EP] = np.inf
            out[i, n + R_ER] = np.inf
            out[i, n + R_ITERS] = 0
            out[i, n + R_RESTARTS] = 0
            out[i, n + R_CODE] = CODE_NOT_RUN
            continue
        _solve_target(targets[i], prev, no_seeds, consts, jdat, Mc, cdat, opts, out[i],
                      work, iwork, no_tab, no_cstart, no_gdat)
        if out[i, n + R_CODE] != CODE_OK:
            first = i
            continue
        jump = 0.0
        for j in range(n):
            d = abs(out[i, j] - prev[j])
            if d > jump:
                jump = d
        if jump > max_jump:
            out[i, n + R_CODE] = CODE_JUMP
            first = i
            continue
        for j in range(n):
            prev[j] = out[i, j]
    return first
