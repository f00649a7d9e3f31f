/*
 * A reachability map's closed-form step for a three-parallel or spherical-wrist 6R
 * arm, fused (robokin.cell._evaluate): per target, the number of IK solutions
 * inside the joint limits, and per voxel (G voxels of K targets each) the best
 * manipulability w = |det J| over those solutions, in one pass.
 *
 * The targets are solved W at a time by six_r.c's six_r_block (the same call as
 * six_r_ik without q_near: the same solutions, checked and polished alike) into a
 * block's scratch rows that stay in cache; the rows inside the limits are packed
 * into lanes and their w computed by manipulability.c's code (chain_pose_jac, then
 * abs_det6), the same per-lane operations abs_det_jacobian runs, so w is the same
 * bit for bit (tests/native/test_reach.py), and the per-voxel maximum is
 * order-free. Nothing of size (N, 8, 6) is written: the outputs are the counts
 * (N,) and the best w (G,) (0 for a voxel without a solution). A pool task takes
 * whole voxels, so no two threads write one voxel's best.
 */
#include "chain.h"
#include "pool.h"

#define REACH_GRAIN 256 /* targets per pool chunk (rounded to whole voxels) */

typedef struct {
    const SR *K;
    const Chain *ch;
    const double *T; /* N x 16 */
    long per;        /* targets per voxel */
    int with_w;
    unsigned char *counts; /* N */
    double *best;          /* G */
} ReachJob;

/* Rows waiting for their w: up to W configurations and their voxels. */
typedef struct {
    vd q[MAXJ];
    long voxel[W];
    int count;
} ReachLanes;

/* w of the pending rows into their voxels' best; the unused lanes repeat lane 0 */
static void reach_flush(const ReachJob *jb, ReachLanes *p)
{
    if (p->count == 0)
        return;
    for (int j = 0; j < 6; j++)
        for (int l = p->count; l < W; l++)
            p->q[j][l] = p->q[j][0];
    vd t[12], J[6 * 6];
    chain_pose_jac(jb->ch, p->q, t, J, 6);
    vd w = abs_det6(J);
    for (int l = 0; l < p->count; l++)
        if (w[l] > jb->best[p->voxel[l]])
            jb->best[p->voxel[l]] = w[l];
    p->count = 0;
}

/* Voxels [b, e) of the job: their targets W at a time. */
static void reach_range(void *ctx, long b, long e)
{
    const ReachJob *jb = ctx;
    long i0 = b * jb->per, i1 = e * jb->per;
    ReachLanes p;
    p.count = 0;
    for (long g = b; g < e; g++)
        jb->best[g] = 0.0;
    for (long i = i0; i < i1; i += W) {
        int nl = i1 - i < W ? (int)(i1 - i) : W;
        const double *T[W];
        double q6[W], Q[W][48];
        unsigned char flags[W][24];
        Slots o[W];
        signed char st[W];
        for (int l = 0; l < W; l++) {
            T[l] = jb->T + 16 * (i + (l < nl ? l : 0));
            q6[l] = NAN;
            o[l] = (Slots){Q[l], flags[l], flags[l] + 8, flags[l] + 16};
        }
        six_r_block(jb->K, jb->ch, T, q6, o, st, nl);
        for (int l = 0; l < nl; l++) {
            const unsigned char *inside = flags[l] + 16;
            int c = 0;
            for (int k = 0; k < 8; k++) {
                if (!inside[k])
                    continue;
                c++;
                if (!jb->with_w)
                    continue;
                for (int j = 0; j < 6; j++)
                    p.q[j][p.count] = Q[l][6 * k + j];
                p.voxel[p.count++] = (i + l) / jb->per;
                if (p.count == W)
                    reach_flush(jb, &p);
            }
            jb->counts[i + l] = (unsigned char)c;
        }
    }
    reach_flush(jb, &p);
}

/* six_r_reach(params, T (G, K, 4, 4), packed, with_w, counts (G, K) u8, best (G,)) */
static PyObject *six_r_reach_body(const six_r_reach_args *a)
{
    SR K;
    sr_read(a->params, &K);
    long G = (long)a->G, per = (long)a->K;
    ReachJob jb = {&K, &a->packed, a->T, per, a->with_w != 0, a->counts, a->best};
    long grain = REACH_GRAIN / per > 1 ? REACH_GRAIN / per : 1;
    Py_BEGIN_ALLOW_THREADS
    if (G * per >= SR_PARALLEL_MIN && G > 1)
        pool_for(G, grain, reach_range, &jb);
    else
        reach_range(&jb, 0, G);
    Py_END_ALLOW_THREADS
    Py_RETURN_NONE;
}
