/*
 * Process paths (robokin.process): the layered graph over every IK solution of a
 * tool path, and its exact shortest path by dynamic programming.
 *
 * A *layer* is one waypoint of the path; its M *nodes* are the IK solutions of the
 * waypoint's sampled tool poses (every solution slot of every sampled rotation
 * about the tool's free axis; empty slots are nodes that are never usable). Node
 * values are joint coordinates, one of three kinds per coordinate (`mode`):
 *
 *   PM_PLAIN    the value as it is (prismatic, or a coordinate whose whole turns
 *               are not symmetries of the chain: chain.h's ch->wrap is 0);
 *   PM_TURN     a revolute coordinate moved by whole turns into its limits
 *               (chain.h's wrap_into): its limits span less than a turn, so at
 *               most one value of the angle is inside them;
 *   PM_CIRCLE   a revolute coordinate whose limits span a turn or more, kept on
 *               the circle [-pi, pi) (wrap_pi): every angle has a value inside
 *               the limits, and steps are measured the short way round. Which
 *               whole turn the arm is on is chosen after the search
 *               (robokin/process/_turns.py); the search is then a relaxation
 *               whose optimum is certified or refined there.
 *
 * process_nodes: per node its canonical values, a status (PN_*), its relative
 *   manipulability and its cost (nearness to singularity and to limits); the loop
 *   over nodes runs on the pool (every node computed by the same code whichever
 *   thread takes it: results do not depend on the number of threads).
 * process_dp: the min-plus recursion V_{i+1}(v) = c(v) + min_u [V_i(u) + w d(u, v)]
 *   over edges with d(u, v) = max_j |v_j - u_j| <= max_step (wrapped for circle
 *   coordinates), then the backtrack. Candidates u of a node v are found through
 *   per-joint buckets of width >= max_step (a counting sort per layer and joint):
 *   only the buckets next to v's, along the joint with the fewest candidates, are
 *   scanned, so a layer costs O(M k) for k candidates instead of O(M^2). Ties go to
 *   the smaller node index, so the result is the same whatever the scan order.
 *   Where no node of a layer can be reached the search restarts there (a new
 *   segment), so every layer gets a configuration where one exists.
 *
 * Its entries and constants are declared in ../_declare.py (PROCESS); the
 * generated entry points check the arguments before the bodies run.
 */
#include "chain.h"
#include "pool.h"

enum { PN_OK = 0, PN_NONE = 1, PN_LIMITS = 2, PN_SINGULAR = 3 };
enum { PM_PLAIN = 0, PM_TURN = 1, PM_CIRCLE = 2 };
/* the weights vector of process_nodes */
enum {
    PW_SING_W,      /* cost of a node at zero manipulability */
    PW_SING_MARGIN, /* relative manipulability below which the cost starts */
    PW_SING_TOL,    /* relative manipulability below which a node is singular */
    PW_MU_REF,      /* the manipulability the relative one divides by */
    PW_LIM_W,       /* cost of a joint at its limit */
    PW_LIM_MARGIN,  /* distance to a limit [rad, m] below which the cost starts */
    PW_N
};

#define PR_LIMIT_TOL 1e-9 /* a value this far outside its limits still counts as inside */
#define PR_GRAIN 256      /* nodes per pool chunk */
#define PR_MAXB 2048      /* buckets per joint and layer in process_dp */
#define PR_DENSE_M 32     /* layers of at most this many nodes: every pair, no buckets */

/* ------------------------------------------------------------------ node costs */

/* The cost of one value at distance d from its nearest limit: ((m - d) / m)^2 inside
 * the margin m, 0 beyond it (a quadratic ramp from 1 at the limit). */
static inline double limit_ramp(double v, double lo, double hi, double margin)
{
    if (!(margin > 0.0))
        return 0.0;
    double d = v - lo < hi - v ? v - lo : hi - v;
    if (d >= margin)
        return 0.0;
    double r = (margin - (d > 0.0 ? d : 0.0)) / margin;
    return r * r;
}

/* The least limit_ramp over the whole-turn equivalents of an angle v inside
 * [lo, hi] (a circle coordinate: the turn is chosen later, the best one counts). */
