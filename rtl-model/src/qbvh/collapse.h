/* The collapse rule shared by the wide float BVHs (docs/qbvh.md §3 for the
 * QBVH, docs/traversal.md §14 for the 8-wide layout).  Internal. */
#ifndef CBVH_COLLAPSE_H
#define CBVH_COLLAPSE_H

#include <stdint.h>

#include "cbvh/bvh.h"

/* Up to w (2..8) nodes of b under inner node src: its two children, then
 * the inner one of largest area opened (the leftmost of equal ones: strict >)
 * until there are w, keeping left-to-right order.  Returns how many, or -1
 * if a child index is outside b or (seen != NULL, one byte per node of b,
 * marking every node placed) a node is placed twice: b is not a tree. */
int cbvh_collapse_gather(const cbvh_bvh *b, uint32_t src, int w, uint32_t *out, uint8_t *seen);

#endif
