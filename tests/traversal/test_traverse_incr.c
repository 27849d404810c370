/* The CBVH traversed with the incremental ray-box unit (docs/traversal.md
 * §17.8): the same closest and any hit as the float BVH at every N and M.
 *
 *   scenes  bunny-small (SAH and LBVH), proc:cloth (edge-on rays in its
 *           plane), proc:far; and random soups at binary32's extremes
 *           (+-FLT_MAX, subnormal, mixed 1e+-30, flat and far)
 *   trees   top-down CBVHs at N = 3..10, modulo, and relative at N = 6; a
 *           bottom-up one at N = 6; min scale -30, and -126 on the soups
 *   units   M = 6, 8, 12, 16, 24 (and 3), X = 8 (and 5, 3 on some)
 *   rays    tests/common/test_trav_util.h's box rays (outside, inside,
 *           axis-parallel with +-0, bounded tmax, edge-on), closest and any
 * Against the float BVH through unit 6 at M = 24: hit, triangle, t, b1, b2;
 * the counters: false-positive box hits <= box tests, their triangle tests
 * <= all triangle tests, and with M = 24 fewer than 2 % of the box tests on
 * the scenes (not on the soups, whose distances overflow or underflow F).
 * Prints the box tests, false positives and triangle tests per (N, M) of
 * bunny-small against the exact unit's CBVH traversal. */
#include <math.h>
#include <stdlib.h>

#include "cbvh/cbvh_tree.h"
#include "cbvh/traverse_incr.h"
#include "scene/scene_load.h"
#include "test_trav_util.h"

#ifdef CBVH_SANITIZE
#define RAYS 150
#else
#define RAYS 1500
#endif

static long fails;
#define CHECK(c, ...) TU_CHECK(fails, stdout, c, __VA_ARGS__)

static void run_tree(const char *what, const cbvh_tree *t, const cbvh_scene *s, const cbvh_ray *rays,
                     const cbvh_trav_hit *ref, const int *ref_any, int nrays, int M, int X, int print) {
    cbvh_trav_stats st = {0}, ex = {0};
    long diff = 0, adiff = 0, hits = 0;
    for (int i = 0; i < nrays; i++) {
        cbvh_trav_hit h, he;
        int rc = cbvh_trace_cbvh_incr(t, s->tris, &rays[i], M, X, CBVH_TRAV_CLOSEST, &h, &st);
        CHECK(rc == 0, "%s M %d X %d ray %d: rc %d", what, M, X, i, rc);
        if (!same_hit(&h, &ref[i])) {
            if (diff++ < 3)
                printf("  %s M %d X %d ray %d: hit %d prim %u t %08x, float BVH hit %d prim %u t %08x\n", what, M, X,
                       i, h.hit, h.prim, h.t, ref[i].hit, ref[i].prim, ref[i].t);
        }
        hits += h.hit;
        cbvh_trav_stats sa = {0};
        rc = cbvh_trace_cbvh_incr(t, s->tris, &rays[i], M, X, CBVH_TRAV_ANY, &h, &sa);
        if (rc != 0 || h.hit != ref_any[i]) adiff++;
        if (print) cbvh_trace_cbvh(t, s->tris, &rays[i], M, CBVH_TRAV_CLOSEST, &he, &ex);
    }
    CHECK(diff == 0 && adiff == 0, "%s M %d X %d: %ld closest and %ld any hits differ from the float BVH's", what, M, X,
          diff, adiff);
    CHECK(st.fp_box_hits <= st.box_tests && st.fp_tri_tests <= st.tri_tests, "%s: counters out of range", what);
    if (M == 24 && X == 8 && st.box_tests > 1000 && strncmp(what, "soup", 4) != 0) /* scenes of moderate extent */
        CHECK(st.fp_box_hits * 50 < st.box_tests, "%s M 24: %llu false-positive box hits of %llu tests", what,
              (unsigned long long)st.fp_box_hits, (unsigned long long)st.box_tests);
    if (print)
        printf("%-28s M %2d: hits %4ld  box tests %8llu (exact unit: %8llu, x%.3f)  false-positive hits %7llu  "
               "triangle tests %8llu (exact: %8llu, x%.3f), %7llu of them under a false positive\n",
               what, M, hits, (unsigned long long)st.box_tests, (unsigned long long)ex.box_tests,
               (double)st.box_tests / (double)(ex.box_tests ? ex.box_tests : 1), (unsigned long long)st.fp_box_hits,
               (unsigned long long)st.tri_tests, (unsigned long long)ex.tri_tests,
               (double)st.tri_tests / (double)(ex.tri_tests ? ex.tri_tests : 1), (unsigned long long)st.fp_tri_tests);
}

