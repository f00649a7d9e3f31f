/*
 * Closed-form IK of the two 6R families, every solution of a pose:
 *
 *   three parallel: axes 2, 3, 4 parallel, axes 5, 6 meeting (UR, AUBO, Doosan);
 *   spherical wrist: axes 2, 3 parallel, axes 4, 5, 6 meeting (Puma, KUKA, ABB).
 *
 * Paden-Kahan subproblems on the chain's product-of-exponentials geometry (the
 * algorithm is described for users in robokin/kinematics/ik/analytic/
 * three_parallel.py and spherical_wrist.py). Plain scalar C, one pose at a time.
 *
 * References:
 *   Paden, "Kinematics and control of robot manipulators", PhD thesis, 1985
 *   (subproblems 1, 3, 4);
 *   Elias and Wen, "IK-Geo", arXiv:2211.05737 (2022), section III and the cases
 *   'three parallel, two intersecting' and 'spherical wrist, two parallel'.
 *
 * Both families read one flat parameter vector that _six_r.pack writes (Python
 * reads these indices from the module constants six_r_constants adds, named
 * without the SR_):
 *
 *   SR_AXES      unit joint axes h1..h6 (base frame, zero chain values), 6 x 3
 *   SR_POINTS    points o1, o2, o3, o4 on axes 1-4, 4 x 3
 *   SR_WRIST     ow: where axes 5, 6 (three parallel) or 4, 5, 6 (spherical) meet
 *   SR_TOOL_T    tool origin t at zero chain values
 *   SR_TOOL_R    rows of the tool rotation R_M at zero chain values, 3 x 3
 *   SR_PERP      unit vector e perpendicular to h2 (three parallel) or h4 (spherical)
 *   SR_SIGN, SR_OFFSET, SR_LO, SR_HI   per joint (6 each): v = sign q + offset,
 *                joint limits
 *   SR_S3, SR_S4 h3 = s3 h2, h4 = s4 h2 (+-1; three parallel uses both)
 *   SR_SING_TOL  wrist singularity: |R06^T R1 h2 (or h4) off axis 6| below it
 *   SR_DISC_TOL  subproblem 4 discriminant tolerance (relative to A^2 + B^2)
 *   SR_MIRROR    1.0: seeds mirrored past a boundary (near-family arms), else 0.0
 *   SR_A3..SR_SPHI3  theta3 subproblem 4: A, B, C, atan2(B, A), its cosine, sine
 *   SR_A5..SR_SPHI5  theta5 subproblem 4: the same
 *   SR_AA, SR_BB |a|^2, |b|^2 of the two-link (elbow) problem
 *   SR_FAMILY    SR_THREE_PARALLEL or SR_SPHERICAL_WRIST
 *
 * Each pose yields 8 slots, slot = 4 shoulder + 2 elbow + wrist, 0 = the '+' and
 * 1 = the '-' root of the subproblem; a slot that has no solution is zero, invalid,
 * not singular and not within limits. Status: 0 ok, 1 out of reach, 2 orientation
 * not achievable; SR_BAD_POSE + pose_problem's code (chain.h) when the one-pose
 * entry found T not a rigid transform (nothing solved).
 *
 * Entries (the Python layer validates what users pass; bad arguments here are
 * internal errors and raise ValueError):
 *   six_r_ik1(T, params, q6): one pose, validated, no pool; METH_FASTCALL.
 *   six_r_ik(params, T, qn): a batch; the pool runs batches of SR_PARALLEL_MIN
 *   poses or more, the GIL released. Each pose is solved by the same code whatever
 *   thread takes it, so results do not depend on the number of threads.
 *   atan2(y, x, out): fast_atan2 on arrays (for tests).
 */
#include "chain.h"
#include "pool.h"

/* No fused multiply-adds in this file, in the AVX2 copy either: the closed forms
 * take branches on rounding-level quantities (a discriminant at a boundary, the
 * wrist-singularity test), and one rounding of every product keeps the two copies'
 * slots, flags and values identical (and equal to the numba kernels they replaced).
 * No auto-vectorisation either: on this scalar code GCC's SLP vectoriser made the
 * kernel about 8 % slower (GCC 12, AMD EPYC). */
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#elif defined(__GNUC__)
#pragma GCC push_options
#pragma GCC optimize("fp-contract=off", "no-tree-vectorize")
#endif

enum {
    SR_AXES = 0, SR_POINTS = 18, SR_WRIST = 30, SR_TOOL_T = 36, SR_TOOL_R = 39,
    SR_PERP = 48, SR_SIGN = 51, SR_OFFSET = 57, SR_LO = 63, SR_HI = 69, SR_S3 = 75,
    SR_S4 = 76, SR_SING_TOL = 77, SR_DISC_TOL = 78, SR_MIRROR = 79,
    SR_A3 = 80, SR_B3 = 81, SR_C3 = 82, SR_PHI3 = 83, SR_CPHI3 = 84, SR_SPHI3 = 85,
    SR_A5 = 86, SR_B5 = 87, SR_C5 = 88, SR_PHI5 = 89, SR_CPHI5 = 90, SR_SPHI5 = 91,
    SR_AA = 92, SR_BB = 93, SR_FAMILY = 94, SR_N_PARAMS = 95
};
enum { SR_THREE_PARALLEL = 0, SR_SPHERICAL_WRIST = 1 };
enum { SR_OK = 0, SR_OUT_OF_REACH = 1, SR_NO_ORIENTATION = 2, SR_BAD_POSE = 16 };
#define SR_PARALLEL_MIN 512 /* below this many poses, one thread */
#define SR_GRAIN 32         /* poses per pool chunk */

