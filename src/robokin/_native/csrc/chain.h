/*
 * The chain maths, written once: sin/cos, the chain product, the Jacobian columns
 * and the pose residual, on W lanes (lanes.h). FK, link frames, Jacobians, the
 * numeric IK and the seed table all call these functions; nothing else in robokin
 * multiplies along a chain, with one exception: general6r.c's g6_rot_span, the
 * rotation part of a span of the *reversed* chain (its own constants, built once
 * per arm, in one lane), which the elimination needs per candidate root.
 *
 *   T(q) = C_0 J_1(v_1) C_1 J_2(v_2) C_2 ... J_n(v_n) C_n,   v = sign * (M q + c) + offset
 *
 * C_0 = B L_0 (base and head), C_k = F_k G_k (C_n also carries the tool); J_k is a
 * rotation about (revolute) or a translation along (prismatic) the local z axis.
 * The arrays come from robokin.model.chain_arrays.ChainArrays.packed; its layout is
 * declared once, in robokin/_native/_declare.py (PACKED_LAYOUT), which chain_arrays
 * packs by and chain_layout.gen.h carries here (chain_view parses and checks it). A transform under
 * construction is its top 3x4 block, row-major, t[4 r + c].
 */
#ifndef ROBOKIN_CHAIN_H
#define ROBOKIN_CHAIN_H

#include <stddef.h>
#include "lanes.h"

#define MAXJ 32        /* chain joints and coordinates the kernels take */
#include "chain_layout.gen.h" /* PACKED_TAG, PACKED_SECTIONS: from _declare.py */

typedef struct {
    int nc;    /* chain joints */
    int n;     /* independent coordinates */
    int ident; /* 1: q_chain = q */
    const double *consts;  /* (nc + 1) x 16: C_0 .. C_n */
    const double *xform;   /* (nc + 1) x 6: [1, cos a, sin a, tx, ty, tz] when C_k = Trans(t) Rx(a), else 0 */
    const double *kind;    /* nc: 1.0 prismatic, 0.0 revolute */
    const double *sign;    /* nc */
    const double *offset;  /* nc */
    const double *M;       /* nc x n, row-major */
    const double *c;       /* nc */
    const double *base;    /* 16 */
    const double *frame;   /* nc x 16: F_k */
    const double *link;    /* nc x 16: G_k (the last times the tool) */
    const double *lo, *hi; /* n: limits */
    const double *seed_lo, *seed_hi; /* n: where random restarts are drawn */
    const double *wrap;    /* n: 1.0 where a coordinate may move by whole turns */
} Chain;

/* Parse ChainArrays.packed (len doubles) into ch; 0 when it is not a consistent
 * layout of at most MAXJ joints. */
static int chain_view(const double *p, long len, Chain *ch)
{
    if (len < 4 || p[0] != PACKED_TAG)
        return 0;
    double fnc = p[1], fn = p[2];
    if (!(fnc >= 1.0 && fnc <= MAXJ && fn >= 1.0 && fn <= MAXJ) || fnc != (int)fnc ||
        fn != (int)fn)
        return 0;
    int nc = (int)fnc, n = (int)fn;
    long need = PACKED_HEAD;
#define CHAIN_SIZE(f, nd, d0, d1, d2, key) need += (long)(d0) * (d1) * (d2);
    PACKED_SECTIONS(CHAIN_SIZE)
#undef CHAIN_SIZE
    if (len != need)
        return 0;
    ch->nc = nc;
    ch->n = n;
    ch->ident = p[3] == 1.0;
    if (ch->ident && nc != n)
        return 0;
    const double *o = p + PACKED_HEAD;
#define CHAIN_TAKE(f, nd, d0, d1, d2, key) ch->f = o; o += (long)(d0) * (d1) * (d2);
    PACKED_SECTIONS(CHAIN_TAKE)
#undef CHAIN_TAKE
    return 1;
}

/* ------------------------------------------------------------------ sin, cos */

