/*
 * State and edge validity for robokin.planning: a compiled model of one robot in one
 * scene (shapes, pairs, motion-bound coefficients; built once by plan_model and
 * owned by the Python Planner through a capsule), and the checks the planners call.
 *
 * A state is free when every checked pair (robot shape against scene object, and
 * robot shape against robot shape) is farther apart than its margin. Each pair
 * first gets a cheap lower bound (the robot shape's bounding ball against the
 * object's rounded box, or against the other shape's ball); only when that does
 * not settle the question its exact distance (plan_geom.c: closed forms, GJK,
 * after broadphase.c's rounded-box bound for GJK pairs) is computed. Every value
 * used is a lower bound, so "free" is never optimistic. A mesh is checked through
 * its convex hull; when the hull does not clear it, the caller's `exact` callable
 * (coal, in Python) gives the real distance.
 *
 * An edge (the straight joint-space segment q(t) = q0 + t (q1 - q0), t in [0, 1])
 * is free by conservative advancement. A point of a shape on link k moves at speed
 * at most sum_j w_j |dv_j| (Schwarzer, Saha & Latombe, "Adaptive dynamic collision
 * checking for single and multiple articulated robots in complex environments",
 * IEEE T-RO 21(3), 2005, eq. 1): dv_j the change of chain joint j over the edge, w_j
 * a bound on the point's distance from joint j's axis (1 for a prismatic joint)
 * while t runs over the interval. w_j is the smaller of
 *   - the static reach R_j of the shape from joint j's origin (link constants and
 *     the shape's bounding ball; prismatic joints in between at their largest
 *     travel), bounded once per model, and
 *   - the ball's distance from the axis at a state of the interval, plus how far
 *     the joints after j can move the shape within the interval (sum over k > j of
 *     w_k |dv_k| times the interval's length),
 * so the pair's distance is Lipschitz in t with that rate. An interval whose end
 * bounds satisfy d(ta) + d(tb) > rate (tb - ta) + 2 margin holds no point at or
 * below the margin. Intervals that do not pass are halved, level by level (all
 * midpoints of a level go through the forward kinematics together, W states per
 * vector: lanes across states), only for the pairs still open, until every pair
 * passes (free) or a bound at or below the margin is exact (collision). An
 * interval still open after PC_MAX_LEVEL halvings, or an edge needing more than
 * PC_MAX_SAMPLES states, counts as a collision: never "free" without a proof.
 *
 * The entries (plan_model, plan_check_states, plan_check_edges, plan_distances) are
 * declared in _native/_declare.py; their generated entry points check every argument
 * but the model capsule and its sizes, which checker_args checks here.
 */
#include <stdint.h>

#include "chain.h"

#define PC_EPS 1e-9            /* [m] taken off every computed distance (rounding) */
#define PC_MAX_LEVEL 48        /* halvings of an edge before an open pair counts as hit */
#define PC_MAX_SAMPLES 200000  /* states per edge before it counts as hit */
#define PC_PROBE_STEP 0.3      /* [m] probe an edge's levels until its shapes move at
                                  most this far between probed states (probe_depth) */
#define PC_PROBE_LEVELS 5      /* at most: 2^5 + 1 states */
#define PC_CAPSULE "robokin.plan_model"

/* min and max of two doubles that are never NaN here (libm's fmin/fmax are calls) */
static inline double dmin(double a, double b)
{
    return a < b ? a : b;
}

static inline double dmax(double a, double b)
{
    return a > b ? a : b;
}

enum { PC_FREE = 0, PC_HIT = 1, PC_UNDECIDED = 2, PC_ERROR = 3 };

/* The compiled model. Shapes 0 .. S-1 are the robot's (rb poses in their link
 * frames), S .. S+O-1 the scene objects' (rb poses in the world). */
typedef struct {
    double *packed;
    Chain ch;
    int n, nc, S, O, N, P, H;
    int *kind, *link, *hs, *hn;   /* per shape (N): core kind, link (-1), hull slice */
    int *centre_in;               /* per shape: its rb centre lies in the shape */
    int *core_ok;                 /* per shape: point_box on (rb, h) is its core's distance */
    double *rb, *h, *rad, *cr;    /* per shape: rb pose (16), half sizes (3), rounding
                                     radius, cylinder radius */
    double *rho;                  /* per shape: radius of a ball about the rb centre
                                     holding the whole shape */
    double *hull;                 /* (H, 3) */
    double *reach;                /* (S, nc): static reach R_j of each robot shape (1 for
                                     a prismatic joint moving it, 0 for joints that do not) */
    int *pa, *pb, *method, *self; /* per pair */
    int *mover, *j0, *j1;         /* per pair: the shape whose motion bounds the pair's,
                                     over chain joints j0 <= j < j1 */
    int *by_link_start, *by_link; /* robot shapes grouped by link: (nc + 3), (S) */
    /* the cheap bounds of every object pair at once (cheap_all), W objects per step */
    int Opad;                     /* objects, padded to a whole number of W */
    double *ob_soa;               /* (16, Opad): centre (3), R^T rows (9), half sizes
                                     (3), radius; padding objects far away */
    int *pair_of;                 /* (S, Opad): the pair of (robot shape, object), -1 */
    int *self_list, n_self;       /* the self pairs */
} PlanModel;

/* One open (pair, interval) of an edge. */
typedef struct {
    int p;
    double la, lb; /* distance bounds at the interval's ends */
    double rate;   /* bound on |d distance / dt| over the interval */
} Item;

typedef struct {
    double ta, tb;
    long first, count; /* its items */
} Span;

/* Work space of the checks (grows, reused by every edge of a planner run). */
typedef struct {
    Span *span[2];
    Item *item[2];
    long span_cap[2], item_cap[2];
    double *q;     /* (cap, n) states of a level */
    double *poses; /* (cap, S, 12) their shape poses */
    double *axes;  /* (cap, nc, 6) their joint axes: origin, unit z */
    double *cum;   /* (cap, S, nc + 1) per state and robot shape, sum_{k >= j} w_k |dv_k|
                      (state_rates) */
    unsigned char *cum_ok; /* (cap, S) whether cum holds them (for this level's h) */
    long q_cap;
    double *rate0; /* (P,) static motion rates of the current edge */
    double *cheap; /* (slots, 2, P): per work-space state of an edge's first levels
                      (edge_ends), its cheap bounds g and ub */
    long cheap_cap; /* slots cheap has room for */
    /* the far end of the last edge whose ends were proven free, with every pair's
     * best lower bound there, its upper bound and whether the lower one is the exact
     * distance: a chain of edges (RRT-Connect's connect steps) starts the next edge
     * from them instead of bounding that state again */
    double *last_q, *last_l, *last_u; /* (n), (P), (P) */
    unsigned char *last_ex;           /* (P) */
    int last_ok;
} Work;

