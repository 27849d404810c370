/* The traversal units' fast paths against their exact paths
 * (docs/traversal.md, "Performance filter"):
 *   - ray-box (grid planes and float planes): whenever the integer fast path
 *     decides, its outputs equal the exact path's bit for bit; the public unit
 *     (fast path + fallback) equals the exact path always;
 *   - ray-triangle: whenever the binary64 miss filter claims a miss, the
 *     exact path misses; the public unit equals the exact path always;
 *     built with -mavx (traversal_fast_path.avx), the wide loop's filter in
 *     four lanes equals the scalar filter on every case;
 *   - and the fast paths actually decide most random cases (so the speed-up
 *     is real and the comparison above is not vacuous).
 * Inputs: random values over wide exponent ranges plus the hard cases -
 * origins on planes, +-0 and subnormal direction components, power-of-two
 * directions, exact quotients that land on the M-bit grid, -Inf context
 * bounds, far-from-origin boxes, rays through triangle vertices and edges,
 * rays in the triangle's plane, degenerate triangles. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fast/ray_prep.h"
#include "fast/tri_filter_avx.h"
#include "cbvh/traversal_units.h"
#include "test_util.h"

#ifdef CBVH_SANITIZE
#define NBOX 400000
#define NTRI 200000
#else
#define NBOX 2000000
#define NTRI 1000000
#endif

static long failures;
static uint64_t rs = 0x9E3779B97F4A7C15u;
static uint64_t rnd(void) { return tu_xorshift64(&rs); }
static uint32_t below(uint32_t n) { return (uint32_t)(rnd() % n); }

/* 1 for a quarter of the inputs: scene-like values (no specials, exponents
 * within +-3 of each other, grid steps down to 2^-20 of the context bound,
 * valid boxes), where the fast paths must decide nearly always. */
static int typical;

/* A finite binary32 pattern with exponent in [emid - spread, emid + spread]
 * (clamped to the finite range), sometimes special. */
static cbvh_f32 rf(int emid, int spread) {
    uint32_t k = typical ? 9 + below(23) : below(32); /* typical: full random fractions */
    cbvh_f32 sign = (rnd() & 1) ? CBVH_F32_SIGN : 0;
    if (k == 0) return sign;                                     /* +-0 */
    if (k == 1) return sign | (uint32_t)(1 + below(0x7FFFFF));   /* subnormal */
    if (k == 2) return sign | CBVH_F32_MAX;                       /* +-FLT_MAX */
    int e = emid - spread + (int)below((uint32_t)(2 * spread + 1));
    if (e < -126) e = -126;
    if (e > 127) e = 127;
    uint32_t frac = (k < 6) ? 0 : (k < 9) ? (below(8) << 20) : (uint32_t)(rnd() & CBVH_F32_FRAC); /* 2^e, few bits, any */
    return sign | cbvh_f32_make(0, e, frac);
}

static int small_exp(void) { return (int)below(21) - 10; }

static int same_box(const cbvh_box_result *a, const cbvh_box_result *b) {
    return a->hit == b->hit && a->t_near == b->t_near && a->t_far == b->t_far;
}

static cbvh_ray random_ray(int emid, int spread) {
    cbvh_ray r;
    for (int a = 0; a < 3; a++) {
        r.o[a] = rf(emid, spread);
        if (typical) {
            r.d[a] = rf(0, 3);
            continue;
        }
        r.d[a] = below(6) == 0 ? ((rnd() & 1) ? CBVH_F32_SIGN : 0) : rf(small_exp(), 12);
        if (below(8) == 0) r.d[a] = (rnd() & 1 ? CBVH_F32_SIGN : 0) | cbvh_f32_make(0, small_exp(), 0); /* 2^k */
        if (below(10) == 0) r.d[a] = (rnd() & 1 ? CBVH_F32_SIGN : 0) | cbvh_f32_make(0, small_exp(), 0x400000u); /* 3*2^k */
    }
    if (cbvh_f32_is_zero(r.d[0]) && cbvh_f32_is_zero(r.d[1]) && cbvh_f32_is_zero(r.d[2])) r.d[below(3)] = 0x3F800000u;
    r.tmin = below(4) ? 0 : rf(emid, spread);
    uint32_t k = below(4);
    r.tmax = k == 0 ? rf(emid + 2, spread) : CBVH_F32_POS_INF;
    if (k == 1) r.tmax = CBVH_F32_MAX;
    return r;
}

