/*
 * Scalar 3-vectors and rotations (by their rows) for the closed-form solvers
 * (six_r.c, pieper.c, pieper_srs.c): one copy of these few formulas.
 */
#ifndef ROBOKIN_VEC3_H
#define ROBOKIN_VEC3_H

typedef struct { double x, y, z; } v3;
typedef struct { v3 r0, r1, r2; } m3; /* a rotation by its rows */

/* the 3-vector at P[i], P[i + 1], P[i + 2] */
static inline v3 v3_at(const double *P, int i) { return (v3){P[i], P[i + 1], P[i + 2]}; }

/* a . b */
static inline double v3_dot(v3 a, v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

/* a x b */
static inline v3 v3_cross(v3 a, v3 b)
{
    return (v3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

/* a + b, a - b, s a */
static inline v3 v3_add(v3 a, v3 b) { return (v3){a.x + b.x, a.y + b.y, a.z + b.z}; }
static inline v3 v3_sub(v3 a, v3 b) { return (v3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static inline v3 v3_scale(v3 a, double s) { return (v3){a.x * s, a.y * s, a.z * s}; }

/* rot(k, t) v for unit k given c = cos t, s = sin t, by Rodrigues' formula:
 * v cos t + (k x v) sin t + k (k . v)(1 - cos t) */
static inline v3 v3_rot(v3 k, double c, double s, v3 v)
{
    double kv = v3_dot(k, v) * (1.0 - c);
    v3 x = v3_cross(k, v);
    return (v3){v.x * c + x.x * s + k.x * kv, v.y * c + x.y * s + k.y * kv,
                v.z * c + x.z * s + k.z * kv};
}

/* R v */
static inline v3 m3_mv(const m3 *R, v3 v)
{
    return (v3){v3_dot(R->r0, v), v3_dot(R->r1, v), v3_dot(R->r2, v)};
}

/* R^T v */
static inline v3 m3_mtv(const m3 *R, v3 v)
{
    return (v3){R->r0.x * v.x + R->r1.x * v.y + R->r2.x * v.z,
                R->r0.y * v.x + R->r1.y * v.y + R->r2.y * v.z,
                R->r0.z * v.x + R->r1.z * v.y + R->r2.z * v.z};
}

#endif /* ROBOKIN_VEC3_H */
