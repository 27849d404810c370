/* The stack of the plain floating-point traversals (traverse_bvh_float.c,
 * traverse_qbvh_float.c; docs/traversal.md §11, §13).  Internal. */
#ifndef CBVH_TRAVERSE_PLAIN_H
#define CBVH_TRAVERSE_PLAIN_H

#include <stdint.h>

#include "fast/ray_box_ref.h"
#include "traverse/traverse_common.h"

/* A child entry as in the records (a record index, or a leaf flag | first
 * and the count) and the lower bound of its entry t. */
typedef struct {
    uint32_t entry, count;
    double t_lo;
} plain_entry;

static inline void plain_push(plain_entry *stack, int *sp, uint32_t entry, uint32_t count, double t_lo) {
    plain_entry *p = &stack[(*sp)++];
    p->entry = entry;
    p->count = count;
    p->t_lo = t_lo;
}

/* Pop the next entry not culled since it was pushed (t_lo > cull: dropped);
 * 1 with it in *entry, *count, 0 when the stack is empty. */
static inline int plain_pop(const plain_entry *stack, int *sp, double cull, uint32_t *entry, uint32_t *count) {
    while (*sp > 0) {
        const plain_entry *p = &stack[--*sp];
        if (p->t_lo > cull) continue;
        *entry = p->entry;
        *count = p->count;
        return 1;
    }
    return 0;
}

/* The root's box test (one box test counted) with §5's culling bound, the
 * same for every plain traversal: 1 if the ray may meet the root.  *cull
 * receives the bound.  In binary32 lanes for a small ray (r->small: only
 * where the tree's planes are small too, §16), else in binary64. */
static inline int plain_root(trav_state *ts, const cbvh_ref_ray *r, const float root_box[12], double *cull) {
    int h[2];
    double tl[2];
    *cull = cbvh_float_of(trav_box_tmax(ts)); /* no acceptable triangle culled */
    ts->s.box_tests++;
    if (r->small) return cbvh_ref_box32_one(r, root_box, r->pn, r->pf, (float)*cull, tl);
    cbvh_ref_box2_for(r, root_box, *cull, h, tl);
    return h[0];
}

/* A leaf's cnt triangles from prims[first]: read from the leaf copy lt when
 * given (the same triangles side by side), else through the ID array.
 * Returns 1 when an any-hit traversal is done, else 0 with *cull the
 * culling bound after them. */
static inline int plain_leaf(trav_state *ts, uint32_t first, uint32_t cnt, const cbvh_cbvh_dtri *lt,
                             const uint32_t *prims, double *cull) {
    trav_fetch(ts, CBVH_FETCH_IDS, ts->ids_base + (uint64_t)first * 4u, (uint64_t)cnt * 4u);
    if (lt) {
        for (uint32_t i = 0; i < cnt && !ts->done; i++)
            trav_triangle_v(ts, lt[first + i].id, (const cbvh_f32(*)[3])lt[first + i].v);
    } else {
        for (uint32_t i = 0; i < cnt && !ts->done; i++) trav_triangle(ts, prims[first + i]);
    }
    if (ts->done) return 1;
    *cull = cbvh_float_of(trav_box_tmax(ts));
    return 0;
}

/* The end of a plain traversal: its loop's counters into the state, then
 * trav_finish. */
static inline void plain_finish(trav_state *ts, uint64_t nodes, uint64_t boxes, uint64_t lines, uint32_t max_stack,
                                cbvh_trav_hit *hit, cbvh_trav_stats *st) {
    ts->s.nodes += nodes;
    ts->s.box_tests += boxes;
    ts->s.lines += lines;
    ts->s.max_stack = max_stack;
    trav_finish(ts, hit, st);
}

#endif
