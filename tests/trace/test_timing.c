/* The timing model, version 2 (docs/timing_model.md): hand-computed worked
 * examples of every term (cost table, units, memory, latency, occupancy,
 * energy, area, the event-driven simulation, the cache), and the model's
 * properties: an infinite zero-latency cache leaves the compute bound;
 * halving node bytes in a bandwidth-bound machine lowers the time; more rays
 * in flight never raise it; the Pareto front of a hand-made table; the cache
 * model leaves the traversals' hits and counters untouched. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "trace/cache_sim.h"
#include "trace/cost_table.h"
#include "trace/effects.h"
#include "trace/event_sim.h"
#include "trace/memsim.h"
#include "trace/model_eval.h"
#include "trace/sweep.h"
#include "trace/timing_model.h"

/* ---- the cost table ------------------------------------------------------ */

static const char *BOX_JSON =
    "{\"unit\": \"ray_box\", \"design_points\": [{\"N\": null, \"M\": null,"
    " \"area\": {\"lut4\": 2577}, \"timing\": {\"latency\": 260, \"II\": 260}, \"asic\": {\"adder_bits\": 16640}}]}";
/* As gateware/scripts/cost-ray-box-incr writes it: unit_P6 and placed. */
static const char *INCR_JSON =
    "{\"unit\": \"ray_box_incr\", \"design_points\": ["
    "{\"N\": 4, \"M\": 8, \"unit_P6\": {\"lut4\": 1000}, \"placed\": {\"latency\": 10, \"II\": 1}},"
    "{\"N\": 8, \"M\": 8, \"unit_P6\": {\"lut4\": 2000}, \"placed\": {\"latency\": 12, \"II\": 2},"
    " \"asic\": {\"multiplier_pp_bits\": 1024, \"adder_bits\": 320}},"
    "{\"N\": 6, \"M\": 24, \"unit_P6\": {\"lut4\": 5000}, \"placed\": {\"latency\": 20, \"II\": 1}}]}";

static void cost_table(void **state) {
    (void)state;
    cbvh_cost_table t = {0};
    char err[256];
    assert_int_equal(cbvh_cost_table_add_json(&t, BOX_JSON, "box", err, sizeof err), 0);
    assert_int_equal(cbvh_cost_table_add_json(&t, INCR_JSON, "incr", err, sizeof err), 0);
    assert_int_equal(t.nrows, 4);
    cbvh_cost_row r;
    /* A row for every N and M. */
    assert_int_equal(cbvh_cost_lookup(&t, "ray_box", 9, 5, &r), 0);
    assert_true(r.lut4 == 2577 && r.latency == 260 && r.ii == 260 && r.adder_bits == 16640 && r.pp_bits == 0);
    /* M = 8 exactly; N = 6 halfway between N = 4 and 8: linear interpolation. */
    assert_int_equal(cbvh_cost_lookup(&t, "ray_box_incr", 6, 8, &r), 0);
    assert_float_equal(r.lut4, 1500, 1e-9);
    assert_float_equal(r.latency, 11, 1e-9);
    assert_float_equal(r.ii, 1.5, 1e-9);
    assert_float_equal(r.pp_bits, 512, 1e-9);
    /* Past the ends: the nearest row. */
    assert_int_equal(cbvh_cost_lookup(&t, "ray_box_incr", 3, 8, &r), 0);
    assert_float_equal(r.lut4, 1000, 0);
    assert_int_equal(cbvh_cost_lookup(&t, "ray_box_incr", 10, 8, &r), 0);
    assert_float_equal(r.lut4, 2000, 0);
    /* M = 12 is not in the table: the smallest M above it (24). */
    assert_int_equal(cbvh_cost_lookup(&t, "ray_box_incr", 6, 12, &r), 0);
    assert_float_equal(r.lut4, 5000, 0);
    /* M = 30 is above every M: the largest (24). */
    assert_int_equal(cbvh_cost_lookup(&t, "ray_box_incr", 6, 30, &r), 0);
    assert_float_equal(r.lut4, 5000, 0);
    assert_int_equal(cbvh_cost_lookup(&t, "ray_sphere", 6, 24, &r), -1);
    /* Bad files: one line naming the file and the field. */
    static const struct {
        const char *json, *msg;
    } bad[] = {{"{", "cost table f: not JSON"},
               {"{\"unit\": 3, \"design_points\": []}", "cost table f: \"unit\": expected a name"},
               {"{\"unit\": \"u\", \"design_points\": []}", "\"design_points\": expected a non-empty array"},
               {"{\"unit\": \"u\", \"design_points\": [{\"timing\": {\"latency\": 1, \"II\": 1}}]}",
                "design_points[0]: no \"area\" object"},
               {"{\"unit\": \"u\", \"design_points\": [{\"area\": {}, \"timing\": {\"latency\": 1, \"II\": 1}}]}",
                "design_points[0]: area.lut4: required"},
               {"{\"unit\": \"u\", \"design_points\": [{\"area\": {\"lut4\": 1}, \"timing\": {\"latency\": 1, \"II\": 0}}]}",
                "design_points[0]: timing.II: required, a number > 0"},
               {"{\"unit\": \"u\", \"design_points\": [{\"N\": 2.5, \"area\": {\"lut4\": 1}, \"timing\": {\"latency\": 1, "
                "\"II\": 1}}]}",
                "design_points[0]: N: expected an integer"}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        err[0] = 0;
        assert_int_equal(cbvh_cost_table_add_json(&t, bad[i].json, "f", err, sizeof err), -1);
        if (!strstr(err, bad[i].msg)) fail_msg("case %zu: '%s' lacks '%s'", i, err, bad[i].msg);
    }
    cbvh_cost_table_free(&t);
    /* The committed table loads and has every unit the model asks for. */
    assert_int_equal(cbvh_cost_table_load(COST_DIR, &t, err, sizeof err), 0);
    const char *units[] = {"ray_box", "ray_triangle", "ray_sphere", "nodepair_decoder", "qbvh_stack"};
    for (size_t i = 0; i < 5; i++) assert_int_equal(cbvh_cost_lookup(&t, units[i], 6, 24, &r), 0);
    assert_int_equal(cbvh_cost_lookup(&t, "nodepair_decoder", 6, 24, &r), 0);
    assert_float_equal(r.lut4, 8504, 0); /* synthesised for N = 6 (docs/results.md: 8,496) */
    cbvh_cost_table_free(&t);
    assert_int_equal(cbvh_cost_table_load("/nonexistent-dir", &t, err, sizeof err), -1);
    assert_non_null(strstr(err, "cost table /nonexistent-dir:"));
}