static double limit_ramp_best(double v, double lo, double hi, double margin)
{
    const double tp = 2.0 * M_PI;
    if (!(margin > 0.0) || !(hi - lo < tp + 2.0 * margin))
        return 0.0; /* some turn is a margin away from both limits (or they are inf) */
    double k0 = ceil((lo - PR_LIMIT_TOL - v) / tp), k1 = floor((hi + PR_LIMIT_TOL - v) / tp);
    double best = INFINITY;
    for (double k = k0; k <= k1 && k <= k0 + 64.0; k += 1.0) {
        double r = limit_ramp(v + k * tp, lo, hi, margin);
        best = r < best ? r : best;
    }
    return isfinite(best) ? best : 1.0;
}

/* |det A| of k x k matrices on W lanes (a column-major: a[c k + r]; destroyed):
 * Householder QR, |det A| = prod_c |r_cc| = prod_c |A_c[c:]| after the earlier
 * reflections (stable without pivoting, so every lane runs the same operations). */
ALWAYS_INLINE vd abs_det_lanes(vd *a, int k)
{
    vd det = BR(1.0);
    for (int c = 0; c < k; c++) {
        vd *x = a + c * k, s = BR(0.0);
        for (int r = c; r < k; r++)
            s += x[r] * x[r];
        vd norm = vsqrt(s);
        det *= norm;
        /* v = x[c:] + sign(x_c) |x[c:]| e_1, v.v = 2 |x[c:]| (|x[c:]| + |x_c|) */
        vd v0 = x[c] + vsel(x[c] < BR(0.0), -norm, norm);
        vd vv = 2.0 * norm * (norm + vabs(x[c]));
        vl live = vv > BR(0.0);
        vd beta = vsel(live, 2.0 / vsel(live, vv, BR(1.0)), BR(0.0));
        for (int d = c + 1; d < k; d++) {
            vd *y = a + d * k, dot = v0 * y[c];
            for (int r = c + 1; r < k; r++)
                dot += x[r] * y[r];
            vd f = beta * dot;
            y[c] -= f * v0;
            for (int r = c + 1; r < k; r++)
                y[r] -= f * x[r];
        }
    }
    return det;
}

/* Yoshikawa's manipulability from Jacobians J (6 rows of MAXJ, n columns) on W
 * lanes: |det J| for n = 6, else sqrt(det(J J^T)) (n > 6) or sqrt(det(J^T J))
 * (n < 6), the formula of robokin.kinematics.jacobian.manipulability. */
ALWAYS_INLINE vd yoshikawa_lanes(const vd *J, int n)
{
    vd a[36];
    if (n == 6) {
        for (int c = 0; c < 6; c++)
            for (int r = 0; r < 6; r++)
                a[c * 6 + r] = J[r * MAXJ + c];
        return abs_det_lanes(a, 6);
    }
    int k = n < 6 ? n : 6;
    for (int r = 0; r < k; r++)
        for (int c = 0; c < k; c++) {
            vd s = BR(0.0);
            if (n > 6)
                for (int j = 0; j < n; j++)
                    s += J[r * MAXJ + j] * J[c * MAXJ + j];
            else
                for (int i = 0; i < 6; i++)
                    s += J[i * MAXJ + r] * J[i * MAXJ + c];
            a[c * k + r] = s;
        }
    return vsqrt(abs_det_lanes(a, k));
}

typedef struct {
    const Chain *ch;
    const double *Q;              /* P x n: IK solutions (NaN rows where not valid) */
    const npy_bool *valid;        /* P */
    const npy_bool *singular;     /* P: flagged singular by the IK */
    const unsigned char *mode;    /* n: PM_* */
    const double *w;              /* PW_N */
    double *Qc;                   /* P x n: canonical values */
    double *cost;                 /* P: inf where not usable */
    double *mu;                   /* P: relative manipulability (NaN where not computed) */
    signed char *code;            /* P: PN_* */
} NodeJob;

