/* Traversal benchmark (the throughput targets against Embree): on the same
 * scene and the same rays in one run, single-ray throughput of
 *   - Embree 3 rtcIntersect1 / rtcOccluded1 (the baseline; if built with it),
 *   - the float BVH with a plain floating-point traversal (conservative
 *     binary64 slab test, the triangle unit: cbvh_trace_bvh_float),
 *   - the float BVH through the bit-exact units (box unit M = 24),
 *   - the bit-exact CBVH traversal (N = 6 modulo, M = 24),
 *   - the same CBVH decoded once (cbvh_cbvh_decode, cbvh_trace_cbvh_decoded),
 *     whose hits and counters must equal the CBVH's on every ray (else exit 1),
 *   - the float BVH collapsed 4-wide (cbvh_qbvh_from_bvh) with the same plain
 *     floating-point box test in four lanes (cbvh_trace_qbvh_float), whose
 *     hit count must equal the plain traversal's (else exit 1),
 *   - the float BVH collapsed 8-wide (cbvh_f8bvh_build) with the same box
 *     test in eight lanes (cbvh_trace_f8bvh_float), likewise checked,
 * closest hit and any hit, one core, as ratios to Embree.
 *
 * usage: bench_traverse [--rays R] [--seed S] [--reps K] [--embree-isa ISA] [--embree-robust]
 *                       [--wide-isa base|avx] [--wide-box f32|f64] [SCENE...]
 *   SCENE as for `cbvh study` (mesh file or proc:NAME[:SIZE]); default: the
 *   bundled bunny.  R rays per kind (default 20000): camera rays (pinhole, a
 *   square image looking at the scene centre from outside its box) and random
 *   rays (origin uniform in the scene box, direction uniform on the sphere),
 *   seeded.  Times are the best of K repetitions (default 3), the tracers
 *   interleaved within each repetition.
 * Embree's device is created with threads=1; the traversal loop runs on the
 * calling thread for every tracer.  --embree-isa limits Embree to one
 * instruction set (Embree's "isa=" setting: sse2, sse4.2, avx, avx2, avx512);
 * by default it picks the widest the CPU has, while our code is built for the
 * x86-64 baseline (SSE2), so sse2 compares like with like; only the wide
 * float traversals (4- and 8-wide) also run an AVX build of their loop on
 * CPUs with AVX, which --wide-isa base turns off (the ISA in use is printed
 * first); their box lanes are binary32 where the ray and planes allow
 * (docs/traversal.md §16), binary64 everywhere with --wide-box f64.
 * --embree-robust
 * builds Embree's scenes in its robust mode (RTC_SCENE_FLAG_ROBUST): ours
 * never miss (conservative boxes, exact triangles), Embree's default mode may. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cbvh/bvh.h"
#include "cbvh/cbvh_tree.h"
#include "cbvh/f8bvh.h"
#include "cbvh/qbvh.h"
#include "cbvh/traverse.h"
#define BENCH_NAME "bench_traverse"
#include "bench_rays.h"

#ifdef CBVH_HAVE_EMBREE
#include "bench_embree.h"
#endif

#ifndef CBVH_SCENES_DIR
#define CBVH_SCENES_DIR "scenes"
#endif

typedef struct {
    double rays_per_s;
    long hits;
} result;

/* tracer: 0 float BVH through the units, 1 CBVH, 2 float BVH plain float,
 * 3 CBVH decoded once, 4 float BVH collapsed 4-wide, plain float, 5 the same
 * 8-wide */
static result run_ours(int cbvh, const cbvh_bvh *b, const cbvh_fbvh *fb, const cbvh_fqbvh *fq,
                       const cbvh_f8bvh *f8, const cbvh_tree *t,
                       const cbvh_cbvh_decoded *dec, const cbvh_tri *tris, const cbvh_ray *rays, int n,
                       cbvh_trav_mode mode, int reps, cbvh_trav_stats *st) {
    result res = {0, 0};
    double best = 1e30;
    for (int k = 0; k < reps; k++) {
        long hits = 0;
        cbvh_trav_stats s = {0};
        double t0 = now();
        for (int i = 0; i < n; i++) {
            cbvh_trav_hit h;
            int rc = cbvh == 1   ? cbvh_trace_cbvh(t, tris, &rays[i], 24, mode, &h, &s)
                     : cbvh == 3 ? cbvh_trace_cbvh_decoded(dec, tris, &rays[i], 24, mode, &h, &s)
                     : cbvh == 2 ? cbvh_trace_bvh_float(fb, tris, &rays[i], mode, &h, &s)
                     : cbvh == 4 ? cbvh_trace_qbvh_float(fq, tris, &rays[i], mode, &h, &s)
                     : cbvh == 5 ? cbvh_trace_f8bvh_float(f8, tris, &rays[i], mode, &h, &s)
                                 : cbvh_trace_bvh(b, tris, &rays[i], 24, mode, &h, &s);
            if (rc) die("trace", "ray rejected");
            hits += h.hit;
        }
        double dt = now() - t0;
        if (dt < best) best = dt;
        res.hits = hits;
        *st = s;
    }
    res.rays_per_s = n / best;
    return res;
}