/* Units from the table: cycles x scale, ceil(II) instances, ASIC energy. */
static void units_from_table(void **state) {
    (void)state;
    cbvh_cost_table t = {0};
    char err[256];
    assert_int_equal(cbvh_cost_table_add_json(&t, INCR_JSON, "incr", err, sizeof err), 0);
    assert_int_equal(cbvh_cost_table_add_json(&t, BOX_JSON, "box", err, sizeof err), 0);
    assert_int_equal(cbvh_cost_table_add_json(&t,
                                              "{\"unit\": \"ray_triangle\", \"design_points\": [{\"area\": {\"lut4\": "
                                              "100}, \"timing\": {\"latency\": 7, \"II\": 2.5}}]}",
                                              "tri", err, sizeof err),
                     0);
    cbvh_timing_params p;
    cbvh_timing_defaults(&p);
    p.unit_cycle_scale = 2;
    cbvh_timing_units u;
    assert_int_equal(cbvh_timing_units_for(&t, &p, "ray_box_incr", 0, 0, 8, 8, &u, err, sizeof err), 0);
    assert_true(u.node.present && !u.dec.present && !u.qstack.present);
    assert_float_equal(u.node.latency, 24, 0);  /* 12 RTL cycles x 2 */
    assert_float_equal(u.node.ii, 4, 0);        /* 2 x 2 */
    assert_float_equal(u.node.instances, 4, 0); /* ceil(4): one test per cycle */
    assert_float_equal(u.node.lut4, 2000, 0);
    /* 1024 partial-product bits x 3.1 pJ / 1024 + 320 adder bits x 0.1 pJ / 32 */
    assert_float_equal(u.node.energy_pj, 3.1 + 1.0, 1e-12);
    assert_float_equal(u.tri.ii, 5, 0);
    assert_float_equal(u.tri.instances, 5, 0);
    /* Four operations per cycle: four times the instances. */
    p.issue_width = 4;
    assert_int_equal(cbvh_timing_units_for(&t, &p, "ray_box_incr", 0, 0, 8, 8, &u, err, sizeof err), 0);
    assert_float_equal(u.node.instances, 16, 0); /* ceil(4 x 4) */
    assert_float_equal(u.tri.instances, 20, 0);  /* 5 x 4 */
    p.issue_width = 1;
    /* The v1 override: latency = II = cycles, one instance. */
    p.box_cycles = 3;
    assert_int_equal(cbvh_timing_units_for(&t, &p, "ray_box", 0, 0, 6, 24, &u, err, sizeof err), 0);
    assert_true(u.node.latency == 3 && u.node.ii == 3 && u.node.instances == 1);
    /* A unit the table lacks: one line. */
    assert_int_equal(cbvh_timing_units_for(&t, &p, "ray_box", 1, 0, 6, 24, &u, err, sizeof err), -1);
    assert_non_null(strstr(err, "no unit \"nodepair_decoder\""));
    cbvh_cost_table_free(&t);
}

/* ---- the formula --------------------------------------------------------- */

