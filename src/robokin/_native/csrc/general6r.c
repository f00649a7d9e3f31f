/*
 * Every IK solution of a general 6R chain: Raghavan-Roth elimination, one pose
 * at a time (a batch runs on the thread pool), each root polished by Newton steps
 * on the true chain (chain.h) and kept only when it reproduces the pose.
 *
 * Loop closure of the canonical chain T = C_0 Rz(v_1) C_1 ... Rz(v_6) C_6:
 *
 *   J_1 K_1 J_2 K_2 ... J_6 K_6 = I,   J_k = Rz(v_k),  K_k = C_k (k < 6),
 *   K_6 = C_6 T^-1 C_0.
 *
 * For a split a in {1, 2, 3} the left side J_a K_a J_{a+1} K_{a+1} J_{a+2} K_{a+2}
 * equals the inverse of the rest; both sides applied to e_z (l) and to the origin
 * (p) give the 14 equations f(l, p) = [l, p, l.p, p.p, l x p, (p.p) l - 2 (l.p) p]
 * (Raghavan & Roth 1993, eq. 10-13). The left side times (1 + x_b^2)(1 + x_c^2),
 * x = tan(theta / 2) of the joints a+1 (b), a+2 (c), is linear in the 27 monomials
 * {s_a, c_a, 1} (x) {x_b^i x_c^j, i, j <= 2}: P(theta_a) = s P_s + c P_c + P_1
 * (14 x 9 each), fitted once per arm in robokin.kinematics.ik.analytic.general_6r
 * from rows this file computes (general6r_fit_rows). The right side does not
 * depend on joint a+3 and is linear in the 9 monomials of joints a+4 (u), a+5 (w)
 * [s_u s_w, s_u c_w, c_u s_w, c_u c_w, s_u, c_u, s_w, c_w, 1]: per pose, from 9
 * evaluations on the grid {0, 2pi/3, 4pi/3}^2 (Q, 14 x 9). The left null space of
 * Q's first 8 columns (Householder QR) eliminates u and w: 6 equations in the 9
 * monomials of (x_b, x_c); multiplied by x_b (or x_c, "mult") they form the 12 x 12
 * dialytic matrix Sigma(theta_a), entries linear in (s_a, c_a, 1) (Manocha & Canny
 * 1994, section 4). det Sigma(theta_a) is a trigonometric polynomial of degree 8:
 * sampled at 24 angles, its DFT gives it (the part above degree 8, the "tail",
 * must vanish), and its real roots are those of the degree-16 polynomial in
 * x = tan((theta_a - phi) / 2) (phi + pi the sample of largest |D|): the roots the
 * samples bracket by safeguarded Newton steps, deflated, then the eigenvalues of
 * the deflated polynomial's balanced companion matrix (Francis double-shift QR as
 * in EISPACK hqr). Roots with a small imaginary part are tried too. Each root: the
 * null vector of Sigma (pivoted QR) gives x_b, x_c; least squares on Q's block
 * gives u, w; joint a+3 follows from the orientation. Where two roots are close or
 * complex (two solutions nearly sharing theta_a) both solutions also come from the
 * span of Sigma's two smallest singular vectors (a 2 x 2 pencil). Newton steps on
 * the true chain polish every candidate; a candidate whose error stops falling is
 * spurious and dropped, and so is one that does not reproduce the pose to 1e-9.
 *
 * An arm is solved by a variant: the split a, the chain or its reversal (the IK
 * of T^-1 on C_6^-1 Rz(-v_6) ... Rz(-v_1) C_0^-1) and the multiplier. The Python
 * set-up picks a primary and a secondary one; the secondary runs for a pose when
 * the primary's determinant is degenerate or one of its roots has a null space of
 * dimension two (two solutions sharing theta_a, e.g. a wrist flip), and the
 * solutions of both are merged.
 *
 * References:
 *   Raghavan, M. and Roth, B. "Inverse kinematics of the general 6R manipulator
 *   and related linkages", J. Mech. Design 115(3), 1993.
 *   Manocha, D. and Canny, J. "Efficient inverse kinematics for general 6R
 *   manipulators", IEEE Trans. Robotics and Automation 10(5), 1994.
 *   Smith, B. T. et al. "Matrix Eigensystem Routines - EISPACK Guide", 1976
 *   (balanc, hqr). Golub, G. and Van Loan, C. "Matrix Computations", 4th ed.,
 *   5.2 (Householder QR), 5.4.2 (column pivoting).
 *
 * Its entries and constants are declared in ../_declare.py (GENERAL6R); g6_init
 * fills the tables at module init.
 */
#include <float.h>
#include <string.h>

#include "chain.h"
#include "pool.h"

#define G6_MAXSOL 16   /* solutions per pose: the 6R problem's degree */
#define G6_MAXROOT 16  /* roots of one variant's polynomial */
#define G6_NSAMP 24    /* samples of det Sigma */
#define G6_DEG 8       /* its trigonometric degree */
#define G6_MAXDEG 32   /* polynomials general6r_roots takes */
#define G6_GRAIN 8     /* poses per pool chunk */
#define G6_PARALLEL_MIN 32

/* params: a header, then G6_NVAR variant blocks (robokin's general_6r packs it) */
enum { GP_NVAR = 0 /* variants: 1 (primary) or 2 (+ secondary) */,
       GP_TAIL_TOL = 1 /* largest relative DFT tail above degree 8 */,
       GP_NULL_TOL = 2 /* second-smallest / largest pivot of Sigma: 2-D null space */,
       GP_IMAG_TOL = 3 /* imaginary part of theta_a accepted as real */,
       GP_TOL = 4 /* position [m] and rotation [rad] error of a solution */,
       GP_DEDUPE = 5 /* solutions closer than this [rad] are one */,
       GP_MAX_ITER = 6 /* Newton iterations */,
       GP_PAIR_GAP = 7 /* [rad] roots closer than this: both solutions from a 2-D null space */,
       GP_HEAD = 8 };
/* variant block: direction (0 the chain, 1 its reversal), split a, multiplier
 * (0 x_b, 1 x_c), the direction's constants C'_0..C'_6 and their inverses (4x4
 * row-major), the fitted P_s, P_c, P_1 (14 x 9 row-major each) */
enum { VB_DIR = 0, VB_A = 1, VB_MULT = 2, VB_C = 4, VB_CI = VB_C + 7 * 16,
       VB_P = VB_CI + 7 * 16, VB_SIZE = VB_P + 3 * 14 * 9 };
/* per pose status */
enum { G6_OK = 0, G6_NONE = 1 /* no real solution */,
       G6_DEGENERATE = 2 /* no solution and the elimination was degenerate */,
       G6_BAD_POSE = 3 /* a non-finite pose */ };
/* per pose diagnostics (bit flags) */
enum { G6F_DEGENERATE = 1, G6F_AMBIGUOUS = 2, G6F_SECONDARY = 4, G6F_SEC_DEGENERATE = 8,
       G6F_SEC_AMBIGUOUS = 16 };
#define G6_DIAG_CAND_SHIFT 8 /* diag >> 8: the roots back-substituted (polish candidates) */

/* tables filled once at module init (general6r_constants) */
static double g6_xgi[9][9];          /* inverse of the u, w grid's monomial matrix */
static double g6_er[17][17], g6_ei[17][17]; /* (1 + ix)^m (1 - ix)^(16-m): x^j coefficients */
static double g6_cs[G6_NSAMP], g6_sn[G6_NSAMP]; /* cos, sin of 2 pi k / 24 */

static const double G6_TWO_PI = 6.283185307179586476925;
static const double G6_PI = 3.141592653589793238463;

/* ---------------------------------------------------------- small helpers */

static void mul4(const double *A, const double *B, double *C) /* C = A B, affine 4x4 */
{
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 4; c++)
            C[4 * r + c] = A[4 * r] * B[c] + A[4 * r + 1] * B[4 + c] + A[4 * r + 2] * B[8 + c];
        C[4 * r + 3] += A[4 * r + 3];
    }
    C[12] = C[13] = C[14] = 0.0;
    C[15] = 1.0;
}

static void rigid_inv(const double *T, double *Ti) /* [R t]^-1 = [R^T, -R^T t] */
{
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++)
            Ti[4 * r + c] = T[4 * c + r];
        Ti[4 * r + 3] = -(T[r] * T[3] + T[4 + r] * T[7] + T[8 + r] * T[11]);
    }
    Ti[12] = Ti[13] = Ti[14] = 0.0;
    Ti[15] = 1.0;
}

/* the 14 equations f(l, p) (Raghavan & Roth 1993, eq. 10-13) */
static void g6_equations(const double *l, const double *p, double *f)
{
    double lp = l[0] * p[0] + l[1] * p[1] + l[2] * p[2];
    double pp = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    f[0] = l[0]; f[1] = l[1]; f[2] = l[2];
    f[3] = p[0]; f[4] = p[1]; f[5] = p[2];
    f[6] = lp;
    f[7] = pp;
    f[8] = l[1] * p[2] - l[2] * p[1];
    f[9] = l[2] * p[0] - l[0] * p[2];
    f[10] = l[0] * p[1] - l[1] * p[0];
    for (int i = 0; i < 3; i++)
        f[11 + i] = pp * l[i] - 2.0 * lp * p[i];
}

