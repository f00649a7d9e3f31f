/*
 * The self-motion of an SRS arm (axes 1-3 meet in the shoulder S, 5-7 in the
 * wrist W: the KUKA iiwa type) over its swivel angle psi, compiled: the twin of
 * robokin/kinematics/ik/swivel.py (its numpy version is the tests' reference;
 * the formulas, slots and conventions are the same, line for line).
 *
 *   swivel_rows:     every configuration (8 slots, slot = 4 elbow + 2 shoulder +
 *                    wrist, each 0 / 1 the + / - root of its subproblem 4) of
 *                    poses T at swivel angles psi, Newton-polished where the
 *                    pose error exceeds 1e-13 (dropped above 5e-13), singular
 *                    flags (a triple's outer axes in line);
 *   swivel_manifold: the exact intervals of psi inside every joint limit, per
 *                    branch, and the points where a branch meets a limit or has
 *                    a triple's outer axes in line.
 *
 * Limits exactly (Shimizu et al. 2008): joint j of a triple at chain angle L is
 * one condition x . rot(u, phi) y = k on the swivel (u the shoulder-wrist
 * direction, phi = psi - psi0 at the shoulder, psi0 - psi at the wrist): a
 * subproblem 4, A cos phi + B sin phi = C, i.e. a quadratic in tan(phi / 2): at
 * most two swivel angles per joint, limit and elbow root. Every change of a
 * branch's state (inside the limits or not, existing or not) happens at one of
 * those angles (existence changes where a triple's middle angle reaches an end
 * of its range, the same condition with L that end), so the state is constant
 * between consecutive ones and decided at the midpoint: the intervals are
 * exact, with no grid.
 *
 * The parameter vector (swivel.py's SwivelArm.pack writes it; Python reads the
 * SM_ indices from the module constants):
 *
 *   SM_H, SM_O    unit joint axes h_k and points o_k at zero chain values (7 x 3)
 *   SM_S, SM_W    the shoulder and wrist points (3 each)
 *   SM_MR, SM_MT  the tool pose at zero: rotation rows (9), translation (3)
 *   SM_SIGN, SM_OFFSET, SM_LO, SM_HI   per joint (7 each): v = sign q + offset, limits
 *   SM_REF        the swivel's reference direction (axis 1) (3)
 *   SM_TAG        SM_TAG_VALUE
 *   SM_ARC        per joint (7 x 4) the quick limit test's constants (sm_arc): the cosine
 *                 and sine of the chain angle at the middle of the limits, cos(w - m) +
 *                 pad and cos(w + m) - pad (w half the range, SM_QUICK_M, SM_QUICK_PAD),
 *                 or (0, 0, 2, -2) where the test does not apply
 *   SM_LIMCS      per joint and limit (7 x 2 x 2) the cosine and sine of the limit's
 *                 chain angle sign lim + offset
 *   SM_FOLDCS     per triple (2 x 2) the cosine and sine of the middle angle where the
 *                 outer axes are nearest (the fold / aligned value, sm_candidates' base)
 *
 * References: Shimizu, Kakuya, Yoon, Kitagaki and Kosuge, "Analytical inverse
 * kinematic computation for 7-DOF redundant manipulators with joint limits and
 * its application to redundancy resolution", IEEE T-RO 24(5), 2008; Elias and
 * Wen, "IK-Geo", arXiv:2211.05737 (subproblems 1 and 4).
 */
#include "chain.h"
#include "pool.h"
#include "vec3.h"

enum {
    SM_H = 0, SM_O = 21, SM_S = 42, SM_W = 45, SM_MR = 48, SM_MT = 57, SM_SIGN = 60,
    SM_OFFSET = 67, SM_LO = 74, SM_HI = 81, SM_REF = 88, SM_TAG = 91, SM_ARC = 92,
    SM_LIMCS = 120, SM_FOLDCS = 148, SM_N_PARAMS = 152
};
#define SM_TAG_VALUE 2008.0625 /* Shimizu et al.'s year, and a sixteenth */
#define SM_MAXI 40             /* intervals per branch (at most 33 cells per elbow) */
#define SM_MAXP 256            /* points per pose: 32 swivel angles per elbow, 4 branches */
#define SM_KIND_LOWER 0
#define SM_KIND_UPPER 1
#define SM_KIND_ALIGNED 2
#define SM_KIND_FOLD 3
#define SM_DOUBLE 1e-12  /* a subproblem-4 |C| past its amplitude by this (relative): a double root */
#define SM_EXACT 1e-13   /* pose errors below it need no polish */
#define SM_ACCEPT 5e-13  /* pose errors above it after the polish: dropped */
#define SM_SAME 1e-6     /* a branch's joint this near a value [rad]: at it */
#define SM_ORTHO 1e-12   /* a triple whose middle axis is this near normal to both others:
                          * its middle angle from the cross product (sm_split_ortho) */
#define SM_LINED 1e-15   /* outer axes this near one line (|xa|): the first angle set to 0;
                          * flagged singular below 1e-9 (sm_first) */
#define SM_GRAIN 16      /* poses per pool chunk */
/* self_motion_intervals' _PAIR and _POINT (they read these): swivel_manifold_one's
 * "close" flag is set when two crossings of a branch lie within SM_PAIR in psi, a
 * crossing within it of an end of [-pi, pi], or an interval is at most SM_POINT long */
#define SM_PAIR 1e-6
#define SM_POINT 1e-12
/* The quick tests (sm_quick_*): a cell's or a point's verdict from the cosines and
 * sines of its angles, without atan2 / acos, where it is certain; else the exact
 * test. The cosine-sine pairs stand for the exact path's angles to 1.1e-8 rad (the
 * middle angle next to the end of its range: sqrt(1 - x^2) of a rounded x); a
 * joint decided quickly is at least SM_QUICK_M from its limits, a point's joint
 * below 0.9 or above 1.1 SM_SAME from the value (chord^2 thresholds). */
#define SM_QUICK_M 1e-6
#define SM_QUICK_PAD 5e-8
#define SM_AT_IN (0.9e-6 * 0.9e-6)
#define SM_AT_OUT (1.1e-6 * 1.1e-6)
#define SM_PARALLEL_MIN 64

static int sm_params_ok(const double *P) { return P[SM_TAG] == SM_TAG_VALUE; }

/* ------------------------------------------------------------ geometry */

typedef struct {
    v3 h[7], o[7], S, Wp, MT, ref;
    v3 perp[2]; /* sm_perp of the shoulder's and the wrist's last axis (h_3, h_7) */
    m3 MR;
    const double *sign, *offset, *lo, *hi, *arc, *limcs, *foldcs;
} SmArm;

typedef struct {
    v3 u, r;
    double v4[2], psi0[2];
    int elbow_real, ref_ok;
    m3 R0[2], R4[2], TR; /* R4: the elbow's rotation rot(h4, v4) per root */
} SmFrame;

/* The rotation about unit axis k with cosine c and sine s */
static inline m3 sm_rotm_cs(v3 k, double c, double s)
{
    double v = 1.0 - c;
    return (m3){{c + k.x * k.x * v, k.x * k.y * v - k.z * s, k.x * k.z * v + k.y * s},
                {k.y * k.x * v + k.z * s, c + k.y * k.y * v, k.y * k.z * v - k.x * s},
                {k.z * k.x * v - k.y * s, k.z * k.y * v + k.x * s, c + k.z * k.z * v}};
}

static inline m3 sm_rotm(v3 k, double t) { return sm_rotm_cs(k, cos(t), sin(t)); }

static inline m3 sm_mul(const m3 *A, const m3 *B) /* A B */
{
    m3 out;
    v3 *o = &out.r0;
    const v3 *a = &A->r0;
    for (int i = 0; i < 3; i++)
        o[i] = v3_add(v3_add(v3_scale(B->r0, a[i].x), v3_scale(B->r1, a[i].y)),
                      v3_scale(B->r2, a[i].z));
    return out;
}

static inline m3 sm_tr(const m3 *A)
{
    return (m3){{A->r0.x, A->r1.x, A->r2.x}, {A->r0.y, A->r1.y, A->r2.y},
                {A->r0.z, A->r1.z, A->r2.z}};
}

static inline double sm_norm(v3 a) { return sqrt(v3_dot(a, a)); }

/* Subproblem 4 (swivel.py _sp4): the angles t with x . rot(h, t) y = c, as
 * A cos t + B sin t = C; returns whether they are real. */
/* Subproblem 4's A, B, C and rho = hypot(A, B); returns whether its roots are real */
static int sm_sp4_abc(v3 h, v3 x, v3 y, double c, double *A, double *B, double *C, double *rho)
{
    v3 ypar = v3_scale(h, v3_dot(h, y)), yp = v3_sub(y, ypar);
    *A = v3_dot(x, yp);
    *B = v3_dot(x, v3_cross(h, yp));
    *C = c - v3_dot(x, ypar);
    *rho = hypot(*A, *B);
    return fabs(*C) <= *rho * (1.0 + SM_DOUBLE) + 1e-300 && *rho > 0.0;
}

static int sm_sp4_rho(v3 h, v3 x, v3 y, double c, double *tp, double *tm, double *A, double *B,
                      double *C, double *rho_out)
{
    int real = sm_sp4_abc(h, x, y, c, A, B, C, rho_out);
    double rho = *rho_out;
    double d = rho > 0.0 ? acos(fmax(-1.0, fmin(1.0, *C / rho))) : NAN;
    double phi = atan2(*B, *A);
    *tp = phi + d;
    *tm = phi - d;
    return real;
}

static int sm_sp4(v3 h, v3 x, v3 y, double c, double *tp, double *tm, double *A, double *B,
                  double *C)
{
    double rho;
    return sm_sp4_rho(h, x, y, c, tp, tm, A, B, C, &rho);
}

/* Subproblem 1 (swivel.py _sp1): the angle about h from x to y; *spread = |x's
 * part normal to h| */
ALWAYS_INLINE double sm_sp1(v3 h, v3 x, v3 y, double *spread)
{
    v3 xp = v3_sub(x, v3_scale(h, v3_dot(h, x))), yp = v3_sub(y, v3_scale(h, v3_dot(h, y)));
    *spread = sm_norm(xp);
    return atan2(v3_dot(h, v3_cross(xp, yp)), v3_dot(xp, yp));
}

