/* Ray-box unit (docs/traversal.md §3) against an exact rational oracle (GMP):
 *   - never a false miss: the exact slab test hits => the unit hits;
 *   - enclosure: t_near <= exact near, t_far >= exact far;
 *   - tightness: t_near / t_far are the M-bit directed roundings (checked by
 *     the next M-bit value beyond them lying on the other side of the exact value);
 * over >= 1M structured and random inputs (hard cases: axis-parallel rays with
 * +0/-0 components, origins on faces and inside, grazing rays along faces,
 * rays aimed at corners, -2^128 lower bounds, huge scales), every M in 3..24.
 * Plus NaN/Inf/zero-direction rejects and the float-plane variant, and the
 * plain floating-point traversal's binary64 box test (ray_box_ref.h,
 * docs/traversal.md §11) on every input whose planes are binary32: never a
 * false miss, t_lo <= the exact near t; the same for its binary32 lanes
 * (§16) wherever the ray and planes are small enough for them, plus rays
 * whose plane distances underflow binary32 (subnormal and zero t). */
#include <gmp.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/traversal_units.h"
#include "fast/ray_box_ref.h"
#include "test_util.h"

#ifdef CBVH_SANITIZE
#define N_CASES 150000
#else
#define N_CASES 1100000
#endif

static uint64_t rs = 0x9E3779B97F4A7C15u;
static uint64_t rnd(void) { return tu_xorshift64(&rs); }
static uint64_t below(uint64_t n) { return rnd() % n; }

/* Structured random float: mostly moderate exponents, sometimes extreme. */
static cbvh_f32 rfloat(void) {
    int k = (int)below(10);
    int sign = (int)below(2);
    if (k == 0) return sign ? CBVH_F32_SIGN : 0;
    if (k == 1) return (sign ? CBVH_F32_SIGN : 0) | (uint32_t)(1 + below(0x7FFFFF)); /* subnormal */
    int e = k <= 6 ? (int)below(21) - 10 : (int)below(254) - 126;
    uint32_t frac = (uint32_t)rnd();
    if (below(3) == 0) frac &= 0xFFF000u; /* short significands: exact grid values */
    return cbvh_f32_make(sign, e, frac);
}

/* Exact rational value of a finite pattern. */
static void q_f32(mpq_t q, cbvh_f32 f) {
    int s, e;
    uint32_t sig;
    cbvh_f32_break(f, &s, &sig, &e);
    mpz_t z;
    mpz_init_set_ui(z, sig);
    if (s) mpz_neg(z, z);
    mpq_set_z(q, z);
    if (e > 0) mpq_mul_2exp(q, q, (unsigned long)e);
    else if (e < 0) mpq_div_2exp(q, q, (unsigned long)-e);
    mpz_clear(z);
}
static void q_grid(mpq_t q, cbvh_f32 u, int e, uint32_t c) {
    mpq_t t;
    mpq_init(t);
    if (u == CBVH_F32_NEG_INF) {
        mpq_set_si(q, -1, 1);
        mpq_mul_2exp(q, q, 128);
    } else
        q_f32(q, u);
    mpq_set_ui(t, c, 1);
    if (e > 0) mpq_mul_2exp(t, t, (unsigned)e);
    else if (e < 0) mpq_div_2exp(t, t, (unsigned)-e);
    mpq_add(q, q, t);
    mpq_clear(t);
}

/* Largest-magnitude-step neighbour of x on the M-bit grid, toward +Inf (up=1)
 * or -Inf, as an exact rational: x + 2^(ulp exponent at M bits). */
static void q_step(mpq_t out, cbvh_f32 x, int M, int up) {
    int s, e;
    uint32_t sig;
    cbvh_f32_break(x, &s, &sig, &e);
    q_f32(out, x);
    mpq_t st;
    mpq_init(st);
    int top;
    if (sig == 0) top = -149 + M - 1; /* zero: any step tiny enough is fine */
    else top = e + (31 - __builtin_clz(sig));
    /* toward zero from a power of two the grid is finer: use the finer step */
    int lsb = top - M + 1;
    if (sig && (sig & (sig - 1)) == 0 && ((up && s) || (!up && !s))) lsb--;
    if (lsb < -149) lsb = -149;
    mpq_set_ui(st, 1, 1);
    if (lsb > 0) mpq_mul_2exp(st, st, (unsigned)lsb);
    else mpq_div_2exp(st, st, (unsigned)-lsb);
    if (up) mpq_add(out, out, st);
    else mpq_sub(out, out, st);
    mpq_clear(st);
}

