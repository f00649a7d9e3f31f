/*
 * robokin's compiled kernels as one CPython extension, built once per instruction
 * set from this unity source, three copies: build_base.c (baseline x86-64, or
 * whatever the compiler targets elsewhere), build_avx2.c (AVX2 + FMA) and
 * build_avx512.c (AVX-512 F/DQ/VL; the last two on x86-64 with GCC or clang).
 * robokin._native picks the copy the CPU runs. The GIL is released while a kernel
 * works.
 *
 * Every entry point is generated (kernels_entry.gen.h, from ../_declare.py): it
 * checks every argument (dtype, shape, alignment, index and option ranges; one
 * parser, args.h's kernel_args, reading the kernel's descriptor table) and
 * fills a <name>_args struct, then calls <name>_body, written by hand in the
 * kernel's file (this file holds the bodies of FK, the numeric IK's helpers and the
 * pool's). Argument errors are internal ones (the Python layer validates what
 * users pass) and raise ValueError. docs/conventions.md, "Adding a kernel".
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>
#include <string.h>

#include "chain.h"
#include "args.h"
#include "kernels_args.gen.h"
#include "pool.c"
#include "fk.c"
#include "lm.c"
#include "nearest.c"
#include "six_r.c"
#include "broadphase.c"
#include "plan_geom.c"
#include "plan_check.c"
#include "plan_rrtc.c"
#include "plan_path.c"
#include "general6r.c"
#include "manipulability.c"
#include "pieper.c"
#include "process.c"
#include "self_motion.c"
#include "held_margins.c"
#include "held_closed.c"
#include "held_manifold.c"
#include "near_coincident.c" /* after pieper.c: linalg6.h */
#include "reach.c"

#define F64(a) ((double *)PyArray_DATA(a))
#define DIM(a, d) (PyArray_DIMS(a)[d])

/* ------------------------------------------------------------------- FK etc. */

/* fk1(q, packed) -> (4, 4) pose, or None unless q is a 1-D native float64 array of
 * the chain's length holding finite values and packed an aligned chain layout (the
 * caller then takes the general, validating path). The fast path for one
 * configuration: no pool, no copies. */
static PyObject *fk1_body(const fk1_args *a)
{
    PyObject *qo = a->q, *po = a->packed;
    if (!PyArray_CheckExact(qo) || !PyArray_Check(po)) /* subclasses (masked): checked path */
        Py_RETURN_NONE;
    PyArrayObject *qa = (PyArrayObject *)qo, *pa = (PyArrayObject *)po;
    if (PyArray_TYPE(qa) != NPY_DOUBLE || PyArray_NDIM(qa) != 1 ||
        !PyArray_ISNOTSWAPPED(qa) || !PyArray_ISALIGNED(qa) ||
        PyArray_TYPE(pa) != NPY_DOUBLE || PyArray_NDIM(pa) != 1 ||
        !PyArray_IS_C_CONTIGUOUS(pa) || !PyArray_ISNOTSWAPPED(pa) || !PyArray_ISALIGNED(pa))
        Py_RETURN_NONE;
    Chain ch;
    if (!chain_view(F64(pa), (long)DIM(pa, 0), &ch) || DIM(qa, 0) != ch.n)
        Py_RETURN_NONE;
    const char *qd = PyArray_BYTES(qa);
    npy_intp qs = PyArray_STRIDE(qa, 0);
    vd q[MAXJ], t[12];
    for (int j = 0; j < ch.n; j++)
        q[j] = BR(*(const double *)(qd + j * qs));
    vl ok = chain_pose(&ch, q, t, NULL, NULL);
    if (!ok[0])
        Py_RETURN_NONE;
    npy_intp dims[2] = {4, 4};
    PyObject *out = PyArray_SimpleNew(2, dims, NPY_DOUBLE);
    if (out == NULL)
        return NULL;
    store_pose(t, 0, F64((PyArrayObject *)out));
    return out;
}

/* a batch of FK, Jacobians or frames on the pool */
static PyObject *fk_run(FkJob job, npy_intp N, void (*range)(void *, long, long))
{
    int ok;
    Py_BEGIN_ALLOW_THREADS
    ok = run_fk_job(&job, (long)N, range);
    Py_END_ALLOW_THREADS
    return PyBool_FromLong(ok);
}

static PyObject *fk_body(const fk_args *a)
{
    return fk_run((FkJob){&a->packed, a->q, a->out, NULL, NULL, 1}, a->N, fk_range);
}

static PyObject *jacobian_body(const jacobian_args *a)
{
    return fk_run((FkJob){&a->packed, a->q, a->T, a->J, NULL, 1}, a->N, jacobian_range);
}

static PyObject *frames_body(const frames_args *a)
{
    return fk_run((FkJob){&a->packed, a->q, NULL, NULL, a->out, 1}, a->N, frames_range);
}

/* ---------------------------------------------------------------- numeric IK */

