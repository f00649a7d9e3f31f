/*
 * The 6 x 6 linear algebra of the compiled kernels, one copy: the least-squares
 * step (Householder QR with column pivoting) and the singular value decomposition
 * (one-sided Jacobi). pieper.c (pk_polish_held, pk_slide, pk_family_dir,
 * pk_gauss_newton) and near_coincident.c use them. Moved here from pieper.c
 * (issue 23): pk_svd6 unchanged, pk_lstsq now lstsq6 with its cut as an argument
 * (pk_lstsq calls it with pieper's 1e-10). pieper.c includes this file where
 * pk_lstsq stood, inside its fp-contract=off region, so its code is compiled as
 * before; the include guard keeps that one definition for the files after it.
 */
#ifndef ROBOKIN_LINALG6_H
#define ROBOKIN_LINALG6_H

#include <math.h>

/* The least-squares step J dx = e of a 6 x 6 Jacobian (rows J[r][.]): Householder
 * QR with column pivoting, columns whose pivot falls below `cut` of the first
 * left out (a singular configuration: no step along its near-null directions).
 * Only the first m columns (1..6) take part (dx's others are 0: a chain with
 * joints held, without zero columns, which the norm downdating could pick as
 * pivots before a nearly dependent real one).
 * Returns the rank kept; *ratio (when given) the last kept pivot over the first,
 * |r_kk| / |r_11| (0 for rank 0). With column pivoting sigma_min >= |r_kk| 3 /
 * sqrt(4^k + 6k - 1) and sigma_max <= sqrt(k) |r_11|, so for k <= 6 the kept
 * columns' sigma_min / sigma_max >= ratio / 53: near_coincident.c reads it to
 * know that no singular value is below its SVD cut. */
static int lstsq6(double J[6][6], const double *e, double *dx, double cut, double *ratio,
                  int m)
{
    double A[6][6], b[6], norms[6];
    int perm[6], rank = 0;
    for (int r = 0; r < 6; r++) {
        b[r] = e[r];
        for (int c = 0; c < 6; c++)
            A[r][c] = J[r][c];
    }
    for (int c = 0; c < 6; c++) {
        perm[c] = c;
        norms[c] = 0.0;
    }
    for (int c = 0; c < m; c++) {
        double s = 0.0;
        for (int r = 0; r < 6; r++)
            s += A[r][c] * A[r][c];
        norms[c] = s;
    }
    double first = 0.0, last = 0.0;
    for (int k = 0; k < m; k++) {
        int best = k; /* pivot: the remaining column of largest norm */
        for (int c = k + 1; c < m; c++)
            if (norms[c] > norms[best])
                best = c;
        if (best != k) {
            for (int r = 0; r < 6; r++) {
                double t = A[r][k];
                A[r][k] = A[r][best];
                A[r][best] = t;
            }
            double t = norms[k];
            norms[k] = norms[best];
            norms[best] = t;
            int ti = perm[k];
            perm[k] = perm[best];
            perm[best] = ti;
        }
        double nx = 0.0;
        for (int r = k; r < 6; r++)
            nx += A[r][k] * A[r][k];
        nx = sqrt(nx);
        if (k == 0)
            first = nx;
        if (!(nx > cut * first))
            break;
        double alpha = A[k][k] > 0.0 ? -nx : nx, v[6];
        for (int r = 0; r < 6; r++)
            v[r] = r < k ? 0.0 : A[r][k];
        v[k] -= alpha;
        double vv = 0.0;
        for (int r = k; r < 6; r++)
            vv += v[r] * v[r];
        if (vv > 0.0) {
            for (int c = k; c < m; c++) {
                double d = 0.0;
                for (int r = k; r < 6; r++)
                    d += v[r] * A[r][c];
                d *= 2.0 / vv;
                for (int r = k; r < 6; r++)
                    A[r][c] -= d * v[r];
            }
            double d = 0.0;
            for (int r = k; r < 6; r++)
                d += v[r] * b[r];
            d *= 2.0 / vv;
            for (int r = k; r < 6; r++)
                b[r] -= d * v[r];
        }
        for (int c = k + 1; c < m; c++)
            norms[c] -= A[k][c] * A[k][c];
        rank = k + 1;
        last = nx;
    }
    double y[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    for (int r = rank - 1; r >= 0; r--) {
        double s = b[r];
        for (int c = r + 1; c < rank; c++)
            s -= A[r][c] * y[c];
        y[r] = s / A[r][r];
    }
    for (int c = 0; c < 6; c++)
        dx[perm[c]] = y[c];
    if (ratio != NULL)
        *ratio = rank > 0 ? last / first : 0.0;
    return rank;
}

/* pieper.c's least-squares step: lstsq6 with the cut at 1e-10 */
static void pk_lstsq(double J[6][6], const double *e, double *dx)
{
    lstsq6(J, e, dx, 1e-10, NULL, 6);
}

/* The singular values (ascending) and right singular vectors (columns of V) of a
 * 6 x 6 matrix A (destroyed): one-sided Jacobi (Hestenes), which keeps small
 * singular values accurate relative to the columns (A^T A would square them into
 * rounding). */
static void pk_svd6(double A[6][6], double *sig, double V[6][6])
{
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 6; j++)
            V[i][j] = i == j ? 1.0 : 0.0;
    for (int sweep = 0; sweep < 30; sweep++) {
        int rotated = 0;
        for (int p = 0; p < 5; p++)
            for (int q = p + 1; q < 6; q++) {
                double a = 0.0, b = 0.0, c = 0.0;
                for (int r = 0; r < 6; r++) {
                    a += A[r][p] * A[r][p];
                    b += A[r][q] * A[r][q];
                    c += A[r][p] * A[r][q];
                }
                if (!(fabs(c) > 1e-15 * sqrt(a * b)))
                    continue;
                rotated = 1;
                double z = 0.5 * (b - a) / c;
                double t = copysign(1.0, z) / (fabs(z) + sqrt(z * z + 1.0));
                double cs = 1.0 / sqrt(t * t + 1.0), sn = t * cs;
                for (int r = 0; r < 6; r++) {
                    double x = A[r][p], y = A[r][q];
                    A[r][p] = cs * x - sn * y;
                    A[r][q] = sn * x + cs * y;
                    x = V[r][p];
                    y = V[r][q];
                    V[r][p] = cs * x - sn * y;
                    V[r][q] = sn * x + cs * y;
                }
            }
        if (!rotated)
            break;
    }
    double nrm[6];
    int idx[6] = {0, 1, 2, 3, 4, 5};
    for (int c = 0; c < 6; c++) {
        double sum = 0.0;
        for (int r = 0; r < 6; r++)
            sum += A[r][c] * A[r][c];
        nrm[c] = sqrt(sum);
    }
    for (int i = 1; i < 6; i++)
        for (int j = i; j > 0 && nrm[idx[j]] < nrm[idx[j - 1]]; j--) {
            int t = idx[j];
            idx[j] = idx[j - 1];
            idx[j - 1] = t;
        }
    double Vs[6][6];
    for (int c = 0; c < 6; c++) {
        sig[c] = nrm[idx[c]];
        for (int r = 0; r < 6; r++)
            Vs[r][c] = V[r][idx[c]];
    }
    for (int r = 0; r < 6; r++)
        for (int c = 0; c < 6; c++)
            V[r][c] = Vs[r][c];
}

#endif
