/*
 * Closed-form IK of 6R chains with three consecutive intersecting axes (Pieper's
 * case), also as the remaining chain of a 7R arm with one joint held at a value:
 *
 *   start triple: axes 1, 2, 3 meet in S (the Panda's and SRS arms' shoulder);
 *   end triple:   axes 4, 5, 6 meet in W (a spherical wrist without axes 2, 3
 *                 parallel; SRS arms with joint 1, 2 or 3 held).
 *
 * The algorithm is described for users in robokin/kinematics/ik/analytic/pieper.py.
 * In short, on the product-of-exponentials geometry T = e1 e2 ... e6 M:
 *
 *   1. the triple rotates about its point, so the point's image fixes the other
 *      three joints a, b, c: e_a e_b e_c p = d (start: p = M T^-1 S, d = S, axes
 *      4-6; end: p = W, d = T M^-1 W, axes 1-3). With y = e_a^-1 d and z = e_c p,
 *      e_b z = y holds when the heights along h_b and the distances to a point o_b
 *      of axis b agree: two equations P u_a - Q u_c = r, linear in u_a = (cos,
 *      sin) theta_a and u_c = (cos, sin) theta_c (Pieper; Raghavan and Roth);
 *   2. when axes b, c (or a, b) are coplanar (meet or are parallel: the mutual
 *      moment vanishes), Q (or P) is singular and a combination of the rows holds
 *      one angle alone: two subproblem-4 equations in turn (He and Liu's closed
 *      form of the Panda with q7 given is this case: axes 5, 6 meet); otherwise
 *      u_c (or u_a) is eliminated, |u| = 1 leaves a trigonometric polynomial of
 *      degree 2 in the other angle, solved as a quartic in the tangent of its
 *      half-angle from a shifted origin (so its leading coefficient, f at the
 *      shift + pi, is never small), every real root Newton-polished;
 *   3. theta_b by subproblem 1; the triple from the orientation: its middle angle
 *      by subproblem 4 (two branches), the outer ones by subproblem 1. When its
 *      outer axes line up (singular) only their sum is fixed: the split is chosen
 *      inside the joint limits, nearest q_near (or 0), and flagged.
 *
 * Each pose yields 8 slots, slot = 2 * position + triple: position 0-3 numbers the
 * solutions of step 1-2 (in the coplanar case 2 * first root + second root, '+'
 * root 0; in the quartic case in increasing angle from the shift + pi), triple 0 / 1
 * the '+' / '-' root of the middle angle. A slot without a solution is NaN,
 * invalid, not singular and not within limits. Status: 0 ok, 1 out of reach, 2
 * orientation not achievable, 5 degenerate (the position equations hold no
 * angle at this held value); PK_BAD_POSE + pose_problem's code when the one-pose
 * entry found T not a rigid transform.
 *
 * The parameter vector (pieper.pack writes it; Python reads the PK_ indices from
 * the module constants, named PIEPER_*):
 *
 *   PK_N         chain joints n (6, or 7 with one held)
 *   PK_HELD      the held joint's index, or -1
 *   PK_CASE      PK_START or PK_END: which triple of the 6 remaining joints meets;
 *                PK_BOTH: both (the swivel case, pk_swivel)
 *   PK_SING_TOL  singular triple: |sin| of the outer axes' angle below it
 *   PK_SCALE     the arm's length scale [m] (row scaling and tolerances)
 *   PK_POINT     the triple's point at zero chain values, full chain (3)
 *   PK_POINT2    PK_BOTH: the end triple's point (PK_POINT is the start's)
 *   PK_AXES, PK_POINTS  unit axes h_k and points o_k at zero chain values (n x 3)
 *   PK_TOOL_R, PK_TOOL_T  M: rotation rows (9), translation (3)
 *   PK_SIGN, PK_OFFSET, PK_LO, PK_HI   per joint (n each): chain value
 *                v = sign q + offset, joint limits
 *   PK_TAG       PK_TAG_VALUE (identifies the vector)
 *
 * A held joint k at value x turns every later axis, point and M about axis k by
 * sign_k x + offset_k: the remaining chain is built per call (a few dozen flops),
 * so a sweep of held values is one batch with no per-value set-up.
 *
 * References:
 *   Pieper, "The kinematics of manipulators under computer control", PhD thesis,
 *   Stanford, 1968; Raghavan and Roth, "Inverse kinematics of the general 6R
 *   manipulator and related linkages", J. Mech. Des. 115 (1993);
 *   He and Liu, "Analytical inverse kinematics for Franka Emika Panda - a
 *   geometrical solver for 7-DOF manipulators with unconventional design",
 *   ICCRE 2021; Elias and Wen, "IK-Geo", arXiv:2211.05737 (subproblems 1-4).
 */
#include "chain.h"
#include "pool.h"
#include "subproblems.h"

/* Same floating-point rules as six_r.c (whose helpers this file uses): no fused
 * multiply-adds, so every copy of the kernels takes the same branches. */
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#elif defined(__GNUC__)
#pragma GCC push_options
#pragma GCC optimize("fp-contract=off", "no-tree-vectorize")
#endif

#define PK_MAXJ 7
enum {
    PK_N = 0, PK_HELD = 1, PK_CASE = 2, PK_SING_TOL = 3, PK_SCALE = 4, PK_POINT = 5,
    PK_AXES = 8, PK_POINTS = 8 + 3 * PK_MAXJ, PK_TOOL_R = 8 + 6 * PK_MAXJ,
    PK_TOOL_T = PK_TOOL_R + 9, PK_SIGN = PK_TOOL_T + 3, PK_OFFSET = PK_SIGN + PK_MAXJ,
    PK_LO = PK_OFFSET + PK_MAXJ, PK_HI = PK_LO + PK_MAXJ, PK_POINT2 = PK_HI + PK_MAXJ,
    PK_TAG = PK_POINT2 + 3,
    PK_N_PARAMS = PK_TAG + 1
};
enum { PK_START = 0, PK_END = 1, PK_BOTH = 2 };
enum { PK_OK = 0, PK_OUT_OF_REACH = 1, PK_NO_ORIENTATION = 2, PK_DEGENERATE = 5,
       PK_BAD_POSE = 16 };
#define PK_TAG_VALUE 1968.0625 /* Pieper's year, and a sixteenth */
#define PK_PARALLEL_MIN 512    /* below this many poses, one thread */
#define PK_GRAIN 32            /* poses per pool chunk */
#define PK_COPLANAR 1e-13      /* |mutual moment| / scale below it: coplanar axes (rounding) */
#define PK_EXACT 1e-13         /* pose errors below it need no Newton polish */
#define PK_ACCEPT 4e-13        /* pose errors above it after the polish: not a solution */
#define PK_NUDGE 1e-4         /* rows this far [rad] outside the limits: pk_inside tries */
#define PK_NUDGE_SING 5e-2    /* the same for rows flagged singular (a thin set's width there) */
#define PK_CLAMP_SLACK 1e-10 /* pk_inside: joints out by at most this [rad] are not clamped */
#define PK_FAMILY_SIGMA 1e-9  /* Jacobian's smallest / largest singular value below it: a family */
#define PK_SLIDE_KEPT 1e-3    /* pk_slide: a step of which the polish keeps less ... */
#define PK_SLIDE_STALL 2      /* ... this many times running: no family to slide along */
#define PK_SP4_SLACK 1e-13     /* |C| - hypot(A, B) / scale below it: a double root (rounding) */
#define PK_SLOW 1e-6           /* polished candidates this far off the pose: pk_polish_slow */
#define PK_SLOW_ITERS 40       /* its most Newton steps */
#define PK_PIN_LINE 1e-6       /* pk_pin_split: Jacobian columns equal to this, joints in line */

/* ------------------------------------------------------------ geometry */

/* rot(k, t) as rows, from c = cos t, s = sin t (Rodrigues) */
static inline m3 pk_rotm(v3 k, double c, double s)
{
    double v = 1.0 - c;
    return (m3){{c + k.x * k.x * v, k.x * k.y * v - k.z * s, k.x * k.z * v + k.y * s},
                {k.y * k.x * v + k.z * s, c + k.y * k.y * v, k.y * k.z * v - k.x * s},
                {k.z * k.x * v - k.y * s, k.z * k.y * v + k.x * s, c + k.z * k.z * v}};
}

/* A B (rows) */
static inline m3 pk_mul(const m3 *A, const m3 *B)
{
    return (m3){v3_add(v3_add(v3_scale(B->r0, A->r0.x), v3_scale(B->r1, A->r0.y)),
                       v3_scale(B->r2, A->r0.z)),
                v3_add(v3_add(v3_scale(B->r0, A->r1.x), v3_scale(B->r1, A->r1.y)),
                       v3_scale(B->r2, A->r1.z)),
                v3_add(v3_add(v3_scale(B->r0, A->r2.x), v3_scale(B->r1, A->r2.y)),
                       v3_scale(B->r2, A->r2.z))};
}

/* A B^T (rows) */
static inline m3 pk_mul_t(const m3 *A, const m3 *B)
{
    return (m3){{v3_dot(A->r0, B->r0), v3_dot(A->r0, B->r1), v3_dot(A->r0, B->r2)},
                {v3_dot(A->r1, B->r0), v3_dot(A->r1, B->r1), v3_dot(A->r1, B->r2)},
                {v3_dot(A->r2, B->r0), v3_dot(A->r2, B->r1), v3_dot(A->r2, B->r2)}};
}

static inline double v3_norm(v3 a) { return sqrt(v3_dot(a, a)); }

/* The remaining 6R chain at zero values (PoE): axes, points, M, the triple's point,
 * and which full-chain joint each of the six is. */
typedef struct {
    v3 h[6], o[6], pt, pt2, tM;
    m3 RM;
    int full[6];
    int kase;
    double scale;
} PkGeo;

/* The remaining chain with the held joint (if any) at joint value x. */
static void pk_geometry(const double *P, double x, PkGeo *g)
{
    int n = (int)P[PK_N], k = (int)P[PK_HELD], r = 0;
    double c = 1.0, s = 0.0;
    v3 hk = {0.0, 0.0, 1.0}, ok = {0.0, 0.0, 0.0};
    if (k >= 0) {
        double v = P[PK_SIGN + k] * x + P[PK_OFFSET + k];
        sincos1(v, &s, &c); /* (chain.h's: libm's sincos ~56 cycles, a held value's every
                             * front and margin; session 28) */
        hk = v3_at(P, PK_AXES + 3 * k);
        ok = v3_at(P, PK_POINTS + 3 * k);
    }
    g->kase = (int)P[PK_CASE];
    g->scale = P[PK_SCALE];
    if (k < 0 || k == n - 1) {
        /* no joint after the held one (a 6R chain; the Panda with q7): the first six
         * as packed, in fixed-size copies (the loop below takes ~175 instructions
         * more a call: pk_front_memo's and hm_margins_d's, ~500 per Panda pose) */
        static const int first6[6] = {0, 1, 2, 3, 4, 5};
        _Static_assert(sizeof(v3) == 3 * sizeof(double), "v3: three packed doubles");
        memcpy(g->h, &P[PK_AXES], sizeof g->h);
        memcpy(g->o, &P[PK_POINTS], sizeof g->o);
        memcpy(g->full, first6, sizeof g->full);
    } else {
        for (int j = 0; j < n; j++) {
            if (j == k)
                continue;
            v3 h = v3_at(P, PK_AXES + 3 * j), o = v3_at(P, PK_POINTS + 3 * j);
            if (j > k) {
                h = v3_rot(hk, c, s, h);
                o = v3_add(ok, v3_rot(hk, c, s, v3_sub(o, ok)));
            }
            g->h[r] = h;
            g->o[r] = o;
            g->full[r++] = j;
        }
    }
    g->RM = (m3){v3_at(P, PK_TOOL_R), v3_at(P, PK_TOOL_R + 3), v3_at(P, PK_TOOL_R + 6)};
    g->tM = v3_at(P, PK_TOOL_T);
    g->pt = v3_at(P, PK_POINT);
    g->pt2 = v3_at(P, PK_POINT2);
    if (k >= 0) {
        m3 Rk = pk_rotm(hk, c, s);
        g->RM = pk_mul(&Rk, &g->RM);
        g->tM = v3_add(ok, v3_rot(hk, c, s, v3_sub(g->tM, ok)));
        int first = g->full[g->kase == PK_END ? 3 : 0];
        if (k < first) /* the triple comes after the held joint: its point moves */
            g->pt = v3_add(ok, v3_rot(hk, c, s, v3_sub(g->pt, ok)));
        if (k < g->full[3])
            g->pt2 = v3_add(ok, v3_rot(hk, c, s, v3_sub(g->pt2, ok)));
    }
}

/* ------------------------------------------------------------ quartic */

/* The largest real root of m^3 + a m^2 + b m + c (Cardano / trigonometric),
 * Newton-refined. */
static double pk_cubic_max(double a, double b, double c)
{
    double q = (a * a - 3.0 * b) / 9.0;
    double r = (2.0 * a * a * a - 9.0 * a * b + 27.0 * c) / 54.0;
    double q3 = q * q * q, m;
    if (r * r < q3) {
        double th = acos(fmax(-1.0, fmin(1.0, r / sqrt(q3))));
        /* the roots are -2 sqrt(q) cos((th + 2 pi j) / 3) - a / 3, th in [0, pi];
         * the largest is j = 1: (th + 2 pi) / 3 in [2 pi / 3, pi], cos <= -1 / 2 */
        m = -2.0 * sqrt(q) * cos((th + 2.0 * M_PI) / 3.0) - a / 3.0;
    } else {
        double A = -copysign(cbrt(fabs(r) + sqrt(r * r - q3)), r);
        double B = A != 0.0 ? q / A : 0.0;
        m = A + B - a / 3.0;
    }
    for (int it = 0; it < 2; it++) {
        double f = ((m + a) * m + b) * m + c, d = (3.0 * m + 2.0 * a) * m + b;
        if (d == 0.0)
            break;
        double mn = m - f / d;
        if (!isfinite(mn))
            break;
        m = mn;
    }
    return m;
}

/* Roots of y^2 + b y + c into re, im (im >= 0 for the first of a complex pair) */
static void pk_quadratic(double b, double c, double *re, double *im)
{
    double disc = 0.25 * b * b - c;
    if (disc >= 0.0) {
        double s = sqrt(disc);
        double y1 = -0.5 * b - copysign(s, b); /* no cancellation */
        re[0] = y1;
        re[1] = y1 != 0.0 ? c / y1 : 0.0;
        im[0] = im[1] = 0.0;
    } else {
        re[0] = re[1] = -0.5 * b;
        im[0] = sqrt(-disc);
        im[1] = -im[0];
    }
}