static long typ_total, typ_decided;

static void box_cases(long *decided, long *total) {
    for (long i = 0; i < NBOX; i++) {
        typical = (i & 3) == 0;
        int emid = below(16) == 0 ? (int)below(200) - 100 : small_exp();
        int spread = below(4) == 0 ? 40 : 3;
        if (typical) spread = 3;
        cbvh_ray ray = random_ray(emid, spread);
        int M = CBVH_MANT_MIN + (int)below(CBVH_MANT_MAX - CBVH_MANT_MIN + 1);
        cbvh_grid_axis g[3];
        for (int a = 0; a < 3; a++) {
            g[a].u = below(64) == 0 && !typical ? CBVH_F32_NEG_INF : rf(emid, spread);
            int eu = (int)cbvh_f32_exp_field(g[a].u) - CBVH_F32_EXP_BIAS;
            g[a].e = typical ? eu - 20 + (int)below(24) : eu - 30 + (int)below(34);
            if (below(16) == 0 && !typical) g[a].e = (int)below(253) - 126;
            if (g[a].e < CBVH_SCALE_FLOOR) g[a].e = CBVH_SCALE_FLOOR;
            if (g[a].e > CBVH_SCALE_CEIL) g[a].e = CBVH_SCALE_CEIL;
            g[a].r = below(1024);
            g[a].s = g[a].r + 1 + below(1024 - g[a].r);
            uint32_t hard = typical ? 7 : below(8);
            if (hard == 0 && g[a].u != CBVH_F32_NEG_INF) { /* origin exactly on the lower plane */
                g[a].r = 0;
                ray.o[a] = g[a].u;
            } else if (hard == 1) { /* exact quotient on the grid: (L - o) = 3 * 2^e, d = 3 * 2^k */
                g[a].u = 0;
                ray.o[a] = 0;
                g[a].r = 3;
                g[a].s = 3 + below(1000);
                ray.d[a] = cbvh_f32_make(0, small_exp(), 0x400000u) | (rnd() & 1 ? CBVH_F32_SIGN : 0);
            }
        }
        if (below(32) == 0 && !typical) g[below(3)].s = g[0].r; /* sometimes an invalid box: status must match too */
        cbvh_box_result fe, ff, fu;
        uint32_t se = cbvh_ray_box_exact_only(&ray, M, g, &fe);
        uint32_t su = cbvh_ray_box(&ray, M, g, &fu);
        int fr = cbvh_ray_box_fast_only(&ray, M, g, &ff);
        (*total)++;
        if (typical) {
            typ_total++;
            typ_decided += fr == 0;
        }
        if (se != su || !same_box(&fe, &fu)) {
            if (failures++ < 10)
                fprintf(stderr, "FAIL box %ld M=%d: unit st %X hit %d %08X %08X, exact st %X hit %d %08X %08X\n", i, M,
                        su, fu.hit, fu.t_near, fu.t_far, se, fe.hit, fe.t_near, fe.t_far);
        }
        if (fr == 0) {
            (*decided)++;
            if (se != 0 || !same_box(&fe, &ff)) {
                if (failures++ < 10)
                    fprintf(stderr, "FAIL box fast %ld M=%d: fast hit %d %08X %08X, exact st %X hit %d %08X %08X\n", i,
                            M, ff.hit, ff.t_near, ff.t_far, se, fe.hit, fe.t_near, fe.t_far);
            }
        }
    }
}

