/* The timing model applied to traced configurations (trace/model_eval.h). */
#include "trace/model_eval.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util/parse_int.h"

int cbvh_config_model_init(cbvh_config_model *cm, const cbvh_fx_result *r, const cbvh_cost_table *t,
                           const cbvh_timing_params *tp, const char *box_unit, int n, int m, char *err, size_t errlen) {
    memset(cm, 0, sizeof *cm);
    cbvh_timing_units u;
    if (cbvh_fx_units(r, t, tp, box_unit, n, m, &u, err, errlen)) return -1;
    cm->ncaches = r->ncaches;
    for (int c = 0; c < r->ncaches; c++) cm->mc[c] = (cbvh_machine){*tp, u, c, r->cache_kb[c]};
    if (!r->ncaches) { /* no cache modelled: the counters say nothing of memory; time from the units */
        cm->mc[0] = (cbvh_machine){*tp, u, 0, 0};
    }
    return 0;
}

const char *cbvh_cache_name_unit(double kb, const char *unit, char *buf, size_t n) {
    if (isinf(kb))
        snprintf(buf, n, "inf");
    else if (!(kb > 0))
        snprintf(buf, n, "none");
    else
        snprintf(buf, n, "%g%s", kb, unit);
    return buf;
}

void cbvh_timing_json(cJSON *o, const cbvh_timing_params *tp, const char *cost_dir) {
    const char *keys[] = {"clock_mhz",        "rays_in_flight",  "dram_bytes_per_cycle", "fetch_latency",
                          "cache_hit_latency", "cache_ways",      "unit_cycle_scale",     "issue_width", "box_cycles",
                          "tri_cycles",       "dram_pj_per_byte", "sram_pj_per_word",     "add_pj_per_bit",
                          "mul_pj_per_pp_bit"};
    const double vals[] = {tp->clock_mhz,        tp->rays_in_flight,   tp->dram_bytes_per_cycle, tp->fetch_latency,
                           tp->cache_hit_latency, tp->cache_ways,       tp->unit_cycle_scale,     tp->issue_width, tp->box_cycles,
                           tp->tri_cycles,        tp->dram_pj_per_byte, tp->sram_pj_per_word,     tp->add_pj_per_bit,
                           tp->mul_pj_per_pp_bit};
    for (size_t i = 0; i < sizeof vals / sizeof vals[0]; i++)
        if (isfinite(vals[i]))
            cJSON_AddNumberToObject(o, keys[i], vals[i]);
        else
            cJSON_AddNullToObject(o, keys[i]); /* box_cycles, tri_cycles: the cost table's */
    cJSON_AddStringToObject(o, "cost_table", cost_dir);
}

cJSON *cbvh_unit_json(const cbvh_unit_cost *u) {
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "unit", u->unit);
    cJSON_AddNumberToObject(o, "latency", u->latency);
    cJSON_AddNumberToObject(o, "ii", u->ii);
    cJSON_AddNumberToObject(o, "instances", u->instances);
    cJSON_AddNumberToObject(o, "lut4_each", u->lut4);
    cJSON_AddNumberToObject(o, "energy_pj_per_op", u->energy_pj);
    return o;
}

void cbvh_model_json(cJSON *o, const cbvh_ray_metrics *m) {
    cJSON_AddNumberToObject(o, "energy_nj_per_ray", m->energy_nj);
    cJSON_AddNumberToObject(o, "area_lut4", m->area_lut4);
    cJSON_AddNumberToObject(o, "dram_bytes_per_ray", m->dram_bytes);
    cJSON_AddNumberToObject(o, "hit_rate", m->hit_rate);
    cJSON_AddStringToObject(o, "bound", cbvh_timing_bound_name(m->bound));
}

int cbvh_cache_kb_parse(const char *s, double *kb) {
    long v;
    if (s && strcmp(s, "inf") == 0) {
        *kb = INFINITY;
        return 0;
    }
    if (cbvh_parse_long(s, 0, CBVH_CACHE_KB_MAX, &v)) return -1;
    *kb = (double)v;
    return 0;
}

/* "x0.87 (-13 %)" style: how much a is of b. */
static double pct(double a, double b) { return b > 0 ? 100.0 * (a / b - 1.0) : 0; }

void cbvh_best_sentence(char *out, size_t n, const char *scene, const char *best_name, double kb,
                        const cbvh_ray_metrics *best, const cbvh_ray_metrics *flt, int best_is_float,
                        const char *runner_name, const cbvh_ray_metrics *runner) {
    char cn[32];
    cbvh_cache_name(kb, cn, sizeof cn);
    if (best_is_float) {
        char dram[80] = "";
        if (flt->dram_bytes > 0)
            snprintf(dram, sizeof dram, " and uses %.2fx its node bandwidth from DRAM",
                     runner->dram_bytes / flt->dram_bytes);
        snprintf(out, n,
                 "Best setting for %s: keep the float BVH (%.1f ns and %.2f nJ per ray with a %s cache); the fastest "
                 "compressed one, %s, is %+.1f %% slower, %+.1f %% in energy%s.",
                 scene, flt->model_ns, flt->energy_nj, cn, runner_name, pct(runner->model_ns, flt->model_ns),
                 pct(runner->energy_nj, flt->energy_nj), dram);
        return;
    }
    snprintf(out, n,
             "Best setting for %s: %s with a %s cache, %.1f ns and %.2f nJ per ray: %+.1f %% time and %+.1f %% "
             "energy against the float BVH (%.1f ns, %.2f nJ), %+.1f %% unit area.",
             scene, best_name, cn, best->model_ns, best->energy_nj, pct(best->model_ns, flt->model_ns),
             pct(best->energy_nj, flt->energy_nj), flt->model_ns, flt->energy_nj,
             pct(best->area_lut4, flt->area_lut4));
}

void cbvh_machine_line(const cbvh_timing_params *tp, char *out, size_t n) {
    snprintf(out, n,
             "%g rays in flight, %g MHz; cache %g-way, %g-cycle hit; DRAM %g cycles, %g B/cycle; units from the "
             "RTL cost table (cycles x %g), %g operation%s per cycle each%s",
             tp->rays_in_flight, tp->clock_mhz, tp->cache_ways, tp->cache_hit_latency, tp->fetch_latency,
             tp->dram_bytes_per_cycle, tp->unit_cycle_scale, tp->issue_width, tp->issue_width == 1 ? "" : "s",
             isnan(tp->box_cycles) && isnan(tp->tri_cycles) ? "" : " (box/triangle cycles set)");
}
