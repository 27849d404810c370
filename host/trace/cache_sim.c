/* Set-associative LRU cache of 64-byte lines (trace/cache_sim.h). */
#include "trace/cache_sim.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/oom.h"

static uint64_t *xcalloc64(uint64_t n) {
    uint64_t *p = calloc((size_t)n, sizeof *p);
    if (!p) cbvh_out_of_memory("cache model");
    return p;
}

int cbvh_cache_init(cbvh_cache *c, uint64_t size, uint32_t ways, char *err, size_t errlen) {
    memset(c, 0, sizeof *c);
    if (ways < 1 || ways > CBVH_CACHE_WAYS_MAX) {
        snprintf(err, errlen, "cache: %u ways, expected 1..%d", ways, CBVH_CACHE_WAYS_MAX);
        return -1;
    }
    c->size = size;
    c->ways = ways;
    if (size == 0) return 0;
    if (size == CBVH_CACHE_INFINITE) {
        c->hcap = 1024;
        c->tag = xcalloc64(c->hcap);
        return 0;
    }
    uint64_t set_bytes = 64u * (uint64_t)ways;
    if (size % set_bytes || size / set_bytes == 0) {
        snprintf(err, errlen, "cache: %llu bytes is not a whole number of %u-way sets of 64-byte lines (%llu bytes)",
                 (unsigned long long)size, ways, (unsigned long long)set_bytes);
        return -1;
    }
    c->nsets = size / set_bytes;
    c->tag = xcalloc64(c->nsets * ways);
    c->used = xcalloc64(c->nsets * ways);
    return 0;
}

void cbvh_cache_free(cbvh_cache *c) {
    free(c->tag);
    free(c->used);
    memset(c, 0, sizeof *c);
}

static uint64_t mix(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9u;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBu;
    return z ^ (z >> 31);
}

/* The infinite cache: has the line been read before?  (Linear probing; the
 * table doubles at half load.) */
static int infinite_access(cbvh_cache *c, uint64_t key) {
    for (uint64_t h = mix(key) & (c->hcap - 1);; h = (h + 1) & (c->hcap - 1)) {
        if (c->tag[h] == key) return 1;
        if (c->tag[h] == 0) {
            c->tag[h] = key;
            break;
        }
    }
    if (++c->hcount * 2 > c->hcap) {
        uint64_t *old = c->tag, ocap = c->hcap;
        c->hcap *= 2;
        c->tag = xcalloc64(c->hcap);
        for (uint64_t i = 0; i < ocap; i++)
            if (old[i]) {
                uint64_t h = mix(old[i]) & (c->hcap - 1);
                while (c->tag[h]) h = (h + 1) & (c->hcap - 1);
                c->tag[h] = old[i];
            }
        free(old);
    }
    return 0;
}

int cbvh_cache_access(cbvh_cache *c, uint64_t line) {
    if (c->size == 0) return 0;
    uint64_t key = line + 1; /* 0 marks an empty way */
    if (c->size == CBVH_CACHE_INFINITE) return infinite_access(c, key);
    uint64_t base = (line % c->nsets) * c->ways, victim = base;
    c->clock++;
    for (uint64_t w = base; w < base + c->ways; w++) {
        if (c->tag[w] == key) {
            c->used[w] = c->clock;
            return 1;
        }
        if (c->used[w] < c->used[victim]) victim = w; /* empty ways have used 0: filled first */
    }
    c->tag[victim] = key;
    c->used[victim] = c->clock;
    return 0;
}
