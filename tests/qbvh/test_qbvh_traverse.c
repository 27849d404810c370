/* QBVH traversal (docs/qbvh.md §4): on scenes/bunny-small.obj and procedural
 * scenes, for every ray the QBVH closest hit (triangle, t, b1, b2 bits) equals
 * the binary float BVH's, any-hit agrees, the three stack kinds visit the same
 * nodes, and the compressed stack is never deeper than the binary one.  Also:
 * the 2^26 limit on a sparse tree (compressed: clear error; wide: correct);
 * the refit of the QBVH's own boxes. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/qbvh.h"
#include "scene/scene_load.h"
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

/* Refit (cbvh_qbvh_refit, docs/qbvh.md §3): with the triangles the QBVH was
 * built from it gives back every box bit for bit (the collapse keeps the
 * binary BVH's tight boxes); with moved triangles (a twist) its boxes enclose
 * them again (cbvh_qbvh_check) and its closest hits equal those of the binary
 * BVH refitted to them (cbvh_bvh_refit), ray by ray; it recomputes every
 * node.  A child group before its parent is refused up front. */
static void refit(const char *spec, int nrays) {
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
    CHECK(cbvh_qbvh_refit_check(&q, err, sizeof err) == 0, "refit check: %s", err);
    size_t box_bytes = (size_t)q.nnodes * sizeof *q.bmin;
    float(*bmin0)[4] = malloc(box_bytes), (*bmax0)[4] = malloc(box_bytes);
    cbvh_tri *moved = malloc((size_t)s.ntris * sizeof *moved);
    if (!bmin0 || !bmax0 || !moved) {
        CHECK(0, "cannot allocate");
        goto out;
    }
    memcpy(bmin0, q.bmin, box_bytes);
    memcpy(bmax0, q.bmax, box_bytes);
    CHECK(cbvh_qbvh_refit(&q, s.tris) == q.nnodes, "refit: not every node recomputed");
    CHECK(memcmp(bmin0, q.bmin, box_bytes) == 0 && memcmp(bmax0, q.bmax, box_bytes) == 0,
          "%s: refit to the same triangles changed a box", spec);
    cbvh_scene_deform(&s, 0.8f, 0.1f, 1.0f, moved);
    cbvh_scene ms = s;
    ms.tris = moved;
    CHECK(cbvh_qbvh_refit(&q, moved) == q.nnodes, "refit: not every node recomputed");
    CHECK(memcmp(bmin0, q.bmin, box_bytes) != 0, "%s: the twist moved no box", spec);
    CHECK(cbvh_qbvh_check(&q, &ms, err, sizeof err) == 0, "%s: refitted QBVH: %s", spec, err);
    cbvh_bvh_refit(&b, moved);
    float lo[3], hi[3];
    cbvh_scene_bounds(&ms, lo, hi);
    int hits = 0;
    for (int i = 0; i < nrays; i++) {
        cbvh_ray r = box_ray(&rs, lo, hi, i, 0);
        cbvh_trav_hit hb, hq;
        cbvh_trav_stats st = {0};
        CHECK(cbvh_trace_bvh(&b, moved, &r, 24, CBVH_TRAV_CLOSEST, &hb, &st) == 0, "bvh ray %d", i);
        CHECK(cbvh_trace_qbvh(&q, moved, &r, 24, CBVH_TRAV_CLOSEST, CBVH_QSTACK_COMPRESSED, &hq, &st) == 0,
              "qbvh ray %d", i);
        CHECK(same_hit(&hb, &hq), "%s refitted, ray %d: bvh hit %d prim %u, qbvh hit %d prim %u", spec, i, hb.hit,
              hb.prim, hq.hit, hq.prim);
        hits += hb.hit;
    }
    CHECK(hits > nrays / 10, "%s refitted: only %d hits of %d rays", spec, hits, nrays);
    /* A child group before its parent: the one pass would use stale boxes. */
    if (q.nnodes > 1 && !(q.count[0] & CBVH_QBVH_LEAF)) {
        uint32_t f0 = q.first[0];
        q.first[0] = 0;
        CHECK(cbvh_qbvh_refit_check(&q, err, sizeof err) == -1 && strstr(err, "before its parent"),
              "a child group before its parent not refused");
        q.first[0] = f0;
    }
    printf("%-22s refit: %u QBVH nodes, %d hits of %d rays after a twist\n", spec, q.nnodes, hits, nrays);
out:
    free(bmin0);
    free(bmax0);
    free(moved);
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

/* A QBVH with a cycle (which cbvh_qbvh_check refuses, but the traversal must
 * not trust): (a) node 0's only child is node 0, no stack entry; (b) node 2's
 * children are node 1 (a leaf) and node 2, one stack entry per visit.  Every
 * box holds the ray.  The traversal must stop after nnodes inner-node visits
 * with -1 and no hit, for every stack kind, instead of looping. */
static void cyclic(void) {
    cbvh_tri tris[1] = {{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}}};
    float bmin[3][4] = {{0, 0, 0, 0}, {0, 0, 0, 0}, {0, 0, 0, 0}};
    float bmax[3][4] = {{1, 1, 2, 0}, {1, 1, 0, 0}, {1, 1, 2, 0}};
    uint32_t prims[1] = {0};
    uint32_t first_a[1] = {0}, count_a[1] = {1};
    uint32_t first_b[3] = {1, 0, 1}, count_b[3] = {2, 1 | CBVH_QBVH_LEAF, 2};
    cbvh_qbvh qa = {1, bmin, bmax, first_a, count_a, prims, 1, 0, 1};
    cbvh_qbvh qb = {3, bmin, bmax, first_b, count_b, prims, 1, 1, 2};
    char err[200];
    tris[0].v[0][2] = tris[0].v[1][2] = tris[0].v[2][2] = 0.0f;
    CHECK(cbvh_qbvh_check(&qb, &(cbvh_scene){.tris = tris, .ntris = 1}, err, sizeof err) == -1,
          "the structure check accepts a cyclic QBVH");
    cbvh_ray r = {{fb(0.25f), fb(0.25f), fb(3.0f)}, {0, 0, fb(-1.0f)}, 0, CBVH_F32_POS_INF};
    const cbvh_qbvh *qs[2] = {&qa, &qb};
    for (int t = 0; t < 2; t++)
        for (int k = 1; k <= 3; k++)
            for (int mode = 0; mode < 2; mode++) {
                cbvh_trav_hit h;
                cbvh_trav_stats st = {0};
                int rc = cbvh_trace_qbvh(qs[t], tris, &r, 24, mode ? CBVH_TRAV_ANY : CBVH_TRAV_CLOSEST,
                                         (cbvh_qstack_kind)k, &h, &st);
                CHECK(rc == -1 && !h.hit && st.nodes == qs[t]->nnodes,
                      "cyclic QBVH %c, stack kind %d, %s: rc %d hit %d after %llu inner-node visits", 'a' + t, k,
                      mode ? "any" : "closest", rc, h.hit, (unsigned long long)st.nodes);
            }
}

