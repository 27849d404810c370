/* The fused streaming build (cbvh_build_lbvh_streaming) against the two-step
 * build it replaces (cbvh_build_lbvh, then cbvh_compress_bottomup): float
 * nodes, primitive order, CBVH bytes, root context and bottom-up statistics
 * identical byte for byte, and the same error message on bad input. */
#include <float.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "cbvh/bvh.h"
#include "cbvh/cbvh_tree.h"
#include "test_util.h"
#include "scene/scene_load.h"
#include "build/cbvh_layout.h"

#ifndef CBVH_SCENES_DIR
#error "CBVH_SCENES_DIR must name the scenes folder"
#endif

static uint32_t rng_state = 987654321u;
static uint32_t rnd(void) { return tu_xorshift32(&rng_state); }
static float rndf(void) { return (float)(rnd() & 0xFFFFFF) / 16777216.0f; }

static cbvh_compress_opts opts(int n, int min_scale, cbvh_encoding enc, int treelet, int naive) {
    cbvh_compress_opts o = {{n, min_scale}, enc, treelet, naive};
    return o;
}

/* Both builds of s with o.  0 if identical (result or error), else 1 with
 * the first difference in why.  *ok: both succeeded. */
static int compare(const cbvh_scene *s, const cbvh_compress_opts *o, char *why, size_t whylen, int *ok) {
    char e1[512] = "", e2[512] = "";
    cbvh_bvh b1, b2;
    cbvh_tree t1, t2;
    cbvh_bu_stats s1, s2;
    memset(&t1, 0, sizeof t1);
    memset(&s1, 0, sizeof s1);
    int r1 = cbvh_build_lbvh(s, &b1, e1, sizeof e1);
    if (r1 == 0) {
        r1 = cbvh_compress_bottomup(&b1, NULL, o, &t1, &s1, e1, sizeof e1);
        if (r1) cbvh_bvh_free(&b1);
    }
    int r2 = cbvh_build_lbvh_streaming(s, o, &b2, &t2, &s2, e2, sizeof e2);
    *ok = r1 == 0 && r2 == 0;
    int d = 1;
    if (r1 != r2)
        snprintf(why, whylen, "two-step rc %d (%s), fused rc %d (%s)", r1, e1, r2, e2);
    else if (r1)
        d = strcmp(e1, e2) != 0, snprintf(why, whylen, "errors differ: '%s' vs '%s'", e1, e2);
    else if (b1.nnodes != b2.nnodes || b1.root != b2.root || b1.nprims != b2.nprims)
        snprintf(why, whylen, "float BVH shape: %u/%u nodes", b1.nnodes, b2.nnodes);
    else if (memcmp(b1.nodes, b2.nodes, (size_t)b1.nnodes * sizeof *b1.nodes))
        snprintf(why, whylen, "float nodes differ");
    else if (memcmp(b1.prims, b2.prims, (size_t)b1.nprims * sizeof *b1.prims))
        snprintf(why, whylen, "primitive order differs");
    else if (t1.npairs != t2.npairs || t1.nids != t2.nids || t1.pair_bytes != t2.pair_bytes ||
             t1.root_pair != t2.root_pair || t1.enc != t2.enc || memcmp(&t1.params, &t2.params, sizeof t1.params))
        snprintf(why, whylen, "CBVH header: %u/%u pairs, %u/%u ids", t1.npairs, t2.npairs, t1.nids, t2.nids);
    else if (memcmp(t1.root_lo, t2.root_lo, sizeof t1.root_lo) || memcmp(t1.root_hi, t2.root_hi, sizeof t1.root_hi) ||
             memcmp(&t1.root_ctx, &t2.root_ctx, sizeof t1.root_ctx))
        snprintf(why, whylen, "root box or context differs");
    else if (memcmp(t1.pairs, t2.pairs, (size_t)t1.npairs * t1.pair_bytes))
        snprintf(why, whylen, "node pairs differ at byte %ld", cbvh_tree_diff(&t1, &t2));
    else if (memcmp(t1.ids, t2.ids, (size_t)t1.nids * sizeof *t1.ids))
        snprintf(why, whylen, "IDs differ");
    else if (memcmp(&s1, &s2, sizeof s1))
        snprintf(why, whylen, "statistics differ: %llu/%llu reencodes, %llu/%llu backtracks",
                 (unsigned long long)s1.reencodes, (unsigned long long)s2.reencodes,
                 (unsigned long long)s1.backtracks, (unsigned long long)s2.backtracks);
    else
        d = 0;
    if (*ok) {
        /* the fused CBVH is also a valid CBVH of its own float BVH (naive
         * re-encoding too: its repairs keep every pair decodable) */
        char e3[512];
        if (!d && cbvh_tree_check(&t2, &b2, e3, sizeof e3))
            d = 1, snprintf(why, whylen, "check: %s", e3);
        cbvh_bvh_free(&b1);
        cbvh_tree_free(&t1);
        cbvh_bvh_free(&b2);
        cbvh_tree_free(&t2);
    }
    return d;
}

