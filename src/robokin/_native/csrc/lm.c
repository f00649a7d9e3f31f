/*
 * Numeric IK: Levenberg-Marquardt descents with limits and restarts, W targets
 * per vector (one per lane; lanes.h). The algorithm (robokin.kinematics.ik.numeric
 * describes it for users):
 *
 *   e = [p_t - p(q); log(R_t R(q)^T)],  E = e^T W e,  lambda = mu E
 *   dq = Jw^T (Jw Jw^T + lambda I)^-1 W^1/2 e,  Jw = W^1/2 J (selected task rows)
 *
 * mu falls (mu_down) after an accepted step, grows (mu_up) after a rejected one;
 * trial points are projected into the limits (2 pi periodic coordinates first by
 * whole turns) and joints the gradient presses into a limit leave the active set.
 * A descent that converges, stalls or runs out of iterations ends its attempt;
 * the next attempt of a target starts from the seed table, then random seeds.
 *
 * Every step each lane makes one trial (or evaluates the start of a new descent)
 * with the arithmetic on all lanes at once; then each lane's bookkeeping (accept
 * or reject, convergence, stall, next seed, next target) runs per lane. A lane
 * whose target is done takes the next one from a queue the pool's threads share,
 * so lanes never wait for each other. A single target uses lane 0 (the idle lanes
 * cost nothing on a vector unit); a path runs one target after the other, each
 * from the previous solution.
 *
 * References:
 *   Sugihara, T. "Solvability-unconcerned inverse kinematics by the
 *   Levenberg-Marquardt method", IEEE Trans. Robotics 27(5), 2011 (eq. 20).
 *   Nocedal, J. and Wright, S. "Numerical Optimization", 2nd ed., ch. 10.3, 16.7.
 */
#include <string.h>

#include "chain.h"
#include "pool.h"

#define NMAX MAXJ
#define TAB_K_MAX 8 /* most seed-table restarts per target */

/* opts[]: the option vector robokin.kinematics.ik.numeric fills; its indices
 * (O_*, N_OPTS) and every entry's range are declared in ../_declare.py (LM_OPTS) and
 * generated into kernels_args.gen.h, whose entry points check them. */
/* out rows: q (n), then these columns */
enum { R_ERR = 0 /* combined residual norm [m, rad] */, R_EP = 1, R_ER = 2, R_ITERS = 3,
       R_RESTARTS = 4, R_CODE = 5, N_RES = 6 };
enum { CODE_OK = 0, CODE_ITER = 1 /* iterations of the last attempt ran out */,
       CODE_STALL = 2 /* a local minimum or pinned at limits */, CODE_BAD_TARGET = 3,
       CODE_JUMP = 4 /* path: joint jump larger than allowed */,
       CODE_NOT_RUN = 5 /* path: after an earlier failure */, CODE_BAD_Q0 = 6 };
/* the task rows opts selects (weights above 0) */
static int lm_mask_rows(const double *opts)
{
    int m = 0;
    for (int i = 0; i < 6; i++)
        m += opts[O_W + i] > 0.0;
    return m;
}

/* whether a seed-table grid description gdat (7,) has G = gdat[6] cells a side
 * (1 to 1024) and cstart the G^3 + 1 entries of its cells */
static int grid_fits(const double *gdat, npy_intp cstart_len)
{
    double G = gdat[6];
    return G >= 1.0 && G <= 1024.0 && G == floor(G) &&
           cstart_len == (npy_intp)(G * G * G) + 1;
}

#define MU_MAX 1e9
#define MU_MIN 1e-9

enum { MODE_IDLE = 0, MODE_INIT = 1, MODE_RUN = 2 };

static const vd ZERO = {0.0};
#define ONE BR(1.0)
#define ZERO_L BRL(0)
#define ONES_L BRL(-1)

typedef struct {
    const Chain *ch;
    const double *targets, *q0, *seeds, *opts, *tab, *gdat;
    const long long *cstart;
    double *out;
    long N, R, tab_cols, M;
    int n_seeds, n_tab, max_iter, check_every;
    int bad_table; /* a table cell read was outside [0, M] or decreasing (atomic) */
    double mid[NMAX];
    long next; /* the queue: next target index (atomic) */
} Ctx;

