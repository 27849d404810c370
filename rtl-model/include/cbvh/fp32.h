/* Integer-only helpers for IEEE-754 binary32 bit patterns.
 *
 * Every hardware unit of the model takes and returns binary32 values as bit
 * patterns (cbvh_f32) and computes with integers only, so its results do not
 * depend on the host FPU, compiler flags or optimisation level.  The names
 * follow docs/datapath.md, section "Number formats". */
#ifndef CBVH_FP32_H
#define CBVH_FP32_H

#include <stdint.h>
#include <string.h>

typedef uint32_t cbvh_f32; /* binary32 bit pattern */

/* The fields: sign (bit 31), biased exponent (bits 30..23), fraction (bits 22..0). */
#define CBVH_F32_FRAC_BITS 23                          /* fraction field width; the exponent field starts here */
#define CBVH_F32_EXP_BIAS 127                          /* exponent field = unbiased exponent + 127 */
#define CBVH_F32_EXP_FIELD_MAX 0xFFu                   /* exponent field of Inf and NaN (and its mask) */
#define CBVH_F32_SIGN 0x80000000u
#define CBVH_F32_EXP 0x7F800000u                       /* the exponent field in place */
#define CBVH_F32_FRAC 0x007FFFFFu                      /* the fraction field */
#define CBVH_F32_HIDDEN 0x00800000u                    /* a normal number's leading significand bit */
#define CBVH_F32_POS_INF 0x7F800000u
#define CBVH_F32_NEG_INF 0xFF800000u
#define CBVH_F32_MAX 0x7F7FFFFFu
/* A normal number is sig * 2^(field - CBVH_F32_ULP_BIAS) with sig = fraction | hidden
 * bit; a subnormal (field 0) is fraction * 2^CBVH_F32_SUB_EXP. */
#define CBVH_F32_ULP_BIAS (CBVH_F32_EXP_BIAS + CBVH_F32_FRAC_BITS)   /* 150 */
#define CBVH_F32_SUB_EXP (1 - CBVH_F32_ULP_BIAS)                      /* -149: the subnormals' ulp */
#define CBVH_F32_EMIN (1 - CBVH_F32_EXP_BIAS)                         /* -126: the smallest normal binade */
#define CBVH_F32_EMAX CBVH_F32_EXP_BIAS                               /* 127: the largest finite binade */

/* Directed rounding modes of the datapath (no round-to-nearest anywhere). */
typedef enum { CBVH_RND_DOWN = 0, CBVH_RND_UP = 1 } cbvh_rnd;

static inline int cbvh_f32_is_nan_or_inf(cbvh_f32 b) { return (b & CBVH_F32_EXP) == CBVH_F32_EXP; }
static inline int cbvh_f32_is_nan(cbvh_f32 b) {
    return cbvh_f32_is_nan_or_inf(b) && (b & CBVH_F32_FRAC) != 0;
}
static inline int cbvh_f32_is_zero(cbvh_f32 b) { return (b & ~CBVH_F32_SIGN) == 0; }

/* Total order key of a binary32 value incl. +-Inf (+0 == -0: both 0); NaN not allowed. */
static inline int64_t cbvh_f32_key(cbvh_f32 x) {
    return (x & CBVH_F32_SIGN) ? -(int64_t)(x & ~CBVH_F32_SIGN) : (int64_t)x;
}

/* The biased exponent field (0: zero or subnormal; CBVH_F32_EXP_FIELD_MAX: Inf or NaN). */
static inline uint32_t cbvh_f32_exp_field(cbvh_f32 b) { return (b >> CBVH_F32_FRAC_BITS) & CBVH_F32_EXP_FIELD_MAX; }
/* 1 unless a biased exponent field is a normal number's (1 .. 254); branch-free. */
static inline int cbvh_f32_field_not_normal(uint32_t field) { return field - 1u > CBVH_F32_EXP_FIELD_MAX - 2u; }
/* A normal number's significand, hidden bit included (< 2^24). */
static inline uint32_t cbvh_f32_normal_sig(cbvh_f32 b) { return (b & CBVH_F32_FRAC) | CBVH_F32_HIDDEN; }
/* The normal number (-1)^sign * 1.frac * 2^e, e in [CBVH_F32_EMIN, CBVH_F32_EMAX]
 * (frac: the fraction field, higher bits ignored). */
static inline cbvh_f32 cbvh_f32_make(int sign, int e, uint32_t frac) {
    return (sign ? CBVH_F32_SIGN : 0u) | (uint32_t)(e + CBVH_F32_EXP_BIAS) << CBVH_F32_FRAC_BITS |
           (frac & CBVH_F32_FRAC);
}

/* break_float: value = (-1)^sign * sig * 2^exp with sig < 2^24 (hidden bit
 * included for normals; subnormals have exp = -149).  Finite inputs only. */
void cbvh_f32_break(cbvh_f32 b, int *sign, uint32_t *sig, int *exp);

/* pack_float: round (-1)^neg * mag * 2^exp to binary32 in the given direction.
 * Overflow follows IEEE-754 directed rounding (to +-Inf away from zero in the
 * rounding direction, else to +-FLT_MAX).  A zero result is +0. */
cbvh_f32 cbvh_f32_pack(int neg, uint64_t mag, int exp, cbvh_rnd mode);

/* Exact a*2^ea + b*2^eb (|a|,|b| < 2^25) rounded once in the given direction. */
cbvh_f32 cbvh_f32_add_dyadic(int64_t a, int ea, int64_t b, int eb, cbvh_rnd mode);

/* Total order of finite values: -1, 0, 1 (+0 == -0). */
int cbvh_f32_cmp(cbvh_f32 a, cbvh_f32 b);

/* Next binary32 toward +Inf / -Inf (finite inputs; -0 treated as +0; a zero
 * result is +0, e.g. next_up(-min subnormal), where IEEE nextUp gives -0). */
cbvh_f32 cbvh_f32_next_up(cbvh_f32 b);
cbvh_f32 cbvh_f32_next_down(cbvh_f32 b);

/* Number of significant bits of x (0 for 0). */
static inline int cbvh_bitlen64(uint64_t x) {
    int n = 0;
    while (x) { n++; x >>= 1; }
    return n;
}

/* A float's binary32 bit pattern and back (the host's float is binary32). */
static inline cbvh_f32 cbvh_f32_of(float x) {
    cbvh_f32 r;
    memcpy(&r, &x, sizeof r);
    return r;
}
static inline float cbvh_float_of(cbvh_f32 x) {
    float r;
    memcpy(&r, &x, sizeof r);
    return r;
}

#endif
