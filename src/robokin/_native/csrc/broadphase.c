/*
 * The collision broad phase behind robokin.collision (collision/_problem.py): lower
 * bounds on every (shape pair, sample) distance from rounded boxes, the closed-form
 * distance of capsule and sphere pairs, the bound on how much a pair's distance can
 * change between two samples, and the spreading of known distances along a
 * trajectory through those bounds.
 *
 * Every shape is bounded by a *rounded box*: an oriented box (centre, axes, half
 * sizes) grown by a radius. A capsule is a segment (half sizes (0, 0, L/2)) grown by
 * its radius, a sphere a point grown by its radius, a box or a cylinder's bounding
 * box a box of radius 0.
 *
 * Plain scalar C. The loops over samples run on the pool (pool.h); every sample is
 * computed by the same code whichever thread takes it, so the results do not depend
 * on the number of threads. Joint values, origins and axes come from chain.h
 * (joint_values, chain_pose): nothing here multiplies along the chain. Poses are the
 * top 3x4 block of a row-major 4x4 transform, p[4 r + c]: a box's axes are its
 * columns, its centre the last column.
 *
 * Its entries and constants are declared in ../_declare.py (BROADPHASE); the
 * generated entry points check shapes and index ranges before the bodies run.
 */
#include "chain.h"
#include "pool.h"

#define BP_CHUNK_WORK 4096 /* pair evaluations (or sphere-joint terms) per pool chunk */
#define BP_AXIS_EPS 1e-12  /* edge-edge axes shorter than sqrt of this are skipped */
#define BP_SEG_EPS 1e-18   /* squared segment lengths at or below this are points */

/* ------------------------------------------------------------------ geometry */

/* o = F (x, y, z, 1): a point placed by the affine transform F (top 3x4). */
static inline void place_point(const double *F, double x, double y, double z, double *o)
{
    for (int a = 0; a < 3; a++)
        o[a] = F[4 * a] * x + F[4 * a + 1] * y + F[4 * a + 2] * z + F[4 * a + 3];
}

/* t = F L (top 3x4 blocks): a shape's bounding box (pose L in its link frame)
 * placed in the world by the link frame F. */
static void place_pose(const double *F, const double *L, double *t)
{
    double c[3];
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            t[4 * a + b] = F[4 * a] * L[b] + F[4 * a + 1] * L[4 + b] + F[4 * a + 2] * L[8 + b];
    place_point(F, L[3], L[7], L[11], c);
    for (int a = 0; a < 3; a++)
        t[4 * a + 3] = c[a];
}

/* A lower bound on the distance between two rounded boxes (poses pa, pb as above;
 * half sizes ha, hb; radii ra, rb): the largest gap between their projections on a
 * candidate axis, negative when every candidate overlaps.
 *
 * The candidates are the 15 axes of the separating axis theorem for two oriented
 * boxes, in A's frame as in Gottschalk, Lin & Manocha, "OBBTree: a hierarchical
 * structure for rapid interference detection", SIGGRAPH 1996 (A's 3 face normals,
 * B's 3, the 9 edge cross products e_i x b_j; also Ericson, "Real-Time Collision
 * Detection", 2005, sec. 4.4.1), plus the line through the centres (tight for round
 * shapes). Each gap is divided by its axis length, so it is a distance along a unit
 * axis, and a radius grows every support by itself, so r_a + r_b comes off every
 * gap. An edge-edge axis is skipped when its squared length, |e_i x b_j|^2 =
 * R[i1][j]^2 + R[i2][j]^2, is below BP_AXIS_EPS (the edges are parallel and a face
 * axis already covers it). That sum, not 1 - R[i][j]^2: the latter cancels for
 * nearly parallel edges (off by ~1e-3 relative near 1e-12) and overstated their
 * gaps, up to 9e-4 m above the exact distance on random boxes. */