static void float_box_cases(long *decided, long *total) {
    for (long i = 0; i < NBOX / 2; i++) {
        typical = (i & 3) == 0;
        int emid = below(16) == 0 ? (int)below(200) - 100 : small_exp();
        int spread = below(4) == 0 ? 40 : 3;
        if (typical) spread = 3;
        cbvh_ray ray = random_ray(emid, spread);
        int M = below(2) ? 24 : CBVH_MANT_MIN + (int)below(CBVH_MANT_MAX - CBVH_MANT_MIN + 1);
        cbvh_f32 lo[3], hi[3];
        for (int a = 0; a < 3; a++) {
            lo[a] = rf(emid, spread);
            hi[a] = rf(emid, spread);
            if (cbvh_f32_cmp(lo[a], hi[a]) > 0 && (typical || below(16))) {
                cbvh_f32 t = lo[a];
                lo[a] = hi[a];
                hi[a] = t;
            }
            uint32_t hard = typical ? 7 : below(8);
            if (hard == 0) ray.o[a] = lo[a];          /* on a face */
            else if (hard == 1) ray.o[a] = hi[a];
            else if (hard == 2) hi[a] = lo[a];        /* flat box */
        }
        cbvh_box_result fe, ff, fu;
        uint32_t se = cbvh_ray_box_float_exact_only(&ray, M, lo, hi, &fe);
        uint32_t su = cbvh_ray_box_float(&ray, M, lo, hi, &fu);
        int fr = cbvh_ray_box_float_fast_only(&ray, M, lo, hi, &ff);
        (*total)++;
        if (typical) {
            typ_total++;
            typ_decided += fr == 0;
        }
        if (se != su || !same_box(&fe, &fu)) {
            if (failures++ < 10) fprintf(stderr, "FAIL float box %ld M=%d: unit != exact\n", i, M);
        }
        if (fr == 0) {
            (*decided)++;
            if (se != 0 || !same_box(&fe, &ff)) {
                if (failures++ < 10) fprintf(stderr, "FAIL float box fast %ld M=%d: fast != exact\n", i, M);
            }
        }
    }
}

/* A ray exactly through the midpoint of edge v0 v1: v1 an even number of
 * ulps from v0 in the same binade (so the midpoint is a binary32), the
 * origin 0 or within a factor of two of the midpoint on every axis (so
 * d = midpoint - o is exact).  The edge function of v0 v1 is exactly 0 and
 * the exact path hits (on the edge); the filters may decide such a ray only
 * as a hit.  (Their binary64 value of that edge function comes out exactly
 * 0 here too: the construction keeps X and Y exact, so it does not probe the
 * size of the error bounds; near-edge random rays above do.) */
static long n_exact_edge, n_exact_edge_hit;
static int exact_edge_ray(cbvh_ray *ray, cbvh_f32 v[3][3]) {
    cbvh_f32 o[3], d[3], v1[3];
    int at0 = rnd() & 1;
    for (int a = 0; a < 3; a++) {
        cbvh_f32 x = v[0][a] & ~CBVH_F32_SIGN;
        if (x < 0x00800000u || x >= 0x7F000000u) return 0; /* normal, not the top binade */
        uint32_t step = 2u * (1u + below(1u << 21)); /* an even number of ulps, up to half the binade */
        v1[a] = v[0][a] + ((rnd() & 1) && (v[0][a] & CBVH_F32_FRAC) >= step ? -step : step);
        float p0, p1;
        memcpy(&p0, &v[0][a], 4);
        memcpy(&p1, &v1[a], 4);
        double mid = 0.5 * ((double)p0 + (double)p1);
        float fo = at0 ? 0.0f : (float)(mid * (0.55 + 0.9 * (double)below(1000) / 1000.0));
        double dd = mid - (double)fo;
        if ((double)(float)mid != mid || (double)(float)dd != dd || (float)dd == 0.0f) return 0;
        float df = (float)dd;
        memcpy(&o[a], &fo, 4);
        memcpy(&d[a], &df, 4);
    }
    memcpy(v[1], v1, sizeof v1);
    memcpy(ray->o, o, sizeof o);
    memcpy(ray->d, d, sizeof d);
    ray->tmin = 0;
    ray->tmax = CBVH_F32_POS_INF;
    n_exact_edge++;
    return 1;
}

