/* The traversal's fast paths (docs/traversal.md §9) against the units:
 *   - the ray-box unit's binary64 filter (rtl-model/src/fast/ray_box_f64.h) on
 *     float planes and on grid planes u + r 2^e: whenever it decides, hit and
 *     t_near equal the exact path's (cbvh_ray_box_*_exact_only) bit for bit;
 *     the claim that a grid plane is exact in binary64 is checked with an
 *     error-free sum (2Sum); the two-box version (cbvh_rbf_box2) equals the
 *     one-box version lane by lane, and its variants for valid planes and
 *     for binary32 planes (SSE2 on x86-64) equal it; test_box_f64_plain is
 *     the same test with the two-box lanes in plain C (CBVH_NO_SSE2);
 *   - the node-pair decode for the traversal (rtl-model/src/fast/decode_fast.h):
 *     accepts exactly the pairs the unit decodes with status 0 (N = 3..10) and
 *     then gives the same leaf/empty/pointer, relative coordinates and child
 *     contexts as cbvh_nodepair_decode + cbvh_axis_child_ctx;
 *   - the plain float traversals' slab test (rtl-model/src/fast/ray_box_ref.h):
 *     cbvh_ref_box2 (SSE2 lanes on x86-64), the four-box cbvh_ref_box4 and
 *     the eight-box cbvh_ref_box8 equal the plain C cbvh_ref_box2_c bit for
 *     bit on every box (whose conservativeness tests/traversal/test_ray_box.c
 *     checks against exact rationals), and the general variant on four and
 *     eight boxes equals it on two; test_box_f64_avx is the same test
 *     compiled with -mavx, where box4 and box8 use AVX's four-lane registers
 *     (the wide float traversals' AVX loop, docs/traversal.md §15);
 *   - and the filter decides nearly all scene-like inputs (so the comparison
 *     is not vacuous and the speed-up is real).
 * Inputs: random values over wide exponent ranges plus hard cases - plane
 * distances exactly on the M-bit grid and one binary32 ulp beside it, origins
 * on planes, power-of-two directions, zero / subnormal / huge bounds, -Inf
 * context bounds, random and corrupted node-pair bytes. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fast/decode_fast.h"
#include "fast/ray_box_f64.h"
#include "fast/ray_box_ref.h"
#include "fast/ray_prep.h"
#include "test_util.h"

#ifdef CBVH_SANITIZE
#define NBOX 300000
#define NPAIR 200000
#else
#define NBOX 2000000
#define NPAIR 1000000
#endif

static long failures;
static uint64_t rs = 0x2545F4914F6CDD1Du;
static uint64_t rnd(void) { return tu_xorshift64(&rs); }
static uint32_t below(uint32_t n) { return (uint32_t)(rnd() % n); }

/* A binary32 pattern with exponent near emid; specials when wide. */
static cbvh_f32 rf(int emid, int spread, int wide) {
    uint32_t k = wide ? below(40) : 10 + below(30);
    cbvh_f32 sign = (rnd() & 1) ? CBVH_F32_SIGN : 0;
    if (k == 0) return sign;
    if (k == 1) return sign | (1 + below(0x7FFFFF));
    if (k == 2) return sign | CBVH_F32_MAX;
    if (k == 3) return sign | CBVH_F32_POS_INF;
    int e = emid - spread + (int)below((uint32_t)(2 * spread + 1));
    if (e < -126) e = -126;
    if (e > 127) e = 127;
    uint32_t frac = k < 7 ? 0 : k < 10 ? below(8) << 20 : (uint32_t)(rnd() & CBVH_F32_FRAC);
    return sign | cbvh_f32_make(0, e, frac);
}

/* A direction component: random, power of two, few bits, sometimes zero. */
static cbvh_f32 rdir(int wide) {
    uint32_t k = below(16);
    if (k == 0 && wide) return (rnd() & 1) ? CBVH_F32_SIGN : 0;
    if (k < 4 && wide) return ((rnd() & 1) ? CBVH_F32_SIGN : 0) | cbvh_f32_make(0, (int)below(7) - 3, 0); /* 2^k */
    return rf(0, wide ? 60 : 3, wide);
}

/* Plane at which the distance from o along d is exactly the M-bit value t
 * (when representable as binary32), or one ulp beside it. */
static cbvh_f32 plane_on_grid(cbvh_f32 o, cbvh_f32 d, int M, int nudge) {
    int mb = M < 18 ? M : 18 - (int)below(3); /* bits of t: o + t d stays within 24 bits */
    double t = (double)(int)(below(1u << mb) | (1u << (mb - 1))) * (double)(1 << below(8)) / (double)(1 << 12);
    if (rnd() & 1) t = -t;
    double p = (double)bf(o) + t * (double)bf(d);
    float pf = (float)p;
    if (nudge) pf = nextafterf(pf, (rnd() & 1) ? 1e30f : -1e30f);
    return fb(pf);
}

