/*
 * The outputs of a held-joint manifold kernel (held_manifold.c, and held_closed.c,
 * which fills them where its closed forms certify a pose): their sizes, the point
 * kinds, the flags and held_manifold's modes.
 */
#ifndef ROBOKIN_HELD_OUTPUTS_H
#define ROBOKIN_HELD_OUTPUTS_H

#define HM_MAXI 40  /* intervals per branch */
#define HM_MAXP 512 /* points per pose */
/* a point [t, branch, joint, kind]: a limit crossing, an aligned-axes value, a branch end */
enum { HM_KIND_LOWER = 0, HM_KIND_UPPER = 1, HM_KIND_ALIGNED = 2, HM_KIND_FOLD = 3 };
/* a pose the kernel could not certify (the caller takes the solved-points path) */
enum { HM_FLAG_SINGULAR = 1, HM_FLAG_UNRESOLVED = 2, HM_FLAG_CONVERGE = 4, HM_FLAG_FULL = 8,
       HM_FLAG_VANISH = 16, HM_FLAG_MEMORY = 32, HM_FLAG_BAD = 64 };
/* held_manifold's mode: held_closed.c's closed forms where they certify the pose, else
 * held_manifold.c's grid (held_manifold_one's: robot.self_motion); the grid alone; the
 * closed forms alone (HM_FLAG_BAD where they do not certify it) */
enum { HM_MODE_AUTO = 0, HM_MODE_GRID = 1, HM_MODE_CLOSED = 2 };

#endif /* ROBOKIN_HELD_OUTPUTS_H */