static void g6_init_tables(void)
{
    /* grid monomials are a permutation of kron(F(u), F(w)), F = [s, c, 1] at
     * 0, 2pi/3, 4pi/3, whose inverse is the discrete Fourier one */
    static const int perm[3][3] = {{0, 1, 4}, {2, 3, 5}, {6, 7, 8}}; /* [iu][iw] -> m */
    double Fi[3][3];
    for (int g = 0; g < 3; g++) {
        double t = G6_TWO_PI * g / 3.0;
        Fi[0][g] = 2.0 / 3.0 * sin(t);
        Fi[1][g] = 2.0 / 3.0 * cos(t);
        Fi[2][g] = 1.0 / 3.0;
    }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            for (int gu = 0; gu < 3; gu++)
                for (int gw = 0; gw < 3; gw++)
                    g6_xgi[perm[i][j]][3 * gu + gw] = Fi[i][gu] * Fi[j][gw];
    for (int m = 0; m <= 16; m++) {
        double pr[17] = {1.0}, pi[17] = {0.0};
        int deg = 0;
        for (int f = 0; f < 16; f++) { /* multiply by (1 + s i x), s = +1 (f < m) or -1 */
            double s = f < m ? 1.0 : -1.0;
            for (int j = deg + 1; j >= 1; j--) {
                /* (a + b i) * (s i) = -s b + s a i */
                double ar = pr[j] - s * pi[j - 1], ai = pi[j] + s * pr[j - 1];
                pr[j] = ar;
                pi[j] = ai;
            }
            deg++;
        }
        for (int j = 0; j <= 16; j++) {
            g6_er[m][j] = pr[j];
            g6_ei[m][j] = pi[j];
        }
    }
    for (int k = 0; k < G6_NSAMP; k++) {
        g6_cs[k] = cos(G6_TWO_PI * k / G6_NSAMP);
        g6_sn[k] = sin(G6_TWO_PI * k / G6_NSAMP);
    }
}

/* ------------------------------------------------------------ linear algebra */

/* Householder QR of the m x n (m >= n) matrix A, column-major (A[j * m + i]): R in
 * the upper triangle; reflector k is I - beta[k] v_k v_k^T with v_k = V[k * m ..]. */
static void house_qr(double *A, int m, int n, double *V, double *beta)
{
    for (int k = 0; k < n; k++) {
        double *a = A + k * m, *v = V + k * m;
        double nrm = 0.0;
        for (int i = k; i < m; i++)
            nrm += a[i] * a[i];
        nrm = sqrt(nrm);
        for (int i = 0; i < m; i++)
            v[i] = 0.0;
        if (nrm == 0.0) {
            beta[k] = 0.0;
            continue;
        }
        double alpha = a[k] > 0.0 ? -nrm : nrm;
        v[k] = a[k] - alpha;
        double vv = v[k] * v[k];
        for (int i = k + 1; i < m; i++) {
            v[i] = a[i];
            vv += v[i] * v[i];
        }
        beta[k] = 2.0 / vv;
        a[k] = alpha;
        for (int i = k + 1; i < m; i++)
            a[i] = 0.0;
        for (int j = k + 1; j < n; j++) {
            double *c = A + j * m, s = 0.0;
            for (int i = k; i < m; i++)
                s += v[i] * c[i];
            s *= beta[k];
            for (int i = k; i < m; i++)
                c[i] -= s * v[i];
        }
    }
}

/* x <- Q^T x for the reflectors of house_qr (x of length m) */
static void house_apply_t(const double *V, const double *beta, int m, int n, double *x)
{
    for (int k = 0; k < n; k++) {
        const double *v = V + k * m;
        double s = 0.0;
        for (int i = k; i < m; i++)
            s += v[i] * x[i];
        s *= beta[k];
        for (int i = k; i < m; i++)
            x[i] -= s * v[i];
    }
}

/* det Sigma(theta_k) = det(s_k S[0] + c_k S[1] + S[2]) (12 x 12 row-major) for the W
 * sample angles k0 .. k0 + W - 1, one per lane: LU with partial pivoting (each lane
 * its own pivots) */
static void det12_lanes(const double (*S)[144], int k0, double *out)
{
    vd sv, cv, A[144];
    for (int l = 0; l < W; l++) {
        sv[l] = g6_sn[k0 + l];
        cv[l] = g6_cs[k0 + l];
    }
    for (int i = 0; i < 144; i++)
        A[i] = sv * S[0][i] + cv * S[1][i] + S[2][i];
    vd d = BR(1.0);
    for (int k = 0; k < 12; k++) {
        vd best = vabs(A[12 * k + k]);
        vl piv = BRL(k);
        for (int i = k + 1; i < 12; i++) {
            vd x = vabs(A[12 * i + k]);
            vl m = x > best;
            best = vsel(m, x, best);
            piv = (piv & ~m) | (BRL(i) & m);
        }
        for (int i = k + 1; i < 12; i++) {
            vl m = piv == BRL(i);
            if (!vany(m))
                continue;
            for (int j = k; j < 12; j++) {
                vd t = A[12 * k + j];
                A[12 * k + j] = vsel(m, A[12 * i + j], t);
                A[12 * i + j] = vsel(m, t, A[12 * i + j]);
            }
            d = vsel(m, -d, d);
        }
        vd p = A[12 * k + k];
        vl zero = p == BR(0.0);
        d = vsel(zero, BR(0.0), d * p);
        vd inv = BR(1.0) / vsel(zero, BR(1.0), p);
        for (int i = k + 1; i < 12; i++) {
            vd f = A[12 * i + k] * inv;
            for (int j = k + 1; j < 12; j++)
                A[12 * i + j] -= f * A[12 * k + j];
        }
    }
    for (int l = 0; l < W; l++)
        out[k0 + l] = d[l];
}

/* Null vectors of Sigma(theta_l) = s_l S[0] + c_l S[1] + S[2] (12 x 12 row-major),
 * one angle per lane, by Householder QR with column pivoting of Sigma^T:
 * Sigma^T P = U R, the null vector y = U e_12 (|Sigma y| = |r_12|) and y2 = U e_11,
 * the next (with y, the null space where two singular values are small); r:
 * |diagonal of R|, non-increasing (Golub & Van Loan 5.4.2, downdated column norms). */
static void null_vector12_lanes(const double (*S)[144], vd sv, vd cv, vd *y, vd *y2, vd *r)
{
    vd A[144], V[11][12], beta[11], n2[12], n2ref[12];
    /* column j of A = Sigma^T is row j of Sigma: A[12 j + i] */
    for (int i = 0; i < 144; i++)
        A[i] = sv * S[0][i] + cv * S[1][i] + S[2][i];
    for (int j = 0; j < 12; j++) {
        vd t = BR(0.0);
        for (int i = 0; i < 12; i++)
            t += A[12 * j + i] * A[12 * j + i];
        n2[j] = n2ref[j] = t;
    }
    for (int k = 0; k < 12; k++) {
        vd best = n2[k];
        vl piv = BRL(k);
        for (int j = k + 1; j < 12; j++) {
            vl m = n2[j] > best;
            best = vsel(m, n2[j], best);
            piv = (piv & ~m) | (BRL(j) & m);
        }
        for (int j = k + 1; j < 12; j++) {
            vl m = piv == BRL(j);
            if (!vany(m))
                continue;
            for (int i = 0; i < 12; i++) {
                vd t = A[12 * k + i];
                A[12 * k + i] = vsel(m, A[12 * j + i], t);
                A[12 * j + i] = vsel(m, t, A[12 * j + i]);
            }
            vd t = n2[k];
            n2[k] = vsel(m, n2[j], t);
            n2[j] = vsel(m, t, n2[j]);
            t = n2ref[k];
            n2ref[k] = vsel(m, n2ref[j], t);
            n2ref[j] = vsel(m, t, n2ref[j]);
        }
        vd nrm = BR(0.0); /* exactly: the downdated norms only choose the pivot */
        for (int i = k; i < 12; i++)
            nrm += A[12 * k + i] * A[12 * k + i];
        nrm = vsqrt(nrm);
        r[k] = nrm;
        if (k == 11)
            break;
        vd *a = A + 12 * k, *v = V[k];
        vd alpha = vsel(a[k] > BR(0.0), -nrm, nrm);
        for (int i = 0; i < k; i++)
            v[i] = BR(0.0);
        v[k] = a[k] - alpha;
        vd vv = v[k] * v[k];
        for (int i = k + 1; i < 12; i++) {
            v[i] = a[i];
            vv += v[i] * v[i];
        }
        vl zero = nrm == BR(0.0);
        beta[k] = vsel(zero, BR(0.0), BR(2.0) / vsel(zero, BR(1.0), vv));
        for (int j = k + 1; j < 12; j++) {
            vd *c = A + 12 * j, t = BR(0.0);
            for (int i = k; i < 12; i++)
                t += v[i] * c[i];
            t *= beta[k];
            for (int i = k; i < 12; i++)
                c[i] -= t * v[i];
            n2[j] -= c[k] * c[k];
            vl redo = n2[j] <= 1e-6 * n2ref[j]; /* cancellation: recompute */
            if (vany(redo)) {
                vd u = BR(0.0);
                for (int i = k + 1; i < 12; i++)
                    u += c[i] * c[i];
                n2[j] = vsel(redo, u, n2[j]);
                n2ref[j] = vsel(redo, u, n2ref[j]);
            }
        }
    }
    for (int i = 0; i < 12; i++) {
        y[i] = BR(i == 11 ? 1.0 : 0.0);
        y2[i] = BR(i == 10 ? 1.0 : 0.0);
    }
    for (int k = 10; k >= 0; k--) {
        vd t = BR(0.0), t2 = BR(0.0);
        for (int i = k; i < 12; i++) {
            t += V[k][i] * y[i];
            t2 += V[k][i] * y2[i];
        }
        t *= beta[k];
        t2 *= beta[k];
        for (int i = k; i < 12; i++) {
            y[i] -= t * V[k][i];
            y2[i] -= t2 * V[k][i];
        }
    }
}

