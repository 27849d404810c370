/* Fast paths of the datapath units for the common case, inline, so that the
 * streaming compressor (compress_bottomup.c) can run them without a call per
 * axis.  Internal to rtl-model.
 *
 * Each function either handles its input completely (returns nonzero) and
 * then gives exactly the unit's outputs, or returns 0 and the caller must
 * use the unit itself (its general path covers every input).  The units call
 * the same code, so there is one definition of each fast path.
 * tests/model/test_unit_fast.c checks them against the units' general paths
 * on millions of inputs (signs, zeros, subnormals, huge exponents, the
 * min-scale clamp, N = 3..10). */
#ifndef CBVH_UNIT_FAST_H
#define CBVH_UNIT_FAST_H

#include "cbvh/datapath.h"
#include "units/grid.h"

/* Widest exponent distance the estimator aligns exactly: significands
 * (< 2^24) shifted by up to 38 bits stay below 2^62, so the difference of
 * two stays below 2^63. */
#define CBVH_WIDTH_SPAN 38

/* floor(v / 2^d) for |v| < 2^62 and d >= 0, by the offset trick (no signed
 * right shift): floor(v / 2^d) = ((v + 2^62) >> d) - 2^(62 - d) for d <= 62,
 * and -1 or 0 beyond (the same as at d = 62). */
static inline int64_t cbvh_fast_floor_shift(int64_t v, int d) {
    d = d > 62 ? 62 : d; /* beyond 62 the floor stays -1 or 0 */
    return (int64_t)(((uint64_t)(v + (INT64_C(1) << 62)) >> d) - ((UINT64_C(1) << 62) >> d));
}

/* Scale estimator (unit 1), fast path: both bounds normal, lb < ub,
 * exponents at most 38 apart; n = N and ms = min_scale already validated.
 * Sets *scale to what cbvh_scale_estimate returns (status 0).  With
 * k != NULL it also sets *k = floor(lb / 2^scale) and *ku = floor(ub / 2^scale)
 * (exact, |.| < 2^62) and returns 2, or returns 1 when the grid is finer
 * than the bounds' common alignment (k not computed).  0: not handled. */
static inline int cbvh_scale_estimate_fast_nm(int n, int ms, cbvh_f32 lb, cbvh_f32 ub, int *scale, int64_t *k,
                                              int64_t *ku) {
    uint32_t el = cbvh_f32_exp_field(lb), eu = cbvh_f32_exp_field(ub);
    int dx = (int)el - (int)eu;
    if (cbvh_f32_field_not_normal(el) || cbvh_f32_field_not_normal(eu) ||
        (uint32_t)(dx + CBVH_WIDTH_SPAN) > 2u * CBVH_WIDTH_SPAN)
        return 0;
    int64_t ml = (int64_t)cbvh_f32_normal_sig(lb), mu = (int64_t)cbvh_f32_normal_sig(ub);
    int xlo = (int)(dx < 0 ? el : eu) - CBVH_F32_ULP_BIAS; /* the lower exponent */
    int64_t vl = (lb & CBVH_F32_SIGN ? -ml : ml) * (INT64_C(1) << (dx > 0 ? dx : 0));
    int64_t vu = (ub & CBVH_F32_SIGN ? -mu : mu) * (INT64_C(1) << (dx < 0 ? -dx : 0));
    if (vl >= vu) return 0; /* inverted or a point */
    int e0 = cbvh_grid_bitlen((uint64_t)(vu - vl)) + xlo - n;
    if (e0 < ms) e0 = ms;
    /* Both bounds are integers at 2^xlo: lb = vl 2^xlo, ub = vu 2^xlo, and
     * w = ub - lb < 2^(e0 + N) by the choice of e0, so with
     * cells(e) = floor(ub/2^e) + 1 - floor(lb/2^e) in (w/2^e, w/2^e + 2),
     * no e < e0 fits and e0 + 1 always fits (docs/datapath.md, unit 1).
     * cells(e0) = floor(vu / 2^d) + 1 - floor(vl / 2^d), d = e0 - xlo.
     * With |v| < 2^62, floor(v / 2^d) = ((v + 2^62) >> d) - 2^(62 - d) for
     * d <= 62 (the offsets cancel in the difference), and every d >= 62
     * gives the same floors (-1 or 0).  d <= 0: always fits. */
    int d = e0 - xlo;
    int dc = d > 62 ? 62 : d < 0 ? 0 : d;
    uint64_t ou = (uint64_t)(vu + (INT64_C(1) << 62)) >> dc, ol = (uint64_t)(vl + (INT64_C(1) << 62)) >> dc;
    int fit = d <= 0 || ou - ol + 1u <= (UINT64_C(1) << n);
    *scale = fit ? e0 : e0 + 1;
    if (!k || d < 0) return 1;
    /* the floors at e0, then one step coarser when e0 did not fit:
     * floor(floor(v / 2^d) / 2) = floor(v / 2^(d+1)) */
    uint64_t off = (UINT64_C(1) << 62) >> dc;
    int64_t k0 = (int64_t)(ol - off), ku0 = (int64_t)(ou - off);
    *k = fit ? k0 : cbvh_fast_floor_shift(k0, 1);
    *ku = fit ? ku0 : cbvh_fast_floor_shift(ku0, 1);
    return 2;
}

