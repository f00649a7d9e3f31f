/*
 * robokin's compiled kernels as one CPython extension, built once per instruction
 * set from this unity source: build_base.c (baseline x86-64, or whatever the
 * compiler targets elsewhere) and build_avx2.c (AVX2 + FMA).
 * robokin._native picks the copy the CPU runs. The GIL is released while a kernel
 * works; argument errors here are internal ones (the Python layer validates what
 * users pass) and raise ValueError.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>
#include <string.h>

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

/* ---------------------------------------------------------------- arguments */

/* o as a C-contiguous, aligned, native float64 (or int64) array of ndim dims
 * (writeable when asked); NULL with ValueError otherwise. */
static PyArrayObject *array_arg(PyObject *o, const char *name, int typenum, int ndim,
                                int writeable)
{
    if (!PyArray_Check(o)) {
        PyErr_Format(PyExc_ValueError, "robokin._native: %s is not an ndarray", name);
        return NULL;
    }
    PyArrayObject *a = (PyArrayObject *)o;
    if (PyArray_TYPE(a) != typenum || PyArray_NDIM(a) != ndim ||
        !PyArray_IS_C_CONTIGUOUS(a) || !PyArray_ISNOTSWAPPED(a) || !PyArray_ISALIGNED(a) ||
        (writeable && !PyArray_ISWRITEABLE(a))) {
        PyErr_Format(PyExc_ValueError,
                     "robokin._native: %s must be a C-contiguous native %s array with %d "
                     "dimension(s)%s", name, typenum == NPY_INT64 ? "int64" : "float64",
                     ndim, writeable ? ", writeable" : "");
        return NULL;
    }
    return a;
}

#define F64(a) ((double *)PyArray_DATA(a))
#define DIM(a, d) (PyArray_DIMS(a)[d])

static int chain_arg(PyObject *o, Chain *ch)
{
    PyArrayObject *p = array_arg(o, "packed", NPY_DOUBLE, 1, 0);
    if (p == NULL)
        return 0;
    if (!chain_view(F64(p), (long)DIM(p, 0), ch)) {
        PyErr_SetString(PyExc_ValueError,
                        "robokin._native: packed is not a ChainArrays layout of at most "
                        "32 joints");
        return 0;
    }
    return 1;
}

/* ------------------------------------------------------------------- FK etc. */

/* fk1(q, packed) -> (4, 4) pose, or None unless q is a 1-D native float64 array of
 * the chain's length holding finite values (the caller then takes the general,
 * validating path). The fast path for one configuration: no pool, no copies. */
static PyObject *py_fk1(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 2) {
        PyErr_SetString(PyExc_TypeError, "fk1(q, packed) takes 2 arguments");
        return NULL;
    }
    PyObject *qo = args[0], *po = args[1];
    if (!PyArray_CheckExact(qo) || !PyArray_Check(po)) /* subclasses (masked): checked path */
        Py_RETURN_NONE;
    PyArrayObject *qa = (PyArrayObject *)qo, *pa = (PyArrayObject *)po;
    if (PyArray_TYPE(qa) != NPY_DOUBLE || PyArray_NDIM(qa) != 1 ||
        !PyArray_ISNOTSWAPPED(qa) || !PyArray_ISALIGNED(qa) ||
        PyArray_TYPE(pa) != NPY_DOUBLE || PyArray_NDIM(pa) != 1 ||
        !PyArray_IS_C_CONTIGUOUS(pa) || !PyArray_ISNOTSWAPPED(pa))
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

/* the (packed, q (N, n)) head of the batch kernels */
static int batch_args(PyObject *po, PyObject *qo, Chain *ch, PyArrayObject **q)
{
    if (!chain_arg(po, ch))
        return 0;
    *q = array_arg(qo, "q", NPY_DOUBLE, 2, 0);
    if (*q == NULL)
        return 0;
    if (DIM(*q, 1) != ch->n) {
        PyErr_SetString(PyExc_ValueError, "robokin._native: q does not fit the chain");
        return 0;
    }
    return 1;
}

