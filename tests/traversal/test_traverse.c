/* Traversal core (docs/traversal.md §5) on real scenes:
 *   - CBVH closest hit == float-BVH closest hit (triangle id and t bit pattern)
 *     for every ray, at N = 3, 6, 10 (modulo) and N = 6 (relative), box unit
 *     M = 24 and M = 8;
 *   - both == brute force over all triangles (a subset of rays);
 *   - any-hit finds a hit iff closest-hit does, and the hit it reports is a
 *     real hit of the unit in [tmin, tmax];
 *   - CBVH box tests >= float-BVH box tests (sums), counters plausible;
 * scenes: scenes/bunny-small.obj, proc:far (far from the origin), proc:cloth
 * (a plane hit edge-on and at grazing angles). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/traverse.h"
#include "cbvh/unit_table.h"
#include "scene_load.h"

#ifdef CBVH_SANITIZE
#define RAYS 300
#define BRUTE 40
#else
#define RAYS 2500
#define BRUTE 250
#endif

static long failures;
static uint64_t rs = 0xD1B54A32D192ED03u;
static uint64_t rnd(void) {
    rs ^= rs << 13;
    rs ^= rs >> 7;
    rs ^= rs << 17;
    return rs;
}
static float unit(void) { return (float)((double)(rnd() >> 11) / 9007199254740992.0); }
static cbvh_f32 fb(float f) {
    cbvh_f32 b;
    memcpy(&b, &f, sizeof b);
    return b;
}

/* Rays: from outside the scene box toward a point inside it, from inside the
 * box, axis-parallel ones (+0/-0 components), and (cloth) edge-on rays in the
 * plane of the cloth. */
static cbvh_ray make_ray(const float lo[3], const float hi[3], int i, int edge_on) {
    cbvh_ray r;
    float o[3], t[3];
    for (int a = 0; a < 3; a++) {
        float ext = hi[a] - lo[a] > 0 ? hi[a] - lo[a] : 1.0f;
        float c = 0.5f * (lo[a] + hi[a]);
        t[a] = lo[a] + unit() * (hi[a] - lo[a]);
        o[a] = (i % 3 == 0) ? lo[a] + unit() * (hi[a] - lo[a]) : c + (unit() * 4 - 2) * ext;
    }
    if (edge_on && i % 4 == 1) { /* in the cloth's plane z = lo (= hi away from the bump) */
        o[2] = lo[2];
        t[2] = lo[2];
    }
    for (int a = 0; a < 3; a++) {
        r.o[a] = fb(o[a]);
        r.d[a] = fb(t[a] - o[a]);
    }
    if (i % 7 == 0) { /* axis-parallel */
        int a = (int)(rnd() % 3);
        for (int b = 0; b < 3; b++)
            if (b != a) r.d[b] = (rnd() & 1) ? 0 : CBVH_F32_SIGN;
        if (cbvh_f32_is_zero(r.d[a])) r.d[a] = fb(1.0f);
    }
    if (cbvh_f32_is_zero(r.d[0]) && cbvh_f32_is_zero(r.d[1]) && cbvh_f32_is_zero(r.d[2])) r.d[0] = fb(1.0f);
    r.tmin = 0;
    r.tmax = (i % 5 == 0) ? fb(0.5f + unit()) : CBVH_F32_POS_INF;
    return r;
}

static cbvh_trav_hit brute(const cbvh_scene *s, const cbvh_ray *r) {
    cbvh_trav_hit best = {0};
    for (uint32_t i = 0; i < s->ntris; i++) {
        cbvh_f32 v[3][3];
        memcpy(v, s->tris[i].v, sizeof v);
        cbvh_tri_result res;
        if (cbvh_ray_triangle(r, v[0], v[1], v[2], &res) || !res.hit) continue;
        int64_t k = cbvh_f32_key(res.t);
        if (k < cbvh_f32_key(r->tmin) || k > cbvh_f32_key(r->tmax)) continue;
        if (best.hit && k >= cbvh_f32_key(best.t)) continue; /* ascending ids: first wins ties */
        best.hit = 1;
        best.prim = i;
        best.t = res.t;
        best.b1 = res.b1;
        best.b2 = res.b2;
    }
    return best;
}

