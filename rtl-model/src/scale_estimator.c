/* Scale estimator: Eq. 2 applied to a float box (docs/datapath.md, unit 1).
 *
 * The result is the finest zero-aligned grid 2^e (e >= min_scale) on which the
 * box, quantized conservatively by Eq. 1, fits in 2^N cells.  The cell count
 * is non-increasing in e, so a binary search over [min_scale, 126] finds it;
 * hardware would take the exponent of ub - lb and correct by at most one. */
#include "cbvh/datapath.h"
#include "grid.h"

/* Does [lb, ub] span at most 2^N cells on grid 2^e? */
static int fits(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, int e) {
    int hl, hu;
    int64_t kl = cbvh_grid_floor(lb, e, &hl);
    int64_t ku = cbvh_grid_floor(ub, e, &hu);
    if (hl || hu) return cbvh_f32_cmp(lb, ub) == 0; /* see cbvh_grid_floor */
    return ku + 1 - kl <= (INT64_C(1) << p->quant_bits);
}

uint32_t cbvh_scale_estimate(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, int *scale) {
    *scale = 0;
    uint32_t st = cbvh_params_check(p);
    if (st) return st;
    if (cbvh_f32_is_nan_or_inf(lb) || cbvh_f32_is_nan_or_inf(ub)) return CBVH_ST_NAN_INF;
    if (cbvh_f32_cmp(lb, ub) > 0) return CBVH_ST_INVERTED;
    int lo = p->min_scale, hi = CBVH_SCALE_CEIL; /* fits(hi) always holds */
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        if (fits(p, lb, ub, mid))
            hi = mid;
        else
            lo = mid + 1;
    }
    *scale = lo;
    return 0;
}