static cbvh_unit_cost unit(double lat, double ii, double lut, double pj) {
    cbvh_unit_cost u = {1, lat, ii, ceil(ii), lut, pj, "u"};
    return u;
}

/* docs/timing_model.md §5, worked example: every term by hand. */
static void worked_example(void **state) {
    (void)state;
    cbvh_timing_params p;
    cbvh_timing_defaults(&p);
    p.rays_in_flight = 4;
    cbvh_timing_units u = {unit(3, 2, 100, 5), unit(10, 5, 200, 50), unit(1, 1, 1000, 2), {0}};
    cbvh_timing_work w = {.rays = 2, .nodes = 6, .starts = 2, .node_ops = 14, .tri_ops = 3, .dec_ops = 6,
                          .steps = 9, .miss_steps = 3, .lines = 12, .words = 30, .miss_lines = 4, .cache_kb = 32};
    cbvh_timing_result r;
    assert_int_equal(cbvh_timing_eval(&p, &u, &w, &r), 0);
    /* memory: 9 steps x 4 (hit) + 3 misses x 100 + 4 lines x 64 / 12.8 */
    assert_float_equal(r.mem_latency, 36 + 300 + 20, 1e-9);
    /* units: (6 reads + 2 starts) x 3 + 6 decodes x 1 + (14 - 8) tests x 2/2 + 3 x 10 */
    assert_float_equal(r.unit_latency, 24 + 6 + 6 + 30, 1e-9);
    assert_float_equal(r.occupancy[CBVH_BOUND_LATENCY], (356.0 + 66.0) / 4, 1e-9);
    assert_float_equal(r.occupancy[CBVH_BOUND_NODE], 14 * 2 / 2.0, 1e-9);
    assert_float_equal(r.occupancy[CBVH_BOUND_TRI], 3 * 5 / 5.0, 1e-9);
    assert_float_equal(r.occupancy[CBVH_BOUND_DEC], 6, 1e-9);
    assert_float_equal(r.occupancy[CBVH_BOUND_DRAM], 20, 1e-9);
    assert_int_equal(r.bound, CBVH_BOUND_LATENCY);
    assert_float_equal(r.cycles, 105.5, 1e-9);
    assert_float_equal(r.seconds, 105.5e-9, 1e-18); /* 1 GHz */
    /* energy: 14 x 5 + 3 x 50 + 6 x 2 pJ; 30 words x 10 pJ x sqrt(32/8); 4 lines x 64 B x 162.5 pJ */
    assert_float_equal(r.energy_units, 70 + 150 + 12, 1e-9);
    assert_float_equal(r.energy_sram, 30 * 10 * 2.0, 1e-9);
    assert_float_equal(r.energy_dram, 4 * 64 * 162.5, 1e-9);
    /* area: 2 box instances, 5 triangle instances, 1 decoder */
    assert_float_equal(r.area_lut4, 2 * 100 + 5 * 200 + 1 * 1000, 1e-9);
    /* Many rays in flight: the busiest resource, DRAM. */
    p.rays_in_flight = 1000;
    assert_int_equal(cbvh_timing_eval(&p, &u, &w, &r), 0);
    assert_int_equal(r.bound, CBVH_BOUND_DRAM);
    assert_float_equal(r.cycles, 20, 1e-9);
    /* No cache: no hit latency, no SRAM energy. */
    w.cache_kb = 0;
    p.rays_in_flight = 4;
    assert_int_equal(cbvh_timing_eval(&p, &u, &w, &r), 0);
    assert_float_equal(r.mem_latency, 300 + 20, 1e-9);
    assert_float_equal(r.energy_sram, 0, 0);
    assert_float_equal(cbvh_timing_word_pj(&p, 8), 10, 1e-12);
    assert_float_equal(cbvh_timing_word_pj(&p, 1024), 10 * sqrt(128.0), 1e-9); /* 113 pJ; Horowitz: 100 at 1 MB */
    assert_float_equal(cbvh_timing_word_pj(&p, INFINITY), 0, 0);
    p.clock_mhz = 0;
    assert_int_equal(cbvh_timing_eval(&p, &u, &w, &r), -1);
}

/* Version 1's worked example (one ray in flight, no cache, v1's one-issue
 * units) comes out of version 2 unchanged: 785 cycles, 1.57 us. */