/* A valid chain QBVH D inner nodes deep: inner node k's children are inner
 * node k+1 (the nearer) and leaves holding triangles at z = -(k+1) - j/4
 * (deferred): one leaf under the root, w (1 or 2) under every other inner
 * node; the last inner node has a leaf in place of inner node D.  A ray down
 * -z defers them all, so at the bottom the compressed and wide stacks hold D
 * entries and the plain stack 1 + w(D-1).  Where that fits CBVH_TRAV_STACK
 * the closest hit is triangle 0 at t = D + 11; where not, the traversal
 * stops with -1 and no hit, its deepest stack the last that fitted.  Also: an
 * unknown stack kind is refused. */
static void deep_chain(int D, int w) {
    cbvh_qbvh q = {0};
    uint32_t ntri = 2u + (uint32_t)w * (uint32_t)(D - 1);
    q.nnodes = 2u + (1u + (uint32_t)w) * (uint32_t)(D - 1) + 1u;
    q.bmin = calloc(q.nnodes, sizeof *q.bmin);
    q.bmax = calloc(q.nnodes, sizeof *q.bmax);
    q.first = calloc(q.nnodes, sizeof *q.first);
    q.count = calloc(q.nnodes, sizeof *q.count);
    q.prims = malloc(ntri * sizeof *q.prims);
    cbvh_tri *tris = calloc(ntri, sizeof *tris);
    if (!q.bmin || !q.bmax || !q.first || !q.count || !q.prims || !tris) {
        CHECK(0, "cannot allocate the chain");
        cbvh_qbvh_free(&q);
        free(tris);
        return;
    }
    q.nprims = ntri;
    for (uint32_t n = 0; n < q.nnodes; n++) q.bmax[n][0] = q.bmax[n][1] = 1; /* x, y in [0, 1] */
    uint32_t self = 0, next = 1, prim = 0;
    for (int k = 0; k < D; k++) {
        int leaves = k == 0 ? 1 : w, last = k == D - 1;
        uint32_t g = next;
        next += 1u + (uint32_t)leaves;
        q.bmin[self][2] = -(float)(D + 2);
        q.bmax[self][2] = (float)(D + 1 - k);
        q.first[self] = g;
        q.count[self] = 1u + (uint32_t)leaves;
        if (g > q.max_first) q.max_first = g;
        for (int j = 0; j <= leaves; j++) {
            uint32_t n = g + (uint32_t)j;
            if (j == 0 && !last) continue; /* inner node k+1, filled next */
            float z = j == 0 ? -(float)(D + 1) : -(float)(k + 1) - 0.25f * (float)(j - 1);
            cbvh_tri t = {{{0, 0, z}, {1, 0, z}, {0, 1, z}}};
            tris[prim] = t;
            q.prims[prim] = prim;
            q.first[n] = prim++;
            q.count[n] = 1 | CBVH_QBVH_LEAF;
            q.bmin[n][2] = q.bmax[n][2] = z;
        }
        self = g;
    }
    q.depth = (uint32_t)D;
    char err[200];
    cbvh_scene sc = {.tris = tris, .ntris = ntri};
    CHECK(prim == ntri && next == q.nnodes, "chain of %d: %u triangles, %u nodes laid out", D, prim, next);
    CHECK(cbvh_qbvh_check(&q, &sc, err, sizeof err) == 0, "chain of %d: %s", D, err);
    uint32_t z0 = 0; /* the triangle at z = -1: the closest */
    while (z0 < ntri && tris[z0].v[0][2] != -1.0f) z0++;
    cbvh_ray r = {{fb(0.25f), fb(0.25f), fb((float)(D + 10))}, {0, 0, fb(-1.0f)}, 0, CBVH_F32_POS_INF};
    for (int k = 1; k <= 3; k++) {
        int per = k == CBVH_QSTACK_PLAIN ? w : 1; /* entries per inner node below the root */
        int need = 1 + per * (D - 1), fits = need <= CBVH_TRAV_STACK;
        int deepest = fits ? need : need - per * ((need - CBVH_TRAV_STACK + per - 1) / per);
        cbvh_trav_hit h;
        cbvh_trav_stats st = {0};
        int rc = cbvh_trace_qbvh(&q, tris, &r, 24, CBVH_TRAV_CLOSEST, (cbvh_qstack_kind)k, &h, &st);
        CHECK(fits ? rc == 0 && h.hit && h.prim == z0 && h.t == fb((float)(D + 11)) : rc == -1 && !h.hit,
              "chain of %d (w %d), stack kind %d: rc %d hit %d prim %u t %08x (stack needs %d of %d)", D, w, k, rc,
              h.hit, h.prim, h.t, need, CBVH_TRAV_STACK);
        CHECK(st.max_stack == (uint32_t)deepest, "chain of %d (w %d), stack kind %d: deepest stack %u, want %d", D,
              w, k, st.max_stack, deepest);
    }
    cbvh_trav_hit h;
    cbvh_trav_stats st = {0};
    CHECK(cbvh_qbvh_stack_check(&q, (cbvh_qstack_kind)7, err, sizeof err) == -1 && strstr(err, "unknown stack kind"),
          "stack kind 7 accepted");
    CHECK(cbvh_trace_qbvh(&q, tris, &r, 24, CBVH_TRAV_CLOSEST, (cbvh_qstack_kind)7, &h, &st) == -1 && !h.hit &&
              st.nodes == 0,
          "traversal with stack kind 7 not refused");
    cbvh_qbvh_free(&q);
    free(tris);
}

