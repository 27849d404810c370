/* Unit 8: the QBVH traversal's compressed 32-bit stack entry and the sort of
 * the four children's hit times (seed 000, Bogolepov & Ulyanov).  A unit like
 * the others: integer-only, status bits of cbvh/datapath.h, spec and errata
 * of the printed pseudocode in docs/qbvh.md §2.  The QBVH format
 * (cbvh/qbvh.h) takes its entry layout and ID limit from here. */
#ifndef CBVH_QBVH_STACK_H
#define CBVH_QBVH_STACK_H

#include <stdint.h>

#include "cbvh/datapath.h"

/* Entry: bits 25..0 first-child ID, bits 27..26 / 29..28 / 31..30 the offsets
 * o0, o1, o2 (0..3) of the siblings still to visit, near to far.  A missing
 * far sibling repeats the previous offset; an entry is exhausted when the
 * offset after the popped one equals it. */
#define CBVH_QSTACK_ID_BITS 26
#define CBVH_QSTACK_ID_LIMIT (UINT32_C(1) << CBVH_QSTACK_ID_BITS) /* first-child IDs must be below */

/* 5-comparator sorting network (pairs (0,1) (2,3) (0,2) (1,3) (1,2)) on the key
 * (missed, t, index): hit children first, by t (binary32 total order, -0 = +0),
 * ties by child index; then the missed children by child index alone (their
 * t is never read).  order[0] is the nearest child; *nhit = number of hit
 * children.  Status: BAD_PARAM if hit_mask > 15 (checked first), else
 * NAN_INF if a hit child's t is NaN; every output 0 then (docs/qbvh.md §2). */
uint32_t cbvh_qstack_sort(const uint32_t t[4], uint32_t hit_mask, uint8_t order[4], int *nhit);

/* Push: the entry for the deferred children order[1 .. nhit-1] (nhit >= 2;
 * for nhit < 2 nothing is pushed and *entry = 0).  BAD_CODE if
 * first >= 2^26 (never wraps), BAD_PARAM if nhit > 4 or order[] is not a
 * permutation of 0..3; every output 0 then. */
uint32_t cbvh_qstack_push(uint32_t first, const uint8_t order[4], int nhit, uint32_t *entry);

/* Pop: *node = first + o0; *keep = 1 and *next = the shifted entry
 * (o1, o2, o2) if o1 != o0, else *keep = 0 (entry exhausted: drop it) and
 * *next = 0.  Every 32-bit entry is valid input (status 0). */
uint32_t cbvh_qstack_pop(uint32_t entry, uint32_t *node, uint32_t *next, int *keep);

/* The same offset logic on a 64-bit entry (bits 31..0 first-child ID, bits
 * 37..32 the offsets): the "wide entry" for trees past 2^26 nodes. */
uint64_t cbvh_qstack_push_wide(uint32_t first, const uint8_t order[4], int nhit);
uint32_t cbvh_qstack_pop_wide(uint64_t entry, uint64_t *next, int *keep);

#endif