/* sm_sp1 with its atan2 arguments (y, x) into xy[1], xy[0] (the same angle) */
ALWAYS_INLINE double sm_sp1_xy(v3 h, v3 x, v3 y, double *xy)
{
    v3 xp = v3_sub(x, v3_scale(h, v3_dot(h, x))), yp = v3_sub(y, v3_scale(h, v3_dot(h, y)));
    double Y = v3_dot(h, v3_cross(xp, yp)), X = v3_dot(xp, yp);
    xy[0] = X;
    xy[1] = Y;
    return atan2(Y, X);
}

/* A unit vector normal to h: the base axis h has least of, less its h part */
static v3 sm_perp(v3 h)
{
    double ax = fabs(h.x), ay = fabs(h.y), az = fabs(h.z);
    v3 e = (ax <= ay && ax <= az) ? (v3){1.0, 0.0, 0.0}
         : (ay <= az) ? (v3){0.0, 1.0, 0.0} : (v3){0.0, 0.0, 1.0};
    e = v3_sub(e, v3_scale(h, v3_dot(e, h)));
    return v3_scale(e, 1.0 / sm_norm(e));
}

static void sm_arm(const double *P, SmArm *a)
{
    for (int k = 0; k < 7; k++) {
        a->h[k] = v3_at(P, SM_H + 3 * k);
        a->o[k] = v3_at(P, SM_O + 3 * k);
    }
    a->S = v3_at(P, SM_S);
    a->Wp = v3_at(P, SM_W);
    a->MT = v3_at(P, SM_MT);
    a->ref = v3_at(P, SM_REF);
    a->MR = (m3){v3_at(P, SM_MR), v3_at(P, SM_MR + 3), v3_at(P, SM_MR + 6)};
    a->sign = P + SM_SIGN;
    a->offset = P + SM_OFFSET;
    a->lo = P + SM_LO;
    a->hi = P + SM_HI;
    a->arc = P + SM_ARC;
    a->limcs = P + SM_LIMCS;
    a->foldcs = P + SM_FOLDCS;
    a->perp[0] = sm_perp(a->h[2]);
    a->perp[1] = sm_perp(a->h[6]);
}

/* Every split of R into rot(ha, va) rot(hb, vb) rot(hc, vc) (swivel.py _triple):
 * v[i] for the middle angle's + / - root; returns whether they are real. The
 * rotations by vb and va are built from the cosines and sines the subproblems
 * give (vb = phi +- d with cos phi = A / rho, cos d = C / rho; va = atan2(y, x)),
 * not from the angles: no sine or cosine is evaluated. */
typedef struct {
    v3 ha, hb, hc, Rhc, ya, e, Re;
    double vb[2], cb[2], sb[2];
    int real, cd_ok; /* cd_ok: |cos d| <= 0.99 (sm_split_root_cs) */
} SmSplit;

/* The middle angle's half-spread d of a triple whose middle axis hb is normal to ha
 * and hc (the SRS arms' shoulders and wrists): there rho = 1 and rho^2 - C^2 =
 * |ha x R hc|^2, so cos d = C, sin d = |ha x R hc| to rounding where the cosine
 * alone (acos, sqrt(1 - x^2)) loses half the digits next to d = 0 or pi (a middle
 * joint 1e-9 from its aligned value came out 0: the row 1e-9 off the pose, which the
 * polish cannot take back on a straight arm). Taken where |cos d| > 0.99 (elsewhere
 * the cosine's d is as exact). Sets (*cd, *sd) (a unit pair); returns 0 (nothing
 * set) for another triple. */
static int sm_split_ortho(v3 ha, v3 hb, v3 hc, v3 Rhc, double C, double *cd, double *sd)
{
    if (!(fabs(v3_dot(ha, hb)) <= SM_ORTHO && fabs(v3_dot(hb, hc)) <= SM_ORTHO))
        return 0;
    double S = sm_norm(v3_cross(ha, Rhc)), n = hypot(C, S);
    if (!(n > 0.0))
        return 0;
    *cd = C / n;
    *sd = S / n;
    return 1;
}

/* The middle angle's roots of the split of R (with their cosines and sines); e =
 * sm_perp(hc) (the arm's constant) */
static void sm_split(v3 ha, v3 hb, v3 hc, v3 e, const m3 *R, SmSplit *t)
{
    double tp, tm, A, B, C, rho;
    t->ha = ha;
    t->hb = hb;
    t->hc = hc;
    t->Rhc = m3_mv(R, hc);
    t->real = sm_sp4_rho(hb, ha, hc, v3_dot(ha, t->Rhc), &tp, &tm, &A, &B, &C, &rho);
    double x = rho > 0.0 ? fmax(-1.0, fmin(1.0, C / rho)) : NAN; /* rho: hypot(A, B) */
    double cp = A / rho, sp = B / rho, cd = x, sd = sqrt(1.0 - x * x);
    t->cd_ok = fabs(x) <= 0.99;
    if (!t->cd_ok && sm_split_ortho(ha, hb, hc, t->Rhc, C, &cd, &sd)) {
        double d = atan2(sd, cd), phi = atan2(B, A);
        tp = phi + d;
        tm = phi - d;
    }
    t->vb[0] = tp;
    t->vb[1] = tm;
    t->cb[0] = cp * cd - sp * sd;
    t->cb[1] = cp * cd + sp * sd;
    t->sb[0] = sp * cd + cp * sd;
    t->sb[1] = sp * cd - cp * sd;
    t->e = e;
    t->Re = m3_mv(R, t->e);
    t->ya = v3_sub(t->Rhc, v3_scale(ha, v3_dot(ha, t->Rhc)));
}

/* The first angle of root i of a split (its cosine and sine, the middle rotation
 * Rb); sing where the outer axes line up (the first angle set to 0) */
typedef struct {
    m3 Rb;
    double va, ca, sa;
    int sing;
} SmFirst;

ALWAYS_INLINE void sm_first(const SmSplit *t, int i, SmFirst *r)
{
    r->Rb = sm_rotm_cs(t->hb, t->cb[i], t->sb[i]);
    v3 xa = m3_mv(&r->Rb, t->hc);
    xa = v3_sub(xa, v3_scale(t->ha, v3_dot(t->ha, xa)));
    double py = v3_dot(t->ha, v3_cross(xa, t->ya)), px = v3_dot(xa, t->ya), rr = hypot(px, py);
    r->va = atan2(py, px);
    r->ca = rr > 0.0 ? px / rr : 1.0;
    r->sa = rr > 0.0 ? py / rr : 0.0;
    double lined = sm_norm(xa);
    r->sing = lined < 1e-9;
    if (lined < SM_LINED) {
        r->va = 0.0;
        r->ca = 1.0;
        r->sa = 0.0;
    }
}

/* The last angle of a root whose first angle r gives */
ALWAYS_INLINE double sm_last(const SmSplit *t, const SmFirst *r)
{
    m3 Ra = sm_rotm_cs(t->ha, r->ca, r->sa), Bm = sm_mul(&Ra, &r->Rb);
    double dummy;
    return sm_sp1(t->hc, t->e, m3_mtv(&Bm, t->Re), &dummy);
}

/* sm_split_root with each angle's cosine and sine as the closed form has them into cs
 * (3 x 2; 0 where not usable: the middle angle within |cos d| > 0.99 of the end of
 * its range, where sqrt(1 - x^2) and acos(x) part by more than rounding) */
static void sm_split_root_cs(const SmSplit *t, int i, double v[3], int *sing, double cs[3][2])
{
    SmFirst r;
    sm_first(t, i, &r);
    *sing = r.sing;
    v[0] = r.va;
    v[1] = t->vb[i];
    m3 Ra = sm_rotm_cs(t->ha, r.ca, r.sa), Bm = sm_mul(&Ra, &r.Rb);
    double xy[2];
    v[2] = sm_sp1_xy(t->hc, t->e, m3_mtv(&Bm, t->Re), xy);
    double n = sqrt(xy[0] * xy[0] + xy[1] * xy[1]);
    cs[0][0] = r.ca;
    cs[0][1] = r.sa;
    cs[1][0] = t->cd_ok ? t->cb[i] : 0.0;
    cs[1][1] = t->cd_ok ? t->sb[i] : 0.0;
    cs[2][0] = n > 0.5 ? xy[0] / n : 0.0;
    cs[2][1] = n > 0.5 ? xy[1] / n : 0.0;
}

/* The outer angles of root i of a split: v (3) chain angles; *sing where the outer
 * axes line up (the first angle set to 0) */
static void sm_split_root(const SmSplit *t, int i, double v[3], int *sing)
{
    SmFirst r;
    sm_first(t, i, &r);
    *sing = r.sing;
    v[0] = r.va;
    v[1] = t->vb[i];
    v[2] = sm_last(t, &r);
}

/* Every split of R into rot(ha, va) rot(hb, vb) rot(hc, vc) (swivel.py _triple):
 * v[i] for the middle angle's + / - root; returns whether they are real. The
 * rotations by vb and va are built from the cosines and sines the subproblems
 * give (vb = phi +- d with cos phi = A / rho, cos d = C / rho; va = atan2(y, x)),
 * not from the angles: no sine or cosine is evaluated. */
static int sm_triple(v3 ha, v3 hb, v3 hc, v3 e, const m3 *R, double v[2][3], int sing[2],
                     double cs[2][3][2])
{
    SmSplit t;
    sm_split(ha, hb, hc, e, R, &t);
    for (int i = 0; i < 2; i++) {
        if (cs)
            sm_split_root_cs(&t, i, v[i], &sing[i], cs[i]);
        else
            sm_split_root(&t, i, v[i], &sing[i]);
    }
    return t.real;
}