#ifdef CBVH_HAVE_EMBREE
static result run_embree(RTCScene sc, const cbvh_ray *rays, int n, int occluded, int reps) {
    result res = {0, 0};
    double best = 1e30;
    for (int k = 0; k < reps; k++) {
        double dt = embree_trace(sc, rays, n, occluded, &res.hits);
        if (dt < best) best = dt;
    }
    res.rays_per_s = n / best;
    return res;
}
#endif

int main(int argc, char **argv) {
    bench_args A = {.nrays = 20000, .reps = 3, .seed = 1};
    bench_parse(argc, argv, &A, CBVH_SCENES_DIR "/bunny-small.obj");
    int nrays = A.nrays, reps = A.reps, ns = A.ns;
    const char *const *specs = A.specs;
#ifdef CBVH_HAVE_EMBREE
    RTCDevice dev = embree_device(A.isa);
    if (A.robust) printf("embree scenes: RTC_SCENE_FLAG_ROBUST\n");
#else
    printf("(built without Embree: no baseline, absolute rays/s only)\n");
#endif
    char err[512];
    printf("# wide float traversals' box test: %s, %s lanes\n", cbvh_wide_isa_name(cbvh_wide_float_isa()),
           cbvh_wide_float_box32_on() ? "binary32 (where small enough)" : "binary64");
    printf("%-24s %7s %-12s %11s %11s %11s %11s %11s %11s %8s %8s %8s %8s %8s %8s %8s %8s %8s %7s %7s %7s %7s %7s "
           "%7s %7s %7s %11s %8s %7s %7s\n",
           "scene", "tris", "kind", "embree_r/s", "float_r/s", "bvh_r/s", "cbvh_r/s", "cbvhd_r/s", "flt4_r/s",
           "float/e", "bvh/emb", "cbvh/emb", "cbvhd/e", "float4/e", "hits_e", "hits_f", "hits_b", "hits_c", "flt_box",
           "flt_tri", "bvh_box", "bvh_tri", "cbv_box", "cbv_tri", "fl4_box", "fl4_tri", "flt8_r/s", "float8/e",
           "fl8_box", "fl8_tri");
    cbvh_ray *rays = malloc((size_t)nrays * sizeof *rays);
    if (!rays) die("rays", "out of memory");
    for (int si = 0; si < ns; si++) {
        cbvh_scene s;
        cbvh_bvh b;
        load_scene(specs[si], &s, &b, "build");
        cbvh_compress_opts o = {{CBVH_N_DEFAULT, CBVH_MIN_SCALE_DEFAULT}, CBVH_ENC_MODULO, 1, 0};
        cbvh_tree t;
        if (cbvh_compress_topdown(&b, &o, &t, err, sizeof err)) die("compress", err);
        cbvh_fbvh fb;
        if (cbvh_fbvh_build(&b, &fb, err, sizeof err)) die("layout", err);
        cbvh_qbvh qb;
        cbvh_fqbvh fq;
        if (cbvh_qbvh_from_bvh(&b, &qb, err, sizeof err) || cbvh_fqbvh_build(&qb, s.tris, s.ntris, &fq, err, sizeof err))
            die("4-wide layout", err);
        cbvh_f8bvh f8;
        if (cbvh_f8bvh_build(&b, s.tris, s.ntris, &f8, err, sizeof err)) die("8-wide layout", err);
        cbvh_cbvh_decoded dt;
        double d0 = now();
        if (cbvh_cbvh_decode(&t, &dt, err, sizeof err) || cbvh_cbvh_decode_leaves(&dt, s.tris, s.ntris, err, sizeof err))
            die("decode", err);
        double decode_s = now() - d0;
        if (!dt.usable || !dt.leaf_tris) die("decode", "the CBVH is not one the fast decode takes");
        float lo[3], hi[3];
        cbvh_scene_bounds(&s, lo, hi);
        make_rays(lo, hi, nrays, rays);
#ifdef CBVH_HAVE_EMBREE
        RTCScene sc = embree_scene(dev, &s, A.robust);
#endif
        const char *base = scene_base(specs[si]);
        /* what decoding once costs: time (a share of one ray batch) and memory */
        printf("# %s: CBVH %u pairs, %zu bytes; decoded once in %.2f ms, %zu bytes (%u pairs with binary64 planes)\n",
               base, t.npairs, (size_t)t.npairs * t.pair_bytes, 1e3 * decode_s,
               (size_t)t.npairs * (sizeof(cbvh_cbvh_dnode) + sizeof(cbvh_cbvh_drel)) +
                   (size_t)dt.nwide * sizeof(cbvh_cbvh_dwide) + (size_t)t.nids * sizeof(cbvh_cbvh_dtri),
               dt.nwide);
        for (int half = 0; half < 2; half++) {
            const cbvh_ray *rr = rays + (half ? nrays / 2 : 0);
            int n = half ? nrays - nrays / 2 : nrays / 2;
            for (int mode = 0; mode < 2; mode++) {
                /* repetitions interleave the tracers so that load changes on the
                 * shared machine hit all of them alike; best time of each */
                cbvh_trav_stats sb = {0}, sc_ = {0}, sf = {0}, sd = {0}, sq = {0}, s8 = {0};
                result rb = {0, 0}, rc = {0, 0}, re = {0, 0}, rf = {0, 0}, rd = {0, 0}, rq = {0, 0}, r8 = {0, 0};
                cbvh_trav_mode md = (cbvh_trav_mode)mode;
                for (int k = 0; k < reps; k++) {
                    result y = run_ours(2, &b, &fb, &fq, &f8, &t, &dt, s.tris, rr, n, md, 1, &sf);
                    if (y.rays_per_s > rf.rays_per_s) rf = y;
                    result x = run_ours(0, &b, &fb, &fq, &f8, &t, &dt, s.tris, rr, n, md, 1, &sb);
                    if (x.rays_per_s > rb.rays_per_s) rb = x;
                    x = run_ours(1, &b, &fb, &fq, &f8, &t, &dt, s.tris, rr, n, md, 1, &sc_);
                    if (x.rays_per_s > rc.rays_per_s) rc = x;
                    x = run_ours(3, &b, &fb, &fq, &f8, &t, &dt, s.tris, rr, n, md, 1, &sd);
                    if (x.rays_per_s > rd.rays_per_s) rd = x;
                    x = run_ours(4, &b, &fb, &fq, &f8, &t, &dt, s.tris, rr, n, md, 1, &sq);
                    if (x.rays_per_s > rq.rays_per_s) rq = x;
                    x = run_ours(5, &b, &fb, &fq, &f8, &t, &dt, s.tris, rr, n, md, 1, &s8);
                    if (x.rays_per_s > r8.rays_per_s) r8 = x;
#ifdef CBVH_HAVE_EMBREE
                    x = run_embree(sc, rr, n, mode, 1);
                    if (x.rays_per_s > re.rays_per_s) re = x;
#endif
                }
                if (rd.hits != rc.hits || memcmp(&sd, &sc_, sizeof sd))
                    die("decoded CBVH", "hits or counters differ from the CBVH traversal's");
                if (rq.hits != rf.hits) die("4-wide float", "hits differ from the plain float traversal's");
                if (r8.hits != rf.hits) die("8-wide float", "hits differ from the plain float traversal's");
                char kind[16];
                snprintf(kind, sizeof kind, "%s-%s", half ? "rand" : "cam", mode ? "any" : "closest");
                /* work per ray behind the throughput: box and triangle tests */
                double e = re.rays_per_s > 0 ? re.rays_per_s : 0;
                printf("%-24s %7u %-12s %11.0f %11.0f %11.0f %11.0f %11.0f %11.0f %8.4f %8.4f %8.4f %8.4f %8.4f "
                       "%8ld %8ld %8ld %8ld %7.2f %7.2f %7.2f %7.2f %7.2f %7.2f %7.2f %7.2f %11.0f %8.4f %7.2f %7.2f\n",
                       base, s.ntris, kind, re.rays_per_s, rf.rays_per_s, rb.rays_per_s, rc.rays_per_s,
                       rd.rays_per_s, rq.rays_per_s, e > 0 ? rf.rays_per_s / e : 0, e > 0 ? rb.rays_per_s / e : 0,
                       e > 0 ? rc.rays_per_s / e : 0, e > 0 ? rd.rays_per_s / e : 0, e > 0 ? rq.rays_per_s / e : 0,
                       re.hits, rf.hits, rb.hits, rc.hits, (double)sf.box_tests / n, (double)sf.tri_tests / n,
                       (double)sb.box_tests / n, (double)sb.tri_tests / n, (double)sc_.box_tests / n,
                       (double)sc_.tri_tests / n, (double)sq.box_tests / n, (double)sq.tri_tests / n,
                       r8.rays_per_s, e > 0 ? r8.rays_per_s / e : 0, (double)s8.box_tests / n,
                       (double)s8.tri_tests / n);
                fflush(stdout);
            }
        }
#ifdef CBVH_HAVE_EMBREE
        rtcReleaseScene(sc);
#endif
        cbvh_cbvh_decoded_free(&dt);
        cbvh_fqbvh_free(&fq);
        cbvh_f8bvh_free(&f8);
        cbvh_qbvh_free(&qb);
        cbvh_tree_free(&t);
        cbvh_fbvh_free(&fb);
        cbvh_bvh_free(&b);
        cbvh_scene_free(&s);
    }
    free(rays);
#ifdef CBVH_HAVE_EMBREE
    rtcReleaseDevice(dev);
#endif
    return 0;
}
