/*
 * Yoshikawa's manipulability of a 6-coordinate arm, w = |det J|, for batches of
 * configurations: the IK solutions of a reachability map or of a placement search
 * (robokin.kinematics.jacobian.manipulability, method="det").
 *
 * For a square Jacobian w = sqrt(det(J J^T)) = |det J| (Yoshikawa, "Manipulability
 * of robotic mechanisms", IJRR 4(2), 1985, eq. 9). One pass per W configurations:
 * the pose and Jacobian of chain.h (chain_pose_jac, the one copy of the Jacobian
 * columns) and then |det J| by Gaussian elimination with partial pivoting, all on
 * W lanes; nothing is written but the one number per configuration. A mask selects
 * the rows to compute (an IK solution set's valid, within-limits rows); the others
 * get 0 and are never read (they may hold NaN). Masked rows are packed into the
 * lanes in order, so a row's value does not depend on which other rows share its
 * vector (every lane operation is element-wise): chunking or threads change no bit.
 */
#include "chain.h"
#include "pool.h"

#define DET_GRAIN 256 /* rows per pool chunk */


typedef struct {
    const Chain *ch;
    const double *q;           /* N x 6 */
    const unsigned char *mask; /* N */
    double *out;               /* N */
    int ok;                    /* cleared (atomically) when a masked row is not finite */
} DetJob;

/* |det A| of one 6x6 matrix per lane, a[6 r + c] (overwritten). Partial pivoting
 * as LAPACK's dgetrf picks it (the first row of largest |a_rk| at or below k), by a
 * running compare-and-swap down the column, per lane; the row swaps only flip the
 * sign, which |det| drops. A zero pivot (a column with no nonzero left) gives 0. */
ALWAYS_INLINE vd abs_det6(vd *a)
{
    vd det = BR(1.0);
    for (int k = 0; k < 6; k++) {
        for (int r = k + 1; r < 6; r++) {
            vl m = vabs(a[6 * r + k]) > vabs(a[6 * k + k]);
            if (!vany(m))
                continue;
            for (int c = k; c < 6; c++) {
                vd x = a[6 * k + c], y = a[6 * r + c];
                a[6 * k + c] = vsel(m, y, x);
                a[6 * r + c] = vsel(m, x, y);
            }
        }
        vd p = a[6 * k + k];
        vl nz = p != 0.0;
        vd inv = 1.0 / vsel(nz, p, BR(1.0));
        for (int r = k + 1; r < 6; r++) {
            vd f = vsel(nz, a[6 * r + k] * inv, BR(0.0));
            for (int c = k + 1; c < 6; c++)
                a[6 * r + c] -= f * a[6 * k + c];
        }
        det *= p;
    }
    return vabs(det);
}

/* rows idx[0 .. count-1] (count <= W) into their lanes; the other lanes repeat the
 * first */
static void det_lanes(DetJob *job, const long *idx, int count)
{
    vd q[MAXJ], t[12], J[6 * 6];
    for (int j = 0; j < 6; j++)
        for (int l = 0; l < W; l++)
            q[j][l] = job->q[idx[l < count ? l : 0] * 6 + j];
    vl ok = chain_pose_jac(job->ch, q, t, J, 6);
    vd w = abs_det6(J);
    for (int l = 0; l < count; l++) {
        job->out[idx[l]] = w[l];
        if (!ok[l])
            __atomic_store_n(&job->ok, 0, __ATOMIC_RELAXED);
    }
}

static void det_range(void *ctx, long b, long e)
{
    DetJob *job = (DetJob *)ctx;
    long idx[W];
    int count = 0;
    for (long i = b; i < e; i++) {
        if (!job->mask[i]) {
            job->out[i] = 0.0;
            continue;
        }
        idx[count++] = i;
        if (count == W) {
            det_lanes(job, idx, count);
            count = 0;
        }
    }
    if (count)
        det_lanes(job, idx, count);
}

/* abs_det_jacobian(packed, q (N, 6), mask (N,) bool, out (N,)) -> all masked rows
 * finite */
static PyObject *abs_det_jacobian_body(const abs_det_jacobian_args *a)
{
    long N = (long)a->N;
    DetJob job = {&a->packed, a->q, a->mask, a->out, 1};
    Py_BEGIN_ALLOW_THREADS
    if (N >= FK_PARALLEL_MIN)
        pool_for(N, DET_GRAIN, det_range, &job);
    else
        det_range(&job, 0, N);
    Py_END_ALLOW_THREADS
    return PyBool_FromLong(job.ok);
}