/* ------------------------------------------------------------------- vectors */

typedef struct { double x, y, z; } v3;
typedef struct { v3 r0, r1, r2; } m3; /* a rotation by its rows */

/* the 3-vector at P[i], P[i + 1], P[i + 2] */
static inline v3 v3_at(const double *P, int i) { return (v3){P[i], P[i + 1], P[i + 2]}; }

/* a . b */
static inline double v3_dot(v3 a, v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

/* a x b */
static inline v3 v3_cross(v3 a, v3 b)
{
    return (v3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

/* a + b, a - b, s a */
static inline v3 v3_add(v3 a, v3 b) { return (v3){a.x + b.x, a.y + b.y, a.z + b.z}; }
static inline v3 v3_sub(v3 a, v3 b) { return (v3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static inline v3 v3_scale(v3 a, double s) { return (v3){a.x * s, a.y * s, a.z * s}; }

/* rot(k, t) v for unit k given c = cos t, s = sin t, by Rodrigues' formula:
 * v cos t + (k x v) sin t + k (k . v)(1 - cos t) */
static inline v3 v3_rot(v3 k, double c, double s, v3 v)
{
    double kv = v3_dot(k, v) * (1.0 - c);
    v3 x = v3_cross(k, v);
    return (v3){v.x * c + x.x * s + k.x * kv, v.y * c + x.y * s + k.y * kv,
                v.z * c + x.z * s + k.z * kv};
}

/* R v */
static inline v3 m3_mv(const m3 *R, v3 v)
{
    return (v3){v3_dot(R->r0, v), v3_dot(R->r1, v), v3_dot(R->r2, v)};
}

/* R^T v */
static inline v3 m3_mtv(const m3 *R, v3 v)
{
    return (v3){R->r0.x * v.x + R->r1.x * v.y + R->r2.x * v.z,
                R->r0.y * v.x + R->r1.y * v.y + R->r2.y * v.z,
                R->r0.z * v.x + R->r1.z * v.y + R->r2.z * v.z};
}

/* ----------------------------------------------------------------- angles */

#define SR_TAN_PI_8 0.41421356237309503

/* atan(u) for |u| <= tan(pi/8): u + u^3 p(u^2), p a degree-10 least-squares fit on
 * Chebyshev nodes to (atan(u) - u) / u^3 (relative error < 3e-16), by Estrin's
 * scheme (short dependency chains). */
static inline double atan_core(double u)
{
    double s = u * u, s2 = s * s, s4 = s2 * s2;
    double q0 = -0.33333333333333326 + 0.19999999999994086 * s;
    double q1 = -0.14285714284481754 + 0.11111111005585772 * s;
    double q2 = -0.0909090431754569 + 0.07692179168372903 * s;
    double q3 = -0.06664474627546399 + 0.05857954331450998 * s;
    double q4 = -0.05084928654128961 + 0.03922789786600753 * s - 0.019183482806421463 * s2;
    double p = (q0 + s2 * q1) + s4 * ((q2 + s2 * q3) + s4 * q4);
    return u + u * s * p;
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
    double r = atan_core(u) + (big ? M_PI_4 : 0.0);
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
 * then moved by whole turns into [lo, hi] (1e-9 slack) where it fits (wrap_into,
 * lm.c); *inside says whether it lies there. */
static inline double joint_value(double v, double sign, double offset, double lo,
                                 double hi, int *inside)
{
    double q = wrap_pi(sign * (v - offset));
    double lo_e = lo - 1e-9, hi_e = hi + 1e-9;
    if (q < lo_e || q > hi_e) /* rare: spares the common case wrap_into's division */
        q = wrap_into(q, lo_e, hi_e);
    *inside = (q >= lo_e) & (q <= hi_e);
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
    if (disc < 0.0) {
        if (disc < -tol * r2) {
            r.n = 0;
            r.boundary = 0;
            r.t[0] = r.t[1] = 0.0;
            r.c[0] = r.c[1] = 1.0;
            r.s[0] = r.s[1] = 0.0;
            return r;
        }
        double base = phi + atan2(0.0, rhs); /* the double root: phi or phi + pi */
        r.boundary = 1;
        if (mirror) {
            double g = atan2(sqrt(-disc), fabs(rhs));
            r.n = 2;
            r.t[0] = base + g;
            r.t[1] = base - g;
            for (int i = 0; i < 2; i++) {
                r.c[i] = cos(r.t[i]);
                r.s[i] = sin(r.t[i]);
            }
            return r;
        }
        r.n = 1;
        r.t[0] = r.t[1] = base;
        r.c[0] = r.c[1] = cos(base);
        r.s[0] = r.s[1] = sin(base);
        return r;
    }
    double sq = sqrt(disc), cg, sg;
    double g = fast_atan2(sq, rhs);
    unit2(sq, rhs, &cg, &sg);
    r.t[0] = phi + g;
    r.c[0] = cphi * cg - sphi * sg;
    r.s[0] = sphi * cg + cphi * sg;
    r.t[1] = phi - g;
    r.c[1] = cphi * cg + sphi * sg;
    r.s[1] = sphi * cg - cphi * sg;
    r.n = disc <= tol * r2 * 1e-3 ? 1 : 2;
    r.boundary = r.n == 1;
    return r;
}

/* A^2 + B^2 - (d - C)^2 of the wrist's subproblem 4 for unit vectors, with
 * |x_perp|^2 = 1 - d^2 exactly. */
static inline double wrist_disc(double A, double B, double C, double d, double xperp2)
{
    return A * A + B * B - C * C - 1.0 + xperp2 + 2.0 * d * C;
}

/* -------------------------------------------------------------- the families */

/* One pose's outputs: Q (8 x 6), valid, singular, within limits (8 each). */
typedef struct {
    double *Q;
    unsigned char *valid, *sing, *inside;
} Slots;

/* All slots empty: NaN (rows that are not solutions), invalid, not singular, not
 * within limits. */
static void slots_clear(Slots o)
{
    for (int k = 0; k < 8; k++) {
        o.valid[k] = o.sing[k] = o.inside[k] = 0;
        for (int j = 0; j < 6; j++)
            o.Q[6 * k + j] = NAN;
    }
}

/* A solution into its slot: chain angles v to joint coordinates, valid, the
 * singular flag and whether every joint is within its limits. */
static void slot_write(const double *P, Slots o, int slot, const double *v, int singular)
{
    int all = 1;
    for (int j = 0; j < 6; j++) {
        int in;
        o.Q[6 * slot + j] =
            joint_value(v[j], P[SR_SIGN + j], P[SR_OFFSET + j], P[SR_LO + j], P[SR_HI + j], &in);
        all &= in;
    }
    o.inside[slot] = (unsigned char)all;
    o.valid[slot] = 1;
    o.sing[slot] = (unsigned char)singular;
}

/* The target: rows of R06 = R_T R_M^T (R_M the tool rotation at zero) and its
 * position p, from T (4 x 4, row-major). */
static void target(const double *T, const double *P, m3 *R, v3 *p)
{
    v3 m0 = v3_at(P, SR_TOOL_R), m1 = v3_at(P, SR_TOOL_R + 3), m2 = v3_at(P, SR_TOOL_R + 6);
    v3 t0 = {T[0], T[1], T[2]}, t1 = {T[4], T[5], T[6]}, t2 = {T[8], T[9], T[10]};
    R->r0 = (v3){v3_dot(t0, m0), v3_dot(t0, m1), v3_dot(t0, m2)};
    R->r1 = (v3){v3_dot(t1, m0), v3_dot(t1, m1), v3_dot(t1, m2)};
    R->r2 = (v3){v3_dot(t2, m0), v3_dot(t2, m1), v3_dot(t2, m2)};
    *p = (v3){T[3], T[7], T[11]};
}

/* The shoulder, theta1 by subproblem 4 (both families): joints 2 on do not change
 * the component along h2 of the point ow, so h2 . R1^T pw = h2 . (ow - o1) with
 * pw = p - R06 (t - ow) - o1 (returned). */
static Roots shoulder(const double *P, const m3 *R, v3 p, v3 *pw)
{
    v3 h1 = v3_at(P, SR_AXES), h2 = v3_at(P, SR_AXES + 3);
    v3 o1 = v3_at(P, SR_POINTS), ow = v3_at(P, SR_WRIST), t = v3_at(P, SR_TOOL_T);
    *pw = v3_sub(v3_sub(p, m3_mv(R, v3_sub(t, ow))), o1);
    double A, B, C;
    sp4_coeffs(*pw, h1, h2, &A, &B, &C);
    double rhs = v3_dot(h2, v3_sub(ow, o1)) - C, cphi, sphi;
    double phi = fast_atan2(B, A);
    unit2(B, A, &cphi, &sphi);
    return sp4_roots(A, B, rhs, A * A + B * B - rhs * rhs, P[SR_DISC_TOL],
                     P[SR_MIRROR] != 0.0, phi, cphi, sphi);
}

/* At the wrist singularity of a three-parallel arm (axes 6 and 2-4 parallel) one
 * combination is free: theta6 turns the tool about axis 6 while theta2 + theta3 +
 * theta4 turns back by as much (th234 = t0 + kappa th6, kappa = +-1). The wrist
 * point then moves with th234 (axis 5 sits off axis 4), so not every theta6 leaves
 * the elbow (subproblem 3) solvable: its right-hand side is M - Rw cos(th234 - psi),
 * solvable where |M - Rw cos(th234 - psi)| <= |(A3, B3)|. */
typedef struct {
    v3 h1, h2, h5, h6, e;
    const m3 *R;
    double c1, s1, c5, s5, pl1, pl2, dh, w41, w42, aa, bb, c3, a3, b3;
} WristFree;

/* th234 for a given theta6 (as three_parallel_one computes it) */
static double wrist_th234(const WristFree *f, double th6)
{
    v3 w = v3_rot(f->h6, cos(th6), -sin(th6), v3_rot(f->h5, f->c5, -f->s5, f->e));
    w = v3_rot(f->h1, f->c1, -f->s1, m3_mv(f->R, w));
    double c, s;
    return sp1(f->h2, f->e, w, &c, &s);
}

/* The theta6 to use at the singularity: `pref` (q_near's, or 0) when the elbow is
 * solvable there, else the solvable value nearest it (a hair inside the boundary),
 * so a reachable pose is never answered 'out of reach'. */
static double singular_theta6(const WristFree *f, double pref)
{
    double t0 = wrist_th234(f, 0.0);
    double kappa = wrap_pi(wrist_th234(f, 0.5 * M_PI) - t0) > 0.0 ? 1.0 : -1.0;
    double k0 = f->pl1 * f->pl1 + f->pl2 * f->pl2 + f->w41 * f->w41 + f->w42 * f->w42;
    double M = 0.5 * (k0 + f->dh * f->dh - f->aa - f->bb) - f->c3;
    double cx = f->pl1 * f->w41 + f->pl2 * f->w42, sx = f->pl2 * f->w41 - f->pl1 * f->w42;
    double Rw = sqrt(cx * cx + sx * sx), S = sqrt(f->a3 * f->a3 + f->b3 * f->b3);
    if (Rw < 1e-12 * (S + fabs(M)) || S == 0.0)
        return pref; /* th234 does not move the wrist point */
    double psi = atan2(sx, cx);
    double cl = (M - S) / Rw, ch = (M + S) / Rw; /* solvable: cos(th234 - psi) in [cl, ch] */
    if (cl > 1.0 || ch < -1.0)
        return pref; /* unreachable for every theta6 */
    double x = wrap_pi(t0 + kappa * pref - psi), cxp = cos(x);
    if (cxp >= cl && cxp <= ch)
        return pref;
    double margin = 1e-9 * (fmin(ch, 1.0) - fmax(cl, -1.0));
    double ends[4];
    int m = 0;
    if (ch < 1.0) {
        double a = acos(ch - margin);
        ends[m++] = a;
        ends[m++] = -a;
    }
    if (cl > -1.0) {
        double a = acos(cl + margin);
        ends[m++] = a;
        ends[m++] = -a;
    }
    double best = x, gap = INFINITY;
    for (int i = 0; i < m; i++) {
        double d = fabs(wrap_pi(ends[i] - x));
        if (d < gap) {
            gap = d;
            best = ends[i];
        }
    }
    return pref + kappa * wrap_pi(best - x); /* th234 moves by as much as kappa th6 */
}

/* Every solution of one pose T (4 x 4, row-major) of a three-parallel arm (axes 2,
 * 3, 4 parallel, axes 5, 6 meeting; IK-Geo 'three parallel, two intersecting'):
 * theta1 (subproblem 4), theta5 (subproblem 4 on h2 . R5 h6 = h2 . R1^T R06 h6),
 * theta6 and theta2 + theta3 + theta4 (subproblem 1), theta3 (subproblem 3 in the
 * plane normal to h2), theta2 (subproblem 1, planar), theta4 from the sum. At the
 * wrist singularity theta6 is q6 (a joint value). Returns the status. */
static int three_parallel_one(const double *T, const double *P, double q6, Slots o)
{
    v3 h1 = v3_at(P, SR_AXES), h2 = v3_at(P, SR_AXES + 3), h5 = v3_at(P, SR_AXES + 12);
    v3 h6 = v3_at(P, SR_AXES + 15);
    v3 o1 = v3_at(P, SR_POINTS), o2 = v3_at(P, SR_POINTS + 3), o3 = v3_at(P, SR_POINTS + 6);
    v3 o4 = v3_at(P, SR_POINTS + 9), ow = v3_at(P, SR_WRIST), e = v3_at(P, SR_PERP);
    double s3 = P[SR_S3], s4 = P[SR_S4], stol = P[SR_SING_TOL], dtol = P[SR_DISC_TOL];
    int mir = P[SR_MIRROR] != 0.0;
    double a3 = P[SR_A3], b3 = P[SR_B3], c3_ = P[SR_C3];
    double a5 = P[SR_A5], b5 = P[SR_B5], c5_ = P[SR_C5], aa = P[SR_AA], bb = P[SR_BB];
    slots_clear(o);
    m3 R;
    v3 p, pp;
    target(T, P, &R, &p);
    Roots r1 = shoulder(P, &R, p, &pp);
    if (r1.n == 0)
        return SR_OUT_OF_REACH;
    v3 g6 = m3_mv(&R, h6);
    v3 a = v3_sub(o3, o2), b = v3_sub(o4, o3), o21 = v3_sub(o2, o1), w4 = v3_sub(ow, o4);
    /* the planar part (axes 2-4 parallel): coordinates in the plane normal to h2,
     * basis (e, e2 = h2 x e); rotations about h2 are 2D rotations there */
    v3 e2 = v3_cross(h2, e);
    double a1 = v3_dot(a, e), a2 = v3_dot(a, e2), b1 = v3_dot(b, e), b2 = v3_dot(b, e2);
    double w41 = v3_dot(w4, e), w42 = v3_dot(w4, e2), w4h = v3_dot(w4, h2);
    int any_wrist = 0, any_ok = 0;
    for (int i1 = 0; i1 < r1.n; i1++) {
        double th1 = r1.t[i1], c1 = r1.c[i1], s1 = r1.s[i1];
        v3 x = v3_rot(h1, c1, -s1, g6); /* R1^T R06 h6 */
        double d5 = v3_dot(h2, x);
        v3 xp = v3_sub(x, v3_scale(h2, d5));
        Roots r5 = sp4_roots(a5, b5, d5 - c5_, wrist_disc(a5, b5, c5_, d5, v3_dot(xp, xp)),
                             dtol, mir, P[SR_PHI5], P[SR_CPHI5], P[SR_SPHI5]);
        if (r5.n == 0)
            continue;
        any_wrist = 1;
        v3 y = m3_mtv(&R, v3_rot(h1, c1, s1, h2)); /* R06^T R1 h2 */
        v3 yp = v3_sub(y, v3_scale(h6, v3_dot(y, h6)));
        int singular = sqrt(v3_dot(yp, yp)) < stol;
        if (singular)
            r5.n = 1;
        v3 pl = v3_sub(v3_rot(h1, c1, -s1, pp), o21); /* R1^T pp - (o2 - o1) */
        double pl1 = v3_dot(pl, e), pl2 = v3_dot(pl, e2);
        double dh = v3_dot(pl, h2) - w4h; /* d's component along h2 */
        for (int i5 = 0; i5 < r5.n; i5++) {
            double th5 = r5.t[i5], c5 = r5.c[i5], s5 = r5.s[i5], th6, c6, s6;
            if (singular) {
                th6 = P[SR_SIGN + 5] * q6 + P[SR_OFFSET + 5];
                WristFree wf = {h1, h2, h5, h6, e, &R, c1, s1, c5, s5, pl1, pl2, dh,
                                w41, w42, aa, bb, c3_, a3, b3};
                th6 = singular_theta6(&wf, th6);
                c6 = cos(th6);
                s6 = sin(th6);
            } else {
                th6 = sp1(h6, y, v3_rot(h5, c5, -s5, h2), &c6, &s6);
            }
            v3 w = v3_rot(h6, c6, -s6, v3_rot(h5, c5, -s5, e));
            w = v3_rot(h1, c1, -s1, m3_mv(&R, w));
            double c234, s234;
            double th234 = sp1(h2, e, w, &c234, &s234);
            double d1 = pl1 - (c234 * w41 - s234 * w42); /* d = pl - rot(h2, th234) w4 */
            double d2 = pl2 - (s234 * w41 + c234 * w42);
            double rhs3 = 0.5 * (d1 * d1 + d2 * d2 + dh * dh - aa - bb) - c3_;
            Roots r3 = sp4_roots(a3, b3, rhs3, a3 * a3 + b3 * b3 - rhs3 * rhs3, dtol, mir,
                                 P[SR_PHI3], P[SR_CPHI3], P[SR_SPHI3]);
            for (int i3 = 0; i3 < r3.n; i3++) {
                double th3 = r3.t[i3], c3 = r3.c[i3], sn3 = r3.s[i3];
                double sg = s3 * sn3; /* rot(h3, th3) = rot(h2, s3 th3) */
                double u1 = a1 + c3 * b1 - sg * b2; /* u = a + rot(h3, th3) b */
                double u2 = a2 + sg * b1 + c3 * b2;
                double th2 = fast_atan2(u1 * d2 - u2 * d1, u1 * d1 + u2 * d2); /* rot(h2, th2) u = d */
                double th4 = s4 * (th234 - th2 - s3 * th3);
                double v[6] = {th1, th2, th3, th4, th5, th6};
                slot_write(P, o, 4 * i1 + 2 * i3 + i5, v,
                           singular || r1.boundary || r3.boundary);
                any_ok = 1;
            }
        }
    }
    if (any_ok)
        return SR_OK;
    return any_wrist ? SR_OUT_OF_REACH : SR_NO_ORIENTATION;
}

/* Every solution of one pose T (4 x 4, row-major) of a spherical-wrist arm (axes
 * 2, 3 parallel, axes 4, 5, 6 meeting; IK-Geo 'spherical wrist, two parallel'):
 * the wrist centre fixes theta1 (subproblem 4), theta3 (subproblem 3) and theta2
 * (subproblem 1); then theta5 (subproblem 4), theta6 and theta4 (subproblem 1). At
 * the wrist singularity theta6 is q6 (a joint value). Returns the status. */
static int spherical_one(const double *T, const double *P, double q6, Slots o)
{
    v3 h1 = v3_at(P, SR_AXES), h2 = v3_at(P, SR_AXES + 3), h3 = v3_at(P, SR_AXES + 6);
    v3 h4 = v3_at(P, SR_AXES + 9), h5 = v3_at(P, SR_AXES + 12), h6 = v3_at(P, SR_AXES + 15);
    v3 o1 = v3_at(P, SR_POINTS), o2 = v3_at(P, SR_POINTS + 3), o3 = v3_at(P, SR_POINTS + 6);
    v3 ow = v3_at(P, SR_WRIST), e = v3_at(P, SR_PERP);
    double sign3 = P[SR_S3], stol = P[SR_SING_TOL], dtol = P[SR_DISC_TOL];
    int mir = P[SR_MIRROR] != 0.0;
    double a3 = P[SR_A3], b3 = P[SR_B3], c3_ = P[SR_C3];
    double a5 = P[SR_A5], b5 = P[SR_B5], c5_ = P[SR_C5], aa = P[SR_AA], bb = P[SR_BB];
    slots_clear(o);
    m3 R;
    v3 p, pw;
    target(T, P, &R, &p);
    Roots r1 = shoulder(P, &R, p, &pw);
    if (r1.n == 0)
        return SR_OUT_OF_REACH;
    v3 g6 = m3_mv(&R, h6);
    v3 a = v3_sub(o3, o2), b = v3_sub(ow, o3), o21 = v3_sub(o2, o1);
    int any_pos = 0, any_ok = 0;
    for (int i1 = 0; i1 < r1.n; i1++) {
        double th1 = r1.t[i1], c1 = r1.c[i1], s1 = r1.s[i1];
        v3 d = v3_sub(v3_rot(h1, c1, -s1, pw), o21);
        double rhs3 = 0.5 * (v3_dot(d, d) - aa - bb) - c3_;
        Roots r3 = sp4_roots(a3, b3, rhs3, a3 * a3 + b3 * b3 - rhs3 * rhs3, dtol, mir,
                             P[SR_PHI3], P[SR_CPHI3], P[SR_SPHI3]);
        v3 g61 = v3_rot(h1, c1, -s1, g6);
        for (int i3 = 0; i3 < r3.n; i3++) {
            any_pos = 1;
            double th3 = r3.t[i3], c3 = r3.c[i3], s3 = r3.s[i3], c2, s2;
            v3 u = v3_add(a, v3_rot(h3, c3, s3, b));
            double th2 = sp1(h2, u, d, &c2, &s2);
            /* h3 = sign3 h2 (snapped): rot(h2, th2) rot(h3, th3) = rot(h2, th2 + sign3 th3) */
            double sg = sign3 * s3;
            double c23 = c2 * c3 - s2 * sg, s23 = s2 * c3 + c2 * sg;
            v3 x = v3_rot(h2, c23, -s23, g61); /* Rw h6 */
            double d5 = v3_dot(h4, x);
            v3 xp = v3_sub(x, v3_scale(h4, d5));
            Roots r5 = sp4_roots(a5, b5, d5 - c5_,
                                 wrist_disc(a5, b5, c5_, d5, v3_dot(xp, xp)), dtol, mir,
                                 P[SR_PHI5], P[SR_CPHI5], P[SR_SPHI5]);
            v3 y = m3_mtv(&R, v3_rot(h1, c1, s1, v3_rot(h2, c23, s23, h4)));
            v3 yp = v3_sub(y, v3_scale(h6, v3_dot(y, h6)));
            int singular = sqrt(v3_dot(yp, yp)) < stol;
            if (singular && r5.n > 1)
                r5.n = 1;
            for (int i5 = 0; i5 < r5.n; i5++) {
                double th5 = r5.t[i5], c5 = r5.c[i5], s5 = r5.s[i5], th6, c6, s6, c4, s4;
                if (singular) {
                    th6 = P[SR_SIGN + 5] * q6 + P[SR_OFFSET + 5];
                    c6 = cos(th6);
                    s6 = sin(th6);
                } else {
                    th6 = sp1(h6, y, v3_rot(h5, c5, -s5, h4), &c6, &s6);
                }
                v3 w = v3_rot(h6, c6, -s6, v3_rot(h5, c5, -s5, e));
                w = v3_rot(h1, c1, -s1, m3_mv(&R, w));
                w = v3_rot(h2, c23, -s23, w);
                double th4 = sp1(h4, e, w, &c4, &s4);
                double v[6] = {th1, th2, th3, th4, th5, th6};
                slot_write(P, o, 4 * i1 + 2 * i3 + i5, v,
                           singular || r1.boundary || r3.boundary);
                any_ok = 1;
            }
        }
    }
    if (any_ok)
        return SR_OK;
    return any_pos ? SR_NO_ORIENTATION : SR_OUT_OF_REACH;
}

/* One pose of the family P[SR_FAMILY] names. */
static int six_r_one(const double *T, const double *P, double q6, Slots o)
{
    return P[SR_FAMILY] == SR_SPHERICAL_WRIST ? spherical_one(T, P, q6, o)
                                              : three_parallel_one(T, P, q6, o);
}

/* --------------------------------------------------------------- entries */

/* module.c's argument helper (defined there, after this file) */
static PyArrayObject *array_arg(PyObject *o, const char *name, int typenum, int ndim,
                                int writeable);
#define SR_F64(a) ((double *)PyArray_DATA((PyArrayObject *)(a)))
#define SR_U8(a) ((unsigned char *)PyArray_DATA((PyArrayObject *)(a)))
#define SR_DIM(a, d) (PyArray_DIMS(a)[d])

/* A batch: poses T (N x 16), joint-6 values at the wrist singularity from qn
 * (m x 6, row i % m), outputs per pose. */
typedef struct {
    const double *P, *T, *qn;
    long m;
    double *Q;
    unsigned char *valid, *sing, *inside;
    signed char *status;
} SixRJob;

/* Poses [b, e) of a batch (a pool task). */
static void six_r_range(void *ctx, long b, long e)
{
    const SixRJob *jb = ctx;
    for (long i = b; i < e; i++) {
        Slots o = {jb->Q + 48 * i, jb->valid + 8 * i, jb->sing + 8 * i,
                   jb->inside + 8 * i};
        jb->status[i] =
            (signed char)six_r_one(jb->T + 16 * i, jb->P, jb->qn[6 * (i % jb->m) + 5], o);
    }
}

/* params as a parameter vector of a known family, or NULL with ValueError */
static const double *six_r_params(PyObject *o)
{
    PyArrayObject *a = array_arg(o, "params", NPY_DOUBLE, 1, 0);
    if (a == NULL)
        return NULL;
    const double *P = SR_F64(a);
    if (SR_DIM(a, 0) != SR_N_PARAMS ||
        (P[SR_FAMILY] != SR_THREE_PARALLEL && P[SR_FAMILY] != SR_SPHERICAL_WRIST)) {
        PyErr_SetString(PyExc_ValueError,
                        "robokin._native: params is not a 6R parameter vector (_six_r.pack)");
        return NULL;
    }
    return P;
}

/* (Q, valid, singular, within_limits) arrays, shapes lead + (8, 6) and lead + (8,)
 * with lead = () (nlead 0) or (N,) (nlead 1), into out[4]; 0 on a memory error. */
static int six_r_outputs(int nlead, npy_intp N, PyObject **out)
{
    npy_intp dq[3] = {N, 8, 6}, df[2] = {N, 8};
    out[0] = PyArray_SimpleNew(nlead + 2, dq + 1 - nlead, NPY_DOUBLE);
    for (int i = 1; i < 4; i++)
        out[i] = out[0] == NULL ? NULL : PyArray_SimpleNew(nlead + 1, df + 1 - nlead, NPY_BOOL);
    if (out[0] == NULL || out[1] == NULL || out[2] == NULL || out[3] == NULL) {
        for (int i = 0; i < 4; i++)
            Py_XDECREF(out[i]);
        return 0;
    }
    return 1;
}

/* six_r_ik1(T, params, q6) -> (code, Q (8, 6), valid (8,), singular (8,),
 * within_limits (8,)): one pose, validated in the same call (pose_problem's tests,
 * as check_poses). code >= BAD_POSE: nothing was solved and the arrays are None
 * (BAD_POSE + pose_problem's code, or BAD_POSE itself when T is not a float64
 * (4, 4) array); the caller takes its general, validating path. The fast path for
 * one pose: METH_FASTCALL, no pool, T read through its strides. */
static PyObject *py_six_r_ik1(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 3) {
        PyErr_SetString(PyExc_TypeError, "six_r_ik1(T, params, q6) takes 3 arguments");
        return NULL;
    }
    const double *P = six_r_params(args[1]);
    if (P == NULL)
        return NULL;
    double q6 = PyFloat_AsDouble(args[2]);
    if (q6 == -1.0 && PyErr_Occurred())
        return NULL;
    int code = SR_BAD_POSE;
    double T[16];
    PyObject *to = args[0];
    if (PyArray_Check(to)) {
        PyArrayObject *ta = (PyArrayObject *)to;
        if (PyArray_TYPE(ta) == NPY_DOUBLE && PyArray_NDIM(ta) == 2 && SR_DIM(ta, 0) == 4 &&
            SR_DIM(ta, 1) == 4 && PyArray_ISNOTSWAPPED(ta) && PyArray_ISALIGNED(ta)) {
            const char *d = PyArray_BYTES(ta);
            npy_intp rs = PyArray_STRIDE(ta, 0), cs = PyArray_STRIDE(ta, 1);
            for (int r = 0; r < 4; r++)
                for (int c = 0; c < 4; c++)
                    T[4 * r + c] = *(const double *)(d + r * rs + c * cs);
            code = pose_problem(T, POSE_ROW_TOL, POSE_ORTH_TOL);
            code = code ? SR_BAD_POSE + code : 0;
        }
    }
    if (code)
        return Py_BuildValue("(iOOOO)", code, Py_None, Py_None, Py_None, Py_None);
    PyObject *out[4];
    if (!six_r_outputs(0, 0, out))
        return NULL;
    Slots o = {SR_F64(out[0]), SR_U8(out[1]), SR_U8(out[2]), SR_U8(out[3])};
    code = six_r_one(T, P, q6, o);
    PyObject *res = PyTuple_New(5);
    if (res == NULL) {
        for (int i = 0; i < 4; i++)
            Py_DECREF(out[i]);
        return NULL;
    }
    PyTuple_SET_ITEM(res, 0, PyLong_FromLong(code));
    for (int i = 0; i < 4; i++)
        PyTuple_SET_ITEM(res, i + 1, out[i]);
    return res;
}

/* six_r_ik(params, T (N, 4, 4), qn (m, 6)) -> (Q (N, 8, 6), valid, singular,
 * within_limits (N, 8), status (N,) int8): a batch, not validated (the caller
 * checked the poses); joint 6 at the wrist singularity is qn[i % m, 5]. Batches of
 * PARALLEL_MIN poses or more run on the pool. */
static PyObject *py_six_r_ik(PyObject *self, PyObject *args)
{
    PyObject *po, *to, *qo;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOO", &po, &to, &qo))
        return NULL;
    const double *P = six_r_params(po);
    PyArrayObject *T, *qn;
    if (P == NULL || !(T = array_arg(to, "T", NPY_DOUBLE, 3, 0)) ||
        !(qn = array_arg(qo, "qn", NPY_DOUBLE, 2, 0)))
        return NULL;
    if (SR_DIM(T, 1) != 4 || SR_DIM(T, 2) != 4 || SR_DIM(qn, 0) < 1 || SR_DIM(qn, 1) != 6) {
        PyErr_SetString(PyExc_ValueError,
                        "robokin._native.six_r_ik: T must be (N, 4, 4) and qn (m >= 1, 6)");
        return NULL;
    }
    npy_intp N = SR_DIM(T, 0);
    PyObject *out[4];
    if (!six_r_outputs(1, N, out))
        return NULL;
    npy_intp dims[1] = {N};
    PyObject *status = PyArray_SimpleNew(1, dims, NPY_INT8);
    if (status == NULL) {
        for (int i = 0; i < 4; i++)
            Py_DECREF(out[i]);
        return NULL;
    }
    SixRJob jb = {P, SR_F64(T), SR_F64(qn), (long)SR_DIM(qn, 0), SR_F64(out[0]),
                   SR_U8(out[1]), SR_U8(out[2]), SR_U8(out[3]),
                   (signed char *)PyArray_DATA((PyArrayObject *)status)};
    Py_BEGIN_ALLOW_THREADS
    if (N >= SR_PARALLEL_MIN)
        pool_for((long)N, SR_GRAIN, six_r_range, &jb);
    else
        six_r_range(&jb, 0, (long)N);
    Py_END_ALLOW_THREADS
    return Py_BuildValue("(NNNNN)", out[0], out[1], out[2], out[3], status);
}

/* atan2(y (N,), x (N,), out (N,)): the kernels' atan2 (for tests) */
static PyObject *py_six_r_atan2(PyObject *self, PyObject *args)
{
    PyObject *yo, *xo, *oo;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOO", &yo, &xo, &oo))
        return NULL;
    PyArrayObject *y, *x, *out;
    if (!(y = array_arg(yo, "y", NPY_DOUBLE, 1, 0)) ||
        !(x = array_arg(xo, "x", NPY_DOUBLE, 1, 0)) ||
        !(out = array_arg(oo, "out", NPY_DOUBLE, 1, 1)))
        return NULL;
    npy_intp N = SR_DIM(y, 0);
    if (SR_DIM(x, 0) != N || SR_DIM(out, 0) != N) {
        PyErr_SetString(PyExc_ValueError, "robokin._native.atan2: sizes differ");
        return NULL;
    }
    for (npy_intp i = 0; i < N; i++)
        SR_F64(out)[i] = fast_atan2(SR_F64(y)[i], SR_F64(x)[i]);
    Py_RETURN_NONE;
}

#define SIX_R_METHODS                                                                    \
    {"six_r_ik1", (PyCFunction)(void (*)(void))py_six_r_ik1, METH_FASTCALL,              \
     "six_r_ik1(T, params, q6) -> (code, Q, valid, singular, within_limits): one pose "   \
     "of a 6R closed form, validated."},                                                  \
    {"six_r_ik", py_six_r_ik, METH_VARARGS,                                              \
     "six_r_ik(params, T, qn) -> (Q, valid, singular, within_limits, status): a batch "  \
     "of a 6R closed form."},                                                             \
    {"atan2", py_six_r_atan2, METH_VARARGS, "atan2(y, x, out): the kernels' atan2."},

static int six_r_constants(PyObject *m)
{
    static const struct { const char *name; int value; } ints[] = {
        {"AXES", SR_AXES}, {"POINTS", SR_POINTS}, {"WRIST", SR_WRIST},
        {"TOOL_T", SR_TOOL_T}, {"TOOL_R", SR_TOOL_R}, {"PERP", SR_PERP},
        {"SIGN", SR_SIGN}, {"OFFSET", SR_OFFSET}, {"LO", SR_LO}, {"HI", SR_HI},
        {"S3", SR_S3}, {"S4", SR_S4}, {"SING_TOL", SR_SING_TOL},
        {"DISC_TOL", SR_DISC_TOL}, {"MIRROR", SR_MIRROR},
        {"A3", SR_A3}, {"B3", SR_B3}, {"C3", SR_C3}, {"PHI3", SR_PHI3},
        {"CPHI3", SR_CPHI3}, {"SPHI3", SR_SPHI3},
        {"A5", SR_A5}, {"B5", SR_B5}, {"C5", SR_C5}, {"PHI5", SR_PHI5},
        {"CPHI5", SR_CPHI5}, {"SPHI5", SR_SPHI5},
        {"AA", SR_AA}, {"BB", SR_BB}, {"FAMILY", SR_FAMILY}, {"N_PARAMS", SR_N_PARAMS},
        {"THREE_PARALLEL", SR_THREE_PARALLEL}, {"SPHERICAL_WRIST", SR_SPHERICAL_WRIST},
        {"STATUS_OK", SR_OK}, {"STATUS_OUT_OF_REACH", SR_OUT_OF_REACH},
        {"STATUS_NO_ORIENTATION", SR_NO_ORIENTATION}, {"BAD_POSE", SR_BAD_POSE},
        {"SIX_R_PARALLEL_MIN", SR_PARALLEL_MIN}};
    for (size_t i = 0; i < sizeof(ints) / sizeof(ints[0]); i++)
        if (PyModule_AddIntConstant(m, ints[i].name, ints[i].value) < 0)
            return -1;
    return 0;
}

#if defined(__clang__)
#pragma STDC FP_CONTRACT DEFAULT
#elif defined(__GNUC__)
#pragma GCC pop_options
#endif
