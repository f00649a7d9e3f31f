/*
 * The argument checks of every kernel entry point: one copy, driven by the
 * per-kernel descriptor tables kernels_entry.gen.h declares (from ../_declare.py).
 * kernel_args() unpacks and checks a METH_FASTCALL argument vector into a
 * kernel's args struct; each failure is a ValueError (TypeError for a Python
 * value of the wrong type or a wrong argument count) naming the kernel and the
 * argument.
 */
#ifndef ROBOKIN_ARGS_H
#define ROBOKIN_ARGS_H

#include <stdio.h>
#include "chain.h"

#define KA_MAXARGS 16 /* the most arguments of a kernel (_generate.py checks) */

/* o as a C-contiguous, aligned, native array of typenum with ndim dimensions
 * (writeable when asked); NULL with ValueError otherwise. */
static PyArrayObject *array_arg(PyObject *o, const char *kernel, const char *name,
                                int typenum, int ndim, int writeable)
{
    if (!PyArray_Check(o)) {
        PyErr_Format(PyExc_ValueError, "robokin._native.%s: %s is not an ndarray", kernel,
                     name);
        return NULL;
    }
    PyArrayObject *a = (PyArrayObject *)o;
    if (PyArray_TYPE(a) != typenum || PyArray_NDIM(a) != ndim ||
        !PyArray_IS_C_CONTIGUOUS(a) || !PyArray_ISNOTSWAPPED(a) || !PyArray_ISALIGNED(a) ||
        (writeable && !PyArray_ISWRITEABLE(a))) {
        const char *type = typenum == NPY_INT64 ? "int64"
                           : typenum == NPY_BOOL ? "bool"
                           : typenum == NPY_INT8 ? "int8"
                           : typenum == NPY_INT32 ? "int32"
                           : typenum == NPY_UINT8 ? "uint8" : "float64";
        PyErr_Format(PyExc_ValueError,
                     "robokin._native.%s: %s must be a C-contiguous aligned native %s array "
                     "with %d dimension(s)%s", kernel, name, type, ndim,
                     writeable ? ", writeable" : "");
        return NULL;
    }
    return a;
}

/* o as ChainArrays.packed, parsed into ch */
static int chain_arg(PyObject *o, Chain *ch, const char *kernel)
{
    PyArrayObject *p = array_arg(o, kernel, "packed", NPY_DOUBLE, 1, 0);
    if (p == NULL)
        return 0;
    if (!chain_view((const double *)PyArray_DATA(p), (long)PyArray_DIMS(p)[0], ch)) {
        PyErr_Format(PyExc_ValueError,
                     "robokin._native.%s: packed is not a ChainArrays layout of at most "
                     "%d joints", kernel, MAXJ);
        return 0;
    }
    return 1;
}

/* o as a Python int in [lo, hi], checked before the cast */
static int long_arg(PyObject *o, const char *kernel, const char *name, long long lo,
                    long long hi, long *out)
{
    int overflow = 0;
    long long v = PyLong_Check(o) ? PyLong_AsLongLongAndOverflow(o, &overflow) : -1;
    if (!PyLong_Check(o) || PyErr_Occurred()) {
        if (!PyErr_Occurred())
            PyErr_Format(PyExc_TypeError, "robokin._native.%s: %s must be an int", kernel,
                         name);
        return 0;
    }
    if (overflow || v < lo || v > hi) {
        PyErr_Format(PyExc_ValueError, "robokin._native.%s: %s must be in [%lld, %lld]",
                     kernel, name, lo, hi);
        return 0;
    }
    *out = (long)v;
    return 1;
}

/* o as a Python int in [lo, hi] of the unsigned 64-bit range */
static int uint64_arg(PyObject *o, const char *kernel, const char *name, long long lo,
                      unsigned long long hi, unsigned long long *out)
{
    if (!PyLong_Check(o)) {
        PyErr_Format(PyExc_TypeError, "robokin._native.%s: %s must be an int", kernel, name);
        return 0;
    }
    unsigned long long v = PyLong_AsUnsignedLongLong(o);
    if (PyErr_Occurred() || (lo > 0 && v < (unsigned long long)lo) || v > hi) {
        PyErr_Clear();
        PyErr_Format(PyExc_ValueError, "robokin._native.%s: %s must be in [%lld, %llu]",
                     kernel, name, lo, hi);
        return 0;
    }
    *out = v;
    return 1;
}