static double sat_gap(const double *pa, const double *ha, double ra, const double *pb,
                      const double *hb, double rb)
{
    double d[3], T[3], R[3][3], A[3][3];
    for (int r = 0; r < 3; r++)
        d[r] = pb[4 * r + 3] - pa[4 * r + 3];
    /* the centre offset and B's axes in A's frame */
    for (int i = 0; i < 3; i++) {
        T[i] = pa[i] * d[0] + pa[4 + i] * d[1] + pa[8 + i] * d[2];
        for (int j = 0; j < 3; j++) {
            double v = pa[i] * pb[j] + pa[4 + i] * pb[4 + j] + pa[8 + i] * pb[8 + j];
            R[i][j] = v;
            A[i][j] = fabs(v);
        }
    }
    const double rr = ra + rb;
    double best = -INFINITY, g;
    for (int i = 0; i < 3; i++) { /* A's face normals */
        g = fabs(T[i]) - ha[i] - (hb[0] * A[i][0] + hb[1] * A[i][1] + hb[2] * A[i][2]) - rr;
        if (g > best)
            best = g;
    }
    for (int j = 0; j < 3; j++) { /* B's face normals */
        g = fabs(T[0] * R[0][j] + T[1] * R[1][j] + T[2] * R[2][j]) -
            (ha[0] * A[0][j] + ha[1] * A[1][j] + ha[2] * A[2][j]) - hb[j] - rr;
        if (g > best)
            best = g;
    }
    /* edge-edge axes e_i x b_j (k = 3 i + j): numerator and squared length of each */
    double num[9], n2[9];
    for (int i = 0; i < 3; i++) {
        const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
        for (int j = 0; j < 3; j++) {
            const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
            n2[3 * i + j] = R[i1][j] * R[i1][j] + R[i2][j] * R[i2][j];
            num[3 * i + j] = fabs(T[i2] * R[i1][j] - T[i1] * R[i2][j]) -
                             (ha[i1] * A[i2][j] + ha[i2] * A[i1][j]) -
                             (hb[j1] * A[i][j2] + hb[j2] * A[i][j1]);
        }
    }
    double ge[9];
    for (int k = 0; k < 9; k++) /* free of branches: the compiler vectorises it */
        ge[k] = num[k] / sqrt(n2[k]) - rr;
    for (int k = 0; k < 9; k++)
        if (n2[k] >= BP_AXIS_EPS && ge[k] > best)
            best = ge[k];
    /* the line through the centres */
    double dn = sqrt(T[0] * T[0] + T[1] * T[1] + T[2] * T[2]);
    if (dn > 1e-12) {
        double u0 = T[0] / dn, u1 = T[1] / dn, u2 = T[2] / dn;
        double sa = ha[0] * fabs(u0) + ha[1] * fabs(u1) + ha[2] * fabs(u2);
        double sb = 0.0;
        for (int j = 0; j < 3; j++)
            sb += hb[j] * fabs(u0 * R[0][j] + u1 * R[1][j] + u2 * R[2][j]);
        g = dn - sa - sb - rr;
        if (g > best)
            best = g;
    }
    return best;
}

static inline double clamp01(double x)
{
    return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x);
}

/* The distance between the segments [p1, q1] and [p2, q2] (either may be a point):
 * Ericson, "Real-Time Collision Detection", 2005, sec. 5.1.9 (ClosestPtSegmentSegment),
 * step for step. Its parallel test is relative here: a e - b^2 <= BP_SEG_EPS a e takes
 * s = 0, and the clamps that follow give the closest pair. */
static double seg_seg(const double *p1, const double *q1, const double *p2, const double *q2)
{
    double d1[3], d2[3], r[3];
    for (int k = 0; k < 3; k++) {
        d1[k] = q1[k] - p1[k];
        d2[k] = q2[k] - p2[k];
        r[k] = p1[k] - p2[k];
    }
    double a = d1[0] * d1[0] + d1[1] * d1[1] + d1[2] * d1[2];
    double e = d2[0] * d2[0] + d2[1] * d2[1] + d2[2] * d2[2];
    double f = d2[0] * r[0] + d2[1] * r[1] + d2[2] * r[2];
    double s, t;
    if (a <= BP_SEG_EPS && e <= BP_SEG_EPS) {
        s = 0.0;
        t = 0.0;
    } else if (a <= BP_SEG_EPS) {
        s = 0.0;
        t = clamp01(f / e);
    } else {
        double c = d1[0] * r[0] + d1[1] * r[1] + d1[2] * r[2];
        if (e <= BP_SEG_EPS) {
            t = 0.0;
            s = clamp01(-c / a);
        } else {
            double b = d1[0] * d2[0] + d1[1] * d2[1] + d1[2] * d2[2];
            double denom = a * e - b * b;
            s = denom > BP_SEG_EPS * a * e ? clamp01((b * f - c * e) / denom) : 0.0;
            t = (b * s + f) / e;
            if (t < 0.0) {
                t = 0.0;
                s = clamp01(-c / a);
            } else if (t > 1.0) {
                t = 1.0;
                s = clamp01((b - c) / a);
            }
        }
    }
    double dx = p1[0] + d1[0] * s - p2[0] - d2[0] * t;
    double dy = p1[1] + d1[1] * s - p2[1] - d2[1] * t;
    double dz = p1[2] + d1[2] * s - p2[2] - d2[2] * t;
    return sqrt(dx * dx + dy * dy + dz * dz);
}

