/* Traversal core: closest-hit and any-hit over the float BVH (reference) and
 * the CBVH (decoding node pairs with the datapath units on the way), using
 * the bit-exact ray-box and ray-triangle units, with per-ray counters.
 * Spec: docs/traversal.md §5. */
#ifndef CBVH_TRAVERSE_H
#define CBVH_TRAVERSE_H

#include <stdint.h>

#include "cbvh/bvh.h"
#include "cbvh/cbvh_tree.h"
#include "cbvh/scene.h"
#include "cbvh/traversal_units.h"

#define CBVH_TRAV_STACK 256 /* entries; deeper trees are an error (-1) */
#define CBVH_LINE_BYTES 64

typedef struct {
    uint64_t nodes;      /* inner nodes whose node pair was fetched */
    uint64_t box_tests;  /* ray-box unit invocations (root box included) */
    uint64_t tri_tests;  /* ray-triangle unit invocations */
    uint64_t lines;      /* 64-byte lines fetched: node pairs, ID-array entries, triangles (no cache) */
    uint64_t bytes;      /* lines * 64 */
    uint32_t max_stack;  /* deepest stack occupancy */
    /* QBVH stack unit (unit 8) operations; 0 for the binary traversals. */
    uint64_t qstack_pushes; /* sort + push operations: one per inner node visited */
    uint64_t qstack_pops;   /* pop operations */
} cbvh_trav_stats;

typedef struct {
    int hit;
    uint32_t prim;       /* triangle index */
    cbvh_f32 t, b1, b2;  /* ray-triangle unit outputs of that triangle */
} cbvh_trav_hit;

/* Bit 0: any hit; bit 1: one-sided (a triangle counts only where
 * cbvh_tri_facing is +1: what back-face culling assumes). */
typedef enum {
    CBVH_TRAV_CLOSEST = 0,
    CBVH_TRAV_ANY = 1,
    CBVH_TRAV_FRONT_ONLY = 2,
    CBVH_TRAV_CLOSEST_FRONT = 2,
    CBVH_TRAV_ANY_FRONT = 3,
} cbvh_trav_mode;

/* Closest hit = the smallest (t bit pattern, triangle index) over all
 * triangles the ray-triangle unit hits with t in [tmin, tmax]; independent of
 * the visiting order because the box unit is conservative (§5).  Any hit = the
 * first such triangle found (hit = 1 iff one exists).
 * mant_bits is the box unit's M.  Stats are added to *st (not cleared).
 * 0, or -1 (stack overflow, decode error, ray rejected by a unit: NaN/Inf,
 * zero direction). */
int cbvh_trace_bvh(const cbvh_bvh *b, const cbvh_tri *tris, const cbvh_ray *ray, int mant_bits, cbvh_trav_mode mode,
                   cbvh_trav_hit *hit, cbvh_trav_stats *st);
int cbvh_trace_cbvh(const cbvh_tree *t, const cbvh_tri *tris, const cbvh_ray *ray, int mant_bits,
                    cbvh_trav_mode mode, cbvh_trav_hit *hit, cbvh_trav_stats *st);

/* Lines covered by [addr, addr + size). */
static inline uint64_t cbvh_lines_touched(uint64_t addr, uint64_t size) {
    return size ? (addr + size - 1) / CBVH_LINE_BYTES - addr / CBVH_LINE_BYTES + 1 : 0;
}

#endif