/* o as a float in [lo, hi] (NaN fails) */
static int double_arg(PyObject *o, const char *kernel, const char *name, double lo,
                      double hi, double *out)
{
    double v = PyFloat_AsDouble(o);
    if (v == -1.0 && PyErr_Occurred())
        return 0;
    if (!(v >= lo && v <= hi) && !(lo == -INFINITY && hi == INFINITY)) { /* unbounded: any */
        char text[200];
        snprintf(text, sizeof(text), "robokin._native.%s: %s = %.17g is outside [%.17g, %.17g]",
                 kernel, name, v, lo, hi);
        PyErr_SetString(PyExc_ValueError, text);
        return 0;
    }
    *out = v;
    return 1;
}

/* every x[i] in [lo, hi], and non-decreasing when asked. Branch-free loops the
 * compiler vectorizes: lm_solve checks the seed table's cell starts (G^3 + 1, ~2,200
 * entries for the built-in arms) on every call, one solve included (an early-exit
 * loop cost ~2 us of a ~10 us single solve; this one ~0.2 us). A non-decreasing
 * array is in [lo, hi] when its ends are. */
static int index_values(const long long *x, npy_intp count, long long lo, long long hi,
                        int monotone)
{
    if (count == 0)
        return 1;
    int bad = 0;
    if (monotone) {
        bad = x[0] < lo || x[count - 1] > hi;
        for (npy_intp i = 1; i < count; i++)
            bad |= x[i] < x[i - 1];
    } else {
        for (npy_intp i = 0; i < count; i++)
            bad |= (x[i] < lo) | (x[i] > hi);
    }
    return !bad;
}

/* ---- the descriptor tables and their one parser ---- */

enum { KA_PACKED, KA_ARR, KA_OPTS, KA_INT, KA_UINT64, KA_FLOAT, KA_FLAG, KA_OBJ };

/* a dimension or an index bound: add + (sym >= 0 ? the kernel's symbol sym : 0) */
typedef struct {
    signed char sym;
    long long add;
} KDim;

/* one entry (or count entries) of an option vector and its range */
typedef struct {
    int at, count, whole;
    double lo, hi;
} KOpt;

/* one argument: kind, where it goes in the args struct, and what it must be */
typedef struct {
    const char *name;
    size_t at;               /* offsetof the field in the kernel's args struct */
    unsigned char kind;      /* KA_* */
    unsigned char out;       /* arrays: writeable */
    unsigned char ndim;      /* arrays: dimensions */
    unsigned char binds;     /* arrays, packed: bit j when dimension j binds its symbol */
    int typenum;             /* arrays: NPY_* */
    const char *shape;       /* arrays, opts: the shape as declared, for messages */
    KDim dim[4];             /* arrays: the shape; packed: the symbols n, nc; opts: size */
    long long lo;            /* ints: range */
    unsigned long long hi;
    double flo, fhi;         /* floats: range */
    const char *values;      /* index arrays: "[lo, hi]" as declared (NULL: no check) */
    KDim vlo, vhi;           /* index arrays: every value in [vlo, vhi] */
    int monotone;            /* index arrays: non-decreasing */
    const KOpt *opts;        /* opts: the ranges of the entries */
    int nopts;
} KArg;

/* one kernel: its name, call signature, arguments and extra checks */
typedef struct {
    const char *name;
    const char *signature;             /* "fk(packed, q, out)" */
    int nargs;
    const KArg *argv;
    size_t sym_at;                     /* offsetof its npy_intp symbol array */
    unsigned late;                     /* bit i: argument i has dimensions to check */
    unsigned indexed;                  /* bit i: argument i is an index array */
    const char *(*check)(const void *a); /* NULL, or the message of the first failed check */
} KSpec;

#define KA_IN_FLAGS (NPY_ARRAY_C_CONTIGUOUS | NPY_ARRAY_ALIGNED)
#define KA_OUT_FLAGS (KA_IN_FLAGS | NPY_ARRAY_WRITEABLE)

