/*
 * Batch numeric IK, several targets per vector: a CPython extension.
 *
 * Why C here when the solver is numba: one Levenberg-Marquardt step is a chain of
 * dependent operations (the transform chain, the 6x6 factorisation), so a scalar
 * kernel leaves most of the CPU's arithmetic units waiting. Advancing W targets
 * at once, one per vector lane, fills them. numba did not vectorise a lane loop
 * written in Python (tried: 1-8 % slower), so the lanes are written here with the
 * GCC/clang vector extension, compiled twice (baseline, and AVX2 + FMA chosen at
 * run time when the CPU has them).
 *
 * It solves what _numeric_kernels.solve_serial / solve_parallel solve (any task
 * mask and weights, dependent joints through q_chain = M q + c) for chains of 1 to
 * NMAX joints. The per-lane logic (seeds, the seed table, limits,
 * acceptance, stall and iteration tests, the best result) is the same as
 * _attempt / _solve_target. The arithmetic order differs (fused multiply-adds;
 * the task-space solve also when frozen joints leave fewer free joints than task
 * rows, the same step in exact arithmetic), so results agree to rounding, not to
 * the bit. numeric.py calls it for batches and falls back to numba when it was not
 * built or the chain is longer.
 *
 * solve(targets (N,4,4), q0 (N,n), seeds (N,R,n), consts (nc+1,4,4), jdat (9,nc),
 *       Mc (nc,n+1), cdat (5,n), opts (N_OPTS,), out (N,n+N_RES), tab (M,12+n),
 *       cstart (G^3+1,) int64, gdat (7,), n_threads) -> (fails, first_bad)
 * Targets are shared out through an atomic counter among n_threads threads; the
 * GIL is released meanwhile.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>
#include <math.h>
#include <string.h>
#ifndef _WIN32
#include <pthread.h>
#endif

#define NMAX 12      /* longer chains take the numba path */
#define W 4          /* lanes per vector */
#define TAB_K_MAX 8  /* as _numeric_kernels.TAB_K_MAX */
#define MAX_THREADS 64

/* mirrors _numeric_kernels (a test compares them) */
enum { O_W = 0, O_TOL_P = 6, O_TOL_R = 7, O_MAX_ITER = 8, O_IDENT = 9, O_USE_Q0 = 10,
       O_MAX_STEP = 11, O_MU0 = 12, O_N_SEEDS = 13, O_PATH_MAX_JUMP = 14,
       O_STALL_EVERY = 15, O_STALL_RATIO = 16, O_MU_DOWN = 17, O_MU_UP = 18,
       O_SEED_SHRINK = 19, O_N_TABLE = 20, O_TABLE_ROT = 21, N_OPTS = 22 };
enum { R_ERR = 0, R_EP = 1, R_ER = 2, R_ITERS = 3, R_RESTARTS = 4, R_CODE = 5,
       N_RES = 6 };
enum { CODE_OK = 0, CODE_ITER = 1, CODE_STALL = 2, CODE_BAD_TARGET = 3,
       CODE_BAD_Q0 = 6 };
#define MU_MAX 1e9
#define MU_MIN 1e-9

enum { MODE_IDLE = 0, MODE_INIT = 1, MODE_RUN = 2 };

typedef double vd __attribute__((vector_size(8 * W)));
typedef long long vl __attribute__((vector_size(8 * W)));

#if W == 4
#define REP(x) {x, x, x, x}
#elif W == 8
#define REP(x) {x, x, x, x, x, x, x, x}
#endif
#define BR(x) ((vd){0} + (x))
static const vd ZERO = REP(0.0);
static const vd ONE = REP(1.0);
static const vl ZERO_L = REP(0);
static const vl ONES_L = REP(-1);
static const vl SIGN_BIT = REP((long long)0x8000000000000000ULL);

#include "../_sincos_consts.h"

