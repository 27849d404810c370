/* Refit (Wald, Boulos, Shirley 2007): keep the topology, recompute every box
 * bottom-up from the moved triangles.  The streaming variant that also
 * re-encodes the CBVH in the same pass is cbvh_compress_bottomup with
 * refit_tris (compress_bottomup.c). */
#include <math.h>
#include <stdlib.h>

#include "cbvh/bvh.h"
#include "cbvh/oom.h"

static void box_union(float lo[3], float hi[3], const float blo[3], const float bhi[3]) {
    for (int a = 0; a < 3; a++) {
        if (blo[a] < lo[a]) lo[a] = blo[a];
        if (bhi[a] > hi[a]) hi[a] = bhi[a];
    }
}

void cbvh_bvh_refit(cbvh_bvh *b, const cbvh_tri *tris) {
    uint32_t *order = malloc((size_t)b->nnodes * sizeof *order);
    if (!order) cbvh_out_of_memory("refit order");
    cbvh_bvh_postorder(b, order);
    for (uint32_t k = 0; k < b->nnodes; k++) {
        cbvh_bvh_node *n = &b->nodes[order[k]];
        for (int a = 0; a < 3; a++) n->lo[a] = INFINITY, n->hi[a] = -INFINITY;
        if (cbvh_bvh_is_leaf(n)) {
            for (uint32_t j = 0; j < n->count; j++) {
                float lo[3], hi[3];
                cbvh_tri_bounds(&tris[b->prims[n->first + j]], lo, hi);
                box_union(n->lo, n->hi, lo, hi);
            }
        } else {
            for (int c = 0; c < 2; c++) box_union(n->lo, n->hi, b->nodes[n->child[c]].lo, b->nodes[n->child[c]].hi);
        }
    }
    free(order);
}