typedef struct {
    /* accepted state of each lane's descent, lane-wise */
    vd q[NMAX], J[6 * NMAX], e[6], cost, ep, er, mu;
    vd qinit[NMAX]; /* start of a new descent (INIT lanes) */
    vd Tt[12];      /* target, top 3x4 row-major */
    /* per-lane bookkeeping */
    long tgt[W];
    int mode[W], attempt[W], it[W], next_check[W], total[W], restarts[W], code[W];
    int tab_found[W], tidx[W][TAB_K_MAX];
    double cost_ref[W], best_cost[W], bep[W], ber[W], best[W][NMAX];
    int start; /* 0: the first attempt starts from q0 */
} Lanes;

static void project(double *q, const Chain *ch)
{
    for (int j = 0; j < ch->n; j++) {
        double lo = ch->lo[j], hi = ch->hi[j], v = q[j];
        if (ch->wrap[j] == 1.0)
            v = wrap_into(v, lo, hi);
        if (v > hi)
            v = hi;
        else if (v < lo)
            v = lo;
        q[j] = v;
    }
}

/* The k = n_tab seed-table rows nearest the target (Tt: top 3x4 row-major) into
 * idx; returns how many were found. Distance |p - p_t|^2 + rot_w |R - R_t|_F^2,
 * searched over the grid cells within Chebyshev radius 1 of the target's cell
 * (wider until k rows are found). The rows of the M-row table a cell names are
 * checked where they are read (0 <= cstart[cell] <= cstart[cell + 1] <= M, else
 * -1): lm_solve passes the table on every call, and scanning all G^3 + 1 cell
 * starts at its entry cost ~1.2 us a call (~10 % of a single solve). */
static int table_nearest(const double *tab, long tab_cols, long M, const long long *cstart,
                         const double *g, int k, double rot_w, const double *Tt, int *idx)
{
    double dist[TAB_K_MAX];
    int G = (int)g[6];
    int c[3];
    for (int a = 0; a < 3; a++) {
        int v = (int)floor((Tt[4 * a + 3] - g[a]) * g[3 + a]);
        c[a] = v < 0 ? 0 : (v > G - 1 ? G - 1 : v);
    }
    int found = 0, r = 1, r_prev = -1;
    for (;;) {
        for (int ix = c[0] - r > 0 ? c[0] - r : 0; ix <= (c[0] + r < G - 1 ? c[0] + r : G - 1); ix++)
            for (int iy = c[1] - r > 0 ? c[1] - r : 0; iy <= (c[1] + r < G - 1 ? c[1] + r : G - 1); iy++)
                for (int iz = c[2] - r > 0 ? c[2] - r : 0; iz <= (c[2] + r < G - 1 ? c[2] + r : G - 1); iz++) {
                    if (abs(ix - c[0]) <= r_prev && abs(iy - c[1]) <= r_prev &&
                        abs(iz - c[2]) <= r_prev)
                        continue; /* scanned at the smaller radius */
                    long cell = ((long)ix * G + iy) * G + iz;
                    long first = cstart[cell], end = cstart[cell + 1];
                    if (first < 0 || end > M || first > end)
                        return -1;
                    for (long row = first; row < end; row++) {
                        const double *t = tab + row * tab_cols;
                        double dx = t[0] - Tt[3], dy = t[1] - Tt[7], dz = t[2] - Tt[11];
                        double d = dx * dx + dy * dy + dz * dz;
                        if (rot_w > 0.0) {
                            double sr = 0.0;
                            for (int a = 0; a < 3; a++)
                                for (int b = 0; b < 3; b++) {
                                    double u = t[3 + 3 * a + b] - Tt[4 * a + b];
                                    sr += u * u;
                                }
                            d += rot_w * sr;
                        }
                        int pos;
                        if (found < k)
                            pos = found++;
                        else if (d < dist[k - 1])
                            pos = k - 1;
                        else
                            continue;
                        while (pos > 0 && dist[pos - 1] > d) {
                            dist[pos] = dist[pos - 1];
                            idx[pos] = idx[pos - 1];
                            pos--;
                        }
                        dist[pos] = d;
                        idx[pos] = (int)row;
                    }
                }
        if (found >= k || r >= G)
            return found;
        r_prev = r;
        r++;
    }
}