static inline npy_intp kdim(KDim d, const npy_intp *sym)
{
    return (npy_intp)(d.add + (d.sym >= 0 ? (long long)sym[d.sym] : 0));
}

static int kopts_ok(const double *v, const KOpt *r, int count)
{
    for (int k = 0; k < count; k++)
        for (int i = r[k].at; i < r[k].at + r[k].count; i++)
            if (!(v[i] >= r[k].lo && v[i] <= r[k].hi) || (r[k].whole && v[i] != floor(v[i])))
                return 0;
    return 1;
}

static int kfail(const KSpec *k, const char *name, const char *what, const char *detail)
{
    PyErr_Format(PyExc_ValueError, "robokin._native.%s: %s%s%s", k->name, name, what, detail);
    return 0;
}

/* pass 1: one argument converted and stored, its binding dimensions bound (option
 * vectors checked whole) */
static inline int karg_parse(const KSpec *k, const KArg *g, PyObject *o, char *a, npy_intp *sym,
                      PyArrayObject **arr)
{
    void *at = a + g->at;
    *arr = NULL;
    switch (g->kind) {
    case KA_PACKED: {
        Chain *ch = (Chain *)at;
        if (!chain_arg(o, ch, k->name))
            return 0;
        const npy_intp got[2] = {ch->n, ch->nc};
        for (int j = 0; j < 2; j++)
            if (g->binds >> j & 1)
                sym[g->dim[j].sym] = got[j];
        return 1;
    }
    case KA_ARR:
    case KA_OPTS:
        *arr = (PyArrayObject *)o;
        if (!(PyArray_Check(o) && PyArray_TYPE(*arr) == g->typenum &&
              PyArray_NDIM(*arr) == g->ndim && PyArray_ISNOTSWAPPED(*arr) &&
              PyArray_CHKFLAGS(*arr, g->out ? KA_OUT_FLAGS : KA_IN_FLAGS)) &&
            (*arr = array_arg(o, k->name, g->name, g->typenum, g->ndim, g->out)) == NULL)
            return 0; /* the fast test failed, array_arg said why */
        *(void **)at = PyArray_DATA(*arr);
        for (int j = 0; j < g->ndim; j++)
            if (g->binds >> j & 1)
                sym[g->dim[j].sym] = PyArray_DIMS(*arr)[j];
        if (g->kind == KA_OPTS) { /* checked at once: the kernel's checks may read it */
            if (PyArray_DIMS(*arr)[0] != g->dim[0].add)
                return kfail(k, g->name, " must be ", g->shape);
            if (!kopts_ok((const double *)PyArray_DATA(*arr), g->opts, g->nopts))
                return kfail(k, g->name, ": a value outside its range (_declare.py)", "");
        }
        return 1;
    case KA_INT:
        return long_arg(o, k->name, g->name, g->lo, (long long)g->hi, (long *)at);
    case KA_UINT64:
        return uint64_arg(o, k->name, g->name, g->lo, g->hi, (unsigned long long *)at);
    case KA_FLOAT:
        return double_arg(o, k->name, g->name, g->flo, g->fhi, (double *)at);
    case KA_FLAG:
        return (*(int *)at = PyObject_IsTrue(o)) >= 0;
    default: /* KA_OBJ */
        *(PyObject **)at = o;
        return 1;
    }
}

/* pass 2: the dimensions that do not bind */
static inline int karg_shape(const KSpec *k, const KArg *g, const char *a, const npy_intp *sym,
                      PyArrayObject *arr)
{
    if (g->kind == KA_PACKED) {
        const Chain *ch = (const Chain *)(a + g->at);
        const npy_intp got[2] = {ch->n, ch->nc};
        static const char *const names[2] = {"n", "nc"};
        for (int j = 0; j < 2; j++)
            if (!(g->binds >> j & 1) && got[j] != kdim(g->dim[j], sym))
                return kfail(k, names[j], " does not fit the chain", "");
        return 1;
    }
    if (g->kind != KA_ARR)
        return 1;
    for (int j = 0; j < g->ndim; j++)
        if (!(g->binds >> j & 1) && PyArray_DIMS(arr)[j] != kdim(g->dim[j], sym))
            return kfail(k, g->name, " must be ", g->shape);
    return 1;
}

