/* The node and triangle cache of the timing model (docs/timing_model.md §3):
 * 64-byte lines, set-associative with LRU replacement, driven by the line
 * addresses the traversals read (cbvh_trav_set_observer).  A size of 0 is
 * no cache (every line comes from DRAM); CBVH_CACHE_INFINITE holds every line
 * it has seen (a miss only on a line's first read). */
#ifndef CBVH_HOST_CACHE_SIM_H
#define CBVH_HOST_CACHE_SIM_H

#include <stddef.h>
#include <stdint.h>

#define CBVH_CACHE_INFINITE UINT64_MAX
#define CBVH_CACHE_KB_MAX 1048576 /* 1 GiB: larger is the infinite cache */
#define CBVH_CACHE_WAYS_MAX 64

typedef struct {
    uint64_t size;  /* bytes; 0 = none; CBVH_CACHE_INFINITE */
    uint32_t ways;  /* associativity (1 = direct mapped); sets = size / (64 * ways) */
    uint64_t nsets;
    uint64_t *tag;  /* nsets * ways line numbers + 1 (0 = empty) */
    uint64_t *used; /* nsets * ways: the access count at the line's last use (LRU) */
    uint64_t clock; /* accesses so far */
    uint64_t hcap, hcount; /* infinite: an open-addressing set of line numbers + 1 in tag */
} cbvh_cache;

/* size in bytes (0, CBVH_CACHE_INFINITE, or a multiple of 64 * ways with
 * at least one set), ways 1 .. CBVH_CACHE_WAYS_MAX.  0, or -1 with a one-line
 * reason (nothing to free). */
int cbvh_cache_init(cbvh_cache *c, uint64_t size, uint32_t ways, char *err, size_t errlen);
void cbvh_cache_free(cbvh_cache *c);

/* A read of 64-byte line `line` (address / 64): 1 = hit, 0 = miss (the line
 * is then filled, evicting its set's least recently used line). */
int cbvh_cache_access(cbvh_cache *c, uint64_t line);

#endif