/* Canonical values of node i into Qc; its status before the singularity test. */
static int canonical(const NodeJob *job, long i, double *lim_cost)
{
    const Chain *ch = job->ch;
    const int n = ch->n;
    const double *q = job->Q + (size_t)i * n;
    double *o = job->Qc + (size_t)i * n;
    const double margin = job->w[PW_LIM_MARGIN];
    int status = job->valid[i] ? PN_OK : PN_NONE;
    double lc = 0.0;
    for (int j = 0; j < n; j++) {
        double v = q[j], lo = ch->lo[j], hi = ch->hi[j];
        if (!isfinite(v))
            status = PN_NONE;
        if (job->mode[j] == PM_CIRCLE) {
            v = wrap_pi(v);
            lc += limit_ramp_best(v, lo, hi, margin);
        } else {
            if (job->mode[j] == PM_TURN)
                v = wrap_into(v, lo, hi);
            if (status == PN_OK && (v < lo - PR_LIMIT_TOL || v > hi + PR_LIMIT_TOL))
                status = PN_LIMITS;
            lc += limit_ramp(v, lo, hi, margin);
        }
        o[j] = v;
    }
    *lim_cost = lc;
    return status;
}

/* Nodes b .. e - 1 (at most PR_GRAIN): canonical values and limits one by one, then
 * the Jacobians and manipulability of the nodes still usable, W at a time. */
static void nodes_block(NodeJob *job, long b, long e)
{
    const Chain *ch = job->ch;
    const int n = ch->n;
    const double *w = job->w;
    int live[PR_GRAIN], count = 0;
    double lim_cost[PR_GRAIN];
    for (long i = b; i < e; i++) {
        double lc;
        int status = canonical(job, i, &lc);
        job->code[i] = (signed char)status;
        job->mu[i] = NAN;
        job->cost[i] = INFINITY;
        if (status == PN_OK) {
            lim_cost[count] = lc;
            live[count++] = (int)(i - b);
        }
    }
    for (int p = 0; p < count; p += W) {
        int m = count - p < W ? count - p : W;
        vd q[MAXJ], t[12], J[6 * MAXJ];
        for (int j = 0; j < n; j++)
            for (int l = 0; l < W; l++)
                q[j][l] = job->Qc[(size_t)(b + live[p + (l < m ? l : 0)]) * n + j];
        chain_pose_jac(ch, q, t, J, MAXJ);
        vd mu = yoshikawa_lanes(J, n);
        for (int l = 0; l < m; l++) {
            long k = b + live[p + l];
            double rel = w[PW_MU_REF] > 0.0 ? mu[l] / w[PW_MU_REF] : 1.0;
            job->mu[k] = rel;
            if (job->singular[k] || rel < w[PW_SING_TOL]) {
                job->code[k] = PN_SINGULAR;
                continue;
            }
            double sm = w[PW_SING_MARGIN], c = w[PW_LIM_W] * lim_cost[p + l];
            if (sm > 0.0 && rel < sm)
                c += w[PW_SING_W] * ((sm - rel) / sm) * ((sm - rel) / sm);
            job->cost[k] = c;
        }
    }
}

static void nodes_range(void *ctx, long b, long e)
{
    for (long c = b; c < e; c += PR_GRAIN)
        nodes_block((NodeJob *)ctx, c, e - c < PR_GRAIN ? e : c + PR_GRAIN);
}

/* ------------------------------------------------------------------ the search */

/* The buckets of one joint: width >= max_step, the same for every layer (so a
 * node's bucket does not depend on the layer it is compared with); per layer the
 * usable nodes sorted into them (a counting sort). */
typedef struct {
    double base, inv_width;
    int nb, circle;
    int *start; /* nb + 1 offsets into order */
    int *order; /* node indices, by bucket, ascending within a bucket */
} Axis;

typedef struct {
    const double *Q;   /* L x M x n canonical values */
    const double *cost; /* L x M: inf where not usable */
    const unsigned char *circle; /* n: 1 where steps wrap */
    int M, n;
    double max_step, weight;
} Graph;

/* |b - a| for canonical values: a circle coordinate's both in [-pi, pi], so the
 * short way round is one turn at most away (wrap_pi without its floor). */
static inline double joint_step(double a, double b, int circle)
{
    double d = b - a;
    if (circle) {
        if (d >= M_PI)
            d -= 2.0 * M_PI;
        else if (d < -M_PI)
            d += 2.0 * M_PI;
    }
    return d < 0.0 ? -d : d;
}

static inline int bucket_of(const Axis *ax, double x)
{
    double f = floor((x - ax->base) * ax->inv_width);
    if (!(f >= 0.0))
        return 0;
    return f >= ax->nb ? ax->nb - 1 : (int)f;
}

