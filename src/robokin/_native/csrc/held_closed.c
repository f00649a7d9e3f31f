/*
 * The whole self-motion of one pose of a Panda-kind arm from closed forms (issue 29,
 * session 26): held_manifold.c's outputs (intervals per slot, points, flags) for the
 * arms whose held joint is the last (q7 = t), whose axes 1-3 meet in S with axes 1
 * and 3 on one line at zero (axis 2 normal to it: the shoulder's angles are Euler
 * angles) and whose axes 5 and 6 meet in W (the Panda, the FR3). held_manifold.c
 * takes every pose this file does not certify (hc_pose returns 0).
 *
 * On the product of exponentials T = e1 ... e7 M (chain values v_k, x = v_7), with
 * p(x) = e7(x) M T^-1 S (S's image: a circle about axis 7) and v = p - W:
 *
 *   E1  |v(x)|^2 = D(x) = d0 + d1 cos x + d2 sin x equals |e4(-v4) S - W|^2 =
 *       K + c1 cos v4 + c2 sin v4: v4's two roots (i = 0: phi + acos, 1: phi - acos);
 *       its branch ends (D - K = +-|c|) and v4 = L are roots of a cos x + b sin x = c;
 *   E2  the height of v along axis 5 after axis 6: f0 + f1 cos v6 + f2 sin v6 = e(v4)
 *       = e0 + e1 cos v4 + e2 sin v4 (f's affine in cos x, sin x): v6's two roots
 *       (j); v6 = L, and v5 = L (the height along axis 6 of e5(-L) (e4(-v4) S - W)
 *       equals v's), are with E1 two linear equations in (cos v4, sin v4) whose
 *       solution on the unit circle is a quartic in tan(x / 2); E2's branch ends
 *       (its discriminant's roots along each v4 root) are found on its margin, no
 *       rows (Brent);
 *   v5  subproblem 1 about axis 5; the shoulder R = R1 R2 R3 = R_T R_M^T R7(-x)
 *       R6(-v6) R5(-v5) R4(-v4): with e1 = h1 (= h3), e2 = h2, ea = e2 x e1, w = R e1
 *       and r = R^T e1, v2 = atan2(|(w.ea, w.e2)|, w.e1), v1 = atan2(w.e2, w.ea), v3 =
 *       atan2(r.e2, -r.ea) (the triple's other solution: v1 + pi, -v2, v3 + pi).
 *
 * Every crossing of a shoulder joint (a limit, an aligned value) is a root of a
 * smooth function of x along a position branch (i, j), both triples at once: v1 = L
 * of -sin L w.ea + cos L w.e2, v2 = +-L of w.e1 - cos L, v3 = L of cos L r.e2 + sin L
 * r.ea (its triple from the sign of the other component). Each is bracketed on nodes
 * of the branch's pieces (between branch ends and the range's ends: nodes evenly
 * spaced in xi, x = a + (b - a)(1 - cos pi xi) / 2, where the rows are smooth at a
 * branch end: they move as its square root) with the functions' slopes (the joint
 * rates from E1, E2 and v5's equation, the shoulder's angular velocity), cells split
 * while a cubic Hermite model is ambiguous, and refined by safeguarded Newton.
 * A piece of a slot between consecutive events is decided at its midpoint. A limit
 * crossing in a cell where another joint of its triple is outside all over it (at
 * both ends, and no event of that joint between) bounds nothing and is not located
 * (held_manifold.c's dead cells); every located crossing is listed, and every aligned
 * point and branch end. A cell with a wrist joint outside all over it (known from the
 * wrist's closed-form events) asks only the queries located everywhere (aligned
 * values, the aligned-shoulder guards), on rows that compute r alone (HC_RONLY; a row
 * that turns out to be a live cell's end is completed, hc_full). A branch end is
 * moved from the margin's exact root to where pk_one's rows of its slot end (hc_snap:
 * pk's own discriminant, held_margins.c, confirmed by a pk_one row), so that
 * SelfMotion.sample has a row at every end.
 *
 * Not certified (0: held_manifold.c's grid instead, ~1 % of uniform Panda poses,
 * ~half of poses with joints at special values, session 27): a branch end pk_one does
 * not confirm; a branch within HC_ALIGNED of an aligned shoulder (1 - |cos v2|: q1
 * and q3 swing there) or a wrist aligned point with a second wrist joint at its
 * aligned value or a joint within HC_CORNER of a limit (self_motion_rates.py seed 0:
 * an isolated in-limit row at q1, q3, q4 limits and q5 = 1e-9, which the grid flags
 * for solved points); a limit function at 0 at a node or at a located extremum (a
 * touch; an isolated in-limit row), a closed-form root pair near double; events of a
 * slot within HC_CORNER of each other or of the range's end (HC_FOLD_GAP of a branch
 * end, where the rows move as the square root of the distance), a joint at a limit at
 * a piece's end (a corner: the generating configuration at two limits, or at a limit
 * and a branch end; there within the end's square-root move from its snap), an aligned
 * value at a branch end (its point at the end itself);
 * a cell not resolved in HC_DEPTH splits, a crossing not at its
 * value to HC_AT (HC_AT_STEEP where x's last bit moves it more); pk_one's slots not
 * these (checked at one value from pk's front: hc_slots_agree); a joint range with a
 * half width within
 * HC_ARC_MIN of 0 or pi (hc_margins); a degenerate coefficient.
 * Measured against the grid on 4,000 uniform and 2,000 special poses (sessions 26 and
 * 27, held_manifold_ab.py --modes GRID CLOSED): the same intervals on every pose both
 * certify, ends within 1.42e-10 at branch ends (the grid's bisection on pk_one's rows
 * to HM_FOLD_TOL; these are the margins' roots) and 2.9e-11 elsewhere. Session 27:
 * ~0.08 ms of CPU per uniform pose (session 26: 0.139 in the same run); a piece of a
 * slot is decided at a node row already evaluated (hc_keep), an event keeps its row's
 * margins (hc_add), margins are taken without angles (hc_margins). Session 28 (an AMD
 * EPYC): 0.083 -> 0.058 ms in one run; rotations about coordinate axes (hc_rot),
 * chain.h's sincos1, the dead cells' r-only rows, branch ends bracketed from the
 * margin's root outward (hc_snap_end), wrist roots polished on their v4 root's
 * branches only, the slot check from pk's front. Session 29: the rows' formulas once
 * for one row and for W rows (held_row.h); a piece's 16 nodes and E2's margin's 33
 * in lanes, with their margins and the queries' values; the cells with nothing to do
 * found in lanes (hc_busy_cells, hc_m2_busy: hc_cell's and hc_m2_cell's common case);
 * a crossing's last Newton step without its row (hc_at_value); a wrist event's row the
 * polish's; a front solving one position root's slots (hc_row_at).
 */

#include "brent.h"
#include "held_outputs.h"

#define HC_NODES 16      /* nodes per piece (its ends included) before splits: 2 x 8 lanes */
#define HC_MNODES 33     /* nodes per piece of E1 for E2's margin, before splits */
#define HC_DEPTH 10      /* splits of a cell */
#define HC_MAXE 64       /* events per branch (i, j) */
#define HC_MAXPC 12      /* pieces per branch */
#define HC_MAXQ 12       /* shoulder functions */
#define HC_MAXN 192      /* node rows kept per branch (hc_keep) */
#define HC_ALIGNED 1e-8  /* 1 - |cos v2| below this on a branch: not certified */
#define HC_CLOSE 1e-9    /* closed-form roots this close: one */
#define HC_CORNER 1e-6   /* events of one slot this close (or an end): the grid's */
#define HC_FOLD_GAP 1e-10 /* ... an event and a branch end */
#define HC_TOUCH 1e-7    /* a model's extremum this close to 0: split (at HC_DEPTH: the grid's) */
#define HC_DIP 0.5       /* a model's extremum toward 0 below this share of its ends: located */
#define HC_AT_FOLD 1e-5  /* a joint this close to a limit at a branch end (rows as its square root) */
#define HC_WRIST_ALIGNED 1e-4 /* |sin| of a second wrist joint at a wrist aligned point: the grid's */
#define HC_AT_NODE 1e-9  /* a limit function this close to 0 at a node or extremum: the grid's */
#define HC_DIP_WIDTH 1e-6 /* an extremum toward 0 still unresolved in a cell this narrow */
#define HC_DOUBLE 1e-4   /* closed-form roots this close to double: the grid's */
#define HC_ROWS_KEPT 8   /* pk_one calls kept by hc_row_at */
#define HC_SNAP_ULPS 16  /* a snapped branch end moved this many doubles inward */
#define HC_SNAP 1e-8     /* pk_one's branch end searched this far (relative) from the margin's */
#define HC_SNAP_TOL 4e-15 /* ... and located this closely (relative) */
#define HC_END_XI 1e-4   /* a branch end's slopes from this far in (in xi) */
#define HC_AT 1e-12      /* a crossing's joint at its value to this [rad] */
#define HC_AT_STEEP 1e-9 /* the same where the last bit of x moves the joint more */
#define HC_LAST_F 1e-8   /* Newton's last step without its row: |f| at most this there */
#define HC_LAST_PRED 1e-15 /* ... and the joint's predicted error at most this [rad] */
#define HC_DECIDE 1e-9   /* a midpoint row this far inside / outside decides its piece */
#define HC_BEND 1.0      /* E2's margin: slopes off the chord by more than this share: split */
#define HC_BEND_FLOOR 1e-2
#define HC_MOVE 0.25     /* a function moving more than this in a cell: split */
#define HC_END_SPLITS 4  /* splits of a cell at a branch end (no slope there) */
#define HC_ARC_MIN 0.05  /* sin of a joint range's half width above this (hc_margins) */

typedef struct {
    v3 h[7], o[7], S, Wc, e1, e2, ea, a0, a1, a2, h56x;
    m3 RM;
    v3 tM;
    double K, c1, c2, cn, ec[3], h56, L;
    double sign[7], off[7], lo[7], hi[7];
    double arc[7][4]; /* each joint's limits as an arc of chain values: cos, sin of its
                       * middle, cos and 1 / sin of its half width (hc_margins) */
    int ax[7];        /* axis k along coordinate ax[k] (0-2, sign axs[k]), else 3 */
    double axs[7];
} HcGeo;

typedef struct {
    const HcGeo *g;
    v3 v[3];             /* v(x) = v[0] + cos x v[1] + sin x v[2] */
    double d[3], f0[3], f1[3], f2[3], h6v[3];
    m3 RG0;              /* R_T R_M^T */
    v3 g1;               /* RG0^T e1 */
    double xlo, xhi;     /* x's range (chain values) */
} HcPose;

/* One position branch's row at x: the joint chain values, the shoulder's w = R e1
 * and r = R^T e1 in the shoulder's basis and their slopes d/dx (slopes only when asked
 * and finite). */
typedef struct {
    double x, cs[7][2], dv[7], noise; /* noise: v5's rounding [rad] */
    double mg[2][7];  /* each joint's margins, both triples (hc_rowq's, when hasmg) */
    double sh[5], dsh[5]; /* w.ea, w.e2, w.e1, r.ea, r.e2 and their slopes */
    double dxi;       /* dx/dxi on its piece (hc_cell's slopes per cell) */
    double c, s;      /* cos x, sin x */
    v3 in;            /* the shoulder's body angular velocity's inner part (hc_full) */
    int sloped, hasmg;
    int ronly;        /* r alone: w.ea, w.e2 (and slopes) NaN, sh[2] = r.e1 (hc_full) */
    int nf;           /* queries with their values in f, df (hc_cell's; 0 until then) */
    double f[HC_MAXQ], df[HC_MAXQ];
} HcRow;

/* A shoulder function: joint j (0-2) at chain value V (kind: HM_KIND_*; -1: the
 * aligned-shoulder guard, |cos v2| = 1) */
typedef struct {
    int j, kind, twin; /* twin: v2's other limit at -V (its crossings the other triple's) */
    double V, cV, sV;
} HcQuery;

#define HC_SHOULDER 1 /* hc_eval: the shoulder's scalars (else the wrist's values alone) */
#define HC_SLOPES 2   /* ... and the slopes d/dx (the wrist's alone without HC_SHOULDER) */
#define HC_NOISE 4    /* ... and v5's rounding (r->noise; else NaN) */
#define HC_RONLY 8    /* ... r alone where a wrist joint is outside (hc_full completes it) */

/* held_row.h's formulas for one row (double) and for W rows (lanes.h's vd) */
typedef struct {
    vd x, y, z;
} HcV3;

#define HR_T double
#define HR_V3 v3
#define HR_M int
#define HR_SUF _1
#define HR_BR(x) ((double)(x))
#define HR_SQRT sqrt
#define HR_ABS fabs
#define HR_SEL(m, a, b) ((m) ? (a) : (b))
#define HR_FINITE(x) (isfinite(x) != 0)
#define HR_NONE(m) (!(m))
#define HR_NOT(m) (!(m))
#include "held_row.h"