/* ---------------------------------------------------------------- the kernels */

/* Items per pool chunk when one item costs `per_item` units (BP_CHUNK_WORK a chunk). */
static long bp_grain(long per_item)
{
    long g = BP_CHUNK_WORK / (per_item > 1 ? per_item : 1);
    return g > 1 ? g : 1;
}

/* Shared by the kernels below: the link frames of m samples, (m, nl, 16), and the
 * shape pairs (robot shape pa[p] against robot shape pb[p] when is_self[p], else
 * against object pb[p]). */
typedef struct {
    const double *frames;
    long m, nl, S, P;
    const long long *link;
    const long long *pa, *pb;
    const npy_bool *is_self;
    int nomem; /* set (atomically) when a chunk could not allocate its scratch */
} Samples;

static void no_memory(Samples *sm)
{
    __atomic_store_n(&sm->nomem, 1, __ATOMIC_RELAXED);
}

typedef struct {
    Samples sm;
    const double *local, *h, *r;       /* robot shapes' boxes: (S, 16), (S, 3), (S,) */
    const double *ob_pose, *ob_h, *ob_r; /* objects' boxes in the world */
    const npy_bool *skip;
    double *out; /* (P, m) */
} BoxJob;

/* Samples [b, e) of rounded_box_bounds: every shape's box placed in the world, then
 * sat_gap of every pair not skipped into out[p, i]. */
static void box_bounds_range(void *ctx, long b, long e)
{
    BoxJob *job = (BoxJob *)ctx;
    const Samples *sm = &job->sm;
    double *box = malloc((size_t)(sm->S > 0 ? sm->S : 1) * 12 * sizeof(double));
    if (box == NULL) {
        no_memory(&job->sm);
        return;
    }
    for (long i = b; i < e; i++) {
        const double *Fi = sm->frames + (size_t)i * sm->nl * 16;
        for (long s = 0; s < sm->S; s++)
            place_pose(Fi + sm->link[s] * 16, job->local + s * 16, box + s * 12);
        for (long p = 0; p < sm->P; p++) {
            if (job->skip[p])
                continue;
            long a = (long)sm->pa[p], o = (long)sm->pb[p];
            double g;
            if (sm->is_self[p])
                g = sat_gap(box + a * 12, job->h + a * 3, job->r[a], box + o * 12,
                            job->h + o * 3, job->r[o]);
            else
                g = sat_gap(box + a * 12, job->h + a * 3, job->r[a], job->ob_pose + o * 16,
                            job->ob_h + o * 3, job->ob_r[o]);
            job->out[p * sm->m + i] = g;
        }
    }
    free(box);
}

typedef struct {
    Samples sm;
    const double *seg, *seg_r;   /* robot shapes' axis end points (S, 2, 3) in their
                                    link frames, radii (S,) */
    const double *ob_seg, *ob_r; /* objects', in the world */
    const long long *pairs;      /* (k,) pairs to compute */
    long k;
    double *out; /* (k, m) */
} CapsuleJob;

/* Samples [b, e) of capsule_distances: every shape's axis placed in the world, then
 * seg_seg minus the radii of the listed pairs into out[k, i]. */
