/*
 * The default planner of robokin.planning: RRT-Connect (Kuffner & LaValle,
 * "RRT-Connect: an efficient approach to single-query path planning", ICRA 2000)
 * in joint space, every edge checked by plan_check.c's check_edge (plan_path.c
 * then shortens and smooths the path it finds). OMPL's planners stay available from Python;
 * this copy exists because OMPL's per-call cost into a Python motion validator
 * dominated the planning time (docs/decisions.md has the measurement).
 *
 * Deterministic: every random number comes from a xoshiro256** generator seeded
 * from the caller's seed (Blackman & Vigna, "Scrambled linear pseudorandom number
 * generators", ACM TOMS 47(4), 2021; seeded through splitmix64), so the same inputs
 * give the same path whenever the time limit is not what stopped the search.
 * Nearest neighbours: a linear scan (trees of a few thousand nodes at most). The
 * generator and the clock serve plan_path.c too (included after this file).
 *
 * plan_rrtc is declared in _native/_declare.py (its option vector RC_* too).
 */
#include <time.h>

/* the option vector (RC_RANGE, RC_TIME, RC_MAX_NODES; RC_N_OPTS entries) is generated
 * from _declare.py's RC_OPTS into kernels_args.gen.h */
/* results */
enum { RC_SOLVED = 0, RC_TIMEOUT = 1, RC_NODES = 2, RC_FAILED = 3 };

/* ---------------------------------------------------------------------- rng */

typedef struct {
    uint64_t s[4];
} Rng;

static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static void rng_seed(Rng *r, uint64_t seed)
{
    for (int i = 0; i < 4; i++)
        r->s[i] = splitmix64(&seed);
}

static inline uint64_t rotl(uint64_t x, int k)
{
    return (x << k) | (x >> (64 - k));
}

static uint64_t rng_next(Rng *r)
{
    uint64_t *s = r->s;
    uint64_t out = rotl(s[1] * 5, 7) * 9, t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return out;
}

/* uniform in [0, 1) with 53 random bits */
static inline double rng_uniform(Rng *r)
{
    return (double)(rng_next(r) >> 11) * 0x1.0p-53;
}

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* --------------------------------------------------------------------- trees */

typedef struct {
    double *q;     /* (cap, n) */
    long *parent;  /* (cap,): -1 - root index for a root */
    long count, cap;
    int n;
} Tree;

static long tree_add(Tree *T, const double *q, long parent)
{
    if (T->count == T->cap) {
        long c = T->cap > 0 ? 2 * T->cap : 256;
        double *nq = realloc(T->q, (size_t)c * T->n * sizeof(double));
        if (nq == NULL)
            return -1;
        T->q = nq;
        long *np = realloc(T->parent, (size_t)c * sizeof(long));
        if (np == NULL)
            return -1;
        T->parent = np;
        T->cap = c;
    }
    memcpy(T->q + (size_t)T->count * T->n, q, (size_t)T->n * sizeof(double));
    T->parent[T->count] = parent;
    return T->count++;
}

static void tree_free(Tree *T)
{
    free(T->q);
    free(T->parent);
}

static inline double dist2(const double *a, const double *b, int n)
{
    double s = 0.0;
    for (int j = 0; j < n; j++) {
        double d = a[j] - b[j];
        s += d * d;
    }
    return s;
}

/* The node of T nearest q (the first of equals: deterministic). */
static long tree_nearest(const Tree *T, const double *q)
{
    long best = 0;
    double bd = INFINITY;
    for (long i = 0; i < T->count; i++) {
        double d = dist2(T->q + (size_t)i * T->n, q, T->n);
        if (d < bd) {
            bd = d;
            best = i;
        }
    }
    return best;
}