typedef struct {
    long states, bounds, exact, callbacks, edges, unproven;
} Stats;

typedef struct {
    const PlanModel *M;
    const double *margin; /* (P,) */
    PyObject *exact_cb;   /* callable (p, q) -> distance, or NULL */
    Work w;
    Stats st;
    double dv[MAXJ];      /* |change| of each chain joint over the current edge */
    int hit_pair;         /* the pair of the last PC_HIT / PC_UNDECIDED */
    double hit_t;         /* where along the last edge */
} Checker;

/* ------------------------------------------------------------------- model */

static void model_free(PlanModel *M)
{
    if (M == NULL)
        return;
    free(M->packed);
    free(M->kind);
    free(M->rb);
    free(M->hull);
    free(M->pa);
    free(M->reach);
    free(M->by_link_start);
    free(M->ob_soa);
    free(M->pair_of);
    free(M->self_list);
    free(M);
}

/* Every robot shape's placed frame and every joint axis at `count` states q
 * (count x n): poses (count, S, 12), each the top 3x4 of F_link(q) L_shape (fk.c's
 * frames_range, then the shape's rb pose); axes (count, nc, 6), joint k's origin and
 * unit z just after its joint (chain_pose's o, z). W states per step. */
static void model_poses(const PlanModel *M, const double *q, long count, double *poses,
                        double *axes)
{
    const Chain *ch = &M->ch;
    const int nc = ch->nc, S = M->S;
    for (long i = 0; i < count; i += W) {
        int cnt = count - i < W ? (int)(count - i) : W;
        vd qv[MAXJ], t[12], v[MAXJ], s[MAXJ], c[MAXJ], u[12];
        gather(q, ch->n, i, cnt, qv);
        joint_values(ch, qv, v, s, c);
        for (int k = 0; k <= nc + 1; k++) {
            if (k == 0)
                load_top(t, ch->base);
            else if (k == 1)
                load_top(t, ch->consts);
            if (k >= 1 && k <= nc) {
                joint_right(t, ch->kind[k - 1] != 0.0, v[k - 1], s[k - 1], c[k - 1]);
                for (int l = 0; l < cnt; l++) {
                    double *ax = axes + ((size_t)(i + l) * nc + (k - 1)) * 6;
                    for (int r = 0; r < 3; r++) {
                        ax[r] = t[4 * r + 3][l];
                        ax[3 + r] = t[4 * r + 2][l];
                    }
                }
                const_right(t, ch->frame + 16 * (k - 1), NULL);
            }
            for (int e = M->by_link_start[k]; e < M->by_link_start[k + 1]; e++) {
                int sh = M->by_link[e];
                memcpy(u, t, sizeof(u));
                const_right(u, M->rb + 16 * sh, NULL);
                for (int l = 0; l < cnt; l++) {
                    double *o = poses + ((size_t)(i + l) * S + sh) * 12;
                    for (int a = 0; a < 12; a++)
                        o[a] = u[a][l];
                }
            }
            if (k >= 1 && k <= nc)
                const_right(t, ch->link + 16 * (k - 1), NULL);
        }
    }
}

static inline const double *shape_pose(const PlanModel *M, const double *poses, int x)
{
    return x < M->S ? poses + 12 * x : M->rb + 16 * x;
}

static inline void make_core(const PlanModel *M, int x, const double *T, Core *c)
{
    c->kind = M->kind[x];
    c->T = T;
    c->h = M->h + 3 * x;
    c->cr = M->cr[x];
    c->v = M->hull + 3 * (size_t)M->hs[x];
    c->nv = M->hn[x];
}

/* The distance from point c (world) to the box |x_a| <= h_a placed at T (top 3x4). */
static inline double point_box(const double *c, const double *T, const double *h)
{
    double d[3] = {c[0] - T[3], c[1] - T[7], c[2] - T[11]}, s = 0.0;
    for (int a = 0; a < 3; a++) {
        double x = fabs(T[a] * d[0] + T[4 + a] * d[1] + T[8 + a] * d[2]) - h[a];
        if (x > 0.0)
            s += x * x;
    }
    return sqrt(s);
}

/* ------------------------------------------------------------------- bounds */

/* Pair p at one state, cheaply: a lower bound *g (the robot shape's ball against
 * the object's rounded box, or the two balls) and an upper bound *ub (the distance
 * from the robot shape's centre, a point of it, to the other's centre or core, less
 * the rounding radii; +inf where a centre may lie outside its shape or the core is
 * not a box). */
static void pair_cheap(Checker *C, int p, const double *poses, double *g, double *ub)
{
    const PlanModel *M = C->M;
    int a = M->pa[p], b = M->pb[p];
    const double *Ta = shape_pose(M, poses, a), *Tb = shape_pose(M, poses, b);
    double ca[3] = {Ta[3], Ta[7], Ta[11]}, d;
    C->st.bounds++;
    if (M->self[p]) {
        double e[3] = {Tb[3] - ca[0], Tb[7] - ca[1], Tb[11] - ca[2]};
        d = sqrt(dot3(e, e));
        *g = d - M->rho[a] - M->rho[b] - PC_EPS;
        *ub = M->centre_in[a] && M->centre_in[b] ? d - M->rad[a] - M->rad[b] : INFINITY;
    } else {
        d = point_box(ca, Tb, M->h + 3 * b);
        *g = d - M->rho[a] - M->rad[b] - PC_EPS;
        *ub = M->centre_in[a] && M->core_ok[b] ? d - M->rad[a] - M->rad[b] : INFINITY;
    }
}

/* pair_cheap of every pair at one state, into g (P) and ub (P): the object pairs
 * W objects at a time (the balls of each robot shape against the objects' boxes, in
 * lanes; the same formulas as pair_cheap), the self pairs one by one. */
