/*
 * Brent's method, one copy for the held-joint kernels' branch ends (held_manifold.c's
 * discriminant margins, held_closed.c's E2 margin), and the Illinois bracket update
 * their safeguarded Newton / regula falsi refinements share.
 */
#ifndef ROBOKIN_BRENT_H
#define ROBOKIN_BRENT_H

#include <math.h>

/* A root of f(ctx, t) in (a, e), fa and fe its values there of opposite signs:
 * inverse quadratic / secant steps safeguarded by bisection until the bracket is
 * 1e-15 (relative to max(1, |t|)) wide or a value is 0; NaN when a value is not
 * finite (or after 100 steps). */
static double brent_root(double (*f)(void *, double), void *ctx, double a, double fa,
                         double e, double fe)
{
    double c = a, fc = fa, d = e - a, g = d;
    for (int it = 0; it < 100; it++) {
        if ((fe > 0) == (fc > 0)) {
            c = a;
            fc = fa;
            d = g = e - a;
        }
        if (fabs(fc) < fabs(fe)) {
            a = e;
            e = c;
            c = a;
            fa = fe;
            fe = fc;
            fc = fa;
        }
        double tol = 0.5e-15 * fmax(1.0, fabs(e)), mid = 0.5 * (c - e);
        if (fabs(mid) <= tol || fe == 0.0)
            return e;
        if (fabs(g) >= tol && fabs(fa) > fabs(fe)) {
            double s = fe / fa, p, q;
            if (a == c) {
                p = 2.0 * mid * s;
                q = 1.0 - s;
            } else {
                double r = fe / fc, u = fa / fc;
                p = s * (2.0 * mid * u * (u - r) - (e - a) * (r - 1.0));
                q = (u - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if (p > 0.0)
                q = -q;
            else
                p = -p;
            if (2.0 * p < fmin(3.0 * mid * q - fabs(tol * q), fabs(g * q))) {
                g = d;
                d = p / q;
            } else {
                d = mid;
                g = d;
            }
        } else {
            d = mid;
            g = d;
        }
        a = e;
        fa = fe;
        e += fabs(d) > tol ? d : copysign(tol, mid);
        fe = f(ctx, e);
        if (!isfinite(fe))
            return NAN;
    }
    return NAN;
}

/* Illinois' bracket update: x, with value f, replaces the end of [*lo, *hi] whose
 * value (*flo, *fhi) has f's sign; when that end moved the time before too (*side:
 * -1 lo, 1 hi, 0 neither yet) the other end's value is halved, so a stale end cannot
 * hold regula falsi's steps to one side. */
static inline void illinois_update(double x, double f, double *lo, double *flo, double *hi,
                                   double *fhi, int *side)
{
    if ((f < 0.0) == (*flo < 0.0)) {
        *lo = x;
        *flo = f;
        if (*side == -1)
            *fhi *= 0.5;
        *side = -1;
    } else {
        *hi = x;
        *fhi = f;
        if (*side == 1)
            *flo *= 0.5;
        *side = 1;
    }
}

#endif /* ROBOKIN_BRENT_H */
