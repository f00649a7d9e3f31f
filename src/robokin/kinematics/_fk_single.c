/*
 * Forward kinematics of ONE configuration, as a CPython extension.
 *
 * Why C here when every other hot loop is numba: a single configuration costs
 * ~60 ns of arithmetic, and calling a numba kernel from Python costs ~400 ns of
 * argument unboxing alone (more than pinocchio's whole forwardKinematics call).
 * This function reads the chain's packed parameter array (see
 * robokin.model.chain.Chain._packed) and mirrors robokin.kinematics._kernels.
 * _fk_one operation for operation, including its sincos, so both paths give the
 * same numbers (the sines and cosines are computed first, which changes no
 * result). It is optional: when it was not built (no C compiler at install
 * time), robokin uses the numba kernel.
 *
 * fk(q, packed) -> (4, 4) float64 ndarray, or None when q is not a 1-D native
 * float64 array of the chain's length or holds NaN/inf: the caller then takes
 * the general (validating) path, which raises the user-facing error.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>
#include <math.h>

#define MAX_JOINTS 64 /* longer chains take the numba path */

/* sincos: Cody-Waite reduction by pi/2 and the fdlibm kernel polynomials, the
 * same constants and operation order as _kernels.sincos. */
#include "_sincos_consts.h"

static void rk_sincos(double x, double *s, double *c)
{
    if (!(fabs(x) < 1e5)) {
        *s = sin(x);
        *c = cos(x);
        return;
    }
    /* floor(t) for |t| < 2^62 without a libm call (no SSE4.1 on baseline x86-64) */
    double t = x * INV_PIO2 + 0.5;
    double n = (double)(long long)t;
    if (n > t)
        n -= 1.0;
    double y = ((x - n * PIO2_1) - n * PIO2_2) - n * PIO2_3;
    double z = y * y;
    double r = S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)));
    double sy = y + z * y * (S1 + z * r);
    double rc = z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    double hz = 0.5 * z;
    double w = 1.0 - hz;
    double cy = w + (((1.0 - w) - hz) + z * rc);
    switch (((long long)n) & 3) {
    case 0: *s = sy; *c = cy; return;
    case 1: *s = cy; *c = -sy; return;
    case 2: *s = -sy; *c = -cy; return;
    default: *s = -cy; *c = sy; return;
    }
}

/* T <- T @ C; C is 4x4 row-major affine, P its Trans(t) Rx(a) parameters. */
static void const_x(double *T, const double *C, const double *P)
{
    if (P[0] == 1.0) {
        double ca = P[1], sa = P[2], tx = P[3], ty = P[4], tz = P[5];
        for (int r = 0; r < 3; r++) {
            double a0 = T[4 * r], a1 = T[4 * r + 1], a2 = T[4 * r + 2];
            T[4 * r + 3] += a0 * tx + a1 * ty + a2 * tz;
            T[4 * r + 1] = ca * a1 + sa * a2;
            T[4 * r + 2] = ca * a2 - sa * a1;
        }
    } else {
        for (int r = 0; r < 3; r++) {
            double a0 = T[4 * r], a1 = T[4 * r + 1], a2 = T[4 * r + 2], a3 = T[4 * r + 3];
            T[4 * r] = a0 * C[0] + a1 * C[4] + a2 * C[8];
            T[4 * r + 1] = a0 * C[1] + a1 * C[5] + a2 * C[9];
            T[4 * r + 2] = a0 * C[2] + a1 * C[6] + a2 * C[10];
            T[4 * r + 3] = a0 * C[3] + a1 * C[7] + a2 * C[11] + a3;
        }
    }
}

static int native_f64_vector(PyObject *o)
{
    if (!PyArray_Check(o))
        return 0;
    PyArrayObject *a = (PyArrayObject *)o;
    return PyArray_TYPE(a) == NPY_DOUBLE && PyArray_NDIM(a) == 1 &&
           PyArray_ISNOTSWAPPED(a) && PyArray_ISALIGNED(a);
}

static PyObject *fk(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 2) {
        PyErr_SetString(PyExc_TypeError, "fk(q, packed) takes 2 arguments");
        return NULL;
    }
    if (!native_f64_vector(args[0]) || !native_f64_vector(args[1]))
        Py_RETURN_NONE;
    PyArrayObject *qa = (PyArrayObject *)args[0], *pa = (PyArrayObject *)args[1];
    if (!PyArray_IS_C_CONTIGUOUS(pa) || PyArray_DIM(pa, 0) < 1)
        Py_RETURN_NONE;
    const double *p = (const double *)PyArray_DATA(pa);
    npy_intp nc = (npy_intp)p[0];
    if (nc < 0 || nc > MAX_JOINTS || PyArray_DIM(pa, 0) != 1 + (nc + 1) * 22 + 3 * nc || PyArray_DIM(qa, 0) != nc)
        Py_RETURN_NONE;
    const double *consts = p + 1;
    const double *xform = consts + (nc + 1) * 16;
    const double *kind = xform + (nc + 1) * 6, *sign = kind + nc, *offset = sign + nc;
    const char *qd = PyArray_BYTES(qa);
    npy_intp qs = PyArray_STRIDE(qa, 0);

    /* All joint sines and cosines first: they are independent, so the CPU
     * overlaps them; the matrix chain after them is the serial part. */
    double sv[MAX_JOINTS], cv[MAX_JOINTS], vv[MAX_JOINTS];
    int ok = 1;
    for (npy_intp k = 0; k < nc; k++) {
        double v = sign[k] * *(const double *)(qd + k * qs) + offset[k];
        if (!isfinite(v))
            ok = 0;
        vv[k] = v;
        if (kind[k] == 0.0)
            rk_sincos(v, &sv[k], &cv[k]);
    }
    if (!ok)
        Py_RETURN_NONE;
    double T[12];
    for (int i = 0; i < 12; i++)
        T[i] = consts[i];
    for (npy_intp k = 0; k < nc; k++) {
        if (kind[k] == 0.0) {
            double s = sv[k], c = cv[k];
            for (int r = 0; r < 3; r++) {
                double x0 = T[4 * r], x1 = T[4 * r + 1];
                T[4 * r] = c * x0 + s * x1;
                T[4 * r + 1] = c * x1 - s * x0;
            }
        } else {
            for (int r = 0; r < 3; r++)
                T[4 * r + 3] += T[4 * r + 2] * vv[k];
        }
        const_x(T, consts + 16 * (k + 1), xform + 6 * (k + 1));
    }
    npy_intp dims[2] = {4, 4};
    PyObject *out = PyArray_SimpleNew(2, dims, NPY_DOUBLE);
    if (out == NULL)
        return NULL;
    double *o = (double *)PyArray_DATA((PyArrayObject *)out);
    for (int i = 0; i < 12; i++)
        o[i] = T[i];
    o[12] = 0.0;
    o[13] = 0.0;
    o[14] = 0.0;
    o[15] = 1.0;
    return out;
}

static PyMethodDef methods[] = {
    {"fk", (PyCFunction)(void (*)(void))fk, METH_FASTCALL,
     "fk(q, packed) -> (4, 4) pose, or None when q needs the general path."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_fk_single",
    "Single-configuration forward kinematics (optional C accelerator).", -1, methods,
    NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__fk_single(void)
{
    import_array();
    return PyModule_Create(&module);
}
