/* Timing, energy and area model of the traversal accelerator, version 2:
 * docs/timing_model.md (every formula and default with its source). */
#include "trace/timing_model.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void cbvh_timing_defaults(cbvh_timing_params *p) {
    p->clock_mhz = 1000.0;            /* seed 003 Sec. 5.3: "The operating frequency is set at 1GHz" */
    p->rays_in_flight = 64.0;         /* assumption (docs/timing_model.md §4) */
    p->dram_bytes_per_cycle = 12.8;   /* seed 003 Sec. 5.3: LPDDR3-1600 dual 32-bit channel, 12.8 GB/s at 1 GHz */
    p->fetch_latency = 100.0;         /* assumption: ~100 ns LPDDR3 round trip at 1 GHz (no paper gives it) */
    p->cache_hit_latency = 4.0;       /* assumption: a 4-cycle L1-style load-to-use latency */
    p->cache_ways = 8.0;              /* assumption */
    p->unit_cycle_scale = 1.0;        /* the RTL's cycle counts at the model clock (docs/timing_model.md §2) */
    p->issue_width = 1.0;             /* assumption: one operation per cycle per unit type */
    p->box_cycles = p->tri_cycles = NAN; /* from the cost table */
    p->dram_pj_per_byte = 1300.0 / 8; /* Horowitz ISSCC 2014 (45 nm): DRAM 1.3-2.6 nJ per 64-bit access, low end */
    p->sram_pj_per_word = 10.0;       /* Horowitz ISSCC 2014: 64-bit read from an 8 KB SRAM, 10 pJ */
    p->add_pj_per_bit = 0.1 / 32;     /* Horowitz ISSCC 2014: 32-bit integer add 0.1 pJ */
    p->mul_pj_per_pp_bit = 3.1 / 1024; /* Horowitz ISSCC 2014: 32-bit integer multiply 3.1 pJ, 32 x 32 partial products */
}

int cbvh_timing_set(cbvh_timing_params *p, const char *spec, char *err, size_t errlen) {
    const struct {
        const char *key;
        double *v;
    } k[] = {{"clock_mhz", &p->clock_mhz},
             {"rays_in_flight", &p->rays_in_flight},
             {"dram_bytes_per_cycle", &p->dram_bytes_per_cycle},
             {"fetch_latency", &p->fetch_latency},
             {"cache_hit_latency", &p->cache_hit_latency},
             {"cache_ways", &p->cache_ways},
             {"unit_cycle_scale", &p->unit_cycle_scale},
             {"issue_width", &p->issue_width},
             {"box_cycles", &p->box_cycles},
             {"tri_cycles", &p->tri_cycles},
             {"dram_pj_per_byte", &p->dram_pj_per_byte},
             {"sram_pj_per_word", &p->sram_pj_per_word}};
    const char *s = spec;
    do {
        size_t n = strcspn(s, ","), klen = strcspn(s, "=");
        char num[64];
        if (klen >= n || n - klen - 1 >= sizeof num || n - klen - 1 == 0) {
            snprintf(err, errlen, "--timing expects key=value[,key=value...], got '%.*s'", (int)n, s);
            return -1;
        }
        size_t i = 0;
        while (i < sizeof k / sizeof k[0] && (strlen(k[i].key) != klen || strncmp(k[i].key, s, klen) != 0)) i++;
        if (i == sizeof k / sizeof k[0]) {
            snprintf(err, errlen, "--timing: unknown key '%.*s' (docs/timing_model.md)", (int)klen, s);
            return -1;
        }
        memcpy(num, s + klen + 1, n - klen - 1);
        num[n - klen - 1] = 0;
        char *end;
        double v = strtod(num, &end);
        if (*end || !isfinite(v)) {
            snprintf(err, errlen, "--timing: %s expects a number, got '%s'", k[i].key, num);
            return -1;
        }
        *k[i].v = v;
        s += n;
    } while (*s++ == ',');
    return cbvh_timing_check(p, err, errlen);
}

static int bad(double x, double lo) { return !isfinite(x) || x < lo || x > CBVH_TIMING_MAX; }

