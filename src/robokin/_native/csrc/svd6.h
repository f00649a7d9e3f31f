/*
 * The 6 x 6 singular value decomposition of the compiled kernels, one copy:
 * pieper.c (pk_slide, pk_family_dir, pk_gauss_newton) and near_coincident.c use it.
 * Moved here from pieper.c unchanged (issue 23); pieper.c includes it where the
 * function stood, inside its fp-contract=off region, so its code is compiled as
 * before (the include guard keeps that one definition for the files after it).
 */
#ifndef ROBOKIN_SVD6_H
#define ROBOKIN_SVD6_H

#include <math.h>

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
