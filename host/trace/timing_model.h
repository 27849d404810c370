/* The timing, energy and area model of the traversal accelerator, version 2
 * (docs/timing_model.md): many rays in flight through the hardware units,
 * whose latency, initiation interval, area and energy come from the RTL cost
 * table (trace/cost_table.h); a node and triangle cache (trace/cache_sim.h)
 * before one DRAM interface with a latency and a bandwidth.  Analytic: the
 * time per ray is the larger of the rays' summed latency over the rays in
 * flight (Little's law) and the busiest resource's occupancy; it is checked
 * against a small event-driven simulation (trace/event_sim.h). */
#ifndef CBVH_HOST_TIMING_MODEL_H
#define CBVH_HOST_TIMING_MODEL_H

#include <stdint.h>

#include "trace/cost_table.h"

/* The machine's parameters (defaults and sources: docs/timing_model.md §4). */
typedef struct {
    double clock_mhz;            /* accelerator clock */
    double rays_in_flight;       /* R: rays the unit keeps in flight */
    double dram_bytes_per_cycle; /* sustained DRAM bandwidth */
    double fetch_latency;        /* DRAM latency in cycles (request to data), on a cache miss */
    double cache_hit_latency;    /* cycles from request to data on a hit (a cache present) */
    double cache_ways;           /* associativity */
    double unit_cycle_scale;     /* model cycles per RTL cycle of a unit (1: the RTL's pipeline at the model clock) */
    double issue_width;          /* operations each unit type can start per cycle (instances = ceil(II x width)) */
    double box_cycles, tri_cycles; /* NaN: the cost table; else that unit's latency and II, one instance */
    double dram_pj_per_byte;     /* DRAM energy per byte moved */
    double sram_pj_per_word;     /* cache energy per 64-bit word read at 8 KB (x sqrt(size / 8 KB)) */
    double add_pj_per_bit;       /* ASIC adder energy per bit (the cost table's adder_bits) */
    double mul_pj_per_pp_bit;    /* ASIC multiplier energy per partial-product bit */
} cbvh_timing_params;

/* Ranges: every parameter <= CBVH_TIMING_MAX; latencies and energies >= 0;
 * clock, bandwidth, rays in flight, cycle scale >= CBVH_TIMING_RATE_MIN;
 * issue width a whole number 1..1024;
 * ways 1..64 (whole); box/tri_cycles NaN or >= 0. */
#define CBVH_TIMING_MAX 1e9
#define CBVH_TIMING_RATE_MIN 1e-3

void cbvh_timing_defaults(cbvh_timing_params *p);

/* Overrides "key=value[,key=value...]" with the scene file's timing keys
 * (docs/scenes.md): clock_mhz, rays_in_flight, dram_bytes_per_cycle,
 * fetch_latency, cache_hit_latency, cache_ways, unit_cycle_scale, issue_width,
 * box_cycles, tri_cycles, dram_pj_per_byte, sram_pj_per_word.  0, or -1
 * with a one-line reason (unknown key, not a number); the ranges are
 * cbvh_timing_check's. */
int cbvh_timing_set(cbvh_timing_params *p, const char *spec, char *err, size_t errlen);
/* 0, or -1 with the first parameter out of range named in err. */
int cbvh_timing_check(const cbvh_timing_params *p, char *err, size_t errlen);

/* One hardware unit as the model sees it (model cycles). */
typedef struct {
    int present;      /* 0: the format does not use it */
    double latency;   /* cycles from an operation's input to its result */
    double ii;        /* cycles between operations on one instance */
    double instances; /* ceil(II x issue_width): enough copies to start issue_width operations per cycle */
    double lut4;      /* area of one instance (iCE40 4-input LUTs) */
    double energy_pj; /* per operation (ASIC widths x per-bit energies) */
    char unit[CBVH_COST_UNIT_MAX];
} cbvh_unit_cost;

/* The units a format runs: node (the box unit, or the sphere unit of the
 * traversal lists: what a node read feeds), triangle, node-pair decoder
 * (CBVH) and QBVH stack unit. */
typedef struct {
    cbvh_unit_cost node, tri, dec, qstack;
} cbvh_timing_units;

/* What the units are: node_unit the cost-table name of the node unit
 * ("ray_box", "ray_box_incr", "ray_sphere"); dec / qstack: whether the format
 * runs the decoder ("nodepair_decoder") / the stack unit ("qbvh_stack"); n,
 * m the design point.  0, or -1 with a one-line reason (a unit the table does
 * not have). */
int cbvh_timing_units_for(const cbvh_cost_table *t, const cbvh_timing_params *p, const char *node_unit, int dec,
                          int qstack, int n, int m, cbvh_timing_units *u, char *err, size_t errlen);

/* Counters of a set of rays (summed). */
typedef struct {
    uint64_t rays;
    uint64_t nodes;    /* node reads that feed the node unit (inner nodes visited, list spheres) */
    uint64_t starts;   /* rays whose first node-unit test needs no read (the root box, held on chip) */
    uint64_t node_ops, tri_ops, dec_ops, qstack_ops; /* operations per unit */
    uint64_t steps;    /* dependent reads: node reads and triangle reads */
    uint64_t miss_steps; /* steps with at least one line from DRAM */
    uint64_t lines;    /* 64-byte lines read (looked up in the cache) */
    uint64_t words;    /* 64-bit words read from the cache (the bytes each read needs) */
    uint64_t miss_lines; /* lines from DRAM */
    double cache_kb;   /* 0: no cache; INFINITY: an infinite one */
} cbvh_timing_work;

typedef enum {
    CBVH_BOUND_LATENCY = 0, /* the rays' latency over the rays in flight */
    CBVH_BOUND_NODE,
    CBVH_BOUND_TRI,
    CBVH_BOUND_DEC,
    CBVH_BOUND_QSTACK,
    CBVH_BOUND_DRAM,
    CBVH_BOUND_COUNT
} cbvh_timing_bound;
const char *cbvh_timing_bound_name(cbvh_timing_bound b);

typedef struct {
    double mem_latency;  /* sum over rays: steps x hit latency + miss steps x DRAM latency + missed lines' transfer */
    double unit_latency; /* sum over rays: the units' latency on each ray's chain */
    double occupancy[CBVH_BOUND_COUNT]; /* [LATENCY] = (mem + unit latency) / R; else busy cycles of that resource */
    cbvh_timing_bound bound; /* the largest term */
    double cycles;       /* max over occupancy[] */
    double seconds;      /* cycles / clock */
    double energy_units, energy_sram, energy_dram; /* pJ, all rays */
    double area_lut4;    /* instances x area, units present */
} cbvh_timing_result;

/* 0, or -1 if p is out of range. */
int cbvh_timing_eval(const cbvh_timing_params *p, const cbvh_timing_units *u, const cbvh_timing_work *w,
                     cbvh_timing_result *out);

/* The build side (docs/timing_model.md §7): a streaming pass that moves
 * `bytes` over the DRAM interface, bandwidth-bound, plus `round_trips`
 * dependent DRAM reads one after another (seed 003's backtracking unit
 * works sequentially), each waiting the DRAM latency (its 128 bytes are
 * among `bytes`).  Cycles: bytes / bandwidth + round_trips x latency. */
double cbvh_build_cycles(const cbvh_timing_params *p, double bytes, double round_trips);

/* Cache energy per 64-bit word read, pJ: sram_pj_per_word x sqrt(kb / 8);
 * 0 for no cache and for the infinite (ideal) one. */
double cbvh_timing_word_pj(const cbvh_timing_params *p, double cache_kb);

#endif