/* cbvh_rbf_box2 on (box, other box) equals cbvh_rbf_box on each lane. */
static double prev_lo[3], prev_hi[3];
static long n_valid_pairs, n_f32_pairs;
static void check_pair(const cbvh_rbf_ray *p, double tmax, const double lo[3], const double hi[3], int dec, int hit,
                       double tn, long i) {
    double pl[2][3][2], t2[2], tb = 0; /* [lower, upper][axis][box] */
    int hit2[2], hb = 0;
    for (int a = 0; a < 3; a++) {
        pl[0][a][0] = lo[a];
        pl[1][a][0] = hi[a];
        pl[0][a][1] = prev_lo[a];
        pl[1][a][1] = prev_hi[a];
    }
    int decb = cbvh_rbf_box(p, tmax, prev_lo, prev_hi, &hb, &tb);
    int d2 = cbvh_rbf_box2(p, tmax, (const double(*)[3][2])pl, hit2, t2);
    if (d2 != (dec | decb << 1) || (dec && (hit2[0] != hit || t2[0] != tn)) ||
        (decb && (hit2[1] != hb || t2[1] != tb))) {
        if (failures++ < 10) printf("FAIL box pair %ld: cbvh_rbf_box2 differs from cbvh_rbf_box\n", i);
    }
    /* the variant without validity tests, on pairs of valid boxes (lo < hi, finite) */
    int valid = 1;
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 2; c++) valid &= pl[0][a][c] < pl[1][a][c] && isfinite(pl[0][a][c]) && isfinite(pl[1][a][c]);
    if (valid) {
        int hv[2];
        double tv[2];
        int dv = cbvh_rbf_box2_valid(p, tmax, (const double(*)[3][2])pl, hv, tv);
        n_valid_pairs++;
        if (dv != d2 || ((dv & 1) && (hv[0] != hit2[0] || tv[0] != t2[0])) ||
            ((dv & 2) && (hv[1] != hit2[1] || tv[1] != t2[1]))) {
            if (failures++ < 10) printf("FAIL box pair %ld: cbvh_rbf_box2_valid differs from cbvh_rbf_box2\n", i);
        }
        /* and on binary32 planes, when every plane is one (the decoded CBVH's records) */
        float p32[2][3][2];
        int all32 = 1;
        for (int k = 0; k < 2; k++)
            for (int a = 0; a < 3; a++)
                for (int c = 0; c < 2; c++) {
                    int fits = fabs(pl[k][a][c]) <= FLT_MAX; /* valid planes are finite; the conversion must not overflow */
                    p32[k][a][c] = fits ? (float)pl[k][a][c] : 0.0f;
                    all32 &= fits && (double)p32[k][a][c] == pl[k][a][c];
                }
        if (all32) {
            int df = cbvh_rbf_box2_valid_f32(p, tmax, (const float(*)[3][2])p32, hv, tv);
            n_f32_pairs++;
            if (df != d2 || ((df & 1) && (hv[0] != hit2[0] || tv[0] != t2[0])) ||
                ((df & 2) && (hv[1] != hit2[1] || tv[1] != t2[1]))) {
                if (failures++ < 10) printf("FAIL box pair %ld: cbvh_rbf_box2_valid_f32 differs from cbvh_rbf_box2\n", i);
            }
        }
    }
    memcpy(prev_lo, lo, sizeof prev_lo);
    memcpy(prev_hi, hi, sizeof prev_hi);
}

static int hit_ok(int decided, int hit, double tn, uint32_t st, const cbvh_box_result *ex) {
    if (!decided) return 1;
    if (st) return !hit; /* a rejected box is a miss for the traversal */
    if (hit != ex->hit) return 0;
    return !hit || cbvh_rbf_to_f32(tn == 0 ? 0.0 : tn) == ex->t_near;
}

/* scene: no power-of-two or zero direction components (where an exact
 * quotient often lands on the grid and the filter leaves it to the unit) */
static void make_ray(cbvh_ray *r, int wide, int scene, int M, int *mout) {
    for (int a = 0; a < 3; a++) {
        r->o[a] = rf(0, wide ? 40 : 4, wide && below(4) == 0);
        r->d[a] = rdir(!scene);
    }
    if (r->d[0] == 0 && r->d[1] == 0 && r->d[2] == 0) r->d[0] = fb(1.0f);
    uint32_t k = below(8);
    r->tmin = k == 0 ? CBVH_F32_SIGN : k == 1 ? rf(0, 6, 0) : 0;
    k = below(8);
    r->tmax = k < 5 ? CBVH_F32_POS_INF : k == 5 ? rf(0, 6, 0) & ~CBVH_F32_SIGN : rf(2, 4, 0);
    *mout = M ? M : CBVH_MANT_MIN + (int)below(CBVH_MANT_MAX - CBVH_MANT_MIN + 1);
}

