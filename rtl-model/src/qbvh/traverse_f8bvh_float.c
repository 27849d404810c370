/* Plain floating-point traversal of the float BVH collapsed 8-wide
 * (docs/traversal.md §14): §13's 4-wide traversal (traverse_wide_float.h)
 * with eight boxes per record, so about a third fewer records on a ray's
 * way down. */
#include <stddef.h>

#include "cbvh/f8bvh.h"
#include "qbvh/traverse_wide_float.h"

_Static_assert(sizeof(cbvh_f8bvh_node) == WIDE_REC_BYTES(8) && offsetof(cbvh_f8bvh_node, child) == WIDE_CHILD_AT(8) &&
                   offsetof(cbvh_f8bvh_node, count) == WIDE_COUNT_AT(8) &&
                   offsetof(cbvh_f8bvh_node, valid) == WIDE_VALID_AT(8) && CBVH_F8BVH_LEAF == WIDE_LEAF,
               "the 8-wide record is traverse_wide_float.h's of width 8");

int cbvh_trace_f8bvh_float(const cbvh_f8bvh *f, const cbvh_tri *tris, const cbvh_ray *ray, cbvh_trav_mode mode,
                           cbvh_trav_hit *hit, cbvh_trav_stats *st) {
    const wide_tree w = {(const unsigned char *)f->nodes, f->nnodes, f->root, f->root_count,
                         f->root_box, f->leaf_tris, f->leaf_src, f->prims, f->nprims, f->small_planes};
    return wide_trace_isa(8, &w, tris, ray, mode, hit, st);
}