static void v1_corner(void **state) {
    (void)state;
    cbvh_timing_params p;
    cbvh_timing_defaults(&p);
    p.rays_in_flight = 1;
    p.clock_mhz = 500;
    cbvh_timing_units u = {unit(2, 2, 0, 0), unit(5, 5, 0, 0), {0}, {0}};
    u.node.instances = u.tri.instances = 1;
    /* 10 box tests (the root's among them: one start), 3 triangles, 4 node pairs, 640 bytes */
    cbvh_timing_work w = {.rays = 1, .nodes = 4, .starts = 1, .node_ops = 10, .tri_ops = 3, .steps = 7,
                          .miss_steps = 7, .lines = 10, .miss_lines = 10, .cache_kb = 0};
    cbvh_timing_result r;
    assert_int_equal(cbvh_timing_eval(&p, &u, &w, &r), 0);
    assert_float_equal(r.unit_latency, 35, 1e-9); /* 10 x 2 + 3 x 5 */
    assert_float_equal(r.mem_latency, 750, 1e-9); /* (4 + 3) x 100 + 640 / 12.8 */
    assert_float_equal(r.cycles, 785, 1e-9);
    assert_float_equal(r.seconds, 1.57e-6, 1e-18);
}

/* The build side (docs/timing_model.md §7): streamed bytes at the bandwidth
 * and the backtracking unit's round trips one after another. */
static void build_time(void **state) {
    (void)state;
    cbvh_timing_params p;
    cbvh_timing_defaults(&p);
    /* a float LBVH of 100 triangles, 99 inner nodes: (40 + 64 + 4) x 100 + 64 x 99 bytes */
    assert_float_equal(cbvh_build_cycles(&p, 17136, 0), 17136 / 12.8, 1e-9);
    /* streaming with 3 backtracks: 108 x 100 + 16 x 99 + 128 x 3 bytes and 3 round trips of 100 cycles */
    assert_float_equal(cbvh_build_cycles(&p, 10800 + 1584 + 384, 3), 12768 / 12.8 + 300, 1e-9);
}

static void timing_set(void **state) {
    (void)state;
    cbvh_timing_params p;
    cbvh_timing_defaults(&p);
    char err[200];
    assert_int_equal(cbvh_timing_set(&p, "rays_in_flight=256,box_cycles=1,tri_cycles=1.5", err, sizeof err), 0);
    assert_true(p.rays_in_flight == 256 && p.box_cycles == 1 && p.tri_cycles == 1.5);
    assert_int_equal(cbvh_timing_set(&p, "cache_ways=3.5", err, sizeof err), -1);
    assert_non_null(strstr(err, "timing.cache_ways: 3.5 is not a whole number"));
    assert_int_equal(cbvh_timing_set(&p, "warp=2", err, sizeof err), -1);
    assert_string_equal(err, "--timing: unknown key 'warp' (docs/timing_model.md)");
    assert_int_equal(cbvh_timing_set(&p, "clock_mhz=x", err, sizeof err), -1);
    assert_string_equal(err, "--timing: clock_mhz expects a number, got 'x'");
    assert_int_equal(cbvh_timing_set(&p, "clock_mhz=1,", err, sizeof err), -1);
    assert_int_equal(cbvh_timing_set(&p, "clock_mhz=0", err, sizeof err), -1);
    assert_non_null(strstr(err, "timing.clock_mhz: 0 is out of range"));
}

/* ---- the cache and the memory side ------------------------------------- */

static void cache_lru(void **state) {
    (void)state;
    cbvh_cache c;
    char err[200];
    assert_int_equal(cbvh_cache_init(&c, 128, 2, err, sizeof err), 0); /* one set of two ways */
    assert_int_equal(cbvh_cache_access(&c, 0), 0);
    assert_int_equal(cbvh_cache_access(&c, 1), 0);
    assert_int_equal(cbvh_cache_access(&c, 0), 1); /* 0 now the most recent */
    assert_int_equal(cbvh_cache_access(&c, 2), 0); /* evicts 1, the least recent */
    assert_int_equal(cbvh_cache_access(&c, 0), 1);
    assert_int_equal(cbvh_cache_access(&c, 1), 0);
    assert_int_equal(cbvh_cache_access(&c, 2), 0); /* 1 evicted 2 (0 was more recent) */
    cbvh_cache_free(&c);
    /* Two sets, direct mapped: lines 0 and 2 share set 0, 1 is apart. */
    assert_int_equal(cbvh_cache_init(&c, 128, 1, err, sizeof err), 0);
    assert_int_equal(cbvh_cache_access(&c, 0), 0);
    assert_int_equal(cbvh_cache_access(&c, 1), 0);
    assert_int_equal(cbvh_cache_access(&c, 2), 0);
    assert_int_equal(cbvh_cache_access(&c, 1), 1);
    assert_int_equal(cbvh_cache_access(&c, 0), 0);
    cbvh_cache_free(&c);
    /* None: always a miss.  Infinite: a miss only the first time, through its growth. */
    assert_int_equal(cbvh_cache_init(&c, 0, 8, err, sizeof err), 0);
    assert_int_equal(cbvh_cache_access(&c, 5), 0);
    assert_int_equal(cbvh_cache_access(&c, 5), 0);
    cbvh_cache_free(&c);
    assert_int_equal(cbvh_cache_init(&c, CBVH_CACHE_INFINITE, 8, err, sizeof err), 0);
    for (uint64_t l = 0; l < 5000; l++) assert_int_equal(cbvh_cache_access(&c, l * 977), 0);
    for (uint64_t l = 0; l < 5000; l++) assert_int_equal(cbvh_cache_access(&c, l * 977), 1);
    cbvh_cache_free(&c);
    assert_int_equal(cbvh_cache_init(&c, 100, 1, err, sizeof err), -1);
    assert_non_null(strstr(err, "not a whole number of 1-way sets"));
    assert_int_equal(cbvh_cache_init(&c, 1024, 0, err, sizeof err), -1);
}

