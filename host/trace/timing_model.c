/* Timing model of the traversal accelerator: docs/timing_model.md. */
#include "trace/timing_model.h"

#include <math.h>

void cbvh_timing_defaults(cbvh_timing_params *p) {
    p->box_cycles = 1.0;           /* assumption: fully pipelined box unit, one test issued per cycle */
    p->tri_cycles = 1.0;           /* assumption: fully pipelined triangle unit */
    p->fetch_latency = 100.0;      /* assumption: ~100 ns LPDDR3 round trip at 1 GHz (no paper gives it) */
    p->dram_bytes_per_cycle = 12.8; /* seed 003 Sec. 6: LPDDR3-1600 dual 32-bit channel, 12.8 GB/s at 1 GHz */
    p->clock_mhz = 1000.0;         /* seed 003 Sec. 6: "operating frequency is set at 1GHz" */
}

static int bad(double x, int rate) {
    return !isfinite(x) || x < (rate ? CBVH_TIMING_RATE_MIN : 0) || x > CBVH_TIMING_MAX;
}

int cbvh_timing_eval(const cbvh_timing_params *p, const cbvh_timing_work *w, cbvh_timing_result *o) {
    if (bad(p->box_cycles, 0) || bad(p->tri_cycles, 0) || bad(p->fetch_latency, 0) ||
        bad(p->dram_bytes_per_cycle, 1) || bad(p->clock_mhz, 1))
        return -1;
    o->compute_cycles = (double)w->box_tests * p->box_cycles + (double)w->tri_tests * p->tri_cycles;
    /* Each node-pair fetch and each triangle fetch depends on the test before it. */
    o->latency_cycles = (double)(w->node_fetches + w->tri_tests) * p->fetch_latency;
    o->transfer_cycles = (double)w->bytes / p->dram_bytes_per_cycle;
    o->cycles = o->compute_cycles + o->latency_cycles + o->transfer_cycles;
    o->seconds = o->cycles / (p->clock_mhz * 1e6);
    return 0;
}