static long n_hit, n_exact_hit, failures;
static long n_ref_checked, n_ref_exact_hit, n_ref_hit;
static long n_ref32_checked, n_ref32_exact_hit, n_ref32_tiny;

/* Plane u + c 2^e as a binary32 when it is one exactly (1), else 0. */
static int plane_f32(const cbvh_grid_axis *g, uint32_t c, cbvh_f32 *out) {
    if (g->u == CBVH_F32_NEG_INF) return 0;
    int s, e;
    uint32_t sig;
    cbvh_f32_break(g->u, &s, &sig, &e);
    cbvh_f32 dn = cbvh_f32_add_dyadic(s ? -(int64_t)sig : (int64_t)sig, e, (int64_t)c, g->e, CBVH_RND_DOWN);
    cbvh_f32 up = cbvh_f32_add_dyadic(s ? -(int64_t)sig : (int64_t)sig, e, (int64_t)c, g->e, CBVH_RND_UP);
    if (dn != up || cbvh_f32_is_nan_or_inf(dn)) return 0;
    *out = dn;
    return 1;
}
static long n_tight_checked;

static void fail(const char *what, const cbvh_ray *r, int M, const cbvh_grid_axis *g) {
    if (failures++ < 10) {
        fprintf(stderr, "FAIL %s: M=%d o=%08X %08X %08X d=%08X %08X %08X t=[%08X,%08X]", what, M, r->o[0], r->o[1],
                r->o[2], r->d[0], r->d[1], r->d[2], r->tmin, r->tmax);
        for (int a = 0; a < 3; a++) fprintf(stderr, " [u=%08X e=%d r=%u s=%u]", g[a].u, g[a].e, g[a].r, g[a].s);
        fprintf(stderr, "\n");
    }
}

/* The plain float traversal's box test for ray against [tmin, tmax]: the
 * variant the ray calls for, or the general one (general = 1). */
static void ref_box(const cbvh_ray *ray, const float box[12], int general, int hit[2], double t_lo[2]) {
    cbvh_ref_ray rr;
    cbvh_ref_prepare(ray, &rr);
    double cull = cbvh_float_of(ray->tmax);
    if (general) cbvh_ref_box2_any(&rr, box, cull, hit, t_lo);
    else cbvh_ref_box2_for(&rr, box, cull, hit, t_lo);
}

/* The binary32 lanes (cbvh_ref_boxw32_c, docs/traversal.md §16) on the same
 * two boxes when the ray and planes are small enough, checked against the
 * exact result of box 0 (hit, exact near tn): never a false miss, t_lo <=
 * tn.  Box 1 must be a superset of box 0 (or the same). */
static void check_ref32(const cbvh_ray *ray, const float box[12], int hit, const mpq_t tn) {
    cbvh_ref_ray rr;
    cbvh_ref_prepare(ray, &rr);
    cbvh_ref_prepare32(ray, &rr);
    int ok = rr.small;
    for (int k = 0; k < 12; k++) ok &= cbvh_ref32_plane_ok(box[k]);
    if (!ok) return;
    double tl[2];
    int m = cbvh_ref_boxw32_c(&rr, box, 2, bf(ray->tmax), tl);
    n_ref32_checked++;
    n_ref32_exact_hit += hit;
    cbvh_grid_axis none[3] = {{0, 0, 0, 1}, {0, 0, 0, 1}, {0, 0, 0, 1}};
    if (hit && (m & 3) != 3) fail("binary32 lanes: false miss", ray, 24, none);
    if (hit) {
        mpq_t t;
        mpq_init(t);
        mpq_set_d(t, tl[0]);
        if (mpq_cmp(t, tn) > 0) fail("binary32 lanes: t_lo above exact near", ray, 24, none);
        mpq_set_d(t, 0x1p-126);
        n_ref32_tiny += mpq_cmp(tn, t) < 0;
        mpq_clear(t);
    }
}