/* fk(packed, q (N, n), out (N, 4, 4)) -> all joint values finite */
static PyObject *py_fk(PyObject *self, PyObject *args)
{
    PyObject *po, *qo, *oo;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOO", &po, &qo, &oo))
        return NULL;
    Chain ch;
    PyArrayObject *q, *out;
    if (!batch_args(po, qo, &ch, &q) || !(out = array_arg(oo, "out", NPY_DOUBLE, 3, 1)))
        return NULL;
    long N = (long)DIM(q, 0);
    if (DIM(out, 0) != N || DIM(out, 1) != 4 || DIM(out, 2) != 4) {
        PyErr_SetString(PyExc_ValueError, "robokin._native.fk: out must be (N, 4, 4)");
        return NULL;
    }
    FkJob job = {&ch, F64(q), F64(out), NULL, NULL, 1};
    int ok;
    Py_BEGIN_ALLOW_THREADS
    ok = run_fk_job(&job, N, fk_range);
    Py_END_ALLOW_THREADS
    return PyBool_FromLong(ok);
}

/* jacobian(packed, q (N, n), J (N, 6, n), T (N, 4, 4)) -> all joint values finite */
static PyObject *py_jacobian(PyObject *self, PyObject *args)
{
    PyObject *po, *qo, *jo, *to;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOO", &po, &qo, &jo, &to))
        return NULL;
    Chain ch;
    PyArrayObject *q, *J, *T;
    if (!batch_args(po, qo, &ch, &q) || !(J = array_arg(jo, "J", NPY_DOUBLE, 3, 1)) ||
        !(T = array_arg(to, "T", NPY_DOUBLE, 3, 1)))
        return NULL;
    long N = (long)DIM(q, 0);
    if (DIM(J, 0) != N || DIM(J, 1) != 6 || DIM(J, 2) != ch.n || DIM(T, 0) != N ||
        DIM(T, 1) != 4 || DIM(T, 2) != 4) {
        PyErr_SetString(PyExc_ValueError, "robokin._native.jacobian: bad output shapes");
        return NULL;
    }
    FkJob job = {&ch, F64(q), F64(T), F64(J), NULL, 1};
    int ok;
    Py_BEGIN_ALLOW_THREADS
    ok = run_fk_job(&job, N, jacobian_range);
    Py_END_ALLOW_THREADS
    return PyBool_FromLong(ok);
}

/* frames(packed, q (N, n), out (N, nc + 2, 4, 4)) -> all joint values finite */
static PyObject *py_frames(PyObject *self, PyObject *args)
{
    PyObject *po, *qo, *oo;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOO", &po, &qo, &oo))
        return NULL;
    Chain ch;
    PyArrayObject *q, *out;
    if (!batch_args(po, qo, &ch, &q) || !(out = array_arg(oo, "out", NPY_DOUBLE, 4, 1)))
        return NULL;
    long N = (long)DIM(q, 0);
    if (DIM(out, 0) != N || DIM(out, 1) != ch.nc + 2 || DIM(out, 2) != 4 ||
        DIM(out, 3) != 4) {
        PyErr_SetString(PyExc_ValueError,
                        "robokin._native.frames: out must be (N, n_chain + 2, 4, 4)");
        return NULL;
    }
    FkJob job = {&ch, F64(q), NULL, NULL, F64(out), 1};
    int ok;
    Py_BEGIN_ALLOW_THREADS
    ok = run_fk_job(&job, N, frames_range);
    Py_END_ALLOW_THREADS
    return PyBool_FromLong(ok);
}

/* ---------------------------------------------------------------- numeric IK */

/* lm_solve(packed, targets (N, 4, 4), q0 (N, n), seeds (N, R, n), opts (N_OPTS,),
 *          out (N, n + N_RES), tab (M, 12 + n), cstart (G^3 + 1,) int64, gdat (7,),
 *          parallel) -> (number not converged, index of the first bad target or q0) */
