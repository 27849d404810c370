/* Shared pieces of the two traversals (docs/traversal.md §5). */
#ifndef CBVH_TRAVERSE_COMMON_H
#define CBVH_TRAVERSE_COMMON_H

#include <string.h>

#include "cbvh/traverse.h"
#include "fast/ray_prep.h"
#include "fast/tri_filter_avx.h"

/* Memory image used for the byte counters: node pairs from address 0, then
 * the primitive-ID array, then the triangles (36 bytes each), each region
 * starting on a line. */
typedef struct {
    const cbvh_ray *ray;
    cbvh_rb_ray prep; /* the ray prepared once for the box unit's fast path */
    cbvh_tri_ray tprep; /* ... and for the triangle unit's filter, at its first triangle */
    int tprep_ready;
    const cbvh_tri *tris;
    cbvh_trav_mode mode;
    int M;
    uint64_t ids_base, tris_base;
    cbvh_trav_hit best;
    cbvh_trav_stats s;
    int done; /* any-hit found */
} trav_state;

/* The ray (every traversal; it has passed cbvh_rb_ray_status, so its o and
 * d are finite, d != 0); its preparation for the triangle unit is made at
 * its first triangle (most rays of a wide view test none). */
static inline void trav_set_ray(trav_state *ts, const cbvh_ray *ray) {
    ts->ray = ray;
    ts->tprep_ready = 0;
}

static inline uint64_t trav_align(uint64_t a) { return (a + CBVH_LINE_BYTES - 1) / CBVH_LINE_BYTES * CBVH_LINE_BYTES; }

/* The start of every traversal: state and hit cleared, the rays the units
 * reject (NaN/Inf, zero direction, bad M) refused with -1 before any unit
 * activity, the ray set and prepared; the memory image has node_bytes of
 * nodes from address 0, then nids 4-byte primitive IDs, then the triangles. */
static inline int trav_begin(trav_state *ts, cbvh_trav_hit *hit, const cbvh_ray *ray, int M, const cbvh_tri *tris,
                             cbvh_trav_mode mode, uint64_t node_bytes, uint64_t nids) {
    /* only what is read before it is written (the state is 360 bytes, most of
     * it the box unit's preparation, made on the first fallback) */
    ts->prep.ray = NULL;
    memset(&ts->best, 0, sizeof ts->best);
    memset(&ts->s, 0, sizeof ts->s);
    ts->done = 0;
    memset(hit, 0, sizeof *hit);
    if (cbvh_rb_ray_status(ray, M)) return -1;
    trav_set_ray(ts, ray);
    ts->tris = tris;
    ts->mode = mode;
    ts->M = M;
    ts->ids_base = trav_align(node_bytes);
    ts->tris_base = trav_align(ts->ids_base + nids * 4u);
    return 0;
}

/* The ray prepared for the box unit's integer fast path, on the first
 * fallback (most rays never need it). */
static inline const cbvh_rb_ray *trav_prep(trav_state *ts) {
    if (!ts->prep.ray) cbvh_rb_prepare(ts->ray, &ts->prep);
    return &ts->prep;
}

/* A read reported to the observer, if one is set (cbvh_trav_set_observer). */
static inline void trav_observe(const trav_state *ts, cbvh_fetch_kind kind, uint64_t addr, uint64_t size) {
    const cbvh_fetch_observer *o = cbvh_trav_observer;
    if (__builtin_expect(o != NULL, 0)) o->fetch(o->ctx, kind, addr, size, &ts->s);
}

/* Lines read; bytes are whole lines, counted once at trav_finish.  The
 * observer sees the same read. */
static inline void trav_fetch(trav_state *ts, cbvh_fetch_kind kind, uint64_t addr, uint64_t size) {
    trav_observe(ts, kind, addr, size);
    ts->s.lines += cbvh_lines_touched(addr, size);
}

/* Upper t for box culling: a triangle is accepted when RD(t) <= X (X = ray
 * tmax, or the best t so far), i.e. t < next_up(X); boxes are kept up to
 * next_up(X) inclusive so no acceptable triangle is ever culled. */
static inline cbvh_f32 trav_box_tmax(const trav_state *ts) {
    cbvh_f32 x = ts->ray->tmax;
    if (ts->best.hit && cbvh_f32_key(ts->best.t) < cbvh_f32_key(x)) x = ts->best.t;
    return x == CBVH_F32_POS_INF ? x : cbvh_f32_next_up(x);
}

/* Triangle id with vertices v (ts->tris[id], or a copy of it). */
static inline void trav_triangle_v(trav_state *ts, uint32_t id, const cbvh_f32 v[3][3]) {
    trav_fetch(ts, CBVH_FETCH_TRI, ts->tris_base + (uint64_t)id * sizeof(cbvh_tri), sizeof(cbvh_tri));
    ts->s.tri_tests++;
    if (!ts->tprep_ready) {
        cbvh_tri_ray_prepare_valid(ts->ray, &ts->tprep);
        ts->tprep_ready = 1;
    }
    cbvh_tri_result r;
#if CBVH_REF_AVX
    /* the wide AVX loop (§15): the unit's filter in lanes decides nearly every
     * triangle without the unit's call; the unit takes the rest */
    int f = cbvh_tri_filter_avx(&ts->tprep, v[0], v[1], v[2], &r, NULL);
    if (f == 1 || (f == 0 && (cbvh_ray_triangle_prepared(&ts->tprep, ts->ray, v[0], v[1], v[2], &r) || !r.hit)))
        return;
#else
    if (cbvh_ray_triangle_prepared(&ts->tprep, ts->ray, v[0], v[1], v[2], &r) || !r.hit) return;
#endif
    int64_t k = cbvh_f32_key(r.t);
    if (k < cbvh_f32_key(ts->ray->tmin) || k > cbvh_f32_key(ts->ray->tmax)) return;
    if ((ts->mode & CBVH_TRAV_FRONT_ONLY) && cbvh_tri_facing(ts->ray->d, v[0], v[1], v[2]) <= 0) return;
    if (ts->best.hit) {
        int64_t kb = cbvh_f32_key(ts->best.t);
        if (k > kb || (k == kb && id >= ts->best.prim)) return;
    }
    ts->best.hit = 1;
    ts->best.prim = id;
    ts->best.t = r.t;
    ts->best.b1 = r.b1;
    ts->best.b2 = r.b2;
    if (ts->mode & CBVH_TRAV_ANY) ts->done = 1;
}

static inline void trav_triangle(trav_state *ts, uint32_t id) {
    cbvh_f32 v[3][3];
    memcpy(v, ts->tris[id].v, sizeof v);
    trav_triangle_v(ts, id, (const cbvh_f32(*)[3])v);
}

/* A ray the units reject (NaN/Inf, zero direction) is an error for the traversal. */
static inline int trav_ray_ok(trav_state *ts, const cbvh_ray *ray, int M) {
    cbvh_f32 lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    cbvh_box_result r;
    cbvh_rb_prepare(ray, &ts->prep);
    return cbvh_ray_box_float_prep(&ts->prep, ray->tmax, M, lo, hi, &r) == 0;
}

static inline void trav_finish(const trav_state *ts, cbvh_trav_hit *hit, cbvh_trav_stats *st) {
    *hit = ts->best;
    st->nodes += ts->s.nodes;
    st->box_tests += ts->s.box_tests;
    st->tri_tests += ts->s.tri_tests;
    st->lines += ts->s.lines;
    st->bytes += ts->s.lines * CBVH_LINE_BYTES;
    if (ts->s.max_stack > st->max_stack) st->max_stack = ts->s.max_stack;
}

#endif
