/*
 * Certified distances between the planner's shapes (robokin.planning; used by
 * plan_check.c): every function returns a LOWER BOUND on the true distance that is
 * exact (to rounding) for primitives, so a pair is called free only when its real
 * shapes are apart.
 *
 * A shape is a convex *core* grown by a radius: a point (sphere), a segment
 * (capsule), a box, a cylinder or the convex hull of a mesh's vertices (a lower
 * bound for a non-convex mesh: plan_check.c then asks coal). A core sits in its
 * rounded-box frame (broadphase.c's boxes: a pose p[4 r + c], top 3x4, centred
 * on the core): a segment runs along z from -h[2] to h[2], a box has half sizes h,
 * a cylinder radius cr and half length h[2] along z, hull vertices are given in
 * that frame.
 *
 * Closed forms where there is one: segment-segment (broadphase.c's seg_seg) and
 * segment-box (seg_box below); everything else goes through GJK (gjk_lower), whose
 * every iteration yields a certified bound v.w / |v| (below).
 */
#include "chain.h"

enum { PG_POINT = 0, PG_SEGMENT = 1, PG_BOX = 2, PG_CYLINDER = 3, PG_HULL = 4 };

#define GJK_MAX_ITER 64  /* iterations of gjk_lower (polytopes finish in a few) */
#define GJK_REL 1e-12    /* stop when |v|^2 - v.w <= GJK_REL |v|^2: lb >= (1 - 1e-12) ub */
#define GJK_TINY 1e-24   /* |v|^2 at or below this: the cores touch */

typedef struct {
    int kind;
    const double *T;  /* world pose of the core's frame, top 3x4 (T[4 r + c]) */
    const double *h;  /* half sizes (3) */
    double cr;        /* cylinder radius */
    const double *v;  /* hull vertices (nv x 3) in the core's frame */
    int nv;
} Core;

static inline double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline void sub3(const double *a, const double *b, double *o)
{
    o[0] = a[0] - b[0];
    o[1] = a[1] - b[1];
    o[2] = a[2] - b[2];
}

/* The support point of a core in the world direction d: argmax_{x in core} d.x. */
static void core_support(const Core *c, const double *d, double *out)
{
    const double *T = c->T;
    double l[3], x[3] = {0.0, 0.0, 0.0};
    for (int a = 0; a < 3; a++) /* d in the core's frame: R^T d */
        l[a] = T[a] * d[0] + T[4 + a] * d[1] + T[8 + a] * d[2];
    switch (c->kind) {
    case PG_SEGMENT:
        x[2] = l[2] >= 0.0 ? c->h[2] : -c->h[2];
        break;
    case PG_BOX:
        for (int a = 0; a < 3; a++)
            x[a] = l[a] >= 0.0 ? c->h[a] : -c->h[a];
        break;
    case PG_CYLINDER: {
        double rr = sqrt(l[0] * l[0] + l[1] * l[1]);
        if (rr > 0.0) {
            x[0] = c->cr * l[0] / rr;
            x[1] = c->cr * l[1] / rr;
        }
        x[2] = l[2] >= 0.0 ? c->h[2] : -c->h[2];
        break;
    }
    case PG_HULL: {
        double best = -INFINITY;
        int k = 0;
        for (int i = 0; i < c->nv; i++) {
            double s = dot3(c->v + 3 * i, l);
            if (s > best) {
                best = s;
                k = i;
            }
        }
        if (c->nv > 0) {
            x[0] = c->v[3 * k];
            x[1] = c->v[3 * k + 1];
            x[2] = c->v[3 * k + 2];
        }
        break;
    }
    default: /* PG_POINT */
        break;
    }
    for (int a = 0; a < 3; a++)
        out[a] = T[4 * a] * x[0] + T[4 * a + 1] * x[1] + T[4 * a + 2] * x[2] + T[4 * a + 3];
}

/* ------------------------------------------------------- closest point on a simplex */

/* The point of triangle (a, b, c) closest to the origin into v; keep[] marks the
 * vertices of the feature it lies on. Ericson, "Real-Time Collision Detection", 2005,
 * sec. 5.1.5 (ClosestPtPointTriangle) with p = 0; a degenerate (flat) triangle falls
 * back to its closest edge. */