static void capsule_range(void *ctx, long b, long e)
{
    CapsuleJob *job = (CapsuleJob *)ctx;
    const Samples *sm = &job->sm;
    double *w = malloc((size_t)(sm->S > 0 ? sm->S : 1) * 6 * sizeof(double));
    if (w == NULL) {
        no_memory(&job->sm);
        return;
    }
    for (long i = b; i < e; i++) {
        const double *Fi = sm->frames + (size_t)i * sm->nl * 16;
        for (long s = 0; s < sm->S; s++)
            for (int end = 0; end < 2; end++) {
                const double *x = job->seg + s * 6 + end * 3;
                place_point(Fi + sm->link[s] * 16, x[0], x[1], x[2], w + s * 6 + end * 3);
            }
        for (long kk = 0; kk < job->k; kk++) {
            long p = (long)job->pairs[kk];
            long a = (long)sm->pa[p], o = (long)sm->pb[p];
            double d;
            if (sm->is_self[p])
                d = seg_seg(w + a * 6, w + a * 6 + 3, w + o * 6, w + o * 6 + 3) -
                    job->seg_r[a] - job->seg_r[o];
            else
                d = seg_seg(w + a * 6, w + a * 6 + 3, job->ob_seg + o * 6,
                            job->ob_seg + o * 6 + 3) - job->seg_r[a] - job->ob_r[o];
            job->out[kk * sm->m + i] = d;
        }
    }
    free(w);
}

/* Spread known lower bounds along each listed row of LB (P, m), in place: a known
 * d_i (known[p, i]) gives d_j >= d_i - |C_j - C_i|, C the cumulative motion bound
 * along the trajectory (nondecreasing). Two sweeps per row: forward with the running
 * max of d_i + C_i over known i <= j, backward with that of d_i - C_i over i >= j. */
static void propagate_rows(double *LB, const npy_bool *known, const double *C, long m,
                           const long long *rows, long nrows)
{
    for (long r = 0; r < nrows; r++) {
        size_t o = (size_t)rows[r] * m;
        double *lb = LB + o;
        const npy_bool *kn = known + o;
        const double *c = C + o;
        double run = -INFINITY;
        for (long j = 0; j < m; j++) {
            if (kn[j] && lb[j] + c[j] > run)
                run = lb[j] + c[j];
            double g = run - c[j];
            if (g > lb[j])
                lb[j] = g;
        }
        run = -INFINITY;
        for (long j = m - 1; j >= 0; j--) {
            if (kn[j] && lb[j] - c[j] > run)
                run = lb[j] - c[j];
            double g = run + c[j];
            if (g > lb[j])
                lb[j] = g;
        }
    }
}

typedef struct {
    Samples sm;
    const Chain *ch;
    const double *q;             /* (m, n) */
    const double *sph_c, *sph_r; /* bounding spheres in their link frames */
    const long long *sph_start, *sph_count;
    const npy_bool *spins;
    double *reach;  /* (nc, S): the caller's static reach, then with the prismatic
                       travel added (pass 2) */
    double *v;      /* (m, nc): joint values (pass 1) */
    double *axis;   /* (m, nc, 6): origin and z axis of every joint (pass 1) */
    double *out;    /* (P, m - 1) */
} MotionJob;

/* Pass 1 of motion_bounds, samples [b, e): joint values, and the origin and axis of
 * every joint, from chain.h, W samples per call. */
static void motion_axes_range(void *ctx, long b, long e)
{
    MotionJob *job = (MotionJob *)ctx;
    const Chain *ch = job->ch;
    const int nc = ch->nc;
    for (long i = b; i < e; i += W) {
        int count = e - i < W ? (int)(e - i) : W;
        vd q[MAXJ], t[12], v[MAXJ], s[MAXJ], c[MAXJ], o[3 * MAXJ], z[3 * MAXJ];
        gather(job->q, ch->n, i, count, q);
        joint_values(ch, q, v, s, c);
        chain_pose(ch, q, t, o, z);
        for (int l = 0; l < count; l++) {
            double *vi = job->v + (size_t)(i + l) * nc;
            double *ax = job->axis + (size_t)(i + l) * nc * 6;
            for (int k = 0; k < nc; k++) {
                vi[k] = v[k][l];
                for (int r = 0; r < 3; r++) {
                    ax[6 * k + r] = o[3 * k + r][l];
                    ax[6 * k + 3 + r] = z[3 * k + r][l];
                }
            }
        }
    }
}

