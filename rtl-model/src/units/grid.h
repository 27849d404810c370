/* Shared steps of the compressor, decoder and estimator (docs/datapath.md,
 * "Grid alignment" and "Child scale"), and the binary32 primitives they are
 * built from.  Internal to rtl-model.
 *
 * Everything here is static inline so that each unit compiles into one
 * straight-line function (bench/bench_datapath.c measures it); the public
 * entry points in fp32.c are thin wrappers around the same code, so there is
 * one definition of every rounding step. */
#ifndef CBVH_GRID_H
#define CBVH_GRID_H

#include "cbvh/datapath.h"

/* Number of significant bits of x (0 for 0); same result as cbvh_bitlen64. */
static inline int cbvh_grid_bitlen(uint64_t x) {
#if defined(__GNUC__)
    return x ? 64 - __builtin_clzll(x) : 0;
#else
    return cbvh_bitlen64(x);
#endif
}

/* The same for x < 2^63, branch-free. */
static inline int cbvh_grid_bitlen63(uint64_t x) {
#if defined(__GNUC__)
    return 63 - __builtin_clzll(2u * x + 1u);
#else
    return cbvh_bitlen64(x);
#endif
}

/* cbvh_params_check, inline. */
static inline uint32_t cbvh_grid_params_check(const cbvh_params *p) {
    if (p->quant_bits < CBVH_N_MIN || p->quant_bits > CBVH_N_MAX) return CBVH_ST_BAD_PARAM;
    if (p->min_scale < CBVH_SCALE_FLOOR || p->min_scale > CBVH_SCALE_CEIL) return CBVH_ST_BAD_PARAM;
    return 0;
}

/* break_float (see cbvh_f32_break). */
static inline void cbvh_grid_break(cbvh_f32 b, int *sign, uint32_t *sig, int *exp) {
    uint32_t e = cbvh_f32_exp_field(b);
    *sign = (int)(b >> 31);
    if (e == 0) {
        *sig = b & CBVH_F32_FRAC;
        *exp = CBVH_F32_SUB_EXP;
    } else {
        *sig = cbvh_f32_normal_sig(b);
        *exp = (int)e - CBVH_F32_ULP_BIAS;
    }
}

/* pack_float (see cbvh_f32_pack). */
static inline cbvh_f32 cbvh_grid_pack(int neg, uint64_t mag, int exp, cbvh_rnd mode) {
    if (mag == 0) return 0;
    int away = neg ? (mode == CBVH_RND_DOWN) : (mode == CBVH_RND_UP);
    int top = exp + cbvh_grid_bitlen(mag) - 1; /* value in [2^top, 2^(top+1)) */
    int lsb = top >= CBVH_F32_EMIN ? top - CBVH_F32_FRAC_BITS : CBVH_F32_SUB_EXP; /* exponent of the result's ulp */
    uint64_t q;
    if (exp >= lsb) {
        q = mag << (exp - lsb); /* exact: fits in 24 bits */
    } else {
        int d = lsb - exp;
        uint64_t rem;
        if (d >= 64) {
            q = 0;
            rem = mag;
        } else {
            q = mag >> d;
            rem = mag & ((UINT64_C(1) << d) - 1);
        }
        if (rem && away) q++;
        if (q == (uint64_t)CBVH_F32_HIDDEN << 1) { /* carry into the next binade */
            q >>= 1;
            lsb++;
        }
    }
    uint32_t sign = neg ? CBVH_F32_SIGN : 0;
    if (q == 0) return away ? (sign | 1u) : 0;                /* below the smallest subnormal */
    if (q < CBVH_F32_HIDDEN) return sign | (uint32_t)q;       /* subnormal (lsb == -149) */
    int biased = lsb + CBVH_F32_ULP_BIAS;
    if (biased >= (int)CBVH_F32_EXP_FIELD_MAX) return away ? (sign | CBVH_F32_POS_INF) : (sign | CBVH_F32_MAX);
    return sign | ((uint32_t)biased << CBVH_F32_FRAC_BITS) | ((uint32_t)q & CBVH_F32_FRAC);
}

/* RD/RU of the integer v times 2^exp. */
static inline cbvh_f32 cbvh_grid_pack_signed(int64_t v, int exp, cbvh_rnd mode) {
    return cbvh_grid_pack(v < 0, v < 0 ? (uint64_t)0 - (uint64_t)v : (uint64_t)v, exp, mode);
}

static inline uint64_t cbvh_grid_mag64(int64_t v) { return v < 0 ? (uint64_t)0 - (uint64_t)v : (uint64_t)v; }

