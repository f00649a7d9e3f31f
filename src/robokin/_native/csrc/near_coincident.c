/*
 * A held joint next to a value that puts its two neighbours' axes on one line
 * (the Panda with q2 held within 1e-3 rad of 0: axes 1 and 3 nearly coincide):
 * the exact rows of kinematics/ik/near_coincident.py, from the helper problem's
 * rows on, in one compiled pass (issue 23; the module's docstring gives the maths).
 *
 * Per helper row (an exact solution of the pose with joint a held, the held joint
 * within KEEP of v0):
 *   1. the splits t = q_a where the family through it crosses the held value v
 *      (nc_splits: n . c(t) = alpha + beta cos t + gamma sin t from three
 *      Jacobians, n the left null vector of the family's 6 x 5 matrix), or eight
 *      spread over the turn where that first-order equation says nothing;
 *   2. each split a seed (the held joint at v), seeds of one pose within
 *      NC_SAME_SEED of an earlier one dropped;
 * per seed:
 *   3. Newton on the free joints (nc_newton: SVD steps, pk_svd6, singular values
 *      below NC_RCOND of the largest left out, at most NC_MAX_STEP rad per joint,
 *      angles wrapped, the best iterate kept; NC_STEPS steps, then NC_FINAL from
 *      the best with the cut at NC_FINAL_RCOND where 1e-16 was not reached);
 *   4. angles at their in-limit turn, the row checked to `accept` (m, rad);
 *   5. a row outside the limits moved in (nc_pinned: the split shifted by at
 *      most NC_SHIFT and held, other small overshoots pinned at their limit, the
 *      rest polished; first with the pair's second joint free, then held) and
 *      kept where it is still exact and less outside;
 *   6. flagged singular where the free joints' smallest singular value is below
 *      NC_FLAG of the largest;
 * and last the exact rows, least outside the limits first, placed in their pose's
 * slots, a row within NC_SAME (every joint, modulo 2 pi) of a placed one dropped.
 *
 * The same algorithm and stopping rules as the numpy version it replaces (c. 27
 * batched numpy SVD steps per call, 3.2-3.7 ms); a row's result depends on its
 * seed alone (no batch), so the order of poses and rows changes nothing.
 */
#include "chain.h"
#include "linalg6.h"

#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#elif defined(__GNUC__)
#pragma GCC push_options
#pragma GCC optimize("fp-contract=off")
#endif

#define NC_RCOND 1e-15       /* relative cut of the Newton step's SVD */
#define NC_FINAL_RCOND 1e-10 /* ... of the last steps, from the best iterate */
#define NC_MAX_STEP 0.5      /* largest Newton step [rad] of any joint */
#define NC_STEPS 15          /* Newton iterations ... */
#define NC_FINAL 3           /* ... then ones with the coarser cut */
#define NC_PIN_STEPS 6       /* iterations of a row moved into the limits */
#define NC_CONVERGED 1e-16   /* largest residual entry of a converged row */
#define NC_SAME 1e-4         /* two rows this close [rad] (every joint): one solution */
#define NC_SAME_SEED 1e-3    /* two seeds of one pose this close [rad]: one */
#define NC_SHIFT 1e-2        /* largest move [rad] that brings a row into the limits */
#define NC_FLAG 1e-5         /* rows flagged singular below this singular value ratio */
#define NC_FAMILY_RANK 1e-6  /* a family's 6 x 5 matrix below this ratio: singular */
#define NC_SPREAD 8          /* splits spread over the turn where the equation fails */
#define NC_SEEDS NC_SPREAD   /* seeds per helper row at most (the Q rows needed) */
#define NC_N 7               /* the arm's joints (7R) */
#define NC_QR_SAFE 100.0     /* QR pivot ratio above this times the cut: no SVD needed */