/* The exact slab test on rational planes lo[a] <= hi[a]: 1 on a hit, with
 * tn / tf the exact near / far t (far_inf: no finite far), near_axis /
 * far_axis the axis that set them (-1: tmin / tmax). */
static int exact_slab(const cbvh_ray *ray, mpq_t lo[3], mpq_t hi[3], mpq_t tn, mpq_t tf, int *far_inf,
                      int *near_axis, int *far_axis) {
    mpq_t o, d, n, f;
    mpq_inits(o, d, n, f, NULL);
    int hit = 1;
    *far_inf = ray->tmax == CBVH_F32_POS_INF;
    *near_axis = *far_axis = -1;
    q_f32(tn, ray->tmin);
    if (!*far_inf) q_f32(tf, ray->tmax);
    for (int a = 0; a < 3 && hit; a++) {
        q_f32(o, ray->o[a]);
        if (cbvh_f32_is_zero(ray->d[a])) {
            if (mpq_cmp(o, lo[a]) < 0 || mpq_cmp(o, hi[a]) > 0) hit = 0;
            continue;
        }
        q_f32(d, ray->d[a]);
        int neg = mpq_sgn(d) < 0;
        mpq_sub(n, neg ? hi[a] : lo[a], o);
        mpq_div(n, n, d);
        mpq_sub(f, neg ? lo[a] : hi[a], o);
        mpq_div(f, f, d);
        if (mpq_cmp(n, tn) > 0) {
            mpq_set(tn, n);
            *near_axis = a;
        }
        if (*far_inf || mpq_cmp(f, tf) < 0) {
            mpq_set(tf, f);
            *far_inf = 0;
            *far_axis = a;
        }
    }
    if (hit && !*far_inf && mpq_cmp(tn, tf) > 0) hit = 0;
    mpq_clears(o, d, n, f, NULL);
    return hit;
}

/* Check one input against the oracle. */
static void check(const cbvh_ray *ray, int M, const cbvh_grid_axis g[3]) {
    cbvh_box_result res;
    uint32_t st = cbvh_ray_box(ray, M, g, &res);
    if (st) {
        fail("unexpected reject", ray, M, g);
        return;
    }
    mpq_t lo[3], hi[3], tn, tf, t;
    for (int a = 0; a < 3; a++) {
        mpq_inits(lo[a], hi[a], NULL);
        q_grid(lo[a], g[a].u, g[a].e, g[a].r);
        q_grid(hi[a], g[a].u, g[a].e, g[a].s);
    }
    mpq_inits(tn, tf, t, NULL);
    int far_inf, near_axis, far_axis;
    int hit = exact_slab(ray, lo, hi, tn, tf, &far_inf, &near_axis, &far_axis);
    n_exact_hit += hit;
    /* the plain float traversal's box test on the same planes, as both children */
    float box[12];
    int planes_ok = 1;
    for (int a = 0; a < 3; a++) {
        cbvh_f32 l, h;
        planes_ok &= plane_f32(&g[a], g[a].r, &l) && plane_f32(&g[a], g[a].s, &h);
        if (!planes_ok) break;
        for (int c = 0; c < 2; c++) {
            box[CBVH_REF_AT(0, a, c)] = bf(l);
            box[CBVH_REF_AT(1, a, c)] = bf(h);
        }
    }
    if (planes_ok) {
        int rh[2];
        double tl[2];
        ref_box(ray, box, 0, rh, tl);
        n_ref_checked++;
        n_ref_exact_hit += hit;
        n_ref_hit += rh[0];
        if (rh[0] != rh[1] || (rh[0] && tl[0] != tl[1])) fail("plain float box: lanes differ", ray, M, g);
        if (hit && !rh[0]) fail("plain float box: false miss", ray, M, g);
        if (hit && rh[0]) {
            mpq_set_d(t, tl[0]);
            if (mpq_cmp(t, tn) > 0) fail("plain float box: t_lo above exact near", ray, M, g);
        }
        check_ref32(ray, box, hit, tn);
    }
    n_hit += res.hit;
    if (hit && !res.hit) fail("false miss", ray, M, g);
    if (res.hit) {
        /* enclosure of the exact interval (when there is one) */
        if (hit) {
            q_f32(t, res.t_near);
            if (mpq_cmp(t, tn) > 0) fail("t_near above exact", ray, M, g);
            if (res.t_far != CBVH_F32_POS_INF) {
                q_f32(t, res.t_far);
                if (far_inf || mpq_cmp(t, tf) < 0) fail("t_far below exact", ray, M, g);
            }
        }
        /* tightness: the next M-bit value beyond the output crosses the exact value */
        /* (skipped where the output is the clamp tmin/tmax, or IEEE overflow to +-FLT_MAX) */
        if (hit && near_axis >= 0 && res.t_near != ray->tmin && (res.t_near & ~CBVH_F32_SIGN) != CBVH_F32_MAX &&
            !cbvh_f32_is_nan_or_inf(res.t_near) && (res.t_near & CBVH_F32_EXP)) {
            q_step(t, res.t_near, M, 1);
            if (mpq_cmp(t, tn) <= 0) fail("t_near not tight", ray, M, g);
            n_tight_checked++;
        }
        if (hit && far_axis >= 0 && res.t_far != ray->tmax && (res.t_far & ~CBVH_F32_SIGN) != CBVH_F32_MAX &&
            !cbvh_f32_is_nan_or_inf(res.t_far) && (res.t_far & CBVH_F32_EXP)) {
            q_step(t, res.t_far, M, 0);
            if (mpq_cmp(t, tf) >= 0) fail("t_far not tight", ray, M, g);
        }
    } else if (res.t_near || res.t_far) fail("miss with non-zero t", ray, M, g);
    for (int a = 0; a < 3; a++) mpq_clears(lo[a], hi[a], NULL);
    mpq_clears(tn, tf, t, NULL);
}