/* lm_solve -> (number not converged, index of the first bad target or q0) */
static PyObject *lm_solve_body(const lm_solve_args *a)
{
    Ctx cx;
    int n = a->packed.n;
    lm_setup(&cx, &a->packed, a->targets, a->q0, a->seeds, (long)a->N, (long)a->R, a->opts,
             a->out, a->tab, (long)a->M, a->cstart, a->gdat);
    Py_BEGIN_ALLOW_THREADS
    lm_run(&cx, a->parallel);
    Py_END_ALLOW_THREADS
    if (__atomic_load_n(&cx.bad_table, __ATOMIC_RELAXED)) /* checked where read (lm.c) */
        return PyErr_Format(PyExc_ValueError, "robokin._native.lm_solve: cstart: an index "
                            "outside [0, M] or decreasing");
    long fails = 0, first_bad = -1;
    for (npy_intp i = 0; i < a->N; i++) {
        double c = cx.out[(size_t)i * (n + N_RES) + n + R_CODE];
        if (c != CODE_OK) {
            fails++;
            if (first_bad < 0 && (c == CODE_BAD_TARGET || c == CODE_BAD_Q0))
                first_bad = (long)i;
        }
    }
    return Py_BuildValue("(ll)", fails, first_bad);
}

/* the numeric IK's restart numbers, from the inputs (lm.c's seed_uniforms) */
static PyObject *seed_uniforms_body(const seed_uniforms_args *a)
{
    Py_BEGIN_ALLOW_THREADS
    seed_uniforms(a->targets, a->q0, (long)a->N, (int)a->n, (long)a->R, a->key, a->base,
                  a->out);
    Py_END_ALLOW_THREADS
    Py_RETURN_NONE;
}

/* lm_path -> index of the first failure, or -1 */
static PyObject *lm_path_body(const lm_path_args *a)
{
    long first;
    Py_BEGIN_ALLOW_THREADS
    first = lm_path(&a->packed, a->targets, a->q_start, (long)a->N, a->opts, a->out);
    Py_END_ALLOW_THREADS
    return PyLong_FromLong(first);
}

/* the residual the numeric IK descends on, [p_t - p; log(R_t R^T)] in the base frame */
static PyObject *pose_error_body(const pose_error_args *a)
{
    const double *c = a->current, *t = a->target;
    double *o = a->out;
    npy_intp N = a->N;
    Py_BEGIN_ALLOW_THREADS
    for (npy_intp i = 0; i < N; i += W) {
        vd x[12], y[12], e[6];
        for (int r = 0; r < 12; r++) {
            double ar[W], br[W];
            for (int l = 0; l < W; l++) {
                npy_intp k = i + l < N ? i + l : i;
                ar[l] = c[16 * k + r];
                br[l] = t[16 * k + r];
            }
            memcpy(&x[r], ar, sizeof(ar));
            memcpy(&y[r], br, sizeof(br));
        }
        pose_residual(x, y, e, BRL(-1));
        for (int l = 0; l < W && i + l < N; l++)
            for (int r = 0; r < 6; r++)
                o[6 * (i + l) + r] = e[r][l];
    }
    Py_END_ALLOW_THREADS
    Py_RETURN_NONE;
}

/* the seed-table rows nearest T, nearest first (for tests) */
static PyObject *table_nearest_body(const table_nearest_args *a)
{
    int idx[TAB_K_MAX];
    int found = table_nearest(a->rows, (long)a->cols, (long)a->M, a->cstart, a->grid,
                              (int)a->k, a->rot_w, a->T, idx);
    if (found < 0) /* not reached: the entry checked every cell start */
        return PyErr_Format(PyExc_ValueError, "robokin._native.table_nearest: cstart: an "
                            "index outside [0, M] or decreasing");
    npy_intp dims[1] = {found};
    PyObject *out = PyArray_SimpleNew(1, dims, NPY_INT64);
    if (out != NULL)
        for (int i = 0; i < found; i++)
            ((long long *)PyArray_DATA((PyArrayObject *)out))[i] = idx[i];
    return out;
}

static PyObject *nearest_body(const nearest_args *a)
{
    nearest_rows(&a->packed, a->Q, a->ok, a->qn, a->is_rev, a->T, (long)a->N, (int)a->k,
                 a->q, a->err, a->found);
    Py_RETURN_NONE;
}

/* (code, index): the first pose that is not a rigid transform and why
 * (pose_problem's code), or (0, -1). */
static PyObject *check_poses_body(const check_poses_args *a)
{
    for (npy_intp i = 0; i < a->N; i++) {
        int code = pose_problem(a->T + 16 * i, POSE_ROW_TOL, a->tol);
        if (code)
            return Py_BuildValue("(in)", code, (Py_ssize_t)i);
    }
    return Py_BuildValue("(in)", 0, (Py_ssize_t)-1);
}

/* chain.h's wrap_into of v[i] into [lo[i], hi[i]] (the one wrap-into-limits rule). */
static PyObject *wrap_into_body(const wrap_into_args *a)
{
    for (npy_intp i = 0; i < a->N; i++)
        a->out[i] = wrap_into(a->v[i], a->lo[i], a->hi[i]);
    Py_RETURN_NONE;
}