#define HR_T vd
#define HR_V3 HcV3
#define HR_M vl
#define HR_SUF _w
#define HR_BR(x) BR(x)
#define HR_SQRT vsqrt
#define HR_ABS vabs
#define HR_SEL vsel
#define HR_FINITE vfinite
#define HR_NONE(m) vany(~(m))
#define HR_NOT(m) (~(m))
#include "held_row.h"


/* The geometry from Pieper's parameter vector: 0 when the arm is not of this kind. */
static int hc_geo(const double *P, HcGeo *g)
{
    if ((int)P[PK_N] != 7 || (int)P[PK_HELD] != 6 || (int)P[PK_CASE] != PK_START)
        return 0;
    double L = P[PK_SCALE];
    g->L = L;
    for (int k = 0; k < 7; k++) {
        g->h[k] = v3_at(P, PK_AXES + 3 * k);
        g->o[k] = v3_at(P, PK_POINTS + 3 * k);
        g->sign[k] = P[PK_SIGN + k];
        g->off[k] = P[PK_OFFSET + k];
        g->lo[k] = P[PK_LO + k];
        g->hi[k] = P[PK_HI + k];
        double half = 0.5 * (g->hi[k] - g->lo[k]);
        double mid = g->sign[k] * (g->lo[k] + half) + g->off[k];
        double sh, ch;
        sincos1(half, &sh, &ch);
        if (fabs(g->sign[k]) != 1.0 || !(sh > HC_ARC_MIN) || !(half > 0.0))
            return 0; /* (a range within HC_ARC_MIN of 0 or a whole turn: the grid's) */
        sincos1(mid, &g->arc[k][1], &g->arc[k][0]);
        g->arc[k][2] = ch;
        g->arc[k][3] = 1.0 / sh;
        const double *h = &P[PK_AXES + 3 * k];
        g->ax[k] = 3;
        g->axs[k] = 1.0;
        for (int a = 0; a < 3; a++)
            if (fabs(fabs(h[a]) - 1.0) < 1e-15 && fabs(h[(a + 1) % 3]) < 1e-15 &&
                fabs(h[(a + 2) % 3]) < 1e-15) { /* (within rounding: a DH frame's 6e-17) */
                g->ax[k] = a;
                g->axs[k] = h[a] > 0.0 ? 1.0 : -1.0;
            }
    }
    g->RM = (m3){v3_at(P, PK_TOOL_R), v3_at(P, PK_TOOL_R + 3), v3_at(P, PK_TOOL_R + 6)};
    g->tM = v3_at(P, PK_TOOL_T);
    g->S = v3_at(P, PK_POINT);
    /* axes 1 and 3 one line through S, axis 2 normal to it */
    if (!(v3_dot(g->h[0], g->h[2]) > 1.0 - 1e-14) || !(fabs(v3_dot(g->h[0], g->h[1])) < 1e-14))
        return 0;
    for (int k = 0; k < 3; k++)
        if (!(v3_norm(v3_cross(g->h[k], v3_sub(g->S, g->o[k]))) < 1e-12 * L))
            return 0;
    g->e1 = g->h[0];
    g->e2 = g->h[1];
    g->ea = v3_cross(g->e2, g->e1);
    /* W: axes 5 and 6 meet */
    v3 n = v3_cross(g->h[4], g->h[5]);
    double nn = v3_dot(n, n);
    if (!(nn > 1e-6))
        return 0;
    v3 d = v3_sub(g->o[5], g->o[4]);
    double s = v3_dot(v3_cross(d, g->h[5]), n) / nn;
    g->Wc = v3_add(g->o[4], v3_scale(g->h[4], s));
    if (!(v3_norm(v3_cross(g->h[5], v3_sub(g->Wc, g->o[5]))) < 1e-12 * L))
        return 0;
    /* E1: |a0 + cos v4 a1 + sin v4 a2|^2 = K + c1 cos v4 + c2 sin v4 */
    v3 h4 = g->h[3], a = v3_sub(g->S, g->o[3]);
    v3 apar = v3_scale(h4, v3_dot(h4, a));
    g->a0 = v3_add(v3_sub(g->o[3], g->Wc), apar);
    g->a1 = v3_sub(a, apar);
    g->a2 = v3_scale(v3_cross(h4, a), -1.0);
    g->K = v3_dot(g->a0, g->a0) + v3_dot(g->a1, g->a1);
    g->c1 = 2.0 * v3_dot(g->a0, g->a1);
    g->c2 = 2.0 * v3_dot(g->a0, g->a2);
    g->cn = hypot(g->c1, g->c2);
    if (!(g->cn > 1e-9 * L * L))
        return 0;
    v3 h5 = g->h[4];
    g->ec[0] = v3_dot(h5, g->a0);
    g->ec[1] = v3_dot(h5, g->a1);
    g->ec[2] = v3_dot(h5, g->a2);
    g->h56 = v3_dot(h5, g->h[5]);
    g->h56x = v3_cross(h5, g->h[5]);
    return 1;
}

/* The pose's coefficients; 0 when a coefficient is degenerate. */
static int hc_setup(const HcGeo *g, const double *T, HcPose *p)
{
    p->g = g;
    m3 RT = {{T[0], T[1], T[2]}, {T[4], T[5], T[6]}, {T[8], T[9], T[10]}};
    v3 pT = {T[3], T[7], T[11]};
    /* p0 = M T^-1 S */
    v3 ts = m3_mtv(&RT, v3_sub(g->S, pT));
    v3 p0 = v3_add(m3_mv(&g->RM, ts), g->tM);
    v3 h7 = g->h[6], B = v3_sub(p0, g->o[6]);
    v3 Bpar = v3_scale(h7, v3_dot(h7, B));
    p->v[0] = v3_add(v3_sub(g->o[6], g->Wc), Bpar);
    p->v[1] = v3_sub(B, Bpar);
    p->v[2] = v3_cross(h7, B);
    p->d[0] = v3_dot(p->v[0], p->v[0]) + v3_dot(p->v[1], p->v[1]);
    p->d[1] = 2.0 * v3_dot(p->v[0], p->v[1]);
    p->d[2] = 2.0 * v3_dot(p->v[0], p->v[2]);
    v3 h5 = g->h[4], h6 = g->h[5];
    for (int k = 0; k < 3; k++) {
        double hv = v3_dot(h6, p->v[k]);
        p->h6v[k] = hv;
        p->f0[k] = g->h56 * hv;
        p->f1[k] = v3_dot(h5, p->v[k]) - p->f0[k];
        p->f2[k] = v3_dot(p->v[k], g->h56x);
    }
    /* R_G0 = R_T R_M^T (rows) */
    for (int r = 0; r < 3; r++) {
        v3 row = r == 0 ? RT.r0 : r == 1 ? RT.r1 : RT.r2;
        v3 out = m3_mv(&g->RM, row); /* (R_T R_M^T)[r][c] = row . RM row c */
        if (r == 0)
            p->RG0.r0 = out;
        else if (r == 1)
            p->RG0.r1 = out;
        else
            p->RG0.r2 = out;
    }
    p->g1 = m3_mtv(&p->RG0, g->e1);
    double a = g->sign[6] * g->lo[6] + g->off[6], b = g->sign[6] * g->hi[6] + g->off[6];
    p->xlo = fmin(a, b);
    p->xhi = fmax(a, b);
    return isfinite(p->d[0] + p->d[1] + p->d[2]);
}

/* E1's margin at x (|c| - |D - K|: >= 0 where v4 has roots) */
static inline double hc_m1(const HcPose *p, double c, double s)
{
    return p->g->cn - fabs(hr_aff_1(p->d, c, s) - p->g->K);
}

/* E2's margin of v4 root i at x (held_row.h's hr_m2), its slope when dm != NULL */
static inline double hc_m2(const HcPose *p, double x, int i, double *dm)
{
    double c, s;
    sincos1(x, &s, &c);
    return hr_m2_1(p, c, s, i, dm);
}

/* Branch (i, j)'s row at x (what: HC_SHOULDER, HC_SLOPES, HC_NOISE, HC_RONLY; held_row.h's
 * hr_row); 0 when it has none (a margin below -tol). */
static int hc_eval(const HcPose *p, double x, int i, int j, int what, HcRow *r)
{
    double c, s;
    sincos1(x, &s, &c);
    r->x = x;
    HrRow_1 o = {0};
    if (!hr_row_1(p, c, s, i, j, what, &o))
        return 0;
    for (int k = 0; k < 3; k++) {
        r->cs[k + 3][0] = o.cs[k][0];
        r->cs[k + 3][1] = o.cs[k][1];
    }
    r->c = c;
    r->s = s;
    r->noise = o.noise;
    r->ronly = o.ronly;
    r->sloped = o.sloped != 0.0;
    r->nf = 0;
    r->hasmg = 0; /* hc_rowq's, when asked */
    if (what & HC_SHOULDER)
        for (int k = 0; k < 5; k++)
            r->sh[k] = o.sh[k];
    if (!(what & HC_SLOPES))
        return 1;
    for (int k = 0; k < 3; k++)
        r->dv[k + 3] = o.dv[k];
    r->dv[6] = 1.0;
    if (what & HC_SHOULDER) {
        r->in = o.in;
        for (int k = 0; k < 5; k++)
            r->dsh[k] = o.dsh[k];
    }
    return 1;
}

/* An r-only row (HC_RONLY) completed: w and its slope by hc_eval's formulas */
static void hc_full(const HcPose *p, HcRow *r)
{
    if (!r->ronly)
        return;
    const HcGeo *g = p->g;
    double cs[4][2] = {{r->cs[3][0], r->cs[3][1]}, {r->cs[4][0], r->cs[4][1]},
                       {r->cs[5][0], r->cs[5][1]}, {r->c, r->s}};
    v3 w = hr_w_1(p, (const double(*)[2])cs);
    r->sh[0] = v3_dot(w, g->ea);
    r->sh[1] = v3_dot(w, g->e2);
    r->sh[2] = v3_dot(w, g->e1);
    if (r->sloped) { /* (never a branch end's row: those are never r-only) */
        double omsum;
        v3 dw = hr_dw_1(p, r->c, r->s, r->in, w, &omsum);
        r->dsh[0] = v3_dot(dw, g->ea);
        r->dsh[1] = v3_dot(dw, g->e2);
        r->dsh[2] = v3_dot(dw, g->e1);
        r->sloped = isfinite(omsum);
    }
    r->ronly = 0;
    r->nf = 0;
    r->hasmg = 0;
}

/* sin v2 = |(w.ea, w.e2)| (r-only rows: |(r.ea, r.e2)|; held_row.h's hr_rho) */
static inline double hc_rho(const HcRow *r) { return hr_rho_1(r->sh, r->ronly); }

/* Chain values of a row, triple k (0: v2 >= 0; 1: the other) */
static void hc_angles(const HcRow *r, int k, double *v)
{
    double wa = r->sh[0], wb = r->sh[1], wc = r->sh[2], ra = r->sh[3], rb = r->sh[4];
    v[0] = fast_atan2(wb, wa);
    v[1] = fast_atan2(sqrt(wa * wa + wb * wb), wc);
    v[2] = fast_atan2(rb, -ra);
    if (k) {
        v[0] = wrap_pi(v[0] + M_PI);
        v[1] = -v[1];
        v[2] = wrap_pi(v[2] + M_PI);
    }
    for (int j = 3; j < 6; j++)
        v[j] = fast_atan2(r->cs[j][1], r->cs[j][0]);
    v[6] = r->x;
}

/* Row r's margins of joints 1-6 to their limits, both triples (mg[k][j]: held_row.h's
 * hr_margins; joint 7, the held one, inside by construction: +inf) */
static void hc_margins(const HcGeo *g, const HcRow *r, double mg[2][7])
{
    double m[2][6];
    hr_margins_1(g, r->sh, r->ronly, (const double(*)[2])(r->cs + 3), m);
    for (int k = 0; k < 2; k++) {
        for (int j = 0; j < 6; j++)
            mg[k][j] = m[k][j];
        mg[k][6] = INFINITY;
    }
}

/* The least of margins mg (7) over the joints other than `skip` */
static inline double hc_least(const double *mg, int skip)
{
    double m = INFINITY;
    for (int j = 0; j < 6; j++)
        if (j != skip && mg[j] < m) /* (a NaN margin, unknown, skipped as fmin does) */
            m = mg[j];
    return m;
}

/* Row r's margins (into r->mg) and each triple's least margin */
static void hc_rowq(const HcPose *p, HcRow *r, double *margin)
{
    hc_margins(p->g, r, r->mg);
    r->hasmg = 1;
    margin[0] = hc_least(r->mg[0], -1);
    margin[1] = hc_least(r->mg[1], -1);
}

/* Triple k's chain value of shoulder joint j (0-2) on row r (hc_angles' for one) */
static double hc_angle1(const HcRow *r, int k, int j)
{
    const double *a = r->sh;
    double v = j == 0 ? fast_atan2(a[1], a[0])
             : j == 1 ? fast_atan2(hc_rho(r), a[2])
                      : fast_atan2(a[4], -a[3]);
    return !k ? v : j == 1 ? -v : wrap_pi(v + M_PI);
}

/* Query q's value on row r, its slope d/dx when ds != NULL, and the triple a root of
 * it belongs to (*k) */
