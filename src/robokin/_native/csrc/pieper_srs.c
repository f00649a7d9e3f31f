/*
 * SRS arms (spherical shoulder 1-3, elbow 4, spherical wrist 5-7: the KUKA iiwa
 * type) with any one joint held, for pieper.c (PK_BOTH: both triples of the whole
 * 7R chain meet). The six joints left are not solved as a Pieper chain (their
 * elimination degenerates where the arm does: full stretch, two remaining axes
 * next to coincident) but on the arm's own structure, every step a subproblem:
 *
 *   1. the elbow from the shoulder-wrist distance |w - S| (subproblem 3; a double
 *      root at full stretch), unless the elbow is held;
 *   2. the shoulder's rotation R_A takes the wrist's elbow-frame direction a to
 *      the target's b: R_A(psi) = rot(b, psi) R0, the swivel psi free (Shimizu
 *      et al.'s arm angle), the wrist's rotation R_B = R4^T R_A^T G;
 *   3. the held joint at its value is one equation A cos psi + B sin psi = C in
 *      the swivel (subproblem 4: each joint's value is a fixed angle between two
 *      vectors, one of which turns with psi): up to two swivel angles per elbow;
 *      the triple holding the held joint then has one solution (pk_known), the
 *      other triple two (pk_triple);
 *   4. where the held joint does not move with the swivel (the elbow held, or
 *      e.g. joint 2 held with the wrist point on axis 1) the six joints move in
 *      a one-parameter family: each branch is taken at the swivel angle where it
 *      lies deepest inside the limits, among psi = 0, the angles where any joint
 *      reaches a limit (the same equation, one per joint and limit) and the
 *      midpoints between them, so a branch with an in-limit configuration gets
 *      one.
 *
 * Every row is then checked by forward kinematics of the remaining chain,
 * Newton-polished, and brought inside the limits where it lies on a singular set
 * (pk_finish). Slots: 2 * position + triple with position = 2 * elbow root +
 * swivel root (the held elbow: position = the shoulder's branch) and triple the
 * other triple's branch.
 *
 * References: Shimizu, Kakuya, Yoon, Kitagaki and Kosuge, "Analytical inverse
 * kinematic computation for 7-DOF redundant manipulators with joint limits and
 * its application to redundancy resolution", IEEE T-RO 24(5), 2008; Elias and
 * Wen, "IK-Geo", arXiv:2211.05737 (subproblems).
 */

/* Included by pieper.c, inside its floating-point rules (no fused multiply-adds). */

#define PS_REACH 1e-13 /* a held angle this far [rad] past the end of its swivel range: at the end */
#define PS_REACH_WIDE 1e-8 /* the same when no row came out at PS_REACH (pk_srs) */

static inline m3 ps_transpose(const m3 *A)
{
    return (m3){{A->r0.x, A->r1.x, A->r2.x}, {A->r0.y, A->r1.y, A->r2.y},
                {A->r0.z, A->r1.z, A->r2.z}};
}

/* A unit vector perpendicular to h (h a unit vector) */
static inline v3 ps_perp(v3 h)
{
    v3 e = fabs(h.x) < 0.6 ? (v3){1.0, 0.0, 0.0} : (v3){0.0, 1.0, 0.0};
    e = v3_sub(e, v3_scale(h, v3_dot(e, h)));
    return v3_scale(e, 1.0 / v3_norm(e));
}

/* Angle between unit vectors */
static inline double ps_between(v3 a, v3 b)
{
    return atan2(v3_norm(v3_cross(a, b)), v3_dot(a, b));
}

/* rot(hx, tx) rot(hy, ty) rot(hz, tz) = R with one angle known (`which` 0, 1, 2:
 * tx, ty, tz = t): the other two into out (out[which] = t). With the middle angle
 * known and the outer axes in line (singular) only their sum is fixed: the split
 * is taken inside the limits (pk_split), nearest pref_z; next to that the exact
 * split is moved inside the limits where the pose cost stays below rounding
 * (as pk_triple). *sing: the outer axes (next to) in line. */
