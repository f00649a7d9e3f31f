/*
 * The argument checks the generated entry points (kernels_entry.gen.h) call: one
 * copy, used by every kernel. Each returns 0 with a ValueError (TypeError for a
 * Python value of the wrong type) naming the kernel and the argument.
 */
#ifndef ROBOKIN_ARGS_H
#define ROBOKIN_ARGS_H

#include <stdio.h>
#include "chain.h"

static PyObject *kernel_fail(const char *message)
{
    PyErr_SetString(PyExc_ValueError, message);
    return NULL;
}

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

/* every x[i] in [lo, hi], and non-decreasing when asked */
static int index_values(const long long *x, npy_intp count, long long lo, long long hi,
                        int monotone)
{
    for (npy_intp i = 0; i < count; i++)
        if (x[i] < lo || x[i] > hi || (monotone && i > 0 && x[i] < x[i - 1]))
            return 0;
    return 1;
}

#endif /* ROBOKIN_ARGS_H */
