/*
 * Scalar angles and Paden subproblems for the one-pose closed forms (pieper.c,
 * pieper_srs.c): a fast atan2, (cos, sin) of an angle without trigonometry, the
 * joint coordinate of a chain angle, and subproblems 1 and 4 (IK-Geo's
 * formulation). six_r.c solves the same subproblems in lanes (L3, vd) for batches.
 */
#ifndef ROBOKIN_SUBPROBLEMS_H
#define ROBOKIN_SUBPROBLEMS_H

#include <math.h>

#include "chain.h"
#include "vec3.h"

#ifndef SR_TAN_PI_8
#define SR_TAN_PI_8 0.41421356237309503
#endif

/* atan(u) for |u| <= tan(pi/8): u + u^3 p(u^2), p a degree-10 least-squares fit on
 * Chebyshev nodes to (atan(u) - u) / u^3 (relative error < 3e-16), by Estrin's
 * scheme (short dependency chains). One copy for a double and for lanes (six_r.c's
 * atan_core): T is the type. */
#define ATAN_CORE_BODY(T, u) \
    T s = (u) * (u), s2 = s * s, s4 = s2 * s2; \
    T q0 = -0.33333333333333326 + 0.19999999999994086 * s; \
    T q1 = -0.14285714284481754 + 0.11111111005585772 * s; \
    T q2 = -0.0909090431754569 + 0.07692179168372903 * s; \
    T q3 = -0.06664474627546399 + 0.05857954331450998 * s; \
    T q4 = -0.05084928654128961 + 0.03922789786600753 * s - 0.019183482806421463 * s2; \
    T p = (q0 + s2 * q1) + s4 * ((q2 + s2 * q3) + s4 * q4); \
    return (u) + (u) * s * p;

static inline double atan_core1(double u)
{
    ATAN_CORE_BODY(double, u)
}

/* atan2(y, x) to within a few ulp (< 1e-15 rad) without the libm call and with few
 * branches (octant reduction to |u| <= tan(pi/8), then atan_core); zeros,
 * infinities and NaN go to libm's atan2. */
static inline double fast_atan2(double y, double x)
{
    double ax = fabs(x), ay = fabs(y);
    if (!(ax < INFINITY && ay < INFINITY) || (ax == 0.0 && ay == 0.0))
        return atan2(y, x);
    int swap = ay > ax;
    double num = swap ? ax : ay, den = swap ? ay : ax;
    int big = num > SR_TAN_PI_8 * den;
    double u = (big ? num - den : num) / (big ? num + den : den);
    double r = atan_core1(u) + (big ? M_PI_4 : 0.0);
    r = swap ? M_PI_2 - r : r;
    r = x < 0.0 ? M_PI - r : r;
    return copysign(r, y);
}

/* (cos, sin) of atan2(y, x) without the trigonometry: (x, y) / |(x, y)|, or (1, 0)
 * at the origin */
static inline void unit2(double y, double x, double *c, double *s)
{
    double r = sqrt(x * x + y * y);
    if (r > 0.0) {
        *c = x / r;
        *s = y / r;
    } else {
        *c = 1.0;
        *s = 0.0;
    }
}

/* The joint coordinate of chain angle v: sign (v - offset) wrapped to [-pi, pi],
 * then by chain.h's wrap_into rule into [lo, hi] (LIMIT_SLACK); *inside says whether
 * it lies there. */
static inline double joint_value(double v, double sign, double offset, double lo,
                                 double hi, int *inside)
{
    double q = wrap_into(wrap_pi(sign * (v - offset)), lo, hi);
    *inside = within_limits(q, lo, hi);
    return q;
}

/* ------------------------------------------------------------ subproblems */

/* Subproblem 1 (Paden): t with rot(k, t) p = q (least squares if inexact), and its
 * cosine and sine. */
static inline double sp1(v3 k, v3 p, v3 q, double *c, double *s)
{
    double kp = v3_dot(k, p);
    double y = v3_dot(q, v3_cross(k, p));
    double x = v3_dot(q, p) - kp * v3_dot(k, q);
    unit2(y, x, c, s);
    return fast_atan2(y, x);
}

