/*
 * Constants of robokin's sin/cos, shared by the C extensions: Cody-Waite reduction
 * by pi/2 and the fdlibm kernel polynomials (< 1 ulp), the same values as
 * robokin.kinematics._kernels.sincos and its private copies in the numba kernels.
 */
#ifndef ROBOKIN_SINCOS_CONSTS_H
#define ROBOKIN_SINCOS_CONSTS_H
static const double INV_PIO2 = 6.36619772367581382433e-01;
static const double PIO2_1 = 1.57079632673412561417e00;
static const double PIO2_2 = 6.07710050630396597660e-11;
static const double PIO2_3 = 2.02226624871116645580e-21;
static const double S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03,
                    S3 = -1.98412698298579493134e-04, S4 = 2.75573137070700676789e-06,
                    S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
static const double C1 = 4.16666666666666019037e-02, C2 = -1.38888888888741095749e-03,
                    C3 = 2.48015872894767294178e-05, C4 = -2.75573143513906633035e-07,
                    C5 = 2.08757232129817482790e-09, C6 = -1.13596475577881948265e-11;
#endif
