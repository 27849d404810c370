/* Single-axis compressor, Fig. 5 of Viitanen et al. with the errata fixed
 * (docs/datapath.md, unit 2).
 *
 *   k = floor(lb / 2^e)            lower bound rounded toward -Inf (also for
 *   l = floor(ub / 2^e) + 1        negative, sign-magnitude inputs)
 *   lb_mod = k mod 2^N, ub_mod = l mod 2^N            (Eq. 8)
 *   child_scale = Eq. 2 of the (l - k)-cell box, clamped to min_scale
 *   clb = RD(k * 2^e), cub = RU(l * 2^e)      (exact grid values, rounded once)
 *   OUTSIDE: k < K or l > K + 2^N, K = floor(node_clb / 2^e): the box leaves
 *            the node's window of 2^N cells, so its codes would not decode to it */
#include "cbvh/datapath.h"
#include "units/grid.h"
#include "fast/unit_fast.h"

static const cbvh_axis_code zero_code;

/* The general path: every input, every corner.  Kept out of line so the fast
 * path below stays small. */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static uint32_t compress_general(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, int e, cbvh_f32 node_clb,
                                 cbvh_axis_code *out) {
    *out = zero_code;
    uint32_t st = cbvh_grid_params_check(p);
    if (st) return st;
    if (cbvh_f32_is_nan_or_inf(lb) || cbvh_f32_is_nan_or_inf(ub) || cbvh_grid_clb_bad(node_clb))
        return CBVH_ST_NAN_INF;
    if (e < p->min_scale || e > CBVH_SCALE_CEIL) return CBVH_ST_BAD_SCALE;
    if (cbvh_f32_key(lb) > cbvh_f32_key(ub)) return CBVH_ST_INVERTED;

    int huge_l, huge_u;
    int64_t k = cbvh_grid_floor(lb, e, &huge_l);
    int64_t ku = cbvh_grid_floor(ub, e, &huge_u);
    uint32_t mask = cbvh_grid_mask(p);

    /* A huge coordinate is exactly x / 2^e and a multiple of 2^N, so it only
     * fits when lb == ub (one cell): any other float is > 2^N cells away. */
    uint64_t cells;
    int fit;
    if (huge_l || huge_u) {
        fit = cbvh_f32_key(lb) == cbvh_f32_key(ub);
        cells = 1;
    } else {
        cells = (uint64_t)(ku + 1 - k);
        fit = cells <= (UINT64_C(1) << p->quant_bits);
    }

    out->lb_mod = (uint32_t)((uint64_t)k & mask);
    out->ub_mod = (uint32_t)((uint64_t)(ku + 1) & mask);
    out->child_scale = fit ? cbvh_grid_child_scale(p, e, cells) : e;

    /* clb: k*2^e is lb itself when huge, else an exact small product. */
    out->clb = cbvh_grid_below(lb, e);
    int s, x;
    uint32_t m;
    if (huge_u) {
        cbvh_grid_break(ub, &s, &m, &x);
        out->cub = cbvh_grid_add_dyadic(s ? -(int64_t)m : (int64_t)m, x, 1, e, CBVH_RND_UP);
    } else {
        out->cub = cbvh_grid_pack_signed(ku + 1, e, CBVH_RND_UP);
    }

    /* The node's window, exactly and for every input, huge ones included:
     * with g = K 2^e (cbvh_grid_below), k < K iff lb < g, and l > K + 2^N iff
     * ub >= g + 2^(N+e), iff ub >= RU(g + 2^(N+e)) (ub is a binary32 value;
     * +Inf when the sum passes FLT_MAX, which no finite ub reaches). */
    cbvh_f32 g = cbvh_grid_below(node_clb, e);
    cbvh_grid_break(g, &s, &m, &x); /* -Inf breaks as -2^128 */
    cbvh_f32 top = cbvh_grid_add_dyadic(s ? -(int64_t)m : (int64_t)m, x, 1, p->quant_bits + e, CBVH_RND_UP);
    int outside = cbvh_f32_key(lb) < cbvh_f32_key(g) || cbvh_f32_key(ub) >= cbvh_f32_key(top);
    return (fit ? 0 : CBVH_ST_NO_FIT) | (outside ? CBVH_ST_OUTSIDE : 0);
}

