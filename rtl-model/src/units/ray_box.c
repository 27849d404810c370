/* Unit 6: low-precision ray-box test on the decoded grid (docs/traversal.md §3).
 *
 * Plane distances t = (plane - o) / d are computed exactly and rounded once to
 * M significant bits, the near distance toward -Inf and the far distance
 * toward +Inf, so the unit's [t_near, t_far] always contains the exact slab
 * interval: it never reports a miss the real-number slab test would call a
 * hit (watertight traversal).  Integer-only. */
#include <string.h>

#include "cbvh/traversal_units.h"
#include "units/exact_wide.h"
#include "fast/fast_paths.h"
#include "units/grid.h"
#include "fast/ray_prep.h"

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

uint32_t cbvh_ray_box_exact_only(const cbvh_ray *ray, int M, const cbvh_grid_axis axis[3], cbvh_box_result *out) {
    memset(out, 0, sizeof *out);
    uint32_t st = cbvh_rb_ray_status(ray, M);
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

uint32_t cbvh_ray_box_float_exact_only(const cbvh_ray *ray, int M, const cbvh_f32 blo[3], const cbvh_f32 bhi[3],
                                       cbvh_box_result *out) {
    memset(out, 0, sizeof *out);
    uint32_t st = cbvh_rb_ray_status(ray, M);
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

/* ---------------------------------------------------------------------------
 * Fast path (docs/traversal.md, "Performance filter").  Same outputs bit for
 * bit, still integer-only.  When the planes and the origin fit in 62-bit
 * fixed point, L - O is exact in an int64; the exact quotient
 *     X = |L - O| * 2^86 / ds   (d = ds * 2^de, ds in [2^23, 2^24))
 * lies in [P, P + |L - O|) with P = |L - O| * floor(2^86 / ds), an interval
 * of relative width < 2^-62.  If both ends truncate to the same M-bit value,
 * that value is the truncation of X, and X is strictly above it (or, for a
 * power-of-two ds, X = P exactly), so the directed rounding and the packing
 * are those of the exact path.  Otherwise (about 2^(M-62) of the cases, and
 * exact quotients that land on the M-bit grid with a non-power-of-two d) the
 * exact path decides.  The filter only chooses between two computations of
 * the same value; tests/traversal/test_fast_path.c compares both on millions
 * of inputs. */
#ifdef __SIZEOF_INT128__
typedef unsigned __int128 u128;

static inline int bitlen64(uint64_t x) { return x ? 64 - __builtin_clzll(x) : 0; }
static inline uint64_t mag64(int64_t v) { return v < 0 ? (uint64_t)0 - (uint64_t)v : (uint64_t)v; }

static inline cbvh_dy dy_f32(cbvh_f32 f) {
    int s, e;
    uint32_t sig;
    cbvh_grid_break(f, &s, &sig, &e);
    cbvh_dy r = {s ? -(int64_t)sig : (int64_t)sig, e};
    return r;
}

/* r = a + (-1)^neg_b b exactly, if the aligned operands fit in 62 bits. */
static inline int dy_add(cbvh_dy a, cbvh_dy b, int neg_b, cbvh_dy *r) {
    if (neg_b) b.m = -b.m;
    if (b.m == 0) {
        *r = a;
        return 0;
    }
    if (a.m == 0) {
        *r = b;
        return 0;
    }
    int e0 = a.e < b.e ? a.e : b.e, sa = a.e - e0, sb = b.e - e0;
    if (bitlen64(mag64(a.m)) + sa > 62 || bitlen64(mag64(b.m)) + sb > 62) return -1;
    r->m = (int64_t)((uint64_t)a.m << sa) + (int64_t)((uint64_t)b.m << sb);
    r->e = e0;
    return 0;
}

/* (num / d_a) rounded to M bits in direction mode, or -1 if undecided.
 * |num| is first normalised to mn in [2^62, 2^63), so the product
 * lo = mn * R lies in [2^124, 2^126) and the rounding position d >= 101 falls
 * in its upper 64-bit word. */
static inline int quot(cbvh_dy num, const cbvh_rb_axis *ax, int M, cbvh_rnd mode, cbvh_f32 *out) {
    if (num.m == 0) {
        *out = 0;
        return 0;
    }
    int neg = (num.m < 0) ^ ax->dneg;
    uint64_t mag = mag64(num.m); /* < 2^63 */
    int sh = 63 - bitlen64(mag);
    uint64_t mn = mag << sh;
    u128 lo = (u128)mn * ax->R;
    u128 hi = ax->rexact ? lo : lo + (mn - 1);
    uint64_t lo_h = (uint64_t)(lo >> 64), hi_h = (uint64_t)(hi >> 64);
    int d = (lo_h >> 61 ? 126 : 125) - M; /* bitlen(lo) - M */
    int s = d - 64;                        /* 77 .. 98 - 64 */
    uint64_t q = lo_h >> s;
    if ((hi_h >> s) != q) return -1;
    int sticky = ax->rexact ? ((lo_h & ((UINT64_C(1) << s) - 1)) | (uint64_t)lo) != 0 : 1;
    int away = neg ? (mode == CBVH_RND_DOWN) : (mode == CBVH_RND_UP);
    if (sticky && away) q++;
    *out = cbvh_grid_pack(neg, q, d + num.e - sh - ax->de - 86, mode);
    return 0;
}

/* The slab test on exact planes, or -1 (then the exact path decides). */
static int fast_slabs(const cbvh_rb_ray *p, cbvh_f32 tmax, int M, const cbvh_dy lo[3], const cbvh_dy hi[3],
                      cbvh_box_result *out) {
    const cbvh_ray *ray = p->ray;
    int64_t kn = cbvh_f32_key(ray->tmin), kf = cbvh_f32_key(tmax);
    cbvh_f32 tn = ray->tmin, tf = tmax;
    int miss = 0;
    for (int a = 0; a < 3; a++) {
        const cbvh_rb_axis *ax = &p->ax[a];
        cbvh_dy num_n, num_f;
        if (dy_add(ax->dneg ? hi[a] : lo[a], ax->o, 1, &num_n) ||
            dy_add(ax->dneg ? lo[a] : hi[a], ax->o, 1, &num_f))
            return -1;
        if (ax->dzero) { /* parallel: inside iff lo - o <= 0 <= hi - o */
            if (num_n.m > 0 || num_f.m < 0) {
                miss = 1;
                break;
            }
            continue;
        }
        cbvh_f32 n, f;
        if (quot(num_n, ax, M, CBVH_RND_DOWN, &n) || quot(num_f, ax, M, CBVH_RND_UP, &f)) return -1;
        int64_t k = cbvh_f32_key(n);
        if (k > kn) {
            kn = k;
            tn = n;
        }
        k = cbvh_f32_key(f);
        if (k < kf) {
            kf = k;
            tf = f;
        }
        /* t_near only grows and t_far only shrinks over the axes, so this is
         * a miss whatever the remaining axes give (and the exact path's miss
         * outputs are all +0 as well) */
        if (kn > kf) break;
    }
    memset(out, 0, sizeof *out);
    if (miss || kn > kf) return 0;
    out->hit = 1;
    out->t_near = cbvh_f32_is_zero(tn) ? 0 : tn;
    out->t_far = cbvh_f32_is_zero(tf) ? 0 : tf;
    return 0;
}
#endif

void cbvh_rb_prepare(const cbvh_ray *ray, cbvh_rb_ray *p) {
    memset(p, 0, sizeof *p);
    p->ray = ray;
    cbvh_ray probe = *ray;
    probe.tmax = 0; /* tmax is checked per call */
    p->status = cbvh_rb_ray_status(&probe, CBVH_MANT_MAX); /* NAN_INF or ZERO_DIR; M is checked per call */
    if (p->status) return;
#ifdef __SIZEOF_INT128__
    for (int a = 0; a < 3; a++) {
        cbvh_rb_axis *ax = &p->ax[a];
        ax->o = dy_f32(ray->o[a]);
        ax->dzero = cbvh_f32_is_zero(ray->d[a]);
        if (ax->dzero) continue;
        int s, e;
        uint32_t sig;
        cbvh_grid_break(ray->d[a], &s, &sig, &e);
        int sh = 24 - bitlen64(sig); /* normalise subnormals */
        uint64_t ds = (uint64_t)sig << sh;
        ax->dneg = s;
        ax->de = e - sh;
        ax->R = (uint64_t)(((u128)1 << 86) / ds);
        ax->rexact = ds == CBVH_F32_HIDDEN; /* a power of two */
    }
#endif
}

static uint32_t prep_status(const cbvh_rb_ray *p, cbvh_f32 tmax, int M) {
    uint32_t st = 0;
    if (M < CBVH_MANT_MIN || M > CBVH_MANT_MAX) st |= CBVH_ST_BAD_PARAM;
    if ((p->status & CBVH_ST_NAN_INF) || cbvh_f32_is_nan(tmax) || tmax == CBVH_F32_NEG_INF) st |= CBVH_ST_NAN_INF;
    else st |= p->status;
    return st;
}

static uint32_t grid_status(const cbvh_grid_axis axis[3]) {
    uint32_t st = 0;
    for (int a = 0; a < 3; a++) {
        const cbvh_grid_axis *g = &axis[a];
        if (cbvh_f32_is_nan(g->u) || g->u == CBVH_F32_POS_INF) st |= CBVH_ST_NAN_INF;
        if (g->e < CBVH_SCALE_FLOOR || g->e > CBVH_SCALE_CEIL) st |= CBVH_ST_BAD_SCALE;
        if (g->r > CBVH_CODE_MAX || g->s > CBVH_CODE_MAX) st |= CBVH_ST_BAD_CODE;
        else if (g->r >= g->s) st |= CBVH_ST_INVERTED;
    }
    return st;
}

static uint32_t float_status(const cbvh_f32 blo[3], const cbvh_f32 bhi[3]) {
    uint32_t st = 0;
    for (int a = 0; a < 3; a++) {
        if (cbvh_f32_is_nan_or_inf(blo[a]) || cbvh_f32_is_nan_or_inf(bhi[a])) st |= CBVH_ST_NAN_INF;
        else if (cbvh_f32_cmp(blo[a], bhi[a]) > 0) st |= CBVH_ST_INVERTED;
    }
    return st;
}

/* Fast path for grid planes of a valid box: 0, or -1 if undecided. */
static int fast_grid(const cbvh_rb_ray *p, cbvh_f32 tmax, int M, const cbvh_grid_axis axis[3],
                     cbvh_box_result *out) {
#ifdef __SIZEOF_INT128__
    cbvh_dy lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        if (axis[a].u == CBVH_F32_NEG_INF) return -1; /* -2^128: leave it to the exact path */
        cbvh_dy u = dy_f32(axis[a].u), r = {(int64_t)axis[a].r, axis[a].e}, s = {(int64_t)axis[a].s, axis[a].e};
        if (dy_add(u, r, 0, &lo[a]) || dy_add(u, s, 0, &hi[a])) return -1;
    }
    return fast_slabs(p, tmax, M, lo, hi, out);
#else
    (void)p, (void)tmax, (void)M, (void)axis, (void)out;
    return -1;
#endif
}

static int fast_float(const cbvh_rb_ray *p, cbvh_f32 tmax, int M, const cbvh_f32 blo[3], const cbvh_f32 bhi[3],
                      cbvh_box_result *out) {
#ifdef __SIZEOF_INT128__
    cbvh_dy lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = dy_f32(blo[a]);
        hi[a] = dy_f32(bhi[a]);
    }
    return fast_slabs(p, tmax, M, lo, hi, out);
#else
    (void)p, (void)tmax, (void)M, (void)blo, (void)bhi, (void)out;
    return -1;
#endif
}