static void run_scene(cbvh_scene *s, const char *name, int lbvh, int min_scale, int all_n) {
    char err[256];
    cbvh_bvh b;
    int rc = lbvh ? cbvh_build_lbvh(s, &b, err, sizeof err) : cbvh_build_sah(s, 0, 0, &b, err, sizeof err);
    if (rc) {
        CHECK(0, "build %s: %s", name, err);
        return;
    }
    float lo[3], hi[3];
    cbvh_scene_bounds(s, lo, hi);
    uint64_t rs = 0x1234567ull + (uint64_t)s->ntris;
    int nrays = all_n ? RAYS : RAYS / 10;
    cbvh_ray *rays = malloc((size_t)nrays * sizeof *rays);
    cbvh_trav_hit *ref = malloc((size_t)nrays * sizeof *ref);
    int *ref_any = malloc((size_t)nrays * sizeof *ref_any);
    if (!rays || !ref || !ref_any) abort();
    int edge_on = strstr(name, "cloth") != NULL;
    for (int i = 0; i < nrays; i++) {
        rays[i] = box_ray(&rs, lo, hi, i, edge_on);
        for (int a = 0; a < 3; a++) { /* the soups at +-FLT_MAX: keep the ray finite */
            if (cbvh_f32_is_nan_or_inf(rays[i].o[a])) rays[i].o[a] = fb(((rays[i].o[a] >> 31) ? -1.0f : 1.0f) * 3e38f);
            if (cbvh_f32_is_nan_or_inf(rays[i].d[a])) rays[i].d[a] = fb((rays[i].d[a] >> 31) ? -1.0f : 1.0f);
        }
        cbvh_trav_stats st = {0};
        CHECK(cbvh_trace_bvh(&b, s->tris, &rays[i], 24, CBVH_TRAV_CLOSEST, &ref[i], &st) == 0, "float BVH ray %d", i);
        cbvh_trav_hit ha;
        cbvh_trace_bvh(&b, s->tris, &rays[i], 24, CBVH_TRAV_ANY, &ha, &st);
        ref_any[i] = ha.hit;
    }
    static const int Ms[6] = {6, 8, 12, 16, 24, 3};
    for (int N = 3; N <= 10; N++) {
        if (!all_n && N != 3 && N != 6 && N != 10) continue;
        for (int enc = 0; enc < (N == 6 ? 2 : 1); enc++) {
            cbvh_compress_opts o = {{N, min_scale}, enc ? CBVH_ENC_RELATIVE : CBVH_ENC_MODULO, 1, 0};
            cbvh_tree t;
            if (cbvh_compress_topdown(&b, &o, &t, err, sizeof err)) {
                CHECK(0, "compress %s N %d: %s", name, N, err);
                continue;
            }
            char what[96];
            snprintf(what, sizeof what, "%s N %d%s", name, N, enc ? " relative" : "");
            for (int m = 0; m < 6; m++)
                run_tree(what, &t, s, rays, ref, ref_any, nrays, Ms[m], 8, all_n && !lbvh && !enc);
            if (N == 6 || N == 3) {
                run_tree(what, &t, s, rays, ref, ref_any, nrays, 8, 5, 0);
                run_tree(what, &t, s, rays, ref, ref_any, nrays, 12, 3, 0);
            }
            cbvh_tree_free(&t);
        }
    }
    { /* a bottom-up (streaming) CBVH */
        cbvh_compress_opts o = {{6, min_scale}, CBVH_ENC_MODULO, 2, 0};
        cbvh_tree t;
        cbvh_bu_stats bs;
        cbvh_bvh bb;
        rc = lbvh ? cbvh_build_lbvh(s, &bb, err, sizeof err) : cbvh_build_sah(s, 0, 0, &bb, err, sizeof err);
        if (rc == 0 && cbvh_compress_bottomup(&bb, NULL, &o, &t, &bs, err, sizeof err) == 0) {
            char what[96];
            snprintf(what, sizeof what, "%s N 6 bottom-up", name);
            run_tree(what, &t, s, rays, ref, ref_any, nrays, 8, 8, 0);
            cbvh_tree_free(&t);
        } else
            CHECK(0, "bottom-up %s: %s", name, err);
        if (rc == 0) cbvh_bvh_free(&bb);
    }
    free(rays), free(ref), free(ref_any);
    cbvh_bvh_free(&b);
}

