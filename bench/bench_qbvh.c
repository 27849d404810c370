/* QBVH (seed 000) vs the binary SAH BVH it is collapsed from, on the same rays
 * in one run: maximum stack depth, node-array footprint, nodes / box tests /
 * triangle tests per ray, rays/s (closest hit, best of K interleaved runs),
 * next to Bogolepov & Ulyanov's table.  Every QBVH hit is checked against the
 * binary BVH's (triangle and t bits); a mismatch aborts.
 *
 * usage: bench_qbvh [--rays R] [--reps K] [SCENE...]   (default: bundled bunny)
 *   R rays per scene: half camera rays (pinhole over a square image), half
 *   random rays (origin uniform in the scene box, direction uniform). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cbvh/qbvh.h"
#define BENCH_NAME "bench_qbvh"
#include "bench_rays.h"

/* Levels below the root of the binary tree (the stack size a traversal must
 * allocate is bounded by it; the paper's "stack size"). */
static uint32_t bvh_depth(const cbvh_bvh *b) {
    uint32_t *st = malloc((size_t)b->nnodes * 2 * sizeof *st), n = 0, best = 0;
    if (!st) die("depth", "out of memory");
    st[n++] = b->root;
    st[n++] = 0;
    while (n) {
        uint32_t d = st[--n], i = st[--n];
        if (d > best) best = d;
        if (cbvh_bvh_is_leaf(&b->nodes[i])) continue;
        for (int c = 0; c < 2; c++) {
            st[n++] = b->nodes[i].child[c];
            st[n++] = d + 1;
        }
    }
    free(st);
    return best;
}

/* kind < 0: binary BVH; else the QBVH with that stack kind. */
static double run(int kind, const cbvh_bvh *b, const cbvh_qbvh *q, const cbvh_tri *tris, const cbvh_ray *rays,
                  int n, cbvh_trav_mode mode, cbvh_trav_hit *hits, cbvh_trav_stats *st) {
    memset(st, 0, sizeof *st);
    double t0 = now();
    for (int i = 0; i < n; i++) {
        int rc = kind < 0 ? cbvh_trace_bvh(b, tris, &rays[i], 24, mode, &hits[i], st)
                          : cbvh_trace_qbvh(q, tris, &rays[i], 24, mode, (cbvh_qstack_kind)kind,
                                            &hits[i], st);
        if (rc) die("trace", "ray rejected or stack overflow");
    }
    return now() - t0;
}