static void pk_known(const double *P, const PkTri *k, const m3 *R, int which, double t,
                     int jx, int jz, double pref_z, double stol, double *out,
                     unsigned char *sing)
{
    v3 hx = k->hx, hy = k->hy, hz = k->hz;
    double c, s;
    out[which] = t;
    if (which == 1) {
        double cy = cos(t), sy = sin(t);
        v3 v = v3_rot(hy, cy, sy, hz), w = m3_mv(R, hz);
        double sv = v3_norm(v3_cross(v, hx)), sigma = v3_dot(v, hx) >= 0.0 ? 1.0 : -1.0;
        *sing = (unsigned char)(sv < 1e-7);
        if (sv < stol) {
            m3 Ry = pk_rotm(hy, cy, sy);
            m3 X = pk_mul_t(R, &Ry); /* R rot(hy, -t) = rot(hx, phi) */
            v3 e = ps_perp(hx);
            double phi = pk_sp1(hx, e, m3_mv(&X, e), &c, &s);
            double tz = pk_split(P, jx, jz, phi, sigma, pref_z);
            out[0] = phi - sigma * tz;
            out[2] = tz;
            return;
        }
        double tx = pk_sp1(hx, v, w, &c, &s);
        v3 u = v3_rot(hy, cy, -sy, hx);
        double tz = -pk_sp1(hz, u, m3_mtv(R, hx), &c, &s);
        if (sv < 1e-6) { /* next to singular: the split costs sv per radian */
            double qz = P[PK_SIGN + jz] * (tz - P[PK_OFFSET + jz]);
            double eps = wrap_pi(pk_split(P, jx, jz, tx + sigma * tz, sigma, qz) - tz);
            if (fabs(eps) * sv <= 0.01 * PK_EXACT) {
                tx -= sigma * eps;
                tz += eps;
            }
        }
        out[0] = tx;
        out[2] = tz;
        return;
    }
    if (which == 0) {
        m3 Rx = pk_rotm(hx, cos(t), sin(t)), RxT = ps_transpose(&Rx);
        m3 Rp = pk_mul(&RxT, R); /* rot(hy, ty) rot(hz, tz) */
        double ty = pk_sp1(hy, hz, m3_mv(&Rp, hz), &c, &s);
        m3 Ry = pk_rotm(hy, c, -s), Z = pk_mul(&Ry, &Rp); /* rot(hz, tz) */
        v3 e = ps_perp(hz);
        out[1] = ty;
        out[2] = pk_sp1(hz, e, m3_mv(&Z, e), &c, &s);
        *sing = (unsigned char)(v3_norm(v3_cross(m3_mv(&Rp, hz), hx)) < 1e-7);
        return;
    }
    m3 Rz = pk_rotm(hz, cos(t), sin(t)), Rp = pk_mul_t(R, &Rz); /* rot(hx, tx) rot(hy, ty) */
    double ty = -pk_sp1(hy, hx, m3_mtv(&Rp, hx), &c, &s);
    m3 Ry = pk_rotm(hy, cos(ty), sin(ty)), X = pk_mul_t(&Rp, &Ry); /* rot(hx, tx) */
    v3 e = ps_perp(hx);
    out[0] = pk_sp1(hx, e, m3_mv(&X, e), &c, &s);
    out[1] = ty;
    *sing = (unsigned char)(v3_norm(v3_cross(m3_mtv(&Rp, hx), hz)) < 1e-7);
}

/* The arm at one elbow angle: the swivel family's constants */
typedef struct {
    v3 h[7], u;
    m3 R0, R0R4, G, R4T;
    double reach; /* ps_roots' slack past the range ends: PS_REACH (PS_REACH_WIDE in pk_srs's retry) */
} PsArm;

/* Joint j (0-2 shoulder, 4-6 wrist) at chain angle L as one condition on the
 * swivel: the angle between hv and rot(u, t) pv equals alpha, t = sg psi (sg +1
 * shoulder, -1 wrist). Each joint's angle is fixed by the angle between two
 * vectors, one of which turns with the swivel: the triple's middle, hx and R hz
 * (alpha: that of hx and rot(hy, L) hz); its first, rot(hx, L) hy and R hz (alpha:
 * that of hy and hz); its last, hx and R rot(hz, -L) hy (alpha: hx and hy). With
 * R = R_A = rot(u, psi) R0 or R_B = R4^T R0^T rot(u, -psi) G. */
static void ps_vectors(const PsArm *a, int j, double L, v3 *hv, v3 *pv, double *alpha,
                       double *sg)
{
    int o3 = j < 3 ? 0 : 4, jj = j - o3;
    v3 hx = a->h[o3], hy = a->h[o3 + 1], hz = a->h[o3 + 2];
    double cL = cos(L), sL = sin(L);
    if (jj == 1) {
        *hv = hx;
        *pv = hz;
        *alpha = ps_between(hx, v3_rot(hy, cL, sL, hz));
    } else if (jj == 0) {
        *hv = v3_rot(hx, cL, sL, hy);
        *pv = hz;
        *alpha = ps_between(hy, hz);
    } else {
        *hv = hx;
        *pv = v3_rot(hz, cL, -sL, hy);
        *alpha = ps_between(hx, hy);
    }
    if (j < 3) {
        *pv = m3_mv(&a->R0, *pv);
        *sg = 1.0;
    } else {
        *hv = m3_mv(&a->R0R4, *hv);
        *pv = m3_mv(&a->G, *pv);
        *sg = -1.0;
    }
}