/* The smallest rotation taking the direction of a to that of b */
static m3 sm_smallest(v3 a, v3 b)
{
    double na = sm_norm(a), nb = sm_norm(b);
    if (na == 0.0 || nb == 0.0)
        return (m3){{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
    a = v3_scale(a, 1.0 / na);
    b = v3_scale(b, 1.0 / nb);
    v3 ax = v3_cross(a, b);
    double s = sm_norm(ax), c = v3_dot(a, b);
    if (s < 1e-15) {
        if (c > 0.0)
            return (m3){{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
        return sm_rotm(sm_perp(a), M_PI);
    }
    return sm_rotm(v3_scale(ax, 1.0 / s), atan2(s, c));
}

/* The swivel angle: about u from r to u x h4 */
static double sm_angle_of(v3 u, v3 r, v3 h4)
{
    v3 d = v3_cross(u, h4);
    return atan2(v3_dot(u, v3_cross(r, d)), v3_dot(r, d));
}

/* The pose's constants (swivel.py SwivelArm.frame); T row-major 4 x 4 */
static void sm_frame(const SmArm *a, const double *T, SmFrame *f)
{
    m3 TRm = {{T[0], T[1], T[2]}, {T[4], T[5], T[6]}, {T[8], T[9], T[10]}};
    v3 Tt = {T[3], T[7], T[11]};
    m3 MRt = sm_tr(&a->MR);
    v3 Wt = v3_add(m3_mv(&TRm, m3_mv(&MRt, v3_sub(a->Wp, a->MT))), Tt);
    v3 w = v3_sub(Wt, a->S);
    double d = sm_norm(w);
    f->u = d > 0.0 ? v3_scale(w, 1.0 / d) : (v3){0.0, 0.0, 1.0};
    v3 h4 = a->h[3], p = v3_sub(a->Wp, a->o[3]), q = v3_sub(a->S, a->o[3]);
    double A, B, C;
    f->elbow_real = sm_sp4(h4, q, p, 0.5 * (v3_dot(p, p) + v3_dot(q, q) - d * d), &f->v4[0],
                           &f->v4[1], &A, &B, &C);
    v3 r = v3_sub(a->ref, v3_scale(f->u, v3_dot(a->ref, f->u)));
    f->ref_ok = sm_norm(r) > 1e-9;
    if (!f->ref_ok) {
        v3 x = {1.0, 0.0, 0.0};
        r = v3_sub(x, v3_scale(f->u, v3_dot(x, f->u)));
    }
    f->r = v3_scale(r, 1.0 / sm_norm(r));
    for (int e = 0; e < 2; e++) {
        f->R4[e] = sm_rotm(h4, f->v4[e]);
        v3 ae = v3_sub(v3_add(a->o[3], m3_mv(&f->R4[e], p)), a->S);
        f->R0[e] = sm_smallest(ae, w);
        f->psi0[e] = sm_angle_of(f->u, f->r, m3_mv(&f->R0[e], h4));
    }
    f->TR = sm_mul(&TRm, &MRt);
}

/* A chain angle as the joint coordinate: wrapped, then by 2 pi into the limits
 * where that fits (swivel.py SwivelArm.wrap) */
static inline double sm_joint(const SmArm *a, int j, double v)
{
    double q = wrap_pi((v - a->offset[j]) * a->sign[j]);
    double lo = a->lo[j], hi = a->hi[j];
    if (q < lo && q + 2.0 * M_PI <= hi)
        q += 2.0 * M_PI;
    else if (q > hi && q - 2.0 * M_PI >= lo)
        q -= 2.0 * M_PI;
    return q;
}

static void sm_configs_part(const SmArm *a, const SmFrame *f, int e, double psi, int part,
                            double q[4][7], int ok[4], int sing[4], double cs[4][7][2]);

/* The 4 configurations of elbow root e at swivel angle psi (slots 4 e + 2 s + w,
 * here 2 s + w): joint coordinates q, whether real, singular; cs (or NULL): each
 * shoulder and wrist angle's cosine and sine as the closed form has them
 * (sm_split_root_cs; the elbow's left unset) */
static void sm_configs(const SmArm *a, const SmFrame *f, int e, double psi, double q[4][7],
                       int ok[4], int sing[4], double cs[4][7][2])
{
    sm_configs_part(a, f, e, psi, 3, q, ok, sing, cs);
}

/* sm_configs of the triples in `part` (1 shoulder, 2 wrist, 3 both); the other
 * triple's joints are left NaN and count as real, not singular */
static void sm_configs_part(const SmArm *a, const SmFrame *f, int e, double psi, int part,
                            double q[4][7], int ok[4], int sing[4], double cs[4][7][2])
{
    double csA[2][3][2], csB[2][3][2];
    m3 Ru = sm_rotm(f->u, psi - f->psi0[e]);
    m3 RA = sm_mul(&Ru, &f->R0[e]);
    double sA[2][3] = {{NAN, NAN, NAN}, {NAN, NAN, NAN}}, sB[2][3] = {{NAN, NAN, NAN}, {NAN, NAN, NAN}};
    int gA[2] = {0, 0}, gB[2] = {0, 0}, rA = 1, rB = 1;
    if (part & 1)
        rA = sm_triple(a->h[0], a->h[1], a->h[2], a->perp[0], &RA, sA, gA, cs ? csA : NULL);
    if (part & 2) {
        m3 RAR4 = sm_mul(&RA, &f->R4[e]), X = sm_tr(&RAR4);
        m3 RB = sm_mul(&X, &f->TR);
        rB = sm_triple(a->h[4], a->h[5], a->h[6], a->perp[1], &RB, sB, gB, cs ? csB : NULL);
    }
    int real = f->elbow_real && rA && rB;
    for (int s = 0; s < 2; s++)
        for (int w = 0; w < 2; w++) {
            int k = 2 * s + w;
            ok[k] = real;
            sing[k] = gA[s] || gB[w];
            for (int j = 0; j < 3; j++) {
                q[k][j] = real ? sm_joint(a, j, sA[s][j]) : NAN;
                q[k][4 + j] = real ? sm_joint(a, 4 + j, sB[w][j]) : NAN;
            }
            q[k][3] = real ? sm_joint(a, 3, f->v4[e]) : NAN;
            if (cs && part == 3)
                for (int j = 0; j < 3; j++)
                    for (int c = 0; c < 2; c++) {
                        cs[k][j][c] = csA[s][j][c];
                        cs[k][4 + j][c] = csB[w][j][c];
                    }
        }
}

/* One branch: slot 4 e + b's joint coordinates q (7) at psi, as sm_configs gives
 * them (the same operations on that root only); returns whether it is real. */
static int sm_branch_row(const SmArm *a, const SmFrame *f, int e, int b, double psi, double *q)
{
    m3 Ru = sm_rotm(f->u, psi - f->psi0[e]);
    m3 RA = sm_mul(&Ru, &f->R0[e]);
    SmSplit tA, tB;
    sm_split(a->h[0], a->h[1], a->h[2], a->perp[0], &RA, &tA);
    m3 RAR4 = sm_mul(&RA, &f->R4[e]), X = sm_tr(&RAR4);
    m3 RB = sm_mul(&X, &f->TR);
    sm_split(a->h[4], a->h[5], a->h[6], a->perp[1], &RB, &tB);
    if (!(f->elbow_real && tA.real && tB.real))
        return 0;
    double sA[3], sB[3];
    int g;
    sm_split_root(&tA, b / 2, sA, &g);
    sm_split_root(&tB, b % 2, sB, &g);
    for (int j = 0; j < 3; j++) {
        q[j] = sm_joint(a, j, sA[j]);
        q[4 + j] = sm_joint(a, 4 + j, sB[j]);
    }
    q[3] = sm_joint(a, 3, f->v4[e]);
    return 1;
}

/* Inside every limit with the slack of SelfMotion.inside (chain.h MANIFOLD_SLACK), so
 * that a cell whose row rides a limit to rounding (a branch tangent to it, q = limit
 * + 4e-16) is decided as .inside decides it. */
static int sm_inside_joint(const SmArm *a, int j, double q)
{
    return q >= a->lo[j] - MANIFOLD_SLACK && q <= a->hi[j] + MANIFOLD_SLACK;
}

/* every joint of a row inside its limits (with the membership slack) */
static int sm_row_inside(const SmArm *a, const double q[7])
{
    for (int j = 0; j < 7; j++)
        if (!sm_inside_joint(a, j, q[j]))
            return 0;
    return 1;
}

/* The quick twin of sm_split: the middle angle's cosines and sines (cb, sb) and
 * whether it is real, computed as sm_split does, without the angles (acos, atan2) */
static void sm_split_quick(v3 ha, v3 hb, v3 hc, v3 e, const m3 *R, SmSplit *t)
{
    t->ha = ha;
    t->hb = hb;
    t->hc = hc;
    t->Rhc = m3_mv(R, hc);
    double A, B, C, rho;
    t->real = sm_sp4_abc(hb, ha, hc, v3_dot(ha, t->Rhc), &A, &B, &C, &rho);
    double x = rho > 0.0 ? fmax(-1.0, fmin(1.0, C / rho)) : NAN;
    double cp = A / rho, sp = B / rho, cd = x, sd = sqrt(1.0 - x * x);
    if (!(fabs(x) <= 0.99))
        sm_split_ortho(ha, hb, hc, t->Rhc, C, &cd, &sd);
    t->cb[0] = cp * cd - sp * sd;
    t->cb[1] = cp * cd + sp * sd;
    t->sb[0] = sp * cd + cp * sd;
    t->sb[1] = sp * cd - cp * sd;
    t->e = e;
    t->Re = m3_mv(R, t->e);
    t->ya = v3_sub(t->Rhc, v3_scale(ha, v3_dot(ha, t->Rhc)));
}

/* The quick limit test of joint j at the chain angle with cosine c and sine s: 1
 * inside its limits by more than SM_QUICK_M, 0 outside by more, -1 not certain.
 * Applies where -pi <= lo < hi <= pi (sm_joint's shift by 2 pi never moves an
 * angle in or out there away from the limits): inside iff the angle is within w
 * of the range's middle; cos of that distance c cos v_c + s sin v_c against the
 * thresholds (SM_ARC), padded by SM_QUICK_PAD for the pairs' 1.1e-8 rad. */
static inline int sm_quick_joint(const SmArm *a, int j, double c, double s)
{
    const double *k = a->arc + 4 * j;
    double g = c * k[0] + s * k[1];
    return g > k[2] ? 1 : g < k[3] ? 0 : -1;
}

/* The quick sm_root_inside of root i of a real quick split: 1, 0, or -1 (not certain:
 * the exact test decides) */
static int sm_quick_root_inside(const SmArm *a, int j0, const SmSplit *t, int i)
{
    int v = sm_quick_joint(a, j0 + 1, t->cb[i], t->sb[i]);
    if (v != 1)
        return v;
    m3 Rb = sm_rotm_cs(t->hb, t->cb[i], t->sb[i]);
    v3 xa = m3_mv(&Rb, t->hc);
    xa = v3_sub(xa, v3_scale(t->ha, v3_dot(t->ha, xa)));
    double py = v3_dot(t->ha, v3_cross(xa, t->ya)), px = v3_dot(xa, t->ya);
    double ca = 1.0, sa = 0.0;
    if (!(sm_norm(xa) < SM_LINED)) { /* else aligned: the first angle 0, as sm_first */
        double rr = sqrt(px * px + py * py);
        if (!(rr > 1e-100))
            return -1;
        ca = px / rr;
        sa = py / rr;
    }
    v = sm_quick_joint(a, j0, ca, sa);
    if (v != 1)
        return v;
    m3 Ra = sm_rotm_cs(t->ha, ca, sa), Bm = sm_mul(&Ra, &Rb);
    v3 h = t->hc, x = t->e, y = m3_mtv(&Bm, t->Re);
    v3 xp = v3_sub(x, v3_scale(h, v3_dot(h, x))), yp = v3_sub(y, v3_scale(h, v3_dot(h, y)));
    double Y = v3_dot(h, v3_cross(xp, yp)), X = v3_dot(xp, yp), r = sqrt(X * X + Y * Y);
    if (!(r > 0.5))
        return -1;
    return sm_quick_joint(a, j0 + 2, X / r, Y / r);
}

/* The quick point test: whether the chain angle (c, s) of root i's joint is within
 * SM_SAME of the candidate's value (cv, sv): 1, 0, or -1 (not certain) */
static inline int sm_quick_at(double c, double s, double cv, double sv)
{
    double dx = c - cv, dy = s - sv, d2 = dx * dx + dy * dy;
    return d2 < SM_AT_IN ? 1 : d2 > SM_AT_OUT ? 0 : -1;
}

/* The cosine and sine of joint j's chain angle on root i of a real quick split (as
 * sm_quick_root_inside computes them); returns 0 where not certain */
static int sm_quick_angle(const SmSplit *t, int k, int i, double *c, double *s)
{
    if (k == 1) {
        *c = t->cb[i];
        *s = t->sb[i];
        return 1;
    }
    m3 Rb = sm_rotm_cs(t->hb, t->cb[i], t->sb[i]);
    v3 xa = m3_mv(&Rb, t->hc);
    xa = v3_sub(xa, v3_scale(t->ha, v3_dot(t->ha, xa)));
    double py = v3_dot(t->ha, v3_cross(xa, t->ya)), px = v3_dot(xa, t->ya);
    double ca = 1.0, sa = 0.0;
    if (!(sm_norm(xa) < SM_LINED)) {
        double rr = sqrt(px * px + py * py);
        if (!(rr > 1e-100))
            return 0;
        ca = px / rr;
        sa = py / rr;
    }
    if (k == 0) {
        *c = ca;
        *s = sa;
        return 1;
    }
    m3 Ra = sm_rotm_cs(t->ha, ca, sa), Bm = sm_mul(&Ra, &Rb);
    v3 h = t->hc, x = t->e, y = m3_mtv(&Bm, t->Re);
    v3 xp = v3_sub(x, v3_scale(h, v3_dot(h, x))), yp = v3_sub(y, v3_scale(h, v3_dot(h, y)));
    double Y = v3_dot(h, v3_cross(xp, yp)), X = v3_dot(xp, yp), r = sqrt(X * X + Y * Y);
    if (!(r > 0.5))
        return 0;
    *c = X / r;
    *s = Y / r;
    return 1;
}

/* The rotation triple `part` (1 the shoulder, 2 the wrist) of elbow root e must make
 * at psi (sm_configs_part's) */
static inline m3 sm_part_rotation(const SmFrame *f, int e, double psi, int part)
{
    m3 Ru = sm_rotm(f->u, psi - f->psi0[e]);
    m3 RA = sm_mul(&Ru, &f->R0[e]);
    if (part == 1)
        return RA;
    m3 RAR4 = sm_mul(&RA, &f->R4[e]), X = sm_tr(&RAR4);
    return sm_mul(&X, &f->TR);
}

/* sm_part_split's quick twin (sm_split_quick) */
static void sm_part_split_quick(const SmArm *a, const SmFrame *f, int e, double psi, int part,
                                SmSplit *t)
{
    m3 R = sm_part_rotation(f, e, psi, part);
    int k = part == 1 ? 0 : 4;
    sm_split_quick(a->h[k], a->h[k + 1], a->h[k + 2], a->perp[part - 1], &R, t);
}

/* The split of one triple (part 1 the shoulder, 2 the wrist) of elbow root e at
 * psi: the middle angle's roots, as sm_configs_part computes them */
static void sm_part_split(const SmArm *a, const SmFrame *f, int e, double psi, int part,
                          SmSplit *t)
{
    m3 R = sm_part_rotation(f, e, psi, part);
    int k = part == 1 ? 0 : 4;
    sm_split(a->h[k], a->h[k + 1], a->h[k + 2], a->perp[part - 1], &R, t);
}

/* Whether root i of a real split t of the triple from joint j0 has its three joints
 * inside their limits (sm_triple_inside on sm_configs_part's row): the middle joint
 * first, then the first, then the last, each angle computed only when the joints
 * before it are inside (the same values, the same verdict) */
static int sm_root_inside(const SmArm *a, int j0, const SmSplit *t, int i)
{
    if (!sm_inside_joint(a, j0 + 1, sm_joint(a, j0 + 1, t->vb[i])))
        return 0;
    SmFirst r;
    sm_first(t, i, &r);
    if (!sm_inside_joint(a, j0, sm_joint(a, j0, r.va)))
        return 0;
    return sm_inside_joint(a, j0 + 2, sm_joint(a, j0 + 2, sm_last(t, &r)));
}

/* Joint j (not the elbow) of root i of a real split t of its triple, as
 * sm_configs_part gives it: only the angles up to j's computed */
static double sm_root_joint(const SmArm *a, int j, const SmSplit *t, int i)
{
    int k = j < 3 ? j : j - 4;
    if (k == 1)
        return sm_joint(a, j, t->vb[i]);
    SmFirst r;
    sm_first(t, i, &r);
    return sm_joint(a, j, k == 0 ? r.va : sm_last(t, &r));
}

/* Whether branch b of elbow root e exists at psi with every joint inside its limits
 * (sm_branch_row's row and sm_row_inside's test): the triple `first` (1 the
 * shoulder, 2 the wrist) decided first, each angle computed only when needed */
static int sm_branch_inside(const SmArm *a, const SmFrame *f, int e, int b, double psi,
                            int first)
{
    if (!f->elbow_real || !sm_inside_joint(a, 3, sm_joint(a, 3, f->v4[e])))
        return 0;
    m3 Ru = sm_rotm(f->u, psi - f->psi0[e]);
    m3 RA = sm_mul(&Ru, &f->R0[e]);
    SmSplit t[2];
    for (int n = 0; n < 2; n++) {
        int part = n ? 3 - first : first;
        if (part == 1) {
            sm_split(a->h[0], a->h[1], a->h[2], a->perp[0], &RA, &t[0]);
        } else {
            m3 RAR4 = sm_mul(&RA, &f->R4[e]), X = sm_tr(&RAR4);
            m3 RB = sm_mul(&X, &f->TR);
            sm_split(a->h[4], a->h[5], a->h[6], a->perp[1], &RB, &t[1]);
        }
        if (!t[part - 1].real)
            return 0;
    }
    for (int n = 0; n < 2; n++) {
        int part = n ? 3 - first : first;
        if (!sm_root_inside(a, part == 1 ? 0 : 4, &t[part - 1], part == 1 ? b / 2 : b % 2))
            return 0;
    }
    return 1;
}

/* ------------------------------------------------------------ the polish */

/* Forward kinematics (product of exponentials) of chain angles v: R, p, and the
 * axes h' and points o' of every joint in the base frame */
static void sm_fk(const SmArm *a, const double *v, m3 *R, v3 *p, v3 *hw, v3 *ow)
{
    m3 G = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
    v3 g = {0.0, 0.0, 0.0};
    for (int k = 0; k < 7; k++) {
        hw[k] = m3_mv(&G, a->h[k]);
        ow[k] = v3_add(m3_mv(&G, a->o[k]), g);
        m3 Rk = sm_rotm(a->h[k], v[k]);
        g = v3_add(m3_mv(&G, v3_sub(a->o[k], m3_mv(&Rk, a->o[k]))), g);
        G = sm_mul(&G, &Rk);
    }
    *R = sm_mul(&G, &a->MR);
    *p = v3_add(m3_mv(&G, a->MT), g);
}

/* The error [p_T - p; log(R_T R^T)] (chain.h pose_residual's) and its size:
 * the larger of the position and rotation norms */
static double sm_error(const m3 *RT, v3 pT, const m3 *R, v3 p, double *e)
{
    v3 dp = v3_sub(pT, p);
    m3 Rt = sm_tr(R), E = sm_mul(RT, &Rt);
    double vx = 0.5 * (E.r2.y - E.r1.z), vy = 0.5 * (E.r0.z - E.r2.x),
           vz = 0.5 * (E.r1.x - E.r0.y);
    double s = sqrt(vx * vx + vy * vy + vz * vz), c = 0.5 * (E.r0.x + E.r1.y + E.r2.z - 1.0);
    double fct = s > 0.0 ? atan2(s, c) / s : 1.0;
    e[0] = dp.x;
    e[1] = dp.y;
    e[2] = dp.z;
    e[3] = fct * vx;
    e[4] = fct * vy;
    e[5] = fct * vz;
    return fmax(sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]),
                sqrt(e[3] * e[3] + e[4] * e[4] + e[5] * e[5]));
}

/* The minimum-norm step dq (7) = pinv(J) e for J (6 x 7), as numpy's pinv:
 * one-sided Jacobi on the columns of A = J^T (7 x 6) gives A V = B with orthogonal
 * columns b_i (sigma_i = |b_i|), so pinv(J) e = sum_i b_i (v_i . e) / sigma_i^2
 * over sigma_i > 1e-15 sigma_max */
static void sm_pinv_step(double J[6][7], const double *e, double *dq)
{
    double B[6][7], V[6][6];
    for (int i = 0; i < 6; i++) {
        for (int k = 0; k < 7; k++)
            B[i][k] = J[i][k];
        for (int l = 0; l < 6; l++)
            V[i][l] = i == l;
    }
    for (int sweep = 0; sweep < 30; sweep++) {
        double off = 0.0;
        for (int i = 0; i < 5; i++)
            for (int l = i + 1; l < 6; l++) {
                double al = 0.0, be = 0.0, ga = 0.0;
                for (int k = 0; k < 7; k++) {
                    al += B[i][k] * B[i][k];
                    be += B[l][k] * B[l][k];
                    ga += B[i][k] * B[l][k];
                }
                if (!(fabs(ga) > 1e-300) || fabs(ga) <= 1e-17 * sqrt(al * be))
                    continue;
                off = fmax(off, fabs(ga) / sqrt(al * be));
                double zeta = (be - al) / (2.0 * ga);
                double t = copysign(1.0, zeta) / (fabs(zeta) + sqrt(1.0 + zeta * zeta));
                double c = 1.0 / sqrt(1.0 + t * t), s = c * t;
                for (int k = 0; k < 7; k++) {
                    double x = B[i][k], y = B[l][k];
                    B[i][k] = c * x - s * y;
                    B[l][k] = s * x + c * y;
                }
                for (int k = 0; k < 6; k++) {
                    double x = V[i][k], y = V[l][k];
                    V[i][k] = c * x - s * y;
                    V[l][k] = s * x + c * y;
                }
            }
        if (off <= 1e-17)
            break;
    }
    double sig2[6], smax = 0.0;
    for (int i = 0; i < 6; i++) {
        sig2[i] = 0.0;
        for (int k = 0; k < 7; k++)
            sig2[i] += B[i][k] * B[i][k];
        smax = fmax(smax, sig2[i]);
    }
    for (int k = 0; k < 7; k++)
        dq[k] = 0.0;
    for (int i = 0; i < 6; i++) {
        if (!(sig2[i] > 1e-30 * smax))
            continue;
        double ve = 0.0;
        for (int l = 0; l < 6; l++)
            ve += V[i][l] * e[l];
        for (int k = 0; k < 7; k++)
            dq[k] += B[i][k] * ve / sig2[i];
    }
}

/* A row q (7) of pose (RT, pT): up to 3 minimum-norm Gauss-Newton steps where its
 * error exceeds SM_EXACT, each kept where it lowers the error (swivel.py's
 * _polish); returns 0 (row dropped) when it stays above SM_ACCEPT. */
static int sm_polish(const SmArm *a, const m3 *RT, v3 pT, double *q)
{
    double v[7], e[6];
    m3 R;
    v3 p, hw[7], ow[7];
    for (int k = 0; k < 7; k++)
        v[k] = a->sign[k] * q[k] + a->offset[k];
    sm_fk(a, v, &R, &p, hw, ow);
    double err = sm_error(RT, pT, &R, p, e);
    for (int it = 0; it < 3 && err > SM_EXACT; it++) {
        double J[6][7], dq[7], vt[7], et[6], qt[7];
        for (int k = 0; k < 7; k++) {
            v3 lin = v3_cross(hw[k], v3_sub(p, ow[k]));
            double s = a->sign[k];
            J[0][k] = s * lin.x;
            J[1][k] = s * lin.y;
            J[2][k] = s * lin.z;
            J[3][k] = s * hw[k].x;
            J[4][k] = s * hw[k].y;
            J[5][k] = s * hw[k].z;
        }
        sm_pinv_step(J, e, dq);
        for (int k = 0; k < 7; k++) {
            qt[k] = q[k] + dq[k];
            vt[k] = a->sign[k] * qt[k] + a->offset[k];
        }
        m3 Rt;
        v3 pt, hwt[7], owt[7];
        sm_fk(a, vt, &Rt, &pt, hwt, owt);
        double et_size = sm_error(RT, pT, &Rt, pt, et);
        if (!(et_size < err))
            break;
        err = et_size;
        for (int k = 0; k < 7; k++) {
            q[k] = qt[k];
            hw[k] = hwt[k];
            ow[k] = owt[k];
        }
        for (int i = 0; i < 6; i++)
            e[i] = et[i];
        p = pt;
    }
    return err <= SM_ACCEPT;
}

/* Whether a row needs no polish, certainly: its pose error from the closed form's
 * cosines and sines cs (7 x 2; sm_split_root_cs) below SM_QUICK_FK. Those pairs
 * stand for the chain angles sm_fk takes (sign q + offset) to ~3e-15 rad each
 * (the wrap into the limits and back), so the two errors part by less than
 * ~3e-14: below SM_QUICK_FK here, sm_polish's error is below SM_EXACT and it
 * leaves the row as it is. 0 where a pair is not usable (then sm_polish decides). */
#define SM_QUICK_FK 3e-14
static int sm_quick_exact(const SmArm *a, const m3 *RT, v3 pT, double cs[7][2])
{
    m3 G = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
    v3 g = {0.0, 0.0, 0.0};
    for (int k = 0; k < 7; k++) {
        if (!(cs[k][0] * cs[k][0] + cs[k][1] * cs[k][1] > 0.5))
            return 0;
        m3 Rk = sm_rotm_cs(a->h[k], cs[k][0], cs[k][1]);
        g = v3_add(m3_mv(&G, v3_sub(a->o[k], m3_mv(&Rk, a->o[k]))), g);
        G = sm_mul(&G, &Rk);
    }
    m3 R = sm_mul(&G, &a->MR);
    v3 p = v3_add(m3_mv(&G, a->MT), g);
    double e[6];
    return sm_error(RT, pT, &R, p, e) < SM_QUICK_FK;
}

/* ------------------------------------------------------------ rows */

typedef struct {
    const double *P, *T, *psi;
    long m;
    double *Q;
    npy_bool *valid, *sing;
} SmRowsJob;

static void sm_rows_range(void *arg, long i0, long i1)
{
    const SmRowsJob *jb = (const SmRowsJob *)arg;
    SmArm a;
    sm_arm(jb->P, &a);
    for (long i = i0; i < i1; i++) {
        const double *T = jb->T + 16 * i;
        SmFrame f;
        sm_frame(&a, T, &f);
        m3 RT = {{T[0], T[1], T[2]}, {T[4], T[5], T[6]}, {T[8], T[9], T[10]}};
        v3 pT = {T[3], T[7], T[11]};
        for (long k = 0; k < jb->m; k++) {
            long row = i * jb->m + k;
            double *Q = jb->Q + 56 * row;
            npy_bool *ok = jb->valid + 8 * row, *sg = jb->sing + 8 * row;
            for (int e = 0; e < 2; e++) {
                double q[4][7], cs[4][7][2];
                int okk[4], sing[4];
                sm_configs(&a, &f, e, jb->psi[row], q, okk, sing, cs);
                for (int b = 0; b < 4; b++) {
                    int slot = 4 * e + b;
                    int good = 0;
                    if (okk[b]) { /* the elbow's cosine and sine: of the angle sm_fk takes */
                        double v4 = a.sign[3] * q[b][3] + a.offset[3];
                        cs[b][3][0] = cos(v4);
                        cs[b][3][1] = sin(v4);
                        good = sm_quick_exact(&a, &RT, pT, cs[b]) || sm_polish(&a, &RT, pT, q[b]);
                    }
                    for (int j = 0; j < 7; j++)
                        Q[7 * slot + j] = good ? q[b][j] : NAN;
                    ok[slot] = (npy_bool)good;
                    sg[slot] = (npy_bool)sing[b];
                }
            }
        }
    }
}

static PyObject *swivel_rows_body(const swivel_rows_args *a)
{
    SmRowsJob jb = {a->params, a->T, a->psi, (long)a->m, a->Q, a->valid, a->sing};
    Py_BEGIN_ALLOW_THREADS
    if (a->N * a->m >= SM_PARALLEL_MIN * 16 && a->N > 1)
        pool_for((long)a->N, SM_GRAIN, sm_rows_range, &jb);
    else
        sm_rows_range(&jb, 0, (long)a->N);
    Py_END_ALLOW_THREADS
    Py_RETURN_NONE;
}

/* ------------------------------------------------------------ the manifold */

typedef struct {
    double psi;
    int joint, kind;
    double value; /* the joint coordinate (limits) or chain angle (aligned / fold) */
    double cv, sv; /* the cosine and sine of the value's chain angle (SM_LIMCS, SM_FOLDCS) */
    int once; /* a limit's double root (the joint's extremum at it: a graze), listed once */
} SmCand;

/* Swivel angles (up to 2) where joint j (0-2, 4-6) is at chain angle L on elbow
 * root e (swivel.py limit_swivels), each Newton-polished on its subproblem 4; *once:
 * the two are one double root (|C| at or past the amplitude within SM_DOUBLE), given once */
static int sm_limit_psi(const SmArm *a, const SmFrame *f, int e, int j, double L, double *psi,
                        int *once)
{
    const v3 *h = a->h;
    v3 x, y;
    double k, sgn;
    if (j < 3) {
        v3 ha = h[0], hb = h[1], hc = h[2];
        const m3 *R0 = &f->R0[e];
        if (j == 0) {
            m3 Ra = sm_rotm(ha, L);
            x = m3_mv(&Ra, hb);
            y = m3_mv(R0, hc);
            k = v3_dot(hb, hc);
        } else if (j == 1) {
            m3 Rb = sm_rotm(hb, L);
            x = ha;
            y = m3_mv(R0, hc);
            k = v3_dot(ha, m3_mv(&Rb, hc));
        } else {
            m3 Rc = sm_rotm(hc, -L);
            x = ha;
            y = m3_mv(R0, m3_mv(&Rc, hb));
            k = v3_dot(ha, hb);
        }
        sgn = 1.0;
    } else {
        v3 ha = h[4], hb = h[5], hc = h[6];
        m3 base = sm_mul(&f->R0[e], &f->R4[e]);
        if (j == 4) {
            m3 Ra = sm_rotm(ha, L);
            x = m3_mv(&base, m3_mv(&Ra, hb));
            y = m3_mv(&f->TR, hc);
            k = v3_dot(hb, hc);
        } else if (j == 5) {
            m3 Rb = sm_rotm(hb, L);
            x = m3_mv(&base, ha);
            y = m3_mv(&f->TR, hc);
            k = v3_dot(ha, m3_mv(&Rb, hc));
        } else {
            m3 Rc = sm_rotm(hc, -L);
            x = m3_mv(&base, ha);
            y = m3_mv(&f->TR, m3_mv(&Rc, hb));
            k = v3_dot(ha, hb);
        }
        sgn = -1.0;
    }
    double t[2], A, B, C;
    *once = 0;
    if (!sm_sp4(f->u, x, y, k, &t[0], &t[1], &A, &B, &C))
        return 0;
    *once = t[0] == t[1];
    int n = 0;
    for (int i = 0; i < 2; i++) {
        double phi = t[i], g = A * cos(phi) + B * sin(phi) - C;
        for (int it = 0; it < 3; it++) { /* Newton on A cos + B sin = C */
            double d = -A * sin(phi) + B * cos(phi);
            if (!(fabs(d) > 1e-8 * hypot(A, B)) || g == 0.0)
                break;
            double p2 = phi - g / d, g2 = A * cos(p2) + B * sin(p2) - C;
            if (!(fabs(g2) < fabs(g)))
                break;
            phi = p2;
            g = g2;
        }
        if (i == 1 && t[0] == t[1])
            break; /* a double root once */
        psi[n++] = wrap_pi(sgn * phi + f->psi0[e]);
    }
    return n;
}

/* The candidates of elbow root e: every joint at each finite limit, and each
 * triple's middle angle at an end of its range (outer axes in line, or a fold) */
static int sm_candidates(const SmArm *a, const SmFrame *f, int e, SmCand *c)
{
    int n = 0, once;
    double psi[2];
    for (int j = 0; j < 7; j++) {
        if (j == 3 || a->hi[j] - a->lo[j] >= 2.0 * M_PI)
            continue;
        for (int s = 0; s < 2; s++) {
            double lim = s ? a->hi[j] : a->lo[j];
            int m = sm_limit_psi(a, f, e, j, a->sign[j] * lim + a->offset[j], psi, &once);
            for (int i = 0; i < m; i++)
                c[n++] = (SmCand){psi[i], j, s ? SM_KIND_UPPER : SM_KIND_LOWER, lim,
                                  a->limcs[4 * j + 2 * s], a->limcs[4 * j + 2 * s + 1], once};
        }
    }
    for (int t = 0; t < 2; t++) {
        int o = 4 * t;
        v3 ha = a->h[o], hb = a->h[o + 1], hc = a->h[o + 2];
        v3 hp = v3_sub(hc, v3_scale(hb, v3_dot(hb, hc)));
        double A = v3_dot(ha, hp), B = v3_dot(ha, v3_cross(hb, hp));
        double base = atan2(B, A); /* ha . rot(hb, v) hc is extremal at base, base + pi */
        for (int s = 0; s < 2; s++) {
            double L = base + s * M_PI;
            m3 Rb = sm_rotm(hb, L);
            double al = fabs(v3_dot(ha, m3_mv(&Rb, hc)));
            int kind = al > 1.0 - 1e-12 ? SM_KIND_ALIGNED : SM_KIND_FOLD;
            int m = sm_limit_psi(a, f, e, o + 1, L, psi, &once);
            for (int i = 0; i < m; i++)
                c[n++] = (SmCand){psi[i], o + 1, kind, L, s ? -a->foldcs[2 * t] : a->foldcs[2 * t],
                                  s ? -a->foldcs[2 * t + 1] : a->foldcs[2 * t + 1], 0};
        }
    }
    return n;
}

typedef struct {
    const double *P, *T;
    double *iv, *pts;
    long long *niv, *npts;
} SmManJob;

/* Candidates within this of each other [rad] may be one corner (sm_runs) */
#define SM_CORNER 1e-9

/* The runs of swivel angles where one triple (part 1 the shoulder, 2 the wrist) of
 * elbow root e exists with its three joints inside their limits, per root r of its
 * middle angle: the cuts are the candidates of that triple's joints only (the other
 * triple's do not change its state), each cell decided at its midpoint, adjacent
 * in-cells merged; a cut whose cells on both sides are outside is a run of its own
 * ([psi, psi]) when the triple's row there is inside (the one-point rule of every
 * path: two joints of the triple at limits at psi, leaving on either side). A branch
 * (shoulder s, wrist w) is inside every limit where the runs of s and of w overlap,
 * a point included (the elbow is constant over the swivel). */
static void sm_runs(const SmArm *a, const SmFrame *f, int e, int part, const SmCand *c, int nc,
                    double run[2][SM_MAXI][2], int nrun[2])
{
    double cut[66];
    int m = 0, j0 = part == 1 ? 0 : 4, once[66] = {0};
    cut[m++] = -M_PI;
    cut[m++] = M_PI;
    for (int i = 0; i < nc; i++)
        if ((c[i].joint < 3) == (part == 1)) {
            once[m] = c[i].once;
            cut[m++] = c[i].psi;
        }
    for (int i = 1; i < m; i++) { /* insertion sort (stable), at most 66 cuts */
        double x = cut[i];
        int k = i, o = once[i];
        for (; k > 0 && cut[k - 1] > x; k--) {
            cut[k] = cut[k - 1];
            once[k] = once[k - 1];
        }
        cut[k] = x;
        once[k] = o;
    }
    int open[2] = {0, 0};
    nrun[0] = nrun[1] = 0;
    for (int i = 0; i + 1 < m; i++) {
        double lo = cut[i], hi = cut[i + 1];
        if (!(hi > lo))
            continue;
        SmSplit t, tq, tc;
        int at = 0, exact = 0; /* at: the split at the cut lo computed; exact: t */
        double mid = 0.5 * (lo + hi);
        sm_part_split_quick(a, f, e, mid, part, &tq);
        for (int r = 0; r < 2; r++) {
            int in = tq.real ? sm_quick_root_inside(a, j0, &tq, r) : 0;
            if (in < 0) { /* not certain: the exact test (tq.real is t.real) */
                if (!exact)
                    sm_part_split(a, f, e, mid, part, &t);
                exact = 1;
                in = sm_root_inside(a, j0, &t, r);
            }
            if (!in && !open[r] && lo > -M_PI && nrun[r] < SM_MAXI &&
                (lo - cut[i - 1] <= SM_CORNER || hi - lo <= SM_CORNER || once[i])) {
                /* both cells next to the cut outside and another cut within SM_CORNER
                 * (two joints of the triple at limits there, leaving on either side), or
                 * the cut a limit's double root (a joint's extremum at its limit to
                 * rounding: a graze from outside, which _points_refined widens to its
                 * in-slack stretch): the cut alone, if its row is in */
                if (!at)
                    sm_part_split(a, f, e, lo, part, &tc);
                at = 1;
                if (tc.real && sm_root_inside(a, j0, &tc, r)) {
                    run[r][nrun[r]][0] = run[r][nrun[r]][1] = lo;
                    nrun[r]++;
                }
            }
            if (in && open[r]) {
                run[r][nrun[r] - 1][1] = hi; /* extends the open run */
            } else if (in && nrun[r] < SM_MAXI) {
                run[r][nrun[r]][0] = lo;
                run[r][nrun[r]][1] = hi;
                nrun[r]++;
            }
            open[r] = in;
        }
    }
    /* the cut at -pi (= pi) by the same rule: both cells next to it outside (no run
     * starts at -pi, none ends at pi) and the row there inside: [-pi, -pi] first and
     * [pi, pi] last (joined across pi into one point, sm_elbow_intervals) */
    int at = 0;
    SmSplit tc;
    for (int r = 0; r < 2; r++) {
        int n = nrun[r];
        if ((n && (run[r][0][0] == -M_PI || run[r][n - 1][1] == M_PI)) || n + 2 > SM_MAXI ||
            !(cut[1] + M_PI <= SM_CORNER || M_PI - cut[m - 2] <= SM_CORNER))
            continue; /* a run at an end, or no candidate at +-pi */
        if (!at)
            sm_part_split(a, f, e, -M_PI, part, &tc);
        at = 1;
        if (!(tc.real && sm_root_inside(a, j0, &tc, r)))
            continue;
        for (int i = n; i > 0; i--) {
            run[r][i][0] = run[r][i - 1][0];
            run[r][i][1] = run[r][i - 1][1];
        }
        run[r][0][0] = run[r][0][1] = -M_PI;
        run[r][n + 1][0] = run[r][n + 1][1] = M_PI;
        nrun[r] = n + 2;
    }
}

/* The overlaps of two sorted lists of disjoint runs into out (at most SM_MAXI) */
static long long sm_overlap(double x[][2], int nx, double y[][2], int ny, double *out)
{
    long long n = 0;
    int i = 0, k = 0;
    while (i < nx && k < ny) {
        double lo = fmax(x[i][0], y[k][0]), hi = fmin(x[i][1], y[k][1]);
        if (hi >= lo && n < SM_MAXI) { /* a point: a one-point run, or two runs meeting */
            out[2 * n] = lo;
            out[2 * n + 1] = hi;
            n++;
        }
        if (x[i][1] < y[k][1])
            i++;
        else
            k++;
    }
    return n;
}

/* Whether psi is in one of the n sorted runs x, ends included */
static int sm_in_runs(double x[][2], int n, double psi)
{
    for (int i = 0; i < n; i++)
        if (x[i][0] <= psi && psi <= x[i][1])
            return 1;
    return 0;
}

/* The touches of branch b of elbow root e: the ends of one triple's runs x (not
 * the cuts at -pi, pi) outside every run y of the other triple where the whole row
 * is inside every limit (SM_INSIDE_SLACK, the slack of the cells): the branch is in
 * the limits at that swivel angle alone, the ends of two runs meeting at one angle
 * (a joint of each triple at its limit there, e.g. a configuration generated with
 * both at limits). The two ends are computed roots of different subproblems: next
 * to a near-tangent one (a joint whose slope over the swivel is small, 1e-6) they
 * miss each other by more than rounding, so the overlap of the runs is empty.
 * Adds each as a one-point interval [psi, psi] into r (k sorted intervals). party:
 * the triple of y (1 the shoulder, 2 the wrist), tested first (usually outside). */
static long long sm_touches(const SmArm *a, const SmFrame *f, int e, int b, double x[][2], int nx,
                            double y[][2], int ny, int party, double *r, long long k)
{
    for (int i = 0; i < nx; i++)
        for (int s = 0; s < 2; s++) {
            double t = x[i][s];
            if (t == -M_PI || t == M_PI || sm_in_runs(y, ny, t) || k >= SM_MAXI ||
                !sm_branch_inside(a, f, e, b, t, party))
                continue;
            long long p = k++;
            while (p > 0 && r[2 * p - 2] > t) {
                r[2 * p] = r[2 * p - 2];
                r[2 * p + 1] = r[2 * p - 1];
                p--;
            }
            r[2 * p] = r[2 * p + 1] = t;
        }
    return k;
}

/* The intervals (4, SM_MAXI, 2) with counts (4) of the branches of elbow root e
 * (slots 4 e + b) inside every limit, from its candidates c: the overlaps of each
 * shoulder root's and wrist root's runs and their touches (sm_touches), a run
 * through pi joined */
static void sm_elbow_intervals(const SmArm *a, const SmFrame *f, int e, const SmCand *c, int nc,
                               double *iv, long long *niv)
{
    for (int b = 0; b < 4; b++)
        niv[b] = 0;
    if (!f->elbow_real || !sm_inside_joint(a, 3, sm_joint(a, 3, f->v4[e])))
        return; /* the elbow outside its limits: no branch of this root inside */
    double rs[2][SM_MAXI][2], rw[2][SM_MAXI][2];
    int ns[2], nw[2];
    sm_runs(a, f, e, 1, c, nc, rs, ns);
    sm_runs(a, f, e, 2, c, nc, rw, nw);
    for (int b = 0; b < 4; b++) {
        double *r = iv + 2 * SM_MAXI * b;
        long long k = sm_overlap(rs[b / 2], ns[b / 2], rw[b % 2], nw[b % 2], r);
        k = sm_touches(a, f, e, b, rs[b / 2], ns[b / 2], rw[b % 2], nw[b % 2], 2, r, k);
        k = sm_touches(a, f, e, b, rw[b % 2], nw[b % 2], rs[b / 2], ns[b / 2], 1, r, k);
        /* periodic: a run ending at pi and one starting at -pi join */
        if (k >= 2 && r[0] == -M_PI && r[2 * k - 1] == M_PI) {
            double end = r[1] + 2.0 * M_PI, start = r[2 * k - 2];
            for (long long i = 0; i + 1 < k; i++) {
                r[2 * i] = r[2 * i + 2];
                r[2 * i + 1] = r[2 * i + 3];
            }
            r[2 * k - 4] = start;
            r[2 * k - 3] = end;
            k--;
        }
        niv[b] = k;
    }
}

/* One pose: intervals (8, SM_MAXI, 2) with counts (8), points (SM_MAXP, 4) */
static void sm_manifold1(const SmArm *a, const double *T, double *iv, long long *niv,
                         double *pts, long long *npts)
{
    SmFrame f;
    sm_frame(a, T, &f);
    *npts = 0;
    for (int b = 0; b < 8; b++)
        niv[b] = 0;
    if (!f.elbow_real)
        return;
    for (int e = 0; e < 2; e++) {
        SmCand c[64];
        int nc = sm_candidates(a, &f, e, c);
        /* the points: which branches are at the value there */
        for (int i = 0; i < nc; i++) {
            int j = c[i].joint, part = j < 3 ? 1 : 2, at[2], exact = 0;
            SmSplit t, tq;
            sm_part_split_quick(a, &f, e, c[i].psi, part, &tq);
            if (!tq.real) /* t.real */
                continue;
            for (int r = 0; r < 2; r++) { /* root r's joint j at the value (within SM_SAME) */
                double cj, sj;
                at[r] = sm_quick_angle(&tq, j < 3 ? j : j - 4, r, &cj, &sj)
                    ? sm_quick_at(cj, sj, c[i].cv, c[i].sv) : -1;
                if (at[r] >= 0)
                    continue;
                if (!exact) /* not certain: the exact test */
                    sm_part_split(a, &f, e, c[i].psi, part, &t);
                exact = 1;
                double qj = sm_root_joint(a, j, &t, r);
                double d = c[i].kind <= SM_KIND_UPPER
                    ? qj - c[i].value
                    : a->sign[j] * qj + a->offset[j] - c[i].value;
                at[r] = fabs(wrap_pi(d)) < SM_SAME;
            }
            for (int b = 0; b < 4; b++) {
                if (*npts >= SM_MAXP)
                    continue;
                if (at[part == 1 ? b / 2 : b % 2]) {
                    double *r = pts + 4 * (*npts)++;
                    r[0] = c[i].psi;
                    r[1] = 4 * e + b;
                    r[2] = c[i].joint;
                    r[3] = c[i].kind;
                }
            }
        }
        sm_elbow_intervals(a, &f, e, c, nc, iv + 2 * SM_MAXI * 4 * e, niv + 4 * e);
    }
}

static void sm_manifold_range(void *arg, long i0, long i1)
{
    const SmManJob *jb = (const SmManJob *)arg;
    SmArm a;
    sm_arm(jb->P, &a);
    for (long i = i0; i < i1; i++)
        sm_manifold1(&a, jb->T + 16 * i, jb->iv + 16 * SM_MAXI * i, jb->niv + 8 * i,
                     jb->pts + 4 * SM_MAXP * i, jb->npts + i);
}

static PyObject *swivel_manifold_body(const swivel_manifold_args *a)
{
    SmManJob jb = {a->params, a->T, a->iv, a->pts, a->niv, a->npts};
    Py_BEGIN_ALLOW_THREADS
    if (a->N >= SM_PARALLEL_MIN)
        pool_for((long)a->N, SM_GRAIN, sm_manifold_range, &jb);
    else
        sm_manifold_range(&jb, 0, (long)a->N);
    Py_END_ALLOW_THREADS
    Py_RETURN_NONE;
}

/* self_motion_intervals._points_refined's cheap test, the same decision bit for bit:
 * 1 when the sorted keys t + 64 branch of the crossings among the points pts (npts,
 * 4) (kind at most upper) have two within SM_PAIR (64 branch is exact: one rounding,
 * as numpy's dot), a crossing's t is within SM_PAIR of the range's end lo or hi (the
 * swivel: -pi, pi; a held joint: its limits, held_manifold.c), or an interval of iv
 * (m, 2) is at most SM_POINT long; key: npts doubles of scratch */
static int sm_close(const double *pts, long long npts, const double *iv, long long m,
                    double lo, double hi, int upper, double *key)
{
    for (long long i = 0; i < m; i++)
        if (iv[2 * i + 1] - iv[2 * i] <= SM_POINT)
            return 1;
    long long n = 0; /* the crossings (kind <= upper: the aligned and fold points make
                      * no candidate of _points_refined's) */
    for (long long i = 0; i < npts; i++) {
        if (pts[4 * i + 3] > upper)
            continue;
        double t = pts[4 * i], k = t + 64.0 * pts[4 * i + 1];
        if (t <= lo + SM_PAIR || t >= hi - SM_PAIR)
            return 1;
        long long j = n++; /* insertion sort into key (npts long): ~10-60 points */
        for (; j > 0 && key[j - 1] > k; j--)
            key[j] = key[j - 1];
        key[j] = k;
    }
    for (long long i = 1; i < n; i++)
        if (key[i] - key[i - 1] <= SM_PAIR)
            return 1;
    return 0;
}

/* One pose (robot.self_motion's call): sm_manifold1, its intervals packed branch by
 * branch; returns new arrays (intervals (m, 2), branches (m,), points (p, 4)) and
 * sm_close's flag (False: _points_refined has nothing to find). */
static PyObject *swivel_manifold_one_body(const swivel_manifold_one_args *a)
{
    double iv[8 * SM_MAXI * 2], pts[4 * SM_MAXP];
    long long niv[8], npts = 0, m = 0;
    SmArm arm;
    sm_arm(a->params, &arm);
    sm_manifold1(&arm, a->T, iv, niv, pts, &npts);
    for (int b = 0; b < 8; b++)
        m += niv[b];
    npy_intp di[2] = {(npy_intp)m, 2}, dp[2] = {(npy_intp)npts, 4};
    PyObject *out_iv = PyArray_SimpleNew(2, di, NPY_DOUBLE);
    PyObject *out_b = PyArray_SimpleNew(1, di, NPY_INT64);
    PyObject *out_p = PyArray_SimpleNew(2, dp, NPY_DOUBLE);
    if (out_iv == NULL || out_b == NULL || out_p == NULL) {
        Py_XDECREF(out_iv);
        Py_XDECREF(out_b);
        Py_XDECREF(out_p);
        return NULL;
    }
    double *ov = (double *)PyArray_DATA((PyArrayObject *)out_iv);
    long long *ob = (long long *)PyArray_DATA((PyArrayObject *)out_b);
    for (int b = 0, k = 0; b < 8; b++)
        for (long long i = 0; i < niv[b]; i++, k++) {
            ov[2 * k] = iv[2 * (SM_MAXI * b + i)];
            ov[2 * k + 1] = iv[2 * (SM_MAXI * b + i) + 1];
            ob[k] = b;
        }
    if (npts)
        memcpy(PyArray_DATA((PyArrayObject *)out_p), pts, (size_t)(4 * npts) * sizeof(double));
    double key[SM_MAXP];
    int close = sm_close(pts, npts, ov, m, -M_PI, M_PI, SM_KIND_UPPER, key);
    return Py_BuildValue("(NNNN)", out_iv, out_b, out_p, PyBool_FromLong(close));
}

/* ------------------------------------------------------------ the nearest point */

#define SM_NEAR_GRID 32 /* swivel values of the coarse grid per elbow root */
#define SM_NEAR_KEEP 3  /* local minima of the samples refined (the best by value) */
#define SM_NEAR_XTOL 1e-8
#define SM_NEAR_TRY 8   /* answers tried, nearest first, until one polishes inside the limits */ /* Brent's tolerance on psi [rad] */

/* The squared 2 pi wrapped distance of row q (7) to qn */
static double sm_dist2(const double *q, const double *qn)
{
    double s = 0.0;
    for (int j = 0; j < 7; j++) {
        double d = wrap_pi(q[j] - qn[j]);
        s += d * d;
    }
    return s;
}

/* sm_dist2 of branch b (0-3) of elbow root e at psi: INFINITY where it has no row */
static double sm_branch_dist(const SmArm *a, const SmFrame *f, int e, int b, double psi,
                             const double *qn)
{
    double q[7];
    return sm_branch_row(a, f, e, b, psi, q) ? sm_dist2(q, qn) : INFINITY;
}

/* Brent's minimisation (golden section with parabolic steps; Brent 1973, ch. 5) of
 * the distance of branch b over [lo, hi] from x (value fx); returns the best psi */
static double sm_brent(const SmArm *a, const SmFrame *f, int e, int b, const double *qn,
                       double lo, double hi, double x, double *fx)
{
    const double g = 0.3819660112501051;
    double w = x, v = x, fw = *fx, fv = *fx, d = 0.0, step = 0.0;
    for (int it = 0; it < 60; it++) {
        double m = 0.5 * (lo + hi), tol = SM_NEAR_XTOL + 1e-12 * fabs(x), t2 = 2.0 * tol;
        if (fabs(x - m) <= t2 - 0.5 * (hi - lo))
            break;
        int golden = 1;
        if (fabs(step) > tol) { /* a parabola through x, w, v */
            double r = (x - w) * (*fx - fv), q = (x - v) * (*fx - fw), p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if (q > 0.0)
                p = -p;
            q = fabs(q);
            if (fabs(p) < fabs(0.5 * q * step) && p > q * (lo - x) && p < q * (hi - x)) {
                step = d;
                d = p / q;
                double u = x + d;
                if (u - lo < t2 || hi - u < t2)
                    d = x < m ? tol : -tol;
                golden = 0;
            }
        }
        if (golden) {
            step = (x < m ? hi : lo) - x;
            d = g * step;
        }
        double u = fabs(d) >= tol ? x + d : x + (d > 0.0 ? tol : -tol);
        double fu = sm_branch_dist(a, f, e, b, u, qn);
        if (fu <= *fx) {
            if (u < x)
                hi = x;
            else
                lo = x;
            v = w;
            fv = fw;
            w = x;
            fw = *fx;
            x = u;
            *fx = fu;
        } else {
            if (u < x)
                lo = u;
            else
                hi = u;
            if (fu <= fw || w == x) {
                v = w;
                fv = fw;
                w = u;
                fw = fu;
            } else if (fu <= fv || v == x || v == w) {
                v = u;
                fv = fu;
            }
        }
    }
    return x;
}

typedef struct {
    double g, psi, lo, hi; /* sampled value at psi, its bracket */
    int e, b;
} SmMin;

/* Keeps the cap smallest of the points offered in best (sorted, *n of them) */
static void sm_keep(SmMin *best, int *n, int cap, SmMin m)
{
    int i;
    if (*n < cap) {
        i = (*n)++;
    } else {
        i = cap - 1;
        if (!(m.g < best[i].g))
            return;
    }
    while (i > 0 && m.g < best[i - 1].g) {
        best[i] = best[i - 1];
        i--;
    }
    best[i] = m;
}

/* The in-limit configuration of pose T nearest qn (7): q (7), its psi and slot; 0
 * when no part of the manifold is inside the limits (or its row fails the polish).
 * Per elbow root: the exact intervals (sm_elbow_intervals), a grid of SM_NEAR_GRID
 * swivel values; per branch and interval the samples (its ends and the grid values
 * inside) give the local minima of the distance, the SM_NEAR_KEEP smallest are
 * refined by Brent's method between their neighbouring samples; the best point
 * (refined or an interval end) is Newton-polished and clamped into the limits. */
static int sm_near1(const SmArm *a, const double *T, const double *qn, double *qout,
                    double *psi_out, long long *slot_out, double *d_out)
{
    SmFrame f;
    sm_frame(a, T, &f);
    if (!f.elbow_real)
        return 0;
    const double h = 2.0 * M_PI / SM_NEAR_GRID;
    SmMin best[SM_NEAR_KEEP];
    int nbest = 0;
    SmMin tries[SM_NEAR_TRY]; /* the nearest interval ends and refined minima */
    int ntries = 0;
    for (int e = 0; e < 2; e++) {
        SmCand c[64];
        int nc = sm_candidates(a, &f, e, c);
        double iv[4][SM_MAXI][2];
        long long niv[4];
        sm_elbow_intervals(a, &f, e, c, nc, &iv[0][0][0], niv);
        if (!(niv[0] | niv[1] | niv[2] | niv[3]))
            continue;
        double grid[SM_NEAR_GRID][4];
        int done[SM_NEAR_GRID] = {0}; /* grid values evaluated when an interval needs them */
        for (int b = 0; b < 4; b++)
            for (long long i = 0; i < niv[b]; i++) {
                double lo = iv[b][i][0], hi = iv[b][i][1];
                double t[SM_NEAR_GRID + 3], g[SM_NEAR_GRID + 3];
                int n = 0;
                t[n] = lo;
                g[n++] = sm_branch_dist(a, &f, e, b, lo, qn);
                for (long k = (long)ceil((lo + M_PI) / h); -M_PI + k * h < hi; k++) {
                    double tk = -M_PI + k * h;
                    if (tk > lo && n < SM_NEAR_GRID + 2) {
                        int kk = (int)(((k % SM_NEAR_GRID) + SM_NEAR_GRID) % SM_NEAR_GRID);
                        if (!done[kk]) {
                            double q[4][7];
                            int ok[4], sg[4];
                            sm_configs(a, &f, e, -M_PI + kk * h, q, ok, sg, NULL);
                            for (int bb = 0; bb < 4; bb++)
                                grid[kk][bb] = ok[bb] ? sm_dist2(q[bb], qn) : INFINITY;
                            done[kk] = 1;
                        }
                        t[n] = tk;
                        g[n++] = grid[kk][b];
                    }
                }
                t[n] = hi;
                g[n++] = sm_branch_dist(a, &f, e, b, hi, qn);
                for (int k = 0; k < n; k += n - 1)
                    if (g[k] < INFINITY)
                        sm_keep(tries, &ntries, SM_NEAR_TRY, (SmMin){g[k], t[k], t[k], t[k], e, b});
                for (int k = 0; k < n; k++) {
                    double gl = k > 0 ? g[k - 1] : INFINITY, gr = k + 1 < n ? g[k + 1] : INFINITY;
                    if (g[k] < INFINITY && g[k] <= gl && g[k] <= gr)
                        sm_keep(best, &nbest, SM_NEAR_KEEP, (SmMin){g[k], t[k], t[k > 0 ? k - 1 : 0],
                                                      t[k + 1 < n ? k + 1 : n - 1], e, b});
                }
            }
    }
    for (int i = 0; i < nbest; i++) {
        SmMin m = best[i];
        m.psi = sm_brent(a, &f, m.e, m.b, qn, m.lo, m.hi, m.psi, &m.g);
        sm_keep(tries, &ntries, SM_NEAR_TRY, m);
    }
    /* nearest first, the first whose row polishes to the pose inside the limits (next
     * to an aligned point the polish may move a row out of them) */
    m3 RT = {{T[0], T[1], T[2]}, {T[4], T[5], T[6]}, {T[8], T[9], T[10]}};
    v3 pT = {T[3], T[7], T[11]};
    for (int i = 0; i < ntries; i++) {
        double q[7];
        if (!sm_branch_row(a, &f, tries[i].e, tries[i].b, tries[i].psi, q) ||
            !sm_polish(a, &RT, pT, q))
            continue;
        if (!sm_row_inside(a, q))
            continue;
        for (int j = 0; j < 7; j++)
            qout[j] = fmin(fmax(q[j], a->lo[j]), a->hi[j]);
        *psi_out = wrap_pi(tries[i].psi);
        *slot_out = 4 * tries[i].e + tries[i].b;
        *d_out = sqrt(sm_dist2(qout, qn));
        return 1;
    }
    return 0;
}
typedef struct {
    const double *P, *T, *qn;
    double *q, *psi, *dist;
    long long *slot;
    npy_bool *found;
} SmNearJob;

static void sm_near_range(void *arg, long i0, long i1)
{
    const SmNearJob *jb = (const SmNearJob *)arg;
    SmArm a;
    sm_arm(jb->P, &a);
    for (long i = i0; i < i1; i++) {
        int ok = sm_near1(&a, jb->T + 16 * i, jb->qn + 7 * i, jb->q + 7 * i, jb->psi + i,
                          jb->slot + i, jb->dist + i);
        jb->found[i] = (npy_bool)ok;
        if (!ok) {
            for (int j = 0; j < 7; j++)
                jb->q[7 * i + j] = NAN;
            jb->psi[i] = NAN;
            jb->slot[i] = -1;
            jb->dist[i] = INFINITY;
        }
    }
}

static PyObject *swivel_near_body(const swivel_near_args *a)
{
    SmNearJob jb = {a->params, a->T, a->q_near, a->q, a->psi, a->dist, a->slot, a->found};
    Py_BEGIN_ALLOW_THREADS
    if (a->N >= SM_PARALLEL_MIN)
        pool_for((long)a->N, SM_GRAIN, sm_near_range, &jb);
    else
        sm_near_range(&jb, 0, (long)a->N);
    Py_END_ALLOW_THREADS
    Py_RETURN_NONE;
}
