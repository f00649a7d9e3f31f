/*
 * Forward kinematics, link frames and Jacobians of batches of configurations,
 * W configurations per step (chain.h). Each kernel takes the chain's packed arrays
 * and C-contiguous float64 buffers, and returns whether every joint value was
 * finite; the Python layer (robokin.kinematics.forward / jacobian) validates shapes
 * and turns a False into an error naming the argument.
 */
#include "chain.h"
#include "pool.h"

#define FK_GRAIN 64          /* configurations per pool chunk */
#define FK_PARALLEL_MIN 1024 /* below this many, one thread */

typedef struct {
    const Chain *ch;
    const double *q; /* N x n */
    double *pose;    /* N x 16 */
    double *jac;     /* N x 6 x n, or NULL */
    double *frames;  /* N x (nc + 2) x 16, or NULL */
    int ok;          /* cleared (atomically) when a joint value is not finite */
} FkJob;

/* lanes l < count take configurations first + l; the others repeat the first */
ALWAYS_INLINE void gather(const double *q, int n, long first, int count, vd *out)
{
    for (int j = 0; j < n; j++)
        for (int l = 0; l < W; l++)
            out[j][l] = q[(first + (l < count ? l : 0)) * n + j];
}

ALWAYS_INLINE void store_pose(const vd *t, int l, double *T)
{
    for (int i = 0; i < 12; i++)
        T[i] = t[i][l];
    T[12] = 0.0;
    T[13] = 0.0;
    T[14] = 0.0;
    T[15] = 1.0;
}

static void flag_bad(FkJob *job, vl ok, int count)
{
    for (int l = 0; l < count; l++)
        if (!ok[l])
            __atomic_store_n(&job->ok, 0, __ATOMIC_RELAXED);
}

static void fk_range(void *ctx, long b, long e)
{
    FkJob *job = (FkJob *)ctx;
    const Chain *ch = job->ch;
    const int n = ch->n;
    for (long i = b; i < e; i += W) {
        int count = e - i < W ? (int)(e - i) : W;
        vd q[MAXJ], t[12];
        gather(job->q, n, i, count, q);
        vl ok = chain_pose(ch, q, t, NULL, NULL);
        for (int l = 0; l < count; l++)
            store_pose(t, l, job->pose + (i + l) * 16);
        flag_bad(job, ok, count);
    }
}

static void jacobian_range(void *ctx, long b, long e)
{
    FkJob *job = (FkJob *)ctx;
    const Chain *ch = job->ch;
    const int n = ch->n;
    for (long i = b; i < e; i += W) {
        int count = e - i < W ? (int)(e - i) : W;
        vd q[MAXJ], t[12], J[6 * MAXJ];
        gather(job->q, n, i, count, q);
        vl ok = chain_pose_jac(ch, q, t, J, MAXJ);
        for (int l = 0; l < count; l++) {
            store_pose(t, l, job->pose + (i + l) * 16);
            double *Jo = job->jac + (i + l) * 6 * n;
            for (int r = 0; r < 6; r++)
                for (int j = 0; j < n; j++)
                    Jo[r * n + j] = J[r * MAXJ + j][l];
        }
        flag_bad(job, ok, count);
    }
}

/* base, the frame of every chain joint (after F_k), then the tool pose: chain.h's
 * one walk (chain_walk), so the tool pose is fk's bit for bit */
static void frames_range(void *ctx, long b, long e)
{
    FkJob *job = (FkJob *)ctx;
    const Chain *ch = job->ch;
    const int n = ch->n, nc = ch->nc;
    for (long i = b; i < e; i += W) {
        int count = e - i < W ? (int)(e - i) : W;
        vd q[MAXJ], t[12], fr[12 * MAXJ];
        gather(job->q, n, i, count, q);
        vl ok = chain_walk(ch, q, t, NULL, NULL, fr);
        double *out = job->frames + i * (nc + 2) * 16;
        for (int l = 0; l < count; l++) {
            double *o = out + l * (nc + 2) * 16;
            for (int a = 0; a < 16; a++)
                o[a] = ch->base[a];
            for (int k = 0; k < nc; k++)
                store_pose(fr + 12 * k, l, o + (k + 1) * 16);
            store_pose(t, l, o + (nc + 1) * 16);
        }
        flag_bad(job, ok, count);
    }
}

static int run_fk_job(FkJob *job, long N, pool_task fn)
{
    job->ok = 1;
    if (N >= FK_PARALLEL_MIN)
        pool_for(N, FK_GRAIN, fn, job);
    else
        fn(job, 0, N);
    return job->ok;
}