static void cheap_all(Checker *C, const double *poses, double *g, double *ub)
{
    const PlanModel *M = C->M;
    const int Op = M->Opad;
    const double *so = M->ob_soa;
    for (int s = 0; s < M->S; s++) {
        const double *T = poses + 12 * s;
        const vd cx = BR(T[3]), cy = BR(T[7]), cz = BR(T[11]);
        const double rho = M->rho[s] + PC_EPS, rad = M->rad[s];
        const int inside = M->centre_in[s];
        const int *pairs = M->pair_of + (size_t)s * Op;
        for (int j = 0; j < Op; j += W) {
            vd f[16];
            for (int k = 0; k < 16; k++)
                memcpy(&f[k], so + (size_t)k * Op + j, sizeof(vd));
            vd dx = cx - f[0], dy = cy - f[1], dz = cz - f[2], e2 = BR(0.0);
            for (int a = 0; a < 3; a++) {
                vd l = f[3 + 3 * a] * dx + f[4 + 3 * a] * dy + f[5 + 3 * a] * dz;
                vd e = vabs(l) - f[12 + a];
                e = vsel(e > BR(0.0), e, BR(0.0));
                e2 += e * e;
            }
            vd d = vsqrt(e2);
            vd gv = d - rho - f[15];
            vd uv = d - rad - f[15];
            for (int l = 0; l < W; l++) {
                int p = pairs[j + l];
                if (p < 0)
                    continue;
                g[p] = gv[l];
                ub[p] = inside && M->core_ok[M->pb[p]] ? uv[l] : INFINITY;
            }
        }
    }
    for (int k = 0; k < M->n_self; k++) {
        int p = M->self_list[k];
        pair_cheap(C, p, poses, g + p, ub + p);
    }
    C->st.bounds += M->P - M->n_self;
}

/* Pair p's distance bound at one state given its cheap bounds (g, ub), refined only
 * as far as it can matter: returned as it is when g exceeds `all` (it closes every
 * interval it bounds), or when g clears the margin and even the true distance (at
 * most ub) could not exceed `any` (nothing to gain); else the exact (or hull)
 * distance. A value at or below the margin is always refined (it decides the
 * state). *exact: the value is the pair's distance, so a value at or below the
 * margin is a real hit (ub at or below the margin is one too). */
static double pair_refine(Checker *C, int p, const double *poses, double g, double ub,
                          double any, double all, int *exact)
{
    const PlanModel *M = C->M;
    const double mg = C->margin[p];
    *exact = 0;
    if (g > mg && g > all)
        return g;
    if (ub <= mg) {
        *exact = 1;
        return ub;
    }
    if (g > mg && ub <= any)
        return g;
    int a = M->pa[p], b = M->pb[p], method = M->method[p];
    const double *Ta = shape_pose(M, poses, a), *Tb = shape_pose(M, poses, b);
    if (method == PD_GJK || method == PD_HULL) {
        double s = sat_gap(Ta, M->h + 3 * a, M->rad[a], Tb, M->h + 3 * b, M->rad[b]) - PC_EPS;
        if (s > g)
            g = s;
        if (g > mg && (g > all || ub <= any))
            return g;
    }
    Core A, B;
    make_core(M, a, Ta, &A);
    make_core(M, b, Tb, &B);
    C->st.exact++;
    *exact = method != PD_HULL;
    double d = core_distance(method, &A, &B) - M->rad[a] - M->rad[b] - PC_EPS;
    return d > g ? d : g;
}

/* The static motion rate of pair p over the current edge: sum_j R_j |dv_j|. */
static double static_rate(const Checker *C, int p)
{
    const PlanModel *M = C->M;
    const double *R = M->reach + (size_t)M->mover[p] * M->nc;
    double r = 0.0;
    for (int j = M->j0[p]; j < M->j1[p]; j++)
        r += R[j] * C->dv[j];
    return r;
}

/* The motion rates of robot shape s over any interval of length h (in t) that has
 * the state (poses, axes) at one end, into cum (nc + 1): cum[j] = sum_{k >= j} w_k
 * |dv_k|, w_k the smaller of the static reach and the ball's distance from joint k's
 * axis plus what the joints after k move it within the interval (the top of this
 * file); a pair moved by joints j0 <= j < j1 then has rate cum[j0] - cum[j1]. */
static void shape_rates(const Checker *C, int s, const double *poses, const double *axes,
                        double h, double *cum)
{
    const PlanModel *M = C->M;
    const int nc = M->nc;
    const double *R = M->reach + (size_t)s * nc, *T = poses + 12 * s;
    const double c[3] = {T[3], T[7], T[11]}, rho = M->rho[s];
    int top = M->link[s] < nc ? M->link[s] : nc;
    for (int j = top; j <= nc; j++)
        cum[j] = 0.0;
    double after = 0.0;
    for (int j = top - 1; j >= 0; j--) {
        double w = R[j];
        if (M->ch.kind[j] == 0.0) {
            const double *o = axes + 6 * j, *z = o + 3;
            double r0 = c[0] - o[0], r1 = c[1] - o[1], r2 = c[2] - o[2];
            double x0 = r1 * z[2] - r2 * z[1], x1 = r2 * z[0] - r0 * z[2];
            double x2 = r0 * z[1] - r1 * z[0];
            double f = sqrt(x0 * x0 + x1 * x1 + x2 * x2) + rho + after;
            if (f < w)
                w = f;
        }
        double m = w * C->dv[j];
        after += m * h;
        cum[j] = cum[j + 1] + m;
    }
}

/* Pair p's motion rate at work-space state `slot` (intervals of length h), through
 * the state's per-shape cache. */
static double state_rate(Checker *C, int p, long slot, double h)
{
    const PlanModel *M = C->M;
    const int s = M->mover[p], S = M->S, nc = M->nc;
    Work *w = &C->w;
    double *cum = w->cum + ((size_t)slot * S + s) * (nc + 1);
    unsigned char *ok = w->cum_ok + (size_t)slot * S + s;
    if (!*ok) {
        shape_rates(C, s, w->poses + (size_t)slot * S * 12, w->axes + (size_t)slot * nc * 6,
                    h, cum);
        *ok = 1;
    }
    return cum[M->j0[p]] - cum[M->j1[p]];
}

/* The caller's exact distance of pair p at state q (with the GIL); NAN on error. */
static double call_exact(Checker *C, int p, const double *q)
{
    double d = NAN;
    PyGILState_STATE g = PyGILState_Ensure();
    npy_intp dims[1] = {C->M->n};
    PyObject *qa = PyArray_SimpleNew(1, dims, NPY_DOUBLE);
    if (qa != NULL) {
        memcpy(PyArray_DATA((PyArrayObject *)qa), q, (size_t)C->M->n * sizeof(double));
        PyObject *r = PyObject_CallFunction(C->exact_cb, "iO", p, qa);
        Py_DECREF(qa);
        if (r != NULL) {
            d = PyFloat_AsDouble(r);
            Py_DECREF(r);
            if (d == -1.0 && PyErr_Occurred())
                d = NAN;
        }
    }
    PyGILState_Release(g);
    C->st.callbacks++;
    return d;
}

/* A bound at or below the margin: decide it. Returns PC_HIT (a real hit), PC_FREE
 * with *lb raised to the exact distance (a hull bound the mesh itself clears),
 * PC_UNDECIDED (no callable) or PC_ERROR (the callable failed). */
