/* Compressed BVHs (CBVH) built from float BVHs with the datapath units.
 *
 * Layout (docs/study.md):
 *   pairs   node pairs (cbvh_nodepair_bytes(N) each), one per inner node of
 *           the float BVH, in post-order (the streaming order: a pair is
 *           written once both children are done), so the root's pair is the
 *           last one.  A root that is itself a leaf gets one pair
 *           {leaf = root box, empty}.
 *   ids     primitive-ID array; a leaf's pointer is its first index; bit 31
 *           set marks the last ID of a leaf (so IDs are < 2^31).
 *   root    the float root box and its context: cbvh_axis_root_ctx per axis.
 * Decoding pair `root_pair` with root_ctx gives the root's two children;
 * an inner child's pointer is the index of its own pair, and its context is
 * cbvh_axis_child_ctx(parent ctx, decoded axis code). */
#ifndef CBVH_CBVH_TREE_H
#define CBVH_CBVH_TREE_H

#include <stddef.h>
#include <stdint.h>

#include "cbvh/bvh.h"
#include "cbvh/datapath.h"

#define CBVH_ID_LAST 0x80000000u

typedef struct {
    cbvh_params params;
    cbvh_encoding enc;
    cbvh_f32 root_lo[3], root_hi[3];
    cbvh_node_ctx root_ctx;
    uint32_t root_pair;
    size_t pair_bytes;
    uint32_t npairs;
    uint8_t *pairs; /* npairs * pair_bytes */
    uint32_t nids;
    uint32_t *ids;
} cbvh_tree;

void cbvh_tree_free(cbvh_tree *t);

/* Byte size of the CBVH (pairs + IDs); float BVH equivalent for comparison:
 * 64-byte node pairs (two 24-byte boxes + two 4-byte child/leaf words,
 * padded to a cache line half) plus 4 bytes per ID. */
size_t cbvh_tree_bytes(const cbvh_tree *t);
size_t cbvh_bvh_bytes(const cbvh_bvh *b);

/* Options shared by the compressors. */
typedef struct {
    cbvh_params params;
    cbvh_encoding enc;
    /* Bottom-up only. */
    int treelet_depth;  /* M: pairs within M-1 levels below the node being
                           processed are still on chip (1 = no treelets, 2..4) */
    int naive_reencode; /* 1: backtracking re-encodes the decoded box [u, v]
                           as printed in Algorithm 1 (may differ from top-down
                           by one upper cell); 0: re-encodes [u, pred(v)],
                           which equals top-down bit for bit */
} cbvh_compress_opts;

/* Baseline: top-down compression of a finished float BVH. 0 or -1 + reason. */
int cbvh_compress_topdown(const cbvh_bvh *b, const cbvh_compress_opts *o, cbvh_tree *out, char *err, size_t errlen);

#define CBVH_BT_HIST 64
typedef struct {
    uint64_t encodes;           /* pairs encoded by the stream (= inner nodes) */
    uint64_t reencodes;         /* backtracking re-encodes, on chip or not */
    uint64_t backtracks;        /* re-encodes of pairs already in DRAM (depth >= M) */
    uint64_t hist[CBVH_BT_HIST]; /* re-encodes by depth below the processed node
                                    (1 = its child's pair; last bin: deeper) */
    uint64_t naive_nofit;       /* naive_reencode only: repairs, where a grown
                                   upper bound left the node's box (the codes
                                   would wrap) or reached 2^128, and [u, pred(v)]
                                   clipped to the node's box was used instead, or
                                   where a pair whose context kept its scale no
                                   longer decoded alike and was re-encoded */
} cbvh_bu_stats;

/* Bottom-up streaming compression (Algorithm 1): the float BVH's inner nodes
 * are consumed in post-order, each encoded with an estimated context
 * (cbvh_axis_root_ctx of its own box), with a context stack and recursive
 * backtracking when the parent invalidates a child's context (modulo: a
 * scale changed; relative: a scale or lower bound changed).
 * With refit_tris != NULL this is the streaming refit: leaf and inner boxes
 * of b are recomputed from refit_tris in the same pass (b is updated). */
/* st is required (not NULL). */
int cbvh_compress_bottomup(cbvh_bvh *b, const cbvh_tri *refit_tris, const cbvh_compress_opts *o, cbvh_tree *out,
                           cbvh_bu_stats *st, char *err, size_t errlen);

/* Fused streaming build: the LBVH of cbvh_build_lbvh with the bottom-up
 * compression done inside its bottom-up pass (each inner node compressed as
 * the LBVH completes it, in post-order; no second walk).  bvh, out and st are
 * bit for bit those of cbvh_build_lbvh followed by cbvh_compress_bottomup
 * (refit_tris = NULL), and so is the error message.  0, or -1 + reason with
 * bvh and out empty. */
int cbvh_build_lbvh_streaming(const cbvh_scene *s, const cbvh_compress_opts *o, cbvh_bvh *bvh, cbvh_tree *out,
                              cbvh_bu_stats *st, char *err, size_t errlen);

/* Decode the whole CBVH and prove it against its float BVH: the root box and
 * its context are the BVH root's, same topology and leaves, every decoded
 * child box encloses the float box, ID flags right, every pair used once.
 * 0 or -1 + reason (first failure). */
int cbvh_tree_check(const cbvh_tree *t, const cbvh_bvh *b, char *err, size_t errlen);

/* SAH cost of the decoded CBVH (same formula as cbvh_bvh_sah, decoded boxes;
 * the root box is the float root box). -1 on a decode error. */
double cbvh_tree_sah(const cbvh_tree *t);

/* Index of the first differing byte of pairs/ids between two trees (IDs
 * counted after the pairs, 4 bytes each; 0 also when the parameters or the
 * root differ), or -1 if bit-identical (same params, root, pairs and IDs). */
long cbvh_tree_diff(const cbvh_tree *a, const cbvh_tree *b);

#endif