static unsigned long n_compared, n_ok;

static void expect_same(const cbvh_scene *s, const cbvh_compress_opts *o, const char *what) {
    char why[1024];
    int ok;
    n_compared++;
    if (compare(s, o, why, sizeof why, &ok))
        fail_msg("%s (N=%d min_scale=%d enc=%d treelet=%d naive=%d): %s", what, o->params.quant_bits,
                 o->params.min_scale, (int)o->enc, o->treelet_depth, o->naive_reencode, why);
    n_ok += (unsigned long)ok;
}

/* Every option on one scene: N, encodings, treelet depths, min scales. */
static void sweep(const cbvh_scene *s, const int *ns, int nn, const int *depths, int nd, const char *what) {
    const int ms[] = {CBVH_MIN_SCALE_DEFAULT, -126, 0};
    for (int i = 0; i < nn; i++)
        for (int e = 0; e < 2; e++)
            for (int d = 0; d < nd; d++)
                for (int m = 0; m < 3; m++) {
                    cbvh_compress_opts o = opts(ns[i], ms[m], (cbvh_encoding)e, depths[d], 0);
                    expect_same(s, &o, what);
                }
}

static void test_bunny(void **st) {
    (void)st;
    cbvh_scene s;
    char err[512];
    if (cbvh_scene_import(CBVH_SCENES_DIR "/bunny-small.obj", &s, err, sizeof err)) fail_msg("%s", err);
    const int ns[] = {3, 4, 5, 6, 7, 8, 9, 10}, depths[] = {1, 2, 3, 4};
    unsigned long before = n_ok;
    sweep(&s, ns, 8, depths, 4, "bunny-small");
    assert_int_equal(n_ok - before, 8 * 2 * 4 * 3); /* every build succeeded */
    /* naive re-encoding goes through the same step */
    for (int e = 0; e < 2; e++) {
        cbvh_compress_opts o = opts(6, CBVH_MIN_SCALE_DEFAULT, (cbvh_encoding)e, 2, 1);
        expect_same(&s, &o, "bunny-small naive");
    }
    cbvh_scene_free(&s);
}

static void test_procedural(void **st) {
    (void)st;
    const char *specs[] = {"proc:cloth:48", "proc:far:16", "proc:wave:24", "proc:instanced:2"};
    const int ns[] = {3, 6, 10}, depths[] = {1, 4};
    for (size_t i = 0; i < sizeof specs / sizeof specs[0]; i++) {
        cbvh_scene s;
        char err[512];
        if (cbvh_scene_open(specs[i], &s, err, sizeof err)) fail_msg("%s", err);
        sweep(&s, ns, 3, depths, 2, specs[i]);
        cbvh_scene_free(&s);
    }
}

/* A random soup of kind k: 0 plain, 1 many equal Morton codes (duplicates
 * and clusters), 2 tiny (down to subnormals), 3 huge (to +-FLT_MAX), 4 mixed
 * magnitudes, 5 flat and far, 6 all triangles identical (a leaf root). */