/* a kernel's check function: the message of its first failed check, or NULL */
#define KERNEL_CHECK(k, expr) \
    static const char *k##_check(const void *p) \
    { \
        const k##_args *a = (const k##_args *)p; \
        return (expr); \
    }

/* a kernel's METH_FASTCALL entry point: arguments checked (k##_spec), then its body */
#define KERNEL_ENTRY(k, doc) \
    static PyObject *py_##k(PyObject *self, PyObject *const *args, Py_ssize_t nargs) \
    { \
        (void)self; \
        k##_args a; \
        memset(&a, 0, sizeof(a)); \
        return kernel_args(&k##_spec, args, nargs, &a) ? k##_body(&a) : NULL; \
    }

/* a kernel's row of the method table */
#define KERNEL_METHOD(k, doc) {#k, (PyCFunction)(void (*)(void))py_##k, METH_FASTCALL, doc},

/* a kernel's body prototype */
#define KERNEL_BODY(k, doc) static PyObject *k##_body(const k##_args *a);

/* descriptor rows (kernels_entry.gen.h): argument f of kernel k */
#define KA_ROW(k, f, kind_, ...) {.name = #f, .at = offsetof(k##_args, f), .kind = kind_, __VA_ARGS__}
#define KA_PLAIN(k, f, kind_) {.name = #f, .at = offsetof(k##_args, f), .kind = kind_}
/* an array: writeable, binds (bit mask), typenum, the shape's text, then its dimensions */
#define KA_ARRAY(k, f, out_, binds_, typenum_, shape_, ...) \
    KA_ROW(k, f, KA_ARR, .out = out_, .binds = binds_, .typenum = typenum_, .shape = shape_, \
           .ndim = sizeof((KDim[]){__VA_ARGS__}) / sizeof(KDim), .dim = {__VA_ARGS__})
/* an int64 index array: as KA_ARRAY, after the values' text, monotony and bounds
 * (every value in [{lo_sym, lo_add}, {hi_sym, hi_add}]) */
#define KA_INDEX(k, f, out_, binds_, said, mono, lo_sym, lo_add, hi_sym, hi_add, shape_, ...) \
    KA_ROW(k, f, KA_ARR, .out = out_, .binds = binds_, .typenum = NPY_INT64, .shape = shape_, \
           .ndim = sizeof((KDim[]){__VA_ARGS__}) / sizeof(KDim), .dim = {__VA_ARGS__}, \
           .values = said, .vlo = {lo_sym, lo_add}, .vhi = {hi_sym, hi_add}, .monotone = mono)

/* args (nargs of them) checked and unpacked into a (k's args struct, zeroed); 0 with an
 * error set */
static int kernel_args(const KSpec *k, PyObject *const *args, Py_ssize_t nargs, void *a)
{
    PyArrayObject *arr[KA_MAXARGS];
    char *base = (char *)a;
    npy_intp *sym = (npy_intp *)(base + k->sym_at);
    if (nargs != k->nargs) {
        PyErr_Format(PyExc_TypeError, "%s takes %d argument%s", k->signature, k->nargs,
                     k->nargs == 1 ? "" : "s");
        return 0;
    }
    for (int i = 0; i < k->nargs; i++)
        if (!karg_parse(k, &k->argv[i], args[i], base, sym, &arr[i]))
            return 0;
    const char *failed = k->check != NULL ? k->check(a) : NULL;
    if (failed != NULL)
        return kfail(k, failed, "", "");
    for (int i = 0; k->late >> i; i++)
        if ((k->late >> i & 1) && !karg_shape(k, &k->argv[i], base, sym, arr[i]))
            return 0;
    for (int i = 0; k->indexed >> i; i++) {
        const KArg *g = &k->argv[i];
        if ((k->indexed >> i & 1) &&
            !index_values((const long long *)PyArray_DATA(arr[i]), PyArray_SIZE(arr[i]),
                          kdim(g->vlo, sym), kdim(g->vhi, sym), g->monotone))
            return kfail(k, g->name, ": an index outside ", g->values);
    }
    return 1;
}

#endif /* ROBOKIN_ARGS_H */
