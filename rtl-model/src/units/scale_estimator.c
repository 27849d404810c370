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
#include "units/grid.h"
#include "fast/unit_fast.h"

/* Does [lb, ub] span at most 2^N cells on grid 2^e? */
static inline int fits(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, int e) {
    int hl, hu;
    int64_t kl = cbvh_grid_floor(lb, e, &hl);
    int64_t ku = cbvh_grid_floor(ub, e, &hu);
    if (hl || hu) return cbvh_f32_key(lb) == cbvh_f32_key(ub); /* see cbvh_grid_floor */
    return ku + 1 - kl <= (INT64_C(1) << p->quant_bits);
}

/* Widest alignment kept exactly (unit_fast.h). */
#define WIDTH_SPAN CBVH_WIDTH_SPAN

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
    int64_t kl = cbvh_f32_key(lb), ku = cbvh_f32_key(ub);
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

/* The fast path lives in unit_fast.h (the bottom-up compressor inlines it);
 * every input it does not take goes to estimate_general. */
uint32_t cbvh_scale_estimate(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, int *scale) {
    if (cbvh_scale_estimate_fast(p, lb, ub, scale)) return 0;
    return estimate_general(p, lb, ub, scale);
}