/* The ray interval of kind tk: 0 random tmin, +Inf; 1 [0, +Inf]; 2 [0, random];
 * 3 [0, random] ordered (a random tmax below 0 becomes tmin). */
static void set_interval(cbvh_ray *r, int tk) {
    r->tmin = tk == 0 ? rfloat() : 0;
    r->tmax = tk <= 1 ? CBVH_F32_POS_INF : rfloat();
    if (tk == 3 && cbvh_f32_key(r->tmax) < cbvh_f32_key(r->tmin)) {
        cbvh_f32 x = r->tmin;
        r->tmin = r->tmax;
        r->tmax = x;
    }
}

/* A grid axis around a random value, sometimes extreme. */
static cbvh_grid_axis raxis(void) {
    cbvh_grid_axis g;
    int k = (int)below(16);
    g.u = k == 0 ? CBVH_F32_NEG_INF : rfloat();
    g.e = k <= 1 ? (int)below(253) - 126 : (int)below(31) - 20;
    uint32_t n = 1u << (3 + below(8)); /* 2^N, N = 3..10 */
    g.r = (uint32_t)below(n);
    g.s = g.r + 1 + (uint32_t)below(n - g.r);
    if (below(8) == 0) g.s = n; /* s = 2^N */
    return g;
}

/* A value exactly on plane u + c 2^e when representable, else u. */
static cbvh_f32 on_plane(const cbvh_grid_axis *g, uint32_t c) {
    if (g->u == CBVH_F32_NEG_INF) return 0xFF7FFFFFu;
    cbvh_f32 v = cbvh_f32_add_dyadic(0, 0, (int64_t)c, g->e, CBVH_RND_DOWN);
    /* exact sum u + c 2^e if it survives both directed roundings */
    int s, e;
    uint32_t sig;
    cbvh_f32_break(g->u, &s, &sig, &e);
    cbvh_f32 dn = cbvh_f32_add_dyadic(s ? -(int64_t)sig : (int64_t)sig, e, (int64_t)c, g->e, CBVH_RND_DOWN);
    cbvh_f32 up = cbvh_f32_add_dyadic(s ? -(int64_t)sig : (int64_t)sig, e, (int64_t)c, g->e, CBVH_RND_UP);
    (void)v;
    return dn == up && !cbvh_f32_is_nan_or_inf(dn) ? dn : g->u;
}