static int settle(Checker *C, int p, int exact, const double *q, double t, double *lb)
{
    if (exact || C->exact_cb == NULL) {
        C->hit_pair = p;
        C->hit_t = t;
        return exact ? PC_HIT : PC_UNDECIDED;
    }
    double d = call_exact(C, p, q);
    if (d != d)
        return PC_ERROR;
    d -= PC_EPS;
    if (d <= C->margin[p]) {
        C->hit_pair = p;
        C->hit_t = t;
        return PC_HIT;
    }
    if (d > *lb)
        *lb = d;
    return PC_FREE;
}

/* ------------------------------------------------------------------- work */

static int grow(void **buf, long *cap, long need, size_t size)
{
    if (need <= *cap)
        return 1;
    long c = *cap > 0 ? *cap : 16;
    while (c < need)
        c *= 2;
    void *p = realloc(*buf, (size_t)c * size);
    if (p == NULL)
        return 0;
    *buf = p;
    *cap = c;
    return 1;
}

/* Room for `count` states (q, poses, axes) in the work space. */
static int work_states(Checker *C, long count)
{
    Work *w = &C->w;
    if (count <= w->q_cap)
        return 1;
    long c = w->q_cap > 0 ? w->q_cap : 16;
    while (c < count)
        c *= 2;
    const PlanModel *M = C->M;
    double *q = realloc(w->q, (size_t)c * M->n * sizeof(double));
    if (q == NULL)
        return 0;
    w->q = q;
    double *ps = realloc(w->poses, ((size_t)c * M->S + 1) * 12 * sizeof(double));
    if (ps == NULL)
        return 0;
    w->poses = ps;
    double *ax = realloc(w->axes, ((size_t)c * M->nc + 1) * 6 * sizeof(double));
    if (ax == NULL)
        return 0;
    w->axes = ax;
    double *cu = realloc(w->cum, ((size_t)c * M->S + 1) * (M->nc + 1) * sizeof(double));
    if (cu == NULL)
        return 0;
    w->cum = cu;
    unsigned char *ok = realloc(w->cum_ok, (size_t)c * M->S + 1);
    if (ok == NULL)
        return 0;
    w->cum_ok = ok;
    w->q_cap = c;
    return 1;
}

static void work_free(Work *w)
{
    for (int k = 0; k < 2; k++) {
        free(w->span[k]);
        free(w->item[k]);
    }
    free(w->q);
    free(w->poses);
    free(w->axes);
    free(w->cum);
    free(w->cum_ok);
    free(w->rate0);
    free(w->cheap);
    free(w->last_q);
    free(w->last_l);
    free(w->last_u);
    free(w->last_ex);
    memset(w, 0, sizeof(*w));
}

static int checker_init(Checker *C, const PlanModel *M, const double *margin, PyObject *cb)
{
    memset(C, 0, sizeof(*C));
    C->M = M;
    C->margin = margin;
    C->exact_cb = cb;
    C->hit_pair = -1;
    C->w.rate0 = malloc(((size_t)M->P + 1) * sizeof(double));
    C->w.cheap = malloc((6 * (size_t)M->P + 1) * sizeof(double));
    C->w.cheap_cap = 3;
    C->w.last_q = malloc(((size_t)M->n + 1) * sizeof(double));
    C->w.last_l = malloc(((size_t)M->P + 1) * sizeof(double));
    C->w.last_u = malloc(((size_t)M->P + 1) * sizeof(double));
    C->w.last_ex = malloc((size_t)M->P + 1);
    return C->w.rate0 != NULL && C->w.cheap != NULL && C->w.last_q != NULL &&
           C->w.last_l != NULL && C->w.last_u != NULL && C->w.last_ex != NULL &&
           work_states(C, 2 * W);
}

/* ------------------------------------------------------------------- checks */

/* Check the states q (count x n); status[i] PC_* and pair[i] the pair that decided it
 * (-1 when free). Returns PC_ERROR on a failed callback, else PC_FREE. */
static int check_states(Checker *C, const double *q, long count, long long *status,
                        long long *pair)
{
    const PlanModel *M = C->M;
    const int S = M->S;
    for (long i0 = 0; i0 < count; i0 += W) {
        long cnt = count - i0 < W ? count - i0 : W;
        model_poses(M, q + (size_t)i0 * M->n, cnt, C->w.poses, C->w.axes);
        C->st.states += cnt;
        for (long l = 0; l < cnt; l++) {
            const double *poses = C->w.poses + (size_t)l * S * 12;
            const double *qi = q + (size_t)(i0 + l) * M->n;
            int code = PC_FREE, who = -1;
            double *G = C->w.cheap, *U = G + M->P;
            cheap_all(C, poses, G, U);
            for (int p = 0; p < M->P && code == PC_FREE; p++) {
                int ex;
                double mg = C->margin[p];
                double lb = G[p] > mg ? G[p] : pair_refine(C, p, poses, G[p], U[p], mg, mg, &ex);
                if (lb <= C->margin[p]) {
                    code = settle(C, p, ex, qi, 0.0, &lb);
                    if (code == PC_ERROR)
                        return PC_ERROR;
                    if (code != PC_FREE)
                        who = p;
                }
            }
            status[i0 + l] = code;
            pair[i0 + l] = who;
        }
    }
    return PC_FREE;
}

/* |change| of every chain joint value over q0 -> q1 into C->dv, through the
 * coupling v = sign (M q + c) + offset. */
static void joint_deltas(Checker *C, const double *q0, const double *q1)
{
    const Chain *ch = &C->M->ch;
    for (int k = 0; k < ch->nc; k++) {
        double x = 0.0;
        if (ch->ident) {
            x = q1[k] - q0[k];
        } else {
            for (int j = 0; j < ch->n; j++)
                x += ch->M[k * ch->n + j] * (q1[j] - q0[j]);
        }
        C->dv[k] = fabs(x);
    }
}

/* Decide the pairs whose cheap bound at work-space state `slot` (q) is at or below
 * their margin; their refined bounds replace G. Returns PC_FREE or what ended it. */
static int probe_state(Checker *C, long slot, const double *q, double t, double *G,
                       const double *U)
{
    const PlanModel *M = C->M;
    const double *poses = C->w.poses + (size_t)slot * M->S * 12;
    for (int p = 0; p < M->P; p++) {
        const double mg = C->margin[p];
        if (G[p] > mg)
            continue;
        int ex;
        double l = pair_refine(C, p, poses, G[p], U[p], mg, mg, &ex);
        if (l <= mg) {
            int r = settle(C, p, ex, q, t, &l);
            if (r != PC_FREE)
                return r;
        }
        G[p] = l; /* refined (or the exact distance coal gave): still a lower bound */
    }
    return PC_FREE;
}

/* The work-space slot of the state at t = (2k + 1) / 2^level of an edge whose first
 * levels were probed (edge_ends): level 1's midpoint is slot 0, q0 and q1 are 1 and
 * 2, level L >= 2 holds slots 1 + 2^(L-1) .. 2^L. */