/* The unit's entry: parameters checked here. */
static inline int cbvh_scale_estimate_fast(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, int *scale) {
    int n = p->quant_bits, ms = p->min_scale;
    if ((uint32_t)(n - CBVH_N_MIN) > (uint32_t)(CBVH_N_MAX - CBVH_N_MIN) || ms < CBVH_SCALE_FLOOR ||
        ms > CBVH_SCALE_CEIL)
        return 0;
    return cbvh_scale_estimate_fast_nm(n, ms, lb, ub, scale, NULL, NULL);
}

/* The compressor's (unit 2) integer part for a box [lb, ub] whose grid
 * coordinates at scale e are known exactly: k = floor(lb / 2^e),
 * ku = floor(ub / 2^e), lb <= ub, e in [min_scale, 126]; n = N and
 * ms = min_scale.  When the box fits (ku + 1 - k <= 2^N) this sets the codes
 * and child scale exactly as cbvh_axis_compress does and returns 1; else
 * returns 0.  (clb and cub are RD(k 2^e) and RU((ku + 1) 2^e):
 * cbvh_grid_pack_signed, when needed.) */
static inline int cbvh_fast_code(int n, int ms, int e, int64_t k, int64_t ku, uint32_t *lb_mod, uint32_t *ub_mod,
                                 int *child_scale) {
    uint64_t cells = (uint64_t)(ku + 1 - k); /* 1 .. 2^62 */
    uint32_t mask = (1u << n) - 1u;
    *lb_mod = (uint32_t)(uint64_t)k & mask;
    *ub_mod = (uint32_t)(uint64_t)(ku + 1) & mask;
    int cs = e - n + cbvh_grid_bitlen63(cells - 1u);
    *child_scale = cs < ms ? ms : cs;
    return cells - 1u < (UINT64_C(1) << n); /* 1 <= cells <= 2^N */
}

/* Little-endian stores (compilers merge them into one store). */
static inline void cbvh_fast_store_le64(uint8_t *b, uint64_t v) {
    b[0] = (uint8_t)v, b[1] = (uint8_t)(v >> 8), b[2] = (uint8_t)(v >> 16), b[3] = (uint8_t)(v >> 24);
    b[4] = (uint8_t)(v >> 32), b[5] = (uint8_t)(v >> 40), b[6] = (uint8_t)(v >> 48), b[7] = (uint8_t)(v >> 56);
}
static inline void cbvh_fast_store_le32(uint8_t *b, uint32_t v) {
    b[0] = (uint8_t)v, b[1] = (uint8_t)(v >> 8), b[2] = (uint8_t)(v >> 16), b[3] = (uint8_t)(v >> 24);
}