static double hc_f(const HcQuery *q, const HcRow *r, double *ds, int *k)
{
    const double *a = r->sh;
    if (ds != NULL)
        *ds = hr_query_1(q, r->dsh, 1);
    if (k != NULL) {
        double side = q->j == 0 ? q->cV * a[0] + q->sV * a[1]
                    : q->j == 1 ? q->V
                                : -q->cV * a[3] + q->sV * a[4];
        *k = side > 0.0 ? 0 : 1;
    }
    return hr_query_1(q, a, 0);
}

/* ------------------------------------------------------------------ events */

typedef struct {
    double x;
    int j, kind, k;  /* k: the triple (-1: both) */
    double mg[2];    /* per triple: the least margin of the other joints there */
    double mgall[2]; /* ... of every joint */
    double wal;      /* the least |sin| of the other wrist joints' chain values */
} HcEvent;

typedef struct {
    const double *T;
    HcPose p;
    HcQuery q[HC_MAXQ];
    int nq, bad;
    int ronly; /* HC_RONLY where every query located everywhere takes r alone, else 0 */
    HcEvent ev[4][HC_MAXE]; /* per position branch 2 i + j */
    int nev[4];
    double cut[4][2 * HC_MAXPC]; /* the branch's piece ends (x), as pairs */
    int cutfold[4][2 * HC_MAXPC]; /* that end: 0 the range's, 1 E1's branch end, 2 E2's */
    double cutd[4][2 * HC_MAXPC]; /* how far hc_snap moved it */
    int npc[4];
    double node[4][HC_MAXN][3]; /* per branch: x and both triples' least margins there */
    double ncs[HC_NODES][2], mcs[HC_MNODES][2]; /* cos, sin of pi xi at the nodes */
    int nnode[4];
    long rows; /* row evaluations (a measuring build's evals: HM_COUNT_CHEAP) */
    double kept_t[HC_ROWS_KEPT]; /* hc_row_at's fronts: their position slots' rows */
    unsigned char kept_valid[HC_ROWS_KEPT][4];
    unsigned kept_known[HC_ROWS_KEPT]; /* the slots solved there (bits 0-3) */
    int nkept;
    PkFrontMemo front; /* pk_front_memo's held-value-free parts */
    double wal[HC_MAXQ][3]; /* the wrist's aligned values: joint, cos and sin of V */
    int nwal;
} HcCtx;

/* ----------------------------------------------------------- rows in lanes */

/* Rows of branch (i, j) at x[0..n) into out[] as hc_eval's HC_SHOULDER | HC_SLOPES rows
 * (in full: never r-only), each with its margins (hc_rowq's: hasmg) and the queries'
 * values and slopes (hc_cell's: nf = c->nq; also fq[m][k], dq[m][k] of query m at
 * x[k], rows of HC_NODES + W doubles), W at a time; 0 when one of them has no row */
static int hc_eval_lanes(const HcCtx *c, const double *x, int n, int i, int j, HcRow *out,
                         double (*fq)[HC_NODES + W], double (*dq)[HC_NODES + W])
{
    const HcPose *p = &c->p;
    for (int b = 0; b < n; b += W) {
        vd X, cx, sx;
        for (int l = 0; l < W; l++)
            X[l] = x[b + l < n ? b + l : n - 1];
        vsincos(X, &sx, &cx);
        HrRow_w o;
        if (!hr_row_w(p, cx, sx, i, j, HC_SHOULDER | HC_SLOPES, &o))
            return 0;
        vd mg[2][6], f[HC_MAXQ], df[HC_MAXQ];
        hr_margins_w(p->g, o.sh, 0, (const vd(*)[2])o.cs, mg);
        for (int m = 0; m < c->nq; m++) {
            f[m] = hr_query_w(&c->q[m], o.sh, 0);
            df[m] = hr_query_w(&c->q[m], o.dsh, 1);
            memcpy(fq[m] + b, &f[m], sizeof(vd)); /* (n <= HC_NODES: within the row) */
            memcpy(dq[m] + b, &df[m], sizeof(vd));
        }
        for (int l = 0; l < W && b + l < n; l++) {
            HcRow *r = &out[b + l];
            r->x = X[l];
            r->c = cx[l];
            r->s = sx[l];
            for (int k = 0; k < 3; k++) {
                r->cs[k + 3][0] = o.cs[k][0][l];
                r->cs[k + 3][1] = o.cs[k][1][l];
                r->dv[k + 3] = o.dv[k][l];
            }
            r->dv[6] = 1.0;
            r->noise = NAN;
            for (int k = 0; k < 5; k++) {
                r->sh[k] = o.sh[k][l];
                r->dsh[k] = o.dsh[k][l];
            }
            r->in = (v3){o.in.x[l], o.in.y[l], o.in.z[l]};
            r->sloped = o.sloped[l] != 0.0;
            r->ronly = 0;
            for (int t = 0; t < 2; t++) {
                for (int jj = 0; jj < 6; jj++)
                    r->mg[t][jj] = mg[t][jj][l];
                r->mg[t][6] = INFINITY;
            }
            r->hasmg = 1;
            for (int m = 0; m < c->nq; m++) {
                r->f[m] = f[m][l];
                r->df[m] = df[m][l];
            }
            r->nf = c->nq;
        }
    }
    for (int m = 0; m < c->nq; m++) /* (read past the last node by hc_busy_cells) */
        fq[m][n] = dq[m][n] = 0.0;
    return 1;
}

/* E2's margin of v4 root i and its slope d/dx (hr_m2) at x[0..n) into m[], dm[], W at
 * a time */
static void hc_m2_lanes(const HcPose *p, const double *x, int n, int i, double *m, double *dm)
{
    for (int b = 0; b < n; b += W) {
        vd X, c, s, d;
        for (int l = 0; l < W; l++)
            X[l] = x[b + l < n ? b + l : n - 1];
        vsincos(X, &s, &c);
        vd mm = hr_m2_w(p, c, s, i, &d);
        for (int l = 0; l < W && b + l < n; l++) {
            m[b + l] = mm[l];
            dm[b + l] = d[l];
        }
    }
}

/* Node row r of branch bj kept (x and both triples' least margins) for the pieces'
 * decisions (a slot is inside or outside all over a piece between its located events:
 * its membership changes only at a crossing with the other joints inside, never in a
 * dead cell); past HC_MAXN the rest are not kept (the decisions' rows then) */
static void hc_keep(HcCtx *c, int bj, HcRow *r)
{
    if (c->nnode[bj] >= HC_MAXN)
        return;
    double mg[2];
    if (r->hasmg) { /* (hc_eval_lanes') */
        mg[0] = hc_least(r->mg[0], -1);
        mg[1] = hc_least(r->mg[1], -1);
    } else
        hc_rowq(&c->p, r, mg);
    double *n = c->node[bj][c->nnode[bj]++];
    n[0] = r->x;
    n[1] = mg[0];
    n[2] = mg[1];
}

/* Event (x, joint j, kind, triple k) of branch bj, its row r there (HC_SHOULDER) */
static void hc_add(HcCtx *c, int bj, double x, int j, int kind, int k, const HcRow *r)
{
    if (c->nev[bj] >= HC_MAXE) {
        c->bad = __LINE__;
        return;
    }
    double mgs[2][7], wal = INFINITY;
    hc_margins(c->p.g, r, mgs);
    for (int jj = 3; jj < 6; jj++)
        if (jj != j)
            wal = fmin(wal, fabs(r->cs[jj][1]));
    c->ev[bj][c->nev[bj]++] =
        (HcEvent){x, j, kind, k, {hc_least(mgs[0], j), hc_least(mgs[1], j)},
                  {hc_least(mgs[0], -1), hc_least(mgs[1], -1)}, wal};
}

/* Roots x of a0 + a1 cos x + a2 sin x = 0 (at most 2) */
static int hc_sin_roots(double a0, double a1, double a2, double *x)
{
    double h2 = a1 * a1 + a2 * a2;
    if (!(h2 > 0.0) || a0 * a0 > h2)
        return 0;
    double cphi, sphi;
    unit2(a2, a1, &cphi, &sphi);
    Roots r = sp4_roots(a1, a2, -a0, h2 - a0 * a0, 0.0, 0, fast_atan2(a2, a1), cphi, sphi);
    x[0] = wrap_pi(r.t[0]);
    x[1] = wrap_pi(r.t[1]);
    double d = 0.5 * fabs(r.t[0] - r.t[1]); /* acos(-a0 / |(a1, a2)|) */
    if (d < HC_DOUBLE || M_PI - d < HC_DOUBLE)
        return -1; /* near double (tangent): the grid's */
    return 2;
}

/* Roots x of (al . w)^2 + (be . w)^2 = 1, w = (1, cos x, sin x): a quartic in
 * tan(y / 2), x = y + phi, phi chosen so that its leading coefficient (the
 * function at y = pi) is not small; every real root Newton-polished. */
static int hc_quartic_roots(const double *al, const double *be, double *x)
{
    static const double turn[4][2] = {{1.0, 0.0}, {0.0, 1.0}, {-1.0, 0.0}, {0.0, -1.0}};
    double best = -1.0;
    int mb = 0;
    for (int m = 0; m < 4; m++) { /* the shift phi = m pi / 2: the largest |F(phi + pi)| */
        double cc = -turn[m][0], ss = -turn[m][1]; /* (cos, sin of phi + pi) */
        double A = al[0] + al[1] * cc + al[2] * ss, B = be[0] + be[1] * cc + be[2] * ss;
        double F = fabs(A * A + B * B - 1.0);
        if (F > best) {
            best = F;
            mb = m;
        }
    }
    double phi = 0.5 * M_PI * mb, cp = turn[mb][0], sp = turn[mb][1];
    /* in y: cos x = cp cos y - sp sin y, sin x = sp cos y + cp sin y */
    double a[3] = {al[0], al[1] * cp + al[2] * sp, -al[1] * sp + al[2] * cp};
    double b[3] = {be[0], be[1] * cp + be[2] * sp, -be[1] * sp + be[2] * cp};
    /* (1 + u^2) (a . w) = (a0 - a1) u^2 + 2 a2 u + (a0 + a1) */
    double pa[3] = {a[0] + a[1], 2.0 * a[2], a[0] - a[1]}; /* u^0, u^1, u^2 */
    double pb[3] = {b[0] + b[1], 2.0 * b[2], b[0] - b[1]};
    double cf[5];
    for (int e = 0; e < 5; e++)
        cf[e] = 0.0;
    for (int m = 0; m < 3; m++)
        for (int n = 0; n < 3; n++)
            cf[m + n] += pa[m] * pa[n] + pb[m] * pb[n];
    cf[0] -= 1.0; /* (1 + u^2)^2 */
    cf[2] -= 2.0;
    cf[4] -= 1.0;
    if (!(fabs(cf[4]) > 1e-12))
        return -1;
    double re[4], im[4];
    pk_quartic(cf, re, im);
    int n = 0;
    for (int m = 0; m < 4; m++) {
        /* a root pair near double (a joint next to tangent to its value): the grid's */
        if (fabs(im[m]) > 0.0 && fabs(im[m]) < HC_DOUBLE * (1.0 + fabs(re[m])))
            return -1;
        for (int o = 0; o < m; o++)
            if (fabs(im[o]) == 0.0 && fabs(im[m]) == 0.0 &&
                fabs(re[m] - re[o]) < HC_DOUBLE * (1.0 + fabs(re[m])))
                return -1;
        if (!(fabs(im[m]) <= 1e-6 * (1.0 + fabs(re[m]))))
            continue;
        double y = 2.0 * atan(re[m]);
        for (int it = 0; it < 8; it++) {
            double cy, sy;
            sincos1(y, &sy, &cy);
            double A = a[0] + a[1] * cy + a[2] * sy, B = b[0] + b[1] * cy + b[2] * sy;
            double dA = -a[1] * sy + a[2] * cy, dB = -b[1] * sy + b[2] * cy;
            double F = A * A + B * B - 1.0, dF = 2.0 * (A * dA + B * dB);
            if (!(fabs(dF) > 0.0))
                break;
            double step = F / dF;
            y -= step;
            if (fabs(step) <= 2.0 * DBL_EPSILON * fmax(1.0, fabs(y)))
                break; /* (at F's rounding: y's last bits) */
        }
        double cy, sy;
        sincos1(y, &sy, &cy);
        double A = a[0] + a[1] * cy + a[2] * sy, B = b[0] + b[1] * cy + b[2] * sy;
        if (fabs(A * A + B * B - 1.0) < 1e-10)
            x[n++] = wrap_pi(y + phi);
    }
    return n;
}

/* Branch (i, j)'s row at x with its joint jj's chain value within 1e-6 of V: the
 * value Newton-polished along the branch (x moved), 1 when it ends within HC_AT with
 * a slope neither steep nor flat (else c->bad); 0 when the branch is not there. *rp:
 * the last row (the wrist's alone; at *x unless the last step moved it). */