/* Solve the n x n row-major A x = b (both destroyed; x in b) by LU with partial
 * pivoting; 0 when a pivot is exactly zero. */
static int solve_dense(double *A, double *b, int n)
{
    for (int k = 0; k < n; k++) {
        int p = k;
        double best = fabs(A[n * k + k]);
        for (int i = k + 1; i < n; i++)
            if (fabs(A[n * i + k]) > best) {
                best = fabs(A[n * i + k]);
                p = i;
            }
        if (best == 0.0)
            return 0;
        if (p != k) {
            for (int j = 0; j < n; j++) {
                double t = A[n * k + j];
                A[n * k + j] = A[n * p + j];
                A[n * p + j] = t;
            }
            double t = b[k];
            b[k] = b[p];
            b[p] = t;
        }
        double inv = 1.0 / A[n * k + k];
        for (int i = k + 1; i < n; i++) {
            double f = A[n * i + k] * inv;
            for (int j = k + 1; j < n; j++)
                A[n * i + j] -= f * A[n * k + j];
            b[i] -= f * b[k];
        }
    }
    for (int k = n - 1; k >= 0; k--) {
        double s = b[k];
        for (int j = k + 1; j < n; j++)
            s -= A[n * k + j] * b[j];
        b[k] = s / A[n * k + k];
    }
    return 1;
}

/* ------------------------------------------------------- polynomial roots */

/* Balance the n x n row-major matrix A by powers of 2 (EISPACK balanc, scaling
 * only): rows and columns of similar norm make the eigenvalues better conditioned. */
static void balance(double *A, int n)
{
    const double radix = 2.0, sqrdx = 4.0;
    int done = 0;
    for (int sweep = 0; !done && sweep < 100; sweep++) {
        done = 1;
        for (int i = 0; i < n; i++) {
            double c = 0.0, r = 0.0;
            for (int j = 0; j < n; j++)
                if (j != i) {
                    c += fabs(A[n * j + i]);
                    r += fabs(A[n * i + j]);
                }
            if (c == 0.0 || r == 0.0)
                continue;
            double g = r / radix, f = 1.0, s = c + r;
            while (c < g) {
                f *= radix;
                c *= sqrdx;
            }
            g = r * radix;
            while (c > g) {
                f /= radix;
                c /= sqrdx;
            }
            if ((c + r) / f < 0.95 * s) {
                done = 0;
                g = 1.0 / f;
                for (int j = 0; j < n; j++)
                    A[n * i + j] *= g;
                for (int j = 0; j < n; j++)
                    A[n * j + i] *= f;
            }
        }
    }
}

/* Eigenvalues (wr + i wi) of the n x n upper Hessenberg row-major A (destroyed)
 * by the Francis double-shift QR iteration without vectors (EISPACK hqr), with
 * exceptional shifts every 10 iterations alternating between the bottom and the
 * top of the active block as LAPACK dlahqr does (an even polynomial with double
 * roots stalls EISPACK's two). Returns 0 when an eigenvalue needs more than
 * HQR_MAX_ITS iterations. */
#define HQR_MAX_ITS 200
static int hqr(double *A, int n, double *wr, double *wi)
{
#define H(i, j) A[n * (i) + (j)]
    double anorm = 0.0, t = 0.0;
    for (int i = 0; i < n; i++)
        for (int j = i > 0 ? i - 1 : 0; j < n; j++)
            anorm += fabs(H(i, j));
    int nn = n - 1;
    while (nn >= 0) {
        int its = 0, l;
        for (;;) {
            /* look for a small subdiagonal element */
            for (l = nn; l >= 1; l--) {
                double s = fabs(H(l - 1, l - 1)) + fabs(H(l, l));
                if (s == 0.0)
                    s = anorm;
                if (fabs(H(l, l - 1)) <= DBL_EPSILON * s) {
                    H(l, l - 1) = 0.0;
                    break;
                }
            }
            double x = H(nn, nn);
            if (l == nn) { /* one root */
                wr[nn] = x + t;
                wi[nn] = 0.0;
                nn--;
                break;
            }
            double y = H(nn - 1, nn - 1), w = H(nn, nn - 1) * H(nn - 1, nn);
            if (l == nn - 1) { /* two roots */
                double p = 0.5 * (y - x), q = p * p + w, z = sqrt(fabs(q));
                x += t;
                if (q >= 0.0) {
                    z = p + (p >= 0.0 ? z : -z);
                    wr[nn - 1] = wr[nn] = x + z;
                    if (z != 0.0)
                        wr[nn] = x - w / z;
                    wi[nn - 1] = wi[nn] = 0.0;
                } else {
                    wr[nn - 1] = wr[nn] = x + p;
                    wi[nn - 1] = z;
                    wi[nn] = -z;
                }
                nn -= 2;
                break;
            }
            if (its == HQR_MAX_ITS)
                return 0;
            if (its > 0 && its % 20 == 0) { /* exceptional shift from the bottom */
                t += x;
                for (int i = 0; i <= nn; i++)
                    H(i, i) -= x;
                double s = fabs(H(nn, nn - 1)) + fabs(H(nn - 1, nn - 2));
                y = x = 0.75 * s;
                w = -0.4375 * s * s;
            } else if (its % 20 == 10) { /* from the top (LAPACK dlahqr alternates) */
                double s = fabs(H(l + 1, l)) + fabs(H(l + 2, l + 1));
                y = x = 0.75 * s + H(l, l);
                w = -0.4375 * s * s;
            }
            its++;
            /* two consecutive small subdiagonal elements: where the bulge starts */
            int m;
            double p = 0.0, q = 0.0, r = 0.0, z = 0.0;
            for (m = nn - 2; m >= l; m--) {
                z = H(m, m);
                r = x - z;
                double s = y - z;
                p = (r * s - w) / H(m + 1, m) + H(m, m + 1);
                q = H(m + 1, m + 1) - z - r - s;
                r = H(m + 2, m + 1);
                s = 1.0 / (fabs(p) + fabs(q) + fabs(r));
                p *= s;
                q *= s;
                r *= s;
                if (m == l)
                    break;
                double u = fabs(H(m, m - 1)) * (fabs(q) + fabs(r));
                double v = fabs(p) * (fabs(H(m - 1, m - 1)) + fabs(z) + fabs(H(m + 1, m + 1)));
                if (u <= DBL_EPSILON * v)
                    break;
            }
            for (int i = m + 2; i <= nn; i++) {
                H(i, i - 2) = 0.0;
                if (i != m + 2)
                    H(i, i - 3) = 0.0;
            }
            /* double QR step on rows l..nn, columns m..nn */
            for (int k = m; k <= nn - 1; k++) {
                if (k != m) {
                    p = H(k, k - 1);
                    q = H(k + 1, k - 1);
                    r = k != nn - 1 ? H(k + 2, k - 1) : 0.0;
                    x = fabs(p) + fabs(q) + fabs(r);
                    if (x != 0.0) {
                        double ix = 1.0 / x;
                        p *= ix;
                        q *= ix;
                        r *= ix;
                    }
                }
                double s = sqrt(p * p + q * q + r * r);
                if (p < 0.0)
                    s = -s;
                if (s == 0.0)
                    continue;
                if (k == m) {
                    if (l != m)
                        H(k, k - 1) = -H(k, k - 1);
                } else {
                    H(k, k - 1) = -s * x;
                }
                p += s;
                double is = 1.0 / s, ip = 1.0 / p;
                x = p * is;
                y = q * is;
                z = r * is;
                q *= ip;
                r *= ip;
                for (int j = k; j <= nn; j++) { /* rows */
                    p = H(k, j) + q * H(k + 1, j);
                    if (k != nn - 1) {
                        p += r * H(k + 2, j);
                        H(k + 2, j) -= p * z;
                    }
                    H(k + 1, j) -= p * y;
                    H(k, j) -= p * x;
                }
                int mmin = nn < k + 3 ? nn : k + 3;
                for (int i = l; i <= mmin; i++) { /* columns */
                    p = x * H(i, k) + y * H(i, k + 1);
                    if (k != nn - 1) {
                        p += z * H(i, k + 2);
                        H(i, k + 2) -= p * r;
                    }
                    H(i, k + 1) -= p * q;
                    H(i, k) -= p;
                }
            }
        }
    }
    return 1;
#undef H
}