typedef struct {
    int n;                /* independent coordinates */
    int nc;               /* chain joints */
    int ident;            /* 1: q_chain = q */
    const double *consts; /* (nc + 1) x 16 */
    const double *jdat;   /* 9 x nc */
    const double *Mc;     /* nc x (n + 1): q_chain = M q + c as [M | c] */
} Chain;

typedef struct {
    Chain ch;
    const double *targets, *q0, *seeds, *cdat, *opts, *tab, *gdat;
    const long long *cstart;
    double *out;
    long N, R, tab_cols;
    int n_seeds, n_tab, max_iter, check_every;
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

/* ------------------------------------------------------------ scalar helpers */

/* True when Tt is finite, has last row 0 0 0 1 and an orthonormal rotation
 * (as _numeric_kernels._check_target). */
static int check_target(const double *T)
{
    for (int i = 0; i < 16; i++)
        if (!isfinite(T[i]))
            return 0;
    if (T[12] != 0.0 || T[13] != 0.0 || T[14] != 0.0 || T[15] != 1.0)
        return 0;
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) {
            double s = T[a] * T[b] + T[4 + a] * T[4 + b] + T[8 + a] * T[8 + b];
            if (fabs(s - (a == b ? 1.0 : 0.0)) > 1e-6)
                return 0;
        }
    double det = T[0] * (T[5] * T[10] - T[6] * T[9]) - T[1] * (T[4] * T[10] - T[6] * T[8]) +
                 T[2] * (T[4] * T[9] - T[5] * T[8]);
    return det > 0.0;
}

/* A 2*pi-periodic coordinate shifted by whole turns into [lo, hi] where possible
 * (the first half of _numeric_kernels._project; the clamp follows). */
static double wrap_into(double v, double lo, double hi)
{
    const double tp = 2.0 * M_PI;
    if (v > hi) {
        double k = ceil((v - hi) / tp);
        if (v - k * tp >= lo)
            v -= k * tp;
    } else if (v < lo) {
        double k = ceil((lo - v) / tp);
        if (v + k * tp <= hi)
            v += k * tp;
    }
    return v;
}

static void project(double *q, const double *cdat, int n)
{
    for (int j = 0; j < n; j++) {
        double lo = cdat[j], hi = cdat[n + j], v = q[j];
        if (cdat[4 * n + j] == 1.0)
            v = wrap_into(v, lo, hi);
        if (v > hi)
            v = hi;
        else if (v < lo)
            v = lo;
        q[j] = v;
    }
}

/* log(R) for the cases outside the small-angle series of the lane code: the
 * atan2 form, and the axis from the symmetric part near pi (as _residual). */
static void rot_log_general(const double *R, double vx, double vy, double vz, double s,
                            double c, double *ev)
{
    if (c > -0.9) {
        double th = atan2(s, c);
        double f = s > 1e-10 ? th / s : 1.0 + s * s / 6.0;
        ev[0] = f * vx;
        ev[1] = f * vy;
        ev[2] = f * vz;
        return;
    }
    double th = atan2(s, c), omc = 1.0 - c;
    double b00 = R[0] - c, b11 = R[4] - c, b22 = R[8] - c, ax, ay, az, d;
    if (b00 >= b11 && b00 >= b22) {
        d = sqrt(fmax(b00 * omc, 1e-300));
        ax = b00 / d;
        ay = 0.5 * (R[1] + R[3]) / d;
        az = 0.5 * (R[2] + R[6]) / d;
    } else if (b11 >= b22) {
        d = sqrt(fmax(b11 * omc, 1e-300));
        ax = 0.5 * (R[1] + R[3]) / d;
        ay = b11 / d;
        az = 0.5 * (R[5] + R[7]) / d;
    } else {
        d = sqrt(fmax(b22 * omc, 1e-300));
        ax = 0.5 * (R[2] + R[6]) / d;
        ay = 0.5 * (R[5] + R[7]) / d;
        az = b22 / d;
    }
    if (ax * vx + ay * vy + az * vz < 0.0) {
        ax = -ax;
        ay = -ay;
        az = -az;
    }
    ev[0] = th * ax;
    ev[1] = th * ay;
    ev[2] = th * az;
}