static void closest_triangle(const double *a, const double *b, const double *c, double *v,
                             int *keep)
{
    double ab[3], ac[3], ap[3] = {-a[0], -a[1], -a[2]};
    sub3(b, a, ab);
    sub3(c, a, ac);
    keep[0] = keep[1] = keep[2] = 0;
    double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) {
        keep[0] = 1;
        memcpy(v, a, 3 * sizeof(double));
        return;
    }
    double bp[3] = {-b[0], -b[1], -b[2]};
    double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) {
        keep[1] = 1;
        memcpy(v, b, 3 * sizeof(double));
        return;
    }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        double t = d1 / (d1 - d3);
        keep[0] = keep[1] = 1;
        for (int k = 0; k < 3; k++)
            v[k] = a[k] + t * ab[k];
        return;
    }
    double cp[3] = {-c[0], -c[1], -c[2]};
    double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) {
        keep[2] = 1;
        memcpy(v, c, 3 * sizeof(double));
        return;
    }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        double t = d2 / (d2 - d6);
        keep[0] = keep[2] = 1;
        for (int k = 0; k < 3; k++)
            v[k] = a[k] + t * ac[k];
        return;
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
        double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        keep[1] = keep[2] = 1;
        for (int k = 0; k < 3; k++)
            v[k] = b[k] + t * (c[k] - b[k]);
        return;
    }
    double den = va + vb + vc;
    if (!(den > 1e-300)) { /* flat: the closest of the three edges */
        const double *P[3][2] = {{a, b}, {a, c}, {b, c}};
        static const int EI[3][2] = {{0, 1}, {0, 2}, {1, 2}};
        double best = INFINITY;
        for (int e = 0; e < 3; e++) {
            const double *p = P[e][0], *q = P[e][1];
            double d[3], w[3];
            sub3(q, p, d);
            double dd = dot3(d, d);
            double t = dd > 0.0 ? -dot3(p, d) / dd : 0.0;
            t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
            for (int k = 0; k < 3; k++)
                w[k] = p[k] + t * d[k];
            double n2 = dot3(w, w);
            if (n2 < best) {
                best = n2;
                memcpy(v, w, 3 * sizeof(double));
                keep[0] = keep[1] = keep[2] = 0;
                keep[EI[e][0]] = t < 1.0;
                keep[EI[e][1]] = t > 0.0;
            }
        }
        return;
    }
    double s = vb / den, t = vc / den;
    keep[0] = keep[1] = keep[2] = 1;
    for (int k = 0; k < 3; k++)
        v[k] = a[k] + ab[k] * s + ac[k] * t;
}

/* Whether the origin and d lie on opposite sides of the plane through a, b, c (or d
 * lies on it: a flat tetrahedron is handled through its faces). Ericson sec. 5.1.6. */
static int origin_outside(const double *a, const double *b, const double *c, const double *d)
{
    double ab[3], ac[3], n[3], ad[3];
    sub3(b, a, ab);
    sub3(c, a, ac);
    n[0] = ab[1] * ac[2] - ab[2] * ac[1];
    n[1] = ab[2] * ac[0] - ab[0] * ac[2];
    n[2] = ab[0] * ac[1] - ab[1] * ac[0];
    sub3(d, a, ad);
    double sp = -dot3(a, n), sd = dot3(ad, n);
    double scale = dot3(n, n) * (dot3(ad, ad) + dot3(a, a));
    if (sd * sd <= 1e-24 * scale)
        return 1;
    return sp * sd < 0.0;
}

/* Reduce the simplex X (nw points) to the feature holding its point closest to the
 * origin, which goes into v. Returns the new size, or 4 when the origin lies inside
 * the tetrahedron (distance 0). */
static int closest_simplex(double X[4][3], int nw, double *v)
{
    if (nw == 1) {
        memcpy(v, X[0], 3 * sizeof(double));
        return 1;
    }
    if (nw == 2) {
        double d[3];
        sub3(X[1], X[0], d);
        double dd = dot3(d, d);
        double t = dd > 0.0 ? -dot3(X[0], d) / dd : 0.0;
        if (t <= 0.0) {
            memcpy(v, X[0], 3 * sizeof(double));
            return 1;
        }
        if (t >= 1.0) {
            memcpy(v, X[1], 3 * sizeof(double));
            memcpy(X[0], X[1], 3 * sizeof(double));
            return 1;
        }
        for (int k = 0; k < 3; k++)
            v[k] = X[0][k] + t * d[k];
        return 2;
    }
    int keep[4] = {0, 0, 0, 0};
    if (nw == 3) {
        closest_triangle(X[0], X[1], X[2], v, keep);
    } else {
        static const int F[4][4] = {{0, 1, 2, 3}, {0, 1, 3, 2}, {0, 2, 3, 1}, {1, 2, 3, 0}};
        double best = INFINITY;
        int any = 0;
        for (int f = 0; f < 4; f++) {
            const int *fi = F[f];
            if (!origin_outside(X[fi[0]], X[fi[1]], X[fi[2]], X[fi[3]]))
                continue;
            any = 1;
            double w[3];
            int kf[3];
            closest_triangle(X[fi[0]], X[fi[1]], X[fi[2]], w, kf);
            double n2 = dot3(w, w);
            if (n2 < best) {
                best = n2;
                memcpy(v, w, 3 * sizeof(double));
                keep[0] = keep[1] = keep[2] = keep[3] = 0;
                for (int k = 0; k < 3; k++)
                    keep[fi[k]] = kf[k];
            }
        }
        if (!any) {
            v[0] = v[1] = v[2] = 0.0;
            return 4;
        }
    }
    int m = 0;
    for (int i = 0; i < nw; i++)
        if (keep[i]) {
            if (m != i)
                memcpy(X[m], X[i], 3 * sizeof(double));
            m++;
        }
    return m;
}