static long typ_tri_miss, typ_tri_decided, typ_tri_hit, typ_tri_hit_decided, tri_hit_decided;

#if CBVH_REF_AVX
/* The scalar filter's edge functions and bounds E, eE, Z, eZ of §9, in
 * ray_triangle.c's order of operations: the reference for the lanes' values. */
static int filter_bounds_ref(const cbvh_tri_ray *p, const cbvh_f32 v[3][3], double ref[4][3]) {
    const double u = 0x1p-53;
    double px[3], py[3], pz[3], X[3], Y[3], eX[3], eY[3], Pm = 0;
    for (int i = 0; i < 3; i++) {
        px[i] = (double)cbvh_float_of(v[i][p->kx]) - p->ox;
        py[i] = (double)cbvh_float_of(v[i][p->ky]) - p->oy;
        pz[i] = (double)cbvh_float_of(v[i][p->kz]) - p->oz;
        X[i] = px[i] * p->dz - pz[i] * p->dx;
        Y[i] = py[i] * p->dz - pz[i] * p->dy;
        double apz = fabs(pz[i]);
        Pm = fmax(Pm, fmax(fabs(px[i]), fmax(fabs(py[i]), apz)));
        eX[i] = 4.0 * u * (fabs(px[i]) * fabs(p->dz) + apz * fabs(p->dx));
        eY[i] = 4.0 * u * (fabs(py[i]) * fabs(p->dz) + apz * fabs(p->dy));
        ref[2][i] = pz[i];
        ref[3][i] = 1.0001 * u * apz;
    }
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3;
        double a = X[k] * Y[j], c = Y[k] * X[j];
        ref[0][i] = a - c;
        ref[1][i] = 1.001 * (fabs(X[k]) * eY[j] + fabs(Y[j]) * eX[k] + eX[k] * eY[j] + fabs(Y[k]) * eX[j] +
                             fabs(X[j]) * eY[k] + eX[j] * eY[k] + 2.0001 * u * (fabs(a) + fabs(c)));
    }
    double s = Pm * fabs(p->dz), B = 0x1p-46 * s * s; /* 1: the quick miss fires */
    int pos = 0, neg = 0;
    for (int i = 0; i < 3; i++) pos |= ref[0][i] > B, neg |= ref[0][i] < -B;
    return pos & neg;
}

/* The wide AVX loop's filter in lanes (tri_filter_avx.h, §15) on every
 * triangle case: its result is the scalar filter's (1 miss, 2 hit with the
 * same outputs, 0 undecided; cbvh_ray_triangle_filter_miss / _hit run the
 * scalar one), a miss or hit is the exact path's, and with one coordinate
 * made infinite or NaN it gives 0 (the unit does not filter such triangles). */
