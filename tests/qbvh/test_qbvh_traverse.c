/* QBVH traversal (docs/qbvh.md §4): on scenes/bunny-small.obj and procedural
 * scenes, for every ray the QBVH closest hit (triangle, t, b1, b2 bits) equals
 * the binary float BVH's, any-hit agrees, the three stack kinds visit the same
 * nodes, and the compressed stack is never deeper than the binary one.  Also:
 * the 2^26 limit on a sparse tree (compressed: clear error; wide: correct). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/qbvh.h"
#include "scene_load.h"
#include "test_trav_util.h"

static int fails;
#define CHECK(c, ...) TU_CHECK(fails, stdout, c, __VA_ARGS__)

static uint64_t rs = 0x9E3779B97F4A7C15ull;

static void run_scene(const char *spec, int nrays) {
    cbvh_scene s = {0};
    char err[256];
    if (cbvh_scene_open(spec, &s, err, sizeof err)) {
        CHECK(0, "%s: %s", spec, err);
        return;
    }
    cbvh_bvh b = {0};
    cbvh_qbvh q = {0};
    CHECK(cbvh_build_sah(&s, 0, 0, &b, err, sizeof err) == 0, "sah: %s", err);
    CHECK(cbvh_qbvh_from_bvh(&b, &q, err, sizeof err) == 0, "collapse: %s", err);
    CHECK(cbvh_qbvh_check(&q, &s, err, sizeof err) == 0, "check: %s", err);
    uint32_t leaves, inner;
    cbvh_bvh_counts(&b, &leaves, &inner);
    CHECK(q.nnodes < leaves + inner, "QBVH has %u nodes, binary %u", q.nnodes, leaves + inner);
    float lo[3], hi[3];
    cbvh_scene_bounds(&s, lo, hi);
    cbvh_trav_stats sb = {0}, sq[4] = {{0}}, sa = {0};
    int hits = 0;
    for (int i = 0; i < nrays; i++) {
        cbvh_ray r = box_ray(&rs, lo, hi, i, 0);
        cbvh_trav_hit hb, hq[4], ha, hqa;
        cbvh_trav_stats one[4] = {{0}};
        CHECK(cbvh_trace_bvh(&b, s.tris, &r, 24, CBVH_TRAV_CLOSEST, &hb, &sb) == 0, "bvh ray %d", i);
        for (int k = 1; k <= 3; k++) {
            CHECK(cbvh_trace_qbvh(&q, s.tris, &r, 24, CBVH_TRAV_CLOSEST, (cbvh_qstack_kind)k, &hq[k], &one[k]) == 0,
                  "qbvh ray %d kind %d", i, k);
            CHECK(same_hit(&hb, &hq[k]), "%s ray %d kind %d: bvh hit %d prim %u t %08x, qbvh hit %d prim %u t %08x",
                  spec, i, k, hb.hit, hb.prim, hb.t, hq[k].hit, hq[k].prim, hq[k].t);
            sq[k].nodes += one[k].nodes;
            sq[k].box_tests += one[k].box_tests;
            sq[k].tri_tests += one[k].tri_tests;
            sq[k].bytes += one[k].bytes;
            if (one[k].max_stack > sq[k].max_stack) sq[k].max_stack = one[k].max_stack;
        }
        /* the stack kinds only change the stack, never the visiting order */
        CHECK(one[1].nodes == one[3].nodes && one[1].box_tests == one[3].box_tests &&
                  one[1].tri_tests == one[3].tri_tests && one[1].bytes == one[3].bytes &&
                  one[1].nodes == one[2].nodes && one[1].max_stack == one[2].max_stack,
              "ray %d: stack kinds visit differently", i);
        CHECK(one[1].max_stack <= one[3].max_stack, "ray %d: compressed deeper than plain", i);
        hits += hb.hit;
        CHECK(cbvh_trace_bvh(&b, s.tris, &r, 24, CBVH_TRAV_ANY, &ha, &sa) == 0, "any bvh");
        CHECK(cbvh_trace_qbvh(&q, s.tris, &r, 24, CBVH_TRAV_ANY, CBVH_QSTACK_AUTO, &hqa, &sa) == 0, "any qbvh");
        CHECK(hqa.hit == hb.hit && ha.hit == hb.hit, "%s ray %d: any-hit %d, closest %d", spec, i, hqa.hit, hb.hit);
        if (hqa.hit) {
            uint32_t best = hqa.t; /* an accepted hit: within [tmin, tmax], never closer than the closest */
            CHECK(cbvh_f32_key(best) >= cbvh_f32_key(hb.t), "any-hit closer than closest");
        }
    }
    CHECK(sq[1].max_stack <= sb.max_stack, "compressed stack %u deeper than binary %u", sq[1].max_stack,
          sb.max_stack);
    printf("%-22s %6u tris  binary %6u nodes depth-stack %2u | QBVH %6u nodes depth %2u stack: compressed %2u plain %2u"
           " | per ray: nodes %.1f/%.1f box %.1f/%.1f tri %.1f/%.1f (binary/QBVH), %d hits of %d\n",
           spec, s.ntris, leaves + inner, sb.max_stack, q.nnodes, q.depth, sq[1].max_stack, sq[3].max_stack,
           (double)sb.nodes / nrays, (double)sq[1].nodes / nrays, (double)sb.box_tests / nrays,
           (double)sq[1].box_tests / nrays, (double)sb.tri_tests / nrays, (double)sq[1].tri_tests / nrays, hits,
           nrays);
    cbvh_qbvh_free(&q);
    cbvh_bvh_free(&b);
    cbvh_scene_free(&s);
}

