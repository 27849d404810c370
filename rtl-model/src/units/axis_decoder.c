/* Single-axis decoder, Fig. 4 of Viitanen et al. for modulo and relative
 * encodings (docs/datapath.md, unit 3).
 *
 *   p^  = (lb_mod << (parent_scale - scale)) mod 2^N    node lower bound at `scale`
 *   mod: r = (lb_code - p^) mod 2^N, s = (ub_code - p^) mod 2^N   (Eq. 9)
 *   rel: r = lb_code,                s = ub_code
 *   s == 0 means s = 2^N (the code's intent; Eq. 9 is garbled in print)
 *   clb = RD(u + r 2^e), cub = RU(u + s 2^e)   exact sum, rounded once
 *   child_scale = Eq. 2 of the (s - r)-cell box, clamped to min_scale */
#include "cbvh/datapath.h"
#include "units/grid.h"

static const cbvh_axis_code zero_code;

uint32_t cbvh_axis_ctx_check(const cbvh_params *p, const cbvh_axis_ctx *c) {
    uint32_t mask = cbvh_grid_mask(p);
    if (c->scale < p->min_scale || c->parent_scale > CBVH_SCALE_CEIL || c->parent_scale < c->scale)
        return CBVH_ST_BAD_SCALE;
    if (c->lb_mod > mask) return CBVH_ST_BAD_CODE;
    /* -Inf is the context's encoding of -2^128; +Inf and NaN are rejected. */
    if (cbvh_grid_clb_bad(c->clb)) return CBVH_ST_NAN_INF;
    return 0;
}

/* The general path: every input, every corner.  Kept out of line so the fast
 * path below stays small. */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static uint32_t decode_general(const cbvh_params *p, cbvh_encoding enc, const cbvh_axis_ctx *ctx, uint32_t lb_code,
                               uint32_t ub_code, cbvh_axis_code *out) {
    *out = zero_code;
    uint32_t st = cbvh_grid_params_check(p);
    if (st) return st;
    uint32_t mask = cbvh_grid_mask(p);
    st = cbvh_axis_ctx_check(p, ctx);
    if (st) return st;
    if (lb_code > mask || ub_code > mask) return CBVH_ST_BAD_CODE;

    int shift = ctx->parent_scale - ctx->scale;
    uint32_t pmod = shift >= p->quant_bits ? 0 : (ctx->lb_mod << shift) & mask;
    uint32_t full = mask + 1u;
    uint32_t r, s;
    if (enc == CBVH_ENC_MODULO) {
        r = (lb_code - pmod) & mask;
        s = (ub_code - pmod) & mask;
    } else {
        r = lb_code;
        s = ub_code;
    }
    if (s == 0) s = full;
    if (r >= s) return CBVH_ST_INVERTED;

    int e = ctx->scale;
    int64_t u_sig;
    int u_exp;
    if (ctx->clb == CBVH_F32_NEG_INF) {
        u_sig = -1;
        u_exp = 128;
    } else {
        int sign;
        uint32_t m;
        cbvh_grid_break(ctx->clb, &sign, &m, &u_exp);
        u_sig = sign ? -(int64_t)m : (int64_t)m;
    }
    out->lb_mod = (r + pmod) & mask;
    out->ub_mod = (s + pmod) & mask;
    out->child_scale = cbvh_grid_child_scale(p, e, s - r);
    out->clb = cbvh_grid_add_dyadic(u_sig, u_exp, (int64_t)r, e, CBVH_RND_DOWN);
    out->cub = cbvh_grid_add_dyadic(u_sig, u_exp, (int64_t)s, e, CBVH_RND_UP);
    return 0;
}

/* Fast path for the common case: valid parameters, context and codes, r < s,
 * and a normal context lower bound u whose lsb exponent lies within 36 of
 * the scale.  Then u + r 2^e and u + s 2^e are formed exactly in 64 bits at
 * the finer of the two exponents and rounded once: the same integers that
 * cbvh_grid_add_dyadic forms for these operands (its exact branch), so the
 * same results as decode_general. */
