/* Counters of traced rays and their per-ray metrics (trace/metrics.h). */
#include "trace/metrics.h"

#include <string.h>

static void trav_stats_add(cbvh_trav_stats *sum, const cbvh_trav_stats *st) {
    sum->nodes += st->nodes;
    sum->box_tests += st->box_tests;
    sum->tri_tests += st->tri_tests;
    sum->lines += st->lines;
    sum->bytes += st->bytes;
    if (st->max_stack > sum->max_stack) sum->max_stack = st->max_stack;
    sum->qstack_pushes += st->qstack_pushes;
    sum->qstack_pops += st->qstack_pops;
}

void cbvh_fx_stats_add_ray(cbvh_fx_stats *s, cbvh_trav_mode mode, int rejected, int hit, const cbvh_trav_stats *st,
                           double seconds) {
    s->cpu_seconds += seconds;
    s->rays++;
    if (mode & CBVH_TRAV_ANY)
        s->any++;
    else
        s->closest++;
    s->rejected += rejected != 0;
    s->hits += hit != 0;
    trav_stats_add(&s->st, st);
}

void cbvh_fx_stats_add(cbvh_fx_stats *sum, const cbvh_fx_stats *s) {
    sum->rays += s->rays;
    sum->closest += s->closest;
    sum->any += s->any;
    sum->hits += s->hits;
    sum->rejected += s->rejected;
    trav_stats_add(&sum->st, &s->st);
    sum->cpu_seconds += s->cpu_seconds;
}

int cbvh_ray_metrics_of(const cbvh_fx_stats *s, const cbvh_timing_params *tp, cbvh_ray_metrics *m) {
    memset(m, 0, sizeof *m);
    m->rays = s->rays;
    m->max_stack = s->st.max_stack;
    cbvh_timing_work w = {s->st.box_tests, s->st.tri_tests, s->st.nodes, s->st.bytes};
    cbvh_timing_result tr;
    int rc = cbvh_timing_eval(tp, &w, &tr);
    if (!s->rays) return rc;
    double n = (double)s->rays;
    m->box = (double)s->st.box_tests / n;
    m->tri = (double)s->st.tri_tests / n;
    m->nodes = (double)s->st.nodes / n;
    m->bytes = (double)s->st.bytes / n;
    if (rc == 0) m->model_ns = tr.seconds * 1e9 / n;
    m->cpu_us = s->cpu_seconds * 1e6 / n;
    return rc;
}
