/*
 * A position branch's row of held_closed.c (issue 29): the formulas once, for one row
 * (HR_T double: hc_eval, the events' rows) and for W rows at a time (HR_T vd, lanes.h:
 * a piece's nodes, known before any of them is looked at, and E2's margin's). Included
 * by held_closed.c once per type after defining
 *
 *   HR_T     the value type (double, vd); HR_V3 its 3-vector (v3, HcV3); HR_M a
 *            comparison's (int 0 or 1, vl)
 *   HR_SUF   the functions' suffix (_1, _w)
 *   HR_BR(x) a double in every lane; HR_SQRT, HR_ABS, HR_SEL(m, a, b), HR_FINITE(x)
 *   HR_NONE(m)  1 when a lane of mask m is false (one row: !m); HR_NOT(m) m negated
 *
 * (it undefines them at its end). The notation is held_closed.c's header's.
 */

#define HR_CAT2(a, b) a##b
#define HR_CAT(a, b) HR_CAT2(a, b)
#define HR(name) HR_CAT(name, HR_SUF)

ALWAYS_INLINE HR_V3 HR(hr_br)(v3 a) { return (HR_V3){HR_BR(a.x), HR_BR(a.y), HR_BR(a.z)}; }
ALWAYS_INLINE HR_T HR(hr_dot)(HR_V3 a, HR_V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
ALWAYS_INLINE HR_T HR(hr_dots)(HR_V3 a, v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
ALWAYS_INLINE HR_V3 HR(hr_cross)(HR_V3 a, HR_V3 b)
{
    return (HR_V3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
ALWAYS_INLINE HR_V3 HR(hr_add)(HR_V3 a, HR_V3 b)
{
    return (HR_V3){a.x + b.x, a.y + b.y, a.z + b.z};
}
ALWAYS_INLINE HR_V3 HR(hr_scale)(HR_V3 a, HR_T t) { return (HR_V3){a.x * t, a.y * t, a.z * t}; }
/* a0 + (c a1 + s a2) */
ALWAYS_INLINE HR_V3 HR(hr_lin)(v3 a0, v3 a1, HR_T c, v3 a2, HR_T s)
{
    return (HR_V3){a0.x + (a1.x * c + a2.x * s), a0.y + (a1.y * c + a2.y * s),
                   a0.z + (a1.z * c + a2.z * s)};
}
/* R v (R by its rows) */
ALWAYS_INLINE HR_V3 HR(hr_m3)(const m3 *R, HR_V3 v)
{
    return (HR_V3){HR(hr_dots)(v, R->r0), HR(hr_dots)(v, R->r1), HR(hr_dots)(v, R->r2)};
}

/* a[0] + a[1] cos x + a[2] sin x and its slope d/dx (c, s: cos x, sin x) */
ALWAYS_INLINE HR_T HR(hr_aff)(const double *a, HR_T c, HR_T s)
{
    return a[0] + a[1] * c + a[2] * s;
}
ALWAYS_INLINE HR_T HR(hr_daff)(const double *a, HR_T c, HR_T s)
{
    return -a[1] * s + a[2] * c;
}

/* sin v2 of a row (sh: w.ea, w.e2, w.e1, r.ea, r.e2): |(w.ea, w.e2)|, r-only |(r.ea, r.e2)| */
ALWAYS_INLINE HR_T HR(hr_rho)(const HR_T *a, int ronly)
{
    return ronly ? HR_SQRT(a[3] * a[3] + a[4] * a[4]) : HR_SQRT(a[0] * a[0] + a[1] * a[1]);
}

/* rot(h_k, t) v (c = cos t, s = sin t): about a coordinate axis (the Panda's, the
 * FR3's: every axis at zero) two coordinates turn; else Rodrigues' formula */
ALWAYS_INLINE HR_V3 HR(hr_rot)(const HcGeo *g, int k, HR_T c, HR_T s, HR_V3 v)
{
    HR_T t = g->axs[k] * s;
    switch (g->ax[k]) {
    case 0:
        return (HR_V3){v.x, c * v.y - t * v.z, t * v.y + c * v.z};
    case 1:
        return (HR_V3){c * v.x + t * v.z, v.y, c * v.z - t * v.x};
    case 2:
        return (HR_V3){c * v.x - t * v.y, t * v.x + c * v.y, v.z};
    default: {
        HR_V3 h = HR(hr_br)(g->h[k]), x = HR(hr_cross)(h, v);
        HR_T kv = HR(hr_dot)(h, v) * (1.0 - c);
        return (HR_V3){v.x * c + x.x * s + h.x * kv, v.y * c + x.y * s + h.y * kv,
                       v.z * c + x.z * s + h.z * kv};
    }
    }
}

/* cos, sin of a root of A cos v + B sin v = C (|(A, B)| = n), root i (0: phi + acos,
 * 1: phi - acos; subproblems.h's SP4_PAIR without the angles), with gamma = C / n
 * clamped to [-1, 1] (a branch end keeps both labels, where sp4_roots merges them);
 * sigma = sin(acos gamma), negative for root 1 */
ALWAYS_INLINE void HR(hr_root)(HR_T A, HR_T B, HR_T n, HR_T C, int i, HR_T *c, HR_T *s,
                               HR_T *sigma)
{
    HR_T gm = C / n;
    gm = HR_SEL(gm > 1.0, HR_BR(1.0), HR_SEL(gm < -1.0, HR_BR(-1.0), gm));
    HR_T sg = HR_SQRT(1.0 - gm * gm), cp = A / n, sp = B / n;
    if (!i) {
        *c = cp * gm - sp * sg;
        *s = sp * gm + cp * sg;
        *sigma = sg;
    } else {
        *c = cp * gm + sp * sg;
        *s = sp * gm - cp * sg;
        *sigma = -sg;
    }
}

/* E2's margin of v4 root i at x (c, s: cos x, sin x; >= 0 where v6 has roots), its
 * slope d/dx when dm != NULL */
ALWAYS_INLINE HR_T HR(hr_m2)(const HcPose *p, HR_T c, HR_T s, int i, HR_T *dm)
{
    const HcGeo *g = p->g;
    HR_T c4, s4, sg;
    HR_T D = HR(hr_aff)(p->d, c, s);
    HR(hr_root)(HR_BR(g->c1), HR_BR(g->c2), HR_BR(g->cn), D - g->K, i, &c4, &s4, &sg);
    HR_T e = g->ec[0] + g->ec[1] * c4 + g->ec[2] * s4;
    HR_T f0 = HR(hr_aff)(p->f0, c, s);
    HR_T f1 = HR(hr_aff)(p->f1, c, s);
    HR_T f2 = HR(hr_aff)(p->f2, c, s);
    HR_T H = HR_SQRT(f1 * f1 + f2 * f2), E = e - f0;
    if (dm != NULL) {
        HR_T dv4 = HR(hr_daff)(p->d, c, s) / (-g->c1 * s4 + g->c2 * c4);
        HR_T de = (-g->ec[1] * s4 + g->ec[2] * c4) * dv4;
        HR_T dH = (f1 * HR(hr_daff)(p->f1, c, s) + f2 * HR(hr_daff)(p->f2, c, s)) / H;
        HR_T sgn = HR_SEL(E < 0.0, HR_BR(-1.0), HR_BR(1.0));
        *dm = dH - sgn * (de - HR(hr_daff)(p->f0, c, s));
    }
    return H - HR_ABS(E);
}

/* w = R e1, R = RG0 R7(-x) R6(-v6) R5(-v5) R4(-v4) (cs: cos, sin of v4, v5, v6, x) */
ALWAYS_INLINE HR_V3 HR(hr_w)(const HcPose *p, const HR_T cs[4][2])
{
    const HcGeo *g = p->g;
    HR_V3 w = HR(hr_rot)(g, 3, cs[0][0], -cs[0][1], HR(hr_br)(g->e1));
    w = HR(hr_rot)(g, 4, cs[1][0], -cs[1][1], w);
    w = HR(hr_rot)(g, 5, cs[2][0], -cs[2][1], w);
    w = HR(hr_rot)(g, 6, cs[3][0], -cs[3][1], w);
    return HR(hr_m3)(&p->RG0, w);
}

/* dw / dx = om x w, om = -RG0 R7(-x) in: the shoulder's spatial angular velocity */
ALWAYS_INLINE HR_V3 HR(hr_dw)(const HcPose *p, HR_T c, HR_T s, HR_V3 in, HR_V3 w, HR_T *omsum)
{
    HR_V3 om = HR(hr_scale)(HR(hr_m3)(&p->RG0, HR(hr_rot)(p->g, 6, c, -s, in)), HR_BR(-1.0));
    *omsum = om.x + om.y + om.z;
    return HR(hr_cross)(om, w);
}

/* The shoulder's scalars from the wrist's values (cs: cos, sin of v4, v5, v6, x): sh =
 * w.ea, w.e2, w.e1, r.ea, r.e2 with w = R e1 (hr_w) and r = R^T e1 (into *w, *rr);
 * r_only: w left out, sh[0], sh[1] NaN and sh[2] = r.e1 (cos v2 both ways) */
ALWAYS_INLINE void HR(hr_shoulder)(const HcPose *p, const HR_T cs[4][2], int ronly, HR_T *sh,
                                   HR_V3 *w, HR_V3 *rr)
{
    const HcGeo *g = p->g;
    if (!ronly)
        *w = HR(hr_w)(p, cs);
    HR_V3 r = HR(hr_rot)(g, 6, cs[3][0], cs[3][1], HR(hr_br)(p->g1));
    r = HR(hr_rot)(g, 5, cs[2][0], cs[2][1], r);
    r = HR(hr_rot)(g, 4, cs[1][0], cs[1][1], r);
    r = HR(hr_rot)(g, 3, cs[0][0], cs[0][1], r);
    *rr = r;
    sh[0] = ronly ? HR_BR(NAN) : HR(hr_dots)(*w, g->ea);
    sh[1] = ronly ? HR_BR(NAN) : HR(hr_dots)(*w, g->e2);
    sh[2] = HR(hr_dots)(ronly ? r : *w, g->e1);
    sh[3] = HR(hr_dots)(r, g->ea);
    sh[4] = HR(hr_dots)(r, g->e2);
}

/* One branch's values at x (hc_eval's; without w where r_only) */
typedef struct {
    HR_T cs[4][2];             /* cos, sin of v4, v5, v6, x */
    HR_T dv[3];                /* d/dx of v4, v5, v6 */
    HR_T noise;                /* v5's rounding (NaN unless asked) */
    HR_T sh[5], dsh[5];        /* w.ea, w.e2, w.e1 (r.e1 r-only), r.ea, r.e2; slopes */
    HR_V3 in;                  /* the shoulder's body angular velocity's inner part */
    HR_T sloped;               /* 1 where the slopes are finite, else 0 */
    int ronly;                 /* w left out (a wrist joint outside: HC_RONLY) */
} HR(HrRow);

/* Branch (i, j)'s row at x (c, s: cos x, sin x; what: HC_SHOULDER, HC_SLOPES,
 * HC_NOISE, HC_RONLY, the last for one row only): 0 when one has none (a margin below
 * -tol) */
ALWAYS_INLINE int HR(hr_row)(const HcPose *p, HR_T c, HR_T s, int i, int j, int what,
                             HR(HrRow) *o)
{
    const HcGeo *g = p->g;
    HR_T D = HR(hr_aff)(p->d, c, s), c4, s4, s4g, c6, s6, s6g;
    if (HR_NONE(g->cn - HR_ABS(D - g->K) >= -1e-12 * g->cn))
        return 0;
    HR(hr_root)(HR_BR(g->c1), HR_BR(g->c2), HR_BR(g->cn), D - g->K, i, &c4, &s4, &s4g);
    HR_V3 x4 = HR(hr_lin)(g->a0, g->a1, c4, g->a2, s4);
    HR_T e = g->ec[0] + g->ec[1] * c4 + g->ec[2] * s4;
    HR_T f0 = HR(hr_aff)(p->f0, c, s);
    HR_T f1 = HR(hr_aff)(p->f1, c, s);
    HR_T f2 = HR(hr_aff)(p->f2, c, s);
    HR_T H = HR_SQRT(f1 * f1 + f2 * f2);
    if (HR_NONE(H > 0.0) || HR_NONE(H - HR_ABS(e - f0) >= -1e-12 * H))
        return 0;
    HR(hr_root)(f1, f2, H, e - f0, j, &c6, &s6, &s6g);
    HR_V3 v = HR(hr_lin)(p->v[0], p->v[1], c, p->v[2], s);
    v3 h4 = g->h[3], h5 = g->h[4], h6 = g->h[5], h7 = g->h[6];
    HR_V3 u6 = HR(hr_rot)(g, 5, c6, s6, v);
    /* v5: e5(-v5) x4 = u6 (the turn about axis 5 taking x4 to u6 is -v5) */
    HR_T x5 = HR(hr_dots)(x4, h5), u5 = HR(hr_dots)(u6, h5);
    HR_V3 xp = {x4.x - h5.x * x5, x4.y - h5.y * x5, x4.z - h5.z * x5};
    HR_V3 up = {u6.x - h5.x * u5, u6.y - h5.y * u5, u6.z - h5.z * u5};
    HR_T yy = HR(hr_dots)(HR(hr_cross)(xp, up), h5), xx = HR(hr_dot)(xp, up);
    HR_T nn = HR_SQRT(yy * yy + xx * xx);
    if (HR_NONE(nn > 1e-9 * g->cn))
        return 0;
    HR_T c5 = xx / nn, s5 = -yy / nn;
    /* v5's rounding: x4 and u6 next to axis 5 leave only their small normal parts */
    o->noise = !(what & HC_NOISE)
                   ? HR_BR(NAN) /* (+ acos at an end) */
                   : 4.0 * DBL_EPSILON *
                         (HR_SQRT(HR(hr_dot)(x4, x4) * HR(hr_dot)(u6, u6)) / nn +
                          1.0 / HR_ABS(s4g) + 1.0 / HR_ABS(s6g));
    HR_T cs[4][2] = {{c4, s4}, {c5, s5}, {c6, s6}, {c, s}};
    for (int k = 0; k < 4; k++) {
        o->cs[k][0] = cs[k][0];
        o->cs[k][1] = cs[k][1];
    }
    /* a wrist joint outside its limits: r alone (a dead cell's row, hc_cell) */
    o->ronly = 0;
    if ((what & (HC_SHOULDER | HC_RONLY)) == (HC_SHOULDER | HC_RONLY))
        for (int jw = 0; jw < 3; jw++)
            o->ronly |= !HR_NONE(cs[jw][0] * g->arc[jw + 3][0] + cs[jw][1] * g->arc[jw + 3][1] <
                                 g->arc[jw + 3][2]);
    HR_V3 w = {HR_BR(0.0), HR_BR(0.0), HR_BR(0.0)}, rr = w;
    if (what & HC_SHOULDER)
        HR(hr_shoulder)(p, (const HR_T(*)[2])cs, o->ronly, o->sh, &w, &rr);
    o->sloped = HR_BR(0.0);
    if (!(what & HC_SLOPES))
        return 1;
    /* joint rates d/dx: E1, E2, v5's equation (m = R5(v5) h6: m . x4 = h6 . v) */
    HR_T dv4 = HR(hr_daff)(p->d, c, s) / (-g->c1 * s4 + g->c2 * c4);
    HR_T de = (-g->ec[1] * s4 + g->ec[2] * c4) * dv4;
    HR_T dv6 = (de - HR(hr_daff)(p->f0, c, s) - HR(hr_daff)(p->f1, c, s) * c6 -
                HR(hr_daff)(p->f2, c, s) * s6) /
               (-f1 * s6 + f2 * c6);
    HR_V3 m = HR(hr_rot)(g, 4, c5, s5, HR(hr_br)(h6));
    HR_V3 dx4 = HR(hr_scale)(HR(hr_lin)((v3){0.0, 0.0, 0.0}, g->a1, -s4, g->a2, c4), dv4);
    HR_V3 dv = HR(hr_lin)((v3){0.0, 0.0, 0.0}, p->v[1], -s, p->v[2], c);
    HR_T dv5 = (HR(hr_dots)(dv, h6) - HR(hr_dot)(m, dx4)) /
               HR(hr_dot)(HR(hr_cross)(HR(hr_br)(h5), m), x4);
    o->dv[0] = dv4;
    o->dv[1] = dv5;
    o->dv[2] = dv6;
    if (!(what & HC_SHOULDER)) {
        o->sloped = HR_SEL(HR_FINITE(dv4) & HR_FINITE(dv5) & HR_FINITE(dv6), HR_BR(1.0),
                           HR_BR(0.0));
        return 1;
    }
    /* the shoulder's angular velocity: spatial om = -RG inner, body -R4 R5 R6 inner */
    HR_V3 in = HR(hr_add)(HR(hr_scale)(HR(hr_rot)(g, 4, c5, -s5, HR(hr_br)(h4)), dv4),
                          HR(hr_scale)(HR(hr_br)(h5), dv5));
    in = HR(hr_add)(HR(hr_rot)(g, 5, c6, -s6, in),
                    HR(hr_add)(HR(hr_scale)(HR(hr_br)(h6), dv6), HR(hr_br)(h7)));
    o->in = in;
    HR_V3 ob = HR(hr_rot)(g, 5, c6, s6, in);
    ob = HR(hr_rot)(g, 4, c5, s5, ob);
    ob = HR(hr_scale)(HR(hr_rot)(g, 3, c4, s4, ob), HR_BR(-1.0));
    HR_V3 dr = HR(hr_cross)(rr, ob);
    o->dsh[3] = HR(hr_dots)(dr, g->ea);
    o->dsh[4] = HR(hr_dots)(dr, g->e2);
    if (o->ronly) {
        o->dsh[0] = o->dsh[1] = HR_BR(NAN);
        o->dsh[2] = HR(hr_dots)(dr, g->e1);
        o->sloped = HR_SEL(HR_FINITE(dv4) & HR_FINITE(dv5) & HR_FINITE(dv6) &
                               HR_FINITE(ob.x + ob.y + ob.z),
                           HR_BR(1.0), HR_BR(0.0));
        return 1;
    }
    HR_T omsum;
    HR_V3 dw = HR(hr_dw)(p, c, s, in, w, &omsum);
    o->dsh[0] = HR(hr_dots)(dw, g->ea);
    o->dsh[1] = HR(hr_dots)(dw, g->e2);
    o->dsh[2] = HR(hr_dots)(dw, g->e1);
    o->sloped = HR_SEL(HR_FINITE(dv4) & HR_FINITE(dv5) & HR_FINITE(dv6) & HR_FINITE(omsum),
                       HR_BR(1.0), HR_BR(0.0));
    return 1;
}

/* A row's margins of joints 1-6 to their limits, both triples (mg[k][j]), without the
 * angles: with m the middle of a joint's range of chain values and h its half width,
 * (cos(v - m) - cos h) / sin h, of the sign of the joint's margin and equal to it to
 * O(margin^2) (sin d + cot h (cos d - 1) at a margin d). The shoulder's (cos, sin) from
 * w and r as hc_angles' (sin v2 = |(w.ea, w.e2)| for triple 0, |(r.ea, r.e2)| r-only;
 * triple 1: v1 + pi, -v2, v3 + pi); cs: cos, sin of v4, v5, v6 */
ALWAYS_INLINE void HR(hr_margins)(const HcGeo *g, const HR_T *a, int ronly, const HR_T cs[3][2],
                                  HR_T mg[2][6])
{
    HR_T rho = HR(hr_rho)(a, ronly), ir = 1.0 / rho;
    HR_T d1 = (a[0] * g->arc[0][0] + a[1] * g->arc[0][1]) * ir;
    HR_T d3 = (-a[3] * g->arc[2][0] + a[4] * g->arc[2][1]) * ir;
    HR_T d2c = a[2] * g->arc[1][0], d2s = rho * g->arc[1][1];
    mg[0][0] = (d1 - g->arc[0][2]) * g->arc[0][3];
    mg[1][0] = (-d1 - g->arc[0][2]) * g->arc[0][3];
    mg[0][1] = (d2c + d2s - g->arc[1][2]) * g->arc[1][3];
    mg[1][1] = (d2c - d2s - g->arc[1][2]) * g->arc[1][3];
    mg[0][2] = (d3 - g->arc[2][2]) * g->arc[2][3];
    mg[1][2] = (-d3 - g->arc[2][2]) * g->arc[2][3];
    for (int j = 3; j < 6; j++)
        mg[0][j] = mg[1][j] =
            (cs[j - 3][0] * g->arc[j][0] + cs[j - 3][1] * g->arc[j][1] - g->arc[j][2]) *
            g->arc[j][3];
}

/* Query q's value on a row (a: sh, w.ea, w.e2, w.e1, r.ea, r.e2), or its slope d/dx
 * (slope = 1, a: dsh) */
ALWAYS_INLINE HR_T HR(hr_query)(const HcQuery *q, const HR_T *a, int slope)
{
    return q->j == 0 ? -q->sV * a[0] + q->cV * a[1]
         : q->j == 1 ? (slope ? a[2] : a[2] - q->cV)
                     : q->cV * a[4] + q->sV * a[3];
}

/* hc_cell's common case: a query of values fa, fb and slopes da, db (times the cell)
 * at a cell's ends is of one sign and clear of tol all over the cell (the cubic Hermite
 * model within 4/27 (|da| + |db|) of a mean of fa and fb), moves by at most HC_MOVE and
 * has no extremum toward 0 (slopes pointing inward): 1 (a lane's mask) where it is */
ALWAYS_INLINE HR_M HR(hr_clear)(HR_T fa, HR_T fb, HR_T da, HR_T db, double tol)
{
    HR_T afa = HR_ABS(fa), afb = HR_ABS(fb), ada = HR_ABS(da), adb = HR_ABS(db);
    HR_M pos = fa > 0.0;
    HR_M inward = (pos & (da < 0.0) & (db > 0.0)) | (HR_NOT(pos) & (da > 0.0) & (db < 0.0));
    return HR_FINITE(da) & HR_FINITE(db) & ((fa < 0.0) == (fb < 0.0)) &
           (HR_SEL(afa < afb, afa, afb) > (4.0 / 27.0) * (ada + adb) + tol) &
           (HR_ABS(fb - fa) <= HC_MOVE) & (ada <= 2.0 * HC_MOVE) & (adb <= 2.0 * HC_MOVE) &
           HR_NOT(inward);
}

/* hc_m2_cell's cell without work: E2's margin m0, m1 at a cell's ends with slopes s0,
 * s1 (times the cell; finite) of one sign and clear of 0 all over the cell by the cubic
 * model's bound (hc_hermite's first test, in units of scale), slopes agreeing with the
 * chord (HC_BEND) and not pointing inward (no extremum toward 0) */
ALWAYS_INLINE HR_M HR(hr_m2_clear)(HR_T m0, HR_T m1, HR_T s0, HR_T s1, double scale)
{
    HR_T u0 = m0 / scale, u1 = m1 / scale, au0 = HR_ABS(u0), au1 = HR_ABS(u1);
    HR_T chord = m1 - m0;
    HR_M pos = m0 > 0.0;
    HR_M inward = (pos & (s0 < 0.0) & (s1 > 0.0)) | (HR_NOT(pos) & (s0 > 0.0) & (s1 < 0.0));
    return HR_FINITE(s0) & HR_FINITE(s1) & ((u0 < 0.0) == (u1 < 0.0)) &
           (HR_SEL(au0 < au1, au0, au1) >
            (4.0 / 27.0) * (HR_ABS(s0 / scale) + HR_ABS(s1 / scale)) + HC_TOUCH) &
           (HR_ABS(s0 - chord) + HR_ABS(s1 - chord) <=
            HC_BEND * (HR_ABS(chord) + HC_BEND_FLOOR * scale)) &
           HR_NOT(inward);
}

#undef HR
#undef HR_CAT
#undef HR_CAT2
/* (the parameters too: the next instantiation defines its own) */
#undef HR_T
#undef HR_V3
#undef HR_SUF
#undef HR_BR
#undef HR_SQRT
#undef HR_ABS
#undef HR_SEL
#undef HR_FINITE
#undef HR_NONE
#undef HR_NOT
#undef HR_M