static void random_case(int M) {
    cbvh_grid_axis g[3];
    cbvh_ray r;
    for (int a = 0; a < 3; a++) g[a] = raxis();
    int kind = (int)below(8);
    for (int a = 0; a < 3; a++) {
        switch (kind) {
        case 0: r.o[a] = on_plane(&g[a], below(2) ? g[a].r : g[a].s); break;      /* on a face */
        case 1: r.o[a] = on_plane(&g[a], g[a].r + (uint32_t)below(g[a].s - g[a].r + 1)); break; /* inside */
        default: r.o[a] = rfloat(); break;
        }
        r.d[a] = rfloat();
        if (below(6) == 0) r.d[a] = below(2) ? 0 : CBVH_F32_SIGN; /* axis-parallel, +0 / -0 */
    }
    if (kind == 2) { /* grazing: parallel to an axis and exactly on a face of it */
        int a = (int)below(3);
        r.d[a] = below(2) ? 0 : CBVH_F32_SIGN;
        r.o[a] = on_plane(&g[a], below(2) ? g[a].r : g[a].s);
    }
    if (kind == 3 || kind == 4) { /* aimed at a corner (3) or a grid point inside (4): d = target - o, rounded */
        for (int a = 0; a < 3; a++) {
            uint32_t code = kind == 3 ? (below(2) ? g[a].r : g[a].s) : g[a].r + (uint32_t)below(g[a].s - g[a].r + 1);
            cbvh_f32 c = on_plane(&g[a], code);
            int s1, e1, s2, e2;
            uint32_t m1, m2;
            cbvh_f32_break(c, &s1, &m1, &e1);
            cbvh_f32_break(r.o[a], &s2, &m2, &e2);
            r.d[a] = cbvh_f32_add_dyadic(s1 ? -(int64_t)m1 : (int64_t)m1, e1, s2 ? (int64_t)m2 : -(int64_t)m2, e2,
                                         below(2) ? CBVH_RND_UP : CBVH_RND_DOWN);
            if (cbvh_f32_is_nan_or_inf(r.d[a])) r.d[a] = 0x3F800000u;
        }
    }
    if (cbvh_f32_is_zero(r.d[0]) && cbvh_f32_is_zero(r.d[1]) && cbvh_f32_is_zero(r.d[2])) r.d[0] = 0x3F800000u;
    int tk = kind >= 3 && kind <= 4 ? (int)below(2) : (int)below(4);
    set_interval(&r, tk);
    check(&r, M, g);
}

/* The plain float box test on a binary32 box [lo, hi] against the exact slab
 * test: never a false miss, t_lo <= the exact near t. */
static void check_ref_float(const cbvh_ray *ray, const cbvh_f32 lo[3], const cbvh_f32 hi[3], cbvh_f32 lo1) {
    mpq_t ql[3], qh[3], tn, tf, n;
    for (int a = 0; a < 3; a++) {
        mpq_inits(ql[a], qh[a], NULL);
        q_f32(ql[a], lo[a]);
        q_f32(qh[a], hi[a]);
    }
    mpq_inits(tn, tf, n, NULL);
    int far_inf, near_axis, far_axis;
    int hit = exact_slab(ray, ql, qh, tn, tf, &far_inf, &near_axis, &far_axis);
    /* child 0 is the box, child 1 the same box with lo_x = lo1 (<= lo_x: a superset) */
    float box[12];
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 2; c++) {
            box[CBVH_REF_AT(0, a, c)] = bf(a == 0 && c == 1 ? lo1 : lo[a]);
            box[CBVH_REF_AT(1, a, c)] = bf(hi[a]);
        }
    int rh[2], gh[2];
    double tl[2], gl[2];
    ref_box(ray, box, 0, rh, tl);
    ref_box(ray, box, 1, gh, gl); /* the general variant is conservative for every ray */
    n_ref_checked++;
    n_ref_exact_hit += hit;
    n_ref_hit += rh[0];
    cbvh_grid_axis none[3] = {{0, 0, 0, 1}, {0, 0, 0, 1}, {0, 0, 0, 1}};
    if (hit && (!rh[0] || !rh[1] || !gh[0] || !gh[1])) fail("plain float box: false miss (float box)", ray, 24, none);
    if (hit) {
        mpq_set_d(n, tl[0]);
        if (mpq_cmp(n, tn) > 0) fail("plain float box: t_lo above exact near (float box)", ray, 24, none);
        mpq_set_d(n, gl[0]);
        if (mpq_cmp(n, tn) > 0) fail("plain float box: general t_lo above exact near", ray, 24, none);
    }
    check_ref32(ray, box, hit, tn);
    for (int a = 0; a < 3; a++) mpq_clears(ql[a], qh[a], NULL);
    mpq_clears(tn, tf, n, NULL);
}