/* Cody-Waite reduction by pi/2 and the fdlibm / musl kernel polynomials
 * (__kernel_sin, __kernel_cos), < 1 ulp on the reduced range; one reduction serves
 * both values. Lanes with |x| >= 1e5, NaN or inf take libm. */
#define ROUND_MAGIC 6755399441055744.0 /* 1.5 * 2^52 */
#define INV_PIO2 6.36619772367581382433e-01
#define PIO2_1 1.57079632673412561417e00  /* first 33 bits of pi/2 */
#define PIO2_2 6.07710050630396597660e-11 /* next 33 bits */
#define PIO2_3 2.02226624871116645580e-21 /* the rest */
#define S1 -1.66666666666666324348e-01
#define S2 8.33333333332248946124e-03
#define S3 -1.98412698298579493134e-04
#define S4 2.75573137070700676789e-06
#define S5 -2.50507602534068634195e-08
#define S6 1.58969099521155010221e-10
#define C1 4.16666666666666019037e-02
#define C2 -1.38888888888741095749e-03
#define C3 2.48015872894767294178e-05
#define C4 -2.75573143513906633035e-07
#define C5 2.08757232129817482790e-09
#define C6 -1.13596475577881948265e-11

/* sin y, cos y of |y| <= pi / 4 (type T: double or vd) into sy, cy */
#define SINCOS_KERNEL(T, y, sy, cy)                                                   \
    do {                                                                              \
        T z_ = (y) * (y);                                                             \
        T rs_ = S2 + z_ * (S3 + z_ * (S4 + z_ * (S5 + z_ * S6)));                     \
        (sy) = (y) + z_ * (y) * (S1 + z_ * rs_);                                      \
        T rc_ = z_ * (C1 + z_ * (C2 + z_ * (C3 + z_ * (C4 + z_ * (C5 + z_ * C6))))); \
        T hz_ = 0.5 * z_, w_ = 1.0 - hz_;                                             \
        (cy) = w_ + (((1.0 - w_) - hz_) + z_ * rc_);                                  \
    } while (0)

ALWAYS_INLINE void vsincos(vd x, vd *s, vd *c)
{
    vl big = ~(vabs(x) < 1e5);
    vd xs = vsel(big, BR(0.0), x);
    /* n = the integer nearest x / (pi / 2), by adding 1.5 * 2^52 (the sum's low
     * mantissa bits are then n mod 2^51: its quadrant is the low two bits); no
     * float-to-integer conversion, which vector units below AVX-512 lack */
    vd r = xs * INV_PIO2 + ROUND_MAGIC;
    vd n = r - ROUND_MAGIC;
    vl k = (vl)r;
    vd y = ((xs - n * PIO2_1) - n * PIO2_2) - n * PIO2_3; /* |y| <= pi / 4 */
    vd sy, cy;
    SINCOS_KERNEL(vd, y, sy, cy);
    vl odd = -(k & 1);
    vl neg_s = (k << 62) & BRL(0x8000000000000000ULL);       /* quadrants 2, 3 */
    vl neg_c = ((k + 1) << 62) & BRL(0x8000000000000000ULL); /* quadrants 1, 2 */
    vd ss = vsel(odd, cy, sy);
    vd cc = vsel(odd, sy, cy);
    *s = (vd)((vl)ss ^ neg_s);
    *c = (vd)((vl)cc ^ neg_c);
    if (vany(big))
        for (int l = 0; l < W; l++)
            if (big[l]) {
                (*s)[l] = sin(x[l]);
                (*c)[l] = cos(x[l]);
            }
}

/* vsincos for one value (the scalar solvers' hot loops: held_closed.c), < 1 ulp on
 * the reduced range; |x| >= 1e5, NaN or inf take libm. */
static inline void sincos1(double x, double *s, double *c)
{
    if (!(fabs(x) < 1e5)) {
        *s = sin(x);
        *c = cos(x);
        return;
    }
    double n = (x * INV_PIO2 + ROUND_MAGIC) - ROUND_MAGIC; /* (as vsincos') */
    double y = ((x - n * PIO2_1) - n * PIO2_2) - n * PIO2_3, sy, cy;
    SINCOS_KERNEL(double, y, sy, cy);
    switch ((long long)n & 3) {
    case 0:
        *s = sy;
        *c = cy;
        break;
    case 1:
        *s = cy;
        *c = -sy;
        break;
    case 2:
        *s = -sy;
        *c = -cy;
        break;
    default:
        *s = -cy;
        *c = sy;
    }
}

