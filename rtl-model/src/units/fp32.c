/* binary32 bit-pattern arithmetic used by every unit (docs/datapath.md,
 * "Number formats").  Integer only: no float type appears in this file. */
#include "cbvh/fp32.h"
#include "units/grid.h"

void cbvh_f32_break(cbvh_f32 b, int *sign, uint32_t *sig, int *exp) { cbvh_grid_break(b, sign, sig, exp); }

/* The rounding steps live in grid.h (inlined into the units); these are the
 * public entry points to the same code. */
cbvh_f32 cbvh_f32_pack(int neg, uint64_t mag, int exp, cbvh_rnd mode) { return cbvh_grid_pack(neg, mag, exp, mode); }

cbvh_f32 cbvh_f32_add_dyadic(int64_t a, int ea, int64_t b, int eb, cbvh_rnd mode) {
    return cbvh_grid_add_dyadic(a, ea, b, eb, mode);
}

int cbvh_f32_cmp(cbvh_f32 a, cbvh_f32 b) {
    int64_t ka = cbvh_f32_key(a), kb = cbvh_f32_key(b); /* monotone; both zeros map to 0 */
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