/* The buckets of joint j over every usable node of the L layers. */
static void axis_setup(const Graph *g, long L, int j, Axis *ax)
{
    const int M = g->M, n = g->n;
    const double d = g->max_step;
    double nb, base, span;
    ax->circle = g->circle[j];
    if (ax->circle) {
        base = -M_PI;
        span = 2.0 * M_PI;
        nb = isfinite(d) ? floor(span / d) : 1.0;
    } else {
        double lo = INFINITY, hi = -INFINITY;
        for (size_t u = 0; u < (size_t)L * M; u++)
            if (isfinite(g->cost[u])) {
                double x = g->Q[u * n + j];
                lo = x < lo ? x : lo;
                hi = x > hi ? x : hi;
            }
        base = isfinite(lo) ? lo : 0.0;
        span = hi > lo ? hi - lo : 0.0;
        nb = isfinite(d) ? floor(span / d) + 1.0 : 1.0;
    }
    ax->nb = nb < 1.0 ? 1 : (nb > PR_MAXB ? PR_MAXB : (int)nb);
    ax->base = base;
    /* width = span / nb >= max_step (the cap only widens it); one bucket: any width */
    ax->inv_width = ax->nb > 1 ? ax->nb / span : 0.0;
}

/* Sort the usable nodes of layer s into ax's buckets. */
static void axis_fill(const Graph *g, long s, int j, Axis *ax)
{
    const int M = g->M, n = g->n;
    const double *Q = g->Q + (size_t)s * M * n, *c = g->cost + (size_t)s * M;
    for (int b = 0; b <= ax->nb; b++)
        ax->start[b] = 0;
    for (int u = 0; u < M; u++)
        if (isfinite(c[u]))
            ax->start[bucket_of(ax, Q[u * n + j]) + 1]++;
    for (int b = 0; b < ax->nb; b++)
        ax->start[b + 1] += ax->start[b];
    int fill[PR_MAXB];
    for (int b = 0; b < ax->nb; b++)
        fill[b] = ax->start[b];
    for (int u = 0; u < M; u++)
        if (isfinite(c[u]))
            ax->order[fill[bucket_of(ax, Q[u * n + j])]++] = u;
}

/* The bucket ranges holding every node within max_step of x along ax: up to two
 * [first, last] ranges (a circle's window may wrap); returns how many ranges, and
 * the number of nodes in them in *count. Buckets are at least max_step wide, so
 * the window is x's bucket and its two neighbours. */
static inline int window(const Axis *ax, double x, int *r0, int *r1, int *count)
{
    const int nb = ax->nb;
    int k = 1;
    if (nb <= 3) {
        r0[0] = 0;
        r1[0] = nb - 1;
    } else {
        int b = bucket_of(ax, x);
        if (!ax->circle || (b > 0 && b < nb - 1)) {
            r0[0] = b > 0 ? b - 1 : 0;
            r1[0] = b < nb - 1 ? b + 1 : nb - 1;
        } else if (b == 0) {
            r0[0] = 0; r1[0] = 1;
            r0[1] = nb - 1; r1[1] = nb - 1;
            k = 2;
        } else {
            r0[0] = b - 1; r1[0] = b;
            r0[1] = 0; r1[1] = 0;
            k = 2;
        }
    }
    int c = ax->start[r1[0] + 1] - ax->start[r0[0]];
    if (k == 2)
        c += ax->start[r1[1] + 1] - ax->start[r0[1]];
    *count = c;
    return k;
}

/* forbidden edges (layer, v, u) sorted ascending; pos advances monotonically */
typedef struct {
    const long long *e; /* F x 3: layer i, node u of layer i, node v of layer i + 1 */
    long F, pos;
} Forbidden;

static int is_forbidden(const Forbidden *fb, long first, long i, int u, int v)
{
    for (long p = first; p < fb->F && fb->e[3 * p] == i && fb->e[3 * p + 2] == v; p++)
        if (fb->e[3 * p + 1] == u)
            return 1;
    return 0;
}

/* The best predecessor so far of one target node. */
typedef struct {
    double best;
    int arg;
} Pull;

/* Candidate u (values x, path value vu) for the target y: kept when its edge is
 * allowed and it beats the best so far (ties to the smaller index). Joints are
 * checked `first` first; the partial step bounds the value, so a candidate that
 * cannot win stops early. Returns 0 when no later candidate of a list sorted by
 * (value, index) can win either. */
