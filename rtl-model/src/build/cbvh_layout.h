/* Internal: the CBVH memory layout shared by the top-down and bottom-up
 * compressors, so both write the same pair to the same place. */
#ifndef CBVH_LAYOUT_H
#define CBVH_LAYOUT_H

#include <string.h>

#include "cbvh/cbvh_tree.h"

typedef struct {
    uint32_t *order; /* post-order node indices */
    uint32_t *slot;  /* inner node: its pair index; leaf: its first ID index */
    uint32_t npairs, nids;
} cbvh_layout;

/* Post-order and slots of every node (one traversal).  -1: out of memory or
 * not a tree. */
int cbvh_layout_make(const cbvh_bvh *b, cbvh_layout *l);
/* Only the counts (npairs, nids) from a linear scan, and an uninitialised
 * slot array: for a compressor that assigns slots itself while it walks the
 * tree in post-order (and checks the counts at the end).  order = NULL. */
int cbvh_layout_count(const cbvh_bvh *b, cbvh_layout *l);
void cbvh_layout_free(cbvh_layout *l);

/* Allocates pairs, fills the ID array (if fill_ids; else the caller does,
 * see cbvh_tree_put_ids), sets params, root box and root context.  0 or -1 +
 * reason. */
int cbvh_tree_init(cbvh_tree *t, const cbvh_bvh *b, const cbvh_compress_opts *o, const cbvh_layout *l, int fill_ids,
                   char *err, size_t errlen);

/* IDs of leaf node n at ID index `first` (bit 31 on the last). */
static inline void cbvh_tree_put_ids(cbvh_tree *t, const cbvh_bvh *b, const cbvh_bvh_node *n, uint32_t first) {
    for (uint32_t j = 0; j < n->count; j++)
        t->ids[first + j] = b->prims[n->first + j] | (j + 1 == n->count ? CBVH_ID_LAST : 0u);
}

/* cbvh_f32_of, cbvh_float_of: cbvh/fp32.h */

/* Node-pair input for float node n whose slot is `slot`. */
static inline void cbvh_child_in_of(const cbvh_bvh_node *n, uint32_t slot, cbvh_child_in *in) {
    for (int a = 0; a < 3; a++) in->lo[a] = cbvh_f32_of(n->lo[a]), in->hi[a] = cbvh_f32_of(n->hi[a]);
    in->leaf = cbvh_bvh_is_leaf(n);
    in->empty = 0;
    in->ptr = slot;
}

/* The same for float node c of b, its slot from the layout. */
static inline void cbvh_child_from_node(const cbvh_bvh *b, const cbvh_layout *l, uint32_t c, cbvh_child_in *in) {
    cbvh_child_in_of(&b->nodes[c], l->slot[c], in);
}

/* Inputs of the pair of node x (inner: its two children; a leaf root: the
 * leaf itself and an empty slot). */
static inline void cbvh_pair_inputs(const cbvh_bvh *b, const cbvh_layout *l, uint32_t x, cbvh_child_in in[2]) {
    memset(in, 0, 2 * sizeof *in);
    if (cbvh_bvh_is_leaf(&b->nodes[x])) {
        cbvh_child_from_node(b, l, x, &in[0]);
        in[1].empty = 1;
        return;
    }
    cbvh_child_from_node(b, l, b->nodes[x].child[0], &in[0]);
    cbvh_child_from_node(b, l, b->nodes[x].child[1], &in[1]);
}

static inline void cbvh_child_ctx3(const cbvh_node_ctx *ctx, const cbvh_child_out *o, cbvh_node_ctx *child) {
    for (int a = 0; a < 3; a++) child->axis[a] = cbvh_axis_child_ctx(&ctx->axis[a], &o->axis[a]);
}

#endif