/* Pass 2 of motion_bounds: reach[j, s] grows by the largest travel |v_k| over the
 * samples of every prismatic joint k between joint j and shape s's link (joints j+1
 * .. min(link, nc) - 1), which lengthen the chain from j's origin to the shape. */
static void motion_reach(MotionJob *job)
{
    const Chain *ch = job->ch;
    const int nc = ch->nc;
    const long m = job->sm.m, S = job->sm.S;
    double ext[MAXJ];
    for (int k = 0; k < nc; k++) {
        ext[k] = 0.0;
        if (ch->kind[k] != 0.0)
            for (long i = 0; i < m; i++)
                ext[k] = fmax(ext[k], fabs(job->v[(size_t)i * nc + k]));
    }
    for (long s = 0; s < S; s++) {
        long top = job->sm.link[s] < nc ? (long)job->sm.link[s] : nc;
        for (long j = 0; j < top; j++) {
            double add = 0.0;
            for (long k = j + 1; k < top; k++)
                add += ext[k];
            job->reach[j * S + s] += add;
        }
    }
}

/* Pass 3 of motion_bounds, intervals [b, e): the bound on how much each pair's
 * distance can change from sample i to i + 1.
 *
 * A point of a shape on link k moves at most sum_j w_j |dv_j| over the interval
 * (Schwarzer, Saha & Latombe, "Adaptive dynamic collision checking for single and
 * multiple articulated robots in complex environments", IEEE T-RO 21(3), 2005,
 * eq. 1), w_j its distance from joint j's axis for a revolute joint, 1 for a
 * prismatic one. w_j is bounded by the farthest bounding sphere from the axis at
 * the interval's start plus what the joints after j can move the shape within the
 * interval, and by the static reach (pass 2); a shape that the last joint moving it
 * turns onto itself (spins) gets w = 0 for that joint. A self pair moves by the
 * joints between its two links, on the farther link's shape. The distance of a
 * sphere centre from an axis is |r x z| (r from the joint origin, z the unit axis):
 * sqrt(|r|^2 - (r.z)^2) cancels for centres on the axis, leaving ~1e-8 |r| of noise. */
static void motion_range(void *ctx, long b, long e)
{
    MotionJob *job = (MotionJob *)ctx;
    const Samples *sm = &job->sm;
    const int nc = job->ch->nc;
    const double *kind = job->ch->kind;
    const long S = sm->S;
    double *wt = malloc((size_t)(S > 0 ? S : 1) * nc * sizeof(double));
    if (wt == NULL) {
        no_memory(&job->sm);
        return;
    }
    double dq[MAXJ];
    for (long i = b; i < e; i++) {
        const double *v0 = job->v + (size_t)i * nc, *v1 = v0 + nc;
        const double *ax = job->axis + (size_t)i * nc * 6;
        const double *Fi = sm->frames + (size_t)i * sm->nl * 16;
        for (int j = 0; j < nc; j++)
            dq[j] = fabs(v1[j] - v0[j]);
        for (long s = 0; s < S; s++) {
            double *ws = wt + s * nc;
            for (int j = 0; j < nc; j++)
                ws[j] = 0.0;
            long kk = sm->link[s] < nc ? (long)sm->link[s] : nc;
            if (kk == 0)
                continue;
            const double *F = Fi + sm->link[s] * 16;
            long q0 = (long)job->sph_start[s], q1 = q0 + (long)job->sph_count[s];
            double after = 0.0; /* what the joints after j can move the shape */
            for (long j = kk - 1; j >= 0; j--) {
                double rj = job->reach[j * S + s];
                if (kind[j] != 0.0) {
                    ws[j] = 1.0;
                } else {
                    const double *o = ax + 6 * j, *z = o + 3;
                    double f = 0.0;
                    for (long qi = q0; qi < q1; qi++) {
                        double c[3];
                        const double *x = job->sph_c + qi * 3;
                        place_point(F, x[0], x[1], x[2], c);
                        double r0 = c[0] - o[0], r1 = c[1] - o[1], r2 = c[2] - o[2];
                        double x0 = r1 * z[2] - r2 * z[1], x1 = r2 * z[0] - r0 * z[2];
                        double x2 = r0 * z[1] - r1 * z[0];
                        double d = sqrt(x0 * x0 + x1 * x1 + x2 * x2) + job->sph_r[qi];
                        if (d > f)
                            f = d;
                    }
                    ws[j] = fmin(rj, f + after);
                    if (j == kk - 1 && job->spins[s])
                        ws[j] = 0.0;
                }
                after += (kind[j] != 0.0 ? 1.0 : rj) * dq[j];
            }
        }
        for (long p = 0; p < sm->P; p++) {
            long a = (long)sm->pa[p];
            double acc = 0.0;
            if (sm->is_self[p]) {
                long o = (long)sm->pb[p];
                long la = (long)sm->link[a], lb = (long)sm->link[o];
                long lo = la < lb ? la : lb, hi = la > lb ? la : lb;
                if (hi > nc)
                    hi = nc;
                const double *ws = wt + (lb >= la ? o : a) * nc;
                for (long j = lo; j < hi; j++)
                    acc += ws[j] * dq[j];
            } else {
                const double *ws = wt + a * nc;
                for (int j = 0; j < nc; j++)
                    acc += ws[j] * dq[j];
            }
            job->out[p * (sm->m - 1) + i] = acc;
        }
    }
    free(wt);
}

