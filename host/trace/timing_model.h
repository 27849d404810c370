/* A simple timing model of the traversal accelerator (docs/timing_model.md):
 * one ray at a time through pipelined ray-box / ray-triangle units, every
 * dependent memory fetch paying the DRAM latency, bytes moving at the DRAM
 * bandwidth.  Input: the traversal counters of docs/traversal.md §5. */
#ifndef CBVH_HOST_TIMING_MODEL_H
#define CBVH_HOST_TIMING_MODEL_H

#include <stdint.h>

typedef struct {
    double box_cycles;           /* issue cycles per ray-box test */
    double tri_cycles;           /* issue cycles per ray-triangle test */
    double fetch_latency;        /* cycles from request to data, per dependent fetch */
    double dram_bytes_per_cycle; /* sustained DRAM bandwidth */
    double clock_mhz;            /* accelerator clock */
} cbvh_timing_params;

/* Ranges: every parameter <= CBVH_TIMING_MAX; cycles and latency >= 0;
 * bandwidth and clock >= CBVH_TIMING_RATE_MIN (a rate near 0 would make the
 * modelled time overflow to infinity). */
#define CBVH_TIMING_MAX 1e9
#define CBVH_TIMING_RATE_MIN 1e-3

/* Defaults (sources in docs/timing_model.md): 1, 1, 100, 12.8, 1000. */
void cbvh_timing_defaults(cbvh_timing_params *p);

/* Counters of one ray or summed over many rays. */
typedef struct {
    uint64_t box_tests, tri_tests, node_fetches, bytes;
} cbvh_timing_work;

typedef struct {
    double compute_cycles; /* box_tests * box_cycles + tri_tests * tri_cycles */
    double latency_cycles; /* (node_fetches + tri_tests) * fetch_latency */
    double transfer_cycles; /* bytes / dram_bytes_per_cycle */
    double cycles;         /* sum of the three */
    double seconds;        /* cycles / (clock_mhz * 1e6) */
} cbvh_timing_result;

/* 0, or -1 if a parameter is out of the ranges above. */
int cbvh_timing_eval(const cbvh_timing_params *p, const cbvh_timing_work *w, cbvh_timing_result *out);

#endif