/* The four roots (re, im) of c4 t^4 + c3 t^3 + c2 t^2 + c1 t + c0, c4 != 0
 * (Ferrari: the depressed quartic factored into two quadratics by the largest
 * root of its resolvent cubic). */
static void pk_quartic(const double *cf, double *re, double *im)
{
    double b = cf[3] / cf[4], c = cf[2] / cf[4], d = cf[1] / cf[4], e = cf[0] / cf[4];
    double bb = b * b;
    double p = c - 0.375 * bb;
    double q = d - 0.5 * b * c + 0.125 * bb * b;
    double r = e - 0.25 * b * d + 0.0625 * bb * c - 3.0 / 256.0 * bb * bb;
    double shift = -0.25 * b;
    double sc = fmax(fmax(fabs(p), sqrt(fabs(r))), cbrt(fabs(q)) * cbrt(fabs(q)));
    if (fabs(q) <= 1e-14 * (sc * sqrt(sc) + 1e-300)) { /* biquadratic */
        double zr[2], zi[2];
        pk_quadratic(p, r, zr, zi);
        for (int i = 0; i < 2; i++) {
            /* sqrt of the complex zr + i zi */
            double mod = hypot(zr[i], zi[i]);
            double sr = sqrt(fmax(0.0, 0.5 * (mod + zr[i])));
            double si = copysign(sqrt(fmax(0.0, 0.5 * (mod - zr[i]))), zi[i]);
            re[2 * i] = shift + sr;
            im[2 * i] = si;
            re[2 * i + 1] = shift - sr;
            im[2 * i + 1] = -si;
        }
        return;
    }
    /* 8 m^3 + 8 p m^2 + (2 p^2 - 8 r) m - q^2 = 0 */
    double m = pk_cubic_max(p, 0.25 * p * p - r, -0.125 * q * q);
    if (!(m > 0.0))
        m = 1e-300;
    double s2 = sqrt(2.0 * m), k = q / (2.0 * s2);
    pk_quadratic(-s2, 0.5 * p + m + k, re, im);
    pk_quadratic(s2, 0.5 * p + m - k, re + 2, im + 2);
    for (int i = 0; i < 4; i++)
        re[i] += shift;
}

/* Subproblem 1 with the components perpendicular to k taken first: t with
 * rot(k, t) p = q (least squares), its cosine and sine. Unlike sp1's
 * q . p - (k . p)(k . q) this keeps its accuracy when p and q lie close to the
 * axis (a triple next to its singularity). */
static inline double pk_sp1(v3 k, v3 p, v3 q, double *c, double *s)
{
    v3 pp = v3_sub(p, v3_scale(k, v3_dot(k, p))), qp = v3_sub(q, v3_scale(k, v3_dot(k, q)));
    double y = v3_dot(k, v3_cross(pp, qp)), x = v3_dot(pp, qp);
    unit2(y, x, c, s);
    return fast_atan2(y, x);
}

/* ------------------------------------------------- the position problem */

/* A trigonometric polynomial of degree 2: a0 + a1 cos x + b1 sin x + a2 cos 2x +
 * b2 sin 2x, its value and derivative */
typedef struct { double a0, a1, b1, a2, b2; } Trig2;

static inline double trig2(const Trig2 *f, double x, double *df)
{
    double c = cos(x), s = sin(x), c2 = c * c - s * s, s2 = 2.0 * s * c;
    if (df)
        *df = -f->a1 * s + f->b1 * c - 2.0 * f->a2 * s2 + 2.0 * f->b2 * c2;
    return f->a0 + f->a1 * c + f->b1 * s + f->a2 * c2 + f->b2 * s2;
}

/* f'' at x */
static inline double trig2_dd(const Trig2 *f, double x)
{
    double c = cos(x), s = sin(x), c2 = c * c - s * s, s2 = 2.0 * s * c;
    return -f->a1 * c - f->b1 * s - 4.0 * f->a2 * c2 - 4.0 * f->b2 * s2;
}

/* Newton on f from x (at most `iters` steps, never a step past pi / 4) */
static double trig2_newton(const Trig2 *f, double x, int iters)
{
    for (int i = 0; i < iters; i++) {
        double d, v = trig2(f, x, &d);
        if (v == 0.0 || d == 0.0)
            break;
        double dx = v / d;
        if (fabs(dx) > 0.25 * M_PI)
            dx = copysign(0.25 * M_PI, dx);
        x -= dx;
        if (fabs(dx) < 1e-16)
            break;
    }
    return x;
}

/* Real roots of f (at most 4) into x, sorted; returns their count. Roots that
 * come out of the quartic as a complex pair with a small imaginary part (a
 * double root split by rounding) are kept as candidates: the extremum between
 * them is found and the pair restored from f's local quadratic (or the double
 * root itself), and the caller verifies every candidate. */
static int trig2_roots(const Trig2 *f, double *x, int *nearly_double)
{
    /* the shift: f(shift + pi) largest of 8 samples */
    double best = -1.0, delta = 0.0;
    for (int j = 0; j < 8; j++) {
        double d = 0.25 * M_PI * j, v = fabs(trig2(f, d + M_PI, NULL));
        if (v > best) {
            best = v;
            delta = d;
        }
    }
    double size = fabs(f->a0) + fabs(f->a1) + fabs(f->b1) + fabs(f->a2) + fabs(f->b2);
    if (!(best > 1e-14 * size)) /* f vanishes identically */
        return -1;
    double cd = cos(delta), sd = sin(delta), c2d = cos(2.0 * delta), s2d = sin(2.0 * delta);
    double A1 = f->a1 * cd + f->b1 * sd, B1 = -f->a1 * sd + f->b1 * cd;
    double A2 = f->a2 * c2d + f->b2 * s2d, B2 = -f->a2 * s2d + f->b2 * c2d;
    double cf[5] = {f->a0 + A1 + A2, 2.0 * B1 + 4.0 * B2, 2.0 * f->a0 - 6.0 * A2,
                    2.0 * B1 - 4.0 * B2, f->a0 - A1 + A2};
    double re[4], im[4];
    pk_quartic(cf, re, im);
    int n = 0;
    *nearly_double = 0;
    for (int i = 0; i < 4; i++) {
        double t = re[i];
        if (!isfinite(t))
            continue;
        double ang = delta + 2.0 * atan(t);
        if (im[i] == 0.0) {
            x[n++] = trig2_newton(f, ang, 3);
            continue;
        }
        if (im[i] < 0.0 || fabs(im[i]) > 1e-4 * (1.0 + t * t))
            continue; /* the second of a pair, or truly complex */
        /* a pair with a small imaginary part: the extremum between them */
        double xm = ang;
        for (int it = 0; it < 6; it++) {
            double d0, dd = trig2_dd(f, xm);
            trig2(f, xm, &d0);
            if (dd == 0.0)
                break;
            double step = d0 / dd;
            if (fabs(step) > 0.1)
                step = copysign(0.1, step);
            xm -= step;
            if (fabs(step) < 1e-15)
                break;
        }
        double v = trig2(f, xm, NULL), dd = trig2_dd(f, xm);
        *nearly_double = 1;
        if (dd != 0.0 && v * dd < 0.0) {
            double w = sqrt(-2.0 * v / dd);
            x[n++] = trig2_newton(f, xm - w, 3);
            x[n++] = trig2_newton(f, xm + w, 3);
        } else {
            x[n++] = xm; /* a double root, or none: verified by the caller */
        }
    }
    /* sort by angle from the shift + pi, where |f| is the largest sample: no root is
     * next to that cut (from the shift itself, a root there, e.g. the iiwa's stretched
     * elbow at 0 by rounding +-1e-11, changed ends with the rounding and the slots with
     * it; issue 29, helper slots29). Insertion sort of <= 4. */
    for (int i = 0; i < n; i++)
        x[i] = delta + wrap_pi(x[i] - delta);
    for (int i = 1; i < n; i++)
        for (int j = i; j > 0 && x[j] < x[j - 1]; j--) {
            double t = x[j];
            x[j] = x[j - 1];
            x[j - 1] = t;
        }
    return n;
}

/* Solutions of the position problem: up to 4 (theta_a, theta_b, theta_c), each
 * with its slot (0-3), singular flag and residual */
typedef struct {
    int n;
    double t[4][3], c[4][3], s[4][3], res[4];
    unsigned char slot[4], sing[4];
} PkPos;

/* The two equations P u_a - Q u_c = r of the position problem (module comment):
 * row 1 the heights along h_b, row 2 the squared distances to o_b divided by
 * 2 scale. */
typedef struct {
    double P[2][2], Q[2][2], r[2];
    v3 ha, hb, hc, oa, ob, oc, d, p;
    double mab, mbc; /* mutual moments / scale of axes (a, b), (b, c) */
    double scale;
    double l1, l2, inv2L; /* pk_equations_d's part of r, for pk_equations_p */
    v3 dcb, wc;
} PkEq;

/* pk_equations' part from d (P, the mutual moments, r's d terms): held-value-free
 * where the held joint is the chain's last and the triple starts it (pk_front_memo) */
static void pk_equations_d(const PkGeo *g, int ia, v3 d, PkEq *e)
{
    v3 ha = g->h[ia], hb = g->h[ia + 1], hc = g->h[ia + 2];
    v3 oa = g->o[ia], oc = g->o[ia + 2];
    v3 mid = v3_scale(v3_add(oa, oc), 0.5);
    v3 ob = v3_add(g->o[ia + 1], v3_scale(hb, v3_dot(hb, v3_sub(mid, g->o[ia + 1]))));
    double L = g->scale, inv2L = 0.5 / L;
    v3 a = v3_sub(d, oa), apar = v3_scale(ha, v3_dot(ha, a)), aperp = v3_sub(a, apar);
    v3 axa = v3_cross(ha, a);
    v3 dab = v3_sub(oa, ob), dcb = v3_sub(oc, ob);
    v3 wa = v3_scale(dab, 1.0 / L), wc = v3_scale(dcb, 1.0 / L);
    e->P[0][0] = v3_dot(hb, aperp);
    e->P[0][1] = -v3_dot(hb, axa);
    e->P[1][0] = v3_dot(wa, aperp);
    e->P[1][1] = -v3_dot(wa, axa);
    e->l1 = v3_dot(hb, v3_add(apar, dab));
    e->l2 = (v3_dot(a, a) + v3_dot(dab, dab)) * inv2L + v3_dot(wa, apar);
    e->inv2L = inv2L;
    e->dcb = dcb;
    e->wc = wc;
    e->ha = ha;
    e->hb = hb;
    e->hc = hc;
    e->oa = oa;
    e->ob = ob;
    e->oc = oc;
    e->d = d;
    e->scale = L;
    e->mab = v3_dot(dab, v3_cross(ha, hb)) / L;
    e->mbc = v3_dot(dcb, v3_cross(hb, hc)) / L;
}

/* pk_equations' part from p (Q, r), after pk_equations_d */
static void pk_equations_p(PkEq *e, v3 p)
{
    v3 hb = e->hb, hc = e->hc, dcb = e->dcb, wc = e->wc;
    v3 b = v3_sub(p, e->oc), bpar = v3_scale(hc, v3_dot(hc, b)), bperp = v3_sub(b, bpar);
    v3 hxb = v3_cross(hc, b);
    e->Q[0][0] = v3_dot(hb, bperp);
    e->Q[0][1] = v3_dot(hb, hxb);
    e->Q[1][0] = v3_dot(wc, bperp);
    e->Q[1][1] = v3_dot(wc, hxb);
    double r1 = v3_dot(hb, v3_add(bpar, dcb));
    double r2 = (v3_dot(b, b) + v3_dot(dcb, dcb)) * e->inv2L + v3_dot(wc, bpar);
    e->r[0] = r1 - e->l1;
    e->r[1] = r2 - e->l2;
    e->p = p;
}

static void pk_equations(const PkGeo *g, int ia, v3 p, v3 d, PkEq *e)
{
    pk_equations_d(g, ia, d, e);
    pk_equations_p(e, p);
}

/* The unit left null vector of the 2 x 2 matrix whose rows are the dot products
 * of v1, v2 (perpendicular to h, parallel to each other) with a basis of the
 * plane perpendicular to h: n1 v1 + n2 v2 = 0. */
static void pk_null(v3 h, v3 v1, v3 v2, double *n)
{
    v1 = v3_sub(v1, v3_scale(h, v3_dot(h, v1)));
    v2 = v3_sub(v2, v3_scale(h, v3_dot(h, v2)));
    v3 e = v3_dot(v1, v1) >= v3_dot(v2, v2) ? v1 : v2;
    double ne = v3_norm(e);
    if (ne > 0.0)
        e = v3_scale(e, 1.0 / ne);
    n[0] = v3_dot(v2, e);
    n[1] = -v3_dot(v1, e);
    double nn = hypot(n[0], n[1]);
    if (nn > 0.0) {
        n[0] /= nn;
        n[1] /= nn;
    } else {
        n[0] = 1.0;
        n[1] = 0.0;
    }
}

/* theta_b from theta_a, theta_c (given by cosine and sine): rot(h_b, theta_b)
 * (z - o_b) = y - o_b (least squares); its cosine, sine into cb, sb and the
 * residual of that rotation [m] into res */
static double pk_theta_b(const PkEq *e, double ca, double sa, double cc, double sc,
                         double *cb, double *sb, double *res)
{
    v3 y = v3_add(e->oa, v3_rot(e->ha, ca, -sa, v3_sub(e->d, e->oa)));
    v3 z = v3_add(e->oc, v3_rot(e->hc, cc, sc, v3_sub(e->p, e->oc)));
    v3 zy = v3_sub(z, e->ob), yy = v3_sub(y, e->ob);
    double tb = pk_sp1(e->hb, zy, yy, cb, sb);
    *res = v3_norm(v3_sub(v3_rot(e->hb, *cb, *sb, zy), yy));
    return tb;
}

/* A c + B s = C: up to two roots (Roots of six_r.c). |C| above hypot(A, B) by
 * at most `slack` (absolute, in the units of A, B, C: what rounding of the
 * coefficients can make of a double root), or a discriminant down to -1e-13
 * (A^2 + B^2), is a double root; any positive discriminant gives two roots,
 * however close: next to a double root a root's error is second order in the
 * pose, so two accurate close roots beat one merged root (which would be off by
 * the square root of their distance). */
static Roots pk_sp4_at(double A, double B, double C, double slack, double phi, double cphi,
                       double sphi)
{
    double disc = A * A + B * B - C * C;
    if (disc < 0.0 && fabs(C) - hypot(A, B) <= slack)
        disc = 0.0;
    return sp4_roots(A, B, C, disc, 1e-13, 0, phi, cphi, sphi);
}