static PyObject *py_lm_solve(PyObject *self, PyObject *args)
{
    PyObject *o[9];
    int parallel;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOOOOOOp", &o[0], &o[1], &o[2], &o[3], &o[4], &o[5],
                          &o[6], &o[7], &o[8], &parallel))
        return NULL;
    Chain ch;
    if (!chain_arg(o[0], &ch))
        return NULL;
    static const char *names[8] = {"targets", "q0", "seeds", "opts", "out", "tab",
                                   "cstart", "gdat"};
    static const int ndims[8] = {3, 2, 3, 1, 2, 2, 1, 1};
    PyArrayObject *a[8];
    for (int i = 0; i < 8; i++) {
        a[i] = array_arg(o[i + 1], names[i], i == 6 ? NPY_INT64 : NPY_DOUBLE, ndims[i],
                         i == 4);
        if (a[i] == NULL)
            return NULL;
    }
    enum { A_T, A_Q0, A_SEEDS, A_OPTS, A_OUT, A_TAB, A_CSTART, A_GDAT };
    npy_intp N = DIM(a[A_T], 0), M = DIM(a[A_TAB], 0);
    int n = ch.n;
    const double *opts = F64(a[A_OPTS]);
    int ok = DIM(a[A_T], 1) == 4 && DIM(a[A_T], 2) == 4 && DIM(a[A_Q0], 0) == N &&
             DIM(a[A_Q0], 1) == n && DIM(a[A_SEEDS], 0) == N && DIM(a[A_SEEDS], 1) >= 1 &&
             DIM(a[A_SEEDS], 2) == n && DIM(a[A_OPTS], 0) == N_OPTS &&
             DIM(a[A_OUT], 0) == N && DIM(a[A_OUT], 1) == n + N_RES &&
             (M == 0 || DIM(a[A_TAB], 1) == 12 + n) && DIM(a[A_GDAT], 0) == 7;
    if (!ok) {
        PyErr_SetString(PyExc_ValueError, "robokin._native.lm_solve: inconsistent shapes");
        return NULL;
    }
    int m = 0;
    for (int i = 0; i < 6; i++)
        m += opts[O_W + i] > 0.0;
    if (m == 0) {
        PyErr_SetString(PyExc_ValueError, "robokin._native.lm_solve: no task row selected");
        return NULL;
    }
    if (M > 0 && opts[O_N_TABLE] > 0) {
        double G = F64(a[A_GDAT])[6];
        if (!(G >= 1.0 && G <= 1024.0) || DIM(a[A_CSTART], 0) != (npy_intp)(G * G * G) + 1) {
            PyErr_SetString(PyExc_ValueError,
                            "robokin._native.lm_solve: cstart does not match gdat");
            return NULL;
        }
    }
    Ctx cx;
    lm_setup(&cx, &ch, F64(a[A_T]), F64(a[A_Q0]), F64(a[A_SEEDS]), (long)N,
             (long)DIM(a[A_SEEDS], 1), opts, F64(a[A_OUT]), F64(a[A_TAB]), (long)M,
             (const long long *)PyArray_DATA(a[A_CSTART]), F64(a[A_GDAT]));
    Py_BEGIN_ALLOW_THREADS
    lm_run(&cx, parallel);
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

/* seed_uniforms(targets (N, 4, 4), q0 (N, n), key, base, out (N, R, n)): the numeric
 * IK's restart numbers, from the inputs (lm.c's seed_uniforms) */
static PyObject *py_seed_uniforms(PyObject *self, PyObject *args)
{
    PyObject *to, *qo, *oo;
    unsigned long long key;
    long base;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOKlO", &to, &qo, &key, &base, &oo))
        return NULL;
    PyArrayObject *T, *q, *out;
    if (!(T = array_arg(to, "targets", NPY_DOUBLE, 3, 0)) ||
        !(q = array_arg(qo, "q0", NPY_DOUBLE, 2, 0)) ||
        !(out = array_arg(oo, "out", NPY_DOUBLE, 3, 1)))
        return NULL;
    npy_intp N = DIM(T, 0), n = DIM(q, 1);
    if (DIM(T, 1) != 4 || DIM(T, 2) != 4 || DIM(q, 0) != N || n < 1 || n > MAXJ ||
        DIM(out, 0) != N || DIM(out, 2) != n || base < 0) {
        PyErr_SetString(PyExc_ValueError, "robokin._native.seed_uniforms: inconsistent shapes");
        return NULL;
    }
    Py_BEGIN_ALLOW_THREADS
    seed_uniforms(F64(T), F64(q), (long)N, (int)n, (long)DIM(out, 1), key, base, F64(out));
    Py_END_ALLOW_THREADS
    Py_RETURN_NONE;
}