static void test_float_boxes(void) {
    long decided = 0, typical_total = 0, typical_decided = 0;
    for (long i = 0; i < NBOX; i++) {
        int wide = (i & 3) == 0, M;
        cbvh_ray ray;
        make_ray(&ray, wide, (int)(i & 1), (i & 2) ? 24 : 0, &M);
        cbvh_f32 lo[3], hi[3];
        int hard = (i & 3) == 2; /* typical (i odd): no hard cases */
        for (int a = 0; a < 3; a++) {
            uint32_t k = hard ? below(3) : 2 + below(8);
            cbvh_f32 x, y;
            if (k == 0) {
                /* a few-bit direction and a few-bit origin: o + t d is often
                 * exact in binary32, so t lies exactly on the M-bit grid
                 * while 1/d is inexact (t^ a few ulps beside t) */
                ray.d[a] = fb((float)((1 + 2 * (int)below(4)) * ((rnd() & 1) ? 1 : -1)) * ldexpf(1.0f, (int)below(9) - 4));
                ray.o[a] = fb((float)((int)below(64) - 32) * ldexpf(1.0f, (int)below(5) - 2));
                x = plane_on_grid(ray.o[a], ray.d[a], M, 0);
                y = plane_on_grid(ray.o[a], ray.d[a], M, below(2));
            } else if (k == 1 && below(2)) {
                /* distances around 2^-126 (the binary32 subnormal border) */
                ray.o[a] = rf(-110, 3, 0);
                ray.d[a] = rf(0, 2, 0);
                x = ray.o[a] + below(300);
                y = x + below(300);
                if ((x ^ ray.o[a]) >> CBVH_F32_FRAC_BITS || (y ^ ray.o[a]) >> CBVH_F32_FRAC_BITS) x = y = ray.o[a]; /* stay in o's binade */
            } else if (k == 1) {
                x = ray.o[a]; /* origin on a plane */
                y = rf(0, wide ? 40 : 4, 0);
            } else {
                x = rf(0, wide ? 40 : 4, wide && below(4) == 0);
                y = rf(0, wide ? 40 : 4, wide && below(4) == 0);
            }
            if ((!hard || below(16)) && cbvh_f32_cmp(x, y) > 0) { /* hard: sometimes inverted */
                cbvh_f32 t = x;
                x = y;
                y = t;
            }
            lo[a] = x;
            hi[a] = y;
        }
        cbvh_box_result ex;
        uint32_t st = cbvh_ray_box_float_exact_only(&ray, M, lo, hi, &ex);
        cbvh_rbf_ray p;
        cbvh_rbf_prepare(&ray, M, &p);
        double dlo[3], dhi[3];
        for (int a = 0; a < 3; a++) {
            dlo[a] = bf(lo[a]);
            dhi[a] = bf(hi[a]);
        }
        int hit = 0;
        double tn = 0;
        int dec = cbvh_rbf_box(&p, (double)bf(ray.tmax), dlo, dhi, &hit, &tn);
        check_pair(&p, (double)bf(ray.tmax), dlo, dhi, dec, hit, tn, i);
        decided += dec;
        if (!hit_ok(dec, hit, tn, st, &ex)) {
            if (failures++ < 10)
                printf("FAIL float box %ld: M=%d filter hit=%d tn=%a, exact st=%x hit=%d tn=%08x\n", i, M, hit, tn,
                       st, ex.hit, ex.t_near);
        }
        if (i & 1) {
            typical_total++;
            typical_decided += dec;
        }
    }
    printf("float planes: %d boxes, filter decided %ld (scene-like: %.4f)\n", NBOX, decided,
           (double)typical_decided / (double)typical_total);
    if ((double)typical_decided < 0.95 * (double)typical_total) {
        printf("FAIL: the filter decides too few scene-like float boxes\n");
        failures++;
    }
}

/* 1 if a + b is exact in binary64 (2Sum error term zero). */
static int sum_exact(double a, double b) {
    double s = a + b, bb = s - a;
    return (a - (s - bb)) + (b - bb) == 0;
}

/* The decoder's clb = RD(u + r 2^e) (axis_decoder.c, general path). */
static cbvh_f32 unit_rd(cbvh_f32 u, uint32_t r, int e) {
    if (u == CBVH_F32_NEG_INF) return cbvh_grid_add_dyadic(-1, 128, (int64_t)r, e, CBVH_RND_DOWN);
    int sign, ue;
    uint32_t m;
    cbvh_grid_break(u, &sign, &m, &ue);
    return cbvh_grid_add_dyadic(sign ? -(int64_t)m : (int64_t)m, ue, (int64_t)r, e, CBVH_RND_DOWN);
}

