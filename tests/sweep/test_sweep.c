/* cbvh sweep core (host/trace/sweep.c, docs/sweep.md): the rows, the relative
 * costs at the extremes, the ray-by-ray identity check (and that a corrupted
 * setting fails it), the heat-map data and the knee rule; the QBVH row
 * (--formats cbvh,qbvh); the box units as a dimension of the rows. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "trace/model_eval.h"
#include "trace/sweep.h"

static cbvh_scene_desc scene;
static cbvh_sweep_result res; /* bits 3..10 x M {24, 8} x E {-30} */
static cbvh_timing_params tp;
static cbvh_cost_table table;

static int setup(void **state) {
    (void)state;
    char err[512];
    if (cbvh_scene_file_load(SWEEP_FIXTURES "/tiny.scene", &scene, err, sizeof err)) {
        fprintf(stderr, "%s\n", err);
        return -1;
    }
    cbvh_sweep_opts o = {.bits_lo = 3, .bits_hi = 10, .mant = {24, 8}, .nmant = 2, .min_scale = {-30},
                         .nmin_scale = 1, .corrupt_setting = -1, .cache_kb = {16, 0}, .ncaches = 2, .cache_ways = 8,
                         .reps = 2};
    if (cbvh_cost_table_load(COST_DIR, &table, err, sizeof err)) {
        fprintf(stderr, "%s\n", err);
        return -1;
    }
    if (cbvh_sweep_run(&scene, &o, &res, err, sizeof err)) {
        fprintf(stderr, "%s\n", err);
        return -1;
    }
    cbvh_fx_timing(&scene, &tp);
    return 0;
}

static int teardown(void **state) {
    (void)state;
    cbvh_sweep_free(&res);
    cbvh_scene_desc_free(&scene);
    cbvh_cost_table_free(&table);
    return 0;
}

/* A run's machine at its first cache (16 KB) with the committed cost table. */
static cbvh_machine machine(const cbvh_sweep_run_t *r) {
    cbvh_config_model cm;
    char err[256];
    if (cbvh_config_model_init(&cm, &r->r, &table, &tp, "ray_box", r->s.bits ? r->s.bits : 6, r->s.mant, err,
                               sizeof err))
        fail_msg("%s", err);
    assert_int_equal(cm.ncaches, 2);
    return cm.mc[0];
}

static double rel_total(const cbvh_sweep_run_t *r, int metric) {
    cbvh_fx_stats a = cbvh_fx_total(&r->r), f = cbvh_fx_total(&res.ref.r);
    double p[SWEEP_NMETRICS], q[SWEEP_NMETRICS];
    cbvh_machine ma = machine(r), mf = machine(&res.ref);
    cbvh_sweep_per_ray(&a, &ma, p);
    cbvh_sweep_per_ray(&f, &mf, q);
    return p[metric] / q[metric];
}

static const cbvh_sweep_run_t *row(int bits, int mant) {
    for (int i = 0; i < res.nrows; i++)
        if (res.rows[i].s.bits == bits && res.rows[i].s.mant == mant) return &res.rows[i];
    return NULL;
}

static void test_rows(void **state) {
    (void)state;
    assert_int_equal(res.nrows, 16); /* 8 N x 2 M x 1 E */
    /* Order: for each M, each E, N ascending. */
    for (int i = 0; i < 16; i++) {
        assert_int_equal(res.rows[i].s.bits, 3 + i % 8);
        assert_int_equal(res.rows[i].s.mant, i < 8 ? 24 : 8);
        assert_int_equal(res.rows[i].s.min_scale, -30);
    }
    /* Every setting traced exactly the reference's rays, per effect. */
    assert_true(res.ref_rays > 300);
    for (int i = 0; i < res.nrows; i++)
        for (int e = 0; e < CBVH_FX_COUNT; e++) assert_int_equal(res.rows[i].r.fx[e].rays, res.ref.r.fx[e].rays);
    assert_int_equal(cbvh_fx_total(&res.ref.r).rays, res.ref_rays);
    assert_int_equal(res.ref.r.fx[CBVH_FX_MIRROR].rays, 0); /* not in the scene */
    assert_true(res.ref.r.fx[CBVH_FX_AMBIENT_OCCLUSION].rays > 0);
}