/* lm_path(packed, targets (N, 4, 4), q_start (n,), opts, out (N, n + N_RES))
 * -> index of the first failure, or -1 */
static PyObject *py_lm_path(PyObject *self, PyObject *args)
{
    PyObject *po, *to, *qo, *oo, *ro;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOO", &po, &to, &qo, &oo, &ro))
        return NULL;
    Chain ch;
    PyArrayObject *T, *q, *opts, *out;
    if (!chain_arg(po, &ch) || !(T = array_arg(to, "targets", NPY_DOUBLE, 3, 0)) ||
        !(q = array_arg(qo, "q_start", NPY_DOUBLE, 1, 0)) ||
        !(opts = array_arg(oo, "opts", NPY_DOUBLE, 1, 0)) ||
        !(out = array_arg(ro, "out", NPY_DOUBLE, 2, 1)))
        return NULL;
    npy_intp N = DIM(T, 0);
    if (DIM(T, 1) != 4 || DIM(T, 2) != 4 || DIM(q, 0) != ch.n || DIM(opts, 0) != N_OPTS ||
        DIM(out, 0) != N || DIM(out, 1) != ch.n + N_RES) {
        PyErr_SetString(PyExc_ValueError, "robokin._native.lm_path: inconsistent shapes");
        return NULL;
    }
    long first;
    Py_BEGIN_ALLOW_THREADS
    first = lm_path(&ch, F64(T), F64(q), (long)N, F64(opts), F64(out));
    Py_END_ALLOW_THREADS
    return PyLong_FromLong(first);
}

/* pose_error(current (N, 4, 4), target (N, 4, 4), out (N, 6)): the residual the
 * numeric IK descends on, [p_t - p; log(R_t R^T)] in the base frame */
static PyObject *py_pose_error(PyObject *self, PyObject *args)
{
    PyObject *co, *to, *oo;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOO", &co, &to, &oo))
        return NULL;
    PyArrayObject *C, *T, *out;
    if (!(C = array_arg(co, "current", NPY_DOUBLE, 3, 0)) ||
        !(T = array_arg(to, "target", NPY_DOUBLE, 3, 0)) ||
        !(out = array_arg(oo, "out", NPY_DOUBLE, 2, 1)))
        return NULL;
    npy_intp N = DIM(C, 0);
    if (DIM(C, 1) != 4 || DIM(C, 2) != 4 || DIM(T, 0) != N || DIM(T, 1) != 4 ||
        DIM(T, 2) != 4 || DIM(out, 0) != N || DIM(out, 1) != 6) {
        PyErr_SetString(PyExc_ValueError, "robokin._native.pose_error: bad shapes");
        return NULL;
    }
    const double *c = F64(C), *t = F64(T);
    double *o = F64(out);
    Py_BEGIN_ALLOW_THREADS
    for (npy_intp i = 0; i < N; i += W) {
        vd a[12], b[12], e[6];
        for (int r = 0; r < 12; r++) {
            double ar[W], br[W];
            for (int l = 0; l < W; l++) {
                npy_intp k = i + l < N ? i + l : i;
                ar[l] = c[16 * k + r];
                br[l] = t[16 * k + r];
            }
            memcpy(&a[r], ar, sizeof(ar));
            memcpy(&b[r], br, sizeof(br));
        }
        pose_residual(a, b, e, BRL(-1));
        for (int l = 0; l < W && i + l < N; l++)
            for (int r = 0; r < 6; r++)
                o[6 * (i + l) + r] = e[r][l];
    }
    Py_END_ALLOW_THREADS
    Py_RETURN_NONE;
}