static void test_grid_boxes(void) {
    long rd32_total = 0, rd32_taken = 0;
    long decided = 0, exact_axes = 0, typical_total = 0, typical_decided = 0;
    for (long i = 0; i < NBOX; i++) {
        int wide = (i & 3) == 0, M;
        cbvh_ray ray;
        make_ray(&ray, wide, (int)(i & 1), (i & 2) ? 24 : 0, &M);
        cbvh_grid_axis g[3];
        cbvh_rbf_axis ax[3];
        double dlo[3], dhi[3];
        int all_exact = 1;
        int hard = (i & 3) == 2, valid = 1;
        for (int a = 0; a < 3; a++) {
            uint32_t k = hard ? below(7) : 6 + below(6);
            g[a].u = k == 0 ? CBVH_F32_NEG_INF : k == 1 ? (rnd() & 1) * CBVH_F32_SIGN : rf(0, wide ? 60 : 4, 0);
            int eu = (int)cbvh_f32_exp_field(g[a].u) - CBVH_F32_EXP_BIAS;
            int e = wide ? (int)below(253) - 126 : eu - 20 + (int)below(24);
            if (k == 5) { /* sums near the binary32 range ends (subnormal / overflow) */
                uint32_t kk = below(3);
                g[a].u = kk == 0 ? rf(126, 1, 0) : kk == 1 ? rf(-126, 1, 0) : ((rnd() & 1) * CBVH_F32_SIGN) | below(1u << 23);
                eu = (int)cbvh_f32_exp_field(g[a].u) - CBVH_F32_EXP_BIAS;
                e = eu - (int)below(30);
            }
            if (k == 2) e = eu - 23 - 29 + (int)below(3); /* at the exactness limits */
            if (k == 3) e = eu - 23 + 42 - (int)below(3);
            if (e < -126) e = -126;
            if (e > 126) e = 126;
            g[a].e = e;
            uint32_t n = 3 + below(8), full = 1u << n;
            g[a].r = below(full);
            g[a].s = g[a].r + 1 + below(full - g[a].r);
            if (hard && below(64) == 0) g[a].s = g[a].r; /* inverted */
            valid &= g[a].r < g[a].s;
            if (k == 4) { /* origin on the lower plane when representable */
                double pl = (double)bf(g[a].u) + (double)g[a].r * ldexp(1.0, e);
                if ((double)(float)pl == pl) ray.o[a] = fb((float)pl);
            }
            ax[a] = cbvh_rbf_axis_prep(g[a].u, g[a].e);
            dlo[a] = ax[a].u + (double)g[a].r * ax[a].step;
            dhi[a] = ax[a].u + (double)g[a].s * ax[a].step;
            if (ax[a].exact) {
                exact_axes++;
                if (!sum_exact(ax[a].u, (double)g[a].r * ax[a].step) ||
                    !sum_exact(ax[a].u, (double)g[a].s * ax[a].step) || ax[a].step != ldexp(1.0, e)) {
                    if (failures++ < 10) printf("FAIL grid axis claimed exact: u=%08x e=%d r=%u\n", g[a].u, e, g[a].r);
                }
            }
            all_exact &= ax[a].exact;
        }
        cbvh_box_result ex;
        uint32_t st = cbvh_ray_box_exact_only(&ray, M, g, &ex);
        cbvh_rbf_ray p;
        cbvh_rbf_prepare(&ray, M, &p);
        int hit = 0;
        double tn = 0;
        /* the traversal calls the filter only for decoded boxes (r < s) */
        int dec = valid && all_exact && cbvh_rbf_box(&p, (double)bf(ray.tmax), dlo, dhi, &hit, &tn);
        if (valid && all_exact) check_pair(&p, (double)bf(ray.tmax), dlo, dhi, dec, hit, tn, i);
        decided += dec;
        if (!hit_ok(dec, hit, tn, st, &ex)) {
            if (failures++ < 10)
                printf("FAIL grid box %ld: M=%d filter hit=%d tn=%a, exact st=%x hit=%d tn=%08x\n", i, M, hit, tn, st,
                       ex.hit, ex.t_near);
        }
        /* the decoded lower bound RD(u + r 2^e), as the traversal rounds it */
        for (int a = 0; a < 3; a++) {
            cbvh_f32 c;
            if (!ax[a].exact) continue;
            rd32_total++;
            if (!cbvh_rbf_rd32(dlo[a], &c)) continue;
            rd32_taken++;
            cbvh_f32 want = unit_rd(g[a].u, g[a].r, g[a].e);
            if (c != want) {
                if (failures++ < 10) printf("FAIL rd32: u=%08x e=%d r=%u: %08x, unit %08x\n", g[a].u, g[a].e, g[a].r, c, want);
            }
        }
        if (i & 1) {
            typical_total++;
            typical_decided += dec;
        }
    }
    printf("grid planes: %d boxes, %ld axes exact in binary64, filter decided %ld (scene-like: %.4f); "
           "RD to binary32 of the lower plane done in binary64 on %ld of %ld exact axes\n", NBOX,
           exact_axes, decided, (double)typical_decided / (double)typical_total, rd32_taken, rd32_total);
    /* the fast RD must take the common case, or the child contexts' fast path is gone */
    if (rd32_taken * 10 < rd32_total * 9) {
        printf("FAIL: cbvh_rbf_rd32 leaves too many lower planes to the units\n");
        failures++;
    }
    if ((double)typical_decided < 0.9 * (double)typical_total) {
        printf("FAIL: the filter decides too few scene-like grid boxes\n");
        failures++;
    }
}

static void random_ctx(const cbvh_params *p, cbvh_axis_ctx *c) {
    uint32_t mask = (1u << p->quant_bits) - 1u;
    c->scale = p->min_scale + (int)below((uint32_t)(127 - p->min_scale));
    if (c->scale > 126) c->scale = 126;
    c->parent_scale = c->scale + (int)below(12);
    if (c->parent_scale > 126) c->parent_scale = 126;
    c->lb_mod = below(mask + 1u);
    uint32_t k = below(40);
    c->clb = k == 0 ? CBVH_F32_NEG_INF : k == 1 ? 0 : rf(c->scale + 20, 8, 0);
    if ((c->clb & 0x7F800000u) == 0x7F800000u && c->clb != CBVH_F32_NEG_INF) c->clb = CBVH_F32_MAX;
    /* rare invalid contexts */
    k = below(200);
    if (k == 0) c->clb = CBVH_F32_POS_INF;
    if (k == 1) c->lb_mod = mask + 1u;
    if (k == 2) c->parent_scale = c->scale - 1;
    if (k == 3) c->scale = p->min_scale - 1;
}

