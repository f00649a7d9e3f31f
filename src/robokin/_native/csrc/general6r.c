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
 * in EISPACK hqr). Roots with a small imaginary part are tried too.
 *
 * Back-substitution. Each root: the null vector of Sigma (pivoted QR) is the
 * monomial vector of (x_b, x_c), read as two half angles (principal axes, finite at
 * x = inf); least squares on Q's block gives u, w; joint a+3 follows from the
 * orientation. Where k solutions share theta_a (special configurations: the four
 * arm solutions of an IRB140 sharing the wrist angle, k = 4), Sigma's null space
 * has dimension k and any null vector is a mix of their monomial vectors. Roots
 * closer than GP_PAIR_GAP or complex (how a k-fold root comes out of rounding:
 * spread by eps^(1/k)) form a cluster; at its centroid the k trailing columns of a
 * rank-revealing QR span the null space, and the monomial structure splits it
 * (g6_split, Moller-Stetter): y[up] = x_b y[dn] for every genuine monomial vector,
 * so inside the null space the solutions are the common eigenvectors of the k x k
 * shift operators along b and along c (one eigenproblem of a generic combination).
 *
 * Degenerate poses. At some poses of some arms det Sigma vanishes for every theta
 * (in every variant): the eliminated system has a spurious solution curve besides
 * the isolated solutions. Then the pose is moved along a fixed direction xi,
 * T(s) = T Exp(s xi): the isolated solutions move with it, so along theta(s)
 * det Sigma(theta(s); T(s)) = 0, and the lowest coefficient c_d(theta) of
 * det(Sigma_0(theta) + s Sigma_1(theta)) (Sigma_1 = d Sigma / ds at s = 0, computed
 * exactly) vanishes at every isolated solution's theta_a (the generalized
 * characteristic polynomial of Canny 1990, with the pose as the perturbation, which
 * keeps the system consistent). c_d is again a trigonometric polynomial of degree
 * 8: sampled from a complete-pivoting LU of Sigma_0 (c_d = det U_11 det(Schur
 * complement of Sigma_1 on the d-dimensional null spaces)); at its roots the
 * solutions' monomial vectors lie in Sigma_0's right null space V and are null
 * vectors of Y^T Sigma_1 V (Y the left null space).
 *
 * Newton steps on the true chain (Levenberg-Marquardt with damping |e|^2,
 * Yamashita & Fukushima 2001: quadratic near regular solutions, and convergent onto
 * a manifold of solutions) polish every candidate; a candidate whose error stops
 * falling far from zero is spurious and dropped; a solution is kept when it
 * reproduces the pose to GP_TOL (position [m] and rotation [rad]), once.
 * Where nothing at all is found and the elimination reported trouble (a singular
 * target: a continuum of solutions), the null spaces of Sigma at the 24 sample
 * angles are split into candidates instead (flagged G6F_RESCUED): where the
 * continuum moves theta_a, those in its range are on it.
 *
 * An arm is solved by a variant: the split a, the chain or its reversal (the IK
 * of T^-1 on C_6^-1 Rz(-v_6) ... Rz(-v_1) C_0^-1) and the multiplier. The Python
 * set-up ranks a few (primary, secondary, then others with another split or
 * direction); for a pose the next one runs while the previous is degenerate or
 * noisy there.
 *
 * References:
 *   Raghavan, M. and Roth, B. "Inverse kinematics of the general 6R manipulator
 *   and related linkages", J. Mech. Design 115(3), 1993.
 *   Manocha, D. and Canny, J. "Efficient inverse kinematics for general 6R
 *   manipulators", IEEE Trans. Robotics and Automation 10(5), 1994.
 *   Canny, J. "Generalised characteristic polynomials", J. Symbolic Computation
 *   9(3), 1990.
 *   Moller, H. M. and Stetter, H. J. "Multivariate polynomial equations with
 *   multiple zeros solved by matrix eigenproblems", Numer. Math. 70, 1995.
 *   Yamashita, N. and Fukushima, M. "On the rate of convergence of the
 *   Levenberg-Marquardt method", Computing Suppl. 15, 2001.
 *   Smith, B. T. et al. "Matrix Eigensystem Routines - EISPACK Guide", 1976
 *   (balanc, hqr). Golub, G. and Van Loan, C. "Matrix Computations", 4th ed.,
 *   5.2 (Householder QR), 5.4.2 (column pivoting), 3.4.8 (complete pivoting),
 *   7.4 (Hessenberg reduction), 7.6.1 (inverse iteration).
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
#define G6_NEAR 4      /* complex root pairs closest to the real axis reported (stats) */
#define G6_NSTATS (4 + 2 * G6_NEAR) /* per pose statistics (general6r_solve's stats) */
#define G6_MAXSPLIT 8  /* largest null space split into solutions */
#define G6_VARCAND (3 * G6_MAXROOT + 2 * G6_MAXSPLIT) /* candidates of one variant */
#define G6_MAXCAND (8 * G6_VARCAND) /* of one pose (the room g6_candidates fills) */
#define G6_MAXVAR 12   /* variants a parameter vector holds */
#define G6_MULTI_TOL 1e-4 /* a root near others whose Sigma has a second pivot below this
                           * fraction of the largest: a spread multiple root */
#define G6_GRAIN 8     /* poses per pool chunk */
#define G6_PARALLEL_MIN 32

/* params: a header, then G6_NVAR variant blocks (robokin's general_6r packs it) */
enum { GP_NVAR = 0 /* variants, in the order tried: 1 (primary) .. G6_MAXVAR */,
       GP_TAIL_TOL = 1 /* largest relative DFT tail above degree 8 */,
       GP_NULL_TOL = 2 /* pivot of Sigma below this fraction of the largest: null */,
       GP_IMAG_TOL = 3 /* imaginary part of theta_a accepted as real */,
       GP_TOL = 4 /* position [m] and rotation [rad] error of a solution */,
       GP_DEDUPE = 5 /* solutions closer than this [rad] are one */,
       GP_MAX_ITER = 6 /* Newton iterations */,
       GP_PAIR_GAP = 7 /* [rad] roots closer than this form a cluster */,
       GP_SCALE = 8 /* [m] the arm's length scale: position part of the pose motions */,
       GP_FALLBACK = 9 /* 1: the projection and the rescue run where needed (0: the
                        * variants alone, for the set-up's trials) */,
       GP_NEAR_TAIL = 10 /* a tail above this (and within GP_TAIL_TOL): a noisy
                          * determinant near a degenerate pose, the projection too */,
       GP_HEAD = 11 };
/* variant block: direction (0 the chain, 1 its reversal), split a, multiplier
 * (0 x_b, 1 x_c), the direction's constants C'_0..C'_6 and their inverses (4x4
 * row-major), the fitted P_s, P_c, P_1 (14 x 9 row-major each) */
enum { VB_DIR = 0, VB_A = 1, VB_MULT = 2, VB_C = 4, VB_CI = VB_C + 7 * 16,
       VB_P = VB_CI + 7 * 16, VB_SIZE = VB_P + 3 * 14 * 9 };
/* per pose status */
enum { G6_OK = 0, G6_NONE = 1 /* no real solution */,
       G6_DEGENERATE = 2 /* no solution and the elimination was degenerate */,
       G6_BAD_POSE = 3 /* a non-finite pose */ };
/* per pose diagnostics (bit flags): the primary degenerate (its right side rank
 * deficient or det Sigma identically 0) / it split a cluster; the secondary ran /
 * was degenerate / split a cluster; the projection (c_d) ran / was degenerate too;
 * the rescue (a singular target) ran; the primary / secondary noisy (near a
 * degenerate pose: a tail above GP_NEAR_TAIL, Sigma nearly singular at every
 * sample, or a simple root with a 2-D null space) */
enum { G6F_DEGENERATE = 1, G6F_CLUSTER = 2, G6F_SECONDARY = 4, G6F_SEC_DEGENERATE = 8,
       G6F_SEC_CLUSTER = 16, G6F_PROJECTED = 32, G6F_PROJ_DEGENERATE = 64,
       G6F_RESCUED = 128, G6F_NOISY = 256, G6F_SEC_NOISY = 512, G6F_EIGEN = 1024,
       G6F_MULTI = 2048 /* internal: a root with a second small pivot */ };
#define G6_DIAG_CAND_SHIFT 16 /* diag >> 16: the candidates polished */

/* the fixed direction xi (rotation, translation per GP_SCALE) poses are moved along:
 * no structure an arm could share (components from the golden ratio's powers) */
static const double G6_XI[6] = {0.3090169943749474, -0.4999999999999999, 0.6180339887498949,
                                0.4045084971874737, -0.2360679774997897, 0.1458980337503155};
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
 * its own pivots); ratio: the smallest |pivot| over the largest (small at every
 * sample: Sigma is nearly rank deficient for every theta, a pose near a degenerate
 * one) */
static void det12_lanes(const double (*S)[144], int k0, double *out, double *ratio)
{
    vd pmin = BR(INFINITY), pmax = BR(0.0);
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
        pmin = vsel(vabs(p) < pmin, vabs(p), pmin);
        pmax = vsel(vabs(p) > pmax, vabs(p), pmax);
        vl zero = p == BR(0.0);
        d = vsel(zero, BR(0.0), d * p);
        vd inv = BR(1.0) / vsel(zero, BR(1.0), p);
        for (int i = k + 1; i < 12; i++) {
            vd f = A[12 * i + k] * inv;
            for (int j = k + 1; j < 12; j++)
                A[12 * i + j] -= f * A[12 * k + j];
        }
    }
    for (int l = 0; l < W; l++) {
        out[k0 + l] = d[l];
        ratio[k0 + l] = pmax[l] > 0.0 ? pmin[l] / pmax[l] : 0.0;
    }
}

/* Null vectors of Sigma(theta_l) = s_l S[0] + c_l S[1] + S[2] (12 x 12 row-major),
 * one angle per lane, by Householder QR with column pivoting of Sigma^T:
 * Sigma^T P = U R, the null vector y = U e_12 (|Sigma y| = |r_12|); r: |diagonal of
 * R|, non-increasing, how many are small is the null space's dimension (Golub & Van
 * Loan 5.4.2, downdated column norms). */
static void null_vector12_lanes(const double (*S)[144], vd sv, vd cv, vd *y, vd *r)
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
    for (int i = 0; i < 12; i++)
        y[i] = BR(i == 11 ? 1.0 : 0.0);
    for (int k = 10; k >= 0; k--) {
        vd t = BR(0.0);
        for (int i = k; i < 12; i++)
            t += V[k][i] * y[i];
        t *= beta[k];
        for (int i = k; i < 12; i++)
            y[i] -= t * V[k][i];
    }
}
/* Solve the n x n row-major A x = b (both destroyed; x in b) by LU with partial
 * pivoting; 0 when a pivot is exactly zero. *pmin, *pmax: the smallest and largest
 * |pivot| (NULL: not wanted). */
static int solve_dense_pivots(double *A, double *b, int n, double *pmin, double *pmax)
{
    double lo = INFINITY, hi = 0.0;
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
        lo = best < lo ? best : lo;
        hi = best > hi ? best : hi;
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
    if (pmin != NULL) {
        *pmin = lo;
        *pmax = hi;
    }
    return 1;
}