static inline long probe_slot(int level, long k)
{
    return level == 1 ? 0 : (1L << (level - 1)) + 1 + k;
}

/* Level 0 of check_edge, with the edge's states in the work space by probe_slot: the
 * midpoint, q0, q1, then the midpoints of levels 2 .. `depth` (2^depth + 1 states;
 * check_edge computed the first five, deeper levels are computed as they are probed,
 * each level's states together). The far end, the midpoint and then the deeper midpoints,
 * coarse to fine, are probed first (a planner's new state, or a shortcut, is often in
 * collision, and finding that before the work of proving the pairs between is
 * cheaper; the probed bounds serve levels 1 .. depth), then both ends of every pair;
 * the pairs whose whole edge is not proven go into items (*ni). When q0 is the far
 * end of the last edge whose ends were proven, its bounds are that edge's (lower
 * bounds at the same state: reusing them only saves work). On success q1's bounds are
 * kept for the next edge. Returns PC_FREE or what ended the edge. */
static int edge_ends(Checker *C, const double *q0, const double *q1, int depth, long *ni)
{
    const PlanModel *M = C->M;
    Work *w = &C->w;
    const int P = M->P, S = M->S;
    const double *P0 = w->poses + (size_t)S * 12, *P1 = P0 + (size_t)S * 12;
    double *Gm = w->cheap, *Um = Gm + P, *G0 = Um + P, *U0 = G0 + P, *G1 = U0 + P;
    double *U1 = G1 + P;
    const int n = M->n, reuse = w->last_ok && memcmp(q0, w->last_q, n * sizeof(double)) == 0;
    w->last_ok = 0; /* last_* are rewritten below */
    memset(w->cum_ok, 0, ((1UL << depth) + 1) * (size_t)S);
    cheap_all(C, P1, G1, U1);
    int r = probe_state(C, 2, q1, 1.0, G1, U1);
    if (r != PC_FREE)
        return r;
    for (int level = 1; level <= depth; level++) {
        const long m = 1L << (level - 1);
        if (level >= 3) { /* this level's states (check_edge computed levels 1-2) */
            const long s0 = probe_slot(level, 0);
            model_poses(M, w->q + (size_t)s0 * n, m, w->poses + (size_t)s0 * S * 12,
                        w->axes + (size_t)s0 * M->nc * 6);
            C->st.states += m;
        }
        for (long k = 0; k < m; k++) {
            const long slot = probe_slot(level, k);
            double *G = w->cheap + 2 * (size_t)P * slot;
            cheap_all(C, w->poses + (size_t)slot * S * 12, G, G + P);
            r = probe_state(C, slot, w->q + (size_t)slot * n, (double)(2 * k + 1) / (double)(2 * m),
                            G, G + P);
            if (r != PC_FREE)
                return r;
        }
    }
    if (reuse) {
        memcpy(G0, w->last_l, (size_t)P * sizeof(double));
        memcpy(U0, w->last_u, (size_t)P * sizeof(double));
    } else {
        cheap_all(C, P0, G0, U0);
    }
    *ni = 0;
    for (int p = 0; p < P; p++) {
        const double mg = C->margin[p];
        double g0 = G0[p], u0 = U0[p], g1 = G1[p], u1 = U1[p], rate = w->rate0[p];
        const int ex0 = reuse && w->last_ex[p];
        w->last_l[p] = g1; /* q1's bounds for the next edge (q0's were read above) */
        w->last_u[p] = u1;
        w->last_ex[p] = 0;
        if (g0 > mg && g1 > mg && g0 + g1 > rate + 2 * mg)
            continue;
        rate = dmin(rate, dmin(state_rate(C, p, 1, 1.0), state_rate(C, p, 2, 1.0)));
        if (g0 > mg && g1 > mg && g0 + g1 > rate + 2 * mg)
            continue;
        const double lim = rate + 2 * mg;
        int ex;
        double l0 = ex0 ? g0 : pair_refine(C, p, P0, g0, u0, lim - g1, lim - g1, &ex);
        if (l0 <= mg) {
            r = settle(C, p, ex, q0, 0.0, &l0);
            if (r != PC_FREE)
                return r;
        }
        double l1 = pair_refine(C, p, P1, g1, u1, lim - l0, lim - l0, &ex);
        if (l1 <= mg) {
            r = settle(C, p, ex, q1, 1.0, &l1);
            if (r != PC_FREE)
                return r;
            ex = 0;
        }
        w->last_l[p] = l1;
        w->last_ex[p] = (unsigned char)ex;
        if (l0 + l1 <= lim)
            w->item[0][(*ni)++] = (Item){p, l0, l1, rate};
    }
    memcpy(w->last_q, q1, n * sizeof(double));
    w->last_ok = 1;
    return PC_FREE;
}

/* One level of check_edge: every span of list `cur` (ns of them, ni items) halved at
 * its midpoint, each item refined there and its halves kept where still open, into
 * list 1 - cur. The midpoints of levels 1 .. `depth` are edge_ends' probed states
 * (their poses and cheap bounds in the slots of probe_slot); deeper ones are computed
 * together, span s in slot s. */