static void test_pair_decode(void) {
    long accepted = 0;
    for (long i = 0; i < NPAIR; i++) {
        cbvh_params p = {3 + (int)below(8), below(4) == 0 ? -126 : -30 + (int)below(20)};
        cbvh_encoding enc = (cbvh_encoding)(rnd() & 1);
        cbvh_node_ctx ctx;
        for (int a = 0; a < 3; a++) random_ctx(&p, &ctx.axis[a]);
        /* nodes of W = 64 (N <= 6) or 96 bits as (w: bits 0..63, x: bits 64..95) */
        int n = p.quant_bits, W = cbvh_node_bits(n), pp = 6 * n + 1, pb = cbvh_node_ptr_bits(n);
        uint8_t bytes[24];
        for (int c = 0; c < 2; c++) {
            uint64_t w = rnd() & ((UINT64_C(1) << (6 * n)) - 1u);
            if (below(4)) { /* mostly valid codes: r < s on every axis */
                uint32_t mask = (1u << n) - 1u;
                w = 0;
                for (int a = 0; a < 3; a++) {
                    uint32_t r = below(mask + 1u), s = r + 1 + below(mask + 1u - r);
                    uint32_t pm = enc == CBVH_ENC_MODULO && ctx.axis[a].parent_scale >= ctx.axis[a].scale
                                      ? cbvh_fast_pmod(&p, &ctx.axis[a])
                                      : 0;
                    w |= (uint64_t)((r + pm) & mask) << (2 * a * n) | (uint64_t)((s + pm) & mask) << (2 * a * n + n);
                }
            }
            uint32_t k = below(16);
            uint64_t ones = (UINT64_C(1) << pb) - 1u;
            if (k == 0) w = 0; /* empty */
            uint64_t ptr = k < 2 ? ones : rnd() & ones, x = 0;
            /* k = 0: the empty marker (leaf, all-ones pointer, codes 0); k = 1: an
             * all-ones pointer with a random leaf bit: an inner child may have it */
            w |= (uint64_t)(k == 0 || (rnd() & 1)) << (pp - 1) | ptr << pp;
            if (W == 96) x = ptr >> (64 - pp); /* the pointer's top bits */
            if (below(32) == 0) { /* a reserved or pointer bit */
                int bit = pp + (int)below((uint32_t)(W - pp));
                if (bit < 64)
                    w |= UINT64_C(1) << bit;
                else
                    x |= UINT64_C(1) << (bit - 64);
            }
            for (int b = 0; b < W / 8; b++) bytes[W / 8 * c + b] = (uint8_t)(b < 8 ? w >> (8 * b) : x >> (8 * (b - 8)));
        }
        cbvh_child_out ch[2];
        uint32_t st = cbvh_nodepair_decode(&p, enc, &ctx, bytes, ch);
        cbvh_fast_child fc[2];
        int ok = cbvh_fast_pair_decode(&p, enc, &ctx, bytes, fc);
        /* accepted => the unit decodes with status 0; the converse may fail
         * only for a pair of two empty children under an invalid context
         * (the unit never reads the context then) */
        int both_empty = 1;
        for (int c = 0; c < 2; c++) both_empty &= ch[c].empty;
        if ((ok && st) || (!ok && !st && !both_empty)) {
            if (failures++ < 10) printf("FAIL pair %ld: fast decode %d, unit status %x\n", i, ok, st);
            continue;
        }
        if (!ok) continue;
        accepted++;
        for (int c = 0; c < 2; c++) {
            if (fc[c].leaf != ch[c].leaf || fc[c].empty != ch[c].empty || fc[c].ptr != ch[c].ptr) {
                if (failures++ < 10) printf("FAIL pair %ld child %d: leaf/empty/ptr differ\n", i, c);
            }
            if (ch[c].empty) continue;
            for (int a = 0; a < 3; a++) {
                uint32_t r, s;
                cbvh_axis_store_codes(&p, CBVH_ENC_RELATIVE, &ctx.axis[a], &ch[c].axis[a], &r, &s);
                if (s == 0) s = 1u << n;
                cbvh_rbf_axis ax = cbvh_rbf_axis_prep(ctx.axis[a].clb, ctx.axis[a].scale);
                double plo = ax.u + (double)fc[c].r[a] * ax.step;
                cbvh_axis_ctx want = cbvh_axis_child_ctx(&ctx.axis[a], &ch[c].axis[a]), got;
                cbvh_fast_child_ctx(&p, enc, &ctx.axis[a], cbvh_fast_pmod(&p, &ctx.axis[a]), &fc[c], a,
                                    ax.exact ? &plo : NULL, &got);
                /* the traversal trusts derived contexts without checking them again */
                if (!cbvh_fast_ctx_ok(&p, &got)) {
                    if (failures++ < 10) printf("FAIL pair %ld child %d axis %d: derived context invalid\n", i, c, a);
                }
                if (r != fc[c].r[a] || s != fc[c].s[a] || memcmp(&want, &got, sizeof want)) {
                    if (failures++ < 10)
                        printf("FAIL pair %ld child %d axis %d: r %u/%u s %u/%u ctx (%d %d %u %08x)/(%d %d %u %08x)\n", i,
                               c, a, fc[c].r[a], r, fc[c].s[a], s, got.parent_scale, got.scale, got.lb_mod, got.clb,
                               want.parent_scale, want.scale, want.lb_mod, want.clb);
                }
            }
        }
    }
    printf("node pairs: %d (N = 3..10), %ld decoded with status 0 by both\n", NPAIR, accepted);
    if (accepted < NPAIR / 10) {
        printf("FAIL: too few valid pairs\n");
        failures++;
    }
}

