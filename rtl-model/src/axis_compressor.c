/* Single-axis compressor, Fig. 5 of Viitanen et al. with the errata fixed
 * (docs/datapath.md, unit 2).
 *
 *   k = floor(lb / 2^e)            lower bound rounded toward -Inf (also for
 *   l = floor(ub / 2^e) + 1        negative, sign-magnitude inputs)
 *   lb_mod = k mod 2^N, ub_mod = l mod 2^N            (Eq. 8)
 *   child_scale = Eq. 2 of the (l - k)-cell box, clamped to min_scale
 *   clb = RD(k * 2^e), cub = RU(l * 2^e)      (exact grid values, rounded once) */
#include "cbvh/datapath.h"
#include "grid.h"

static const cbvh_axis_code zero_code;

uint32_t cbvh_axis_compress(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, int e, cbvh_axis_code *out) {
    *out = zero_code;
    uint32_t st = cbvh_params_check(p);
    if (st) return st;
    if (cbvh_f32_is_nan_or_inf(lb) || cbvh_f32_is_nan_or_inf(ub)) return CBVH_ST_NAN_INF;
    if (e < p->min_scale || e > CBVH_SCALE_CEIL) return CBVH_ST_BAD_SCALE;
    if (cbvh_f32_cmp(lb, ub) > 0) return CBVH_ST_INVERTED;

    int huge_l, huge_u;
    int64_t k = cbvh_grid_floor(lb, e, &huge_l);
    int64_t ku = cbvh_grid_floor(ub, e, &huge_u);
    uint32_t mask = cbvh_grid_mask(p);

    /* A huge coordinate is exactly x / 2^e and a multiple of 2^N, so it only
     * fits when lb == ub (one cell): any other float is > 2^N cells away. */
    uint64_t cells;
    int fit;
    if (huge_l || huge_u) {
        fit = cbvh_f32_cmp(lb, ub) == 0;
        cells = 1;
    } else {
        cells = (uint64_t)(ku + 1 - k);
        fit = cells <= (UINT64_C(1) << p->quant_bits);
    }

    out->lb_mod = (uint32_t)((uint64_t)k & mask);
    out->ub_mod = (uint32_t)((uint64_t)(ku + 1) & mask);
    out->child_scale = fit ? cbvh_grid_child_scale(p, e, cells) : e;

    /* clb: k*2^e is lb itself when huge, else an exact small product. */
    out->clb = huge_l ? (cbvh_f32_is_zero(lb) ? 0u : lb)
                      : cbvh_f32_pack(k < 0, k < 0 ? (uint64_t)-k : (uint64_t)k, e, CBVH_RND_DOWN);
    if (huge_u) {
        int s, x;
        uint32_t m;
        cbvh_f32_break(ub, &s, &m, &x);
        out->cub = cbvh_f32_add_dyadic(s ? -(int64_t)m : (int64_t)m, x, 1, e, CBVH_RND_UP);
    } else {
        int64_t l = ku + 1;
        out->cub = cbvh_f32_pack(l < 0, l < 0 ? (uint64_t)-l : (uint64_t)l, e, CBVH_RND_UP);
    }
    return fit ? 0 : CBVH_ST_NO_FIT;
}