static int edge_level(Checker *C, const double *q0, const double *dq, int cur, long *ns,
                      long *ni, int level, int depth)
{
    const PlanModel *M = C->M;
    const int n = M->n, S = M->S, P = M->P;
    Work *w = &C->w;
    const int probed = level <= depth;
    const double scale = (double)(1L << (level - 1));
    if (!probed) {
        for (long s = 0; s < *ns; s++) {
            double t = 0.5 * (w->span[cur][s].ta + w->span[cur][s].tb);
            double *qm = w->q + (size_t)s * n;
            for (int j = 0; j < n; j++)
                qm[j] = q0[j] + t * dq[j];
        }
        model_poses(M, w->q, *ns, w->poses, w->axes);
        C->st.states += *ns;
        memset(w->cum_ok, 0, (size_t)*ns * S);
    }
    const int nxt = 1 - cur;
    if (!grow((void **)&w->span[nxt], &w->span_cap[nxt], 2 * *ns, sizeof(Span)) ||
        !grow((void **)&w->item[nxt], &w->item_cap[nxt], 2 * *ni, sizeof(Item)))
        return PC_ERROR;
    long ns2 = 0, ni2 = 0;
    for (long s = 0; s < *ns; s++) {
        const Span sp = w->span[cur][s];
        const double tm = 0.5 * (sp.ta + sp.tb), half = 0.5 * (sp.tb - sp.ta);
        const long slot = probed ? probe_slot(level, (long)(sp.ta * scale + 0.5)) : s;
        const double *poses = w->poses + (size_t)slot * S * 12;
        const double *qm = w->q + (size_t)slot * n;
        const double *Gs = w->cheap + 2 * (size_t)P * slot, *Us = Gs + P;
        Item *left = w->item[nxt] + ni2, *right = left + sp.count;
        long nl = 0, nr = 0;
        for (long it = sp.first; it < sp.first + sp.count; it++) {
            const Item I0 = w->item[cur][it];
            const double mg = C->margin[I0.p];
            double g, ub, rate = I0.rate;
            if (probed) {
                g = Gs[I0.p];
                ub = Us[I0.p];
            } else {
                pair_cheap(C, I0.p, poses, &g, &ub);
            }
            double lim = rate * half + 2 * mg;
            if (g > mg && g > lim - I0.la && g > lim - I0.lb)
                continue; /* both halves proven */
            rate = dmin(rate, state_rate(C, I0.p, slot, half));
            lim = rate * half + 2 * mg;
            int ex;
            double lm = pair_refine(C, I0.p, poses, g, ub, dmin(lim - I0.la, lim - I0.lb),
                                    dmax(lim - I0.la, lim - I0.lb), &ex);
            if (lm <= mg) {
                int r = settle(C, I0.p, ex, qm, tm, &lm);
                if (r != PC_FREE)
                    return r;
            }
            if (I0.la + lm <= lim)
                left[nl++] = (Item){I0.p, I0.la, lm, rate};
            if (lm + I0.lb <= lim)
                right[nr++] = (Item){I0.p, lm, I0.lb, rate};
        }
        if (nl > 0)
            w->span[nxt][ns2++] = (Span){sp.ta, tm, ni2, nl};
        if (nr > 0) {
            if (nl < sp.count) /* close the gap left by the closed left halves */
                memmove(left + nl, right, (size_t)nr * sizeof(Item));
            w->span[nxt][ns2++] = (Span){tm, sp.tb, ni2 + nl, nr};
        }
        ni2 += nl + nr;
    }
    *ns = ns2;
    *ni = ni2;
    return PC_FREE;
}

/* How many levels of the current edge edge_ends probes before proving it (1: the
 * midpoint only): the fewest that leave at most PC_PROBE_STEP of the largest motion
 * bound of a pair (rate0, [m] over the edge) between probed states, up to
 * PC_PROBE_LEVELS. On the issue-26 problem set (docs/planning.md) 0.3 m gave a 0.5 rad
 * search step 2 levels and a long shortcut 4-5: the median query 6.3 -> 4.9 ms CPU
 * (0.2 m: 5.2, 0.45 m: 5.2, a fixed 2 levels: 5.5). */
static int probe_depth(const Checker *C)
{
    double motion = 0.0;
    for (int p = 0; p < C->M->P; p++)
        motion = dmax(motion, C->w.rate0[p]);
    int d = 1;
    while (d < PC_PROBE_LEVELS && motion > PC_PROBE_STEP * (double)(1L << d))
        d++;
    return d;
}

/* Whether the edge q0 -> q1 is free (PC_FREE), hits (PC_HIT, or not proven free),
 * needs a callable it was not given (PC_UNDECIDED), or the callable failed
 * (PC_ERROR). See the top of this file. */
static int check_edge(Checker *C, const double *q0, const double *q1)
{
    const PlanModel *M = C->M;
    const int n = M->n, P = M->P;
    Work *w = &C->w;
    double dq[MAXJ];
    C->st.edges++;
    joint_deltas(C, q0, q1);
    for (int j = 0; j < n; j++)
        dq[j] = q1[j] - q0[j];
    for (int p = 0; p < P; p++)
        w->rate0[p] = static_rate(C, p);
    const int depth = probe_depth(C);
    const long first = (1L << depth) + 1; /* the states edge_ends computes */
    if (!work_states(C, first) ||
        !grow((void **)&w->cheap, &w->cheap_cap, first, 2 * (size_t)P * sizeof(double)) ||
        !grow((void **)&w->span[0], &w->span_cap[0], 1, sizeof(Span)) ||
        !grow((void **)&w->item[0], &w->item_cap[0], P, sizeof(Item)))
        return PC_ERROR;
    memcpy(w->q + n, q0, n * sizeof(double));
    memcpy(w->q + 2 * n, q1, n * sizeof(double));
    for (int level = 1; level <= depth; level++) {
        const long m = 1L << (level - 1);
        for (long k = 0; k < m; k++) {
            const double t = (double)(2 * k + 1) / (double)(2 * m);
            double *q = w->q + (size_t)probe_slot(level, k) * n;
            for (int j = 0; j < n; j++)
                q[j] = q0[j] + t * dq[j];
        }
    }
    const long now = first < 5 ? first : 5; /* levels 1-2 now, deeper ones when probed */
    model_poses(M, w->q, now, w->poses, w->axes);
    C->st.states += now;
    long ni = 0;
    int r = edge_ends(C, q0, q1, depth, &ni);
    if (r != PC_FREE)
        return r;
    long ns = ni > 0;
    w->span[0][0] = (Span){0.0, 1.0, 0, ni};
    long total = first;
    int cur = 0;
    for (int level = 1; ns > 0; level++) {
        if (level > PC_MAX_LEVEL || total + ns > PC_MAX_SAMPLES) {
            C->st.unproven++;
            C->hit_pair = w->item[cur][w->span[cur][0].first].p;
            C->hit_t = 0.5 * (w->span[cur][0].ta + w->span[cur][0].tb);
            return PC_HIT;
        }
        if (!work_states(C, ns))
            return PC_ERROR;
        total += level > depth ? ns : 0;
        r = edge_level(C, q0, dq, cur, &ns, &ni, level, depth);
        if (r != PC_FREE)
            return r;
        cur = 1 - cur;
    }
    return PC_FREE;
}

/* ---------------------------------------------------------------- arguments */

static void capsule_free(PyObject *cap)
{
    model_free((PlanModel *)PyCapsule_GetPointer(cap, PC_CAPSULE));
}

static const PlanModel *model_arg(PyObject *o)
{
    PlanModel *M = (PlanModel *)PyCapsule_GetPointer(o, PC_CAPSULE);
    if (M == NULL) {
        PyErr_Clear();
        PyErr_SetString(PyExc_ValueError, "robokin._native: model is not a plan_model");
    }
    return M;
}

/* Copy a C-contiguous array's data into a new buffer of `count` items. */
static void *dup_data(const void *data, size_t count, size_t size)
{
    void *p = malloc(count * size + 1);
    if (p != NULL && count > 0)
        memcpy(p, data, count * size);
    return p;
}

/* The tables of cheap_all: the objects' boxes in lanes (padded with boxes far away,
 * which no pair reads), the pair of each (robot shape, object), the self pairs. */
