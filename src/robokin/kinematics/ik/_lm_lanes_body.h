/*
 * The lane kernel of _lm_lanes.c, included once per instruction set: FN(x) names
 * this copy's functions, so the same source compiles for baseline x86-64 / other
 * CPUs and, under a "target" pragma, for AVX2 + FMA.
 *
 * W targets advance together, one per lane of a vector: every step each lane
 * makes one Levenberg-Marquardt trial (or evaluates the start of a new descent),
 * the arithmetic on all lanes at once; then each lane's bookkeeping (accept or
 * reject, convergence, stall, next seed, next target) runs per lane. A lane whose
 * target is done takes the next one from the shared queue, so lanes never wait for
 * each other. The per-lane logic mirrors _numeric_kernels._attempt and
 * _solve_target step for step (the same tests in the same order).
 */

static inline __attribute__((always_inline)) vd FN(vsel)(vl m, vd a, vd b)
{
    return (vd)(((vl)a & m) | ((vl)b & ~m));
}

static inline __attribute__((always_inline)) vd FN(vabs)(vd x)
{
    return (vd)((vl)x & ~SIGN_BIT);
}

/* (sin x, cos x) per lane: the Cody-Waite / fdlibm polynomials of the numba
 * kernels; lanes with |x| >= 1e5 or NaN/inf take libm. */
static inline __attribute__((always_inline)) void FN(vsincos)(vd x, vd *s, vd *c)
{
    vd t = x * INV_PIO2 + 0.5;
    vd n = __builtin_convertvector(__builtin_convertvector(t, vl), vd);
    n += __builtin_convertvector(n > t, vd); /* floor: -1.0 where the cast rounded up */
    vd y = ((x - n * PIO2_1) - n * PIO2_2) - n * PIO2_3;
    vd z = y * y;
    vd r = S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)));
    vd sy = y + z * y * (S1 + z * r);
    vd rc = z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    vd hz = 0.5 * z;
    vd w = 1.0 - hz;
    vd cy = w + (((1.0 - w) - hz) + z * rc);
    vl k = __builtin_convertvector(n, vl);
    vl odd = -(k & 1);
    vl neg_s = -((k >> 1) & 1) & SIGN_BIT;
    vl neg_c = -(((k + 1) >> 1) & 1) & SIGN_BIT;
    vd ss = FN(vsel)(odd, cy, sy);
    vd cc = FN(vsel)(odd, sy, cy);
    *s = (vd)((vl)ss ^ neg_s);
    *c = (vd)((vl)cc ^ neg_c);
    vl big = ~(FN(vabs)(x) < 1e5);
    int any = 0;
    for (int l = 0; l < W; l++)
        any |= (big[l] != 0);
    if (any) {
        for (int l = 0; l < W; l++)
            if (big[l]) {
                (*s)[l] = sin(x[l]);
                (*c)[l] = cos(x[l]);
            }
    }
}

/* Pose (T: 12 vectors, rows of the top 3x4) and Jacobian (J[6][n]) with respect
 * to the independent coordinates q (n); through the coupling q_chain = M q + c
 * unless it is the identity. Mirrors _pose_jac. */