/* The target of lane l is done: its best configuration and the result columns. */
static void lane_write(const Ctx *cx, const Lanes *L, int l)
{
    const int n = cx->ch->n;
    double *out = cx->out + (size_t)L->tgt[l] * (n + N_RES);
    for (int j = 0; j < n; j++)
        out[j] = L->best[l][j];
    double bep = L->bep[l], ber = L->ber[l];
    out[n + R_ERR] = sqrt(bep * bep + ber * ber);
    out[n + R_EP] = bep;
    out[n + R_ER] = ber;
    out[n + R_ITERS] = L->total[l];
    out[n + R_RESTARTS] = L->restarts[l];
    out[n + R_CODE] = L->code[l];
}

/* Start descent attempt a of lane l: a = 0 from q0, then the seed-table rows, then
 * random seeds (alternately from the central part of the seed range, where descents
 * meet limits less often, and from all of it); returns 0 when the target has no
 * attempt left. */
static inline int lane_next_attempt(const Ctx *cx, Lanes *L, int l)
{
    const int n = cx->ch->n;
    int a = ++L->attempt[l];
    if (a > cx->n_seeds)
        return 0;
    long i = L->tgt[l];
    const double *seeds = cx->seeds + (size_t)i * cx->R * n;
    double q[NMAX];
    if (a == 0) {
        const double *q0 = cx->q0 + (size_t)i * n;
        for (int j = 0; j < n; j++)
            q[j] = q0[j];
    } else if (a <= cx->n_tab && L->tab_found[l] != 0) {
        if (L->tab_found[l] < 0) {
            double Tt[12];
            for (int r = 0; r < 12; r++)
                Tt[r] = L->Tt[r][l];
            int found = table_nearest(cx->tab, cx->tab_cols, cx->M, cx->cstart, cx->gdat,
                                      cx->n_tab, cx->opts[O_TABLE_ROT], Tt, L->tidx[l]);
            if (found < 0) { /* a bad table: random seeds instead, lm_solve refuses it */
                __atomic_store_n((int *)&cx->bad_table, 1, __ATOMIC_RELAXED); /* cx: not const */
                found = 0;
            }
            L->tab_found[l] = found;
        }
        if (a > L->tab_found[l]) {
            for (int j = 0; j < n; j++)
                q[j] = cx->ch->seed_lo[j] + seeds[(size_t)(a - 1) * n + j] *
                       (cx->ch->seed_hi[j] - cx->ch->seed_lo[j]);
        } else {
            const double *row = cx->tab + (size_t)L->tidx[l][a - 1] * cx->tab_cols;
            for (int j = 0; j < n; j++)
                q[j] = row[12 + j];
        }
        if (a > 1 || L->start == 0)
            L->restarts[l]++;
    } else {
        /* three seed distributions in turn: the central part of the seed range
         * (descents from there meet limits less often), all of it uniformly, and
         * the arcsine law (most of its mass near the ends: solutions with joints
         * pressed against their limits, which descents from inside the range
         * often stall short of) */
        double lo_f = 0.0, span_f = 1.0;
        int edges = a % 3 == 0;
        if (a % 3 == 1) {
            lo_f = cx->opts[O_SEED_SHRINK];
            span_f = 1.0 - 2.0 * lo_f;
        }
        for (int j = 0; j < n; j++) {
            double v = seeds[(size_t)(a - 1) * n + j];
            double u = edges ? 0.5 - 0.5 * cos(M_PI * v) : lo_f + span_f * v;
            q[j] = cx->ch->seed_lo[j] + u * (cx->ch->seed_hi[j] - cx->ch->seed_lo[j]);
        }
        if (a > 1 || L->start == 0)
            L->restarts[l]++;
    }
    project(q, cx->ch);
    for (int j = 0; j < n; j++)
        L->qinit[j][l] = q[j];
    L->mode[l] = MODE_INIT;
    return 1;
}

/* Lane l takes targets from the queue until one needs solving (bad inputs are
 * answered at once); idle when the queue is empty. */