/* q_new = the point at most `range` from a towards b; returns 1 when it is b. */
static int steer(const double *a, const double *b, double range, int n, double *out)
{
    double d = sqrt(dist2(a, b, n));
    if (d <= range) {
        memcpy(out, b, (size_t)n * sizeof(double));
        return 1;
    }
    double f = range / d;
    for (int j = 0; j < n; j++)
        out[j] = a[j] + f * (b[j] - a[j]);
    return 0;
}

enum { GROW_TRAPPED = 0, GROW_ADVANCED = 1, GROW_REACHED = 2, GROW_ERROR = 3 };

/* One step of T towards target: the new node in *added. */
static int grow_tree(Checker *C, Tree *T, const double *target, double range, double *tmp,
                     long *added)
{
    long near = tree_nearest(T, target);
    const double *qn = T->q + (size_t)near * T->n;
    int reach = steer(qn, target, range, T->n, tmp);
    if (dist2(qn, tmp, T->n) == 0.0)
        return GROW_TRAPPED;
    int r = check_edge(C, qn, tmp);
    if (r == PC_ERROR || r == PC_UNDECIDED)
        return GROW_ERROR;
    if (r != PC_FREE)
        return GROW_TRAPPED;
    *added = tree_add(T, tmp, near);
    if (*added < 0)
        return GROW_ERROR;
    return reach ? GROW_REACHED : GROW_ADVANCED;
}

typedef struct {
    double *q; /* (count, n) */
    long count;
    long goal; /* the goal reached (index into the goals) */
} Path;

/* The path root(a) .. a in A then b .. root(b) in B (a and b hold the same state:
 * b is skipped); A is the start tree when a_is_start, else the order is reversed. */
static int join_path(const Tree *A, long a, const Tree *B, long b, int a_is_start, Path *out)
{
    const Tree *S = a_is_start ? A : B, *G = a_is_start ? B : A;
    long s = a_is_start ? a : b, g = a_is_start ? b : a;
    long ns = 0, ng = 0;
    for (long i = s; i >= 0; i = S->parent[i])
        ns++;
    for (long i = g; i >= 0; i = G->parent[i])
        ng++;
    const int n = A->n;
    out->count = ns + ng - 1;
    out->q = malloc((size_t)out->count * n * sizeof(double));
    if (out->q == NULL)
        return 0;
    long k = ns - 1;
    for (long i = s; i >= 0; i = S->parent[i], k--)
        memcpy(out->q + (size_t)k * n, S->q + (size_t)i * n, (size_t)n * sizeof(double));
    k = ns;
    long last = g;
    for (long i = G->parent[g]; i >= 0; i = G->parent[i], k++) {
        memcpy(out->q + (size_t)k * n, G->q + (size_t)i * n, (size_t)n * sizeof(double));
        last = i;
    }
    out->goal = last; /* the goal tree's roots are the goals, added first */
    return 1;
}

typedef struct {
    long iterations, nodes_start, nodes_goal;
    double seconds;
} RrtStats;

/* RRT-Connect from start to any of the k goals (roots of the goal tree). The caller
 * has checked start and goals. Returns RC_*; the path in *out when RC_SOLVED. */