static inline __attribute__((always_inline)) void FN(pose_jac)(const Chain *ch, const vd *q,
                                                             vd *J, vd *T)
{
    const int n = ch->nc; /* from here on: chain joints */
    const double *jd = ch->jdat;
    vd qcb[NMAX], Jcb[6 * NMAX];
    vd *Jc = J;
    if (!ch->ident) {
        const int ni = ch->n;
        const double *Mc = ch->Mc;
        for (int k = 0; k < n; k++) {
            vd s = BR(Mc[k * (ni + 1) + ni]);
            for (int j = 0; j < ni; j++)
                s += Mc[k * (ni + 1) + j] * q[j];
            qcb[k] = s;
        }
        q = qcb;
        Jc = Jcb;
    }
    vd sn[NMAX], cs[NMAX], o[3][NMAX], zz[3][NMAX];
    for (int k = 0; k < n; k++)
        if (jd[k] == 0.0)
            FN(vsincos)(jd[n + k] * q[k] + jd[2 * n + k], &sn[k], &cs[k]);
    const double *C0 = ch->consts;
    vd t00 = BR(C0[0]), t01 = BR(C0[1]), t02 = BR(C0[2]), t03 = BR(C0[3]);
    vd t10 = BR(C0[4]), t11 = BR(C0[5]), t12 = BR(C0[6]), t13 = BR(C0[7]);
    vd t20 = BR(C0[8]), t21 = BR(C0[9]), t22 = BR(C0[10]), t23 = BR(C0[11]);
    for (int k = 0; k < n; k++) {
        if (jd[k] == 0.0) {
            vd sk = sn[k], ck = cs[k], x0;
            x0 = t00;
            t00 = ck * x0 + sk * t01;
            t01 = ck * t01 - sk * x0;
            x0 = t10;
            t10 = ck * x0 + sk * t11;
            t11 = ck * t11 - sk * x0;
            x0 = t20;
            t20 = ck * x0 + sk * t21;
            t21 = ck * t21 - sk * x0;
        } else {
            vd v = jd[n + k] * q[k] + jd[2 * n + k];
            t03 += t02 * v;
            t13 += t12 * v;
            t23 += t22 * v;
        }
        o[0][k] = t03;
        o[1][k] = t13;
        o[2][k] = t23;
        zz[0][k] = t02;
        zz[1][k] = t12;
        zz[2][k] = t22;
        if (jd[3 * n + k] == 1.0) {
            double ca = jd[4 * n + k], sa = jd[5 * n + k];
            double tx = jd[6 * n + k], ty = jd[7 * n + k], tz = jd[8 * n + k];
            vd a1;
            t03 += t00 * tx + t01 * ty + t02 * tz;
            t13 += t10 * tx + t11 * ty + t12 * tz;
            t23 += t20 * tx + t21 * ty + t22 * tz;
            a1 = t01;
            t01 = ca * a1 + sa * t02;
            t02 = ca * t02 - sa * a1;
            a1 = t11;
            t11 = ca * a1 + sa * t12;
            t12 = ca * t12 - sa * a1;
            a1 = t21;
            t21 = ca * a1 + sa * t22;
            t22 = ca * t22 - sa * a1;
        } else {
            const double *C = ch->consts + 16 * (k + 1);
            vd a0, a1, a2;
            a0 = t00; a1 = t01; a2 = t02;
            t00 = a0 * C[0] + a1 * C[4] + a2 * C[8];
            t01 = a0 * C[1] + a1 * C[5] + a2 * C[9];
            t02 = a0 * C[2] + a1 * C[6] + a2 * C[10];
            t03 += a0 * C[3] + a1 * C[7] + a2 * C[11];
            a0 = t10; a1 = t11; a2 = t12;
            t10 = a0 * C[0] + a1 * C[4] + a2 * C[8];
            t11 = a0 * C[1] + a1 * C[5] + a2 * C[9];
            t12 = a0 * C[2] + a1 * C[6] + a2 * C[10];
            t13 += a0 * C[3] + a1 * C[7] + a2 * C[11];
            a0 = t20; a1 = t21; a2 = t22;
            t20 = a0 * C[0] + a1 * C[4] + a2 * C[8];
            t21 = a0 * C[1] + a1 * C[5] + a2 * C[9];
            t22 = a0 * C[2] + a1 * C[6] + a2 * C[10];
            t23 += a0 * C[3] + a1 * C[7] + a2 * C[11];
        }
    }
    T[0] = t00; T[1] = t01; T[2] = t02; T[3] = t03;
    T[4] = t10; T[5] = t11; T[6] = t12; T[7] = t13;
    T[8] = t20; T[9] = t21; T[10] = t22; T[11] = t23;
    for (int k = 0; k < n; k++) {
        double s = jd[n + k];
        vd zx = zz[0][k], zy = zz[1][k], zq = zz[2][k];
        if (jd[k] == 0.0) {
            vd dx = t03 - o[0][k], dy = t13 - o[1][k], dz = t23 - o[2][k];
            Jc[0 * NMAX + k] = s * (zy * dz - zq * dy);
            Jc[1 * NMAX + k] = s * (zq * dx - zx * dz);
            Jc[2 * NMAX + k] = s * (zx * dy - zy * dx);
            Jc[3 * NMAX + k] = s * zx;
            Jc[4 * NMAX + k] = s * zy;
            Jc[5 * NMAX + k] = s * zq;
        } else {
            Jc[0 * NMAX + k] = s * zx;
            Jc[1 * NMAX + k] = s * zy;
            Jc[2 * NMAX + k] = s * zq;
            Jc[3 * NMAX + k] = ZERO;
            Jc[4 * NMAX + k] = ZERO;
            Jc[5 * NMAX + k] = ZERO;
        }
    }
    if (!ch->ident) {
        /* J = Jc M */
        const int ni = ch->n;
        const double *Mc = ch->Mc;
        for (int r = 0; r < 6; r++)
            for (int j = 0; j < ni; j++) {
                vd s = ZERO;
                for (int k = 0; k < n; k++)
                    s += Jc[r * NMAX + k] * Mc[k * (ni + 1) + j];
                J[r * NMAX + j] = s;
            }
    }
}