/* Node-pair layout (nodepair_codec.c): one node of W = 64 (N <= 6) or 96
 * bits, little endian: codes (lower, upper) per axis at bits 2aN and
 * 2aN + N (here already packed in `codes`, bits [0, 6N)), leaf bit at 6N,
 * pointer of P = min(32, W - 6N - 1) bits from 6N + 1, zero after;
 * ptr < 2^P. */
static inline void cbvh_fast_put_node(int n, uint64_t codes, int leaf, uint32_t ptr, uint8_t *bytes) {
    int pp = 6 * n + 1; /* pointer position: 19 .. 61 */
    uint64_t w0 = codes | (uint64_t)(leaf != 0) << (pp - 1) | (uint64_t)ptr << pp; /* N <= 6: P bits fit */
    cbvh_fast_store_le64(bytes, w0);
    if (n > 6) cbvh_fast_store_le32(bytes + 8, (uint32_t)((uint64_t)ptr >> (64 - pp))); /* the rest of 96 bits */
}

/* An unsigned key that orders the finite nonzero binary32 values (negative
 * patterns inverted): a < b iff key(a) < key(b).  -0 sorts below +0, so a
 * fast path that takes only key(lb) <= key(ub) sends [+0, -0] (a valid
 * point box) to the general path. */
static inline uint32_t cbvh_fast_order_key(cbvh_f32 x) { return x ^ ((0u - (x >> 31)) >> 1) ^ CBVH_F32_SIGN; }

/* Whether the grid step 2^e lies inside the significand of x: x normal and
 * d = e - (lsb exponent of x) in [1, 23], d returned as unsigned.  Then
 * 2^e <= |x| < 2^(e+24), so floor(x / 2^e) is nonzero and below 2^24 in
 * magnitude. */
static inline int cbvh_fast_in_sig(cbvh_f32 x, int e, uint32_t *d) {
    uint32_t ex = cbvh_f32_exp_field(x);
    *d = (uint32_t)(e + CBVH_F32_ULP_BIAS) - ex;
    return !(cbvh_f32_field_not_normal(ex) | (*d - 1u > CBVH_F32_FRAC_BITS - 1u));
}

/* floor(x / 2^e) when cbvh_fast_in_sig(x, e, &d): floor(v / 2^d) of the
 * signed significand v by the offset trick, as cbvh_fast_floor_shift. */
static inline int64_t cbvh_fast_floor_in_sig(cbvh_f32 x, uint32_t d) {
    uint32_t s = 0u - (x >> 31);                                      /* all ones if negative */
    uint32_t v = ((cbvh_f32_normal_sig(x) ^ s) - s) + (1u << 30);    /* signed significand + 2^30 */
    return (int64_t)(v >> d) - (int64_t)((1u << 30) >> d);
}

/* floor(x / 2^e) 2^e, the grid line at or below x, when
 * cbvh_fast_in_sig(x, e, &d): x with its d low significand bits cleared
 * (x > 0), or its magnitude rounded up to a multiple of 2^d in the bit
 * pattern (x < 0; a carry moves into the exponent field and gives the exact
 * power of two, or the -Inf pattern for -2^128).  Exact: it is the binary32
 * value k 2^e itself (or -Inf for -2^128, which is RD of it). */
static inline cbvh_f32 cbvh_fast_grid_below_in_sig(cbvh_f32 x, uint32_t d) {
    uint32_t low = (1u << d) - 1u, s = 0u - (x >> 31);
    return (((x & ~CBVH_F32_SIGN) + (low & s)) & ~low) | (x & CBVH_F32_SIGN);
}

/* floor(x / 2^e) for a finite x and e in [-126, 126]: exact, or 0 when x's
 * lsb lies more than 37 binades above 2^e (cbvh_grid_floor's "huge").  Fast
 * when cbvh_fast_in_sig. */
static inline int cbvh_fast_floor(cbvh_f32 x, int e, int64_t *k) {
    uint32_t d;
    if (!cbvh_fast_in_sig(x, e, &d)) {
        int huge;
        *k = cbvh_grid_floor(x, e, &huge);
        return !huge;
    }
    *k = cbvh_fast_floor_in_sig(x, d);
    return 1;
}

#endif