/* Roots of c[0] + c[1] x + ... + c[deg] x^deg (c[deg] != 0, deg <= G6_MAXDEG):
 * eigenvalues of the balanced companion matrix. Returns 0 when hqr fails. */
static int poly_roots(const double *c, int deg, double *wr, double *wi)
{
    double A[G6_MAXDEG * G6_MAXDEG];
    memset(A, 0, sizeof(double) * deg * deg);
    for (int k = 0; k < deg; k++)
        A[k] = -c[deg - 1 - k] / c[deg];
    for (int i = 1; i < deg; i++)
        A[deg * i + i - 1] = 1.0;
    balance(A, deg);
    return hqr(A, deg, wr, wi);
}

/* p(x) and p'(x) of c[0] + ... + c[deg] x^deg (Horner) */
static double poly_eval(const double *c, int deg, double x, double *dp)
{
    double p = c[deg], d = 0.0;
    for (int j = deg - 1; j >= 0; j--) {
        d = d * x + p;
        p = p * x + c[j];
    }
    *dp = d;
    return p;
}

/* The root of c in [a, b] where p(a), p(b) have opposite signs: Newton steps kept
 * inside the shrinking bracket, bisection where they leave it. */
static double bracketed_root(const double *c, int deg, double a, double b, double pa)
{
    double x = 0.5 * (a + b);
    for (int it = 0; it < 100; it++) {
        double d, p = poly_eval(c, deg, x, &d);
        if (p == 0.0)
            return x;
        if ((p < 0.0) == (pa < 0.0))
            a = x, pa = p;
        else
            b = x;
        double xn = d != 0.0 ? x - p / d : 0.5 * (a + b);
        if (!(xn > fmin(a, b) && xn < fmax(a, b)))
            xn = 0.5 * (a + b);
        if (fabs(xn - x) <= 4.0 * DBL_EPSILON * fabs(x) || fabs(b - a) <= 4.0 * DBL_EPSILON * fabs(x))
            return xn;
        x = xn;
    }
    return x;
}

/* Divide c (degree deg) by (x - r) in place (degree deg - 1): composite deflation,
 * the forward recurrence for the high coefficients and the backward one for the
 * low ones, joined at the dominant term of p(r) (Peters & Wilkinson 1971). */
static void deflate(double *c, int deg, double r)
{
    double qf[G6_MAXDEG], qb[G6_MAXDEG];
    qf[deg - 1] = c[deg];
    for (int j = deg - 1; j >= 1; j--)
        qf[j - 1] = c[j] + r * qf[j];
    int split = 0; /* q_j from the forward recurrence for j >= split */
    if (r != 0.0) {
        double best = -1.0, rp = 1.0;
        for (int j = 0; j <= deg; j++) {
            double t = fabs(c[j]) * rp;
            if (t > best) {
                best = t;
                split = j;
            }
            rp *= fabs(r);
        }
        if (split > deg - 1)
            split = deg - 1;
        qb[0] = -c[0] / r;
        for (int j = 1; j < split; j++)
            qb[j] = (qb[j - 1] - c[j]) / r;
    }
    for (int j = 0; j < deg; j++)
        c[j] = j < split ? qb[j] : qf[j];
    c[deg] = 0.0;
}

/* All 16 roots (wr + i wi) of the degree-16 polynomial c in x = tan((theta - phi)/2)
 * from the sampled determinant (phi + pi = sample jbest): the real roots the 24
 * sample points bracket (a sign change of p between neighbouring samples) by
 * safeguarded Newton steps, deflated; the rest as the eigenvalues of the deflated
 * polynomial's balanced companion matrix (hqr), a smaller matrix for every root
 * already found. Returns 0 when hqr fails. */
static int all_roots16(const double *c, int jbest, double *wr, double *wi)
{
    double xs[G6_NSAMP], ps[G6_NSAMP], d, work[17];
    for (int m = 1; m < G6_NSAMP; m++) { /* sample jbest + m, x increasing with m */
        xs[m] = tan(0.5 * (G6_TWO_PI * m / G6_NSAMP - G6_PI));
        ps[m] = poly_eval(c, 16, xs[m], &d);
    }
    memcpy(work, c, sizeof(work));
    int nf = 0, deg = 16;
    for (int m = 1; m < G6_NSAMP && deg > 1; m++) {
        double r;
        if (ps[m] == 0.0)
            r = xs[m];
        else if (m + 1 < G6_NSAMP && ps[m + 1] != 0.0 && (ps[m] < 0.0) != (ps[m + 1] < 0.0))
            r = bracketed_root(c, 16, xs[m], xs[m + 1], ps[m]);
        else
            continue;
        wr[nf] = r;
        wi[nf] = 0.0;
        nf++;
        deflate(work, deg, r);
        deg--;
    }
    return poly_roots(work, deg, wr + nf, wi + nf);
}

/* -------------------------------------------------------- the elimination */

typedef struct {
    double v[6]; /* chain values, original joint order */
    int slow;    /* from a close pair: Newton may converge only linearly there */
} G6Cand;

/* The inverse of K_k (1-based k) in the direction's loop for the pose Tp. */
static const double *g6_kinv(const double *vb, int k, const double *k6inv)
{
    return k == 6 ? k6inv : vb + VB_CI + 16 * k;
}

static int g6_idx(int k) /* 1-based joint index modulo 6 */
{
    return (k - 1) % 6 + 1;
}

/* Q (14 x 9 row-major): the right side's coefficients in the monomials of (u, w) */
static void g6_right(const double *vb, int a, const double *k6inv, double *Q)
{
    const double *A = g6_kinv(vb, g6_idx(a + 5), k6inv);
    const double *B = g6_kinv(vb, g6_idx(a + 4), k6inv);
    const double *Cm = g6_kinv(vb, g6_idx(a + 3), k6inv);
    double Y[9][14];
    double cz[3] = {Cm[2], Cm[6], Cm[10]}, ct[3] = {Cm[3], Cm[7], Cm[11]};
    for (int iu = 0; iu < 3; iu++) {
        double cu = g6_cs[8 * iu], su = g6_sn[8 * iu]; /* 2 pi iu / 3 */
        /* Rz(-u) = [[c, s], [-s, c]] */
        double l1[3] = {cu * cz[0] + su * cz[1], -su * cz[0] + cu * cz[1], cz[2]};
        double p1[3] = {cu * ct[0] + su * ct[1], -su * ct[0] + cu * ct[1], ct[2]};
        double l2[3], p2[3];
        for (int r = 0; r < 3; r++) {
            l2[r] = B[4 * r] * l1[0] + B[4 * r + 1] * l1[1] + B[4 * r + 2] * l1[2];
            p2[r] = B[4 * r] * p1[0] + B[4 * r + 1] * p1[1] + B[4 * r + 2] * p1[2] + B[4 * r + 3];
        }
        for (int iw = 0; iw < 3; iw++) {
            double cw = g6_cs[8 * iw], sw = g6_sn[8 * iw];
            double l3[3] = {cw * l2[0] + sw * l2[1], -sw * l2[0] + cw * l2[1], l2[2]};
            double p3[3] = {cw * p2[0] + sw * p2[1], -sw * p2[0] + cw * p2[1], p2[2]};
            double l[3], p[3];
            for (int r = 0; r < 3; r++) {
                l[r] = A[4 * r] * l3[0] + A[4 * r + 1] * l3[1] + A[4 * r + 2] * l3[2];
                p[r] = A[4 * r] * p3[0] + A[4 * r + 1] * p3[1] + A[4 * r + 2] * p3[2] + A[4 * r + 3];
            }
            g6_equations(l, p, Y[3 * iu + iw]);
        }
    }
    for (int e = 0; e < 14; e++)
        for (int m = 0; m < 9; m++) {
            double s = 0.0;
            for (int g = 0; g < 9; g++)
                s += g6_xgi[m][g] * Y[g][e];
            Q[9 * e + m] = s;
        }
}

/* x_b, x_c monomial (i, j) -> column of Sigma for the multiplier, row block h
 * (0: as is, 1: multiplied) */