static inline void lane_load(Ctx *cx, Lanes *L, int l)
{
    const int n = cx->ch->n;
    for (;;) {
        long i = __atomic_fetch_add(&cx->next, 1, __ATOMIC_RELAXED);
        if (i >= cx->N) {
            L->mode[l] = MODE_IDLE;
            L->tgt[l] = -1;
            for (int j = 0; j < n; j++)
                L->qinit[j][l] = cx->mid[j];
            return;
        }
        const double *Tt = cx->targets + (size_t)i * 16;
        const double *q0 = cx->q0 + (size_t)i * n;
        int bad = 0;
        if (pose_problem(Tt, POSE_ROW_TOL, POSE_ORTH_TOL))
            bad = CODE_BAD_TARGET;
        else if (cx->opts[O_USE_Q0] == 1.0) {
            for (int j = 0; j < n; j++)
                if (!isfinite(q0[j]))
                    bad = CODE_BAD_Q0;
        }
        if (bad) {
            double *out = cx->out + (size_t)i * (n + N_RES);
            for (int j = 0; j < n; j++)
                out[j] = 0.0;
            out[n + R_ERR] = INFINITY;
            out[n + R_EP] = INFINITY;
            out[n + R_ER] = INFINITY;
            out[n + R_ITERS] = 0;
            out[n + R_RESTARTS] = 0;
            out[n + R_CODE] = bad;
            continue;
        }
        L->tgt[l] = i;
        for (int r = 0; r < 12; r++)
            L->Tt[r][l] = Tt[r];
        L->tab_found[l] = -1;
        L->best_cost[l] = INFINITY;
        L->bep[l] = INFINITY;
        L->ber[l] = INFINITY;
        L->total[l] = 0;
        L->restarts[l] = 0;
        L->code[l] = CODE_STALL;
        for (int j = 0; j < n; j++)
            L->best[l][j] = cx->mid[j]; /* reported only if no attempt runs */
        L->attempt[l] = L->start - 1;
        if (lane_next_attempt(cx, L, l))
            return;
        lane_write(cx, L, l); /* no attempt at all (n_seeds < start) */
    }
}

/* The attempt of lane l ended with `code` after `it` iterations: keep the best,
 * then start the next attempt, or write the target's result and load another. */
static inline void lane_end_attempt(Ctx *cx, Lanes *L, int l, int code, int it)
{
    const int n = cx->ch->n;
    double cost = L->cost[l];
    L->total[l] += it;
    if (cost < L->best_cost[l] || code == CODE_OK || L->attempt[l] == L->start) {
        L->best_cost[l] = cost;
        L->bep[l] = L->ep[l];
        L->ber[l] = L->er[l];
        for (int j = 0; j < n; j++)
            L->best[l][j] = L->q[j][l];
    }
    L->code[l] = code;
    if (code != CODE_OK && lane_next_attempt(cx, L, l))
        return;
    lane_write(cx, L, l);
    lane_load(cx, L, l);
}

/* Top of the descent loop after an accepted step (or the start): converged, out
 * of iterations, or stalled (the cost has not fallen below stall_ratio times its
 * value check_every iterations before) ends the attempt. */
static inline void lane_top(Ctx *cx, Lanes *L, int l)
{
    int it = L->it[l];
    if (L->ep[l] <= cx->opts[O_TOL_P] && L->er[l] <= cx->opts[O_TOL_R]) {
        lane_end_attempt(cx, L, l, CODE_OK, it);
        return;
    }
    if (it >= cx->max_iter) {
        lane_end_attempt(cx, L, l, CODE_ITER, it);
        return;
    }
    if (it >= L->next_check[l]) {
        if (L->cost[l] > cx->opts[O_STALL_RATIO] * L->cost_ref[l]) {
            lane_end_attempt(cx, L, l, CODE_STALL, it);
            return;
        }
        L->cost_ref[l] = L->cost[l];
        L->next_check[l] = it + cx->check_every;
    }
}

/* Solve the k x k system A x = b in place (x into b) for SPD A (lower triangle
 * read, overwritten with L D) by L D L^T, per lane; lanes where A is not SPD get
 * 0 in the returned mask. */