static int hc_polish(HcCtx *c, int i, int j, int jj, double V, double *x, HcRow *rp)
{
    HcRow r = {0};
    double t = *x, f = NAN, d = NAN;
    for (int it = 0; it < 5; it++) {
        if (!hc_eval(&c->p, t, i, j, HC_SLOPES | HC_NOISE, &r)) /* (the wrist alone) */
            return 0;
        c->rows++;
        f = wrap_pi(fast_atan2(r.cs[jj][1], r.cs[jj][0]) - V);
        if (it == 0 && !(fabs(f) < 1e-6))
            return 0;
        d = r.dv[jj];
        if (!r.sloped || !(fabs(d) > 1e-6)) {
            c->bad = __LINE__; /* a touch (or a branch end) */
            return 0;
        }
        double step = f / d;
        if (fabs(f) <= 0.25 * HC_AT || fabs(step) <= DBL_EPSILON * fmax(1.0, fabs(t)))
            break;
        t -= step;
    }
    /* as hc_root_q: to HC_AT, or what the last bits of x allow (a steep crossing) */
    double tol = fmax(HC_AT, 8.0 * fmax(fabs(d) * DBL_EPSILON * fmax(1.0, fabs(t)), r.noise));
    if (!(fabs(f) <= tol) || !(fabs(f) <= HC_AT_STEEP)) {
        c->bad = __LINE__;
        return 0;
    }
    *x = t;
    *rp = r;
    return 1;
}

/* The closed-form events of joint jj (3: v4, 4: v5, 5: v6) at chain value V */
static void hc_closed_events(HcCtx *c, int jj, double V, int kind)
{
    const HcGeo *g = c->p.g;
    const HcPose *p = &c->p;
    double cV, sV, x[4];
    sincos1(V, &sV, &cV);
    double al[3] = {NAN, NAN, NAN}, be[3] = {NAN, NAN, NAN}; /* (cos, sin v4) = (al, be) . w */
    int n;
    if (jj == 3) {
        n = hc_sin_roots(p->d[0] - g->K - g->c1 * cV - g->c2 * sV, p->d[1], p->d[2], x);
        if (n < 0) {
            c->bad = __LINE__;
            return;
        }
    } else {
        double row0, row1, rhs[3];
        if (jj == 5) {
            row0 = g->ec[1];
            row1 = g->ec[2];
            for (int m = 0; m < 3; m++)
                rhs[m] = p->f0[m] + p->f1[m] * cV + p->f2[m] * sV - (m == 0 ? g->ec[0] : 0.0);
        } else {
            v3 mv = hr_rot_1(g, 4, cV, sV, g->h[5]);
            row0 = v3_dot(mv, g->a1);
            row1 = v3_dot(mv, g->a2);
            double m0 = v3_dot(mv, g->a0);
            for (int m = 0; m < 3; m++)
                rhs[m] = p->h6v[m] - (m == 0 ? m0 : 0.0);
        }
        double det = g->c1 * row1 - g->c2 * row0, nr = hypot(row0, row1);
        if (!(nr > 1e-12 * g->L) || !(fabs(det) > 1e-10 * g->cn * nr)) {
            /* the two equations dependent: the value fixes x alone (the Panda's v5 = 0,
             * pi: axes 4 and 6 parallel; row = lambda (c1, c2), or 0) */
            double lam = nr > 1e-12 * g->L ? (row0 * g->c1 + row1 * g->c2) / (g->cn * g->cn) : 0.0;
            n = hc_sin_roots(lam * (p->d[0] - g->K) - rhs[0], lam * p->d[1] - rhs[1],
                             lam * p->d[2] - rhs[2], x);
            if (n < 0) {
                c->bad = __LINE__;
                return;
            }
            goto found;
        }
        for (int m = 0; m < 3; m++) {
            double r1 = p->d[m] - (m == 0 ? g->K : 0.0);
            al[m] = (row1 * r1 - g->c2 * rhs[m]) / det;
            be[m] = (g->c1 * rhs[m] - row0 * r1) / det;
        }
        n = hc_quartic_roots(al, be, x);
        if (n < 0) {
            c->bad = __LINE__;
            return;
        }
    }
found:
    for (int m = 0; m < n; m++) {
        if (fabs(x[m] - p->xlo) < HC_CORNER || fabs(x[m] - p->xhi) < HC_CORNER) {
            c->bad = __LINE__; /* a value at an end of the range (a corner) */
            return;
        }
        if (!(x[m] >= p->xlo && x[m] <= p->xhi))
            continue;
        /* the v4 root at x[m] (V itself, or the quartic's (cos, sin v4)): its branches
         * i alone are polished (both near E1's branch end; all four where the value
         * fixes x alone) */
        int want = 15;
        double cx, sx, c4 = jj == 3 ? cV : NAN, s4 = jj == 3 ? sV : NAN;
        sincos1(x[m], &sx, &cx);
        if (jj != 3 && isfinite(al[0])) {
            c4 = al[0] + al[1] * cx + al[2] * sx;
            s4 = be[0] + be[1] * cx + be[2] * sx;
        }
        if (isfinite(c4)) {
            want = 0;
            double D = hr_aff_1(p->d, cx, sx);
            for (int i = 0; i < 2; i++) {
                double ci, si, sg;
                hr_root_1(g->c1, g->c2, g->cn, D - g->K, i, &ci, &si, &sg);
                if (fabs(ci - c4) + fabs(si - s4) < 1e-3) /* (hc_polish: 1e-6 of V) */
                    want |= 3 << (2 * i);
            }
        }
        for (int bj = 0; bj < 4; bj++) {
            double t = x[m];
            HcRow r;
            if ((want >> bj & 1) && hc_polish(c, bj >> 1, bj & 1, jj, V, &t, &r) &&
                t >= p->xlo && t <= p->xhi) {
                int dup = 0; /* a double root of the quartic, or the same root twice */
                for (int e = 0; e < c->nev[bj]; e++)
                    dup |= c->ev[bj][e].j == jj && c->ev[bj][e].kind == kind &&
                           fabs(c->ev[bj][e].x - t) < HC_CLOSE;
                if (dup)
                    continue;
                if (r.x == t) { /* the polish's row, its shoulder added */
                    double cs[4][2] = {{r.cs[3][0], r.cs[3][1]}, {r.cs[4][0], r.cs[4][1]},
                                       {r.cs[5][0], r.cs[5][1]}, {r.c, r.s}};
                    v3 w, rr;
                    hr_shoulder_1(&c->p, (const double(*)[2])cs, 0, r.sh, &w, &rr);
                } else if (!hc_eval(&c->p, t, bj >> 1, bj & 1, HC_SHOULDER, &r)) {
                    c->bad = __LINE__;
                    return;
                } else {
                    c->rows++;
                }
                hc_add(c, bj, t, jj, kind, -1, &r);
            }
        }
    }
}

/* ---------------------------------------------------- the numeric events */

/* The cubic Hermite model's (hc_hermite's) interior extremum nearest 0: its place
 * (*tau in (0, 1)) and value; 0 when it has none */
static int hc_extremum(double f0, double f1, double d0, double d1, double *tau, double *val)
{
    double A = 6.0 * f0 + 3.0 * d0 - 6.0 * f1 + 3.0 * d1;
    double B = -6.0 * f0 - 4.0 * d0 + 6.0 * f1 - 2.0 * d1, C = d0;
    double t[2];
    int n = 0, found = 0;
    if (fabs(A) > 1e-300) {
        double disc = B * B - 4.0 * A * C;
        if (disc >= 0.0) {
            double sq = sqrt(disc), qq = -0.5 * (B + copysign(sq, B));
            t[n++] = qq != 0.0 ? qq / A : 0.0;
            if (qq != 0.0)
                t[n++] = C / qq;
        }
    } else if (fabs(B) > 1e-300) {
        t[n++] = -C / B;
    }
    for (int m = 0; m < n; m++) {
        double u = t[m];
        if (!(u > 0.0 && u < 1.0))
            continue;
        double u2 = u * u, u3 = u2 * u;
        double v = (2 * u3 - 3 * u2 + 1) * f0 + (u3 - 2 * u2 + u) * d0 + (-2 * u3 + 3 * u2) * f1 +
                   (u3 - u2) * d1;
        if (!found || fabs(v) < fabs(*val)) {
            *tau = u;
            *val = v;
            found = 1;
        }
    }
    return found;
}

/* Whether a cubic Hermite model on [0, 1] (values f0, f1, slopes d0, d1 times the
 * cell) may cross 0 other than once at a sign change (*split) or comes within tol
 * of it without one (*near). */
static inline void hc_hermite(double f0, double f1, double d0, double d1, double tol,
                              int *split, int *near)
{
    /* the model within 4/27 (|d0| + |d1|) of a mean of f0 and f1 (its Hermite basis):
     * of one sign and clear of tol when both ends are further than that */
    if ((f0 < 0.0) == (f1 < 0.0) &&
        fmin(fabs(f0), fabs(f1)) > (4.0 / 27.0) * (fabs(d0) + fabs(d1)) + tol) {
        *split = *near = 0;
        return;
    }
    double A = 6.0 * f0 + 3.0 * d0 - 6.0 * f1 + 3.0 * d1;
    double B = -6.0 * f0 - 4.0 * d0 + 6.0 * f1 - 2.0 * d1, C = d0;
    double tau[2];
    int nt = 0;
    if (fabs(A) > 1e-300) {
        double disc = B * B - 4.0 * A * C;
        if (disc >= 0.0) {
            double sq = sqrt(disc), qq = -0.5 * (B + copysign(sq, B));
            if (qq != 0.0) {
                tau[nt++] = qq / A;
                tau[nt++] = C / qq;
            } else {
                tau[nt++] = 0.0;
            }
        }
    } else if (fabs(B) > 1e-300) {
        tau[nt++] = -C / B;
    }
    int changes = 0;
    double last = f0;
    *split = *near = 0;
    double ext[2];
    int ne = 0;
    for (int m = 0; m < nt; m++)
        if (tau[m] > 0.0 && tau[m] < 1.0)
            ext[ne++] = tau[m];
    if (ne == 2 && ext[0] > ext[1]) {
        double w = ext[0];
        ext[0] = ext[1];
        ext[1] = w;
    }
    for (int m = 0; m <= ne; m++) {
        double v;
        if (m < ne) {
            double t = ext[m], t2 = t * t, t3 = t2 * t;
            v = (2 * t3 - 3 * t2 + 1) * f0 + (t3 - 2 * t2 + t) * d0 + (-2 * t3 + 3 * t2) * f1 +
                (t3 - t2) * d1;
            if (fabs(v) < tol)
                *near = 1;
        } else {
            v = f1;
        }
        changes += (v < 0.0) != (last < 0.0);
        last = v;
    }
    *split = changes != ((f0 < 0.0) != (f1 < 0.0));
}

typedef struct {
    double a, b; /* the piece [a, b] in x */
    int fa, fb;  /* its ends are branch ends */
    int i, j;
    double sa, sb; /* how far hc_snap moved a branch end (x) */
} HcPiece;

static inline double hc_x(const HcPiece *pc, double xi)
{
    double s, c;
    sincos1(M_PI * xi, &s, &c);
    return pc->a + (pc->b - pc->a) * 0.5 * (1.0 - c);
}

static inline double hc_dx(const HcPiece *pc, double xi)
{
    double s, c;
    sincos1(M_PI * xi, &s, &c);
    return (pc->b - pc->a) * 0.5 * M_PI * s;
}

/* The root in (0, 1) of the cubic Hermite model with values f0, f1 of opposite signs
 * and slopes d0, d1 (times the cell): a start for hc_root_q (Illinois on the model) */
static double hc_model_root(double f0, double f1, double d0, double d1)
{
    double lo = 0.0, hi = 1.0, flo = f0, fhi = f1, t = 0.5;
    int side = 0;
    for (int it = 0; it < 30 && hi - lo > 1e-9; it++) {
        t = lo - flo * (hi - lo) / (fhi - flo);
        if (!(t > lo && t < hi))
            t = 0.5 * (lo + hi);
        double t2 = t * t, t3 = t2 * t;
        double v = (2 * t3 - 3 * t2 + 1) * f0 + (t3 - 2 * t2 + t) * d0 + (-2 * t3 + 3 * t2) * f1 +
                   (t3 - t2) * d1;
        if (v == 0.0)
            break;
        illinois_update(t, v, &lo, &flo, &hi, &fhi, &side);
    }
    return t;
}

/* Whether row r at x is query q's crossing (*k: its triple): the joint at its value
 * to HC_AT, or to what the last bits of x allow where it moves fast (next to a branch
 * end: as the square root of the distance), or what f's rounding and v5's (r.noise)
 * allow where the joint is ill-conditioned (q1, q3 next to an aligned shoulder: f at
 * its rounding is the joint off by that over |sin v2|), at most HC_AT_STEEP; |df / dv_j|
 * is |sin v2 cos(v_j - V)| ~ |sin v2| (v1, v3) or |sin V|. With step != 0 (Newton's
 * from x, f and slope d there, curv the slopes' secant over the last two iterates):
 * whether x + step is the crossing without its row (held_manifold.c's hm_last): the
 * joint's value there predicted by Newton's error (half the curvature times the step
 * squared, over cond) within HC_LAST_PRED, |f| <= HC_LAST_F, and the tolerance HC_AT
 * itself (neither steep nor ill-conditioned: r's rounding below it). */