static long lanes_total, lanes_miss, lanes_hit, typ_lanes_miss, lanes_bounds;
static void check_filter_lanes(const cbvh_ray *ray, const cbvh_f32 v[3][3], uint32_t se, const cbvh_tri_result *re,
                               int typ) {
    cbvh_tri_ray p;
    cbvh_tri_ray_prepare(ray, &p);
    if (!p.ok) return;
    cbvh_tri_result rl, rh;
    memset(&rl, 0xA5, sizeof rl);
    double lanes[4][4], ref[4][3];
    lanes[0][0] = NAN;
    int fl = cbvh_tri_filter_avx(&p, v[0], v[1], v[2], &rl, lanes);
    int quick = filter_bounds_ref(&p, v, ref);
    if (quick != isnan(lanes[0][0]) && failures++ < 10)
        fprintf(stderr, "FAIL tri filter in lanes: quick miss %d, scalar %d\n", isnan(lanes[0][0]), quick);
    if (!isnan(lanes[0][0])) { /* formed (past the quick miss): the same values bit for bit */
        lanes_bounds++;
        for (int q = 0; q < 4; q++)
            for (int i = 0; i < 3; i++)
                if (memcmp(&lanes[q][i], &ref[q][i], sizeof(double)) && failures++ < 10)
                    fprintf(stderr, "FAIL tri filter in lanes: value %d of lane %d %a, scalar %a\n", q, i,
                            lanes[q][i], ref[q][i]);
    }
    int fm = cbvh_ray_triangle_filter_miss(ray, v[0], v[1], v[2]);
    int fh = cbvh_ray_triangle_filter_hit(ray, v[0], v[1], v[2], &rh);
    lanes_total++;
    lanes_miss += fl == 1;
    lanes_hit += fl == 2;
    typ_lanes_miss += typ && fl == 1;
    if (fl != (fm ? 1 : fh ? 2 : 0) && failures++ < 10)
        fprintf(stderr, "FAIL tri filter in lanes: %d, scalar filter miss %d hit %d\n", fl, fm, fh);
    if (fl == 2 && (memcmp(&rl, &rh, sizeof rl) || memcmp(&rl, re, sizeof rl) || se != 0) && failures++ < 10)
        fprintf(stderr, "FAIL tri filter in lanes: hit outputs differ from the scalar filter's or the exact path's\n");
    if (fl == 1 && (se != 0 || re->hit) && failures++ < 10)
        fprintf(stderr, "FAIL tri filter in lanes claims a miss: exact status %X hit %d\n", se, re->hit);
    static const cbvh_f32 special[4] = {CBVH_F32_POS_INF, CBVH_F32_NEG_INF, 0x7FC00000u, 0xFFC00001u};
    cbvh_f32 w[3][3];
    memcpy(w, v, sizeof w);
    w[below(3)][below(3)] = special[below(4)];
    if (cbvh_tri_filter_avx(&p, w[0], w[1], w[2], &rl, NULL) && failures++ < 10)
        fprintf(stderr, "FAIL tri filter in lanes decides a triangle with a non-finite vertex\n");
}
#endif