static inline int consider(const Graph *g, const double *x, const double *y, int first,
                           int u, double vu, Pull *pl, const Forbidden *fb, long i, int v,
                           int check_fb)
{
    if (vu > pl->best || (vu == pl->best && u > pl->arg))
        return 0;
    double step = joint_step(x[first], y[first], g->circle[first]);
    if (step > g->max_step)
        return 1;
    for (int j = 0; j < g->n; j++) {
        double s = joint_step(x[j], y[j], g->circle[j]);
        if (s > g->max_step)
            return 1;
        step = s > step ? s : step;
        double lb = vu + g->weight * step;
        if (lb > pl->best || (lb == pl->best && u > pl->arg))
            return 1;
    }
    double val = vu + g->weight * step;
    if ((val < pl->best || (val == pl->best && u < pl->arg)) &&
        !(check_fb && is_forbidden(fb, fb->pos, i, u, v))) {
        pl->best = val;
        pl->arg = u;
    }
    return 1;
}

/* The views of layers i (source s) and i + 1 (target t) both relax_* steps read:
 * nodes Qs, Qt (M x n), target costs ct, values Vs, Vt and target predecessors Pt. */
#define LAYER_PAIR(g, i, value, pred) \
    const int M = (g)->M, n = (g)->n; \
    const double *Qs = (g)->Q + (size_t)(i) * M * n, *Qt = Qs + (size_t)M * n; \
    const double *ct = (g)->cost + (size_t)((i) + 1) * M; \
    const double *Vs = (value) + (size_t)(i) * M; \
    double *Vt = (value) + (size_t)((i) + 1) * M; \
    int *Pt = (pred) + (size_t)((i) + 1) * M

/* Pull every node of layer i + 1 from layer i: through the buckets of `axes`, or,
 * without a step limit (dense), through the usable nodes of layer i sorted by
 * value (`byval`, count `nval`), which stops at the first that cannot win.
 * Returns the number of nodes of layer i + 1 reached. */
static long relax_layer(const Graph *g, long i, const Axis *axes, const int *byval,
                        int nval, double *value, int *pred, Forbidden *fb)
{
    LAYER_PAIR(g, i, value, pred);
    long reached = 0;
    for (int v = 0; v < M; v++) {
        Vt[v] = INFINITY;
        Pt[v] = -1;
        if (!isfinite(ct[v]))
            continue;
        const double *y = Qt + (size_t)v * n;
        while (fb->pos < fb->F &&
               (fb->e[3 * fb->pos] < i ||
                (fb->e[3 * fb->pos] == i && fb->e[3 * fb->pos + 2] < v)))
            fb->pos++;
        int check_fb = fb->pos < fb->F && fb->e[3 * fb->pos] == i && fb->e[3 * fb->pos + 2] == v;
        Pull pl = {INFINITY, -1};
        if (byval != NULL) {
            for (int p = 0; p < nval; p++) {
                int u = byval[p];
                if (!consider(g, Qs + (size_t)u * n, y, 0, u, Vs[u], &pl, fb, i, v, check_fb))
                    break;
            }
        } else {
            int best_j = 0, best_count = M + 1, r0[2] = {0, 0}, r1[2] = {-1, -1}, k = 0;
            for (int j = 0; j < n; j++) {
                int a0[2] = {0, 0}, a1[2] = {-1, -1}, count;
                int kk = window(&axes[j], y[j], a0, a1, &count);
                if (count < best_count) {
                    best_count = count;
                    best_j = j;
                    k = kk;
                    r0[0] = a0[0]; r1[0] = a1[0];
                    r0[1] = a0[1]; r1[1] = a1[1];
                }
                if (count == 0)
                    break;
            }
            const Axis *ax = &axes[best_j];
            for (int r = 0; r < k && best_count > 0; r++)
                for (int p = ax->start[r0[r]]; p < ax->start[r1[r] + 1]; p++) {
                    int u = ax->order[p];
                    consider(g, Qs + (size_t)u * n, y, best_j, u, Vs[u], &pl, fb, i, v,
                             check_fb);
                }
        }
        if (pl.arg >= 0) {
            Vt[v] = ct[v] + pl.best;
            Pt[v] = pl.arg;
            reached++;
        }
    }
    return reached;
}

/* Pull layer i + 1 from layer i over every pair of nodes (no step limit, or too
 * few nodes for buckets to pay), W targets at a time: sources in ascending index
 * order and a strict < keep the smallest index among equal values, as consider()
 * does. yT: scratch n x M (the targets' values, joint-major). No forbidden edges
 * may touch this layer (the caller checks). Returns the nodes reached. */
