/*
 * The whole self-motion of one pose of a 7R arm with a held-joint Pieper closed
 * form (the Panda / FR3 with q7 as the parameter t; issue 29), in one pass per
 * pose, on top of pieper.c's pk_one (its rows, unchanged):
 *
 *   1. a grid of t values over the held joint's range, every slot's row there
 *      (pk_one) and its derivative dq/dt (the six other joints' Jacobian columns
 *      solve -J_held: the pose stays fixed along the manifold; hm_slopes_fast
 *      where the first three axes meet: two 3 x 3 solves);
 *   2. per slot and cell between grid nodes with a row at both ends: the cell is
 *      split (a midpoint solved, up to HM_DEPTH times; for the slot pair where the
 *      partner splits the same cell, hm_split_row) while a joint moves more
 *      than HM_JUMP in it or a joint's distance to a value (a limit or an
 *      aligned-axes value) changes sign inconsistently with its end slopes, or
 *      its cubic Hermite model (values and slopes at the ends) dips across the
 *      value; then per (joint, value) a sign change of q_j - value brackets one
 *      crossing, and opposite end slopes an extremum (located by regula falsi on
 *      dq_j/dt) whose value decides two crossings or none; every crossing is
 *      refined by safeguarded Newton (the analytic slope, from the root of the
 *      cell's cubic Hermite model) / Illinois regula falsi on q_j(t) - value
 *      until the joint is at the value to 1e-14 (the row is
 *      pk_one's: pose error <= 4e-13); Newton's last step takes no row where its
 *      predicted residual is below the stop and the row's side of every limit follows
 *      from the last row and its slopes (hm_last, session 12); in a cell where a
 *      joint is certainly outside its limits (hm_dead: its model with every turn
 *      away from them) no limit crossing is located and the splits are those its
 *      aligned values ask for (its crossings bound no interval; its aligned points
 *      are still located; session 24: 38.9 -> 12.7 crossings and ~13 % of the time
 *      per Panda pose);
 *   3. cells where a slot's row appears or disappears (a fold: two slots meet):
 *      the end where the position root's subproblem-4 discriminant reaches 0
 *      (or HM_DISC_TWO for the pair's second root), by Brent's method on the
 *      margins (no rows), confirmed by two rows; else searched on the row's
 *      existence to HM_FOLD_TOL; the piece from the end to its grid node is one
 *      cell in sigma = sqrt|t - end| (hm_sigma), where the rows are smooth;
 *   4. per slot, the pieces between domain ends, limit crossings, folds and slot
 *      changes are decided at their midpoints (a row inside every limit) and joined.
 *
 * A slot change: where the held closed form numbers its rows differently on either
 * side of a value (the Gen3-like arm, joint_3 held: at ~ +-2.9e-13 and +-(pi - 2.9e-13)
 * its solver's case changes), a slot holds one branch on one side and another on the
 * other; the cell there is split to HM_DEPTH and its jump bisected to adjacent doubles
 * (hm_jump): a cut of that slot, no point (the solved-points path ends its intervals
 * there too: its rows are the same).
 *
 * Every row is pk_one's: hm_closed evaluates its closed form for the slots asked
 * for (either of pk_one's families: the meeting triple first, PK_START, the Panda's
 * shoulder, or last, PK_END, the Gen3-like arm's wrist with joint_3 held; before
 * session 10 the PK_END rows were full pk_one solves, ~550 per pose), with pk_one's
 * polish and its repairs of those rows (the late ones, hm_stays, only where no
 * row of any slot is inside: hm_others_inside), and hands over to
 * pk_one only where a repair pk_one tries when no other row is inside would move
 * one (never on the 1,150 development poses; ~750 full solves per pose before
 * round 5), the same rows bit for bit (HM_VERIFY: 0 differences on 1,150 poses).
 *
 * A pose is flagged (flags != 0: the caller takes the solved-points path) when a
 * row next to an aligned triple is met (pk_one flags it singular: q1, q3 swing
 * there; on a pose with slot changes, a limit crossing or fold within
 * HM_ALIGNED_NEAR of an aligned-axes point of its branch, on the Panda-type arm not
 * the shoulder swing's own (hm_near_aligned): HM_FLAG_SINGULAR), a cell
 * cannot be resolved within HM_DEPTH splits (nor is a slot change, nor a swing: see
 * HM_SWING), a crossing does not
 * converge to HM_TOL, a branch vanishes inside a cell with rows at both ends, or
 * an output fills up; or before any row, when the held family is not of the Panda's
 * kind (PK_BOTH) or its position equations are not of the coplanar kind at a grid
 * value (HM_FLAG_BAD: Pieper's quartic, the rtb-data iiwa14 with joint_a3 held).
 * The pass stops at its first flag (the caller discards a flagged pose; its niv are
 * 0 and flags holds the first flag only): the work after it cost 44 ms per iiwa14
 * pose and up to 7 s per special Gen3-like pose (issue 29, helper quartic29).
 *
 * Since session 26 held_closed.c's closed forms take a pose first (HM_MODE_AUTO,
 * robot.self_motion's): this grid runs on the poses they do not certify (~4 % of
 * uniform Panda poses, about half of those with joints at special values, every pose
 * of other arms), as it did on every pose before.
 */

#include "brent.h"
#include "held_outputs.h"

#define HM_MAXQ 24      /* (joint, value) queries */
#define HM_MAXCUT 256   /* cuts per branch */
#define HM_JUMP 0.5     /* a joint moving more than this [rad] in a cell: split */
#define HM_DEPTH 14     /* splits of a grid cell */
/* A cell still to be split at HM_DEPTH that is no slot change, where the slot's q2 is
 * within HM_SWING_NEAR of its aligned-axes value at an end and a joint still moves by
 * more than HM_SWING [rad] (or would at its end slopes; one not finite counts) is a
 * swing (q1 and q3 turning by ~pi next to an aligned shoulder, q2 ~ 1e-13..1e-4:
 * their slopes ~1/q2): split on, to HM_DEEP
 * splits, HM_DEEP_ROWS such rows a pose, until the swing's centre is two adjacent
 * doubles (a cut there, as at a slot change). Session 21: 130 of the 148 flagged of
 * 2,000 special development poses had their shoulder aligned (q2 at 0 or 1e-9) and
 * took the solved-points path, 17 ms a pose. */
#define HM_SWING 1e-2
#define HM_SWING_NEAR 1e-3
#define HM_DEEP 96 /* (t ~ 1e-9: its ulp is 2^-77 of a grid cell) */
#define HM_DEEP_ROWS 1000
#define HM_TOL 1e-12    /* a crossing's joint at its value to this [rad] */
#define HM_TOL_STEEP 1e-9 /* the same where t's last bit moves the joint more */
#ifndef HM_FLOOR
#define HM_FLOOR 4.0 /* hm_root stops with q_j - value below this many ulps of t times dq_j/dt
                      * (8: 1.7 rows per pose fewer still, but an interval end of seed 1's corner pose 384
                      * no longer on its crossing record: held_manifold_check.py) */
#endif
#define HM_GRAIN 4
#define HM_NEAR 1e-6 /* a node with 1 / |dq/dt|^2 below this times its cell: at a branch end */
#define HM_MAXF 32 /* branch ends per slot remembered for its partner */
#define HM_FOLD_TOL 1e-11 /* a branch end to this (relative) */
#define HM_FOLD_STEPS 6 /* rows between a branch end and its grid row (a node at one) */
#define HM_PARALLEL_MIN 8
#define HM_DECIDE 1e-9 /* a grid row this far inside / outside decides its piece [rad] */
#define HM_SLOT_JUMP 1e-3 /* a slot's row moving more in one ulp of t: another branch [rad] */
#define HM_MAXJUMP 16 /* slot changes remembered per pose (hm_jump) */
#define HM_ALIGNED_NEAR 1e-4 /* a pose with slot jumps: a limit crossing or fold this close
                              * to an aligned-axes point of its branch is not certified */
#ifndef HM_SLOPE_DET
#define HM_SLOPE_DET 1e-10 /* hm_slopes_fast: a block's determinant per unit columns below it: hm_slopes */
#endif
#define HM_GAP_NEAR 3e-2 /* hm_grid: a second-angle margin next to the first angle's end is
                          * searched for a gap only where a node's is below this (the 40
                          * gaps of 12,000 development poses: at most 8.3e-4; 48 % of the
                          * ~3.3 searches a pose) */
#define HM_PAIR_ROWS 128 /* rows kept for the partner slot (hm_eval_pair, hm_split_row) */
#define HM_MAXG 8 /* grazes (a branch inside a limit by under HM_TOL) per slot */
#ifndef HM_UNSURE
#define HM_UNSURE 1 /* 0: a measuring build, coarse cells split as the others */
#endif
#define HM_MAXSEEN 256 /* rows per slot kept to decide pieces (hm_seen) */
#ifndef HM_STRIDE
#define HM_STRIDE 6 /* rows at every HM_STRIDE-th margin node where the margins keep their signs
                        * (6: 31 of 181 nodes, t = 0 among them, as on the fine grid) */
#endif



#define HM_MEMO 64 /* recent evaluations kept (hm_recall) */
#define HM_FRONTS 64 /* recent fronts kept (hm_front) */

/* Every slot at one t: coordinates (into the limits where a turn fits), slopes dq/dt
 * (NaN where the six other joints' Jacobian is singular), row exists, singular; the
 * slots whose slopes were computed (sloped: a bit per slot, the others' dq unset). */
typedef struct {
    double t;
    double q[8][PK_MAXJ], dq[8][PK_MAXJ];
    unsigned char valid[8], sing[8];
    unsigned sloped;
} HmRow;

typedef struct { /* one evaluation's rows (hm_keep, hm_recall) */
    double t;
    unsigned need;
    int closed;
    double q[8][PK_MAXJ];
    unsigned char valid[8], sing[8];
} HmMemo;


typedef struct {
    const double *P, *T;
    int n, k;
    double qn[PK_MAXJ];
    int nq, qj[HM_MAXQ], qkind[HM_MAXQ];
    double qv[HM_MAXQ];
    double hfine; /* the margins' grid spacing (the rows' grid is HM_STRIDE times coarser) */
    int flags;
    long evals, cheap;
    double *pts;
    long npts;
    double cut[8][HM_MAXCUT];
    int ncut[8];
    long fold_cell[8][HM_MAXF];
    double fold_t[8][HM_MAXF];
    int nfold[8];
    double graze_t[8][HM_MAXG][2]; /* a graze's in-limit stretch */
    int graze_j[8][HM_MAXG], ngraze[8];
    /* rows of a slot evaluated off the grid that decide a piece (hm_seen, round 8b) */
    double seen_t[8][HM_MAXSEEN];
    unsigned char seen_good[8][HM_MAXSEEN];
    int nseen[8];
    /* whether slot b's row at a cut is inside (hm_at: the row the cut was found on) */
    double at_t[8][HM_MAXSEEN];
    unsigned char at_in[8][HM_MAXSEEN];
    int nat[8];
    /* the slopes' structured solve (hm_slopes_fast; fast = 0: the full FK, hm_slopes):
     * the first three axes meeting at fc, the held joint last; the chain's product
     * of exponentials is G = T M^-1 (GA, Gt); per t (ft), the first six joints'
     * B5, b5 = G E_held(t)^-1; the held joint's columns at fc (u6, w6) */
    int fast, full_fk; /* full_fk: hm_slopes wanted (the fold search) */
    int deep; /* split rows past HM_DEPTH in swings (HM_DEEP_ROWS) */
    int deep_cell; /* hm_needs_split: a touch of an aligned-axes value is no split */
    int jumped; /* a slot's rows jump somewhere (hm_jump): the pose gets hm_near_aligned's test */
    int repaired; /* rows a repair brought inside (hm_repairs) */
    int coarse; /* a crossing decided on a bracket below one ulp of 1, not of t (hm_root) */
    double sq_te; /* NaN: cells in t; else a branch end's t: cells in sigma (hm_sigma) */
    int retry; /* a new slot change found by hm_root: the slot's pass is redone */
    double jump_t[HM_MAXJUMP][2]; /* the slot changes found (adjacent doubles), for every slot */
    int njump;
    v3 fc, Gt, u6, w6, b5;
    m3 GA, B5;
    double ft;
    /* the last wrist solve (hm_wrist): its t, q5, q6, whether it held, x and r */
    double wt, wq[2], wx[3];
    int wok;
    v3 wr;
    /* rows of a slot pair (b, b ^ 1) evaluated together (hm_eval_pair): near a fold, and
     * split midpoints the partner splits too (hm_split_row) */
    HmRow pair_row[HM_PAIR_ROWS];
    unsigned pair_need[HM_PAIR_ROWS], pair_mask[HM_PAIR_ROWS];
    int npair, ipair;
    HmMemo memo[HM_MEMO];
    double memo_t[HM_MEMO]; /* memo[i].t, contiguous: hm_recall's first test */
    long nmemo;
    PkFrontMemo front; /* pk_front's held-value-free parts (hm_closed) */
    HmMargMemo marg; /* hm_margins_d's held-value-free parts */
    /* recent fronts (hm_front): held value, the position slots solved, status */
    PkFront fronts[HM_FRONTS];
    double front_t[HM_FRONTS];
    unsigned front_want[HM_FRONTS];
    int front_code[HM_FRONTS];
    long nfront;
} HmCtx;

/* Gaussian elimination with partial pivoting of M (6 x 6 | right-hand side) into x;
 * 0 when a pivot is below 1e-14 (singular to rounding). */
static int hm_solve6(double M[6][7], double x[6])
{
    for (int i = 0; i < 6; i++) {
        int piv = i;
        for (int r = i + 1; r < 6; r++)
            if (fabs(M[r][i]) > fabs(M[piv][i]))
                piv = r;
        if (!(fabs(M[piv][i]) > 1e-14))
            return 0;
        if (piv != i)
            for (int m = i; m < 7; m++) {
                double s = M[i][m];
                M[i][m] = M[piv][m];
                M[piv][m] = s;
            }
        for (int r = i + 1; r < 6; r++) {
            double f = M[r][i] / M[i][i];
            for (int m = i; m < 7; m++)
                M[r][m] -= f * M[i][m];
        }
    }
    for (int i = 5; i >= 0; i--) {
        double s = M[i][6];
        for (int m = i + 1; m < 6; m++)
            s -= M[i][m] * x[m];
        x[i] = s / M[i][i];
    }
    return 1;
}

/* The slopes dq/dt (n) of configuration q (n) along the manifold (held joint k at
 * slope 1): the full chain's spatial Jacobian columns [h x (p - o) / scale; h],
 * the six other columns solving -J_k (Gaussian elimination, partial pivoting).
 * NaN when that 6 x 6 is singular to rounding. */
static void hm_slopes(const double *P, int n, int k, const double *q, double *dq)
{
    double scale = P[PK_SCALE], C[PK_MAXJ][6];
    m3 A = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
    v3 t = {0.0, 0.0, 0.0}, hc[PK_MAXJ], oc[PK_MAXJ];
    for (int j = 0; j < n; j++) {
        v3 h = v3_at(P, PK_AXES + 3 * j), o = v3_at(P, PK_POINTS + 3 * j);
        double th = P[PK_SIGN + j] * q[j] + P[PK_OFFSET + j];
        hc[j] = m3_mv(&A, h);
        oc[j] = v3_add(m3_mv(&A, o), t);
        m3 Rj = pk_rotm(h, cos(th), sin(th));
        t = v3_add(t, m3_mv(&A, v3_sub(o, m3_mv(&Rj, o))));
        A = pk_mul(&A, &Rj);
    }
    v3 p = v3_add(m3_mv(&A, v3_at(P, PK_TOOL_T)), t);
    for (int j = 0; j < n; j++) {
        v3 v = v3_scale(v3_cross(hc[j], v3_sub(p, oc[j])), P[PK_SIGN + j] / scale);
        v3 w = v3_scale(hc[j], P[PK_SIGN + j]);
        C[j][0] = v.x;
        C[j][1] = v.y;
        C[j][2] = v.z;
        C[j][3] = w.x;
        C[j][4] = w.y;
        C[j][5] = w.z;
    }
    double M[6][7];
    int col[6], c = 0;
    for (int j = 0; j < n && c < 6; j++)
        if (j != k)
            col[c++] = j;
    for (int r = 0; r < 6; r++) {
        for (int i = 0; i < 6; i++)
            M[r][i] = C[col[i]][r];
        M[r][6] = -C[k][r];
    }
    double x[6];
    if (!hm_solve6(M, x)) {
        for (int j = 0; j < n; j++)
            dq[j] = NAN;
        return;
    }
    for (int i = 0; i < 6; i++)
        dq[col[i]] = x[i];
    dq[k] = 1.0;
}

/* From here to hm_closed's end: no contraction into fused multiply-adds (and no
 * vectorisation), as pieper.c: the slopes' values then do not depend on how their
 * formulas are split over functions (contracted, the compiler fuses a split
 * computation's products differently: issue 29 rounds 7b, 8a). */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC push_options
#pragma GCC optimize("fp-contract=off", "no-tree-vectorize")
#endif
/* The first three axes' common point (zero configuration) into *pc when they meet
 * (to 1e-12 of the scale) and the held joint is the last of seven: the structure
 * hm_slopes_fast needs. */
static int hm_fast_setup(HmCtx *c)
{
    const double *P = c->P, *T = c->T;
    if (c->n != 7 || c->k != 6)
        return 0;
    v3 h0 = v3_at(P, PK_AXES), h1 = v3_at(P, PK_AXES + 3), h2 = v3_at(P, PK_AXES + 6);
    v3 o0 = v3_at(P, PK_POINTS), o1 = v3_at(P, PK_POINTS + 3), o2 = v3_at(P, PK_POINTS + 6);
    /* the point of axis 0 nearest axis 1 (they meet: that is their common point) */
    v3 n = v3_cross(h0, h1), d = v3_sub(o1, o0);
    double nn = v3_dot(n, n), scale = P[PK_SCALE];
    if (!(nn > 1e-12))
        return 0;
    v3 pc = v3_add(o0, v3_scale(h0, v3_dot(v3_cross(d, h1), n) / nn));
    for (int j = 0; j < 3; j++) {
        v3 h = j == 0 ? h0 : j == 1 ? h1 : h2, o = j == 0 ? o0 : j == 1 ? o1 : o2;
        v3 e = v3_sub(pc, o);
        if (!(v3_norm(v3_sub(e, v3_scale(h, v3_dot(e, h)))) <= 1e-12 * scale))
            return 0;
    }
    m3 RT = {{T[0], T[1], T[2]}, {T[4], T[5], T[6]}, {T[8], T[9], T[10]}};
    m3 RM = {v3_at(P, PK_TOOL_R), v3_at(P, PK_TOOL_R + 3), v3_at(P, PK_TOOL_R + 6)};
    c->fc = pc;
    c->GA = pk_mul_t(&RT, &RM);
    c->Gt = v3_sub((v3){T[3], T[7], T[11]}, m3_mv(&c->GA, v3_at(P, PK_TOOL_T)));
    double sg = P[PK_SIGN + 6];
    v3 h6 = m3_mv(&c->GA, v3_at(P, PK_AXES + 18));
    v3 o6 = v3_add(m3_mv(&c->GA, v3_at(P, PK_POINTS + 18)), c->Gt);
    c->u6 = v3_scale(v3_cross(h6, v3_sub(pc, o6)), sg);
    c->w6 = v3_scale(h6, sg);
    c->ft = NAN;
    c->wt = NAN;
    return 1;
}

