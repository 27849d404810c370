/* Internal: the two phases of the LBVH builder (build_lbvh.c), shared with
 * the fused LBVH + streaming compression builder (build_lbvh_streaming.c) so
 * that both make the same float BVH node for node.
 *
 * Phase 1, cbvh_lbvh_leaves: validation, Morton codes, sort, distinct codes
 * and the leaves (nodes [m-1, 2m-1), Morton order, primitive order).
 * Phase 2, cbvh_lbvh_hierarchy: the radix tree and the inner boxes in one
 * bottom-up pass (Apetrei 2014, see build_lbvh.c).  Run sequentially over the
 * leaves from left to right, it completes the inner nodes exactly in
 * post-order (child 0's subtree, child 1's subtree, node): a node completes
 * when the climb from the last leaf of its range reaches it, i.e. after its
 * right child, and its left child ended at an earlier leaf.  The hook sees
 * the nodes in that order. */
#ifndef CBVH_LBVH_INTERNAL_H
#define CBVH_LBVH_INTERNAL_H

#include <stdint.h>

#include "cbvh/cbvh_tree.h"

typedef struct {
    cbvh_bvh_node *nodes; /* 2m-1; inner [0, m-1) (root 0), leaves [m-1, 2m-1) */
    uint32_t *prims;      /* n, grouped by leaf */
    uint32_t *ids;        /* with_ids: the CBVH ID array (prims, CBVH_ID_LAST on each leaf's last);
                             n words at the start of buf[1] */
    uint32_t *codes;      /* m distinct codes, ascending (in buf[1], after n words) */
    uint32_t *split;      /* 2(m-1) words of scratch for the hierarchy */
    void *buf[2];         /* what codes and split live in */
    uint32_t n, m;
} cbvh_lbvh_work;

/* Phase 1; with_ids also writes the CBVH ID array as the leaves are made
 * (leaf slots are their first primitive: leaves are in post-order).  0, or -1
 * with the one-line reason of cbvh_build_lbvh (nothing left allocated). */
int cbvh_lbvh_leaves(const cbvh_scene *s, cbvh_lbvh_work *w, int with_ids, char *err, size_t errlen);

/* Hands the nodes to out (root 0) and frees the scratch buffers (with the
 * IDs, unless buf[1] was taken). */
void cbvh_lbvh_finish(cbvh_lbvh_work *w, cbvh_bvh *out);

static inline void cbvh_lbvh_merge_box(cbvh_bvh_node *p, const cbvh_bvh_node *a, const cbvh_bvh_node *b) {
    for (int x = 0; x < 3; x++) {
        p->lo[x] = a->lo[x] < b->lo[x] ? a->lo[x] : b->lo[x];
        p->hi[x] = a->hi[x] > b->hi[x] ? a->hi[x] : b->hi[x];
    }
}

/* Whether the subtree over leaves [lo, hi] (not the whole range) is its
 * parent's left child: its parent splits after hi when the code difference
 * there is the smaller one (Apetrei 2014). */
static inline int cbvh_lbvh_is_left(const uint32_t *codes, uint32_t m, uint32_t lo, uint32_t hi) {
    return lo == 0 || (hi != m - 1 && (codes[hi] ^ codes[hi + 1]) < (codes[lo - 1] ^ codes[lo]));
}

/* Phase 2.  inner(ctx, node) is called for each inner node once its
 * children and box are set (post-order), unless NULL.  Inline so that a
 * constant hook is inlined too. */
static inline void cbvh_lbvh_hierarchy(cbvh_lbvh_work *w, void (*inner)(void *, uint32_t), void *ctx) {
    const uint32_t m = w->m, L = m - 1, *codes = w->codes;
    uint32_t *split = w->split;
    cbvh_bvh_node *nodes = w->nodes;
    /* split[2g] and split[2g+1]: the far range end and node index of the
     * first child to reach split g (between leaves g and g+1); UINT32_MAX =
     * none yet. */
    for (uint32_t g = 0; g + 1 < m; g++) split[2 * g] = UINT32_MAX;
    for (uint32_t i = 0; m > 1 && i < m; i++) {
        uint32_t lo = i, hi = i, x = L + i;
        for (;;) {
            if (lo == 0 && hi == m - 1) break; /* the root (node 0) is done */
            int left = cbvh_lbvh_is_left(codes, m, lo, hi);
            uint32_t g = left ? hi : lo - 1;
            if (split[2 * g] == UINT32_MAX) { /* the sibling is not done yet */
                split[2 * g] = left ? lo : hi;
                split[2 * g + 1] = x;
                break;
            }
            uint32_t other = split[2 * g + 1];
            uint32_t lc = left ? x : other, rc = left ? other : x;
            if (left)
                hi = split[2 * g];
            else
                lo = split[2 * g];
            /* The parent's number: 0 for the root, else its end touching its
             * own parent's split. */
            uint32_t p = lo == 0 && hi == m - 1 ? 0 : cbvh_lbvh_is_left(codes, m, lo, hi) ? hi : lo;
            cbvh_bvh_node *pn = &nodes[p];
            pn->child[0] = lc;
            pn->child[1] = rc;
            pn->first = 0;
            pn->count = 0;
            cbvh_lbvh_merge_box(pn, &nodes[lc], &nodes[rc]);
            if (inner) inner(ctx, p);
            x = p;
        }
    }
}

#endif