/* The angle between hv and rot(u, t) pv (unit vectors) and its derivative in t,
 * from their cross and dot products (accurate near 0 and pi, where the dot
 * product alone loses half the digits). *s2: the squared sine. */
static double ps_angle(v3 hv, v3 u, v3 pv, double t, double *d, double *s2)
{
    double c = cos(t), s = sin(t);
    v3 p = v3_rot(u, c, s, pv), dp = v3_cross(u, p);
    v3 v = v3_cross(hv, p), dv = v3_cross(hv, dp);
    double sn = v3_norm(v), w = v3_dot(hv, p), dw = v3_dot(hv, dp);
    double dsn = sn > 0.0 ? v3_dot(v, dv) / sn : v3_norm(dv);
    *d = (w * dsn - sn * dw) / (sn * sn + w * w);
    *s2 = sn * sn;
    return atan2(sn, w);
}

/* Newton on ps_angle(t) = alpha from t (steps kept while they reduce the error) */
static double ps_angle_newton(v3 hv, v3 u, v3 pv, double alpha, double t)
{
    double d, s2, f = ps_angle(hv, u, pv, t, &d, &s2) - alpha;
    for (int it = 0; it < 8 && f != 0.0 && d != 0.0; it++) {
        double step = f / d;
        if (fabs(step) > 0.25)
            step = copysign(0.25, step);
        double d2, f2 = ps_angle(hv, u, pv, t - step, &d2, &s2) - alpha;
        if (!(fabs(f2) < fabs(f)))
            break;
        t -= step;
        f = f2;
        d = d2;
    }
    return t;
}

/* The swivel angles t = sg psi (up to 2, *n) where joint j is at chain angle L:
 * where the angle between hv and rot(u, t) pv (ps_vectors) equals alpha. The
 * turning vector sweeps a cone about u: with gh, gp the angles of hv, pv to u and
 * t0 the turn that brings pv's azimuth onto hv's, the spherical law of cosines in
 * haversine form, hav(alpha) = hav(gh - gp) + sin gh sin gp hav(t - t0), gives
 * t = t0 +- D from products of sines of half-angles, so that angles next to 0 or
 * pi (two remaining axes next to coincident, the arm next to full stretch) keep
 * every digit (a cosine alone loses half of them); Newton-polished on the angle.
 * *dbl: a double root or two within 1e-7 rad (alpha at an end of the range, or
 * past it by at most a->reach: rounding, a pose error that small); *flat:
 * the whole range within 1e-13 rad of alpha (the joint does not move with the
 * swivel: a family). */
static void ps_roots(const PsArm *a, int j, double L, double *t, int *n, int *dbl, int *flat,
                     double *sg)
{
    v3 hv, pv, u = a->u;
    double alpha;
    ps_vectors(a, j, L, &hv, &pv, &alpha, sg);
    double gh = ps_between(hv, u), gp = ps_between(pv, u);
    v3 hp = v3_sub(hv, v3_scale(u, v3_dot(u, hv))), pp = v3_sub(pv, v3_scale(u, v3_dot(u, pv)));
    double t0 = atan2(v3_dot(u, v3_cross(pp, hp)), v3_dot(pp, hp));
    double amin = fabs(gh - gp), amax = M_PI - fabs(M_PI - gh - gp);
    *n = 0;
    *dbl = 0;
    *flat = amax - amin <= 2e-13 && fabs(alpha - 0.5 * (amin + amax)) <= 1e-13;
#ifdef PK_DEBUG
    fprintf(stderr, " roots j %d alpha %.9e range %.9e %.9e gh %.3e gp %.3e\n", j, alpha, amin, amax, gh, gp);
#endif
    if (*flat || alpha < amin - a->reach || alpha > amax + a->reach)
        return;
    double k = sin(gh) * sin(gp);
    double hav = sin(0.5 * (alpha - gh + gp)) * sin(0.5 * (alpha + gh - gp)) / k;
    hav = alpha <= amin ? 0.0 : alpha >= amax ? 1.0 : fmax(0.0, fmin(1.0, hav));
    double D = 2.0 * atan2(sqrt(hav), sqrt(1.0 - hav));
    t[(*n)++] = ps_angle_newton(hv, u, pv, alpha, t0 + D);
    *dbl = D < 1e-7 || M_PI - D < 1e-7;
    if (D == 0.0 || D == M_PI)
        return;
    t[(*n)++] = ps_angle_newton(hv, u, pv, alpha, t0 - D);
}