/* The k = n_tab seed-table rows nearest the target (Tt: top 3x4 row-major) into
 * idx; returns how many were found (as _numeric_kernels._table_nearest). */
static int table_nearest(const Ctx *cx, const double *Tt, int *idx)
{
    const double *g = cx->gdat;
    const int k = cx->n_tab;
    const double rot_w = cx->opts[O_TABLE_ROT];
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
                    for (long row = cx->cstart[cell]; row < cx->cstart[cell + 1]; row++) {
                        const double *t = cx->tab + row * cx->tab_cols;
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
    const int n = cx->ch.n;
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

/* ------------------------------------------------ the lane kernel, per ISA */
#define FN(x) x##_base
#include "_lm_lanes_body.h"
#undef FN

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define HAVE_AVX2_COPY 1
#pragma GCC push_options
#pragma GCC target("avx2,fma")
#define FN(x) x##_avx2
#include "_lm_lanes_body.h"
#undef FN
#pragma GCC pop_options
#endif

typedef void (*worker_fn)(Ctx *);

static worker_fn pick_worker(void)
{
#ifdef HAVE_AVX2_COPY
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
        return worker_avx2;
#endif
    return worker_base;
}

static worker_fn WORKER;

#ifndef _WIN32
static void *thread_main(void *arg)
{
    WORKER((Ctx *)arg);
    return NULL;
}
#endif

static void run_threads(Ctx *cx, int n_threads)
{
#ifndef _WIN32
    pthread_t th[MAX_THREADS];
    int started = 0;
    for (int t = 1; t < n_threads; t++) {
        if (pthread_create(&th[started], NULL, thread_main, cx) != 0)
            break; /* fewer threads: the queue still gets emptied */
        started++;
    }
    WORKER(cx);
    for (int t = 0; t < started; t++)
        pthread_join(th[t], NULL);
#else
    (void)n_threads;
    WORKER(cx);
#endif
}

/* ------------------------------------------------------------ Python binding */

static PyArrayObject *arg_array(PyObject *o, const char *name, int typenum, int ndim)
{
    if (!PyArray_Check(o)) {
        PyErr_Format(PyExc_TypeError, "_lm_lanes.solve: %s is not an ndarray", name);
        return NULL;
    }
    PyArrayObject *a = (PyArrayObject *)o;
    if (PyArray_TYPE(a) != typenum || PyArray_NDIM(a) != ndim ||
        !PyArray_IS_C_CONTIGUOUS(a) || !PyArray_ISNOTSWAPPED(a)) {
        PyErr_Format(PyExc_ValueError,
                     "_lm_lanes.solve: %s must be a C-contiguous native %d-D array of "
                     "type %d", name, ndim, typenum);
        return NULL;
    }
    return a;
}

static PyObject *py_solve(PyObject *self, PyObject *args)
{
    PyObject *o[12];
    int n_threads;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOOOOOOOOOi", &o[0], &o[1], &o[2], &o[3], &o[4], &o[5],
                          &o[6], &o[7], &o[8], &o[9], &o[10], &o[11], &n_threads))
        return NULL;
    static const char *names[12] = {"targets", "q0", "seeds", "consts", "jdat", "Mc",
                                    "cdat", "opts", "out", "tab", "cstart", "gdat"};
    static const int ndims[12] = {3, 2, 3, 3, 2, 2, 2, 1, 2, 2, 1, 1};
    PyArrayObject *a[12];
    for (int i = 0; i < 12; i++) {
        a[i] = arg_array(o[i], names[i], i == 10 ? NPY_INT64 : NPY_DOUBLE, ndims[i]);
        if (a[i] == NULL)
            return NULL;
    }
    enum { A_T, A_Q0, A_SEEDS, A_CONSTS, A_JDAT, A_MC, A_CDAT, A_OPTS, A_OUT, A_TAB,
           A_CSTART, A_GDAT };
#define DIM(k, d) PyArray_DIMS(a[k])[d]
    npy_intp N = DIM(A_T, 0), M = DIM(A_TAB, 0);
    int n = (int)DIM(A_Q0, 1), nc = (int)DIM(A_JDAT, 1);
    const double *opts = (const double *)PyArray_DATA(a[A_OPTS]);
    int ident = DIM(A_OPTS, 0) == N_OPTS && opts[O_IDENT] == 1.0;
    int ok = DIM(A_T, 1) == 4 && DIM(A_T, 2) == 4 && DIM(A_Q0, 0) == N &&
             DIM(A_SEEDS, 0) == N && DIM(A_SEEDS, 1) >= 1 && DIM(A_SEEDS, 2) == n &&
             n >= 1 && n <= NMAX && nc >= 1 && nc <= NMAX && (!ident || nc == n) &&
             DIM(A_CONSTS, 0) == nc + 1 && DIM(A_CONSTS, 1) == 4 && DIM(A_CONSTS, 2) == 4 &&
             DIM(A_JDAT, 0) == 9 && DIM(A_MC, 0) == nc && DIM(A_MC, 1) == n + 1 &&
             DIM(A_CDAT, 0) == 5 && DIM(A_CDAT, 1) == n && DIM(A_OPTS, 0) == N_OPTS &&
             DIM(A_OUT, 0) == N && DIM(A_OUT, 1) == n + N_RES &&
             (M == 0 || DIM(A_TAB, 1) == 12 + n) && DIM(A_GDAT, 0) == 7 &&
             PyArray_ISWRITEABLE(a[A_OUT]);
    if (!ok) {
        PyErr_SetString(PyExc_ValueError, "_lm_lanes.solve: inconsistent array shapes");
        return NULL;
    }
    int m = 0;
    for (int i = 0; i < 6; i++)
        m += opts[O_W + i] > 0.0;
    if (m == 0) {
        PyErr_SetString(PyExc_ValueError, "_lm_lanes.solve: no task row selected");
        return NULL;
    }
    Ctx cx;
    memset(&cx, 0, sizeof(cx));
    cx.ch.n = n;
    cx.ch.nc = nc;
    cx.ch.ident = ident;
    cx.ch.consts = (const double *)PyArray_DATA(a[A_CONSTS]);
    cx.ch.jdat = (const double *)PyArray_DATA(a[A_JDAT]);
    cx.ch.Mc = (const double *)PyArray_DATA(a[A_MC]);
    cx.targets = (const double *)PyArray_DATA(a[A_T]);
    cx.q0 = (const double *)PyArray_DATA(a[A_Q0]);
    cx.seeds = (const double *)PyArray_DATA(a[A_SEEDS]);
    cx.cdat = (const double *)PyArray_DATA(a[A_CDAT]);
    cx.opts = opts;
    cx.out = (double *)PyArray_DATA(a[A_OUT]);
    cx.tab = (const double *)PyArray_DATA(a[A_TAB]);
    cx.cstart = (const long long *)PyArray_DATA(a[A_CSTART]);
    cx.gdat = (const double *)PyArray_DATA(a[A_GDAT]);
    cx.N = (long)N;
    cx.R = (long)DIM(A_SEEDS, 1);
    cx.tab_cols = 12 + n;
    cx.n_seeds = (int)(opts[O_N_SEEDS] < (double)cx.R ? opts[O_N_SEEDS] : (double)cx.R);
    int nt = (int)opts[O_N_TABLE];
    cx.n_tab = M > 0 ? (nt < TAB_K_MAX ? nt : TAB_K_MAX) : 0;
    if (cx.n_tab > 0) {
        long G = (long)cx.gdat[6];
        if (G < 1 || DIM(A_CSTART, 0) != G * G * G + 1) {
            PyErr_SetString(PyExc_ValueError, "_lm_lanes.solve: cstart does not match gdat");
            return NULL;
        }
    }
#undef DIM
    cx.max_iter = (int)opts[O_MAX_ITER];
    cx.check_every = (int)opts[O_STALL_EVERY];
    for (int j = 0; j < n; j++)
        cx.mid[j] = 0.5 * (cx.cdat[2 * n + j] + cx.cdat[3 * n + j]);
    cx.next = 0;
    if (n_threads < 1)
        n_threads = 1;
    if (n_threads > MAX_THREADS)
        n_threads = MAX_THREADS;
    if ((npy_intp)n_threads * W > N)
        n_threads = (int)((N + W - 1) / W) > 0 ? (int)((N + W - 1) / W) : 1;
    Py_BEGIN_ALLOW_THREADS
    run_threads(&cx, n_threads);
    Py_END_ALLOW_THREADS
    long fails = 0, first_bad = -1;
    for (npy_intp i = 0; i < N; i++) {
        double c = cx.out[(size_t)i * (n + N_RES) + n + R_CODE];
        if (c != CODE_OK) {
            fails++;
            if (first_bad < 0 && (c == CODE_BAD_TARGET || c == CODE_BAD_Q0))
                first_bad = (long)i;
        }
    }
    return Py_BuildValue("(ll)", fails, first_bad);
}

