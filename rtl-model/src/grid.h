/* Shared steps of the compressor, decoder and estimator (docs/datapath.md,
 * "Grid alignment" and "Child scale"). Internal to rtl-model. */
#ifndef CBVH_GRID_H
#define CBVH_GRID_H

#include "cbvh/datapath.h"

/* Largest alignment shift kept exactly: |k| < 2^24 * 2^37 = 2^61. */
#define CBVH_GRID_EXACT_SHIFT 37

/* alignf(RND_DOWN): k = floor(x / 2^e) for finite x.  When x's own ulp is
 * coarser than 2^(e+37), k is not kept (*huge = 1): then k * 2^e == x exactly
 * and k mod 2^N == 0 for every supported N. */
static inline int64_t cbvh_grid_floor(cbvh_f32 x, int e, int *huge) {
    int sign, exp;
    uint32_t sig;
    cbvh_f32_break(x, &sign, &sig, &exp);
    *huge = 0;
    if (sig == 0) return 0;
    int sh = exp - e;
    if (sh >= 0) {
        if (sh > CBVH_GRID_EXACT_SHIFT) {
            *huge = 1;
            return 0;
        }
        int64_t k = (int64_t)sig * (INT64_C(1) << sh);
        return sign ? -k : k;
    }
    int d = -sh;
    if (d >= 25) return sign ? -1 : 0;
    uint32_t q = sig >> d, rem = sig & ((1u << d) - 1u);
    return sign ? -(int64_t)(q + (rem != 0)) : (int64_t)q;
}

/* Eq. 2 for a box `cells` grid cells wide at scale e (1 <= cells <= 2^N):
 * the smallest k with cells * 2^e <= 2^N * 2^k, clamped to min_scale. */
static inline int cbvh_grid_child_scale(const cbvh_params *p, int e, uint64_t cells) {
    int k = e - p->quant_bits + cbvh_bitlen64(cells - 1);
    return k < p->min_scale ? p->min_scale : k;
}

static inline uint32_t cbvh_grid_mask(const cbvh_params *p) { return (1u << p->quant_bits) - 1u; }

#endif
