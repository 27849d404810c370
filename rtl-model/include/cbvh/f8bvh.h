/* The float BVH collapsed 8-wide, for the plain floating-point traversal
 * (docs/traversal.md §14): what a software renderer runs on the float BVH
 * with 8-wide nodes (Embree's single-ray kernels on AVX use 8-wide trees).
 * Not a unit and not a model of the accelerator: the software baseline for
 * speed.  Same hit rules as cbvh_trace_bvh, so the closest hit equals the
 * units' bit for bit (ties go to the lowest primitive ID whatever the order)
 * and the any-hit flag too. */
#ifndef CBVH_F8BVH_H
#define CBVH_F8BVH_H

#include <stddef.h>
#include <stdint.h>

#include "cbvh/bvh.h"
#include "cbvh/traverse.h"

#define CBVH_F8BVH_LEAF 0x80000000u /* child entry of a leaf: | its first index into prims */
#define CBVH_F8BVH_MAX_LEAF 65535u  /* primitives in one leaf (the record's count) */

typedef struct {
    float pl[48];      /* plane (0 lower, 1 upper) of axis a of child c at ((plane * 3) + a) * 8 + c */
    uint32_t child[8]; /* inner child: record index; leaf: CBVH_F8BVH_LEAF | first */
    uint16_t count[8]; /* leaf child: its primitive count (1 .. 65535); inner: 0 */
    uint32_t valid;    /* bit c: slot c holds a child (2 to 8 do) */
    uint32_t pad[3];
} cbvh_f8bvh_node;

typedef struct {
    cbvh_f8bvh_node *nodes; /* 64-byte aligned, one per inner node, breadth-first */
    uint32_t nnodes;
    uint32_t root, root_count; /* the root as a child entry */
    float root_box[12];        /* the root's box as child 0 and 1 of a pair (cbvh_ref_box2) */
    const uint32_t *prims;     /* the binary BVH's primitive array (not owned) */
    uint32_t nprims;
    const cbvh_tri *leaf_src;  /* the triangles copied into leaf_tris, or NULL */
    cbvh_cbvh_dtri *leaf_tris; /* nprims records in prims order: a leaf's triangles side by side */
    int small_planes;          /* every plane's magnitude <= 2^62: the binary32 box lanes may run (§16) */
} cbvh_f8bvh;

/* Collapse b (rtl-model/src/qbvh/build_f8bvh.c): each inner record takes up to 8
 * of b's nodes below it by opening the inner child of largest area (the
 * leftmost of equal ones) until there are 8, as the QBVH's collapse does for
 * 4; leaves and boxes are b's.  0, or -1 with a one-line reason (out of
 * memory, a child index outside b, a node reached twice, a leaf outside the
 * primitive array or of more than 65535 primitives).  out->prims points
 * into b, which must outlive out.  With tris (ntris triangles), each leaf's
 * triangles are also copied next to their IDs (40 bytes per primitive);
 * tracing reads the copy only when given the same tris pointer. */
int cbvh_f8bvh_build(const cbvh_bvh *b, const cbvh_tri *tris, uint32_t ntris, cbvh_f8bvh *out, char *err,
                     size_t errlen);
void cbvh_f8bvh_free(cbvh_f8bvh *f);

/* rtl-model/src/qbvh/traverse_f8bvh_float.c.  Stats: nodes = inner records
 * visited, box tests = their children (2..8) plus one for the root, 256
 * bytes (four lines) per node; 0, or -1 (stack overflow, a ray the units
 * reject). */
int cbvh_trace_f8bvh_float(const cbvh_f8bvh *f, const cbvh_tri *tris, const cbvh_ray *ray, cbvh_trav_mode mode,
                           cbvh_trav_hit *hit, cbvh_trav_stats *st);

#endif