/* A random binary32 box and a ray that often starts on its faces, inside it,
 * grazes a face or is aimed at a corner; extreme and subnormal values,
 * +0 / -0 direction components. */
static void random_float_box(void) {
    cbvh_f32 lo[3], hi[3];
    cbvh_ray r;
    for (int a = 0; a < 3; a++) {
        cbvh_f32 x = rfloat(), y = below(4) ? rfloat() : x; /* sometimes flat */
        if (cbvh_f32_key(x) > cbvh_f32_key(y)) {
            cbvh_f32 t = x;
            x = y;
            y = t;
        }
        lo[a] = x;
        hi[a] = y;
    }
    int kind = (int)below(6);
    for (int a = 0; a < 3; a++) {
        r.o[a] = kind == 0 ? (below(2) ? lo[a] : hi[a]) : rfloat();
        r.d[a] = rfloat();
        if (below(6) == 0) r.d[a] = below(2) ? 0 : CBVH_F32_SIGN;
    }
    if (kind == 1) { /* grazing: parallel to an axis, on a face of it */
        int a = (int)below(3);
        r.d[a] = below(2) ? 0 : CBVH_F32_SIGN;
        r.o[a] = below(2) ? lo[a] : hi[a];
    }
    if (kind == 2) /* aimed at a corner: d = corner - o, rounded */
        for (int a = 0; a < 3; a++) {
            float dd = bf(below(2) ? lo[a] : hi[a]) - bf(r.o[a]);
            r.d[a] = isfinite(dd) ? fb(dd) : 0x3F800000u;
        }
    if (cbvh_f32_is_zero(r.d[0]) && cbvh_f32_is_zero(r.d[1]) && cbvh_f32_is_zero(r.d[2])) r.d[0] = 0x3F800000u;
    int tk = (int)below(4);
    set_interval(&r, tk);
    cbvh_f32 lo1 = below(2) ? lo[0] : rfloat();
    if (cbvh_f32_key(lo1) > cbvh_f32_key(lo[0])) lo1 = lo[0];
    check_ref_float(&r, lo, hi, lo1);
}

/* Where the binary32 lanes underflow: an origin and planes a few multiples
 * of a small spacing apart (down to 2^-149), directions up to 2^62 in
 * magnitude, so plane distances are subnormal or round to zero; tmax
 * sometimes a binary32 near the exact far t (the far margin decides). */
static void random_tiny_box(void) {
    cbvh_f32 lo[3], hi[3];
    cbvh_ray r;
    int e = -149 + (int)below(40); /* the spacing 2^e */
    for (int a = 0; a < 3; a++) {
        float base = ldexpf((float)((int)below(2001) - 1000), e);
        float x = base + ldexpf((float)((int)below(9) - 4), e), y = base + ldexpf((float)((int)below(9) - 4), e);
        lo[a] = fb(x < y ? x : y);
        hi[a] = fb(x < y ? y : x);
        r.o[a] = below(4) ? fb(base + ldexpf((float)((int)below(13) - 6), e)) : (below(2) ? lo[a] : hi[a]);
        float d = ldexpf(1.0f + (float)below(1u << 20) * 0x1p-20f, (int)below(125) - 62);
        r.d[a] = fb(below(2) ? -d : d);
    }
    r.tmin = below(4) ? 0 : fb(ldexpf(1.0f, -149 + (int)below(30)));
    r.tmax = CBVH_F32_POS_INF;
    if (below(2)) { /* tmax at or just around the exact far t of the box */
        mpq_t ql[3], qh[3], tn, tf;
        for (int a = 0; a < 3; a++) {
            mpq_inits(ql[a], qh[a], NULL);
            q_f32(ql[a], lo[a]);
            q_f32(qh[a], hi[a]);
        }
        mpq_inits(tn, tf, NULL);
        int far_inf, na, fa;
        exact_slab(&r, ql, qh, tn, tf, &far_inf, &na, &fa);
        if (!far_inf && mpq_sgn(tf) > 0) {
            cbvh_f32 t = fb((float)mpq_get_d(tf)); /* the far t truncated, then a few ulps either way */
            int64_t k = (int64_t)t + (int64_t)below(5) - 2;
            if (k < 0) k = 0;
            r.tmax = (cbvh_f32)k;
            if (cbvh_f32_key(r.tmax) < cbvh_f32_key(r.tmin)) r.tmin = r.tmax;
        }
        for (int a = 0; a < 3; a++) mpq_clears(ql[a], qh[a], NULL);
        mpq_clears(tn, tf, NULL);
    }
    check_ref_float(&r, lo, hi, lo[0]);
}