/* A sparse QBVH whose child group starts at 2^26: root 0 -> leaves at 2^26,
 * 2^26 + 1.  The arrays are calloc'ed (untouched pages cost nothing). */
static void past_limit(void) {
    const uint32_t F = CBVH_QSTACK_ID_LIMIT;
    cbvh_tri tris[3] = {{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}}, {{{0, 0, 1}, {1, 0, 1}, {0, 1, 1}}},
                        {{{0, 0, 2}, {1, 0, 2}, {0, 1, 2}}}};
    cbvh_qbvh q = {0};
    q.nnodes = F + 2;
    q.bmin = calloc(q.nnodes, sizeof *q.bmin);
    q.bmax = calloc(q.nnodes, sizeof *q.bmax);
    q.first = calloc(q.nnodes, sizeof *q.first);
    q.count = calloc(q.nnodes, sizeof *q.count);
    q.prims = malloc(3 * sizeof *q.prims);
    if (!q.bmin || !q.bmax || !q.first || !q.count || !q.prims) {
        CHECK(0, "cannot allocate the sparse tree");
        cbvh_qbvh_free(&q);
        return;
    }
    q.nprims = 3;
    for (uint32_t i = 0; i < 3; i++) q.prims[i] = 2 - i; /* leaf A: tris 2, 1; leaf B: tri 0 */
    const uint32_t nodes[3] = {0, F, F + 1};
    const float zlo[3] = {0, 1, 0}, zhi[3] = {2, 2, 0};
    for (int k = 0; k < 3; k++) {
        uint32_t n = nodes[k];
        q.bmin[n][0] = q.bmin[n][1] = 0;
        q.bmax[n][0] = q.bmax[n][1] = 1;
        q.bmin[n][2] = zlo[k];
        q.bmax[n][2] = zhi[k];
    }
    q.first[0] = F;
    q.count[0] = 2;
    q.first[F] = 0;
    q.count[F] = 2 | CBVH_QBVH_LEAF;
    q.first[F + 1] = 2;
    q.count[F + 1] = 1 | CBVH_QBVH_LEAF;
    q.max_first = F;
    char err[200];
    CHECK(cbvh_qbvh_stack_check(&q, CBVH_QSTACK_COMPRESSED, err, sizeof err) == -1 && strstr(err, "26-bit"),
          "compressed entry past 2^26 not refused");
    printf("past 2^26: %s\n", err);
    CHECK(cbvh_qbvh_stack_check(&q, CBVH_QSTACK_WIDE, err, sizeof err) == 0, "wide entry refused");
    /* a ray down -z at (0.25, 0.25): hits z = 2, 1, 0; closest is tri 2 at t = 1 */
    cbvh_ray r = {{fb(0.25f), fb(0.25f), fb(3.0f)}, {0, 0, fb(-1.0f)}, 0, CBVH_F32_POS_INF};
    cbvh_trav_hit h;
    cbvh_trav_stats st = {0};
    CHECK(cbvh_trace_qbvh(&q, tris, &r, 24, CBVH_TRAV_CLOSEST, CBVH_QSTACK_COMPRESSED, &h, &st) == -1 && !h.hit,
          "compressed traversal past 2^26 must fail, not wrap");
    for (int k = 0; k < 4; k++) {
        if (k == CBVH_QSTACK_COMPRESSED) continue;
        memset(&h, 0, sizeof h);
        CHECK(cbvh_trace_qbvh(&q, tris, &r, 24, CBVH_TRAV_CLOSEST, (cbvh_qstack_kind)k, &h, &st) == 0 && h.hit &&
                  h.prim == 2 && h.t == fb(1.0f),
              "kind %d past 2^26: hit %d prim %u t %08x", k, h.hit, h.prim, h.t);
    }
    /* the ray from below: closest is tri 0, reached only after popping the wide entry */
    cbvh_ray r2 = {{fb(0.25f), fb(0.25f), fb(-1.0f)}, {0, 0, fb(1.0f)}, 0, CBVH_F32_POS_INF};
    CHECK(cbvh_trace_qbvh(&q, tris, &r2, 24, CBVH_TRAV_CLOSEST, CBVH_QSTACK_WIDE, &h, &st) == 0 && h.hit &&
              h.prim == 0 && h.t == fb(1.0f),
          "wide from below: hit %d prim %u", h.hit, h.prim);
    cbvh_qbvh_free(&q);
}

int main(void) {
#ifdef CBVH_SANITIZE
    int n = 3000;
#else
    int n = 20000;
#endif
    run_scene(CBVH_SCENES_DIR "/bunny-small.obj", n);
    run_scene("proc:cloth:48", n);
    run_scene("proc:far", n / 2);
    past_limit();
    printf("%s (%d failures)\n", fails ? "FAILED" : "ok", fails);
    return fails ? 1 : 0;
}