/* Fast path for the common case: valid parameters and scale, lb <= ub, both
 * bounds normal numbers whose grid step 2^e lies inside their significand
 * (cbvh_fast_in_sig: d = e - lsb exponent in [1, 23]), and node_clb either
 * such a number too or +-0 (K = 0); any other node_clb (NaN, +-Inf, one below
 * 2^e or with its lsb at or above 2^e) goes to the general path, which also
 * decides the faults.  The grid coordinates are unit_fast.h's
 * cbvh_fast_floor_in_sig and the codes and Eq. 2 child
 * scale its cbvh_fast_code: the same inline steps the streaming compressor
 * runs, so each has one definition.  Then 0 < |k|, |ku| < 2^24, |K| < 2^24,
 * and:
 *   - clb = RD(k 2^e) is k 2^e itself, formed on lb's bit pattern
 *     (cbvh_fast_grid_below_in_sig; -2^128 comes out as -Inf);
 *   - with l = ku + 1, l 2^e (l != 0) has at most 24 significant bits or is
 *     a power of two, and e >= -126 keeps it normal: it is a binary32 value
 *     unless it overflows (RU gives +Inf), so pack_exact needs no rounding
 *     step; l = 0 gives +0;
 *   - OUTSIDE is the integer test of the spec, k < K or l - K > 2^N, in 64 bits.
 * These are the values compress_general forms (cbvh_grid_floor, its
 * cells and child scale, cbvh_grid_pack_signed, the window as values).
 * tests/model/test_properties.c and test_unit_fast.c check both paths
 * against an FPU oracle. */

/* v * 2^e for 0 < |v| <= 2^24 and e >= -126: exact and normal (v has <= 24
 * significant bits or is 2^24), except overflow to +-Inf. */
static inline cbvh_f32 pack_exact(int32_t v, int e) {
    uint32_t sign = v < 0 ? CBVH_F32_SIGN : 0u;
    uint32_t m = v < 0 ? 0u - (uint32_t)v : (uint32_t)v;
    int b = cbvh_grid_bitlen63(m); /* the leading bit of m 2^e is 2^(e + b - 1) */
    int biased = e + b - 1 + CBVH_F32_EXP_BIAS;
    cbvh_f32 r = sign | ((uint32_t)biased << CBVH_F32_FRAC_BITS) | (((m << (32 - b)) >> 8) & CBVH_F32_FRAC);
    return biased >= (int)CBVH_F32_EXP_FIELD_MAX ? (sign | CBVH_F32_POS_INF) : r;
}

uint32_t cbvh_axis_compress(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, int e, cbvh_f32 node_clb,
                            cbvh_axis_code *out) {
    int n = p->quant_bits, ms = p->min_scale;
    uint32_t dl, du, dn;
    if ((uint32_t)(n - CBVH_N_MIN) > (uint32_t)(CBVH_N_MAX - CBVH_N_MIN) || ms < CBVH_SCALE_FLOOR || e < ms ||
        e > CBVH_SCALE_CEIL || !(cbvh_fast_in_sig(lb, e, &dl) & cbvh_fast_in_sig(ub, e, &du)) ||
        cbvh_fast_order_key(lb) > cbvh_fast_order_key(ub))
        return compress_general(p, lb, ub, e, node_clb, out);
    /* +-0: d = 31 gives floor(v / 2^31) = 0 for either sign (|v| < 2^24) */
    if (!cbvh_fast_in_sig(node_clb, e, &dn)) {
        if (!cbvh_f32_is_zero(node_clb)) return compress_general(p, lb, ub, e, node_clb, out);
        dn = 31;
    }
    int64_t k = cbvh_fast_floor_in_sig(lb, dl), ku = cbvh_fast_floor_in_sig(ub, du);
    int64_t kn = cbvh_fast_floor_in_sig(node_clb, dn);
    int fit = cbvh_fast_code(n, ms, e, k, ku, &out->lb_mod, &out->ub_mod, &out->child_scale);
    if (!fit) out->child_scale = e;
    out->clb = cbvh_fast_grid_below_in_sig(lb, dl);
    out->cub = ku == -1 ? 0u : pack_exact((int32_t)(ku + 1), e);
    int outside = (k < kn) | (ku + 1 - kn > (INT64_C(1) << n));
    return (fit ? 0 : CBVH_ST_NO_FIT) | (outside ? CBVH_ST_OUTSIDE : 0);
}