/* An angle wrapped into [-pi, pi) (the one wrap of the C code). */
static inline double wrap_pi(double x)
{
    return x - 2.0 * M_PI * floor((x + M_PI) * (0.5 / M_PI));
}

/* ---------------------------------------------------------- the chain product */

/* t <- t J(v): rotation by (s, c) about local z, or translation v along it. */
ALWAYS_INLINE void joint_right(vd *t, int prismatic, vd v, vd s, vd c)
{
    if (prismatic) {
        for (int r = 0; r < 3; r++)
            t[4 * r + 3] += t[4 * r + 2] * v;
    } else {
        for (int r = 0; r < 3; r++) {
            vd x0 = t[4 * r], x1 = t[4 * r + 1];
            t[4 * r] = c * x0 + s * x1;
            t[4 * r + 1] = c * x1 - s * x0;
        }
    }
}

/* t <- t C for an affine C (4x4 row-major); with P (its xform row) when
 * C = Trans(tx, ty, tz) Rx(a), which every DH row's constant is: fewer products. */
ALWAYS_INLINE void const_right(vd *t, const double *C, const double *P)
{
    if (P != NULL && P[0] == 1.0) {
        double ca = P[1], sa = P[2], tx = P[3], ty = P[4], tz = P[5];
        for (int r = 0; r < 3; r++) {
            vd a0 = t[4 * r], a1 = t[4 * r + 1], a2 = t[4 * r + 2];
            t[4 * r + 3] += a0 * tx + a1 * ty + a2 * tz;
            t[4 * r + 1] = ca * a1 + sa * a2;
            t[4 * r + 2] = ca * a2 - sa * a1;
        }
    } else {
        for (int r = 0; r < 3; r++) {
            vd a0 = t[4 * r], a1 = t[4 * r + 1], a2 = t[4 * r + 2];
            t[4 * r] = a0 * C[0] + a1 * C[4] + a2 * C[8];
            t[4 * r + 1] = a0 * C[1] + a1 * C[5] + a2 * C[9];
            t[4 * r + 2] = a0 * C[2] + a1 * C[6] + a2 * C[10];
            t[4 * r + 3] += a0 * C[3] + a1 * C[7] + a2 * C[11];
        }
    }
}

ALWAYS_INLINE void load_top(vd *t, const double *C)
{
    for (int i = 0; i < 12; i++)
        t[i] = BR(C[i]);
}

/* Chain joint values v_k = sign_k (M q + c)_k + offset_k into v (nc); for revolute
 * joints their sines and cosines into s, c (computed first, in a loop of
 * independent iterations the CPU overlaps; the chain after them is the serial part).
 * Returns the lanes whose values are all finite. */
ALWAYS_INLINE vl joint_values(const Chain *ch, const vd *q, vd *v, vd *s, vd *c)
{
    const int nc = ch->nc, n = ch->n;
    vl ok = BRL(-1);
    for (int k = 0; k < nc; k++) {
        vd x;
        if (ch->ident) {
            x = q[k];
        } else {
            x = BR(ch->c[k]);
            for (int j = 0; j < n; j++)
                x += ch->M[k * n + j] * q[j];
        }
        vd val = ch->sign[k] * x + ch->offset[k];
        ok &= vfinite(val);
        v[k] = val;
    }
    for (int k = 0; k < nc; k++)
        if (ch->kind[k] == 0.0)
            vsincos(v[k], &s[k], &c[k]);
    return ok;
}