static void tri_cases(long *decided, long *total, long *exact_hits) {
    for (long i = 0; i < NTRI; i++) {
        typical = (i & 3) == 0;
        int emid = below(16) == 0 ? (int)below(200) - 100 : small_exp();
        int spread = below(4) == 0 && !typical ? 30 : 2;
        cbvh_ray ray = random_ray(emid, spread);
        cbvh_f32 v[3][3];
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++) v[k][a] = rf(emid, spread);
        uint32_t hard = typical ? 7 : below(10);
        int edge = 0;
        if (hard == 0) { /* through a vertex: d = v0 - o when exact */
            float o[3], p[3];
            for (int a = 0; a < 3; a++) {
                memcpy(&o[a], &ray.o[a], 4);
                memcpy(&p[a], &v[0][a], 4);
                float dd = p[a] - o[a];
                memcpy(&ray.d[a], &dd, 4);
            }
        } else if (hard == 1) { /* through the midpoint of an edge (often exact) */
            for (int a = 0; a < 3; a++) {
                float p0, p1, o;
                memcpy(&p0, &v[0][a], 4);
                memcpy(&p1, &v[1][a], 4);
                memcpy(&o, &ray.o[a], 4);
                float dd = 0.5f * p0 + 0.5f * p1 - o;
                memcpy(&ray.d[a], &dd, 4);
            }
        } else if (hard == 2) { /* origin in the triangle's plane (a vertex) */
            memcpy(ray.o, v[2], sizeof ray.o);
        } else if (hard == 3) { /* degenerate: two equal vertices */
            memcpy(v[1], v[0], sizeof v[0]);
        } else if (hard == 4) { /* axis-parallel ray toward the triangle's box */
            int a = (int)below(3);
            for (int b = 0; b < 3; b++) ray.d[b] = (rnd() & 1) ? CBVH_F32_SIGN : 0;
            ray.d[a] = (rnd() & 1) ? 0xBF800000u : 0x3F800000u;
            for (int b = 0; b < 3; b++)
                if (b != a) ray.o[b] = v[below(3)][b];
        } else if (hard >= 8) { /* exactly through an edge's midpoint (below) */
            edge = exact_edge_ray(&ray, v);
        }
        int bad = 0;
        for (int a = 0; a < 3; a++)
            bad |= cbvh_f32_is_nan_or_inf(ray.d[a]) | cbvh_f32_is_nan_or_inf(ray.o[a]);
        if (bad || (cbvh_f32_is_zero(ray.d[0]) && cbvh_f32_is_zero(ray.d[1]) && cbvh_f32_is_zero(ray.d[2])))
            ray.d[0] = 0x3F800000u;
        cbvh_tri_result re, ru;
        uint32_t se = cbvh_ray_triangle_exact_only(&ray, v[0], v[1], v[2], &re);
        uint32_t su = cbvh_ray_triangle(&ray, v[0], v[1], v[2], &ru);
        (*total)++;
        *exact_hits += re.hit;
        n_exact_edge_hit += edge && re.hit;
        if (se != su || memcmp(&re, &ru, sizeof re)) {
            if (failures++ < 10) fprintf(stderr, "FAIL tri %ld: unit != exact\n", i);
        }
        int fm = cbvh_ray_triangle_filter_miss(&ray, v[0], v[1], v[2]);
        if (typical && !re.hit) {
            typ_tri_miss++;
            typ_tri_decided += fm;
        }
        cbvh_tri_result rh;
        int fh = cbvh_ray_triangle_filter_hit(&ray, v[0], v[1], v[2], &rh);
        if (typical && re.hit) {
            typ_tri_hit++;
            typ_tri_hit_decided += fh;
        }
        if (fh) {
            tri_hit_decided++;
            if (se != 0 || memcmp(&re, &rh, sizeof re)) {
                if (failures++ < 10) fprintf(stderr, "FAIL tri %ld: hit filter's outputs != exact path's\n", i);
            }
        }
        if (fm && fh) {
            if (failures++ < 10) fprintf(stderr, "FAIL tri %ld: filter claims both a hit and a miss\n", i);
        }
#if CBVH_REF_AVX
        check_filter_lanes(&ray, (const cbvh_f32(*)[3])v, se, &re, typical);
#endif
        if (fm) {
            (*decided)++;
            if (se != 0 || re.hit) {
                if (failures++ < 10) fprintf(stderr, "FAIL tri %ld: filter claims a miss, exact path hits\n", i);
            }
        }
    }
}

/* Rays aimed at a point inside the triangle (d = p - o in binary32): nearly
 * every case is a hit, so the hit filter's outputs (t, b1, b2 truncated) meet
 * the exact path's on many quotients, including t exactly 1 or a power of two
 * (d scaled by 2^k) where the filter must leave the decision to the exact path. */