/* Steps, lines, words and misses of hand-made reads; an ID read's miss goes
 * with the triangle it names. */
static void memsim_counts(void **state) {
    (void)state;
    double kb[2] = {0, INFINITY};
    cbvh_memsim M;
    char err[200];
    cbvh_step_log log = {.max_rays = 4, .cache = 1};
    assert_int_equal(cbvh_memsim_init(&M, kb, 2, 8, &log, err, sizeof err), 0);
    cbvh_mem_counts mc[CBVH_CACHES_MAX] = {{0}};
    cbvh_trav_stats s = {0};
    cbvh_memsim_ray_begin(&M, mc);
    s.box_tests = 1; /* the root box, before any read */
    M.obs.fetch(M.obs.ctx, CBVH_FETCH_NODE, 0, 16, &s);  /* line 0, words 0..1 */
    s.box_tests = 3;
    M.obs.fetch(M.obs.ctx, CBVH_FETCH_IDS, 1000, 4, &s); /* line 15 */
    M.obs.fetch(M.obs.ctx, CBVH_FETCH_TRI, 2040, 36, &s); /* bytes 2040..2075: lines 31, 32; words 255..259 */
    s.tri_tests = 1;
    cbvh_memsim_ray_end(&M, &s);
    /* a second ray: the same node (a hit in the infinite cache) */
    cbvh_trav_stats s2 = {0};
    cbvh_memsim_ray_begin(&M, mc);
    M.obs.fetch(M.obs.ctx, CBVH_FETCH_NODE, 8, 8, &s2);
    s2.box_tests = 2;
    cbvh_memsim_ray_end(&M, &s2);
    for (int c = 0; c < 2; c++) {
        assert_int_equal(mc[c].steps, 3);  /* node, triangle, node */
        assert_int_equal(mc[c].lines, 5);  /* 1 + 1 + 2 + 1 */
        assert_int_equal(mc[c].words, 9);  /* 2 + 1 + 5 + 1 */
        assert_int_equal(mc[c].starts, 1); /* the first ray tested its root before reading */
    }
    assert_int_equal(mc[0].miss_lines, 5);
    assert_int_equal(mc[0].miss_steps, 3);
    assert_int_equal(mc[1].miss_lines, 4);
    assert_int_equal(mc[1].miss_steps, 2);
    /* the log (cache 1): ray 0 = start, node, triangle; ray 1 = start, node */
    assert_int_equal(log.nrays, 2);
    assert_int_equal(log.first[1], 3);
    assert_int_equal(log.nsteps, 5);
    const cbvh_step *st = log.steps;
    assert_true(st[0].kind == CBVH_STEP_START && st[0].node_ops == 1);
    assert_true(st[1].kind == CBVH_STEP_NODE && st[1].miss && st[1].miss_lines == 1 && st[1].node_ops == 2);
    assert_true(st[2].kind == CBVH_STEP_TRI && st[2].miss && st[2].miss_lines == 3 && st[2].tri_ops == 1);
    assert_true(st[3].kind == CBVH_STEP_START && st[3].node_ops == 0);
    assert_true(st[4].kind == CBVH_STEP_NODE && !st[4].miss && st[4].node_ops == 2);
    cbvh_memsim_free(&M);
    cbvh_step_log_free(&log);
}

/* ---- the event-driven check ---------------------------------------------- */