static int g6_col(int mult, int h, int i, int j)
{
    return mult == 0 ? 3 * (i + h) + j : 4 * i + j + h;
}

/* The angle t with (den, num) ~ (cos t/2, sin t/2) over all pairs of the null
 * vector: the principal axis of the pairs (robust to x = tan(t/2) = inf). */
static double g6_half_angle(const double *y, int mult, int along_b)
{
    double sdd = 0.0, snn = 0.0, sdn = 0.0;
    int ni = mult == 0 ? 4 : 3, nj = mult == 0 ? 3 : 4;
    for (int i = 0; i < ni; i++)
        for (int j = 0; j < nj; j++) {
            int i2 = i + (along_b ? 1 : 0), j2 = j + (along_b ? 0 : 1);
            if (i2 >= ni || j2 >= nj)
                continue;
            double d = y[nj * i + j], u = y[nj * i2 + j2];
            sdd += d * d;
            snn += u * u;
            sdn += d * u;
        }
    return atan2(2.0 * sdn, sdd - snn);
}

/* Rotation part of C'_0 Rz(v_1) C'_1 ... over joints [from, to) (1-based, with the
 * constant after each), starting with constant C'_{from - 1} when with_head. */
static void g6_rot_span(const double *vb, const double *v, int first_const, int j0, int j1,
                        double *R)
{
    const double *C = vb + VB_C + 16 * first_const;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            R[3 * r + c] = C[4 * r + c];
    for (int k = j0; k < j1; k++) { /* R <- R Rz(v_k) rot(C'_k) */
        double c = cos(v[k - 1]), s = sin(v[k - 1]);
        for (int r = 0; r < 3; r++) {
            double x0 = R[3 * r], x1 = R[3 * r + 1];
            R[3 * r] = c * x0 + s * x1;
            R[3 * r + 1] = -s * x0 + c * x1;
        }
        const double *K = vb + VB_C + 16 * k;
        double tmp[9];
        for (int r = 0; r < 3; r++)
            for (int cc = 0; cc < 3; cc++)
                tmp[3 * r + cc] = R[3 * r] * K[cc] + R[3 * r + 1] * K[4 + cc] + R[3 * r + 2] * K[8 + cc];
        memcpy(R, tmp, sizeof(tmp));
    }
}

/* Two solutions (t_b, t_c) in the span of y, y2 (Sigma's two smallest singular
 * vectors at a root two solutions (nearly) share): the combinations c with the
 * monomial structure, shift(c) = tan(t/2) c along b or c, from the 2 x 2 pencil
 * the shifted rows make (the eigenvector structure of a multiple root, Manocha &
 * Canny 1994, section 5.2), along the direction where the two differ more.
 * Returns how many (1 or 2) went to tb, tc. */
static int g6_two_solutions(const double *y, const double *y2, int mult, double *tb,
                            double *tc)
{
    int ni = mult == 0 ? 4 : 3, nj = mult == 0 ? 3 : 4;
    double best_sep = -1.0, psi_best[2] = {0.0, 0.0}, A0b[4] = {0}, A1b[4] = {0};
    for (int along_b = 1; along_b >= 0; along_b--) {
        /* A0 = P^T B_dn, A1 = P^T B_up with P = B_dn + B_up (2 x 2, row-major) */
        double A0[4] = {0}, A1[4] = {0};
        for (int i = 0; i < ni; i++)
            for (int j = 0; j < nj; j++) {
                int i2 = i + along_b, j2 = j + !along_b;
                if (i2 >= ni || j2 >= nj)
                    continue;
                double dn[2] = {y[nj * i + j], y2[nj * i + j]};
                double up[2] = {y[nj * i2 + j2], y2[nj * i2 + j2]};
                for (int r = 0; r < 2; r++)
                    for (int c = 0; c < 2; c++) {
                        A0[2 * r + c] += (dn[r] + up[r]) * dn[c];
                        A1[2 * r + c] += (dn[r] + up[r]) * up[c];
                    }
            }
        /* det(cos(psi) A1 - sin(psi) A0) = ca cos^2 + cb cos sin + cc sin^2 = 0 */
        double ca = A1[0] * A1[3] - A1[1] * A1[2], cc = A0[0] * A0[3] - A0[1] * A0[2];
        double cb = -(A1[0] * A0[3] + A0[0] * A1[3] - A1[1] * A0[2] - A0[1] * A1[2]);
        /* the two angles: a quadratic in tan (or cot) psi, the discriminant clamped */
        double disc = cb * cb - 4.0 * ca * cc, sq = sqrt(disc > 0.0 ? disc : 0.0), psi[2];
        if (fabs(cc) >= fabs(ca)) { /* cc tan^2 + cb tan + ca = 0 */
            double qq = -0.5 * (cb + (cb >= 0.0 ? sq : -sq));
            psi[0] = atan2(qq, cc);
            psi[1] = qq != 0.0 ? atan2(ca, qq) : psi[0];
        } else { /* ca cot^2 + cb cot + cc = 0 */
            double qq = -0.5 * (cb + (cb >= 0.0 ? sq : -sq));
            psi[0] = atan2(ca, qq);
            psi[1] = qq != 0.0 ? atan2(qq, cc) : psi[0];
        }
        double sep = fabs(sin(psi[0] - psi[1]));
        if (sep > best_sep) {
            best_sep = sep;
            psi_best[0] = psi[0];
            psi_best[1] = psi[1];
            memcpy(A0b, A0, sizeof(A0));
            memcpy(A1b, A1, sizeof(A1));
        }
    }
    int n = best_sep > 1e-12 ? 2 : 1;
    for (int k = 0; k < n; k++) {
        double cs = cos(psi_best[k]), sn = sin(psi_best[k]), Mx[4];
        for (int i = 0; i < 4; i++)
            Mx[i] = cs * A1b[i] - sn * A0b[i];
        /* c: the null vector of the 2 x 2 Mx, from its larger row */
        double c0, c1;
        if (Mx[0] * Mx[0] + Mx[1] * Mx[1] >= Mx[2] * Mx[2] + Mx[3] * Mx[3]) {
            c0 = -Mx[1];
            c1 = Mx[0];
        } else {
            c0 = -Mx[3];
            c1 = Mx[2];
        }
        double z[12];
        for (int i = 0; i < 12; i++)
            z[i] = c0 * y[i] + c1 * y2[i];
        tb[k] = g6_half_angle(z, mult, 1);
        tc[k] = g6_half_angle(z, mult, 0);
    }
    return n;
}

/* What the back-substitution of one variant and pose needs. */
typedef struct {
    const double *vb, *Tp, *Q, *V8, *beta8, *A8;
    int a, dir;
} G6Back;

/* The candidate of root theta (sin s, cos c) with joints a+1, a+2 at tb, tc: u, w
 * by least squares on Q's block, P'(theta) e(t_b) (x) e(t_c) = Q_8 y; joint a+3
 * from the orientation; into o in the original joint order. Returns 1, or 0 when
 * a value is not finite. */
static int g6_candidate(const G6Back *G, double th, double s, double c, double tb,
                    double tc, G6Cand *o)
{
    const double *Pm = G->vb + VB_P, *Q = G->Q, *A8 = G->A8;
    const int a = G->a;
    /* u, w: least squares on Q's block, P'(theta) e(t_b) (x) e(t_c) = Q_8 y */
    double eb[3] = {0.5 * (1.0 + cos(tb)), 0.5 * sin(tb), 0.5 * (1.0 - cos(tb))};
    double ec[3] = {0.5 * (1.0 + cos(tc)), 0.5 * sin(tc), 0.5 * (1.0 - cos(tc))};
    double mono[9], rhs[14];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            mono[3 * i + j] = eb[i] * ec[j];
    for (int e = 0; e < 14; e++) {
        double acc = -Q[9 * e + 8];
        for (int m = 0; m < 9; m++)
            acc += (s * Pm[9 * e + m] + c * Pm[126 + 9 * e + m] + Pm[252 + 9 * e + m]) *
                   mono[m];
        rhs[e] = acc;
    }
    house_apply_t(G->V8, G->beta8, 14, 8, rhs);
    double yu[8];
    for (int i = 7; i >= 0; i--) {
        double acc = rhs[i];
        for (int j = i + 1; j < 8; j++)
            acc -= A8[14 * j + i] * yu[j];
        yu[i] = acc / A8[14 * i + i];
    }
    double u = atan2(yu[4], yu[5]), w = atan2(yu[6], yu[7]);
    /* the direction's chain values; joint a+3 from the orientation */
    double v[6];
    v[a - 1] = th;
    v[a] = tb;
    v[a + 1] = tc;
    int j3 = g6_idx(a + 3);
    v[g6_idx(a + 4) - 1] = u;
    v[g6_idx(a + 5) - 1] = w;
    v[j3 - 1] = 0.0;
    double RL[9], RR[9], Rm[9];
    g6_rot_span(G->vb, v, 0, 1, j3, RL);  /* C'_0 ... Rz(v_{j3-1}) C'_{j3-1} */
    g6_rot_span(G->vb, v, j3, j3 + 1, 7, RR); /* C'_{j3} Rz(v_{j3+1}) ... C'_6 */
    /* Rz(v_j3) = RL^T R_T' RR^T */
    for (int r = 0; r < 3; r++)
        for (int cc = 0; cc < 3; cc++) {
            double acc = 0.0;
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++)
                    acc += RL[3 * i + r] * G->Tp[4 * i + j] * RR[3 * cc + j];
            Rm[3 * r + cc] = acc;
        }
    v[j3 - 1] = atan2(Rm[3] - Rm[1], Rm[0] + Rm[4]);
    for (int k2 = 0; k2 < 6; k2++)
        o->v[k2] = G->dir ? -v[5 - k2] : v[k2];
    int ok = 1;
    for (int k2 = 0; k2 < 6; k2++)
        ok &= isfinite(o->v[k2]);
    return ok;
}