static Roots pk_sp4(double A, double B, double C, double slack)
{
    double phi = fast_atan2(B, A), cphi, sphi;
    unit2(B, A, &cphi, &sphi);
    return pk_sp4_at(A, B, C, slack, phi, cphi, sphi);
}

/* A solution (theta_a, theta_c given by angle, cosine and sine; theta_b solved) */
static void pk_pos_add(PkPos *out, const PkEq *e, int slot, double ta, double ca, double sa,
                       double tc, double cc, double sc, int sing)
{
    int i = out->n++;
    double cb, sb, res;
    double tb = pk_theta_b(e, ca, sa, cc, sc, &cb, &sb, &res);
    out->t[i][0] = ta;
    out->t[i][1] = tb;
    out->t[i][2] = tc;
    out->c[i][0] = ca;
    out->s[i][0] = sa;
    out->c[i][1] = cb;
    out->s[i][1] = sb;
    out->c[i][2] = cc;
    out->s[i][2] = sc;
    out->res[i] = res;
    out->slot[i] = (unsigned char)slot;
    out->sing[i] = (unsigned char)sing;
}

/* pk_coplanar's part from x's matrix (P, or Q when swapped): the null combination n,
 * theta_x's subproblem 4 coefficients A, B (its phase phi, cphi, sphi), whether
 * theta_x is free, the other combination m */
typedef struct {
    double n[2], A, B, phi, cphi, sphi, m0, m1;
    int xfree;
} PkCop;

static void pk_coplanar_x(const PkEq *e, int swap, PkCop *k)
{
    double L = e->scale;
    v3 h = swap ? e->ha : e->hc, o = swap ? e->oa : e->oc;
    /* the rows' vectors: h_b and (o - o_b) / scale (the second row's scaling) */
    pk_null(h, e->hb, v3_scale(v3_sub(o, e->ob), 1.0 / L), k->n);
    const double(*X)[2] = swap ? e->Q : e->P; /* x's matrix */
    double sx = swap ? -1.0 : 1.0; /* P u_a - Q u_c = r: the sign of x's term */
    k->A = sx * (k->n[0] * X[0][0] + k->n[1] * X[1][0]);
    k->B = sx * (k->n[0] * X[0][1] + k->n[1] * X[1][1]);
    k->xfree = hypot(k->A, k->B) <= 1e-12 * L;
    if (!k->xfree) {
        k->phi = fast_atan2(k->B, k->A);
        unit2(k->B, k->A, &k->cphi, &k->sphi);
    }
    k->m0 = -k->n[1];
    k->m1 = k->n[0];
}

/* Coplanar axes b, c (Q singular; swap: a, b and P): the null combination n of the
 * rows holds theta_x alone (x = a, or c when swapped); the other combination m then
 * gives theta_y. pref_a, pref_c: the chain angles to take when one is free. k:
 * pk_coplanar_x's part (NULL: computed here). want: the position slots (bits 0-3)
 * to solve (the others are left out of out, as if they had no root). */
static int pk_coplanar(const PkEq *e, int swap, const PkCop *k, double pref_a, double pref_c,
                       unsigned want, PkPos *out)
{
    double L = e->scale;
    PkCop own;
    if (k == NULL) {
        pk_coplanar_x(e, swap, &own);
        k = &own;
    }
    const double *n = k->n;
    const double(*X)[2] = swap ? e->Q : e->P; /* x's matrix */
    const double(*Y)[2] = swap ? e->P : e->Q;
    double sx = swap ? -1.0 : 1.0; /* P u_a - Q u_c = r: the sign of x's term */
    double A = k->A, B = k->B;
    double C = n[0] * e->r[0] + n[1] * e->r[1];
    Roots rx;
    int xfree = k->xfree;
#ifdef PK_DEBUG
    fprintf(stderr, " coplanar swap %d n %.3e %.3e A %.6e B %.6e C %.6e disc %.3e xfree %d\n", swap, n[0], n[1], A, B, C, A*A+B*B-C*C, xfree);
#endif
    if (xfree) { /* the point on axis x: theta_x free (or no solution) */
        if (fabs(C) > 1e-9 * L)
            return PK_OUT_OF_REACH;
        double tx = swap ? pref_c : pref_a;
        rx.n = 1;
        rx.boundary = 1;
        rx.t[0] = tx;
        rx.c[0] = cos(tx);
        rx.s[0] = sin(tx);
    } else {
        rx = pk_sp4_at(A, B, C, PK_SP4_SLACK * L, k->phi, k->cphi, k->sphi);
    }
    double m0 = k->m0, m1 = k->m1;
    double Ay = -sx * (m0 * Y[0][0] + m1 * Y[1][0]);
    double By = -sx * (m0 * Y[0][1] + m1 * Y[1][1]);
    /* hypot(Ay, By) >= max(|Ay|, |By|): the call only where that cannot decide */
    double yl = 1e-12 * L;
    int yfree = !(fabs(Ay) > yl || fabs(By) > yl) && hypot(Ay, By) <= yl;
    double phy = 0.0, cphy = 1.0, sphy = 0.0; /* theta_y's phase (pk_sp4's), once */
    if (!yfree && (want & ((rx.n > 1 ? 15u : 3u))) != 0u) {
        phy = fast_atan2(By, Ay);
        unit2(By, Ay, &cphy, &sphy);
    }
    for (int i = 0; i < rx.n; i++) {
        if (!(want & 3u << 2 * i))
            continue; /* neither of this root's position slots asked for */
        double cx = rx.c[i], sxn = rx.s[i];
        /* m . (X u_x sx - r) = -sx m . Y u_y ... written out: */
        double Xu0 = X[0][0] * cx + X[0][1] * sxn, Xu1 = X[1][0] * cx + X[1][1] * sxn;
        double Cy = m0 * (e->r[0] - sx * Xu0) + m1 * (e->r[1] - sx * Xu1);
        Roots ry;
        if (yfree) {
            double ty = swap ? pref_a : pref_c;
            ry.n = 1;
            ry.boundary = 1;
            ry.t[0] = ty;
            ry.c[0] = cos(ty);
            ry.s[0] = sin(ty);
        } else {
            ry = pk_sp4_at(Ay, By, Cy, PK_SP4_SLACK * L, phy, cphy, sphy);
        }
#ifdef PK_DEBUG
        fprintf(stderr, "  y: Ay %.6e By %.6e Cy %.6e disc %.3e n %d\n", Ay, By, Cy, Ay*Ay+By*By-Cy*Cy, ry.n);
#endif
        for (int j = 0; j < ry.n; j++) {
            int sing = xfree || rx.boundary || ry.boundary;
            if (!(want >> (2 * i + j) & 1u))
                continue;
            if (swap)
                pk_pos_add(out, e, 2 * i + j, ry.t[j], ry.c[j], ry.s[j], rx.t[i], rx.c[i],
                           rx.s[i], sing);
            else
                pk_pos_add(out, e, 2 * i + j, rx.t[i], rx.c[i], rx.s[i], ry.t[j], ry.c[j],
                           ry.s[j], sing);
        }
    }
    return out->n ? PK_OK : PK_OUT_OF_REACH;
}

/* General axes: u_y eliminated through the better-conditioned of P, Q; f(theta_x)
 * = |K u_x - k|^2 - D^2 = 0 with u_y = (K u_x - k) / D. */
static int pk_general(const PkEq *e, PkPos *out)
{
    double dP = e->P[0][0] * e->P[1][1] - e->P[0][1] * e->P[1][0];
    double dQ = e->Q[0][0] * e->Q[1][1] - e->Q[0][1] * e->Q[1][0];
    double nP = e->P[0][0] * e->P[0][0] + e->P[0][1] * e->P[0][1] +
                e->P[1][0] * e->P[1][0] + e->P[1][1] * e->P[1][1];
    double nQ = e->Q[0][0] * e->Q[0][0] + e->Q[0][1] * e->Q[0][1] +
                e->Q[1][0] * e->Q[1][0] + e->Q[1][1] * e->Q[1][1];
    /* eliminate u_c (x = a) when Q is the better conditioned */
    int xa = fabs(dQ) * (nP + 1e-300) >= fabs(dP) * (nQ + 1e-300);
    double K[2][2], k[2], D;
    if (xa) { /* Q u_c = P u_a - r: u_c = adj(Q) (P u_a - r) / dQ */
        double aq[2][2] = {{e->Q[1][1], -e->Q[0][1]}, {-e->Q[1][0], e->Q[0][0]}};
        for (int i = 0; i < 2; i++) {
            for (int j = 0; j < 2; j++)
                K[i][j] = aq[i][0] * e->P[0][j] + aq[i][1] * e->P[1][j];
            k[i] = aq[i][0] * e->r[0] + aq[i][1] * e->r[1];
        }
        D = dQ;
    } else { /* P u_a = Q u_c + r: u_a = adj(P) (Q u_c + r) / dP */
        double ap[2][2] = {{e->P[1][1], -e->P[0][1]}, {-e->P[1][0], e->P[0][0]}};
        for (int i = 0; i < 2; i++) {
            for (int j = 0; j < 2; j++)
                K[i][j] = ap[i][0] * e->Q[0][j] + ap[i][1] * e->Q[1][j];
            k[i] = -(ap[i][0] * e->r[0] + ap[i][1] * e->r[1]);
        }
        D = dP;
    }
    if (D == 0.0)
        return PK_DEGENERATE;
    double al = K[0][0] * K[0][0] + K[1][0] * K[1][0];
    double ga = K[0][1] * K[0][1] + K[1][1] * K[1][1];
    double be = K[0][0] * K[0][1] + K[1][0] * K[1][1];
    double g1 = K[0][0] * k[0] + K[1][0] * k[1], g2 = K[0][1] * k[0] + K[1][1] * k[1];
    Trig2 f = {0.5 * (al + ga) + k[0] * k[0] + k[1] * k[1] - D * D, -2.0 * g1, -2.0 * g2,
               0.5 * (al - ga), be};
    double xs[8];
    int nd;
    int nx = trig2_roots(&f, xs, &nd);
    if (nx < 0)
        return PK_DEGENERATE;
    /* |u_y| = 1 at a root, to a tolerance scale-aware in the elimination: a root x
     * next to a double one (the reach boundary, a stretched elbow) is off by up to
     * sqrt(eps), and u_y by |K| / |D| that (|D| 2.5e-10 against |K| 1e-4 on the
     * rtb-data iiwa14 with joint_a3 held at -1e-7: |u_y| - 1 = 1.2e-5); u_y is
     * normalised, the residual below, the polish and the pose check decide */
    double ktol = 1e-6 + 1.5e-8 * sqrt(al + ga) / fabs(D);
    for (int i = 0; i < nx && out->n < 4; i++) {
        double x = xs[i], cx = cos(x), sx = sin(x);
        double uy0 = (K[0][0] * cx + K[0][1] * sx - k[0]) / D;
        double uy1 = (K[1][0] * cx + K[1][1] * sx - k[1]) / D;
        double ny = hypot(uy0, uy1);
        if (!(fabs(ny - 1.0) < ktol))
            continue; /* not a root */
        double y = fast_atan2(uy1, uy0), cy, sy;
        unit2(uy1, uy0, &cy, &sy);
        double ta = xa ? x : y, tc = xa ? y : x;
        /* the same solution twice (a double root found from both sides) */
        int dup = 0;
        for (int j = 0; j < out->n; j++)
            if (fabs(wrap_pi(out->t[j][0] - ta)) < 1e-9 &&
                fabs(wrap_pi(out->t[j][2] - tc)) < 1e-9)
                dup = 1;
        if (dup)
            continue;
        if (xa)
            pk_pos_add(out, e, out->n, x, cx, sx, y, cy, sy, nd);
        else
            pk_pos_add(out, e, out->n, y, cy, sy, x, cx, sx, nd);
        if (!(out->res[out->n - 1] < 1e-6 * e->scale))
            out->n--; /* not a root after all */
    }
    return out->n ? PK_OK : PK_OUT_OF_REACH;
}

/* ------------------------------------------------------------- the triple */

/* Joint x's coordinate interval for a split theta_x + sigma theta_z = phi: the
 * joint z value (coordinate) nearest pref such that both joints are within their
 * limits (by whole turns), or pref clamped into z's limits when none is. */
static double pk_split(const double *P, int jx, int jz, double phi, double sigma,
                       double pref)
{
    double sx = P[PK_SIGN + jx], ox = P[PK_OFFSET + jx], sz = P[PK_SIGN + jz];
    double oz = P[PK_OFFSET + jz];
    double lox = P[PK_LO + jx], hix = P[PK_HI + jx], loz = P[PK_LO + jz], hiz = P[PK_HI + jz];
    /* q_x = c0 + kappa q_z (mod 2 pi) */
    double c0 = wrap_pi(sx * (phi - sigma * oz - ox)), kappa = -sx * sigma * sz;
    double best = NAN, bestd = INFINITY;
    for (int m = -2; m <= 2; m++) {
        double lo, hi;
        if (kappa > 0.0) {
            lo = lox - c0 + 2.0 * M_PI * m;
            hi = hix - c0 + 2.0 * M_PI * m;
        } else {
            lo = c0 + 2.0 * M_PI * m - hix;
            hi = c0 + 2.0 * M_PI * m - lox;
        }
        lo = fmax(lo, loz);
        hi = fmin(hi, hiz);
        if (lo > hi)
            continue;
        double q = fmin(fmax(pref, lo), hi), d = fabs(q - pref);
        if (d < bestd) {
            bestd = d;
            best = q;
        }
    }
    if (isnan(best))
        best = fmin(fmax(pref, loz), hiz);
    return sz * best + oz; /* theta_z */
}

/* A triple's pose-independent constants: the half-angle sines and cosines of
 * (bx - bz) / 2 and (bx + bz) / 2, bx, bz the angles of hx, hz from hy, and the
 * azimuth t0 about hy where rot(hy, t) hz comes nearest hx (with its cosine, sine). */
typedef struct {
    v3 hx, hy, hz;
    double cd, sd, cs, ss, t0, c0, s0;
} PkTri;

static void pk_tri_init(PkTri *k, v3 hx, v3 hy, v3 hz)
{
    double bx = atan2(v3_norm(v3_cross(hy, hx)), v3_dot(hy, hx));
    double bz = atan2(v3_norm(v3_cross(hy, hz)), v3_dot(hy, hz));
    v3 xp = v3_sub(hx, v3_scale(hy, v3_dot(hx, hy)));
    v3 zp = v3_sub(hz, v3_scale(hy, v3_dot(hz, hy)));
    k->hx = hx;
    k->hy = hy;
    k->hz = hz;
    k->cd = cos(0.5 * (bx - bz));
    k->sd = sin(0.5 * (bx - bz));
    k->cs = cos(0.5 * (bx + bz));
    k->ss = sin(0.5 * (bx + bz));
    k->t0 = atan2(v3_dot(hy, v3_cross(zp, xp)), v3_dot(zp, xp));
    unit2(v3_dot(hy, v3_cross(zp, xp)), v3_dot(zp, xp), &k->c0, &k->s0);
}