/* The filter's guard band at its limit: one axis decides t_near with a plane
 * a few ulps beside o + g d for an M-bit grid value g (others wide open), so
 * the exact t_near sits next to a rounding boundary of the M-bit result.
 * Found by mutation testing: an 8-ulp band cut to 1 ulp passed every other
 * case here (M = 3: filter 24, exact 28). */
static void test_filter_margin(void) {
    long decided = 0, n = NBOX;
    for (long i = 0; i < n; i++) {
        int M = CBVH_MANT_MIN + (int)below(CBVH_MANT_MAX - CBVH_MANT_MIN + 1);
        float o = (float)((tu_unit_d(&rs) * 2 - 1) * ldexp(1, (int)below(20) - 10));
        float d = (float)((tu_unit_d(&rs) * 2 - 1) * ldexp(1, (int)below(10) - 5));
        if (d == 0) continue;
        double g = ldexp(1 + floor(tu_unit_d(&rs) * ldexp(1, M - 1)) / ldexp(1, M - 1), (int)below(10) - 5);
        cbvh_f32 pb = fb((float)(o + g * d)) + (uint32_t)((int)below(9) - 4); /* a few ulps beside */
        float P = bf(pb);
        if (!isfinite(P)) continue;
        cbvh_ray ray;
        ray.o[0] = fb(o);
        ray.d[0] = fb(d);
        ray.o[1] = ray.o[2] = 0;
        ray.d[1] = ray.d[2] = fb(1e-3f);
        ray.tmin = fb(-1e30f);
        ray.tmax = CBVH_F32_POS_INF;
        float lo[3] = {d > 0 ? P : P - fabsf(P) - 1e6f, -1e20f, -1e20f};
        float hi[3] = {d > 0 ? P + fabsf(P) + 1e6f : P, 1e20f, 1e20f};
        cbvh_f32 flo[3], fhi[3];
        double dlo[3], dhi[3];
        for (int a = 0; a < 3; a++) {
            flo[a] = fb(lo[a]);
            fhi[a] = fb(hi[a]);
            dlo[a] = lo[a];
            dhi[a] = hi[a];
        }
        cbvh_rbf_ray p;
        cbvh_rbf_prepare(&ray, M, &p);
        int hit = 0;
        double tn = 0;
        int dec = cbvh_rbf_box(&p, HUGE_VAL, dlo, dhi, &hit, &tn);
        decided += dec;
        cbvh_box_result ex;
        uint32_t st = cbvh_ray_box_float_exact_only(&ray, M, flo, fhi, &ex);
        if (!hit_ok(dec, hit, tn, st, &ex) && failures++ < 10)
            printf("FAIL margin case %ld: M=%d o=%a d=%a P=%a: filter hit=%d tn=%a, exact st=%x hit=%d tn=%08x\n", i, M,
                   (double)o, (double)d, (double)P, hit, tn, st, ex.hit, ex.t_near);
    }
    printf("planes beside the M-bit grid: %ld rays, filter decided %ld\n", n, decided);
    if (decided < n / 2) {
        printf("FAIL: the filter decided too few margin cases\n");
        failures++;
    }
}

/* A finite binary32 box coordinate for the plain float slab test. */
static float ref_coord(int wide) {
    float v = bf(rf(0, wide ? 60 : 4, wide));
    return isfinite(v) ? v : (rnd() & 1) ? FLT_MAX : -FLT_MAX;
}