static void test_relative_costs(void **state) {
    (void)state;
    /* N = 10 with a full-width box unit: within a few percent of the float BVH. */
    double b10 = rel_total(row(10, 24), SWEEP_BOX), t10 = rel_total(row(10, 24), SWEEP_TRI);
    assert_true(b10 >= 1.0 && b10 < 1.05);
    assert_true(t10 >= 1.0 && t10 < 1.05);
    /* N = 3: clearly more work; and never less than the float BVH (boxes only grow). */
    double b3 = rel_total(row(3, 24), SWEEP_BOX), t3 = rel_total(row(3, 24), SWEEP_TRI);
    assert_true(b3 > b10 + 0.2);
    assert_true(t3 > t10 + 0.2);
    assert_true(rel_total(row(3, 24), SWEEP_MODEL_NS) > rel_total(row(10, 24), SWEEP_MODEL_NS));
    /* The caches saw every setting's reads; the timed repetitions every configuration. */
    for (int i = -1; i < res.nrows; i++) {
        const cbvh_sweep_run_t *r = i < 0 ? &res.ref : &res.rows[i];
        cbvh_fx_stats t = cbvh_fx_total(&r->r);
        assert_true(t.mem[0].lines > 0 && t.mem[0].miss_lines < t.mem[0].lines);
        assert_int_equal(t.mem[1].miss_lines, t.mem[1].lines); /* no cache */
        assert_int_equal(t.nreps, 2);
        assert_true(t.cpu_rep[0] > 0 && t.cpu_rep[1] > 0);
        assert_int_equal(r->r.ncaches, 2);
    }
    /* A narrower box unit only loosens the test: at least as much work. */
    for (int b = 3; b <= 10; b++) assert_true(rel_total(row(b, 8), SWEEP_BOX) >= rel_total(row(b, 24), SWEEP_BOX));
    /* Node memory: 16-byte pairs up to N = 6, 24-byte from N = 7, both below the float BVH. */
    assert_true(row(6, 24)->r.node_bytes < row(7, 24)->r.node_bytes);
    assert_true(row(10, 24)->r.node_bytes < res.ref.r.node_bytes);
    assert_int_equal(row(3, 24)->r.node_bytes, row(6, 24)->r.node_bytes);
}

static void test_identity_passes(void **state) {
    (void)state;
    assert_true(res.all_same);
    size_t npx = (size_t)res.width * (size_t)res.height;
    int lit = 0;
    for (size_t p = 0; p < npx; p++) lit += res.ref.image[p] > 0;
    assert_true(lit > 20 && lit < (int)npx); /* the image shows the bunny, not a blank frame */
    for (int i = 0; i < res.nrows; i++) {
        assert_true(res.rows[i].same);
        assert_memory_equal(res.rows[i].image, res.ref.image, npx);
        assert_int_equal(res.rows[i].r.hit_digest, res.ref.r.hit_digest);
    }
}

static void test_heatmap_data(void **state) {
    (void)state;
    /* Per-pixel box tests add up to the primary effect's box tests (1 spp, static). */
    for (int i = -1; i < res.nrows; i++) {
        const cbvh_sweep_run_t *r = i < 0 ? &res.ref : &res.rows[i];
        double sum = 0;
        for (size_t p = 0; p < (size_t)res.width * (size_t)res.height; p++) sum += r->box_px[p];
        assert_true(sum == (double)r->r.fx[CBVH_FX_PRIMARY].st.box_tests);
    }
}