static long relax_dense(const Graph *g, long i, double *value, int *pred, double *yT)
{
    LAYER_PAIR(g, i, value, pred);
    const double tp = 2.0 * M_PI;
    for (int v = 0; v < M; v++)
        for (int j = 0; j < n; j++)
            yT[(size_t)j * M + v] = Qt[(size_t)v * n + j];
    long reached = 0;
    for (int v0 = 0; v0 < M; v0 += W) {
        int m = M - v0 < W ? M - v0 : W;
        vd y[MAXJ], best = BR(INFINITY), arg = BR(-1.0);
        for (int j = 0; j < n; j++)
            for (int l = 0; l < W; l++)
                y[j][l] = yT[(size_t)j * M + v0 + (l < m ? l : 0)];
        for (int u = 0; u < M; u++) {
            if (!isfinite(Vs[u]))
                continue;
            const double *x = Qs + (size_t)u * n;
            vd step = BR(0.0);
            for (int j = 0; j < n; j++) {
                vd d = y[j] - x[j];
                if (g->circle[j]) {
                    d = vsel(d >= BR(M_PI), d - tp, d);
                    d = vsel(d < BR(-M_PI), d + tp, d);
                }
                d = vabs(d);
                step = vsel(d > step, d, step);
            }
            vd val = Vs[u] + g->weight * step;
            vl take = (val < best) & (step <= BR(g->max_step));
            best = vsel(take, val, best);
            arg = vsel(take, BR((double)u), arg);
        }
        for (int l = 0; l < m; l++) {
            int v = v0 + l;
            Vt[v] = INFINITY;
            Pt[v] = -1;
            if (isfinite(ct[v]) && arg[l] >= 0.0) {
                Vt[v] = ct[v] + best[l];
                Pt[v] = (int)arg[l];
                reached++;
            }
        }
    }
    return reached;
}

typedef struct {
    double value;
    int index;
} Ranked;

static int ranked_cmp(const void *pa, const void *pb)
{
    const Ranked *a = (const Ranked *)pa, *b = (const Ranked *)pb;
    if (a->value != b->value)
        return a->value < b->value ? -1 : 1;
    return (a->index > b->index) - (a->index < b->index);
}

/* The usable (finite) nodes of a value row sorted by (value, index) into out
 * (scratch: M Ranked); returns how many. */
static int sort_by_value(const double *row, int M, Ranked *scratch, int *out)
{
    int k = 0;
    for (int u = 0; u < M; u++)
        if (isfinite(row[u])) {
            scratch[k].value = row[u];
            scratch[k++].index = u;
        }
    qsort(scratch, (size_t)k, sizeof(Ranked), ranked_cmp);
    for (int p = 0; p < k; p++)
        out[p] = scratch[p].index;
    return k;
}

/* Layer s's usable nodes start a segment: value = start (layer 0) or cost. */
static long start_layer(const Graph *g, long s, const double *start, double *value,
                        int *pred)
{
    const int M = g->M;
    const double *c = g->cost + (size_t)s * M;
    long usable = 0;
    for (int u = 0; u < M; u++) {
        pred[(size_t)s * M + u] = -1;
        if (isfinite(c[u])) {
            value[(size_t)s * M + u] = c[u] + (start != NULL ? start[u] : 0.0);
            usable++;
        } else {
            value[(size_t)s * M + u] = INFINITY;
        }
    }
    return usable;
}

/* The index of the least finite value of row (ties: the first), or -1. */
static int argmin_row(const double *row, int M)
{
    int arg = -1;
    for (int u = 0; u < M; u++)
        if (isfinite(row[u]) && (arg < 0 || row[u] < row[arg]))
            arg = u;
    return arg;
}

/* The whole search: forward pass, then the backtrack of every segment into
 * choice (L). restart[s] = 1 where a segment starts (s > 0 only where layer s - 1
 * was reachable or empty and no edge reaches layer s). Returns 0, or -1 when out
 * of memory. */
