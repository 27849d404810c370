/* The exact facing predicate (rtl-model/src/units/tri_facing.c) against a GMP
 * rational oracle, over structured and random inputs, and one-sided traversal
 * (CBVH_TRAV_FRONT_ONLY) against brute force over every triangle. */
#include <gmp.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/bvh.h"
#include "cbvh/traversal_units.h"
#include "cbvh/traverse.h"
#include "test_util.h"

#ifdef CBVH_SANITIZE
#define N_RANDOM 60000
#define N_RAYS 4000
#else
#define N_RANDOM 300000
#define N_RAYS 20000
#endif

static int failures;
#define CHECK(c, ...) TU_CHECK(failures, stderr, c, __VA_ARGS__)

static uint64_t rng_s = 0x1234567887654321u;
static uint64_t rnd64(void) { return tu_xorshift64(&rng_s); }

/* A finite binary32 with a random exponent in [emin, emax] (or 0). */
static cbvh_f32 rnd_f32(int emin, int emax) {
    uint64_t r = rnd64();
    if ((r & 63) == 0) return (r & 64) ? CBVH_F32_SIGN : 0;
    int e = emin + (int)((r >> 8) % (uint64_t)(emax - emin + 1));
    cbvh_f32 field = e < CBVH_F32_EMIN ? 0 : (cbvh_f32)(e + CBVH_F32_EXP_BIAS); /* below the normal range: a subnormal */
    return (cbvh_f32)((r >> 63) << 31) | field << CBVH_F32_FRAC_BITS | (cbvh_f32)((r >> 20) & CBVH_F32_FRAC);
}

static void q_of(mpq_t q, cbvh_f32 b) {
    mpq_set_d(q, (double)cbvh_float_of(b)); /* exact: every binary32 is a binary64 */
}

static int oracle(const cbvh_f32 d[3], const cbvh_f32 v0[3], const cbvh_f32 v1[3], const cbvh_f32 v2[3]) {
    mpq_t e1[3], e2[3], dd[3], a, b, n, s;
    mpq_inits(a, b, n, s, NULL);
    for (int k = 0; k < 3; k++) {
        mpq_inits(e1[k], e2[k], dd[k], NULL);
        q_of(a, v1[k]);
        q_of(b, v0[k]);
        mpq_sub(e1[k], a, b);
        q_of(a, v2[k]);
        mpq_sub(e2[k], a, b);
        q_of(dd[k], d[k]);
    }
    for (int k = 0; k < 3; k++) {
        int i = (k + 1) % 3, j = (k + 2) % 3;
        mpq_mul(a, e1[i], e2[j]);
        mpq_mul(b, e1[j], e2[i]);
        mpq_sub(n, a, b);
        mpq_mul(a, dd[k], n);
        mpq_add(s, s, a);
    }
    int r = -mpq_sgn(s);
    for (int k = 0; k < 3; k++) mpq_clears(e1[k], e2[k], dd[k], NULL);
    mpq_clears(a, b, n, s, NULL);
    return r;
}

static void one(const cbvh_f32 d[3], const cbvh_f32 v0[3], const cbvh_f32 v1[3], const cbvh_f32 v2[3]) {
    int f = cbvh_tri_facing(d, v0, v1, v2), o = oracle(d, v0, v1, v2);
    CHECK(f == o, "facing %d, oracle %d (d %08x %08x %08x)", f, o, d[0], d[1], d[2]);
    /* Swapping two vertices flips the winding; negating d flips the side. */
    CHECK(cbvh_tri_facing(d, v0, v2, v1) == -f, "swap did not flip");
    cbvh_f32 nd[3] = {d[0] ^ CBVH_F32_SIGN, d[1] ^ CBVH_F32_SIGN, d[2] ^ CBVH_F32_SIGN};
    CHECK(cbvh_tri_facing(nd, v0, v1, v2) == -f, "negated d did not flip");
}

static void predicate_tests(void) {
    /* Structured: the unit triangle in z = 0 seen along +-z, and edge-on. */
    float V[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    cbvh_f32 v[3][3];
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++) v[i][k] = fb(V[i][k]);
    cbvh_f32 down[3] = {0, 0, fb(-1.0f)}, up[3] = {0, 0, fb(1.0f)}, side[3] = {fb(1.0f), 0, 0};
    CHECK(cbvh_tri_facing(down, v[0], v[1], v[2]) == 1, "ccw seen from +z is the front");
    CHECK(cbvh_tri_facing(up, v[0], v[1], v[2]) == -1, "from below is the back");
    CHECK(cbvh_tri_facing(side, v[0], v[1], v[2]) == 0, "edge-on");
    cbvh_f32 col[3] = {fb(2.0f), 0, 0}; /* degenerate: collinear */
    CHECK(cbvh_tri_facing(down, v[0], v[1], col) == 0, "degenerate");
    long n = 0;
    for (; n < N_RANDOM; n++) {
        cbvh_f32 d[3], a[3], b[3], c[3];
        int kind = (int)(n % 5);
        int lo = kind == 0 ? -140 : -20, hi = kind == 0 ? 120 : 20;
        for (int k = 0; k < 3; k++) {
            d[k] = rnd_f32(lo, hi);
            a[k] = rnd_f32(lo, hi);
            b[k] = rnd_f32(lo, hi);
            c[k] = rnd_f32(lo, hi);
        }
        if (kind == 2) /* d along an edge: d . n = 0 exactly when the edge is exact */
            for (int k = 0; k < 3; k++) {
                b[k] = a[k] & 0xFFFFF000u;
                d[k] = b[k];
                a[k] = 0;
            }
        if (kind == 3) /* nearly collinear: c = b + tiny */
            for (int k = 0; k < 3; k++) c[k] = b[k] + (rnd64() & 1);
        if (kind == 4) /* shared tiny/huge mix: far-from-origin sliver */
            for (int k = 0; k < 3; k++) {
                a[k] = fb(1e6f) + (cbvh_f32)(rnd64() & 7);
                b[k] = fb(1e6f) + (cbvh_f32)(rnd64() & 7);
                c[k] = fb(1e6f) + (cbvh_f32)(rnd64() & 7);
            }
        one(d, a, b, c);
    }
    printf("facing predicate: %ld random + structured cases against GMP\n", n);
}