/* A setting that returns one wrong answer must fail the check, naming the ray. */
static void corrupt_run(uint64_t ray, cbvh_sweep_result *out) {
    cbvh_sweep_opts o = {.bits_lo = 5, .bits_hi = 6, .mant = {24}, .nmant = 1, .min_scale = {-30},
                         .nmin_scale = 1, .corrupt_setting = 1, .corrupt_ray = ray};
    char err[256];
    assert_int_equal(cbvh_sweep_run(&scene, &o, out, err, sizeof err), 0);
    assert_int_equal(out->nrows, 2);
    assert_true(out->rows[0].same);
    assert_false(out->rows[1].same);
    assert_false(out->all_same);
    assert_int_equal(out->rows[1].bad_ray, ray);
}

/* Trace-order index of the first primary hit: pixels before the first lit one
 * are primary misses with no secondary rays, one ray each (1 spp). */
static uint64_t first_hit_ray(void) {
    int first = -1;
    for (int p = 0; p < res.width * res.height && first < 0; p++)
        if (res.ref.image[p]) first = p;
    assert_true(first > 0);
    return (uint64_t)first;
}

static void test_corrupted_miss_fails(void **state) {
    (void)state;
    cbvh_sweep_result r;
    corrupt_run(0, &r); /* pixel (0,0) sees the sky: a miss turned into a hit */
    assert_non_null(strstr(r.rows[1].why, "ray 0 (primary, pixel 0,0"));
    assert_non_null(strstr(r.rows[1].why, "false hit"));
    cbvh_sweep_free(&r);
}

static void test_corrupted_t_fails(void **state) {
    (void)state;
    uint64_t first = first_hit_ray();
    cbvh_sweep_result r;
    corrupt_run(first, &r); /* t one ulp off on a primary hit */
    assert_non_null(strstr(r.rows[1].why, "t=0x"));
    assert_int_equal(r.rows[1].bad_px, (int)(first % (uint64_t)res.width));
    assert_int_equal(r.rows[1].bad_py, (int)(first / (uint64_t)res.width));
    cbvh_sweep_free(&r);
}

static void test_corrupted_anyhit_fails(void **state) {
    (void)state;
    /* The ray after the first primary hit is that point's first any-hit ray
     * (a shadow ray, or AO when the light is behind the surface). */
    uint64_t ray = first_hit_ray() + 1;
    cbvh_sweep_result r;
    corrupt_run(ray, &r);
    assert_true(r.rows[1].bad_fx == CBVH_FX_HARD_SHADOWS || r.rows[1].bad_fx == CBVH_FX_AMBIENT_OCCLUSION);
    assert_true(strstr(r.rows[1].why, "false miss") || strstr(r.rows[1].why, "false hit"));
    cbvh_sweep_free(&r);
}

/* The QBVH row: traced on the same rays, same hits and image as the float
 * BVH, its own heat-map data and stack-unit activity; absent by default. */
static void qbvh_run(int corrupt, uint64_t ray, cbvh_sweep_result *out) {
    cbvh_sweep_opts o = {.bits_lo = 6, .bits_hi = 6, .mant = {24}, .nmant = 1, .min_scale = {-30},
                         .nmin_scale = 1, .nextra = 1, .corrupt_setting = corrupt, .corrupt_ray = ray};
    o.extra[0] = (cbvh_sweep_format){.ops = cbvh_format_find("qbvh"), .name = "qbvh"};
    char err[256];
    assert_int_equal(cbvh_sweep_run(&scene, &o, out, err, sizeof err), 0);
    assert_int_equal(out->nrows, 1);
    assert_int_equal(out->nextra, 1);
    assert_true(out->rows[0].same);
}

static void test_qbvh_row(void **state) {
    (void)state;
    assert_int_equal(res.nextra, 0);
    cbvh_sweep_result r;
    qbvh_run(-1, 0, &r);
    const cbvh_sweep_run_t *q = &r.extra[0];
    size_t npx = (size_t)r.width * (size_t)r.height;
    assert_true(q->same);
    assert_true(r.all_same);
    assert_int_equal(q->s.bits, 0);
    assert_int_equal(q->s.mant, 24);
    assert_int_equal(q->r.hit_digest, r.ref.r.hit_digest);
    assert_memory_equal(q->image, r.ref.image, npx);
    cbvh_fx_stats t = cbvh_fx_total(&q->r), f = cbvh_fx_total(&r.ref.r);
    assert_int_equal(t.rays, f.rays);
    assert_int_equal(t.hits, f.hits);
    assert_true(q->r.units.qbvh_stack > 0);
    assert_int_equal(r.rows[0].r.units.qbvh_stack, 0);
    assert_int_equal(r.ref.r.units.qbvh_stack, 0);
    assert_true(q->r.node_bytes < r.ref.r.node_bytes);
    double sum = 0;
    for (size_t p = 0; p < npx; p++) sum += q->box_px[p];
    assert_true(sum == (double)q->r.fx[CBVH_FX_PRIMARY].st.box_tests);
    cbvh_sweep_free(&r);
}