int cbvh_timing_check(const cbvh_timing_params *p, char *err, size_t errlen) {
    const struct {
        const char *name;
        double v, lo;
    } f[] = {{"clock_mhz", p->clock_mhz, CBVH_TIMING_RATE_MIN},
             {"rays_in_flight", p->rays_in_flight, CBVH_TIMING_RATE_MIN},
             {"dram_bytes_per_cycle", p->dram_bytes_per_cycle, CBVH_TIMING_RATE_MIN},
             {"fetch_latency", p->fetch_latency, 0},
             {"cache_hit_latency", p->cache_hit_latency, 0},
             {"unit_cycle_scale", p->unit_cycle_scale, CBVH_TIMING_RATE_MIN},
             {"dram_pj_per_byte", p->dram_pj_per_byte, 0},
             {"sram_pj_per_word", p->sram_pj_per_word, 0},
             {"add_pj_per_bit", p->add_pj_per_bit, 0},
             {"mul_pj_per_pp_bit", p->mul_pj_per_pp_bit, 0}};
    for (size_t i = 0; i < sizeof f / sizeof f[0]; i++)
        if (bad(f[i].v, f[i].lo)) {
            snprintf(err, errlen, "timing.%s: %g is out of range [%g, %g]", f[i].name, f[i].v, f[i].lo,
                     CBVH_TIMING_MAX);
            return -1;
        }
    if (bad(p->issue_width, 1) || p->issue_width > 1024 || p->issue_width != floor(p->issue_width)) {
        snprintf(err, errlen, "timing.issue_width: %g is not a whole number in [1, 1024]", p->issue_width);
        return -1;
    }
    if (bad(p->cache_ways, 1) || p->cache_ways > 64 || p->cache_ways != floor(p->cache_ways)) {
        snprintf(err, errlen, "timing.cache_ways: %g is not a whole number in [1, 64]", p->cache_ways);
        return -1;
    }
    if ((!isnan(p->box_cycles) && bad(p->box_cycles, 0)) || (!isnan(p->tri_cycles) && bad(p->tri_cycles, 0))) {
        snprintf(err, errlen, "timing.box_cycles / tri_cycles: out of range [0, %g]", CBVH_TIMING_MAX);
        return -1;
    }
    return 0;
}

/* A unit from its cost-table row: cycles scaled to the model clock, enough
 * instances to start one operation per cycle, energy from the ASIC widths. */
static void unit_from(const cbvh_timing_params *p, const cbvh_cost_row *r, cbvh_unit_cost *u) {
    memset(u, 0, sizeof *u);
    u->present = 1;
    snprintf(u->unit, sizeof u->unit, "%s", r->unit);
    u->latency = r->latency * p->unit_cycle_scale;
    u->ii = r->ii * p->unit_cycle_scale;
    u->instances = ceil(u->ii * p->issue_width - 1e-9);
    if (u->instances < p->issue_width) u->instances = p->issue_width;
    u->lut4 = r->lut4;
    u->energy_pj = r->pp_bits * p->mul_pj_per_pp_bit + r->adder_bits * p->add_pj_per_bit;
}

/* v1's pipelined unit: latency = II = cycles, one instance (issue_width of them). */
static void unit_cycles(cbvh_unit_cost *u, double cycles, double width) {
    u->latency = u->ii = cycles;
    u->instances = width;
}

static int lookup(const cbvh_cost_table *t, const cbvh_timing_params *p, const char *unit, int n, int m,
                  cbvh_unit_cost *u, char *err, size_t errlen) {
    cbvh_cost_row r;
    if (cbvh_cost_lookup(t, unit, n, m, &r)) {
        snprintf(err, errlen, "the cost table has no unit \"%s\" (gateware/cost/, docs/timing_model.md §2)", unit);
        return -1;
    }
    unit_from(p, &r, u);
    return 0;
}

int cbvh_timing_units_for(const cbvh_cost_table *t, const cbvh_timing_params *p, const char *node_unit, int dec,
                          int qstack, int n, int m, cbvh_timing_units *u, char *err, size_t errlen) {
    memset(u, 0, sizeof *u);
    if (lookup(t, p, node_unit, n, m, &u->node, err, errlen) ||
        lookup(t, p, "ray_triangle", n, m, &u->tri, err, errlen) ||
        (dec && lookup(t, p, "nodepair_decoder", n, m, &u->dec, err, errlen)) ||
        (qstack && lookup(t, p, "qbvh_stack", n, m, &u->qstack, err, errlen)))
        return -1;
    if (!isnan(p->box_cycles) && strcmp(node_unit, "ray_sphere") != 0)
        unit_cycles(&u->node, p->box_cycles, p->issue_width);
    if (!isnan(p->tri_cycles)) unit_cycles(&u->tri, p->tri_cycles, p->issue_width);
    return 0;
}

