/* Scale estimator: Eq. 2 applied to a float box (docs/datapath.md, unit 1).
 *
 * The result is the finest zero-aligned grid 2^e (e >= min_scale) on which the
 * box, quantized conservatively by Eq. 1, fits in 2^N cells.  Like the
 * hardware, the model takes the exponent of the exact width w = ub - lb and
 * corrects by at most one step, in constant time:
 *
 *   cells(e) = floor(ub/2^e) + 1 - floor(lb/2^e)  lies in (w/2^e, w/2^e + 2),
 *
 * so with t = floor(log2 w) no e < e0 = t + 1 - N fits (cells > 2^N) and
 * e0 + 1 always fits (cells < 2^(N-1) + 2 <= 2^N); cells is non-increasing in
 * e, so the answer is max(min_scale, e0) or one more.  A point box (w = 0)
 * spans one cell at every scale.  tests/model/test_estimator_fast.c checks
 * this against the binary search over [min_scale, 126] it replaces. */
#include "cbvh/datapath.h"
#include "grid.h"

/* Does [lb, ub] span at most 2^N cells on grid 2^e? */
static inline int fits(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, int e) {
    int hl, hu;
    int64_t kl = cbvh_grid_floor(lb, e, &hl);
    int64_t ku = cbvh_grid_floor(ub, e, &hu);
    if (hl || hu) return cbvh_grid_key(lb) == cbvh_grid_key(ub); /* see cbvh_grid_floor */
    return ku + 1 - kl <= (INT64_C(1) << p->quant_bits);
}

/* Widest alignment kept exactly: significands (< 2^24) shifted by up to 38
 * bits stay below 2^62, so the sum of two stays below 2^63. */
#define WIDTH_SPAN 38

/* Every input: parameter and input checks, zeros, subnormals, bounds far
 * apart.  Kept out of line so the fast path below stays small. */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static uint32_t estimate_general(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, int *scale) {
    *scale = 0;
    uint32_t st = cbvh_grid_params_check(p);
    if (st) return st;
    if (cbvh_f32_is_nan_or_inf(lb) || cbvh_f32_is_nan_or_inf(ub)) return CBVH_ST_NAN_INF;
    int64_t kl = cbvh_grid_key(lb), ku = cbvh_grid_key(ub);
    if (kl > ku) return CBVH_ST_INVERTED;
    if (kl == ku) {
        *scale = p->min_scale;
        return 0;
    }

    /* The bounds as signed terms m * 2^x. */
    int sl, su, xl, xu;
    uint32_t ml, mu;
    cbvh_grid_break(lb, &sl, &ml, &xl);
    cbvh_grid_break(ub, &su, &mu, &xu);
    int64_t tl = sl ? -(int64_t)ml : (int64_t)ml;
    int64_t tu = su ? -(int64_t)mu : (int64_t)mu;
    if (ml == 0) xl = xu; /* zero is exact at every exponent */
    if (mu == 0) xu = xl;
    int n = p->quant_bits;
    int xhi = xl > xu ? xl : xu, xlo = xl < xu ? xl : xu;

    if (xhi - xlo <= WIDTH_SPAN) {
        /* Both bounds exact as integers at 2^xlo: lb = vl 2^xlo, ub = vu 2^xlo,
         * w = (vu - vl) 2^xlo, and floor(x / 2^e) = floor(v / 2^(e - xlo)). */
        int64_t vl = tl * (INT64_C(1) << (xl - xlo)), vu = tu * (INT64_C(1) << (xu - xlo));
        int e0 = cbvh_grid_bitlen((uint64_t)(vu - vl)) + xlo - n;
        if (e0 < p->min_scale) e0 = p->min_scale;
        int d = e0 - xlo, fit = 1, inexact;
        /* d <= 0: cells = w 2^-d + 1 with w 2^-d < 2^N, always fits. */
        if (d > 0)
            fit = cbvh_grid_floor_shift(vu, d, &inexact) + 1 - cbvh_grid_floor_shift(vl, d, &inexact) <=
                  (INT64_C(1) << n);
        *scale = fit ? e0 : e0 + 1;
        return 0;
    }

    /* Bounds many binades apart: align at u = xhi - 38 and floor the lower
     * term.  The other term is an integer at 2^u, so the sum is
     * floor(w / 2^u) >= 1 (w >= 2^(xhi+22) here), whose bit length is
     * floor(log2 w) + 1 - u. */
    int u = xhi - WIDTH_SPAN, inexact;
    int64_t a = -tl, b = tu; /* w = b + a */
    int64_t w = (xl >= u ? a * (INT64_C(1) << (xl - u)) : cbvh_grid_floor_shift(a, u - xl, &inexact)) +
                (xu >= u ? b * (INT64_C(1) << (xu - u)) : cbvh_grid_floor_shift(b, u - xu, &inexact));
    int e0 = cbvh_grid_bitlen((uint64_t)w) + u - n;
    if (e0 < p->min_scale) e0 = p->min_scale;
    *scale = fits(p, lb, ub, e0) ? e0 : e0 + 1;
    return 0;
}

/* Fast path: valid parameters, both bounds normal, lb < ub, exponents at
 * most 38 apart: the near case of estimate_general without its checks. */
uint32_t cbvh_scale_estimate(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, int *scale) {
    int n = p->quant_bits, ms = p->min_scale;
    uint32_t el = (lb >> 23) & 0xFFu, eu = (ub >> 23) & 0xFFu;
    int dx = (int)el - (int)eu;
    if ((uint32_t)(n - CBVH_N_MIN) > (uint32_t)(CBVH_N_MAX - CBVH_N_MIN) || ms < CBVH_SCALE_FLOOR ||
        ms > CBVH_SCALE_CEIL || el - 1u > 253u || eu - 1u > 253u || dx < -WIDTH_SPAN || dx > WIDTH_SPAN)
        return estimate_general(p, lb, ub, scale);
    int64_t ml = (int64_t)((lb & CBVH_F32_FRAC) | 0x800000u), mu = (int64_t)((ub & CBVH_F32_FRAC) | 0x800000u);
    int xlo = (int)(dx < 0 ? el : eu) - 150; /* the lower exponent */
    int64_t vl = (lb & CBVH_F32_SIGN ? -ml : ml) * (INT64_C(1) << (dx > 0 ? dx : 0));
    int64_t vu = (ub & CBVH_F32_SIGN ? -mu : mu) * (INT64_C(1) << (dx < 0 ? -dx : 0));
    if (vl >= vu) return estimate_general(p, lb, ub, scale); /* inverted or a point */
    int e0 = cbvh_grid_bitlen((uint64_t)(vu - vl)) + xlo - n;
    if (e0 < ms) e0 = ms;
    /* cells(e0) = floor(vu / 2^d) + 1 - floor(vl / 2^d), d = e0 - xlo.  With
     * |v| < 2^62, floor(v / 2^d) = ((v + 2^62) >> d) - 2^(62 - d) for
     * d <= 62 (the offsets cancel in the difference), and every d >= 62 gives
     * the same floors (-1 or 0).  d <= 0: always fits (see above). */
    int d = e0 - xlo;
    if (d > 62) d = 62;
    uint64_t ou = (uint64_t)(vu + (INT64_C(1) << 62)), ol = (uint64_t)(vl + (INT64_C(1) << 62));
    int fit = d <= 0 || (ou >> d) - (ol >> d) + 1u <= (UINT64_C(1) << n);
    *scale = fit ? e0 : e0 + 1;
    return 0;
}