/* The first six joints' transform at held value t: B5 x + b5 = G E_6(t)^-1 x */
static void hm_fast_at(HmCtx *c, double t)
{
    const double *P = c->P;
    if (t == c->ft)
        return;
    double th = P[PK_SIGN + 6] * t + P[PK_OFFSET + 6];
    v3 h = v3_at(P, PK_AXES + 18), o = v3_at(P, PK_POINTS + 18);
    m3 Rt = pk_rotm(h, cos(th), -sin(th)); /* E_6^-1's rotation */
    c->B5 = pk_mul(&c->GA, &Rt);
    c->b5 = v3_add(m3_mv(&c->GA, v3_sub(o, m3_mv(&Rt, o))), c->Gt);
    c->ft = t;
}

/* x solving [a b e] x = r (Cramer); 0 when the determinant is below tol times the
 * product of the columns' lengths */
static int hm_solve3(v3 a, v3 b, v3 e, v3 r, double tol, double x[3])
{
    v3 be = v3_cross(b, e);
    double det = v3_dot(a, be);

    if (!(det * det > tol * tol * v3_dot(a, a) * v3_dot(b, b) * v3_dot(e, e)))
        return 0;
    x[0] = v3_dot(r, be) / det;
    x[1] = v3_dot(a, v3_cross(r, e)) / det;
    x[2] = v3_dot(a, v3_cross(b, r)) / det;
    return 1;
}

/* hm_slopes_fast's wrist part at held value t for a row whose q5, q6 are q[4],
 * q[5]: the wrist joints' rates x (joints 4-6 against the held joint's linear
 * column at fc) and r, the angular velocity the shoulder must cancel; 0 when the
 * wrist block is singular to HM_SLOPE_DET. A function of t, q5 and q6 alone, so a
 * slot pair (the same position root: the same q4-q6) shares it: the last one is
 * kept (c->wt, wq) and taken again for the same t, q5, q6 (the same values: no
 * contraction in this region). */
static int hm_wrist(HmCtx *c, double t, const double *q, double x[3], v3 *r)
{
    const double *P = c->P;
    if (t == c->wt && q[4] == c->wq[0] && q[5] == c->wq[1]) {
        for (int i = 0; i < 3; i++)
            x[i] = c->wx[i];
        *r = c->wr;
        return c->wok;
    }
    hm_fast_at(c, t);
    double cs[6], sn[6], sg[6];
    for (int j = 3; j < 6; j++) {
        sg[j] = P[PK_SIGN + j];
        if (j == 3)
            continue;
        double th = sg[j] * q[j] + P[PK_OFFSET + j];
        cs[j] = cos(th);
        sn[j] = sin(th);
    }
    v3 h[6], o[6];
    for (int j = 3; j < 6; j++) {
        h[j] = v3_at(P, PK_AXES + 3 * j);
        o[j] = v3_at(P, PK_POINTS + 3 * j);
    }
    /* joints 4, 5 (0-based 3, 4) in joint 6's frame (E_5^-1, E_4^-1), then B5 */
    v3 h4 = v3_rot(h[5], cs[5], -sn[5], h[4]);
    v3 o4 = v3_add(v3_rot(h[5], cs[5], -sn[5], v3_sub(o[4], o[5])), o[5]);
    v3 r3 = v3_add(v3_rot(h[4], cs[4], -sn[4], v3_sub(o[3], o[4])), o[4]);
    v3 h3 = v3_rot(h[5], cs[5], -sn[5], v3_rot(h[4], cs[4], -sn[4], h[3]));
    v3 o3 = v3_add(v3_rot(h[5], cs[5], -sn[5], v3_sub(r3, o[5])), o[5]);
    v3 H[3] = {m3_mv(&c->B5, h3), m3_mv(&c->B5, h4), m3_mv(&c->B5, h[5])};
    v3 O[3] = {v3_add(m3_mv(&c->B5, o3), c->b5), v3_add(m3_mv(&c->B5, o4), c->b5),
               v3_add(m3_mv(&c->B5, o[5]), c->b5)};
    v3 U[3], Wa[3];
    for (int i = 0; i < 3; i++) {
        U[i] = v3_scale(v3_cross(H[i], v3_sub(c->fc, O[i])), sg[3 + i]);
        Wa[i] = v3_scale(H[i], sg[3 + i]);
    }
    int ok = hm_solve3(U[0], U[1], U[2], v3_scale(c->u6, -1.0), HM_SLOPE_DET, x);
    if (ok)
        *r = v3_add(v3_add(v3_scale(Wa[0], x[0]), v3_scale(Wa[1], x[1])),
                    v3_add(v3_scale(Wa[2], x[2]), c->w6));
    c->wt = t;
    c->wq[0] = q[4];
    c->wq[1] = q[5];
    c->wok = ok;
    for (int i = 0; i < 3; i++)
        c->wx[i] = ok ? x[i] : NAN;
    c->wr = ok ? *r : (v3){NAN, NAN, NAN};
    return ok;
}

/* hm_slopes by the structure (hm_fast_setup): the manifold's velocity equations
 * taken at the first three axes' common point fc, where those three columns have
 * no linear part, split into the wrist joints' 3 x 3 (linear: joints 4-6 against
 * the held joint's column) and the shoulder's 3 x 3 (angular); the world axes of
 * joints 4-6 from the pose backwards (G E_6^-1 E_5^-1 ...), of joints 1-3 from
 * the base: 2 sincos per row and slot and 2 per slot pair (the wrist, hm_wrist)
 * instead of the full FK's 7 and a 6 x 6.
 * The same slopes to rounding (the system differs by row operations); 0 (and
 * hm_slopes decides) where a block's determinant is below HM_SLOPE_DET times its
 * columns' lengths: next to a fold or an aligned shoulder, where the two differ
 * by more than rounding and hm_slopes' own singular test (a pivot below 1e-14)
 * decides whether the slope is NaN. */
static int hm_slopes_fast(HmCtx *c, double t, const double *q, double *dq)
{
    const double *P = c->P;
    double x[3], y[3], cs[2], sn[2], sg[3];
    v3 r;
    if (!hm_wrist(c, t, q, x, &r))
        return 0;
    for (int j = 0; j < 3; j++)
        sg[j] = P[PK_SIGN + j];
    for (int j = 0; j < 2; j++) {
        double th = sg[j] * q[j] + P[PK_OFFSET + j];
        cs[j] = cos(th);
        sn[j] = sin(th);
    }
    v3 h0 = v3_at(P, PK_AXES), h1 = v3_at(P, PK_AXES + 3), h2 = v3_at(P, PK_AXES + 6);
    /* the shoulder: world axes R0 h1, R0 R1 h2 */
    v3 a1 = v3_rot(h0, cs[0], sn[0], h1);
    v3 a2 = v3_rot(h0, cs[0], sn[0], v3_rot(h1, cs[1], sn[1], h2));
    if (!hm_solve3(v3_scale(h0, sg[0]), v3_scale(a1, sg[1]), v3_scale(a2, sg[2]),
                   v3_scale(r, -1.0), HM_SLOPE_DET, y))
        return 0;
    dq[0] = y[0];
    dq[1] = y[1];
    dq[2] = y[2];
    dq[3] = x[0];
    dq[4] = x[1];
    dq[5] = x[2];
    dq[6] = 1.0;
    return 1;
}

/* The slots in `need` at held value x by pk_one's closed form (its position
 * roots, theta_b, the triple, the coordinates, its pose check and polish: the
 * same calls in the same order; front f and its status code from hm_front:
 * pk_front_memo's, the per-arm parts kept, only the position roots of the slots
 * asked for solved), into r (the other slots
 * invalid). A row outside the limits that pk_one's repairs may move (singular;
 * within PK_NUDGE of them: pk_inside; not isolated: pk_slide) gets those repairs
 * here (hm_repairs); the repairs pk_one tries only when no row is inside
 * (hm_stays) run only when no row made here is inside (session 11: a fold end's
 * pair often has one). Returns 1 when these are pk_one's rows for those slots, 0
 * when pk_one must decide: the position is not of the coplanar kind, or what
 * pk_one makes of a row depends on its other slots (a repair it tries only when no
 * row is inside would move it). (Round 8a: 0 of ~494 evaluations per pose on the
 * development poses return 0, against ~21 before.) */
/* How far chain angles th (remaining chain) lie outside the limits, each joint at
 * its turn nearest them (as pk_inside measures it) [rad]: the largest. */
static double hm_outside(const double *P, const PkGeo *g, const double *th)
{
    double worst = 0.0;
    for (int j = 0; j < 6; j++) {
        int f = g->full[j];
        double lo = P[PK_LO + f], hi = P[PK_HI + f];
        double q = wrap_pi(P[PK_SIGN + f] * (th[j] - P[PK_OFFSET + f])), gap = INFINITY;
        for (int m = -1; m <= 1; m++) { /* (fmin, fmax: never NaN here, inline) */
            double qm = q + 2.0 * M_PI * m, d = qm < lo ? lo - qm : qm > hi ? qm - hi : 0.0;
            gap = d < gap ? d : gap;
        }
        worst = gap > worst ? gap : worst;
    }
    return worst;
}

/* Whether J's smallest singular value certainly exceeds PK_FAMILY_SIGMA times its
 * largest (pk_slide's family test, which pk_svd6 decides where pk_regular's
 * determinant bound cannot): sigma_min >= 1 / |J^-1|_F and sigma_max <= |J|_F, so
 * |J^-1|_F |J|_F < 1 / (2 PK_FAMILY_SIGMA) proves it (2: room for the computed
 * inverse's rounding, relative cond(J) eps < 1e-6 wherever the bound can hold).
 * LU with partial pivoting and six solves (~500 flops) against the Jacobi SVD's
 * thousands; 0 (the SVD decides) when it cannot prove it. */
static int hm_regular(const double J[6][6])
{
    double A[6][6], fro = 0.0, inv = 0.0;
    int perm[6];
    for (int r = 0; r < 6; r++) {
        perm[r] = r;
        for (int m = 0; m < 6; m++) {
            A[r][m] = J[r][m];
            fro += J[r][m] * J[r][m];
        }
    }
    for (int i = 0; i < 6; i++) {
        int piv = i;
        for (int r = i + 1; r < 6; r++)
            if (fabs(A[r][i]) > fabs(A[piv][i]))
                piv = r;
        if (!(fabs(A[piv][i]) > 0.0))
            return 0;
        if (piv != i) {
            for (int m = 0; m < 6; m++) {
                double w = A[i][m];
                A[i][m] = A[piv][m];
                A[piv][m] = w;
            }
            int w = perm[i];
            perm[i] = perm[piv];
            perm[piv] = w;
        }
        for (int r = i + 1; r < 6; r++) {
            A[r][i] /= A[i][i];
            for (int m = i + 1; m < 6; m++)
                A[r][m] -= A[r][i] * A[i][m];
        }
    }
    for (int k = 0; k < 6; k++) { /* column k of J^-1: L U x = P e_k */
        double x[6];
        for (int r = 0; r < 6; r++) {
            double v = perm[r] == k ? 1.0 : 0.0;
            for (int m = 0; m < r; m++)
                v -= A[r][m] * x[m];
            x[r] = v;
        }
        for (int r = 5; r >= 0; r--) {
            double v = x[r];
            for (int m = r + 1; m < 6; m++)
                v -= A[r][m] * x[m];
            x[r] = v / A[r][r];
            inv += x[r] * x[r];
        }
    }
    return 4.0 * PK_FAMILY_SIGMA * PK_FAMILY_SIGMA * inv * fro < 1.0;
}

/* pk_one's own repairs of row th (coordinates q, outside the limits, the held
 * joint inside; sing: flagged singular), in its order (pk_resplit; pk_repair when
 * singular; pk_inside; pk_slide when singular), th and q taking their moves.
 * Returns 1 when they bring it inside (then it is pk_one's row). */
static int hm_repairs(const HmCtx *c, const PkFront *f, double *th, double *q, int sing)
{
    const double *P = c->P;
    const PkGeo *g = &f->g;
    int held = (int)P[PK_HELD];
    double x = q[held];
    int all = 0;
    if (pk_resplit(P, g, f->it, &f->RT, f->pT, th))
        all = pk_coords(P, g, th, held, x, q) >= -1e-9;
    if (!all && sing && pk_repair(P, g, &f->RT, f->pT, th))
        all = pk_coords(P, g, th, held, x, q) >= -1e-9;
    if (!all && pk_inside(P, g, &f->RT, f->pT, th, sing ? PK_NUDGE_SING : PK_NUDGE))
        all = pk_coords(P, g, th, held, x, q) >= -1e-9;
    if (!all && sing && pk_slide(P, g, &f->RT, f->pT, th))
        all = pk_coords(P, g, th, held, x, q) >= -1e-9;
    return all;
}

/* Whether a row hm_repairs left outside (th, coordinates q) is pk_one's: the
 * repairs pk_one tries only when no row of the pose is inside find nothing from
 * it (pk_walk_rows' pk_walk, else pk_pin, from the coordinates, for a singular
 * row; the late pk_slide for another). hm_closed asks only when none of the rows
 * it made at that value is inside (one is: pk_one tries none of them). 0: the
 * other slots decide (pk_one must). */
static int hm_stays(const HmCtx *c, const PkFront *f, const double *th, const double *q,
                    int sing)
{
    const double *P = c->P;
    const PkGeo *g = &f->g;
    double tw[6], tp[6];
    for (int j = 0; j < 6; j++) {
        int fj = g->full[j];
        tw[j] = sing ? P[PK_SIGN + fj] * q[fj] + P[PK_OFFSET + fj] : th[j];
        tp[j] = tw[j];
    }
    if (!sing)
        return !pk_slide(P, g, &f->RT, f->pT, tw);
    return !pk_walk(P, g, &f->RT, f->pT, tw) && !pk_pin(P, g, &f->RT, f->pT, tp);
}

/* Whether row th (chain angles of the remaining chain, either triple first) is
 * certainly left alone by pk_resplit and pk_slide, the repairs hm_closed must
 * otherwise mirror for a row outside the limits not flagged singular: the
 * triple's outer axes are apart (sv >= 2e-6: pk_resplit acts only below 1e-6; the
 * same v as its own) and pk_isolated's determinant bound holds with a factor 2 to
 * spare (then pk_isolated, and so pk_slide, holds on the same row whatever the
 * rounding of either product). The bound's two factors as pk_isolated takes them:
 * the triple's from v (one sincos, shared with the sv test), the position joints'
 * from the position root's own cosines and sines (no sincos; cs[0] = {cos, sin}
 * of the joint pk_isolated undoes, th[3] of the Panda's PK_START, th[2] of a
 * PK_END chain; cs[1] of th[p0 + 1], its middle position joint), and the bound of
 * |J|_F^2 once per hm_closed call (*f2, NAN until then). 0: unproven (the caller
 * runs pk_resplit and pk_isolated as before). Replaces ~1,100 instructions per
 * such row (2 of every 3 rows the Panda's kernel evaluates) with ~300. */
static int hm_far_isolated(const PkGeo *g, const double *th, const double cs[2][2],
                           double *f2)
{
    if (g->kase != PK_START && g->kase != PK_END)
        return 0;
    int t0 = g->kase == PK_END ? 3 : 0, p0 = 3 - t0;
    v3 v = v3_rot(g->h[t0 + 1], cos(th[t0 + 1]), sin(th[t0 + 1]), g->h[t0 + 2]);
    if (!(v3_norm(v3_cross(v, g->h[t0])) >= 2e-6))
        return 0;
    double s = g->scale;
    if (isnan(*f2)) { /* pk_isolated's |J|_F^2 bound: the reach from each joint */
        double reach = v3_norm(v3_sub(g->tM, g->o[5])), b = 6.0;
        for (int j = 5; j >= 0; j--) {
            b += reach * reach / (s * s);
            if (j > 0)
                reach += v3_norm(v3_sub(g->o[j], g->o[j - 1]));
        }
        *f2 = b;
    }
    double dt = v3_dot(g->h[t0], v3_cross(g->h[t0 + 1], v));
    v3 ha = g->h[p0 + 1], oa = g->o[p0 + 1], w = g->pt;
    double ca = cs[1][0], sa = cs[1][1];
    v3 hb = v3_rot(ha, ca, sa, g->h[p0 + 2]);
    v3 ob = v3_add(oa, v3_rot(ha, ca, sa, v3_sub(g->o[p0 + 2], oa)));
    if (p0 == 0) { /* w after joints 1 and 2 (joint 0 undone) */
        w = v3_add(g->o[2], v3_rot(g->h[2], cs[0][0], cs[0][1], v3_sub(w, g->o[2])));
        w = v3_add(oa, v3_rot(ha, ca, sa, v3_sub(w, oa)));
    } else { /* w before joint 3 (the triple and joint 3 undone) */
        w = v3_add(g->o[3], v3_rot(g->h[3], cs[0][0], -cs[0][1], v3_sub(w, g->o[3])));
    }
    v3 c0 = v3_cross(g->h[p0], v3_sub(w, g->o[p0]));
    v3 c1 = v3_cross(ha, v3_sub(w, oa)), c2 = v3_cross(hb, v3_sub(w, ob));
    double det = fabs(dt * v3_dot(c0, v3_cross(c1, c2))) / (s * s * s), b = *f2;
    return det > 8.0 * PK_FAMILY_SIGMA * b * b * b;
}

/* The position slots (a bit each) of the slots in `need` */
static unsigned hm_want(unsigned need)
{
    unsigned want = 0u;
    for (int i = 0; i < 4; i++)
        want |= (need >> 2 * i & 3u) != 0u ? 1u << i : 0u;
    return want;
}

/* hm_closed's rows: the slots in `need` at x from front f (status PK_OK) into r
 * (cleared before); the rows hm_repairs left outside, which only pk_one's late
 * repairs may move, into late_th and *late (a bit per slot). Returns whether a row
 * made here is inside (after the early repairs: pk_one's test before its late ones).
 * late NULL: a probe (hm_others_inside), no repairs tried: whether a row is inside as
 * made (1 at the first; the rows in r then partial). */
