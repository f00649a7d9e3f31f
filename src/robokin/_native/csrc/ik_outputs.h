/*
 * The Python side of the closed-form IK kernels with up to 8 slots per pose
 * (six_r.c, pieper.c): their output arrays, the single-pose entries' pose read
 * and result tuple, the batch entries' run. Included by both (unity build:
 * guarded), after chain.h (pose_problem) and pool.h, with the NumPy C API in scope.
 */
#ifndef ROBOKIN_IK_OUTPUTS_H
#define ROBOKIN_IK_OUTPUTS_H

/* (Q, valid, singular, within_limits): lead + (8, n) and lead + (8,) with lead = ()
 * (nlead 0) or (N,) (nlead 1), into out[4]; 0 on a memory error (nothing kept). */
static int ik_outputs(int nlead, npy_intp N, int n, PyObject **out)
{
    npy_intp dq[3] = {N, 8, n}, df[2] = {N, 8};
    out[0] = PyArray_SimpleNew(nlead + 2, dq + 1 - nlead, NPY_DOUBLE);
    for (int i = 1; i < 4; i++)
        out[i] = out[0] == NULL ? NULL : PyArray_SimpleNew(nlead + 1, df + 1 - nlead, NPY_BOOL);
    if (out[0] == NULL || out[1] == NULL || out[2] == NULL || out[3] == NULL) {
        for (int i = 0; i < 4; i++)
            Py_XDECREF(out[i]);
        return 0;
    }
    return 1;
}

/* A batch's status array (N,) int8 into *status; on a memory error the four
 * outputs are released and 0 returned. */
static int ik_status(npy_intp N, PyObject **out, PyObject **status)
{
    npy_intp dims[1] = {N};
    *status = PyArray_SimpleNew(1, dims, NPY_INT8);
    if (*status == NULL) {
        for (int i = 0; i < 4; i++)
            Py_DECREF(out[i]);
        return 0;
    }
    return 1;
}

/* A single pose from object `to` into T (row-major): 0 when it is a float64
 * (4, 4) rigid transform (read through its strides), bad + pose_problem's code
 * when it is not rigid, bad itself when it is not such an array. */
static int ik_read_pose(PyObject *to, double *T, int bad)
{
    if (!PyArray_Check(to))
        return bad;
    PyArrayObject *ta = (PyArrayObject *)to;
    if (!(PyArray_TYPE(ta) == NPY_DOUBLE && PyArray_NDIM(ta) == 2 &&
          PyArray_DIMS(ta)[0] == 4 && PyArray_DIMS(ta)[1] == 4 && PyArray_ISNOTSWAPPED(ta) &&
          PyArray_ISALIGNED(ta)))
        return bad;
    const char *d = PyArray_BYTES(ta);
    npy_intp rs = PyArray_STRIDE(ta, 0), cs = PyArray_STRIDE(ta, 1);
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++)
            T[4 * r + c] = *(const double *)(d + r * rs + c * cs);
    int code = pose_problem(T, POSE_ROW_TOL, POSE_ORTH_TOL);
    return code ? bad + code : 0;
}

/* (code, Q, valid, singular, within_limits): steals the four outputs (released
 * on a memory error) */
static PyObject *ik_result(long code, PyObject **out)
{
    PyObject *res = PyTuple_New(5);
    if (res == NULL) {
        for (int i = 0; i < 4; i++)
            Py_DECREF(out[i]);
        return NULL;
    }
    PyTuple_SET_ITEM(res, 0, PyLong_FromLong(code));
    for (int i = 0; i < 4; i++)
        PyTuple_SET_ITEM(res, i + 1, out[i]);
    return res;
}

/* A batch of N poses: range(job, 0, N) on this thread below `parallel` poses, else
 * on the pool in chunks of `grain`, without the GIL; then (Q, valid, singular,
 * within_limits, status), stealing the five arrays. */
static PyObject *ik_run_batch(npy_intp N, long parallel, long grain, pool_task range,
                              void *job, PyObject **out, PyObject *status)
{
    Py_BEGIN_ALLOW_THREADS
    if (N >= parallel)
        pool_for((long)N, grain, range, job);
    else
        range(job, 0, (long)N);
    Py_END_ALLOW_THREADS
    return Py_BuildValue("(NNNNN)", out[0], out[1], out[2], out[3], status);
}

#endif