/* Random soups at binary32's extremes (tests/traversal/test_traverse_extremes.c's kinds). */
static void soup(cbvh_scene *s, int k, uint64_t *rs) {
    uint32_t n = 1 + (uint32_t)(tu_xorshift64(rs) % 100);
    memset(s, 0, sizeof *s);
    s->tris = calloc(n, sizeof *s->tris);
    s->ntris = n;
    for (uint32_t i = 0; i < n; i++) {
        float c[3];
        for (int a = 0; a < 3; a++) c[a] = tu_unit_f(rs) - 0.5f;
        for (int v = 0; v < 3; v++)
            for (int a = 0; a < 3; a++) {
                float x = c[a] + 0.1f * (tu_unit_f(rs) - 0.5f);
                if (k == 0) x = 2.0f * x * 3.0e38f;
                else if (k == 1) x *= 1e-38f;
                else if (k == 2) x *= (i & 1) ? 1e30f : 1e-30f;
                else x = a == 2 ? 1e5f : 1e5f + 10.0f * x;
                s->tris[i].v[v][a] = x;
            }
    }
}

int main(int argc, char **argv) {
    const char *dir = argc > 1 ? argv[1] : CBVH_SCENES_DIR;
    char path[1024], err[256];
    snprintf(path, sizeof path, "%s/bunny-small.obj", dir);
    cbvh_scene s;
    if (cbvh_scene_open(path, &s, err, sizeof err)) {
        printf("FAIL %s: %s\n", path, err);
        return 1;
    }
    run_scene(&s, "bunny-small SAH", 0, CBVH_MIN_SCALE_DEFAULT, 1);
    run_scene(&s, "bunny-small LBVH", 1, CBVH_MIN_SCALE_DEFAULT, 0);
    cbvh_scene_free(&s);
    static const char *const procs[2] = {"proc:cloth:24", "proc:far:8"};
    for (int i = 0; i < 2; i++) {
        if (cbvh_scene_open(procs[i], &s, err, sizeof err)) {
            CHECK(0, "%s: %s", procs[i], err);
            continue;
        }
        run_scene(&s, procs[i], 0, CBVH_MIN_SCALE_DEFAULT, 0);
        cbvh_scene_free(&s);
    }
    uint64_t rs = 0xC0FFEEu;
    static const char *const kinds[4] = {"soup +-FLT_MAX", "soup subnormal", "soup mixed 1e+-30", "soup flat far"};
    for (int i = 0; i < 12; i++) {
        soup(&s, i % 4, &rs);
        run_scene(&s, kinds[i % 4], (int)(i / 4) % 2, i % 3 ? CBVH_MIN_SCALE_DEFAULT : -126, 0);
        cbvh_scene_free(&s);
    }
    if (fails) printf("%ld failures\n", fails);
    else printf("ok\n");
    return fails != 0;
}