static int hc_at_value(const HcQuery *q, const HcRow *r, double x, double step, double f,
                       double curv, int *k)
{
    double d;
    hc_f(q, r, &d, k);
    double cond = q->j == 1 ? fabs(q->sV) : hc_rho(r), rate = fabs(d) / cond;
    double tol = fmax(HC_AT, 8.0 * fmax(rate * DBL_EPSILON * fmax(1.0, fabs(x)),
                                        (r->noise + 4.0 * DBL_EPSILON) / cond));
    if (step != 0.0)
        return r->sloped && tol == HC_AT && fabs(f) <= HC_LAST_F &&
               0.5 * curv * step * step <= HC_LAST_PRED * cond;
    double off = fabs(wrap_pi(hc_angle1(r, *k, q->j) - q->V));
    return r->sloped && off <= tol && off <= HC_AT_STEEP;
}

/* A crossing of query q in the cell (ra, rb) at xi0 < xi1 (values f0, f1 of opposite
 * signs, slopes d0, d1 times the cell) on the piece's branch: from the cubic model's
 * root, safeguarded Newton / Illinois to the last bits; the event with its triple.
 * Newton's last step is taken without its row where hc_at_value predicts it at the
 * crossing: the last row stands for it (its triple, the other joints' margins). */
static void hc_root_q(HcCtx *c, const HcPiece *pc, const HcQuery *q, const HcRow *ra,
                      double xi0, double f0, double d0, const HcRow *rb, double xi1,
                      double f1, double d1, int ronly)
{
    HcRow r;
    double lo = ra->x, hi = rb->x, flo = f0, fhi = f1, xp = NAN, dp = NAN, xr;
    double x = hc_x(pc, xi0 + (xi1 - xi0) * hc_model_root(f0, f1, d0, d1));
    int side = 0, k, at = 0;
    for (int it = 0;; it++) {
        if (it >= 40) {
            c->bad = __LINE__;
            return;
        }
        if (!(x > lo && x < hi))
            x = 0.5 * (lo + hi);
        if (!hc_eval(&c->p, x, pc->i, pc->j, HC_SHOULDER | HC_SLOPES | HC_NOISE | ronly, &r)) {
            c->bad = __LINE__;
            return;
        }
        c->rows++;
        xr = x;
        double d, f = hc_f(q, &r, &d, NULL);
        /* at the root to its rounding: f is sin v2 sin(v_j - V) (v1, v3), cos v2 - cos V
         * (v2), each O(1), with v5's rounding (r.noise) in the angles */
        double sfac = q->j == 1 ? fabs(q->sV) : hc_rho(&r);
        if (fabs(f) <= 4.0 * DBL_EPSILON + 4.0 * r.noise * sfac)
            break;
        illinois_update(x, f, &lo, &flo, &hi, &fhi, &side);
        if (hi - lo <= 2.0 * DBL_EPSILON * fmax(1.0, fabs(x)))
            break;
        double nx = r.sloped && d != 0.0 ? x - f / d : NAN;
        if (nx > lo && nx < hi && nx != x &&
            hc_at_value(q, &r, x, nx - x, f, fabs((d - dp) / (x - xp)), &k)) {
            x = nx; /* Newton's last step (xp: NaN at the first row) */
            at = 1;
            break;
        }
        xp = x;
        dp = d;
        if (!(nx > lo && nx < hi)) /* Illinois */
            nx = lo - flo * (hi - lo) / (fhi - flo);
        x = nx;
    }
    if (!at && !hc_at_value(q, &r, xr, 0.0, NAN, NAN, &k)) { /* (r is xr's row) */
        c->bad = __LINE__;
        return;
    }
    hc_add(c, 2 * pc->i + pc->j, x, q->j, q->kind, k, &r);
    if (q->twin) /* the other triple at the other limit (-V) */
        hc_add(c, 2 * pc->i + pc->j, x, q->j,
               q->kind == HM_KIND_UPPER ? HM_KIND_LOWER : HM_KIND_UPPER, 1 - k, &r);
}

/* Whether joint m of triple k is outside its limits over (ra, rb) for certain: outside
 * at both ends and no event of that joint between them (the closed-form events of
 * v4-v6 on branch bj; a shoulder joint's limit functions of the same signs at both
 * ends, fa, fb: the queries' values) */
static int hc_out(const HcCtx *c, int bj, const HcRow *ra, const HcRow *rb, int k, int m,
                  const double *fa, const double *fb)
{
    for (const HcRow *r = ra; r != NULL; r = r == ra ? rb : NULL)
        if (!(r->mg[k][m] < 0.0)) /* (NaN: not known) */
            return 0;
    if (m >= 3) {
        for (int e = 0; e < c->nev[bj]; e++) {
            const HcEvent *ev = &c->ev[bj][e];
            if (ev->j == m && ev->kind != HM_KIND_ALIGNED && ev->x >= ra->x && ev->x <= rb->x)
                return 0;
        }
        return 1;
    }
    for (int n = 0; n < c->nq; n++)
        if (c->q[n].j == m && c->q[n].kind >= 0 && c->q[n].kind != HM_KIND_ALIGNED &&
            (fa[n] < 0.0) != (fb[n] < 0.0))
            return 0;
    return 1;
}

/* The cell (ra, rb) at xi0 < xi1 of a piece: each query's crossings, or a split */
static void hc_cell(HcCtx *c, const HcPiece *pc, HcRow *ra, double xi0, HcRow *rb,
                    double xi1, int depth)
{
    if (c->bad)
        return;
    double h = xi1 - xi0, sa = ra->dxi * h, sb = rb->dxi * h;
    double ea = 0.5 * (pc->b - pc->a) * M_PI * h; /* a branch end's row: d/dxi given */
    double at = 0.5; /* where a split cuts the cell */
    int split = 0, bj = 2 * pc->i + pc->j;
    double fa[HC_MAXQ], fb[HC_MAXQ], dfa[HC_MAXQ], dfb[HC_MAXQ], mgt[2];
    /* a wrist joint outside all over the cell (at both ends, no event of it between):
     * a dead cell for both triples, whose limit crossings bound nothing; only the
     * queries located everywhere are asked there (aligned values, the aligned-shoulder
     * guards), on r-only rows where those need r alone (c->ronly) */
    int dead = 0;
    for (HcRow *r = ra; r != NULL; r = r == ra ? rb : NULL)
        if (!r->hasmg)
            hc_rowq(&c->p, r, mgt);
    for (int m = 3; m < 6 && !dead; m++)
        dead = hc_out(c, bj, ra, rb, 0, m, NULL, NULL);
    if (!dead) {
        hc_full(&c->p, ra);
        hc_full(&c->p, rb);
    }
    for (HcRow *r = ra; r != NULL; r = r == ra ? rb : NULL) /* (a node is two cells') */
        for (; r->nf < c->nq; r->nf++)
            r->f[r->nf] = hc_f(&c->q[r->nf], r, &r->df[r->nf], NULL);
    for (int m = 0; m < c->nq && !split; m++) {
        const HcQuery *q = &c->q[m];
        if (dead && q->kind >= 0 && q->kind != HM_KIND_ALIGNED)
            continue;
        double da = ra->df[m], db = rb->df[m];
        fa[m] = ra->f[m];
        fb[m] = rb->f[m];
        da = ra->sloped == 2 ? da * ea : ra->sloped ? da * sa : NAN;
        db = rb->sloped == 2 ? db * ea : rb->sloped ? db * sb : NAN;
        int known = isfinite(da) && isfinite(db);
        if (!isfinite(da))
            da = fb[m] - fa[m];
        if (!isfinite(db))
            db = fb[m] - fa[m];
        dfa[m] = da;
        dfb[m] = db;
        double tol = q->kind < 0 ? HC_ALIGNED : HC_TOUCH;
        /* the common case first: of one sign and clear of 0 all over the cell (the
         * tests below then neither split nor flag it) */
        if (known && hr_clear_1(fa[m], fb[m], da, db, tol))
            continue;
        if (fabs(fa[m]) < (q->kind < 0 ? tol : HC_AT_NODE) ||
            fabs(fb[m]) < (q->kind < 0 ? tol : HC_AT_NODE)) {
            c->bad = __LINE__; /* next to an aligned shoulder; a node at a value (a touch,
                                * a corner: the generating configuration at a limit) */
            return;
        }
        int sp, near;
        hc_hermite(fa[m], fb[m], da, db, tol, &sp, &near);
        if (fabs(fb[m] - fa[m]) > HC_MOVE || fabs(da) > 2.0 * HC_MOVE || fabs(db) > 2.0 * HC_MOVE)
            sp = 1;
        if (!known && depth < HC_END_SPLITS && ((fa[m] < 0.0) != (fb[m] < 0.0) || near))
            sp = 1; /* next to a branch end: no slope there */
        split |= sp || near;
        /* an extremum toward 0 inside (a shallow excursion past a limit, q2 close to
         * an aligned shoulder): the cell split at the model's extremum until it is a
         * node (then both halves are monotone), as held_manifold.c locates extrema */
        double tau = 0.5, val = 0.0;
        if (!split && known && (fa[m] < 0.0) == (fb[m] < 0.0) &&
            (fa[m] > 0.0 ? da < 0.0 && db > 0.0 : da > 0.0 && db < 0.0) &&
            hc_extremum(fa[m], fb[m], da, db, &tau, &val) &&
            fabs(val) < HC_DIP * fmin(fabs(fa[m]), fabs(fb[m]))) {
            split = 1;
            at = fmin(fmax(tau, 0.1), 0.9);
            if (fabs(rb->x - ra->x) < HC_DIP_WIDTH || fabs(val) < HC_AT_NODE) {
                c->bad = __LINE__; /* a touch, or a crossing pair closer than this */
                return;
            }
        }
    }
    if (split) {
        if (depth >= HC_DEPTH) {
            c->bad = __LINE__;
            return;
        }
        double xm = xi0 + at * (xi1 - xi0);
        HcRow rm;
        if (!hc_eval(&c->p, hc_x(pc, xm), pc->i, pc->j,
                     HC_SHOULDER | HC_SLOPES | (dead ? c->ronly : 0), &rm)) {
            c->bad = __LINE__;
            return;
        }
        rm.dxi = hc_dx(pc, xm);
        c->rows++;
        hc_keep(c, 2 * pc->i + pc->j, &rm);
        hc_cell(c, pc, ra, xi0, &rm, xm, depth + 1);
        hc_cell(c, pc, &rm, xm, rb, xi1, depth + 1);
        return;
    }
    int deadk[2] = {-1, -1}; /* per triple: unknown yet */
    for (int m = 0; m < c->nq; m++) {
        const HcQuery *q = &c->q[m];
        if (q->kind < 0 || (dead && q->kind != HM_KIND_ALIGNED) || (fa[m] < 0.0) == (fb[m] < 0.0))
            continue;
        if (fa[m] == 0.0 || fb[m] == 0.0) {
            c->bad = __LINE__; /* a node exactly on a crossing */
            return;
        }
        if (q->kind != HM_KIND_ALIGNED) {
            /* a limit crossing bounds nothing where another joint of its triple (or of
             * both: the triple known only at the root) is outside all over the cell
             * (held_manifold.c's dead cells; aligned points are listed everywhere) */
            int ka, kb, skip = 1;
            hc_f(q, ra, NULL, &ka);
            hc_f(q, rb, NULL, &kb);
            for (HcRow *r = ra; r != NULL; r = r == ra ? rb : NULL)
                if (!r->hasmg)
                    hc_rowq(&c->p, r, mgt);
            for (int k = 0; k < 2 && skip; k++) {
                if (ka == kb && k != ka && !q->twin)
                    continue; /* the root's triple known: its side at both ends */
                if (deadk[k] < 0) {
                    deadk[k] = 0;
                    for (int jj = 0; jj < 3 && !deadk[k]; jj++) /* (3-5: not dead) */
                        deadk[k] = jj != q->j && hc_out(c, bj, ra, rb, k, jj, fa, fb);
                }
                skip = deadk[k];
            }
            if (skip)
                continue;
        }
        hc_root_q(c, pc, q, ra, xi0, fa[m], dfa[m], rb, xi1, fb[m], dfb[m], dead ? c->ronly : 0);
    }
}

/* The cells of a piece's nodes r (k, k + 1) with work for hc_cell (busy[k] = 1): those
 * where a query fails hc_cell's common case (of one sign and clear of 0 all over the
 * cell by the cubic model's bound, moving little, no extremum toward 0), by hc_cell's
 * own arithmetic, W cells at a time (fq, dq: the queries' values and slopes at the
 * nodes, hc_eval_lanes'); a cell at a branch end's node (slopes d/dxi: sloped 2) or
 * without slopes is busy. hc_cell does nothing in the others. */