/* One-sided traversal equals brute force with the facing rule. */
static void one_sided_traversal(void) {
    enum { NT = 600 };
    cbvh_scene s = {0};
    s.ntris = NT;
    s.tris = calloc(NT, sizeof *s.tris);
    if (!s.tris) abort();
    for (int i = 0; i < NT; i++) {
        float cx = (float)(rnd64() % 1000) / 100.0f, cy = (float)(rnd64() % 1000) / 100.0f,
              cz = (float)(rnd64() % 1000) / 100.0f;
        for (int v = 0; v < 3; v++) {
            s.tris[i].v[v][0] = cx + (float)(rnd64() % 200) / 100.0f - 1.0f;
            s.tris[i].v[v][1] = cy + (float)(rnd64() % 200) / 100.0f - 1.0f;
            s.tris[i].v[v][2] = cz + (float)(rnd64() % 200) / 100.0f - 1.0f;
        }
    }
    cbvh_bvh b;
    char err[200];
    if (cbvh_build_sah(&s, 0, 0, &b, err, sizeof err)) {
        fprintf(stderr, "build: %s\n", err);
        exit(1);
    }
    long front_hits = 0, back_skipped = 0;
    for (int r = 0; r < N_RAYS; r++) {
        cbvh_ray ray;
        for (int k = 0; k < 3; k++) {
            ray.o[k] = fb((float)(rnd64() % 1200) / 100.0f - 1.0f);
            ray.d[k] = fb((float)((int)(rnd64() % 2001) - 1000) / 1000.0f);
        }
        if (!ray.d[0] && !ray.d[1] && !ray.d[2]) ray.d[0] = fb(1.0f);
        ray.tmin = 0;
        ray.tmax = CBVH_F32_POS_INF;
        for (int any = 0; any < 2; any++) {
            cbvh_trav_hit h;
            cbvh_trav_stats st = {0};
            cbvh_trav_mode m = any ? CBVH_TRAV_ANY_FRONT : CBVH_TRAV_CLOSEST_FRONT;
            CHECK(cbvh_trace_bvh(&b, s.tris, &ray, 24, m, &h, &st) == 0, "trace");
            /* brute force */
            int bh = 0;
            uint32_t bp = 0;
            cbvh_f32 bt = 0;
            for (uint32_t t = 0; t < NT; t++) {
                cbvh_f32 v[3][3];
                memcpy(v, s.tris[t].v, sizeof v);
                cbvh_tri_result tr;
                if (cbvh_ray_triangle(&ray, v[0], v[1], v[2], &tr) || !tr.hit) continue;
                if (cbvh_tri_facing(ray.d, v[0], v[1], v[2]) != 1) {
                    back_skipped++;
                    continue;
                }
                if (!bh || cbvh_f32_key(tr.t) < cbvh_f32_key(bt) || (tr.t == bt && t < bp)) {
                    bh = 1;
                    bp = t;
                    bt = tr.t;
                }
            }
            CHECK(h.hit == bh, "ray %d any %d: hit %d, brute force %d", r, any, h.hit, bh);
            if (h.hit && bh && !any) CHECK(h.prim == bp && h.t == bt, "ray %d: prim %u t %08x, brute %u %08x", r, h.prim, h.t, bp, bt);
            if (h.hit && any) {
                cbvh_f32 v[3][3];
                memcpy(v, s.tris[h.prim].v, sizeof v);
                CHECK(cbvh_tri_facing(ray.d, v[0], v[1], v[2]) == 1, "any-hit returned a back face");
            }
            front_hits += h.hit && !any;
        }
    }
    CHECK(back_skipped > 0, "the test never met a back face");
    printf("one-sided traversal: %d rays x closest/any == brute force (%ld front hits, %ld back-face hits skipped)\n",
           N_RAYS, front_hits, back_skipped);
    cbvh_bvh_free(&b);
    free(s.tris);
}

int main(void) {
    predicate_tests();
    one_sided_traversal();
    if (failures) {
        fprintf(stderr, "%d failures\n", failures);
        return 1;
    }
    printf("ok\n");
    return 0;
}