static void rejects(void) {
    cbvh_grid_axis g[3] = {{0, 0, 0, 1}, {0, 0, 0, 1}, {0, 0, 0, 1}};
    cbvh_ray r = {{0, 0, 0}, {0x3F800000u, 0, 0}, 0, CBVH_F32_POS_INF};
    cbvh_box_result res;
    struct {
        int field; /* 0..5 o/d, 6 tmin, 7 tmax */
        cbvh_f32 v;
        uint32_t want;
    } cases[] = {{0, 0x7FC00000u, CBVH_ST_NAN_INF}, {3, CBVH_F32_POS_INF, CBVH_ST_NAN_INF},
                 {4, CBVH_F32_NEG_INF, CBVH_ST_NAN_INF}, {6, CBVH_F32_NEG_INF, CBVH_ST_NAN_INF},
                 {7, CBVH_F32_NEG_INF, CBVH_ST_NAN_INF}, {7, 0x7FC00001u, CBVH_ST_NAN_INF},
                 {3, CBVH_F32_SIGN, CBVH_ST_ZERO_DIR}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        cbvh_ray x = r;
        cbvh_f32 *f = cases[i].field < 3 ? &x.o[cases[i].field]
                      : cases[i].field < 6 ? &x.d[cases[i].field - 3]
                      : cases[i].field == 6 ? &x.tmin
                                             : &x.tmax;
        *f = cases[i].v;
        memset(&res, 0xAB, sizeof res);
        uint32_t st = cbvh_ray_box(&x, 24, g, &res);
        if (st != cases[i].want || res.hit || res.t_near || res.t_far) {
            fprintf(stderr, "FAIL reject case %zu: status %02X\n", i, st);
            failures++;
        }
    }
    /* unit's own rejects: M, scale, codes, inverted, NaN/+Inf u */
    cbvh_grid_axis b[3];
    memcpy(b, g, sizeof b);
    if (cbvh_ray_box(&r, 2, g, &res) != CBVH_ST_BAD_PARAM || cbvh_ray_box(&r, 25, g, &res) != CBVH_ST_BAD_PARAM) failures++;
    b[1].e = 127;
    if (cbvh_ray_box(&r, 24, b, &res) != CBVH_ST_BAD_SCALE) failures++;
    memcpy(b, g, sizeof b);
    b[2].s = 1025;
    if (cbvh_ray_box(&r, 24, b, &res) != CBVH_ST_BAD_CODE) failures++;
    memcpy(b, g, sizeof b);
    b[0].r = 5;
    b[0].s = 5;
    if (cbvh_ray_box(&r, 24, b, &res) != CBVH_ST_INVERTED) failures++;
    memcpy(b, g, sizeof b);
    b[0].u = CBVH_F32_POS_INF;
    if (cbvh_ray_box(&r, 24, b, &res) != CBVH_ST_NAN_INF) failures++;
    b[0].u = CBVH_F32_NEG_INF; /* -2^128: valid */
    if (cbvh_ray_box(&r, 24, b, &res) != 0) failures++;
}

/* Hand-checked values: unit box [0,1]^3, ray from (-1, .5, .5) along +x:
 * t in [1, 2]; with d = (+0 | -0) on y/z; a ray on the face y = 1 grazes it;
 * one just above misses. */