ALWAYS_INLINE vl ldl_solve(vd (*A)[NMAX], vd *b, int k)
{
    vd dinv[NMAX];
    vl ok = ONES_L;
    for (int j = 0; j < k; j++) {
        vd s = A[j][j];
        for (int i = 0; i < j; i++)
            s -= A[j][i] * A[j][i] * dinv[i];
        ok &= (s > 0.0);
        dinv[j] = 1.0 / vsel(s > 0.0, s, ONE);
        for (int i = j + 1; i < k; i++) {
            vd t = A[i][j];
            for (int r = 0; r < j; r++)
                t -= A[i][r] * A[j][r] * dinv[r];
            A[i][j] = t;
        }
    }
    for (int i = 0; i < k; i++) {
        vd t = b[i];
        for (int r = 0; r < i; r++)
            t -= A[i][r] * dinv[r] * b[r];
        b[i] = t;
    }
    for (int i = k - 1; i >= 0; i--) {
        vd di = dinv[i];
        vd t = b[i] * di;
        for (int r = i + 1; r < k; r++)
            t -= A[r][i] * di * b[r];
        b[i] = t;
    }
    return ok;
}

/* The lower triangle of the damped Gram matrix A = V V^T + lam I (k x k) of k vectors
 * of length len: the rows of Jw (by_cols 0: Jw Jw^T) or its columns (by_cols 1:
 * Jw^T Jw). by_cols is a constant at both calls, so each inlined copy indexes Jw as
 * the 2-D array it is: a flat x[r * step + t * stride] form cost lm_worker ~10 % more
 * instructions (callgrind, AVX2 copy, same iterations). */
ALWAYS_INLINE void damped_gram(vd (*Jw)[NMAX], int k, int len, int by_cols, vd lam,
                               vd (*A)[NMAX])
{
    for (int r = 0; r < k; r++) {
        for (int c = 0; c <= r; c++) {
            vd s = ZERO;
            for (int t = 0; t < len; t++)
                s += by_cols ? Jw[t][r] * Jw[t][c] : Jw[r][t] * Jw[c][t];
            A[r][c] = s;
        }
        A[r][r] += lam;
    }
}

/* The task-space step dq = Jw^T (Jw Jw^T + lam I)^-1 ye for m task rows, per lane.
 * Frozen joints have zero columns, so this is also the joint-space step when
 * fewer joints than task rows are free (the same step in exact arithmetic). */
ALWAYS_INLINE vl task_space_step(vd (*Jw)[NMAX], const vd *ye, vd lam, int n, int m,
                                 vd *dq)
{
    vd A[NMAX][NMAX], y[6];
    damped_gram(Jw, m, n, 0, lam, A); /* Jw Jw^T + lam I */
    for (int a = 0; a < m; a++)
        y[a] = ye[a];
    vl ok = ldl_solve(A, y, m);
    for (int j = 0; j < n; j++) {
        vd s = ZERO;
        for (int a = 0; a < m; a++)
            s += Jw[a][j] * y[a];
        dq[j] = s;
    }
    return ok;
}