/* floor(v / 2^d) for d >= 0 without relying on signed right shifts. */
static inline int64_t cbvh_grid_floor_shift(int64_t v, int d, int *inexact) {
    if (d == 0) {
        *inexact = 0;
        return v;
    }
    uint64_t m = cbvh_grid_mag64(v);
    if (d >= 63) {
        *inexact = m != 0;
        return v < 0 ? -1 : 0;
    }
    uint64_t q = m >> d, rem = m & ((UINT64_C(1) << d) - 1);
    *inexact = rem != 0;
    if (v >= 0) return (int64_t)q;
    return -(int64_t)(q + (rem != 0));
}

/* Exact a*2^ea + b*2^eb (|a|,|b| < 2^25) rounded once (see cbvh_f32_add_dyadic). */
static inline cbvh_f32 cbvh_grid_add_dyadic(int64_t a, int ea, int64_t b, int eb, cbvh_rnd mode) {
    if (a == 0 && b == 0) return 0;
    if (a == 0) return cbvh_grid_pack(b < 0, cbvh_grid_mag64(b), eb, mode);
    if (b == 0) return cbvh_grid_pack(a < 0, cbvh_grid_mag64(a), ea, mode);
    int ta = ea + cbvh_grid_bitlen(cbvh_grid_mag64(a)), tb = eb + cbvh_grid_bitlen(cbvh_grid_mag64(b));
    if (tb > ta) { /* make a the operand with the higher top bit */
        int64_t t = a;
        a = b;
        b = t;
        int te = ea;
        ea = eb;
        eb = te;
        te = ta;
        ta = tb;
        tb = te;
    }
    int lo = ea < eb ? ea : eb;
    if (ta - lo <= 61) { /* both operands fit aligned in 62 bits: exact */
        int64_t s = a * (INT64_C(1) << (ea - lo)) + b * (INT64_C(1) << (eb - lo));
        return cbvh_grid_pack(s < 0, cbvh_grid_mag64(s), lo, mode);
    }
    /* b lies far below a's significant bits.  Align to unit 2^u, keep the
     * floor of b plus a sticky bit; the result's ulp is >= 2^u, so directed
     * rounding of (sum + sticky/2) equals that of the exact sum. */
    int u = ta - 61, inexact;
    int64_t s = a * (INT64_C(1) << (ea - u)) + cbvh_grid_floor_shift(b, u - eb, &inexact);
    uint64_t m = cbvh_grid_mag64(s) << 1;
    if (inexact) m = s >= 0 ? m + 1 : m - 1;
    return cbvh_grid_pack(s < 0, m, u - 1, mode);
}

/* Largest alignment shift kept exactly: |k| < 2^24 * 2^37 = 2^61. */
#define CBVH_GRID_EXACT_SHIFT 37

/* alignf(RND_DOWN): k = floor(x / 2^e) for finite x.  When x's own ulp is
 * coarser than 2^(e+37), k is not kept (*huge = 1): then k * 2^e == x exactly
 * and k mod 2^N == 0 for every supported N. */
static inline int64_t cbvh_grid_floor(cbvh_f32 x, int e, int *huge) {
    int sign, exp;
    uint32_t sig;
    cbvh_grid_break(x, &sign, &sig, &exp);
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
    int k = e - p->quant_bits + cbvh_grid_bitlen(cells - 1);
    return k < p->min_scale ? p->min_scale : k;
}

static inline uint32_t cbvh_grid_mask(const cbvh_params *p) { return (1u << p->quant_bits) - 1u; }

/* A node's decoded lower bound as a context or compressor input: -Inf is the
 * encoding of -2^128 (section 3), so only NaN and +Inf are faults. */
static inline int cbvh_grid_clb_bad(cbvh_f32 clb) { return cbvh_f32_is_nan_or_inf(clb) && clb != CBVH_F32_NEG_INF; }

/* floor(x / 2^e) 2^e, the grid line at or below a finite x (or -Inf =
 * -2^128): a binary32 value (section 3), or -Inf for -2^128, and x itself
 * when the coordinate is "huge" (then x is a multiple of 2^e); -0 gives +0. */
static inline cbvh_f32 cbvh_grid_below(cbvh_f32 x, int e) {
    int huge;
    int64_t k = cbvh_grid_floor(x, e, &huge);
    return huge ? (cbvh_f32_is_zero(x) ? 0u : x) : cbvh_grid_pack_signed(k, e, CBVH_RND_DOWN);
}

#endif