/* Two rays of two steps by hand, contending for the DRAM channel. */
static void event_example(void **state) {
    (void)state;
    cbvh_step steps[] = {{CBVH_STEP_START, 0, 0, 0, 0, 0}, {CBVH_STEP_NODE, 1, 2, 2, 0, 0},
                         {CBVH_STEP_START, 0, 0, 0, 0, 0}, {CBVH_STEP_NODE, 1, 1, 2, 0, 0}};
    uint64_t first[] = {0, 2, 4};
    cbvh_step_log log = {.max_rays = 2, .steps = steps, .nsteps = 4, .first = first, .nrays = 2};
    cbvh_timing_params p;
    cbvh_timing_defaults(&p);
    p.rays_in_flight = 2;
    cbvh_timing_units u = {unit(3, 1, 0, 0), unit(1, 1, 0, 0), {0}, {0}};
    cbvh_event_result ev;
    assert_int_equal(cbvh_event_sim(&log, &p, &u, 16, &ev), 0);
    /* ray 0: hit check 4, DRAM channel 4..14 (2 lines x 5), data at 114; tests issue at 114, 115: done 118.
     * ray 1: channel free at 14, busy 14..19, data at 119; tests at 119, 120: done 123. */
    assert_float_equal(ev.cycles, 123, 1e-9);
    assert_float_equal(ev.steady, 123, 1e-9); /* both rays start at once: no steady state, the makespan */
    assert_int_equal(ev.rays, 2);
    assert_int_equal(ev.steps, 2);
    /* analytic: latency (2 x 4 + 2 x 100 + 3 x 5 + 2 x 3 + 2 x 1) / 2 = 115.5 */
    assert_float_equal(ev.analytic, 115.5, 1e-9);
    assert_float_equal(ev.rel_error, (115.5 - 123) / 123, 1e-12);
    /* one ray in flight: the analytic sum is exact */
    p.rays_in_flight = 1;
    assert_int_equal(cbvh_event_sim(&log, &p, &u, 16, &ev), 0);
    assert_float_equal(ev.cycles, 118 + 4 + 5 + 100 + 4, 1e-9); /* ray 1 starts at 118 */
    assert_float_equal(ev.cycles, ev.analytic, 1e-9);
    assert_float_equal(ev.steady, 118 * 2, 1e-9); /* one ray done when the last started at 118 */
}

/* ---- on traced rays ------------------------------------------------------ */

static cbvh_scene_desc scene;
static cbvh_cost_table table;

static int setup(void **state) {
    (void)state;
    char err[512];
    if (cbvh_scene_file_load(TIMING_FIXTURE, &scene, err, sizeof err) ||
        cbvh_cost_table_load(COST_DIR, &table, err, sizeof err)) {
        fprintf(stderr, "%s\n", err);
        return -1;
    }
    return 0;
}

static int teardown(void **state) {
    (void)state;
    cbvh_scene_desc_free(&scene);
    cbvh_cost_table_free(&table);
    return 0;
}

static void traced(const char *format, const double *kb, int n, cbvh_step_log *log, cbvh_fx_result *r) {
    char err[512];
    cbvh_fx_opts o = {.format = format, .params = {6, CBVH_MIN_SCALE_DEFAULT}, .mant = 24, .cache_kb = kb,
                      .ncaches = n, .cache_ways = 8, .steps = log};
    if (cbvh_fx_run(&scene, &o, r, err, sizeof err)) fail_msg("%s", err);
}

/* The cache model observes; it does not change what the traversals do:
 * the same hits and counters with and without it, for every format. */
static void cache_leaves_hits(void **state) {
    (void)state;
    static const char *formats[] = {"float", "cbvh", "qbvh", "tlist"};
    double kb[3] = {16, 0, INFINITY};
    for (int f = 0; f < 4; f++) {
        static cbvh_fx_result a, b;
        traced(formats[f], NULL, 0, NULL, &a);
        traced(formats[f], kb, 3, NULL, &b);
        assert_int_equal(a.hit_digest, b.hit_digest);
        cbvh_fx_stats ta = cbvh_fx_total(&a), tb = cbvh_fx_total(&b);
        assert_int_equal(ta.st.box_tests, tb.st.box_tests);
        assert_int_equal(ta.st.tri_tests, tb.st.tri_tests);
        assert_int_equal(ta.st.lines, tb.st.lines);
        assert_int_equal(ta.mem[0].lines, 0);
        /* without a cache every line read comes from DRAM; the reads are the counters' (the QBVH's in its
         * hardware layout) */
        assert_int_equal(tb.mem[1].miss_lines, tb.mem[1].lines);
        assert_int_equal(tb.mem[1].miss_steps, tb.mem[1].steps);
        if (f != 2) assert_int_equal(tb.mem[1].lines, tb.st.lines);
        assert_int_equal(tb.mem[1].steps, tb.st.nodes + tb.st.tri_tests);
        assert_true(tb.mem[0].miss_lines < tb.mem[0].lines);
        assert_true(tb.mem[2].miss_lines <= tb.mem[0].miss_lines);
    }
}

/* An infinite cache misses only a line's first read: as a cache larger than
 * every line read; warm and with no latency, the model is the compute bound. */
