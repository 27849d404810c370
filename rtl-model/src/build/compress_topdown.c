/* Top-down compression of a finished float BVH (the baseline): every pair is
 * encoded once, with its exact traversal context, starting from the root
 * context (cbvh_axis_root_ctx) and descending with cbvh_axis_child_ctx. */
#include <stdio.h>
#include <stdlib.h>

#include "build/cbvh_layout.h"
#include "cbvh/oom.h"

int cbvh_compress_topdown(const cbvh_bvh *b, const cbvh_compress_opts *o, cbvh_tree *out, char *err, size_t errlen) {
    cbvh_layout l;
    if (cbvh_layout_make(b, &l)) {
        snprintf(err, errlen, "cbvh: out of memory");
        return -1;
    }
    if (cbvh_tree_init(out, b, o, &l, 1, err, errlen)) {
        cbvh_layout_free(&l);
        return -1;
    }
    typedef struct {
        uint32_t node;
        cbvh_node_ctx ctx;
    } item;
    item *stack = malloc(((size_t)l.npairs + 2) * sizeof *stack);
    if (!stack) cbvh_out_of_memory("top-down compressor stack");
    uint32_t sp = 0;
    int rc = 0;
    stack[sp++] = (item){b->root, out->root_ctx};
    while (sp) {
        item it = stack[--sp];
        cbvh_child_in in[2];
        cbvh_child_out co[2];
        cbvh_pair_inputs(b, &l, it.node, in);
        uint32_t pair = cbvh_bvh_is_leaf(&b->nodes[it.node]) ? out->root_pair : l.slot[it.node];
        uint32_t st = cbvh_nodepair_encode(&o->params, o->enc, &it.ctx, in, out->pairs + (size_t)pair * out->pair_bytes, co);
        /* OUTSIDE: a child leaves its node's window, i.e. not inside its
         * parent's box (not a BVH); real children never do */
        if (st & (CBVH_ST_REJECT | CBVH_ST_BAD_FORMAT | CBVH_ST_NO_FIT | CBVH_ST_OUTSIDE)) {
            snprintf(err, errlen, "cbvh top-down: pair %u rejected by the encoder (status 0x%x)", pair, st);
            rc = -1;
            break;
        }
        for (int c = 0; c < 2; c++) {
            if (in[c].empty || in[c].leaf) continue;
            item nx = {b->nodes[it.node].child[c], {{{0}}}};
            cbvh_child_ctx3(&it.ctx, &co[c], &nx.ctx);
            stack[sp++] = nx;
        }
    }
    free(stack);
    cbvh_layout_free(&l);
    if (rc) cbvh_tree_free(out);
    return rc;
}