/* Candidate chain values of one variant for the pose T (4x4 row-major): appended
 * to cand (at most 3 G6_MAXROOT); flags get G6F_DEGENERATE / G6F_AMBIGUOUS; stats[0]
 * the relative DFT tail, stats[1] the margin (the smallest ratio of Sigma's
 * second-smallest to largest pivot over the roots tried), stats[2] how many roots
 * were close to another (two solutions nearly sharing theta_a: both taken from a
 * 2-D null space). Returns the number of candidates. */
static int g6_variant(const double *P, const double *vb, const double *T, G6Cand *cand,
                      int *flags, double *stats)
{
    const int dir = (int)vb[VB_DIR], a = (int)vb[VB_A], mult = (int)vb[VB_MULT];
    const double tail_tol = P[GP_TAIL_TOL], null_tol = P[GP_NULL_TOL];
    const double imag_tol = P[GP_IMAG_TOL];
    double Tp[16], k6inv[16], tmp[16];
    double *tail = stats;
    stats[0] = stats[1] = INFINITY;
    stats[2] = 0.0;
    if (dir)
        rigid_inv(T, Tp);
    else
        memcpy(Tp, T, sizeof(Tp));
    mul4(vb + VB_CI, Tp, tmp);             /* C'_0^-1 T' */
    mul4(tmp, vb + VB_CI + 16 * 6, k6inv); /* ... C'_6^-1 = K_6^-1 */

    /* right side, its 14 x 8 block's QR and left null space */
    double Q[14 * 9], A8[8 * 14], V8[8 * 14], beta8[8];
    g6_right(vb, a, k6inv, Q);
    for (int j = 0; j < 8; j++)
        for (int i = 0; i < 14; i++)
            A8[14 * j + i] = Q[9 * i + j];
    house_qr(A8, 14, 8, V8, beta8);
    double rmax = 0.0, rmin = INFINITY;
    for (int k = 0; k < 8; k++) {
        double d = fabs(A8[14 * k + k]);
        rmax = d > rmax ? d : rmax;
        rmin = d < rmin ? d : rmin;
    }
    if (!(rmin > 1e-12 * rmax)) {
        *flags |= G6F_DEGENERATE;
        return 0;
    }
    /* the left null space N (6 x 14): rows 8..13 of Q^T, i.e. H_0 .. H_7 e_r */
    double Nn[6][14];
    for (int r = 0; r < 6; r++) {
        double *x = Nn[r];
        for (int i = 0; i < 14; i++)
            x[i] = i == 8 + r ? 1.0 : 0.0;
        for (int k = 7; k >= 0; k--) {
            const double *v = V8 + 14 * k;
            double s = 0.0;
            for (int i = k; i < 14; i++)
                s += v[i] * x[i];
            s *= beta8[k];
            for (int i = k; i < 14; i++)
                x[i] -= s * v[i];
        }
    }
    /* M = N P' (6 x 27): N [P_s | P_c | P_1 - Q_9 (x) h], h = (1+x_b^2)(1+x_c^2) */
    static const double h9[9] = {1, 0, 1, 0, 0, 0, 1, 0, 1};
    const double *Pm = vb + VB_P;
    double Mx[6][27];
    for (int r = 0; r < 6; r++) {
        double nq = 0.0;
        for (int e = 0; e < 14; e++)
            nq += Nn[r][e] * Q[9 * e + 8];
        for (int m = 0; m < 9; m++)
            Mx[r][18 + m] = -nq * h9[m];
        for (int m = 0; m < 18; m++)
            Mx[r][m] = 0.0;
        for (int blk = 0; blk < 3; blk++)
            for (int e = 0; e < 14; e++) {
                double f = Nn[r][e];
                for (int m = 0; m < 9; m++)
                    Mx[r][9 * blk + m] += f * Pm[126 * blk + 9 * e + m];
            }
    }
    for (int r = 0; r < 6; r++) { /* equilibrate the 6 equations */
        double mx = 0.0;
        for (int col = 0; col < 27; col++)
            mx = fabs(Mx[r][col]) > mx ? fabs(Mx[r][col]) : mx;
        if (mx == 0.0) {
            *flags |= G6F_DEGENERATE;
            return 0;
        }
        for (int col = 0; col < 27; col++)
            Mx[r][col] /= mx;
    }
    /* the dialytic matrices: Sigma(theta) = s S[0] + c S[1] + S[2] */
    double S[3][144];
    memset(S, 0, sizeof(S));
    for (int blk = 0; blk < 3; blk++)
        for (int r = 0; r < 6; r++)
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++) {
                    double x = Mx[r][9 * blk + 3 * i + j];
                    S[blk][12 * r + g6_col(mult, 0, i, j)] = x;
                    S[blk][12 * (6 + r) + g6_col(mult, 1, i, j)] = x;
                }
    /* det Sigma at 24 angles, its DFT */
    double D[G6_NSAMP];
    int jbest = 0;
    for (int k = 0; k < G6_NSAMP; k += W)
        det12_lanes((const double (*)[144])S, k, D);
    for (int k = 1; k < G6_NSAMP; k++)
        if (fabs(D[k]) > fabs(D[jbest]))
            jbest = k;
    double dr[G6_NSAMP / 2 + 1], di[G6_NSAMP / 2 + 1], head = 0.0, tl = 0.0;
    for (int f = 0; f <= G6_NSAMP / 2; f++) {
        double sr = 0.0, si = 0.0;
        for (int k = 0; k < G6_NSAMP; k++) {
            int idx = (f * k) % G6_NSAMP;
            sr += D[k] * g6_cs[idx];
            si -= D[k] * g6_sn[idx];
        }
        dr[f] = sr / G6_NSAMP;
        di[f] = si / G6_NSAMP;
        double mag = hypot(dr[f], di[f]);
        if (f <= G6_DEG)
            head = mag > head ? mag : head;
        else
            tl = mag > tl ? mag : tl;
    }
    if (!(head > 0.0) || !isfinite(head)) {
        *flags |= G6F_DEGENERATE;
        return 0;
    }
    *tail = tl / head;
    if (!(*tail <= tail_tol)) {
        *flags |= G6F_DEGENERATE;
        return 0;
    }
    /* the degree-16 polynomial in x = tan((theta - phi) / 2), phi + pi the sample
     * of largest |D| (its leading coefficient is D there) */
    double phi = G6_TWO_PI * jbest / G6_NSAMP - G6_PI;
    double cpoly[17];
    for (int j = 0; j <= 16; j++) {
        double acc = dr[0] * g6_er[8][j];
        for (int f = 1; f <= G6_DEG; f++) {
            double cf = cos(f * phi), sf = sin(f * phi);
            double zr = dr[f] * cf - di[f] * sf, zi = dr[f] * sf + di[f] * cf;
            acc += 2.0 * (zr * g6_er[8 + f][j] - zi * g6_ei[8 + f][j]);
        }
        cpoly[j] = acc;
    }
    double wr[16], wi[16];
    if (!all_roots16(cpoly, jbest, wr, wi)) {
        *flags |= G6F_DEGENERATE;
        return 0;
    }
    /* the accepted roots (a complex pair counts once, as a possible pair of close
     * real roots; so do roots within the pair gap of another) */
    const double pair_gap = P[GP_PAIR_GAP];
    double ths[16];
    int nr = 0, pair[16];
    for (int k = 0; k < 16; k++) {
        if (wi[k] < 0.0)
            continue; /* the conjugate's twin */
        double z2 = wr[k] * wr[k] + wi[k] * wi[k];
        if (2.0 * fabs(wi[k]) / (1.0 + z2) <= imag_tol) {
            pair[nr] = wi[k] != 0.0;
            ths[nr++] = phi + 2.0 * atan(wr[k]);
        }
    }
    for (int i = 0; i < nr; i++)
        for (int j = i + 1; j < nr; j++)
            if (fabs(wrap_pi(ths[i] - ths[j])) < pair_gap)
                pair[i] = pair[j] = 1;
    G6Back G = {vb, Tp, Q, V8, beta8, A8, a, dir};
    /* back-substitution, W roots at a time for the null vectors */
    int nc = 0;
    for (int k0 = 0; k0 < nr; k0 += W) {
        vd sv, cv, yv[12], yv2[12], rv[12];
        for (int l = 0; l < W; l++) {
            double th = ths[k0 + l < nr ? k0 + l : k0];
            sv[l] = sin(th);
            cv[l] = cos(th);
        }
        null_vector12_lanes((const double (*)[144])S, sv, cv, yv, yv2, rv);
        for (int l = 0; l < W && k0 + l < nr; l++) {
            double th = ths[k0 + l], s = sv[l], c = cv[l];
            double y[12];
            for (int i = 0; i < 12; i++)
                y[i] = yv[i][l];
            double margin = rv[10][l] / rv[0][l];
            stats[1] = margin < stats[1] ? margin : stats[1];
            if (!(margin > null_tol))
                *flags |= G6F_AMBIGUOUS;
            /* the smallest singular vector's solution; where two solutions may share
             * theta (a close or complex pair, a 2-D null space) also the two in the
             * span of the two smallest (at a singular solution the pair is one
             * solution twice and only the first is right) */
            double tb[3], tc[3];
            int np = 1;
            tb[0] = g6_half_angle(y, mult, 1);
            tc[0] = g6_half_angle(y, mult, 0);
            if (pair[k0 + l] || !(margin > null_tol)) {
                stats[2] += 1.0;
                double y2[12];
                for (int i = 0; i < 12; i++)
                    y2[i] = yv2[i][l];
                np += g6_two_solutions(y, y2, mult, tb + 1, tc + 1);
            }
            for (int k = 0; k < np; k++) {
                cand[nc].slow = np > 1;
                nc += g6_candidate(&G, th, s, c, tb[k], tc[k], cand + nc);
            }
        }
    }
    return nc;
}