static void hc_busy_cells(const HcCtx *c, const HcRow *r, const double (*fq)[HC_NODES + W],
                          const double (*dq)[HC_NODES + W], int *busy)
{
    enum { NC = HC_NODES - 1, NB = (NC + W - 1) / W * W };
    double sa[NB], sb[NB];
    vl free[NB / W];
    for (int k = 0; k < NB; k++) { /* (hc_cell's h, sa, sb) */
        double h = (double)(k + 1) / (HC_NODES - 1) - (double)k / (HC_NODES - 1);
        int in = k < NC && r[k].sloped == 1 && r[k + 1].sloped == 1;
        sa[k] = in ? r[k].dxi * h : NAN;
        sb[k] = in ? r[k + 1].dxi * h : NAN;
    }
    for (int b = 0; b < NB / W; b++)
        free[b] = BRL(-1);
    for (int m = 0; m < c->nq; m++) {
        const HcQuery *q = &c->q[m];
        double tol = q->kind < 0 ? HC_ALIGNED : HC_TOUCH;
        const double *fv = fq[m], *dv = dq[m]; /* (past HC_NODES: lanes sa, sb leave out) */
        for (int b = 0; b < NB / W; b++) {
            vd fa, fb, da, db, s0, s1;
            memcpy(&fa, fv + b * W, sizeof(vd));
            memcpy(&fb, fv + b * W + 1, sizeof(vd));
            memcpy(&da, dv + b * W, sizeof(vd));
            memcpy(&db, dv + b * W + 1, sizeof(vd));
            memcpy(&s0, sa + b * W, sizeof(vd));
            memcpy(&s1, sb + b * W, sizeof(vd));
            free[b] &= hr_clear_w(fa, fb, da * s0, db * s1, tol);
        }
    }
    for (int k = 0; k < NC; k++)
        busy[k] = free[k / W][k % W] == 0;
}

/* Every shoulder event of a piece */
static void hc_piece(HcCtx *c, const HcPiece *pc)
{
    HcRow r[HC_NODES];
    double nx[HC_NODES];
    for (int k = 0; k < HC_NODES; k++)
        nx[k] = k == 0 ? pc->a : k == HC_NODES - 1 ? pc->b
                               : pc->a + (pc->b - pc->a) * 0.5 * (1.0 - c->ncs[k][0]);
    double fq[HC_MAXQ][HC_NODES + W], dq[HC_MAXQ][HC_NODES + W];
    if (!hc_eval_lanes(c, nx, HC_NODES, pc->i, pc->j, r, fq, dq)) {
        c->bad = __LINE__;
        return;
    }
    c->rows += HC_NODES;
    for (int k = 0; k < HC_NODES; k++) {
        r[k].dxi = (pc->b - pc->a) * 0.5 * M_PI * c->ncs[k][1];
        hc_keep(c, 2 * pc->i + pc->j, &r[k]);
        if ((k == 0 && pc->fa) || (k == HC_NODES - 1 && pc->fb)) {
            /* a branch end: rates infinite in x, finite in xi (x - end ~ xi^2): the
             * row's slopes from HC_END_XI of the piece further in (d/dxi there) */
            HcRow e = {0};
            double xe = k == 0 ? HC_END_XI : 1.0 - HC_END_XI;
            if (!hc_eval(&c->p, hc_x(pc, xe), pc->i, pc->j, HC_SHOULDER | HC_SLOPES, &e) ||
                !e.sloped) {
                c->bad = __LINE__;
                return;
            }
            c->rows++;
            double f = hc_dx(pc, xe) / (0.5 * (pc->b - pc->a) * M_PI); /* dx/dxi ~ this */
            for (int m = 0; m < 7; m++)
                r[k].dv[m] = e.dv[m] * f;
            for (int m = 0; m < 5; m++)
                r[k].dsh[m] = e.dsh[m] * f;
            r[k].sloped = 2; /* slopes d/dxi / (pi (b - a) / 2): see hc_cell */
            r[k].nf = 0;     /* (the queries' slopes again, from these) */
        }
        if (k == 0 || k == HC_NODES - 1) {
            /* a joint at its limit at the piece's end (a corner: the slot may be inside
             * at that one value): the grid's */
            double mg[2], near = (k == 0 ? pc->fa : pc->fb) ? HC_AT_FOLD : HC_DECIDE;
            hc_rowq(&c->p, &r[k], mg);
            if (fabs(mg[0]) < near || fabs(mg[1]) < near) {
                c->bad = __LINE__;
                return;
            }
            /* at a branch end the rows move as beta sqrt(|x - end|), and the end is
             * pk_one's, hc_snap's shift from the margins' (up to HC_SNAP): a joint
             * within beta sqrt(shift) of a limit may be at it at the true end (the
             * generating configuration an isolated in-limit point there; beta from
             * the end's slopes d/dxi: s sqrt(b - a) in hc_piece's units) */
            if ((k == 0 && pc->fa) || (k == HC_NODES - 1 && pc->fb)) {
                const HcRow *e = &r[k];
                const double *a = e->sh, *da = e->dsh;
                double rho2 = a[0] * a[0] + a[1] * a[1], rho = sqrt(rho2);
                double r2 = a[3] * a[3] + a[4] * a[4];
                double drho = (a[0] * da[0] + a[1] * da[1]) / rho;
                double rate[6] = {(a[0] * da[1] - a[1] * da[0]) / rho2,
                                  (a[2] * drho - rho * da[2]) / (rho2 + a[2] * a[2]),
                                  (a[4] * da[3] - a[3] * da[4]) / r2, e->dv[3], e->dv[4],
                                  e->dv[5]};
                double shift = k == 0 ? pc->sa : pc->sb;
                double sq = sqrt((shift + 4.0 * DBL_EPSILON * fmax(1.0, fabs(e->x))) *
                                 (pc->b - pc->a));
                for (int j = 0; j < 6; j++)
                    for (int t = 0; t < 2; t++)
                        if (!(fabs(e->mg[t][j]) >= HC_AT_FOLD + fabs(rate[j]) * sq)) {
                            c->bad = __LINE__;
                            return;
                        }
            }
            /* ... or at an aligned value at a branch end (the generating configuration
             * there: an aligned point the end's rounding, which moves the joint as the
             * square root, would leave unlocated on either side) */
            if ((k == 0 && pc->fa) || (k == HC_NODES - 1 && pc->fb)) {
                for (int m = 0; m < c->nq; m++)
                    if (c->q[m].kind == HM_KIND_ALIGNED &&
                        fabs(hc_f(&c->q[m], &r[k], NULL, NULL)) < HC_AT_FOLD) {
                        c->bad = __LINE__;
                        return;
                    }
                for (int m = 0; m < c->nwal; m++) {
                    const double *cs = r[k].cs[(int)c->wal[m][0]];
                    if (fabs(cs[1] * c->wal[m][1] - cs[0] * c->wal[m][2]) < HC_AT_FOLD) {
                        c->bad = __LINE__;
                        return;
                    }
                }
            }
        }
    }
    int busy[HC_NODES - 1];
    hc_busy_cells(c, r, (const double(*)[HC_NODES + W])fq, (const double(*)[HC_NODES + W])dq,
                  busy);
    for (int k = 0; k + 1 < HC_NODES && !c->bad; k++)
        if (busy[k])
            hc_cell(c, pc, &r[k], (double)k / (HC_NODES - 1), &r[k + 1],
                    (double)(k + 1) / (HC_NODES - 1), 0);
}

/* --------------------------------------------------------- branch ends */

typedef struct {
    const HcPose *p;
    int i;
} HcMarginArg;

static double hc_m2_at(void *arg, double x)
{
    const HcMarginArg *m = arg;
    return hc_m2(m->p, x, m->i, NULL);
}

/* A node of E2's margin on a piece: xi, x, dx/dxi, the margin and its slope d/dx (NaN
 * at a branch end) */
typedef struct {
    double xi, x, dx, m, d;
} HcMNode;

/* E2's branch ends of root i in the cell (n0, n1) of E1's piece pc: into ends[] */
static void hc_m2_cell(HcCtx *c, const HcPiece *pc, int i, const HcMNode *n0,
                       const HcMNode *n1, int depth, double *ends, int *ne)
{
    if (c->bad)
        return;
    double h = n1->xi - n0->xi, x0 = n0->x, x1 = n1->x, m0 = n0->m, m1 = n1->m;
    double s0 = n0->d * n0->dx * h, s1 = n1->d * n1->dx * h;
    double scale = c->p.g->cn;
    int known = isfinite(s0) && isfinite(s1);
    if (!isfinite(s0))
        s0 = m1 - m0;
    if (!isfinite(s1))
        s1 = m1 - m0;
    int sp, near;
    hc_hermite(m0 / scale, m1 / scale, s0 / scale, s1 / scale, HC_TOUCH, &sp, &near);
    if (!known && depth < HC_END_SPLITS && ((m0 < 0.0) != (m1 < 0.0) || near))
        sp = 1;
    /* the model trusted only where the slopes agree with the chord (a gap or an
     * island of E2 ~0.03 wide between nodes: session 26) */
    double chord = m1 - m0;
    if (known && fabs(s0 - chord) + fabs(s1 - chord) > HC_BEND * (fabs(chord) + HC_BEND_FLOOR * scale))
        sp = 1;
    if (fabs(m0) < HC_AT_NODE * scale || fabs(m1) < HC_AT_NODE * scale) {
        c->bad = __LINE__; /* a branch end at a node (or E2 touching 0 there) */
        return;
    }
    /* an extremum toward 0 (E2 touching 0 between nodes: an isolated row, a branch's
     * end pair): located as hc_cell's */
    double at = 0.5, tau = 0.5, val = 0.0;
    if (!sp && !near && known && (m0 < 0.0) == (m1 < 0.0) &&
        (m0 > 0.0 ? s0 < 0.0 && s1 > 0.0 : s0 > 0.0 && s1 < 0.0) &&
        hc_extremum(m0, m1, s0, s1, &tau, &val) && fabs(val) < HC_DIP * fmin(fabs(m0), fabs(m1))) {
        sp = 1;
        at = fmin(fmax(tau, 0.1), 0.9);
        if (fabs(x1 - x0) < HC_DIP_WIDTH || fabs(val) < HC_AT_NODE * scale) {
            c->bad = __LINE__;
            return;
        }
    }
    if (sp || near) {
        if (depth >= HC_DEPTH) {
            c->bad = __LINE__;
            return;
        }
        HcMNode nm;
        nm.xi = n0->xi + at * h;
        nm.x = hc_x(pc, nm.xi);
        nm.dx = hc_dx(pc, nm.xi);
        nm.m = hc_m2(&c->p, nm.x, i, &nm.d);
        c->rows++;
        hc_m2_cell(c, pc, i, n0, &nm, depth + 1, ends, ne);
        hc_m2_cell(c, pc, i, &nm, n1, depth + 1, ends, ne);
        return;
    }
    if ((m0 < 0.0) != (m1 < 0.0)) {
        HcMarginArg arg = {&c->p, i};
        double x = brent_root(hc_m2_at, &arg, x0, m0, x1, m1); /* E2's branch end */
        if (!isfinite(x) || *ne >= 2 * HC_MAXPC) {
            c->bad = __LINE__;
            return;
        }
        ends[(*ne)++] = x;
    }
}

/* The cells of E2's margin's nodes nd (k, k + 1) with work for hc_m2_cell (busy[k] =
 * 1): all but those hr_m2_clear passes (hc_m2_cell's own arithmetic; it does nothing
 * there), W cells at a time */
static void hc_m2_busy(const HcMNode *nd, double scale, int *busy)
{
    enum { NC = HC_MNODES - 1, NB = (NC + W - 1) / W * W };
    for (int b = 0; b < NB; b += W) {
        vd m0, m1, s0, s1;
        for (int l = 0; l < W; l++) {
            int k = b + l < NC ? b + l : NC - 1;
            const HcMNode *n0 = &nd[k], *n1 = &nd[k + 1];
            double h = n1->xi - n0->xi; /* (hc_m2_cell's) */
            m0[l] = n0->m;
            m1[l] = n1->m;
            s0[l] = n0->d * n0->dx * h;
            s1[l] = n1->d * n1->dx * h;
        }
        vl clear = hr_m2_clear_w(m0, m1, s0, s1, scale);
        for (int l = 0; l < W && b + l < NC; l++)
            busy[b + l] = clear[l] == 0;
    }
}

static int hc_cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Branch (i, j)'s pieces (both j of root i share them): E1's pieces cut where E2's
 * margin of root i changes sign. Into c->cut[2 i + j] (pairs) and c->cutfold. */
