/* The 4- and 8-wide plain float traversals behind one face, so that a test
 * runs the same checks on both (docs/traversal.md §13, §14).  Header-only. */
#ifndef CBVH_TEST_WIDE_H
#define CBVH_TEST_WIDE_H

#include <string.h>

#include "cbvh/f8bvh.h"
#include "cbvh/qbvh.h"

typedef struct {
    int w8;        /* 0: the QBVH collapse's 4-wide layout, 1: the 8-wide one */
    cbvh_qbvh q;   /* the 4-wide layout's QBVH (the layout points into it) */
    cbvh_fqbvh f4;
    cbvh_f8bvh f8;
} any_wide;

static const char *const wide_name[2] = {"4-wide", "8-wide"};

/* Built in place (the 4-wide layout points to a->q); 0 or -1 with err. */
static inline int aw_build(any_wide *a, int w8, const cbvh_bvh *b, const cbvh_tri *tris, uint32_t ntris, char *err,
                           size_t errlen) {
    memset(a, 0, sizeof *a);
    a->w8 = w8;
    if (w8) return cbvh_f8bvh_build(b, tris, ntris, &a->f8, err, errlen);
    if (cbvh_qbvh_from_bvh(b, &a->q, err, errlen)) return -1;
    if (!cbvh_fqbvh_build(&a->q, tris, ntris, &a->f4, err, errlen)) return 0;
    cbvh_qbvh_free(&a->q);
    return -1;
}

static inline void aw_free(any_wide *a) {
    cbvh_f8bvh_free(&a->f8);
    cbvh_fqbvh_free(&a->f4);
    cbvh_qbvh_free(&a->q);
}

static inline int aw_trace(const any_wide *a, const cbvh_tri *tris, const cbvh_ray *ray, cbvh_trav_mode mode,
                           cbvh_trav_hit *hit, cbvh_trav_stats *st) {
    return a->w8 ? cbvh_trace_f8bvh_float(&a->f8, tris, ray, mode, hit, st)
                 : cbvh_trace_qbvh_float(&a->f4, tris, ray, mode, hit, st);
}

/* records, the leaf copy and its source, and record i's mask, child c and count c */
static inline uint32_t aw_nrecs(const any_wide *a) { return a->w8 ? a->f8.nnodes : a->f4.nnodes; }
static inline const cbvh_cbvh_dtri *aw_leaf_tris(const any_wide *a) {
    return a->w8 ? a->f8.leaf_tris : a->f4.leaf_tris;
}
static inline const cbvh_tri *aw_leaf_src(const any_wide *a) { return a->w8 ? a->f8.leaf_src : a->f4.leaf_src; }
static inline int aw_small(const any_wide *a) { return a->w8 ? a->f8.small_planes : a->f4.small_planes; }
static inline uint32_t aw_valid(const any_wide *a, uint32_t i) {
    return a->w8 ? a->f8.nodes[i].valid : a->f4.nodes[i].valid;
}
static inline uint32_t aw_child(const any_wide *a, uint32_t i, int c) {
    return a->w8 ? a->f8.nodes[i].child[c] : a->f4.nodes[i].child[c];
}
static inline uint32_t aw_count(const any_wide *a, uint32_t i, int c) {
    return a->w8 ? a->f8.nodes[i].count[c] : a->f4.nodes[i].count[c];
}

#endif