static void tri_hit_cases(long *hits, long *decided, long *on_grid) {
    for (long i = 0; i < NTRI; i++) {
        typical = 1;
        int emid = below(8) == 0 ? (int)below(160) - 80 : small_exp();
        cbvh_ray ray = random_ray(emid, 2);
        cbvh_f32 v[3][3];
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++) v[k][a] = rf(emid, 2);
        float w1 = (float)(below(1000) + 1) / 1024.0f, w2 = (float)(below(1000) + 1) / 1024.0f;
        if (w1 + w2 >= 1.0f) w1 = 1.0f - w1, w2 = 1.0f - w2;
        int k2 = (int)below(9) - 4;
        float scale = k2 >= 0 ? (float)(1u << k2) : 1.0f / (float)(1u << -k2);
        for (int a = 0; a < 3; a++) {
            float p0, p1, p2, o;
            memcpy(&p0, &v[0][a], 4);
            memcpy(&p1, &v[1][a], 4);
            memcpy(&p2, &v[2][a], 4);
            memcpy(&o, &ray.o[a], 4);
            float p = p0 + w1 * (p1 - p0) + w2 * (p2 - p0);
            float dd = (p - o) * scale;
            memcpy(&ray.d[a], &dd, 4);
        }
        ray.tmin = 0;
        ray.tmax = CBVH_F32_POS_INF;
        int bad = 0;
        for (int a = 0; a < 3; a++)
            bad |= cbvh_f32_is_nan_or_inf(ray.d[a]) | cbvh_f32_is_nan_or_inf(ray.o[a]);
        if (bad || (cbvh_f32_is_zero(ray.d[0]) && cbvh_f32_is_zero(ray.d[1]) && cbvh_f32_is_zero(ray.d[2])))
            continue;
        cbvh_tri_result re, ru, rh;
        uint32_t se = cbvh_ray_triangle_exact_only(&ray, v[0], v[1], v[2], &re);
        uint32_t su = cbvh_ray_triangle(&ray, v[0], v[1], v[2], &ru);
        if (se != su || memcmp(&re, &ru, sizeof re)) {
            if (failures++ < 10) fprintf(stderr, "FAIL tri hit %ld: unit != exact\n", i);
        }
        *hits += re.hit;
        if (re.hit && (re.t & CBVH_F32_FRAC) == 0) (*on_grid)++;
#if CBVH_REF_AVX
        check_filter_lanes(&ray, (const cbvh_f32(*)[3])v, se, &re, 0);
#endif
        if (cbvh_ray_triangle_filter_hit(&ray, v[0], v[1], v[2], &rh)) {
            (*decided)++;
            if (se != 0 || memcmp(&re, &rh, sizeof re)) {
                if (failures++ < 10) fprintf(stderr, "FAIL tri hit %ld: hit filter's outputs != exact path's\n", i);
            }
        }
    }
}

/* The triangle unit's ray preparation picks the exact path's axes: kz =
 * the largest |d| (the first on ties), kx and ky cyclic after it and
 * swapped when d_kz < 0 (the filter's error bound needs |d_kz| largest).
 * Every combination of eight magnitudes (ties, +-0, subnormal, largest
 * finite) and signs per component, then random directions. */
static void tri_axes(void) {
    static const uint32_t mag[8] = {0, 1, 0x00800000u, 0x3F800000u, 0x3F800001u, 0x40000000u, 0x7F7FFFFFu,
                                    0x3F800000u};
    long n = 0;
    uint64_t seed = 77;
    for (long i = 0; i < (8L * 8 * 8 * 8) + 200000; i++) {
        cbvh_ray r;
        memset(&r, 0, sizeof r);
        for (int a = 0; a < 3; a++) {
            uint32_t m = i < 8L * 8 * 8 * 8 ? mag[(i >> (3 * a)) & 7] : (uint32_t)tu_xorshift64(&seed) & 0x7FFFFFFFu;
            int neg = i < 8L * 8 * 8 * 8 ? (int)(i >> (9 + a)) & 1 : (int)(tu_xorshift64(&seed) & 1);
            r.d[a] = m | (neg ? CBVH_F32_SIGN : 0);
        }
        if (((r.d[0] | r.d[1] | r.d[2]) & ~CBVH_F32_SIGN) == 0) continue;
        int kz = 0;
        for (int a = 1; a < 3; a++)
            if ((r.d[a] & ~CBVH_F32_SIGN) > (r.d[kz] & ~CBVH_F32_SIGN)) kz = a;
        int kx = (kz + 1) % 3, ky = (kx + 1) % 3;
        if (r.d[kz] & CBVH_F32_SIGN) {
            int t = kx;
            kx = ky;
            ky = t;
        }
        cbvh_tri_ray p;
        cbvh_tri_ray_prepare_valid(&r, &p);
        n++;
        if ((p.kx != kx || p.ky != ky || p.kz != kz) && failures++ < 10)
            fprintf(stderr, "FAIL triangle ray axes for d = %08X %08X %08X: %d %d %d, want %d %d %d\n", r.d[0], r.d[1],
                    r.d[2], p.kx, p.ky, p.kz, kx, ky, kz);
    }
    printf("ray_triangle: the prepared ray's axes equal the exact path's for %ld directions\n", n);
}