static int same(const cbvh_trav_hit *a, const cbvh_trav_hit *b) {
    return a->hit == b->hit && (!a->hit || (a->prim == b->prim && a->t == b->t && a->b1 == b->b1 && a->b2 == b->b2));
}

static void run_scene(const char *spec) {
    cbvh_scene s;
    char err[256];
    if (cbvh_scene_open(spec, &s, err, sizeof err)) {
        fprintf(stderr, "FAIL %s: %s\n", spec, err);
        failures++;
        return;
    }
    cbvh_bvh b;
    if (cbvh_build_sah(&s, 0, 0, &b, err, sizeof err)) {
        fprintf(stderr, "FAIL build %s: %s\n", spec, err);
        failures++;
        cbvh_scene_free(&s);
        return;
    }
    float lo[3], hi[3];
    cbvh_scene_bounds(&s, lo, hi);
    int edge_on = strstr(spec, "cloth") != NULL;
    cbvh_ray *rays = malloc(RAYS * sizeof *rays);
    cbvh_trav_hit *ref = malloc(RAYS * sizeof *ref);
    cbvh_trav_stats fs = {0}, fa = {0};
    long hits = 0;
    for (int i = 0; i < RAYS; i++) {
        rays[i] = make_ray(lo, hi, i, edge_on);
        cbvh_trav_hit any;
        if (cbvh_trace_bvh(&b, s.tris, &rays[i], 24, CBVH_TRAV_CLOSEST, &ref[i], &fs) ||
            cbvh_trace_bvh(&b, s.tris, &rays[i], 24, CBVH_TRAV_ANY, &any, &fa)) {
            failures++;
            continue;
        }
        hits += ref[i].hit;
        if (any.hit != ref[i].hit) failures++;
        if (i < BRUTE) {
            cbvh_trav_hit bf = brute(&s, &rays[i]);
            if (!same(&bf, &ref[i])) {
                if (failures++ < 10) fprintf(stderr, "FAIL %s ray %d: float BVH != brute force\n", spec, i);
            }
        }
    }
    printf("%-22s %6u tris: %d rays, %ld hits | float BVH   closest: %.1f nodes %.1f box %.1f tri %.0f B/ray, "
           "stack %u; any-hit %.1f box\n",
           spec, s.ntris, RAYS, hits, (double)fs.nodes / RAYS, (double)fs.box_tests / RAYS,
           (double)fs.tri_tests / RAYS, (double)fs.bytes / RAYS, fs.max_stack, (double)fa.box_tests / RAYS);
    if (hits < RAYS / 10 || fs.box_tests < (uint64_t)RAYS) failures++;
    struct {
        int N, M;
        cbvh_encoding enc;
    } cfg[] = {{3, 24, CBVH_ENC_MODULO}, {6, 24, CBVH_ENC_MODULO}, {10, 24, CBVH_ENC_MODULO},
               {6, 24, CBVH_ENC_RELATIVE}, {6, 8, CBVH_ENC_MODULO}, {3, 3, CBVH_ENC_MODULO}};
    for (size_t c = 0; c < sizeof cfg / sizeof cfg[0]; c++) {
        cbvh_compress_opts o = {{cfg[c].N, CBVH_MIN_SCALE_DEFAULT}, cfg[c].enc, 1, 0};
        cbvh_tree t;
        if (cbvh_compress_topdown(&b, &o, &t, err, sizeof err)) {
            fprintf(stderr, "FAIL compress %s N=%d: %s\n", spec, cfg[c].N, err);
            failures++;
            continue;
        }
        cbvh_trav_stats cs = {0}, ca = {0};
        long mismatches = 0;
        for (int i = 0; i < RAYS; i++) {
            cbvh_trav_hit h, any;
            if (cbvh_trace_cbvh(&t, s.tris, &rays[i], cfg[c].M, CBVH_TRAV_CLOSEST, &h, &cs) ||
                cbvh_trace_cbvh(&t, s.tris, &rays[i], cfg[c].M, CBVH_TRAV_ANY, &any, &ca)) {
                failures++;
                continue;
            }
            if (!same(&h, &ref[i])) {
                if (mismatches++ < 3)
                    fprintf(stderr, "FAIL %s N=%d M=%d ray %d: CBVH hit %d prim %u t %08X, float %d prim %u t %08X\n",
                            spec, cfg[c].N, cfg[c].M, i, h.hit, h.prim, h.t, ref[i].hit, ref[i].prim, ref[i].t);
            }
            if (any.hit != ref[i].hit) mismatches++;
        }
        failures += mismatches;
        printf("%-22s N=%-2d M=%-2d %-8s CBVH closest: %.1f nodes %.1f box (x%.3f) %.1f tri (x%.3f) %.0f B/ray "
               "(x%.3f), stack %u; any-hit %.1f box; mismatches %ld\n",
               spec, cfg[c].N, cfg[c].M, cbvh_encoding_name(cfg[c].enc), (double)cs.nodes / RAYS,
               (double)cs.box_tests / RAYS, (double)cs.box_tests / (double)fs.box_tests, (double)cs.tri_tests / RAYS,
               (double)cs.tri_tests / (double)fs.tri_tests, (double)cs.bytes / RAYS,
               (double)cs.bytes / (double)fs.bytes, cs.max_stack, (double)ca.box_tests / RAYS, mismatches);
        if (cs.box_tests < fs.box_tests) {
            fprintf(stderr, "FAIL %s N=%d: CBVH box tests %llu < float %llu\n", spec, cfg[c].N,
                    (unsigned long long)cs.box_tests, (unsigned long long)fs.box_tests);
            failures++;
        }
        if (cs.bytes != cs.lines * CBVH_LINE_BYTES || cs.nodes == 0) failures++;
        cbvh_tree_free(&t);
    }
    free(rays);
    free(ref);
    cbvh_bvh_free(&b);
    cbvh_scene_free(&s);
}

