/*
 * The lane dialect every chain kernel is written in.
 *
 * W values (targets, configurations) advance together, one per lane of a GCC
 * vector: `vd` holds W doubles, `vl` W 64-bit lane masks (-1 true, 0 false, as a
 * vector comparison returns). One source serves a batch (W configurations per
 * step) and a single configuration (lane 0; the other lanes repeat it): on a
 * vector unit the W lanes cost what one costs, so a lone configuration runs at
 * scalar speed without a second, scalar copy of the formulas.
 *
 * The translation unit is compiled once per instruction set (module.c): baseline
 * (2 lanes: one SSE2 / NEON register), AVX2 + FMA (4 lanes) and AVX-512 (8 lanes).
 */
#ifndef ROBOKIN_LANES_H
#define ROBOKIN_LANES_H

#include <math.h>

#ifndef W
#if defined(__AVX512F__)
#define W 8 /* one 512-bit register */
#elif defined(__AVX__)
#define W 4 /* one 256-bit register */
#else
#define W 2 /* one 128-bit register (SSE2, NEON): wider vectors would be split */
#endif
#endif

typedef double vd __attribute__((vector_size(8 * W)));
typedef long long vl __attribute__((vector_size(8 * W)));

#define ALWAYS_INLINE static inline __attribute__((always_inline))

/* a scalar in every lane */
#define BR(x) ((vd){0} + (double)(x))
#define BRL(x) ((vl){0} + (long long)(x))

ALWAYS_INLINE vd vsel(vl m, vd a, vd b) /* m ? a : b, per lane */
{
    return (vd)(((vl)a & m) | ((vl)b & ~m));
}

ALWAYS_INLINE vd vabs(vd x)
{
    return (vd)((vl)x & ~BRL(0x8000000000000000ULL));
}

ALWAYS_INLINE int vany(vl m)
{
    int any = 0;
    for (int l = 0; l < W; l++)
        any |= (m[l] != 0);
    return any;
}

ALWAYS_INLINE vd vsqrt(vd x)
{
    vd r;
    for (int l = 0; l < W; l++)
        r[l] = sqrt(x[l]);
    return r;
}

/* lanes holding a finite value (false for NaN and +-inf) */
ALWAYS_INLINE vl vfinite(vd x)
{
    return vabs(x) <= BR(1.7976931348623157e308);
}

#endif
