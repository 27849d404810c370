/* Test hooks of the ray-sphere unit (rtl-model/src/units/ray_sphere.c), internal to
 * rtl-model: tests/traversal/test_ray_sphere.c checks that the unit (fast
 * path + exact path) equals the exact path alone on every input, and that the
 * fast path alone never decides differently from the exact path. */
#ifndef CBVH_RAY_SPHERE_INTERNAL_H
#define CBVH_RAY_SPHERE_INTERNAL_H

#include <stdint.h>

#include "cbvh/traversal_units.h"

/* cbvh_ray_sphere with the binary64 fast path switched off: same status and
 * *hit, always computed by the exact path (the definition). */
uint32_t cbvh_ray_sphere_exact_only(const cbvh_ray *ray, const cbvh_f32 c[3], cbvh_f32 r, int *hit);

/* The fast path alone: 1 = proven hit, 0 = proven miss, -1 = undecided (the
 * exact path decides).  Caller guarantees valid inputs (status 0) and
 * tmin <= tmax. */
int cbvh_ray_sphere_fast_only(const cbvh_ray *ray, const cbvh_f32 c[3], cbvh_f32 r);

/* The fast path's binary64 values y^ and absolute-value bounds A^ of its
 * polynomials, for checking |y^ - y| <= 2^-49 A^ against exact values:
 * [0] D = |w x d|^2 - r^2 A, [1] S0 = B - tmin A, [2] E0 = |tmin d - w|^2 - r^2,
 * and if tmax is finite [3] S1 = tmax A - B, [4] E1 = |tmax d - w|^2 - r^2
 * (w = c - o, A = d . d, B = w . d).  Returns 3 or 5 (how many are set). */
int cbvh_ray_sphere_fast_terms(const cbvh_ray *ray, const cbvh_f32 c[3], cbvh_f32 r, double y[5], double ay[5]);

/* The fast path's relative bound (docs/traversal.md §10.3). */
#define CBVH_RAY_SPHERE_REL_BOUND 0x1p-49

#endif