/* Task error e = [p_t - p; log(R_t R^T)] per lane (mirrors _residual); active
 * lanes outside the small-angle case take the scalar formula. */
static inline __attribute__((always_inline)) void FN(residual)(const vd *T, const vd *Tt,
                                                             vd *e, vl active)
{
    e[0] = Tt[3] - T[3];
    e[1] = Tt[7] - T[7];
    e[2] = Tt[11] - T[11];
    vd r00 = Tt[0] * T[0] + Tt[1] * T[1] + Tt[2] * T[2];
    vd r01 = Tt[0] * T[4] + Tt[1] * T[5] + Tt[2] * T[6];
    vd r02 = Tt[0] * T[8] + Tt[1] * T[9] + Tt[2] * T[10];
    vd r10 = Tt[4] * T[0] + Tt[5] * T[1] + Tt[6] * T[2];
    vd r11 = Tt[4] * T[4] + Tt[5] * T[5] + Tt[6] * T[6];
    vd r12 = Tt[4] * T[8] + Tt[5] * T[9] + Tt[6] * T[10];
    vd r20 = Tt[8] * T[0] + Tt[9] * T[1] + Tt[10] * T[2];
    vd r21 = Tt[8] * T[4] + Tt[9] * T[5] + Tt[10] * T[6];
    vd r22 = Tt[8] * T[8] + Tt[9] * T[9] + Tt[10] * T[10];
    vd vx = 0.5 * (r21 - r12);
    vd vy = 0.5 * (r02 - r20);
    vd vz = 0.5 * (r10 - r01);
    vd s2 = vx * vx + vy * vy + vz * vz;
    vd s;
    for (int l = 0; l < W; l++)
        s[l] = sqrt(s2[l]);
    vd c = 0.5 * (r00 + r11 + r22 - 1.0);
    vl small = (c > 0.0) & (s < 0.1 * c);
    vd ic = 1.0 / FN(vsel)(small, c, ONE);
    vd x = s * ic;
    vd z = x * x;
    vd f = ic * (1.0 + z * (-1.0 / 3.0 + z * (1.0 / 5.0 + z * (-1.0 / 7.0 + z * (
        1.0 / 9.0 + z * (-1.0 / 11.0 + z * (1.0 / 13.0 + z * (-1.0 / 15.0))))))));
    e[3] = f * vx;
    e[4] = f * vy;
    e[5] = f * vz;
    vl other = active & ~small;
    int any = 0;
    for (int l = 0; l < W; l++)
        any |= (other[l] != 0);
    if (!any)
        return;
    for (int l = 0; l < W; l++) {
        if (!other[l])
            continue;
        double R[9] = {r00[l], r01[l], r02[l], r10[l], r11[l], r12[l], r20[l], r21[l],
                       r22[l]};
        double ev[3];
        rot_log_general(R, vx[l], vy[l], vz[l], s[l], c[l], ev);
        e[3][l] = ev[0];
        e[4][l] = ev[1];
        e[5][l] = ev[2];
    }
}

