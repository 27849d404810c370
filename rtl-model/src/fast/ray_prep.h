/* Per-ray precomputation for the ray-box unit's fast path (docs/traversal.md,
 * "Performance filter").  Internal to rtl-model: the traversal prepares a ray
 * once and tests many boxes with it; cbvh_ray_box / cbvh_ray_box_float are
 * exactly prepare + test.  Integer-only. */
#ifndef CBVH_RAY_PREP_H
#define CBVH_RAY_PREP_H

#include <stdint.h>

#include "cbvh/traversal_units.h"

/* An exact dyadic v = m * 2^e with |m| < 2^62 (m = 0: v = 0, e arbitrary). */
typedef struct {
    int64_t m;
    int e;
} cbvh_dy;

typedef struct {
    int dzero;   /* d_a = +-0: the ray is parallel to the slab */
    int dneg;    /* d_a < 0 */
    int de;      /* |d_a| = ds * 2^de with ds in [2^23, 2^24) (normalised) */
    uint64_t R;  /* floor(2^86 / ds), in (2^62, 2^63] */
    int rexact;  /* 2^86 mod ds == 0 (d_a a power of two): R is exact */
    cbvh_dy o;   /* o_a exactly */
} cbvh_rb_axis;

typedef struct {
    const cbvh_ray *ray;
    uint32_t status;  /* check of the ray alone (NAN_INF, ZERO_DIR), M not included */
    cbvh_rb_axis ax[3];
} cbvh_rb_ray;

void cbvh_rb_prepare(const cbvh_ray *ray, cbvh_rb_ray *p);

/* The status bits the box unit gives for the ray and M alone (BAD_PARAM,
 * NAN_INF, ZERO_DIR): the unit returns at least these for every box, and no
 * other bit for a valid box.  The traversals' ray check (inline: one per ray,
 * a tenth of a small scene's ray). */
static inline uint32_t cbvh_rb_ray_status(const cbvh_ray *ray, int M) {
    uint32_t st = M < CBVH_MANT_MIN || M > CBVH_MANT_MAX ? CBVH_ST_BAD_PARAM : 0;
    int bad = cbvh_f32_is_nan_or_inf(ray->tmin) | cbvh_f32_is_nan(ray->tmax) | (ray->tmax == CBVH_F32_NEG_INF);
    cbvh_f32 dmag = 0; /* zero iff every d_a is +-0 */
    for (int a = 0; a < 3; a++) {
        bad |= cbvh_f32_is_nan_or_inf(ray->o[a]) | cbvh_f32_is_nan_or_inf(ray->d[a]);
        dmag |= ray->d[a] & ~CBVH_F32_SIGN;
    }
    return st | (bad ? CBVH_ST_NAN_INF : dmag == 0 ? CBVH_ST_ZERO_DIR : 0);
}

/* cbvh_ray_box / cbvh_ray_box_float for a prepared ray with tmax replaced by
 * `tmax` (the traversal's culling bound); same outputs and status bit for bit. */
uint32_t cbvh_ray_box_prep(const cbvh_rb_ray *p, cbvh_f32 tmax, int M, const cbvh_grid_axis axis[3],
                           cbvh_box_result *out);
uint32_t cbvh_ray_box_float_prep(const cbvh_rb_ray *p, cbvh_f32 tmax, int M, const cbvh_f32 lo[3],
                                 const cbvh_f32 hi[3], cbvh_box_result *out);

/* Test hooks (tests/traversal/test_fast_path.c): run only the exact path, or
 * only the fast path (returns -1 when the fast path cannot decide). */
uint32_t cbvh_ray_box_exact_only(const cbvh_ray *ray, int M, const cbvh_grid_axis axis[3], cbvh_box_result *out);
int cbvh_ray_box_fast_only(const cbvh_ray *ray, int M, const cbvh_grid_axis axis[3], cbvh_box_result *out);
uint32_t cbvh_ray_box_float_exact_only(const cbvh_ray *ray, int M, const cbvh_f32 lo[3], const cbvh_f32 hi[3],
                                       cbvh_box_result *out);
int cbvh_ray_box_float_fast_only(const cbvh_ray *ray, int M, const cbvh_f32 lo[3], const cbvh_f32 hi[3],
                                 cbvh_box_result *out);

/* A ray prepared once for the ray-triangle unit's binary64 filter: the axis
 * permutation and the permuted o, d as binary64 (ok: finite, d != 0). */
typedef struct {
    int ok, kx, ky, kz;
    double dx, dy, dz, ox, oy, oz;
} cbvh_tri_ray;
void cbvh_tri_ray_prepare(const cbvh_ray *ray, cbvh_tri_ray *p);
/* The same for a ray already known valid (finite o and d, d != 0: e.g. one
 * cbvh_rb_ray_status accepted), without checking it again: ok = 1. */
void cbvh_tri_ray_prepare_valid(const cbvh_ray *ray, cbvh_tri_ray *p);
/* cbvh_ray_triangle with the ray prepared (same outputs and status). */
uint32_t cbvh_ray_triangle_prepared(const cbvh_tri_ray *p, const cbvh_ray *ray, const cbvh_f32 v0[3],
                                    const cbvh_f32 v1[3], const cbvh_f32 v2[3], cbvh_tri_result *out);

/* The ray-triangle unit's exact path alone, and its miss filter alone
 * (1 = proven miss; caller guarantees finite inputs and d != 0). */
uint32_t cbvh_ray_triangle_exact_only(const cbvh_ray *ray, const cbvh_f32 v0[3], const cbvh_f32 v1[3],
                                      const cbvh_f32 v2[3], cbvh_tri_result *out);
int cbvh_ray_triangle_filter_miss(const cbvh_ray *ray, const cbvh_f32 v0[3], const cbvh_f32 v1[3],
                                  const cbvh_f32 v2[3]);
/* Its hit path alone: 1 = proven hit with *out = the exact path's outputs. */
int cbvh_ray_triangle_filter_hit(const cbvh_ray *ray, const cbvh_f32 v0[3], const cbvh_f32 v1[3], const cbvh_f32 v2[3],
                                 cbvh_tri_result *out);

#endif
