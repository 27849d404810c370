/* Pieces the CBVH traversals share (docs/traversal.md §5, §9, §12):
 * the root box test, an inner node's visit and a leaf's triangles.  Internal to rtl-model. */
#ifndef CBVH_TRAVERSE_CBVH_COMMON_H
#define CBVH_TRAVERSE_CBVH_COMMON_H

#include "fast/ray_box_f64.h"
#include "traverse/traverse_common.h"

/* The root's float box: the binary64 filter, else the box unit.  Counts the
 * box test; hit, and t_near in binary64. */
static inline int trav_cbvh_root(trav_state *ts, const cbvh_rbf_ray *fp, const cbvh_tree *t, cbvh_f32 cull,
                                 double *t_near) {
    ts->s.box_tests++;
    double lo[3], hi[3];
    int hit;
    for (int a = 0; a < 3; a++) {
        lo[a] = cbvh_rbf_f32(t->root_lo[a]);
        hi[a] = cbvh_rbf_f32(t->root_hi[a]);
    }
    if (!cbvh_rbf_box(fp, cbvh_rbf_f32(cull), lo, hi, &hit, t_near)) {
        cbvh_box_result r;
        hit = cbvh_ray_box_float_prep(trav_prep(ts), cull, ts->M, t->root_lo, t->root_hi, &r) == 0 && r.hit;
        *t_near = cbvh_rbf_f32(r.t_near);
    }
    return hit;
}

/* An inner node's pair at index ptr: counts the visit and its fetch.  NULL
 * when ptr is out of range or the visits outnumber the pairs (a tree visits
 * each pair at most once per ray: more is a pointer cycle). */
static inline const uint8_t *trav_cbvh_pair(trav_state *ts, const cbvh_tree *t, uint32_t ptr) {
    if (ptr >= t->npairs || ts->s.nodes >= t->npairs) return NULL;
    ts->s.nodes++;
    trav_fetch(ts, CBVH_FETCH_NODE, (uint64_t)ptr * t->pair_bytes, t->pair_bytes);
    return t->pairs + (size_t)ptr * t->pair_bytes;
}

/* A leaf's triangles from ID index `first` to the one marked last (their
 * loads started together: memory latency); then the culling bound, which
 * only an accepted triangle changes.  1 when an any-hit traversal is done. */
static inline int trav_cbvh_leaf(trav_state *ts, const cbvh_tree *t, uint32_t first, cbvh_f32 *cull, double *cull_d) {
    for (uint32_t i = first; i < t->nids; i++) {
        __builtin_prefetch(&ts->tris[t->ids[i] & ~CBVH_ID_LAST]);
        if (t->ids[i] & CBVH_ID_LAST) break;
    }
    for (uint32_t i = first; i < t->nids && !ts->done; i++) {
        trav_fetch(ts, CBVH_FETCH_IDS, ts->ids_base + (uint64_t)i * 4u, 4u);
        trav_triangle(ts, t->ids[i] & ~CBVH_ID_LAST);
        if (t->ids[i] & CBVH_ID_LAST) break;
    }
    *cull = trav_box_tmax(ts);
    *cull_d = cbvh_rbf_f32(*cull);
    return ts->done;
}

#endif