double cbvh_build_cycles(const cbvh_timing_params *p, double bytes, double round_trips) {
    return bytes / p->dram_bytes_per_cycle + round_trips * p->fetch_latency;
}

const char *cbvh_timing_bound_name(cbvh_timing_bound b) {
    static const char *const names[CBVH_BOUND_COUNT] = {"latency", "node unit", "triangle unit", "decoder",
                                                        "stack unit", "DRAM"};
    return b < CBVH_BOUND_COUNT ? names[b] : "?";
}

double cbvh_timing_word_pj(const cbvh_timing_params *p, double cache_kb) {
    if (!(cache_kb > 0) || isinf(cache_kb)) return 0; /* none; the infinite cache is ideal */
    return p->sram_pj_per_word * sqrt(cache_kb / 8.0);
}

/* Busy cycles of a unit: ops x II over its instances. */
static double busy(const cbvh_unit_cost *u, uint64_t ops) {
    return u->present ? (double)ops * u->ii / u->instances : 0;
}

int cbvh_timing_eval(const cbvh_timing_params *p, const cbvh_timing_units *u, const cbvh_timing_work *w,
                     cbvh_timing_result *o) {
    char err[160];
    memset(o, 0, sizeof *o);
    if (cbvh_timing_check(p, err, sizeof err)) return -1;
    int cached = w->cache_kb > 0;
    double xfer = 64.0 / p->dram_bytes_per_cycle; /* one line over the DRAM interface */
    /* Memory: every step asks the cache; a step with a missing line waits
     * for DRAM, and for its missing lines to stream in. */
    o->mem_latency = (cached ? (double)w->steps * p->cache_hit_latency : 0) +
                     (double)w->miss_steps * p->fetch_latency + (double)w->miss_lines * xfer;
    /* Units: a node read feeds the node unit (its first test after the unit's
     * latency, the others one issue interval apart over its instances) and,
     * in a CBVH, the decoder first; a triangle test, a stack operation each
     * their unit's latency. */
    double node_ii = u->node.present ? u->node.ii / u->node.instances : 0;
    uint64_t groups = w->nodes + w->starts; /* node reads, and ray starts with a root test */
    double extra = w->node_ops > groups ? (double)(w->node_ops - groups) : 0;
    o->unit_latency = (double)groups * (u->node.present ? u->node.latency : 0) +
                      (double)w->nodes * (u->dec.present ? u->dec.latency : 0) + extra * node_ii +
                      (double)w->tri_ops * (u->tri.present ? u->tri.latency : 0) +
                      (double)w->qstack_ops * (u->qstack.present ? u->qstack.latency : 0);
    o->occupancy[CBVH_BOUND_LATENCY] = (o->mem_latency + o->unit_latency) / p->rays_in_flight;
    o->occupancy[CBVH_BOUND_NODE] = busy(&u->node, w->node_ops);
    o->occupancy[CBVH_BOUND_TRI] = busy(&u->tri, w->tri_ops);
    o->occupancy[CBVH_BOUND_DEC] = busy(&u->dec, w->dec_ops);
    o->occupancy[CBVH_BOUND_QSTACK] = busy(&u->qstack, w->qstack_ops);
    o->occupancy[CBVH_BOUND_DRAM] = (double)w->miss_lines * xfer;
    o->bound = CBVH_BOUND_LATENCY;
    for (int b = 1; b < CBVH_BOUND_COUNT; b++)
        if (o->occupancy[b] > o->occupancy[o->bound]) o->bound = (cbvh_timing_bound)b;
    o->cycles = o->occupancy[o->bound];
    o->seconds = o->cycles / (p->clock_mhz * 1e6);
    const cbvh_unit_cost *us[4] = {&u->node, &u->tri, &u->dec, &u->qstack};
    const uint64_t ops[4] = {w->node_ops, w->tri_ops, w->dec_ops, w->qstack_ops};
    for (int k = 0; k < 4; k++)
        if (us[k]->present) {
            o->energy_units += (double)ops[k] * us[k]->energy_pj;
            o->area_lut4 += us[k]->instances * us[k]->lut4;
        }
    o->energy_sram = cached ? (double)w->words * cbvh_timing_word_pj(p, w->cache_kb) : 0;
    o->energy_dram = (double)w->miss_lines * 64.0 * p->dram_pj_per_byte;
    return 0;
}