/* The middle angle of a triple: ty with rot(hy, ty) hz at the angle psi from hx
 * that w = R hz makes. Subproblem 4 for unit vectors by the spherical law of
 * cosines in half-angle form, so that roots next to a double root keep their
 * accuracy: with D the turn from t0,
 *   sin^2(D / 2) ~ sin((psi + bx - bz) / 2) sin((psi - bx + bz) / 2),
 *   cos^2(D / 2) ~ sin((bx + bz + psi) / 2) sin((bx + bz - psi) / 2),
 * sin, cos(psi / 2) = |hx -+ w| / 2 (no trigonometry). Roots t0 + D, t0 - D. */
static Roots pk_middle(const PkTri *k, v3 w)
{
    Roots r;
    double sp = 0.5 * v3_norm(v3_sub(k->hx, w)), cp = 0.5 * v3_norm(v3_add(k->hx, w));
    double a1 = sp * k->cd + cp * k->sd, a2 = sp * k->cd - cp * k->sd;
    double b1 = k->ss * cp + k->cs * sp, b2 = k->ss * cp - k->cs * sp;
    double S = a1 * a2, C = b1 * b2;
    r.boundary = 0;
    if (S < -1e-13 || C < -1e-13) {
        r.n = 0;
        return r;
    }
    S = fmax(S, 0.0);
    C = fmax(C, 0.0);
    double hs = sqrt(S), hc = sqrt(C);
    double D = 2.0 * fast_atan2(hs, hc), n2 = S + C;
    double cD = (C - S) / n2, sD = 2.0 * hs * hc / n2;
    r.t[0] = k->t0 + D;
    r.t[1] = k->t0 - D;
    r.c[0] = k->c0 * cD - k->s0 * sD;
    r.s[0] = k->s0 * cD + k->c0 * sD;
    r.c[1] = k->c0 * cD + k->s0 * sD;
    r.s[1] = k->s0 * cD - k->c0 * sD;
    r.n = S > 0.0 ? 2 : 1;
    r.boundary = r.n == 1;
    return r;
}

/* A triple's solutions: angles, singular flags, and whether the solution still
 * needs checking against the pose (near the singularity the two vector residuals
 * do not pin the rotation) */
typedef struct {
    int n;
    double t[2][3];
    unsigned char sing[2], check[2];
} PkTrip;

/* rot(hx, tx) rot(hy, ty) rot(hz, tz) = R: up to two solutions; jx, jz: the outer
 * joints' full-chain indices, pref_z z's preferred coordinate at the singularity.
 * want: the solutions (bits 0, 1) to complete; the others keep their place (and
 * the singular case its single solution) with NaN angles, unflagged. */
static void pk_triple_want(const double *P, const PkTri *k, const m3 *R, int jx, int jz,
                           double pref_z, double stol, unsigned want, PkTrip *out)
{
    v3 hx = k->hx, hy = k->hy, hz = k->hz;
    v3 w = m3_mv(R, hz), rtx = m3_mtv(R, hx);
    Roots ry = pk_middle(k, w);
    out->n = 0;
    for (int i = 0; i < ry.n; i++) {
        double ty = ry.t[i], cy = ry.c[i], sy = ry.s[i];
        v3 v = v3_rot(hy, cy, sy, hz);
        double sv = v3_norm(v3_cross(v, hx));
        if (sv < stol) {
            /* at the singularity: hold the exact singular angle where it reproduces
             * R, and split the outer angles inside the limits */
            double sigma = v3_dot(v, hx) >= 0.0 ? 1.0 : -1.0, cs, ss;
            double tys = sp1(hy, hz, v3_scale(hx, sigma), &cs, &ss);
            v3 vs = v3_rot(hy, cs, ss, hz);
            if (v3_norm(v3_sub(vs, v3_scale(hx, sigma))) < 1e-13) {
                m3 Ry = pk_rotm(hy, cs, ss);
                m3 X = pk_mul_t(R, &Ry); /* R rot(hy, -tys) = rot(hx, phi) */
                if (v3_norm(v3_sub(m3_mv(&X, hx), hx)) < PK_EXACT) {
                    v3 e = v3_cross(hx, hy);
                    double ne = v3_norm(e);
                    e = ne > 1e-6 ? v3_scale(e, 1.0 / ne) : v3_cross(hx, hz);
                    double cp, sp;
                    double phi = sp1(hx, e, m3_mv(&X, e), &cp, &sp);
                    double tz = pk_split(P, jx, jz, phi, sigma, pref_z);
                    out->t[0][0] = phi - sigma * tz;
                    out->t[0][1] = tys;
                    out->t[0][2] = tz;
                    out->sing[0] = 1;
                    out->check[0] = 1;
                    out->n = 1;
                    return;
                }
            }
        }
        if (!(want >> i & 1u)) {
            int j = out->n++;
            out->t[j][0] = out->t[j][1] = out->t[j][2] = NAN;
            out->sing[j] = out->check[j] = 0;
            continue;
        }
        double cx, sx, cz, sz;
        double tx = pk_sp1(hx, v, w, &cx, &sx);
        v3 u = v3_rot(hy, cy, -sy, hx);
        double tz = -pk_sp1(hz, u, rtx, &cz, &sz);
        if (sv < 1e-6) {
            /* near the singularity the split of tx + sigma tz costs only sv per
             * radian of pose: move it inside the limits when that stays exact */
            double sigma = v3_dot(v, hx) >= 0.0 ? 1.0 : -1.0;
            double qz = P[PK_SIGN + jz] * (tz - P[PK_OFFSET + jz]);
            double tz2 = pk_split(P, jx, jz, tx + sigma * tz, sigma, qz);
            double eps = wrap_pi(tz2 - tz);
#ifdef PK_DEBUG
            fprintf(stderr, "   resplit sv %.3e tz %.17g tz2 %.17g eps %.3e\n", sv, tz, tz2, eps);
#endif
            if (fabs(eps) * sv <= 0.01 * PK_EXACT) {
                tx -= sigma * eps;
                tz += eps;
            }
        }
        int j = out->n++;
        out->t[j][0] = tx;
        out->t[j][1] = ty;
        out->t[j][2] = tz;
        out->sing[j] = (unsigned char)(sv < 1e-7);
        /* R' hz = R hz and R'^T hx = R^T hx pin R' = R, to within the residuals
         * divided by sv (the sine of the angle between hz and R'^T hx) */
        double res = v3_norm(v3_sub(v3_rot(hx, cx, sx, v), w)) +
                     v3_norm(v3_sub(v3_rot(hz, cz, sz, u), rtx));
        out->check[j] = (unsigned char)(sv < 1e-4 || !(res < 1e-2 * PK_EXACT * sv));
    }
}

static void pk_triple(const double *P, const PkTri *k, const m3 *R, int jx, int jz,
                      double pref_z, double stol, PkTrip *out)
{
    pk_triple_want(P, k, R, jx, jz, pref_z, stol, 3u, out);
}

/* ---------------------------------------------------------------- polish */

/* Pose of the remaining chain at angles th, and the Jacobian (6 x 6, rows
 * [v / scale; w], spatial at the tool point) when J is not NULL. */
static void pk_fk(const PkGeo *g, const double *th, m3 *R, v3 *p, double J[6][6])
{
    m3 A = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
    v3 t = {0.0, 0.0, 0.0}, hc[6], oc[6];
    for (int j = 0; j < 6; j++) {
        hc[j] = m3_mv(&A, g->h[j]);
        oc[j] = v3_add(m3_mv(&A, g->o[j]), t);
        m3 Rj = pk_rotm(g->h[j], cos(th[j]), sin(th[j]));
        t = v3_add(t, m3_mv(&A, v3_sub(g->o[j], m3_mv(&Rj, g->o[j]))));
        A = pk_mul(&A, &Rj);
    }
    *R = pk_mul(&A, &g->RM);
    *p = v3_add(m3_mv(&A, g->tM), t);
    if (J == NULL)
        return;
    for (int j = 0; j < 6; j++) {
        v3 v = v3_scale(v3_cross(hc[j], v3_sub(*p, oc[j])), 1.0 / g->scale);
        J[0][j] = v.x;
        J[1][j] = v.y;
        J[2][j] = v.z;
        J[3][j] = hc[j].x;
        J[4][j] = hc[j].y;
        J[5][j] = hc[j].z;
    }
}

/* The pose error e = [(p_T - p) / scale; rotation vector of R_T R^T] (small angles);
 * returns the larger of |p_T - p| / max(1, scale) and the rotation angle */
static double pk_error(const m3 *RT, v3 pT, const m3 *R, v3 p, double scale, double *e)
{
    v3 dp = v3_scale(v3_sub(pT, p), 1.0 / scale);
    double pn = v3_norm(v3_sub(pT, p)) / fmax(1.0, scale);
    m3 E = pk_mul_t(RT, R);
    e[0] = dp.x;
    e[1] = dp.y;
    e[2] = dp.z;
    e[3] = 0.5 * (E.r2.y - E.r1.z);
    e[4] = 0.5 * (E.r0.z - E.r2.x);
    e[5] = 0.5 * (E.r1.x - E.r0.y);
    /* |rotation vector| for small angles; 3 - trace = 2 (1 - cos) is large past pi / 2 */
    double rn = sqrt(e[3] * e[3] + e[4] * e[4] + e[5] * e[5]);
    return fmax(fmax(pn, rn), 3.0 - (E.r0.x + E.r1.y + E.r2.z));
}

/* The pose error (pk_error) of chain angles th */
static double pk_error_of(const PkGeo *g, const m3 *RT, v3 pT, const double *th)
{
    m3 R;
    v3 p;
    double e[6];
    pk_fk(g, th, &R, &p, NULL);
    return pk_error(RT, pT, &R, p, g->scale, e);
}

/* A repair's trial angles: copied into th when they reach the pose to PK_ACCEPT.
 * Returns 1 when th changed. */
static int pk_accept(const PkGeo *g, const m3 *RT, v3 pT, const double *trial, double *th)
{
    if (!(pk_error_of(g, RT, pT, trial) <= PK_ACCEPT))
        return 0;
    for (int j = 0; j < 6; j++)
        th[j] = trial[j];
    return 1;
}

#include "linalg6.h" /* pk_lstsq, pk_svd6 */

/* Newton steps (pk_polish_held) up to `iters`; with `twice`, each step the better
 * of Newton's and twice it (pk_polish_slow) */
static double pk_newton(const PkGeo *g, const m3 *RT, v3 pT, double *th, unsigned frozen,
                        int iters, int twice)
{
    m3 R;
    v3 p;
    double J[6][6], e[6];
    pk_fk(g, th, &R, &p, J);
    double err = pk_error(RT, pT, &R, p, g->scale, e);
    for (int it = 0; it < iters && err > 1e-16; it++) {
        double dx[6], trial[6], big = 0.0;
        for (int j = 0; j < 6; j++)
            if (frozen >> j & 1u)
                for (int r = 0; r < 6; r++)
                    J[r][j] = 0.0;
        pk_lstsq(J, e, dx);
        for (int j = 0; j < 6; j++) {
            if (frozen >> j & 1u)
                dx[j] = 0.0;
            trial[j] = wrap_pi(th[j] + dx[j]);
            big = fmax(big, fabs(dx[j]));
        }
        if (!(big < 0.1))
            break; /* not a small correction: a near-null direction */
        m3 R2;
        v3 p2;
        double J2[6][6], e2[6];
        pk_fk(g, trial, &R2, &p2, J2);
        double err2 = pk_error(RT, pT, &R2, p2, g->scale, e2);
        if (twice && 2.0 * big < 0.1) {
            /* the doubled step: at a double root (a singular solution, where the
             * error is quadratic along the null direction) Newton only halves the
             * distance; twice its step lands on the root to first order */
            double trial2[6], J3[6][6], e3[6];
            for (int j = 0; j < 6; j++)
                trial2[j] = wrap_pi(th[j] + 2.0 * dx[j]);
            pk_fk(g, trial2, &R2, &p2, J3);
            double err3 = pk_error(RT, pT, &R2, p2, g->scale, e3);
            if (err3 < err2) {
                err2 = err3;
                for (int j = 0; j < 6; j++) {
                    trial[j] = trial2[j];
                    e2[j] = e3[j];
                    for (int r = 0; r < 6; r++)
                        J2[r][j] = J3[r][j];
                }
            }
        }
#ifdef PK_DEBUG
        fprintf(stderr, "    polish it %d frozen %x err %.3e -> %.3e big %.3e\n", it, frozen, err, err2, big);
#endif
        if (!(err2 < err))
            break;
        err = err2;
        for (int j = 0; j < 6; j++) {
            th[j] = trial[j];
            e[j] = e2[j];
            for (int r = 0; r < 6; r++)
                J[r][j] = J2[r][j];
        }
    }
    return err;
}

/* Newton steps on the remaining chain's angles (least squares, pk_lstsq; kept only
 * while they reduce the error), the joints in `frozen` (bit j: angle j) held;
 * returns the final error (pk_error) */
static double pk_polish_held(const PkGeo *g, const m3 *RT, v3 pT, double *th, unsigned frozen)
{
    return pk_newton(g, RT, pT, th, frozen, 6, 0);
}

static double pk_polish(const PkGeo *g, const m3 *RT, v3 pT, double *th)
{
    return pk_polish_held(g, RT, pT, th, 0u);
}

/* A candidate the polish left above PK_ACCEPT but within PK_SLOW of the pose
 * (next to a doubly singular configuration, e.g. both triples of the Panda with q6
 * held next to aligned: the position step's double root rounded to one angle and
 * the triple's outer angles taken at sv ~ 1e-11 start the polish 1e-5 off, where
 * Newton converges only linearly, by 4x a step): up to PK_SLOW_ITERS more steps,
 * each the better of Newton's step and twice it. Returns the final error; the
 * caller still keeps the row only at PK_ACCEPT. */
static double pk_polish_slow(const PkGeo *g, const m3 *RT, v3 pT, double *th, double err)
{
    if (!(err > PK_ACCEPT && err <= PK_SLOW))
        return err;
    return pk_newton(g, RT, pT, th, 0u, PK_SLOW_ITERS, 1);
}

/* ------------------------------------------------------------- one pose */

/* One pose's outputs: Q (8 x n), valid, singular, within limits (8 each). */
typedef struct {
    double *Q;
    unsigned char *valid, *sing, *inside;
    int n;
} PkOut;