/* A certified lower bound on the distance between two cores (radii not included),
 * and in *ub the length of a vector of A - B (an upper bound; 0 when they overlap).
 *
 * GJK: Gilbert, Johnson & Keerthi, "A fast procedure for computing the distance
 * between complex objects in three-dimensional space", IEEE J. Robotics and
 * Automation 4(2), 1988; van den Bergen, "Collision Detection in Interactive 3D
 * Environments", 2004, sec. 4.3. For the point v of A - B found so far and w the
 * support point of A - B in direction -v, every x of A - B has |x| >= v.x / |v| >=
 * v.w / |v| (Cauchy-Schwarz, then w minimises v.x): the bound holds at every
 * iteration, however GJK's simplex arithmetic rounds, so stopping early (iteration
 * cap, no progress) only loosens it. A positive bound also overrules the simplex
 * when it reports the origin inside: on a cylinder GJK creeps towards the answer
 * with ever thinner tetrahedra, whose inside test (with FMA contraction) could
 * flip and report an overlap of cores 8 mm apart (docs/planning.md). */
static double gjk_lower(const Core *A, const Core *B, double *ub)
{
    double X[4][3], v[3], d[3], sa[3], sb[3], w[3];
    /* start from a point of A - B: the supports along the centre line */
    d[0] = B->T[3] - A->T[3];
    d[1] = B->T[7] - A->T[7];
    d[2] = B->T[11] - A->T[11];
    if (dot3(d, d) <= 0.0)
        d[0] = 1.0;
    core_support(A, d, sa);
    double nd[3] = {-d[0], -d[1], -d[2]};
    core_support(B, nd, sb);
    sub3(sa, sb, v);
    memcpy(X[0], v, 3 * sizeof(double));
    int nw = 1;
    double lb = 0.0, vv = dot3(v, v);
    for (int it = 0; it < GJK_MAX_ITER && vv > GJK_TINY; it++) {
        nd[0] = -v[0];
        nd[1] = -v[1];
        nd[2] = -v[2];
        core_support(A, nd, sa);
        core_support(B, v, sb);
        sub3(sa, sb, w);
        double vw = dot3(v, w);
        if (vw > 0.0) {
            double l = vw / sqrt(vv);
            if (l > lb)
                lb = l;
        }
        if (vv - vw <= GJK_REL * vv)
            break;
        int dup = 0;
        for (int i = 0; i < nw; i++)
            if (X[i][0] == w[0] && X[i][1] == w[1] && X[i][2] == w[2])
                dup = 1;
        if (dup)
            break;
        memcpy(X[nw++], w, 3 * sizeof(double));
        double vn[3];
        nw = closest_simplex(X, nw, vn);
        double vvn = dot3(vn, vn);
        if (nw == 4) { /* the origin is inside: the cores overlap ... */
            if (lb > 0.0) /* ... unless a certified bound says they are apart: then the */
                break;    /* simplex (a sliver, on a curved core) misread its rounding */
            *ub = 0.0;
            return 0.0;
        }
        if (vvn >= vv) /* no progress: rounding; the bound so far stands */
            break;
        memcpy(v, vn, 3 * sizeof(double));
        vv = vvn;
    }
    if (vv <= GJK_TINY) {
        *ub = sqrt(vv);
        return 0.0;
    }
    *ub = sqrt(vv);
    return lb < *ub ? lb : *ub;
}

/* ------------------------------------------------------------------ segment-box */