/* ------------------------------------------------------------ Newton polish */

#define NEWTON_RATIO 0.7 /* a step must cut the error by this factor (after 3) */
#define SLOW_RATIO 0.9   /* ... from a close pair of roots (after SLOW_START) */
#define SLOW_START 8

/* Smallest singular value of the 6 x 6 row-major J (lane-wise): inverse iteration
 * on J^T J (Cholesky), started at the unit vector of the smallest Cholesky pivot;
 * an upper bound that is sharp when J is nearly singular, 0 where J^T J is not
 * positive definite. */
static vd g6_sigma_min(const vd *J)
{
    vd B[36], L[36];
    for (int i = 0; i < 6; i++)
        for (int j = i; j < 6; j++) {
            vd s = BR(0.0);
            for (int r = 0; r < 6; r++)
                s += J[6 * r + i] * J[6 * r + j];
            B[6 * i + j] = B[6 * j + i] = s;
        }
    vl bad = BRL(0);
    for (int j = 0; j < 6; j++) {
        vd s = B[6 * j + j];
        for (int k = 0; k < j; k++)
            s -= L[6 * j + k] * L[6 * j + k];
        bad |= ~(s > BR(0.0));
        L[6 * j + j] = vsqrt(vsel(bad, BR(1.0), s));
        vd inv = BR(1.0) / L[6 * j + j];
        for (int i = j + 1; i < 6; i++) {
            vd t = B[6 * i + j];
            for (int k = 0; k < j; k++)
                t -= L[6 * i + k] * L[6 * j + k];
            L[6 * i + j] = t * inv;
        }
    }
    vd x[6], small = L[0];
    vl at = BRL(0);
    for (int k = 1; k < 6; k++) {
        vl m = L[6 * k + k] < small;
        small = vsel(m, L[6 * k + k], small);
        at = (at & ~m) | (BRL(k) & m);
    }
    for (int k = 0; k < 6; k++)
        x[k] = vsel(at == BRL(k), BR(1.0), BR(0.0));
    for (int it = 0; it < 4; it++) {
        vd z[6];
        for (int i = 0; i < 6; i++) { /* L z = x */
            vd s = x[i];
            for (int k = 0; k < i; k++)
                s -= L[6 * i + k] * z[k];
            z[i] = s / L[6 * i + i];
        }
        vd nrm = BR(0.0);
        for (int i = 5; i >= 0; i--) { /* L^T x = z */
            vd s = z[i];
            for (int k = i + 1; k < 6; k++)
                s -= L[6 * k + i] * x[k];
            x[i] = s / L[6 * i + i];
            nrm += x[i] * x[i];
        }
        vd inv = BR(1.0) / vsqrt(nrm);
        for (int i = 0; i < 6; i++)
            x[i] *= inv;
    }
    vd lam = BR(0.0); /* Rayleigh quotient x^T B x */
    for (int i = 0; i < 6; i++) {
        vd bx = BR(0.0);
        for (int j = 0; j < 6; j++)
            bx += B[6 * i + j] * x[j];
        lam += x[i] * bx;
    }
    vd sig = vsqrt(vsel(lam > BR(0.0), lam, BR(0.0)));
    return vsel(bad | ~vfinite(sig), BR(0.0), sig);
}

/* Newton steps on the true chain from the candidates (chain values), W at a time;
 * the distinct ones that reproduce T within tol go to q (wrapped into [-pi, pi))
 * and sig (Jacobian's smallest singular value). Returns how many. */
static int g6_polish(const Chain *ch, const double *P, const double *T, const G6Cand *cand,
                     int ncand, double *q, double *sig)
{
    const double tol = P[GP_TOL], dedupe = P[GP_DEDUPE];
    const int max_iter = (int)P[GP_MAX_ITER];
    int nsol = 0;
    vd tt[12];
    for (int i = 0; i < 12; i++)
        tt[i] = BR(T[i]);
    for (int c0 = 0; c0 < ncand; c0 += W) {
        vd qv[MAXJ], t[12], J[36], e[6];
        for (int j = 0; j < 6; j++)
            for (int l = 0; l < W; l++) {
                int c = c0 + l < ncand ? c0 + l : c0;
                qv[j][l] = ch->sign[j] * (cand[c].v[j] - ch->offset[j]);
            }
        vl done = BRL(0);
        for (int l = 0; l < W; l++)
            if (c0 + l >= ncand)
                done[l] = -1;
        double prev[W];
        int slow[W];
        for (int l = 0; l < W; l++)
            slow[l] = c0 + l < ncand && cand[c0 + l].slow;
        for (int it = 0;; it++) {
            chain_pose_jac(ch, qv, t, J, 6);
            pose_residual(t, tt, e, BRL(-1));
            int all = 1;
            for (int l = 0; l < W; l++) {
                double m = 0.0;
                for (int r = 0; r < 6; r++)
                    m = fabs(e[r][l]) > m ? fabs(e[r][l]) : m;
                /* converged, or a spurious root: from a true one Newton converges
                 * quadratically, so a lane whose error stops falling gives up; near
                 * a singular solution (a close pair of roots) it may be linear with
                 * ratio 1/2 after an erratic start */
                int stalled = slow[l] ? it >= SLOW_START && m > SLOW_RATIO * prev[l]
                                      : it >= 3 && m > NEWTON_RATIO * prev[l];
                if (!(m > 1e-14) || !isfinite(m) || stalled)
                    done[l] = -1;
                prev[l] = m;
                all &= done[l] != 0;
            }
            if (all || it == max_iter)
                break;
            for (int l = 0; l < W; l++) {
                if (done[l])
                    continue;
                double A[36], b[6];
                for (int r = 0; r < 6; r++) {
                    b[r] = e[r][l];
                    for (int j = 0; j < 6; j++)
                        A[6 * r + j] = J[6 * r + j][l];
                }
                if (!solve_dense(A, b, 6)) {
                    done[l] = -1;
                    continue;
                }
                double big = 0.0;
                for (int j = 0; j < 6; j++)
                    big = fabs(b[j]) > big ? fabs(b[j]) : big;
                double f = big > 0.5 ? 0.5 / big : 1.0; /* a far seed: damp */
                for (int j = 0; j < 6; j++)
                    qv[j][l] += f * b[j];
            }
        }
        vd sg = g6_sigma_min(J);
        for (int l = 0; l < W && c0 + l < ncand; l++) {
            double ep = sqrt(e[0][l] * e[0][l] + e[1][l] * e[1][l] + e[2][l] * e[2][l]);
            double er = sqrt(e[3][l] * e[3][l] + e[4][l] * e[4][l] + e[5][l] * e[5][l]);
            if (!(ep <= tol && er <= tol))
                continue;
            double qs[6];
            for (int j = 0; j < 6; j++)
                qs[j] = wrap_pi(qv[j][l]);
            int dup = 0;
            for (int s = 0; s < nsol && !dup; s++) {
                double m = 0.0;
                for (int j = 0; j < 6; j++) {
                    double d = fabs(wrap_pi(qs[j] - q[6 * s + j]));
                    m = d > m ? d : m;
                }
                dup = m < dedupe;
            }
            if (dup || nsol == G6_MAXSOL)
                continue;
            memcpy(q + 6 * nsol, qs, sizeof(qs));
            sig[nsol] = sg[l];
            nsol++;
        }
    }
    return nsol;
}