static int rrt_connect(Checker *C, const double *start, const double *goals, long k,
                       const double *lo, const double *hi, const double *opts, Rng *rng,
                       Path *out, RrtStats *rs)
{
    const int n = C->M->n;
    const double range = opts[RC_RANGE], t0 = now_seconds();
    const long max_nodes = (long)opts[RC_MAX_NODES];
    Tree Ts = {NULL, NULL, 0, 0, n}, Tg = {NULL, NULL, 0, 0, n};
    double qr[MAXJ], tmp[MAXJ];
    int code = RC_FAILED;
    if (tree_add(&Ts, start, -1) < 0)
        goto done;
    for (long i = 0; i < k; i++)
        if (tree_add(&Tg, goals + (size_t)i * n, -1) < 0)
            goto done;
    /* the straight edge to the nearest goal first */
    {
        long g = tree_nearest(&Tg, start);
        int r = check_edge(C, start, Tg.q + (size_t)g * n);
        if (r == PC_ERROR || r == PC_UNDECIDED)
            goto done;
        if (r == PC_FREE) { /* the goal joins the start tree: [start, goal] */
            long a = tree_add(&Ts, Tg.q + (size_t)g * n, 0);
            if (a >= 0 && join_path(&Ts, a, &Tg, g, 1, out))
                code = RC_SOLVED;
            goto done;
        }
    }
    Tree *A = &Ts, *B = &Tg;
    for (long it = 0;; it++) {
        rs->iterations = it;
        if (now_seconds() - t0 > opts[RC_TIME]) {
            code = RC_TIMEOUT;
            break;
        }
        if (Ts.count + Tg.count >= max_nodes) {
            code = RC_NODES;
            break;
        }
        for (int j = 0; j < n; j++)
            qr[j] = lo[j] + rng_uniform(rng) * (hi[j] - lo[j]);
        long added = -1;
        int r = grow_tree(C, A, qr, range, tmp, &added);
        if (r == GROW_ERROR)
            break;
        if (r != GROW_TRAPPED) {
            double target[MAXJ];
            memcpy(target, A->q + (size_t)added * n, (size_t)n * sizeof(double));
            long other = -1;
            int g;
            do {
                g = grow_tree(C, B, target, range, tmp, &other);
            } while (g == GROW_ADVANCED);
            if (g == GROW_ERROR)
                break;
            if (g == GROW_REACHED) {
                code = join_path(A, added, B, other, A == &Ts, out) ? RC_SOLVED : RC_FAILED;
                break;
            }
        }
        Tree *x = A;
        A = B;
        B = x;
    }
done:
    rs->nodes_start = Ts.count;
    rs->nodes_goal = Tg.count;
    rs->seconds = now_seconds() - t0;
    tree_free(&Ts);
    tree_free(&Tg);
    return code;
}

/* --------------------------------------------------------------- entries */

static PyObject *path_array(const double *q, long K, int n)
{
    npy_intp dims[2] = {K, n};
    PyObject *a = PyArray_SimpleNew(2, dims, NPY_DOUBLE);
    if (a != NULL && K > 0)
        memcpy(PyArray_DATA((PyArrayObject *)a), q, (size_t)K * n * sizeof(double));
    return a;
}

/* plan_rrtc(model, start (n,), goals (k, n), lo (n,), hi (n,), margin (P,), opts
 * (RC_N_OPTS,), seed, exact) -> (code, path (K, n) or None, goal index, stats,
 * (iterations, start nodes, goal nodes, seconds)) */
static PyObject *plan_rrtc_body(const plan_rrtc_args *a)
{
    Checker C;
    if (!checker_args(a->model, a->n, a->margin, a->P, a->exact, &C))
        return NULL;
    const int n = C.M->n;
    Rng rng;
    rng_seed(&rng, (uint64_t)a->seed);
    Path path = {NULL, 0, -1};
    RrtStats rs = {0, 0, 0, 0.0};
    int code;
    Py_BEGIN_ALLOW_THREADS
    code = rrt_connect(&C, a->start, a->goals, (long)a->k, a->lo, a->hi, a->opts, &rng, &path,
                       &rs);
    Py_END_ALLOW_THREADS
    if (PyErr_Occurred()) {
        free(path.q);
        return check_failed(&C);
    }
    PyObject *pa;
    if (code == RC_SOLVED) {
        pa = path_array(path.q, path.count, n);
    } else {
        pa = Py_None;
        Py_INCREF(pa);
    }
    free(path.q);
    work_free(&C.w);
    if (pa == NULL)
        return NULL;
    return Py_BuildValue("(iNlN(llld))", code, pa, path.goal, stats_tuple(&C.st), rs.iterations,
                         rs.nodes_start, rs.nodes_goal, rs.seconds);
}