/* The one walk along the chain: the tool pose (top 3x4 into t) of configurations q
 * (n lane-vectors). When o and z are given, the origin and z axis of every joint
 * frame (just after its joint) go there, 3 x nc each (o[3 k + r]); when fr is
 * given, the top 3x4 of every link frame (after F_k), 12 x nc each (fr[12 k + i]),
 * taken off the walk without changing it (so the tool pose is fk's, bit for bit).
 * Returns the lanes with finite joint values. */
ALWAYS_INLINE vl chain_walk(const Chain *ch, const vd *q, vd *t, vd *o, vd *z, vd *fr)
{
    vd v[MAXJ], s[MAXJ], c[MAXJ];
    vl ok = joint_values(ch, q, v, s, c);
    load_top(t, ch->consts);
    for (int k = 0; k < ch->nc; k++) {
        joint_right(t, ch->kind[k] != 0.0, v[k], s[k], c[k]);
        if (o != NULL)
            for (int r = 0; r < 3; r++) {
                o[3 * k + r] = t[4 * r + 3];
                z[3 * k + r] = t[4 * r + 2];
            }
        if (fr != NULL) {
            for (int i = 0; i < 12; i++)
                fr[12 * k + i] = t[i];
            const_right(fr + 12 * k, ch->frame + 16 * k, NULL);
        }
        const_right(t, ch->consts + 16 * (k + 1), ch->xform + 6 * (k + 1));
    }
    return ok;
}

/* The tool pose (and joint origins and axes when o, z are given): chain_walk */
ALWAYS_INLINE vl chain_pose(const Chain *ch, const vd *q, vd *t, vd *o, vd *z)
{
    return chain_walk(ch, q, t, o, z, NULL);
}

/* Pose (into t) and the geometric Jacobian with respect to the independent
 * coordinates q: J[r * js + j], rows [v; w] in the base frame at the tool point.
 * A revolute column is sign * [z x (p - o); z], a prismatic one sign * [z; 0];
 * dependent joints fold in through J = Jc M. */
ALWAYS_INLINE vl chain_pose_jac(const Chain *ch, const vd *q, vd *t, vd *J, int js)
{
    const int nc = ch->nc, n = ch->n;
    vd o[3 * MAXJ], z[3 * MAXJ], Jcb[6 * MAXJ];
    vl ok = chain_pose(ch, q, t, o, z);
    vd *Jc = ch->ident ? J : Jcb;
    int cs = ch->ident ? js : MAXJ;
    vd px = t[3], py = t[7], pz = t[11];
    for (int k = 0; k < nc; k++) {
        double sg = ch->sign[k];
        vd zx = z[3 * k], zy = z[3 * k + 1], zq = z[3 * k + 2];
        if (ch->kind[k] == 0.0) {
            vd dx = px - o[3 * k], dy = py - o[3 * k + 1], dz = pz - o[3 * k + 2];
            Jc[0 * cs + k] = sg * (zy * dz - zq * dy);
            Jc[1 * cs + k] = sg * (zq * dx - zx * dz);
            Jc[2 * cs + k] = sg * (zx * dy - zy * dx);
            Jc[3 * cs + k] = sg * zx;
            Jc[4 * cs + k] = sg * zy;
            Jc[5 * cs + k] = sg * zq;
        } else {
            Jc[0 * cs + k] = sg * zx;
            Jc[1 * cs + k] = sg * zy;
            Jc[2 * cs + k] = sg * zq;
            Jc[3 * cs + k] = BR(0.0);
            Jc[4 * cs + k] = BR(0.0);
            Jc[5 * cs + k] = BR(0.0);
        }
    }
    if (!ch->ident)
        for (int r = 0; r < 6; r++)
            for (int j = 0; j < n; j++) {
                vd acc = BR(0.0);
                for (int k = 0; k < nc; k++)
                    acc += Jc[r * cs + k] * ch->M[k * n + j];
                J[r * js + j] = acc;
            }
    return ok;
}

/* ------------------------------------------------------------- pose residual */

/* log(R) of a rotation R (row-major 3x3) given its skew part v = vee(R - R^T) / 2,
 * s = |v| and c = (trace R - 1) / 2, outside the small-angle series: the atan2
 * form, and near pi the axis from the symmetric part (1 - c) a a^T. */