/* Swivel angles where joint j reaches chain angle L, appended to psi[*n] */
static void ps_limit_roots(const PsArm *a, int j, double L, double *psi, int *n)
{
    double t[2], sg;
    int m, dbl, flat;
    ps_roots(a, j, L, t, &m, &dbl, &flat, &sg);
    for (int i = 0; i < m; i++)
        psi[(*n)++] = wrap_pi(sg * t[i]);
}

/* The rotations of the two triples at swivel angle psi */
static void ps_rotations(const PsArm *a, double psi, m3 *RA, m3 *RB)
{
    m3 Ru = pk_rotm(a->u, cos(psi), sin(psi));
    *RA = pk_mul(&Ru, &a->R0);
    m3 RAt = ps_transpose(RA), X = pk_mul(&RAt, &a->G);
    *RB = pk_mul(&a->R4T, &X);
}

/* Up to 4 configurations (th: 7 chain angles) at swivel angle psi and elbow th4:
 * the held joint's triple by pk_known (held in 0-2 or 4-6), the other by
 * pk_triple; held elbow (3): both by pk_triple. Each with its branch index (the
 * other triple's, or 2 * shoulder + wrist for the held elbow) and singular flag. */
static int ps_configs(const double *P, const PsArm *a, const PkTri *ta, const PkTri *tb,
                      double psi, double th4, int held, double tk, const double *qn,
                      double th[4][7], int *branch, unsigned char *sing)
{
    m3 RA, RB;
    ps_rotations(a, psi, &RA, &RB);
    double stol = P[PK_SING_TOL];
    PkTrip A, B;
    double known[3];
    unsigned char ks = 0;
    if (held == 3 || held > 3)
        pk_triple(P, ta, &RA, 0, 2, qn[2], stol, &A);
    if (held <= 3)
        pk_triple(P, tb, &RB, 4, 6, qn[6], stol, &B);
    if (held < 3)
        pk_known(P, ta, &RA, held, tk, 0, 2, qn[2], stol, known, &ks);
    else if (held > 3)
        pk_known(P, tb, &RB, held - 4, tk, 4, 6, qn[6], stol, known, &ks);
    int m = 0;
    int na = held < 3 ? 1 : A.n, nb = held > 3 ? 1 : B.n;
    for (int ka = 0; ka < na; ka++)
        for (int kb = 0; kb < nb; kb++) {
            for (int j = 0; j < 3; j++) {
                th[m][j] = held < 3 ? known[j] : A.t[ka][j];
                th[m][4 + j] = held > 3 ? known[j] : B.t[kb][j];
            }
            th[m][3] = th4;
            branch[m] = held == 3 ? 2 * ka + kb : held < 3 ? kb : ka;
            sing[m] = (unsigned char)((held < 3 ? ks : A.sing[ka]) ||
                                      (held > 3 ? ks : B.sing[kb]));
            m++;
        }
    return m;
}

/* A configuration (7 chain angles, the held one at its value) into slot: checked
 * by forward kinematics of the remaining chain, Newton-polished when not exact,
 * dropped above PK_ACCEPT; outside the limits it is brought in where it lies on a
 * singular set (pk_repair, pk_inside, pk_slide). Returns 1 when stored. */
static int ps_finish(const double *P, const PkGeo *g, const m3 *RT, v3 pT, const double *th7,
                     int held, double x, int sing, int slot, PkOut o)
{
    double th[6];
    for (int j = 0, r = 0; j < 7; j++)
        if (j != held)
            th[r++] = th7[j];
    double err = pk_error_of(g, RT, pT, th);
    if (err > PK_EXACT)
        err = pk_polish_slow(g, RT, pT, th, pk_polish(g, RT, pT, th));
#ifdef PK_DEBUG
    fprintf(stderr, "  finish slot %d err %.3e th %.12g %.12g %.12g %.12g %.12g %.12g\n", slot, err, th[0], th[1], th[2], th[3], th[4], th[5]);
#endif
    if (!(err <= PK_ACCEPT))
        return 0;
    double *qs = o.Q + o.n * slot;
    int all = pk_coords(P, g, th, held, x, qs) >= -1e-9, fix = pk_held_inside(P, held, x);
    if (fix && !all && sing && pk_repair(P, g, RT, pT, th))
        all = pk_coords(P, g, th, held, x, qs) >= -1e-9;
    if (fix && !all && pk_inside(P, g, RT, pT, th, sing ? PK_NUDGE_SING : PK_NUDGE))
        all = pk_coords(P, g, th, held, x, qs) >= -1e-9;
    if (fix && !all && pk_slide(P, g, RT, pT, th))
        all = pk_coords(P, g, th, held, x, qs) >= -1e-9;
    o.valid[slot] = 1;
    o.inside[slot] = (unsigned char)all;
    o.sing[slot] = (unsigned char)sing;
    return 1;
}

