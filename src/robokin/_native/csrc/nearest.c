/*
 * The IK solution nearest a configuration, per pose: robokin.kinematics.ik.nearest
 * (Robot.ik_near) picks among a solution set's rows in one call instead of a dozen
 * numpy operations (the single-pose latency is the point).
 */
#include "chain.h"

/* For each pose i: among rows r of Q[i] (k x n) with ok[i, r], the one nearest
 * qn[i] (revolute differences wrapped into [-pi, pi)), moved by whole turns to the
 * equivalent nearest qn[i] when that stays within [lo, hi] (chain.h's
 * within_limits, the slack of the wrap_into rule); into q[i]. err[i] gets
 * its position and rotation error against T[i] (chain_pose, pose_residual).
 * Returns found[i]; rows of poses without a candidate are NaN. */
static void nearest_rows(const Chain *ch, const double *Q, const unsigned char *ok,
                         const double *qn, const unsigned char *is_rev, const double *T,
                         long N, int k, double *q, double *err, unsigned char *found)
{
    const int n = ch->n;
    for (long i = 0; i < N; i++) {
        const double *Qi = Q + (size_t)i * k * n, *qni = qn + (size_t)i * n;
        double *qi = q + (size_t)i * n;
        int best = -1;
        double best_d = INFINITY;
        for (int r = 0; r < k; r++) {
            if (!ok[(size_t)i * k + r])
                continue;
            double d = 0.0;
            for (int j = 0; j < n; j++) {
                double x = Qi[r * n + j] - qni[j];
                if (is_rev[j])
                    x = wrap_pi(x);
                d += x * x;
            }
            if (d < best_d) {
                best_d = d;
                best = r;
            }
        }
        found[i] = best >= 0;
        if (best < 0) {
            for (int j = 0; j < n; j++)
                qi[j] = NAN;
            err[2 * i] = err[2 * i + 1] = NAN;
            continue;
        }
        for (int j = 0; j < n; j++) {
            double v = Qi[best * n + j];
            if (is_rev[j]) {
                double s = qni[j] + wrap_pi(v - qni[j]);
                if (within_limits(s, ch->lo[j], ch->hi[j]))
                    v = s;
            }
            qi[j] = v;
        }
        vd qv[MAXJ], t[12], tt[12], e[6];
        for (int j = 0; j < n; j++)
            qv[j] = BR(qi[j]);
        for (int a = 0; a < 12; a++)
            tt[a] = BR(T[16 * i + a]);
        chain_pose(ch, qv, t, NULL, NULL);
        pose_residual(t, tt, e, BRL(-1));
        err[2 * i] = sqrt(e[0][0] * e[0][0] + e[1][0] * e[1][0] + e[2][0] * e[2][0]);
        err[2 * i + 1] = sqrt(e[3][0] * e[3][0] + e[4][0] * e[4][0] + e[5][0] * e[5][0]);
    }
}
