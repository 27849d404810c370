/* The stack of the plain floating-point traversals (traverse_bvh_float.c,
 * traverse_qbvh_float.c; docs/traversal.md §11, §13).  Internal. */
#ifndef CBVH_TRAVERSE_PLAIN_H
#define CBVH_TRAVERSE_PLAIN_H

#include <stdint.h>

#include "ray_box_ref.h"
#include "traverse_common.h"

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
 * receives the bound. */
static inline int plain_root(trav_state *ts, const cbvh_ref_ray *r, const float root_box[12], double *cull) {
    int h[2];
    double tl[2];
    *cull = cbvh_float_of(trav_box_tmax(ts)); /* no acceptable triangle culled */
    ts->s.box_tests++;
    cbvh_ref_box2_for(r, root_box, *cull, h, tl);
    return h[0];
}

#endif
