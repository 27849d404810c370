/* Internal: the per-node step of the bottom-up streaming compressor
 * (Algorithm 1, compress_bottomup.c), shared by cbvh_compress_bottomup (which
 * walks a finished float BVH in post-order) and the fused LBVH builder
 * (build_lbvh_streaming.c, which feeds each inner node as the LBVH's
 * bottom-up pass completes it).  One implementation, so both give the same
 * bits and statistics.
 *
 * The caller feeds the inner nodes in post-order (child 0's subtree, child
 * 1's subtree, node), each once both children's boxes are final, with the
 * children's slots (inner: pair index; leaf: first ID index) and its own
 * pair index. */
#ifndef CBVH_BU_STREAM_H
#define CBVH_BU_STREAM_H

#include "cbvh/cbvh_tree.h"

typedef struct cbvh_bu_stream cbvh_bu_stream;

/* A stream writing into t (allocated by cbvh_tree_init for npairs pairs),
 * counting into st (zeroed by the caller).  Aborts when out of memory.
 * Error messages of the steps go to err. */
cbvh_bu_stream *cbvh_bu_open(const cbvh_compress_opts *o, cbvh_tree *t, cbvh_bu_stats *st, uint32_t npairs,
                             char *err, size_t errlen);
void cbvh_bu_close(cbvh_bu_stream *s);

/* Inner node n with children c[0], c[1] (slots slot[0], slot[1]) into pair
 * `pair`.  0, or -1 with the reason in err (the stream is then unusable). */
int cbvh_bu_inner(cbvh_bu_stream *s, const cbvh_bvh_node *n, const cbvh_bvh_node *const c[2], const uint32_t slot[2],
                  uint32_t pair);

/* A root that is itself a leaf (first ID index `slot`): the pair {leaf, empty}. */
int cbvh_bu_leaf_root(cbvh_bu_stream *s, const cbvh_bvh_node *n, uint32_t slot, uint32_t pair);

#endif