static PyObject *sincos_body(const sincos_args *a)
{
    npy_intp N = a->N;
    if (a->scalar) {
        for (npy_intp i = 0; i < N; i++)
            sincos1(a->x[i], &a->s[i], &a->c[i]);
        Py_RETURN_NONE;
    }
    for (npy_intp i = 0; i < N; i += W) {
        vd v, vs, vc;
        for (int l = 0; l < W; l++)
            v[l] = a->x[i + l < N ? i + l : i];
        vsincos(v, &vs, &vc);
        for (int l = 0; l < W && i + l < N; l++) {
            a->s[i + l] = vs[l];
            a->c[i + l] = vc[l];
        }
    }
    Py_RETURN_NONE;
}

/* layout(packed) -> dict of the arrays chain_view finds in it (for tests) */
static PyObject *section(const double *p, int ndim, npy_intp d0, npy_intp d1, npy_intp d2)
{
    npy_intp dims[3] = {d0, d1, d2};
    PyObject *arr = PyArray_SimpleNew(ndim, dims, NPY_DOUBLE);
    if (arr != NULL) {
        npy_intp size = d0 * (ndim > 1 ? d1 : 1) * (ndim > 2 ? d2 : 1);
        memcpy(PyArray_DATA((PyArrayObject *)arr), p, (size_t)size * sizeof(double));
    }
    return arr;
}

static PyObject *layout_body(const layout_args *a)
{
    const Chain *ch = &a->packed;
    int nc = ch->nc, n = ch->n;
    PyObject *d = Py_BuildValue("{s:i,s:i,s:O}", "n_chain", nc, "n", n, "identity",
                                ch->ident ? Py_True : Py_False);
    if (d == NULL)
        return NULL;
#define LAYOUT_ITEM(f, nd, d0, d1, d2, key)                                              \
    {                                                                                    \
        PyObject *v = section(ch->f, nd, d0, d1, d2);                                    \
        if (v == NULL || PyDict_SetItemString(d, key, v) < 0) {                          \
            Py_XDECREF(v);                                                               \
            Py_DECREF(d);                                                                \
            return NULL;                                                                 \
        }                                                                                \
        Py_DECREF(v);                                                                    \
    }
    PACKED_SECTIONS(LAYOUT_ITEM)
#undef LAYOUT_ITEM
    return d;
}

/* ---------------------------------------------------------- pool and the CPU */

static PyObject *num_threads_body(const num_threads_args *a)
{
    (void)a;
    return PyLong_FromLong(pool_threads());
}

static PyObject *set_num_threads_body(const set_num_threads_args *a)
{
    pool_set_threads((int)a->k);
    return PyLong_FromLong(pool_threads());
}

/* The code that runs before a copy knows the CPU runs it (the CPU tests and the
 * module's init) is compiled for the baseline: without it the AVX-512 copy's init
 * filled its constants table with zmm moves, and importing that copy on a CPU without
 * AVX-512 (a documentation tool importing every submodule does) died of SIGILL. */
#if defined(__GNUC__) && defined(__x86_64__)
#define BASELINE_CODE __attribute__((target("no-avx")))
#else
#define BASELINE_CODE
#endif

BASELINE_CODE static int cpu_runs_avx2_fma(void)
{
#if defined(__GNUC__) && defined(__x86_64__)
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#else
    return 0;
#endif
}

BASELINE_CODE static int cpu_runs_avx512(void)
{
#if defined(__GNUC__) && defined(__x86_64__)
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
           __builtin_cpu_supports("avx512vl") && cpu_runs_avx2_fma();
#else
    return 0;
#endif
}

static PyObject *cpu_has_avx2_fma_body(const cpu_has_avx2_fma_args *a)
{
    (void)a;
    return PyBool_FromLong(cpu_runs_avx2_fma());
}

static PyObject *cpu_has_avx512_body(const cpu_has_avx512_args *a)
{
    (void)a;
    return PyBool_FromLong(cpu_runs_avx512());
}

#include "kernels_entry.gen.h"

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, MODULE_NAME,
                                    "robokin's compiled kernels (" ISA_NAME ").", -1,
                                    kernel_methods, NULL, NULL, NULL, NULL};

/* ISA_RUNS (build_*.c): whether this CPU runs this copy; an import of a copy it
 * does not run is an ImportError naming the copy, before any of its instructions. */
BASELINE_CODE PyMODINIT_FUNC MODULE_INIT(void)
{
    if (!(ISA_RUNS)) {
        PyErr_Format(PyExc_ImportError,
                     "robokin._native.%s is the %s copy of robokin's kernels and this "
                     "CPU does not run it; `import robokin` picks the copy the CPU runs",
                     MODULE_NAME, ISA_NAME);
        return NULL;
    }
    import_array();
    PyObject *m = PyModule_Create(&module);
    if (m == NULL)
        return NULL;
    if (PyModule_AddStringConstant(m, "ISA", ISA_NAME) < 0 || add_constants(m) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