static void known(void) {
    cbvh_grid_axis g[3] = {{0, 0, 0, 1}, {0, 0, 0, 1}, {0, 0, 0, 1}};
    cbvh_ray r = {{0xBF800000u, 0x3F000000u, 0x3F000000u}, {0x3F800000u, CBVH_F32_SIGN, 0}, 0, CBVH_F32_POS_INF};
    cbvh_box_result res;
    if (cbvh_ray_box(&r, 8, g, &res) || !res.hit || res.t_near != 0x3F800000u || res.t_far != 0x40000000u) {
        fprintf(stderr, "FAIL known 1: %d %08X %08X\n", res.hit, res.t_near, res.t_far);
        failures++;
    }
    r.o[1] = 0x3F800000u; /* on the face y = 1, parallel to it: hit */
    if (cbvh_ray_box(&r, 8, g, &res) || !res.hit) failures++;
    r.o[1] = 0x3F800001u; /* just outside: miss */
    if (cbvh_ray_box(&r, 8, g, &res) || res.hit) failures++;
    /* d = 3: t = [1/3, 2/3] rounded at M = 3 bits: RD(1/3) = 0.3125, RU(2/3) = 0.75 */
    r.o[1] = 0x3F000000u;
    r.d[0] = 0x40400000u;
    if (cbvh_ray_box(&r, 3, g, &res) || !res.hit || res.t_near != 0x3EA00000u || res.t_far != 0x3F400000u) {
        fprintf(stderr, "FAIL known M=3: %08X %08X\n", res.t_near, res.t_far);
        failures++;
    }
    /* float variant agrees with the grid variant on the same planes */
    cbvh_f32 lo[3] = {0, 0, 0}, hi[3] = {0x3F800000u, 0x3F800000u, 0x3F800000u};
    cbvh_box_result rf;
    if (cbvh_ray_box_float(&r, 3, lo, hi, &rf) || memcmp(&rf, &res, sizeof rf)) failures++;
}

int main(void) {
    known();
    rejects();
    long per_m = N_CASES / (CBVH_MANT_MAX - CBVH_MANT_MIN + 1);
    long total = 0;
    for (int M = CBVH_MANT_MIN; M <= CBVH_MANT_MAX; M++)
        for (long i = 0; i < per_m; i++, total++) random_case(M);
    printf("ray_box: %ld inputs, M = %d..%d: exact hits %ld, unit hits %ld (conservative extra %ld), "
           "tightness checked %ld, failures %ld\n",
           total, CBVH_MANT_MIN, CBVH_MANT_MAX, n_exact_hit, n_hit, n_hit - n_exact_hit, n_tight_checked, failures);
    for (long i = 0; i < N_CASES / 2; i++) random_float_box();
    for (long i = 0; i < N_CASES / 4; i++) random_tiny_box();
    printf("plain float box test: %ld inputs with binary32 planes, exact hits %ld, its hits %ld\n", n_ref_checked,
           n_ref_exact_hit, n_ref_hit);
    printf("its binary32 lanes: %ld inputs small enough for them, exact hits %ld (%ld entering below 2^-126)\n",
           n_ref32_checked, n_ref32_exact_hit, n_ref32_tiny);
    if (n_ref32_checked < N_CASES / 4 || n_ref32_exact_hit < n_ref32_checked / 20 || n_ref32_tiny < N_CASES / 100) {
        fprintf(stderr, "FAIL: too few binary32 lane checks (%ld, %ld exact hits, %ld tiny)\n", n_ref32_checked,
                n_ref32_exact_hit, n_ref32_tiny);
        return 1;
    }
    if (n_ref_checked < N_CASES / 2 || n_ref_exact_hit < n_ref_checked / 20) {
        fprintf(stderr, "FAIL: too few plain float box checks (%ld, %ld exact hits)\n", n_ref_checked,
                n_ref_exact_hit);
        return 1;
    }
    if (n_exact_hit < total / 50) {
        fprintf(stderr, "FAIL: too few exact hits (%ld) for a meaningful test\n", n_exact_hit);
        return 1;
    }
    return failures ? 1 : 0;
}
