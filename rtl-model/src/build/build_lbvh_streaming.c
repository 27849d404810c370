/* Fused builder: the LBVH (build_lbvh.c) with the bottom-up streaming
 * compression (compress_bottomup.c) done inside its bottom-up pass, as the
 * paper's hardware does.
 *
 * The LBVH's hierarchy pass, run over the leaves from left to right,
 * completes the inner nodes in post-order (lbvh_internal.h), which is the
 * order Algorithm 1 consumes them in.  So each inner node goes to the
 * compressor's step (bu_stream.h, the same code cbvh_compress_bottomup runs)
 * the moment its box is merged, while it and its children are in cache:
 * there is no second walk over the float nodes, no count scan and no slot
 * table.  Slots follow from the LBVH's order: a leaf's IDs start at its
 * first primitive (leaves are in Morton order, which post-order keeps), so
 * the leaves phase writes the ID array as it makes the leaves, into its own
 * scratch buffer (already paged in by the sort); an inner node's pair is its
 * post-order rank, and the children's pair indices are kept on a small stack
 * beside the compressor's context stack.
 *
 * Result and errors are those of cbvh_build_lbvh followed by
 * cbvh_compress_bottomup (tests/build/test_build_streaming.c). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "build/bu_stream.h"
#include "build/cbvh_layout.h"
#include "build/lbvh_internal.h"
#include "cbvh/oom.h"

typedef struct {
    const cbvh_bvh_node *nodes;
    uint32_t L; /* first leaf node */
    cbvh_bu_stream *bu;
    uint32_t *pairs; /* pair indices of finished inner nodes whose parent has not come */
    uint32_t psp, npairs;
    int rc; /* the first compression error stops the compression, not the build */
} fuse_ctx;

static inline void on_inner(void *v, uint32_t x) {
    fuse_ctx *f = v;
    if (f->rc) return;
    const cbvh_bvh_node *n = &f->nodes[x];
    const uint32_t c0 = n->child[0], c1 = n->child[1];
    const cbvh_bvh_node *c[2] = {&f->nodes[c0], &f->nodes[c1]};
    uint32_t slot[2];
    slot[1] = c1 >= f->L ? c[1]->first : f->pairs[--f->psp]; /* child 1 finished last: on top */
    slot[0] = c0 >= f->L ? c[0]->first : f->pairs[--f->psp];
    uint32_t pair = f->npairs++;
    f->pairs[f->psp++] = pair;
    f->rc = cbvh_bu_inner(f->bu, n, c, slot, pair);
}

int cbvh_build_lbvh_streaming(const cbvh_scene *s, const cbvh_compress_opts *o, cbvh_bvh *bvh, cbvh_tree *out,
                              cbvh_bu_stats *stats, char *err, size_t errlen) {
    memset(bvh, 0, sizeof *bvh);
    memset(out, 0, sizeof *out);
    memset(stats, 0, sizeof *stats);
    cbvh_lbvh_work w;
    if (cbvh_lbvh_leaves(s, &w, 1, err, errlen)) return -1;
    /* cbvh_compress_bottomup's checks, in its order. */
    if (o->treelet_depth < 1 || o->treelet_depth > 8) {
        snprintf(err, errlen, "cbvh bottom-up: treelet depth %d outside 1..8", o->treelet_depth);
        cbvh_lbvh_finish(&w, bvh);
        cbvh_bvh_free(bvh);
        return -1;
    }
    const uint32_t m = w.m;
    cbvh_layout l = {NULL, NULL, m == 1 ? 1 : m - 1, w.n};
    /* cbvh_tree_init checks the parameters and the pointer widths and
     * allocates.  The root box is not made yet: it gets a zero box (always
     * accepted once the parameters are), and the real root context is formed
     * and checked at the end, its error taking precedence as there. */
    cbvh_bvh_node zero;
    memset(&zero, 0, sizeof zero);
    zero.count = 1;
    const cbvh_bvh view = {&zero, 1, 0, NULL, 0};
    if (cbvh_tree_init(out, &view, o, &l, 0, err, errlen)) {
        cbvh_lbvh_finish(&w, bvh);
        cbvh_bvh_free(bvh);
        return -1;
    }
    free(out->ids); /* untouched: the leaves phase has written the IDs */
    out->ids = NULL;
    /* When the pairs and the split table both fit the sort's key buffer
     * (8n bytes, paged in already), the pairs go to its start and the split
     * table after them: every pair is written whole by the encoder, and the
     * buffer is shrunk to the pairs at the end. */
    size_t pairs_size = (size_t)l.npairs * out->pair_bytes, keys_pairs = 0;
    if (m > 1 && pairs_size + 8u * (size_t)(m - 1) <= 8u * (size_t)w.n) {
        free(out->pairs);
        out->pairs = w.buf[0];
        w.buf[0] = NULL;
        w.split = (uint32_t *)(out->pairs + pairs_size);
        keys_pairs = 1;
    }
    fuse_ctx f = {w.nodes, m - 1, NULL, malloc((size_t)m * sizeof(uint32_t)), 0, 0, 0};
    if (!f.pairs) cbvh_out_of_memory("streaming build pair buffer");
    f.bu = cbvh_bu_open(o, out, stats, l.npairs, err, errlen);
    cbvh_lbvh_hierarchy(&w, on_inner, &f);
    if (m == 1) f.rc = cbvh_bu_leaf_root(f.bu, &w.nodes[0], 0, out->root_pair);
    cbvh_bu_close(f.bu);
    free(f.pairs);
    /* The IDs fill the start of the leaves phase's scratch buffer; the codes
     * after them are dead now: shrink it (in place) and keep it. */
    uint32_t *ids = realloc(w.buf[1], (size_t)w.n * sizeof *ids);
    out->ids = ids ? ids : (uint32_t *)w.buf[1];
    w.buf[1] = NULL;
    if (keys_pairs) {
        uint8_t *pairs = realloc(out->pairs, pairs_size);
        if (pairs) out->pairs = pairs;
    }
    cbvh_lbvh_finish(&w, bvh);

    int rc = f.rc;
    const cbvh_bvh_node *r = &bvh->nodes[bvh->root];
    for (int a = 0; a < 3; a++) {
        out->root_lo[a] = cbvh_f32_of(r->lo[a]), out->root_hi[a] = cbvh_f32_of(r->hi[a]);
        uint32_t st = cbvh_axis_root_ctx(&o->params, out->root_lo[a], out->root_hi[a], &out->root_ctx.axis[a]);
        if (st) { /* as cbvh_tree_init words it; the compression never ran there */
            snprintf(err, errlen, "cbvh: root box axis %d rejected (status 0x%x)", a, st);
            memset(stats, 0, sizeof *stats);
            rc = -1;
            break;
        }
    }
    if (rc) {
        cbvh_tree_free(out);
        cbvh_bvh_free(bvh);
        return -1;
    }
    return 0;
}