static void test_qbvh_corrupted_fails(void **state) {
    (void)state;
    uint64_t first = first_hit_ray();
    cbvh_sweep_result r;
    qbvh_run(1, first, &r); /* setting index 1 = the row after the CBVH settings: the QBVH */
    assert_false(r.extra[0].same);
    assert_false(r.all_same);
    assert_int_equal(r.extra[0].bad_ray, first);
    assert_non_null(strstr(r.extra[0].why, "t=0x"));
    cbvh_sweep_free(&r);
}

static void test_knee_rule(void **state) {
    (void)state;
    int bits[] = {3, 4, 5, 6};
    double a[] = {1.6, 1.2, 1.05, 1.0};
    assert_int_equal(cbvh_sweep_knee(bits, a, 4, 0.10), 5);
    assert_int_equal(cbvh_sweep_knee(bits, a, 4, 0.25), 4);
    assert_int_equal(cbvh_sweep_knee(bits, a, 4, 0.0), 6);
    double b[] = {1.0, 1.0, 1.3, 1.0}; /* a bump after a low value: the knee is after the bump */
    assert_int_equal(cbvh_sweep_knee(bits, b, 4, 0.10), 6);
    double c[] = {0.8, 0.9, 1.0, 1.0}; /* cheaper than the finest: within from the start */
    assert_int_equal(cbvh_sweep_knee(bits, c, 4, 0.10), 3);
    assert_int_equal(cbvh_sweep_knee(bits, c, 1, 0.10), 3);
    /* The float BVH did none of a cost: ratios 0/0 or x/0 give no knee (0),
     * not one computed from stand-in values. */
    double u[] = {NAN, NAN, NAN, NAN}, v[] = {INFINITY, 1.0, 1.0, 1.0};
    assert_int_equal(cbvh_sweep_knee(bits, u, 4, 0.10), 0);
    assert_int_equal(cbvh_sweep_knee(bits, v, 4, 0.10), 0);
}

/* A sweep over N 5..6, M {24, 8}, E -30 with the given box units. */
static void units_run(const int *units, int n, cbvh_sweep_result *r) {
    char err[512];
    cbvh_sweep_opts o = {.bits_lo = 5, .bits_hi = 6, .mant = {24, 8}, .nmant = 2, .min_scale = {-30},
                         .nmin_scale = 1, .corrupt_setting = -1, .cache_kb = {16}, .ncaches = 1, .cache_ways = 8,
                         .nbox_unit = n, .texp = 8};
    for (int i = 0; i < n; i++) o.box_unit[i] = units[i];
    if (cbvh_sweep_run(&scene, &o, r, err, sizeof err)) fail_msg("%s", err);
}

static void assert_same_row(const cbvh_sweep_run_t *a, const cbvh_sweep_run_t *b) {
    assert_int_equal(a->s.bits, b->s.bits);
    assert_int_equal(a->s.mant, b->s.mant);
    assert_int_equal(a->s.box_unit, b->s.box_unit);
    assert_int_equal(a->r.hit_digest, b->r.hit_digest);
    assert_int_equal(a->r.node_bytes, b->r.node_bytes);
    cbvh_fx_stats x = cbvh_fx_total(&a->r), y = cbvh_fx_total(&b->r);
    assert_int_equal(x.st.box_tests, y.st.box_tests);
    assert_int_equal(x.st.tri_tests, y.st.tri_tests);
    assert_int_equal(x.st.fp_box_hits, y.st.fp_box_hits);
    assert_int_equal(x.st.fp_tri_tests, y.st.fp_tri_tests);
}

