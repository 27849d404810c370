/* What a set of traced rays did and what it costs per ray: one set of
 * counters (cbvh_fx_stats), summed ray by ray as the tracer traces and over
 * effects, and one derivation of the per-ray metrics (cbvh_ray_metrics: box
 * and triangle tests, nodes, bytes, the timing model's time, CPU time) that
 * `cbvh trace`, `cbvh run` and `cbvh sweep` all print (docs/scenes.md,
 * docs/timing_model.md). */
#ifndef CBVH_HOST_METRICS_H
#define CBVH_HOST_METRICS_H

#include <stdint.h>

#include "cbvh/traverse.h"
#include "trace/timing_model.h"

typedef struct {
    uint64_t rays;            /* rays traced */
    uint64_t closest, any;    /* traversals by kind */
    uint64_t hits;
    uint64_t rejected;        /* rays a unit rejected (NaN/Inf, zero direction): no hit */
    cbvh_trav_stats st;       /* summed counters; max_stack = deepest */
    double cpu_seconds;       /* time spent in traversal (per-ray monotonic clock, its cost removed) */
} cbvh_fx_stats;

/* One traversal more: its mode (CBVH_TRAV_ANY bit: an any-hit ray), whether
 * a unit rejected it, whether it hit, its counters and its time. */
void cbvh_fx_stats_add_ray(cbvh_fx_stats *s, cbvh_trav_mode mode, int rejected, int hit, const cbvh_trav_stats *st,
                           double seconds);

/* sum += s (max_stack: the deeper). */
void cbvh_fx_stats_add(cbvh_fx_stats *sum, const cbvh_fx_stats *s);

/* Per-ray metrics of a set of rays; with no rays every per-ray value is 0. */
typedef struct {
    uint64_t rays;
    double box, tri, nodes, bytes; /* box tests, triangle tests, inner nodes, bytes per ray */
    double model_ns;               /* the timing model's time per ray (docs/timing_model.md) */
    double cpu_us;                 /* the bit-exact model's own CPU time per ray */
    uint32_t max_stack;            /* deepest stack */
} cbvh_ray_metrics;

/* 0, or -1 when the timing model rejects tp (model_ns is 0 then). */
int cbvh_ray_metrics_of(const cbvh_fx_stats *s, const cbvh_timing_params *tp, cbvh_ray_metrics *m);

#endif