static void lm_worker(Ctx *cx)
{
    const int n = cx->ch->n;
    const double *opts = cx->opts;
    const Chain *ch = cx->ch;
    /* the selected task rows (weight > 0) and their square-root weights */
    double w[6], sw[6];
    int rows[6], m = 0;
    for (int a = 0; a < 6; a++) {
        w[a] = opts[O_W + a];
        if (w[a] > 0.0) {
            rows[m] = a;
            sw[m] = sqrt(w[a]);
            m++;
        }
    }
    const double max_step = opts[O_MAX_STEP], mu0 = opts[O_MU0];
    const double mu_down = opts[O_MU_DOWN], mu_up = opts[O_MU_UP];
    Lanes L;
    memset(&L, 0, sizeof(L));
    L.start = opts[O_USE_Q0] == 1.0 ? 0 : 1;
    for (int l = 0; l < W; l++) {
        for (int j = 0; j < NMAX; j++) {
            L.q[j][l] = 0.0;
            L.qinit[j][l] = 0.0;
        }
        lane_load(cx, &L, l);
    }
    vd Jn[6 * NMAX], Tn[12], en[6], Jw[6][NMAX], qn[NMAX], ye[6];
    for (;;) {
        int busy = 0;
        for (int l = 0; l < W; l++)
            busy |= (L.mode[l] != MODE_IDLE);
        if (!busy)
            return;
        /* weighted task rows; joints pushed into a limit by the gradient Jw^T ye
         * leave the active set */
        vl nfree = (vl)ZERO_L;
        for (int a = 0; a < m; a++) {
            ye[a] = sw[a] * L.e[rows[a]];
            for (int j = 0; j < n; j++)
                Jw[a][j] = sw[a] * L.J[rows[a] * NMAX + j];
        }
        for (int j = 0; j < n; j++) {
            /* a joint whose range is a whole turn or more passes a limit by
             * wrapping (project); any other stops there */
            if (ch->wrap[j] == 0.0 || ch->hi[j] - ch->lo[j] < 2.0 * M_PI) {
                vl hi = L.q[j] >= ch->hi[j];
                vl lo = L.q[j] <= ch->lo[j];
                vl at = hi | lo;
                int any = 0;
                for (int l = 0; l < W; l++)
                    any |= (at[l] != 0);
                if (any) {
                    vd gj = ZERO;
                    for (int a = 0; a < m; a++)
                        gj += Jw[a][j] * ye[a];
                    vl frz = (hi & (gj > 0.0)) | (lo & (gj < 0.0));
                    for (int a = 0; a < m; a++)
                        Jw[a][j] = vsel(frz, ZERO, Jw[a][j]);
                    nfree += 1 + frz; /* frz is -1 where frozen */
                    continue;
                }
            }
            nfree += 1;
        }
        for (int l = 0; l < W; l++)
            if (L.mode[l] == MODE_RUN && nfree[l] == 0)
                lane_end_attempt(cx, &L, l, CODE_STALL, L.it[l]);
        vd lam = L.mu * L.cost + 1e-14;
        vd dq[NMAX];
        vl ok;
        if (m <= n) {
            /* (a constant 6 lets the compiler unroll the full-pose case) */
            if (m == 6)
                ok = task_space_step(Jw, ye, lam, n, 6, dq);
            else
                ok = task_space_step(Jw, ye, lam, n, m, dq);
        } else {
            /* joint space (more task rows than joints): (Jw^T Jw + lam I) dq = Jw^T ye */
            vd A[NMAX][NMAX];
            damped_gram(Jw, n, m, 1, lam, A); /* Jw^T Jw + lam I */
            for (int i = 0; i < n; i++) {
                vd g = ZERO;
                for (int a = 0; a < m; a++)
                    g += Jw[a][i] * ye[a];
                dq[i] = g;
            }
            ok = ldl_solve(A, dq, n);
        }
        vd big = ZERO;
        for (int j = 0; j < n; j++) {
            vd ad = vabs(dq[j]);
            big = vsel(ad > big, ad, big);
        }
        vd scale = vsel(big > max_step, max_step / vsel(big > max_step, big, ONE),
                            ONE);
        vl fresh = (vl)ZERO_L; /* lanes evaluating a new start, or idle */
        vl running = (vl)ZERO_L;
        for (int l = 0; l < W; l++) {
            fresh[l] = L.mode[l] != MODE_RUN ? -1 : 0;
            running[l] = L.mode[l] == MODE_RUN ? -1 : 0;
        }
        for (int j = 0; j < n; j++)
            qn[j] = vsel(fresh, L.qinit[j], L.q[j] + scale * dq[j]);
        /* project into the limits (2*pi-periodic coordinates first by whole turns) */
        for (int j = 0; j < n; j++) {
            double lo = ch->lo[j], hi = ch->hi[j];
            vd v = qn[j];
            if (ch->wrap[j] == 1.0) {
                vl above = v > hi, below = v < lo;
                int any = 0;
                for (int l = 0; l < W; l++)
                    any |= ((above[l] | below[l]) != 0);
                if (any)
                    for (int l = 0; l < W; l++)
                        v[l] = wrap_into(v[l], lo, hi);
            }
            v = vsel(v > hi, BR(hi), v);
            v = vsel(v < lo, BR(lo), v);
            qn[j] = v;
        }
        chain_pose_jac(ch, qn, Tn, Jn, NMAX);
        pose_residual(Tn, L.Tt, en, running | fresh);
        /* (as _errors: over the selected rows only) */
        vd cost_n = ZERO, ep2 = ZERO, er2 = ZERO;
        for (int a = 0; a < 3; a++)
            if (w[a] > 0.0) {
                cost_n += w[a] * en[a] * en[a];
                ep2 += en[a] * en[a];
            }
        for (int a = 3; a < 6; a++)
            if (w[a] > 0.0) {
                cost_n += w[a] * en[a] * en[a];
                er2 += en[a] * en[a];
            }
        vl acc = fresh | (running & ok & (cost_n < L.cost));
        for (int j = 0; j < n; j++)
            L.q[j] = vsel(acc, qn[j], L.q[j]);
        for (int a = 0; a < 6; a++) {
            for (int j = 0; j < n; j++)
                L.J[a * NMAX + j] = vsel(acc, Jn[a * NMAX + j], L.J[a * NMAX + j]);
            L.e[a] = vsel(acc, en[a], L.e[a]);
        }
        L.cost = vsel(acc, cost_n, L.cost);
        vd epn, ern;
        for (int l = 0; l < W; l++) {
            epn[l] = sqrt(ep2[l]);
            ern[l] = sqrt(er2[l]);
        }
        L.ep = vsel(acc, epn, L.ep);
        L.er = vsel(acc, ern, L.er);
        vd mu_acc = L.mu * mu_down;
        mu_acc = vsel(mu_acc < MU_MIN, BR(MU_MIN), mu_acc);
        L.mu = vsel(fresh, BR(mu0), vsel(acc, mu_acc, L.mu * mu_up));
        /* per-lane control flow */
        for (int l = 0; l < W; l++) {
            int mode = L.mode[l];
            if (mode == MODE_IDLE)
                continue;
            if (mode == MODE_INIT) {
                if (!isfinite(L.cost[l])) {
                    lane_end_attempt(cx, &L, l, CODE_STALL, 0);
                    continue;
                }
                L.mode[l] = MODE_RUN;
                L.it[l] = 0;
                L.next_check[l] = cx->check_every;
                L.cost_ref[l] = L.cost[l];
                lane_top(cx, &L, l);
                continue;
            }
            L.it[l]++;
            if (acc[l]) {
                lane_top(cx, &L, l);
                continue;
            }
            if (L.mu[l] > MU_MAX) {
                lane_end_attempt(cx, &L, l, CODE_STALL, L.it[l]);
                continue;
            }
            if (L.it[l] >= cx->max_iter)
                lane_end_attempt(cx, &L, l, CODE_ITER, L.it[l]);
        }
    }
}