static void hc_pieces(HcCtx *c)
{
    const HcPose *p = &c->p;
    const HcGeo *g = p->g;
    double e1[8];
    int n1 = 0;
    e1[n1++] = p->xlo;
    e1[n1++] = p->xhi;
    double r[2];
    for (int sgn = -1; sgn <= 1; sgn += 2) {
        int n = hc_sin_roots(p->d[0] - g->K + sgn * g->cn, p->d[1], p->d[2], r);
        if (n < 0) {
            c->bad = __LINE__; /* E1 tangent to its ends: a branch end doubled */
            return;
        }
        for (int m = 0; m < n; m++)
            if (r[m] > p->xlo && r[m] < p->xhi)
                e1[n1++] = r[m];
    }
    qsort(e1, (size_t)n1, sizeof(double), hc_cmp);
    for (int m = 0; m + 1 < n1; m++)
        if (e1[m + 1] - e1[m] < HC_CORNER) {
            c->bad = __LINE__; /* a branch end at the range's end or another's */
            return;
        }
    for (int i = 0; i < 2; i++)
        c->npc[2 * i] = c->npc[2 * i + 1] = 0;
    for (int m = 0; m + 1 < n1 && !c->bad; m++) {
        double a = e1[m], b = e1[m + 1];
        if (!(b > a))
            continue;
        if (b - a < HC_CLOSE) {
            c->bad = __LINE__;
            return;
        }
        double xm = 0.5 * (a + b);
        double cm, sm;
        sincos1(xm, &sm, &cm);
        if (!(hc_m1(p, cm, sm) > 0.0))
            continue;
        HcPiece pc = {a, b, a != p->xlo, b != p->xhi, 0, 0, 0.0, 0.0};
        double nx[HC_MNODES], nm[HC_MNODES], ndm[HC_MNODES]; /* the nodes' x, margin, slope */
        for (int k = 0; k < HC_MNODES; k++)
            nx[k] = k == 0 ? a : k == HC_MNODES - 1 ? b : a + (b - a) * 0.5 * (1.0 - c->mcs[k][0]);
        for (int i = 0; i < 2 && !c->bad; i++) {
            /* E2's margin on nodes of the piece: its sign changes */
            HcMNode nd[HC_MNODES];
            double ends[2 * HC_MAXPC];
            int ne = 0;
            hc_m2_lanes(p, nx, HC_MNODES, i, nm, ndm);
            for (int k = 0; k < HC_MNODES; k++) {
                nd[k].xi = (double)k / (HC_MNODES - 1);
                nd[k].x = nx[k];
                nd[k].dx = (b - a) * 0.5 * M_PI * c->mcs[k][1];
                nd[k].m = nm[k];
                nd[k].d = ndm[k];
                if ((k == 0 && pc.fa) || (k == HC_MNODES - 1 && pc.fb))
                    nd[k].d = NAN;
            }
            int busy[HC_MNODES - 1];
            hc_m2_busy(nd, c->p.g->cn, busy);
            for (int k = 0; k + 1 < HC_MNODES; k++)
                if (busy[k])
                    hc_m2_cell(c, &pc, i, &nd[k], &nd[k + 1], 0, ends, &ne);
            if (c->bad)
                return;
            /* the sub-pieces where the margin is >= 0 */
            double cuts[2 * HC_MAXPC + 2];
            int nc = 0;
            cuts[nc++] = a;
            for (int e = 0; e < ne; e++)
                cuts[nc++] = ends[e];
            cuts[nc++] = b;
            for (int e = 0; e + 1 < nc; e++) {
                double u = cuts[e], w = cuts[e + 1];
                if (w - u < HC_CORNER) {
                    c->bad = __LINE__;
                    return;
                }
                if (!(hc_m2(p, 0.5 * (u + w), i, NULL) > 0.0))
                    continue;
                for (int j = 0; j < 2; j++) {
                    int bj = 2 * i + j, k = c->npc[bj];
                    if (k >= HC_MAXPC) {
                        c->bad = __LINE__;
                        return;
                    }
                    c->cut[bj][2 * k] = u;
                    c->cut[bj][2 * k + 1] = w;
                    c->cutfold[bj][2 * k] = e > 0 ? 2 : pc.fa;
                    c->cutfold[bj][2 * k + 1] = e + 2 < nc ? 2 : pc.fb;
                    c->npc[bj]++;
                }
            }
        }
    }
}

/* pk_one's slot of branch (i, j), triple k */
static inline int hc_slot(int i, int j, int k) { return 4 * (1 - i) + 2 * (1 - j) + k; }

/* Whether pk_one has a row of slot b at held value t: its front's position root of that
 * slot (pk_front_memo, as held_manifold.c's hm_closed takes a row; the triple and the
 * pose check after it agreed on all 17,048 branch ends of 300 uniform poses, session
 * 26), for the last HC_ROWS_KEPT values (an E1 branch end is four branches'). The
 * front solves the two slots of b's first position root (pk_coplanar's want). */
static int hc_row_at(HcCtx *c, const double *P, double t, int b)
{
    int s = b >> 1, m = -1;
    unsigned want = 3u << (s & 2);
    for (int k = 0; k < c->nkept && k < HC_ROWS_KEPT; k++)
        if (c->kept_t[k] == t) {
            if (c->kept_known[k] & want)
                return c->kept_valid[k][s];
            m = k; /* (the other first root's slots solved there: these added) */
        }
    if (m < 0) {
        m = c->nkept++ % HC_ROWS_KEPT;
        c->kept_t[m] = t;
        c->kept_known[m] = 0;
        for (int k = 0; k < 4; k++)
            c->kept_valid[m][k] = 0;
    }
    double qn[PK_MAXJ] = {0};
    PkFront f;
    int code = pk_front_memo(P, c->T, t, qn, 0, &c->front, want, &f);
    for (int i = 0; code == PK_OK && i < f.pos.n; i++)
        if ((want >> f.pos.slot[i] & 1u) && f.pos.res[i] < 1e-6 * f.g.scale)
            c->kept_valid[m][f.pos.slot[i]] = 1;
    c->kept_known[m] |= want;
    return c->kept_valid[m][s];
}

/* hc_snap's function: pk's discriminant kk at held value t, less off */
typedef struct {
    const double *P, *T;
    HmMargMemo *memo;
    int kk;
    double off;
} HcDiscArg;

static double hc_disc_at(void *arg, double t)
{
    HcDiscArg *a = arg;
    double m[3], d[3];
    if (!hm_margins_pk(a->P, a->T, a->memo, t, m, d))
        return NAN;
    return d[a->kk] - a->off;
}

/* Where pk_one's rows of a slot end next to t (the margin's root, in held values; out:
 * the direction of the piece's outside): the root of pk's discriminant (arg) to
 * HC_SNAP_TOL, its inside end moved HC_SNAP_ULPS doubles further in; NaN where none
 * is within HC_SNAP (or the discriminant is not finite). wide = 0: bracketed from t
 * outward (where it has a row: the discriminant >= 0 inside the piece) or inward by
 * probes HC_SNAP_TOL, 8, 64, ... times that far (pk's root is within 4e-15 of the
 * margin's at 79 % of the ends, 1.6e-14 at 95 %: session 28); wide = 1: from the
 * bracket [t - HC_SNAP, t + HC_SNAP] (sessions 26-27; hc_snap's second try). */
static double hc_snap_end(HcDiscArg *arg, double t, double out, int wide)
{
    double w = HC_SNAP * fmax(1.0, fabs(t)), tol = HC_SNAP_TOL * fmax(1.0, fabs(t));
    double lo, hi, flo, fhi;
    if (wide) {
        lo = t - w;
        hi = t + w;
        flo = hc_disc_at(arg, lo);
        fhi = hc_disc_at(arg, hi);
        if (!((flo < 0.0) != (fhi < 0.0)))
            return NAN;
    } else {
        double f0 = hc_disc_at(arg, t), dir = f0 >= 0.0 ? out : -out;
        double prev = t, fprev = f0, probe = t, fp = f0;
        for (double step = tol;; step *= 8.0) {
            if (!isfinite(fprev) || step > w)
                return NAN;
            probe = t + dir * step;
            fp = hc_disc_at(arg, probe);
            if (isfinite(fp) && (fp < 0.0) != (fprev < 0.0))
                break;
            prev = probe;
            fprev = fp;
        }
        lo = fmin(prev, probe);
        hi = fmax(prev, probe);
        flo = prev < probe ? fprev : fp;
        fhi = prev < probe ? fp : fprev;
    }
    /* the root to HC_SNAP_TOL: regula falsi steps (the retained end's value halved, as
     * Illinois), each followed by a probe just past it (across the bracket the
     * discriminant is nearly linear: a step lands next to the root, the probe closes
     * the bracket) */
    double glo = flo, ghi = fhi;
    for (int it = 0; hi - lo > tol; it++) {
        if (it >= 40)
            return NAN;
        double x = lo - glo * (hi - lo) / (ghi - glo);
        if (!(x > lo && x < hi))
            x = 0.5 * (lo + hi);
        for (int np = 0; np < 2 && hi - lo > tol; np++) {
            double fx = hc_disc_at(arg, x);
            if (!isfinite(fx))
                return NAN;
            int below = (fx < 0.0) == (flo < 0.0); /* the root above x */
            if (below) {
                lo = x;
                flo = glo = fx;
                ghi *= 0.5; /* (hi retained) */
            } else {
                hi = x;
                fhi = ghi = fx;
                glo *= 0.5;
            }
            x += below ? 0.5 * tol : -0.5 * tol;
            if (!(x > lo && x < hi))
                break;
        }
    }
    /* the last value with a discriminant >= 0 (a row): the bracket's inside end, moved
     * clear of the discriminant's rounding (r's ulp upward: across a power of 2 twice
     * the doubles downward) */
    double r = flo >= 0.0 ? lo : hi, in = flo >= 0.0 ? -1.0 : 1.0;
    return r + in * HC_SNAP_ULPS * (nextafter(r, INFINITY) - r);
}

/* Every branch end of every piece moved to where pk_one's rows of its slot end (what
 * SelfMotion.sample gives there): the root of pk's own discriminant of that position
 * root (held_margins.c; the pair's second root at HM_DISC_TWO, as held_manifold.c's
 * hm_fold_margin) within HC_SNAP of the margin's exact root (hc_snap_end), confirmed
 * by a pk_one row there (its rows near a double root are not the discriminant's sign
 * alone: held_manifold.c's confirmation); c->bad where none is. */
static void hc_snap(HcCtx *c, const double *P, HmMargMemo *memo)
{
    const HcGeo *g = c->p.g;
    double s7 = g->sign[6], o7 = g->off[6];
    for (int bj = 0; bj < 4; bj++)
        for (int m = 0; m < 2 * c->npc[bj]; m++) {
            int kind = c->cutfold[bj][m];
            if (!kind)
                continue;
            int b = hc_slot(bj >> 1, bj & 1, 0), kk = kind == 1 ? 0 : 1 + (b >> 2);
            HcDiscArg arg = {P, c->T, memo, kk,
                             (kk == 0 ? b >= 4 : (b & 2) != 0) ? HM_DISC_TWO : 0.0};
            double t = s7 * (c->cut[bj][m] - o7), out = (m % 2 == 0 ? -1.0 : 1.0) * s7;
            double r = hc_snap_end(&arg, t, out, 0);
            if (!isfinite(r) || !hc_row_at(c, P, r, b)) {
                r = hc_snap_end(&arg, t, out, 1); /* (a root in the discriminant's noise) */
                if (!isfinite(r) || !hc_row_at(c, P, r, b)) {
                    c->bad = __LINE__;
                    return;
                }
            }
            c->cutd[bj][m] = fabs(s7 * r + o7 - c->cut[bj][m]);
            c->cut[bj][m] = s7 * r + o7;
        }
    for (int bj = 0; bj < 4; bj++)
        for (int m = 0; m < c->npc[bj]; m++)
            if (!(c->cut[bj][2 * m + 1] - c->cut[bj][2 * m] >= HC_CORNER)) {
                c->bad = __LINE__;
                return;
            }
}

/* ------------------------------------------------------------ the pose */

/* A branch's events in x: insertion (a few, those of a piece in order; stable) */
static void hc_sort_events(HcEvent *ev, int n)
{
    for (int u = 1; u < n; u++) {
        HcEvent e = ev[u];
        int v = u;
        for (; v > 0 && ev[v - 1].x > e.x; v--)
            ev[v] = ev[v - 1];
        ev[v] = e;
    }
}

/* Whether pk_one numbers the rows at x as hc_slot does. Its position slots from its
 * front: each branch's wrist (cos, sin) within 1e-6 of one position root's, that of
 * its slot alone. Its triple order (pk_middle's t0 + D first, D in [0, pi]; hc_slot's
 * k = 0 the triple with v2 >= 0) on one branch: pk's two rows there, from its front
 * and triples and checked and polished as pk_one checks them (its repairs, which move
 * a row outside the limits by at most a nudge, left out), within 1e-6 of these, each
 * nearest its own slot's. */
