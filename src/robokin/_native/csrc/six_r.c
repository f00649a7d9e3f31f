/*
 * Closed-form IK of the two 6R families (three parallel axes, spherical wrist).
 * (Being ported from robokin/kinematics/ik/analytic/_kernels6r.py.)
 *
 * SIX_R_METHODS lists this file's entries of module.c's method table;
 * six_r_constants(m) adds its constants to the module.
 */
#define SIX_R_METHODS
static int six_r_constants(PyObject *m)
{
    (void)m;
    return 0;
}
