/* Exact wide dyadic numbers for the traversal units (docs/traversal.md §2).
 *
 * value = (-1)^neg * mag * 2^exp, mag an unsigned integer of up to
 * CBVH_XW_LIMBS 32-bit limbs.  Sums and products of binary32 values are exact
 * in this form; the units only round once, at the end, with cbvh_xw_div_round.
 * This is the model's stand-in for a datapath that is wide enough to be exact
 * (the widths actually needed are listed in docs/traversal.md). */
#ifndef CBVH_EXACT_WIDE_H
#define CBVH_EXACT_WIDE_H

#include <stdint.h>

#include "cbvh/fp32.h"

/* Worst case: the triangle unit's T numerator spans about 1400 bits. */
#define CBVH_XW_LIMBS 72

typedef struct {
    int neg;
    int exp;
    int n;                        /* limbs in use; n == 0 means zero */
    uint32_t m[CBVH_XW_LIMBS];    /* little-endian magnitude, m[n-1] != 0 */
} cbvh_xw;

void cbvh_xw_zero(cbvh_xw *x);
/* Exact value of a finite binary32 pattern. */
void cbvh_xw_from_f32(cbvh_xw *x, cbvh_f32 f);
/* v * 2^exp. */
void cbvh_xw_from_int(cbvh_xw *x, int64_t v, int exp);
static inline int cbvh_xw_sign(const cbvh_xw *x) { return x->n == 0 ? 0 : (x->neg ? -1 : 1); }
void cbvh_xw_add(cbvh_xw *r, const cbvh_xw *a, const cbvh_xw *b);
void cbvh_xw_sub(cbvh_xw *r, const cbvh_xw *a, const cbvh_xw *b);
void cbvh_xw_mul(cbvh_xw *r, const cbvh_xw *a, const cbvh_xw *b);
/* Sign of a - b: -1, 0, 1. */
int cbvh_xw_cmp(const cbvh_xw *a, const cbvh_xw *b);
/* a / b (b != 0) rounded once to `bits` (1..24) significant bits in direction
 * mode, then to binary32 in the same direction (IEEE directed overflow, +0 for
 * zero).  For bits = 24 this is exactly RD/RU of a / b. */
cbvh_f32 cbvh_xw_div_round(const cbvh_xw *a, const cbvh_xw *b, int bits, cbvh_rnd mode);

#endif
