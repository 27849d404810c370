/* The CBVH traversed with the incremental ray-box unit (unit 10,
 * docs/traversal.md §17.8) instead of the exact one: each node's plane
 * distances ride on the stack, and its children's come from them (Eq. 5).
 * Same closest and any hit as cbvh_trace_cbvh and the float BVH (the unit is
 * conservative, the triangle test exact); more box hits. */
#ifndef CBVH_TRAVERSE_INCR_H
#define CBVH_TRAVERSE_INCR_H

#include <stdint.h>

#include "cbvh/cbvh_tree.h"
#include "cbvh/ray_box_incr.h"
#include "cbvh/traverse.h"

/* cbvh_trace_cbvh with the incremental unit at M = mant_bits, X = texp (the
 * root's float box still goes through unit 6 at M, as in cbvh_trace_cbvh).
 * The counters are added to *st, with its fp_box_hits (children unit 10 hits
 * that unit 6 at the same M misses) and fp_tri_tests (triangle tests in
 * leaves reached through such a child).  0, or -1 (a ray the units reject, a
 * bad M or X, a stack overflow, a decode error or pointer cycle): no hit. */
int cbvh_trace_cbvh_incr(const cbvh_tree *t, const cbvh_tri *tris, const cbvh_ray *ray, int mant_bits, int texp,
                         cbvh_trav_mode mode, cbvh_trav_hit *hit, cbvh_trav_stats *st);

#endif