/* select_isa("baseline" | "avx2+fma") -> the one in use; for tests of the copy this
 * CPU would not pick. ValueError when the CPU (or build) lacks it. */
static PyObject *py_select_isa(PyObject *self, PyObject *args)
{
    const char *name;
    (void)self;
    if (!PyArg_ParseTuple(args, "s", &name))
        return NULL;
    if (strcmp(name, "baseline") == 0)
        WORKER = worker_base;
    else if (strcmp(name, "avx2+fma") == 0 && pick_worker() != worker_base)
        WORKER = pick_worker();
    else {
        PyErr_Format(PyExc_ValueError, "select_isa: %s is not available here", name);
        return NULL;
    }
    return PyUnicode_FromString(WORKER == worker_base ? "baseline" : "avx2+fma");
}

static PyMethodDef methods[] = {
    {"select_isa", py_select_isa, METH_VARARGS,
     "select_isa(name) -> name: run the 'baseline' or the 'avx2+fma' copy."},
    {"solve", py_solve, METH_VARARGS,
     "solve(targets, q0, seeds, consts, jdat, Mc, cdat, opts, out, tab, cstart, "
     "gdat, n_threads) -> (fails, first_bad): batch IK, W targets per vector."},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_lm_lanes",
                                    "Batch numeric IK, several targets per vector.", -1,
                                    methods, NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__lm_lanes(void)
{
    import_array();
    WORKER = pick_worker();
    PyObject *m = PyModule_Create(&module);
    if (m == NULL)
        return NULL;
    PyModule_AddIntConstant(m, "LANES", W);
    PyModule_AddIntConstant(m, "NMAX", NMAX);
    PyModule_AddIntConstant(m, "TAB_K_MAX", TAB_K_MAX);
    PyModule_AddIntConstant(m, "N_OPTS", N_OPTS);
    PyModule_AddIntConstant(m, "N_RES", N_RES);
    PyModule_AddIntConstant(m, "O_TABLE_ROT", O_TABLE_ROT);
    PyModule_AddIntConstant(m, "R_CODE", R_CODE);
    PyModule_AddIntConstant(m, "CODE_BAD_Q0", CODE_BAD_Q0);
    PyModule_AddStringConstant(m, "ISA", WORKER == worker_base ? "baseline" : "avx2+fma");
    return m;
}
