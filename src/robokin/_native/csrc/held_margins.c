/*
 * The existence margins of a held-joint Pieper family's position roots at a held
 * value (pk_one's front end written out): held_manifold.c bisects its branch ends on
 * them, held_closed.c puts its own (the margins' exact roots) where pk_one's rows end.
 */

#define HM_DISC_TWO 1e-15 /* a discriminant / (A^2 + B^2) above it: sp4_roots' two roots */

/* hm_margins_d's parts that do not depend on the held value x where PkFrontMemo's
 * do (the Panda): the position equations' d part (pk_equations_d's), the null
 * combination n, theta_a's subproblem 4 coefficients A, B, hab = hypot(A, B) and
 * their phase (pk_sp4's); computed by hm_margins_d at its first call of a pose and
 * copied after (the same operations on the same values: the same bits; not
 * PkFrontMemo's e and pk_coplanar_x part: the same expressions, inlined into other
 * code, are contracted into FMAs differently, which moved interval ends by up to
 * 2.2e-11). set = 0 empties it; cop: axes b, c coplanar (else only e is kept). */
typedef struct {
    int set, cop;
    PkEq e;
    double n[2], A, B, hab, phi, cphi, sphi;
} HmMargMemo;

/* The existence margins of the position roots at held value x (pk_one's front end
 * and pk_coplanar's two subproblems 4 written out): m[0] = (hypot(A, B) - |C|) /
 * scale of the first angle (its two roots exist where m[0] >= 0), m[1 + i] the same
 * of the second angle given first root i (NaN without it); d (or NULL) the
 * discriminants over A^2 + B^2. A branch is born or dies where one crosses 0. The
 * x-free parts are kept in *memo (HmMargMemo; set = 0 before a pose's first call). Returns 0 when the position
 * equations are not of the coplanar kind (He and Liu's case; the kernel then
 * flags the pose). */
static int hm_margins_pk(const double *P, const double *T, HmMargMemo *memo, double x, double *m,
                         double *d)
{
    PkGeo g;
    pk_geometry(P, x, &g);
    m3 RT = {{T[0], T[1], T[2]}, {T[4], T[5], T[6]}, {T[8], T[9], T[10]}};
    v3 pT = {T[3], T[7], T[11]};
    m3 G = pk_mul_t(&RT, &g.RM);
    HmMargMemo *k = pk_memo_usable(P, &g) ? memo : NULL;
    PkEq e;
    if (k != NULL && k->set) {
        v3 p, pd;
        pk_pose_points(&g, &RT, pT, &G, &p, &pd);
        e = k->e;
        pk_equations_p(&e, p);
    } else {
        pk_pose_equations(&g, &RT, pT, &G, &e);
    }
    int swap;
    if (fabs(e.mbc) <= PK_COPLANAR)
        swap = 0;
    else if (fabs(e.mab) <= PK_COPLANAR)
        swap = 1;
    else
        return 0;
    double n[2], L = e.scale, A, B, hab, phi = 0.0, cphi = 1.0, sphi = 0.0;
    const double(*X)[2] = swap ? e.Q : e.P;
    const double(*Y)[2] = swap ? e.P : e.Q;
    double sx = swap ? -1.0 : 1.0;
    if (k != NULL && k->set && k->cop) {
        n[0] = k->n[0];
        n[1] = k->n[1];
        A = k->A;
        B = k->B;
        hab = k->hab;
        phi = k->phi;
        cphi = k->cphi;
        sphi = k->sphi;
    } else {
        v3 h = swap ? e.ha : e.hc, o = swap ? e.oa : e.oc;
        pk_null(h, e.hb, v3_scale(v3_sub(o, e.ob), 1.0 / L), n);
        A = sx * (n[0] * X[0][0] + n[1] * X[1][0]);
        B = sx * (n[0] * X[0][1] + n[1] * X[1][1]);
        hab = hypot(A, B);
        if (!(hab <= 1e-12 * L)) {
            phi = fast_atan2(B, A);
            unit2(B, A, &cphi, &sphi);
        }
        if (k != NULL && !k->set) { /* kept: x-free (PkFrontMemo's premise) */
            k->e = e;
            k->cop = !swap;
            k->n[0] = n[0];
            k->n[1] = n[1];
            k->A = A;
            k->B = B;
            k->hab = hab;
            k->phi = phi;
            k->cphi = cphi;
            k->sphi = sphi;
            k->set = 1;
        }
    }
    double C = n[0] * e.r[0] + n[1] * e.r[1];
    m[0] = (hab - fabs(C)) / L;
    m[1] = m[2] = NAN;
    if (d != NULL) {
        d[0] = (A * A + B * B - C * C) / (A * A + B * B);
        d[1] = d[2] = NAN;
    }
    if (hab <= 1e-12 * L)
        return 0; /* the first angle free: not this kind */
    Roots rx = pk_sp4_at(A, B, C, PK_SP4_SLACK * L, phi, cphi, sphi);
    double m0 = -n[1], m1 = n[0];
    double Ay = -sx * (m0 * Y[0][0] + m1 * Y[1][0]);
    double By = -sx * (m0 * Y[0][1] + m1 * Y[1][1]);
    double hy = hypot(Ay, By);
    for (int i = 0; i < rx.n && i < 2; i++) {
        double Xu0 = X[0][0] * rx.c[i] + X[0][1] * rx.s[i];
        double Xu1 = X[1][0] * rx.c[i] + X[1][1] * rx.s[i];
        double Cy = m0 * (e.r[0] - sx * Xu0) + m1 * (e.r[1] - sx * Xu1);
        m[1 + i] = (hy - fabs(Cy)) / L;
        if (d != NULL)
            d[1 + i] = (Ay * Ay + By * By - Cy * Cy) / (Ay * Ay + By * By);
    }
    if (rx.n == 1) {
        m[2] = m[1];
        if (d != NULL)
            d[2] = d[1];
    }
    return 1;
}