static int hm_make(HmCtx *c, double x, unsigned need, const PkFront *f, HmRow *r,
                   double late_th[8][6], unsigned *late)
{
    const double *P = c->P;
    const PkGeo *g = &f->g;
    const PkPos *pos = &f->pos;
    int held = (int)P[PK_HELD];
    double stol = P[PK_SING_TOL];
    int held_in = pk_held_inside(P, held, x);
    int ia = f->ia, it = f->it;
    double f2 = NAN; /* hm_far_isolated's bound of |J|_F^2, once per call */
    int inside = 0; /* a row made here is inside: pk_one tries no late repair */
    for (int i = 0; i < pos->n; i++) {
        unsigned slots = 3u << (2 * pos->slot[i]);
        if (!(need & slots) || !(pos->res[i] < 1e-6 * g->scale))
            continue;
        double th[6];
        m3 Rt = pk_front_rotation(f, i, th);
        PkTrip tr;
        pk_triple_want(P, &f->tri, &Rt, f->jx, f->jz, c->qn[f->jz], stol,
                       need >> 2 * pos->slot[i] & 3u, &tr);
        for (int k = 0; k < tr.n; k++) {
            int slot = 2 * pos->slot[i] + k;
            if (!(need >> slot & 1u))
                continue;
            int sing = pos->sing[i] || tr.sing[k];
            for (int j = 0; j < 3; j++) {
                th[ia + j] = pos->t[i][j];
                th[it + j] = tr.t[k][j];
            }
            /* pk_one's check: kept unchanged when exact, else polished (its calls) */
            if (tr.check[k] || !(pos->res[i] < f->exact_p)) {
                double err = pk_error_of(g, &f->RT, f->pT, th);
                if (err > PK_EXACT)
                    err = pk_polish_slow(g, &f->RT, f->pT, th, pk_polish(g, &f->RT, f->pT, th));
                if (!(err <= PK_ACCEPT))
                    continue; /* not a solution to 1e-12: no row */
            }
            double m = pk_coords(P, g, th, held, x, r->q[slot]);
            inside |= m >= -1e-9;
            if (late == NULL && inside)
                return 1; /* a probe (hm_others_inside): one row inside */
            if (!(m >= -1e-9) && held_in && late != NULL) {
                /* pk_one's repairs may move it: a singular row, one within reach of
                 * pk_inside, one pk_resplit moves (next to an aligned triple: its
                 * split of the outer angles; tried on a copy, hm_stays moves the
                 * row: the Gen3-like arm's wrist at q6 ~ 0 moved q5 by an ulp or a
                 * turn), one on a family (pk_slide's own test) */
                int moves = sing || !(hm_outside(P, g, th) > 2.0 * PK_NUDGE);
                /* far outside, not singular: most rows; proven alone (the position
                 * joints as solved, not polished) or tested as pk_one would */
                int u = f->start ? 0 : 2; /* the position joint pk_isolated undoes */
                int alone = !moves && th[ia + u] == pos->t[i][u] &&
                            th[ia + 1] == pos->t[i][1] &&
                            hm_far_isolated(g, th, (const double[2][2]){
                                {pos->c[i][u], pos->s[i][u]}, {pos->c[i][1], pos->s[i][1]}},
                                &f2);
                if (!moves && !alone) {
                    double tc[6];
                    memcpy(tc, th, sizeof tc);
                    moves = pk_resplit(P, g, it, &f->RT, f->pT, tc);
                }
                /* not proven isolated: maybe on a family, which only pk_one's late
                 * pk_slide would move (its early repairs leave a far row alone: the
                 * resplit tested above, pk_inside's reach below the row's gap), so
                 * hm_stays decides, by pk_slide's own SVD, and only when no row made
                 * here is inside (pk_slide then has the same J: session 12) */
                int family = 0;
                if (!moves && !alone && !pk_isolated(g, th)) {
                    m3 R;
                    v3 p;
                    double J[6][6];
                    pk_fk(g, th, &R, &p, J);
                    family = !pk_regular(J) && !hm_regular(J);
                }
                if (moves && hm_repairs(c, f, th, r->q[slot], sing)) {
                    inside = 1;
                    c->repaired++;
                } else if (moves || family) {
                    memcpy(late_th[slot], th, sizeof late_th[slot]);
                    *late |= 1u << slot;
                }
            }
            r->valid[slot] = 1;
            r->sing[slot] = (unsigned char)sing;
        }
    }
    return inside;
}

/* Whether a slot not in `need` has a row inside at x as made, before any repair
 * (hm_make's probe; from a front of their own, not kept: pk_front_memo's, the same
 * bits as any front at x for those slots): then pk_one, which makes every slot, tries
 * no late repair on any row (a row inside as made is inside after its early repairs,
 * which leave it alone), and the late rows of the slots in need stay as made. 0 where
 * only a repair could bring one inside: hm_stays decides, as before. Asked only where
 * hm_stays would run (a row of `need` left outside, none inside): its repairs
 * (pk_slide's SVD, pk_walk, pk_pin) cost ~20,000 instructions a call, the probe a few
 * thousand. */
static int hm_others_inside(HmCtx *c, double x, unsigned need)
{
    unsigned rest = 0xffu & ~need;
    if (!rest)
        return 0;
    PkFront f;
    if (pk_front_memo(c->P, c->T, x, c->qn, 0, &c->front, hm_want(rest), &f) != PK_OK)
        return 0; /* no row of those slots */
    HmRow o;
    return hm_make(c, x, rest, &f, &o, NULL, NULL);
}