uint32_t cbvh_ray_box_prep(const cbvh_rb_ray *p, cbvh_f32 tmax, int M, const cbvh_grid_axis axis[3],
                           cbvh_box_result *out) {
    uint32_t st = prep_status(p, tmax, M) | grid_status(axis);
    if (st) {
        memset(out, 0, sizeof *out);
        return st;
    }
    if (CBVH_FAST_PATHS && fast_grid(p, tmax, M, axis, out) == 0) return 0;
    cbvh_ray r = *p->ray;
    r.tmax = tmax;
    return cbvh_ray_box_exact_only(&r, M, axis, out);
}

uint32_t cbvh_ray_box_float_prep(const cbvh_rb_ray *p, cbvh_f32 tmax, int M, const cbvh_f32 lo[3],
                                 const cbvh_f32 hi[3], cbvh_box_result *out) {
    uint32_t st = prep_status(p, tmax, M) | float_status(lo, hi);
    if (st) {
        memset(out, 0, sizeof *out);
        return st;
    }
    if (CBVH_FAST_PATHS && fast_float(p, tmax, M, lo, hi, out) == 0) return 0;
    cbvh_ray r = *p->ray;
    r.tmax = tmax;
    return cbvh_ray_box_float_exact_only(&r, M, lo, hi, out);
}