static void infinite_cache_compute_bound(void **state) {
    (void)state;
    double kb[2] = {INFINITY, 65536}; /* 64 MB: larger than every line the scene reads */
    static cbvh_fx_result r;
    traced("cbvh", kb, 2, NULL, &r);
    cbvh_fx_stats t = cbvh_fx_total(&r);
    assert_int_equal(t.mem[0].miss_lines, t.mem[1].miss_lines);
    cbvh_timing_params p;
    cbvh_timing_defaults(&p);
    p.cache_hit_latency = 0;
    p.fetch_latency = 1e6; /* never paid */
    char err[256];
    cbvh_timing_units u;
    assert_int_equal(cbvh_fx_units(&r, &table, &p, "ray_box", 6, 24, &u, err, sizeof err), 0);
    assert_true(u.dec.present && !u.qstack.present);
    cbvh_timing_work w;
    cbvh_fx_timing_work(&t, 0, INFINITY, &w);
    w.miss_lines = w.miss_steps = 0; /* warm */
    for (double R = 1; R <= 4096; R *= 4) {
        p.rays_in_flight = R;
        cbvh_timing_result tr;
        assert_int_equal(cbvh_timing_eval(&p, &u, &w, &tr), 0);
        double compute = tr.unit_latency / R;
        compute = fmax(compute, (double)w.node_ops * u.node.ii / u.node.instances);
        compute = fmax(compute, (double)w.tri_ops * u.tri.ii / u.tri.instances);
        compute = fmax(compute, (double)w.dec_ops * u.dec.ii / u.dec.instances);
        assert_float_equal(tr.mem_latency, 0, 0);
        assert_float_equal(tr.cycles, compute, 1e-9 * compute);
        assert_float_equal(tr.energy_sram + tr.energy_dram, 0, 0);
    }
}

/* Halving node bytes in a bandwidth-bound machine lowers the time: nodes of
 * 64 bytes against 32, read one after another through a 1 KB cache (a
 * second node of a line is then a hit), many rays in flight.  (Without any
 * cache each read is a whole line from DRAM: a smaller node saves nothing.) */
static void half_node_bytes(void **state) {
    (void)state;
    double kb = 1, t[2];
    for (int k = 0; k < 2; k++) {
        uint64_t size = k ? 32 : 64;
        cbvh_memsim M;
        char err[200];
        assert_int_equal(cbvh_memsim_init(&M, &kb, 1, 8, NULL, err, sizeof err), 0);
        cbvh_mem_counts mc[CBVH_CACHES_MAX] = {{0}};
        cbvh_trav_stats s = {0};
        for (int ray = 0; ray < 100; ray++) {
            cbvh_memsim_ray_begin(&M, mc);
            for (uint64_t n = 0; n < 20; n++) M.obs.fetch(M.obs.ctx, CBVH_FETCH_NODE, (ray * 20 + n) * size, size, &s);
            cbvh_memsim_ray_end(&M, &s);
        }
        cbvh_memsim_free(&M);
        cbvh_timing_params p;
        cbvh_timing_defaults(&p);
        p.rays_in_flight = 1e6;
        cbvh_timing_units u = {unit(1, 1, 0, 0), unit(1, 1, 0, 0), {0}, {0}};
        cbvh_timing_work w = {.rays = 100, .nodes = 2000, .node_ops = 4000, .steps = mc[0].steps,
                              .miss_steps = mc[0].miss_steps, .lines = mc[0].lines, .miss_lines = mc[0].miss_lines,
                              .cache_kb = kb};
        cbvh_timing_result r;
        assert_int_equal(cbvh_timing_eval(&p, &u, &w, &r), 0);
        assert_int_equal(r.bound, CBVH_BOUND_DRAM);
        t[k] = r.cycles;
    }
    assert_true(t[1] < t[0]);
    assert_float_equal(t[1], t[0] / 2, 1e-9); /* half the lines: two 32-byte nodes per line */
}

/* More rays in flight never raise the time: the analytic model, on traced
 * rays, every format and cache; and the event-driven simulation's error
 * stays small on them. */
static void rays_in_flight_monotone(void **state) {
    (void)state;
    static const char *formats[] = {"float", "cbvh", "qbvh", "tlist"};
    double kb[3] = {0, 16, 256};
    char err[256];
    for (int f = 0; f < 4; f++) {
        static cbvh_fx_result r;
        cbvh_step_log log = {.max_rays = 2000, .cache = 1};
        traced(formats[f], kb, 3, &log, &r);
        cbvh_fx_stats t = cbvh_fx_total(&r);
        for (int c = 0; c < 3; c++)
            for (int one = 0; one < 2; one++) {
                cbvh_timing_params p;
                cbvh_timing_defaults(&p);
                if (one) p.box_cycles = p.tri_cycles = 1;
                cbvh_timing_units u;
                assert_int_equal(cbvh_fx_units(&r, &table, &p, "ray_box", 6, 24, &u, err, sizeof err), 0);
                cbvh_timing_work w;
                cbvh_fx_timing_work(&t, c, kb[c], &w);
                double prev = INFINITY;
                for (double R = 1; R <= 1 << 14; R *= 2) {
                    p.rays_in_flight = R;
                    cbvh_timing_result tr;
                    assert_int_equal(cbvh_timing_eval(&p, &u, &w, &tr), 0);
                    assert_true(tr.cycles <= prev);
                    prev = tr.cycles;
                }
                if (c != 1) continue;
                for (double R = 1; R <= 16; R *= 4) { /* the event-driven check on the logged rays */
                    p.rays_in_flight = R;
                    cbvh_event_result ev;
                    assert_int_equal(cbvh_event_sim(&log, &p, &u, kb[c], &ev), 0);
                    assert_true(ev.analytic <= ev.cycles * (1 + 1e-9)); /* a lower bound */
                    if (fabs(ev.rel_error) > 0.25) /* near the knee, queueing: docs/timing_model.md §6 */
                        fail_msg("%s R=%g: analytic %g, event-driven %g", formats[f], R, ev.analytic, ev.cycles);
                    if (R == 1) assert_float_equal(ev.analytic, ev.cycles, 1e-9 * ev.cycles);
                }
            }
        cbvh_step_log_free(&log);
    }
}

