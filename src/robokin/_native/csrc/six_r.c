/*
 * Closed-form IK of the two 6R families, every solution of a pose:
 *
 *   three parallel: axes 2, 3, 4 parallel, axes 5, 6 meeting (UR, AUBO, Doosan);
 *   spherical wrist: axes 2, 3 parallel, axes 4, 5, 6 meeting (Puma, KUKA, ABB).
 *
 * Paden-Kahan subproblems on the chain's product-of-exponentials geometry (the
 * algorithm is described for users in robokin/kinematics/ik/analytic/
 * three_parallel.py and spherical_wrist.py), in the lane dialect (lanes.h): W poses
 * advance together, one per lane; a single pose runs in lane 0.
 *
 * References:
 *   Paden, "Kinematics and control of robot manipulators", PhD thesis, 1985
 *   (subproblems 1, 3, 4);
 *   Elias and Wen, "IK-Geo", arXiv:2211.05737 (2022), section III and the cases
 *   'three parallel, two intersecting' and 'spherical wrist, two parallel'.
 *
 * Accuracy. Three places lose digits near the wrist singularity (axis 6 in line
 * with axes 2-4, or with axis 4), and each is computed so it does not:
 *   - theta5's subproblem 4 needs A^2 + B^2 - (d - C)^2, which for unit vectors is
 *     |x_perp|^2 - (h.k)^2 - (k.p)^2 + 2 d C: |x_perp| is taken from the projected
 *     vector and the constant -(h.k)^2 - (k.p)^2 (SR_E5) is exact, so theta5 keeps
 *     its digits (A^2 + B^2 - C^2 - 1 rounded to 1e-16 against |x_perp|^2 = 1e-18
 *     at q5 = 1e-9 had lost half of them: 1.4e-8 pose errors);
 *   - subproblem 1 projects both vectors off the axis before their dot and cross
 *     products (q.p - (k.p)(k.q) cancels to eps / sin^2 of the angle to the axis:
 *     6e-6 rad in theta6 at q5 = 1e-6);
 *   - the free combination: see 'the wrist split' below.
 * Every solution whose subproblems were near a boundary (a double root) or near a
 * singularity is checked against the true chain (chain.h's FK) and, when its pose
 * error exceeds SR_TOL_P [m] / SR_TOL_R [rad], polished by damped Newton steps
 * (sr_polish); the others meet it by construction (measured in docs/ik.md).
 *
 * The wrist split. Near the wrist singularity theta6 and the combination it trades
 * with (theta2 + theta3 + theta4, or theta4) are ill-conditioned: moving theta6 by
 * D and the combination back changes the tool orientation by about |y_perp| D
 * (y_perp: the off-axis part of axis 2's (axis 4's) direction in the tool frame,
 * |y_perp| = |sin(theta5 - singular value)|). So every theta6 within SR_SPLIT_TOL /
 * |y_perp| of the exact one reproduces the pose to SR_SPLIT_TOL; below
 * |y_perp| = SR_SPLIT_TOL / pi every theta6 does (the pose is singular to rounding:
 * theta6 is then q_near's, or 0). Within that window theta6 is moved, when needed,
 * to the value nearest the preferred one (q_near's at a singular pose, the exact one
 * otherwise) for which the elbow is solvable and every joint is inside its limits
 * (else only solvable): a one-dimensional search over the window (sr_split), each
 * elbow branch on its own. Three-parallel arms need it for the elbow too: the wrist
 * point moves with theta2 + theta3 + theta4 (axis 5 sits off axis 4).
 *
 * Flags. A solution is flagged singular when the smallest singular value of its
 * Jacobian (position rows divided by the arm's size L) is below SR_SING_TOL. It is
 * computed (chain.h's jac_sigma_min6) for the solutions checked against the chain:
 * those near a singularity, where the sine of the gap between the two roots of the
 * shoulder's or the elbow's subproblem 4 (0 at a double root: the wrist centre on
 * the shoulder's boundary cylinder, the elbow stretched or folded) or |y_perp| (the
 * wrist) is below SR_CHECK_BAND; the others are not singular.
 *
 * Both families read one flat parameter vector that _six_r.pack writes (Python
 * reads these indices from the module constants _declare.py declares, named
 * without the SR_):
 *
 *   SR_AXES      unit joint axes h1..h6 (base frame, zero chain values), 6 x 3
 *   SR_POINTS    points o1, o2, o3, o4 on axes 1-4, 4 x 3
 *   SR_WRIST     ow: where axes 5, 6 (three parallel) or 4, 5, 6 (spherical) meet
 *   SR_PERP2     e2 = hw x e (hw = h2, three parallel, or h4, spherical)
 *   SR_TOOL_T    tool origin t at zero chain values
 *   SR_TOOL_R    rows of the tool rotation R_M at zero chain values, 3 x 3
 *   SR_PERP      unit vector e perpendicular to hw
 *   SR_SIGN, SR_OFFSET, SR_LO, SR_HI   per joint (6 each): v = sign q + offset,
 *                joint limits
 *   SR_S3, SR_S4 h3 = s3 h2, h4 = s4 h2 (+-1; three parallel uses both)
 *   SR_SING_TOL  singular flag: within this (a sine) of a singularity
 *   SR_DISC_TOL  subproblem 4 discriminant tolerance (relative to A^2 + B^2)
 *   SR_MIRROR    1.0: seeds mirrored past a boundary (near-family arms, whose
 *                solutions Python polishes on the true chain), else 0.0
 *   SR_A3..SR_SPHI3  theta3 subproblem 4: A, B, C, atan2(B, A), its cosine, sine
 *   SR_A5..SR_SPHI5  theta5 subproblem 4: the same
 *   SR_AA, SR_BB |a|^2, |b|^2 of the two-link (elbow) problem
 *   SR_FAMILY    SR_THREE_PARALLEL or SR_SPHERICAL_WRIST
 *   SR_E5        -(hw.h5)^2 - (h5.h6)^2: theta5's discriminant constant
 *   SR_PLANE     three parallel: a, b, w4 = ow - o4 in the plane basis (e, e2)
 *                (a1, a2, b1, b2, w41, w42) and w4's component along h2
 *   SR_SPLIT_TOL the wrist split's orientation budget [rad]
 *   SR_TOL_P, SR_TOL_R  pose error a solution must meet [m], [rad]
 *   SR_CHECK     1.0: check (and polish) every solution, not only those near a
 *                boundary or singularity (tests); -1.0: none (near-family arms)
 *   SR_SIZE      the arm's size L (sum of its link offsets) [m]: the singular flag
 *                reads the Jacobian with its position rows divided by L
 *
 * Each pose yields 8 slots, slot = 4 shoulder + 2 elbow + wrist, 0 = the '+' and
 * 1 = the '-' root of the subproblem; a slot that has no solution is NaN, invalid,
 * not singular and not within limits. Status: 0 ok, 1 out of reach, 2 orientation
 * not achievable; SR_BAD_POSE + pose_problem's code (chain.h) when the one-pose
 * entry found T not a rigid transform (nothing solved).
 *
 * Entries (the Python layer validates what users pass; bad arguments here are
 * internal errors and raise ValueError):
 *   six_r_ik1(T, params, q6, packed): one pose, validated, no pool; METH_FASTCALL.
 *   six_r_ik(params, T, qn, packed): a batch; the pool runs batches of
 *   SR_PARALLEL_MIN poses or more, the GIL released. A pose's lane computes only
 *   from its own pose, whichever lane and thread take it, so results do not depend
 *   on its place in the batch or on the number of threads.
 *   atan2(y, x, out): the kernels' atan2 on arrays (for tests).
 */
#include "chain.h"
#include "pool.h"
#include "subproblems.h"
#include "vec3.h"

enum {
    SR_AXES = 0, SR_POINTS = 18, SR_WRIST = 30, SR_PERP2 = 33, SR_TOOL_T = 36,
    SR_TOOL_R = 39, SR_PERP = 48, SR_SIGN = 51, SR_OFFSET = 57, SR_LO = 63, SR_HI = 69,
    SR_S3 = 75, SR_S4 = 76, SR_SING_TOL = 77, SR_DISC_TOL = 78, SR_MIRROR = 79,
    SR_A3 = 80, SR_B3 = 81, SR_C3 = 82, SR_PHI3 = 83, SR_CPHI3 = 84, SR_SPHI3 = 85,
    SR_A5 = 86, SR_B5 = 87, SR_C5 = 88, SR_PHI5 = 89, SR_CPHI5 = 90, SR_SPHI5 = 91,
    SR_AA = 92, SR_BB = 93, SR_FAMILY = 94, SR_E5 = 95, SR_PLANE = 96,
    SR_SPLIT_TOL = 103, SR_TOL_P = 104, SR_TOL_R = 105, SR_CHECK = 106,
    SR_SIZE = 107, SR_N_PARAMS = 108
};
enum { SR_THREE_PARALLEL = 0, SR_SPHERICAL_WRIST = 1 };
enum { SR_OK = 0, SR_OUT_OF_REACH = 1, SR_NO_ORIENTATION = 2, SR_BAD_POSE = 16 };
#define SR_PARALLEL_MIN 512 /* below this many poses, one thread */
#define SR_GRAIN 32         /* poses per pool chunk (a multiple of every W) */
/* A solution is checked against the chain when a subproblem sat this close (a
 * sine) to a double root or the wrist to its singularity (docs/ik.md: below it the
 * closed form alone met the pose tolerance on every pose measured). */
#define SR_CHECK_BAND 1e-3
/* Near-singular wrists whose solution is infeasible (elbow, limits) get the split
 * search while |y_perp| is below this (above it the window is < 1e-9 rad wide). */
#define SR_SPLIT_BAND 1e-4
/* Joints are inside when within 1e-9 of their limits; the split search aims this
 * much further in, so the solution it picks passes that test after rounding. */
/* The split search takes the elbow as solvable when its relative discriminant is
 * above -SR_SPLIT_DISC: rounding (1.4e-15 seen at a tangency), not the kernel's
 * 1e-12 tolerance (whose boundary root leaves up to 3e-12 m at a folded elbow). */
#define SR_SPLIT_DISC 1e-14
#define SR_LIMIT_SLACK LIMIT_SLACK /* chain.h: the wrap_into rule's */
#define SR_LIMIT_AIM 1e-12
#define SR_POLISH_ITERS 6
/* A valid solution outside its limits by at most this much [rad, m] gets a descent
 * into them (sr_rescue), of at most SR_RESCUE_ITERS steps: flagged singular ones
 * (whose solutions form a near-continuum: the split wanders with rounding) up to
 * SR_RESCUE_REACH, the others (isolated: a descent from further out may land on
 * another solution) up to SR_RESCUE_NEAR. */
#define SR_RESCUE_REACH 1e-2
#define SR_RESCUE_NEAR 1e-4
#define SR_RESCUE_ITERS 40

/* ------------------------------------------------------------------- vectors */