/* Start descent attempt a of lane l (mirrors the seed choice of _solve_target);
 * returns 0 when the target has no attempt left. */
static inline int FN(lane_next_attempt)(const Ctx *cx, Lanes *L, int l)
{
    const int n = cx->ch.n;
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
            L->tab_found[l] = table_nearest(cx, Tt, L->tidx[l]);
        }
        if (a > L->tab_found[l]) {
            for (int j = 0; j < n; j++)
                q[j] = cx->cdat[2 * n + j] + seeds[(size_t)(a - 1) * n + j] *
                       (cx->cdat[3 * n + j] - cx->cdat[2 * n + j]);
        } else {
            const double *row = cx->tab + (size_t)L->tidx[l][a - 1] * cx->tab_cols;
            for (int j = 0; j < n; j++)
                q[j] = row[12 + j];
        }
        if (a > 1 || L->start == 0)
            L->restarts[l]++;
    } else {
        double lo_f = 0.0, span_f = 1.0;
        if (a % 2 == 1) {
            lo_f = cx->opts[O_SEED_SHRINK];
            span_f = 1.0 - 2.0 * lo_f;
        }
        for (int j = 0; j < n; j++) {
            double u = lo_f + span_f * seeds[(size_t)(a - 1) * n + j];
            q[j] = cx->cdat[2 * n + j] + u * (cx->cdat[3 * n + j] - cx->cdat[2 * n + j]);
        }
        if (a > 1 || L->start == 0)
            L->restarts[l]++;
    }
    project(q, cx->cdat, n);
    for (int j = 0; j < n; j++)
        L->qinit[j][l] = q[j];
    L->mode[l] = MODE_INIT;
    return 1;
}

/* Lane l takes targets from the queue until one needs solving (bad inputs are
 * answered at once); idle when the queue is empty. */
static inline void FN(lane_load)(Ctx *cx, Lanes *L, int l)
{
    const int n = cx->ch.n;
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
        if (!check_target(Tt))
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
        if (FN(lane_next_attempt)(cx, L, l))
            return;
        lane_write(cx, L, l); /* no attempt at all (n_seeds < start) */
    }
}

/* The attempt of lane l ended with `code` after `it` iterations: keep the best,
 * then start the next attempt, or write the target's result and load another. */
static inline void FN(lane_end_attempt)(Ctx *cx, Lanes *L, int l, int code, int it)
{
    const int n = cx->ch.n;
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
    if (code != CODE_OK && FN(lane_next_attempt)(cx, L, l))
        return;
    lane_write(cx, L, l);
    FN(lane_load)(cx, L, l);
}

/* Top of the descent loop of _attempt after an accepted step (or the start):
 * converged, out of iterations, or stalled ends the attempt. */
static inline void FN(lane_top)(Ctx *cx, Lanes *L, int l)
{
    int it = L->it[l];
    if (L->ep[l] <= cx->opts[O_TOL_P] && L->er[l] <= cx->opts[O_TOL_R]) {
        FN(lane_end_attempt)(cx, L, l, CODE_OK, it);
        return;
    }
    if (it >= cx->max_iter) {
        FN(lane_end_attempt)(cx, L, l, CODE_ITER, it);
        return;
    }
    if (it >= L->next_check[l]) {
        if (L->cost[l] > cx->opts[O_STALL_RATIO] * L->cost_ref[l]) {
            FN(lane_end_attempt)(cx, L, l, CODE_STALL, it);
            return;
        }
        L->cost_ref[l] = L->cost[l];
        L->next_check[l] = it + cx->check_every;
    }
}