static void test_ref_lanes(void) {
    long n = 0, ngeneral = 0, nhit = 0, n_margin = 0, n32 = 0, n32_hit = 0;
    for (long i = 0; i < NBOX; i++) {
        int wide = (i & 3) == 0, M;
        cbvh_ray ray;
        make_ray(&ray, wide, (i & 7) == 1, 24, &M);
        if (cbvh_f32_is_nan_or_inf(ray.tmin) || cbvh_f32_is_nan(ray.tmax)) continue;
        int finite = 1;
        for (int a = 0; a < 3; a++) finite &= !cbvh_f32_is_nan_or_inf(ray.o[a]) && !cbvh_f32_is_nan_or_inf(ray.d[a]);
        if (!finite || (cbvh_f32_is_zero(ray.d[0]) && cbvh_f32_is_zero(ray.d[1]) && cbvh_f32_is_zero(ray.d[2])))
            continue;
        cbvh_ref_ray r;
        cbvh_ref_prepare(&ray, &r);
        cbvh_ref_prepare32(&ray, &r);
        float b4[24], b2[2][12], b8[48];
        for (int c = 0; c < 4; c++)
            for (int a = 0; a < 3; a++) {
                float x = ref_coord(wide), y = (rnd() & 3) ? ref_coord(wide) : x;
                if (rnd() & 1) { /* near the ray origin, where boxes are entered and left */
                    x = bf(ray.o[a]) + x * 0x1p-20f;
                    y = bf(ray.o[a]) + y * 0x1p-20f;
                }
                float lo = x < y ? x : y, hi = x < y ? y : x;
                b4[CBVH_REF4_AT(0, a, c)] = b2[c / 2][CBVH_REF_AT(0, a, c % 2)] = lo;
                b4[CBVH_REF4_AT(1, a, c)] = b2[c / 2][CBVH_REF_AT(1, a, c % 2)] = hi;
            }
        double cull = (rnd() & 3) ? cbvh_float_of(ray.tmax) : fabs((double)ref_coord(0));
        /* eight boxes: slot c holds box c, slot c + 4 box 3 - c */
        for (int c = 0; c < 8; c++)
            for (int p = 0; p < 2; p++)
                for (int a = 0; a < 3; a++) b8[(p * 3 + a) * 8 + c] = b4[CBVH_REF4_AT(p, a, c < 4 ? c : 7 - c)];
        int h[4], g[4], g8[8];
        double t[4], u[4], u8[8];
        if (!r.general && (i & 3) == 2) { /* cull just below a box's entry: a hit only through the far margin */
            for (int k = 0; k < 2; k++) cbvh_ref_box2_c(&r, b2[k], HUGE_VAL, h + 2 * k, t + 2 * k);
            for (int j = 0, c0 = (int)below(4); j < 4; j++) {
                int c = (c0 + j) & 3;
                if (h[c] && t[c] > 0) {
                    cull = t[c] * (1 + 0x1p-51);
                    n_margin++;
                    break;
                }
            }
        }
        if (r.general) {
            ngeneral++;
            cbvh_ref_boxw_any(&r, b4, 4, cull, g, u);
            cbvh_ref_boxw_any(&r, b8, 8, cull, g8, u8);
            for (int k = 0; k < 2; k++) cbvh_ref_box2_any(&r, b2[k], cull, h + 2 * k, t + 2 * k);
        } else {
            for (int k = 0; k < 2; k++) cbvh_ref_box2_c(&r, b2[k], cull, h + 2 * k, t + 2 * k);
            int m = cbvh_ref_box4(&r, b4, cull, u);
            for (int c = 0; c < 4; c++) g[c] = m >> c & 1;
            int m8 = cbvh_ref_box8(&r, b8, cull, u8);
            for (int c = 0; c < 8; c++) g8[c] = m8 >> c & 1;
            int ok32 = r.small;
            for (int k = 0; k < 48; k++) ok32 &= cbvh_ref32_plane_ok(b8[k]);
            if (ok32) { /* the binary32 lanes (§16): SIMD == plain C, bit for bit */
                float c32 = (float)cull;
                double v4[4], w4[4], v8[8], w8[8];
                if ((double)c32 != cull) c32 = bf(ray.tmax); /* cull is a binary32 value in the traversals */
                int a4 = cbvh_ref_box4_32(&r, b4, c32, v4), c4 = cbvh_ref_boxw32_c(&r, b4, 4, c32, w4);
                int a8 = cbvh_ref_box8_32(&r, b8, c32, v8), c8 = cbvh_ref_boxw32_c(&r, b8, 8, c32, w8);
                n32++;
                n32_hit += a8 != 0;
                if ((a4 != c4 || memcmp(v4, w4, sizeof v4) || a8 != c8 || memcmp(v8, w8, sizeof v8)) && failures++ < 10)
                    printf("FAIL ref lanes %ld: binary32 lanes %x/%x differ from the plain C %x/%x\n", i, a4, a8, c4, c8);
                for (int k = 0; k < 2; k++) { /* the root's test: one box of a two-box row, at r.pn / r.pf */
                    double w2[2], v1;
                    int c2 = cbvh_ref_boxw32_c(&r, b2[k], 2, c32, w2), a1 = cbvh_ref_box32_one(&r, b2[k], r.pn, r.pf, c32, &v1);
                    if ((a1 != (c2 & 1) || memcmp(&v1, &w2[0], sizeof v1)) && failures++ < 10)
                        printf("FAIL ref lanes %ld: the root's binary32 test %d differs from the row's %d\n", i, a1, c2 & 1);
                }
            }
            int h2[2];
            double t2[2];
            for (int k = 0; k < 2; k++) { /* the two-box lanes too */
                cbvh_ref_box2(&r, b2[k], cull, h2, t2);
                if ((h2[0] != h[2 * k] || h2[1] != h[2 * k + 1] || memcmp(t2, t + 2 * k, sizeof t2)) &&
                    failures++ < 10)
                    printf("FAIL ref lanes %ld: cbvh_ref_box2 pair %d differs from cbvh_ref_box2_c\n", i, k);
            }
        }
        n++;
        for (int c = 0; c < 4; c++) {
            nhit += h[c];
            if ((g[c] != h[c] || memcmp(&u[c], &t[c], sizeof u[c])) && failures++ < 10)
                printf("FAIL ref lanes %ld box %d (%s): four-box hit %d t_lo %a, two-box hit %d t_lo %a\n", i, c,
                       r.general ? "general" : "fast", g[c], u[c], h[c], t[c]);
        }
        for (int c = 0; c < 8; c++) {
            int k = c < 4 ? c : 7 - c;
            if ((g8[c] != h[k] || memcmp(&u8[c], &t[k], sizeof u8[c])) && failures++ < 10)
                printf("FAIL ref lanes %ld slot %d (%s): eight-box hit %d t_lo %a, two-box hit %d t_lo %a\n", i, c,
                       r.general ? "general" : "fast", g8[c], u8[c], h[k], t[k]);
        }
    }
    printf("plain float slab test: %ld rays x 4 boxes (%ld general, %ld culled just below an entry), %ld box hits; "
           "eight-, four- and two-box lanes (%s) equal the plain C\n",
           n, ngeneral, n_margin, nhit, CBVH_REF_AVX ? "AVX" : CBVH_REF_SSE2 ? "SSE2" : "plain C");
    printf("binary32 lanes (%s): %ld rays x 8 boxes small enough for them, %ld with a hit; equal the plain C\n",
           CBVH_REF_AVX ? "AVX" : CBVH_REF_SSE2 ? "SSE" : "plain C", n32, n32_hit);
    if (n < NBOX / 2 || ngeneral < n / 20 || n_margin < n / 200 || nhit < n / 4 || nhit > 3 * n || n32 < n / 4 ||
        n32_hit < n32 / 10) {
        printf("FAIL: plain float lane test inputs not varied enough\n");
        failures++;
    }
}

