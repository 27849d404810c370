/* The accelerator's traversal units, bit-exact and integer-defined.
 *
 * Spec: docs/traversal.md.  One unit per source file:
 *   ray_box.c        low-precision ray-box test on the decoded grid (Eq. 4/5)
 *   ray_triangle.c   watertight ray-triangle test (Woop, Benthin, Wald 2013)
 * Ports are binary32 bit patterns (cbvh_f32); status bits are those of
 * datapath.h, with bit 7 CBVH_ST_ZERO_DIR below (the compressor's bit 7,
 * OUTSIDE, no ray unit sets). */
#ifndef CBVH_TRAVERSAL_UNITS_H
#define CBVH_TRAVERSAL_UNITS_H

#include <stdint.h>

#include "cbvh/datapath.h"

#define CBVH_MANT_MIN 3   /* M: mantissa bits of the box unit's plane distances */
#define CBVH_MANT_MAX 24
#define CBVH_CODE_MAX 1024 /* r, s of the box unit: 0 .. 2^10 (s = 2^N allowed) */

/* Reject: the ray direction is the zero vector (status bit 7). */
#define CBVH_ST_ZERO_DIR (1u << 7)

/* A ray o + t d, t in [tmin, tmax].  All finite except tmax, which may be
 * +Inf (an unbounded ray). */
typedef struct {
    cbvh_f32 o[3], d[3];
    cbvh_f32 tmin, tmax;
} cbvh_ray;

/* One axis of a box as two exact planes on the decoded grid:
 *   lower plane u + r * 2^e,  upper plane u + s * 2^e,  0 <= r < s <= 1024,
 * u a binary32 pattern (-Inf encodes -2^128, as in a context), e in
 * [-126, 126].  A float box axis [lo, hi] is {u = lo, e = 0, r = 0, s = 0}
 * with upper plane hi: see cbvh_ray_box_float. */
typedef struct {
    cbvh_f32 u;
    int e;
    uint32_t r, s;
} cbvh_grid_axis;

typedef struct {
    int hit;
    cbvh_f32 t_near, t_far; /* RD/RU to M bits, clamped to [tmin, tmax]; +0 on a miss */
} cbvh_box_result;

/* Ray-box unit (docs/traversal.md §3).  mant_bits = M in [3, 24]. */
uint32_t cbvh_ray_box(const cbvh_ray *ray, int mant_bits, const cbvh_grid_axis axis[3], cbvh_box_result *out);

/* The same datapath with the planes given as float bounds lo[a] <= hi[a]
 * (used by the float-BVH reference traversal). */
uint32_t cbvh_ray_box_float(const cbvh_ray *ray, int mant_bits, const cbvh_f32 lo[3], const cbvh_f32 hi[3],
                            cbvh_box_result *out);

typedef struct {
    int hit;
    cbvh_f32 t;      /* RD(t), t > 0 */
    cbvh_f32 b1, b2; /* RD of the barycentrics of v1 and v2 */
} cbvh_tri_result;

/* Watertight ray-triangle unit (docs/traversal.md §4).  The ray's tmin/tmax
 * are not used: the unit reports every hit with t > 0. */
uint32_t cbvh_ray_triangle(const cbvh_ray *ray, const cbvh_f32 v0[3], const cbvh_f32 v1[3], const cbvh_f32 v2[3],
                           cbvh_tri_result *out);

/* Ray-sphere unit (unit 9, rtl-model/src/units/ray_sphere.c, docs/traversal.md §10):
 * *hit = 1 iff the closed ball |p - c| <= r meets the segment o + t d,
 * t in [tmin, tmax] (tmax may be +Inf), decided exactly.  Status as the box
 * unit for the ray (NaN/Inf, zero direction); NaN/Inf c or r, or r < 0 (sign
 * bit set, -0 allowed) -> BAD_PARAM; *hit = 0 on any status. */
uint32_t cbvh_ray_sphere(const cbvh_ray *ray, const cbvh_f32 c[3], cbvh_f32 r, int *hit);

/* Facing of a triangle for direction d, exact (rtl-model/src/units/tri_facing.c):
 * +1 if d . ((v1 - v0) x (v2 - v0)) < 0 (the ray meets the counter-clockwise
 * front side), -1 if > 0 (back side), 0 if edge-on or degenerate.  Used by
 * one-sided traversal and by the traversal lists' back-face culling; not a
 * datapath port (no vectors). */
int cbvh_tri_facing(const cbvh_f32 d[3], const cbvh_f32 v0[3], const cbvh_f32 v1[3], const cbvh_f32 v2[3]);

/* Which of the model's computations produces a unit's outputs for these
 * inputs.  The outputs never depend on it (the fast paths return only what
 * they prove equal to the exact path's); it tells the vector generator and
 * the coverage test which inputs exercise the integer-defined exact path,
 * where the hard cases are (docs/vectors.md, "Exact-path cases"). */
typedef enum {
    CBVH_PATH_REJECT = 0, /* a nonzero status (or, sphere: an empty segment) */
    CBVH_PATH_FAST = 1,   /* a fast path or binary64 filter decided */
    CBVH_PATH_EXACT = 2   /* the exact path decided */
} cbvh_unit_path;
cbvh_unit_path cbvh_ray_box_path(const cbvh_ray *ray, int mant_bits, const cbvh_grid_axis axis[3]);
cbvh_unit_path cbvh_ray_triangle_path(const cbvh_ray *ray, const cbvh_f32 v0[3], const cbvh_f32 v1[3],
                                      const cbvh_f32 v2[3]);
cbvh_unit_path cbvh_ray_sphere_path(const cbvh_ray *ray, const cbvh_f32 c[3], cbvh_f32 r);

#endif