/* Lane vectors: one 3-vector per lane, and a rotation by its rows. */
typedef struct { vd x, y, z; } L3;
typedef struct { L3 r0, r1, r2; } LM3;

ALWAYS_INLINE L3 l3_const(v3 a) { return (L3){BR(a.x), BR(a.y), BR(a.z)}; }
ALWAYS_INLINE vd l3_dot(L3 a, L3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
ALWAYS_INLINE vd l3_dotc(L3 a, v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
ALWAYS_INLINE L3 l3_add(L3 a, L3 b) { return (L3){a.x + b.x, a.y + b.y, a.z + b.z}; }
ALWAYS_INLINE L3 l3_sub(L3 a, L3 b) { return (L3){a.x - b.x, a.y - b.y, a.z - b.z}; }
ALWAYS_INLINE L3 l3_subc(L3 a, v3 b) { return (L3){a.x - b.x, a.y - b.y, a.z - b.z}; }
ALWAYS_INLINE L3 l3_addc(L3 a, v3 b) { return (L3){a.x + b.x, a.y + b.y, a.z + b.z}; }

/* k s for a constant k */
ALWAYS_INLINE L3 l3_ks(v3 k, vd s) { return (L3){k.x * s, k.y * s, k.z * s}; }

/* k x v for a constant k */
ALWAYS_INLINE L3 l3_kcross(v3 k, L3 v)
{
    return (L3){k.y * v.z - k.z * v.y, k.z * v.x - k.x * v.z, k.x * v.y - k.y * v.x};
}

/* v - k (k . v): v's part perpendicular to the unit vector k */
ALWAYS_INLINE L3 l3_perp(v3 k, L3 v) { return l3_sub(v, l3_ks(k, l3_dotc(v, k))); }

/* rot(k, t) v for a constant unit k given c = cos t, s = sin t (Rodrigues):
 * v cos t + (k x v) sin t + k (k . v)(1 - cos t) */
ALWAYS_INLINE L3 l3_rot(v3 k, vd c, vd s, L3 v)
{
    vd kv = l3_dotc(v, k) * (1.0 - c);
    L3 x = l3_kcross(k, v);
    return (L3){v.x * c + x.x * s + k.x * kv, v.y * c + x.y * s + k.y * kv,
                v.z * c + x.z * s + k.z * kv};
}

/* the same for a constant v */
ALWAYS_INLINE L3 l3_rotc(v3 k, vd c, vd s, v3 v)
{
    double kv = v3_dot(k, v);
    v3 x = v3_cross(k, v);
    vd f = kv * (1.0 - c);
    return (L3){v.x * c + x.x * s + k.x * f, v.y * c + x.y * s + k.y * f,
                v.z * c + x.z * s + k.z * f};
}

ALWAYS_INLINE L3 lm3_mv(const LM3 *R, L3 v)
{
    return (L3){l3_dot(R->r0, v), l3_dot(R->r1, v), l3_dot(R->r2, v)};
}

ALWAYS_INLINE L3 lm3_mvc(const LM3 *R, v3 v)
{
    return (L3){l3_dotc(R->r0, v), l3_dotc(R->r1, v), l3_dotc(R->r2, v)};
}

/* R^T v */
ALWAYS_INLINE L3 lm3_mtv(const LM3 *R, L3 v)
{
    return (L3){R->r0.x * v.x + R->r1.x * v.y + R->r2.x * v.z,
                R->r0.y * v.x + R->r1.y * v.y + R->r2.y * v.z,
                R->r0.z * v.x + R->r1.z * v.y + R->r2.z * v.z};
}

/* ----------------------------------------------------------------- angles */

#define SIGN_BIT BRL(0x8000000000000000ULL)

ALWAYS_INLINE vd vmin(vd a, vd b) { return vsel(a < b, a, b); }
ALWAYS_INLINE vd vmax(vd a, vd b) { return vsel(a > b, a, b); }

/* floor(x) for |x| < 2^51 (angles): round to nearest by adding 1.5 * 2^52, then down */
ALWAYS_INLINE vd vfloor(vd x)
{
    vd r = (x + ROUND_MAGIC) - ROUND_MAGIC;
    return vsel(r > x, r - 1.0, r);
}

ALWAYS_INLINE vd vceil(vd x) { return -vfloor(-x); }

/* an angle wrapped into [-pi, pi) (chain.h's wrap_pi, lane-wise) */
ALWAYS_INLINE vd vwrap_pi(vd x)
{
    return x - 2.0 * M_PI * vfloor((x + M_PI) * (0.5 / M_PI));
}

/* atan(u) for |u| <= tan(pi/8), lane-wise (subproblems.h's polynomial) */
ALWAYS_INLINE vd atan_core(vd u)
{
    ATAN_CORE_BODY(vd, u)
}

/* atan2(y, x) to within a few ulp (< 1e-15 rad): octant reduction to
 * |u| <= tan(pi/8), then atan_core; lanes with both zero, an infinity or NaN take
 * libm's atan2. */
ALWAYS_INLINE vd vatan2(vd y, vd x)
{
    vd ax = vabs(x), ay = vabs(y);
    vl swap = ay > ax;
    vd num = vsel(swap, ax, ay), den = vsel(swap, ay, ax);
    vl big = num > SR_TAN_PI_8 * den;
    vd nn = vsel(big, num - den, num), dd = vsel(big, num + den, den);
    vl odd = ~(dd > 0.0) | ~vfinite(ax) | ~vfinite(ay);
    vd u = nn / vsel(odd, BR(1.0), dd);
    vd r = atan_core(u) + vsel(big, BR(M_PI_4), BR(0.0));
    r = vsel(swap, M_PI_2 - r, r);
    r = vsel(x < 0.0, M_PI - r, r);
    r = (vd)(((vl)r & ~SIGN_BIT) | ((vl)y & SIGN_BIT));
    if (vany(odd))
        for (int l = 0; l < W; l++)
            if (odd[l])
                r[l] = atan2(y[l], x[l]);
    return r;
}

/* (cos, sin) of atan2(y, x) without trigonometry: (x, y) / |(x, y)|, or (1, 0) */
ALWAYS_INLINE void vunit(vd x, vd y, vd *c, vd *s)
{
    vd r = vsqrt(x * x + y * y);
    vl pos = r > 0.0;
    vd ir = 1.0 / vsel(pos, r, BR(1.0));
    *c = vsel(pos, x * ir, BR(1.0));
    *s = vsel(pos, y * ir, BR(0.0));
}

/* --------------------------------------------------------------- parameters */

/* The parameter vector, read once per call. */
typedef struct {
    v3 h[6], o[4], ow, t, e, e2, o21, tw, h1x2, a, b;
    v3 rm0, rm1, rm2; /* rows of R_M */
    double sign[6], off[6], lo[6], hi[6];
    double s3, s4, stol, dtol, split_tol, free_tol, tolp, tolr, check, size;
    double ea, eb, ec, ephi, ecphi, esphi, wa, wb, wc, wphi, wcphi, wsphi, we5, aa, bb;
    double a1, a2, b1, b2, w41, w42, w4h, h12, rhs1, er2;
    int mirror, family;
} SR;

static void sr_read(const double *P, SR *K)
{
    for (int k = 0; k < 6; k++) {
        K->h[k] = v3_at(P, SR_AXES + 3 * k);
        K->sign[k] = P[SR_SIGN + k];
        K->off[k] = P[SR_OFFSET + k];
        K->lo[k] = P[SR_LO + k];
        K->hi[k] = P[SR_HI + k];
    }
    for (int k = 0; k < 4; k++)
        K->o[k] = v3_at(P, SR_POINTS + 3 * k);
    K->ow = v3_at(P, SR_WRIST);
    K->t = v3_at(P, SR_TOOL_T);
    K->e = v3_at(P, SR_PERP);
    K->e2 = v3_at(P, SR_PERP2);
    K->rm0 = v3_at(P, SR_TOOL_R);
    K->rm1 = v3_at(P, SR_TOOL_R + 3);
    K->rm2 = v3_at(P, SR_TOOL_R + 6);
    K->s3 = P[SR_S3];
    K->s4 = P[SR_S4];
    K->stol = P[SR_SING_TOL];
    K->dtol = P[SR_DISC_TOL];
    K->mirror = P[SR_MIRROR] != 0.0;
    K->ea = P[SR_A3];
    K->eb = P[SR_B3];
    K->ec = P[SR_C3];
    K->ephi = P[SR_PHI3];
    K->ecphi = P[SR_CPHI3];
    K->esphi = P[SR_SPHI3];
    K->wa = P[SR_A5];
    K->wb = P[SR_B5];
    K->wc = P[SR_C5];
    K->wphi = P[SR_PHI5];
    K->wcphi = P[SR_CPHI5];
    K->wsphi = P[SR_SPHI5];
    K->aa = P[SR_AA];
    K->bb = P[SR_BB];
    K->family = (int)P[SR_FAMILY];
    K->we5 = P[SR_E5];
    K->a1 = P[SR_PLANE];
    K->a2 = P[SR_PLANE + 1];
    K->b1 = P[SR_PLANE + 2];
    K->b2 = P[SR_PLANE + 3];
    K->w41 = P[SR_PLANE + 4];
    K->w42 = P[SR_PLANE + 5];
    K->w4h = P[SR_PLANE + 6];
    K->split_tol = P[SR_SPLIT_TOL];
    K->free_tol = P[SR_SPLIT_TOL] / M_PI;
    K->tolp = P[SR_TOL_P];
    K->tolr = P[SR_TOL_R];
    K->check = P[SR_CHECK];
    K->size = P[SR_SIZE];
    K->o21 = v3_sub(K->o[1], K->o[0]);
    K->tw = v3_sub(K->t, K->ow);
    K->h12 = v3_dot(K->h[0], K->h[1]);
    K->h1x2 = v3_cross(K->h[0], K->h[1]);
    K->rhs1 = v3_dot(K->h[1], v3_sub(K->ow, K->o[0]));
    K->er2 = K->ea * K->ea + K->eb * K->eb;
    K->a = v3_sub(K->o[2], K->o[1]);
    K->b = v3_sub(K->ow, K->o[2]);
}

/* ------------------------------------------------------------ subproblems */

/* Subproblem 1 (Paden): t with rot(k, t) p = q (least squares if inexact), its
 * cosine and sine; both vectors are projected off k first (see the header). */
ALWAYS_INLINE vd lsp1(v3 k, L3 p, L3 q, vd *c, vd *s)
{
    L3 pp = l3_perp(k, p), qp = l3_perp(k, q);
    vd x = l3_dot(qp, pp), y = l3_dot(qp, l3_kcross(k, pp));
    vunit(x, y, c, s);
    return vatan2(y, x);
}

/* The roots of a subproblem 4, A cos t + B sin t = rhs (Paden; IK-Geo sec. III),
 * per lane: t[0] (the '+' root) and t[1] ('-'), their cosines and sines; `one`
 * where there is a root, `two` where there are two; `gap` the sine of half their
 * separation (0 at a double root). A negative disc = A^2 + B^2 - rhs^2 within
 * tol (A^2 + B^2) is a double root (the pose on a singular boundary); with mirror
 * (near-family seeds) it gives two seeds mirrored about it instead. disc within
 * 1e-3 tol (A^2 + B^2) of zero is a double root too. */
typedef struct {
    vl one, two;
    vd t[2], c[2], s[2], gap;
} LRoots;

ALWAYS_INLINE LRoots lsp4(vd A, vd B, vd rhs, vd disc, double tol, int mirror, vd phi,
                          vd cphi, vd sphi)
{
    LRoots r;
    vd r2 = A * A + B * B;
    vd sq = vsqrt(vmax(disc, BR(0.0)));
    vd g = vatan2(sq, rhs), cg, sg;
    vunit(rhs, sq, &cg, &sg);
    SP4_PAIR(r, phi, cphi, sphi, g, cg, sg);
    r.one = ~(disc < -tol * r2);
    r.two = r.one & (disc > tol * r2 * 1e-3);
    r.gap = vsel(r2 > 0.0, sq / vsqrt(vsel(r2 > 0.0, r2, BR(1.0))), BR(0.0));
    if (mirror) {
        vl mir = r.one & (disc < 0.0);
        if (vany(mir))
            for (int l = 0; l < W; l++) {
                if (!mir[l])
                    continue;
                double t[2], c[2], s[2];
                sp4_mirror(phi[l], rhs[l], disc[l], t, c, s);
                for (int i = 0; i < 2; i++) {
                    r.t[i][l] = t[i];
                    r.c[i][l] = c[i];
                    r.s[i][l] = s[i];
                }
                r.two[l] = -1;
            }
    }
    return r;
}

/* theta5's subproblem 4 (both families): h . rot(h5, t) h6 = d with the wrist
 * direction x (unit, lanes) and h = hw; the exact discriminant (see the header).
 * Two roots wherever it is positive: the scalar equation cannot tell theta5 = +g
 * from -g but the orientation can (q5 = -1e-9 taken as +1e-9 put theta6 half a
 * turn off); the split merges them only at a singular pose. */
ALWAYS_INLINE LRoots wrist_roots(const SR *K, v3 hw, L3 x)
{
    vd d = l3_dotc(x, hw);
    L3 xp = l3_perp(hw, x);
    vd disc = K->we5 + l3_dot(xp, xp) + 2.0 * d * K->wc;
    LRoots r = lsp4(BR(K->wa), BR(K->wb), d - K->wc, disc, K->dtol, K->mirror,
                    BR(K->wphi), BR(K->wcphi), BR(K->wsphi));
    r.two |= r.one & (disc > 0.0);
    return r;
}

/* The wrist split (see the header), lane-wise: the window's half-width about the
 * exact theta6 for a wrist |y_perp| = sw (pi at a singular pose), and the theta6 to
 * use (th6, c6, s6 in and out): at a singular pose the preferred one (pref, a chain
 * angle; q6 = 0 where pref is NaN: none given); near it (sw below SR_SPLIT_BAND)
 * the exact one moved toward pref by at most the half-width; else the exact one. */
ALWAYS_INLINE vd wrist_split(const SR *K, vd sw, vd pref, vd *th6, vd *c6, vd *s6)
{
    vl free_ = sw < K->free_tol, has = pref == pref;
    vd half = vsel(free_, BR(M_PI), K->split_tol / vsel(free_, BR(1.0), sw));
    half = vmin(half, BR(M_PI));
    vd p = vsel(has, pref, BR(K->off[5]));
    vd d = vwrap_pi(p - *th6);
    d = vmax(vmin(d, half), -half);
    vl move = free_ | (has & (sw < SR_SPLIT_BAND) & (d != 0.0));
    if (vany(move)) {
        vd t = vsel(free_, p, *th6 + d), s, c;
        vsincos(t, &s, &c);
        *th6 = vsel(move, t, *th6);
        *c6 = vsel(move, c, *c6);
        *s6 = vsel(move, s, *s6);
    }
    return half;
}

/* Lanes where the preferred theta6 (pref, a chain angle) was not reached by the
 * window (wrist_split's estimate, from a |y_perp| that rounding near another
 * singularity can make 1e-12 too large) and is worth trying as it is: the solution
 * there is kept when the chain confirms it within the split's budget. */
ALWAYS_INLINE vl pref_untried(vd sw, vd pref, vd th6)
{
    return (sw < SR_SPLIT_BAND) & (pref == pref) & (vabs(vwrap_pi(pref - th6)) > 0.0);
}

/* theta5 at the wrist's double root (the singular value: phi5, or phi5 + pi) for
 * the wrist direction x (lanes) and h = hw, with its cosine and sine. */
ALWAYS_INLINE vd wrist_double_root(const SR *K, L3 x, v3 hw, vd *c5, vd *s5)
{
    vd rhs = l3_dotc(x, hw) - K->wc;
    vd t = K->wphi + vsel(rhs < 0.0, BR(M_PI), BR(0.0));
    vsincos(t, s5, c5);
    return t;
}

/* theta3's subproblem 4 (the elbow) for its right-hand side */
ALWAYS_INLINE LRoots elbow_roots(const SR *K, vd rhs3)
{
    return lsp4(BR(K->ea), BR(K->eb), rhs3, K->er2 - rhs3 * rhs3, K->dtol, K->mirror,
                BR(K->ephi), BR(K->ecphi), BR(K->esphi));
}

/* --------------------------------------------------------------- joint values */

/* The joint coordinates of chain angles v (lanes) of joint j: sign (v - offset)
 * wrapped to [-pi, pi), then moved by whole turns into [lo, hi] (1e-9 slack) where
 * that fits (chain.h's wrap_into, lane-wise); *inside says whether it lies there. */
ALWAYS_INLINE vd ljoint(const SR *K, int j, vd v, vl *inside)
{
    const double tp = 2.0 * M_PI;
    vd q = vwrap_pi(K->sign[j] * (v - K->off[j]));
    double lo = K->lo[j] - SR_LIMIT_SLACK, hi = K->hi[j] + SR_LIMIT_SLACK;
    vl above = q > hi, below = q < lo;
    if (vany(above | below)) {
        vd qa = q - vceil((q - hi) * (1.0 / tp)) * tp;
        vd qb = q + vceil((lo - q) * (1.0 / tp)) * tp;
        q = vsel(above & (qa >= lo), qa, q);
        q = vsel(below & (qb <= hi), qb, q);
    }
    *inside = (q >= lo) & (q <= hi);
    return q;
}

/* How far inside its limits (with their 1e-9 slack, less SR_LIMIT_AIM) some whole
 * turn puts joint j at chain angles v: >= 0 inside, < 0 outside (by how much);
 * a large value for a joint whose range is a whole turn or more. */
ALWAYS_INLINE vd limit_margin(const SR *K, int j, vd v)
{
    const double tp = 2.0 * M_PI;
    double lo = K->lo[j] - SR_LIMIT_SLACK + SR_LIMIT_AIM;
    double span = K->hi[j] + SR_LIMIT_SLACK - SR_LIMIT_AIM - lo;
    if (span >= tp)
        return BR(1.0);
    vd x = K->sign[j] * (v - K->off[j]) - lo;
    vd u = x - tp * vfloor(x * (1.0 / tp)); /* [0, 2 pi) */
    vd in = vmin(u, span - u), out = -vmin(u - span, tp - u);
    return vsel(u <= span, in, out);
}

/* ------------------------------------------------------------------ outputs */

/* One pose's outputs: Q (8 x 6), valid, singular, within limits (8 each). */
typedef struct {
    double *Q;
    unsigned char *valid, *sing, *inside;
} Slots;

/* All slots empty: invalid, not singular, not within limits (their rows are
 * filled with NaN at the end, slots_finish: written once). */
static void slots_clear(Slots o)
{
    memset(o.valid, 0, 8);
    memset(o.sing, 0, 8);
    memset(o.inside, 0, 8);
}

/* NaN in the rows of the slots that hold no solution (rows that are not solutions) */
static void slots_finish(Slots o)
{
    for (int k = 0; k < 8; k++)
        if (!o.valid[k])
            for (int j = 0; j < 6; j++)
                o.Q[6 * k + j] = NAN;
}

/* Where lane l's solution goes: its pose's outputs and slot (slot < 0: nowhere). */
typedef struct {
    Slots o;
    int slot;
} Dest;

/* Write the solutions v (chain angles, 6 lanes-vectors) of the lanes in ok to their
 * destinations: joint coordinates, valid, singular, within limits. Returns the
 * lanes whose every joint is within its limits. */
ALWAYS_INLINE vl lanes_write(const SR *K, const Dest *dst, const vd *v, vl ok, vl sing)
{
    vd q[6];
    vl all = BRL(-1);
    for (int j = 0; j < 6; j++) {
        vl in;
        q[j] = ljoint(K, j, v[j], &in);
        all &= in;
    }
    for (int l = 0; l < W; l++) {
        if (!ok[l] || dst[l].slot < 0)
            continue;
        Slots o = dst[l].o;
        int k = dst[l].slot;
        for (int j = 0; j < 6; j++)
            o.Q[6 * k + j] = q[j][l];
        o.valid[k] = 1;
        o.sing[k] = sing[l] != 0;
        o.inside[k] = all[l] != 0;
    }
    return all;
}

/* ---------------------------------------------------------- the wrist split */

/* Functions of the free angle evaluated W at a time: f[i] (i < nf) >= 0 where the
 * solution of branch i is acceptable. */
#define SPLIT_NF 4
typedef void (*SplitEval)(const void *ctx, vd x, vd *f);
#define SPLIT_GRID 64   /* grid intervals over the window */
#define SPLIT_SECT 8    /* interior points per refinement pass */
#define SPLIT_PASSES 17 /* (1/9)^17: 1.7e-16 of a grid interval */

/* f at n points xs into fv[n][nf], SPLIT_SECT (or fewer) points per pass so the
 * points do not depend on W. */
static void split_eval(const void *ctx, SplitEval ev, int nf, const double *xs, int n,
                       double (*fv)[SPLIT_NF])
{
    for (int b = 0; b < n; b += W) {
        vd x, f[SPLIT_NF];
        for (int l = 0; l < W; l++)
            x[l] = xs[b + l < n ? b + l : b];
        ev(ctx, x, f);
        for (int l = 0; l < W && b + l < n; l++)
            for (int i = 0; i < nf; i++)
                fv[b + l][i] = f[i][l];
    }
}

/* The boundary of {f_i >= 0} in [a, b] (fa = f_i(a), fb = f_i(b) on opposite sides):
 * 8-section to rounding; returns its end on the acceptable side. */
static double split_boundary(const void *ctx, SplitEval ev, int nf, int i, double a,
                             double b, int a_ok)
{
    for (int pass = 0; pass < SPLIT_PASSES; pass++) {
        double xs[SPLIT_SECT], fv[SPLIT_SECT][SPLIT_NF];
        for (int k = 0; k < SPLIT_SECT; k++)
            xs[k] = a + (b - a) * (k + 1) / (SPLIT_SECT + 1);
        split_eval(ctx, ev, nf, xs, SPLIT_SECT, fv);
        int k = 0; /* the first point past the change, scanning from a */
        while (k < SPLIT_SECT && (fv[k][i] >= 0.0) == a_ok)
            k++;
        double na = k ? xs[k - 1] : a, nb = k < SPLIT_SECT ? xs[k] : b;
        if (na == a && nb == b)
            break;
        a = na;
        b = nb;
    }
    return a_ok ? a : b;
}

/* The largest f_i on [a, b] by 8-section (a local maximum), stopping early at an
 * acceptable point; returns its argument, *fm its value. */
static double split_maximum(const void *ctx, SplitEval ev, int nf, int i, double a,
                            double b, double *fm)
{
    double best = 0.5 * (a + b), fbest = -INFINITY;
    for (int pass = 0; pass < 2 * SPLIT_PASSES; pass++) {
        double xs[SPLIT_SECT], fv[SPLIT_SECT][SPLIT_NF];
        for (int k = 0; k < SPLIT_SECT; k++)
            xs[k] = a + (b - a) * (k + 1) / (SPLIT_SECT + 1);
        split_eval(ctx, ev, nf, xs, SPLIT_SECT, fv);
        int m = 0;
        for (int k = 1; k < SPLIT_SECT; k++)
            if (fv[k][i] > fv[m][i])
                m = k;
        if (fv[m][i] > fbest) {
            fbest = fv[m][i];
            best = xs[m];
        }
        if (fbest >= 0.0)
            break;
        double na = m ? xs[m - 1] : a, nb = m < SPLIT_SECT - 1 ? xs[m + 1] : b;
        if (na == a && nb == b)
            break;
        a = na;
        b = nb;
    }
    *fm = fbest;
    return best;
}

/* The search grid: SPLIT_GRID intervals over [c - half, c + half], c in the middle,
 * and every function's values on it. */
typedef struct {
    const void *ctx;
    SplitEval ev;
    int nf, circle; /* circle: the window is the whole turn */
    double c, h, g[SPLIT_GRID + 1], fv[SPLIT_GRID + 1][SPLIT_NF];
} SplitGrid;

static void split_grid(SplitGrid *G, const void *ctx, SplitEval ev, int nf, double c,
                       double half)
{
    G->ctx = ctx;
    G->ev = ev;
    G->nf = nf;
    G->c = c;
    G->circle = half >= M_PI;
    G->h = 2.0 * half / SPLIT_GRID;
    for (int k = 0; k <= SPLIT_GRID; k++)
        G->g[k] = c - half + G->h * k;
    G->g[SPLIT_GRID / 2] = c;
    split_eval(ctx, ev, nf, G->g, SPLIT_GRID + 1, G->fv);
}

/* The point of the grid's window nearest c where f_i >= 0 into *x; 0 when none was
 * found. Grid intervals are visited outward from c (stopping once nothing nearer
 * than the best found can remain): every change of sign is refined to its
 * boundary; every grid point that is a local maximum of a negative f_i is searched
 * for a narrow acceptable window (two constraints nearly at odds). */
static int split_find(const SplitGrid *G, int i, double *x)
{
    const int M = SPLIT_GRID / 2;
    const double (*fv)[SPLIT_NF] = G->fv;
    const double *g = G->g;
    *x = G->c;
    if (fv[M][i] >= 0.0)
        return 1;
    double best = INFINITY;
    for (int j = 0; j < M && j * G->h < best; j++) {
        /* the intervals [k, k + 1] at distance j h, and their outer grid points (the
         * centre too, first) as local maxima */
        int ks[2] = {M - 1 - j, M + j}, ms[3] = {M, M - 1 - j, M + j + 1};
        double cand[6];
        int nc = 0;
        for (int side = 0; side < 2; side++) {
            int k = ks[side];
            if ((fv[k][i] >= 0.0) != (fv[k + 1][i] >= 0.0))
                cand[nc++] = split_boundary(G->ctx, G->ev, G->nf, i, g[k], g[k + 1],
                                            fv[k][i] >= 0.0);
        }
        for (int n = j ? 1 : 0; n < 3; n++) {
            /* on the full circle the two ends are one point, between 63 and 1 */
            int m = ms[n], wrap = G->circle && m == 0;
            if (G->circle && m == SPLIT_GRID)
                continue;
            double fl = wrap ? fv[SPLIT_GRID - 1][i] : m > 0 ? fv[m - 1][i] : INFINITY;
            double fr = m < SPLIT_GRID ? fv[m + 1][i] : INFINITY;
            /* a plateau (no solution there: f held at its floor) is no maximum */
            if (fv[m][i] >= 0.0 || fv[m][i] < fl || fv[m][i] < fr ||
                (fv[m][i] == fl && fv[m][i] == fr))
                continue;
            double a = wrap ? g[0] - G->h : g[m - 1], b = g[m + 1], fm;
            double xm = split_maximum(G->ctx, G->ev, G->nf, i, a, b, &fm);
            if (fm >= 0.0) {
                cand[nc++] = split_boundary(G->ctx, G->ev, G->nf, i, a, xm, 0);
                cand[nc++] = split_boundary(G->ctx, G->ev, G->nf, i, xm, b, 1);
            }
        }
        for (int n = 0; n < nc; n++) {
            double d = fabs(remainder(cand[n] - G->c, 2.0 * M_PI));
            if (d < best) {
                best = d;
                *x = cand[n];
            }
        }
    }
    return best < INFINITY;
}

/* ------------------------------------------------------------------ polish */

/* Damped Newton steps on the chain for the configurations q (joint coordinates,
 * lanes) against the targets tt, in the lanes of `active` not yet within the
 * kernel's tolerance (tolp, tolr): lm.c's task_space_step with the damping the
 * squared error (so near a singular Jacobian a step stays small), a step kept only
 * where it lowers the error. The pose (top 3x4) and Jacobian of the final q into
 * t, J (row stride NMAX), its error into e; returns the lanes that moved. */
ALWAYS_INLINE vl lanes_newton(const SR *K, const Chain *ch, vd *q, const vd *tt, vl active,
                              vd *t, vd *J, vd *e)
{
    vd Jw[6][NMAX], dq[NMAX];
    chain_pose_jac(ch, q, t, J, NMAX);
    pose_residual(t, tt, e, BRL(-1));
    vl moved = BRL(0);
    for (int it = 0; it < SR_POLISH_ITERS; it++) {
        vd ep = e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
        vd er = e[3] * e[3] + e[4] * e[4] + e[5] * e[5];
        vl todo = active & ~((ep <= K->tolp * K->tolp) & (er <= K->tolr * K->tolr)) &
                  vfinite(ep + er);
        if (!vany(todo))
            break;
        for (int r = 0; r < 6; r++)
            for (int j = 0; j < 6; j++)
                Jw[r][j] = J[r * NMAX + j];
        vd cost = ep + er;
        task_space_step(Jw, e, cost, 6, 6, dq);
        vd qn[MAXJ], tn[12], Jn[6 * NMAX], en[6];
        for (int j = 0; j < 6; j++)
            qn[j] = q[j] + dq[j];
        chain_pose_jac(ch, qn, tn, Jn, NMAX);
        pose_residual(tn, tt, en, BRL(-1));
        vd cn = en[0] * en[0] + en[1] * en[1] + en[2] * en[2] + en[3] * en[3] +
                en[4] * en[4] + en[5] * en[5];
        vl acc = todo & (cn < cost);
        if (!vany(acc))
            break;
        moved |= acc;
        for (int j = 0; j < 6; j++)
            q[j] = vsel(acc, qn[j], q[j]);
        for (int i = 0; i < 12; i++)
            t[i] = vsel(acc, tn[i], t[i]);
        for (int i = 0; i < 6 * NMAX; i++)
            J[i] = vsel(acc, Jn[i], J[i]);
        for (int r = 0; r < 6; r++)
            e[r] = vsel(acc, en[r], e[r]);
    }
    return moved;
}

/* Lanes whose pose error e is within the guarantee (twice the kernel's tolerance) */
ALWAYS_INLINE vl within_guarantee(const SR *K, const vd *e)
{
    vd ep = e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
    vd er = e[3] * e[3] + e[4] * e[4] + e[5] * e[5];
    return (ep <= 4.0 * K->tolp * K->tolp) & (er <= 4.0 * K->tolr * K->tolr);
}

/* Check the solutions of one pose in the slots of `mask` against the chain (their
 * pose error [m], [rad] against T, chain.h's FK and residual); polish those above
 * the tolerance (lanes_newton); drop those still above the guarantee (the pose lies
 * outside the workspace by more than that); flag the others singular where the
 * Jacobian's smallest singular value (chain.h's jac_sigma_min6, at the final
 * configuration, position rows per unit of the arm's size) is below SR_SING_TOL.
 * W slots at a time; rows rewritten. */
static void sr_check(const SR *K, const Chain *ch, const double *T, Slots o, unsigned mask)
{
    int idx[8], m = 0;
    for (int k = 0; k < 8; k++)
        if ((mask >> k & 1u) && o.valid[k])
            idx[m++] = k;
    vd tt[12];
    for (int i = 0; i < 12; i++)
        tt[i] = BR(T[i]);
    for (int b = 0; b < m; b += W) {
        vd q[MAXJ], t[12], J[6 * NMAX], e[6];
        for (int j = 0; j < 6; j++)
            for (int l = 0; l < W; l++)
                q[j][l] = o.Q[6 * idx[b + l < m ? b + l : b] + j];
        vl moved = lanes_newton(K, ch, q, tt, BRL(-1), t, J, e);
        vl off = ~within_guarantee(K, e);
        for (int l = 0; l < W && b + l < m; l++)
            if (off[l]) {
                int k = idx[b + l];
                o.valid[k] = o.sing[k] = o.inside[k] = 0;
                for (int j = 0; j < 6; j++)
                    o.Q[6 * k + j] = NAN;
            }
        moved &= ~off;
        for (int i = 0; i < 3 * NMAX; i++) /* position rows per unit of the arm's size */
            J[i] *= 1.0 / K->size;
        vl sing = jac_sigma_min6(J, NMAX) < K->stol;
        vd v[6];
        for (int j = 0; j < 6; j++)
            v[j] = K->sign[j] * q[j] + K->off[j];
        Dest dst[W];
        for (int l = 0; l < W; l++) {
            dst[l].o = o;
            dst[l].slot = b + l < m && moved[l] ? idx[b + l] : -1;
            if (b + l < m && !off[l])
                o.sing[idx[b + l]] = sing[l] != 0;
        }
        if (vany(moved))
            lanes_write(K, dst, v, moved, sing);
    }
}

/* The lanes of `active` whose solution v (chain angles, updated) is within the
 * split's budget on the chain after lanes_newton's steps (near another
 * singularity rounding leaves the other joints 1e-12 off the configuration at
 * the preferred split: a few steps move them) */
static vl within_split(const SR *K, const Chain *ch, vd *v, const vd *tt, vl active)
{
    vd q[MAXJ], t[12], J[6 * NMAX], e[6];
    for (int j = 0; j < 6; j++)
        q[j] = K->sign[j] * (v[j] - K->off[j]);
    lanes_newton(K, ch, q, tt, active, t, J, e);
    for (int j = 0; j < 6; j++)
        v[j] = K->sign[j] * q[j] + K->off[j];
    vd ep = e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
    vd er = e[3] * e[3] + e[4] * e[4] + e[5] * e[5];
    return active & (ep <= 0.8 * 0.8 * K->tolp * K->tolp) &
           (er <= K->split_tol * K->split_tol);
}

/* A valid solution of one pose just outside the limits, near a singularity (where
 * solutions are ill-conditioned: rounding moves them by more than the 1e-9 slack
 * of the limits, and configurations within it of each other reproduce the pose):
 * damped Newton steps (as sr_check's: damping mu times the squared error, so they
 * reach along the Jacobian's near-null directions; mu grows tenfold after a
 * rejected step) from it clamped into the limits, every step clamped too and
 * joints pressed outward at a limit held there (an active set); the result
 * replaces the row when it meets the pose tolerance. One slot, in every lane. */
/* Whether the rescued solution v (chain angles, lane 0) is another valid slot's
 * inside the limits (every joint within SR_SAME of it, angles modulo 2 pi): then
 * the slot keeps its own solution, outside the limits, rather than repeat one */
#define SR_SAME 1e-7
static int rescue_lands_on_another(const SR *K, Slots o, int slot, const vd *v)
{
    double q[6];
    for (int j = 0; j < 6; j++) {
        vl in;
        q[j] = ljoint(K, j, v[j], &in)[0];
    }
    for (int k = 0; k < 8; k++) {
        if (k == slot || !o.valid[k] || !o.inside[k])
            continue;
        int same = 1;
        for (int j = 0; j < 6 && same; j++)
            same = fabs(remainder(q[j] - o.Q[6 * k + j], 2.0 * M_PI)) <= SR_SAME;
        if (same)
            return 1;
    }
    return 0;
}

static void sr_rescue(const SR *K, const Chain *ch, const double *T, Slots o, int slot)
{
    double far = 0.0;
    vd q[MAXJ], t[12], J[6 * NMAX], e[6], tt[12], lo[6], hi[6];
    for (int j = 0; j < 6; j++) {
        double v = o.Q[6 * slot + j];
        far = fmax(far, fmax(K->lo[j] - v, v - K->hi[j]));
        lo[j] = BR(K->lo[j]);
        hi[j] = BR(K->hi[j]);
        q[j] = vmin(vmax(BR(v), lo[j]), hi[j]);
    }
    if (!(far <= (o.sing[slot] ? SR_RESCUE_REACH : SR_RESCUE_NEAR)))
        return;
    for (int i = 0; i < 12; i++)
        tt[i] = BR(T[i]);
    chain_pose_jac(ch, q, t, J, NMAX);
    pose_residual(t, tt, e, BRL(-1));
    vd cost = BR(0.0);
    for (int r = 0; r < 6; r++)
        cost += e[r] * e[r];
    double mu = 1.0;
    for (int it = 0; it < SR_RESCUE_ITERS; it++) {
        vd ep = e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
        vd er = e[3] * e[3] + e[4] * e[4] + e[5] * e[5];
        if ((ep <= K->tolp * K->tolp)[0] && (er <= K->tolr * K->tolr)[0])
            break;
        vd Jw[6][NMAX], dq[NMAX], qn[MAXJ], tn[12], Jn[6 * NMAX], en[6];
        for (int j = 0; j < 6; j++) {
            vd g = BR(0.0); /* the descent direction J^T e of joint j */
            for (int r = 0; r < 6; r++)
                g += J[r * NMAX + j] * e[r];
            vl held = ((q[j] >= hi[j]) & (g > 0.0)) | ((q[j] <= lo[j]) & (g < 0.0));
            for (int r = 0; r < 6; r++)
                Jw[r][j] = vsel(held, BR(0.0), J[r * NMAX + j]);
        }
        task_space_step(Jw, e, mu * cost, 6, 6, dq);
        for (int j = 0; j < 6; j++)
            qn[j] = vmin(vmax(q[j] + dq[j], lo[j]), hi[j]);
        chain_pose_jac(ch, qn, tn, Jn, NMAX);
        pose_residual(tn, tt, en, BRL(-1));
        vd cn = BR(0.0);
        for (int r = 0; r < 6; r++)
            cn += en[r] * en[r];
        if (!(cn[0] < cost[0])) { /* rejected: more damping (Levenberg-Marquardt) */
            mu *= 10.0;
            if (mu > 1e8)
                break;
            continue;
        }
        mu = fmax(mu * 0.1, 1.0);
        cost = cn;
        for (int j = 0; j < 6; j++)
            q[j] = qn[j];
        for (int i = 0; i < 6 * NMAX; i++)
            J[i] = Jn[i];
        for (int r = 0; r < 6; r++)
            e[r] = en[r];
    }
    vd ep = e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
    vd er = e[3] * e[3] + e[4] * e[4] + e[5] * e[5];
    if (!((ep <= 2.56 * K->tolp * K->tolp)[0] && (er <= 2.56 * K->tolr * K->tolr)[0]))
        return; /* kept within 80 % of the guarantee (tolp is half of it) */
    vd v[6];
    for (int j = 0; j < 6; j++)
        v[j] = K->sign[j] * q[j] + K->off[j];
    if (rescue_lands_on_another(K, o, slot, v))
        return;
    Dest dst[W];
    for (int k = 0; k < W; k++) {
        dst[k].o = o;
        dst[k].slot = k == 0 ? slot : -1;
    }
    lanes_write(K, dst, v, BRL(-1), BRL(o.sing[slot] ? -1 : 0));
}

/* ------------------------------------------------------------- the target */

/* The poses T[l] (4 x 4, row-major) as lanes: their top 3x4 into tt. */
static void lanes_pose(const double *const *T, vd *tt)
{
    for (int i = 0; i < 12; i++) {
        vd x = BR(0.0);
        for (int l = 0; l < W; l++)
            x[l] = T[l][i];
        tt[i] = x;
    }
}

/* Rows of R06 = R_T R_M^T and the position p of the poses T[l] (4 x 4, row-major). */
static void lanes_target(const SR *K, const double *const *T, LM3 *R, L3 *p)
{
    L3 *rows[3] = {&R->r0, &R->r1, &R->r2};
    for (int l = 0; l < W; l++) {
        p->x[l] = T[l][3];
        p->y[l] = T[l][7];
        p->z[l] = T[l][11];
    }
    for (int i = 0; i < 3; i++) {
        vd x = BR(0.0), y = BR(0.0), z = BR(0.0);
        for (int l = 0; l < W; l++) {
            x[l] = T[l][4 * i];
            y[l] = T[l][4 * i + 1];
            z[l] = T[l][4 * i + 2];
        }
        L3 ti = {x, y, z};
        *rows[i] = (L3){l3_dotc(ti, K->rm0), l3_dotc(ti, K->rm1), l3_dotc(ti, K->rm2)};
    }
}

/* The shoulder, theta1 by subproblem 4 (both families): joints 2 on do not change
 * the component along h2 of the point ow, so h2 . R1^T pw = h2 . (ow - o1) with
 * pw = p - R06 (t - ow) - o1 (returned). */
ALWAYS_INLINE LRoots lanes_shoulder(const SR *K, const LM3 *R, L3 p, L3 *pw)
{
    *pw = l3_subc(l3_sub(p, lm3_mvc(R, K->tw)), K->o[0]);
    vd hk = l3_dotc(*pw, K->h[0]);
    vd A = l3_dotc(*pw, K->h[1]) - hk * K->h12;
    vd B = l3_dotc(*pw, K->h1x2);
    vd rhs = K->rhs1 - hk * K->h12;
    vd phi = vatan2(B, A), cphi, sphi;
    vunit(A, B, &cphi, &sphi);
    return lsp4(A, B, rhs, A * A + B * B - rhs * rhs, K->dtol, K->mirror, phi, cphi, sphi);
}

/* What family_block starts from (lanes): R06 and the poses' entries, the
 * shoulder's roots (theta1) and pw, R06 h6, joint 6's preferred chain angle at the
 * wrist singularity (from q6n), and one destination per lane (o[l]). */
typedef struct {
    LM3 R;
    L3 pw, g6;
    LRoots r1;
    vd tt[12], pref;
    Dest dst[W];
} BlockStart;

ALWAYS_INLINE void block_start(const SR *K, const double *const *T, const double *q6n,
                               Slots *o, BlockStart *b)
{
    L3 p;
    lanes_target(K, T, &b->R, &p);
    lanes_pose(T, b->tt);
    b->r1 = lanes_shoulder(K, &b->R, p, &b->pw);
    b->g6 = lm3_mvc(&b->R, K->h[5]);
    b->pref = BR(0.0);
    for (int l = 0; l < W; l++) {
        b->pref[l] = K->sign[5] * q6n[l] + K->off[5];
        b->dst[l].o = o[l];
    }
}

/* Shoulder branch i1 of a block: R06 and theta1's cosine and sine into the first
 * fields of the family's context. */
ALWAYS_INLINE void block_branch(const BlockStart *b, int i1, LM3 *R, vd *c1, vd *s1)
{
    *R = b->R;
    *c1 = b->r1.c[i1];
    *s1 = b->r1.s[i1];
}

/* Lane l of those fields, broadcast to every lane (the split searches' contexts). */
ALWAYS_INLINE void lane_shoulder(const LM3 *R, vd c1, vd s1, int l, LM3 *Rl, vd *c1l,
                                 vd *s1l)
{
    Rl->r0 = (L3){BR(R->r0.x[l]), BR(R->r0.y[l]), BR(R->r0.z[l])};
    Rl->r1 = (L3){BR(R->r1.x[l]), BR(R->r1.y[l]), BR(R->r1.z[l])};
    Rl->r2 = (L3){BR(R->r2.x[l]), BR(R->r2.y[l]), BR(R->r2.z[l])};
    *c1l = BR(c1[l]);
    *s1l = BR(s1[l]);
}

/* ------------------------------------------------ three parallel axes (UR) */

/* A three-parallel pose with theta1 and theta5 chosen (lanes): what theta2-theta4
 * need. */
typedef struct {
    LM3 R;
    vd c1, s1, c5, s5, pl1, pl2, dh;
} TPCtx;

/* The planar two-link step for theta3 (lanes): theta2 by subproblem 1 in the plane
 * normal to h2 (rot(h2, theta2) u = d, u = a + rot(h3, theta3) b), theta4 from the
 * sum theta234; |u|'s in-plane length into *un (|d|'s when theta3 solves the elbow). */
ALWAYS_INLINE void tp_planar(const SR *K, vd d1, vd d2, vd th234, vd th3, vd c3, vd s3,
                             vd *th2, vd *th4, vd *un)
{
    vd sg = K->s3 * s3;
    vd u1 = K->a1 + c3 * K->b1 - sg * K->b2;
    vd u2 = K->a2 + sg * K->b1 + c3 * K->b2;
    *th2 = vatan2(u1 * d2 - u2 * d1, u1 * d1 + u2 * d2);
    *th4 = K->s4 * (th234 - *th2 - K->s3 * th3);
    *un = vsqrt(u1 * u1 + u2 * u2);
}

/* Theta2-theta4 of both elbow branches for theta6 (lanes): theta2 + theta3 +
 * theta4 by subproblem 1 (planar), theta3 by subproblem 3 in the plane normal to
 * h2 (as 4), then tp_planar. */
typedef struct {
    LRoots r3;
    vd th[2][3]; /* [branch]: theta2, theta3, theta4 */
    vd disc;     /* the elbow's discriminant */
    vd d1, d2, th234;
} TPArm;

ALWAYS_INLINE void tp_arm(const SR *K, const TPCtx *c, vd c6, vd s6, TPArm *a)
{
    L3 w = l3_rot(K->h[5], c6, -s6, l3_rotc(K->h[4], c->c5, -c->s5, K->e));
    w = l3_rot(K->h[0], c->c1, -c->s1, lm3_mv(&c->R, w));
    vd we = l3_dotc(w, K->e), we2 = l3_dotc(w, K->e2), c234, s234;
    vd th234 = vatan2(we2, we);
    vunit(we, we2, &c234, &s234);
    vd d1 = c->pl1 - (c234 * K->w41 - s234 * K->w42); /* d = pl - rot(h2, th234) w4 */
    vd d2 = c->pl2 - (s234 * K->w41 + c234 * K->w42);
    vd rhs3 = 0.5 * (d1 * d1 + d2 * d2 + c->dh * c->dh - K->aa - K->bb) - K->ec;
    a->disc = K->er2 - rhs3 * rhs3;
    a->r3 = elbow_roots(K, rhs3);
    a->d1 = d1;
    a->d2 = d2;
    a->th234 = th234;
    for (int i3 = 0; i3 < 2; i3++) {
        vd un;
        a->th[i3][1] = a->r3.t[i3];
        tp_planar(K, d1, d2, th234, a->r3.t[i3], a->r3.c[i3], a->r3.s[i3], &a->th[i3][0],
                  &a->th[i3][2], &un);
    }
}

/* The split search's functions for a three-parallel pose (one pose in every lane):
 * per elbow branch, acceptable within the limits (f[0], f[1]) and solvable
 * (f[2], f[3]). */
typedef struct {
    const SR *K;
    TPCtx c;
    vd th1, th5;
    double wc, wh; /* the window: theta6 within wh of wc (none: wh >= pi) */
} TPSplit;

/* How far inside the window [wc - wh, wc + wh] (on the circle) angles x are */
ALWAYS_INLINE vd window_margin(double wc, double wh, vd x)
{
    return wh >= M_PI ? BR(1.0) : wh - vabs(vwrap_pi(x - wc));
}

static void tp_split_eval(const void *ctx, vd th6, vd *f)
{
    const TPSplit *s = ctx;
    const SR *K = s->K;
    vd c6, s6;
    vsincos(th6, &s6, &c6);
    TPArm a;
    tp_arm(K, &s->c, c6, s6, &a);
    /* the elbow's subproblem has a root within SR_SPLIT_DISC (the boundary root:
     * at a tangency, the only one), two distinct ones past twice the double-root
     * threshold */
    vd rel = a.disc * (1.0 / K->er2);
    vd fixed = vmin(limit_margin(K, 0, s->th1), limit_margin(K, 4, s->th5));
    fixed = vmin(fixed, limit_margin(K, 5, th6));
    vd win = window_margin(s->wc, s->wh, th6);
    for (int i3 = 0; i3 < 2; i3++) {
        vd sv = i3 ? rel - 2e-3 * K->dtol : rel + SR_SPLIT_DISC;
        sv = vmin(sv, win);
        vd m = fixed;
        for (int j = 0; j < 3; j++)
            m = vmin(m, limit_margin(K, j + 1, a.th[i3][j]));
        /* inside the limits where solvable, far below zero where not (so that a
         * narrow acceptable window, a joint at an extremum at its limit, is a local
         * maximum of f, not hidden by the solvability boundary next to it) */
        f[i3] = vsel(sv >= 0.0, vmin(m, win), BR(-10.0));
        f[2 + i3] = sv;
    }
}

/* Lane l of a block at a (near-)singular wrist whose solution is not acceptable:
 * theta6 from the split search (each elbow branch), its slots rewritten. */
static void tp_split(const SR *K, const TPCtx *c, int l, vd th1v, vd th5v, double th6,
                     double wc, double half, double sw, double gap1, Slots o, int i1,
                     int i5, unsigned char *need)
{
    TPSplit s;
    s.K = K;
    s.wc = wc;
    s.wh = half;
    s.th1 = BR(th1v[l]);
    s.th5 = BR(th5v[l]);
    lane_shoulder(&c->R, c->c1, c->s1, l, &s.c.R, &s.c.c1, &s.c.s1);
    s.c.c5 = BR(c->c5[l]);
    s.c.s5 = BR(c->s5[l]);
    s.c.pl1 = BR(c->pl1[l]);
    s.c.pl2 = BR(c->pl2[l]);
    s.c.dh = BR(c->dh[l]);
    /* per elbow branch: inside the limits, else only solvable; where neither is
     * found, a window 16 times wider (up to the whole turn): rounding near another
     * singularity (a shoulder near its double root) can move the exact theta6 by
     * more than the window, and sr_check then holds the result to the guarantee */
    int found[2] = {0, 0}, inside[2] = {0, 0};
    double step[2] = {0.0, 0.0};
    vd th6v = BR(th6);
    for (;;) {
        SplitGrid G;
        split_grid(&G, &s, tp_split_eval, 4, th6,
                   fmin(M_PI, half + fabs(remainder(th6 - wc, 2.0 * M_PI))));
        for (int i3 = 0; i3 < 2; i3++) {
            double x;
            if (found[i3])
                continue;
            inside[i3] = split_find(&G, i3, &x);
            if (inside[i3] || split_find(&G, 2 + i3, &x)) {
                found[i3] = 1;
                th6v[i3] = x;
                step[i3] = G.h;
            }
        }
        if ((found[0] && found[1]) || half >= M_PI)
            break;
        half = fmin(M_PI, 16.0 * half);
        s.wh = half;
    }
    /* only solvable: the solvable window may be narrower than the grid's step (an
     * elbow near full stretch), and an in-limit split inside it narrower still (a
     * joint at its limit): a grid of its own over a step either side */
    for (int i3 = 0; i3 < 2; i3++) {
        double x;
        if (!found[i3] || inside[i3])
            continue;
        SplitGrid G;
        split_grid(&G, &s, tp_split_eval, 4, th6v[i3], step[i3]);
        if (split_find(&G, i3, &x))
            th6v[i3] = x;
    }
    vd c6, s6;
    vsincos(th6v, &s6, &c6);
    TPArm a;
    tp_arm(K, &s.c, c6, s6, &a);
    /* lane i3 holds elbow branch i3's solution */
    vd v[6];
    vl ok = BRL(0), sing = BRL(0);
    for (int i3 = 0; i3 < 2; i3++) {
        v[0][i3] = th1v[l];
        v[1][i3] = a.th[i3][0][i3];
        v[2][i3] = a.th[i3][1][i3];
        v[3][i3] = a.th[i3][2][i3];
        v[4][i3] = th5v[l];
        v[5][i3] = th6v[i3];
        ok[i3] = (i3 ? a.r3.two[i3] : a.r3.one[i3]) && found[i3] ? -1 : 0;
        double sm = fmin(fmin(gap1, sw), a.r3.gap[i3]);
        sing[i3] = sm < K->stol ? -1 : 0;
    }
    for (int l2 = 2; l2 < W; l2++)
        for (int j = 0; j < 6; j++)
            v[j][l2] = v[j][0];
    Dest dst[W];
    for (int k = 0; k < W; k++) {
        dst[k].o = o;
        dst[k].slot = k < 2 && ok[k] ? 4 * i1 + 2 * k + i5 : -1;
    }
    lanes_write(K, dst, v, ok, sing);
    for (int i3 = 0; i3 < 2; i3++)
        if (ok[i3])
            need[4 * i1 + 2 * i3 + i5] = 1;
}

/* Shoulder branch i1 (lanes m1) of W poses of a three-parallel arm (axes 2, 3, 4
 * parallel, axes 5, 6 meeting; IK-Geo 'three parallel, two intersecting'): theta5
 * (subproblem 4 on h2 . R5 h6 = h2 . R1^T R06 h6), theta6 (subproblem 1; the split at
 * the wrist singularity, see the header), then tp_arm. *any_mid gets the lanes whose
 * wrist solves, *any_ok those with a solution. */
static void tp_branch(const SR *K, const Chain *ch, BlockStart *b, int i1, vl m1,
                      unsigned char (*need)[8], int nl, vl *any_mid, vl *any_ok)
{
    TPCtx c;
    block_branch(b, i1, &c.R, &c.c1, &c.s1);
    vd th1 = b->r1.t[i1];
    L3 x = l3_rot(K->h[0], c.c1, -c.s1, b->g6); /* R1^T R06 h6 */
    LRoots r5 = wrist_roots(K, K->h[1], x);
    vl mw = m1 & r5.one;
    *any_mid |= mw;
    if (!vany(mw))
        return;
    L3 y = lm3_mtv(&b->R, l3_rotc(K->h[0], c.c1, c.s1, K->h[1])); /* R06^T R1 h2 */
    L3 yp = l3_perp(K->h[5], y);
    vd sw = vsqrt(l3_dot(yp, yp));
    vl free_ = sw < K->free_tol, nearby = sw < SR_SPLIT_BAND;
    L3 pl = l3_subc(l3_rot(K->h[0], c.c1, -c.s1, b->pw), K->o21); /* R1^T pw - o21 */
    c.pl1 = l3_dotc(pl, K->e);
    c.pl2 = l3_dotc(pl, K->e2);
    c.dh = l3_dotc(pl, K->h[1]) - K->w4h;
    vd gap1 = vmin(b->r1.gap, sw);
    vl check1 = ~b->r1.two | ~r5.two | (gap1 < SR_CHECK_BAND) | BRL(K->check > 0.0 ? -1 : 0);
    for (int i5 = 0; i5 < 2; i5++) {
        vl m5 = m1 & (i5 ? r5.two & ~free_ : r5.one);
        if (!vany(m5))
            continue;
        c.c5 = r5.c[i5];
        c.s5 = r5.s[i5];
        vd th5 = r5.t[i5], c6, s6;
        vd th6 = lsp1(K->h[5], y, l3_rotc(K->h[4], c.c5, -c.s5, K->h[1]), &c6, &s6);
        vd exact = th6, half = wrist_split(K, sw, b->pref, &th6, &c6, &s6);
        TPArm a, ap;
        tp_arm(K, &c, c6, s6, &a);
        /* the preferred theta6 with theta5 at its singular value (the double
         * root: rounding near another singularity can leave it 1e-12 off) */
        vl tryp = m5 & pref_untried(sw, b->pref, th6) & BRL(i5 == 0 ? -1 : 0);
        vd th5s = BR(0.0);
        if (vany(tryp)) {
            TPCtx cs = c;
            vd cp, sp;
            th5s = wrist_double_root(K, x, K->h[1], &cs.c5, &cs.s5);
            vsincos(b->pref, &sp, &cp);
            tp_arm(K, &cs, cp, sp, &ap);
        } else {
            ap = a;
        }
        /* not acceptable: the elbow unsolvable, or solvable only within the
         * kernel's tolerance (its boundary root leaves up to 3e-12 m at a folded
         * elbow), or a joint outside its limits */
        vl bad = BRL(0);
        for (int i3 = 0; i3 < 2; i3++) {
            int slot = 4 * i1 + 2 * i3 + i5;
            vd v[6] = {th1, a.th[i3][0], a.th[i3][1], a.th[i3][2], th5, th6};
            vl ok = m5 & (i3 ? a.r3.two : a.r3.one);
            vd gap = vmin(gap1, a.r3.gap);
            vl shaky = ~a.r3.one | (a.disc < -SR_SPLIT_DISC * K->er2);
            vl usep = tryp & (i3 ? ap.r3.two : ap.r3.one);
            if (vany(usep)) { /* the preferred theta6 as it is, where the chain agrees */
                vd vp[6] = {th1, ap.th[i3][0], ap.th[i3][1], ap.th[i3][2], th5s, b->pref};
                usep = within_split(K, ch, vp, b->tt, usep);
                for (int j = 0; j < 6; j++)
                    v[j] = vsel(usep, vp[j], v[j]);
                ok |= usep;
                shaky &= ~usep;
                gap = vsel(usep, vmin(gap1, ap.r3.gap), gap);
            }
            vl sing = gap < K->stol;
            for (int l = 0; l < W; l++)
                b->dst[l].slot = slot;
            vl in = lanes_write(K, b->dst, v, ok, sing);
            bad |= (i3 ? BRL(0) : shaky) | (ok & ~in);
            vl chk = ok & (check1 | ~a.r3.two | (a.r3.gap < SR_CHECK_BAND) | usep);
            for (int l = 0; l < W; l++)
                if (chk[l])
                    need[l][slot] = 1;
            *any_ok |= ok;
        }
        vl split = m5 & (free_ | nearby) & bad;
        if (vany(split))
            for (int l = 0; l < nl; l++) {
                if (!split[l])
                    continue;
                tp_split(K, &c, l, th1, th5, th6[l], free_[l] ? th6[l] : exact[l],
                         half[l], sw[l], gap1[l], b->dst[l].o, i1, i5, need[l]);
                for (int i3 = 0; i3 < 2; i3++)
                    if (b->dst[l].o.valid[4 * i1 + 2 * i3 + i5])
                        (*any_ok)[l] = -1;
            }
    }
}

/* ----------------------------------------------------- spherical wrist (Puma) */

/* A spherical-wrist pose with theta1-theta3 and theta5 chosen (lanes). */
typedef struct {
    LM3 R;
    vd c1, s1, c23, s23, c5, s5;
} SWCtx;

/* theta4 for theta6 (lanes): R4 = rot(h4, theta4) takes e to the wrist's
 * (R1 R23)^T R06 R6^T R5^T e (subproblem 1; e is perpendicular to h4). */
ALWAYS_INLINE vd sw_theta4(const SR *K, const SWCtx *c, vd c6, vd s6)
{
    L3 w = l3_rot(K->h[5], c6, -s6, l3_rotc(K->h[4], c->c5, -c->s5, K->e));
    w = l3_rot(K->h[0], c->c1, -c->s1, lm3_mv(&c->R, w));
    w = l3_rot(K->h[1], c->c23, -c->s23, w);
    return vatan2(l3_dotc(w, K->e2), l3_dotc(w, K->e));
}

typedef struct {
    const SR *K;
    SWCtx c;
    vd fixed; /* the limit margin of joints 1, 2, 3, 5 */
    double wc, wh; /* the window, as TPSplit's */
} SWSplit;

static void sw_split_eval(const void *ctx, vd th6, vd *f)
{
    const SWSplit *s = ctx;
    vd c6, s6;
    vsincos(th6, &s6, &c6);
    vd th4 = sw_theta4(s->K, &s->c, c6, s6);
    f[0] = vmin(s->fixed, vmin(limit_margin(s->K, 3, th4), limit_margin(s->K, 5, th6)));
    f[0] = vmin(f[0], window_margin(s->wc, s->wh, th6));
}

/* Lane l of a block at a (near-)singular wrist whose solution is outside the
 * limits: theta6 from the split search, its slot rewritten. */
static void sw_split(const SR *K, const SWCtx *c, int l, const vd *v0, double wc,
                     double half, int sing, Slots o, int slot, unsigned char *need)
{
    SWSplit s;
    s.K = K;
    s.wc = wc;
    s.wh = half;
    lane_shoulder(&c->R, c->c1, c->s1, l, &s.c.R, &s.c.c1, &s.c.s1);
    s.c.c23 = BR(c->c23[l]);
    s.c.s23 = BR(c->s23[l]);
    s.c.c5 = BR(c->c5[l]);
    s.c.s5 = BR(c->s5[l]);
    s.fixed = BR(INFINITY);
    for (int j = 0; j < 5; j++)
        if (j != 3)
            s.fixed = vmin(s.fixed, limit_margin(K, j, BR(v0[j][l])));
    double x, t6 = v0[5][l];
    SplitGrid G;
    split_grid(&G, &s, sw_split_eval, 1, t6,
               fmin(M_PI, half + fabs(remainder(t6 - wc, 2.0 * M_PI))));
    if (!split_find(&G, 0, &x))
        return;
    vd th6 = BR(x), c6, s6;
    vsincos(th6, &s6, &c6);
    vd v[6];
    for (int j = 0; j < 6; j++)
        v[j] = BR(v0[j][l]);
    v[3] = sw_theta4(K, &s.c, c6, s6);
    v[5] = th6;
    Dest dst[W];
    for (int k = 0; k < W; k++) {
        dst[k].o = o;
        dst[k].slot = k == 0 ? slot : -1;
    }
    lanes_write(K, dst, v, BRL(-1), BRL(sing ? -1 : 0));
    need[slot] = 1;
}

/* Shoulder branch i1 (lanes m1) of W poses of a spherical-wrist arm (axes 2, 3
 * parallel, axes 4, 5, 6 meeting; IK-Geo 'spherical wrist, two parallel'): the wrist
 * centre fixes theta3 (subproblem 3) and theta2 (subproblem 1); then theta5
 * (subproblem 4), theta6 (subproblem 1; the split at the wrist singularity) and
 * theta4 (subproblem 1). *any_mid gets the lanes whose position solves, *any_ok those
 * with a solution. */
static void sw_branch(const SR *K, const Chain *ch, BlockStart *b, int i1, vl m1,
                      unsigned char (*need)[8], int nl, vl *any_mid, vl *any_ok)
{
    SWCtx c;
    block_branch(b, i1, &c.R, &c.c1, &c.s1);
    vd th1 = b->r1.t[i1];
    L3 d = l3_subc(l3_rot(K->h[0], c.c1, -c.s1, b->pw), K->o21);
    vd rhs3 = 0.5 * (l3_dot(d, d) - K->aa - K->bb) - K->ec;
    LRoots r3 = elbow_roots(K, rhs3);
    L3 g61 = l3_rot(K->h[0], c.c1, -c.s1, b->g6);
    for (int i3 = 0; i3 < 2; i3++) {
        vl mask3 = m1 & (i3 ? r3.two : r3.one);
        if (!vany(mask3))
            continue;
        *any_mid |= mask3;
        vd th3 = r3.t[i3], c3 = r3.c[i3], s3 = r3.s[i3], c2, s2;
        L3 u = l3_addc(l3_rotc(K->h[2], c3, s3, K->b), K->a);
        vd th2 = lsp1(K->h[1], u, d, &c2, &s2);
        /* h3 = s3 h2 (snapped): rot(h2, th2) rot(h3, th3) = rot(h2, th2 + s3 th3) */
        vd sg = K->s3 * s3;
        c.c23 = c2 * c3 - s2 * sg;
        c.s23 = s2 * c3 + c2 * sg;
        L3 x = l3_rot(K->h[1], c.c23, -c.s23, g61); /* Rw h6 */
        LRoots r5 = wrist_roots(K, K->h[3], x);
        L3 y = lm3_mtv(&b->R, l3_rot(K->h[0], c.c1, c.s1,
                                  l3_rotc(K->h[1], c.c23, c.s23, K->h[3])));
        L3 yp = l3_perp(K->h[5], y);
        vd sw = vsqrt(l3_dot(yp, yp));
        vl free_ = sw < K->free_tol, nearby = sw < SR_SPLIT_BAND;
        vd gap = vmin(vmin(b->r1.gap, r3.gap), sw);
        vl check = ~b->r1.two | ~r3.two | ~r5.two | (gap < SR_CHECK_BAND) |
                   BRL(K->check > 0.0 ? -1 : 0);
        for (int i5 = 0; i5 < 2; i5++) {
            vl m5 = mask3 & (i5 ? r5.two & ~free_ : r5.one);
            if (!vany(m5))
                continue;
            c.c5 = r5.c[i5];
            c.s5 = r5.s[i5];
            vd th5 = r5.t[i5], c6, s6;
            vd th6 = lsp1(K->h[5], y, l3_rotc(K->h[4], c.c5, -c.s5, K->h[3]), &c6, &s6);
            vd exact = th6, half = wrist_split(K, sw, b->pref, &th6, &c6, &s6);
            vd th4 = sw_theta4(K, &c, c6, s6);
            int slot = 4 * i1 + 2 * i3 + i5;
            vd v[6] = {th1, th2, th3, th4, th5, th6};
            vl usep = m5 & pref_untried(sw, b->pref, th6) & BRL(i5 == 0 ? -1 : 0);
            if (vany(usep)) { /* the preferred theta6 as it is, theta5 at the double
                               * root, where the chain agrees */
                SWCtx cs = c;
                vd cp, sp, th5s = wrist_double_root(K, x, K->h[3], &cs.c5, &cs.s5);
                vsincos(b->pref, &sp, &cp);
                vd vp[6] = {th1, th2, th3, sw_theta4(K, &cs, cp, sp), th5s, b->pref};
                usep = within_split(K, ch, vp, b->tt, usep);
                for (int j = 0; j < 6; j++)
                    v[j] = vsel(usep, vp[j], v[j]);
            }
            for (int l = 0; l < W; l++)
                b->dst[l].slot = slot;
            vl sing = gap < K->stol;
            vl in = lanes_write(K, b->dst, v, m5, sing);
            *any_ok |= m5;
            for (int l = 0; l < W; l++)
                if ((m5 & (check | usep))[l])
                    need[l][slot] = 1;
            vl split = m5 & ~in & (free_ | nearby);
            if (vany(split))
                for (int l = 0; l < nl; l++)
                    if (split[l])
                        sw_split(K, &c, l, v, free_[l] ? th6[l] : exact[l], half[l],
                                 sing[l] != 0, b->dst[l].o, slot, need[l]);
        }
    }
}

/* Every solution of W poses T[l] of the family K->family: theta1 (subproblem 4, the
 * shared block_start), then each shoulder branch by tp_branch or sw_branch. Lane l's
 * outputs go to o[l] and need[l] (slots to check against the chain), its status to
 * status[l]: no orientation when the position solves (three parallel: the shoulder
 * solves and no wrist does), else out of reach. */
static void family_block(const SR *K, const Chain *ch, const double *const *T,
                         const double *q6n, Slots *o, int *status,
                         unsigned char (*need)[8], int nl)
{
    BlockStart b;
    block_start(K, T, q6n, o, &b);
    const int wrist = K->family == SR_SPHERICAL_WRIST;
    vl any_mid = BRL(0), any_ok = BRL(0);
    for (int i1 = 0; i1 < 2; i1++) {
        vl m1 = i1 ? b.r1.two : b.r1.one;
        if (!vany(m1))
            continue;
        if (wrist)
            sw_branch(K, ch, &b, i1, m1, need, nl, &any_mid, &any_ok);
        else
            tp_branch(K, ch, &b, i1, m1, need, nl, &any_mid, &any_ok);
    }
    vl no_orientation = wrist ? any_mid : b.r1.one & ~any_mid;
    for (int l = 0; l < W; l++)
        status[l] = any_ok[l] ? SR_OK : no_orientation[l] ? SR_NO_ORIENTATION
                                                          : SR_OUT_OF_REACH;
}

/* ------------------------------------------------------------------ blocks */

/* Up to W poses T[l] (the first nl; the others repeat pose 0 and are not written)
 * of the family K->family, with joint-6 values q6n[l] at the wrist singularity:
 * every solution into o[l], status[l]; then the solutions near a boundary or a
 * singularity checked against the chain and polished (ch may be NULL: no check). */
static void six_r_block(const SR *K, const Chain *ch, const double *const *T,
                        const double *q6n, Slots *o, signed char *status, int nl)
{
    Slots own[W];
    double scratch[W][48];
    unsigned char flags[W][24];
    for (int l = 0; l < W; l++) {
        if (l < nl) {
            own[l] = o[l];
        } else {
            own[l] = (Slots){scratch[l], flags[l], flags[l] + 8, flags[l] + 16};
        }
        slots_clear(own[l]);
    }
    unsigned char need[W][8];
    memset(need, 0, sizeof(need));
    int st[W];
    family_block(K, ch, T, q6n, own, st, need, nl);
    for (int l = 0; l < nl; l++) {
        status[l] = (signed char)st[l];
        if (ch == NULL || K->check < 0.0)
            continue;
        unsigned mask = 0;
        for (int k = 0; k < 8; k++)
            mask |= (unsigned)(need[l][k] != 0) << k;
        if (mask)
            sr_check(K, ch, T[l], own[l], mask);
        for (int k = 0; k < 8; k++)
            if (need[l][k] && own[l].valid[k] && !own[l].inside[k])
                sr_rescue(K, ch, T[l], own[l], k);
    }
    for (int l = 0; l < nl; l++)
        slots_finish(own[l]);
}

/* --------------------------------------------------------------- entries */

#define SR_F64(a) ((double *)PyArray_DATA((PyArrayObject *)(a)))
#define SR_U8(a) ((unsigned char *)PyArray_DATA((PyArrayObject *)(a)))
#define SR_DIM(a, d) (PyArray_DIMS(a)[d])

/* A batch: poses T (N x 16), joint-6 values at the wrist singularity from qn
 * (m x 6, row i % m), outputs per pose. */
typedef struct {
    const SR *K;
    const Chain *ch;
    const double *T, *qn;
    long m;
    double *Q;
    unsigned char *valid, *sing, *inside;
    signed char *status;
} SixRJob;

/* Poses [b, e) of a batch (a pool task), W at a time. */
static void six_r_range(void *ctx, long b, long e)
{
    const SixRJob *jb = ctx;
    for (long i = b; i < e; i += W) {
        int nl = e - i < W ? (int)(e - i) : W;
        const double *T[W];
        double q6[W];
        Slots o[W];
        for (int l = 0; l < W; l++) {
            long k = i + (l < nl ? l : 0);
            T[l] = jb->T + 16 * k;
            q6[l] = jb->qn[6 * (k % jb->m) + 5];
            o[l] = (Slots){jb->Q + 48 * k, jb->valid + 8 * k, jb->sing + 8 * k,
                           jb->inside + 8 * k};
        }
        six_r_block(jb->K, jb->ch, T, q6, o, jb->status + i, nl);
    }
}

/* whether params (SR_N_PARAMS values) is a parameter vector of a known family */
static int six_r_params_ok(const double *P)
{
    return P[SR_FAMILY] == SR_THREE_PARALLEL || P[SR_FAMILY] == SR_SPHERICAL_WRIST;
}

#include "ik_outputs.h"

/* six_r_ik1(T, params, q6, packed) -> (code, Q (8, 6), valid (8,), singular (8,),
 * within_limits (8,)): one pose, validated in the same call (pose_problem's tests,
 * as check_poses). code >= BAD_POSE: nothing was solved and the arrays are None
 * (BAD_POSE + pose_problem's code, or BAD_POSE itself when T is not a float64
 * (4, 4) array); the caller takes its general, validating path. The fast path for
 * one pose: METH_FASTCALL, no pool, T read through its strides, lane 0 of a block. */
static PyObject *six_r_ik1_body(const six_r_ik1_args *a)
{
    const double *P = a->params;
    double q6 = a->q6;
    const Chain ch = a->packed;
    int code = SR_BAD_POSE;
    double T[16];
    code = ik_read_pose(a->T, T, SR_BAD_POSE);
    if (code)
        return Py_BuildValue("(iOOOO)", code, Py_None, Py_None, Py_None, Py_None);
    PyObject *out[4];
    if (!ik_outputs(0, 0, 6, out))
        return NULL;
    SR K;
    sr_read(P, &K);
    const double *Tl[W];
    double q6l[W];
    Slots o[W];
    for (int l = 0; l < W; l++) {
        Tl[l] = T;
        q6l[l] = q6;
        o[l] = (Slots){SR_F64(out[0]), SR_U8(out[1]), SR_U8(out[2]), SR_U8(out[3])};
    }
    signed char st;
    six_r_block(&K, &ch, Tl, q6l, o, &st, 1);
    return ik_result(st, out);
}

/* six_r_ik(params, T (N, 4, 4), qn (m, 6), packed) -> (Q (N, 8, 6), valid,
 * singular, within_limits (N, 8), status (N,) int8): a batch, not validated (the
 * caller checked the poses); joint 6 at the wrist singularity is qn[i % m, 5].
 * Batches of PARALLEL_MIN poses or more run on the pool. */
static PyObject *six_r_ik_body(const six_r_ik_args *a)
{
    const double *P = a->params;
    npy_intp N = a->N;
    PyObject *out[4], *status;
    if (!ik_outputs(1, N, 6, out) || !ik_status(N, out, &status))
        return NULL;
    SR K;
    sr_read(P, &K);
    SixRJob jb = {&K, &a->packed, a->T, a->qn, (long)a->m, SR_F64(out[0]),
                  SR_U8(out[1]), SR_U8(out[2]), SR_U8(out[3]),
                  (signed char *)PyArray_DATA((PyArrayObject *)status)};
    return ik_run_batch(N, SR_PARALLEL_MIN, SR_GRAIN, six_r_range, &jb, out, status);
}

/* atan2(y (N,), x (N,), out (N,)): the kernels' atan2 (for tests) */
static PyObject *atan2_body(const atan2_args *a)
{
    npy_intp N = a->N;
    for (npy_intp i = 0; i < N; i += W) {
        vd yv, xv;
        for (int l = 0; l < W; l++) {
            yv[l] = a->y[i + l < N ? i + l : i];
            xv[l] = a->x[i + l < N ? i + l : i];
        }
        vd r = vatan2(yv, xv);
        for (int l = 0; l < W && i + l < N; l++)
            a->out[i + l] = r[l];
    }
    Py_RETURN_NONE;
}


/* Subproblem 4 of every row of x (N, 7) = [A, B, rhs, disc, phi, cos phi, sin phi],
 * in lanes (lsp4) into lane and one row at a time (subproblems.h's sp4_roots) into
 * one, each row [t0, t1, c0, c1, s0, s1, roots, two]; for the test tying them. */
static PyObject *sp4_pair_body(const sp4_pair_args *a)
{
    npy_intp N = a->N;
    for (npy_intp i = 0; i < N; i += W) {
        double buf[7][W];
        vd in[7];
        for (int j = 0; j < 7; j++) {
            for (int l = 0; l < W; l++)
                buf[j][l] = a->x[7 * (i + l < N ? i + l : i) + j];
            memcpy(&in[j], buf[j], sizeof(vd));
        }
        LRoots r = lsp4(in[0], in[1], in[2], in[3], a->tol, a->mirror, in[4], in[5], in[6]);
        for (int l = 0; l < W && i + l < N; l++) {
            const double *x = a->x + 7 * (i + l);
            Roots q = sp4_roots(x[0], x[1], x[2], x[3], a->tol, a->mirror, x[4], x[5], x[6]);
            double *o = a->lane + 8 * (i + l), *p = a->one + 8 * (i + l);
            const double lv[8] = {r.t[0][l], r.t[1][l], r.c[0][l], r.c[1][l], r.s[0][l],
                                  r.s[1][l], r.one[l] ? 1.0 : 0.0, r.two[l] ? 1.0 : 0.0};
            const double sv[8] = {q.t[0], q.t[1], q.c[0], q.c[1], q.s[0], q.s[1],
                                  q.n >= 1 ? 1.0 : 0.0, q.n == 2 ? 1.0 : 0.0};
            memcpy(o, lv, sizeof(lv));
            memcpy(p, sv, sizeof(sv));
        }
    }
    Py_RETURN_NONE;
}