static int model_lanes(PlanModel *M)
{
    const int O = M->O, S = M->S, Op = ((O + W - 1) / W) * W;
    M->Opad = Op;
    M->ob_soa = malloc((16 * (size_t)Op + 1) * sizeof(double));
    M->pair_of = malloc(((size_t)S * Op + 1) * sizeof(int));
    M->self_list = malloc(((size_t)M->P + 1) * sizeof(int));
    if (!M->ob_soa || !M->pair_of || !M->self_list) {
        PyErr_NoMemory();
        return 0;
    }
    for (int j = 0; j < Op; j++) {
        const double *T = j < O ? M->rb + 16 * (size_t)(S + j) : NULL;
        double col[16];
        for (int k = 0; k < 16; k++)
            col[k] = 0.0;
        if (T == NULL) {
            col[0] = col[1] = col[2] = 1e30;
            col[3] = col[7] = col[11] = 1.0;
        } else {
            col[0] = T[3];
            col[1] = T[7];
            col[2] = T[11];
            for (int a = 0; a < 3; a++)
                for (int r = 0; r < 3; r++)
                    col[3 + 3 * a + r] = T[4 * r + a]; /* row a of R^T */
            for (int a = 0; a < 3; a++)
                col[12 + a] = M->h[3 * (size_t)(S + j) + a];
            col[15] = M->rad[S + j];
        }
        for (int k = 0; k < 16; k++)
            M->ob_soa[(size_t)k * Op + j] = col[k];
    }
    for (size_t i = 0; i < (size_t)S * Op; i++)
        M->pair_of[i] = -1;
    M->n_self = 0;
    for (int p = 0; p < M->P; p++) {
        if (M->self[p])
            M->self_list[M->n_self++] = p;
        else
            M->pair_of[(size_t)M->pa[p] * Op + (M->pb[p] - S)] = p;
    }
    return 1;
}

/* Fill M's tables from the arguments of plan_model; 0 with ValueError if they are
 * inconsistent, -1 with MemoryError. */
static int model_fill(PlanModel *M, const plan_model_args *a)
{
    /* the entry checked the shapes, S <= N <= 1e6 and P <= 1e7; reach's columns are
     * checked against the chain here */
    const long N = (long)a->N, H = (long)a->H, P = (long)a->P, S = a->S, nc = M->ch.nc;
    if ((long)a->nc != nc)
        return 0;
    M->S = (int)S;
    M->O = (int)(N - S);
    M->N = (int)N;
    M->P = (int)P;
    M->H = (int)H;
    M->n = M->ch.n;
    M->nc = (int)nc;
    M->kind = malloc((size_t)N * 6 * sizeof(int) + 1);
    M->rb = malloc((size_t)N * 22 * sizeof(double) + 1);
    M->hull = dup_data(a->hull, (size_t)H * 3, sizeof(double));
    M->pa = malloc((size_t)P * 7 * sizeof(int) + 1);
    M->reach = dup_data(a->reach, (size_t)S * nc, sizeof(double));
    M->by_link_start = malloc(((size_t)nc + 3 + S) * sizeof(int) + 1);
    if (!M->kind || !M->rb || !M->hull || !M->pa || !M->reach || !M->by_link_start) {
        PyErr_NoMemory();
        return -1;
    }
    M->link = M->kind + N;
    M->hs = M->link + N;
    M->hn = M->hs + N;
    M->centre_in = M->hn + N;
    M->core_ok = M->centre_in + N;
    M->h = M->rb + (size_t)N * 16;
    M->rad = M->h + (size_t)N * 3;
    M->cr = M->rad + N;
    M->rho = M->cr + N;
    const long long *si = a->shape_i;
    const double *sf = a->shape_f;
    for (long x = 0; x < N; x++) {
        long long kind = si[4 * x], link = si[4 * x + 1], hs = si[4 * x + 2], hn = si[4 * x + 3];
        if (kind < PG_POINT || kind > PG_HULL || (x < S ? (link < 0 || link > nc + 1) : link != -1) ||
            hs < 0 || hn < 0 || hs + hn > H || (kind == PG_HULL && hn < 1))
            return 0;
        M->kind[x] = (int)kind;
        M->link[x] = (int)link;
        M->hs[x] = (int)hs;
        M->hn[x] = (int)hn;
        M->centre_in[x] = kind != PG_HULL;
        M->core_ok[x] = kind == PG_POINT || kind == PG_SEGMENT || kind == PG_BOX;
        memcpy(M->rb + 16 * x, sf + 21 * x, 16 * sizeof(double));
        memcpy(M->h + 3 * x, sf + 21 * x + 16, 3 * sizeof(double));
        M->rad[x] = sf[21 * x + 19];
        M->cr[x] = sf[21 * x + 20];
        const double *h = M->h + 3 * x;
        double rho = sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
        if (kind == PG_HULL) {
            rho = 0.0;
            for (long k = hs; k < hs + hn; k++)
                rho = dmax(rho, sqrt(dot3(M->hull + 3 * k, M->hull + 3 * k)));
        }
        M->rho[x] = rho + M->rad[x];
    }
    M->pb = M->pa + P;
    M->method = M->pb + P;
    M->self = M->method + P;
    M->mover = M->self + P;
    M->j0 = M->mover + P;
    M->j1 = M->j0 + P;
    const long long *pi = a->pair_i;
    for (long p = 0; p < P; p++) {
        const long long *r = pi + 7 * p;
        long long pa = r[0], pb = r[1], me = r[2], se = r[3], mv = r[4], j0 = r[5], j1 = r[6];
        if (pa < 0 || pa >= S || pb < 0 || pb >= N || me < PD_SEGSEG || me > PD_HULL ||
            (se != 0 && se != 1) || (se ? pb >= S : pb < S) || (mv != pa && mv != pb) ||
            j0 < 0 || j1 < j0 || j1 > nc)
            return 0;
        M->pa[p] = (int)pa;
        M->pb[p] = (int)pb;
        M->method[p] = (int)me;
        M->self[p] = (int)se;
        M->mover[p] = (int)mv;
        M->j0[p] = (int)j0;
        M->j1[p] = (int)j1;
    }
    /* robot shapes grouped by link (a counting sort) */
    M->by_link = M->by_link_start + nc + 3;
    for (long k = 0; k < nc + 3; k++)
        M->by_link_start[k] = 0;
    for (long x = 0; x < S; x++)
        M->by_link_start[M->link[x] + 1]++;
    for (long k = 0; k < nc + 2; k++)
        M->by_link_start[k + 1] += M->by_link_start[k];
    int fill[MAXJ + 3];
    for (long k = 0; k < nc + 2; k++)
        fill[k] = M->by_link_start[k];
    for (long x = 0; x < S; x++)
        M->by_link[fill[M->link[x]]++] = (int)x;
    return model_lanes(M) ? 1 : -1;
}

