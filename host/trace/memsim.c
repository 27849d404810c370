/* The memory side of the timing model as rays are traced (trace/memsim.h). */
#include "trace/memsim.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/oom.h"

void cbvh_step_log_free(cbvh_step_log *l) {
    free(l->steps);
    free(l->first);
    l->steps = NULL;
    l->first = NULL;
    l->nsteps = l->cap = l->nrays = 0;
    l->open = 0;
}

static uint16_t sat16(uint64_t v) { return v > 65535 ? 65535 : (uint16_t)v; }

/* The operations between the logged ray's last step and counters now. */
static void close_step(cbvh_step_log *l, const cbvh_trav_stats *now) {
    cbvh_step *s = &l->steps[l->nsteps - 1];
    s->node_ops = sat16(now->box_tests - l->last.box_tests);
    s->tri_ops = sat16(now->tri_tests - l->last.tri_tests);
    s->qstack_ops = sat16(now->qstack_pushes + now->qstack_pops - l->last.qstack_pushes - l->last.qstack_pops);
    l->last = *now;
}

static void push_step(cbvh_step_log *l, cbvh_step_kind kind, int miss, uint64_t miss_lines) {
    if (l->nsteps == l->cap) {
        l->cap = l->cap ? 2 * l->cap : 65536;
        l->steps = realloc(l->steps, l->cap * sizeof *l->steps);
        if (!l->steps) cbvh_out_of_memory("timing check steps");
    }
    l->steps[l->nsteps++] = (cbvh_step){(uint8_t)kind, (uint8_t)(miss != 0), sat16(miss_lines), 0, 0, 0};
}

static void on_fetch(void *ctx, cbvh_fetch_kind kind, uint64_t addr, uint64_t size, const cbvh_trav_stats *so_far) {
    cbvh_memsim *M = ctx;
    if (!size) return;
    if (!M->read_seen) { /* the ray's first read: was its root box tested before it? */
        M->read_seen = 1;
        for (int c = 0; c < M->n; c++) M->cur[c].starts += so_far->box_tests > 0;
    }
    uint64_t l0 = addr / 64, l1 = (addr + size - 1) / 64;
    cbvh_step_log *log = M->log && M->log->open ? M->log : NULL;
    for (int c = 0; c < M->n; c++) {
        cbvh_mem_counts *mc = &M->cur[c];
        uint64_t missed = 0;
        for (uint64_t l = l0; l <= l1; l++) missed += !cbvh_cache_access(&M->cache[c], l);
        mc->lines += l1 - l0 + 1;
        mc->words += (addr + size - 1) / 8 - addr / 8 + 1;
        mc->miss_lines += missed;
        int logged = log && c == log->cache;
        if (kind == CBVH_FETCH_IDS) { /* waits with the triangle it names */
            M->pending[c] |= missed > 0;
            if (logged) log->pending_lines += (uint32_t)missed;
            continue;
        }
        int miss = missed > 0 || (kind == CBVH_FETCH_TRI && M->pending[c]);
        mc->steps++;
        mc->miss_steps += miss;
        if (logged) {
            close_step(log, so_far);
            push_step(log, kind == CBVH_FETCH_TRI ? CBVH_STEP_TRI : CBVH_STEP_NODE, miss,
                      missed + (kind == CBVH_FETCH_TRI ? log->pending_lines : 0));
            if (kind == CBVH_FETCH_TRI) log->pending_lines = 0;
        }
        if (kind == CBVH_FETCH_TRI) M->pending[c] = 0;
    }
}

int cbvh_memsim_init(cbvh_memsim *M, const double *kb, int n, uint32_t ways, cbvh_step_log *log, char *err,
                     size_t errlen) {
    memset(M, 0, sizeof *M);
    if (n < 0 || n > CBVH_CACHES_MAX) {
        snprintf(err, errlen, "at most %d cache sizes", CBVH_CACHES_MAX);
        return -1;
    }
    for (int c = 0; c < n; c++) {
        uint64_t bytes = isinf(kb[c]) ? CBVH_CACHE_INFINITE : (uint64_t)(kb[c] * 1024.0 + 0.5);
        if (!(kb[c] >= 0) || (!isinf(kb[c]) && kb[c] > CBVH_CACHE_KB_MAX) ||
            cbvh_cache_init(&M->cache[c], bytes, ways, err, errlen)) {
            if (!(kb[c] >= 0) || (!isinf(kb[c]) && kb[c] > CBVH_CACHE_KB_MAX))
                snprintf(err, errlen, "cache size %g KB out of range 0..%d (or infinite)", kb[c], CBVH_CACHE_KB_MAX);
            cbvh_memsim_free(M);
            return -1;
        }
        M->kb[c] = kb[c];
        M->n = c + 1;
    }
    M->log = log;
    if (log) {
        cbvh_step_log_free(log);
        log->first = calloc((size_t)log->max_rays + 1, sizeof *log->first);
        if (!log->first) cbvh_out_of_memory("timing check rays");
    }
    M->obs = (cbvh_fetch_observer){on_fetch, M};
    return 0;
}

void cbvh_memsim_free(cbvh_memsim *M) {
    for (int c = 0; c < M->n; c++) cbvh_cache_free(&M->cache[c]);
    M->n = 0;
}

void cbvh_memsim_ray_begin(cbvh_memsim *M, cbvh_mem_counts *cur) {
    M->cur = cur;
    M->read_seen = 0;
    memset(M->pending, 0, sizeof M->pending);
    cbvh_step_log *l = M->log;
    if (l && l->nrays < l->max_rays) {
        l->first[l->nrays] = l->nsteps;
        memset(&l->last, 0, sizeof l->last);
        l->pending_lines = 0;
        l->open = 1;
        push_step(l, CBVH_STEP_START, 0, 0);
    }
}

void cbvh_memsim_ray_end(cbvh_memsim *M, const cbvh_trav_stats *final) {
    if (!M->read_seen)
        for (int c = 0; c < M->n; c++) M->cur[c].starts += final->box_tests > 0;
    cbvh_step_log *l = M->log;
    if (l && l->open) {
        close_step(l, final);
        l->open = 0;
        l->first[++l->nrays] = l->nsteps;
    }
}
