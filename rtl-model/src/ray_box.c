/* Unit 6: low-precision ray-box test on the decoded grid (docs/traversal.md §3).
 *
 * Plane distances t = (plane - o) / d are computed exactly and rounded once to
 * M significant bits, the near distance toward -Inf and the far distance
 * toward +Inf, so the unit's [t_near, t_far] always contains the exact slab
 * interval: it never reports a miss the real-number slab test would call a
 * hit (watertight traversal).  Integer-only. */
#include <string.h>

#include "cbvh/traversal_units.h"
#include "exact_wide.h"

static int ray_bad(const cbvh_ray *ray) {
    for (int a = 0; a < 3; a++)
        if (cbvh_f32_is_nan_or_inf(ray->o[a]) || cbvh_f32_is_nan_or_inf(ray->d[a])) return 1;
    if (cbvh_f32_is_nan_or_inf(ray->tmin)) return 1;
    if (cbvh_f32_is_nan(ray->tmax) || ray->tmax == CBVH_F32_NEG_INF) return 1;
    return 0;
}

static int dir_zero(const cbvh_ray *ray) {
    return cbvh_f32_is_zero(ray->d[0]) && cbvh_f32_is_zero(ray->d[1]) && cbvh_f32_is_zero(ray->d[2]);
}

/* The slab test of three axes, planes lo[a] <= hi[a] exact. */
static void slabs(const cbvh_ray *ray, int M, const cbvh_xw lo[3], const cbvh_xw hi[3], cbvh_box_result *out) {
    int64_t kn = cbvh_f32_key(ray->tmin), kf = cbvh_f32_key(ray->tmax);
    cbvh_f32 tn = ray->tmin, tf = ray->tmax;
    memset(out, 0, sizeof *out);
    for (int a = 0; a < 3; a++) {
        cbvh_xw o;
        cbvh_xw_from_f32(&o, ray->o[a]);
        if (cbvh_f32_is_zero(ray->d[a])) {
            /* parallel to the slab: inside (faces included) or a miss */
            if (cbvh_xw_cmp(&lo[a], &o) > 0 || cbvh_xw_cmp(&o, &hi[a]) > 0) return;
            continue;
        }
        int neg = (ray->d[a] & CBVH_F32_SIGN) != 0;
        cbvh_xw d, num_n, num_f;
        cbvh_xw_from_f32(&d, ray->d[a]);
        cbvh_xw_sub(&num_n, neg ? &hi[a] : &lo[a], &o);
        cbvh_xw_sub(&num_f, neg ? &lo[a] : &hi[a], &o);
        cbvh_f32 n = cbvh_xw_div_round(&num_n, &d, M, CBVH_RND_DOWN);
        cbvh_f32 f = cbvh_xw_div_round(&num_f, &d, M, CBVH_RND_UP);
        if (cbvh_f32_key(n) > kn) {
            kn = cbvh_f32_key(n);
            tn = n;
        }
        if (cbvh_f32_key(f) < kf) {
            kf = cbvh_f32_key(f);
            tf = f;
        }
    }
    if (kn > kf) return;
    out->hit = 1;
    out->t_near = cbvh_f32_is_zero(tn) ? 0 : tn;
    out->t_far = cbvh_f32_is_zero(tf) ? 0 : tf;
}

static uint32_t check_common(const cbvh_ray *ray, int M) {
    uint32_t st = 0;
    if (M < CBVH_MANT_MIN || M > CBVH_MANT_MAX) st |= CBVH_ST_BAD_PARAM;
    if (ray_bad(ray)) st |= CBVH_ST_NAN_INF;
    else if (dir_zero(ray)) st |= CBVH_ST_ZERO_DIR;
    return st;
}

uint32_t cbvh_ray_box(const cbvh_ray *ray, int M, const cbvh_grid_axis axis[3], cbvh_box_result *out) {
    memset(out, 0, sizeof *out);
    uint32_t st = check_common(ray, M);
    for (int a = 0; a < 3; a++) {
        const cbvh_grid_axis *g = &axis[a];
        if (cbvh_f32_is_nan(g->u) || g->u == CBVH_F32_POS_INF) st |= CBVH_ST_NAN_INF;
        if (g->e < CBVH_SCALE_FLOOR || g->e > CBVH_SCALE_CEIL) st |= CBVH_ST_BAD_SCALE;
        if (g->r > CBVH_CODE_MAX || g->s > CBVH_CODE_MAX) st |= CBVH_ST_BAD_CODE;
        else if (g->r >= g->s) st |= CBVH_ST_INVERTED;
    }
    if (st) return st;
    cbvh_xw lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        cbvh_xw u, step;
        if (axis[a].u == CBVH_F32_NEG_INF) cbvh_xw_from_int(&u, -1, 128); /* -Inf encodes -2^128 */
        else cbvh_xw_from_f32(&u, axis[a].u);
        cbvh_xw_from_int(&step, (int64_t)axis[a].r, axis[a].e);
        cbvh_xw_add(&lo[a], &u, &step);
        cbvh_xw_from_int(&step, (int64_t)axis[a].s, axis[a].e);
        cbvh_xw_add(&hi[a], &u, &step);
    }
    slabs(ray, M, lo, hi, out);
    return 0;
}

uint32_t cbvh_ray_box_float(const cbvh_ray *ray, int M, const cbvh_f32 blo[3], const cbvh_f32 bhi[3],
                            cbvh_box_result *out) {
    memset(out, 0, sizeof *out);
    uint32_t st = check_common(ray, M);
    for (int a = 0; a < 3; a++) {
        if (cbvh_f32_is_nan_or_inf(blo[a]) || cbvh_f32_is_nan_or_inf(bhi[a])) st |= CBVH_ST_NAN_INF;
        else if (cbvh_f32_cmp(blo[a], bhi[a]) > 0) st |= CBVH_ST_INVERTED;
    }
    if (st) return st;
    cbvh_xw lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        cbvh_xw_from_f32(&lo[a], blo[a]);
        cbvh_xw_from_f32(&hi[a], bhi[a]);
    }
    slabs(ray, M, lo, hi, out);
    return 0;
}
