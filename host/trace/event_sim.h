/* A small event-driven simulation of the machine the analytic timing model
 * describes (docs/timing_model.md §6), to measure the analytic formula's
 * error: R ray slots take the logged rays (trace/memsim.h) in trace order;
 * each ray runs its steps one after another: a read (cache hit latency; on a
 * miss the DRAM interface, one shared channel at the modelled bandwidth,
 * then the DRAM latency), then the step's operations through the units (each
 * unit one issue port taking an operation every II / instances cycles,
 * results after its latency).  Events are processed in time order, so rays
 * queue for the DRAM channel and for the units.  The hits and misses are the
 * logged ones (the cache simulated in trace order): the check is of the time
 * formula, not of the cache. */
#ifndef CBVH_HOST_EVENT_SIM_H
#define CBVH_HOST_EVENT_SIM_H

#include "trace/memsim.h"
#include "trace/timing_model.h"

typedef struct {
    double cycles;       /* simulated: the last ray's completion (start-up and drain included) */
    double steady;       /* simulated, in steady state: rays x (the time the last ray started / the rays done by
                            then); = cycles if no ray was done before the last one started */
    double analytic;     /* cbvh_timing_eval on the same rays' counts */
    double rel_error;    /* (analytic - cycles) / cycles */
    double rel_error_steady; /* (analytic - steady) / steady */
    cbvh_timing_bound bound; /* the analytic model's limiting term */
    uint64_t rays, steps;
} cbvh_event_result;

/* The logged rays of log on the machine (p, u; cache_kb > 0: a cache, its
 * hit latency applies).  0, or -1 if p is out of range or nothing was
 * logged. */
int cbvh_event_sim(const cbvh_step_log *log, const cbvh_timing_params *p, const cbvh_timing_units *u, double cache_kb,
                   cbvh_event_result *out);

/* The analytic model's input for the logged rays (what it is compared on). */
void cbvh_step_log_work(const cbvh_step_log *log, const cbvh_timing_units *u, double cache_kb, cbvh_timing_work *w);

#endif
