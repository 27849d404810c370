/* The memory side of the timing model as rays are traced
 * (docs/timing_model.md §3): the traversals' reads (cbvh_trav_set_observer)
 * run through one simulated cache per modelled size, counted per effect as
 * dependent steps, lines and lines from DRAM (cbvh_mem_counts); and,
 * optionally, each ray's steps in order for the event-driven check
 * (trace/event_sim.h).  Used by host/trace/effects.c. */
#ifndef CBVH_HOST_MEMSIM_H
#define CBVH_HOST_MEMSIM_H

#include <stddef.h>
#include <stdint.h>

#include "cbvh/traverse.h"
#include "trace/cache_sim.h"
#include "trace/metrics.h"

/* One dependent step of a ray (the event-driven check's input). */
typedef enum { CBVH_STEP_START = 0, CBVH_STEP_NODE = 1, CBVH_STEP_TRI = 2 } cbvh_step_kind;
typedef struct {
    uint8_t kind;        /* cbvh_step_kind; START: the ray's on-chip start (the root box test) */
    uint8_t miss;        /* a line of the step (or of the IDs before a triangle) came from DRAM */
    uint16_t miss_lines; /* how many (saturates at 65535) */
    uint16_t node_ops, tri_ops, qstack_ops; /* unit operations after the step's data, before the next step */
} cbvh_step;

/* The steps of the first max_rays rays under cache `cache` of the run:
 * ray i's are steps[first[i] .. first[i + 1]) (first[nrays] = nsteps). */
typedef struct {
    uint64_t max_rays;
    int cache;
    cbvh_step *steps;
    uint64_t nsteps, cap;
    uint64_t *first; /* max_rays + 1 entries once allocated */
    uint64_t nrays;
    /* the ray being logged */
    int open;
    cbvh_trav_stats last; /* its counters at its last step */
    uint32_t pending_lines;
} cbvh_step_log;

void cbvh_step_log_free(cbvh_step_log *l);

typedef struct {
    cbvh_cache cache[CBVH_CACHES_MAX];
    double kb[CBVH_CACHES_MAX];
    int n;
    uint8_t pending[CBVH_CACHES_MAX]; /* an ID read missed: charged to the next triangle step */
    int read_seen;                    /* the ray being traced has read something */
    cbvh_mem_counts *cur;             /* the counters of the effect being traced (n entries) */
    cbvh_step_log *log;               /* optional */
    cbvh_fetch_observer obs;
} cbvh_memsim;

/* n caches of kb[i] KB (0: none, INFINITY: infinite), ways each; log may be
 * NULL.  0, or -1 with a one-line reason. */
int cbvh_memsim_init(cbvh_memsim *M, const double *kb, int n, uint32_t ways, cbvh_step_log *log, char *err,
                     size_t errlen);
void cbvh_memsim_free(cbvh_memsim *M);

/* Around one ray's traversal: its effect's counters before, its own final
 * counters after (they close its logged steps). */
void cbvh_memsim_ray_begin(cbvh_memsim *M, cbvh_mem_counts *cur);
void cbvh_memsim_ray_end(cbvh_memsim *M, const cbvh_trav_stats *final);

#endif