/* ---------------------------------------------------------------- arguments */

/* the pair indices pb: a robot shape where is_self, an object (below `objects`)
 * elsewhere (the generated entry checked pa and the shapes) */
static int samples_args(const double *frames, npy_intp m, npy_intp nl, const long long *link,
                        const long long *pa, const long long *pb, const npy_bool *self,
                        npy_intp S, npy_intp P, npy_intp objects, Samples *sm)
{
    for (npy_intp p = 0; p < P; p++)
        if (pb[p] < 0 || pb[p] >= (self[p] ? S : objects))
            return 0;
    sm->frames = frames;
    sm->m = (long)m;
    sm->nl = (long)nl;
    sm->S = (long)S;
    sm->P = (long)P;
    sm->link = link;
    sm->pa = pa;
    sm->pb = pb;
    sm->is_self = self;
    sm->nomem = 0;
    return 1;
}

static PyObject *bp_fail(const char *what)
{
    PyErr_Format(PyExc_ValueError, "robokin._native.%s", what);
    return NULL;
}

#define SAMPLES(a, nl, objects, sm) \
    samples_args((a)->frames, (a)->m, (nl), (a)->link, (a)->pa, (a)->pb, (a)->is_self, (a)->S, \
                 (a)->P, (objects), (sm))

/* rounded_box_bounds(frames (m, L, 4, 4), link (S,), local (S, 4, 4), h (S, 3),
 * r (S,), ob_pose (O, 4, 4), ob_h (O, 3), ob_r (O,), pa (P,), pb (P,),
 * is_self (P,) bool, skip (P,) bool, out (P, m)): sat_gap of every pair not
 * skipped at every sample into out (skipped rows are left as they are). */
static PyObject *rounded_box_bounds_body(const rounded_box_bounds_args *a)
{
    BoxJob job;
    npy_intp S = a->S, P = a->P, m = a->m;
    if (!SAMPLES(a, a->L, a->O, &job.sm))
        return bp_fail("rounded_box_bounds: a pair index out of range");
    job.local = a->local;
    job.h = a->h;
    job.r = a->r;
    job.ob_pose = a->ob_pose;
    job.ob_h = a->ob_h;
    job.ob_r = a->ob_r;
    job.skip = a->skip;
    job.out = a->out;
    Py_BEGIN_ALLOW_THREADS
    pool_for((long)m, bp_grain((long)(P + S)), box_bounds_range, &job);
    Py_END_ALLOW_THREADS
    if (job.sm.nomem)
        return PyErr_NoMemory();
    Py_RETURN_NONE;
}

/* capsule_distances(frames (m, L, 4, 4), link (S,), seg (S, 2, 3), seg_r (S,),
 * ob_seg (O, 2, 3), ob_r (O,), pa, pb, is_self (P,), pairs (k,), out (k, m)): the
 * exact distance of every listed capsule/sphere pair at every sample. */