/* plan_model(packed, shape_i (N, 4) int64, shape_f (N, 21), hull (H, 3), pair_i (P, 7)
 * int64, reach (S, nc), S) -> capsule: the compiled model (see PlanModel). shape_i:
 * core kind, link (-1 for objects), hull start, hull count; shape_f: rb pose (16),
 * half sizes (3), rounding radius, cylinder radius; pair_i: shape a, shape b (objects
 * after the S robot shapes), method PD_*, self, mover, j0, j1. */
static PyObject *plan_model_body(const plan_model_args *a)
{
    PlanModel *M = calloc(1, sizeof(PlanModel));
    if (M == NULL)
        return PyErr_NoMemory();
    long len = (long)a->len;
    M->packed = dup_data(a->packed, (size_t)len, sizeof(double));
    if (M->packed == NULL) {
        model_free(M);
        return PyErr_NoMemory();
    }
    if (!chain_view(M->packed, len, &M->ch)) {
        model_free(M);
        return bp_fail("plan_model: packed is not a ChainArrays layout");
    }
    int ok = model_fill(M, a);
    if (ok <= 0) {
        model_free(M);
        return ok < 0 ? NULL : bp_fail("plan_model: inconsistent shapes, pairs or indices");
    }
    PyObject *cap = PyCapsule_New(M, PC_CAPSULE, capsule_free);
    if (cap == NULL)
        model_free(M);
    return cap;
}

/* The (model, margin (P,), exact) arguments every check takes. */
/* The (model, q's columns n, margin (P,), exact) arguments every check takes: the
 * generated entry checked the arrays; here the capsule, that n and P are the model's
 * and that exact is None or callable. */
static int checker_args(PyObject *mo, npy_intp n, const double *margin, npy_intp P,
                        PyObject *cb, Checker *C)
{
    const PlanModel *M = model_arg(mo);
    if (M == NULL)
        return 0;
    if (n != M->n) {
        bp_fail("plan: q must have one column per joint of the model");
        return 0;
    }
    if (P != M->P) {
        bp_fail("plan: margin must hold one value per pair");
        return 0;
    }
    if (cb != Py_None && !PyCallable_Check(cb)) {
        bp_fail("plan: exact must be None or a callable (p, q) -> distance");
        return 0;
    }
    if (!checker_init(C, M, margin, cb == Py_None ? NULL : cb)) {
        work_free(&C->w);
        PyErr_NoMemory();
        return 0;
    }
    return 1;
}

static PyObject *stats_tuple(const Stats *s)
{
    return Py_BuildValue("(llllll)", s->states, s->bounds, s->exact, s->callbacks, s->edges,
                         s->unproven);
}

/* A failed check: the callable's exception, or no memory. */
static PyObject *check_failed(Checker *C)
{
    work_free(&C->w);
    if (!PyErr_Occurred())
        PyErr_NoMemory();
    return NULL;
}

/* plan_check_states(model, q (m, n), margin (P,), exact, status (m,) int64,
 * pair (m,) int64) -> stats: PC_* per state and the pair that decided it (-1). */
static PyObject *plan_check_states_body(const plan_check_states_args *a)
{
    Checker C;
    if (!checker_args(a->model, a->n, a->margin, a->P, a->exact, &C))
        return NULL;
    if (!work_states(&C, W))
        return check_failed(&C);
    int r;
    Py_BEGIN_ALLOW_THREADS
    r = check_states(&C, a->q, (long)a->m, a->status, a->pair);
    Py_END_ALLOW_THREADS
    if (r == PC_ERROR)
        return check_failed(&C);
    work_free(&C.w);
    return stats_tuple(&C.st);
}

/* plan_check_edges(model, q0 (m, n), q1 (m, n), margin (P,), exact, status (m,) int64,
 * pair (m,) int64, where (m,) float64) -> stats: per edge PC_*, the pair that decided
 * it (-1 when free) and where along it (t in [0, 1]). */
static PyObject *plan_check_edges_body(const plan_check_edges_args *a)
{
    Checker C;
    if (!checker_args(a->model, a->n, a->margin, a->P, a->exact, &C))
        return NULL;
    const npy_intp m = a->m;
    const int n = C.M->n;
    long long *status = a->status, *pair = a->pair;
    double *where = a->where;
    int r = PC_FREE;
    Py_BEGIN_ALLOW_THREADS
    for (npy_intp i = 0; i < m && r != PC_ERROR; i++) {
        C.hit_pair = -1;
        C.hit_t = NAN;
        r = check_edge(&C, a->q0 + (size_t)i * n, a->q1 + (size_t)i * n);
        status[i] = r;
        pair[i] = r == PC_FREE ? -1 : C.hit_pair;
        where[i] = r == PC_FREE ? NAN : C.hit_t;
    }
    Py_END_ALLOW_THREADS
    if (r == PC_ERROR)
        return check_failed(&C);
    work_free(&C.w);
    return stats_tuple(&C.st);
}

/* plan_distances(model, q (m, n), out (m, P)): per state and pair the certified lower
 * bound on the distance (exact for primitives; a mesh's convex hull). */
static PyObject *plan_distances_body(const plan_distances_args *a)
{
    const PlanModel *M = model_arg(a->model);
    if (M == NULL)
        return NULL;
    const npy_intp m = a->m;
    if (a->n != M->n || a->P != M->P)
        return bp_fail("plan_distances: q must be (m, n) and out (m, P) of the model");
    Checker C;
    memset(&C, 0, sizeof(C));
    C.M = M;
    size_t room = (size_t)M->S * 12 + (size_t)M->nc * 6 + (size_t)M->P + 1;
    double *poses = malloc(room * sizeof(double));
    if (poses == NULL)
        return PyErr_NoMemory();
    double *axes = poses + (size_t)M->S * 12, *none = axes + (size_t)M->nc * 6;
    for (int p = 0; p < M->P; p++)
        none[p] = -INFINITY; /* no margin: always the exact (or hull) distance */
    C.margin = none;
    double *o = a->out;
    Py_BEGIN_ALLOW_THREADS
    for (npy_intp i = 0; i < m; i++) {
        model_poses(M, a->q + (size_t)i * M->n, 1, poses, axes);
        for (int p = 0; p < M->P; p++) {
            int ex;
            double g, ub;
            pair_cheap(&C, p, poses, &g, &ub);
            o[(size_t)i * M->P + p] = pair_refine(&C, p, poses, g, INFINITY, -INFINITY,
                                                  INFINITY, &ex);
        }
    }
    Py_END_ALLOW_THREADS
    free(poses);
    Py_RETURN_NONE;
}