static void soup(cbvh_scene *s, int k) {
    uint32_t n = 1 + rnd() % (k == 6 ? 8 : 160);
    memset(s, 0, sizeof *s);
    snprintf(s->name, sizeof s->name, "soup%d", k);
    s->tris = malloc(n * sizeof *s->tris);
    assert_non_null(s->tris);
    s->ntris = n;
    for (uint32_t i = 0; i < n; i++) {
        float c[3], size = 0.05f;
        for (int a = 0; a < 3; a++) c[a] = rndf() - 0.5f;
        if (k == 1) { /* few distinct centres: equal codes */
            for (int a = 0; a < 3; a++) c[a] = (float)(rnd() % 3);
            if (i && rnd() % 2) {
                s->tris[i] = s->tris[rnd() % i];
                continue;
            }
            size = 0.0f;
        }
        for (int v = 0; v < 3; v++)
            for (int a = 0; a < 3; a++) {
                float x = c[a] + size * (rndf() - 0.5f);
                if (k == 2) x *= 1e-38f * (float)(1u << (rnd() % 8)); /* subnormal to tiny normal */
                if (k == 3) x = (2.0f * x) * 3.2e38f;                  /* up to +-3.4e38 */
                if (k == 4) x *= (i & 1) ? 1e30f : 1e-30f;
                if (k == 5) x = a == 2 ? 1e5f : 1e5f + 1e-2f * x;
                s->tris[i].v[v][a] = x;
            }
        if (k == 3 && i == 0) s->tris[0].v[0][0] = -FLT_MAX, s->tris[0].v[1][1] = FLT_MAX;
        if (k == 6 && i) s->tris[i] = s->tris[0];
    }
}

static void test_random_soups(void **st) {
    (void)st;
    const int ns[] = {3, 6, 10}, depths[] = {1, 4};
    unsigned long before = n_compared, ok_before = n_ok;
    for (int i = 0; i < 1050; i++) {
        cbvh_scene s;
        soup(&s, i % 7);
        char what[64];
        snprintf(what, sizeof what, "soup %d (kind %d, %u triangles)", i, i % 7, s.ntris);
        for (int a = 0; a < 3; a++)
            for (int e = 0; e < 2; e++)
                for (int d = 0; d < 2; d++) {
                    int ms = (int)(rnd() % 4);
                    cbvh_compress_opts o = opts(ns[a], ms == 0 ? -126 : ms == 1 ? -30 : ms == 2 ? -10 : 0,
                                                (cbvh_encoding)e, depths[d], rnd() % 16 == 0);
                    expect_same(&s, &o, what);
                }
        cbvh_scene_free(&s);
    }
    assert_true(n_compared - before == 1050ul * 12);
    assert_true(n_ok - ok_before > 1050ul * 12 * 9 / 10); /* mostly builds, not just errors */
}

/* A tree whose pairs or IDs do not fit the node's pointer field (or the ID
 * array's 31 bits) is refused before anything is allocated: checked on the
 * counts alone, as a scene this large cannot be built in a test. */
static void test_pointer_limits(void **st) {
    (void)st;
    static const struct {
        int n;
        uint32_t npairs, nids;
    } c[] = {{6, 1u << 27, 1}, {6, 1, (1u << 27) - 1u}, {3, 1, 0x80000000u}, {10, 1, 0x80000000u}};
    for (size_t i = 0; i < sizeof c / sizeof c[0]; i++) {
        cbvh_compress_opts o = opts(c[i].n, CBVH_MIN_SCALE_DEFAULT, CBVH_ENC_MODULO, 1, 0);
        cbvh_layout l = {NULL, NULL, c[i].npairs, c[i].nids};
        cbvh_bvh b;
        memset(&b, 0, sizeof b);
        cbvh_tree t;
        char why[256] = "";
        assert_int_equal(cbvh_tree_init(&t, &b, &o, &l, 0, why, sizeof why), -1);
        assert_non_null(strstr(why, "do not fit"));
        assert_null(t.pairs);
    }
}