static PyObject *capsule_distances_body(const capsule_distances_args *a)
{
    CapsuleJob job;
    npy_intp S = a->S, m = a->m, k = a->k;
    if (!SAMPLES(a, a->L, a->O, &job.sm))
        return bp_fail("capsule_distances: a pair index out of range");
    job.seg = a->seg;
    job.seg_r = a->seg_r;
    job.ob_seg = a->ob_seg;
    job.ob_r = a->ob_r;
    job.pairs = a->pairs;
    job.k = (long)k;
    job.out = a->out;
    Py_BEGIN_ALLOW_THREADS
    pool_for((long)m, bp_grain((long)(k + S)), capsule_range, &job);
    Py_END_ALLOW_THREADS
    if (job.sm.nomem)
        return PyErr_NoMemory();
    Py_RETURN_NONE;
}

/* propagate_bounds(LB (P, m), known (P, m) bool, C (P, m), rows (k,)):
 * propagate_rows, in place (one thread: each row is one pass over m values). */
static PyObject *propagate_bounds_body(const propagate_bounds_args *a)
{
    double *LB = a->LB;
    npy_intp m = a->m, k = a->k;
    Py_BEGIN_ALLOW_THREADS
    propagate_rows(LB, a->known, a->C, (long)m, a->rows, (long)k);
    Py_END_ALLOW_THREADS
    Py_RETURN_NONE;
}

/* motion_bounds(packed, q (m, n), frames (m, nc + 2, 4, 4), link (S,), sph_c (Q, 3),
 * sph_r (Q,), sph_start (S,), sph_count (S,), reach (nc, S), spins (S,) bool, pa, pb,
 * is_self (P,), out (P, m - 1)): per interval and pair the bound on the change of
 * the pair's distance (motion_range). q holds finite values and frames are its link
 * frames (robokin.kinematics.forward.link_frames, which checks q); reach[j, s] bounds
 * the distance from joint j's origin to shape s with prismatic joints at zero travel. */
static PyObject *motion_bounds_body(const motion_bounds_args *a)
{
    MotionJob job;
    const int nc = a->packed.nc;
    npy_intp m = a->m, S = a->S, P = a->P, nq = a->nq;
    /* pb of an object pair is not read here: any index passes */
    int ok = SAMPLES(a, a->nc + 2, NPY_MAX_INTP, &job.sm);
    for (npy_intp s = 0; ok && s < S; s++)
        ok = a->sph_start[s] + a->sph_count[s] <= nq;
    if (!ok)
        return bp_fail("motion_bounds: a pair or sphere index out of range");
    job.ch = &a->packed;
    job.q = a->q;
    job.sph_c = a->sph_c;
    job.sph_r = a->sph_r;
    job.sph_start = a->sph_start;
    job.sph_count = a->sph_count;
    job.spins = a->spins;
    job.out = a->out;
    job.reach = malloc(((size_t)nc * S + 1) * sizeof(double));
    job.v = malloc(((size_t)m * nc + 1) * sizeof(double));
    job.axis = malloc(((size_t)m * nc * 6 + 1) * sizeof(double));
    if (job.reach == NULL || job.v == NULL || job.axis == NULL) {
        free(job.reach);
        free(job.v);
        free(job.axis);
        return PyErr_NoMemory();
    }
    memcpy(job.reach, a->reach, (size_t)nc * S * sizeof(double));
    Py_BEGIN_ALLOW_THREADS
    pool_for((long)m, 64, motion_axes_range, &job);
    motion_reach(&job);
    pool_for((long)(m - 1), bp_grain((long)((nq + P) * nc)), motion_range, &job);
    Py_END_ALLOW_THREADS
    free(job.reach);
    free(job.v);
    free(job.axis);
    if (job.sm.nomem)
        return PyErr_NoMemory();
    Py_RETURN_NONE;
}

/* seg_seg(pts (N, 4, 3), out (N,)): the distance between segments [p1, q1] and
 * [p2, q2] given as the rows p1, q1, p2, q2 of each pts[i] (for tests). */
static PyObject *seg_seg_body(const seg_seg_args *a)
{
    npy_intp N = a->N;
    const double *p = a->pts;
    double *out = a->out;
    Py_BEGIN_ALLOW_THREADS
    for (npy_intp i = 0; i < N; i++)
        out[i] = seg_seg(p + 12 * i, p + 12 * i + 3, p + 12 * i + 6, p + 12 * i + 9);
    Py_END_ALLOW_THREADS
    Py_RETURN_NONE;
}