static int hc_slots_agree(HcCtx *c, const double *P, double x)
{
    const HcGeo *g = c->p.g;
    double t = g->sign[6] * (x - g->off[6]), qn[PK_MAXJ] = {0};
    PkFront f;
    if (pk_front_memo(P, c->T, t, qn, 0, &c->front, 15u, &f) != PK_OK)
        return 0;
    const PkPos *pos = &f.pos;
    int tried = 0;
    for (int bj = 0; bj < 4; bj++) {
        HcRow r;
        if (!hc_eval(&c->p, x, bj >> 1, bj & 1, tried ? 0 : HC_SHOULDER, &r))
            continue;
        int b = hc_slot(bj >> 1, bj & 1, 0), best = -1, near = 0;
        double bd = INFINITY;
        for (int i = 0; i < pos->n; i++) {
            if (!(pos->res[i] < 1e-6 * f.g.scale))
                continue;
            double d = 0.0;
            for (int j = 0; j < 3; j++) {
                const double *cs = r.cs[f.g.full[f.ia + j]];
                d = fmax(d, fabs(cs[0] - pos->c[i][j]) + fabs(cs[1] - pos->s[i][j]));
            }
            near += d < 1e-6;
            if (d < bd) {
                bd = d;
                best = i;
            }
        }
        if (best < 0 || near != 1 || 2 * pos->slot[best] != b)
            return 0;
        if (tried++)
            continue;
        /* the triple order on this branch */
        double th[6], Q[2][6];
        m3 Rt = pk_front_rotation(&f, best, th);
        PkTrip tr;
        pk_triple(P, &f.tri, &Rt, f.jx, f.jz, qn[f.jz], P[PK_SING_TOL], &tr);
        if (tr.n != 2)
            return 0;
        for (int k = 0; k < 2; k++) {
            for (int j = 0; j < 3; j++) {
                th[f.ia + j] = pos->t[best][j];
                th[f.it + j] = tr.t[k][j];
            }
            if (tr.check[k] || !(pos->res[best] < f.exact_p)) {
                double err = pk_error_of(&f.g, &f.RT, f.pT, th);
                if (err > PK_EXACT)
                    err = pk_polish_slow(&f.g, &f.RT, f.pT, th, pk_polish(&f.g, &f.RT, f.pT, th));
                if (!(err <= PK_ACCEPT))
                    return 0; /* (pk_one returns no row) */
            }
            for (int j = 0; j < 6; j++)
                Q[k][f.g.full[j]] = th[j];
        }
        for (int k = 0; k < 2; k++) {
            double v[7], d[2] = {0.0, 0.0};
            hc_angles(&r, k, v);
            for (int kk = 0; kk < 2; kk++)
                for (int jj = 0; jj < 6; jj++)
                    d[kk] = fmax(d[kk], fabs(wrap_pi(v[jj] - Q[kk][jj])));
            if (!(d[k] < 1e-6) || !(d[k] < d[1 - k]))
                return 0;
        }
    }
    return tried > 0;
}

/* cos, sin of pi k / (n - 1), k = 0 .. n - 1 (the nodes' Chebyshev spacing), W at a time */
static void hc_nodes_cs(int n, double (*cs)[2])
{
    for (int b = 0; b < n; b += W) {
        vd x, s, c;
        for (int l = 0; l < W; l++)
            x[l] = M_PI * (b + l) / (n - 1);
        vsincos(x, &s, &c);
        for (int l = 0; l < W && b + l < n; l++) {
            cs[b + l][0] = c[l];
            cs[b + l][1] = s[l];
        }
    }
}

/* The intervals and points of one pose (held_manifold's outputs: iv (8, HM_MAXI, 2),
 * niv (8), pts (HM_MAXP, 4), *npts); 1 when certified (else the outputs undefined) */
static int hc_pose(const double *P, const double *T, const double *al, long nal, double *iv,
                   long long *niv, double *pts, long *npts, long *rows, long *solves)
{
    HcGeo geo;
    if (!hc_geo(P, &geo))
        return 0;
    HcCtx *c = malloc(sizeof(HcCtx));
    if (c == NULL)
        return 0;
    c->T = T;
    c->bad = 0;
    c->rows = 0;
    c->nkept = 0;
    c->front.set = 0;
    c->nq = c->nwal = 0;
    for (int bj = 0; bj < 4; bj++)
        c->nev[bj] = c->npc[bj] = c->nnode[bj] = 0;
    hc_nodes_cs(HC_NODES, c->ncs);
    hc_nodes_cs(HC_MNODES, c->mcs);
    const HcGeo *g = &geo;
    int ok = 0;
    if (!hc_setup(g, T, &c->p))
        goto done;
    /* the shoulder's queries: limits, aligned values, the aligned-shoulder guards */
    for (int j = 0; j < 3; j++) {
        double V[2];
        for (int e = 0; e < 2; e++)
            V[e] = g->sign[j] * (e ? g->hi[j] : g->lo[j]) + g->off[j];
        for (int e = 0; e < 2; e++) {
            int kind = e ? HM_KIND_UPPER : HM_KIND_LOWER; /* of the joint value q */
            /* v2's limits at +-V: one function (cos v2 = cos V), its roots both triples' */
            int twin = j == 1 && V[0] == -V[1];
            if (twin && e == 0)
                continue;
            double cV, sV;
            sincos1(V[e], &sV, &cV);
            c->q[c->nq++] = (HcQuery){j, kind, twin, V[e], cV, sV};
        }
    }
    c->q[c->nq++] = (HcQuery){1, -1, 0, 0.0, 1.0, 0.0};
    c->q[c->nq++] = (HcQuery){1, -1, 0, M_PI, -1.0, 0.0};
    for (long a = 0; a < nal; a++) {
        int j = (int)al[2 * a];
        double V = g->sign[j < 0 || j > 6 ? 0 : j] * al[2 * a + 1] + g->off[j < 0 || j > 6 ? 0 : j];
        if (j == 0 || j == 2) {
            if (c->nq >= HC_MAXQ)
                goto done;
            double cV, sV;
            sincos1(V, &sV, &cV);
            c->q[c->nq++] = (HcQuery){j, HM_KIND_ALIGNED, 0, V, cV, sV};
        } else if (j >= 3 && j <= 5) {
            if (c->nwal >= HC_MAXQ)
                goto done;
            c->wal[c->nwal][0] = j;
            sincos1(V, &c->wal[c->nwal][2], &c->wal[c->nwal][1]);
            c->nwal++;
        } else if (j != 1 && j != 6) {
            goto done;
        }
    }
    c->ronly = HC_RONLY;
    for (int m = 0; m < c->nq; m++)
        if (c->q[m].j == 0 && c->q[m].kind == HM_KIND_ALIGNED)
            c->ronly = 0; /* (v1's aligned values take w) */
    hc_pieces(c);
    if (c->bad)
        goto done;
    HmMargMemo memo = {0};
    hc_snap(c, P, &memo);
    if (c->bad)
        goto done;
    int pieces = 0; /* (none: no row anywhere, an empty manifold; no event to find) */
    for (int bj = 0; bj < 4; bj++)
        pieces += c->npc[bj];
    for (int j = 3; j < 6 && !c->bad && pieces; j++)
        for (int e = 0; e < 2; e++)
            hc_closed_events(c, j, g->sign[j] * (e ? g->hi[j] : g->lo[j]) + g->off[j],
                             e ? HM_KIND_UPPER : HM_KIND_LOWER);
    for (long a = 0; a < nal && !c->bad && pieces; a++) {
        int j = (int)al[2 * a];
        if (j >= 3 && j <= 5)
            hc_closed_events(c, j, g->sign[j] * al[2 * a + 1] + g->off[j], HM_KIND_ALIGNED);
    }
    for (int bj = 0; bj < 4 && !c->bad; bj++)
        for (int m = 0; m < c->npc[bj] && !c->bad; m++) {
            HcPiece pc = {c->cut[bj][2 * m], c->cut[bj][2 * m + 1], c->cutfold[bj][2 * m],
                          c->cutfold[bj][2 * m + 1], bj >> 1, bj & 1,
                          c->cutd[bj][2 * m], c->cutd[bj][2 * m + 1]};
            hc_piece(c, &pc);
        }
    if (c->bad)
        goto done;
    /* pk_one's slots: checked at a piece's middle */
    for (int bj = 0; bj < 4; bj++)
        if (c->npc[bj]) {
            if (!hc_slots_agree(c, P, 0.5 * (c->cut[bj][0] + c->cut[bj][1])))
                goto done;
            break;
        }
    /* the intervals and points of each slot */
    *npts = 0;
    double s7 = g->sign[6], o7 = g->off[6];
    for (int bj = 0; bj < 4; bj++) {
        hc_sort_events(c->ev[bj], c->nev[bj]);
        /* the kept nodes in x (insertion: a piece's nodes come in order, its splits'
         * after them), swept once per triple below */
        double (*nd)[3] = c->node[bj];
        for (int u = 1; u < c->nnode[bj]; u++) {
            double e[3] = {nd[u][0], nd[u][1], nd[u][2]};
            int v = u;
            for (; v > 0 && nd[v - 1][0] > e[0]; v--)
                for (int w = 0; w < 3; w++)
                    nd[v][w] = nd[v - 1][w];
            for (int w = 0; w < 3; w++)
                nd[v][w] = e[w];
        }
        for (int k = 0; k < 2; k++) {
            int b = hc_slot(bj >> 1, bj & 1, k);
            double *out = iv + 2 * HM_MAXI * b;
            long long n = 0;
            int e = 0, u = 0; /* u: the first kept node not below the piece's start */
            for (int m = 0; m < c->npc[bj]; m++) {
                double a = c->cut[bj][2 * m], z = c->cut[bj][2 * m + 1];
                if (c->cutfold[bj][2 * m] || c->cutfold[bj][2 * m + 1]) {
                    for (int side = 0; side < 2; side++) {
                        if (!c->cutfold[bj][2 * m + side])
                            continue;
                        if (*npts >= HM_MAXP)
                            goto done;
                        double *pt = pts + 4 * (*npts)++;
                        pt[0] = s7 * ((side ? z : a) - o7);
                        pt[1] = b;
                        pt[2] = -1;
                        pt[3] = HM_KIND_FOLD;
                    }
                }
                double prev = a;
                for (;; e++) {
                    while (e < c->nev[bj] && c->ev[bj][e].k >= 0 && c->ev[bj][e].k != k)
                        e++;
                    int last = !(e < c->nev[bj] && c->ev[bj][e].x < z);
                    double x = last ? z : c->ev[bj][e].x;
                    if (!last && c->ev[bj][e].x < a)
                        continue;
                    /* a corner: two events (or one and the range's end) together; next
                     * to a branch end, where the rows move as the square root of the
                     * distance, HC_FOLD_GAP */
                    int fold = (prev == a && c->cutfold[bj][2 * m]) ||
                               (last && c->cutfold[bj][2 * m + 1]);
                    if (!(x - prev >= (fold ? HC_FOLD_GAP : HC_CORNER)))
                        goto done;
                    if (x > prev) {
                        /* decided at the kept node inside furthest from a limit, else
                         * at a row in the middle */
                        double mg = 0.0;
                        while (u < c->nnode[bj] && !(nd[u][0] > prev))
                            u++;
                        for (; u < c->nnode[bj] && nd[u][0] < x; u++)
                            if (fabs(nd[u][1 + k]) > fabs(mg))
                                mg = nd[u][1 + k];
                        if (!(fabs(mg) >= HC_DECIDE)) {
                            HcRow r;
                            double mgs[2][7];
                            if (!hc_eval(&c->p, 0.5 * (prev + x), bj >> 1, bj & 1, HC_SHOULDER,
                                         &r))
                                goto done;
                            c->rows++;
                            hc_margins(g, &r, mgs);
                            mg = hc_least(mgs[k], -1);
                        }
                        if (!(fabs(mg) >= HC_DECIDE))
                            goto done;
                        if (mg > 0.0) {
                            if (n > 0 && out[2 * n - 1] == prev) {
                                out[2 * n - 1] = x;
                            } else {
                                if (n >= HM_MAXI)
                                    goto done;
                                out[2 * n] = prev;
                                out[2 * n + 1] = x;
                                n++;
                            }
                        }
                    }
                    if (!last) {
                        const HcEvent *ev = &c->ev[bj][e];
                        int list = ev->kind == HM_KIND_ALIGNED;
                        /* a wrist joint at its aligned value with another there too
                         * (q5 and q6 at 0: a swing, as the shoulder's), or with a joint
                         * at a limit (a corner at a singular point: an isolated
                         * in-limit row the grid leaves to solved points): the grid's */
                        if (list && ev->j >= 3 &&
                            (ev->wal < HC_WRIST_ALIGNED || fabs(ev->mgall[k]) < HC_CORNER))
                            goto done;
                        if (!list) { /* a crossing: another joint at a limit there too */
                            if (fabs(ev->mg[k]) < HC_CORNER)
                                goto done;
                            list = 1; /* (every located one: SelfMotion.crossings keeps
                                       * those with every other joint inside) */
                        }
                        if (list) {
                            if (*npts >= HM_MAXP)
                                goto done;
                            double *pt = pts + 4 * (*npts)++;
                            pt[0] = s7 * (ev->x - o7);
                            pt[1] = b;
                            pt[2] = ev->j;
                            pt[3] = ev->kind;
                        }
                    }
                    prev = x;
                    if (last)
                        break;
                }
            }
            /* in t (the held joint's value) */
            for (long long m = 0; m < 2 * n; m++)
                out[m] = s7 * (out[m] - o7);
            if (s7 < 0.0)
                for (long long m = 0; m < n / 2; m++)
                    for (int side = 0; side < 2; side++) {
                        double w = out[2 * m + side];
                        out[2 * m + side] = out[2 * (n - 1 - m) + 1 - side];
                        out[2 * (n - 1 - m) + 1 - side] = w;
                    }
            niv[b] = n;
        }
    }
    ok = 1;
done:
#ifdef HC_DEBUG_BAD
    fprintf(stderr, "bad %d ", c->bad);
#endif
    *rows = c->rows;
    *solves = 0; /* pk_one calls (hc_row_at's and hc_slots_agree's fronts are none) */
    free(c);
    return ok;
}
