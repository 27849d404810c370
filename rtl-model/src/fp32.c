/* binary32 bit-pattern arithmetic used by every unit (docs/datapath.md,
 * "Number formats").  Integer only: no float type appears in this file. */
#include "cbvh/fp32.h"

void cbvh_f32_break(cbvh_f32 b, int *sign, uint32_t *sig, int *exp) {
    uint32_t e = (b >> 23) & 0xFFu;
    *sign = (int)(b >> 31);
    if (e == 0) {
        *sig = b & CBVH_F32_FRAC;
        *exp = -149;
    } else {
        *sig = (b & CBVH_F32_FRAC) | 0x800000u;
        *exp = (int)e - 150;
    }
}

/* Fast bit length for the hot path (values below 2^64). */
static int top_bit(uint64_t x) {
#if defined(__GNUC__)
    return x ? 64 - __builtin_clzll(x) : 0;
#else
    return cbvh_bitlen64(x);
#endif
}

cbvh_f32 cbvh_f32_pack(int neg, uint64_t mag, int exp, cbvh_rnd mode) {
    if (mag == 0) return 0;
    int away = neg ? (mode == CBVH_RND_DOWN) : (mode == CBVH_RND_UP);
    int top = exp + top_bit(mag) - 1;          /* value in [2^top, 2^(top+1)) */
    int lsb = top >= -126 ? top - 23 : -149;   /* exponent of the result's ulp */
    uint64_t q;
    if (exp >= lsb) {
        q = mag << (exp - lsb);                /* exact: fits in 24 bits */
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
        if (q == (UINT64_C(1) << 24)) { /* carry into the next binade */
            q >>= 1;
            lsb++;
        }
    }
    uint32_t sign = neg ? CBVH_F32_SIGN : 0;
    if (q == 0) return away ? (sign | 1u) : 0; /* below the smallest subnormal */
    if (q < (UINT64_C(1) << 23)) return sign | (uint32_t)q; /* subnormal (lsb == -149) */
    int biased = lsb + 150;
    if (biased >= 255) return away ? (sign | CBVH_F32_POS_INF) : (sign | CBVH_F32_MAX);
    return sign | ((uint32_t)biased << 23) | ((uint32_t)q & CBVH_F32_FRAC);
}

static uint64_t mag64(int64_t v) { return v < 0 ? (uint64_t)0 - (uint64_t)v : (uint64_t)v; }

/* floor(v / 2^d) for d >= 0 without relying on signed right shifts. */
static int64_t floor_shift(int64_t v, int d, int *inexact) {
    if (d == 0) { *inexact = 0; return v; }
    uint64_t m = mag64(v);
    if (d >= 63) {
        *inexact = m != 0;
        return v < 0 ? -1 : 0;
    }
    uint64_t q = m >> d, rem = m & ((UINT64_C(1) << d) - 1);
    *inexact = rem != 0;
    if (v >= 0) return (int64_t)q;
    return -(int64_t)(q + (rem != 0));
}

cbvh_f32 cbvh_f32_add_dyadic(int64_t a, int ea, int64_t b, int eb, cbvh_rnd mode) {
    if (a == 0 && b == 0) return 0;
    if (a == 0) return cbvh_f32_pack(b < 0, mag64(b), eb, mode);
    if (b == 0) return cbvh_f32_pack(a < 0, mag64(a), ea, mode);
    int ta = ea + top_bit(mag64(a)), tb = eb + top_bit(mag64(b));
    if (tb > ta) { /* make a the operand with the higher top bit */
        int64_t t = a; a = b; b = t;
        int te = ea; ea = eb; eb = te;
        te = ta; ta = tb; tb = te;
    }
    int lo = ea < eb ? ea : eb;
    if (ta - lo <= 61) { /* both operands fit aligned in 62 bits: exact */
        int64_t s = a * (INT64_C(1) << (ea - lo)) + b * (INT64_C(1) << (eb - lo));
        return cbvh_f32_pack(s < 0, mag64(s), lo, mode);
    }
    /* b lies far below a's significant bits.  Align to unit 2^u, keep the
     * floor of b plus a sticky bit; the result's ulp is >= 2^u, so directed
     * rounding of (sum + sticky/2) equals that of the exact sum. */
    int u = ta - 61, inexact;
    int64_t s = a * (INT64_C(1) << (ea - u)) + floor_shift(b, u - eb, &inexact);
    uint64_t m = mag64(s) << 1;
    if (inexact) m = s >= 0 ? m + 1 : m - 1;
    return cbvh_f32_pack(s < 0, m, u - 1, mode);
}

int cbvh_f32_cmp(cbvh_f32 a, cbvh_f32 b) {
    /* map to a monotone signed key; both zeros map to 0 */
    int64_t ka = (a & CBVH_F32_SIGN) ? -(int64_t)(a & ~CBVH_F32_SIGN) : (int64_t)a;
    int64_t kb = (b & CBVH_F32_SIGN) ? -(int64_t)(b & ~CBVH_F32_SIGN) : (int64_t)b;
    return (ka > kb) - (ka < kb);
}

cbvh_f32 cbvh_f32_next_up(cbvh_f32 b) {
    if (cbvh_f32_is_zero(b)) return 1u;
    if (b & CBVH_F32_SIGN) {
        cbvh_f32 r = b - 1u;
        return r == CBVH_F32_SIGN ? 0u : r;
    }
    return b + 1u; /* FLT_MAX -> +Inf */
}

cbvh_f32 cbvh_f32_next_down(cbvh_f32 b) {
    if (cbvh_f32_is_zero(b)) return CBVH_F32_SIGN | 1u;
    if (b & CBVH_F32_SIGN) return b + 1u; /* -FLT_MAX -> -Inf */
    return b - 1u;
}