/* table_nearest(rows (M, 12 + n), cstart, grid (7,), T (4, 4), k, rot_w) -> (k',)
 * int64: the seed-table rows nearest T, nearest first (for tests) */
static PyObject *py_table_nearest(PyObject *self, PyObject *args)
{
    PyObject *ro, *so, *go, *to;
    int k;
    double rot_w;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOid", &ro, &so, &go, &to, &k, &rot_w))
        return NULL;
    PyArrayObject *rows, *cs, *g, *T;
    if (!(rows = array_arg(ro, "rows", NPY_DOUBLE, 2, 0)) ||
        !(cs = array_arg(so, "cstart", NPY_INT64, 1, 0)) ||
        !(g = array_arg(go, "grid", NPY_DOUBLE, 1, 0)) ||
        !(T = array_arg(to, "T", NPY_DOUBLE, 2, 0)))
        return NULL;
    double G = DIM(g, 0) == 7 ? F64(g)[6] : 0.0;
    if (!(G >= 1.0 && G <= 1024.0) || DIM(cs, 0) != (npy_intp)(G * G * G) + 1 ||
        DIM(rows, 1) < 12 || DIM(T, 0) != 4 || DIM(T, 1) != 4 || k < 1 || k > TAB_K_MAX) {
        PyErr_SetString(PyExc_ValueError, "robokin._native.table_nearest: bad arguments");
        return NULL;
    }
    int idx[TAB_K_MAX];
    int found = table_nearest(F64(rows), (long)DIM(rows, 1),
                              (const long long *)PyArray_DATA(cs), F64(g), k, rot_w, F64(T),
                              idx);
    npy_intp dims[1] = {found};
    PyObject *out = PyArray_SimpleNew(1, dims, NPY_INT64);
    if (out != NULL)
        for (int i = 0; i < found; i++)
            ((long long *)PyArray_DATA((PyArrayObject *)out))[i] = idx[i];
    return out;
}

/* nearest(packed, Q (N, k, n), ok (N, k) bool, qn (N, n), is_rev (n,) bool,
 *         T (N, 4, 4), q (N, n), err (N, 2), found (N,) bool) */
static PyObject *py_nearest(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 9) {
        PyErr_SetString(PyExc_TypeError, "nearest takes 9 arguments");
        return NULL;
    }
    Chain ch;
    PyArrayObject *Q, *ok, *qn, *rev, *T, *q, *err, *found;
    if (!chain_arg(args[0], &ch) || !(Q = array_arg(args[1], "Q", NPY_DOUBLE, 3, 0)) ||
        !(ok = array_arg(args[2], "ok", NPY_BOOL, 2, 0)) ||
        !(qn = array_arg(args[3], "qn", NPY_DOUBLE, 2, 0)) ||
        !(rev = array_arg(args[4], "is_rev", NPY_BOOL, 1, 0)) ||
        !(T = array_arg(args[5], "T", NPY_DOUBLE, 3, 0)) ||
        !(q = array_arg(args[6], "q", NPY_DOUBLE, 2, 1)) ||
        !(err = array_arg(args[7], "err", NPY_DOUBLE, 2, 1)) ||
        !(found = array_arg(args[8], "found", NPY_BOOL, 1, 1)))
        return NULL;
    npy_intp N = DIM(Q, 0), k = DIM(Q, 1);
    int n = ch.n;
    if (DIM(Q, 2) != n || DIM(ok, 0) != N || DIM(ok, 1) != k || DIM(qn, 0) != N ||
        DIM(qn, 1) != n || DIM(rev, 0) != n || DIM(T, 0) != N || DIM(T, 1) != 4 ||
        DIM(T, 2) != 4 || DIM(q, 0) != N || DIM(q, 1) != n || DIM(err, 0) != N ||
        DIM(err, 1) != 2 || DIM(found, 0) != N) {
        PyErr_SetString(PyExc_ValueError, "robokin._native.nearest: inconsistent shapes");
        return NULL;
    }
    nearest_rows(&ch, F64(Q), (const unsigned char *)PyArray_DATA(ok), F64(qn),
                 (const unsigned char *)PyArray_DATA(rev), F64(T), (long)N, (int)k, F64(q),
                 F64(err), (unsigned char *)PyArray_DATA(found));
    Py_RETURN_NONE;
}