static void pk_clear(PkOut o)
{
    for (int k = 0; k < 8; k++) {
        o.valid[k] = o.sing[k] = o.inside[k] = 0;
        for (int j = 0; j < o.n; j++)
            o.Q[o.n * k + j] = NAN;
    }
}

/* Near a singular triple (its outer axes almost in line) only tx + sigma tz is
 * well determined: when th (remaining chain, triple at it) lies outside the
 * limits, move that split inside them where the pose error stays within
 * PK_ACCEPT (checked by forward kinematics). Returns 1 when th changed. */
static int pk_resplit(const double *P, const PkGeo *g, int it, const m3 *RT, v3 pT,
                      double *th)
{
    v3 hx = g->h[it], hy = g->h[it + 1], hz = g->h[it + 2];
    v3 v = v3_rot(hy, cos(th[it + 1]), sin(th[it + 1]), hz);
    double sv = v3_norm(v3_cross(v, hx));
    if (!(sv < 1e-6))
        return 0;
    int jx = g->full[it], jz = g->full[it + 2];
    double sigma = v3_dot(v, hx) >= 0.0 ? 1.0 : -1.0;
    double tx = th[it], tz = th[it + 2];
    double qz = P[PK_SIGN + jz] * (tz - P[PK_OFFSET + jz]);
    double eps = wrap_pi(pk_split(P, jx, jz, tx + sigma * tz, sigma, qz) - tz);
    if (eps == 0.0 || !(fabs(eps) * sv <= 0.1 * PK_ACCEPT))
        return 0;
    double trial[6];
    for (int j = 0; j < 6; j++)
        trial[j] = th[j];
    trial[it] = tx - sigma * eps;
    trial[it + 2] = tz + eps;
    return pk_accept(g, RT, pT, trial, th);
}

/* Joints on one line (a singular configuration: equal Jacobian columns up to the
 * sign sigma) only fix th_i + sigma th_j: when th lies outside the limits, trade
 * each such pair's split inside them (pk_split), two passes over the pairs, kept
 * when the pose still holds to PK_ACCEPT. Returns 1 when th changed. */
static int pk_repair(const double *P, const PkGeo *g, const m3 *RT, v3 pT, double *th)
{
    double trial[6];
    int moved = 0;
    for (int j = 0; j < 6; j++)
        trial[j] = th[j];
    for (int pass = 0; pass < 2; pass++) {
        m3 R;
        v3 p;
        double J[6][6];
        pk_fk(g, trial, &R, &p, J);
        for (int i = 0; i < 6; i++)
            for (int j = i + 1; j < 6; j++) {
                double dot = J[3][i] * J[3][j] + J[4][i] * J[4][j] + J[5][i] * J[5][j];
                double sigma = dot >= 0.0 ? 1.0 : -1.0, diff = 0.0;
                for (int r = 0; r < 6; r++)
                    diff = fmax(diff, fabs(J[r][i] - sigma * J[r][j]));
                if (!(diff < 1e-9))
                    continue;
                int fi = g->full[i], fj = g->full[j], ini, inj;
                joint_value(trial[i], P[PK_SIGN + fi], P[PK_OFFSET + fi], P[PK_LO + fi],
                            P[PK_HI + fi], &ini);
                double qj = joint_value(trial[j], P[PK_SIGN + fj], P[PK_OFFSET + fj],
                                        P[PK_LO + fj], P[PK_HI + fj], &inj);
                if (ini && inj)
                    continue;
                double phi = trial[i] + sigma * trial[j];
                double tj = pk_split(P, fi, fj, phi, sigma, qj);
                trial[j] = tj;
                trial[i] = phi - sigma * tj;
                moved = 1;
#ifdef PK_DEBUG
                fprintf(stderr, "   repair pair %d %d sigma %g diff %.3e -> %.6f %.6f\n", i, j,
                        sigma, diff, trial[i], trial[j]);
#endif
            }
    }
    if (!moved)
        return 0;
    for (int j = 0; j < 6; j++)
        trial[j] = wrap_pi(trial[j]);
    return pk_accept(g, RT, pT, trial, th);
}

/* The joint coordinates of chain angles th (6, remaining chain) into q (full
 * chain, held joint at x) and their smallest margin to the limits [rad]
 * (negative: outside) */
/* fmin's value inline (NaN: the other argument), for margins that are only
 * compared (a zero's sign may differ from libm's) */
static inline double pk_min_num(double a, double b)
{
    return isnan(a) ? b : isnan(b) ? a : b < a ? b : a;
}

static double pk_coords(const double *P, const PkGeo *g, const double *th, int held,
                        double x, double *q)
{
    double margin = INFINITY;
    for (int j = 0; j < 6; j++) {
        int f = g->full[j], in;
        double lo = P[PK_LO + f], hi = P[PK_HI + f];
        q[f] = joint_value(th[j], P[PK_SIGN + f], P[PK_OFFSET + f], lo, hi, &in);
        margin = pk_min_num(margin, pk_min_num(q[f] - lo, hi - q[f]));
    }
    if (held >= 0) {
        q[held] = x;
        margin = pk_min_num(margin, pk_min_num(x - P[PK_LO + held], P[PK_HI + held] - x));
    }
    return margin;
}

/* Whether held value x (none: held < 0) lies inside its limits (1e-9 slack, as
 * pk_coords): when it does not, no row can, and the repairs are not tried. */
static int pk_held_inside(const double *P, int held, double x)
{
    return held < 0 || (x - P[PK_LO + held] >= -1e-9 && P[PK_HI + held] - x >= -1e-9);
}

/* A row th (remaining chain, exact) just outside the limits, next to a singular
 * configuration: the exact configurations around it form a thin set along the
 * near-null directions, and the generating configuration may be one of them at
 * a limit (a joint exactly at its limit reached only to rounding). Clamp the
 * joints outside to the limit they passed, hold them there and Newton-polish the
 * others (their least-squares step slides along the singular direction back to
 * the pose); up to three rounds, as a polish may push another joint out. Joints
 * out by at most PK_CLAMP_SLACK stay free (held at a limit they were only
 * rounding past, the polish cannot return to the pose along a thin set). Tried
 * for rows at most `reach` [rad] outside (PK_NUDGE; PK_NUDGE_SING at rows flagged
 * singular, where the exact set next to a row is wider: the SRS arm stretched with
 * q6 at 1e-9 has its in-limit member 3e-3 rad away). Kept when the pose holds to
 * PK_ACCEPT and every joint is inside (1e-9 slack, as pk_coords): returns 1 when
 * th changed. */
static int pk_inside(const double *P, const PkGeo *g, const m3 *RT, v3 pT, double *th,
                     double reach)
{
    double trial[6];
    unsigned frozen = 0u;
    for (int j = 0; j < 6; j++)
        trial[j] = th[j];
    for (int round = 0; round < 3; round++) {
        int moved = 0;
        for (int j = 0; j < 6; j++) {
            int f = g->full[j];
            double sg = P[PK_SIGN + f], off = P[PK_OFFSET + f];
            double lo = P[PK_LO + f], hi = P[PK_HI + f];
            double q = wrap_pi(sg * (trial[j] - off)), best = q, gap = INFINITY;
            for (int m = -1; m <= 1; m++) { /* the turn of q nearest [lo, hi] */
                double qm = q + 2.0 * M_PI * m;
                double d = qm < lo ? lo - qm : qm > hi ? qm - hi : 0.0;
                if (d < gap) {
                    gap = d;
                    best = qm;
                }
            }
            if (gap <= PK_CLAMP_SLACK || (frozen >> j & 1u))
                continue; /* inside, or out by less than rounding: not held */
            if (gap > reach)
                return 0; /* not a thin set's width away */
            trial[j] = sg * (best < lo ? lo : hi) + off;
            frozen |= 1u << j;
            moved = 1;
        }
        if (!moved)
            break;
        double perr = pk_polish_held(g, RT, pT, trial, frozen);
#ifdef PK_DEBUG
        fprintf(stderr, "   inside round %d frozen %x err %.3e th %.12f %.12f %.12f %.12f %.12f %.12f\n", round, frozen, perr, trial[0], trial[1], trial[2], trial[3], trial[4], trial[5]);
#endif
        if (!(perr <= PK_ACCEPT))
            return 0;
    }
    double q[PK_MAXJ];
    if (!(pk_coords(P, g, trial, -1, 0.0, q) >= -1e-9))
        return 0;
    return pk_accept(g, RT, pT, trial, th);
}

/* How far joint coordinate q lies outside [lo, hi] at its nearest turn (0 inside),
 * and that limit into *lim. */
static double pk_outside(double q, double lo, double hi, double *lim)
{
    double gap = INFINITY;
    *lim = lo;
    for (int m = -1; m <= 1; m++) {
        double qm = q + 2.0 * M_PI * m;
        double d = qm < lo ? lo - qm : qm > hi ? qm - hi : 0.0;
        if (d < gap) {
            gap = d;
            *lim = qm < lo ? lo - 2.0 * M_PI * m : hi - 2.0 * M_PI * m;
        }
    }
    return gap;
}

/* Whether the 6 x 6 Jacobian J certainly has no singular value below
 * PK_FAMILY_SIGMA of its largest: |det J| = prod sigma_i <= sigma_min sigma_max^5
 * and sigma_max <= |J|_F, so |det J| > 2 PK_FAMILY_SIGMA |J|_F^6 (2: room for
 * the rounding of the elimination) proves sigma_min > PK_FAMILY_SIGMA sigma_max.
 * Gaussian elimination with partial pivoting, a few hundred flops: the Jacobi SVD
 * of pk_slide (thousands) runs only where this cannot rule a family out. */
static int pk_regular(const double J[6][6])
{
    double A[6][6], fro = 0.0, det = 1.0;
    for (int r = 0; r < 6; r++)
        for (int c = 0; c < 6; c++) {
            A[r][c] = J[r][c];
            fro += J[r][c] * J[r][c];
        }
    for (int c = 0; c < 6; c++) {
        int piv = c;
        for (int r = c + 1; r < 6; r++)
            if (fabs(A[r][c]) > fabs(A[piv][c]))
                piv = r;
        if (!(fabs(A[piv][c]) > 0.0))
            return 0;
        if (piv != c)
            for (int k = c; k < 6; k++) {
                double t = A[c][k];
                A[c][k] = A[piv][k];
                A[piv][k] = t;
            }
        det *= A[c][c];
        for (int r = c + 1; r < 6; r++) {
            double m = A[r][c] / A[c][c];
            for (int k = c + 1; k < 6; k++)
                A[r][k] -= m * A[c][k];
        }
    }
    return fabs(det) > 2.0 * PK_FAMILY_SIGMA * fro * fro * fro;
}

/* Whether the row th is certainly isolated (pk_regular's bound, |det J| >
 * 2 PK_FAMILY_SIGMA |J|_F^6, proven with room to spare) without forming J: the
 * cheap first test of pk_slide, which most rows outside the limits pass.
 * About the triple's point w the triple's columns have no linear part, so
 * det J = det[h_x, h_y, h_z] det[h_j x (w - o_j)] / scale^3 over the three
 * position joints j; the first depends on the triple's middle angle only, the
 * second on two of the position joints' angles (each factor taken in a frame
 * where the other angles drop out; det is unchanged by a rigid motion). |J|_F
 * is bounded by its value with every |h_j x (p - o_j)| at its largest, the
 * chain's length from o_j to the tool point (the 4 instead of pk_regular's 2
 * covers that this bound and the two determinants round differently). */
static int pk_isolated(const PkGeo *g, const double *th)
{
    if (g->kase == PK_BOTH)
        return 0; /* SRS: a held joint may split the triples; pk_regular decides */
    int t0 = g->kase == PK_END ? 3 : 0, p0 = 3 - t0;
    double s = g->scale, reach = v3_norm(v3_sub(g->tM, g->o[5])), f2 = 6.0;
    for (int j = 5; j >= 0; j--) {
        f2 += reach * reach / (s * s);
        if (j > 0)
            reach += v3_norm(v3_sub(g->o[j], g->o[j - 1]));
    }
    v3 hz = v3_rot(g->h[t0 + 1], cos(th[t0 + 1]), sin(th[t0 + 1]), g->h[t0 + 2]);
    double dt = v3_dot(g->h[t0], v3_cross(g->h[t0 + 1], hz));
    v3 ha = g->h[p0 + 1], oa = g->o[p0 + 1], w = g->pt;
    double ca = cos(th[p0 + 1]), sa = sin(th[p0 + 1]);
    v3 hb = v3_rot(ha, ca, sa, g->h[p0 + 2]);
    v3 ob = v3_add(oa, v3_rot(ha, ca, sa, v3_sub(g->o[p0 + 2], oa)));
    if (p0 == 0) { /* w after joints 1 and 2 (joint 0 undone) */
        w = v3_add(g->o[2], v3_rot(g->h[2], cos(th[2]), sin(th[2]), v3_sub(w, g->o[2])));
        w = v3_add(oa, v3_rot(ha, ca, sa, v3_sub(w, oa)));
    } else { /* w before joint 3 (the triple and joint 3 undone) */
        w = v3_add(g->o[3], v3_rot(g->h[3], cos(th[3]), -sin(th[3]), v3_sub(w, g->o[3])));
    }
    v3 c0 = v3_cross(g->h[p0], v3_sub(w, g->o[p0]));
    v3 c1 = v3_cross(ha, v3_sub(w, oa)), c2 = v3_cross(hb, v3_sub(w, ob));
    double det = fabs(dt * v3_dot(c0, v3_cross(c1, c2))) / (s * s * s);
    return det > 4.0 * PK_FAMILY_SIGMA * f2 * f2 * f2;
}

/* A row th on a one-parameter family of exact solutions (a singular configuration
 * whose remaining Jacobian has a null direction: smallest singular value below
 * PK_FAMILY_SIGMA of the largest) but outside the limits: slide along the family.
 * Each step linearizes every joint along the null vector, q_j(a) = q_j + d_j a,
 * intersects the intervals of a that keep each joint inside its limits (the
 * feasible set of the family parameter, to first order), moves to the point of
 * the intersection nearest a = 0 (its middle when rounding left it empty: two
 * joints at their limits at one point), at most 0.05 rad, and Newton-polishes
 * the pose with the joints brought to a limit held. Kept when every joint ends
 * inside and the pose holds to PK_ACCEPT: returns 1 when th changed. A row only
 * near a family (q2 ~ 1e-9 on the Panda: the smallest singular value ~1e-9, not 0)
 * is pulled back by each polish to within ~1e-7 of where it was: when the polish
 * undoes all but PK_SLIDE_KEPT of PK_SLIDE_STALL steps running, the slide gives up
 * (session 22: it went on for all 96 steps, each with its SVD, and failed). */