/* Which rays the binary32 lanes take (cbvh_ref_prepare32, docs/traversal.md
 * §16): |o_a| <= 2^62 and 2^-62 <= |d_a| <= 2^62 on every axis, tmin >= 0,
 * no zero d_a; each limit and the binary32 just beyond it, either sign. */
static void test_small_rays(void) {
    static const struct {
        int field; /* 0 o, 1 d, 2 tmin */
        cbvh_f32 v;
        int small;
    } cases[] = {{0, 0x5E800000u, 1},  {0, 0x5E800001u, 0}, {0, 0xDE800000u, 1}, {0, 0xDE800001u, 0},
                 {0, 0, 1},            {0, 0x00000001u, 1}, {1, 0x5E800000u, 1}, {1, 0x5E800001u, 0},
                 {1, 0xA0800000u, 1},  {1, 0xA07FFFFFu, 0}, {1, 0x20800000u, 1}, {1, 0, 0},
                 {1, CBVH_F32_SIGN, 0}, {2, 0xBF800000u, 0}, {2, CBVH_F32_SIGN, 1}, {2, 0x7F7FFFFFu, 1},
                 /* beyond the limits' bit patterns: Inf and NaN (o, d), the largest and smallest magnitudes */
                 {0, 0x7F800000u, 0},  {0, 0xFFC00000u, 0}, {1, 0x7F800000u, 0}, {1, 0x7FC00001u, 0},
                 {0, 0x7F7FFFFFu, 0},  {1, 0x00000001u, 0}, {1, 0x80000001u, 0}, {1, 0x7F7FFFFFu, 0}};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++)
        for (int a = 0; a < 3; a++) {
            cbvh_ray ray = {{0x3F800000u, 0xBF800000u, 0x40000000u}, {0x3F000000u, 0x3F800000u, 0xBF800000u}, 0,
                            CBVH_F32_POS_INF};
            if (cases[k].field == 0) ray.o[a] = cases[k].v;
            else if (cases[k].field == 1) ray.d[a] = cases[k].v;
            else ray.tmin = cases[k].v;
            cbvh_ref_ray r;
            cbvh_ref_prepare(&ray, &r);
            if (r.small) {
                printf("FAIL small rays: r.small set before cbvh_ref_prepare32\n");
                failures++;
            }
            cbvh_ref_prepare32(&ray, &r);
            cbvh_ref_ray alone; /* without cbvh_ref_prepare, as the wide loop takes a small ray */
            memset(&alone, 0x5A, sizeof alone);
            cbvh_ref_prepare32(&ray, &alone);
            if (alone.small != r.small ||
                (r.small && (alone.general || memcmp(alone.pn4, r.pn4, sizeof r.pn4) ||
                             memcmp(alone.pn, r.pn, sizeof r.pn) || memcmp(alone.pf, r.pf, sizeof r.pf) ||
                             memcmp(alone.pf4, r.pf4, sizeof r.pf4) || memcmp(alone.inv32, r.inv32, sizeof r.inv32)))) {
                printf("FAIL small rays: case %zu axis %d: cbvh_ref_prepare32 alone differs\n", k, a);
                failures++;
            }
            int inv_ok = 1;
            for (int b = 0; b < 3 && r.small; b++) inv_ok &= r.inv32[b] == 1.0f / bf(ray.d[b]);
            if (r.small != cases[k].small || !inv_ok) {
                printf("FAIL small rays: case %zu axis %d (%08X): small %d, want %d\n", k, a, cases[k].v, r.small,
                       cases[k].small);
                failures++;
            }
        }
    printf("binary32 lanes' ray limits: %zu cases x 3 axes checked\n", sizeof cases / sizeof cases[0]);
}

int main(void) {
#if CBVH_REF_AVX && defined(__GNUC__)
    if (!__builtin_cpu_supports("avx")) {
        printf("skipped: built with AVX lanes, and this CPU has no AVX\n");
        return 77;
    }
#endif
    test_small_rays();
    test_ref_lanes();
    test_float_boxes();
    test_filter_margin();
    test_grid_boxes();
    test_pair_decode();
    printf("box pairs with valid planes (cbvh_rbf_box2_valid checked): %ld, %ld of them binary32 "
           "(cbvh_rbf_box2_valid_f32 checked); two-box lanes in %s\n",
           n_valid_pairs, n_f32_pairs, CBVH_RBF_SSE2 ? "SSE2" : "plain C");
    if (n_valid_pairs < 100000 || n_f32_pairs < 10000) {
        printf("FAIL: too few valid box pairs\n");
        failures++;
    }
    if (failures) {
        printf("test_box_f64: %ld failures\n", failures);
        return 1;
    }
    printf("test_box_f64: all passed\n");
    return 0;
}