/* check_poses(T (N, 4, 4), tol) -> (code, index): the first pose that is not a
 * rigid transform and why (pose_problem's code), or (0, -1). */
static PyObject *py_check_poses(PyObject *self, PyObject *args)
{
    PyObject *to;
    double tol;
    (void)self;
    if (!PyArg_ParseTuple(args, "Od", &to, &tol))
        return NULL;
    PyArrayObject *T = array_arg(to, "T", NPY_DOUBLE, 3, 0);
    if (T == NULL)
        return NULL;
    if (DIM(T, 1) != 4 || DIM(T, 2) != 4) {
        PyErr_SetString(PyExc_ValueError, "robokin._native.check_poses: T must be (N, 4, 4)");
        return NULL;
    }
    const double *p = F64(T);
    for (npy_intp i = 0; i < DIM(T, 0); i++) {
        int code = pose_problem(p + 16 * i, POSE_ROW_TOL, tol);
        if (code)
            return Py_BuildValue("(in)", code, (Py_ssize_t)i);
    }
    return Py_BuildValue("(in)", 0, (Py_ssize_t)-1);
}

/* sincos(x (N,), s (N,), c (N,)): the kernels' sine and cosine (for tests) */
static PyObject *py_sincos(PyObject *self, PyObject *args)
{
    PyObject *xo, *so, *co;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOO", &xo, &so, &co))
        return NULL;
    PyArrayObject *x, *s, *c;
    if (!(x = array_arg(xo, "x", NPY_DOUBLE, 1, 0)) ||
        !(s = array_arg(so, "s", NPY_DOUBLE, 1, 1)) ||
        !(c = array_arg(co, "c", NPY_DOUBLE, 1, 1)))
        return NULL;
    npy_intp N = DIM(x, 0);
    if (DIM(s, 0) != N || DIM(c, 0) != N) {
        PyErr_SetString(PyExc_ValueError, "robokin._native.sincos: sizes differ");
        return NULL;
    }
    for (npy_intp i = 0; i < N; i += W) {
        vd v, vs, vc;
        for (int l = 0; l < W; l++)
            v[l] = F64(x)[i + l < N ? i + l : i];
        vsincos(v, &vs, &vc);
        for (int l = 0; l < W && i + l < N; l++) {
            F64(s)[i + l] = vs[l];
            F64(c)[i + l] = vc[l];
        }
    }
    Py_RETURN_NONE;
}

/* layout(packed) -> dict of the arrays chain_view finds in it (for tests) */
static PyObject *section(const double *p, int ndim, npy_intp d0, npy_intp d1, npy_intp d2)
{
    npy_intp dims[3] = {d0, d1, d2};
    PyObject *a = PyArray_SimpleNew(ndim, dims, NPY_DOUBLE);
    if (a != NULL) {
        npy_intp size = d0 * (ndim > 1 ? d1 : 1) * (ndim > 2 ? d2 : 1);
        memcpy(PyArray_DATA((PyArrayObject *)a), p, (size_t)size * sizeof(double));
    }
    return a;
}