static int layered_search(const Graph *g, long L, const double *start, Forbidden *fb,
                          double *value, int *pred, unsigned char *restart, int *choice)
{
    const int M = g->M, n = g->n;
    Axis axes[MAXJ];
    int *mem = (int *)malloc(sizeof(int) * ((size_t)n * ((PR_MAXB + 1) + (size_t)M) + M));
    if (mem == NULL)
        return -1;
    int dense = !isfinite(g->max_step) || M <= PR_DENSE_M, *byval = mem + (size_t)n * (PR_MAXB + 1 + M);
    Ranked *scratch = dense ? (Ranked *)malloc(sizeof(Ranked) * (size_t)M) : NULL;
    double *yT = dense ? (double *)malloc(sizeof(double) * (size_t)M * n) : NULL;
    if (dense && (scratch == NULL || yT == NULL)) {
        free(mem);
        free(scratch);
        free(yT);
        return -1;
    }
    for (int j = 0; j < n; j++) {
        axes[j].start = mem + (size_t)j * (PR_MAXB + 1 + M);
        axes[j].order = axes[j].start + PR_MAXB + 1;
    }
    for (int j = 0; j < n; j++)
        axis_setup(g, L, j, &axes[j]);
    start_layer(g, 0, start, value, pred);
    restart[0] = 1;
    for (long i = 0; i + 1 < L; i++) {
        int nval = 0;
        long reached;
        while (fb->pos < fb->F && fb->e[3 * fb->pos] < i)
            fb->pos++;
        int edges_here = fb->pos < fb->F && fb->e[3 * fb->pos] == i;
        if (dense && !edges_here) {
            reached = relax_dense(g, i, value, pred, yT);
        } else {
            if (dense)
                nval = sort_by_value(value + (size_t)i * M, M, scratch, byval);
            else
                for (int j = 0; j < n; j++)
                    axis_fill(g, i, j, &axes[j]);
            reached = relax_layer(g, i, axes, dense ? byval : NULL, nval, value, pred, fb);
        }
        restart[i + 1] = 0;
        if (reached == 0) {
            start_layer(g, i + 1, NULL, value, pred);
            restart[i + 1] = 1;
        }
    }
    free(mem);
    free(scratch);
    free(yT);
    /* backtrack: every segment from its last layer */
    long end = L - 1;
    while (end >= 0) {
        long s = end;
        while (!restart[s])
            s--;
        int u = argmin_row(value + (size_t)end * M, M);
        for (long i = end; i >= s; i--) {
            choice[i] = u;
            if (u >= 0)
                u = pred[(size_t)i * M + u];
        }
        end = s - 1;
    }
    return 0;
}

/* ------------------------------------------------------- clusters (order) */

typedef struct {
    const double *Q;             /* P x M x n canonical values */
    const double *cost;          /* P x M: inf where not usable */
    const unsigned char *circle; /* n */
    int P, M, n;
    double *out;                 /* P x P */
} ClusterJob;

/* Row i of the cluster distances: min over usable u of i, v of j of the largest
 * joint change (joint_step), for every j > i (and mirrored). */
static void clusters_range(void *ctx, long b, long e)
{
    ClusterJob *job = (ClusterJob *)ctx;
    const int P = job->P, M = job->M, n = job->n;
    for (long i = b; i < e; i++) {
        job->out[(size_t)i * P + i] = 0.0;
        const double *Qi = job->Q + (size_t)i * M * n, *ci = job->cost + (size_t)i * M;
        for (long j = i + 1; j < P; j++) {
            const double *Qj = job->Q + (size_t)j * M * n, *cj = job->cost + (size_t)j * M;
            double best = INFINITY;
            for (int u = 0; u < M; u++) {
                if (!isfinite(ci[u]))
                    continue;
                const double *x = Qi + (size_t)u * n;
                for (int v = 0; v < M; v++) {
                    if (!isfinite(cj[v]))
                        continue;
                    const double *y = Qj + (size_t)v * n;
                    double step = 0.0;
                    int k = 0;
                    for (; k < n; k++) {
                        double s = joint_step(x[k], y[k], job->circle[k]);
                        if (s >= best)
                            break;
                        step = s > step ? s : step;
                    }
                    if (k == n)
                        best = step;
                }
            }
            job->out[(size_t)i * P + j] = best;
            job->out[(size_t)j * P + i] = best;
        }
    }
}

typedef struct {
    const double *A, *B;         /* a x n, b x n */
    const unsigned char *circle; /* n */
    long b;
    int n;
    double *out;                 /* a x b */
} PairJob;