/* Subproblem 4 (Paden), its coefficients: h . rot(k, t) p = A cos t + B sin t + C.
 * (Subproblem 3, |a + rot(k, t) b| = d, reduces to it; pack computes those
 * pose-independent coefficients.) */
static inline void sp4_coeffs(v3 h, v3 k, v3 p, double *A, double *B, double *C)
{
    double kp = v3_dot(k, p), hk = v3_dot(h, k);
    *A = v3_dot(h, p) - hk * kp;
    *B = v3_dot(h, v3_cross(k, p));
    *C = hk * kp;
}

/* The roots of a subproblem 4: t[0] (the '+' root) and t[1] ('-'), their cosines
 * and sines; n of them (0, 1 or 2); boundary: a double root (the pose is on a
 * singular boundary). */
typedef struct {
    int n, boundary;
    double t[2], c[2], s[2];
} Roots;

/* The two roots phi + g and phi - g of a subproblem 4 into r.t, with their cosines
 * and sines from those of phi and g. One copy for a double and for lanes (six_r.c's
 * lsp4). */
#define SP4_PAIR(r, phi, cphi, sphi, g, cg, sg) \
    do { \
        (r).t[0] = (phi) + (g); \
        (r).c[0] = (cphi) * (cg) - (sphi) * (sg); \
        (r).s[0] = (sphi) * (cg) + (cphi) * (sg); \
        (r).t[1] = (phi) - (g); \
        (r).c[1] = (cphi) * (cg) + (sphi) * (sg); \
        (r).s[1] = (sphi) * (cg) - (cphi) * (sg); \
    } while (0)

/* A negative disc's two seeds mirrored about the double root phi (+ pi when
 * rhs < 0), with their cosines and sines (near-family seeds; scalar and lanes). */
static inline void sp4_mirror(double phi, double rhs, double disc, double t[2], double c[2],
                              double s[2])
{
    double base = phi + atan2(0.0, rhs); /* the double root: phi or phi + pi */
    double g = atan2(sqrt(-disc), fabs(rhs));
    t[0] = base + g;
    t[1] = base - g;
    for (int i = 0; i < 2; i++) {
        c[i] = cos(t[i]);
        s[i] = sin(t[i]);
    }
}

/* Roots of A cos t + B sin t = rhs given disc = A^2 + B^2 - rhs^2 and the phase
 * phi = atan2(B, A) with its cosine and sine (Paden subproblem 4; IK-Geo sec. III).
 * A negative disc within tol (A^2 + B^2) is a double root (boundary); with mirror
 * (near-family seeds) it gives two seeds mirrored about it instead. disc within
 * 1e-3 tol (A^2 + B^2) of zero is a double root too. */
static inline Roots sp4_roots(double A, double B, double rhs, double disc, double tol,
                              int mirror, double phi, double cphi, double sphi)
{
    Roots r;
    double r2 = A * A + B * B;
    if (disc < -tol * r2) {
        r.n = 0;
        r.boundary = 0;
        r.t[0] = r.t[1] = 0.0;
        r.c[0] = r.c[1] = 1.0;
        r.s[0] = r.s[1] = 0.0;
        return r;
    }
    if (disc < 0.0 && mirror) {
        r.n = 2;
        r.boundary = 1;
        sp4_mirror(phi, rhs, disc, r.t, r.c, r.s);
        return r;
    }
    double sq = sqrt(fmax(disc, 0.0)), cg, sg;
    double g = fast_atan2(sq, rhs);
    unit2(sq, rhs, &cg, &sg);
    SP4_PAIR(r, phi, cphi, sphi, g, cg, sg);
    r.n = disc <= tol * r2 * 1e-3 ? 1 : 2;
    r.boundary = r.n == 1;
    return r;
}

#endif /* ROBOKIN_SUBPROBLEMS_H */
