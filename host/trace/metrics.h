/* What a set of traced rays did and what it costs per ray: one set of
 * counters (cbvh_fx_stats), summed ray by ray as the tracer traces and over
 * effects, and one derivation of the per-ray metrics (cbvh_ray_metrics: box
 * and triangle tests, nodes, bytes, the timing model's time, energy and
 * area, the cache's hit rate, CPU time) that `cbvh trace`, `cbvh run` and
 * `cbvh sweep` all print (docs/scenes.md, docs/timing_model.md). */
#ifndef CBVH_HOST_METRICS_H
#define CBVH_HOST_METRICS_H

#include <stdint.h>

#include "cbvh/format.h"
#include "cbvh/traverse.h"
#include "trace/timing_model.h"

#define CBVH_CACHES_MAX 8 /* cache sizes modelled in one run */
#define CBVH_REPS_MAX 32  /* timed repetitions of the CPU-time column */

/* The memory side of a set of rays under one cache (docs/timing_model.md §3). */
typedef struct {
    uint64_t steps;      /* dependent reads: node reads and triangle reads (a leaf's IDs go with its triangles) */
    uint64_t miss_steps; /* steps with at least one line from DRAM */
    uint64_t lines;      /* lines read */
    uint64_t words;      /* 64-bit words read (what a cache read of the bytes needed costs) */
    uint64_t miss_lines; /* lines from DRAM */
    uint64_t starts;     /* rays whose root box test came before any read (the same for every cache) */
} cbvh_mem_counts;

typedef struct {
    uint64_t rays;            /* rays traced */
    uint64_t closest, any;    /* traversals by kind */
    uint64_t hits;
    uint64_t rejected;        /* rays a unit rejected (NaN/Inf, zero direction): no hit */
    cbvh_trav_stats st;       /* summed counters; max_stack = deepest */
    double cpu_seconds;       /* time spent in traversal (per-ray monotonic clock, its cost removed) */
    cbvh_unit_activity ops;   /* the traversals' unit operations (the format's units(), at the end of a run) */
    cbvh_mem_counts mem[CBVH_CACHES_MAX]; /* per cache of the run (cbvh_fx_result.cache_kb) */
    double cpu_rep[CBVH_REPS_MAX]; /* cpu_seconds of each timed repetition (cbvh_fx_add_rep) */
    int nreps;
} cbvh_fx_stats;

/* One traversal more: its mode (CBVH_TRAV_ANY bit: an any-hit ray), whether
 * a unit rejected it, whether it hit, its counters and its time. */
void cbvh_fx_stats_add_ray(cbvh_fx_stats *s, cbvh_trav_mode mode, int rejected, int hit, const cbvh_trav_stats *st,
                           double seconds);

/* sum += s (max_stack: the deeper; repetitions summed one by one). */
void cbvh_fx_stats_add(cbvh_fx_stats *sum, const cbvh_fx_stats *s);

/* What the model needs besides the counters: its parameters, the units of
 * the format and design point (cbvh_timing_units_for), and which of the
 * run's caches, of what size. */
typedef struct {
    cbvh_timing_params tp;
    cbvh_timing_units units;
    int cache;       /* index into cbvh_fx_stats.mem */
    double cache_kb; /* 0: none; INFINITY */
} cbvh_machine;

/* Per-ray metrics of a set of rays; with no rays every per-ray value is 0. */
typedef struct {
    uint64_t rays;
    double box, tri, nodes, bytes; /* box tests, triangle tests, inner nodes, bytes read per ray (no cache) */
    double fp_box, fp_tri;         /* the incremental box unit's false-positive box hits and the triangle
                                       tests under them, per ray (0 with the exact unit) */
    double model_ns;               /* the timing model's time per ray (docs/timing_model.md) */
    double energy_nj;              /* the model's energy per ray: units + cache + DRAM */
    double area_lut4;              /* the units' area (instances x LUT4) */
    double dram_bytes;             /* bytes from DRAM per ray (after the cache) */
    double hit_rate;               /* lines found in the cache / lines read (0 without a cache) */
    cbvh_timing_bound bound;       /* what limits the time */
    double cpu_us;                 /* the bit-exact model's own CPU time per ray: the median repetition */
    double cpu_lo, cpu_hi;         /* the fastest and slowest repetition (= cpu_us with one) */
    uint32_t max_stack;            /* deepest stack */
} cbvh_ray_metrics;

/* 0, or -1 when the timing model rejects the parameters (time, energy 0). */
int cbvh_ray_metrics_of(const cbvh_fx_stats *s, const cbvh_machine *mc, cbvh_ray_metrics *m);

/* The timing model's input for a set of rays under cache `cache`. */
void cbvh_fx_timing_work(const cbvh_fx_stats *s, int cache, double cache_kb, cbvh_timing_work *w);

/* CPU time of a against f (the float BVH's, same rays): the median over the
 * repetitions of each repetition's ratio (pairs timed close together), NaN /
 * infinity as cbvh_ratio when f's is 0.  Without repetitions: one pass each. */
double cbvh_fx_cpu_ratio(const cbvh_fx_stats *a, const cbvh_fx_stats *f);

#endif