/* --box-unit incremental,exact: the units are an outer dimension of the rows,
 * in the order given, each block the same rows as a sweep with that unit
 * alone; the exact rows count no false positives, every row keeps the float
 * BVH's hits. */
static void test_box_units(void **state) {
    (void)state;
    static const int both[2] = {CBVH_FORMAT_BOX_INCREMENTAL, CBVH_FORMAT_BOX_EXACT};
    cbvh_sweep_result r2, ri, re;
    units_run(both, 2, &r2);
    units_run(&both[0], 1, &ri);
    units_run(&both[1], 1, &re);
    assert_int_equal(ri.nrows, 4);
    assert_int_equal(r2.nrows, 8);
    assert_true(r2.all_same);
    for (int i = 0; i < 4; i++) {
        assert_same_row(&r2.rows[i], &ri.rows[i]);
        assert_same_row(&r2.rows[4 + i], &re.rows[i]);
        assert_int_equal(cbvh_fx_total(&re.rows[i].r).st.fp_box_hits, 0);
    }
    /* the incremental unit's false positives at M = 8 are real extra box tests */
    cbvh_fx_stats i8 = cbvh_fx_total(&r2.rows[3].r), e8 = cbvh_fx_total(&r2.rows[7].r);
    assert_int_equal(r2.rows[3].s.mant, 8);
    assert_true(i8.st.fp_box_hits > 0);
    assert_true(i8.st.box_tests > e8.st.box_tests);
    cbvh_sweep_free(&r2);
    cbvh_sweep_free(&ri);
    cbvh_sweep_free(&re);
    /* a unit twice is refused */
    static const int twice[2] = {CBVH_FORMAT_BOX_EXACT, CBVH_FORMAT_BOX_EXACT};
    char err[256];
    cbvh_sweep_opts o = {.bits_lo = 6, .bits_hi = 6, .mant = {24}, .nmant = 1, .min_scale = {-30}, .nmin_scale = 1,
                         .corrupt_setting = -1, .nbox_unit = 2};
    memcpy(o.box_unit, twice, sizeof twice);
    cbvh_sweep_result r;
    assert_int_equal(cbvh_sweep_run(&scene, &o, &r, err, sizeof err), -1);
    assert_non_null(strstr(err, "twice"));
}

static void test_bad_options(void **state) {
    (void)state;
    cbvh_sweep_result r;
    char err[256];
    cbvh_sweep_opts o = {.bits_lo = 2, .bits_hi = 10, .mant = {24}, .nmant = 1, .min_scale = {-30}, .nmin_scale = 1,
                         .corrupt_setting = -1};
    assert_int_equal(cbvh_sweep_run(&scene, &o, &r, err, sizeof err), -1);
    assert_non_null(strstr(err, "--bits"));
    o.bits_lo = 3;
    o.mant[0] = 25;
    assert_int_equal(cbvh_sweep_run(&scene, &o, &r, err, sizeof err), -1);
    assert_non_null(strstr(err, "--mant 25"));
    o.mant[0] = 24;
    o.min_scale[0] = -127;
    assert_int_equal(cbvh_sweep_run(&scene, &o, &r, err, sizeof err), -1);
    assert_non_null(strstr(err, "--min-scale -127"));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rows),
        cmocka_unit_test(test_relative_costs),
        cmocka_unit_test(test_identity_passes),
        cmocka_unit_test(test_heatmap_data),
        cmocka_unit_test(test_corrupted_miss_fails),
        cmocka_unit_test(test_corrupted_anyhit_fails),
        cmocka_unit_test(test_corrupted_t_fails),
        cmocka_unit_test(test_qbvh_row),
        cmocka_unit_test(test_qbvh_corrupted_fails),
        cmocka_unit_test(test_knee_rule),
        cmocka_unit_test(test_box_units),
        cmocka_unit_test(test_bad_options),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
