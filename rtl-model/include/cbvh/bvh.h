/* Float (binary32) BVHs: the builders' output and the compressors' input.
 *
 * Binary tree, nodes in any order, root at `root`.  A leaf holds the
 * primitive indices prims[first .. first+count). */
#ifndef CBVH_BVH_H
#define CBVH_BVH_H

#include <stddef.h>
#include <stdint.h>

#include "cbvh/scene.h"

typedef struct {
    float lo[3], hi[3];
    uint32_t child[2]; /* inner: node indices */
    uint32_t first;    /* leaf: first index into prims */
    uint32_t count;    /* leaf: > 0 primitives; inner: 0 */
} cbvh_bvh_node;

typedef struct {
    cbvh_bvh_node *nodes;
    uint32_t nnodes;
    uint32_t root;
    uint32_t *prims; /* triangle indices, grouped by leaf */
    uint32_t nprims;
} cbvh_bvh;

static inline int cbvh_bvh_is_leaf(const cbvh_bvh_node *n) { return n->count != 0; }

void cbvh_bvh_free(cbvh_bvh *b);

/* LBVH (Karras 2012 over 30-bit Morton codes of triangle centroids).
 * Triangles with equal Morton codes share one leaf (as the paper assumes for
 * its hardware builder).  0, or -1 with a one-line reason. */
int cbvh_build_lbvh(const cbvh_scene *s, cbvh_bvh *out, char *err, size_t errlen);

/* Binned SAH (Wald 2007): `bins` bins per axis (4..64, 0 = 16), leaves of at
 * most max_leaf primitives (1..64, 0 = 4) unless all centroids coincide. */
int cbvh_build_sah(const cbvh_scene *s, int bins, int max_leaf, cbvh_bvh *out, char *err, size_t errlen);

/* Refit (Wald et al. 2007): recompute every box bottom-up for moved vertices
 * (same triangle count and topology). */
void cbvh_bvh_refit(cbvh_bvh *b, const cbvh_tri *tris);

/* Node indices in post-order (children before parent, left before right):
 * the streaming order of a bottom-up builder.  order has nnodes entries. */
void cbvh_bvh_postorder(const cbvh_bvh *b, uint32_t *order);

/* SAH cost with C_node = 1 and C_tri = 1, areas relative to the root:
 * sum_inner A(n)/A(root) + sum_leaf count * A(n)/A(root).  A degenerate root
 * (zero area) uses the sum of box half-perimeters instead. */
double cbvh_bvh_sah(const cbvh_bvh *b);

/* Structural check: every node reachable once, every primitive in exactly
 * one leaf, every box encloses its children / triangles (a NaN bound never
 * does).  0 or -1 + reason. */
int cbvh_bvh_check(const cbvh_bvh *b, const cbvh_scene *s, char *err, size_t errlen);

/* Leaves and inner nodes reachable from the root. */
void cbvh_bvh_counts(const cbvh_bvh *b, uint32_t *leaves, uint32_t *inner);

#endif