static int pk_slide(const double *P, const PkGeo *g, const m3 *RT, v3 pT, double *th)
{
    double trial[6];
    if (pk_isolated(g, th))
        return 0; /* isolated: no family to slide along */
    for (int j = 0; j < 6; j++)
        trial[j] = th[j];
    int stalled = 0;
    for (int it = 0; it < 96; it++) {
        m3 R;
        v3 p;
        double J[6][6], sig[6], V[6][6], lo = -INFINITY, hi = INFINITY, worst = 0.0;
        pk_fk(g, trial, &R, &p, J);
        if (it == 0 && pk_regular(J))
            return 0; /* isolated: no family to slide along */
        pk_svd6(J, sig, V);
        if (!(sig[0] <= PK_FAMILY_SIGMA * sig[5]))
            return 0; /* no one-parameter family here */
        for (int j = 0; j < 6; j++) {
            int f = g->full[j];
            double sg = P[PK_SIGN + f], d = sg * V[j][0];
            double qw = wrap_pi(sg * (trial[j] - P[PK_OFFSET + f]));
            double l = P[PK_LO + f], h = P[PK_HI + f], best = qw, bd = INFINITY;
            for (int m = -1; m <= 1; m++) { /* the turn of q nearest [l, h] */
                double qm = qw + 2.0 * M_PI * m, dd = qm < l ? l - qm : qm > h ? qm - h : 0.0;
                if (dd < bd) {
                    bd = dd;
                    best = qm;
                }
            }
            worst = fmax(worst, bd);
            if (fabs(d) > 1e-12) {
                double a1 = (l - best) / d, a2 = (h - best) / d;
                lo = fmax(lo, fmin(a1, a2));
                hi = fmin(hi, fmax(a1, a2));
            } else if (bd > 1e-10) {
                return 0; /* outside (beyond the 1e-10 of "inside" below), the family does not move it */
            }
        }
        if (!(worst > 1e-10))
            break; /* inside */
        double alpha = lo <= hi ? fmin(fmax(0.0, lo), hi) : 0.5 * (lo + hi);
        if (!isfinite(alpha))
            return 0;
        double big = 0.0;
        for (int j = 0; j < 6; j++)
            big = fmax(big, fabs(V[j][0]));
        double cap = 0.05 / big;
        if (fabs(alpha) > cap)
            alpha = copysign(cap, alpha);
        else if (fabs(alpha) * big < 1e-15)
            return 0; /* no progress */
        unsigned frozen = 0u;
        double before[6];
        for (int j = 0; j < 6; j++)
            before[j] = trial[j];
        for (int j = 0; j < 6; j++) {
            trial[j] += alpha * V[j][0];
            int f = g->full[j];
            double q = wrap_pi(P[PK_SIGN + f] * (trial[j] - P[PK_OFFSET + f])), lim;
            if (pk_outside(q, P[PK_LO + f], P[PK_HI + f], &lim) == 0.0 &&
                fmin(q - P[PK_LO + f], P[PK_HI + f] - q) < 1e-12 && fabs(V[j][0]) > 1e-6)
                frozen |= 1u << j; /* brought to a limit: held there by the polish */
        }
        double perr = pk_polish_held(g, RT, pT, trial, frozen);
#ifdef PK_DEBUG
        fprintf(stderr, "   slide it %d sig %.2e worst %.3e interval [%.3e, %.3e] alpha %.3e err %.3e\n", it, sig[0], worst, lo, hi, alpha, perr);
#endif
        if (!(perr <= PK_ACCEPT))
            return 0;
        double kept = 0.0; /* how far the step stayed after the polish [rad] */
        for (int j = 0; j < 6; j++)
            kept = fmax(kept, fabs(trial[j] - before[j]));
        stalled = kept < PK_SLIDE_KEPT * fabs(alpha) * big ? stalled + 1 : 0;
        if (stalled >= PK_SLIDE_STALL)
            return 0; /* pulled back every step: not a family */
    }
    double q[PK_MAXJ];
    if (!(pk_coords(P, g, trial, -1, 0.0, q) >= -1e-9))
        return 0;
    for (int j = 0; j < 6; j++)
        th[j] = wrap_pi(trial[j]);
    return 1;
}

/* ------------------------------------------------- walk along a family */

/* How far each joint of chain angles th (remaining chain) lies outside its limits
 * (o[j], at the turn nearest them; negative: the margin inside) and the largest:
 * a continuous function of th on the circle, so linear between nearby rows. */
static double pk_excess(const double *P, const PkGeo *g, const double *th, double *o)
{
    double worst = -INFINITY;
    for (int j = 0; j < 6; j++) {
        int f = g->full[j];
        double q = wrap_pi(P[PK_SIGN + f] * (th[j] - P[PK_OFFSET + f]));
        double lo = P[PK_LO + f], hi = P[PK_HI + f], best = INFINITY;
        for (int m = -1; m <= 1; m++) {
            double qm = q + 2.0 * M_PI * m;
            double d = qm < lo ? lo - qm : qm > hi ? qm - hi : -fmin(qm - lo, hi - qm);
            best = fmin(best, d);
        }
        o[j] = best;
        worst = fmax(worst, best);
    }
    return worst;
}

/* The t in [0, 1] where max_j (a_j + t (b_j - a_j)) is least (a convex piecewise
 * linear function: its least value lies at an end or where two lines cross); the
 * value into *val. */
static double pk_minmax(const double *a, const double *b, double *val)
{
    double cand[2 + 15], best_t = 0.0, best = INFINITY;
    int nc = 0;
    cand[nc++] = 0.0;
    cand[nc++] = 1.0;
    for (int i = 0; i < 6; i++)
        for (int k = i + 1; k < 6; k++) {
            double den = (b[i] - a[i]) - (b[k] - a[k]);
            if (den != 0.0) {
                double t = (a[k] - a[i]) / den;
                if (t > 0.0 && t < 1.0)
                    cand[nc++] = t;
            }
        }
    for (int c = 0; c < nc; c++) {
        double t = cand[c], m = -INFINITY;
        for (int j = 0; j < 6; j++)
            m = fmax(m, a[j] + t * (b[j] - a[j]));
        if (m < best) {
            best = m;
            best_t = t;
        }
    }
    *val = best;
    return best_t;
}

/* The unit null vector of the remaining Jacobian at th into v (oriented along
 * `prev` when given, else by `sign` on its largest entry), if th lies on a
 * one-parameter family (smallest singular value at most PK_FAMILY_SIGMA of the
 * largest); returns 0 when it does not. */
static int pk_family_dir(const PkGeo *g, const double *th, const double *prev, double sign,
                         double *v)
{
    m3 R;
    v3 p;
    double J[6][6], sig[6], V[6][6];
    pk_fk(g, th, &R, &p, J);
    pk_svd6(J, sig, V);
    if (!(sig[0] <= PK_FAMILY_SIGMA * sig[5]))
        return 0;
    double d = 0.0, big = 0.0;
    for (int j = 0; j < 6; j++) {
        v[j] = V[j][0];
        if (prev != NULL)
            d += v[j] * prev[j];
        else if (fabs(v[j]) > fabs(big))
            big = v[j];
    }
    double s = prev != NULL ? (d < 0.0 ? -1.0 : 1.0) : (big * sign < 0.0 ? -1.0 : 1.0);
    for (int j = 0; j < 6; j++)
        v[j] *= s;
    return 1;
}

/* The last resort for a row th (remaining chain, exact) outside the limits on a
 * one-parameter family of exact solutions, when no row of the pose came inside:
 * next to several singular joints at once (the SRS arm stretched with the shoulder
 * and its held joint 2 at 1e-9; the Panda with q2, q3 at 1e-9 and q5 at 1e-6) the
 * joints outside move along the family at only ~1e-9 rad per radian, so the
 * in-limit members can lie radians away, past stretches where other joints are
 * outside (pk_inside's clamp and pk_slide's first-order step stall there). Walk
 * the family (predictor: PK_WALK_STEP along the Jacobian's null vector; corrector:
 * pk_polish) in both directions, up to PK_WALK_LEN each, and stop at the first
 * row with every joint inside its limits; between two rows, where the linear
 * interpolation of the joints' excess (pk_excess) says a window narrower than a
 * step lies, that point is tried too. Failing that, the row with the smallest
 * excess when it is within the 1e-9 slack. A walk ends early where the family
 * does (the row is isolated), loses the pose, or leaves a joint outside by more
 * than PK_WALK_STUCK times the most the rest of the walk could move it at its
 * present rate (a wrist flipped to q7 = pi: outside by 0.09 rad, moved 1e-9 per
 * radian). Rows more than PK_WALK_REACH outside are not walked (a q1 0.165 rad
 * past its limit on an SRS arm's coaxial family came inside; the bound keeps the
 * cost down where no row can come inside). Kept when the pose holds to PK_ACCEPT:
 * returns 1 when th changed. */
#define PK_WALK_STEP 0.05
#define PK_WALK_LEN (2.0 * M_PI)
#define PK_WALK_STUCK 1e3 /* outside by more than this times the most the family moves it: hopeless */
#define PK_WALK_REACH 0.2  /* rows outside by more than this [rad] are not walked */
static int pk_walk(const double *P, const PkGeo *g, const m3 *RT, v3 pT, double *th)
{
    double v0[6], o0[6];
    if (!(pk_excess(P, g, th, o0) <= PK_WALK_REACH))
        return 0; /* farther out: the walk's cost where no row can come inside */
    if (pk_isolated(g, th))
        return 0;
    m3 R;
    v3 p;
    double J[6][6];
    pk_fk(g, th, &R, &p, J);
    if (pk_regular(J))
        return 0;
    if (!pk_family_dir(g, th, NULL, 1.0, v0))
        return 0; /* no family */
    for (int j = 0; j < 6; j++)
        if (o0[j] > PK_WALK_STUCK * fabs(v0[j]) * PK_WALK_LEN)
            return 0; /* a joint outside that the family hardly moves (both ways) */
#ifdef PK_DEBUG
    fprintf(stderr, "   walk start\n");
#endif
    double best[6], best_x = INFINITY;
    for (int dir = 0; dir < 2; dir++) {
        double cur[6], oa[6], v[6], prev[6];
        for (int j = 0; j < 6; j++) {
            cur[j] = th[j];
            oa[j] = o0[j];
            v[j] = dir ? -v0[j] : v0[j];
        }
        for (int k = 0; k * PK_WALK_STEP < PK_WALK_LEN; k++) {
            if (k && !pk_family_dir(g, cur, prev, 1.0, v))
                break; /* the family ends (an isolated row) */
            int stuck = 0;
            for (int j = 0; j < 6; j++)
                stuck |= oa[j] > PK_WALK_STUCK * fabs(v[j]) * PK_WALK_LEN;
#ifdef PK_DEBUG
            if (stuck || k == 0)
                fprintf(stderr, "   walk dir %d step %d stuck %d o %.2e %.2e %.2e %.2e %.2e %.2e v %.2e %.2e %.2e %.2e %.2e %.2e\n", dir, k, stuck, oa[0], oa[1], oa[2], oa[3], oa[4], oa[5], v[0], v[1], v[2], v[3], v[4], v[5]);
#endif
            if (stuck)
                break; /* a joint outside that the family hardly moves */
            double nxt[6], ob[6];
            for (int j = 0; j < 6; j++)
                nxt[j] = cur[j] + PK_WALK_STEP * v[j];
            if (!(pk_polish(g, RT, pT, nxt) <= PK_ACCEPT))
                break; /* lost the family */
            double xb = pk_excess(P, g, nxt, ob), xm, tm = pk_minmax(oa, ob, &xm);
            if (xb > 0.0 && xm < fmin(0.0, best_x) && tm > 0.0 && tm < 1.0) {
                double mid[6], om[6];
                for (int j = 0; j < 6; j++)
                    mid[j] = cur[j] + tm * PK_WALK_STEP * v[j];
                if (pk_polish(g, RT, pT, mid) <= PK_ACCEPT) {
                    double x = pk_excess(P, g, mid, om);
#ifdef PK_DEBUG
                    fprintf(stderr, "   walk dir %d step %d window t %.3f predicted %.3e got %.3e\n", dir, k, tm, xm, x);
#endif
                    if (x < best_x) {
                        best_x = x;
                        for (int j = 0; j < 6; j++)
                            best[j] = mid[j];
                    }
                    if (x <= 0.0)
                        break;
                }
            }
#ifdef PK_DEBUG
            if (k % 8 == 0)
                fprintf(stderr, "   walk dir %d step %d excess %.3e\n", dir, k, xb);
#endif
            if (xb < best_x) {
                best_x = xb;
                for (int j = 0; j < 6; j++)
                    best[j] = nxt[j];
            }
            if (best_x <= 0.0)
                break;
            for (int j = 0; j < 6; j++) {
                cur[j] = nxt[j];
                oa[j] = ob[j];
                prev[j] = v[j];
            }
        }
        if (best_x <= 0.0)
            break;
    }
    if (!(best_x <= 0.5 * LIMIT_SLACK))
        return 0;
    for (int j = 0; j < 6; j++)
        best[j] = wrap_pi(best[j]);
    return pk_accept(g, RT, pT, best, th);
}

/* Gauss-Newton steps on the pose with the joints in `frozen` held: the least-squares
 * step of least norm over every singular direction down to 1e-15 of the largest
 * (pk_lstsq leaves out those below 1e-10, and pk_polish_held steps of 0.1 rad or
 * more: near several singular joints the pose is reached again only radians away
 * along directions of singular value 1e-10), halved until it reduces the error (at
 * most 14 times), up to 24 steps; returns the final error (pk_error). */