/* NaN/Inf and zero-direction rays are rejected (-1), with no hit reported. */
static void bad_rays(void) {
    cbvh_scene s;
    char err[256];
    if (cbvh_scene_open("proc:far:8", &s, err, sizeof err)) {
        failures++;
        return;
    }
    cbvh_bvh b;
    if (cbvh_build_sah(&s, 0, 0, &b, err, sizeof err)) {
        failures++;
        cbvh_scene_free(&s);
        return;
    }
    cbvh_compress_opts o = {{6, CBVH_MIN_SCALE_DEFAULT}, CBVH_ENC_MODULO, 1, 0};
    cbvh_tree t;
    if (cbvh_compress_topdown(&b, &o, &t, err, sizeof err) == 0) {
        cbvh_ray bad[3] = {{{0x7FC00000u, 0, 0}, {fb(1), 0, 0}, 0, CBVH_F32_POS_INF},
                           {{0, 0, 0}, {CBVH_F32_POS_INF, 0, 0}, 0, CBVH_F32_POS_INF},
                           {{0, 0, 0}, {0, CBVH_F32_SIGN, 0}, 0, CBVH_F32_POS_INF}};
        for (int i = 0; i < 3; i++) {
            cbvh_trav_hit h;
            cbvh_trav_stats st = {0};
            if (cbvh_trace_bvh(&b, s.tris, &bad[i], 24, CBVH_TRAV_CLOSEST, &h, &st) != -1 || h.hit) failures++;
            if (cbvh_trace_cbvh(&t, s.tris, &bad[i], 24, CBVH_TRAV_CLOSEST, &h, &st) != -1 || h.hit) failures++;
            if (st.box_tests || st.tri_tests) failures++;
        }
        cbvh_tree_free(&t);
    } else
        failures++;
    cbvh_bvh_free(&b);
    cbvh_scene_free(&s);
}

int main(void) {
    bad_rays();
    run_scene(CBVH_SCENES_DIR "/bunny-small.obj");
    run_scene("proc:far:8");
    run_scene("proc:cloth:24");
    if (failures) fprintf(stderr, "%ld failures\n", failures);
    return failures ? 1 : 0;
}
