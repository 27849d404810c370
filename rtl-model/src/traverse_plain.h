/* The stack of the plain floating-point traversals (traverse_bvh_float.c,
 * traverse_qbvh_float.c; docs/traversal.md §11, §13).  Internal. */
#ifndef CBVH_TRAVERSE_PLAIN_H
#define CBVH_TRAVERSE_PLAIN_H

#include <stdint.h>

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

#endif