static PyObject *py_layout(PyObject *self, PyObject *args)
{
    PyObject *po;
    (void)self;
    if (!PyArg_ParseTuple(args, "O", &po))
        return NULL;
    Chain ch;
    if (!chain_arg(po, &ch))
        return NULL;
    int nc = ch.nc, n = ch.n;
    return Py_BuildValue(
        "{s:i,s:i,s:O,s:N,s:N,s:N,s:N,s:N,s:N,s:N,s:N,s:N,s:N,s:N,s:N,s:N,s:N,s:N}",
        "n_chain", nc, "n", n, "identity", ch.ident ? Py_True : Py_False,
        "consts", section(ch.consts, 3, nc + 1, 4, 4), "xform", section(ch.xform, 2, nc + 1, 6, 0),
        "kind", section(ch.kind, 1, nc, 0, 0), "sign", section(ch.sign, 1, nc, 0, 0),
        "offset", section(ch.offset, 1, nc, 0, 0), "M", section(ch.M, 2, nc, n, 0),
        "c", section(ch.c, 1, nc, 0, 0), "base", section(ch.base, 2, 4, 4, 0),
        "frame", section(ch.frame, 3, nc, 4, 4), "link", section(ch.link, 3, nc, 4, 4),
        "lower", section(ch.lo, 1, n, 0, 0), "upper", section(ch.hi, 1, n, 0, 0),
        "seed_lower", section(ch.seed_lo, 1, n, 0, 0), "seed_upper", section(ch.seed_hi, 1, n, 0, 0),
        "wrap", section(ch.wrap, 1, n, 0, 0));
}

static PyObject *py_num_threads(PyObject *self, PyObject *args)
{
    (void)self;
    (void)args;
    return PyLong_FromLong(pool_threads());
}

static PyObject *py_set_num_threads(PyObject *self, PyObject *args)
{
    int k;
    (void)self;
    if (!PyArg_ParseTuple(args, "i", &k))
        return NULL;
    pool_set_threads(k);
    return PyLong_FromLong(pool_threads());
}