static void test_errors(void **st) {
    (void)st;
    cbvh_compress_opts o = opts(6, CBVH_MIN_SCALE_DEFAULT, CBVH_ENC_MODULO, 4, 0);
    char why[1024];
    int ok;
    cbvh_scene s;
    /* non-finite vertices at every position */
    const float bad[] = {NAN, INFINITY, -INFINITY};
    for (int t = 0; t < 3; t++)
        for (int pos = 0; pos < 9; pos++) {
            rng_state = 4242u + (uint32_t)pos;
            soup(&s, 0);
            uint32_t tri = rnd() % s.ntris;
            s.tris[tri].v[pos / 3][pos % 3] = bad[t];
            if (compare(&s, &o, why, sizeof why, &ok)) fail_msg("non-finite: %s", why);
            assert_false(ok);
            cbvh_scene_free(&s);
        }
    /* empty scene, no triangle array */
    soup(&s, 0);
    uint32_t n = s.ntris;
    s.ntris = 0;
    if (compare(&s, &o, why, sizeof why, &ok)) fail_msg("empty: %s", why);
    assert_false(ok);
    s.ntris = n;
    /* bad options: treelet depth, N, min scale */
    const cbvh_compress_opts bad_opts[] = {opts(6, -30, CBVH_ENC_MODULO, 0, 0), opts(6, -30, CBVH_ENC_MODULO, 9, 0),
                                           opts(2, -30, CBVH_ENC_MODULO, 1, 0), opts(11, -30, CBVH_ENC_RELATIVE, 1, 0),
                                           opts(6, 1000, CBVH_ENC_MODULO, 1, 0)};
    for (size_t i = 0; i < sizeof bad_opts / sizeof bad_opts[0]; i++) {
        if (compare(&s, &bad_opts[i], why, sizeof why, &ok)) fail_msg("bad option %zu: %s", i, why);
        assert_false(ok);
    }
    /* both bad: the scene's error wins in both */
    s.tris[0].v[0][0] = NAN;
    if (compare(&s, &bad_opts[0], why, sizeof why, &ok)) fail_msg("both bad: %s", why);
    cbvh_scene_free(&s);
    /* a zeroed scene (no triangle array): an error, and nothing returned */
    memset(&s, 0, sizeof s);
    if (compare(&s, &o, why, sizeof why, &ok)) fail_msg("zeroed scene: %s", why);
    assert_false(ok);
    cbvh_bvh b;
    cbvh_tree t;
    cbvh_bu_stats bs;
    char err[512];
    assert_int_equal(cbvh_build_lbvh_streaming(&s, &o, &b, &t, &bs, err, sizeof err), -1);
    assert_null(b.nodes);
    assert_null(t.pairs);
    assert_true(strlen(err) > 0);
}

/* The comparison can fail: different options give different bytes or stats. */
static void test_compare_detects(void **st) {
    (void)st;
    cbvh_scene s;
    char err[512];
    if (cbvh_scene_open("proc:cloth:16", &s, err, sizeof err)) fail_msg("%s", err);
    cbvh_compress_opts a = opts(6, -30, CBVH_ENC_MODULO, 1, 0), b = opts(6, -30, CBVH_ENC_MODULO, 4, 0);
    cbvh_bvh b1, b2;
    cbvh_tree t1, t2;
    cbvh_bu_stats s1, s2;
    assert_int_equal(cbvh_build_lbvh(&s, &b1, err, sizeof err), 0);
    assert_int_equal(cbvh_compress_bottomup(&b1, NULL, &a, &t1, &s1, err, sizeof err), 0);
    assert_int_equal(cbvh_build_lbvh_streaming(&s, &b, &b2, &t2, &s2, err, sizeof err), 0);
    /* same bytes, different treelet statistics */
    assert_int_equal(cbvh_tree_diff(&t1, &t2), -1);
    assert_true(s1.backtracks != s2.backtracks);
    assert_true(s1.reencodes == s2.reencodes);
    assert_true(s2.encodes == t2.npairs);
    /* a flipped bit is seen */
    t2.pairs[t2.npairs / 2 * t2.pair_bytes] ^= 1u;
    assert_true(cbvh_tree_diff(&t1, &t2) != -1);
    cbvh_bvh_free(&b1);
    cbvh_bvh_free(&b2);
    cbvh_tree_free(&t1);
    cbvh_tree_free(&t2);
    cbvh_scene_free(&s);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_compare_detects), cmocka_unit_test(test_bunny),  cmocka_unit_test(test_procedural),
        cmocka_unit_test(test_random_soups),    cmocka_unit_test(test_errors), cmocka_unit_test(test_pointer_limits),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