/* --------------------------------------------------------------- per pose */

static int g6_pose(const Chain *ch, const double *P, const double *T, double *q, double *sig,
                   long long *diag, double *stats)
{
    for (int i = 0; i < 16; i++)
        if (!isfinite(T[i])) {
            *diag = 0;
            stats[0] = stats[1] = INFINITY;
            stats[2] = 0.0;
            return -1;
        }
    G6Cand cand[6 * G6_MAXROOT]; /* two variants, up to three per root */
    int flags = 0, f2 = 0;
    double st2[3];
    int nc = g6_variant(P, P + GP_HEAD, T, cand, &flags, stats);
    if ((int)P[GP_NVAR] > 1 && (flags & (G6F_DEGENERATE | G6F_AMBIGUOUS))) {
        nc += g6_variant(P, P + GP_HEAD + VB_SIZE, T, cand + nc, &f2, st2);
        flags |= G6F_SECONDARY;
        if (f2 & G6F_DEGENERATE)
            flags |= G6F_SEC_DEGENERATE;
        if (f2 & G6F_AMBIGUOUS)
            flags |= G6F_SEC_AMBIGUOUS;
    }
    *diag = flags | (nc << G6_DIAG_CAND_SHIFT);
    int ns = g6_polish(ch, P, T, cand, nc, q, sig);
    if (ns == 0 && (flags & G6F_DEGENERATE) &&
        (!(flags & G6F_SECONDARY) || (flags & G6F_SEC_DEGENERATE)))
        return -2;
    return ns;
}

typedef struct {
    const Chain *ch;
    const double *P, *T;
    double *Q, *sig, *stats;
    npy_bool *valid, *inside;
    long long *status, *diag;
} G6Job;

static void g6_range(void *ctx, long b, long e)
{
    G6Job *job = (G6Job *)ctx;
    for (long i = b; i < e; i++) {
        double q[6 * G6_MAXSOL], sig[G6_MAXSOL];
        int ns = g6_pose(job->ch, job->P, job->T + 16 * i, q, sig, job->diag + i,
                         job->stats + 3 * i);
        job->status[i] = ns == -1 ? G6_BAD_POSE : ns == -2 ? G6_DEGENERATE
                         : ns == 0 ? G6_NONE : G6_OK;
        ns = ns < 0 ? 0 : ns;
        double *Qo = job->Q + (size_t)i * 6 * G6_MAXSOL;
        const Chain *ch = job->ch;
        for (int s = 0; s < G6_MAXSOL; s++) {
            int ok = s < ns, in = ok;
            for (int j = 0; j < 6; j++) {
                /* whole turns into the limits where possible (chain.h's wrap_into) */
                double v = ok ? wrap_into(q[6 * s + j], ch->lo[j], ch->hi[j]) : NAN;
                in &= v >= ch->lo[j] - 1e-9 && v <= ch->hi[j] + 1e-9;
                Qo[6 * s + j] = v;
            }
            job->valid[i * G6_MAXSOL + s] = (npy_bool)ok;
            job->inside[i * G6_MAXSOL + s] = (npy_bool)in;
            job->sig[i * G6_MAXSOL + s] = ok ? sig[s] : NAN;
        }
    }
}

/* ---------------------------------------------------------- Python entries */

/* a 6R chain of revolute joints without dependent ones */
static int g6_chain_ok(const Chain *ch)
{
    if (ch->nc != 6 || ch->n != 6 || !ch->ident)
        return 0;
    for (int k = 0; k < 6; k++)
        if (ch->kind[k] != 0.0)
            return 0;
    return 1;
}

static int g6_params_ok(const double *P, long len)
{
    if (len < GP_HEAD)
        return 0;
    int nv = (int)P[GP_NVAR];
    if (!(P[GP_NVAR] == 1.0 || P[GP_NVAR] == 2.0) || len != GP_HEAD + nv * VB_SIZE)
        return 0;
    if (!(P[GP_MAX_ITER] >= 0.0 && P[GP_MAX_ITER] <= 100.0))
        return 0;
    for (int k = 0; k < nv; k++) {
        const double *vb = P + GP_HEAD + k * VB_SIZE;
        if (!(vb[VB_DIR] == 0.0 || vb[VB_DIR] == 1.0) ||
            !(vb[VB_A] == 1.0 || vb[VB_A] == 2.0 || vb[VB_A] == 3.0) ||
            !(vb[VB_MULT] == 0.0 || vb[VB_MULT] == 1.0))
            return 0;
    }
    return 1;
}

/* general6r_solve(packed, params, T (N, 4, 4), Q (N, 16, 6), valid (N, 16) bool,
 *                 inside (N, 16) bool, sigma (N, 16), status (N,) int64,
 *                 diag (N,) int64, stats (N, 3), parallel): per pose up to 16
 * solutions (joint coordinates, revolute ones in [-pi, pi) or moved by whole turns
 * into their limits; rows that are not solutions 0), which are solutions, which
 * are inside the limits, the Jacobian's smallest singular value (NaN on other
 * rows), the status (G6_OK ...), the flags (G6F_..., candidates tried above
 * G6_DIAG_CAND_SHIFT) and the primary's tail, margin and close pairs. */
static PyObject *general6r_solve_body(const general6r_solve_args *a)
{
    npy_intp N = a->N;
    int parallel = a->parallel;
    G6Job job = {&a->packed, a->params, a->T, a->Q, a->sigma, a->stats, a->valid, a->inside,
                 a->status, a->diag};
    Py_BEGIN_ALLOW_THREADS
    if (parallel && N >= G6_PARALLEL_MIN)
        pool_for((long)N, G6_GRAIN, g6_range, &job);
    else
        g6_range(&job, 0, (long)N);
    Py_END_ALLOW_THREADS
    Py_RETURN_NONE;
}

/* general6r_fit_rows(consts (7, 4, 4), a, angles (M, 3), X (M, 27), Y (M, 14)):
 * the left side J_a K_a J_{a+1} K_{a+1} J_{a+2} K_{a+2} at the angles: Y its 14
 * equations times (1 + x_b^2)(1 + x_c^2), X the 27 monomials
 * {s_a, c_a, 1} (x) {x_b^i x_c^j} (index 9 block + 3 i + j) they are linear in */
static PyObject *general6r_fit_rows_body(const general6r_fit_rows_args *args)
{
    npy_intp M = args->M;
    int a = (int)args->a;
    const double *K = args->consts, *t = args->angles;
    double *x = args->X, *y = args->Y;
    for (npy_intp r = 0; r < M; r++) {
        double L[16], Rz[16] = {0}, tmp[16];
        memset(L, 0, sizeof(L));
        L[0] = L[5] = L[10] = L[15] = 1.0;
        for (int k = 0; k < 3; k++) {
            double c = cos(t[3 * r + k]), s = sin(t[3 * r + k]);
            memset(Rz, 0, sizeof(Rz));
            Rz[0] = c; Rz[1] = -s; Rz[4] = s; Rz[5] = c; Rz[10] = 1.0; Rz[15] = 1.0;
            mul4(L, Rz, tmp);
            mul4(tmp, K + 16 * (a + k), L);
        }
        double l[3] = {L[2], L[6], L[10]}, p[3] = {L[3], L[7], L[11]};
        double xb = tan(0.5 * t[3 * r + 1]), xc = tan(0.5 * t[3 * r + 2]);
        double scale = (1.0 + xb * xb) * (1.0 + xc * xc);
        g6_equations(l, p, y + 14 * r);
        for (int e = 0; e < 14; e++)
            y[14 * r + e] *= scale;
        double pb[3] = {1.0, xb, xb * xb}, pc[3] = {1.0, xc, xc * xc};
        double th[3] = {sin(t[3 * r]), cos(t[3 * r]), 1.0};
        for (int blk = 0; blk < 3; blk++)
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++)
                    x[27 * r + 9 * blk + 3 * i + j] = th[blk] * pb[i] * pc[j];
    }
    Py_RETURN_NONE;
}

/* general6r_roots(c (deg + 1,) lowest power first, wr (deg,), wi (deg,)) -> bool:
 * the kernel's polynomial root finder (balanced companion matrix + hqr), for tests */
static PyObject *general6r_roots_body(const general6r_roots_args *a)
{
    npy_intp deg = a->D - 1;
    const double *cd = a->c;
    int ok;
    Py_BEGIN_ALLOW_THREADS
    ok = poly_roots(cd, (int)deg, a->wr, a->wi);
    Py_END_ALLOW_THREADS
    return PyBool_FromLong(ok);
}

/* module init: the tables (run once per process per copy) */
static int g6_init(void)
{
    g6_init_tables();
    return 0;
}