static int solve_dense(double *A, double *b, int n)
{
    return solve_dense_pivots(A, b, n, NULL, NULL);
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
 * already found. Returns 0 when hqr fails.
 * jbest is not needed (not a bug): c's variable is measured from phi, so sample
 * jbest + m sits at x = tan(pi m / 24 - pi / 2) whatever jbest is (the sample jbest
 * itself at x = infinity, where c's leading coefficient is f); the choice of
 * jbest (the elimination phase) is already in c. */
static int all_roots16(const double *c, int jbest, double *wr, double *wi)
{
    (void)jbest;
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

/* ------------------------------------------------- small dense linear algebra */

/* The k trailing columns of U in the Householder QR with column pivoting
 * A^T P = U R of the n x n row-major A (n <= 12, k <= n): an orthonormal basis of
 * the space of A's k smallest singular values (its null space where they vanish);
 * Y (k x n row-major), Y[0] = U e_n the null vector; r: |diagonal of R|,
 * non-increasing. Column norms are recomputed at every step (small n). */
static void null_basis(const double *A, int n, int k, double *Y, double *r)
{
    double M[144], V[12][12], beta[12];
    /* column j of M (column-major, M[n j + i]) is row j of A: M = A^T */
    memcpy(M, A, sizeof(double) * n * n);
    for (int c = 0; c < n; c++) {
        int p = c;
        double best = -1.0;
        for (int j = c; j < n; j++) {
            double t = 0.0;
            for (int i = c; i < n; i++)
                t += M[n * j + i] * M[n * j + i];
            if (t > best) {
                best = t;
                p = j;
            }
        }
        if (p != c)
            for (int i = 0; i < n; i++) {
                double t = M[n * c + i];
                M[n * c + i] = M[n * p + i];
                M[n * p + i] = t;
            }
        double nrm = sqrt(best), *a = M + n * c, *v = V[c];
        r[c] = nrm;
        double alpha = a[c] > 0.0 ? -nrm : nrm;
        for (int i = 0; i < n; i++)
            v[i] = i < c ? 0.0 : a[i];
        v[c] = a[c] - alpha;
        double vv = 0.0;
        for (int i = c; i < n; i++)
            vv += v[i] * v[i];
        beta[c] = vv > 0.0 ? 2.0 / vv : 0.0;
        for (int j = c + 1; j < n; j++) {
            double *col = M + n * j, t = 0.0;
            for (int i = c; i < n; i++)
                t += v[i] * col[i];
            t *= beta[c];
            for (int i = c; i < n; i++)
                col[i] -= t * v[i];
        }
    }
    for (int j = 0; j < k; j++) {
        double *y = Y + n * j;
        for (int i = 0; i < n; i++)
            y[i] = i == n - 1 - j ? 1.0 : 0.0;
        for (int c = n - 1; c >= 0; c--) {
            double t = 0.0;
            for (int i = c; i < n; i++)
                t += V[c][i] * y[i];
            t *= beta[c];
            for (int i = c; i < n; i++)
                y[i] -= t * V[c][i];
        }
    }
}

/* Reduce the n x n row-major A (n <= 24) to upper Hessenberg form by Householder
 * similarity transformations (Golub & Van Loan 7.4.3; eigenvalues only, the
 * transformations are not kept); the entries below the subdiagonal become 0. */
static void hessenberg(double *A, int n)
{
    for (int k = 0; k + 2 < n; k++) {
        double v[24], nrm = 0.0;
        for (int i = k + 1; i < n; i++)
            nrm += A[n * i + k] * A[n * i + k];
        nrm = sqrt(nrm);
        if (nrm == 0.0)
            continue;
        double alpha = A[n * (k + 1) + k] > 0.0 ? -nrm : nrm, vv = 0.0;
        for (int i = 0; i < n; i++)
            v[i] = i <= k ? 0.0 : A[n * i + k];
        v[k + 1] -= alpha;
        for (int i = k + 1; i < n; i++)
            vv += v[i] * v[i];
        if (vv == 0.0)
            continue;
        double beta = 2.0 / vv;
        for (int j = 0; j < n; j++) { /* A <- H A */
            double t = 0.0;
            for (int i = k + 1; i < n; i++)
                t += v[i] * A[n * i + j];
            t *= beta;
            for (int i = k + 1; i < n; i++)
                A[n * i + j] -= t * v[i];
        }
        for (int i = 0; i < n; i++) { /* A <- A H */
            double t = 0.0;
            for (int j = k + 1; j < n; j++)
                t += A[n * i + j] * v[j];
            t *= beta;
            for (int j = k + 1; j < n; j++)
                A[n * i + j] -= t * v[j];
        }
        for (int i = k + 2; i < n; i++)
            A[n * i + k] = 0.0;
    }
}

/* x (n) the unit eigenvector of the n x n row-major M (n <= G6_MAXSPLIT) for its
 * eigenvalue nearest lam: inverse iteration (Golub & Van Loan 7.6.1) with the shift
 * a hair off lam (moved further if it hits an eigenvalue exactly), from a start with
 * no structure an eigenvector could be orthogonal to. */
static void inverse_iteration(const double *M, int n, double lam, double *x)
{
    double scale = fabs(lam);
    for (int i = 0; i < n * n; i++)
        scale = fabs(M[i]) > scale ? fabs(M[i]) : scale;
    double mu = lam + 1e-10 * scale;
    for (int i = 0; i < n; i++)
        x[i] = 1.0 + 0.3183098861837907 * i;
    for (int it = 0; it < 3; it++) {
        double A[G6_MAXSPLIT * G6_MAXSPLIT], b[G6_MAXSPLIT], nrm = 0.0;
        for (int i = 0; i < n * n; i++)
            A[i] = M[i];
        for (int i = 0; i < n; i++) {
            A[n * i + i] -= mu;
            b[i] = x[i];
        }
        if (!solve_dense(A, b, n)) {
            mu += 1e-8 * scale;
            continue;
        }
        for (int i = 0; i < n; i++)
            nrm += b[i] * b[i];
        nrm = sqrt(nrm);
        if (!(nrm > 0.0) || !isfinite(nrm))
            break;
        for (int i = 0; i < n; i++)
            x[i] = b[i] / nrm;
    }
}

/* det of the n x n row-major A (destroyed), LU with partial pivoting */
static double det_small(double *A, int n)
{
    double d = 1.0;
    for (int k = 0; k < n; k++) {
        int p = k;
        for (int i = k + 1; i < n; i++)
            if (fabs(A[n * i + k]) > fabs(A[n * p + k]))
                p = i;
        if (A[n * p + k] == 0.0)
            return 0.0;
        if (p != k) {
            for (int j = 0; j < n; j++) {
                double t = A[n * k + j];
                A[n * k + j] = A[n * p + j];
                A[n * p + j] = t;
            }
            d = -d;
        }
        d *= A[n * k + k];
        for (int i = k + 1; i < n; i++) {
            double f = A[n * i + k] / A[n * k + k];
            for (int j = k + 1; j < n; j++)
                A[n * i + j] -= f * A[n * k + j];
        }
    }
    return d;
}

/* The LU factorization with complete pivoting Pr A Pc = L U of a 12 x 12 row-major
 * A (Golub & Van Loan 3.4.8): the multipliers L (unit lower, row-major, zero above
 * the diagonal), U (upper), the row and column orders pr, pc (row i of Pr A is row
 * pr[i] of A), sign = sign(Pr) sign(Pc), piv = |U_kk|. An exactly zero pivot is
 * replaced by DBL_EPSILON times the first (a rank below 12: counted as null). */
typedef struct {
    double L[144], U[144], piv[12];
    int pr[12], pc[12], sign;
} G6Lu;

static void lu_complete(const double *A0, G6Lu *F)
{
    double *A = F->U, *L = F->L;
    memcpy(A, A0, sizeof(F->U));
    memset(L, 0, sizeof(F->L));
    F->sign = 1;
    for (int i = 0; i < 12; i++)
        F->pr[i] = F->pc[i] = i;
    for (int k = 0; k < 12; k++) {
        int bi = k, bj = k;
        double best = -1.0;
        for (int i = k; i < 12; i++)
            for (int j = k; j < 12; j++)
                if (fabs(A[12 * i + j]) > best) {
                    best = fabs(A[12 * i + j]);
                    bi = i;
                    bj = j;
                }
        if (bi != k) {
            for (int j = 0; j < 12; j++) {
                double t = A[12 * k + j];
                A[12 * k + j] = A[12 * bi + j];
                A[12 * bi + j] = t;
                t = L[12 * k + j];
                L[12 * k + j] = L[12 * bi + j];
                L[12 * bi + j] = t;
            }
            int t = F->pr[k];
            F->pr[k] = F->pr[bi];
            F->pr[bi] = t;
            F->sign = -F->sign;
        }
        if (bj != k) {
            for (int i = 0; i < 12; i++) {
                double t = A[12 * i + k];
                A[12 * i + k] = A[12 * i + bj];
                A[12 * i + bj] = t;
            }
            int t = F->pc[k];
            F->pc[k] = F->pc[bj];
            F->pc[bj] = t;
            F->sign = -F->sign;
        }
        double p = A[12 * k + k];
        if (p == 0.0)
            p = A[12 * k + k] = DBL_EPSILON * (k > 0 ? F->piv[0] : 1.0);
        F->piv[k] = fabs(p);
        for (int i = k + 1; i < 12; i++) {
            double f = A[12 * i + k] / p;
            L[12 * i + k] = f;
            A[12 * i + k] = 0.0;
            for (int j = k + 1; j < 12; j++)
                A[12 * i + j] -= f * A[12 * k + j];
        }
    }
}

/* The pencil A + s B (12 x 12 row-major, A of rank 12 - d, factored in F) near
 * s = 0. With m = 12 - d, the first m steps of F are a factorization Pr A Pc =
 * L' [U_11 U_12; 0 S] with L' = F's multipliers of those steps (identity below) and
 * S, zero to rounding, ignored (the later steps only reorder its rows and columns):
 *   V (d x 12): a basis of A's right null space, Pc [-U_11^-1 U_12; I];
 *   Y (d x 12): of its left null space, Pr^T L'^-T [0; I];
 *   G (d x d) = Y^T B V, the Schur complement of L'^-1 Pr B Pc on the null spaces;
 *   returns det(A + s B) / s^d at s = 0: sign(Pr) sign(Pc) det U_11 det G
 *   (Canny's generalized characteristic polynomial, lowest coefficient).
 * V, Y or G may be NULL. */
static double pencil_lowest(const G6Lu *F, const double *B, int d, double *V, double *Y,
                            double *G)
{
    const double *U = F->U, *L = F->L;
    const int m = 12 - d;
    double du = F->sign;
    for (int k = 0; k < m; k++)
        du *= U[12 * k + k];
    double X[12 * 12], Vl[12 * 12], Yl[12 * 12], BV[12 * 12], Gl[144];
    for (int c = 0; c < d; c++) /* X = -U_11^-1 U_12 (m x d) */
        for (int i = m - 1; i >= 0; i--) {
            double acc = -U[12 * i + m + c];
            for (int j = i + 1; j < m; j++)
                acc -= U[12 * i + j] * X[d * j + c];
            X[d * i + c] = acc / U[12 * i + i];
        }
    for (int c = 0; c < d; c++) {
        double *v = Vl + 12 * c, *y = Yl + 12 * c, w[12];
        for (int i = 0; i < 12; i++)
            v[F->pc[i]] = i < m ? X[d * i + c] : (i - m == c ? 1.0 : 0.0);
        for (int i = 11; i >= 0; i--) { /* L'^T w = e_{m + c} */
            double acc = i == m + c ? 1.0 : 0.0;
            if (i < m)
                for (int j = i + 1; j < 12; j++)
                    acc -= L[12 * j + i] * w[j];
            w[i] = acc;
        }
        for (int i = 0; i < 12; i++)
            y[F->pr[i]] = w[i];
        for (int i = 0; i < 12; i++) { /* B v */
            double acc = 0.0;
            for (int j = 0; j < 12; j++)
                acc += B[12 * i + j] * v[j];
            BV[12 * c + i] = acc;
        }
    }
    for (int r = 0; r < d; r++)
        for (int c = 0; c < d; c++) {
            double acc = 0.0;
            for (int i = 0; i < 12; i++)
                acc += Yl[12 * r + i] * BV[12 * c + i];
            Gl[d * r + c] = acc;
        }
    if (V != NULL)
        memcpy(V, Vl, sizeof(double) * 12 * d);
    if (Y != NULL)
        memcpy(Y, Yl, sizeof(double) * 12 * d);
    if (G != NULL)
        memcpy(G, Gl, sizeof(double) * d * d);
    return du * det_small(Gl, d);
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

/* Rows (dn, up) of the monomial shift along b (along_b) or c: y[up] = x y[dn] for
 * the monomial vector of (x_b, x_c), x its tangent of half the angle. Returns how
 * many (8 or 9). */
static int g6_shift_rows(int mult, int along_b, int *dn, int *up)
{
    int ni = mult == 0 ? 4 : 3, nj = mult == 0 ? 3 : 4, m = 0;
    for (int i = 0; i < ni; i++)
        for (int j = 0; j < nj; j++) {
            int i2 = i + along_b, j2 = j + !along_b;
            if (i2 >= ni || j2 >= nj)
                continue;
            dn[m] = nj * i + j;
            up[m] = nj * i2 + j2;
            m++;
        }
    return m;
}

/* The shift operator on the span of Y (k x 12 row-major, k <= 8): X (k x k
 * row-major) with F X = E in the least squares sense, E = (cos g U - sin g D) Y^T,
 * F = (sin g U + cos g D) Y^T (U, D the up and down rows). For a monomial vector
 * Y^T c whose half angle is g + delta, (cos delta E - sin delta F) c = 0, so c is an
 * eigenvector of X for tan(delta) (whatever else the span holds). The chart offset
 * g among 0, pi/4, pi/2, 3 pi/4 with the best conditioned F (its R's diagonal); 0
 * when F is rank deficient for every one. */
static int g6_shift_operator(const double *Y, int k, int mult, int along_b, double *X)
{
    int dn[9], up[9];
    const int m = g6_shift_rows(mult, along_b, dn, up);
    double best = 0.0, Fb[9 * G6_MAXSPLIT], Vb[9 * G6_MAXSPLIT], Eb[9 * G6_MAXSPLIT];
    double betab[G6_MAXSPLIT];
    for (int gi = 0; gi < 4; gi++) {
        const double cg = cos(0.25 * G6_PI * gi), sg = sin(0.25 * G6_PI * gi);
        double F[9 * G6_MAXSPLIT], E[9 * G6_MAXSPLIT], V[9 * G6_MAXSPLIT], beta[G6_MAXSPLIT];
        for (int j = 0; j < k; j++) /* column-major, column j */
            for (int i = 0; i < m; i++) {
                double u = Y[12 * j + up[i]], d = Y[12 * j + dn[i]];
                F[m * j + i] = sg * u + cg * d;
                E[m * j + i] = cg * u - sg * d;
            }
        house_qr(F, m, k, V, beta);
        double rmin = INFINITY, rmax = 0.0;
        for (int j = 0; j < k; j++) {
            double r = fabs(F[m * j + j]);
            rmin = r < rmin ? r : rmin;
            rmax = r > rmax ? r : rmax;
        }
        double cond = rmax > 0.0 ? rmin / rmax : 0.0;
        if (cond > best) {
            best = cond;
            memcpy(Fb, F, sizeof(F));
            memcpy(Vb, V, sizeof(V));
            memcpy(Eb, E, sizeof(E));
            memcpy(betab, beta, sizeof(beta));
        }
    }
    if (!(best > 1e-12))
        return 0;
    for (int j = 0; j < k; j++) { /* column j of X: R x = (Q^T E)_j */
        double *e = Eb + m * j;
        house_apply_t(Vb, betab, m, k, e);
        for (int i = k - 1; i >= 0; i--) {
            double acc = e[i];
            for (int c = i + 1; c < k; c++)
                acc -= Fb[m * c + i] * X[k * c + j];
            X[k * i + j] = acc / Fb[m * i + i];
        }
    }
    return 1;
}

/* The solutions (t_b, t_c) in the span of Y (k x 12 row-major, 2 <= k <= 8), the
 * null space where k solutions share theta_a (Moller & Stetter 1995; Manocha &
 * Canny 1994, 5.2): each is a common eigenvector c of the shift operators along b
 * and c, so an eigenvector of X_b + rho X_c (rho generic), read as half angles of
 * Y^T c. Every eigenvalue gives a candidate (complex ones their real part: two
 * solutions nearly sharing both angles); the spurious ones fail the Newton polish.
 * Returns how many went to tb, tc. */
static int g6_split(const double *Y, int k, int mult, double *tb, double *tc)
{
    const double rho = 0.6180339887498949;
    double Xb[G6_MAXSPLIT * G6_MAXSPLIT], Xc[G6_MAXSPLIT * G6_MAXSPLIT];
    double M[G6_MAXSPLIT * G6_MAXSPLIT], H[G6_MAXSPLIT * G6_MAXSPLIT];
    double wr[G6_MAXSPLIT], wi[G6_MAXSPLIT];
    int ob = g6_shift_operator(Y, k, mult, 1, Xb), oc = g6_shift_operator(Y, k, mult, 0, Xc);
    if (!ob && !oc)
        return 0;
    for (int i = 0; i < k * k; i++)
        M[i] = (ob ? Xb[i] : 0.0) + (oc ? rho * Xc[i] : 0.0);
    memcpy(H, M, sizeof(double) * k * k);
    hessenberg(H, k);
    if (!hqr(H, k, wr, wi))
        return 0;
    int n = 0;
    for (int e = 0; e < k; e++) {
        if (wi[e] < 0.0)
            continue; /* the conjugate's twin */
        double x[G6_MAXSPLIT], z[12];
        inverse_iteration(M, k, wr[e], x);
        for (int i = 0; i < 12; i++) {
            double acc = 0.0;
            for (int j = 0; j < k; j++)
                acc += x[j] * Y[12 * j + i];
            z[i] = acc;
        }
        tb[n] = g6_half_angle(z, mult, 1);
        tc[n] = g6_half_angle(z, mult, 0);
        n++;
    }
    return n;
}
/* What the back-substitution of one variant and pose needs. */
typedef struct {
    const double *vb, *Tp, *Q, *V8, *beta8, *A8;
    int a, dir, mult;
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

/* ------------------------------------------------ one variant at one pose */

/* A variant at a pose: the right side, its 14 x 8 block's QR and left null space,
 * the dialytic matrices Sigma(theta) = s S[0] + c S[1] + S[2]. */
typedef struct {
    const double *vb;
    int dir, a, mult;
    double Tp[16], k6inv[16];
    double Q[14 * 9], A8[8 * 14], V8[8 * 14], beta8[8];
    double Nn[6][14];
    double rowscale[6]; /* the 6 equations' equilibration */
    double rcond;       /* the right side's block: smallest / largest |R_kk| */
    double S[3][144];
} G6Var;

/* The projection's data (degenerate poses): Sigma's derivative along the pose motion
 * and the dimension d of Sigma's generic null space. */
typedef struct {
    int d;
    double Sd[3][144];
} G6Proj;

/* The 6 eliminated equations (6 x 27) in {s, c, 1} (x) the 9 monomials of (x_b, x_c):
 * Na [P_s | P_c | P_1 - q (x) h] with q = Na qa + Nb qb (Nb may be NULL) and
 * h = (1 + x_b^2)(1 + x_c^2): N P' for Sigma, and its derivative dN P' + N dP'. */
static void g6_rows(const double *Pm, const double (*Na)[14], const double (*Nb)[14],
                    const double *qa, const double *qb, double (*Mx)[27])
{
    static const double h9[9] = {1, 0, 1, 0, 0, 0, 1, 0, 1};
    for (int r = 0; r < 6; r++) {
        double nq = 0.0;
        for (int e = 0; e < 14; e++)
            nq += Na[r][e] * qa[e] + (Nb != NULL ? Nb[r][e] * qb[e] : 0.0);
        for (int m = 0; m < 18; m++)
            Mx[r][m] = 0.0;
        for (int m = 0; m < 9; m++)
            Mx[r][18 + m] = -nq * h9[m];
        for (int blk = 0; blk < 3; blk++)
            for (int e = 0; e < 14; e++) {
                double f = Na[r][e];
                for (int m = 0; m < 9; m++)
                    Mx[r][9 * blk + m] += f * Pm[126 * blk + 9 * e + m];
            }
    }
}

/* Sigma's three 12 x 12 blocks from the equations Mx (rows divided by scale): the
 * 6 equations, then the same multiplied by x_b (mult 0) or x_c (mult 1). */
static void g6_layout(const double (*Mx)[27], const double *scale, int mult, double (*S)[144])
{
    memset(S, 0, 3 * 144 * sizeof(double));
    for (int blk = 0; blk < 3; blk++)
        for (int r = 0; r < 6; r++)
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++) {
                    double x = Mx[r][9 * blk + 3 * i + j] / scale[r];
                    S[blk][12 * r + g6_col(mult, 0, i, j)] = x;
                    S[blk][12 * (6 + r) + g6_col(mult, 1, i, j)] = x;
                }
}

/* Sigma(theta) (12 x 12 row-major) of the blocks S */
static void g6_sigma_at(const double (*S)[144], double th, double *A)
{
    double s = sin(th), c = cos(th);
    for (int i = 0; i < 144; i++)
        A[i] = s * S[0][i] + c * S[1][i] + S[2][i];
}

/* The reciprocal condition number of the 8 x 8 upper triangular R (column-major in
 * a 14 x 8 array, R_ij = A[14 j + i]): its smallest singular value by three steps of
 * inverse iteration on R^T R, over its largest column norm (the diagonal of an
 * unpivoted QR does not reveal a near rank deficiency). */
static double g6_rcond8(const double *A)
{
    double x[8], y[8], big = 0.0;
    for (int j = 0; j < 8; j++) {
        double c = 0.0;
        for (int i = 0; i <= j; i++)
            c += A[14 * j + i] * A[14 * j + i];
        big = c > big ? c : big;
        x[j] = 1.0 + 0.3183098861837907 * j;
    }
    double nrm = 0.0;
    for (int it = 0; it < 3; it++) {
        for (int i = 0; i < 8; i++) { /* R^T y = x */
            double acc = x[i];
            for (int k = 0; k < i; k++)
                acc -= A[14 * i + k] * y[k];
            y[i] = acc / A[14 * i + i];
        }
        for (int i = 7; i >= 0; i--) { /* R x = y */
            double acc = y[i];
            for (int k = i + 1; k < 8; k++)
                acc -= A[14 * k + i] * x[k];
            x[i] = acc / A[14 * i + i];
        }
        nrm = 0.0;
        for (int i = 0; i < 8; i++)
            nrm += x[i] * x[i];
        nrm = sqrt(nrm);
        if (!(nrm > 0.0) || !isfinite(nrm))
            return 0.0;
        for (int i = 0; i < 8; i++)
            x[i] /= nrm;
    }
    return sqrt(1.0 / nrm) / sqrt(big); /* |(R^T R)^-1 x| -> 1 / sigma_min^2 */
}

/* Variant vb at pose T (4x4 row-major) into V; 0 when its right side's 14 x 8 block
 * is rank deficient or an equation vanishes (the elimination does not apply). */
static int g6_prepare(const double *vb, const double *T, G6Var *V)
{
    double tmp[16];
    V->vb = vb;
    V->dir = (int)vb[VB_DIR];
    V->a = (int)vb[VB_A];
    V->mult = (int)vb[VB_MULT];
    if (V->dir)
        rigid_inv(T, V->Tp);
    else
        memcpy(V->Tp, T, sizeof(V->Tp));
    mul4(vb + VB_CI, V->Tp, tmp);                /* C'_0^-1 T' */
    mul4(tmp, vb + VB_CI + 16 * 6, V->k6inv);    /* ... C'_6^-1 = K_6^-1 */
    g6_right(vb, V->a, V->k6inv, V->Q);
    for (int j = 0; j < 8; j++)
        for (int i = 0; i < 14; i++)
            V->A8[14 * j + i] = V->Q[9 * i + j];
    house_qr(V->A8, 14, 8, V->V8, V->beta8);
    double rmax = 0.0, rmin = INFINITY;
    for (int k = 0; k < 8; k++) {
        double d = fabs(V->A8[14 * k + k]);
        rmax = d > rmax ? d : rmax;
        rmin = d < rmin ? d : rmin;
    }
    if (!(rmin > 1e-12 * rmax))
        return 0;
    V->rcond = g6_rcond8(V->A8);
    /* the left null space N (6 x 14): rows 8..13 of Q^T, i.e. H_0 .. H_7 e_r */
    for (int r = 0; r < 6; r++) {
        double *x = V->Nn[r];
        for (int i = 0; i < 14; i++)
            x[i] = i == 8 + r ? 1.0 : 0.0;
        for (int k = 7; k >= 0; k--) {
            const double *v = V->V8 + 14 * k;
            double s = 0.0;
            for (int i = k; i < 14; i++)
                s += v[i] * x[i];
            s *= V->beta8[k];
            for (int i = k; i < 14; i++)
                x[i] -= s * v[i];
        }
    }
    double q9[14], Mx[6][27];
    for (int e = 0; e < 14; e++)
        q9[e] = V->Q[9 * e + 8];
    g6_rows(vb + VB_P, (const double (*)[14])V->Nn, NULL, q9, NULL, Mx);
    for (int r = 0; r < 6; r++) { /* equilibrate the 6 equations */
        double mx = 0.0;
        for (int col = 0; col < 27; col++)
            mx = fabs(Mx[r][col]) > mx ? fabs(Mx[r][col]) : mx;
        if (!(mx > 0.0))
            return 0;
        V->rowscale[r] = mx;
    }
    g6_layout((const double (*)[27])Mx, V->rowscale, V->mult, V->S);
    return 1;
}

/* C = A B for 4x4 row-major matrices (general: the last rows may be anything) */
static void mul4g(const double *A, const double *B, double *C)
{
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) {
            double acc = 0.0;
            for (int k = 0; k < 4; k++)
                acc += A[4 * r + k] * B[4 * k + c];
            C[4 * r + c] = acc;
        }
}

/* The twist matrix [w]x, v of xi = (w, v) (4x4 row-major, last row 0) */
static void g6_twist(const double *w, const double *v, double *X)
{
    double Xm[16] = {0.0, -w[2], w[1], v[0], w[2], 0.0, -w[0], v[1],
                     -w[1], w[0], 0.0, v[2], 0.0, 0.0, 0.0, 0.0};
    memcpy(X, Xm, sizeof(Xm));
}

/* pj->Sd = d Sigma / ds at s = 0 for the pose T Exp(s xi) (G6_XI, its translation
 * times scale), exactly: the right side Q is a polynomial of degree 3 in the entries
 * of K_6^-1, so the five-point central difference of Q is exact up to rounding; the
 * left null space moves by dN = -N dQ_8 Q_8^+ (first order; any smooth choice of
 * basis changes det Sigma by a factor that does not vanish); the equations' scales
 * stay those of Sigma. */
static void g6_derivative(const G6Var *V, double scale, G6Proj *pj)
{
    double X[16], dTp[16], tmp[16], dk6[16];
    double v[3] = {G6_XI[3] * scale, G6_XI[4] * scale, G6_XI[5] * scale};
    g6_twist(G6_XI, v, X);
    if (V->dir) { /* T' = (T Exp(s xi))^-1 = Exp(-s xi) T^-1 */
        mul4g(X, V->Tp, dTp);
        for (int i = 0; i < 16; i++)
            dTp[i] = -dTp[i];
    } else {
        mul4g(V->Tp, X, dTp);
    }
    mul4g(V->vb + VB_CI, dTp, tmp);
    mul4g(tmp, V->vb + VB_CI + 16 * 6, dk6);
    double big = 0.0, dbig = 0.0;
    for (int i = 0; i < 12; i++) {
        big = fabs(V->k6inv[i]) > big ? fabs(V->k6inv[i]) : big;
        dbig = fabs(dk6[i]) > dbig ? fabs(dk6[i]) : dbig;
    }
    const double h = dbig > 0.0 ? 0.25 * big / dbig : 1.0;
    double Qs[4][14 * 9], dQ[14 * 9];
    static const double steps[4] = {1.0, -1.0, 2.0, -2.0};
    for (int k = 0; k < 4; k++) {
        double K[16];
        for (int i = 0; i < 16; i++)
            K[i] = V->k6inv[i] + steps[k] * h * dk6[i];
        g6_right(V->vb, V->a, K, Qs[k]);
    }
    for (int i = 0; i < 14 * 9; i++)
        dQ[i] = (8.0 * (Qs[0][i] - Qs[1][i]) - (Qs[2][i] - Qs[3][i])) / (12.0 * h);
    /* dN_r = -(H [z; 0])^T with z R = N_r dQ_8 (R the 8 x 8 factor of Q_8 = H R) */
    double dN[6][14];
    for (int r = 0; r < 6; r++) {
        double w[8], x[14];
        for (int c = 0; c < 8; c++) {
            double acc = 0.0;
            for (int e = 0; e < 14; e++)
                acc += V->Nn[r][e] * dQ[9 * e + c];
            w[c] = acc;
        }
        for (int j = 0; j < 8; j++) {
            double acc = w[j];
            for (int i = 0; i < j; i++)
                acc -= x[i] * V->A8[14 * j + i];
            x[j] = acc / V->A8[14 * j + j];
        }
        for (int i = 8; i < 14; i++)
            x[i] = 0.0;
        for (int k = 7; k >= 0; k--) {
            const double *hv = V->V8 + 14 * k;
            double s = 0.0;
            for (int i = k; i < 14; i++)
                s += hv[i] * x[i];
            s *= V->beta8[k];
            for (int i = k; i < 14; i++)
                x[i] -= s * hv[i];
        }
        for (int i = 0; i < 14; i++)
            dN[r][i] = -x[i];
    }
    double q9[14], dq9[14], M1[6][27];
    for (int e = 0; e < 14; e++) {
        q9[e] = V->Q[9 * e + 8];
        dq9[e] = dQ[9 * e + 8];
    }
    g6_rows(V->vb + VB_P, (const double (*)[14])dN, (const double (*)[14])V->Nn, q9, dq9,
            M1);
    g6_layout((const double (*)[27])M1, V->rowscale, V->mult, pj->Sd);
}

/* From 24 samples D_k = f(2 pi k / 24) of a trigonometric polynomial f of degree 8:
 * its DFT, the relative tail above degree 8 (*tail, which must vanish) and the
 * degree-16 polynomial cpoly in x = tan((theta - phi) / 2) whose roots are f's,
 * phi + pi the sample of largest |f| (cpoly's leading coefficient is f there).
 * Returns the index of that sample, or -1 when f vanishes or is not finite. */
static int g6_trig_poly(const double *D, double *cpoly, double *phi, double *tail)
{
    int jbest = 0;
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
    *tail = INFINITY;
    if (!(head > 0.0) || !isfinite(head))
        return -1;
    *tail = tl / head;
    const double ph = G6_TWO_PI * jbest / G6_NSAMP - G6_PI;
    double zr[G6_DEG + 1], zi[G6_DEG + 1];
    for (int f = 1; f <= G6_DEG; f++) { /* the DFT rotated by phi */
        double cf = cos(f * ph), sf = sin(f * ph);
        zr[f] = dr[f] * cf - di[f] * sf;
        zi[f] = dr[f] * sf + di[f] * cf;
    }
    for (int j = 0; j <= 16; j++) {
        double acc = dr[0] * g6_er[8][j];
        for (int f = 1; f <= G6_DEG; f++)
            acc += 2.0 * (zr[f] * g6_er[8 + f][j] - zi[f] * g6_ei[8 + f][j]);
        cpoly[j] = acc;
    }
    *phi = ph;
    return jbest;
}

/* The roots theta of cpoly that are real or within imag_tol of it, in [-pi, pi),
 * sorted, each with a weight (2 for a complex pair: a possible pair of close real
 * roots, how a double root comes out of rounding; else 1) and near[i]: the root may
 * be part of a multiple root spread by rounding (by eps^(1/k) for a k-fold one): it
 * is complex, or another root lies within gap, or a complex root close to the axis
 * (imaginary part of theta below 0.25) lies within 0.15 rad. cx (NULL: not asked)
 * gets the G6_NEAR non-real pairs closest to the axis, nearest first, as (imaginary
 * part of theta > 0, its real part in [-pi, pi)), INFINITY where there are fewer:
 * a pair of real roots is born or dies where a pair's imaginary part passes 0
 * (issue 29: an island of a self-motion between two held values). Returns how many,
 * or -1 when the eigenvalue iteration fails. */
static int g6_real_roots(const double *cpoly, int jbest, double phi, double imag_tol,
                         double gap, double *ths, int *wts, int *near, double *cx)
{
    double wr[16], wi[16], re[16];
    if (!all_roots16(cpoly, jbest, wr, wi))
        return -1;
    int nn = 0, nr = 0, nx = 0;
    for (int k = 0; k < 16; k++) { /* complex roots close to the axis */
        double z2 = wr[k] * wr[k] + wi[k] * wi[k], ia = 2.0 * fabs(wi[k]) / (1.0 + z2);
        if (wi[k] > 0.0 && ia < 0.25)
            re[nn++] = phi + 2.0 * atan(wr[k]);
        if (cx == NULL || !(wi[k] > 0.0))
            continue;
        /* theta = phi + 2 atan(x), x = a + i b: Im = atanh(2 b / (1 + |x|^2)),
         * Re = phi + atan2(2 a, 1 - |x|^2); kept sorted by Im (insertion) */
        double im = atanh(fmin(ia, 1.0 - DBL_EPSILON)),
               th = wrap_pi(phi + atan2(2.0 * wr[k], 1.0 - z2));
        int i = nx < G6_NEAR ? nx++ : G6_NEAR;
        if (i == G6_NEAR && !(im < cx[2 * (G6_NEAR - 1)]))
            continue;
        i = i == G6_NEAR ? G6_NEAR - 1 : i;
        for (; i > 0 && cx[2 * (i - 1)] > im; i--) {
            cx[2 * i] = cx[2 * (i - 1)];
            cx[2 * i + 1] = cx[2 * (i - 1) + 1];
        }
        cx[2 * i] = im;
        cx[2 * i + 1] = th;
    }
    for (int i = nx; cx != NULL && i < G6_NEAR; i++)
        cx[2 * i] = cx[2 * i + 1] = INFINITY;
    for (int k = 0; k < 16; k++) {
        if (wi[k] < 0.0)
            continue; /* the conjugate's twin */
        double z2 = wr[k] * wr[k] + wi[k] * wi[k];
        if (!(2.0 * fabs(wi[k]) / (1.0 + z2) <= imag_tol))
            continue;
        double th = wrap_pi(phi + 2.0 * atan(wr[k]));
        int w = wi[k] != 0.0 ? 2 : 1, i = nr++, nb = w > 1;
        for (int j = 0; j < nn && !nb; j++) /* a complex one near, not itself */
            nb = fabs(wrap_pi(re[j] - th)) < 0.15 && !(w > 1 && fabs(wrap_pi(re[j] - th)) < 1e-12);
        for (; i > 0 && ths[i - 1] > th; i--) {
            ths[i] = ths[i - 1];
            wts[i] = wts[i - 1];
            near[i] = near[i - 1];
        }
        ths[i] = th;
        wts[i] = w;
        near[i] = nb;
    }
    for (int i = 0; i < nr; i++) /* neighbours within the gap (around the circle too) */
        for (int j = 0; j < nr; j++)
            if (i != j && fabs(wrap_pi(ths[i] - ths[j])) < gap)
                near[i] = 1;
    return nr;
}

/* The same roots as eigenvalues (Manocha & Canny 1994, section 5): with t = theta -
 * phi, x = tan(t / 2), (1 + x^2) Sigma = x^2 M2 + x M1 + M0 (M2 = Sigma(phi + pi),
 * the best conditioned sample, invertible), and its roots are the eigenvalues of the
 * companion matrix [[0, I], [-M2^-1 M0, -M2^-1 M1]] (24 x 24; 8 of them at x = +-i,
 * dropped by the imaginary-part rule). Where k solutions share theta_a with a
 * k-dimensional null space the eigenvalue is semi-simple and comes out to rounding,
 * where the determinant's k-fold root spreads by eps^(1/k): run where the
 * determinant's roots cluster. Sorted and weighted as g6_real_roots; -1 when M2 is
 * singular or hqr fails. */
static int g6_eig_roots(const double (*S)[144], double phi, double imag_tol, double *ths,
                        int *wts)
{
    const double cp = cos(phi), sp = sin(phi);
    double M2[144], R[12 * 24], E[24 * 24], wr[24], wi[24];
    for (int i = 0; i < 144; i++) {
        double a = cp * S[0][i] - sp * S[1][i], b = sp * S[0][i] + cp * S[1][i];
        M2[i] = S[2][i] - b;
        R[24 * (i / 12) + (i % 12)] = b + S[2][i]; /* M0 | M1, 12 x 24 row-major */
        R[24 * (i / 12) + 12 + (i % 12)] = 2.0 * a;
    }
    /* R <- M2^-1 [M0 M1]: LU with partial pivoting, 24 right-hand sides */
    for (int k = 0; k < 12; k++) {
        int p = k;
        for (int i = k + 1; i < 12; i++)
            if (fabs(M2[12 * i + k]) > fabs(M2[12 * p + k]))
                p = i;
        if (M2[12 * p + k] == 0.0)
            return -1;
        if (p != k) {
            for (int j = 0; j < 12; j++) {
                double t = M2[12 * k + j];
                M2[12 * k + j] = M2[12 * p + j];
                M2[12 * p + j] = t;
            }
            for (int j = 0; j < 24; j++) {
                double t = R[24 * k + j];
                R[24 * k + j] = R[24 * p + j];
                R[24 * p + j] = t;
            }
        }
        for (int i = k + 1; i < 12; i++) {
            double f = M2[12 * i + k] / M2[12 * k + k];
            for (int j = k + 1; j < 12; j++)
                M2[12 * i + j] -= f * M2[12 * k + j];
            for (int j = 0; j < 24; j++)
                R[24 * i + j] -= f * R[24 * k + j];
        }
    }
    for (int k = 11; k >= 0; k--)
        for (int j = 0; j < 24; j++) {
            double acc = R[24 * k + j];
            for (int c = k + 1; c < 12; c++)
                acc -= M2[12 * k + c] * R[24 * c + j];
            R[24 * k + j] = acc / M2[12 * k + k];
        }
    memset(E, 0, sizeof(E));
    for (int i = 0; i < 12; i++) {
        E[24 * i + 12 + i] = 1.0;
        for (int j = 0; j < 24; j++)
            E[24 * (12 + i) + j] = -R[24 * i + j];
    }
    balance(E, 24);
    hessenberg(E, 24);
    if (!hqr(E, 24, wr, wi))
        return -1;
    int nr = 0;
    for (int k = 0; k < 24 && nr < G6_MAXROOT; k++) {
        if (wi[k] < 0.0)
            continue;
        double z2 = wr[k] * wr[k] + wi[k] * wi[k];
        if (!(2.0 * fabs(wi[k]) / (1.0 + z2) <= imag_tol))
            continue;
        double th = wrap_pi(phi + 2.0 * atan(wr[k]));
        int w = wi[k] != 0.0 ? 2 : 1, i = nr++;
        for (; i > 0 && ths[i - 1] > th; i--) {
            ths[i] = ths[i - 1];
            wts[i] = wts[i - 1];
        }
        ths[i] = th;
        wts[i] = w;
    }
    return nr;
}

/* Orthonormalize the k rows of Z (k x 12) in place (modified Gram-Schmidt), dropping
 * rows that are (nearly) in the span of the previous ones; returns how many remain. */
static int g6_orthonormal(double *Z, int k)
{
    int n = 0;
    for (int j = 0; j < k; j++) {
        double *z = Z + 12 * j, n0 = 0.0, nrm = 0.0;
        for (int i = 0; i < 12; i++)
            n0 += z[i] * z[i];
        for (int p = 0; p < n; p++) {
            const double *y = Z + 12 * p;
            double t = 0.0;
            for (int i = 0; i < 12; i++)
                t += y[i] * z[i];
            for (int i = 0; i < 12; i++)
                z[i] -= t * y[i];
        }
        for (int i = 0; i < 12; i++)
            nrm += z[i] * z[i];
        if (!(nrm > 1e-20 * n0) || !(nrm > 0.0))
            continue;
        nrm = 1.0 / sqrt(nrm);
        double *o = Z + 12 * n;
        for (int i = 0; i < 12; i++)
            o[i] = z[i] * nrm;
        n++;
    }
    return n;
}

/* The dimension of a null space from the |diagonal| r[0..n-1] (non-increasing) of a
 * rank-revealing factorization: the most trailing directions (at most kmax) that
 * lie below a gap (a ratio above 1e3) and below tiny r[0]; 0 when there is no such
 * gap (a larger space is safe: the split keeps every solution it holds). Near a multiple root or a degenerate pose the null directions are small
 * but not at rounding level, so a fixed threshold would cut them. */
static int g6_nullity(const double *r, int n, int kmax, double tiny)
{
    int k = 0;
    for (int j = 1; j <= kmax && j < n; j++) {
        const int i = n - j;
        if (r[i] < tiny * r[0] && r[i - 1] > 1e3 * r[i])
            k = j;
    }
    return k;
}

/* Projected mode: an orthonormal basis Z (k' x 12, k' <= k) of the monomial vectors
 * the projection allows at theta: in the right null space of Sigma_0(theta) (its
 * dimension dl >= d: more where the rank drops further, counted from the pivots
 * below null_tol of the largest) and there in the null space of the Schur
 * complement G = Y^T Sigma_1 V (its k smallest directions). Returns k'. */
static int g6_proj_basis(const G6Var *V, const G6Proj *pj, double th, int k, double null_tol,
                         double *Z)
{
    double A[144], B[144], Vn[12 * 12], G[144], C[144], r[12];
    G6Lu F;
    g6_sigma_at((const double (*)[144])V->S, th, A);
    g6_sigma_at((const double (*)[144])pj->Sd, th, B);
    lu_complete(A, &F);
    int dl = pj->d;
    for (int i = 1; i < 12 - pj->d; i++)
        if (F.piv[i] < null_tol * F.piv[0] && dl < G6_MAXSPLIT)
            dl++;
    pencil_lowest(&F, B, dl, Vn, NULL, G);
    int kk = k < dl ? k : dl;
    null_basis(G, dl, kk, C, r);
    for (int j = 0; j < kk; j++)
        for (int i = 0; i < 12; i++) {
            double acc = 0.0;
            for (int c = 0; c < dl; c++)
                acc += C[dl * j + c] * Vn[12 * c + i];
            Z[12 * j + i] = acc;
        }
    return g6_orthonormal(Z, kk);
}

/* Candidates from one theta and a basis Z (k x 12) of the monomial vectors there:
 * the vector itself (k = 1) or the split of the span; appended to cand (at most
 * room), slow marks those from a multiple root. Returns how many. */
static int g6_from_basis(const G6Back *G, double th, const double *Z, int k, int slow,
                         G6Cand *cand, int room)
{
    double tb[G6_MAXSPLIT], tc[G6_MAXSPLIT];
    int n = 0, nc = 0;
    if (k == 1) {
        tb[0] = g6_half_angle(Z, G->mult, 1);
        tc[0] = g6_half_angle(Z, G->mult, 0);
        n = 1;
    } else if (k > 1) {
        n = g6_split(Z, k, G->mult, tb, tc);
    }
    const double s = sin(th), c = cos(th);
    for (int i = 0; i < n && nc < room; i++) {
        cand[nc].slow = slow;
        nc += g6_candidate(G, th, s, c, tb[i], tc[i], cand + nc);
    }
    return nc;
}

/* Back-substitution of the roots ths (sorted, weights wts) of one variant: every
 * root alone (Sigma's null vector; projected: the projection's; where its null space
 * has dimension k >= 2, also its split), then every cluster of roots closer than
 * GP_PAIR_GAP (complex ones count twice) or with a null space of dimension k >= 2,
 * split at its centroid. Flags get G6F_CLUSTER; stats[1] the
 * smallest ratio of Sigma's second-smallest to largest pivot over the roots, stats[2]
 * the clusters split. Returns the candidates appended to cand. */
static int g6_back(const G6Var *V, const G6Proj *pj, const double *P, const double *ths,
                   const int *wts, const int *near, int nr, G6Cand *cand, int *flags,
                   double *stats)
{
    const double null_tol = P[GP_NULL_TOL], gap = P[GP_PAIR_GAP];
    G6Back G = {V->vb, V->Tp, V->Q, V->V8, V->beta8, V->A8, V->a, V->dir, V->mult};
    double Z[12 * 12], r[12];
    int nc = 0, nul[G6_MAXROOT], lab[G6_MAXROOT];
    if (pj == NULL) {
        for (int k0 = 0; k0 < nr; k0 += W) { /* W roots at a time for the null vectors */
            vd sv, cv, yv[12], rv[12];
            for (int l = 0; l < W; l++) {
                double th = ths[k0 + l < nr ? k0 + l : k0];
                sv[l] = sin(th);
                cv[l] = cos(th);
            }
            null_vector12_lanes((const double (*)[144])V->S, sv, cv, yv, rv);
            for (int l = 0; l < W && k0 + l < nr; l++) {
                double y[12], margin = rv[10][l] / rv[0][l];
                if (near[k0 + l] && margin < G6_MULTI_TOL)
                    *flags |= G6F_MULTI; /* near others, a second small pivot */
                for (int i = 0; i < 12; i++)
                    y[i] = yv[i][l];
                stats[1] = margin < stats[1] ? margin : stats[1];
                double rl[12];
                for (int i = 0; i < 12; i++)
                    rl[i] = rv[i][l];
                nul[k0 + l] = g6_nullity(rl, 12, G6_MAXSPLIT, null_tol);
                nul[k0 + l] = nul[k0 + l] < 1 ? 1 : nul[k0 + l];
                nc += g6_from_basis(&G, ths[k0 + l], y, 1, 0, cand + nc, G6_VARCAND - nc);
                if (nul[k0 + l] > 1) { /* solutions sharing this theta: split here too
                                        * (a cluster's centroid may be off it) */
                    double A[144];
                    g6_sigma_at((const double (*)[144])V->S, ths[k0 + l], A);
                    null_basis(A, 12, nul[k0 + l], Z, r);
                    nc += g6_from_basis(&G, ths[k0 + l], Z, nul[k0 + l], 1, cand + nc,
                                        G6_VARCAND - nc);
                }
            }
        }
    } else {
        for (int i = 0; i < nr; i++) {
            int k = g6_proj_basis(V, pj, ths[i], 1, null_tol, Z);
            nul[i] = 1;
            nc += g6_from_basis(&G, ths[i], Z, k, 0, cand + nc, G6_VARCAND - nc);
        }
    }
    /* clusters: chains of neighbours closer than the gap (around the circle too) */
    int ncl = 0;
    for (int i = 0; i < nr; i++)
        lab[i] = i > 0 && ths[i] - ths[i - 1] < gap ? lab[i - 1] : ncl++;
    if (ncl > 1 && ths[0] + G6_TWO_PI - ths[nr - 1] < gap)
        for (int i = 0; i < nr; i++)
            lab[i] = lab[i] == ncl - 1 ? 0 : lab[i];
    for (int c = 0; c < ncl; c++) {
        int weight = 0, k = 0;
        double sx = 0.0, sy = 0.0;
        for (int i = 0; i < nr; i++)
            if (lab[i] == c) {
                weight += wts[i];
                k = nul[i] > k ? nul[i] : k;
                sx += wts[i] * cos(ths[i]);
                sy += wts[i] * sin(ths[i]);
            }
        if (pj == NULL && weight == 1 && k > 1)
            *flags |= G6F_NOISY; /* a simple root with a 2-D null space */
        k = weight > k ? weight : k;
        if (k < 2)
            continue;
        const double th = atan2(sy, sx);
        k = k < G6_MAXSPLIT ? k : G6_MAXSPLIT;
        *flags |= G6F_CLUSTER;
        stats[2] += 1.0;
        if (pj == NULL) {
            double A[144];
            g6_sigma_at((const double (*)[144])V->S, th, A);
            null_basis(A, 12, G6_MAXSPLIT, Z, r);
            /* the null space's dimension at the centroid (off the multiple root by
             * about the roots' spread: looser) */
            int n0 = g6_nullity(r, 12, G6_MAXSPLIT, 1e-4);
            k = n0 > k ? n0 : k;
        } else {
            k = g6_proj_basis(V, pj, th, k, null_tol, Z);
        }
        nc += g6_from_basis(&G, th, Z, k, 1, cand + nc, G6_VARCAND - nc);
    }
    return nc;
}

/* Candidate chain values of one variant for the pose T (4x4 row-major), appended to
 * cand (at most G6_VARCAND); project: through the projection (a degenerate pose).
 * flags get G6F_DEGENERATE (the right side is rank deficient, the determinant or
 * the projection vanishes, or the root finder fails) and G6F_CLUSTER; stats[0] the
 * relative DFT tail, stats[1], stats[2] as g6_back. Returns the candidates. */
static int g6_variant(const double *P, const double *vb, const double *T, int project,
                      G6Cand *cand, int *flags, double *stats)
{
    const double tail_tol = P[GP_TAIL_TOL];
    G6Var V;
    G6Proj pj;
    double D[G6_NSAMP], cpoly[17], phi = 0.0, tail = INFINITY;
    int jbest = -1;
    stats[0] = stats[1] = INFINITY;
    stats[2] = 0.0;
    if (!project)
        for (int i = 4; i < G6_NSTATS; i++)
            stats[i] = INFINITY;
    if (!g6_prepare(vb, T, &V)) {
        *flags |= G6F_DEGENERATE;
        return 0;
    }
    if (!project) {
        double ratio[G6_NSAMP], rmax = 0.0;
        for (int k = 0; k < G6_NSAMP; k += W)
            det12_lanes((const double (*)[144])V.S, k, D, ratio);
        for (int k = 0; k < G6_NSAMP; k++)
            rmax = ratio[k] > rmax ? ratio[k] : rmax;
        jbest = g6_trig_poly(D, cpoly, &phi, &tail);
        /* noisy: near a degenerate pose (a noisy determinant, Sigma nearly singular
         * at every sample) or a right side nearly rank deficient (u, w badly
         * determined by the back-substitution) */
        if (tail > P[GP_NEAR_TAIL] || rmax < 1e-5 || V.rcond < 1e-6)
            *flags |= G6F_NOISY;
    } else {
        /* c_d at the samples, d the smallest null space seen (pivots below 1e-5 of
         * the largest: near a degenerate pose they are ~ its distance, and the
         * coefficients below d are that small, with their roots spread by rounding),
         * else the first of d - 1, d + 1, d + 2 whose polynomial has no tail */
        double A[144], B[G6_NSAMP][144];
        G6Lu F[G6_NSAMP];
        int d0 = 12;
        g6_derivative(&V, P[GP_SCALE], &pj);
        for (int k = 0; k < G6_NSAMP; k++) {
            double th = G6_TWO_PI * k / G6_NSAMP;
            int dk = 0;
            g6_sigma_at((const double (*)[144])V.S, th, A);
            g6_sigma_at((const double (*)[144])pj.Sd, th, B[k]);
            lu_complete(A, &F[k]);
            for (int i = 11; i > 0 && F[k].piv[i] < 1e-5 * F[k].piv[0]; i--)
                dk++;
            d0 = dk < d0 ? dk : d0;
        }
        d0 = d0 < 1 ? 1 : d0;
        const int tries[4] = {d0, d0 - 1, d0 + 1, d0 + 2};
        for (int t = 0; t < 4; t++) {
            const int d = tries[t];
            if (d < 1 || d > G6_MAXSPLIT)
                continue;
            for (int k = 0; k < G6_NSAMP; k++)
                D[k] = pencil_lowest(&F[k], B[k], d, NULL, NULL, NULL);
            jbest = g6_trig_poly(D, cpoly, &phi, &tail);
            pj.d = d;
            if (jbest >= 0 && tail <= tail_tol)
                break;
        }
    }
    stats[0] = tail;
    if (jbest < 0 || !(tail <= tail_tol)) {
        *flags |= G6F_DEGENERATE;
        return 0;
    }
    double ths[G6_MAXROOT];
    int wts[G6_MAXROOT];
    int near[G6_MAXROOT];
    int nr = g6_real_roots(cpoly, jbest, phi, P[GP_IMAG_TOL], P[GP_PAIR_GAP], ths, wts, near,
                           project ? NULL : stats + 4);
    if (nr < 0) {
        *flags |= G6F_DEGENERATE;
        return 0;
    }
    int f = 0;
    int nc = g6_back(&V, project ? &pj : NULL, P, ths, wts, near, nr, cand, &f, stats);
    if ((f & G6F_MULTI) && !project) {
        /* a multiple root (roots close together where Sigma has a second small
         * pivot, not a pair of solutions turning complex): its eigenvalue is
         * accurate where the determinant's roots spread; the back-substitution again
         * from the eigenvalues */
        int nr2 = g6_eig_roots((const double (*)[144])V.S, phi, P[GP_IMAG_TOL], ths, wts);
        if (nr2 >= 0) {
            f = G6F_EIGEN;
            stats[1] = INFINITY;
            stats[2] = 0.0;
            memset(near, 0, sizeof(near));
            nc = g6_back(&V, NULL, P, ths, wts, near, nr2, cand, &f, stats);
        }
    }
    *flags |= f & ~G6F_MULTI;
    return nc;
}

/* The candidates of pose T: the primary variant; where its determinant is
 * degenerate or noisy (a tail above GP_NEAR_TAIL: near a degenerate pose, where the
 * roots of close solutions spread) the secondary too; where that is as well, the
 * projection of each in turn (until one is not degenerate). flags as g6_pose's diag,
 * stats the primary's. Returns how many went to cand (room for G6_MAXCAND). */
static int g6_candidates(const double *P, const double *T, G6Cand *cand, int *flags,
                         double *stats)
{
    const int nv = (int)P[GP_NVAR];
    int nc = 0;
    double st[G6_NSTATS];
    for (int v = 0; v < nv && nc + 2 * G6_VARCAND <= G6_MAXCAND; v++) {
        int f = 0;
        nc += g6_variant(P, P + GP_HEAD + v * VB_SIZE, T, 0, cand + nc, &f, v ? st : stats);
        if (v == 0)
            *flags |= f;
        else
            *flags |= G6F_SECONDARY | (f & G6F_DEGENERATE ? G6F_SEC_DEGENERATE : 0) |
                      (f & G6F_CLUSTER ? G6F_SEC_CLUSTER : 0) |
                      (f & G6F_NOISY ? G6F_SEC_NOISY : 0);
        if (!(f & (G6F_DEGENERATE | G6F_NOISY)))
            return nc;
    }
    if (P[GP_FALLBACK] == 0.0)
        return nc;
    *flags |= G6F_PROJECTED;
    for (int v = 0; v < nv && nc + G6_VARCAND <= G6_MAXCAND; v++) {
        int f = 0;
        nc += g6_variant(P, P + GP_HEAD + v * VB_SIZE, T, 1, cand + nc, &f, st);
        if (!(f & G6F_DEGENERATE))
            return nc;
    }
    *flags |= G6F_PROJ_DEGENERATE;
    return nc;
}

/* ------------------------------------------------------------ Newton polish */

/* Smallest singular value of the 6 x 6 row-major J (lane-wise): chain.h's
 * jac_sigma_min6, the one copy of the inverse iteration on J^T J. */
static vd g6_sigma_min(const vd *J) { return jac_sigma_min6(J, 6); }

#define NEWTON_RATIO 0.7 /* a step must cut the error by this factor (after 3) ... */
#define SLOW_RATIO 0.9   /* ... from a multiple root (after SLOW_START) ... */
#define SLOW_START 8
#define G6_FAR 1e-6      /* ... while the error [m, rad] is above this: else spurious */

/* Levenberg-Marquardt steps dq, one per lane in `lanes` (W at once; ok: the lanes
 * whose step is finite): the least-squares solution of [J; sqrt(lam) I] dq = [e; 0]
 * with lam = |e|^2 (Yamashita & Fukushima 2001: quadratic convergence to a regular
 * solution and onto a manifold of solutions, where J is singular), by Householder QR
 * of the 12 x 6 matrix (house_qr's steps, lane-wise; not the normal equations, whose
 * squared condition number stalls the error near a solution with sigma ~ 1e-9); a
 * step above 0.5 rad is shortened to it. Next to a near-continuum every candidate
 * takes these steps (the offset iiwa's stretched elbow: ~40 % of its solves' time,
 * one lane at a time before); a lone lane (g6_step) is broadcast, so every step of a
 * lane is this arithmetic whichever way it comes. */
static void g6_lm_steps(const vd *J, const vd *e, vl lanes, vd *dq, vl *ok)
{
    /* column-major, column j < 6: J's, then mu e_j; column 6 the right side [e; 0],
     * which each reflector meets as it meets the columns (house_apply_t's steps) */
    vd A[7 * 12], V[6 * 12], beta[6], e2 = BR(0.0), *b = A + 6 * 12;
    for (int r = 0; r < 6; r++)
        e2 += e[r] * e[r];
    const vd mu = vsqrt(e2) + 1e-300;
    for (int j = 0; j < 6; j++)
        for (int r = 0; r < 12; r++)
            A[12 * j + r] = r < 6 ? J[6 * r + j] : (r - 6 == j ? mu : BR(0.0));
    for (int r = 0; r < 12; r++)
        b[r] = r < 6 ? e[r] : BR(0.0);
    for (int k = 0; k < 6; k++) {
        vd *a = A + k * 12, *v = V + k * 12;
        vd nrm = BR(0.0);
        for (int i = k; i < 12; i++)
            nrm += a[i] * a[i];
        nrm = vsqrt(nrm);
        vd alpha = vsel(a[k] > 0.0, -nrm, nrm);
        v[k] = a[k] - alpha;
        vd vv = v[k] * v[k];
        for (int i = k + 1; i < 12; i++) {
            v[i] = a[i];
            vv += v[i] * v[i];
        }
        beta[k] = 2.0 / vv;
        a[k] = alpha;
        for (int j = k + 1; j < 7; j++) {
            vd *c = A + j * 12, sj = BR(0.0);
            for (int i = k; i < 12; i++)
                sj += v[i] * c[i];
            sj *= beta[k];
            for (int i = k; i < 12; i++)
                c[i] -= sj * v[i];
        }
    }
    vd big = BR(0.0);
    for (int i = 5; i >= 0; i--) {
        vd acc = b[i];
        for (int k = i + 1; k < 6; k++)
            acc -= A[12 * k + i] * dq[k];
        dq[i] = acc / A[12 * i + i];
        vd ad = vabs(dq[i]);
        big = vsel(ad > big, ad, big);
    }
    *ok = lanes & vfinite(big);
    vl shorten = *ok & (big > 0.5);
    if (vany(shorten)) {
        vd f = 0.5 / vsel(shorten, big, BR(1.0));
        for (int i = 0; i < 6; i++)
            dq[i] = vsel(shorten, dq[i] * f, dq[i]);
    }
}

/* Newton's step dq of lane l (LU with partial pivoting of J) where J is well
 * conditioned (its pivots within 1e-6 of each other): 1, else 0 (dq unset). */
static int g6_newton_step(const vd *J, const vd *e, int l, double *dq)
{
    double A[36];
    for (int r = 0; r < 6; r++) {
        dq[r] = e[r][l];
        for (int j = 0; j < 6; j++)
            A[6 * r + j] = J[6 * r + j][l];
    }
    double pmin, pmax;
    if (solve_dense_pivots(A, dq, 6, &pmin, &pmax) && pmin > 1e-6 * pmax) {
        double big = 0.0;
        for (int i = 0; i < 6; i++)
            big = fabs(dq[i]) > big ? fabs(dq[i]) : big;
        if (isfinite(big)) {
            if (big > 0.5)
                for (int i = 0; i < 6; i++)
                    dq[i] *= 0.5 / big;
            return 1;
        }
    }
    return 0;
}

/* One step dq of lane l: g6_newton_step's, else g6_lm_steps' (lane l alone). */
static int g6_step(const vd *J, const vd *e, int l, double *dq)
{
    if (g6_newton_step(J, e, l, dq))
        return 1;
    vd Jl[36], el[6], dqv[6];
    vl ok;
    for (int i = 0; i < 36; i++)
        Jl[i] = BR(J[i][l]);
    for (int r = 0; r < 6; r++)
        el[r] = BR(e[r][l]);
    g6_lm_steps(Jl, el, BRL(-1), dqv, &ok);
    for (int i = 0; i < 6; i++)
        dq[i] = dqv[i][0];
    return ok[0] != 0;
}

/* Polish the candidates (chain values) towards T, W at a time, by the steps above
 * until the error stops falling: the distinct ones that reproduce T (position error
 * within GP_TOL times max(1, GP_SCALE) [m], rotation within GP_TOL [rad]) are
 * appended to q (joint coordinates wrapped into [-pi, pi)), after the nsol there, and
 * sig (the Jacobian's smallest singular value). Two solutions are one when they
 * differ by less than GP_DEDUPE, or than 1e-10 / sigma (capped at 1e-3) for a
 * near-singular one (Newton leaves it 1e-15 / sigma off) that the solution set joins
 * (g6_joined: not the two roots of a near-double root). A lane within the
 * tolerance but above G6_TIGHT of it is taken by g6_refine to G6_TIGHT of it, else
 * dropped: such a lane is no near-converged solution but a point of a near-continuum
 * (issue 23: the offset iiwa at q4 = +-1e-9, where axes 3 and 5 almost meet; the
 * poses of the q4 = 0 family pass 1.0-1.16e-12 m from T, while the solutions at
 * q4 = +-1e-9 are 0.1-2.6 rad away along it, measured in 40-digit arithmetic), and
 * the true solution it leads to is usually found already (then a duplicate). *best:
 * the smallest final error of any candidate. Returns the solutions in q. */
#define G6_NEAR_MISS 1e-9 /* [m per m of arm, rad] a lane ending this close: g6_refine */
#define G6_TIGHT 0.5      /* of the tolerance: a row ending above, g6_refine'd or dropped */
#define G6_ABS_POS 1e-12  /* [m] the tight position target's cap, whatever the scale */

/* Lane l of qv (chain values) ended within G6_NEAR_MISS of T but above the
 * tolerance: next to a near-double root (a solution with sigma ~ 1e-7, the
 * candidate a few 1e-6 rad off along the near-null direction, issue 23's Panda with
 * joint 2 held) the full step overshoots (the error grows from 1e-11 to 1e-6) and
 * the lane stalls at its start. Here each step is halved until the error falls
 * (at most 40 halvings, 100 steps), from the lane's best. Also a lane within the
 * tolerance but above G6_TIGHT of it, with (tol_p, tol_r) the tight ones. Returns 1
 * when the lane now meets (tol_p, tol_r) (qv's lane l is then the refined point),
 * else 0 and qv is unchanged.
 *
 * The halvings are tried W at a time, one per lane (lane k: the step times 2^-(h0 +
 * k)), and the first whose error falls is taken: the point one halving at a time
 * would take, bit for bit (each lane's arithmetic is the scalar one's), at one pose
 * and Jacobian per W halvings instead of one each (next to a near-continuum, the
 * offset iiwa's stretched elbow, a lane takes ~6 halvings a step and most of its 100
 * steps). The taken lane's pose and Jacobian are the next step's where its point is
 * the updated one to the bit (always, unless the compiler contracts the two sums
 * differently: then they are computed again). */
static int g6_refine(const Chain *ch, const vd *tt, vd *qv, int l, double tol_p,
                     double tol_r, double floor_err)
{
    vd qq[MAXJ], t[12], J[36], e[6];
    double q0[6], ep = 0.0, er = 0.0, m0 = 0.0;
    int have = 0; /* J, e (lane 0) are those at q0 already: the taken halving's */
    for (int j = 0; j < 6; j++)
        q0[j] = qv[j][l];
    for (int it = 0; it < 100; it++) {
        if (!have) {
            for (int j = 0; j < 6; j++)
                qq[j] = BR(q0[j]);
            chain_pose_jac(ch, qq, t, J, 6);
            pose_residual(t, tt, e, BRL(-1));
        }
        have = 0;
        ep = sqrt(e[0][0] * e[0][0] + e[1][0] * e[1][0] + e[2][0] * e[2][0]);
        er = sqrt(e[3][0] * e[3][0] + e[4][0] * e[4][0] + e[5][0] * e[5][0]);
        m0 = 0.0;
        for (int r = 0; r < 6; r++)
            m0 = fabs(e[r][0]) > m0 ? fabs(e[r][0]) : m0;
        if (!(m0 > floor_err))
            break;
        double dq[6];
        if (!g6_step(J, e, 0, dq))
            break;
        int moved = 0;
        for (int h0 = 0; h0 < 40 && !moved; h0 += W) {
            vd qt[MAXJ], tq[12], Jt[36], et[6];
            double lam[W];
            for (int k = 0; k < W; k++)
                lam[k] = ldexp(1.0, -(h0 + k)); /* 1, 1/2, ...: exact, as lam *= 0.5 */
            for (int j = 0; j < 6; j++)
                for (int k = 0; k < W; k++)
                    qt[j][k] = q0[j] + lam[k] * dq[j];
            chain_pose_jac(ch, qt, tq, Jt, 6);
            pose_residual(tq, tt, et, BRL(-1));
            for (int k = 0; k < W && h0 + k < 40 && !moved; k++) {
                double m = 0.0;
                for (int r = 0; r < 6; r++)
                    m = fabs(et[r][k]) > m ? fabs(et[r][k]) : m;
                if (!(m < m0))
                    continue;
                int same = 1;
                for (int j = 0; j < 6; j++) {
                    double tj = qt[j][k];
                    unsigned long long a, b; /* the bits (-0.0, NaN) */
                    q0[j] += lam[k] * dq[j];
                    memcpy(&a, &q0[j], sizeof a);
                    memcpy(&b, &tj, sizeof b);
                    same &= a == b;
                }
                if (same) {
                    for (int i = 0; i < 36; i++)
                        J[i] = BR(Jt[i][k]);
                    for (int r = 0; r < 6; r++)
                        e[r] = BR(et[r][k]);
                    have = 1;
                }
                moved = 1;
            }
        }
        if (!moved)
            break;
    }
    if (!(ep <= tol_p && er <= tol_r))
        return 0;
    for (int j = 0; j < 6; j++)
        qv[j][l] = q0[j];
    return 1;
}

#define G6_JOIN_STEPS 4  /* Gauss-Newton steps of g6_joined's halfway point */
#define G6_JOIN_RATIO 10 /* its error above this times the rows' (and the floor): two */

/* The pose error max(|position error| [m], |rotation error| [rad]) of chain values x
 * (6) against tt (broadcast), with the Jacobian J and residual e there (lane 0). */
static double g6_error_at(const Chain *ch, const vd *tt, const double *x, vd *J, vd *e)
{
    vd qq[MAXJ], t[12];
    for (int j = 0; j < 6; j++)
        qq[j] = BR(x[j]);
    chain_pose_jac(ch, qq, t, J, 6);
    pose_residual(t, tt, e, BRL(-1));
    double ep = sqrt(e[0][0] * e[0][0] + e[1][0] * e[1][0] + e[2][0] * e[2][0]);
    double er = sqrt(e[3][0] * e[3][0] + e[4][0] * e[4][0] + e[5][0] * e[5][0]);
    return fmax(ep, er);
}

/* Whether near-singular solutions a and b (6 chain values each, within the
 * near-singular dedupe distance of each other) are one solution: two exact points of
 * one thin set (a continuum at the rounding floor), or two roots with the pose left
 * between them, which are two solutions (the Panda with joint 2 held at q3 = q6 =
 * 1e-6: two exact rows 7.4e-6 apart along the near-null direction, 7e-15 from T,
 * 2.6e-13 at best halfway; the merge kept the one whose candidate came first, which
 * the instruction sets' roundings decide). The point halfway is moved onto the
 * solution set across the chord: G6_JOIN_STEPS Gauss-Newton steps of least squares
 * [J; w u^T] s = [e; 0] (u along b - a, w the largest column norm of J) remove a thin
 * set's departure from its chord (its curvature), not a gap along it. One when the
 * best point's error is within (tol_p, tol_r) and at most G6_JOIN_RATIO times the
 * worse of the two rows' errors plus floor_err. */
static int g6_joined(const Chain *ch, const vd *tt, const double *a, const double *b,
                     double tol_p, double tol_r, double floor_err)
{
    vd J[36], e[6];
    double x[6], u[6], un = 0.0;
    const double ends = fmax(g6_error_at(ch, tt, a, J, e), g6_error_at(ch, tt, b, J, e));
    for (int j = 0; j < 6; j++) {
        u[j] = wrap_pi(b[j] - a[j]);
        x[j] = a[j] + 0.5 * u[j];
        un += u[j] * u[j];
    }
    un = sqrt(un);
    if (!(un > 0.0))
        return 1;
    double best = INFINITY, bp = INFINITY, br = INFINITY;
    for (int it = 0;; it++) {
        double m = g6_error_at(ch, tt, x, J, e);
        if (m < best) {
            best = m;
            bp = sqrt(e[0][0] * e[0][0] + e[1][0] * e[1][0] + e[2][0] * e[2][0]);
            br = sqrt(e[3][0] * e[3][0] + e[4][0] * e[4][0] + e[5][0] * e[5][0]);
        }
        if (it == G6_JOIN_STEPS)
            break;
        double A[7 * 6], V[7 * 6], beta[6], r[7], s[6], w = 0.0, big = 0.0;
        for (int c = 0; c < 6; c++) {
            double n2 = 0.0;
            for (int i = 0; i < 6; i++)
                n2 += J[6 * i + c][0] * J[6 * i + c][0];
            w = fmax(w, sqrt(n2));
        }
        for (int c = 0; c < 6; c++) /* column-major, column c: J's, then w u_c */
            for (int i = 0; i < 7; i++)
                A[7 * c + i] = i < 6 ? J[6 * i + c][0] : w * u[c] / un;
        for (int i = 0; i < 7; i++)
            r[i] = i < 6 ? e[i][0] : 0.0;
        house_qr(A, 7, 6, V, beta);
        house_apply_t(V, beta, 7, 6, r);
        for (int i = 5; i >= 0; i--) {
            double acc = r[i];
            for (int k = i + 1; k < 6; k++)
                acc -= A[7 * k + i] * s[k];
            s[i] = acc / A[7 * i + i];
            big = fmax(big, fabs(s[i]));
        }
        if (!isfinite(big))
            break;
        for (int j = 0; j < 6; j++)
            x[j] += s[j];
    }
    return bp <= tol_p && br <= tol_r && best <= G6_JOIN_RATIO * ends + floor_err;
}

/* How far coordinates qs (6) lie outside the limits [rad] as g6_range returns them
 * (whole turns into the limits where possible: chain.h's wrap_into; 0 when inside up
 * to LIMIT_SLACK), those values into w when given. */
static double g6_excess(const Chain *ch, const double *qs, double *w)
{
    double excess = 0.0;
    for (int j = 0; j < 6; j++) {
        double v = wrap_into(qs[j], ch->lo[j], ch->hi[j]);
        if (!within_limits(v, ch->lo[j], ch->hi[j]))
            excess = fmax(excess, fmax(v - ch->hi[j], ch->lo[j] - v));
        if (w != NULL)
            w[j] = v;
    }
    return excess;
}

static int g6_polish(const Chain *ch, const double *P, const double *T, const G6Cand *cand,
                     int ncand, double *q, double *sig, int nsol, double *best, int patient)
{
    const double tol_r = P[GP_TOL], dedupe = P[GP_DEDUPE], scale = fmax(1.0, P[GP_SCALE]);
    const double tol_p = tol_r * scale, floor_err = 1e-14 * scale;
    /* the tight position target: per metre of the scale, at most G6_ABS_POS [m] (issue
     * 23: every row to 1e-12; GP_SCALE overstates some arms' size, 3.33 m for the
     * IRB140 URDF of 0.81 m reach) */
    const double tight_p = fmin(G6_TIGHT * tol_p, G6_ABS_POS);
    const int max_iter = (int)P[GP_MAX_ITER] * (patient ? 2 : 1);
    vd tt[12];
    for (int i = 0; i < 12; i++)
        tt[i] = BR(T[i]);
    if (best != NULL)
        *best = INFINITY;
    for (int c0 = 0; c0 < ncand; c0 += W) {
        vd qv[MAXJ], t[12], J[36], e[6];
        for (int j = 0; j < 6; j++)
            for (int l = 0; l < W; l++) {
                int c = c0 + l < ncand ? c0 + l : c0;
                qv[j][l] = ch->sign[j] * (cand[c].v[j] - ch->offset[j]);
            }
        vl done = BRL(0);
        double prev[W], qbest[6][W] = {{0.0}}, mlast[W];
        int slow[W], since[W];
        for (int l = 0; l < W; l++) {
            if (c0 + l >= ncand)
                done[l] = -1;
            slow[l] = c0 + l < ncand && cand[c0 + l].slow;
            prev[l] = mlast[l] = INFINITY;
            since[l] = 0;
        }
        for (int it = 0;; it++) {
            chain_pose_jac(ch, qv, t, J, 6);
            pose_residual(t, tt, e, BRL(-1));
            int all = 1;
            for (int l = 0; l < W; l++) {
                if (done[l])
                    continue;
                double m = 0.0;
                for (int r = 0; r < 6; r++)
                    m = fabs(e[r][l]) > m ? fabs(e[r][l]) : m;
                /* converged (to rounding), or spurious: from a true root Newton
                 * converges quadratically, so far from zero a lane whose error stops
                 * falling gives up; from a multiple root it may be linear with ratio
                 * 1/2 after an erratic start; close to zero (a near-singular
                 * solution) it goes on until 3 steps bring no new best */
                since[l] = m < prev[l] ? 0 : since[l] + 1;
                int stalled = m > G6_FAR ? (slow[l] ? it >= SLOW_START && m > SLOW_RATIO * prev[l]
                                                     : it >= 3 && m > NEWTON_RATIO * prev[l])
                                         : since[l] >= 3;
                /* patient (nothing found otherwise: a near-singular target, whose
                 * steps may fall slowly and erratically from far): only 15 steps
                 * without a new best stop a lane */
                if (patient)
                    stalled = since[l] >= 15;
                if (m < prev[l]) {
                    prev[l] = m;
                    for (int j = 0; j < 6; j++)
                        qbest[j][l] = qv[j][l];
                }
                mlast[l] = m;
                if (!(m > floor_err) || !isfinite(m) || stalled)
                    done[l] = -1;
                all &= done[l] != 0;
            }
            if (all || it == max_iter)
                break;
            vl lm = BRL(0); /* lanes whose Newton step is refused: g6_lm_steps, at once */
            for (int l = 0; l < W; l++) {
                double dq[6];
                if (done[l])
                    continue;
                if (!g6_newton_step(J, e, l, dq)) {
                    lm[l] = -1;
                    continue;
                }
                for (int j = 0; j < 6; j++)
                    qv[j][l] += dq[j];
            }
            if (vany(lm)) {
                vd dqv[6];
                vl ok;
                g6_lm_steps(J, e, lm, dqv, &ok);
                for (int l = 0; l < W; l++) {
                    if (!lm[l])
                        continue;
                    if (!ok[l]) {
                        done[l] = -1;
                        continue;
                    }
                    for (int j = 0; j < 6; j++)
                        qv[j][l] += dqv[j][l];
                }
            }
        }
        int worse = 0; /* a lane that ended above its best: back to the best */
        for (int l = 0; l < W && c0 + l < ncand; l++)
            if (mlast[l] > prev[l] && isfinite(prev[l])) {
                worse = 1;
                for (int j = 0; j < 6; j++)
                    qv[j][l] = qbest[j][l];
            }
        if (worse) {
            chain_pose_jac(ch, qv, t, J, 6);
            pose_residual(t, tt, e, BRL(-1));
        }
        int refined = 0; /* near misses: halved steps (the other lanes unchanged) */
        for (int l = 0; l < W && c0 + l < ncand; l++) {
            double m = 0.0;
            for (int r = 0; r < 6; r++)
                m = fabs(e[r][l]) > m ? fabs(e[r][l]) : m;
            double ep = sqrt(e[0][l] * e[0][l] + e[1][l] * e[1][l] + e[2][l] * e[2][l]);
            double er = sqrt(e[3][l] * e[3][l] + e[4][l] * e[4][l] + e[5][l] * e[5][l]);
            if (!(ep <= tol_p && er <= tol_r) && m < G6_NEAR_MISS * scale)
                refined |= g6_refine(ch, tt, qv, l, tol_p, tol_r, floor_err);
        }
        if (refined) {
            chain_pose_jac(ch, qv, t, J, 6);
            pose_residual(t, tt, e, BRL(-1));
        }
        vd sg = g6_sigma_min(J);
        for (int l = 0; l < W && c0 + l < ncand; l++) {
            double ep = sqrt(e[0][l] * e[0][l] + e[1][l] * e[1][l] + e[2][l] * e[2][l]);
            double er = sqrt(e[3][l] * e[3][l] + e[4][l] * e[4][l] + e[5][l] * e[5][l]);
            if (best != NULL && fmax(ep, er) < *best)
                *best = fmax(ep, er);
            if (!(ep <= tol_p && er <= tol_r))
                continue;
            if (!(ep <= tight_p && er <= G6_TIGHT * tol_r)) {
                /* within the tolerance but not the tight one: settled or dropped */
                if (!g6_refine(ch, tt, qv, l, tight_p, G6_TIGHT * tol_r, floor_err))
                    continue;
                chain_pose_jac(ch, qv, t, J, 6);
                pose_residual(t, tt, e, BRL(-1));
                sg = g6_sigma_min(J);
            }
            double qs[6];
            for (int j = 0; j < 6; j++)
                qs[j] = wrap_pi(qv[j][l]);
            int dup = 0;
            for (int s = 0; s < nsol && !dup; s++) {
                double m = 0.0, smin = fmin(sg[l], sig[s]);
                double tol = smin > 0.0 ? fmax(dedupe, fmin(1e-3, 1e-10 / smin)) : 1e-3;
                for (int j = 0; j < 6; j++) {
                    double d = fabs(wrap_pi(qs[j] - q[6 * s + j]));
                    m = d > m ? d : m;
                }
                /* beyond GP_DEDUPE: one near-singular solution twice only where the
                 * solution set joins them (g6_joined; a near-double root's two
                 * roots are both kept) */
                dup = m < tol
                      && (m < dedupe || g6_joined(ch, tt, qs, q + 6 * s, tol_p, tol_r, floor_err));
                /* one near-singular solution twice (two exact points of its thin
                 * set, up to 1e-3 apart): the kept one is the one inside the limits,
                 * or nearer them by more than GP_DEDUPE (two polishes of one regular
                 * solution, ulps apart, keep the first) */
                if (dup) {
                    double xs = g6_excess(ch, q + 6 * s, NULL), xn = g6_excess(ch, qs, NULL);
                    if (xs > 0.0 && (xn == 0.0 || xn < xs - dedupe)) {
                        memcpy(q + 6 * s, qs, sizeof(qs));
                        sig[s] = sg[l];
                    }
                }
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

/* A singular target (nothing found and the elimination in trouble: a continuum of
 * solutions, where det Sigma vanishes identically or is noisy, or a candidate came
 * within G6_FAR: a near-singular solution). A cluster alone does not call it: it is
 * how an unreachable pose near the workspace's boundary looks (pairs of solutions
 * turned complex). First the nc0 candidates again, patiently (from far a
 * near-singular solution's Newton steps may fall slowly). Then, where a continuum
 * moves theta_a, every theta_a in its range has a solution, whose monomial vector
 * lies in Sigma(theta_a)'s null space: at each of the 24 sample angles of each
 * variant the null space (pivots below 1e-8 of the largest, at least one vector) is
 * split into candidates, polished onto T. Returns the solutions in q. */
static int g6_sampled(const Chain *ch, const double *P, const double *T, G6Cand *cand,
                      double *q, double *sig, int ns);

static int g6_rescue(const Chain *ch, const double *P, const double *T, G6Cand *cand,
                     int nc0, double *q, double *sig)
{
    int ns = g6_polish(ch, P, T, cand, nc0, q, sig, 0, NULL, 1); /* the candidates, patiently */
    if (ns > 0)
        return ns;
    return g6_sampled(ch, P, T, cand, q, sig, 0);
}

/* The sampled null spaces of g6_rescue: each variant's Sigma at its 24 sample
 * angles split into candidates, polished onto T and appended to the ns rows of q
 * (duplicates dropped); the first variant that adds a row ends it. Returns the
 * rows. */
static int g6_sampled(const Chain *ch, const double *P, const double *T, G6Cand *cand,
                      double *q, double *sig, int ns)
{
    const int ns0 = ns;
    const int nv = (int)P[GP_NVAR];
    for (int v = 0; v < nv; v++) {
        G6Var V;
        if (!g6_prepare(P + GP_HEAD + v * VB_SIZE, T, &V))
            continue;
        G6Back G = {V.vb, V.Tp, V.Q, V.V8, V.beta8, V.A8, V.a, V.dir, V.mult};
        int nc = 0;
        for (int k = 0; k < G6_NSAMP; k++) {
            double A[144], Z[12 * 12], r[12], th = G6_TWO_PI * k / G6_NSAMP;
            int n0 = 1;
            g6_sigma_at((const double (*)[144])V.S, th, A);
            null_basis(A, 12, G6_MAXSPLIT, Z, r);
            while (n0 < G6_MAXSPLIT && r[11 - n0] < 1e-8 * r[0])
                n0++;
            nc += g6_from_basis(&G, th, Z, n0, 1, cand + nc, G6_MAXCAND - nc);
        }
        ns = g6_polish(ch, P, T, cand, nc, q, sig, ns, NULL, 1);
        if (ns > ns0)
            return ns;
    }
    return ns;
}

/* A cluster resolved short (issue 23: the rtb-data iiwa14 with joint_a5 held at a
 * stretched elbow, four solutions within 2.1e-3 rad, the elimination's candidates
 * two, each 1e-3 rad off and polishing onto another member): a candidate whose
 * nearest row lies between G6_SEED_LO and G6_SEED_HI from it was pulled across a
 * cluster; the row mirrored through the candidate (2 c - row, joint coordinates) is
 * a fresh start on the far side, polished and appended (duplicates dropped, the
 * rows found untouched). Only where the roots clustered (G6F_CLUSTER) and rows
 * exist; returns the rows. */
#define G6_SEED_LO 1e-6 /* [rad] candidate to its row: closer is the row's own root */
#define G6_SEED_HI 1e-2 /* [rad] ... farther: another solution's candidate */

static int g6_reseed(const Chain *ch, const double *P, const double *T, const G6Cand *cand,
                     int nc, double *q, double *sig, int ns)
{
    G6Cand seed[G6_MAXCAND];
    int ne = 0;
    const int ns0 = ns;
    for (int c = 0; c < nc; c++) {
        double jq[6], dbest = INFINITY;
        int sbest = -1;
        for (int j = 0; j < 6; j++)
            jq[j] = ch->sign[j] * (cand[c].v[j] - ch->offset[j]);
        for (int s = 0; s < ns0; s++) {
            double m = 0.0;
            for (int j = 0; j < 6; j++)
                m = fmax(m, fabs(wrap_pi(jq[j] - q[6 * s + j])));
            if (m < dbest) {
                dbest = m;
                sbest = s;
            }
        }
        if (!(dbest > G6_SEED_LO && dbest < G6_SEED_HI))
            continue;
        for (int j = 0; j < 6; j++) {
            double x = jq[j] + wrap_pi(jq[j] - q[6 * sbest + j]);
            seed[ne].v[j] = ch->sign[j] * x + ch->offset[j];
        }
        seed[ne].slow = 1;
        ne++;
    }
    if (ne == 0)
        return ns;
    /* polished against a copy: the rows found stay as they were (the dedupe may
     * swap a row for a seed's polish of it); only new rows are appended */
    double qq[6 * G6_MAXSOL], sq[G6_MAXSOL];
    memcpy(qq, q, sizeof(double) * 6 * (size_t)ns);
    memcpy(sq, sig, sizeof(double) * (size_t)ns);
    int n2 = g6_polish(ch, P, T, seed, ne, qq, sq, ns, NULL, 0);
    memcpy(q + 6 * ns, qq + 6 * ns, sizeof(double) * 6 * (size_t)(n2 - ns));
    memcpy(sig + ns, sq + ns, sizeof(double) * (size_t)(n2 - ns));
    return n2;
}

static int g6_pose(const Chain *ch, const double *P, const double *T, double *q, double *sig,
                   long long *diag, double *stats)
{
    for (int i = 0; i < 16; i++)
        if (!isfinite(T[i])) {
            *diag = 0;
            for (int k = 0; k < G6_NSTATS; k++)
                stats[k] = INFINITY;
            stats[2] = 0.0;
            return -1;
        }
    G6Cand cand[G6_MAXCAND];
    int flags = 0;
    double best;
    int nc = g6_candidates(P, T, cand, &flags, stats);
    int ns = g6_polish(ch, P, T, cand, nc, q, sig, 0, &best, 0);
    stats[3] = best;
    if (ns == 0 && P[GP_FALLBACK] != 0.0 &&
        ((flags & (G6F_DEGENERATE | G6F_NOISY)) || best < G6_FAR * fmax(1.0, P[GP_SCALE]))) {
        ns = g6_rescue(ch, P, T, cand, nc, q, sig);
        flags |= G6F_RESCUED;
    } else if (ns > 0 && P[GP_FALLBACK] != 0.0 &&
               (flags & G6F_DEGENERATE) && (flags & G6F_SEC_DEGENERATE) &&
               (flags & G6F_NOISY) && (flags & G6F_SEC_NOISY)) {
        /* every variant degenerate and noisy, some rows found: a near-continuum
         * (the offset iiwa with q4 = -1e-9: axes 3 and 5 1e-9 from one line) whose
         * rows neither the roots nor the projection gave; its members lie in the
         * sampled null spaces as a continuum's do */
        ns = g6_sampled(ch, P, T, cand, q, sig, ns);
        flags |= G6F_RESCUED;
    }
    if (ns > 0 && (flags & G6F_CLUSTER))
        ns = g6_reseed(ch, P, T, cand, nc, q, sig, ns);
    *diag = flags | ((long long)nc << G6_DIAG_CAND_SHIFT);
    if (ns == 0 && (flags & G6F_DEGENERATE) &&
        (P[GP_FALLBACK] == 0.0 || (flags & G6F_PROJ_DEGENERATE)))
        return -2;
    return ns;
}

/* ------------------------------------------------- joints on one line */

/* A solution with two free joints on one line (equal Jacobian columns up to the
 * sign sigma: the offset iiwa with q4 = 0 puts axes 3 and 5 on one line) lies on a
 * continuum: only q_i + sigma q_j is fixed, and the elimination returns whichever
 * split its null vector gave (issue 23: six of 857 singular special configurations,
 * every split outside the limits). Such rows are re-split inside the limits
 * (g6_coaxial_row); only rows outside the limits with a Jacobian singular value
 * below G6_COAX_SIG per metre are looked at, so regular poses are untouched. */
#define G6_COAX_SIG 1e-6  /* [per m of arm] a row's sigma below this: look for a pair */
#define G6_COAX_DIFF 1e-8 /* [per m of arm] Jacobian columns this close: one line */

/* The value of coordinate j nearest pref (within j's limits) such that q_i = phi -
 * sigma q_j lies within i's limits by whole turns; NaN when no split does.
 * pieper.c's pk_split is the same search on chain values; it stays a separate copy
 * because pieper.c is compiled without FMA contraction (every kernel copy takes the
 * same branches there) and this file is not: one shared helper would change the
 * last bits of one of them on the AVX copies. */
static double g6_split_pair(const Chain *ch, int i, int j, double phi, double sigma,
                            double pref)
{
    double best = NAN, bestd = INFINITY;
    for (int m = -2; m <= 2; m++) {
        double c = phi + 2.0 * M_PI * m, lo, hi;
        if (sigma > 0.0) {
            lo = c - ch->hi[i];
            hi = c - ch->lo[i];
        } else {
            lo = ch->lo[i] - c;
            hi = ch->hi[i] - c;
        }
        lo = fmax(lo, ch->lo[j]);
        hi = fmin(hi, ch->hi[j]);
        if (lo > hi)
            continue;
        double v = fmin(fmax(pref, lo), hi), d = fabs(v - pref);
        if (d < bestd) {
            bestd = d;
            best = v;
        }
    }
    return best;
}

static int g6_inside(const Chain *ch, const double *qs)
{
    int in = 1;
    for (int j = 0; j < 6; j++)
        in &= within_limits(wrap_into(qs[j], ch->lo[j], ch->hi[j]), ch->lo[j], ch->hi[j]);
    return in;
}

/* Row qs (coordinates, outside the limits): each pair of joints on one line whose
 * split is outside the limits is re-split inside them (two passes, as pieper.c's
 * pk_repair), then polished onto T (g6_polish: the columns agree to G6_COAX_DIFF,
 * not exactly, so the moved row is off by up to ~1e-8). Kept (qs, *sg replaced)
 * when the polished row reproduces T and lies inside the limits; returns 1 then. */
static int g6_coaxial_row(const Chain *ch, const double *P, const double *T, double *qs,
                          double *sg)
{
    const double scale = fmax(1.0, P[GP_SCALE]);
    double trial[6];
    int moved = 0;
    memcpy(trial, qs, sizeof(trial));
    for (int pass = 0; pass < 2; pass++) {
        vd qv[MAXJ], t[12], J[36];
        for (int j = 0; j < 6; j++)
            qv[j] = BR(trial[j]);
        chain_pose_jac(ch, qv, t, J, 6);
        for (int i = 0; i < 6; i++)
            for (int j = i + 1; j < 6; j++) {
                double dot = J[18 + i][0] * J[18 + j][0] + J[24 + i][0] * J[24 + j][0] +
                             J[30 + i][0] * J[30 + j][0];
                double sigma = dot >= 0.0 ? 1.0 : -1.0, diff = 0.0;
                for (int r = 0; r < 6; r++)
                    diff = fmax(diff, fabs(J[6 * r + i][0] - sigma * J[6 * r + j][0]));
                if (!(diff < G6_COAX_DIFF * scale))
                    continue;
                double qi = wrap_into(trial[i], ch->lo[i], ch->hi[i]);
                double qj = wrap_into(trial[j], ch->lo[j], ch->hi[j]);
                if (within_limits(qi, ch->lo[i], ch->hi[i]) &&
                    within_limits(qj, ch->lo[j], ch->hi[j]))
                    continue;
                double phi = trial[i] + sigma * trial[j];
                double v = g6_split_pair(ch, i, j, phi, sigma, qj);
                if (isnan(v))
                    continue;
                trial[j] = v;
                trial[i] = phi - sigma * v;
                moved = 1;
            }
    }
    if (!moved)
        return 0;
    G6Cand c = {{0.0}, 0};
    for (int j = 0; j < 6; j++)
        c.v[j] = ch->sign[j] * trial[j] + ch->offset[j];
    double out[6 * G6_MAXSOL], osg[G6_MAXSOL];
    if (g6_polish(ch, P, T, &c, 1, out, osg, 0, NULL, 0) != 1 || !g6_inside(ch, out))
        return 0;
    memcpy(qs, out, sizeof(trial));
    *sg = osg[0];
    return 1;
}

/* Row qs (coordinates), singular, outside the limits by at most G6_SLIDE_REACH:
 * next to a singular configuration the exact configurations form a thin set along
 * the Jacobian's null vector n, and the in-limit one may be a small step away (the
 * offset iiwa with q3 = -1e-9 and q6 at its limit: the row 1.7e-7 past it, sigma
 * 6e-12). The smallest step t n that puts every joint inside (each joint's
 * interval for t intersected), then g6_polish; kept (qs, *sg replaced) when the
 * polished row reproduces T and lies inside the limits; returns 1 then. */
#define G6_SLIDE_REACH 1e-3 /* [rad] rows farther outside are not slid */
static int g6_slide_row(const Chain *ch, const double *P, const double *T, double *qs,
                        double *sg)
{
    double w[6], tlo = -INFINITY, thi = INFINITY;
    if (!(g6_excess(ch, qs, w) <= G6_SLIDE_REACH))
        return 0;
    vd qv[MAXJ], t[12], Jv[36];
    double J[36], n[6], r[6];
    for (int j = 0; j < 6; j++)
        qv[j] = BR(w[j]);
    chain_pose_jac(ch, qv, t, Jv, 6);
    for (int k = 0; k < 36; k++)
        J[k] = Jv[k][0];
    null_basis(J, 6, 1, n, r);
    for (int j = 0; j < 6; j++) {
        double a = ch->lo[j] - w[j], b = ch->hi[j] - w[j]; /* n_j t in [a, b] */
        if (fabs(n[j]) < 1e-12) {
            if (a > LIMIT_SLACK || b < -LIMIT_SLACK)
                return 0;
            continue;
        }
        double ta = a / n[j], tb = b / n[j];
        tlo = fmax(tlo, fmin(ta, tb));
        thi = fmin(thi, fmax(ta, tb));
    }
    if (!(tlo <= thi))
        return 0;
    double step = fmin(fmax(0.0, tlo), thi);
    step += step > 0.0 ? 0.01 * (thi - step) : step < 0.0 ? 0.01 * (tlo - step) : 0.0;
    G6Cand c = {{0.0}, 0};
    for (int j = 0; j < 6; j++)
        c.v[j] = ch->sign[j] * (w[j] + step * n[j]) + ch->offset[j];
    double out[6 * G6_MAXSOL], osg[G6_MAXSOL];
    if (g6_polish(ch, P, T, &c, 1, out, osg, 0, NULL, 0) != 1 || !g6_inside(ch, out))
        return 0;
    memcpy(qs, out, sizeof(double) * 6);
    *sg = osg[0];
    return 1;
}

/* g6_coaxial_row, else g6_slide_row, on every singular row of q (ns rows) outside
 * the limits; a moved row that lands on another row (within GP_DEDUPE) is dropped.
 * Returns the rows. */
static int g6_coaxial_rows(const Chain *ch, const double *P, const double *T, double *q,
                           double *sig, int ns)
{
    const double scale = fmax(1.0, P[GP_SCALE]);
    for (int s = 0; s < ns; s++) {
        if (!(sig[s] < G6_COAX_SIG * scale) || g6_inside(ch, q + 6 * s) ||
            !(g6_coaxial_row(ch, P, T, q + 6 * s, sig + s) ||
              g6_slide_row(ch, P, T, q + 6 * s, sig + s)))
            continue;
        for (int o = 0; o < ns; o++) {
            double m = 0.0;
            for (int j = 0; o != s && j < 6; j++)
                m = fmax(m, fabs(wrap_pi(q[6 * s + j] - q[6 * o + j])));
            if (o != s && m < P[GP_DEDUPE]) { /* a duplicate: drop row s */
                memmove(q + 6 * s, q + 6 * (s + 1), sizeof(double) * 6 * (ns - s - 1));
                memmove(sig + s, sig + s + 1, sizeof(double) * (ns - s - 1));
                ns--;
                s--;
                break;
            }
        }
    }
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
                         job->stats + G6_NSTATS * i);
        job->status[i] = ns == -1 ? G6_BAD_POSE : ns == -2 ? G6_DEGENERATE
                         : ns == 0 ? G6_NONE : G6_OK;
        ns = ns < 0 ? 0 : ns;
        ns = g6_coaxial_rows(job->ch, job->P, job->T + 16 * i, q, sig, ns);
        double *Qo = job->Q + (size_t)i * 6 * G6_MAXSOL;
        const Chain *ch = job->ch;
        for (int s = 0; s < G6_MAXSOL; s++) {
            int ok = s < ns, in = ok;
            for (int j = 0; j < 6; j++) {
                /* whole turns into the limits where possible (chain.h's wrap_into) */
                double v = ok ? wrap_into(q[6 * s + j], ch->lo[j], ch->hi[j]) : NAN;
                in &= within_limits(v, ch->lo[j], ch->hi[j]);
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
    if (!(P[GP_NVAR] >= 1.0 && P[GP_NVAR] <= G6_MAXVAR && P[GP_NVAR] == nv) ||
        len != GP_HEAD + nv * VB_SIZE)
        return 0;
    if (!(P[GP_MAX_ITER] >= 0.0 && P[GP_MAX_ITER] <= 100.0) ||
        !(P[GP_SCALE] > 0.0 && P[GP_SCALE] < 1e6) ||
        !(P[GP_FALLBACK] == 0.0 || P[GP_FALLBACK] == 1.0))
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
 *                 diag (N,) int64, stats (N, 12), parallel): per pose up to 16
 * solutions (joint coordinates, revolute ones in [-pi, pi) or moved by whole turns
 * into their limits; rows that are not solutions 0), which are solutions, which
 * are inside the limits, the Jacobian's smallest singular value (NaN on other
 * rows), the status (G6_OK ...), the flags (G6F_..., candidates tried above
 * G6_DIAG_CAND_SHIFT), the primary's tail, margin and clusters split, the
 * smallest error a candidate's polish reached, and the primary's G6_NEAR complex root
 * pairs nearest the real axis (g6_real_roots' cx: imaginary, real part of theta). */
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

/* general6r_candidates(params, T (4, 4), out (G6_MAXCAND, 6)) -> (n, flags): the
 * candidates one pose gives before the polish (chain values, original joint order),
 * for tests and diagnostics */
static PyObject *general6r_candidates_body(const general6r_candidates_args *a)
{
    G6Cand cand[G6_MAXCAND];
    int flags = 0, n;
    double stats[G6_NSTATS], *out = a->out;
    n = g6_candidates(a->params, a->T, cand, &flags, stats);
    for (int i = 0; i < n; i++)
        memcpy(out + 6 * i, cand[i].v, sizeof(cand[i].v));
    return Py_BuildValue("ii", n, flags);
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