/* a target for the evaluations whose residual is not used */
static const double NC_EYE[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

typedef struct {
    const Chain *ch;
    int held, a, b;
    double sign, v0, v, accept;
} NcProblem;

/* Pose error e (6) of configuration q (n) against the target T (4 x 4, row-major)
 * and, when J is given, the Jacobian columns `cols` (k of them) into J's first k
 * columns, the others zero; 0 when a joint value is not finite. */
static int nc_eval(const Chain *ch, const double *q, const double *T, const int *cols, int k,
                   double J[6][6], double *e)
{
    vd qv[MAXJ], t[12], tt[12], ev[6], Jv[6 * MAXJ];
    for (int j = 0; j < ch->n; j++)
        qv[j] = BR(q[j]);
    vl ok = J != NULL ? chain_pose_jac(ch, qv, t, Jv, MAXJ) : chain_pose(ch, qv, t, NULL, NULL);
    for (int i = 0; i < 12; i++)
        tt[i] = BR(T[i]);
    pose_residual(t, tt, ev, BRL(-1));
    for (int r = 0; r < 6; r++) {
        e[r] = ev[r][0];
        if (J != NULL)
            for (int c = 0; c < 6; c++)
                J[r][c] = c < k ? Jv[r * MAXJ + cols[c]][0] : 0.0;
    }
    return ok[0] != 0;
}

/* max |e_r| (NaN when one is NaN), as numpy's abs(e).max() */
static double nc_maxabs(const double *e)
{
    double m = 0.0;
    for (int r = 0; r < 6; r++) {
        if (isnan(e[r]))
            return NAN;
        m = fmax(m, fabs(e[r]));
    }
    return m;
}

/* One least-squares step on the joints `cols` of q, in place: J's k columns'
 * least-squares solution with singular values at most `cut` of the largest (or
 * zero) left out, the step scaled to at most NC_MAX_STEP rad, angles wrapped.
 * 1 when q changed.
 *
 * Where the pivoted QR (lstsq6) shows every singular value above NC_QR_SAFE
 * times the cut (its pivot ratio bounds sigma_min / sigma_max from below by
 * ratio / 53, linalg6.h), no value would be cut and the step is the unique
 * least-squares solution, which the QR gives (a tenth of the SVD's cost); else
 * the SVD (pk_svd6) takes the step with the cut. */
static int nc_step(const Chain *ch, double J[6][6], const double *e, double cut, double *q,
                   const int *cols, int k)
{
    double A[6][6], dx[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0}, ratio;
    memcpy(A, J, sizeof(A));
    int rank = lstsq6(A, e, dx, 0.0, &ratio, k);
    if (!(rank == k && ratio > NC_QR_SAFE * cut)) {
        double sig[6], V[6][6], g[6];
        memcpy(A, J, sizeof(A));
        pk_svd6(A, sig, V); /* ascending */
        for (int c = 0; c < 6; c++) { /* J^T e */
            double s = 0.0;
            for (int r = 0; r < 6; r++)
                s += J[r][c] * e[r];
            g[c] = s;
            dx[c] = 0.0;
        }
        /* V diag(1 / s) U^T e = sum_c V_c (V_c . J^T e) / s_c^2 over the kept s_c */
        for (int c = 0; c < 6; c++) {
            if (!(sig[c] > cut * sig[5]) || !(sig[c] > 0.0))
                continue;
            double d = 0.0;
            for (int i = 0; i < 6; i++)
                d += V[i][c] * g[i];
            d /= sig[c] * sig[c];
            for (int i = 0; i < 6; i++)
                dx[i] += V[i][c] * d;
        }
    }
    double big = 1e-300;
    for (int i = 0; i < k; i++)
        big = fmax(big, fabs(dx[i]));
    double f = fmin(1.0, NC_MAX_STEP / big);
    int moved = 0;
    for (int i = 0; i < k; i++) {
        int j = cols[i];
        double x = q[j] + dx[i] * f;
        if (ch->kind[j] == 0.0)
            x = wrap_pi(x);
        moved |= x != q[j];
        q[j] = x;
    }
    return moved;
}

/* Newton on the joints `cols` (k) of q (n) towards T: `steps` iterations, then
 * `final` from the best iterate with the coarser cut where NC_CONVERGED was not
 * reached; q <- the best iterate (the smallest largest residual entry). */
static void nc_newton(const Chain *ch, const double *T, double *q, const int *cols, int k,
                      int steps, int final)
{
    const int n = ch->n;
    double best[MAXJ], low = INFINITY;
    memcpy(best, q, sizeof(double) * (size_t)n);
    for (int phase = 0; phase < 2; phase++) {
        int count = phase ? final : steps;
        if (phase) {
            if (count == 0 || !(low > NC_CONVERGED))
                break;
            memcpy(q, best, sizeof(double) * (size_t)n);
        }
        for (int it = 0; it < count; it++) {
            double J[6][6], e[6];
            if (!nc_eval(ch, q, T, cols, k, J, e))
                break;
            double err = nc_maxabs(e);
            if (err < low) {
                low = err;
                memcpy(best, q, sizeof(double) * (size_t)n);
            }
            if (!(err > NC_CONVERGED))
                break;
            if (!nc_step(ch, J, e, phase ? NC_FINAL_RCOND : NC_RCOND, q, cols, k))
                break; /* a fixed point: the next steps would repeat this one */
        }
    }
    memcpy(q, best, sizeof(double) * (size_t)n);
}

/* Revolute values wrapped, then at their in-limit turn (fit_turns) */
static void nc_fit_turns(const Chain *ch, double *q)
{
    for (int j = 0; j < ch->n; j++)
        if (ch->kind[j] == 0.0)
            q[j] = wrap_into(wrap_pi(q[j]), ch->lo[j], ch->hi[j]);
}

/* How far [rad] q lies outside the limits at most (0 inside) */
static double nc_past(const Chain *ch, const double *q)
{
    double m = 0.0;
    for (int j = 0; j < ch->n; j++)
        m = fmax(m, fmax(ch->lo[j] - q[j], q[j] - ch->hi[j]));
    return m;
}

/* q reaches T to `accept` (position and rotation norms) with every value finite */
static int nc_exact(const NcProblem *p, const double *q, const double *T)
{
    double e[6];
    for (int j = 0; j < p->ch->n; j++)
        if (!isfinite(q[j]))
            return 0;
    nc_eval(p->ch, q, T, NULL, 0, NULL, e);
    double ep = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
    double er = sqrt(e[3] * e[3] + e[4] * e[4] + e[5] * e[5]);
    return fmax(ep, er) <= p->accept; /* NaN: no */
}

/* The free joints (every one but the held) not in `pinned` (bit j) into cols */
static int nc_cols(const NcProblem *p, unsigned pinned, int *cols)
{
    int k = 0;
    for (int j = 0; j < p->ch->n; j++)
        if (j != p->held && !(pinned >> j & 1u))
            cols[k++] = j;
    return k;
}

/* The pair's split of q moved (by at most NC_SHIFT) into both joints' limits:
 * next to aligned the pose barely depends on it (~|v - v0| per radian). */
static void nc_into_limits(const NcProblem *p, const double *q, double *out)
{
    const Chain *ch = p->ch;
    const int a = p->a, b = p->b;
    double e0 = p->sign * (q[b] - ch->hi[b]), e1 = p->sign * (q[b] - ch->lo[b]);
    double lo_e = fmin(e0, e1), hi_e = fmax(e0, e1); /* q_b - sign d within b's limits */
    double lo = fmax(ch->lo[a] - q[a], lo_e), hi = fmin(ch->hi[a] - q[a], hi_e);
    /* an empty interval (both joints at a limit: a single in-limit split Newton
     * misses by ~1e-7): the middle; the polish after it recomputes q_b */
    double d = lo <= hi ? fmin(fmax(0.0, lo), hi) : 0.5 * (lo + hi);
    if (!(lo <= hi + NC_SHIFT && fabs(d) <= NC_SHIFT))
        d = 0.0;
    memcpy(out, q, sizeof(double) * (size_t)ch->n);
    out[a] += d;
    out[b] -= p->sign * d;
}

/* q (at most NC_SHIFT outside) moved into the limits (step 5 above) into out:
 * the split moved and held (every row's split held when hold_split), other
 * joints outside by at most NC_SHIFT set to their limit and held (the pair's
 * second joint only when hold_split), the rest polished. */
static void nc_pinned(const NcProblem *p, const double *q, const double *T, int hold_split,
                      double *out)
{
    const Chain *ch = p->ch;
    const int n = ch->n;
    nc_into_limits(p, q, out);
    unsigned pin = 0;
    for (int j = 0; j < n; j++) {
        double past = fmax(ch->lo[j] - out[j], out[j] - ch->hi[j]);
        if (past > 0.0 && past <= NC_SHIFT && j != p->held && j != p->a &&
            (hold_split || j != p->b))
            pin |= 1u << j;
    }
    if (hold_split || out[p->a] != q[p->a])
        pin |= 1u << p->a;
    int changed = hold_split;
    for (int j = 0; j < n; j++) {
        if (pin >> j & 1u)
            out[j] = fmin(fmax(out[j], ch->lo[j]), ch->hi[j]);
        changed |= out[j] != q[j];
    }
    if (changed) {
        int cols[MAXJ], k = nc_cols(p, pin, cols);
        nc_newton(ch, T, out, cols, k, NC_PIN_STEPS, 0);
    }
    nc_fit_turns(ch, out);
    out[p->held] = q[p->held];
}

/* x of [1 cos t sin t] x = h at three splits (Gaussian elimination, partial
 * pivoting); 0 when singular */
static int nc_solve3(double M[3][3], double *h, double *x)
{
    for (int k = 0; k < 3; k++) {
        int best = k;
        for (int r = k + 1; r < 3; r++)
            if (fabs(M[r][k]) > fabs(M[best][k]))
                best = r;
        if (!(M[best][k] != 0.0))
            return 0;
        if (best != k) {
            for (int c = 0; c < 3; c++) {
                double t = M[k][c];
                M[k][c] = M[best][c];
                M[best][c] = t;
            }
            double t = h[k];
            h[k] = h[best];
            h[best] = t;
        }
        for (int r = k + 1; r < 3; r++) {
            double f = M[r][k] / M[k][k];
            for (int c = k; c < 3; c++)
                M[r][c] -= f * M[k][c];
            h[r] -= f * h[k];
        }
    }
    for (int r = 2; r >= 0; r--) {
        double s = h[r];
        for (int c = r + 1; c < 3; c++)
            s -= M[r][c] * x[c];
        x[r] = s / M[r][r];
    }
    return 1;
}

/* The unit vector n orthogonal to F's first five columns (F's sixth is zero),
 * when their smallest singular value is at least NC_FAMILY_RANK of the largest
 * (else 0: the family is singular itself). The SVD of F (pk_svd6: the zero
 * column never rotates) gives their left singular vectors U_c = F V_c / s_c; n is
 * the unit vector e_i least inside their span with that span projected out
 * (twice, for orthogonality to rounding). */
static int nc_left_null(double F[6][6], double *nv)
{
    double A[6][6], sig[6], V[6][6], U[5][6];
    memcpy(A, F, sizeof(A));
    pk_svd6(A, sig, V); /* ascending: sig[0] the zero column's */
    if (!(sig[1] >= NC_FAMILY_RANK * sig[5]))
        return 0;
    for (int c = 0; c < 5; c++)
        for (int r = 0; r < 6; r++) {
            double s = 0.0;
            for (int j = 0; j < 6; j++)
                s += F[r][j] * V[j][c + 1];
            U[c][r] = s / sig[c + 1];
        }
    int best = 0;
    double most = -1.0;
    for (int i = 0; i < 6; i++) { /* |e_i - P e_i|^2 = 1 - sum_c U_c[i]^2 */
        double s = 1.0;
        for (int c = 0; c < 5; c++)
            s -= U[c][i] * U[c][i];
        if (s > most) {
            most = s;
            best = i;
        }
    }
    for (int r = 0; r < 6; r++)
        nv[r] = r == best;
    for (int pass = 0; pass < 2; pass++) {
        for (int c = 0; c < 5; c++) {
            double d = 0.0;
            for (int r = 0; r < 6; r++)
                d += U[c][r] * nv[r];
            for (int r = 0; r < 6; r++)
                nv[r] -= d * U[c][r];
        }
        double len = 0.0;
        for (int r = 0; r < 6; r++)
            len += nv[r] * nv[r];
        len = sqrt(len);
        for (int r = 0; r < 6; r++)
            nv[r] /= len;
    }
    return 1;
}

/* The splits t = q_a where the self-motion through `row` (an exact solution with
 * the held joint at w next to v0, q_a at c) crosses the held value v: to first
 * order (v - v0) h(t) = (w - v0) h(c), h(t) = n . c(t) = alpha + beta cos t +
 * gamma sin t (n: the left null vector of the family's columns [a, others] at the
 * aligned value); two splits, or NC_SPREAD spread over the turn where the family
 * is singular or the equation has no root. Returns the count, splits into ts. */
static int nc_splits(const NcProblem *p, const double *row, double *ts)
{
    const Chain *ch = p->ch;
    const int n = ch->n;
    const double c = row[p->a];
    const double w = wrap_pi(row[p->held] - p->v0);
    const double total = row[p->a] + p->sign * row[p->b];
    double t3[3] = {c, c + 2.0 * M_PI / 3.0, c + 4.0 * M_PI / 3.0}, col[3][6], F[6][6];
    int cols[MAXJ], k = 0;
    cols[k++] = p->a;
    for (int j = 0; j < n; j++)
        if (j != p->held && j != p->a && j != p->b)
            cols[k++] = j;
    for (int i = 0; i < 3; i++) {
        double q[MAXJ], J[6][6], e[6];
        int held[1] = {p->held};
        memcpy(q, row, sizeof(double) * (size_t)n);
        q[p->held] = p->v0;
        q[p->a] = t3[i];
        q[p->b] = p->sign * (total - t3[i]);
        if (i == 0)
            nc_eval(ch, q, NC_EYE, cols, k, F, e); /* the family's columns, padded */
        nc_eval(ch, q, NC_EYE, held, 1, J, e);
        for (int r = 0; r < 6; r++)
            col[i][r] = J[r][0];
    }
    int m = 0;
    double nv[6];
    if (k == 5 && nc_left_null(F, nv)) {
        double h[3], hmax = 0.0, M[3][3], x[3];
        for (int i = 0; i < 3; i++) {
            h[i] = 0.0;
            for (int r = 0; r < 6; r++)
                h[i] += nv[r] * col[i][r];
            hmax = fmax(hmax, fabs(h[i]));
            M[i][0] = 1.0;
            M[i][1] = cos(t3[i]);
            M[i][2] = sin(t3[i]);
        }
        double h0 = h[0];
        if (nc_solve3(M, h, x)) {
            double radius = hypot(x[1], x[2]);
            if (radius > 1e-12 * fmax(1.0, hmax)) {
                double xx = (w / (p->v - p->v0) * h0 - x[0]) / radius;
                if (fabs(xx) <= 1.0 + 1e-6) {
                    double phi = atan2(x[2], x[1]), d = acos(fmin(1.0, fmax(-1.0, xx)));
                    ts[m++] = phi + d;
                    ts[m++] = phi - d;
                }
            }
        }
    }
    if (m == 0)
        for (int i = 0; i < NC_SPREAD; i++)
            ts[m++] = c + i * (M_PI / 4.0);
    return m;
}

/* max |wrap(x - y)| over the n joints */
static double nc_gap(const double *x, const double *y, int n)
{
    double m = 0.0;
    for (int j = 0; j < n; j++)
        m = fmax(m, fabs(wrap_pi(x[j] - y[j])));
    return m;
}

/* Steps 1-2: the seeds of every helper row (their poses non-decreasing) into Q
 * (and their poses into at), each pose's seeds in one block; their count */
static long nc_seeds(const NcProblem *p, const double *H, const long long *pose, long M,
                     double *Q, long long *at)
{
    const int n = p->ch->n;
    long S = 0, block = 0;
    for (long h = 0; h < M; h++) {
        if (h > 0 && pose[h] != pose[h - 1])
            block = S;
        const double *row = H + h * n;
        double ts[NC_SEEDS], total = row[p->a] + p->sign * row[p->b];
        int m = nc_splits(p, row, ts);
        for (int i = 0; i < m; i++) {
            double *q = Q + S * n;
            memcpy(q, row, sizeof(double) * (size_t)n);
            q[p->a] = ts[i];
            q[p->b] = p->sign * (total - ts[i]);
            q[p->held] = p->v;
            int dup = 0;
            for (long s = block; s < S && !dup; s++)
                dup = nc_gap(Q + s * n, q, n) <= NC_SAME_SEED;
            if (!dup)
                at[S++] = pose[h];
        }
    }
    return S;
}

/* Whether the free joints' smallest singular value at q is below NC_FLAG of the
 * largest. The pivoted QR's ratio r bounds sigma_min / sigma_max within [r / 53,
 * r] (linalg6.h): the SVD only where that interval straddles NC_FLAG. */
static int nc_flag(const Chain *ch, const double *q, const double *T, const int *cols, int k)
{
    double J[6][6], A[6][6], e[6], dx[6], ratio, sig[6], V[6][6];
    nc_eval(ch, q, T, cols, k, J, e);
    memcpy(A, J, sizeof(A));
    int rank = lstsq6(A, e, dx, 0.0, &ratio, k);
    if (rank < k || ratio < NC_FLAG)
        return 1;
    if (ratio > NC_QR_SAFE * NC_FLAG)
        return 0;
    pk_svd6(J, sig, V);
    return sig[0] < NC_FLAG * sig[5];
}

/* Steps 3-6 on one seed q (in place) of pose T: exact (1/0) and singular flags */
static void nc_row(const NcProblem *p, double *q, const double *T, npy_bool *exact,
                   npy_bool *singular)
{
    const Chain *ch = p->ch;
    int cols[MAXJ], k = nc_cols(p, 0, cols);
    nc_newton(ch, T, q, cols, k, NC_STEPS, NC_FINAL);
    nc_fit_turns(ch, q);
    q[p->held] = p->v;
    int ok = nc_exact(p, q, T);
    for (int hold = 0; hold < 2; hold++) { /* outside the limits: moved in where exact */
        double past = nc_past(ch, q), moved[MAXJ];
        if (!(past > 0.0))
            break;
        nc_pinned(p, q, T, hold, moved);
        if (nc_exact(p, moved, T) && nc_past(ch, moved) < past) {
            memcpy(q, moved, sizeof(double) * (size_t)ch->n);
            ok = 1;
        }
    }
    *exact = (npy_bool)ok;
    *singular = (npy_bool)nc_flag(ch, q, T, cols, k);
}

/* The last step, on one pose's rows [b, e): the slot of each exact row, least
 * outside the limits first (ties in seed order), -1 for a copy of a placed row
 * and for rows that are not exact; order, past: scratch of e - b entries. */
static void nc_place(const NcProblem *p, const double *Q, const npy_bool *exact, long b,
                     long e, long long *slot, long *order, double *past)
{
    const int n = p->ch->n;
    long m = 0;
    for (long i = b; i < e; i++) {
        slot[i] = -1;
        if (!exact[i])
            continue;
        double x = nc_past(p->ch, Q + i * n);
        long j = m++; /* insertion sort, stable */
        while (j > 0 && past[j - 1] > x) {
            order[j] = order[j - 1];
            past[j] = past[j - 1];
            j--;
        }
        order[j] = i;
        past[j] = x;
    }
    long used = 0;
    for (long r = 0; r < m; r++) {
        long i = order[r];
        int dup = 0;
        for (long s = 0; s < r && !dup; s++)
            dup = slot[order[s]] >= 0 && nc_gap(Q + order[s] * n, Q + i * n, n) <= NC_SAME;
        if (!dup)
            slot[i] = used++;
    }
}

static PyObject *near_coincident_body(const near_coincident_args *a)
{
    NcProblem p = {&a->packed, (int)a->held, (int)a->a, (int)a->b, a->sign, a->v0, a->v,
                   a->accept};
    long S, *order = malloc(sizeof(long) * (size_t)(a->S + 1));
    double *past = malloc(sizeof(double) * (size_t)(a->S + 1));
    if (order == NULL || past == NULL) {
        free(order);
        free(past);
        return PyErr_NoMemory();
    }
    Py_BEGIN_ALLOW_THREADS
    S = nc_seeds(&p, a->H, a->pose, (long)a->M, a->Q, a->at);
    for (long i = 0; i < S; i++)
        nc_row(&p, a->Q + i * a->n, a->T + 16 * a->at[i], a->exact + i, a->singular + i);
    for (long b = 0, e = 0; b < S; b = e) {
        for (e = b + 1; e < S && a->at[e] == a->at[b]; e++)
            ;
        nc_place(&p, a->Q, a->exact, b, e, a->slot, order, past);
    }
    for (long i = S; i < (long)a->S; i++)
        a->slot[i] = -1;
    Py_END_ALLOW_THREADS
    free(order);
    free(past);
    return PyLong_FromLong(S);
}

#if defined(__clang__)
#pragma STDC FP_CONTRACT DEFAULT
#elif defined(__GNUC__)
#pragma GCC pop_options
#endif