int main(int argc, char **argv) {
    rs = 0x51ED2701F00DULL; /* the seed of the figures in docs/results.md */
    int nrays = 20000, reps = 3, ns = 0;
    const char *specs[64];
    for (int i = 1; i < argc; i++) {
        if (int_option(argc, argv, &i, "--rays", 2, 10000000, &nrays) ||
            int_option(argc, argv, &i, "--reps", 1, 100, &reps))
            continue;
        if (argv[i][0] == '-') {
            fprintf(stderr, "usage: bench_qbvh [--rays R] [--reps K] [SCENE...]\n");
            return 2;
        } else if (ns < 64) {
            specs[ns++] = argv[i];
        }
    }
    if (!ns) specs[ns++] = CBVH_SCENES_DIR "/bunny-small.obj";
    cbvh_ray *rays = malloc((size_t)nrays * sizeof *rays);
    cbvh_trav_hit *hb = malloc((size_t)nrays * sizeof *hb), *hq = malloc((size_t)nrays * sizeof *hq);
    if (!rays || !hb || !hq) die("rays", "out of memory");
    printf("closest hit, %d rays per scene (half camera, half random), best of %d; per ray: binary / QBVH\n", nrays,
           reps);
    printf("%-24s %9s %7s %7s | %7s | %5s %5s %5s | %9s %9s %6s | %11s %11s %11s | %9s %9s %6s | %6s\n", "scene", "tris",
           "bin_n", "q_n", "depthBQ", "stkB", "stkQ", "stkQp", "bin_KiB", "q_KiB", "ratio", "nodes", "box", "tri", "bin_r/s",
           "q_r/s", "speed", "any");
    char err[512];
    for (int si = 0; si < ns; si++) {
        cbvh_scene s;
        cbvh_bvh b;
        cbvh_qbvh q;
        load_scene(specs[si], &s, &b, "build");
        if (cbvh_qbvh_from_bvh(&b, &q, err, sizeof err)) die("collapse", err);
        if (cbvh_qbvh_check(&q, &s, err, sizeof err)) die("qbvh check", err);
        float lo[3], hi[3];
        cbvh_scene_bounds(&s, lo, hi);
        make_rays(lo, hi, nrays, rays);
        uint32_t leaves, inner;
        cbvh_bvh_counts(&b, &leaves, &inner);
        cbvh_trav_stats sb, sq, sp;
        double tb = 1e30, tq = 1e30, tab = 1e30, taq = 1e30;
        for (int k = 0; k < reps; k++) { /* interleaved: load changes hit both alike */
            double t = run(-1, &b, &q, s.tris, rays, nrays, CBVH_TRAV_ANY, hb, &sb);
            if (t < tab) tab = t;
            t = run(CBVH_QSTACK_COMPRESSED, &b, &q, s.tris, rays, nrays, CBVH_TRAV_ANY, hq, &sq);
            if (t < taq) taq = t;
            for (int i = 0; i < nrays; i++)
                if (hb[i].hit != hq[i].hit) die(specs[si], "QBVH any-hit differs from the binary BVH");
            t = run(-1, &b, &q, s.tris, rays, nrays, CBVH_TRAV_CLOSEST, hb, &sb);
            if (t < tb) tb = t;
            t = run(CBVH_QSTACK_COMPRESSED, &b, &q, s.tris, rays, nrays, CBVH_TRAV_CLOSEST, hq, &sq);
            if (t < tq) tq = t;
        }
        run(CBVH_QSTACK_PLAIN, &b, &q, s.tris, rays, nrays, CBVH_TRAV_CLOSEST, hq, &sp);
        for (int i = 0; i < nrays; i++)
            if (hb[i].hit != hq[i].hit || (hb[i].hit && (hb[i].prim != hq[i].prim || hb[i].t != hq[i].t)))
                die(specs[si], "QBVH hit differs from the binary BVH");
        /* Node arrays in the same 40-byte SoA format for both trees. */
        double bk = (double)(leaves + inner) * CBVH_QBVH_NODE_BYTES / 1024, qk = (double)cbvh_qbvh_node_bytes(&q) / 1024;
        const char *base = scene_base(specs[si]);
        char nodes[32], box[32], tri[32], depth[32];
        snprintf(depth, sizeof depth, "%u/%u", bvh_depth(&b), q.depth);
        snprintf(nodes, sizeof nodes, "%.1f/%.1f", (double)sb.nodes / nrays, (double)sq.nodes / nrays);
        snprintf(box, sizeof box, "%.1f/%.1f", (double)sb.box_tests / nrays, (double)sq.box_tests / nrays);
        snprintf(tri, sizeof tri, "%.2f/%.2f", (double)sb.tri_tests / nrays, (double)sq.tri_tests / nrays);
        printf("%-24s %9u %7u %7u | %7s | %5u %5u %5u | %9.1f %9.1f %6.3f | %11s %11s %11s | %9.0f %9.0f %6.3f | %6.3f\n", base,
               s.ntris, leaves + inner, q.nnodes, depth, sb.max_stack, sq.max_stack, sp.max_stack, bk, qk, bk / qk, nodes,
               box, tri, nrays / tb, nrays / tq, tb / tq, tab / taq);
        fflush(stdout);
        cbvh_qbvh_free(&q);
        cbvh_bvh_free(&b);
        cbvh_scene_free(&s);
    }
    printf("paper (GTX 770, 1280x720): stack 34->15, 25->11, 54->25; footprint 1.24-1.34x smaller; +14%% to +39%% fps\n");
    printf("depthBQ = tree depth binary/QBVH (the stack a traversal must allocate);\n");
    printf("speed = QBVH/binary rays/s (closest hit); any = the same for any-hit (shadow rays)\n");
    printf("stkB = binary traversal's max stack (traverse_bvh.c: includes the next node to visit);\n"
           "stkQ = compressed 32-bit entries (deferred only); stkQp = plain one-ID-per-entry stack\n");
    free(rays);
    free(hb);
    free(hq);
    return 0;
}
