/* Event-driven check of the analytic timing model (trace/event_sim.h,
 * docs/timing_model.md §6). */
#include "trace/event_sim.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/oom.h"

/* A unit as one issue port: the next free issue time and the interval. */
typedef struct {
    double free, interval, latency;
} port;

static port port_of(const cbvh_unit_cost *u) {
    port p = {0, 0, 0};
    if (u->present) {
        p.interval = u->ii / u->instances;
        p.latency = u->latency;
    }
    return p;
}

/* n operations issued in order from time t; returns the last result's time
 * (t when n = 0). */
static double issue(port *p, double t, unsigned n) {
    double done = t;
    for (unsigned i = 0; i < n; i++) {
        double at = t > p->free ? t : p->free;
        p->free = at + p->interval;
        t = at + p->interval; /* the ray's next operation goes after this one */
        done = at + p->latency;
    }
    return done;
}

/* Events: a slot's ray is ready for its next step (phase 0) or its step's
 * data has arrived (phase 1).  A binary min-heap on time, ties by sequence. */
typedef struct {
    double t;
    uint64_t seq;
    int slot, phase;
} event;

typedef struct {
    event *e;
    int n;
} heap;

static int before(const event *a, const event *b) { return a->t < b->t || (a->t == b->t && a->seq < b->seq); }

static void heap_push(heap *h, event v) {
    int i = h->n++;
    while (i > 0 && before(&v, &h->e[(i - 1) / 2])) {
        h->e[i] = h->e[(i - 1) / 2];
        i = (i - 1) / 2;
    }
    h->e[i] = v;
}

static event heap_pop(heap *h) {
    event top = h->e[0], last = h->e[--h->n];
    int i = 0;
    for (;;) {
        int c = 2 * i + 1;
        if (c >= h->n) break;
        if (c + 1 < h->n && before(&h->e[c + 1], &h->e[c])) c++;
        if (!before(&h->e[c], &last)) break;
        h->e[i] = h->e[c];
        i = c;
    }
    if (h->n) h->e[i] = last;
    return top;
}

void cbvh_step_log_work(const cbvh_step_log *log, const cbvh_timing_units *u, double cache_kb, cbvh_timing_work *w) {
    memset(w, 0, sizeof *w);
    w->rays = log->nrays;
    w->cache_kb = cache_kb;
    uint64_t end = log->nrays ? log->first[log->nrays] : 0;
    for (uint64_t i = 0; i < end; i++) {
        const cbvh_step *s = &log->steps[i];
        w->node_ops += s->node_ops;
        w->tri_ops += s->tri_ops;
        w->qstack_ops += s->qstack_ops;
        if (s->kind == CBVH_STEP_START) {
            w->starts += s->node_ops > 0;
            continue;
        }
        w->steps++;
        w->miss_steps += s->miss;
        w->miss_lines += s->miss_lines;
        if (s->kind == CBVH_STEP_NODE) w->nodes++;
    }
    if (u->dec.present) w->dec_ops = w->nodes;
}

int cbvh_event_sim(const cbvh_step_log *log, const cbvh_timing_params *p, const cbvh_timing_units *u, double cache_kb,
                   cbvh_event_result *out) {
    memset(out, 0, sizeof *out);
    char err[160];
    if (!log->nrays || cbvh_timing_check(p, err, sizeof err)) return -1;
    int R = (int)floor(p->rays_in_flight + 0.5);
    if (R < 1) R = 1;
    if ((uint64_t)R > log->nrays) R = (int)log->nrays;
    port node = port_of(&u->node), tri = port_of(&u->tri), dec = port_of(&u->dec), qs = port_of(&u->qstack);
    double xfer = 64.0 / p->dram_bytes_per_cycle, chan = 0, hit_lat = cache_kb > 0 ? p->cache_hit_latency : 0;
    uint64_t *cur = malloc((size_t)R * sizeof *cur); /* each slot's next step */
    uint64_t *stop = malloc((size_t)R * sizeof *stop);
    heap h = {malloc((size_t)R * sizeof(event)), 0};
    if (!cur || !stop || !h.e) cbvh_out_of_memory("event simulation");
    uint64_t next_ray = 0, seq = 0, done = 0, done_at_last_start = 0;
    double last = 0, last_start = 0;
    for (int s = 0; s < R; s++) {
        cur[s] = log->first[next_ray];
        stop[s] = log->first[next_ray + 1];
        next_ray++;
        heap_push(&h, (event){0, seq++, s, 0});
    }
    while (h.n) {
        event ev = heap_pop(&h);
        int s = ev.slot;
        if (cur[s] == stop[s]) { /* the ray is done: the slot takes the next one */
            if (ev.t > last) last = ev.t;
            done++;
            if (next_ray == log->nrays) continue;
            if (next_ray + 1 == log->nrays) { /* the last ray starts: the steady state ends */
                last_start = ev.t;
                done_at_last_start = done;
            }
            cur[s] = log->first[next_ray];
            stop[s] = log->first[next_ray + 1];
            next_ray++;
            heap_push(&h, (event){ev.t, seq++, s, 0});
            continue;
        }
        const cbvh_step *st = &log->steps[cur[s]];
        /* Phases, each processed at its own start time so that a unit is
         * claimed only when the ray is there (no reservation in the future):
         * 0 the read, 1 the decoder, 2 the node unit, 3 the triangle unit,
         * 4 + k the k-th stack operation. */
        double t = ev.t;
        int next = ev.phase + 1;
        switch (ev.phase) {
        case 0:
            if (st->kind != CBVH_STEP_START) {
                t += hit_lat;
                if (st->miss) {
                    double start = t > chan ? t : chan;
                    chan = start + st->miss_lines * xfer;
                    t = chan + p->fetch_latency;
                }
            }
            break;
        case 1:
            if (st->kind == CBVH_STEP_NODE && u->dec.present) t = issue(&dec, t, 1);
            break;
        case 2: t = issue(&node, t, st->node_ops); break;
        case 3: t = issue(&tri, t, st->tri_ops); break;
        default:
            if (ev.phase - 4 < (int)st->qstack_ops) t = issue(&qs, t, 1);
            else { /* the step is done */
                cur[s]++;
                out->steps += st->kind != CBVH_STEP_START;
                next = 0;
            }
        }
        heap_push(&h, (event){t, seq++, s, next});
    }
    free(cur);
    free(stop);
    free(h.e);
    out->rays = log->nrays;
    out->cycles = last;
    out->steady = done_at_last_start ? last_start / (double)done_at_last_start * (double)log->nrays : last;
    cbvh_timing_work w;
    cbvh_step_log_work(log, u, cache_kb, &w);
    cbvh_timing_result r;
    if (cbvh_timing_eval(p, u, &w, &r)) return -1;
    out->analytic = r.cycles;
    out->bound = r.bound;
    out->rel_error = last > 0 ? (r.cycles - last) / last : 0;
    out->rel_error_steady = out->steady > 0 ? (r.cycles - out->steady) / out->steady : 0;
    return 0;
}
