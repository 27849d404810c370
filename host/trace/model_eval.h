/* The timing model applied to traced configurations, for `cbvh trace`, `run`
 * and `sweep` (docs/timing_model.md): the machine of a configuration at each
 * cache size of its run, the Pareto marks and the best configuration, and the
 * one sentence `cbvh run` ends with. */
#ifndef CBVH_HOST_MODEL_EVAL_H
#define CBVH_HOST_MODEL_EVAL_H

#include <stddef.h>

#include <cjson/cJSON.h>

#include "trace/cost_table.h"
#include "trace/effects.h"
#include "trace/metrics.h"
#include "trace/timing_model.h"

/* A traced configuration's machines, one per cache size of its run. */
typedef struct {
    cbvh_machine mc[CBVH_CACHES_MAX];
    int ncaches;
} cbvh_config_model;

/* The machines of run r (cbvh_fx_units: box_unit is a cost-table unit, n and
 * m the design point; a format without N takes n = 6).  0, or -1 with a
 * one-line reason. */
int cbvh_config_model_init(cbvh_config_model *cm, const cbvh_fx_result *r, const cbvh_cost_table *t,
                           const cbvh_timing_params *tp, const char *box_unit, int n, int m, char *err, size_t errlen);

/* A cache size for tables: "none", "inf", "64 KB"; with unit = "" for file
 * names: "none", "inf", "64". */
const char *cbvh_cache_name_unit(double kb, const char *unit, char *buf, size_t n);
static inline const char *cbvh_cache_name(double kb, char *buf, size_t n) {
    return cbvh_cache_name_unit(kb, " KB", buf, n);
}

/* The machine's parameters into a JSON object ("timing"): every key of
 * cbvh_timing_set and the energies per bit, the cost table's folder. */
void cbvh_timing_json(cJSON *o, const cbvh_timing_params *tp, const char *cost_dir);
/* A unit as the model sees it: unit, latency, ii, instances, lut4_each,
 * energy_pj_per_op. */
cJSON *cbvh_unit_json(const cbvh_unit_cost *u);

/* The timing model's figures of a set of rays into a JSON object:
 * energy_nj_per_ray, area_lut4, dram_bytes_per_ray, hit_rate, bound. */
void cbvh_model_json(cJSON *o, const cbvh_ray_metrics *m);

/* "--cache" values: an integer 0 .. CBVH_CACHE_KB_MAX (KB; 0 = no cache) or
 * "inf".  0 or -1. */
int cbvh_cache_kb_parse(const char *s, double *kb);

/* The sentence a person can act on: the fastest configuration in modelled
 * time (name, at cache kb) against the float BVH (flt, the same cache), or
 * that the float BVH stays fastest and what the best other one costs. */
void cbvh_best_sentence(char *out, size_t n, const char *scene, const char *best_name, double kb,
                        const cbvh_ray_metrics *best, const cbvh_ray_metrics *flt, int best_is_float,
                        const char *runner_name, const cbvh_ray_metrics *runner);

/* The machine's parameters in one line, for tables. */
void cbvh_machine_line(const cbvh_timing_params *tp, char *out, size_t n);

#endif