/* The distance between the segment [p, q] and the box |x_a| <= h_a (both in the
 * box's frame), exactly. The squared distance from x(t) = p + t (q - p) to the box
 * is f(t) = sum_a e_a(t)^2, e_a = max(|x_a| - h_a, 0): convex, continuously
 * differentiable, and quadratic between the (at most 6) parameters where some
 * |x_a(t)| = h_a, so its derivative f' is nondecreasing and linear between them.
 * The minimum is at t = 0 when f'(0) >= 0, at t = 1 when f'(1) <= 0, else at the
 * root of f', found on the first piece whose end has f' >= 0 by interpolating f'
 * linearly there (exact on the piece). */
static inline double seg_box_slope(const double *p, const double *d, const double *h,
                                   double t)
{
    double g = 0.0;
    for (int a = 0; a < 3; a++) {
        double x = p[a] + t * d[a];
        if (x > h[a])
            g += (x - h[a]) * d[a];
        else if (x < -h[a])
            g += (x + h[a]) * d[a];
    }
    return g; /* f'(t) / 2 */
}

static double seg_box(const double *p, const double *q, const double *h)
{
    double d[3], br[7];
    int nb = 0;
    sub3(q, p, d);
    for (int a = 0; a < 3; a++)
        if (d[a] != 0.0)
            for (int s = -1; s <= 1; s += 2) {
                double t = (s * h[a] - p[a]) / d[a];
                if (t > 0.0 && t < 1.0)
                    br[nb++] = t;
            }
    for (int i = 1; i < nb; i++) /* insertion sort: at most 6 values */
        for (int j = i; j > 0 && br[j] < br[j - 1]; j--) {
            double x = br[j];
            br[j] = br[j - 1];
            br[j - 1] = x;
        }
    br[nb++] = 1.0;
    double t = 1.0, prev = 0.0, g_prev = seg_box_slope(p, d, h, 0.0);
    if (g_prev >= 0.0) {
        t = 0.0;
    } else {
        for (int i = 0; i < nb; i++) {
            double g = seg_box_slope(p, d, h, br[i]);
            if (g >= 0.0) {
                double span = g - g_prev;
                t = span > 0.0 ? prev - g_prev * (br[i] - prev) / span : br[i];
                t = t < prev ? prev : (t > br[i] ? br[i] : t);
                break;
            }
            prev = br[i];
            g_prev = g;
        }
    }
    double f = 0.0;
    for (int a = 0; a < 3; a++) { /* f at the minimiser, from its definition */
        double x = fabs(p[a] + t * d[a]) - h[a];
        if (x > 0.0)
            f += x * x;
    }
    return sqrt(f);
}

/* The core of a point or segment as its two end points in the world. */
static inline void core_ends(const Core *c, double *p, double *q)
{
    const double *T = c->T;
    double hz = c->kind == PG_SEGMENT ? c->h[2] : 0.0;
    for (int a = 0; a < 3; a++) {
        p[a] = T[4 * a + 3] - hz * T[4 * a + 2];
        q[a] = T[4 * a + 3] + hz * T[4 * a + 2];
    }
}

/* A point or segment core s against a box core b: seg_box in b's frame. */
static double seg_box_world(const Core *s, const Core *b)
{
    double p[3], q[3], pl[3], ql[3];
    core_ends(s, p, q);
    const double *T = b->T;
    double dp[3] = {p[0] - T[3], p[1] - T[7], p[2] - T[11]};
    double dq[3] = {q[0] - T[3], q[1] - T[7], q[2] - T[11]};
    for (int a = 0; a < 3; a++) { /* R^T (x - t) */
        pl[a] = T[a] * dp[0] + T[4 + a] * dp[1] + T[8 + a] * dp[2];
        ql[a] = T[a] * dq[0] + T[4 + a] * dq[1] + T[8 + a] * dq[2];
    }
    return seg_box(pl, ql, b->h);
}

/* Pair methods (plan_check.c picks one per pair when the model is built). */
enum { PD_SEGSEG = 0, PD_SEGBOX = 1, PD_BOXSEG = 2, PD_GJK = 3, PD_HULL = 4 };

/* The distance between two cores (radii excluded) by the pair's method: exact to
 * rounding for PD_SEGSEG / PD_SEGBOX / PD_BOXSEG, a certified lower bound from GJK
 * otherwise (PD_HULL: of a mesh's convex hull). */
static double core_distance(int method, const Core *A, const Core *B)
{
    double p1[3], q1[3], p2[3], q2[3], ub;
    switch (method) {
    case PD_SEGSEG:
        core_ends(A, p1, q1);
        core_ends(B, p2, q2);
        return seg_seg(p1, q1, p2, q2);
    case PD_SEGBOX:
        return seg_box_world(A, B);
    case PD_BOXSEG:
        return seg_box_world(B, A);
    default:
        return gjk_lower(A, B, &ub);
    }
}