/* --------------------------------------------------------- restart seeds */

/* The restarts' random numbers come from the inputs, not from a generator's
 * state: target i's numbers are a counter-based stream keyed by a hash of its
 * pose's bits, its start configuration's bits and a caller's key (0 by default,
 * or drawn once from an explicit rng). So a target's answer does not depend on
 * its place in a batch, on the other targets, on the number of threads or on
 * earlier calls (robokin.kinematics.ik.numeric). */

/* splitmix64's finaliser (Steele, Lea and Flood, "Fast splittable pseudorandom
 * number generators", OOPSLA 2014): a bijective avalanche of 64 bits */
static inline unsigned long long seed_mix(unsigned long long z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

/* The stream key of one target: its pose T (16 values) and start q0 (n values),
 * bit for bit, and the caller's key */
static unsigned long long seed_key(const double *T, const double *q0, int n,
                                   unsigned long long key)
{
    unsigned long long h = seed_mix(key ^ 0x6a09e667f3bcc909ULL);
    for (int i = 0; i < 16 + n; i++) {
        unsigned long long w;
        memcpy(&w, i < 16 ? T + i : q0 + (i - 16), sizeof(w));
        h = seed_mix(h ^ w) + 0x9e3779b97f4a7c15ULL;
    }
    return h;
}

/* Number (r, j) of a stream: uniform in [0, 1) on the 2^53 grid */
static inline double seed_uniform(unsigned long long h, long r, int j)
{
    unsigned long long c = (unsigned long long)r * NMAX + (unsigned long long)j + 1ULL;
    return (double)(seed_mix(h + c * 0x9e3779b97f4a7c15ULL) >> 11) * 0x1.0p-53;
}

/* out[i, r, j] = seed_uniform(stream of target i, base + r, j) for targets (N x 16),
 * q0 (N x n), out (N x R x n) */
static void seed_uniforms(const double *targets, const double *q0, long N, int n, long R,
                          unsigned long long key, long base, double *out)
{
    for (long i = 0; i < N; i++) {
        unsigned long long h = seed_key(targets + 16 * i, q0 + (size_t)i * n, n, key);
        for (long r = 0; r < R; r++)
            for (int j = 0; j < n; j++)
                out[((size_t)i * R + r) * n + j] = seed_uniform(h, base + r, j);
    }
}

/* ------------------------------------------------------------------ drivers */

static void lm_task(void *ctx, long b, long e)
{
    for (long i = b; i < e; i++)
        lm_worker((Ctx *)ctx);
}

/* Fill cx for targets (N x 16), q0 (N x n), seeds (N x R x n) and the table
 * (M x tab_cols, cstart, gdat; M = 0: none). */
static void lm_setup(Ctx *cx, const Chain *ch, const double *targets, const double *q0,
                     const double *seeds, long N, long R, const double *opts, double *out,
                     const double *tab, long M, const long long *cstart, const double *gdat)
{
    memset(cx, 0, sizeof(*cx));
    cx->ch = ch;
    cx->targets = targets;
    cx->q0 = q0;
    cx->seeds = seeds;
    cx->opts = opts;
    cx->out = out;
    cx->tab = tab;
    cx->cstart = cstart;
    cx->gdat = gdat;
    cx->N = N;
    cx->R = R;
    cx->tab_cols = 12 + ch->n;
    cx->M = M;
    cx->n_seeds = (int)(opts[O_N_SEEDS] < (double)R ? opts[O_N_SEEDS] : (double)R);
    int nt = (int)opts[O_N_TABLE];
    cx->n_tab = M > 0 ? (nt < TAB_K_MAX ? nt : TAB_K_MAX) : 0;
    cx->max_iter = (int)opts[O_MAX_ITER];
    cx->check_every = (int)opts[O_STALL_EVERY];
    for (int j = 0; j < ch->n; j++)
        cx->mid[j] = 0.5 * (ch->seed_lo[j] + ch->seed_hi[j]);
    cx->next = 0;
}

/* Solve every target of cx, on the pool's threads when `parallel` (one lane worker
 * per thread, all taking targets from the queue). */
static void lm_run(Ctx *cx, int parallel)
{
    long workers = parallel ? (cx->N + W - 1) / W : 1;
    if (workers > pool_threads())
        workers = pool_threads();
    if (workers > 1)
        pool_for(workers, 1, lm_task, cx);
    else
        lm_worker(cx);
}

/* The warm-started path: target i starts from the solution of i - 1 (the first
 * from q_start), no restarts. Stops at the first failure (not converged, or a joint
 * change above opts[O_PATH_MAX_JUMP]); later rows get the last good q and
 * CODE_NOT_RUN. Returns the index of the first failure, or -1. */
static long lm_path(const Chain *ch, const double *targets, const double *q_start, long N,
                    const double *opts, double *out)
{
    const int n = ch->n;
    double prev[NMAX];
    for (int j = 0; j < n; j++)
        prev[j] = q_start[j];
    const double max_jump = opts[O_PATH_MAX_JUMP];
    long first = -1;
    for (long i = 0; i < N; i++) {
        double *row = out + i * (n + N_RES);
        if (first >= 0) {
            for (int j = 0; j < n; j++)
                row[j] = prev[j];
            row[n + R_ERR] = INFINITY;
            row[n + R_EP] = INFINITY;
            row[n + R_ER] = INFINITY;
            row[n + R_ITERS] = 0;
            row[n + R_RESTARTS] = 0;
            row[n + R_CODE] = CODE_NOT_RUN;
            continue;
        }
        Ctx cx;
        lm_setup(&cx, ch, targets + 16 * i, prev, prev, 1, 0, opts, row, NULL, 0, NULL,
                 NULL);
        lm_worker(&cx);
        if (row[n + R_CODE] != CODE_OK) {
            first = i;
            continue;
        }
        double jump = 0.0;
        for (int j = 0; j < n; j++) {
            double d = fabs(row[j] - prev[j]);
            if (d > jump)
                jump = d;
        }
        if (jump > max_jump) {
            row[n + R_CODE] = CODE_JUMP;
            first = i;
            continue;
        }
        for (int j = 0; j < n; j++)
            prev[j] = row[j];
    }
    return first;
}
