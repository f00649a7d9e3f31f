/*
 * From a planner's path to a shorter, smoother one (robokin.planning): random
 * shortcuts and Chaikin corner cutting, every new edge proven free by plan_check.c's
 * check_edge; the random numbers and the clock are plan_rrtc.c's (deterministic for
 * a seed).
 *
 * plan_simplify is declared in _native/_declare.py (its option vector SP_* too).
 */

/* the option vector (SP_*, SP_N_OPTS entries) is generated from _declare.py's SP_OPTS
 * into kernels_args.gen.h */

/* ---------------------------------------------------------------- shortcuts */

static double path_length(const double *q, long K, int n)
{
    double s = 0.0;
    for (long i = 0; i + 1 < K; i++)
        s += sqrt(dist2(q + (size_t)i * n, q + (size_t)(i + 1) * n, n));
    return s;
}

/* Drop the waypoints of q (*K x n) that lie on the straight segment between their
 * neighbours (to rounding: off it by at most 1e-12 of its length), as RRT-Connect's
 * connect steps leave them: the segments on either side are that segment, already
 * checked. */
static void drop_collinear(double *q, long *K, int n)
{
    long m = 1;
    for (long i = 1; i + 1 < *K; i++) {
        const double *a = q + (size_t)(m - 1) * n, *b = q + (size_t)i * n, *c = b + n;
        double ab = 0.0, bc = 0.0, ac = 0.0;
        for (int d = 0; d < n; d++) {
            ab += (b[d] - a[d]) * (b[d] - a[d]);
            bc += (c[d] - b[d]) * (c[d] - b[d]);
            ac += (c[d] - a[d]) * (c[d] - a[d]);
        }
        if (sqrt(ab) + sqrt(bc) <= sqrt(ac) * (1.0 + 1e-12))
            continue; /* b lies on a -> c */
        if (m != i)
            memcpy(q + (size_t)m * n, b, (size_t)n * sizeof(double));
        m++;
    }
    memcpy(q + (size_t)m * n, q + (size_t)(*K - 1) * n, (size_t)n * sizeof(double));
    *K = m + 1;
}

/* Greedy vertex shortcuts of the path q (*K x n, in place): from vertex i = 0 on, the
 * farthest later vertex j >= i + 2 it sees (the edge i -> j proven free, tried from
 * the last vertex down) replaces the vertices between; at most `tries` edges
 * checked. The colliding tries are cheap (plan_check.c probes an edge coarse to fine
 * before proving it), and one success can drop most of a planner's zigzag at once.
 * Returns PC_FREE or PC_ERROR. */
static int shortcut_vertices(Checker *C, double *q, long *K, long tries, double t0,
                             double time_limit)
{
    const int n = C->M->n;
    for (long i = 0; i + 2 < *K && tries > 0; i++) {
        for (long j = *K - 1; j >= i + 2 && tries > 0; j--) {
            if (now_seconds() - t0 > time_limit)
                return PC_FREE;
            tries--;
            int r = check_edge(C, q + (size_t)i * n, q + (size_t)j * n);
            if (r == PC_ERROR || r == PC_UNDECIDED)
                return PC_ERROR;
            if (r == PC_FREE) {
                memmove(q + (size_t)(i + 1) * n, q + (size_t)j * n,
                        (size_t)(*K - j) * n * sizeof(double));
                *K -= j - i - 1;
                break;
            }
        }
    }
    return PC_FREE;
}

/* Shortcutting of the path q (*K x n, capacity cap rows, in place): first greedy
 * vertex shortcuts (shortcut_vertices, opts[SP_VERTEX_TRIES] edges), then random
 * pairs of points on two segments joined straight, each kept only when free and
 * shorter; opts[SP_MAX_FAIL] failures in a row end the second phase. Returns PC_FREE
 * or PC_ERROR. */
static int shortcut(Checker *C, double *q, long *K, long cap, const double *opts, Rng *rng)
{
    const int n = C->M->n;
    const double t0 = now_seconds();
    if (*K > 2)
        drop_collinear(q, K, n);
    if (shortcut_vertices(C, q, K, (long)opts[SP_VERTEX_TRIES], t0, opts[SP_TIME]) == PC_ERROR)
        return PC_ERROR;
    long fails = 0;
    double a[MAXJ], b[MAXJ];
    for (long it = 0; it < (long)opts[SP_TRIES] && *K > 2; it++) {
        if (fails >= (long)opts[SP_MAX_FAIL] || now_seconds() - t0 > opts[SP_TIME])
            break;
        long S = *K - 1; /* segments */
        long i = (long)(rng_uniform(rng) * (double)S), j = (long)(rng_uniform(rng) * (double)S);
        double ti = rng_uniform(rng), tj = rng_uniform(rng);
        if (i > j || (i == j && ti > tj)) {
            long x = i;
            i = j;
            j = x;
            double y = ti;
            ti = tj;
            tj = y;
        }
        if (i == j) {
            fails++;
            continue;
        }
        const double *qi = q + (size_t)i * n, *qj = q + (size_t)j * n;
        for (int d = 0; d < n; d++) {
            a[d] = qi[d] + ti * (qi[n + d] - qi[d]);
            b[d] = qj[d] + tj * (qj[n + d] - qj[d]);
        }
        /* the stretch a -> q[i+1] .. q[j] -> b against the straight a -> b */
        double old = sqrt(dist2(a, qi + n, n)) + path_length(qi + n, j - i, n) +
                     sqrt(dist2(qj, b, n));
        double shorter = sqrt(dist2(a, b, n));
        if (!(shorter < old - 1e-9 * (1.0 + old))) {
            fails++;
            continue;
        }
        int r = check_edge(C, a, b);
        if (r == PC_ERROR || r == PC_UNDECIDED)
            return PC_ERROR;
        if (r != PC_FREE) {
            fails++;
            continue;
        }
        /* new path: q[0..i], a, b, q[j+1..]: j - i vertices out, 2 in */
        long newK = *K - (j - i) + 2;
        if (newK > cap) {
            fails++;
            continue;
        }
        memmove(q + (size_t)(i + 3) * n, q + (size_t)(j + 1) * n,
                (size_t)(*K - j - 1) * n * sizeof(double));
        memcpy(q + (size_t)(i + 1) * n, a, (size_t)n * sizeof(double));
        memcpy(q + (size_t)(i + 2) * n, b, (size_t)n * sizeof(double));
        *K = newK;
        fails = 0;
    }
    return PC_FREE;
}