static void rotation_log_wide(const double *R, double vx, double vy, double vz, double s,
                              double c, double *ev)
{
    if (c > -0.9) {
        double th = atan2(s, c);
        double f = s > 1e-10 ? th / s : 1.0 + s * s / 6.0;
        ev[0] = f * vx;
        ev[1] = f * vy;
        ev[2] = f * vz;
        return;
    }
    double th = atan2(s, c), omc = 1.0 - c;
    double b00 = R[0] - c, b11 = R[4] - c, b22 = R[8] - c, ax, ay, az, d;
    if (b00 >= b11 && b00 >= b22) {
        d = sqrt(fmax(b00 * omc, 1e-300));
        ax = b00 / d;
        ay = 0.5 * (R[1] + R[3]) / d;
        az = 0.5 * (R[2] + R[6]) / d;
    } else if (b11 >= b22) {
        d = sqrt(fmax(b11 * omc, 1e-300));
        ax = 0.5 * (R[1] + R[3]) / d;
        ay = b11 / d;
        az = 0.5 * (R[5] + R[7]) / d;
    } else {
        d = sqrt(fmax(b22 * omc, 1e-300));
        ax = 0.5 * (R[2] + R[6]) / d;
        ay = 0.5 * (R[5] + R[7]) / d;
        az = b22 / d;
    }
    if (ax * vx + ay * vy + az * vz < 0.0) {
        ax = -ax;
        ay = -ay;
        az = -az;
    }
    ev[0] = th * ax;
    ev[1] = th * ay;
    ev[2] = th * az;
}

/* The task error e = [p_t - p; log(R_t R^T)] (base frame) of poses t against
 * targets tt (both top 3x4, lane-wise). Lanes in `active` outside the small-angle
 * case take rotation_log_wide; the others keep the series value. */
ALWAYS_INLINE void pose_residual(const vd *t, const vd *tt, vd *e, vl active)
{
    e[0] = tt[3] - t[3];
    e[1] = tt[7] - t[7];
    e[2] = tt[11] - t[11];
    /* R_e = R_t R^T */
    vd r00 = tt[0] * t[0] + tt[1] * t[1] + tt[2] * t[2];
    vd r01 = tt[0] * t[4] + tt[1] * t[5] + tt[2] * t[6];
    vd r02 = tt[0] * t[8] + tt[1] * t[9] + tt[2] * t[10];
    vd r10 = tt[4] * t[0] + tt[5] * t[1] + tt[6] * t[2];
    vd r11 = tt[4] * t[4] + tt[5] * t[5] + tt[6] * t[6];
    vd r12 = tt[4] * t[8] + tt[5] * t[9] + tt[6] * t[10];
    vd r20 = tt[8] * t[0] + tt[9] * t[1] + tt[10] * t[2];
    vd r21 = tt[8] * t[4] + tt[9] * t[5] + tt[10] * t[6];
    vd r22 = tt[8] * t[8] + tt[9] * t[9] + tt[10] * t[10];
    vd vx = 0.5 * (r21 - r12);
    vd vy = 0.5 * (r02 - r20);
    vd vz = 0.5 * (r10 - r01);
    vd s = vsqrt(vx * vx + vy * vy + vz * vz);
    vd c = 0.5 * (r00 + r11 + r22 - 1.0);
    /* small angles (every descent's last iterations): th / s = atan(x) / (x c) with
     * x = s / c < 0.1, by its Maclaurin series to x^14 (next term < 1e-17) */
    vl small = (c > 0.0) & (s < 0.1 * c);
    vd ic = 1.0 / vsel(small, c, BR(1.0));
    vd x = s * ic;
    vd zz = x * x;
    vd f = ic * (1.0 + zz * (-1.0 / 3.0 + zz * (1.0 / 5.0 + zz * (-1.0 / 7.0 + zz * (
        1.0 / 9.0 + zz * (-1.0 / 11.0 + zz * (1.0 / 13.0 + zz * (-1.0 / 15.0))))))));
    e[3] = f * vx;
    e[4] = f * vy;
    e[5] = f * vz;
    vl other = active & ~small;
    if (!vany(other))
        return;
    for (int l = 0; l < W; l++) {
        if (!other[l])
            continue;
        double R[9] = {r00[l], r01[l], r02[l], r10[l], r11[l], r12[l], r20[l], r21[l],
                       r22[l]};
        double ev[3];
        rotation_log_wide(R, vx[l], vy[l], vz[l], s[l], c[l], ev);
        e[3][l] = ev[0];
        e[4][l] = ev[1];
        e[5][l] = ev[2];
    }
}

