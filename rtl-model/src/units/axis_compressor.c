/* Single-axis compressor, Fig. 5 of Viitanen et al. with the errata fixed
 * (docs/datapath.md, unit 2).
 *
 *   k = floor(lb / 2^e)            lower bound rounded toward -Inf (also for
 *   l = floor(ub / 2^e) + 1        negative, sign-magnitude inputs)
 *   lb_mod = k mod 2^N, ub_mod = l mod 2^N            (Eq. 8)
 *   child_scale = Eq. 2 of the (l - k)-cell box, clamped to min_scale
 *   clb = RD(k * 2^e), cub = RU(l * 2^e)      (exact grid values, rounded once) */
#include "cbvh/datapath.h"
#include "units/grid.h"

static const cbvh_axis_code zero_code;

/* The general path: every input, every corner.  Kept out of line so the fast
 * path below stays small. */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static uint32_t compress_general(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, int e, cbvh_axis_code *out) {
    *out = zero_code;
    uint32_t st = cbvh_grid_params_check(p);
    if (st) return st;
    if (cbvh_f32_is_nan_or_inf(lb) || cbvh_f32_is_nan_or_inf(ub)) return CBVH_ST_NAN_INF;
    if (e < p->min_scale || e > CBVH_SCALE_CEIL) return CBVH_ST_BAD_SCALE;
    if (cbvh_grid_key(lb) > cbvh_grid_key(ub)) return CBVH_ST_INVERTED;

    int huge_l, huge_u;
    int64_t k = cbvh_grid_floor(lb, e, &huge_l);
    int64_t ku = cbvh_grid_floor(ub, e, &huge_u);
    uint32_t mask = cbvh_grid_mask(p);

    /* A huge coordinate is exactly x / 2^e and a multiple of 2^N, so it only
     * fits when lb == ub (one cell): any other float is > 2^N cells away. */
    uint64_t cells;
    int fit;
    if (huge_l || huge_u) {
        fit = cbvh_grid_key(lb) == cbvh_grid_key(ub);
        cells = 1;
    } else {
        cells = (uint64_t)(ku + 1 - k);
        fit = cells <= (UINT64_C(1) << p->quant_bits);
    }

    out->lb_mod = (uint32_t)((uint64_t)k & mask);
    out->ub_mod = (uint32_t)((uint64_t)(ku + 1) & mask);
    out->child_scale = fit ? cbvh_grid_child_scale(p, e, cells) : e;

    /* clb: k*2^e is lb itself when huge, else an exact small product. */
    out->clb = huge_l ? (cbvh_f32_is_zero(lb) ? 0u : lb) : cbvh_grid_pack_signed(k, e, CBVH_RND_DOWN);
    if (huge_u) {
        int s, x;
        uint32_t m;
        cbvh_grid_break(ub, &s, &m, &x);
        out->cub = cbvh_grid_add_dyadic(s ? -(int64_t)m : (int64_t)m, x, 1, e, CBVH_RND_UP);
    } else {
        out->cub = cbvh_grid_pack_signed(ku + 1, e, CBVH_RND_UP);
    }
    return fit ? 0 : CBVH_ST_NO_FIT;
}

/* Fast path for the common case: valid parameters and scale, lb <= ub, both
 * bounds normal numbers whose grid step 2^e lies inside their significand:
 * d = e - (lsb exponent of x) in [1, 23].  Then it computes the values of
 * compress_general without a general rounding step, because:
 *   - floor(x / 2^e) is sig >> d for x > 0 and -ceil(sig / 2^d) for x < 0;
 *   - k * 2^e is x with its low d significand bits cleared (x > 0) or its
 *     magnitude rounded up to a multiple of 2^d in the bit pattern (x < 0; a
 *     carry moves into the exponent field and yields the exact power of two,
 *     or the -Inf pattern for -2^128), so clb is exact and needs no rounding;
 *   - (ku + 1) * 2^e has at most 24 significant bits or is a power of two, so
 *     cub is exact too, except overflow to +Inf (pack_exact).
 * tests/model/test_properties.c checks both paths against an FPU oracle. */

/* Significant bits of x < 2^31 (0 for 0), branch-free. */
static inline int bitlen31(uint32_t x) {
#if defined(__GNUC__)
    return 31 - __builtin_clz(2u * x + 1u);
#else
    return cbvh_bitlen64(x);
#endif
}

/* v * 2^e for 0 < |v| <= 2^24 and e >= -126: exact and normal (v has <= 24
 * significant bits or is 2^24), except overflow to +-Inf. */
static inline cbvh_f32 pack_exact(int32_t v, int e) {
    uint32_t sign = v < 0 ? CBVH_F32_SIGN : 0u;
    uint32_t m = v < 0 ? 0u - (uint32_t)v : (uint32_t)v;
    int b = bitlen31(m);
    int biased = e + b + 126;
    cbvh_f32 r = sign | ((uint32_t)biased << 23) | (((m << (32 - b)) >> 8) & CBVH_F32_FRAC);
    return biased >= 255 ? (sign | CBVH_F32_POS_INF) : r;
}

uint32_t cbvh_axis_compress(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, int e, cbvh_axis_code *out) {
    int n = p->quant_bits, ms = p->min_scale;
    uint32_t el = (lb >> 23) & 0xFFu, eu = (ub >> 23) & 0xFFu;
    uint32_t dl = (uint32_t)(e + 150) - el, du = (uint32_t)(e + 150) - eu; /* d, as unsigned */
    uint32_t sl = 0u - (lb >> 31), su = 0u - (ub >> 31);                     /* all ones if negative */
    /* unsigned order keys of nonzero values (negative patterns inverted) */
    uint32_t kl = lb ^ (sl >> 1) ^ CBVH_F32_SIGN, ku = ub ^ (su >> 1) ^ CBVH_F32_SIGN;
    if ((uint32_t)(n - CBVH_N_MIN) > (uint32_t)(CBVH_N_MAX - CBVH_N_MIN) || ms < CBVH_SCALE_FLOOR || e < ms ||
        e > CBVH_SCALE_CEIL || el - 1u > 253u || eu - 1u > 253u || dl - 1u > 22u || du - 1u > 22u || kl > ku)
        return compress_general(p, lb, ub, e, out);

    uint32_t maskl = (1u << dl) - 1u, masku = (1u << du) - 1u;
    uint32_t addl = maskl & sl, addu = masku & su; /* round magnitude up when negative */
    uint32_t sigl = (lb & CBVH_F32_FRAC) | 0x800000u, sigu = (ub & CBVH_F32_FRAC) | 0x800000u;
    uint32_t ql = (sigl + addl) >> dl, qu = (sigu + addu) >> du; /* <= 2^24: negate without branches */
    int32_t k = (int32_t)ql - (int32_t)((ql << 1) & sl);
    int32_t l = (int32_t)qu - (int32_t)((qu << 1) & su) + 1;
    uint32_t mask = (1u << n) - 1u;
    uint32_t cells = (uint32_t)(l - k);
    int fit = cells <= (1u << n);
    int cs = e - n + bitlen31(cells - 1u);
    out->lb_mod = (uint32_t)k & mask;
    out->ub_mod = (uint32_t)l & mask;
    out->child_scale = fit ? (cs < ms ? ms : cs) : e;
    out->clb = (((lb & ~CBVH_F32_SIGN) + addl) & ~maskl) | (lb & CBVH_F32_SIGN);
    out->cub = l == 0 ? 0u : pack_exact(l, e);
    return fit ? 0 : CBVH_ST_NO_FIT;
}