uint32_t cbvh_axis_decode(const cbvh_params *p, cbvh_encoding enc, const cbvh_axis_ctx *ctx, uint32_t lb_code,
                          uint32_t ub_code, cbvh_axis_code *out) {
    int n = p->quant_bits, ms = p->min_scale, e = ctx->scale;
    uint32_t mask = (1u << (n & 31)) - 1u;
    uint32_t eu = cbvh_f32_exp_field(ctx->clb);
    int d = (int)eu - CBVH_F32_ULP_BIAS - e; /* u's lsb exponent minus the scale */
    if ((uint32_t)(n - CBVH_N_MIN) > (uint32_t)(CBVH_N_MAX - CBVH_N_MIN) || ms < CBVH_SCALE_FLOOR ||
        ms > CBVH_SCALE_CEIL || e < ms || ctx->parent_scale > CBVH_SCALE_CEIL || ctx->parent_scale < e ||
        ctx->lb_mod > mask || lb_code > mask || ub_code > mask || cbvh_f32_field_not_normal(eu) || d < -36 || d > 36)
        return decode_general(p, enc, ctx, lb_code, ub_code, out);

    int shift = ctx->parent_scale - e;
    uint32_t pmod = shift >= n ? 0 : (ctx->lb_mod << shift) & mask;
    uint32_t r = lb_code, s = ub_code;
    if (enc == CBVH_ENC_MODULO) {
        r = (lb_code - pmod) & mask;
        s = (ub_code - pmod) & mask;
    }
    if (s == 0) s = mask + 1u;
    if (r >= s) return decode_general(p, enc, ctx, lb_code, ub_code, out);

    int64_t u = (int64_t)cbvh_f32_normal_sig(ctx->clb);
    if (ctx->clb & CBVH_F32_SIGN) u = -u;
    int lo;
    int64_t sr, ss;
    if (d >= 0) { /* align at the scale */
        lo = e;
        u *= INT64_C(1) << d;
        sr = u + (int64_t)r;
        ss = u + (int64_t)s;
    } else { /* align at u's lsb */
        lo = e + d;
        sr = u + (int64_t)r * (INT64_C(1) << -d);
        ss = u + (int64_t)s * (INT64_C(1) << -d);
    }
    out->lb_mod = (r + pmod) & mask;
    out->ub_mod = (s + pmod) & mask;
    out->child_scale = cbvh_grid_child_scale(p, e, s - r);
    out->clb = cbvh_grid_pack_signed(sr, lo, CBVH_RND_DOWN);
    out->cub = cbvh_grid_pack_signed(ss, lo, CBVH_RND_UP);
    return 0;
}

void cbvh_axis_store_codes(const cbvh_params *p, cbvh_encoding enc, const cbvh_axis_ctx *ctx,
                           const cbvh_axis_code *code, uint32_t *lb_code, uint32_t *ub_code) {
    uint32_t mask = cbvh_grid_mask(p);
    if (enc == CBVH_ENC_MODULO) {
        *lb_code = code->lb_mod;
        *ub_code = code->ub_mod;
        return;
    }
    int shift = ctx->parent_scale - ctx->scale; /* >= 0 for a context that passes cbvh_axis_ctx_check */
    uint32_t pmod = shift < 0 || shift >= p->quant_bits ? 0 : (ctx->lb_mod << shift) & mask;
    *lb_code = (code->lb_mod - pmod) & mask;
    *ub_code = (code->ub_mod - pmod) & mask;
}

cbvh_axis_ctx cbvh_axis_child_ctx(const cbvh_axis_ctx *ctx, const cbvh_axis_code *code) {
    cbvh_axis_ctx c = {ctx->scale, code->child_scale, code->lb_mod, code->clb};
    return c;
}

uint32_t cbvh_axis_root_ctx(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, cbvh_axis_ctx *ctx) {
    static const cbvh_axis_ctx zero_ctx;
    *ctx = zero_ctx;
    int e;
    uint32_t st = cbvh_scale_estimate(p, lb, ub, &e);
    if (st) return st;
    cbvh_axis_code code;
    /* The root is the only child of a virtual node whose window starts at the
     * root's own grid line: node_clb = lb (any value in that cell would do). */
    st = cbvh_axis_compress(p, lb, ub, e, lb, &code);
    if (st) return st; /* cannot be NO_FIT or OUTSIDE: e was chosen to fit */
    ctx->parent_scale = e;
    ctx->scale = code.child_scale;
    ctx->lb_mod = code.lb_mod;
    ctx->clb = code.clb;
    return 0;
}