/* How far outside its limits a joint value still counts as inside them [rad, m]. */
#define LIMIT_SLACK 1e-9

/* Whether v lies within [lo, hi] up to LIMIT_SLACK (NaN: no). */
static inline int within_limits(double v, double lo, double hi)
{
    return v >= lo - LIMIT_SLACK && v <= hi + LIMIT_SLACK;
}

/* The one wrap-into-limits rule (docs/conventions.md "Joint values and limits"): a
 * 2*pi-periodic coordinate v within [lo, hi] up to LIMIT_SLACK stays as it is;
 * otherwise it moves by the fewest whole turns that bring it within them (the same
 * slack), where some do; else (or NaN) it stays. Python's fit_turns calls it
 * (kernel wrap_into); six_r.c's ljoint is its lane-wise twin (tested against it). */
static inline double wrap_into(double v, double lo, double hi)
{
    const double tp = 2.0 * M_PI, lo_e = lo - LIMIT_SLACK, hi_e = hi + LIMIT_SLACK;
    if (v > hi_e) {
        double u = v - ceil((v - hi_e) / tp) * tp;
        if (u >= lo_e)
            v = u;
    } else if (v < lo_e) {
        double u = v + ceil((lo_e - v) / tp) * tp;
        if (u <= hi_e)
            v = u;
    }
    return v;
}

/* ------------------------------------------------------------ pose checks */

/* Largest translation [m] a pose may have: beyond it float64 kinematics lose every
 * digit of a sub-millimetre result (robokin._validation.MAX_TRANSLATION reads it). */
#define MAX_TRANSLATION 1.0e6

/* The self-motion membership slack [rad, m]: a manifold's row is inside its limits
 * where every coordinate is within MANIFOLD_SLACK of them (lo - MANIFOLD_SLACK <= q
 * <= hi + MANIFOLD_SLACK). Every interval decision takes it, with this comparison:
 * the compiled manifolds' pieces (held_manifold.c, self_motion.c) and, through
 * robokin.kinematics.ik.self_motion_intervals.MANIFOLD_SLACK, SelfMotion.inside and
 * the solved-points and continued families' pieces (docs/ik.md "The membership
 * slack"). Tighter than LIMIT_SLACK (the IK rows' within_limits and wrap rule):
 * a manifold's crossings are exact to 1e-12. */
#define MANIFOLD_SLACK 1e-12

/* The tolerances every pose check uses (robokin._validation.check_transform, the
 * closed-form and the numeric IK): the last row to POSE_ROW_TOL, the rotation
 * block's orthonormality to POSE_ORTH_TOL. */
#define POSE_ROW_TOL 1e-9
#define POSE_ORTH_TOL 1e-6

/* 0 when T (4x4 row-major) is a rigid transform: 1 a non-finite entry, 2 a last
 * row other than 0 0 0 1 (within row_tol), 3 a rotation block not orthonormal
 * within orth_tol, 4 a reflection, 5 a translation beyond MAX_TRANSLATION. */
