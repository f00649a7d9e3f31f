/*
 * The collision broad phase: rounded-box bounds, capsule distances and the bounds
 * along a motion. (Being ported from robokin/collision/_kernels.py.)
 *
 * BROADPHASE_METHODS lists this file's entries of module.c's method table;
 * broadphase_constants(m) adds its constants to the module.
 */
#define BROADPHASE_METHODS
static int broadphase_constants(PyObject *m)
{
    (void)m;
    return 0;
}