/* ---- the sweep's choices ------------------------------------------------- */

static void pareto_hand_made(void **state) {
    (void)state;
    const double cost[][3] = {
        {1, 5, 5},   /* 0: on (fastest) */
        {2, 2, 2},   /* 1: on */
        {3, 3, 3},   /* 2: dominated by 1 */
        {1, 5, 5},   /* 3: equal to 0: on too */
        {NAN, 1, 1}, /* 4: no time: never on, dominates nothing */
        {5, 1, 9},   /* 5: on (least energy) */
        {2, 2, 3},   /* 6: dominated by 1 (equal in two, worse in one) */
        {9, 9, 1},   /* 7: on (least area) */
    };
    int front[8], want[8] = {1, 1, 0, 1, 0, 1, 0, 1};
    cbvh_pareto_front(cost, 8, front);
    for (int i = 0; i < 8; i++)
        if (front[i] != want[i]) fail_msg("point %d: front %d, expected %d", i, front[i], want[i]);
    double t[] = {NAN, 3, 1, 1, INFINITY};
    assert_int_equal(cbvh_argmin(t, 5), 2); /* ties: the first */
    assert_int_equal(cbvh_argmin(t, 1), -1);
}

/* cbvh run's sentence: the winner, its cache and its saving against float;
 * or that the float BVH stays fastest and what the best CBVH costs. */
static void best_sentence(void **state) {
    (void)state;
    cbvh_ray_metrics f = {0}, b = {0};
    f.model_ns = 200;
    f.energy_nj = 10;
    f.area_lut4 = 1000;
    f.dram_bytes = 100;
    b.model_ns = 150;
    b.energy_nj = 8;
    b.area_lut4 = 1100;
    b.dram_bytes = 50;
    char s[600];
    cbvh_best_sentence(s, sizeof s, "x.scene", "the CBVH at N=6", 64, &b, &f, 0, "", &b);
    assert_string_equal(s, "Best setting for x.scene: the CBVH at N=6 with a 64 KB cache, 150.0 ns and 8.00 nJ per ray: "
                           "-25.0 % time and -20.0 % energy against the float BVH (200.0 ns, 10.00 nJ), +10.0 % unit "
                           "area.");
    b.model_ns = 210;
    cbvh_best_sentence(s, sizeof s, "x.scene", "", 16, &f, &f, 1, "the CBVH at N=7", &b);
    assert_string_equal(s, "Best setting for x.scene: keep the float BVH (200.0 ns and 10.00 nJ per ray with a 16 KB "
                           "cache); the fastest compressed one, the CBVH at N=7, is +5.0 % slower, -20.0 % in energy "
                           "and uses 0.50x its node bandwidth from DRAM.");
    double kb;
    assert_int_equal(cbvh_cache_kb_parse("inf", &kb), 0);
    assert_true(isinf(kb));
    assert_int_equal(cbvh_cache_kb_parse("64", &kb), 0);
    assert_float_equal(kb, 64, 0);
    assert_int_equal(cbvh_cache_kb_parse("-1", &kb), -1);
    assert_int_equal(cbvh_cache_kb_parse("1048577", &kb), -1);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(cost_table),
        cmocka_unit_test(units_from_table),
        cmocka_unit_test(worked_example),
        cmocka_unit_test(v1_corner),
        cmocka_unit_test(timing_set),
        cmocka_unit_test(build_time),
        cmocka_unit_test(cache_lru),
        cmocka_unit_test(memsim_counts),
        cmocka_unit_test(event_example),
        cmocka_unit_test(cache_leaves_hits),
        cmocka_unit_test(infinite_cache_compute_bound),
        cmocka_unit_test(half_node_bytes),
        cmocka_unit_test(rays_in_flight_monotone),
        cmocka_unit_test(pareto_hand_made),
        cmocka_unit_test(best_sentence),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
