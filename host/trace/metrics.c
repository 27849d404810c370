/* Counters of traced rays and their per-ray metrics (trace/metrics.h). */
#include "trace/metrics.h"

#include <math.h>
#include <stdlib.h>
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
    sum->fp_box_hits += st->fp_box_hits;
    sum->fp_tri_tests += st->fp_tri_tests;
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
    sum->ops.compressor += s->ops.compressor;
    sum->ops.decoder += s->ops.decoder;
    sum->ops.ray_box += s->ops.ray_box;
    sum->ops.ray_triangle += s->ops.ray_triangle;
    sum->ops.refit += s->ops.refit;
    sum->ops.qbvh_stack += s->ops.qbvh_stack;
    sum->ops.ray_sphere += s->ops.ray_sphere;
    for (int c = 0; c < CBVH_CACHES_MAX; c++) {
        sum->mem[c].steps += s->mem[c].steps;
        sum->mem[c].miss_steps += s->mem[c].miss_steps;
        sum->mem[c].lines += s->mem[c].lines;
        sum->mem[c].words += s->mem[c].words;
        sum->mem[c].miss_lines += s->mem[c].miss_lines;
        sum->mem[c].starts += s->mem[c].starts;
    }
    if (s->nreps > sum->nreps) sum->nreps = s->nreps;
    for (int k = 0; k < s->nreps; k++) sum->cpu_rep[k] += s->cpu_rep[k];
}

void cbvh_fx_timing_work(const cbvh_fx_stats *s, int cache, double cache_kb, cbvh_timing_work *w) {
    memset(w, 0, sizeof *w);
    w->rays = s->rays;
    w->nodes = s->st.nodes;
    w->node_ops = s->ops.ray_box + s->ops.ray_sphere;
    w->tri_ops = s->ops.ray_triangle;
    w->dec_ops = s->ops.decoder / 6; /* six axis decodes per node pair: one pair decoder operation */
    w->qstack_ops = s->ops.qbvh_stack;
    const cbvh_mem_counts *mc = &s->mem[cache >= 0 && cache < CBVH_CACHES_MAX ? cache : 0];
    w->steps = mc->steps;
    w->miss_steps = mc->miss_steps;
    w->lines = mc->lines;
    w->words = mc->words;
    w->miss_lines = mc->miss_lines;
    w->starts = mc->starts;
    w->cache_kb = cache_kb;
}

static int cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n) {
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

int cbvh_ray_metrics_of(const cbvh_fx_stats *s, const cbvh_machine *mc, cbvh_ray_metrics *m) {
    memset(m, 0, sizeof *m);
    m->rays = s->rays;
    m->max_stack = s->st.max_stack;
    cbvh_timing_work w;
    cbvh_fx_timing_work(s, mc->cache, mc->cache_kb, &w);
    cbvh_timing_result tr;
    int rc = cbvh_timing_eval(&mc->tp, &mc->units, &w, &tr);
    if (rc == 0) m->area_lut4 = tr.area_lut4;
    if (!s->rays) return rc;
    double n = (double)s->rays;
    m->box = (double)s->st.box_tests / n;
    m->tri = (double)s->st.tri_tests / n;
    m->nodes = (double)s->st.nodes / n;
    m->bytes = (double)s->st.bytes / n;
    m->fp_box = (double)s->st.fp_box_hits / n;
    m->fp_tri = (double)s->st.fp_tri_tests / n;
    m->dram_bytes = (double)w.miss_lines * 64.0 / n;
    m->hit_rate = w.cache_kb > 0 && w.lines ? 1.0 - (double)w.miss_lines / (double)w.lines : 0;
    if (rc == 0) {
        m->model_ns = tr.seconds * 1e9 / n;
        m->energy_nj = (tr.energy_units + tr.energy_sram + tr.energy_dram) * 1e-3 / n;
        m->bound = tr.bound;
    }
    double v[CBVH_REPS_MAX];
    int k = s->nreps;
    for (int i = 0; i < k; i++) v[i] = s->cpu_rep[i];
    double med = k ? median(v, k) : s->cpu_seconds;
    m->cpu_us = med * 1e6 / n;
    m->cpu_lo = (k ? v[0] : s->cpu_seconds) * 1e6 / n;
    m->cpu_hi = (k ? v[k - 1] : s->cpu_seconds) * 1e6 / n;
    return rc;
}

double cbvh_fx_cpu_ratio(const cbvh_fx_stats *a, const cbvh_fx_stats *f) {
    double v[CBVH_REPS_MAX];
    int k = a->nreps < f->nreps ? a->nreps : f->nreps, n = 0;
    double pa = a->rays ? 1.0 / (double)a->rays : 0, pf = f->rays ? 1.0 / (double)f->rays : 0;
    if (!k) {
        double x = a->cpu_seconds * pa, y = f->cpu_seconds * pf;
        return y > 0 ? x / y : x > 0 ? INFINITY : NAN;
    }
    for (int i = 0; i < k; i++) {
        double x = a->cpu_rep[i] * pa, y = f->cpu_rep[i] * pf;
        if (!(y > 0)) return x > 0 ? INFINITY : NAN;
        v[n++] = x / y;
    }
    return median(v, n);
}