static PyObject *py_cpu_has_avx2_fma(PyObject *self, PyObject *args)
{
    (void)self;
    (void)args;
#if defined(__GNUC__) && defined(__x86_64__)
    __builtin_cpu_init();
    return PyBool_FromLong(__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"));
#else
    Py_RETURN_FALSE;
#endif
}

static PyObject *py_cpu_has_avx512(PyObject *self, PyObject *args)
{
    (void)self;
    (void)args;
#if defined(__GNUC__) && defined(__x86_64__)
    __builtin_cpu_init();
    return PyBool_FromLong(__builtin_cpu_supports("avx512f") &&
                           __builtin_cpu_supports("avx512dq") &&
                           __builtin_cpu_supports("avx512vl") &&
                           __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"));
#else
    Py_RETURN_FALSE;
#endif
}

static PyMethodDef methods[] = {
    {"fk1", (PyCFunction)(void (*)(void))py_fk1, METH_FASTCALL,
     "fk1(q, packed) -> (4, 4) pose, or None when q needs the general path."},
    {"fk", py_fk, METH_VARARGS, "fk(packed, q, out) -> all finite: batch FK."},
    {"jacobian", py_jacobian, METH_VARARGS,
     "jacobian(packed, q, J, T) -> all finite: Jacobians and poses."},
    {"frames", py_frames, METH_VARARGS,
     "frames(packed, q, out) -> all finite: base, link frames, tool pose."},
    {"lm_solve", py_lm_solve, METH_VARARGS,
     "lm_solve(packed, targets, q0, seeds, opts, out, tab, cstart, gdat, parallel) "
     "-> (fails, first_bad): numeric IK of a batch."},
    {"seed_uniforms", py_seed_uniforms, METH_VARARGS,
     "seed_uniforms(targets, q0, key, base, out): restart numbers from the inputs."},
    {"lm_path", py_lm_path, METH_VARARGS,
     "lm_path(packed, targets, q_start, opts, out) -> first failure or -1."},
    {"pose_error", py_pose_error, METH_VARARGS,
     "pose_error(current, target, out): [p_t - p; log(R_t R^T)] per pose."},
    {"table_nearest", py_table_nearest, METH_VARARGS,
     "table_nearest(rows, cstart, grid, T, k, rot_w) -> the nearest seed-table rows."},
    {"nearest", (PyCFunction)(void (*)(void))py_nearest, METH_FASTCALL,
     "nearest(packed, Q, ok, qn, is_rev, T, q, err, found): the row nearest qn."},
    {"check_poses", py_check_poses, METH_VARARGS,
     "check_poses(T, tol) -> (code, index) of the first non-rigid pose."},
    {"sincos", py_sincos, METH_VARARGS, "sincos(x, s, c): the kernels' sin and cos."},
    {"layout", py_layout, METH_VARARGS, "layout(packed) -> dict: the parsed sections."},
    {"num_threads", py_num_threads, METH_NOARGS, "num_threads() -> threads of the pool."},
    {"set_num_threads", py_set_num_threads, METH_VARARGS,
     "set_num_threads(k) -> k: threads of the pool (1 to 64)."},
    {"cpu_has_avx2_fma", py_cpu_has_avx2_fma, METH_NOARGS,
     "cpu_has_avx2_fma() -> bool: whether this CPU runs the AVX2 + FMA copy."},
    {"cpu_has_avx512", py_cpu_has_avx512, METH_NOARGS,
     "cpu_has_avx512() -> bool: whether this CPU runs the AVX-512 copy."},
    SIX_R_METHODS
    BROADPHASE_METHODS
    PLAN_CHECK_METHODS
    PLAN_RRTC_METHODS
    PLAN_PATH_METHODS
    GENERAL6R_METHODS
    MANIPULABILITY_METHODS
    PIEPER_METHODS
    PROCESS_METHODS
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, MODULE_NAME,
                                    "robokin's compiled kernels (" ISA_NAME ").", -1,
                                    methods, NULL, NULL, NULL, NULL};

PyMODINIT_FUNC MODULE_INIT(void)
{
    import_array();
    PyObject *m = PyModule_Create(&module);
    if (m == NULL)
        return NULL;
    PyModule_AddStringConstant(m, "ISA", ISA_NAME);
    static const struct { const char *name; int value; } ints[] = {
        {"O_W", O_W}, {"O_TOL_P", O_TOL_P}, {"O_TOL_R", O_TOL_R}, {"O_MAX_ITER", O_MAX_ITER},
        {"O_USE_Q0", O_USE_Q0}, {"O_MAX_STEP", O_MAX_STEP}, {"O_MU0", O_MU0},
        {"O_N_SEEDS", O_N_SEEDS}, {"O_PATH_MAX_JUMP", O_PATH_MAX_JUMP},
        {"O_STALL_EVERY", O_STALL_EVERY}, {"O_STALL_RATIO", O_STALL_RATIO},
        {"O_MU_DOWN", O_MU_DOWN}, {"O_MU_UP", O_MU_UP}, {"O_SEED_SHRINK", O_SEED_SHRINK},
        {"O_N_TABLE", O_N_TABLE}, {"O_TABLE_ROT", O_TABLE_ROT}, {"N_OPTS", N_OPTS},
        {"R_ERR", R_ERR}, {"R_EP", R_EP}, {"R_ER", R_ER}, {"R_ITERS", R_ITERS},
        {"R_RESTARTS", R_RESTARTS}, {"R_CODE", R_CODE}, {"N_RES", N_RES},
        {"CODE_OK", CODE_OK}, {"CODE_ITER", CODE_ITER}, {"CODE_STALL", CODE_STALL},
        {"CODE_BAD_TARGET", CODE_BAD_TARGET}, {"CODE_JUMP", CODE_JUMP},
        {"CODE_NOT_RUN", CODE_NOT_RUN}, {"CODE_BAD_Q0", CODE_BAD_Q0},
        {"TAB_K_MAX", TAB_K_MAX}, {"LANES", W}, {"MAX_JOINTS", MAXJ},
        {"FK_PARALLEL_MIN", FK_PARALLEL_MIN}};
    for (size_t i = 0; i < sizeof(ints) / sizeof(ints[0]); i++)
        PyModule_AddIntConstant(m, ints[i].name, ints[i].value);
    PyModule_AddObject(m, "LAYOUT_TAG", PyFloat_FromDouble(PACKED_TAG));
    PyModule_AddObject(m, "MAX_TRANSLATION", PyFloat_FromDouble(MAX_TRANSLATION));
    if (six_r_constants(m) < 0 || broadphase_constants(m) < 0 ||
        general6r_constants(m) < 0 || pieper_constants(m) < 0 ||
        plan_check_constants(m) < 0 || plan_rrtc_constants(m) < 0 ||
        plan_path_constants(m) < 0 || process_constants(m) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