/* Solve the k x k system A x = b in place (x into b) for SPD A (lower triangle
 * read, overwritten with L D) by L D L^T, per lane; lanes where A is not SPD get
 * 0 in the returned mask. */
static inline __attribute__((always_inline)) vl FN(ldl_solve)(vd (*A)[NMAX], vd *b, int k)
{
    vd dinv[NMAX];
    vl ok = ONES_L;
    for (int j = 0; j < k; j++) {
        vd s = A[j][j];
        for (int i = 0; i < j; i++)
            s -= A[j][i] * A[j][i] * dinv[i];
        ok &= (s > 0.0);
        dinv[j] = 1.0 / FN(vsel)(s > 0.0, s, ONE);
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

/* The task-space step dq = Jw^T (Jw Jw^T + lam I)^-1 ye for m task rows, per lane.
 * Frozen joints have zero columns, so this is also the step of the joint-space
 * form the numba kernel takes when fewer joints than task rows are free. */
static inline __attribute__((always_inline)) vl FN(task_space_step)(vd (*Jw)[NMAX],
                                                                  const vd *ye, vd lam,
                                                                  int n, int m, vd *dq)
{
    vd A[NMAX][NMAX], y[6];
    for (int a = 0; a < m; a++) {
        for (int b = 0; b <= a; b++) {
            vd s = ZERO;
            for (int j = 0; j < n; j++)
                s += Jw[a][j] * Jw[b][j];
            A[a][b] = s;
        }
        A[a][a] += lam;
        y[a] = ye[a];
    }
    vl ok = FN(ldl_solve)(A, y, m);
    for (int j = 0; j < n; j++) {
        vd s = ZERO;
        for (int a = 0; a < m; a++)
            s += Jw[a][j] * y[a];
        dq[j] = s;
    }
    return ok;
}

static void FN(worker)(Ctx *cx)
{
    const int n = cx->ch.n;
    const double *opts = cx->opts;
    const double *cdat = cx->cdat;
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
        FN(lane_load)(cx, &L, l);
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
            if (cdat[4 * n + j] == 0.0) {
                vl hi = L.q[j] >= cdat[n + j];
                vl lo = L.q[j] <= cdat[j];
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
                        Jw[a][j] = FN(vsel)(frz, ZERO, Jw[a][j]);
                    nfree += 1 + frz; /* frz is -1 where frozen */
                    continue;
                }
            }
            nfree += 1;
        }
        for (int l = 0; l < W; l++)
            if (L.mode[l] == MODE_RUN && nfree[l] == 0)
                FN(lane_end_attempt)(cx, &L, l, CODE_STALL, L.it[l]);
        vd lam = L.mu * L.cost + 1e-14;
        vd dq[NMAX];
        vl ok;
        if (m <= n) {
            /* (a constant 6 lets the compiler unroll the full-pose case) */
            if (m == 6)
                ok = FN(task_space_step)(Jw, ye, lam, n, 6, dq);
            else
                ok = FN(task_space_step)(Jw, ye, lam, n, m, dq);
        } else {
            /* joint space (more task rows than joints): (Jw^T Jw + lam I) dq = Jw^T ye */
            vd A[NMAX][NMAX];
            for (int i = 0; i < n; i++) {
                for (int k = 0; k <= i; k++) {
                    vd s = ZERO;
                    for (int a = 0; a < m; a++)
                        s += Jw[a][i] * Jw[a][k];
                    A[i][k] = s;
                }
                A[i][i] += lam;
                vd g = ZERO;
                for (int a = 0; a < m; a++)
                    g += Jw[a][i] * ye[a];
                dq[i] = g;
            }
            ok = FN(ldl_solve)(A, dq, n);
        }
        vd big = ZERO;
        for (int j = 0; j < n; j++) {
            vd ad = FN(vabs)(dq[j]);
            big = FN(vsel)(ad > big, ad, big);
        }
        vd scale = FN(vsel)(big > max_step, max_step / FN(vsel)(big > max_step, big, ONE),
                            ONE);
        vl fresh = (vl)ZERO_L; /* lanes evaluating a new start, or idle */
        vl running = (vl)ZERO_L;
        for (int l = 0; l < W; l++) {
            fresh[l] = L.mode[l] != MODE_RUN ? -1 : 0;
            running[l] = L.mode[l] == MODE_RUN ? -1 : 0;
        }
        for (int j = 0; j < n; j++)
            qn[j] = FN(vsel)(fresh, L.qinit[j], L.q[j] + scale * dq[j]);
        /* project into the limits (2*pi-periodic coordinates first by whole turns) */
        for (int j = 0; j < n; j++) {
            double lo = cdat[j], hi = cdat[n + j];
            vd v = qn[j];
            if (cdat[4 * n + j] == 1.0) {
                vl above = v > hi, below = v < lo;
                int any = 0;
                for (int l = 0; l < W; l++)
                    any |= ((above[l] | below[l]) != 0);
                if (any)
                    for (int l = 0; l < W; l++)
                        v[l] = wrap_into(v[l], lo, hi);
            }
            v = FN(vsel)(v > hi, BR(hi), v);
            v = FN(vsel)(v < lo, BR(lo), v);
            qn[j] = v;
        }
        FN(pose_jac)(&cx->ch, qn, Jn, Tn);
        FN(residual)(Tn, L.Tt, en, running | fresh);
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
            L.q[j] = FN(vsel)(acc, qn[j], L.q[j]);
        for (int a = 0; a < 6; a++) {
            for (int j = 0; j < n; j++)
                L.J[a * NMAX + j] = FN(vsel)(acc, Jn[a * NMAX + j], L.J[a * NMAX + j]);
            L.e[a] = FN(vsel)(acc, en[a], L.e[a]);
        }
        L.cost = FN(vsel)(acc, cost_n, L.cost);
        vd epn, ern;
        for (int l = 0; l < W; l++) {
            epn[l] = sqrt(ep2[l]);
            ern[l] = sqrt(er2[l]);
        }
        L.ep = FN(vsel)(acc, epn, L.ep);
        L.er = FN(vsel)(acc, ern, L.er);
        vd mu_acc = L.mu * mu_down;
        mu_acc = FN(vsel)(mu_acc < MU_MIN, BR(MU_MIN), mu_acc);
        L.mu = FN(vsel)(fresh, BR(mu0), FN(vsel)(acc, mu_acc, L.mu * mu_up));
        /* per-lane control flow */
        for (int l = 0; l < W; l++) {
            int mode = L.mode[l];
            if (mode == MODE_IDLE)
                continue;
            if (mode == MODE_INIT) {
                if (!isfinite(L.cost[l])) {
                    FN(lane_end_attempt)(cx, &L, l, CODE_STALL, 0);
                    continue;
                }
                L.mode[l] = MODE_RUN;
                L.it[l] = 0;
                L.next_check[l] = cx->check_every;
                L.cost_ref[l] = L.cost[l];
                FN(lane_top)(cx, &L, l);
                continue;
            }
            L.it[l]++;
            if (acc[l]) {
                FN(lane_top)(cx, &L, l);
                continue;
            }
            if (L.mu[l] > MU_MAX) {
                FN(lane_end_attempt)(cx, &L, l, CODE_STALL, L.it[l]);
                continue;
            }
            if (L.it[l] >= cx->max_iter)
                FN(lane_end_attempt)(cx, &L, l, CODE_ITER, L.it[l]);
        }
    }
}