/* The elbow: its chain angles for the shoulder-wrist distance (subproblem 3) and,
 * next to full stretch or full fold (a double root), the band of angles where
 * that distance holds to rounding: |t - center| within [inner, outer]. */
typedef struct {
    int n, dbl;
    double t[2], center, inner, outer;
} PsElbow;

/* The elbow's roots and band for shoulder-wrist distance rho; 0 when out of reach */
static int ps_elbow(const double *P, v3 S, v3 Wp, double rho, double scale, PsElbow *e)
{
    v3 h4 = v3_at(P, PK_AXES + 9), o4 = v3_at(P, PK_POINTS + 9);
    v3 d = v3_sub(o4, S), f = v3_sub(Wp, o4);
    double A, B, C;
    sp4_coeffs(d, h4, f, &A, &B, &C);
    double rhs = 0.5 * (rho * rho - v3_dot(d, d) - v3_dot(f, f)) - C;
    double eps = PK_SP4_SLACK * scale * scale, r = hypot(A, B);
    Roots rt = pk_sp4(A, B, rhs, eps);
    e->n = rt.n;
    e->dbl = rt.boundary;
    for (int i = 0; i < rt.n; i++)
        e->t[i] = rt.t[i];
    double m = fabs(rhs);
    e->center = atan2(B, A) + (rhs < 0.0 ? M_PI : 0.0);
    e->inner = r > 0.0 ? acos(fmax(-1.0, fmin(1.0, (m + eps) / r))) : 0.0;
    e->outer = r > 0.0 ? acos(fmax(-1.0, fmin(1.0, (m - eps) / r))) : 0.0;
    return rt.n > 0;
}

/* The swivel's constants at elbow angle th4 (a: the wrist point's direction from
 * the shoulder after the elbow, b: the target's); 0 when the wrist point sits on
 * the shoulder (a two-parameter family: not solved). */