/* Lines a run of n bytes at a touches (64-byte lines). */
static uint64_t lines_of(uint64_t a, uint64_t n) { return (a + n - 1) / 64 - a / 64 + 1; }

static uint64_t align64(uint64_t a) { return (a + 63) / 64 * 64; }

/* The QBVH memory image (docs/qbvh.md §3 and §4: bmin, bmax, info, IDs,
 * triangles, each region line-aligned; a visit fetches its children's three
 * runs of 16k, 16k and 8k bytes).  A sparse QBVH: the root's four leaf
 * children start at node f (1..40), each leaf holds one ID; the hit leaf c's
 * ID is in slot p of 64 and names triangle id.  The line count must be the
 * image's: the root's three runs, the ID word and the triangle's 36 bytes. */
static void memory_map(void) {
    cbvh_tri tris[16];
    for (int i = 0; i < 16; i++) {
        cbvh_tri t = {{{0, 0, 0.5f}, {1, 0, 0.5f}, {0, 1, 0.5f}}};
        tris[i] = t;
    }
    long bad = 0;
    for (uint32_t f = 1; f <= 40; f++)
        for (uint32_t c = 0; c < 4; c++)
            for (uint32_t p = 0; p < 64; p++) {
                enum { MAXN = 44, NP = 64 };
                uint32_t id = (p * 7u + f) % 16u;
                float bmin[MAXN][4] = {{0}}, bmax[MAXN][4] = {{0}};
                uint32_t first[MAXN] = {0}, count[MAXN] = {0}, prims[NP];
                for (uint32_t i = 0; i < NP; i++) prims[i] = (id + 1u + i) % 16u;
                cbvh_qbvh q = {f + 4, bmin, bmax, first, count, prims, NP, f, 1};
                bmax[0][0] = 8;
                bmax[0][1] = bmax[0][2] = 1;
                first[0] = f;
                count[0] = 4;
                for (uint32_t k = 0; k < 4; k++) {
                    uint32_t n = f + k;
                    bmin[n][0] = 2.0f * (float)k; /* leaf k spans x in [2k, 2k + 1] */
                    bmax[n][0] = 2.0f * (float)k + 1;
                    bmax[n][1] = bmax[n][2] = 1;
                    first[n] = k == c ? p : (p + 1u + k) % NP;
                    count[n] = 1 | CBVH_QBVH_LEAF;
                }
                prims[p] = id;
                cbvh_tri local[16]; /* the hit triangle moved under leaf c */
                memcpy(local, tris, sizeof local);
                for (int v = 0; v < 3; v++) local[id].v[v][0] += 2.0f * (float)c;
                uint64_t bmax_base = align64(16u * q.nnodes), info_base = bmax_base + align64(16u * q.nnodes);
                uint64_t ids_base = info_base + align64(8u * q.nnodes), tris_base = align64(ids_base + 4u * NP);
                uint64_t want = lines_of(16u * f, 64) + lines_of(bmax_base + 16u * f, 64) +
                                lines_of(info_base + 8u * f, 32) + lines_of(ids_base + 4u * p, 4) +
                                lines_of(tris_base + 36u * id, 36);
                cbvh_ray r = {{fb(2.0f * (float)c + 0.25f), fb(0.25f), fb(2)}, {0, 0, fb(-1)}, 0, CBVH_F32_POS_INF};
                for (int k = 1; k <= 3; k++) {
                    cbvh_trav_hit h;
                    cbvh_trav_stats st = {0};
                    int rc = cbvh_trace_qbvh(&q, local, &r, 24, CBVH_TRAV_CLOSEST, (cbvh_qstack_kind)k, &h, &st);
                    if (rc || !h.hit || h.prim != id || st.nodes != 1 || st.tri_tests != 1 || st.lines != want ||
                        st.bytes != 64 * want) {
                        if (bad++ < 5)
                            printf("FAIL memory map: first child %u, leaf %u, ID slot %u, triangle %u, stack kind %d: "
                                   "rc %d hit %d prim %u, %llu lines / %llu bytes, want %llu\n",
                                   f, c, p, id, k, rc, h.hit, h.prim, (unsigned long long)st.lines,
                                   (unsigned long long)st.bytes, (unsigned long long)want);
                    }
                }
            }
    fails += (int)bad;
}