/* Rows of the pairwise largest joint changes (joint_step). */
static void pairs_range(void *ctx, long r0, long r1)
{
    PairJob *job = (PairJob *)ctx;
    const int n = job->n;
    for (long r = r0; r < r1; r++) {
        const double *x = job->A + (size_t)r * n;
        for (long c = 0; c < job->b; c++) {
            const double *y = job->B + (size_t)c * n;
            double step = 0.0;
            for (int j = 0; j < n; j++) {
                double s = joint_step(x[j], y[j], job->circle[j]);
                step = s > step ? s : step;
            }
            job->out[(size_t)r * job->b + c] = step;
        }
    }
}

/* ------------------------------------------------------------ Python bindings */

/* every coordinate's mode known, and turn modes only where the coordinate wraps */
static int pr_modes_ok(const Chain *ch, const unsigned char *mode)
{
    for (int j = 0; j < ch->n; j++)
        if (mode[j] > PM_CIRCLE || (mode[j] != PM_PLAIN && ch->wrap[j] != 1.0))
            return 0;
    return 1;
}

/* forbidden edges (F, 3) = (layer, u, v): inside (L - 1, M, M), sorted by (layer, v) */
static int pr_forbidden_ok(const long long *e, npy_intp F, npy_intp L, npy_intp M)
{
    for (npy_intp p = 0; p < F; p++) {
        if (e[3 * p] < 0 || e[3 * p] >= L - 1 || e[3 * p + 1] < 0 || e[3 * p + 1] >= M ||
            e[3 * p + 2] < 0 || e[3 * p + 2] >= M)
            return 0;
        if (p > 0 && (e[3 * p] < e[3 * p - 3] ||
                      (e[3 * p] == e[3 * p - 3] && e[3 * p + 2] < e[3 * p - 1])))
            return 0;
    }
    return 1;
}

/* canonical values, status, relative manipulability and cost of every node */
static PyObject *process_nodes_body(const process_nodes_args *a)
{
    NodeJob job = {&a->packed, a->Q, a->valid, a->singular, a->mode, a->weights, a->Qc,
                   a->cost, a->mu, a->code};
    Py_BEGIN_ALLOW_THREADS
    pool_for((long)a->P, PR_GRAIN, nodes_range, &job);
    Py_END_ALLOW_THREADS
    Py_RETURN_NONE;
}

/* the exact layered shortest path -> segments */
static PyObject *process_dp_body(const process_dp_args *a)
{
    Graph g = {a->Q, a->cost, a->circle, (int)a->M, (int)a->n, a->max_step, a->weight};
    Forbidden fb = {a->forbidden, (long)a->F, 0};
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = layered_search(&g, (long)a->L, a->start, &fb, a->value, a->pred, a->restart,
                        a->choice);
    Py_END_ALLOW_THREADS
    if (rc < 0)
        return PyErr_NoMemory();
    long segments = 0;
    for (npy_intp s = 0; s < a->L; s++)
        segments += a->restart[s];
    return PyLong_FromLong(segments);
}

/* the least largest-joint-change between the usable nodes of every two layers */
static PyObject *process_clusters_body(const process_clusters_args *a)
{
    ClusterJob job = {a->Q, a->cost, a->circle, (int)a->P, (int)a->M, (int)a->n, a->out};
    Py_BEGIN_ALLOW_THREADS
    pool_for((long)a->P, 1, clusters_range, &job);
    Py_END_ALLOW_THREADS
    Py_RETURN_NONE;
}

/* the largest joint change between every row of A and every row of B */
static PyObject *process_pairs_body(const process_pairs_args *a)
{
    PairJob job = {a->A, a->B, a->circle, (long)a->nb, (int)a->n, a->out};
    long grain = a->nb > 0 ? 1 + 4096 / (long)a->nb : 1;
    Py_BEGIN_ALLOW_THREADS
    pool_for((long)a->na, grain, pairs_range, &job);
    Py_END_ALLOW_THREADS
    Py_RETURN_NONE;
}

/* limit_ramp per value (the limit cost process_nodes adds up) */
static PyObject *process_limit_cost_body(const process_limit_cost_args *a)
{
    for (npy_intp i = 0; i < a->P; i++)
        a->out[i] = limit_ramp(a->values[i], a->lo, a->hi, a->margin);
    Py_RETURN_NONE;
}