/* ------------------------------------------------------------ corner cutting */

/* Chaikin's corner cutting (Chaikin, "An algorithm for high speed curve generation",
 * Computer Graphics and Image Processing 3(4), 1974) of the corners of q (*K x n)
 * that turn by more than `sharp` [rad], `rounds` times: corner w_i becomes the
 * points a quarter of the way to its neighbours when the edge between them is free
 * (else it stays); the other new segments lie on old ones. *q may be reallocated.
 * Returns PC_FREE, or PC_ERROR (no memory, a failed or missing callable). */
static int cut_corners(Checker *C, double **q, long *K, int rounds, double sharp)
{
    const int n = C->M->n;
    const double cos_sharp = cos(sharp);
    for (int round = 0; round < rounds && *K >= 3; round++) {
        const double *w = *q;
        double *out = malloc((size_t)(2 * *K) * n * sizeof(double));
        if (out == NULL)
            return PC_ERROR;
        long m = 0;
        int cut_any = 0;
        memcpy(out, w, (size_t)n * sizeof(double));
        m = 1;
        for (long i = 1; i + 1 < *K; i++) {
            const double *p = w + (size_t)(i - 1) * n, *c = p + n, *r = c + n;
            double uu = 0.0, vv = 0.0, uv = 0.0;
            for (int d = 0; d < n; d++) {
                double u = c[d] - p[d], v = r[d] - c[d];
                uu += u * u;
                vv += v * v;
                uv += u * v;
            }
            int sharp_here = uu > 0.0 && vv > 0.0 && uv < cos_sharp * sqrt(uu * vv);
            double a[MAXJ], b[MAXJ];
            for (int d = 0; d < n; d++) {
                a[d] = c[d] + 0.25 * (p[d] - c[d]);
                b[d] = c[d] + 0.25 * (r[d] - c[d]);
            }
            int ok = 0;
            if (sharp_here) {
                int res = check_edge(C, a, b);
                if (res == PC_ERROR || res == PC_UNDECIDED) {
                    free(out);
                    return PC_ERROR;
                }
                ok = res == PC_FREE;
            }
            if (ok) {
                memcpy(out + (size_t)m++ * n, a, (size_t)n * sizeof(double));
                memcpy(out + (size_t)m++ * n, b, (size_t)n * sizeof(double));
                cut_any = 1;
            } else {
                memcpy(out + (size_t)m++ * n, c, (size_t)n * sizeof(double));
            }
        }
        memcpy(out + (size_t)m++ * n, w + (size_t)(*K - 1) * n, (size_t)n * sizeof(double));
        free(*q);
        *q = out;
        *K = m;
        if (!cut_any)
            break;
    }
    return PC_FREE;
}

/* --------------------------------------------------------------- entries */

/* plan_simplify(model, path (K, n), margin (P,), opts (SP_N_OPTS,), seed, exact) ->
 * (path (K', n), stats): random shortcuts, then the sharp corners cut; every new edge
 * checked. */
static PyObject *plan_simplify_body(const plan_simplify_args *a)
{
    Checker C;
    if (!checker_args(a->model, a->n, a->margin, a->P, a->exact, &C))
        return NULL;
    const int n = C.M->n;
    const double *opts = a->opts;
    long K = (long)a->K, cap = 2 * K + 16;
    double *q = malloc((size_t)cap * n * sizeof(double));
    if (q == NULL)
        return check_failed(&C);
    memcpy(q, a->path, (size_t)K * n * sizeof(double));
    Rng rng;
    rng_seed(&rng, (uint64_t)a->seed);
    int r;
    Py_BEGIN_ALLOW_THREADS
    r = shortcut(&C, q, &K, cap, opts, &rng);
    if (r != PC_ERROR)
        r = cut_corners(&C, &q, &K, (int)opts[SP_CUT_ROUNDS], opts[SP_SHARP_TURN]);
    Py_END_ALLOW_THREADS
    if (r == PC_ERROR) {
        free(q);
        return check_failed(&C);
    }
    PyObject *out = path_array(q, K, n);
    free(q);
    work_free(&C.w);
    if (out == NULL)
        return NULL;
    return Py_BuildValue("(NN)", out, stats_tuple(&C.st));
}