uint32_t cbvh_ray_box(const cbvh_ray *ray, int M, const cbvh_grid_axis axis[3], cbvh_box_result *out) {
    cbvh_rb_ray p;
    cbvh_rb_prepare(ray, &p);
    return cbvh_ray_box_prep(&p, ray->tmax, M, axis, out);
}

uint32_t cbvh_ray_box_float(const cbvh_ray *ray, int M, const cbvh_f32 lo[3], const cbvh_f32 hi[3],
                            cbvh_box_result *out) {
    cbvh_rb_ray p;
    cbvh_rb_prepare(ray, &p);
    return cbvh_ray_box_float_prep(&p, ray->tmax, M, lo, hi, out);
}

int cbvh_ray_box_fast_only(const cbvh_ray *ray, int M, const cbvh_grid_axis axis[3], cbvh_box_result *out) {
    cbvh_rb_ray p;
    cbvh_rb_prepare(ray, &p);
    if (prep_status(&p, ray->tmax, M) | grid_status(axis)) return -1;
    return fast_grid(&p, ray->tmax, M, axis, out);
}

int cbvh_ray_box_float_fast_only(const cbvh_ray *ray, int M, const cbvh_f32 lo[3], const cbvh_f32 hi[3],
                                 cbvh_box_result *out) {
    cbvh_rb_ray p;
    cbvh_rb_prepare(ray, &p);
    if (prep_status(&p, ray->tmax, M) | float_status(lo, hi)) return -1;
    return fast_float(&p, ray->tmax, M, lo, hi, out);
}

cbvh_unit_path cbvh_ray_box_path(const cbvh_ray *ray, int M, const cbvh_grid_axis axis[3]) {
    cbvh_rb_ray p;
    cbvh_box_result out;
    cbvh_rb_prepare(ray, &p);
    if (prep_status(&p, ray->tmax, M) | grid_status(axis)) return CBVH_PATH_REJECT;
    return fast_grid(&p, ray->tmax, M, axis, &out) == 0 ? CBVH_PATH_FAST : CBVH_PATH_EXACT;
}