static double pk_gauss_newton(const PkGeo *g, const m3 *RT, v3 pT, double *th, unsigned frozen)
{
    m3 R;
    v3 p;
    double J[6][6], e[6];
    pk_fk(g, th, &R, &p, J);
    double err = pk_error(RT, pT, &R, p, g->scale, e);
    for (int it = 0; it < 24 && err > 1e-16; it++) {
        double A[6][6], sig[6], V[6][6], dx[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
        for (int r = 0; r < 6; r++)
            for (int c = 0; c < 6; c++)
                A[r][c] = (frozen >> c & 1u) ? 0.0 : J[r][c];
        pk_svd6(A, sig, V);
        for (int i = 0; i < 6; i++) {
            if (!(sig[i] > 1e-15 * sig[5]))
                continue;
            double ue = 0.0; /* (J v_i) . e = sigma_i u_i . e */
            for (int r = 0; r < 6; r++) {
                double a = 0.0;
                for (int c = 0; c < 6; c++)
                    a += ((frozen >> c & 1u) ? 0.0 : J[r][c]) * V[c][i];
                ue += a * e[r];
            }
            for (int c = 0; c < 6; c++)
                dx[c] += V[c][i] * ue / (sig[i] * sig[i]);
        }
        double t = 1.0, trial[6], e2[6], err2 = INFINITY;
        for (int half = 0; half < 15; half++, t *= 0.5) {
            for (int c = 0; c < 6; c++)
                trial[c] = th[c] + t * dx[c];
            m3 R2;
            v3 p2;
            pk_fk(g, trial, &R2, &p2, NULL);
            err2 = pk_error(RT, pT, &R2, p2, g->scale, e2);
            if (err2 < err)
                break;
        }
        if (!(err2 < err))
            break;
        for (int c = 0; c < 6; c++)
            th[c] = trial[c];
        pk_fk(g, th, &R, &p, J);
        err = pk_error(RT, pT, &R, p, g->scale, e);
    }
    return err;
}

/* pk_pin's move for joint j of trial outside by more than PK_NUDGE (the row's own
 * flip, or where a round's Gauss-Newton took it): where its axis lies in line with
 * a free joint i's (their remaining Jacobian columns equal up to the sign sigma, to
 * PK_PIN_LINE, so that only th_i + sigma th_j is fixed to first order: the SRS
 * arm's joints 3, 5, 7 with q4 and q6 next to 0), the split of that sum put inside
 * both limits (pk_split, nearest j's present value) instead of clamping j; the
 * next round's Gauss-Newton brings the pose back. Returns 1 when trial changed. */
static int pk_pin_split(const double *P, const PkGeo *g, double *trial, int j,
                        unsigned frozen)
{
    m3 R;
    v3 p;
    double J[6][6];
    pk_fk(g, trial, &R, &p, J);
    for (int i = 0; i < 6; i++) {
        if (i == j || (frozen >> i & 1u))
            continue;
        double dot = J[3][i] * J[3][j] + J[4][i] * J[4][j] + J[5][i] * J[5][j];
        double sigma = dot >= 0.0 ? 1.0 : -1.0, diff = 0.0;
        for (int r = 0; r < 6; r++)
            diff = fmax(diff, fabs(J[r][i] - sigma * J[r][j]));
        if (!(diff < PK_PIN_LINE))
            continue;
        int fi = g->full[i], fj = g->full[j];
        double phi = trial[i] + sigma * trial[j], t2[6], o[6];
        double qj = wrap_pi(P[PK_SIGN + fj] * (trial[j] - P[PK_OFFSET + fj]));
        for (int m = 0; m < 6; m++)
            t2[m] = trial[m];
        t2[j] = pk_split(P, fi, fj, phi, sigma, qj);
        t2[i] = wrap_pi(phi - sigma * t2[j]);
        pk_excess(P, g, t2, o);
        if (o[i] > 0.0 || o[j] > 0.0)
            continue; /* no split of this pair inside both limits */
        for (int m = 0; m < 6; m++)
            trial[m] = t2[m];
        return 1;
    }
    return 0;
}

/* The other last resort (after pk_walk): a row th just outside the limits whose
 * joints outside the family does not move, or that lies on no exact family but on
 * a thin set of near-solutions (singular values of 1e-10 to 1e-8): clamp the joints
 * outside to the limit they passed, hold them, and Gauss-Newton the others back to
 * the pose (pk_gauss_newton: it may move them radians); up to three rounds, as a
 * joint may leave its limits on the way. A joint outside by more than PK_NUDGE
 * (a whole flip, q + pi, or where a round's Gauss-Newton took it) is moved by its
 * split with a joint in line (pk_pin_split) when it has one; otherwise the row is
 * not tried (round 0) or the joint clamped (later rounds). A round ending between
 * PK_ACCEPT and PK_SLOW gets pk_polish_slow's steps (the clamped joints held).
 * Kept when every joint ends inside and the pose holds to PK_ACCEPT: returns 1
 * when th changed. */
static int pk_pin(const double *P, const PkGeo *g, const m3 *RT, v3 pT, double *th)
{
    double trial[6], o[6];
    unsigned frozen = 0u;
    for (int j = 0; j < 6; j++)
        trial[j] = th[j];
    for (int round = 0; round < 3; round++) {
        int moved = 0;
        pk_excess(P, g, trial, o);
        for (int j = 0; j < 6; j++) {
            if (!(o[j] > 0.0) || (frozen >> j & 1u))
                continue;
            if (o[j] > PK_NUDGE && pk_pin_split(P, g, trial, j, frozen)) {
                moved = 1;
                continue;
            }
            if (round == 0 && o[j] > PK_NUDGE)
                return 0; /* the row itself: only joints a thin set's width out are clamped */
            int f = g->full[j];
            double sg = P[PK_SIGN + f], off = P[PK_OFFSET + f], lim;
            pk_outside(wrap_pi(sg * (trial[j] - off)), P[PK_LO + f], P[PK_HI + f], &lim);
            trial[j] = sg * lim + off;
            frozen |= 1u << j;
            moved = 1;
        }
        if (!moved)
            break;
        double err = pk_gauss_newton(g, RT, pT, trial, frozen);
        if (err > PK_ACCEPT && err <= PK_SLOW)
            err = pk_newton(g, RT, pT, trial, frozen, PK_SLOW_ITERS, 1);
#ifdef PK_DEBUG
        fprintf(stderr, "   pin round %d frozen %x err %.3e excess %.3e\n", round, frozen, err, pk_excess(P, g, trial, o));
#endif
        if (!(err <= PK_ACCEPT))
            return 0;
    }
    if (!(pk_excess(P, g, trial, o) <= 0.5 * LIMIT_SLACK))
        return 0;
    for (int j = 0; j < 6; j++)
        trial[j] = wrap_pi(trial[j]);
    return pk_accept(g, RT, pT, trial, th);
}

/* The last resorts (pk_walk, then pk_pin) for every valid row flagged singular and
 * outside the limits of a pose none of whose rows came inside: th from the row's
 * coordinates; o has `slots` rows (8 from this kernel, 16 from the general 6R
 * solver through pieper_limit_rows). */
static void pk_walk_rows(const double *P, const PkGeo *g, const m3 *RT, v3 pT, int held,
                         double x, PkOut o, int slots)
{
    for (int slot = 0; slot < slots; slot++)
        if (o.valid[slot] && o.inside[slot])
            return;
    if (!pk_held_inside(P, held, x))
        return; /* no row can come inside */
    for (int slot = 0; slot < slots; slot++) {
        if (!o.valid[slot] || !o.sing[slot])
            continue;
        double th[6], *qs = o.Q + o.n * slot;
        for (int j = 0; j < 6; j++) {
            int f = g->full[j];
            th[j] = P[PK_SIGN + f] * qs[f] + P[PK_OFFSET + f];
        }
        if (pk_walk(P, g, RT, pT, th) || pk_pin(P, g, RT, pT, th))
            o.inside[slot] = pk_coords(P, g, th, held, x, qs) >= -1e-9;
    }
}

#include "pieper_srs.c"

/* The position equations of pose (RT, pT) for geometry g (not PK_BOTH), G (pk_one's G)
 * the rotation of e1 ... e6: the wrist point p and direction d of the held split,
 * then pk_equations on the position joints (the first three, or the last three
 * when the chain starts with its wrist). One copy for pk_one and the compiled
 * manifold's existence margins (held_manifold.c). */
static void pk_pose_points(const PkGeo *g, const m3 *RT, v3 pT, const m3 *G, v3 *p, v3 *d)
{
    if (g->kase == PK_START) {
        *p = v3_add(m3_mv(&g->RM, m3_mtv(RT, v3_sub(g->pt, pT))), g->tM);
        *d = g->pt;
    } else {
        *p = g->pt;
        *d = v3_add(m3_mv(G, v3_sub(g->pt, g->tM)), pT);
    }
}

static void pk_pose_equations(const PkGeo *g, const m3 *RT, v3 pT, const m3 *G, PkEq *e)
{
    v3 p, d;
    pk_pose_points(g, RT, pT, G, &p, &d);
    pk_equations(g, g->kase == PK_START ? 3 : 0, p, d, e);
}

/* pk_one's closed form up to the triple, shared with held_manifold.c's
 * one-slot evaluation: the remaining chain at held value x, the pose's position
 * equations and their roots (pos), the triple's axes. */
typedef struct {
    PkGeo g;
    m3 RT, G; /* the pose's rotation; the rotation of e1 ... e6 */
    v3 pT;
    int start, ia, it, jx, jz; /* the position joints from ia, the triple's from it */
    PkPos pos;
    PkTri tri;
    double exact_p; /* a position root's residual below this needs no pose check */
} PkFront;

enum { PK_FRONT_SWIVEL = -1, PK_FRONT_GENERAL = -2 };

/* pk_front's parts that do not depend on the held value x where the held joint is
 * the chain's last and the triple starts it (the Panda with q7: every remaining
 * axis and point, the triple's point d, hence pk_equations_d's part, theta_a's
 * subproblem 4 coefficients when axes b, c are coplanar, and the triple's
 * constants): computed at a caller's first pk_front_memo call and copied after
 * (the same operations on the same values: the same bits). set = 0 empties it. */
typedef struct {
    int set, cop; /* filled; cop: k holds pk_coplanar_x's part (axes b, c coplanar) */
    PkEq e;
    PkCop k;
    PkTri tri;
} PkFrontMemo;

/* Whether PkFrontMemo's parts are held-value-free at geometry g: the chain starts
 * with its triple and the held joint is the last (pk_front_memo, held_manifold.c's
 * margins) */
static int pk_memo_usable(const double *P, const PkGeo *g)
{
    return g->kase == PK_START && (int)P[PK_HELD] == (int)P[PK_N] - 1;
}

/* Axes i < j of the full chain (i, j != held) are coplanar (mutual moment below
 * PK_COPLANAR) at held value x only incidentally: the held joint lies between them
 * (turning axis j about the held axis, the moment is a cos v + b sin v + c in the
 * joint value v, at most two zeros a turn) and the moment is not zero at x + 1 or
 * x + 2 as well (else it vanishes for every x: coplanar by design, the Panda's axes
 * 5, 6). There the coplanar solver numbers its roots 2 * first root + second root,
 * not as the quartic does at the values either side (increasing angle): the slots
 * would be permuted at x alone (issue 29, helper slots29). */
static int pk_incidental(const double *P, double x, int i, int j)
{
    int k = (int)P[PK_HELD];
    if (k < 0 || !(i < k && k < j))
        return 0;
    v3 hk = v3_at(P, PK_AXES + 3 * k), ok = v3_at(P, PK_POINTS + 3 * k);
    v3 hi = v3_at(P, PK_AXES + 3 * i), oi = v3_at(P, PK_POINTS + 3 * i);
    v3 hj = v3_at(P, PK_AXES + 3 * j), oj = v3_at(P, PK_POINTS + 3 * j);
    for (int s = 1; s <= 2; s++) {
        double v = P[PK_SIGN + k] * (x + s) + P[PK_OFFSET + k], c = cos(v), sn = sin(v);
        v3 h = v3_rot(hk, c, sn, hj), o = v3_add(ok, v3_rot(hk, c, sn, v3_sub(oj, ok)));
        if (fabs(v3_dot(v3_sub(o, oi), v3_cross(hi, h))) > 1e3 * PK_COPLANAR * P[PK_SCALE])
            return 1;
    }
    return 0;
}

/* The coplanar solver's position roots (cop) numbered as the quartic's (gen) at the
 * same held value: repeatedly the closest pair (a root of each, position angles
 * wrapped, within 1e-3 rad) not yet paired gives the cop root the gen root's slot
 * (its index); cop's other roots take the slots left, in their order. */
static void pk_reslot(PkPos *cop, const PkPos *gen)
{
    unsigned used = 0u, taken = 0u, had = 0u;
    int to[4] = {-1, -1, -1, -1};
    for (int round = 0; round < 4; round++) {
        int bi = -1, bj = -1;
        double bd = 1e-3;
        for (int i = 0; i < gen->n; i++) {
            if (had >> i & 1u)
                continue;
            for (int j = 0; j < cop->n; j++) {
                if (taken >> j & 1u)
                    continue;
                double dj = 0.0;
                for (int a = 0; a < 3; a++)
                    dj = fmax(dj, fabs(wrap_pi(cop->t[j][a] - gen->t[i][a])));
                if (dj < bd) {
                    bd = dj;
                    bi = i;
                    bj = j;
                }
            }
        }
        if (bi < 0)
            break;
        to[bj] = gen->slot[bi];
        taken |= 1u << bj;
        had |= 1u << bi;
        used |= 1u << gen->slot[bi];
    }
    for (int j = 0; j < cop->n; j++) {
        if (to[j] >= 0)
            continue;
        int sl = 0;
        while (sl < 3 && (used >> sl & 1u))
            sl++;
        to[j] = sl;
        used |= 1u << sl;
    }
    for (int j = 0; j < cop->n; j++)
        cop->slot[j] = (unsigned char)to[j];
}

/* The front of pose T at held value x (qn: preferred coordinates where a position
 * joint is free). Returns PK_OK with f->pos, a status (no position root), or
 * PK_FRONT_SWIVEL (both triples meet: pk_srs), PK_FRONT_GENERAL (no coplanar
 * pair and `general` 0: Pieper's quartic not taken). memo (or NULL): x-free parts
 * kept between calls of one arm (PkFrontMemo); want: the position slots to solve
 * where the position axes are coplanar (pk_coplanar; 15: all). */
static int pk_front_memo(const double *P, const double *T, double x, const double *qn,
                         int general, PkFrontMemo *memo, unsigned want, PkFront *f)
{
    PkGeo *g = &f->g;
    pk_geometry(P, x, g);
    f->RT = (m3){{T[0], T[1], T[2]}, {T[4], T[5], T[6]}, {T[8], T[9], T[10]}};
    f->pT = (v3){T[3], T[7], T[11]};
    f->G = pk_mul_t(&f->RT, &g->RM);
    f->pos.n = 0;
    if (g->kase == PK_BOTH)
        return PK_FRONT_SWIVEL;
    f->start = g->kase == PK_START;
    f->ia = f->start ? 3 : 0;
    f->it = f->start ? 0 : 3;
    if (memo != NULL && !pk_memo_usable(P, g))
        memo = NULL; /* the remaining chain moves with x */
    PkEq e;
    v3 p, d;
    pk_pose_points(g, &f->RT, f->pT, &f->G, &p, &d);
    if (memo != NULL && memo->set)
        e = memo->e;
    else
        pk_equations_d(g, f->ia, d, &e);
    pk_equations_p(&e, p);
    int ia = f->ia, code;
    /* preferred chain angles of the position joints (when one is free) */
    double pref_a = P[PK_SIGN + g->full[ia]] * qn[g->full[ia]] + P[PK_OFFSET + g->full[ia]];
    double pref_c = P[PK_SIGN + g->full[ia + 2]] * qn[g->full[ia + 2]] +
                    P[PK_OFFSET + g->full[ia + 2]];
    if (memo != NULL && !memo->set) {
        memo->e = e;
        memo->cop = fabs(e.mbc) <= PK_COPLANAR;
        if (memo->cop)
            pk_coplanar_x(&e, 0, &memo->k);
        pk_tri_init(&memo->tri, g->h[f->it], g->h[f->it + 1], g->h[f->it + 2]);
        memo->set = 1;
    }
    int cbc = fabs(e.mbc) <= PK_COPLANAR, cab = fabs(e.mab) <= PK_COPLANAR;
    /* coplanar only at this held value (the rtb-data iiwa14 at joint_a3 = 0,
     * pk_incidental): the coplanar solver's roots (exact there; the quartic's can be
     * off next to a double root, or missing), each in the slot the quartic gives it,
     * as at the values either side (pk_reslot) */
    if (general && cbc != cab && pk_incidental(P, x, g->full[ia + cbc], g->full[ia + cbc + 1])) {
        code = pk_coplanar(&e, cab, NULL, pref_a, pref_c, want, &f->pos);
        if (code == PK_OK) {
            PkPos gen;
            gen.n = 0;
            pk_general(&e, &gen);
            pk_reslot(&f->pos, &gen);
        }
    } else if (cbc)
        code = pk_coplanar(&e, 0, memo != NULL ? &memo->k : NULL, pref_a, pref_c, want,
                           &f->pos);
    else if (cab)
        code = pk_coplanar(&e, 1, NULL, pref_a, pref_c, want, &f->pos);
    else if (general)
        code = pk_general(&e, &f->pos);
    else
        return PK_FRONT_GENERAL;
#ifdef PK_DEBUG
    fprintf(stderr, "code %d mab %.3e mbc %.3e npos %d\n", code, e.mab, e.mbc, f->pos.n);
    for (int i = 0; i < f->pos.n; i++)
        fprintf(stderr, "  pos %d: %.12f %.12f %.12f res %.3e sing %d\n", f->pos.slot[i],
                f->pos.t[i][0], f->pos.t[i][1], f->pos.t[i][2], f->pos.res[i], f->pos.sing[i]);
#endif
    f->jx = g->full[f->it];
    f->jz = g->full[f->it + 2];
    if (memo != NULL)
        f->tri = memo->tri;
    else
        pk_tri_init(&f->tri, g->h[f->it], g->h[f->it + 1], g->h[f->it + 2]);
    f->exact_p = PK_EXACT * fmax(1.0, g->scale);
    return code;
}

static int pk_front(const double *P, const double *T, double x, const double *qn, int general,
                    PkFront *f)
{
    return pk_front_memo(P, T, x, qn, general, NULL, 15u, f);
}

/* Position root i of the front: its angles into th (the position joints') and the
 * rotation the triple must make. */
static m3 pk_front_rotation(const PkFront *f, int i, double *th)
{
    const PkGeo *g = &f->g;
    m3 Rp = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
    for (int j = 0; j < 3; j++) {
        th[f->ia + j] = f->pos.t[i][j];
        m3 Rj = pk_rotm(g->h[f->ia + j], f->pos.c[i][j], f->pos.s[i][j]);
        Rp = pk_mul(&Rp, &Rj);
    }
    if (f->start)
        return pk_mul_t(&f->G, &Rp); /* R_A = G R_B^T */
    m3 Rpt = {{Rp.r0.x, Rp.r1.x, Rp.r2.x},
              {Rp.r0.y, Rp.r1.y, Rp.r2.y},
              {Rp.r0.z, Rp.r1.z, Rp.r2.z}};
    return pk_mul(&Rpt, &f->G); /* R_B = R_A^T G */
}

/* Every solution of pose T (4 x 4 row-major) with the held joint (if any) at x;
 * qn: the preferred coordinates (n) at singularities. Returns the status. */
static int pk_one(const double *P, const double *T, double x, const double *qn, PkOut o)
{
    PkFront f;
    pk_clear(o);
    int code = pk_front(P, T, x, qn, 1, &f);
    const PkGeo *g = &f.g;
    const m3 *RT = &f.RT;
    v3 pT = f.pT;
    if (code == PK_FRONT_SWIVEL)
        return pk_srs(P, g, RT, pT, x, qn, o);
    if (code != PK_OK)
        return code;
    int held = (int)P[PK_HELD];
    double stol = P[PK_SING_TOL];
    int any = 0;
    unsigned lmask = 0u; /* rows outside, not flagged singular: slid only when none is inside */
    int held_in = pk_held_inside(P, held, x); /* else no row can come inside */
    double late[8][6];
    int ia = f.ia, it = f.it, jx = f.jx, jz = f.jz;
    const PkPos *pos = &f.pos;
    for (int i = 0; i < pos->n; i++) {
        if (!(pos->res[i] < 1e-6 * g->scale))
            continue;
        double th[6];
        m3 Rt = pk_front_rotation(&f, i, th);
        PkTrip tr;
        pk_triple(P, &f.tri, &Rt, jx, jz, qn[jz], stol, &tr);
#ifdef PK_DEBUG
        fprintf(stderr, "  triple n %d\n", tr.n);
#endif
        for (int k = 0; k < tr.n; k++) {
            /* this solution's angles (the polish and the repairs change all six) */
            for (int j = 0; j < 3; j++) {
                th[ia + j] = pos->t[i][j];
                th[it + j] = tr.t[k][j];
            }
            if (tr.check[k] || !(pos->res[i] < f.exact_p)) {
                /* check against the pose; Newton-polish when not exact */
                double err = pk_error_of(g, RT, pT, th);
                if (err > PK_EXACT)
                    err = pk_polish_slow(g, RT, pT, th, pk_polish(g, RT, pT, th));
#ifdef PK_DEBUG
                fprintf(stderr, "    check slot %d err %.3e th %.17g %.17g %.17g\n", 2 * pos->slot[i] + k, err, th[0], th[1], th[2]);
#endif
                if (!(err <= PK_ACCEPT))
                    continue; /* not a solution to 1e-12: never returned */
            }
            int slot = 2 * pos->slot[i] + k;
            double *qs = o.Q + o.n * slot;
            int all = pk_coords(P, g, th, held, x, qs) >= -1e-9;
            int sing = pos->sing[i] || tr.sing[k], fix = !all && held_in;
            if (fix && pk_resplit(P, g, it, RT, pT, th))
                all = pk_coords(P, g, th, held, x, qs) >= -1e-9;
            /* joints on one line only at a singular configuration: try there only */
            if (fix && !all && sing && pk_repair(P, g, RT, pT, th))
                all = pk_coords(P, g, th, held, x, qs) >= -1e-9;
            if (fix && !all && pk_inside(P, g, RT, pT, th, sing ? PK_NUDGE_SING : PK_NUDGE))
                all = pk_coords(P, g, th, held, x, qs) >= -1e-9;
            /* a family to slide along: at rows the subproblems flag singular here,
             * at the others below only when no row came inside */
            if (fix && !all && sing) {
                if (pk_slide(P, g, RT, pT, th))
                    all = pk_coords(P, g, th, held, x, qs) >= -1e-9;
            } else if (fix && !all) {
                for (int j = 0; j < 6; j++)
                    late[slot][j] = th[j];
                lmask |= 1u << slot;
            }
            o.valid[slot] = 1;
            o.inside[slot] = (unsigned char)all;
            o.sing[slot] = (unsigned char)sing;
            any = 1;
        }
    }
    int inside = 0;
    for (int slot = 0; slot < 8; slot++)
        inside |= o.valid[slot] && o.inside[slot];
    for (int slot = 0; slot < 8 && !inside; slot++)
        if ((lmask >> slot & 1u) && pk_slide(P, g, RT, pT, late[slot]))
            o.inside[slot] = pk_coords(P, g, late[slot], held, x, o.Q + o.n * slot) >= -1e-9;
    if (any)
        pk_walk_rows(P, g, RT, pT, held, x, o, 8);
    return any ? PK_OK : PK_NO_ORIENTATION;
}

/* --------------------------------------------------------------- entries */

#define PK_F64(a) ((double *)PyArray_DATA((PyArrayObject *)(a)))
#define PK_U8(a) ((unsigned char *)PyArray_DATA((PyArrayObject *)(a)))
#define PK_DIM(a, d) (PyArray_DIMS((PyArrayObject *)(a))[d])

/* A batch: poses T (N x 16), held values x (m, row i % m), preferred
 * coordinates qn (mq x n, row i % mq), outputs per pose. */
typedef struct {
    const double *P, *T, *x, *qn;
    long mx, mq;
    int n;
    double *Q;
    unsigned char *valid, *sing, *inside;
    signed char *status;
} PkJob;

/* Poses [b, e) of a batch (a pool task). */
static void pk_range(void *ctx, long b, long e)
{
    const PkJob *jb = ctx;
    int n = jb->n;
    for (long i = b; i < e; i++) {
        PkOut o = {jb->Q + 8 * n * i, jb->valid + 8 * i, jb->sing + 8 * i,
                   jb->inside + 8 * i, n};
        jb->status[i] = (signed char)pk_one(jb->P, jb->T + 16 * i, jb->x[i % jb->mx],
                                            jb->qn + n * (i % jb->mq), o);
    }
}

/* whether params (PK_N_PARAMS values) is a Pieper parameter vector (pieper.pack) */
static int pk_params_ok(const double *P)
{
    return P[PK_TAG] == PK_TAG_VALUE && (P[PK_N] == 6.0 || P[PK_N] == 7.0) &&
           P[PK_HELD] >= -1.0 && P[PK_HELD] < P[PK_N] &&
           (P[PK_N] == 7.0) == (P[PK_HELD] >= 0.0);
}

/* the joints of a parameter vector (for the generated shape check of qn) */
#define PK_N_OF(P) ((P)[PK_N])

#include "ik_outputs.h"

/* pieper_ik1(T, params, x, qn) -> (code, Q (8, n), valid (8,), singular (8,),
 * within_limits (8,)): one pose with the held joint at x (ignored without one),
 * validated in the same call (pose_problem's tests); qn None or a float64 (n,)
 * array of preferred coordinates at singularities. code >= BAD_POSE: nothing was
 * solved and the arrays are None. The fast path for one pose: METH_FASTCALL, no
 * pool, T read through its strides. */
static PyObject *pieper_ik1_body(const pieper_ik1_args *a)
{
    const double *P = a->params;
    double x = a->x;
    int n = (int)P[PK_N];
    double qn[PK_MAXJ] = {0.0};
    if (a->qn != Py_None) {
        PyArrayObject *qa = array_arg(a->qn, "pieper_ik1", "qn", NPY_DOUBLE, 1, 0);
        if (qa == NULL)
            return NULL;
        if (PK_DIM(qa, 0) != n) {
            PyErr_SetString(PyExc_ValueError, "robokin._native.pieper_ik1: qn must be (n,)");
            return NULL;
        }
        for (int j = 0; j < n; j++)
            qn[j] = PK_F64(qa)[j];
    }
    double T[16];
    int code = ik_read_pose(a->T, T, PK_BAD_POSE);
    if (code == 0 && !isfinite(x))
        code = PK_BAD_POSE;
    if (code)
        return Py_BuildValue("(iOOOO)", code, Py_None, Py_None, Py_None, Py_None);
    PyObject *out[4];
    if (!ik_outputs(0, 0, n, out))
        return NULL;
    PkOut o = {PK_F64(out[0]), PK_U8(out[1]), PK_U8(out[2]), PK_U8(out[3]), n};
    code = pk_one(P, T, x, qn, o);
    return ik_result(code, out);
}

/* pieper_ik(params, T (N, 4, 4), x (m,), qn (mq, n)) -> (Q (N, 8, n), valid,
 * singular, within_limits (N, 8), status (N,) int8): a batch, not validated (the
 * caller checked poses and values); pose i's held value is x[i % m] and its
 * preferred coordinates qn[i % mq] (a sweep of held values is one batch).
 * Batches of PARALLEL_MIN poses or more run on the pool. */
static PyObject *pieper_ik_body(const pieper_ik_args *a)
{
    const double *P = a->params;
    int n = (int)P[PK_N];
    npy_intp N = a->N;
    PyObject *out[4], *status;
    if (!ik_outputs(1, N, n, out) || !ik_status(N, out, &status))
        return NULL;
    PkJob jb = {P, a->T, a->x, a->qn, (long)a->m, (long)a->mq, n, PK_F64(out[0]), PK_U8(out[1]), PK_U8(out[2]),
                PK_U8(out[3]), (signed char *)PyArray_DATA((PyArrayObject *)status)};
    return ik_run_batch(N, PK_PARALLEL_MIN, PK_GRAIN, pk_range, &jb, out, status);
}

/* pieper_limit_rows(params, T (N, 4, 4), x (N,), Q (N, k, n), valid, singular,
 * inside (N, k)): the last resorts of pk_walk_rows (pk_walk, then pk_pin) on rows
 * another solver returned for a 7R chain with joint PK_HELD held at x[i] (the
 * general 6R path: the Panda with joint 1, 2 or 3 held; params from
 * pieper.limit_params, no triple needed). A pose none of whose valid rows is
 * inside: each valid row flagged singular is moved along its family, or pinned at
 * the limit it passed, into the limits, exactly (PK_ACCEPT); Q and inside are
 * updated in place. Other poses and rows are left as they are. */
static PyObject *pieper_limit_rows_body(const pieper_limit_rows_args *a)
{
    const double *P = a->params;
    int n = (int)P[PK_N], held = (int)P[PK_HELD];
    long k = (long)a->k;
    for (npy_intp i = 0; i < a->N; i++) {
        const double *T = a->T + 16 * i;
        double x = a->x[i];
        PkOut o = {a->Q + k * n * i, (unsigned char *)a->valid + k * i,
                   (unsigned char *)a->singular + k * i, (unsigned char *)a->inside + k * i, n};
        PkGeo g;
        pk_geometry(P, x, &g);
        m3 RT = {{T[0], T[1], T[2]}, {T[4], T[5], T[6]}, {T[8], T[9], T[10]}};
        v3 pT = {T[3], T[7], T[11]};
        pk_walk_rows(P, &g, &RT, pT, held, x, o, (int)k);
    }
    Py_RETURN_NONE;
}

/* pieper_roots(coeffs (5,), re (4,), im (4,)): the quartic solver (for tests) */
static PyObject *pieper_roots_body(const pieper_roots_args *a)
{
    pk_quartic(a->coeffs, a->re, a->im);
    Py_RETURN_NONE;
}


#if defined(__clang__)
#pragma STDC FP_CONTRACT DEFAULT
#elif defined(__GNUC__)
#pragma GCC pop_options
#endif