static int hm_closed(HmCtx *c, double x, unsigned need, const PkFront *f, int code, HmRow *r)
{
    for (int b = 0; b < 8; b++) {
        r->valid[b] = r->sing[b] = 0;
        for (int j = 0; j < PK_MAXJ; j++)
            r->q[b][j] = NAN;
    }
    if (code == PK_FRONT_SWIVEL || code == PK_FRONT_GENERAL)
        return 0; /* He and Liu's general case: not this kernel's */
    if (code != PK_OK)
        return 1; /* pk_one: cleared, no row */
    double late_th[8][6]; /* rows hm_repairs left outside: hm_stays after the loop */
    unsigned late = 0u;
    int inside = hm_make(c, x, need, f, r, late_th, &late);
    if (late && !inside)
        inside = hm_others_inside(c, x, need);
    for (int slot = 0; slot < 8 && !inside; slot++)
        if ((late >> slot & 1u) && !hm_stays(c, f, late_th[slot], r->q[slot], r->sing[slot]))
            return 0; /* what pk_one makes of it depends on the other slots */
    return 1;
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC pop_options
#endif

/* pk_front_memo's front at held value x for the position slots of the slots in
 * `need` (its status into *code), or a recent one at the same x that solved them (HM_FRONTS kept): each
 * position root is solved alone, so a kept front has the same bits for the slots
 * asked; its status may be PK_OK where the slots asked have no root, and then
 * hm_closed makes no row either way. Found for ~20 % of the calls on the Panda's
 * development poses: a slot evaluated where its partner was (the same position
 * root), at a shared crossing (hm_shared) or a pair's piece. */
static const PkFront *hm_front(HmCtx *c, double x, unsigned need, int *code)
{
    unsigned want = hm_want(need);
    int seen = 0; /* any kept front at x: one vectorised pass (as hm_recall) */
    for (int i = 0; i < HM_FRONTS; i++)
        seen |= c->front_t[i] == x;
    for (int i = 0; i < HM_FRONTS && seen; i++)
        if (c->front_t[i] == x && (want & ~c->front_want[i]) == 0u) {
            *code = c->front_code[i];
            return &c->fronts[i];
        }
    int i = (int)(c->nfront++ % HM_FRONTS);
    *code = pk_front_memo(c->P, c->T, x, c->qn, 0, &c->front, want, &c->fronts[i]);
    c->front_t[i] = x;
    c->front_want[i] = want;
    c->front_code[i] = *code;
    return &c->fronts[i];
}

/* The rows of a recent evaluation (hm_keep, hm_recall): t, the slots asked for,
 * whether hm_closed gave them (else pk_one gave every slot) and the rows. */
static int hm_recall(HmCtx *c, double t, unsigned need, HmRow *r)
{
    int seen = 0; /* any kept evaluation at t (~7 % of calls): one vectorised pass */
    for (int i = 0; i < HM_MEMO; i++)
        seen |= c->memo_t[i] == t;
    if (!seen)
        return 0;
    for (int i = 0; i < HM_MEMO; i++) {
        const HmMemo *m = &c->memo[i];
        if (m->t != t || (m->closed ? (need & ~m->need) != 0u : need != m->need))
            continue;
        /* hm_closed's rows for the slots in need: those of m (each slot's rows are
         * computed alone), the others invalid; pk_one's: all of m (hm_closed with the
         * same need gave way to it again) */
        for (int b = 0; b < 8; b++) {
            int own = !m->closed || (need >> b & 1u);
            r->valid[b] = own ? m->valid[b] : 0;
            r->sing[b] = own ? m->sing[b] : 0;
            for (int j = 0; j < PK_MAXJ; j++)
                r->q[b][j] = own ? m->q[b][j] : NAN;
        }
        c->evals += !m->closed; /* counted as the pk_one call it replaces */
        return 1;
    }
    return 0;
}

static void hm_keep(HmCtx *c, double t, unsigned need, int closed, const HmRow *r)
{
    c->memo_t[c->nmemo % HM_MEMO] = t;
    HmMemo *m = &c->memo[c->nmemo++ % HM_MEMO];
    m->t = t;
    m->need = need;
    m->closed = closed;
    memcpy(m->q, r->q, sizeof m->q);
    memcpy(m->valid, r->valid, sizeof m->valid);
    memcpy(m->sing, r->sing, sizeof m->sing);
}

/* A slot pair's missing row where the shoulder is aligned: the held solvers give the
 * pair (b, b ^ 1: the same position root, the shoulder's two triples (q1, q2, q3) and
 * (q1 + pi, -q2, q3 + pi)) one row where |q2| <= HM_TOL (the two within rounding of
 * one configuration). The other is that row's mirror, which has the same pose (q2 = 0:
 * axes 1 and 3 on one line). Session 21: the odd slot had no row at a grid node where
 * the generating configuration's q2 = 0 and q7 is a node (0, a limit), its cells there
 * looked like a branch end or an absence, and a piece of its branch was missed (special
 * #1163 of seed 22: branch 5 inside over (2.8701, 2.8973), no interval). Both slots'
 * rows are solved wherever one asked for is missing (hm_eval, hm_partners); on arms
 * with q7 held only (the Panda's kind; the mirror checked on the Panda: FK equal to
 * 6e-16). */
static void hm_mirror(const HmCtx *c, unsigned need, HmRow *r)
{
    if (c->n != 7 || c->k != 6)
        return; /* the Panda's kind: q7 held, the shoulder triple q1-q3 */
    for (int e = 0; e < 8; e += 2) {
        if ((need >> e & 3u) != 3u || r->valid[e] == r->valid[e + 1])
            continue;
        int from = r->valid[e] ? e : e + 1, to = from ^ 1;
        if (!(fabs(r->q[from][1]) <= HM_TOL))
            continue;
        for (int j = 0; j < c->n; j++)
            r->q[to][j] = r->q[from][j];
        r->q[to][0] = wrap_pi(r->q[from][0] + M_PI);
        r->q[to][1] = -r->q[from][1];
        r->q[to][2] = wrap_pi(r->q[from][2] + M_PI);
        r->valid[to] = 1;
        r->sing[to] = r->sing[from];
    }
}

/* The partners of the slots in `need` whose rows hm_closed left missing, where the
 * partner was not asked for (hm_mirror needs its row): 0 on other arms. */
static unsigned hm_partners(const HmCtx *c, unsigned need, const HmRow *r)
{
    unsigned more = 0u;
    if (c->n != 7 || c->k != 6)
        return 0u;
    for (int b = 0; b < 8; b++)
        if ((need >> b & 1u) && !r->valid[b] && !(need >> (b ^ 1) & 1u))
            more |= 1u << (b ^ 1);
    return more;
}

/* The slots in `need` at t (hm_closed, else pk_one's every slot), shifted into the
 * limits by whole turns where that fits (as the numpy path's _into_limits); slopes
 * for the slots in `mask`. The rows of an evaluation at the same t among the last
 * HM_MEMO that covers these slots are taken again (hm_recall: the same rows, each a
 * function of t and its slot; ~7 % of the evaluations, 1 in 5 of them pk_one's). */
#ifdef HM_STAGES /* a measuring build: evaluations per calling function, to stderr */
static const char *hm_tag;
static const char *hm_tags[16];
static long hm_tag_n[16];
static void hm_eval_(HmCtx *c, double t, unsigned mask, unsigned need, HmRow *r);
#define hm_eval(...) (hm_tag = __func__, hm_eval_(__VA_ARGS__))
static void hm_eval_(HmCtx *c, double t, unsigned mask, unsigned need, HmRow *r)
{
    for (int i = 0; i < 16; i++)
        if (hm_tags[i] == NULL || hm_tags[i] == hm_tag) {
            hm_tags[i] = hm_tag;
            hm_tag_n[i]++;
            break;
        }
#else
static void hm_eval(HmCtx *c, double t, unsigned mask, unsigned need, HmRow *r)
{
#endif

    const double *P = c->P;
    r->t = t;
    c->cheap++;
    if (hm_recall(c, t, need, r))
        goto slopes;
    int code, closed;
    for (;;) {
        const PkFront *f = hm_front(c, t, need, &code);
        closed = hm_closed(c, t, need, f, code, r);
        if (!closed) {
            unsigned char inside[8];
            PkOut o = {&r->q[0][0], r->valid, r->sing, inside, PK_MAXJ};
            c->evals++;
            pk_one(P, c->T, t, c->qn, o);
        }
        unsigned more = closed ? hm_partners(c, need, r) : 0u;
        if (!more)
            break;
        need |= more; /* a slot's row missing where its partner's may be aligned: both */
    }
#ifdef HM_VERIFY
    if (closed) { /* a checking build (-DHM_VERIFY): every closed-form row against pk_one's */
        double Q[8][PK_MAXJ];
        unsigned char v[8], sg[8], in[8];
        PkOut o = {&Q[0][0], v, sg, in, PK_MAXJ};
        pk_one(P, c->T, t, c->qn, o);
        for (int b = 0; b < 8; b++) {
            if (!(need >> b & 1u))
                continue;
            int bad = v[b] != r->valid[b];
            for (int j = 0; j < c->n && v[b] && !bad; j++)
                bad = Q[b][j] != r->q[b][j];
            if (bad)
                fprintf(stderr, "mismatch t %.17g slot %d valid %d/%d q0 %.17g/%.17g\n", t, b,
                        v[b], r->valid[b], Q[b][0], r->q[b][0]);
        }
    }
#endif
    hm_mirror(c, closed ? need : 0xffu, r); /* (after the check: pk_one has no mirror) */
    for (int b = 0; b < 8; b++) {
        if (!r->valid[b])
            continue;
        for (int j = 0; j < c->n; j++) {
            double q = r->q[b][j], lo = P[PK_LO + j], hi = P[PK_HI + j];
            if (q < lo && q + 2.0 * M_PI <= hi)
                q += 2.0 * M_PI;
            else if (q > hi && q - 2.0 * M_PI >= lo)
                q -= 2.0 * M_PI;
            r->q[b][j] = q;
        }
    }
    hm_keep(c, t, need, closed, r);
slopes:
    r->sloped = 0u;
    for (int b = 0; b < 8; b++) {
        if (!r->valid[b] || !(mask >> b & 1u))
            continue;
        r->sloped |= 1u << b;
        if (!(c->fast && !c->full_fk && hm_slopes_fast(c, t, r->q[b], r->dq[b])))
            hm_slopes(P, c->n, c->k, r->q[b], r->dq[b]);
#ifdef HM_SLOPE_CHECK
        if (c->fast) { /* a checking build: the structured slopes against the full FK's */
            double ref[PK_MAXJ], worst = 0.0, big = 0.0;
            hm_slopes(P, c->n, c->k, r->q[b], ref);
            for (int j = 0; j < c->n; j++) {
                worst = fmax(worst, fabs(ref[j] - r->dq[b][j]));
                big = fmax(big, fabs(ref[j]));
            }
            fprintf(stderr, "slope %.3e %.3e %d %d\n", worst / big, big, isfinite(ref[0]),
                    isfinite(r->dq[b][0]));
        }
#endif
    }
}


/* Whether a pair row at t with slot b (its slope when `slopes`) is kept: then into *r. */
static int hm_pair_find(const HmCtx *c, double t, int b, int slopes, HmRow *r)
{
    unsigned mask = slopes ? 1u << b : 0u;
    for (int i = 0; i < c->npair; i++)
        if (c->pair_row[i].t == t && (c->pair_need[i] >> b & 1u) &&
            (c->pair_mask[i] & mask) == mask) {
            *r = c->pair_row[i];
            return 1;
        }
    return 0;
}

/* Slot b's row at t (its slope when `slopes`) for a branch end and its near-fold
 * piece, or a split midpoint (hm_split_row): the slot and its partner b ^ 1 (the
 * same position root, the wrist's other solution: its branch ends at the same t
 * and its piece has rows at the same t values) are evaluated together and the row
 * kept (HM_PAIR_ROWS of them), so that the partner's end, piece and splits take it
 * from here: one closed form (pk_front, the position roots and the triple) for both. The rows are the same as evaluated one
 * slot at a time (hm_closed's per-slot rows, or pk_one's where it hands over). */
static void hm_eval_pair(HmCtx *c, double t, int b, int slopes, HmRow *r)
{
    unsigned pair = 3u << (b & ~1);
    if (hm_pair_find(c, t, b, slopes, r))
        return;
    hm_eval(c, t, slopes ? pair : 0u, pair, r);
    int i = c->ipair;
    c->ipair = (i + 1) % HM_PAIR_ROWS;
    c->npair += c->npair < HM_PAIR_ROWS;
    c->pair_row[i] = *r;
    c->pair_need[i] = pair;
    c->pair_mask[i] = slopes ? pair : 0u;
}

static void hm_point(HmCtx *c, double t, int b, int j, int kind)
{
    if (c->npts >= HM_MAXP) {
        c->flags |= HM_FLAG_FULL;
        return;
    }
    double *p = c->pts + 4 * c->npts++;
    p[0] = t;
    p[1] = b;
    p[2] = j;
    p[3] = kind;
    if (kind == HM_KIND_ALIGNED)
        return;
    if (c->ncut[b] >= HM_MAXCUT) {
        c->flags |= HM_FLAG_FULL;
        return;
    }
    c->cut[b][c->ncut[b]++] = t;
}

/* q_j - value of slot b's row, at the turn of value nearest q_j */
static inline double hm_f(const HmCtx *c, const HmRow *r, int b, int qi)
{
    return wrap_pi(r->q[b][c->qj[qi]] - c->qv[qi]);
}

/* The cells' coordinate: t itself, or within a branch end's near-fold piece
 * (hm_fold_piece sets c->sq_te to the end's t) sigma = sign(t - te) sqrt|t - te|,
 * in which the rows are smooth (q - q_end grows as the square root of the distance
 * from the end: a power series in sigma), so that the cells' cubic Hermite models
 * and their splits work there as on the grid's cells. */
static double hm_sigma(const HmCtx *c, double t)
{
    if (isnan(c->sq_te))
        return t;
    double d = t - c->sq_te;
    return copysign(sqrt(fabs(d)), d);
}

/* The t of coordinate s (hm_sigma's inverse) */
static double hm_of_sigma(const HmCtx *c, double s)
{
    return isnan(c->sq_te) ? s : c->sq_te + copysign(s * s, s);
}

/* dt / d(coordinate) at t: 1 in t, 2 |sigma| in sigma */
static double hm_dtds(const HmCtx *c, double t)
{
    return isnan(c->sq_te) ? 1.0 : 2.0 * fabs(hm_sigma(c, t));
}

/* The cubic Hermite model of f on a cell (values f0, f1 at its ends, slopes d0, d1 per
 * unit of the cell): f(s) = f0 + d0 s + A s^2 + B s^3 (s in [0, 1]); its values lie
 * within the range of f0, f1 +- HM_H4_27 (|d0| + |d1|) (the basis: h00 + h01 = 1,
 * |h10|, |h11| <= 4/27). */
#define HM_H4_27 0.1482
static inline void hm_hermite_ab(double f0, double f1, double d0, double d1, double *A,
                                 double *B)
{
    *A = 3.0 * (f1 - f0) - 2.0 * d0 - d1;
    *B = 2.0 * (f0 - f1) + d0 + d1;
}

/* The root in (0, 1) of the cubic Hermite model of f on a cell (values f0, f1 of
 * opposite signs, slopes d0, d1 per unit of the cell): safeguarded Newton on the
 * cubic from the secant's root (no rows). */
static double hm_hermite_root(double f0, double f1, double d0, double d1)
{
    double A, B;
    hm_hermite_ab(f0, f1, d0, d1, &A, &B);
    double lo = 0.0, hi = 1.0, s = f0 / (f0 - f1);
    for (int it = 0; it < 12; it++) {
        double v = f0 + s * (d0 + s * (A + s * B)), dv = d0 + s * (2.0 * A + 3.0 * s * B);
        if (v == 0.0)
            break;
        if ((v < 0) == (f0 < 0))
            lo = s;
        else
            hi = s;
        double sn = s - v / dv;
        s = sn > lo && sn < hi ? sn : 0.5 * (lo + hi);
    }
    return s;
}

static void hm_seen(HmCtx *c, int b, const HmRow *r);
static int hm_inside(const HmCtx *c, const HmRow *r, int b, double slack);
static int hm_bisect_jump(HmCtx *c, int b, HmRow *ra, HmRow *rb);

/* Slot b's row at cut t is inside (with MANIFOLD_SLACK) or not: kept from the row the
 * cut was found on, so that hm_intervals' [t, t] rule needs no row there (round 8b) */
static void hm_at(HmCtx *c, int b, double t, int in)
{
    if (c->nat[b] < HM_MAXSEEN) {
        c->at_t[b][c->nat[b]] = t;
        c->at_in[b][c->nat[b]++] = (unsigned char)in;
    }
}

/* A cut of slot b at t where its rows jump (a slot change, a swing's centre): no
 * point, and its row not inside (hm_at: never a one-point interval); the pose then
 * gets hm_near_aligned's test. 0 when the slot's cuts are full (HM_FLAG_FULL). */
static int hm_jump_cut(HmCtx *c, int b, double t)
{
    if (c->ncut[b] >= HM_MAXCUT) {
        c->flags |= HM_FLAG_FULL;
        return 0;
    }
    c->cut[b][c->ncut[b]++] = t;
    c->jumped = 1;
    hm_at(c, b, t, 0);
    return 1;
}

#ifdef HM_SHARE_STATS /* a measuring build: partner lookups per joint (tried, taken) */
static long hm_share_n[PK_MAXJ][2];
#endif

/* A crossing of joint j (query qi) by the odd slot b in (a, e) (fa at a) taken from
 * its partner b ^ 1 (the same position root, evaluated first): a partner's point of
 * joint j inside (a, e) (the shared joints cross their values at the same t: q4-q6
 * are the position root's, q2 the mirror of its partner's) confirmed by b's own row
 * there, at the value to hm_root's own 1e-14. 1 when taken (the point recorded). */
static int hm_shared(HmCtx *c, int b, int qi, double a, double fa, double e)
{
    int j = c->qj[qi];
    if (!(b & 1))
        return 0;
    double found = NAN;
    for (long i = 0; i < c->npts; i++) {
        const double *p = c->pts + 4 * i;
        if (p[1] == (double)(b ^ 1) && p[2] == (double)j && p[3] != HM_KIND_FOLD && p[0] > a &&
            p[0] < e) {
            if (!isnan(found))
                return 0; /* two: not this one's to choose */
            found = p[0];
        }
    }
    if (isnan(found))
        return 0;
#ifdef HM_SHARE_STATS
    hm_share_n[j][0]++;
#endif
    HmRow r;
    hm_eval(c, found, 0u, 1u << b, &r);
    if (!r.valid[b])
        return 0;
    hm_seen(c, b, &r);
    double f = fa + wrap_pi(hm_f(c, &r, b, qi) - fa);
    if (!(fabs(f) <= 1e-14))
        return 0;
#ifdef HM_SHARE_STATS
    hm_share_n[j][1]++;
#endif
    hm_point(c, found, b, j, c->qkind[qi]);
    hm_at(c, b, found, hm_inside(c, &r, b, MANIFOLD_SLACK));
    return 1;
}

#ifndef HM_LAST_SLOPE
#define HM_LAST_SLOPE 20.0 /* hm_last: |dq_j/dt| at most this (steeper: the rows' rounding rules) */
#endif
#define HM_LAST_F 1e-8     /* hm_last: |q_j - value| at most this at the last row */
#define HM_LAST_PRED 1e-17 /* hm_last: Newton's predicted |q_j - value| at its step at most this */

/* Whether hm_root's Newton step tn from slot b's row r (query qi, its q_j - value f
 * and slope d; the previous iterate tp, its slope dp) ends the crossing without a row
 * at tn (session 12): q_j - value at tn is predicted by Newton's error, half the
 * curvature (the slopes' secant) times the step squared, at most HM_LAST_PRED (the
 * stop asks 1e-14 of the row), with |f| <= HM_LAST_F and |d| <= HM_LAST_SLOPE (where
 * the row's own rounding is below 1e-14: steeper joints, next to an aligned shoulder,
 * have rows noisier than the stop); and whether slot b's row at tn is inside (into
 * *in, as hm_inside with MANIFOLD_SLACK would find it) is decided by r and its slopes
 * (every joint's extrapolated coordinate more than twice its move plus 1e-12 from
 * each bound; joint j at its queried limit is inside that bound). 0: the row at tn is
 * evaluated, as before. tn's value is the one hm_root evaluates next. */
static int hm_last(const HmCtx *c, int b, int qi, const HmRow *r, double f, double d, double tn,
                   double tp, double dp, int *in)
{
    int j = c->qj[qi], kind = c->qkind[qi];
    double s = tn - r->t, curv = fabs((d - dp) / (r->t - tp));
    if (!(fabs(f) <= HM_LAST_F && fabs(d) <= HM_LAST_SLOPE &&
          0.5 * curv * s * s <= HM_LAST_PRED))
        return 0;
    int good = 1;
    for (int m = 0; m < c->n; m++) {
        double q = r->q[b][m] + r->dq[b][m] * s, room = 2.0 * fabs(r->dq[b][m] * s) + 1e-12;
        double lo = q - (c->P[PK_LO + m] - MANIFOLD_SLACK);
        double hi = c->P[PK_HI + m] + MANIFOLD_SLACK - q;
        if (m == j && kind != HM_KIND_ALIGNED) {
            if (!(fabs(q - c->qv[qi]) <= 1e-13))
                return 0; /* at another turn of the value */
            if (kind == HM_KIND_LOWER) /* at its limit: inside it */
                lo = 1.0;
            else
                hi = 1.0;
        }
        if (!(fabs(lo) > room && fabs(hi) > room))
            return 0;
        good = good && lo > 0.0 && hi > 0.0;
    }
    *in = good;
    return 1;
}

static double hm_move(const HmCtx *c, int b, const HmRow *r0, const HmRow *r1);

/* The root of q_j(t) - value (query qi, slot b) in (a, e), fa, fe of opposite
 * signs (fa at a, continuous over the cell; da, de the slopes there, NaN where
 * not known): Newton with the slope from the root of the cell's cubic Hermite
 * model (the secant's where a slope is not known), Illinois regula falsi where
 * Newton leaves the bracket. */
static void hm_root(HmCtx *c, int b, int qi, double a, double fa, double e, double fe,
                    double da, double de)
{
    int j = c->qj[qi];
    if (c->flags || c->retry || hm_shared(c, b, qi, a, fa, e))
        return;
    double best_t = fabs(fa) < fabs(fe) ? a : e, best_f = fmin(fabs(fa), fabs(fe));
    double t = a - fa * (e - a) / (fe - fa);
    if (isfinite(da) && isfinite(de)) { /* the cell's model in its coordinate (hm_sigma) */
        double sa = hm_sigma(c, a), se = hm_sigma(c, e), h = se - sa;
        double tn = hm_of_sigma(c, sa + h * hm_hermite_root(fa, fe, da * hm_dtds(c, a) * h,
                                                             de * hm_dtds(c, e) * h));
        if (tn > a && tn < e)
            t = tn;
    }
    int side = 0, best_in = -1; /* best_in: the row at best_t inside (-1: not evaluated) */
    double tp = NAN, dp = NAN; /* the previous iterate and its slope (hm_last) */
    HmRow r;
    for (int it = 0; it < 80; it++) {
        hm_eval(c, t, 1u << b, 1u << b, &r);
        if (!r.valid[b]) {
            c->flags |= HM_FLAG_VANISH;
            return;
        }
        hm_seen(c, b, &r);
        /* f continuous from a: the turn of q_j nearest fa's */
        double f = fa + wrap_pi(hm_f(c, &r, b, qi) - fa), d = r.dq[b][j];
        if (fabs(f) < best_f) {
            best_f = fabs(f);
            best_t = t;
            best_in = hm_inside(c, &r, b, MANIFOLD_SLACK);
        }
        if (f == 0.0 || best_f <= 1e-14)
            break;
        /* the rounding floor (session 11): the joint within HM_FLOOR ulps of t's
         * motion of its value (its slope times one ulp of t), the root within a few
         * ulps of t; where the row's own rounding is about 1e-14 (q1, q3 next to an
         * aligned shoulder) the steps below it trade rounding for rounding (5-33 more
         * rows; 4.0 rows per pose fewer here, the crossings within 6e-15 in t) */
        if (best_f <= HM_TOL && fabs(f) <= HM_FLOOR * (nextafter(fabs(t), INFINITY) - fabs(t)) *
                                                 fabs(d))
            break;
        illinois_update(t, f, &a, &fa, &e, &fe, &side);
        if (!(e - a > 2.0 * DBL_EPSILON * fmax(fabs(a), fabs(e))))
            break;
        double tn = t - f / d;
        if (tn > a && tn < e && hm_last(c, b, qi, &r, f, d, tn, tp, dp, &best_in)) {
            best_t = tn; /* Newton's last step, its row not evaluated */
            best_f = 0.0;
            break;
        }
        tp = t;
        dp = d;
        if (!(tn > a && tn < e) || !isfinite(tn))
            tn = a - fa * (e - a) / (fe - fa);
        if (!(tn > a && tn < e))
            tn = 0.5 * (a + e);
        t = tn;
    }
    /* a crossing as steep as an aligned triple makes it (q1, q3 swinging) may end
     * with its bracket two adjacent floats: the value nearest the joint's there */
    int collapsed = !(e - a > 2.0 * DBL_EPSILON * fmax(fabs(a), fabs(e)));
    /* or narrower than one ulp of 1 where t ~ 1e-16..1e-13 (q7 = 0 with q2 = 0: the
     * swing's jump at an aligned point there needs more halvings than the loop's 80 to
     * reach adjacent doubles; session 22), trusted only on a pose without repaired rows
     * (hm_pose: a row a repair pinned at a limit there, special #1420 of seed 8) */
    if (!collapsed && !(best_f <= HM_TOL) &&
        !(e - a > 2.0 * DBL_EPSILON * fmax(1.0, fmax(fabs(a), fabs(e))))) {
        collapsed = 1;
        c->coarse = 1;
    }
    /* or, in a swing (hm_cell), the joint's move over the last bits of t (1e-7..3e-5
     * at slopes of 1e9..1e11: no double puts it nearer) */
    double last = HM_FLOOR * fabs(r.dq[b][j]) * (e - a);
    if (!(best_f <= HM_TOL) && !(collapsed && best_f <= fmax(HM_TOL_STEEP, last))) {
        if (collapsed && c->njump < HM_MAXJUMP) { /* a slot change, not a crossing? */
            HmRow ra, rb;
            hm_eval(c, a, 1u << b, 0xffu, &ra);
            hm_eval(c, e, 1u << b, 0xffu, &rb);
            int n0 = c->njump;
            if (ra.valid[b] && rb.valid[b] && hm_bisect_jump(c, b, &ra, &rb) && c->njump > n0) {
                c->retry = 1; /* a new one: the slot's pass is redone with it (hm_pose) */
                return;
            }
            /* a known one, or one next to a row of an exactly aligned shoulder (q2 = 0
             * within ~1e-12 of an aligned node: q1 and q3 split by the solver's rule,
             * no slope; session 21): a cut there, no point, as hm_split_jump makes */
            if (ra.valid[b] && rb.valid[b] && hm_move(c, b, &ra, &rb) > HM_SLOT_JUMP &&
                c->ncut[b] < HM_MAXCUT && hm_jump_cut(c, b, e))
                return;
        }
        c->flags |= HM_FLAG_CONVERGE;
    }
    int kind = c->qkind[qi];
    hm_point(c, best_t, b, j, kind);
    if (best_in >= 0)
        hm_at(c, b, best_t, best_in);
}

/* The extremum of q_j (slot b) in (a, e) where the slopes da, de have opposite
 * signs: Illinois regula falsi on the slope; its row into *out. */
static void hm_extremum(HmCtx *c, int b, int j, double a, double da, double e, double de,
                        HmRow *out)
{
    int side = 0;
    double t = 0.5 * (a + e), ta = a, te = e; /* a, e, t: the cell's coordinate (hm_sigma) */
    da *= hm_dtds(c, a);
    de *= hm_dtds(c, e);
    a = hm_sigma(c, a);
    e = hm_sigma(c, e);
    for (int it = 0; it < 60; it++) {
        t = a - da * (e - a) / (de - da);
        if (!(t > a && t < e))
            t = 0.5 * (a + e);
        double tt = hm_of_sigma(c, t);
        if (!(tt > ta && tt < te)) {
            tt = 0.5 * (ta + te);
            t = hm_sigma(c, tt);
        }
        hm_eval(c, tt, 1u << b, 1u << b, out);
        if (!out->valid[b]) {
            c->flags |= HM_FLAG_VANISH;
            return;
        }
        hm_seen(c, b, out);
        double d = out->dq[b][j] * hm_dtds(c, tt);
        if (!isfinite(d) || d == 0.0)
            return;
        illinois_update(t, d, &a, &da, &e, &de, &side);
        if (!(e - a > 1e-13 * fmax(1.0, fabs(t))))
            return;
    }
}

/* Whether the cubic Hermite model of f on [0, 1] (values f0, f1, slopes d0, d1 per
 * unit of the cell) takes the other sign of f0 inside (at an extremum). */
static int hm_hermite_dips(double f0, double f1, double d0, double d1)
{
    /* f(s) = f0 + d0 s + a s^2 + b s^3 */
    double a, b;
    hm_hermite_ab(f0, f1, d0, d1, &a, &b);
    double A = 3.0 * b, B = 2.0 * a, C = d0, s[2];
    int ns = 0;
    if (fabs(A) < 1e-300) {
        if (fabs(B) > 0.0)
            s[ns++] = -C / B;
    } else {
        double disc = B * B - 4.0 * A * C;
        if (disc >= 0.0) {
            double sq = sqrt(disc);
            s[ns++] = (-B + sq) / (2.0 * A);
            s[ns++] = (-B - sq) / (2.0 * A);
        }
    }
    for (int i = 0; i < ns; i++)
        if (s[i] > 0.0 && s[i] < 1.0) {
            double x = s[i], v = f0 + x * (d0 + x * (a + x * b));
            if ((v < 0) != (f0 < 0) || fabs(v) <= HM_TOL)
                return 1;
        }
    return 0;
}

/* Whether a cell wider than a margin cell (round 8b: rows at every HM_STRIDE-th
 * margin node) must be split for one query, its rows not excluding a crossing that
 * its cubic Hermite model (f0, f1, d0, d1 per unit of the cell) does not show: the
 * model's departure from its chord, |A| + |B| (f = f0 + d0 s + A s^2 + B s^3), is
 * the scale of what the rows leave unknown; split where it reaches the distance
 * that keeps the value away (no sign change: the model's nearest approach to the
 * value) or the chord's own motion (one crossing: a second extremum inside). */
static int hm_coarse_unsure(double f0, double f1, double d0, double d1)
{
    double A, B;
    hm_hermite_ab(f0, f1, d0, d1, &A, &B);
    double e = fabs(A) + fabs(B);
    if ((f0 < 0) != (f1 < 0))
        return e >= fabs(f1 - f0);
    double near = fmin(fabs(f0), fabs(f1));
    /* the model's extrema inside: f' = d0 + 2 A s + 3 B s^2 = 0 */
    double qa = 3.0 * B, qb = 2.0 * A, disc = qb * qb - 4.0 * qa * d0;
    if (fabs(qa) > 1e-300 && disc >= 0.0) {
        double sq = sqrt(disc);
        for (int i = 0; i < 2; i++) {
            double x = (-qb + (i ? sq : -sq)) / (2.0 * qa);
            if (x > 0.0 && x < 1.0)
                near = fmin(near, fabs(f0 + x * (d0 + x * (A + x * B))));
        }
    } else if (!(fabs(qa) > 1e-300) && fabs(qb) > 0.0) {
        double x = -d0 / qb;
        if (x > 0.0 && x < 1.0)
            near = fmin(near, fabs(f0 + x * (d0 + x * A)));
    }
    return e >= near;
}

/* 1 / |dq/dt|^2 of slot b's row (0 where a slope is not finite) */
static double hm_gap(const HmCtx *c, int b, const HmRow *r)
{
    double s = 0.0;
    for (int j = 0; j < c->n; j++)
        s += r->dq[b][j] * r->dq[b][j];
    return isfinite(s) ? 1.0 / s : 0.0;
}

/* Whether a cell [r0, r1] of slot b must be split: a joint moving more than
 * HM_JUMP, a slope missing, or a query's sign change that its end slopes do not
 * explain as one monotone crossing, or whose Hermite model dips across. dj: each
 * joint's move over the cell (wrap_pi(q1 - q0)), fq: each query's q_j - value at
 * r0 (hm_f), as hm_moves computes them once for both (the same values). aligned_only:
 * the aligned-axes queries only (a dead cell, hm_dead: its limit queries need none). */
static int hm_needs_split(const HmCtx *c, int b, const HmRow *r0, const HmRow *r1,
                          const double *dj, const double *fq, int aligned_only)
{
    double h = r1->t - r0->t, big = 0.0;
    int coarse = h > 1.5 * c->hfine; /* wider than a margin cell (round 8b) */
    /* the end slopes per unit of the cell in its coordinate (hm_sigma) */
    double hs = hm_sigma(c, r1->t) - hm_sigma(c, r0->t);
    double m0 = hm_dtds(c, r0->t) * hs, m1 = hm_dtds(c, r1->t) * hs;
    for (int j = 0; j < c->n; j++) /* (fmax's value: dj is finite, rows at both ends) */
        big = fabs(dj[j]) > big ? fabs(dj[j]) : big;
    if (h < 1e-9 && big < 1e-6)
        return 0; /* at a branch end (its rows within rounding of the double root) */
    for (int j = 0; j < c->n; j++) {
        if (fabs(dj[j]) > HM_JUMP)
            return 1;
        if (!isfinite(r0->dq[b][j]) || !isfinite(r1->dq[b][j]))
            return 1;
    }
    for (int qi = 0; qi < c->nq; qi++) {
        if (aligned_only && c->qkind[qi] != HM_KIND_ALIGNED)
            continue;
        int j = c->qj[qi];
        double f0 = fq[qi], f1 = f0 + dj[j];
        double d0 = r0->dq[b][j] * m0, d1 = r1->dq[b][j] * m1;
        if (fabs(f0) > 3.0 || fabs(f1) > 3.0)
            continue; /* the value's far turn: nothing near */
        if (c->deep_cell && c->qkind[qi] == HM_KIND_ALIGNED && (f0 < 0) == (f1 < 0))
            continue; /* a swing's centre: q2 ~ 1e-13 within HM_TOL of 0 (hm_cell) */
        if ((f0 < 0) == (f1 < 0)) {
            /* round 8b, no sqrt: the Hermite cubic is h00 f0 + h01 f1 (between f0 and
             * f1) plus d0 h10 + d1 h11 with |h10|, |h11| <= 4/27 on the cell, so it stays
             * `far` from the value; when that exceeds the tests' thresholds (with room for
             * their rounding) neither hm_hermite_dips nor hm_coarse_unsure can split */
            double a0 = fabs(f0), a1 = fabs(f1); /* (fmin's value: both finite) */
            double far = (a1 < a0 ? a1 : a0) - HM_H4_27 * (fabs(d0) + fabs(d1)) -
                         1e-13 * (fabs(f0) + fabs(f1) + fabs(d0) + fabs(d1));
            double A, B;
            hm_hermite_ab(f0, f1, d0, d1, &A, &B);
            if (far > 2.0 * HM_TOL && !(HM_UNSURE && coarse && !(far > fabs(A) + fabs(B))))
                continue;
        }
        if ((f0 < 0) != (f1 < 0)) {
            if ((d0 < 0) != (d1 < 0) || (d0 < 0) != (f1 < f0))
                return 1; /* more than one crossing may lie inside */
        } else if ((d0 < 0) == (d1 < 0) && hm_hermite_dips(f0, f1, d0, d1)) {
            return 1;
        }
        if (HM_UNSURE && coarse && hm_coarse_unsure(f0, f1, d0, d1))
            return 1;
    }
    return 0;
}

static void hm_cell(HmCtx *c, int b, const HmRow *r0, const HmRow *r1, int depth);

/* Whether slot b is outside a joint's limits over the whole cell [r0, r1] (a dead
 * cell: no crossing in it bounds an interval; session 24). Its premises are
 * hm_needs_split's: every joint moving less than HM_JUMP with finite slopes at both
 * ends. Then a joint whose cubic Hermite model (values and slopes at the ends, per
 * unit of the cell in its coordinate) stays, with every whole turn of it, away from
 * its limits by more than the model's departure from its chord (hm_coarse_unsure's
 * scale of what the rows leave unknown), 2 HM_TOL and MANIFOLD_SLACK: the model lies
 * within its chord's range +- 4/27 (|d0| + |d1|) (the Hermite basis: h00 + h01 = 1,
 * |h10|, |h11| <= 4/27). Per joint and modulo 2 pi, not per wrapped query: a row at
 * a limit to rounding can stay a whole turn off it (q6 = 3.7525 - 2 pi on the Panda,
 * q + 2 pi rounding above the limit). A build with -DHM_NO_DEAD has no dead cells
 * (the A/B measurement of session 24). */
static int hm_dead(const HmCtx *c, int b, const HmRow *r0, const HmRow *r1, const double *dj)
{
#ifdef HM_NO_DEAD
    return 0;
#endif
    for (int j = 0; j < c->n; j++)
        if (!(fabs(dj[j]) <= HM_JUMP) || !isfinite(r0->dq[b][j]) || !isfinite(r1->dq[b][j]))
            return 0;
    double hs = hm_sigma(c, r1->t) - hm_sigma(c, r0->t);
    double m0 = hm_dtds(c, r0->t) * hs, m1 = hm_dtds(c, r1->t) * hs;
    for (int j = 0; j < c->n; j++) {
        double lo = c->P[PK_LO + j], hi = c->P[PK_HI + j], q0 = r0->q[b][j], f1 = dj[j];
        double d0 = r0->dq[b][j] * m0, d1 = r1->dq[b][j] * m1;
        double A, B;
        hm_hermite_ab(0.0, f1, d0, d1, &A, &B);
        double pad = fmax(2.0 * HM_TOL, fabs(A) + fabs(B)) + MANIFOLD_SLACK +
                     1e-13 * (fabs(q0) + fabs(f1) + fabs(d0) + fabs(d1));
        double spread = HM_H4_27 * (fabs(d0) + fabs(d1)) + pad;
        double a = q0 + fmin(0.0, f1) - spread, e = q0 + fmax(0.0, f1) + spread;
        if (!(e - a < 2.0 * M_PI - (hi - lo)))
            continue;
        int meets = 0;
        for (int k = -2; k <= 2 && !meets; k++)
            meets = a + 2.0 * M_PI * k <= hi && e + 2.0 * M_PI * k >= lo;
        if (!meets)
            return 1;
    }
    return 0;
}

/* The zeros of queries exactly at a node (a generating configuration at a limit) */
static void hm_node(HmCtx *c, int b, const HmRow *r)
{
    for (int qi = 0; qi < c->nq; qi++)
        if (fabs(hm_f(c, r, b, qi)) <= HM_TOL) {
            hm_point(c, r->t, b, c->qj[qi], c->qkind[qi]);
            hm_at(c, b, r->t, hm_inside(c, r, b, MANIFOLD_SLACK));
        }
}

/* Joint j of configuration q (n) polished against the pose T: one Newton step whose
 * pose residual is computed in long double (the six other joints' Jacobian in
 * double). pk_one's rows are exact to ~1e-14 only, too coarse where a branch grazes
 * a limit: its in-limit stretch is 2 sqrt(excess / curvature) wide, and 7e-15 of
 * rounding in the excess moved its ends by 1.4e-7 (issue 29's slivers). */
static double hm_polished(const HmCtx *c, const double *q, int j)
{
    const double *P = c->P, *T = c->T;
    long double A[3][3] = {{1.0L, 0.0L, 0.0L}, {0.0L, 1.0L, 0.0L}, {0.0L, 0.0L, 1.0L}};
    long double t[3] = {0.0L, 0.0L, 0.0L}, hc[PK_MAXJ][3], oc[PK_MAXJ][3];
    for (int i = 0; i < c->n; i++) {
        const double *h = P + PK_AXES + 3 * i, *o = P + PK_POINTS + 3 * i;
        long double th = (long double)P[PK_SIGN + i] * q[i] + P[PK_OFFSET + i];
        long double cs = cosl(th), sn = sinl(th), v = 1.0L - cs, R[3][3], Ro[3], An[3][3];
        for (int r = 0; r < 3; r++)
            for (int m = 0; m < 3; m++)
                R[r][m] = (long double)h[r] * h[m] * v + (r == m ? cs : 0.0L);
        R[0][1] -= h[2] * sn, R[0][2] += h[1] * sn, R[1][0] += h[2] * sn;
        R[1][2] -= h[0] * sn, R[2][0] -= h[1] * sn, R[2][1] += h[0] * sn;
        for (int r = 0; r < 3; r++) {
            Ro[r] = o[r] - (R[r][0] * o[0] + R[r][1] * o[1] + R[r][2] * o[2]);
            hc[i][r] = A[r][0] * h[0] + A[r][1] * h[1] + A[r][2] * h[2];
            oc[i][r] = A[r][0] * o[0] + A[r][1] * o[1] + A[r][2] * o[2] + t[r];
        }
        for (int r = 0; r < 3; r++) {
            t[r] += A[r][0] * Ro[0] + A[r][1] * Ro[1] + A[r][2] * Ro[2];
            for (int m = 0; m < 3; m++)
                An[r][m] = A[r][0] * R[0][m] + A[r][1] * R[1][m] + A[r][2] * R[2][m];
        }
        memcpy(A, An, sizeof(A));
    }
    /* the pose A M + t against T: position error and the small rotation w with
     * R_T = exp([w]) R (the skew part of R_T R^T) */
    long double R[3][3], p[3], E[3][3];
    const double *RM = P + PK_TOOL_R, *tM = P + PK_TOOL_T;
    for (int r = 0; r < 3; r++) {
        p[r] = A[r][0] * tM[0] + A[r][1] * tM[1] + A[r][2] * tM[2] + t[r];
        for (int m = 0; m < 3; m++)
            R[r][m] = A[r][0] * RM[m] + A[r][1] * RM[3 + m] + A[r][2] * RM[6 + m];
    }
    for (int r = 0; r < 3; r++)
        for (int m = 0; m < 3; m++)
            E[r][m] = T[4 * r] * R[m][0] + T[4 * r + 1] * R[m][1] + T[4 * r + 2] * R[m][2];
    double scale = P[PK_SCALE], rhs[6] = {
        (double)((T[3] - p[0]) / scale), (double)((T[7] - p[1]) / scale),
        (double)((T[11] - p[2]) / scale), (double)(0.5L * (E[2][1] - E[1][2])),
        (double)(0.5L * (E[0][2] - E[2][0])), (double)(0.5L * (E[1][0] - E[0][1]))};
    double M[6][7], x[6];
    int col[6], m = 0;
    for (int i = 0; i < c->n && m < 6; i++)
        if (i != c->k)
            col[m++] = i;
    for (int i = 0; i < 6; i++) {
        int a = col[i];
        long double d[3] = {p[0] - oc[a][0], p[1] - oc[a][1], p[2] - oc[a][2]};
        double sg = P[PK_SIGN + a];
        M[0][i] = (double)((hc[a][1] * d[2] - hc[a][2] * d[1]) * sg / scale);
        M[1][i] = (double)((hc[a][2] * d[0] - hc[a][0] * d[2]) * sg / scale);
        M[2][i] = (double)((hc[a][0] * d[1] - hc[a][1] * d[0]) * sg / scale);
        for (int r = 0; r < 3; r++)
            M[3 + r][i] = (double)(hc[a][r] * sg);
    }
    for (int r = 0; r < 6; r++)
        M[r][6] = rhs[r];
    if (j == c->k || !hm_solve6(M, x))
        return q[j];
    for (int i = 0; i < 6; i++)
        if (col[i] == j)
            return q[j] + x[i];
    return q[j];
}

/* The t between an extremum tm and a cell end te where joint j of slot b is at v
 * (q_j - v is fm at tm, of the other sign at te, where its slope is de): Newton on
 * the polished joint from the parabola's estimate (curvature |de| / 2|te - tm|),
 * safeguarded by bisection of the bracket. */
static double hm_graze_root(HmCtx *c, int b, int j, double v, double tm, double fm, double te,
                            double de)
{
    double a = tm, e = te, kappa = fabs(de) / (2.0 * fabs(te - tm));
    double t = tm + copysign(sqrt(fabs(fm) / kappa), te - tm), best = t, best_f = HUGE_VAL;
    HmRow r;
    for (int it = 0; it < 60; it++) {
        if (!((t - a) * (t - e) < 0.0) || !isfinite(t))
            t = 0.5 * (a + e);
        hm_eval(c, t, 1u << b, 1u << b, &r);
        if (!r.valid[b]) {
            c->flags |= HM_FLAG_VANISH;
            return best;
        }
        double f = wrap_pi(hm_polished(c, r.q[b], j) - v), step = f / r.dq[b][j];
        if (fabs(f) < best_f) {
            best_f = fabs(f);
            best = t;
        }
        if (f == 0.0)
            break;
        if ((f < 0) == (fm < 0))
            a = t;
        else
            e = t;
        if (!(fabs(a - e) > 2.0 * DBL_EPSILON * fabs(t)) || fabs(step) <= DBL_EPSILON * fabs(t))
            break;
        t -= step;
    }
    if (!(best_f <= HM_TOL))
        c->flags |= HM_FLAG_CONVERGE;
    return best;
}

/* An extremum m of joint j (query qi, slot b) within HM_TOL of a limit, reached
 * from outside: a branch grazing the limit. Inside is taken with the slack every
 * membership test has (HM_TOL, as hm_inside's [t, t] and SelfMotion.inside): the
 * branch is inside where the polished joint (hm_polished: the double row is only
 * exact to ~1e-14) is within HM_TOL of its limit, a stretch of 2 sqrt((excess +
 * HM_TOL) / curvature) in t, whose two ends are crossings (points, cuts) and which
 * hm_intervals decides with the same slack. The stretch's width is then set by
 * the slack, not by rounding (at the limit itself it would be 2 sqrt(excess /
 * curvature): 3.7e-7 from an excess of 6.5e-15 that the model's own rounding
 * moves). A dip from inside by less than HM_TOL is not a gap, as before; an
 * aligned-axes value touched is one point. */
static void hm_graze(HmCtx *c, int b, int qi, const HmRow *r0, const HmRow *m, const HmRow *r1)
{
    int j = c->qj[qi], g = c->ngraze[b], kind = c->qkind[qi];
    double in = kind == HM_KIND_LOWER ? 1.0 : -1.0; /* the inside's sign of q_j - limit */
    double v = c->qv[qi] - in * MANIFOLD_SLACK, f0 = hm_f(c, r0, b, qi);
    double fm = wrap_pi(hm_polished(c, m->q[b], j) - v);
    if (kind == HM_KIND_ALIGNED || f0 * in > 0.0 || !(fm * in > 0.0) || g >= HM_MAXG) {
        hm_point(c, m->t, b, j, kind);
        return;
    }
    double lo = hm_graze_root(c, b, j, v, m->t, fm, r0->t, r0->dq[b][j]);
    double hi = hm_graze_root(c, b, j, v, m->t, fm, r1->t, r1->dq[b][j]);
    hm_point(c, lo, b, j, kind);
    hm_point(c, hi, b, j, kind);
    c->graze_t[b][g][0] = lo;
    c->graze_t[b][g][1] = hi;
    c->graze_j[b][g] = j;
    c->ngraze[b]++;
}

/* The largest 2 pi wrapped move of a joint of slot b between rows r0 and r1 */
static double hm_move(const HmCtx *c, int b, const HmRow *r0, const HmRow *r1)
{
    double big = 0.0;
    for (int j = 0; j < c->n; j++)
        big = fmax(big, fabs(wrap_pi(r1->q[b][j] - r0->q[b][j])));
    return big;
}

/* A cell of slot b still to be split at HM_DEPTH: where the held closed form numbers
 * its rows differently on either side of a value (the Gen3-like arm with joint_3 held
 * at ~ +-2.9e-13 and +-(pi - 2.9e-13): the solver's case changes there, its slots
 * permuted), slot b is another branch on each side. The largest move is bisected to
 * adjacent doubles (ta, tb); when slot b's row still moves by more than HM_SLOT_JUMP
 * there (a continuous branch moves by its slope times one ulp: 4e-7 at a slope of
 * 1e9, next to an aligned triple) and exists on both sides, tb is a cut of slot b
 * (never a one-point interval: hm_at marks its row not inside) and the two sides are
 * cells of their own. 0 (nothing done) when the move is continuous at the last bit
 * or a row is missing. A change found before (by another slot: the solver's case
 * changes at one value for every slot) is taken where the slot jumps there too
 * (hm_known_jump, at every cell before its split test: one bisection per pose and
 * value, not per slot); a change inside a cell that needs no split (its end rows
 * look like one crossing: q4 mirrored) shows as a crossing whose bracket collapses
 * on a jump (hm_root): it is recorded and the slot's pass redone (hm_pose). */
/* Bisects slot b's largest move between rows *ra < *rb (slopes of b in both) down to
 * adjacent doubles; 1 when the slot's row still moves by more than HM_SLOT_JUMP there
 * (a slot change; recorded in jump_t for the other slots), 0 when it is continuous at
 * the last bit or a row is missing. The steps evaluate slot b alone and without
 * slopes (its row is a function of t and b: the same row as with every slot); the
 * two rows it ends on are evaluated again with slot b's slope (session 10: the
 * steps' 8 slots and slopes took the Gen3-like kernel from 0.88 to 1.23 ms per
 * uniform pose, baseline ISA). */
static int hm_bisect_jump(HmCtx *c, int b, HmRow *ra, HmRow *rb)
{
    HmRow m;
    double t0 = ra->t, t1 = rb->t;
    for (int it = 0; it < 80; it++) {
        double mid = 0.5 * (ra->t + rb->t);
        if (!(mid > ra->t && mid < rb->t))
            break;
        hm_eval(c, mid, 0u, 1u << b, &m);
        if (!m.valid[b])
            return 0;
        if (hm_move(c, b, ra, &m) >= hm_move(c, b, &m, rb))
            *rb = m;
        else
            *ra = m;
    }
    if (!(nextafter(ra->t, rb->t) == rb->t) || !(hm_move(c, b, ra, rb) > HM_SLOT_JUMP))
        return 0;
    if (ra->t != t0)
        hm_eval(c, ra->t, 1u << b, 1u << b, ra);
    if (rb->t != t1)
        hm_eval(c, rb->t, 1u << b, 1u << b, rb);
    if (!isfinite(ra->dq[b][0]) || !isfinite(rb->dq[b][0]))
        return 0;
    int known = 0;
    for (int k = 0; k < c->njump && !known; k++)
        known = c->jump_t[k][1] == rb->t;
    if (!known && c->njump < HM_MAXJUMP) {
        c->jump_t[c->njump][0] = ra->t;
        c->jump_t[c->njump++][1] = rb->t;
    }
    return 1;
}

/* Slot b's cell [r0, r1] with a slot change between its rows ra, rb (adjacent doubles
 * inside it): tb is a cut (no point; hm_at: not a one-point interval), the two sides
 * are cells of their own. 0 (nothing done) when slot b does not jump there. */
static int hm_split_jump(HmCtx *c, int b, const HmRow *r0, const HmRow *r1, const HmRow *ra,
                         const HmRow *rb, int depth)
{
    if (!ra->valid[b] || !rb->valid[b] || !(nextafter(ra->t, rb->t) == rb->t) ||
        !(hm_move(c, b, ra, rb) > HM_SLOT_JUMP) || !isfinite(ra->dq[b][0]) ||
        !isfinite(rb->dq[b][0]))
        return 0;
    if (!hm_jump_cut(c, b, rb->t))
        return 1;
    hm_seen(c, b, ra);
    hm_seen(c, b, rb);
    hm_node(c, b, ra);
    hm_node(c, b, rb);
    hm_cell(c, b, r0, ra, depth);
    hm_cell(c, b, rb, r1, depth);
    return 1;
}

/* A slot change another slot (or an earlier pass) found strictly inside the cell
 * [r0, r1] where slot b jumps too: the cell split there (hm_split_jump); 1 when done. */
static int hm_known_jump(HmCtx *c, int b, const HmRow *r0, const HmRow *r1, int depth)
{
    HmRow ra, rb;
    for (int k = 0; k < c->njump; k++) {
        double ta = c->jump_t[k][0], tb = c->jump_t[k][1];
        if (!(ta >= r0->t && tb <= r1->t) || (ta == r0->t && tb == r1->t))
            continue;
        hm_eval(c, ta, 1u << b, 0xffu, &ra);
        hm_eval(c, tb, 1u << b, 0xffu, &rb);
        if (hm_split_jump(c, b, r0, r1, &ra, &rb, depth))
            return 1;
    }
    return 0;
}

static int hm_jump(HmCtx *c, int b, const HmRow *r0, const HmRow *r1, int depth)
{
    HmRow ra = *r0, rb = *r1;
    return hm_bisect_jump(c, b, &ra, &rb) && hm_split_jump(c, b, r0, r1, &ra, &rb, depth);
}

/* Slot b's cell [r0, r1]: each joint's move dj (wrap_pi(q1 - q0)) and each query's
 * q_j - value at r0 (fq, hm_f), as hm_needs_split and the crossings take them */
static void hm_moves(const HmCtx *c, int b, const HmRow *r0, const HmRow *r1, double *dj,
                     double *fq)
{
    for (int j = 0; j < c->n; j++)
        dj[j] = wrap_pi(r1->q[b][j] - r0->q[b][j]);
    for (int qi = 0; qi < c->nq; qi++)
        fq[qi] = hm_f(c, r0, b, qi);
}

/* Slot b's row at t, the midpoint of its cell [r0, r1] that hm_cell splits, with b's
 * slope. The partner slot p = b ^ 1 (the same q4 - q6; its shoulder the other
 * triple: the two swing together next to an aligned shoulder) has its pass right
 * after b's: where b is the first of the pair and p's rows at r0 and r1 exist with
 * their slopes and need the split too (hm_needs_split on p's cell: p's pass splits
 * the same cell at the same t), both are evaluated together and kept
 * (hm_eval_pair), and p's pass takes its row from there (hm_pair_find): one front
 * and triple for both (session 13: ~25 such rows per Panda pose, half of hm_cell's;
 * the same rows, each a function of t and its slot). */
static void hm_split_row(HmCtx *c, int b, double t, const HmRow *r0, const HmRow *r1,
                         HmRow *m)
{
    int p = b ^ 1;
    if (hm_pair_find(c, t, b, 1, m))
        return;
    if (!(b & 1) && r0->valid[p] && r1->valid[p] && (r0->sloped & r1->sloped) >> p & 1u) {
        double dj[PK_MAXJ], fq[HM_MAXQ];
        hm_moves(c, p, r0, r1, dj, fq);
        if (hm_needs_split(c, p, r0, r1, dj, fq, hm_dead(c, p, r0, r1, dj))) {
            hm_eval_pair(c, t, b, 1, m);
            return;
        }
    }
    hm_eval(c, t, 1u << b, 1u << b, m);
}

/* Slot b's last row from *ra towards t, where its row is missing: bisection to
 * adjacent doubles; that row (with b's slope) into *ra */
static void hm_last_valid(HmCtx *c, int b, HmRow *ra, double t)
{
    double good = ra->t, bad = t;
    HmRow m;
    for (int it = 0; it < 80; it++) {
        double mid = 0.5 * (good + bad);
        if (mid == good || mid == bad)
            break;
        hm_eval(c, mid, 0u, 1u << b, &m);
        if (m.valid[b])
            good = mid;
        else
            bad = mid;
    }
    if (good != ra->t)
        hm_eval(c, good, 1u << b, 1u << b, ra);
}

/* A swing's cell [r0, r1] of slot b whose midpoint has no row (the odd slot where the
 * shoulder is aligned to ~1e-13: the closed form gives the pair one row): the gap
 * between b's last rows on either side (~1e-13 of t) is outside, each end a cut, the
 * sides cells of their own. 0 (nothing done) when those rows are not regular. */
static int hm_swing_gap(HmCtx *c, int b, const HmRow *r0, const HmRow *r1, double t,
                        int depth)
{
    HmRow ra = *r0, rb = *r1;
    hm_last_valid(c, b, &ra, t);
    hm_last_valid(c, b, &rb, t);
    if (!ra.valid[b] || !rb.valid[b] || !isfinite(ra.dq[b][0]) || !isfinite(rb.dq[b][0]))
        return 0;
    if (c->ncut[b] + 2 > HM_MAXCUT) {
        c->flags |= HM_FLAG_FULL;
        return 1;
    }
    c->cut[b][c->ncut[b]++] = ra.t;
    c->cut[b][c->ncut[b]++] = rb.t;
    c->jumped = 1;
    hm_at(c, b, ra.t, hm_inside(c, &ra, b, MANIFOLD_SLACK));
    hm_at(c, b, rb.t, hm_inside(c, &rb, b, MANIFOLD_SLACK));
    hm_seen(c, b, &ra);
    hm_seen(c, b, &rb);
    hm_node(c, b, &ra);
    hm_node(c, b, &rb);
    if (ra.t > r0->t)
        hm_cell(c, b, r0, &ra, depth);
    if (rb.t < r1->t)
        hm_cell(c, b, &rb, r1, depth);
    return 1;
}

/* Whether slot b's cell [r0, r1], still to be split at HM_DEPTH (or past it) and no
 * slot change, is split on: 0 with *resolved set when only a touch of an aligned-axes
 * value asked for the split (the swing's centre: q2 within HM_TOL of 0, an aligned
 * point, as a graze records it); 1 when it is a swing (HM_SWING: hm_cell splits it
 * within HM_DEEP and HM_DEEP_ROWS, or cuts it at its centre); else 0 with *resolved
 * 0 (the pose is flagged: e.g. a joint riding its limit to ~1e-14, which splitting on
 * does not decide). */
static int hm_swing(HmCtx *c, int b, const HmRow *r0, const HmRow *r1, const double *dj,
                    const double *fq, int *resolved)
{
    c->deep_cell = 1;
    int still = hm_needs_split(c, b, r0, r1, dj, fq, hm_dead(c, b, r0, r1, dj));
    c->deep_cell = 0;
    if (!still) {
        *resolved = 1;
        return 0;
    }
    int near = 0;
    for (int qi = 0; qi < c->nq; qi++)
        if (c->qkind[qi] == HM_KIND_ALIGNED &&
            fmin(fabs(fq[qi]), fabs(fq[qi] + dj[c->qj[qi]])) < HM_SWING_NEAR)
            near = 1;
    if (!near)
        return 0;
    double steep = 0.0; /* the largest end slope (a singular end: infinite) */
    for (int j = 0; j < c->n; j++) {
        double s0 = fabs(r0->dq[b][j]), s1 = fabs(r1->dq[b][j]);
        steep = fmax(steep, fmax(isfinite(s0) ? s0 : HUGE_VAL, isfinite(s1) ? s1 : HUGE_VAL));
    }
    return hm_move(c, b, r0, r1) > HM_SWING || steep * (r1->t - r0->t) > HM_SWING;
}

static void hm_cell(HmCtx *c, int b, const HmRow *r0, const HmRow *r1, int depth)
{
    if (c->flags || c->retry)
        return; /* flagged: the caller discards the pose; retry: the slot is redone (hm_pose) */
    if (c->njump && hm_known_jump(c, b, r0, r1, depth))
        return;
    double dj[PK_MAXJ], fq[HM_MAXQ];
    hm_moves(c, b, r0, r1, dj, fq);
    int dead = hm_dead(c, b, r0, r1, dj); /* then split for its aligned values only */
    if (hm_needs_split(c, b, r0, r1, dj, fq, dead)) {
        int resolved = 0, swing = 0;
        if (depth == HM_DEPTH && hm_jump(c, b, r0, r1, depth))
            return;
        if (depth >= HM_DEPTH && !c->flags && !c->retry)
            swing = hm_swing(c, b, r0, r1, dj, fq, &resolved);
        if (swing && nextafter(r0->t, r1->t) == r1->t) {
            hm_jump_cut(c, b, r1->t); /* the swing's centre between adjacent doubles */
            return;
        }
        if (depth < HM_DEPTH || (swing && depth < HM_DEEP && c->deep++ < HM_DEEP_ROWS)) {
            HmRow m;
            double mid = 0.5 * (r0->t + r1->t);
            if (!isnan(c->sq_te)) { /* the coordinate's midpoint (hm_sigma) */
                double sm = hm_of_sigma(c, 0.5 * (hm_sigma(c, r0->t) + hm_sigma(c, r1->t)));
                mid = sm > r0->t && sm < r1->t ? sm : mid;
            }
            hm_split_row(c, b, mid, r0, r1, &m);
            if (!m.valid[b] && depth >= HM_DEPTH && hm_swing_gap(c, b, r0, r1, mid, depth + 1))
                return;
            if (!m.valid[b]) {
                c->flags |= HM_FLAG_VANISH;
                return;
            }
            hm_seen(c, b, &m);
            hm_node(c, b, &m);
            hm_cell(c, b, r0, &m, depth + 1);
            hm_cell(c, b, &m, r1, depth + 1);
            return;
        }
        if (!resolved)
            c->flags |= HM_FLAG_UNRESOLVED;
    }
    /* a dead cell's limit crossings bound no interval (the piece they lie in is outside:
     * hm_intervals decides it so from any row in it); its aligned points are still
     * located (an aligned pair's continuum can bring a joint outside back in) */
    double hs = hm_sigma(c, r1->t) - hm_sigma(c, r0->t);
    double m0 = hm_dtds(c, r0->t) * hs, m1 = hm_dtds(c, r1->t) * hs; /* per unit of the cell */
    for (int qi = 0; qi < c->nq && !c->flags; qi++) {
        if (dead && c->qkind[qi] != HM_KIND_ALIGNED)
            continue;
        int j = c->qj[qi];
        double f0 = fq[qi], f1 = f0 + dj[j];
        double d0 = r0->dq[b][j], d1 = r1->dq[b][j];
        if (fabs(f0) > 3.0)
            continue; /* the far turn */
        int z0 = fabs(f0) <= HM_TOL, z1 = fabs(f1) <= HM_TOL;
        if (z0 || z1) {
            /* a node's zero (hm_node records it); when f leaves it into the cell on
             * the side away from the other end's value, it comes back through the
             * value inside: that crossing lies past f's extremum (session 20: q4 at
             * its limit at the range's end, t = q7's limit, then out for 0.023 of t:
             * its way back in was not found and the branch was inside over it) */
            double s = z0 ? d0 : -d1, fo = z0 ? f1 : f0;
            if (z0 == z1 || !(isfinite(s) && s != 0.0) || (s > 0) == (fo > 0))
                continue;
            if ((d0 < 0) == (d1 < 0)) {
                c->flags |= HM_FLAG_UNRESOLVED; /* two extrema: not this cell's model */
                continue;
            }
            HmRow m;
            hm_extremum(c, b, j, r0->t, d0, r1->t, d1, &m);
            if (!m.valid[b])
                continue; /* (hm_extremum flagged the pose) */
            double fm = f0 + wrap_pi(m.q[b][j] - r0->q[b][j]);
            if (fabs(fm) <= HM_TOL || (fm > 0) != (s > 0))
                continue; /* the extremum on the zero's side of the value: no return */
            if (z0)
                hm_root(c, b, qi, m.t, fm, r1->t, f1, m.dq[b][j], d1);
            else
                hm_root(c, b, qi, r0->t, f0, m.t, fm, d0, m.dq[b][j]);
            continue;
        }
        if ((f0 < 0) != (f1 < 0)) {
            hm_root(c, b, qi, r0->t, f0, r1->t, f1, d0, d1);
            continue;
        }
        if ((d0 < 0) == (d1 < 0) || (f0 > 0) != (d0 < 0))
            continue; /* monotone, or moving away from the value first */
        if (fmin(fabs(f0), fabs(f1)) > fmax(fabs(d0 * m0), fabs(d1 * m1)))
            continue; /* cannot reach it with the slopes seen (splits bound them) */
        HmRow m;
        hm_extremum(c, b, j, r0->t, d0, r1->t, d1, &m);
        if (!m.valid[b])
            continue;
        double fm = f0 + wrap_pi(m.q[b][j] - r0->q[b][j]);
        if (fabs(fm) <= HM_TOL) {
            hm_graze(c, b, qi, r0, &m, r1); /* touches the value, or grazes a limit */
        } else if ((fm < 0) != (f0 < 0)) {
            hm_root(c, b, qi, r0->t, f0, m.t, fm, d0, m.dq[b][j]);
            hm_root(c, b, qi, m.t, fm, r1->t, f1, m.dq[b][j], d1);
        }
    }
}

/* The piece between a branch end (row re, slope infinite there: q - q_end grows
 * as the square root of the distance) and the grid row rn. sigma (re a branch end
 * that hm_fold located): one row at 4^-HM_FOLD_STEPS of the piece from the end, and
 * the cell from it to rn as any other but in sigma = sign(t - te) sqrt|t - te|
 * (hm_sigma: the rows are smooth in it; its cubic Hermite models and midpoints;
 * session 11: rows per pose in these pieces 65 -> 10, the splits they need +2);
 * else (re a grid node next to a branch end, hm_pose's HM_NEAR test, or a steep
 * swing there: q1, q3 at an aligned shoulder) rows at distances 4^-k (k = 1 ..
 * HM_FOLD_STEPS) of the piece from the end, even in that square root, and the cells
 * between them in t. The cell at the end by its sign changes alone (regula falsi
 * needs no slope). */
static void hm_fold_piece(HmCtx *c, int b, const HmRow *re, const HmRow *rn, int sigma)
{
    if (c->flags)
        return;
    HmRow r[HM_FOLD_STEPS + 1];
    int m = 0;
    double w = rn->t - re->t, tol = HM_FOLD_TOL * fmax(1.0, fabs(re->t));
    int kmin = sigma ? HM_FOLD_STEPS : 1;
    for (int k = HM_FOLD_STEPS; k >= kmin; k--) {
        double t = re->t + w * ldexp(1.0, -2 * k);
        hm_eval_pair(c, t, b, 1, &r[m]);
        if (!r[m].valid[b]) {
            if (m == 0 && k > 1 && fabs(t - re->t) <= tol) {
                /* no row yet within the end's own tolerance (the rows' rounding puts
                 * the end a little further on, e.g. without FMA): the first row
                 * further from it */
                kmin = k - 1 < kmin ? k - 1 : kmin;
                continue;
            }
            c->flags |= HM_FLAG_VANISH;
            return;
        }
        hm_seen(c, b, &r[m]);
        hm_node(c, b, &r[m]);
        m++;
    }
    /* ordered from the end: re, r[0], ..., r[m - 1], rn (w may be negative) */
    const HmRow *first = &r[0];
    for (int qi = 0; qi < c->nq; qi++) {
        int j = c->qj[qi];
        double f0 = hm_f(c, re, b, qi), f1 = f0 + wrap_pi(first->q[b][j] - re->q[b][j]);
        if (fabs(f0) <= HM_TOL || fabs(f1) <= HM_TOL || fabs(f0) > 3.0)
            continue;
        if ((f0 < 0) != (f1 < 0)) {
            if (w > 0)
                hm_root(c, b, qi, re->t, f0, first->t, f1, NAN, NAN);
            else
                hm_root(c, b, qi, first->t, f1, re->t, f0, NAN, NAN);
        }
    }
    c->sq_te = sigma ? re->t : NAN; /* the cells in sigma (hm_sigma) */
    for (int i = 0; i + 1 <= m; i++) {
        const HmRow *x = &r[i], *y = i + 1 < m ? &r[i + 1] : rn;
        if (w > 0)
            hm_cell(c, b, x, y, 0);
        else
            hm_cell(c, b, y, x, 0);
    }
    c->sq_te = NAN;
}

static int hm_margins_d(HmCtx *c, double x, double *m, double *d);

/* hm_margin_root's function: the discriminant of subproblem k minus off at x */
typedef struct {
    HmCtx *c;
    int k;
    double off;
} HmMarginArg;

static double hm_margin_at(void *arg, double x)
{
    HmMarginArg *m = arg;
    double mv[3], dk[3];
    hm_margins_d(m->c, x, mv, dk);
    return dk[m->k] - m->off;
}

/* The t in (a, e) where the discriminant of subproblem k (hm_margins_d's d[k]) is
 * `off`, fa and fe its values minus off there, of opposite signs: brent_root, no
 * rows. NaN when a discriminant is not finite inside. */
static double hm_margin_root(HmCtx *ctx, int k, double off, double a,
                             double fa, double e, double fe)
{
    HmMarginArg arg = {ctx, k, off};
    return brent_root(hm_margin_at, &arg, a, fa, e, fe);
}

/* Slot b's branch end in (r0, r1) from the existence margins: its position root
 * ends where the discriminant of the first angle's subproblem 4, or of the
 * second's given the slot's first root, falls to 0 (the pair's first root; the
 * margin hm_margins crosses 0 there) or, for the pair's second root, to
 * HM_DISC_TWO (sp4_roots merges the two roots below 1e-16 of A^2 + B^2, and
 * pk_one's rows of that root come and go between there and 0: taking 0 for it
 * flagged a branch vanishing next to its end on development poses 494 and 830):
 * hm_margin_root, ~12 margin evaluations and no rows. Confirmed by rows: slot b's
 * row at the end (into *re, with its slope) and none HM_FOLD_TOL past it. Returns
 * 0 (*re undefined; hm_fold bisects on rows) when no discriminant brackets the end
 * or the rows disagree. */
static int hm_fold_margin(HmCtx *c, int b, const HmRow *r0, const HmRow *r1, HmRow *re,
                          double *end)
{
    double m0[3], m1[3], d0[3], d1[3];
    int state0 = r0->valid[b];
    if (!hm_margins_d(c, r0->t, m0, d0) || !hm_margins_d(c, r1->t, m1, d1))
        return 0;
    const double *mv = state0 ? m0 : m1, *mu = state0 ? m1 : m0;
    int k = -1;
    if (mv[0] >= 0.0 && mu[0] < 0.0)
        k = 0; /* the first angle's roots end */
    else if (mv[0] >= 0.0 && mu[0] >= 0.0 && mv[1 + (b >> 2)] >= 0.0 && mu[1 + (b >> 2)] < 0.0)
        k = 1 + (b >> 2); /* the second's, given the slot's first root */
    if (k < 0)
        return 0;
    /* the pair's second root (slot bit 2 of the first angle, bit 1 of the second)
     * ends where sp4_roots merges the two: at HM_DISC_TWO; the first at 0 */
    double off = (k == 0 ? b >= 4 : (b & 2) != 0) ? HM_DISC_TWO : 0.0;
    double fa = d0[k] - off, fe = d1[k] - off;
    if (!((fa > 0.0) == (state0 != 0) && (fe > 0.0) != (state0 != 0)))
        return 0;
    double t = hm_margin_root(c, k, off, r0->t, fa, r1->t, fe);
    if (!(t > r0->t && t < r1->t))
        return 0;
    double dir = state0 ? 1.0 : -1.0; /* toward the side without the row */
    hm_eval_pair(c, t, b, 1, re);
    if (!re->valid[b])
        return 0;
    HmRow chk;
    hm_eval_pair(c, t + dir * HM_FOLD_TOL * fmax(1.0, fabs(t)), b, 0, &chk);
    if (chk.valid[b])
        return 0;
    *end = t;
    return 1;
}

/* A fold in (r0, r1): slot b's row exists at one end only. Its end from the
 * margins (hm_fold_margin), else bisected on the row's existence (extrapolating
 * 1 / |dq/dt|^2) to HM_FOLD_TOL; the last t with a row is the branch end (a cut and
 * a point). The partner slot (b ^ 1: the same position root) takes the same end
 * when its existence agreed at both ends of the cell (and its rows confirm it). */
static void hm_fold(HmCtx *c, int b, long cell, const HmRow *r0, const HmRow *r1)
{
    if (c->flags)
        return;
    double lo = r0->t, hi = r1->t, end = lo;
    int state0 = r0->valid[b], p = b ^ 1;
    HmRow chk, re;
    int known = 0;
    for (int f = 0; f < c->nfold[b] && !known; f++) {
        if (c->fold_cell[b][f] != cell)
            continue; /* the partner's end in this cell: checked on both sides */
        double e = c->fold_t[b][f];
        double out = e + copysign(HM_FOLD_TOL * fmax(1.0, fabs(e)), state0 ? 1.0 : -1.0);
        hm_eval_pair(c, e, b, 1, &re);
        int ok = re.valid[b];
        hm_eval_pair(c, out, b, 0, &chk);
        known = ok && !chk.valid[b];
        end = e;
    }
    int agree = r0->valid[p] == state0 && r1->valid[p] == r1->valid[b];
    if (!known && hm_fold_margin(c, b, r0, r1, &re, &end)) {
        known = 1;
        if (agree && c->nfold[p] < HM_MAXF) {
            c->fold_cell[p][c->nfold[p]] = cell;
            c->fold_t[p][c->nfold[p]++] = end;
        }
    }
    if (!known) {
        /* v: the valid side, u: the other; g = 1 / |dq/dt|^2 falls linearly to 0
         * at the fold (q moves as the square root of the distance): extrapolated
         * from the last two valid rows, safeguarded by bisection */
        double v = state0 ? lo : hi, u = state0 ? hi : lo, tv[2] = {v, NAN}, gv[2] = {0.0, 0.0};
        HmRow m;
        int last_out = 0, last_est = 0;
        gv[0] = hm_gap(c, b, state0 ? r0 : r1);
        c->full_fk = 1;
        for (int it = 0; it < 80; it++) {
            int est_used = 0;
            double probe = 0.5 * (v + u), tiny = 0.25 * HM_FOLD_TOL * fmax(1.0, fabs(v));
            if (probe == v || probe == u)
                break;
            if (gv[0] == 0.0) {
                probe = v + copysign(tiny, u - v); /* a slope infinite: at the fold */
            } else if (last_out && last_est) {
                probe = u - 0.05 * (u - v); /* the estimate overshot: just short of it */
            } else if (isfinite(tv[1]) && gv[0] != gv[1]) {
                double est = tv[0] - gv[0] * (tv[0] - tv[1]) / (gv[0] - gv[1]);
                if ((est - v) * (u - v) > 0.0 && fabs(est - v) < fabs(u - v))
                    probe = est;
                est_used = probe == est;
                if (fabs(probe - v) < tiny)
                    probe = v + copysign(tiny, u - v);
            }
            if ((probe - u) * (u - v) >= 0.0)
                probe = 0.5 * (v + u);
            hm_eval(c, probe, 1u << b, 1u << b, &m);
            last_out = !m.valid[b];
            last_est = est_used;
            if (m.valid[b]) {
                tv[1] = tv[0];
                gv[1] = gv[0];
                tv[0] = v = probe;
                gv[0] = hm_gap(c, b, &m);
            } else {
                u = probe;
            }
            if (fabs(u - v) <= HM_FOLD_TOL * fmax(1.0, fabs(v)))
                break;
        }
        c->full_fk = 0;
        if (!(fabs(u - v) <= 2.0 * HM_FOLD_TOL * fmax(1.0, fabs(v)))) {
            c->flags |= HM_FLAG_CONVERGE;
        }
        lo = state0 ? v : u;
        hi = state0 ? u : v;
        end = state0 ? lo : hi;
        if (agree && c->nfold[p] < HM_MAXF) {
            c->fold_cell[p][c->nfold[p]] = cell;
            c->fold_t[p][c->nfold[p]++] = end;
        }
        hm_eval_pair(c, end, b, 1, &re);
    }
    hm_point(c, end, b, -1, HM_KIND_FOLD);
    if (!re.valid[b]) {
        c->flags |= HM_FLAG_VANISH;
        return;
    }
    hm_at(c, b, end, hm_inside(c, &re, b, MANIFOLD_SLACK));
    hm_node(c, b, &re);
    const HmRow *rv = state0 ? r0 : r1;
    if (hm_gap(c, b, rv) < HM_NEAR * fabs(rv->t - end)) {
        /* the piece's node is at another branch end too (hm_pose's test on the
         * piece: the node hm_grid puts just inside the first angle's end, ~0.002 rad
         * from this one, an end of the second angle; session 20): the piece split at
         * its middle, each half from its own end (in sigma from this one, from the
         * node as hm_pose takes a node at a branch end), else its cells next to the
         * node do not resolve in HM_DEPTH splits (the pose was flagged) */
        HmRow m;
        hm_eval_pair(c, 0.5 * (end + rv->t), b, 1, &m);
        if (!m.valid[b]) {
            c->flags |= HM_FLAG_VANISH;
            return;
        }
        hm_seen(c, b, &m);
        hm_node(c, b, &m);
        hm_fold_piece(c, b, &re, &m, 1);
        hm_fold_piece(c, b, rv, &m, 0);
        return;
    }
    hm_fold_piece(c, b, &re, rv, 1);
}

static int hm_cmp(const void *x, const void *y)
{
    double a = *(const double *)x, b = *(const double *)y;
    return a < b ? -1 : a > b;
}

/* Whether slot b's row exists and is inside every limit (slack: allowed excess) */
static int hm_inside(const HmCtx *c, const HmRow *r, int b, double slack)
{
    int good = r->valid[b];
    for (int j = 0; j < c->n && good; j++)
        good = r->q[b][j] >= c->P[PK_LO + j] - slack && r->q[b][j] <= c->P[PK_HI + j] + slack;
    return good;
}

static int hm_emit(HmCtx *c, double *iv, long *k, double a, double e)
{
    if (*k > 0 && iv[2 * (*k - 1) + 1] == a && iv[2 * (*k - 1)] < a) {
        iv[2 * (*k - 1) + 1] = e; /* continues the last one */
        return 1;
    }
    if (*k >= HM_MAXI) {
        c->flags |= HM_FLAG_FULL;
        return 0;
    }
    iv[2 * *k] = a;
    iv[2 * *k + 1] = e;
    (*k)++;
    return 1;
}

/* Slot b's pieces between its cuts (sorted, distinct), each decided at its
 * midpoint, joined; a cut whose pieces on both sides are outside is an interval
 * of its own ([t, t]) when its row is inside to 1e-12 (a branch touching the
 * limits, e.g. the generating configuration at a limit at the range's end). */
/* Whether slot b's grid row r decides a piece: every joint is inside its limits,
 * or one outside, by more than HM_DECIDE (far from the piece's cuts, which hold the
 * joints at their limits to HM_TOL_STEEP), or the row does not exist (outside: the
 * slot's row appears and disappears only at branch ends, which are cuts; session 12:
 * 14.4 midpoint rows per pose, each without a row, on the 1,150 development poses);
 * into *good. */
static int hm_decides(const HmCtx *c, const HmRow *r, int b, unsigned char *good)
{
    if (!r->valid[b]) {
        *good = 0;
        return 1;
    }
    double worst = HUGE_VAL;
    for (int j = 0; j < c->n; j++) {
        double m = fmin(r->q[b][j] - c->P[PK_LO + j], c->P[PK_HI + j] - r->q[b][j]);
        worst = fmin(worst, m);
    }
    if (!(fabs(worst) > HM_DECIDE))
        return 0;
    *good = worst > 0.0;
    return 1;
}

/* Slot b's row r, evaluated off the grid (a split, a crossing's iterate, an
 * extremum's, a near-fold row), kept when it decides a piece as a grid row does
 * (hm_decides: every joint inside, or one outside, by more than HM_DECIDE): a
 * piece holding such a row strictly inside needs no midpoint row (round 8b). */
static void hm_seen(HmCtx *c, int b, const HmRow *r)
{
    unsigned char good;
    if (c->nseen[b] < HM_MAXSEEN && hm_decides(c, r, b, &good)) {
        c->seen_t[b][c->nseen[b]] = r->t;
        c->seen_good[b][c->nseen[b]++] = good;
    }
}

/* Whether the piece (a, e) of slot b lies in a graze's stretch (hm_graze): then
 * decided by the row at its middle with the grazing joint polished, inside to
 * HM_TOL, into *good. */
static int hm_grazed(HmCtx *c, int b, double a, double e, unsigned char *good)
{
    for (int g = 0; g < c->ngraze[b]; g++) {
        if (!(a >= c->graze_t[b][g][0] && e <= c->graze_t[b][g][1]))
            continue;
        HmRow r;
        hm_eval(c, 0.5 * (a + e), 0u, 1u << b, &r);
        if (r.valid[b])
            r.q[b][c->graze_j[b][g]] = hm_polished(c, r.q[b], c->graze_j[b][g]);
        *good = (unsigned char)hm_inside(c, &r, b, MANIFOLD_SLACK);
        return 1;
    }
    return 0;
}

static void hm_intervals(HmCtx *c, int b, double lo, double hi, const HmRow *rows, long G,
                         double *iv, long long *niv)
{
    double *cut = c->cut[b];
    int m = c->ncut[b], u = 0;
    unsigned char good[HM_MAXCUT];
    if (m + 2 > HM_MAXCUT) {
        c->flags |= HM_FLAG_FULL;
        return;
    }
    cut[m++] = lo;
    cut[m++] = hi;
    for (int i = 0; i < m; i++)
        cut[i] = fmin(fmax(cut[i], lo), hi);
    qsort(cut, (size_t)m, sizeof(double), hm_cmp);
    for (int i = 0; i < m; i++)
        if (u == 0 || cut[i] > cut[u - 1])
            cut[u++] = cut[i];
    HmRow r;
    long g = 0; /* the first grid row past cut[i] */
    for (int i = 0; i + 1 < u; i++) {
        /* a grid row strictly inside the piece, nearest its midpoint, decides it
         * (the piece has one verdict: every crossing and fold is a cut); else
         * the midpoint's row */
        double mid = 0.5 * (cut[i] + cut[i + 1]);
        long best = -1;
        while (g < G && rows[g].t <= cut[i])
            g++;
        if (hm_grazed(c, b, cut[i], cut[i + 1], &good[i]))
            continue;
        for (long h = g; h < G && rows[h].t < cut[i + 1]; h++)
            if (best < 0 || fabs(rows[h].t - mid) < fabs(rows[best].t - mid))
                best = h;
        if (best >= 0 && hm_decides(c, &rows[best], b, &good[i]))
            continue;
        int seen = -1; /* else a row off the grid strictly inside, nearest the midpoint */
        for (int s = 0; s < c->nseen[b]; s++)
            if (c->seen_t[b][s] > cut[i] && c->seen_t[b][s] < cut[i + 1] &&
                (seen < 0 || fabs(c->seen_t[b][s] - mid) < fabs(c->seen_t[b][seen] - mid)))
                seen = s;
        if (seen >= 0) {
            good[i] = c->seen_good[b][seen];
            continue;
        }
        hm_eval(c, mid, 0u, 1u << b, &r);
        good[i] = (unsigned char)hm_inside(c, &r, b, MANIFOLD_SLACK);
    }
    long k = 0;
    for (int i = 0; i < u; i++) {
        int left = i > 0 && good[i - 1], right = i + 1 < u && good[i];
        if (!left && !right) {
            int in = -1; /* the row the cut was found on, else the grid's at the range's ends */
            for (int s = 0; s < c->nat[b] && in < 0; s++)
                if (c->at_t[b][s] == cut[i])
                    in = c->at_in[b][s];
            if (in < 0 && G > 0 && (cut[i] == rows[0].t || cut[i] == rows[G - 1].t))
                in = hm_inside(c, cut[i] == rows[0].t ? &rows[0] : &rows[G - 1], b,
                               MANIFOLD_SLACK);
            if (in < 0) {
                hm_eval(c, cut[i], 0u, 1u << b, &r);
                in = hm_inside(c, &r, b, MANIFOLD_SLACK);
            }
            if (in && !hm_emit(c, iv, &k, cut[i], cut[i]))
                break;
        }
        if (right && !hm_emit(c, iv, &k, cut[i], cut[i + 1]))
            break;
    }
    *niv = k;
}

/* held_margins.c's margins with this pose's memo (c->marg) */
static int hm_margins_d(HmCtx *c, double x, double *m, double *d)
{
    return hm_margins_pk(c->P, c->T, &c->marg, x, m, d);
}

static int hm_margins(HmCtx *c, double x, double *m)
{
    return hm_margins_d(c, x, m, NULL);
}

/* Golden section on margin k over (a, e), towards its maximum when want_max (NaN
 * counts as low), at most 60 steps. flip = 0: until the bracket is 1e-13 (relative to
 * |a|, at least 1) wide; its middle. flip = 1: until it is w wide, or at the first
 * value of margin k with the sign opposite to want_max's (want_max: negative at both
 * ends), which it returns; NaN when none is met. */
static double hm_margin_golden(HmCtx *c, int k, double a, double e, int want_max, int flip,
                               double w)
{
    const double r = 0.6180339887498949;
    double x1 = e - r * (e - a), x2 = a + r * (e - a), m[3], f1, f2;
    hm_margins(c, x1, m);
    if (flip && isfinite(m[k]) && (m[k] < 0) != want_max)
        return x1;
    f1 = want_max ? m[k] : -m[k];
    hm_margins(c, x2, m);
    if (flip && isfinite(m[k]) && (m[k] < 0) != want_max)
        return x2;
    f2 = want_max ? m[k] : -m[k];
    for (int it = 0; it < 60 && e - a > (flip ? w : 1e-13 * fmax(1.0, fabs(a))); it++) {
        double x;
        int left = !(f1 <= f2); /* the maximum in (a, x2) */
        if (left) {
            e = x2;
            x2 = x1;
            f2 = f1;
            x = x1 = e - r * (e - a);
        } else {
            a = x1;
            x1 = x2;
            f1 = f2;
            x = x2 = a + r * (e - a);
        }
        hm_margins(c, x, m);
        if (flip && isfinite(m[k]) && (m[k] < 0) != want_max)
            return x;
        if (left)
            f1 = want_max ? m[k] : -m[k];
        else
            f2 = want_max ? m[k] : -m[k];
    }
    return flip ? NAN : 0.5 * (a + e);
}

/* The extremum of margin k in (a, e) (golden section; a maximum when want_max):
 * its t. */
static double hm_margin_extremum(HmCtx *c, int k, double a, double e, int want_max)
{
    return hm_margin_golden(c, k, a, e, want_max, 0, 0.0);
}

/* A t in (a, e) where margin k has the sign opposite to `neg` (neg: negative at both
 * ends), searched for at its extremum as hm_margin_extremum does, but stopping at the
 * first such value, or with the bracket 1e-7 of (a, e) wide (~35 margin values; the
 * extremum's value then known to the margin's curvature times 1e-14 of the cell
 * squared); NaN when none is found. Only its sign decides: a node there shows the
 * margin's gap or island to the cells. */
static double hm_margin_flip(HmCtx *c, int k, double a, double e, int neg)
{
    return hm_margin_golden(c, k, a, e, neg, 1, 1e-7 * (e - a));
}

typedef struct { /* a node of hm_grid: its t, and whether rows are evaluated there */
    double t;
    int keep;
} HmNode;

/* The grid: the existence margins at G values over [lo, hi] (cheap scalars, no rows),
 * and in every cell where a margin keeps its sign at both nodes but the parabola
 * through it and a neighbour node turns back toward 0 inside the cell, its extremum
 * (a branch born and dying between two nodes: an island; or a short gap). Rows are
 * wanted (round 8b) at every HM_STRIDE-th node, the range's ends, the extra nodes,
 * and both nodes of every margin cell where a margin changes sign or existence or
 * turns back (a branch is born or dies there): so every cell where a branch end can
 * lie is a margin cell, as before, and the others are HM_STRIDE cells wide, where
 * hm_cell splits what its rows do not certify. Returns the count of row nodes
 * (<= cap) into t, sorted; 0 and a flag when the margins are not available. */
static long hm_grid(HmCtx *c, long G, double lo, double hi, double *t, long cap)
{
    double (*m)[3] = malloc((size_t)G * sizeof(*m));
    HmNode *nd = malloc((size_t)cap * sizeof(HmNode));
    unsigned char *seen = calloc((size_t)G, 1); /* bit k: cell i's margin k searched */
    long nt = 0;
    if (m == NULL || nd == NULL || seen == NULL) {
        free(m);
        free(nd);
        free(seen);
        c->flags |= HM_FLAG_MEMORY;
        return 0;
    }
    for (long i = 0; i < G; i++) {
        nd[i].t = i == G - 1 ? hi : lo + (hi - lo) * (double)i / (double)(G - 1);
        nd[i].keep = i % HM_STRIDE == 0 || i == G - 1;
        if (!hm_margins(c, nd[i].t, m[i])) {
            /* not the coplanar kind (Pieper's quartic: the offset-SRS iiwa14): the pose
             * is flagged whatever the rest finds, so stop here (the rows, cells and
             * folds cost ~44 ms per such pose for an output the caller discards) */
            c->flags |= HM_FLAG_BAD;
            free(m);
            free(nd);
            free(seen);
            return 0;
        }
    }
    nt = G;
    for (long i = 0; i + 1 < G; i++) {
        for (int k = 0; k < 3; k++) /* a margin changing sign or existence: a branch end */
            if (isfinite(m[i][k]) != isfinite(m[i + 1][k]) ||
                (isfinite(m[i][k]) && (m[i][k] < 0) != (m[i + 1][k] < 0)))
                nd[i].keep = nd[i + 1].keep = 1;
        if (isfinite(m[i][0]) && isfinite(m[i + 1][0]) && (m[i][0] < 0) != (m[i + 1][0] < 0)) {
            /* the first angle's roots end here: the second's margins may change sign
             * between the node and that end; a node just inside the end sees it */
            double a = nd[i].t, e = nd[i + 1].t, me[3];
            int in_a = m[i][0] >= 0;
            for (int it = 0; it < 60 && e - a > 1e-12 * fmax(1.0, fabs(a)); it++) {
                double mid = 0.5 * (a + e);
                hm_margins(c, mid, me);
                if ((me[0] >= 0) == in_a)
                    a = mid;
                else
                    e = mid;
            }
            double w = 1e-9 * (nd[i + 1].t - nd[i].t) * (in_a ? -1.0 : 1.0), tin = in_a ? a : e;
            if (nt < cap && (in_a ? tin + w > nd[i].t : tin + w < nd[i + 1].t)) {
                nd[nt++] = (HmNode){tin + w, 1};
                /* the second angle's margins next to that end: in the sub-cell between
                 * that node and the cell's node with roots, and in the next margin cell
                 * on that side, they have no third finite node for the parabola test
                 * below, or one across the first angle's square root: a gap or an
                 * island of theirs there (a pair of branch ends within ~0.05 rad of the
                 * first angle's end) is looked for at their extremum in each
                 * (hm_margin_flip; 1-2 such ends a pose) */
                long ir = in_a ? i : i + 1, in = in_a ? i - 1 : i + 2;
                double mt[3];
                hm_margins(c, tin + w, mt);
                for (int k = 1; k < 3; k++) {
                    for (int part = 0; part < 2; part++) {
                        double sa, se, fa, fe;
                        long c0 = -1; /* the grid cell searched (part 1) */
                        if (part == 0) { /* the sub-cell */
                            sa = in_a ? nd[i].t : tin + w;
                            se = in_a ? tin + w : nd[i + 1].t;
                            fa = m[ir][k];
                            fe = mt[k];
                        } else { /* the next cell out */
                            if (in < 0 || in >= G)
                                continue;
                            c0 = in_a ? in : ir; /* its left node */
                            if (seen[c0] >> k & 1u)
                                continue;
                            sa = nd[c0].t;
                            se = nd[c0 + 1].t;
                            fa = m[ir][k];
                            fe = m[in][k];
                        }
                        if (!isfinite(fa) || !isfinite(fe) || (fa < 0) != (fe < 0))
                            continue; /* a sign change: the loop below keeps both nodes */
                        if (fmin(fabs(fa), fabs(fe)) > HM_GAP_NEAR)
                            continue; /* far from 0 at a node: no gap (measured) */
                        if (c0 >= 0) /* searched here: not again by the parabola test */
                            seen[c0] |= (unsigned char)(1u << k);
                        double te = hm_margin_flip(c, k, sa, se, fa < 0);
                        if (isnan(te))
                            continue; /* no island, no gap */
                        if (nt >= cap) {
                            c->flags |= HM_FLAG_FULL;
                            break;
                        }
                        nd[nt++] = (HmNode){te, 1};
                        if (part == 1)
                            nd[in_a ? in : ir].keep = nd[in_a ? ir : in].keep = 1;
                    }
                }
            }
        }
        for (int k = 0; k < 3; k++) {
            double a = m[i][k], e = m[i + 1][k];
            if (!isfinite(a) || !isfinite(e) || (a < 0) != (e < 0) || (seen[i] >> k & 1u))
                continue;
            /* the parabolas through (i - 1, i, i + 1) and (i, i + 1, i + 2) */
            int turns = 0;
            for (int side = 0; side < 2 && !turns; side++) {
                long j = side ? i + 2 : i - 1;
                if (j < 0 || j >= G || !isfinite(m[j][k]))
                    continue;
                double u[3] = {nd[i].t, nd[i + 1].t, nd[j].t}, f[3] = {a, e, m[j][k]};
                /* divided differences */
                double d1 = (f[1] - f[0]) / (u[1] - u[0]), d2 = (f[2] - f[1]) / (u[2] - u[1]);
                double q2 = (d2 - d1) / (u[2] - u[0]);
                if (q2 == 0.0)
                    continue;
                /* f = f0 + d1 (s - u0) + q2 (s - u0)(s - u1): f' = 0 at */
                double s0 = 0.5 * (u[0] + u[1]) - d1 / (2.0 * q2);
                if (!(s0 > u[0] && s0 < u[1]))
                    continue;
                double fs = f[0] + d1 * (s0 - u[0]) + q2 * (s0 - u[0]) * (s0 - u[1]);
                /* toward 0: a maximum of a negative margin, a minimum of a positive one */
                if ((a < 0 && q2 < 0 && fs > 2.0 * a) || (a >= 0 && q2 > 0 && fs < 0.5 * a))
                    turns = 1;
            }
            if (!turns)
                continue;
            seen[i] |= (unsigned char)(1u << k);
            nd[i].keep = nd[i + 1].keep = 1;
            double te = hm_margin_extremum(c, k, nd[i].t, nd[i + 1].t, a < 0);
            double me[3];
            hm_margins(c, te, me);
            if (!isfinite(me[k]) || (me[k] < 0) == (a < 0))
                continue; /* no island, no gap */
            if (nt >= cap) {
                c->flags |= HM_FLAG_FULL;
                break;
            }
            nd[nt++] = (HmNode){te, 1};
        }
    }
    free(m);
    free(seen);
    /* the grid's nodes are in order and the extra ones (all kept) few: the extra ones
     * sorted by insertion (stable), then merged with the grid's kept nodes, a grid node
     * first at equal t (qsort's stable order; ~4 % of the kernel's instructions before) */
    for (long i = G + 1; i < nt; i++) {
        HmNode x = nd[i];
        long j = i - 1;
        for (; j >= G && nd[j].t > x.t; j--)
            nd[j + 1] = nd[j];
        nd[j + 1] = x;
    }
    long kept = 0, e = G;
    for (long i = 0; i < G; i++) {
        if (!nd[i].keep)
            continue;
        for (; e < nt && nd[e].t < nd[i].t; e++)
            t[kept++] = nd[e].t;
        t[kept++] = nd[i].t;
    }
    for (; e < nt; e++)
        t[kept++] = nd[e].t;
    free(nd);
    return kept;
}

/* Whether a limit crossing or a fold of a branch lies within HM_ALIGNED_NEAR of an
 * aligned-axes point of that branch. Asked only on poses with slot jumps (the
 * Gen3-like arm, whose poses the kernel certifies since hm_jump): next to its aligned
 * shoulder (q2 = 0) the rows are conditioned so that a joint can sit within the
 * slack of its limit over 1e-5 of t, or cross it within 1e-9 of the aligned point,
 * where the pieces' midpoint verdicts and the solved-points path differ by more than
 * 1e-9 (3 of 288 certified special poses, seed 0, before this test).
 *
 * On the Panda-type arm (q7 held, the shoulder triple q1, q2, q3 first) the shoulder's
 * own swing is not such a reason (session 22): where q2 passes 0 or within ~1e-4 of it
 * q1 and q3 turn by ~pi (crossing their limits and q3 its aligned value 0 there), and
 * where q2 is exactly 0 the held chain is singular (axes 1 and 3 on one line: a fold
 * of t at the aligned point). Those crossings (joints 0 and 2) and folds are located
 * as in any cell (HM_SWING); every other joint's crossing next to an aligned point
 * (q4 or q6 at its limit there: special #241, #874 of seed 22, #305 of seed 31, where
 * the intervals differ from the solved-points path by up to 9e-6 of t at the slack)
 * still flags the pose. */
static int hm_near_aligned(const HmCtx *c)
{
    int shoulder = c->n == 7 && c->k == 6;
    for (long i = 0; i < c->npts; i++) {
        const double *a = c->pts + 4 * i;
        if (a[3] != HM_KIND_ALIGNED)
            continue;
        for (long k = 0; k < c->npts; k++) {
            const double *p = c->pts + 4 * k;
            if (shoulder && (p[3] == HM_KIND_FOLD || p[2] == 0.0 || p[2] == 2.0))
                continue; /* the swing's q1, q3 and the fold at q2 = 0 */
            if (p[3] != HM_KIND_ALIGNED && p[1] == a[1] && fabs(p[0] - a[0]) < HM_ALIGNED_NEAR)
                return 1;
        }
    }
    return 0;
}

/* One pose: grid rows, cells, folds, intervals. */
static void hm_pose(HmCtx *c, long G, double *iv, long long *niv)
{
    const double *P = c->P;
    double lo = P[PK_LO + c->k], hi = P[PK_HI + c->k];
    long cap = 2 * G;
    HmRow *rows = malloc((size_t)cap * sizeof(HmRow));
    double *tg = malloc((size_t)cap * sizeof(double));
    for (int b = 0; b < 8; b++)
        niv[b] = 0;
    if (rows == NULL || tg == NULL) {
        free(rows);
        free(tg);
        c->flags |= HM_FLAG_MEMORY;
        return;
    }
    c->hfine = (hi - lo) / (double)(G - 1);
    G = hm_grid(c, G, lo, hi, tg, cap);
    if (c->flags) {
        free(rows);
        free(tg);
        return; /* flagged: no intervals (niv 0) */
    }
    for (long i = 0; i < G; i++)
        hm_eval(c, tg[i], 0xffu, 0xffu, &rows[i]);
    free(tg);
    for (int b = 0; b < 8; b++)
        c->nfold[b] = 0;
    for (int b = 0; b < 8 && !c->flags; b++) {
        long npts0 = c->npts;
        int nfold0[8], passes = 0;
        memcpy(nfold0, c->nfold, sizeof nfold0);
        if (!(b & 1))
            c->npair = c->ipair = 0; /* a new pair */
    again: /* (a slot change found by hm_root: the slot's pass again, with it known) */
        c->retry = 0;
        c->npts = npts0;
        memcpy(c->nfold, nfold0, sizeof nfold0);
        c->ncut[b] = 0;
        c->ngraze[b] = 0;
        c->nseen[b] = 0;
        c->nat[b] = 0;
        for (long i = 0; i < G && !c->flags && !c->retry; i++) {
            if (rows[i].valid[b])
                hm_node(c, b, &rows[i]);
            if (i + 1 == G)
                break;
            int v0 = rows[i].valid[b], v1 = rows[i + 1].valid[b];
            double near = HM_NEAR * fmin(rows[i + 1].t - rows[i].t, c->hfine);
            if (v0 && v1 && hm_gap(c, b, &rows[i]) < near)
                hm_fold_piece(c, b, &rows[i], &rows[i + 1], 0); /* a node at a branch end */
            else if (v0 && v1 && hm_gap(c, b, &rows[i + 1]) < near)
                hm_fold_piece(c, b, &rows[i + 1], &rows[i], 0);
            else if (v0 && v1)
                hm_cell(c, b, &rows[i], &rows[i + 1], 0);
            else if (v0 != v1)
                hm_fold(c, b, i, &rows[i], &rows[i + 1]);
        }
        if (c->retry && ++passes < 4)
            goto again;
        if (c->retry)
            c->flags |= HM_FLAG_CONVERGE;
        if (!c->flags)
            hm_intervals(c, b, lo, hi, rows, G, iv + 2 * HM_MAXI * b, niv + b);
    }
    if (!c->flags && c->jumped && hm_near_aligned(c))
        c->flags |= HM_FLAG_SINGULAR;
    if (!c->flags && c->coarse && c->repaired)
        c->flags |= HM_FLAG_CONVERGE; /* a coarse crossing on a pose with repaired rows */
    if (c->flags) /* a flagged pose stops at its first flag: no intervals */
        for (int b = 0; b < 8; b++)
            niv[b] = 0;
    free(rows);
}

typedef struct {
    const double *P, *T, *al;
    long nal, G, mode; /* HM_MODE_* */
    double *iv, *pts;
    long long *niv, *npts, *flags, *evals;
} HmJob;

static void hm_range(void *ctx, long b0, long e0)
{

    const HmJob *jb = ctx;
    const double *P = jb->P;
    for (long i = b0; i < e0; i++) {
        if (jb->mode != HM_MODE_GRID) { /* held_closed.c's closed forms first */
            long npts = 0, rows = 0, solves = 0;
            if (P[PK_CASE] != PK_BOTH &&
                hc_pose(P, jb->T + 16 * i, jb->al, jb->nal, jb->iv + 2 * HM_MAXI * 8 * i,
                        jb->niv + 8 * i, jb->pts + 4 * HM_MAXP * i, &npts, &rows, &solves)) {
                jb->npts[i] = npts;
                jb->flags[i] = 0;
#ifdef HM_COUNT_CHEAP
                jb->evals[i] = rows; /* a measuring build: every row evaluation */
#else
                jb->evals[i] = solves; /* its pk_one calls (the slot order's) */
#endif
                continue;
            }
            if (jb->mode == HM_MODE_CLOSED) {
                for (int b = 0; b < 8; b++)
                    jb->niv[8 * i + b] = 0;
                jb->npts[i] = 0;
                jb->flags[i] = HM_FLAG_BAD;
                jb->evals[i] = 0;
                continue;
            }
        }
        HmCtx *c = malloc(sizeof(HmCtx));
        if (c == NULL) {
            jb->flags[i] = HM_FLAG_MEMORY;
            jb->npts[i] = 0;
            continue;
        }
        c->P = P;
        c->T = jb->T + 16 * i;
        c->n = (int)P[PK_N];
        c->k = (int)P[PK_HELD];
        c->flags = 0;
        c->evals = 0;
        c->cheap = 0;
        c->pts = jb->pts + 4 * HM_MAXP * i;
        c->npts = 0;
        for (int j = 0; j < PK_MAXJ; j++)
            c->qn[j] = 0.0;
        c->nq = 0;
        for (int j = 0; j < c->n; j++) {
            double l = P[PK_LO + j], h = P[PK_HI + j];
            if (j == c->k || h - l >= 2.0 * M_PI)
                continue; /* the parameter, or every angle has an in-limit turn */
            c->qj[c->nq] = j;
            c->qv[c->nq] = l;
            c->qkind[c->nq++] = HM_KIND_LOWER;
            c->qj[c->nq] = j;
            c->qv[c->nq] = h;
            c->qkind[c->nq++] = HM_KIND_UPPER;
        }
        for (long a = 0; a < jb->nal; a++) {
            int j = (int)jb->al[2 * a];
            if (j == c->k || j < 0 || j >= c->n)
                continue;
            if (c->nq >= HM_MAXQ) {
                c->flags |= HM_FLAG_FULL;
                break;
            }
            c->qj[c->nq] = j;
            c->qv[c->nq] = jb->al[2 * a + 1];
            c->qkind[c->nq++] = HM_KIND_ALIGNED;
        }
        for (int m = 0; m < HM_MEMO; m++)
            c->memo[m].t = c->memo_t[m] = NAN; /* nothing kept */
        c->nmemo = 0;
        c->front.set = 0;
        c->marg.set = 0;
        for (int m = 0; m < HM_FRONTS; m++)
            c->front_t[m] = NAN; /* no front kept */
        c->nfront = 0;
        c->fast = hm_fast_setup(c);
        c->full_fk = 0;
        c->jumped = 0;
        c->repaired = 0;
        c->coarse = 0;
        c->deep = 0;
        c->deep_cell = 0;
        c->sq_te = NAN;
        c->njump = 0;
        c->retry = 0;
        if (P[PK_CASE] == PK_BOTH || c->k < 0 || c->n != 7)
            c->flags |= HM_FLAG_BAD; /* not a Panda-type held family */
        else
            hm_pose(c, jb->G, jb->iv + 2 * HM_MAXI * 8 * i, jb->niv + 8 * i);
        jb->npts[i] = c->npts;
        jb->flags[i] = c->flags;
#ifdef HM_STAGES
        for (int t = 0; t < 16 && hm_tags[t]; t++)
            fprintf(stderr, "%s %ld ", hm_tags[t], hm_tag_n[t]);
        fprintf(stderr, "\n");
        for (int t = 0; t < 16; t++)
            hm_tag_n[t] = 0;
#endif
#ifdef HM_SHARE_STATS
        for (int j = 0; j < PK_MAXJ; j++) /* cumulative over the process' poses */
            fprintf(stderr, "share j%d %ld %ld\n", j, hm_share_n[j][0], hm_share_n[j][1]);
#endif
#ifdef HM_COUNT_CHEAP
        jb->evals[i] = c->cheap; /* a measuring build: every evaluation */
#else
        jb->evals[i] = c->evals;
#endif
        free(c);
    }
}

/* held_manifold(params, T (N, 4, 4), aligned (A, 2), grid, iv, niv, pts, npts,
 * flags, evals): per pose the intervals of every slot inside every limit, the
 * points [t, branch, joint, kind], the flags (0: certain) and pk_one calls. */
static PyObject *held_manifold_body(const held_manifold_args *a)
{
    HmJob jb = {a->params, a->T, a->aligned, (long)a->A, (long)a->grid, (long)a->mode, a->iv,
                a->pts, a->niv, a->npts, a->flags, a->evals};
    Py_BEGIN_ALLOW_THREADS
    if (a->N >= HM_PARALLEL_MIN)
        pool_for((long)a->N, HM_GRAIN, hm_range, &jb);
    else
        hm_range(&jb, 0, (long)a->N);
    Py_END_ALLOW_THREADS
    Py_RETURN_NONE;
}


/* One pose (robot.self_motion's call): held_manifold of T (4, 4), its intervals
 * packed branch by branch; returns new arrays (intervals (m, 2), branches (m,),
 * points (p, 4)), the flags, the pk_one calls and sm_close's flag on the held range (False:
 * _points_refined has nothing to find; False on a flagged pose, whose arrays are
 * empty but for the points found before the flag). None, before any row, where T
 * is not a C-contiguous aligned native float64 (4, 4) ndarray (a subclass neither),
 * or, with exact > 0, where pose_problem finds it more than exact from orthonormal
 * (or not rigid): the caller checks it (check_rigid) and calls again. */
static PyObject *held_manifold_one_body(const held_manifold_one_args *a)
{
    static const int stride = 2 * HM_MAXI;
    PyArrayObject *ta = (PyArrayObject *)a->T;
    if (!PyArray_CheckExact(a->T) || PyArray_TYPE(ta) != NPY_DOUBLE || PyArray_NDIM(ta) != 2 ||
        PyArray_DIMS(ta)[0] != 4 || PyArray_DIMS(ta)[1] != 4 || !PyArray_IS_C_CONTIGUOUS(ta) ||
        !PyArray_ISNOTSWAPPED(ta) || !PyArray_ISALIGNED(ta))
        Py_RETURN_NONE;
    const double *T = (const double *)PyArray_DATA(ta);
    if (a->exact > 0.0 && pose_problem(T, POSE_ROW_TOL, a->exact))
        Py_RETURN_NONE;
    double *iv = malloc((8 * 2 * HM_MAXI + 4 * HM_MAXP) * sizeof(double));
    if (iv == NULL)
        return PyErr_NoMemory();
    double *pts = iv + 8 * stride;
    long long niv[8] = {0}, npts = 0, flags = 0, evals = 0, m = 0; /* (hm_range sets niv
                                                                      * only where it runs hm_pose) */
    HmJob jb = {a->params, T, a->aligned, (long)a->A, (long)a->grid, HM_MODE_AUTO, iv, pts, niv,
                &npts,
                &flags, &evals};
    Py_BEGIN_ALLOW_THREADS
    hm_range(&jb, 0, 1);
    Py_END_ALLOW_THREADS
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
        free(iv);
        return NULL;
    }
    double *ov = (double *)PyArray_DATA((PyArrayObject *)out_iv);
    long long *ob = (long long *)PyArray_DATA((PyArrayObject *)out_b);
    for (long long b = 0, k = 0; b < 8; b++) {
        memcpy(ov + 2 * k, iv + stride * b, (size_t)(2 * niv[b]) * sizeof(double));
        for (long long i = 0; i < niv[b]; i++)
            ob[k++] = b;
    }
    if (npts)
        memcpy(PyArray_DATA((PyArrayObject *)out_p), pts, (size_t)(4 * npts) * sizeof(double));
    const double *P = a->params;
    int k = (int)P[PK_HELD];
    double key[HM_MAXP];
    int close = !flags &&
                sm_close(pts, npts, ov, m, P[PK_LO + k], P[PK_HI + k], HM_KIND_UPPER, key);
    free(iv);
    return Py_BuildValue("(NNNLLN)", out_iv, out_b, out_p, flags, evals, PyBool_FromLong(close));
}