/* The collapse's order and its tie rule (qbvh.h): a node opens the inner
 * child of largest area, the leftmost of equal ones, and keeps the binary
 * left-to-right order.  Every box here is [0, 1]^3, so every choice is a tie:
 *   root -> A, B;  A -> a0, leaf p4;  B -> b0, leaf p5;
 *   a0 -> leaves p0, p1;  b0 -> leaves p2, p3.
 * Leftmost first: the root opens A, then a0: children p0, p1, p4, B, and B's
 * children p2, p3, p5.  (Rightmost first would give A, p2, p3, p5.) */
static void collapse_ties(void) {
    cbvh_bvh_node n[11];
    memset(n, 0, sizeof n);
    static const uint32_t kids[11][2] = {{1, 2}, {3, 4}, {5, 6}, {7, 8}, {0, 0}, {9, 10}};
    static const uint32_t prim_of[11] = {0, 0, 0, 0, 4, 0, 5, 0, 1, 2, 3};
    uint32_t prims[6] = {0, 1, 2, 3, 4, 5};
    for (int i = 0; i < 11; i++) {
        for (int a = 0; a < 3; a++) n[i].hi[a] = 1.0f;
        int leaf = i == 4 || i == 6 || i >= 7;
        if (leaf) {
            n[i].first = prim_of[i];
            n[i].count = 1;
        } else {
            n[i].child[0] = kids[i][0];
            n[i].child[1] = kids[i][1];
        }
    }
    cbvh_bvh b = {n, 11, 0, prims, 6};
    cbvh_qbvh q = {0};
    char err[256] = "";
    CHECK(cbvh_qbvh_from_bvh(&b, &q, err, sizeof err) == 0, "collapse of the tie tree: %s", err);
    if (!q.nnodes) return;
    /* a child's primitive (a leaf) or -1 (inner) */
    uint32_t f = q.first[0];
    CHECK(q.count[0] == 4 && q.nnodes == 8, "root has %u children, %u nodes; want 4, 8", q.count[0], q.nnodes);
    static const int want_root[4] = {0, 1, 4, -1}, want_b[3] = {2, 3, 5};
    for (int c = 0; c < 4 && q.count[0] == 4; c++) {
        uint32_t i = f + (uint32_t)c;
        int got = (q.count[i] & CBVH_QBVH_LEAF) ? (int)q.prims[q.first[i]] : -1;
        CHECK(got == want_root[c], "root child %d: primitive %d, want %d", c, got, want_root[c]);
    }
    uint32_t bi = f + 3;
    CHECK(q.nnodes == 8 && !(q.count[bi] & CBVH_QBVH_LEAF) && q.count[bi] == 3, "B: count %08X, want 3",
          q.nnodes == 8 ? q.count[bi] : 0);
    for (int c = 0; c < 3 && q.nnodes == 8 && q.count[bi] == 3; c++) {
        uint32_t i = q.first[bi] + (uint32_t)c;
        int got = (q.count[i] & CBVH_QBVH_LEAF) ? (int)q.prims[q.first[i]] : -1;
        CHECK(got == want_b[c], "B child %d: primitive %d, want %d", c, got, want_b[c]);
    }
    cbvh_qbvh_free(&q);
    /* a child index outside the binary BVH, met when node 5 is opened: refused, not read */
    n[5].child[1] = 11;
    err[0] = 0;
    CHECK(cbvh_qbvh_from_bvh(&b, &q, err, sizeof err) == -1 && strstr(err, "not a tree") && !q.nnodes,
          "collapse of a BVH with a child outside it: %s", err);
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
    refit(CBVH_SCENES_DIR "/bunny-small.obj", n / 4);
    refit("proc:cloth:48", n / 4);
    past_limit();
    cyclic();
    collapse_ties();
    memory_map();
    /* The compressed and wide stacks overflow past CBVH_TRAV_STACK inner
     * nodes; the plain stack with two entries per node at 129. */
    deep_chain(CBVH_TRAV_STACK, 1);
    deep_chain(CBVH_TRAV_STACK + 1, 1);
    deep_chain(CBVH_TRAV_STACK / 2, 2);
    deep_chain(CBVH_TRAV_STACK / 2 + 1, 2);
    printf("%s (%d failures)\n", fails ? "FAILED" : "ok", fails);
    return fails ? 1 : 0;
}