int main(void) {
#if CBVH_REF_AVX && defined(__GNUC__)
    if (!__builtin_cpu_supports("avx")) {
        printf("skipped: built with AVX lanes, and this CPU has no AVX\n");
        return 77;
    }
#endif
    long bd = 0, bt = 0, fd = 0, ft = 0, td = 0, tt = 0, th = 0;
    tri_axes();
    box_cases(&bd, &bt);
    float_box_cases(&fd, &ft);
    tri_cases(&td, &tt, &th);
    long hh = 0, hd = 0, hg = 0;
    tri_hit_cases(&hh, &hd, &hg);
    printf("ray_triangle aimed rays: %d rays, %ld exact hits (%ld with t truncated to a power of two), hit filter decided %ld "
           "(%.2f%%)\n",
           NTRI, hh, hg, hd, 100.0 * (double)hd / (double)(hh ? hh : 1));
    printf("ray_triangle: %ld rays exactly through an edge's midpoint, %ld exact hits\n", n_exact_edge,
           n_exact_edge_hit);
    printf("ray_box grid: %ld inputs, fast path decided %ld (%.2f%%)\n", bt, bd, 100.0 * (double)bd / (double)bt);
    printf("ray_box float: %ld inputs, fast path decided %ld (%.2f%%)\n", ft, fd, 100.0 * (double)fd / (double)ft);
    printf("ray_triangle: %ld inputs (%ld exact hits), filter proved %ld misses (%.2f%% of the %ld misses)\n", tt, th,
           td, 100.0 * (double)td / (double)(tt - th), tt - th);
    printf("ray_triangle: hit filter decided %ld of the %ld exact hits; scene-like: %ld of %ld (%.2f%%)\n",
           tri_hit_decided, th, typ_tri_hit_decided, typ_tri_hit,
           100.0 * (double)typ_tri_hit_decided / (double)(typ_tri_hit ? typ_tri_hit : 1));
    printf("scene-like inputs: box fast path decided %.3f%% of %ld, triangle filter proved %.3f%% of %ld misses\n",
           100.0 * (double)typ_decided / (double)typ_total, typ_total,
           100.0 * (double)typ_tri_decided / (double)typ_tri_miss, typ_tri_miss);
#if CBVH_REF_AVX
    printf("ray_triangle filter in four lanes: %ld inputs, %ld misses (%ld of %ld scene-like misses), %ld hits "
           "decided, each compared with the scalar filter; bounds of %ld compared bit for bit\n",
           lanes_total, lanes_miss, typ_lanes_miss, typ_tri_miss, lanes_hit, lanes_bounds);
    if (lanes_total < 2 * NTRI * 99 / 100 || typ_lanes_miss < typ_tri_miss * 9 / 10 || lanes_hit < NTRI / 2 ||
        lanes_bounds < NTRI) {
        fprintf(stderr, "FAIL: the filter in lanes decides too few cases\n");
        failures++;
    }
#endif
    /* the fast paths must carry the bulk of the work, or the speed-up is fake */
    if (typ_decided < typ_total * 99 / 100 || typ_tri_decided < typ_tri_miss * 9 / 10 || bd == 0 || fd == 0 ||
        td == 0 || typ_tri_hit == 0 || typ_tri_hit_decided < typ_tri_hit * 9 / 10 ||
        hh < NTRI / 2 || hd < hh / 2 || n_exact_edge_hit < NTRI / 40) {
        fprintf(stderr, "FAIL: fast paths decide too few cases\n");
        failures++;
    }
    if (failures) fprintf(stderr, "%ld failures\n", failures);
    return failures ? 1 : 0;
}