static int pose_problem(const double *T, double row_tol, double orth_tol)
{
    for (int i = 0; i < 16; i++)
        if (!isfinite(T[i]))
            return 1;
    if (fabs(T[3]) > MAX_TRANSLATION || fabs(T[7]) > MAX_TRANSLATION ||
        fabs(T[11]) > MAX_TRANSLATION)
        return 5;
    if (fabs(T[12]) > row_tol || fabs(T[13]) > row_tol || fabs(T[14]) > row_tol ||
        fabs(T[15] - 1.0) > row_tol)
        return 2;
    for (int r = 0; r < 3; r++)
        for (int q = 0; q < 3; q++) {
            double d = T[4 * r] * T[4 * q] + T[4 * r + 1] * T[4 * q + 1] +
                       T[4 * r + 2] * T[4 * q + 2];
            if (r == q)
                d -= 1.0;
            if (fabs(d) > orth_tol)
                return 3;
        }
    double det = T[0] * (T[5] * T[10] - T[6] * T[9]) - T[1] * (T[4] * T[10] - T[6] * T[8]) +
                 T[2] * (T[4] * T[9] - T[5] * T[8]);
    return det < 0.0 ? 4 : 0;
}

/* ------------------------------------------------------- singular values */

/* Smallest singular value of 6 x 6 Jacobians J[r * js + j] (lane-wise): inverse
 * iteration on J^T J (Cholesky), from the unit vector of the smallest Cholesky
 * pivot, then the Rayleigh quotient; an upper bound that is sharp when J is nearly
 * singular, 0 where J^T J is not positive definite (to rounding). The closed forms'
 * singular flag (six_r.c); robot.is_singular computes the same with an SVD. */
ALWAYS_INLINE vd jac_sigma_min6(const vd *J, int js)
{
    vd B[36], L[36];
    for (int i = 0; i < 6; i++)
        for (int j = i; j < 6; j++) {
            vd s = BR(0.0);
            for (int r = 0; r < 6; r++)
                s += J[r * js + i] * J[r * js + j];
            B[6 * i + j] = B[6 * j + i] = s;
        }
    vl bad = BRL(0);
    for (int j = 0; j < 6; j++) {
        vd s = B[6 * j + j];
        for (int k = 0; k < j; k++)
            s -= L[6 * j + k] * L[6 * j + k];
        bad |= ~(s > BR(0.0));
        L[6 * j + j] = vsqrt(vsel(bad, BR(1.0), s));
        vd inv = BR(1.0) / L[6 * j + j];
        for (int i = j + 1; i < 6; i++) {
            vd t = B[6 * i + j];
            for (int k = 0; k < j; k++)
                t -= L[6 * i + k] * L[6 * j + k];
            L[6 * i + j] = t * inv;
        }
    }
    vd x[6], small = L[0];
    vl at = BRL(0);
    for (int k = 1; k < 6; k++) {
        vl m = L[6 * k + k] < small;
        small = vsel(m, L[6 * k + k], small);
        at = (at & ~m) | (BRL(k) & m);
    }
    for (int k = 0; k < 6; k++)
        x[k] = vsel(at == BRL(k), BR(1.0), BR(0.0));
    for (int it = 0; it < 4; it++) {
        vd z[6], nrm = BR(0.0);
        for (int i = 0; i < 6; i++) { /* L z = x */
            vd s = x[i];
            for (int k = 0; k < i; k++)
                s -= L[6 * i + k] * z[k];
            z[i] = s / L[6 * i + i];
        }
        for (int i = 5; i >= 0; i--) { /* L^T x = z */
            vd s = z[i];
            for (int k = i + 1; k < 6; k++)
                s -= L[6 * k + i] * x[k];
            x[i] = s / L[6 * i + i];
            nrm += x[i] * x[i];
        }
        vd inv = BR(1.0) / vsqrt(vsel(nrm > BR(0.0), nrm, BR(1.0)));
        for (int i = 0; i < 6; i++)
            x[i] *= inv;
    }
    vd lam = BR(0.0); /* Rayleigh quotient x^T B x */
    for (int i = 0; i < 6; i++) {
        vd bx = BR(0.0);
        for (int j = 0; j < 6; j++)
            bx += B[6 * i + j] * x[j];
        lam += x[i] * bx;
    }
    vd sig = vsqrt(vsel(lam > BR(0.0), lam, BR(0.0)));
    return vsel(bad | ~vfinite(sig), BR(0.0), sig);
}

#endif