static int ps_arm(const double *P, v3 S, v3 Wp, v3 w, const m3 *G, double th4, double scale,
                  PsArm *a)
{
    for (int j = 0; j < 7; j++)
        a->h[j] = v3_at(P, PK_AXES + 3 * j);
    v3 o4 = v3_at(P, PK_POINTS + 9);
    double c4 = cos(th4), s4 = sin(th4);
    v3 av = v3_sub(v3_add(o4, v3_rot(a->h[3], c4, s4, v3_sub(Wp, o4))), S);
    v3 bv = v3_sub(w, S);
    double la = v3_norm(av), lb = v3_norm(bv);
    if (la < 1e-12 * scale || lb < 1e-12 * scale)
        return 0;
    av = v3_scale(av, 1.0 / la);
    bv = v3_scale(bv, 1.0 / lb);
    v3 ax = v3_cross(av, bv);
    double sn = v3_norm(ax), cs = v3_dot(av, bv);
    if (sn > 1e-12) {
        a->R0 = pk_rotm(v3_scale(ax, 1.0 / sn), cs, sn);
    } else if (cs > 0.0) {
        a->R0 = (m3){{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
    } else {
        a->R0 = pk_rotm(ps_perp(av), -1.0, 0.0);
    }
    a->u = bv;
    m3 R4 = pk_rotm(a->h[3], c4, s4);
    a->R0R4 = pk_mul(&a->R0, &R4);
    a->R4T = ps_transpose(&R4);
    a->G = *G;
    a->reach = PS_REACH;
    return 1;
}

/* The cone angles of the held joint's swivel condition (ps_roots) at elbow angle
 * th4: gm, that of the vector which moves with the elbow (pv for a shoulder joint,
 * hv for a wrist joint), and gd, that of the other; over the swivel the angle
 * sweeps [|gm - gd|, min(gm + gd, 2 pi - gm - gd)]. 0 when ps_arm fails. */
static int ps_cones(const double *P, v3 S, v3 Wp, v3 w, const m3 *G, int held, double L,
                    double th4, double scale, double *gm, double *gd, double *alpha)
{
    PsArm a;
    if (!ps_arm(P, S, Wp, w, G, th4, scale, &a))
        return 0;
    v3 hv, pv;
    double sg;
    ps_vectors(&a, held, L, &hv, &pv, alpha, &sg);
    double gh = ps_between(hv, a.u), gp = ps_between(pv, a.u);
    *gm = held < 3 ? gp : gh;
    *gd = held < 3 ? gh : gp;
    return 1;
}

/* Next to full stretch the shoulder-wrist distance fixes the elbow only to its
 * band (PsElbow), while the held joint's angle range over the swivel moves with
 * the elbow to first order: when the range at th4 misses the held value, the
 * elbow angle on side `side` (+1 / -1) of the band's center where the range just
 * reaches it (bisection on the cone angle gm, which grows away from the center).
 * Returns 0 when the band holds none. */
static int ps_band_elbow(const double *P, v3 S, v3 Wp, v3 w, const m3 *G, int held, double L,
                         const PsElbow *e, int side, double th4, double scale, double *out)
{
    double gm, gd, alpha;
    if (!ps_cones(P, S, Wp, w, G, held, L, th4, scale, &gm, &gd, &alpha))
        return 0;
    double lo = fabs(alpha - gd), hi = fmin(alpha + gd, 2.0 * M_PI - alpha - gd), target;
    if (gm < lo)
        target = lo;
    else if (gm > hi)
        target = hi;
    else
        return 0;
    double a = e->center + side * e->inner, b = e->center + side * e->outer, ga, gb;
    if (!ps_cones(P, S, Wp, w, G, held, L, a, scale, &ga, &gd, &alpha) ||
        !ps_cones(P, S, Wp, w, G, held, L, b, scale, &gb, &gd, &alpha) ||
        (ga - target) * (gb - target) > 0.0)
        return 0;
    for (int it = 0; it < 80; it++) {
        double m = 0.5 * (a + b), gmid;
        if (!ps_cones(P, S, Wp, w, G, held, L, m, scale, &gmid, &gd, &alpha))
            return 0;
        if ((gmid - target) * (ga - target) > 0.0) {
            a = m;
            ga = gmid;
        } else {
            b = m;
            gb = gmid;
        }
    }
    int a_ok = target == lo ? ga >= target : ga <= target; /* the end on the feasible side */
    *out = a_ok ? a : b;
    return 1;
}

/* The smallest elbow deviation f in [0, outer] from the band's center (side +1 /
 * -1) at which the held joint's angle range over the swivel reaches its value
 * (at f = 0, full stretch, the range shrinks to a point): bisection on whether
 * the range holds it. Returns 0 when it holds it at f = 0 or never. */
static int ps_touch(const double *P, v3 S, v3 Wp, v3 w, const m3 *G, int held, double L,
                    const PsElbow *e, int side, double scale, double *out)
{
    double a = 0.0, b = e->outer;
    for (int it = 0; it < 64; it++) {
        double f = it == 0 ? a : it == 1 ? b : 0.5 * (a + b), gm, gd, alpha;
        if (!ps_cones(P, S, Wp, w, G, held, L, e->center + side * f, scale, &gm, &gd, &alpha))
            return 0;
        double lo = fabs(alpha - gd), hi = fmin(alpha + gd, 2.0 * M_PI - alpha - gd);
        int ok = gm >= lo && gm <= hi;
        if (it == 0 && ok)
            return 0;
        if (it == 1 && !ok)
            return 0;
        if (it >= 2) {
            if (ok)
                b = f;
            else
                a = f;
        }
    }
    *out = b;
    return 1;
}

/* Swivel candidates of a one-parameter family: 0, where each free joint reaches a
 * limit, and the midpoints between them around the circle. Returns the count. */
static int ps_candidates(const double *P, const PsArm *a, int held, double *psi)
{
    int np = 0;
    psi[np++] = 0.0;
    for (int j = 0; j < 7; j++) {
        if (j == 3 || j == held)
            continue;
        for (int side = 0; side < 2; side++)
            ps_limit_roots(a, j, P[PK_SIGN + j] * P[(side ? PK_HI : PK_LO) + j] +
                                     P[PK_OFFSET + j], psi, &np);
    }
    for (int i = 1; i < np; i++)
        for (int j = i; j > 0 && psi[j] < psi[j - 1]; j--) {
            double t = psi[j];
            psi[j] = psi[j - 1];
            psi[j - 1] = t;
        }
    int nb = np;
    for (int i = 0; i < nb; i++) {
        double nxt = i + 1 < nb ? psi[i + 1] : psi[0] + 2.0 * M_PI;
        psi[np++] = 0.5 * (psi[i] + nxt);
    }
    return np;
}

/* The best configuration offered for each slot: the largest limit margin */
typedef struct {
    double th[7], margin;
    int have;
    unsigned char sing;
} PsBest;

static void ps_offer(const double *P, const PkGeo *g, int held, double x, const double *th7,
                     int slot, int sing, PsBest *best)
{
    double th6[6], q[PK_MAXJ];
    for (int j = 0, r = 0; j < 7; j++)
        if (j != held)
            th6[r++] = th7[j];
    double mg = pk_coords(P, g, th6, held, x, q);
    PsBest *b = best + slot;
    if (!b->have || mg > b->margin) {
        b->have = 1;
        b->margin = mg;
        b->sing = (unsigned char)sing;
        for (int j = 0; j < 7; j++)
            b->th[j] = th7[j];
    }
}

/* Every configuration at elbow angle th4 (elbow slot i4; the arm a) offered to
 * best: at the held joint's swivel roots (slot 4 i4 + 2 root + branch), or,
 * where the held joint does not move with the swivel (always for the held
 * elbow), at every candidate swivel angle of the family (slot 4 i4 + branch;
 * held elbow: 2 shoulder + wrist branch), each then flagged singular. */
static void ps_at_elbow(const double *P, const PkGeo *g, const PsArm *a, const PkTri *ta,
                        const PkTri *tb, int held, double tk, double x, const double *qn,
                        double th4, int i4, int sing, PsBest *best)
{
    double tr[2], sg, th[4][7], psi[64];
    int nr = 0, dblr = 0, flat = held == 3, br[4];
    unsigned char sgl[4];
    if (!flat)
        ps_roots(a, held, tk, tr, &nr, &dblr, &flat, &sg);
    if (flat) {
        int np = ps_candidates(P, a, held, psi);
        for (int i = 0; i < np; i++) {
            int m = ps_configs(P, a, ta, tb, psi[i], th4, held, tk, qn, th, br, sgl);
            for (int c = 0; c < m; c++)
                ps_offer(P, g, held, x, th[c], held == 3 ? br[c] : 4 * i4 + br[c], 1, best);
        }
        return;
    }
    for (int ip = 0; ip < nr; ip++) {
        int m = ps_configs(P, a, ta, tb, sg * tr[ip], th4, held, tk, qn, th, br, sgl);
        for (int c = 0; c < m; c++)
            ps_offer(P, g, held, x, th[c], 4 * i4 + 2 * ip + br[c], sgl[c] || sing || dblr,
                     best);
    }
}

/* Next to full stretch every elbow angle in the distance's rounding band
 * (PsElbow) reaches the wrist point, and the rest of the arm moves with it to
 * first order: a one-parameter family. When no row so far lies inside the
 * limits, each side of the band (slots 0-3: +, 4-7: -) is searched at its ends,
 * its center and 14 points between, and a slot's best replaces a row outside the
 * limits. */
static void ps_band_family(const double *P, const PkGeo *g, const m3 *RT, v3 pT, v3 S,
                           v3 Wp, v3 w, const m3 *G, const PsElbow *el, const PkTri *ta,
                           const PkTri *tb, int held, double tk, double x, const double *qn,
                           PkOut o)
{
    double scale = g->scale;
    for (int i4 = 0; i4 < 2; i4++) {
        double side = i4 ? -1.0 : 1.0;
        PsBest best[8];
        for (int k = 0; k < 8; k++)
            best[k].have = 0;
        double ft = 0.0;
        int touch = ps_touch(P, S, Wp, w, G, held, tk, el, (int)side, scale, &ft) &&
                    ft > 0.0 && ft < el->outer;
#ifdef PK_DEBUG
        fprintf(stderr, " band side %g center %.3e inner %.3e outer %.3e touch %d ft %.3e\n", side, el->center, el->inner, el->outer, touch, ft);
#endif
        for (int k = -1; k <= 15 + 17 * touch; k++) {
            double f = k < 0    ? 0.0
                       : k < 16 ? el->inner + (el->outer - el->inner) * k / 15.0
                                : ft * pow(el->outer / ft, (k - 16) / 16.0);
            if (k < 0 && el->inner > 0.0)
                continue; /* the center is in the band only when the ends touch */
            double th4 = el->center + side * f;
            PsArm a;
            if (ps_arm(P, S, Wp, w, G, th4, scale, &a))
                ps_at_elbow(P, g, &a, ta, tb, held, tk, x, qn, th4, i4, 1, best);
        }
        for (int slot = 4 * i4; slot < 4 * i4 + 4; slot++)
            if (best[slot].have && !(o.valid[slot] && o.inside[slot]))
                ps_finish(P, g, RT, pT, best[slot].th, held, x, 1, slot, o);
    }
}

/* Every solution of an SRS arm with joint `held` at x (the module comment), the
 * held joint's swivel roots taken up to `reach` past the ends of its range.
 * Where none came out at PS_REACH, again at PS_REACH_WIDE: the held value at an
 * end of its range (a double root, e.g. the shoulder's middle joint held at 0:
 * axes 1 and 3 in line) is missed by rounding when the elbow, next to stretched,
 * carries errors ~ 1e-16 / sin(elbow) into the cone angles (1.9e-13 rad past the
 * end at q4 = -2.9e-3); the rows found are polished and checked as any other. */
static int pk_srs_reach(const double *P, const PkGeo *g, const m3 *RT, v3 pT, double x,
                        const double *qn, double reach, PkOut o)
{
    int held = (int)P[PK_HELD];
    double scale = g->scale;
    v3 S = v3_at(P, PK_POINT), Wp = v3_at(P, PK_POINT2), tM = v3_at(P, PK_TOOL_T);
    m3 RM = {v3_at(P, PK_TOOL_R), v3_at(P, PK_TOOL_R + 3), v3_at(P, PK_TOOL_R + 6)};
    m3 G = pk_mul_t(RT, &RM); /* the rotation of e1 ... e7 */
    v3 w = v3_add(pT, m3_mv(&G, v3_sub(Wp, tM)));
    double tk = P[PK_SIGN + held] * x + P[PK_OFFSET + held];
    double rho = v3_norm(v3_sub(w, S));
    PsElbow el = {0, 0, {0.0, 0.0}, 0.0, 0.0, 0.0};
    if (held == 3) {
        v3 o4 = v3_at(P, PK_POINTS + 9), h4 = v3_at(P, PK_AXES + 9);
        v3 W4 = v3_add(o4, v3_rot(h4, cos(tk), sin(tk), v3_sub(Wp, o4)));
        if (fabs(v3_norm(v3_sub(W4, S)) - rho) > 1e-9 * fmax(1.0, scale))
            return PK_OUT_OF_REACH;
        el.n = 1;
        el.t[0] = tk;
    } else if (!ps_elbow(P, S, Wp, rho, scale, &el)) {
        return PK_OUT_OF_REACH;
    }
    PkTri ta, tb;
    v3 h[7];
    for (int j = 0; j < 7; j++)
        h[j] = v3_at(P, PK_AXES + 3 * j);
    pk_tri_init(&ta, h[0], h[1], h[2]);
    pk_tri_init(&tb, h[4], h[5], h[6]);
    /* elbow candidates: the roots; a double root stands for both sides of its band
     * (slots 0-3 and 4-7) when the held joint needs the band (ps_band_elbow) */
    int ne = el.n, side[2] = {1, -1}, degenerate = 0;
    double te[2] = {el.t[0], el.t[1]};
    if (el.n == 1 && held != 3) {
        ne = 2;
        te[1] = el.t[0];
    }
    PsBest best[8];
    for (int k = 0; k < 8; k++)
        best[k].have = 0;
    for (int i4 = 0; i4 < ne; i4++) {
        double th4 = te[i4], tr[2], sg, tb4;
        PsArm a;
        if (!ps_arm(P, S, Wp, w, &G, th4, scale, &a)) {
            degenerate = 1;
            continue;
        }
        a.reach = reach;
        int nr = 0, dblr = 0, flat = held == 3;
        if (!flat)
            ps_roots(&a, held, tk, tr, &nr, &dblr, &flat, &sg);
        if (!nr && !flat && el.outer < 1e-3 &&
            ps_band_elbow(P, S, Wp, w, &G, held, tk, &el, side[i4], th4, scale, &tb4) &&
            ps_arm(P, S, Wp, w, &G, tb4, scale, &a)) {
            th4 = tb4;
        } else if (ne > el.n && i4 == 1) {
            continue; /* the double root itself served: no second side */
        }
        ps_at_elbow(P, g, &a, &ta, &tb, held, tk, x, qn, th4, i4, el.dbl, best);
    }
    for (int slot = 0; slot < 8; slot++)
        if (best[slot].have)
            ps_finish(P, g, RT, pT, best[slot].th, held, x, best[slot].sing, slot, o);
    int inside = 0;
    for (int slot = 0; slot < 8; slot++)
        inside |= o.valid[slot] && o.inside[slot];
    if (!inside && held != 3 && el.outer < 1e-3)
        ps_band_family(P, g, RT, pT, S, Wp, w, &G, &el, &ta, &tb, held, tk, x, qn, o);
    pk_walk_rows(P, g, RT, pT, held, x, o, 8);
    for (int slot = 0; slot < 8; slot++)
        if (o.valid[slot])
            return PK_OK;
    return degenerate ? PK_DEGENERATE : PK_NO_ORIENTATION;
}

/* Every solution of an SRS arm with joint `held` at x: pk_srs_reach at PS_REACH,
 * and again at PS_REACH_WIDE when that gave no row (not for the held elbow, whose
 * swivel is a family: no held joint's roots to widen). */
static int pk_srs(const double *P, const PkGeo *g, const m3 *RT, v3 pT, double x,
                  const double *qn, PkOut o)
{
    int code = pk_srs_reach(P, g, RT, pT, x, qn, PS_REACH, o);
    if (code == PK_NO_ORIENTATION && (int)P[PK_HELD] != 3) {
        pk_clear(o);
        code = pk_srs_reach(P, g, RT, pT, x, qn, PS_REACH_WIDE, o);
    }
    return code;
}
