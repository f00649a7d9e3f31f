/*
 * Every IK solution of a general 6R chain (Raghavan-Roth elimination).
 * (Being written: see robokin/kinematics/ik/analytic/general_6r.py.)
 *
 * GENERAL6R_METHODS lists this file's entries of module.c's method table;
 * general6r_constants(m) adds its constants to the module.
 */
#define GENERAL6R_METHODS
static int general6r_constants(PyObject *m)
{
    (void)m;
    return 0;
}
