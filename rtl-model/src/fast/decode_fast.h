/* Node-pair decode for the traversal (docs/traversal.md §9).  Internal to
 * rtl-model.  The traversal needs, per child, only the leaf bit, the pointer
 * and the relative coordinates r, s of each axis (the box unit's planes are
 * u + r 2^e and u + s 2^e under the node's context); the decoded child
 * bounds clb (and never cub) only for children it pushes.
 *
 * cbvh_fast_pair_decode handles 64-bit (N <= 6) and 96-bit (N = 7..10)
 * nodes whose decode by the unit (cbvh_nodepair_decode) returns status 0:
 * valid parameters and contexts, no reserved bit set, empty children with
 * zero codes, r < s on every axis.  It then returns 1 with the same leaf,
 * empty, ptr as the unit, and r, s equal to cbvh_axis_store_codes(RELATIVE)
 * of the unit's outputs (s = 0 read as 2^N), as the traversal used them.
 * Otherwise it returns 0 and the caller runs the unit.
 * tests/traversal/test_box_f64.c compares both on random and hard node
 * pairs. */
#ifndef CBVH_DECODE_FAST_H
#define CBVH_DECODE_FAST_H

#include "cbvh/datapath.h"
#include "units/grid.h"
#include "fast/ray_box_f64.h"

typedef struct {
    int leaf, empty;
    uint32_t ptr;
    uint32_t r[3], s[3];   /* relative coordinates, s in [1, 2^N] */
    uint32_t lc[3], uc[3]; /* the stored codes */
} cbvh_fast_child;

/* 1 if the context passes cbvh_axis_ctx_check (for valid parameters). */
static inline int cbvh_fast_ctx_ok(const cbvh_params *p, const cbvh_axis_ctx *c) {
    return c->scale >= p->min_scale && c->parent_scale <= CBVH_SCALE_CEIL && c->parent_scale >= c->scale &&
           c->lb_mod <= cbvh_grid_mask(p) && !(cbvh_f32_is_nan_or_inf(c->clb) && c->clb != CBVH_F32_NEG_INF);
}

/* pmod of the decoder (axis_decoder.c) for a valid context. */
static inline uint32_t cbvh_fast_pmod(const cbvh_params *p, const cbvh_axis_ctx *c) {
    int shift = c->parent_scale - c->scale;
    return shift >= p->quant_bits ? 0 : (c->lb_mod << shift) & cbvh_grid_mask(p);
}

static inline uint64_t cbvh_fast_load_le64(const uint8_t *b) {
    return (uint64_t)b[0] | (uint64_t)b[1] << 8 | (uint64_t)b[2] << 16 | (uint64_t)b[3] << 24 |
           (uint64_t)b[4] << 32 | (uint64_t)b[5] << 40 | (uint64_t)b[6] << 48 | (uint64_t)b[7] << 56;
}

static inline uint64_t cbvh_fast_load_le32(const uint8_t *b) {
    return (uint64_t)b[0] | (uint64_t)b[1] << 8 | (uint64_t)b[2] << 16 | (uint64_t)b[3] << 24;
}

/* Node layout (nodepair_codec.c): codes in bits [0, 6N), leaf at 6N, pointer
 * from 6N + 1, P = min(32, W - 6N - 1) bits, then reserved zeros.  For
 * N <= 10 the codes and the leaf bit lie in the first 64 bits; a 96-bit node
 * (N >= 7, P = 32) has its pointer's top bits and the reserved bits
 * [6N + 33, 96) in the last 32. */
static inline int cbvh_fast_params_ok(const cbvh_params *p) {
    return p->quant_bits >= CBVH_N_MIN && p->quant_bits <= CBVH_N_MAX && p->min_scale >= CBVH_SCALE_FLOOR &&
           p->min_scale <= CBVH_SCALE_CEIL;
}

static inline int cbvh_fast_node_ctx_ok(const cbvh_params *p, const cbvh_node_ctx *c) {
    return cbvh_fast_ctx_ok(p, &c->axis[0]) & cbvh_fast_ctx_ok(p, &c->axis[1]) & cbvh_fast_ctx_ok(p, &c->axis[2]);
}

/* The decode proper, for valid parameters (cbvh_fast_params_ok) and a valid
 * context (cbvh_fast_node_ctx_ok, or valid by construction: every context
 * cbvh_fast_child_ctx derives from a valid one is valid, see there).  Also
 * gives each axis's pmod (cbvh_fast_pmod, whatever the encoding) for the
 * children's contexts. */
static inline int cbvh_fast_pair_decode_valid(const cbvh_params *p, cbvh_encoding enc, const cbvh_node_ctx *ctx,
                                              const uint8_t *bytes, cbvh_fast_child ch[2], uint32_t pm[3]) {
    int n = p->quant_bits;
    int wide = n > 6, node_bytes = wide ? 12 : 8;
    uint32_t mask = cbvh_grid_mask(p), full = mask + 1u;
    uint32_t pmod[3];
    for (int a = 0; a < 3; a++) {
        pm[a] = cbvh_fast_pmod(p, &ctx->axis[a]);
        pmod[a] = enc == CBVH_ENC_MODULO ? pm[a] : 0; /* relative: r, s = codes */
    }
    int pp = 6 * n + 1;                                 /* pointer position */
    int pb = wide || 64 - pp >= 32 ? 32 : 64 - pp;      /* pointer bits */
    uint64_t ones = (UINT64_C(1) << pb) - 1u;
    for (int c = 0; c < 2; c++) {
        const uint8_t *b = bytes + node_bytes * c;
        uint64_t w = cbvh_fast_load_le64(b), x = wide ? cbvh_fast_load_le32(b + 8) : 0; /* bits 64..95 */
        if (wide ? (x >> (pp + pb - 64)) != 0 : pp + pb < 64 && (w >> (pp + pb)) != 0) return 0; /* reserved */
        cbvh_fast_child *o = &ch[c];
        o->leaf = (int)((w >> (pp - 1)) & 1u);
        o->ptr = (uint32_t)(((w >> pp) | (wide ? x << (64 - pp) : 0)) & ones);
        o->empty = o->leaf && o->ptr == ones;
        if (o->empty) {
            if (w & ((UINT64_C(1) << (pp - 1)) - 1u)) return 0; /* codes of an empty child */
            continue;
        }
        for (int a = 0; a < 3; a++) {
            uint32_t lc = (uint32_t)(w >> (2 * a * n)) & mask, uc = (uint32_t)(w >> (2 * a * n + n)) & mask;
            uint32_t r = (lc - pmod[a]) & mask, s = (uc - pmod[a]) & mask;
            if (s == 0) s = full;
            if (r >= s) return 0; /* INVERTED: the unit rejects */
            o->lc[a] = lc;
            o->uc[a] = uc;
            o->r[a] = r;
            o->s[a] = s;
        }
    }
    return 1;
}

/* The same with the parameters and the context checked first. */
static inline int cbvh_fast_pair_decode(const cbvh_params *p, cbvh_encoding enc, const cbvh_node_ctx *ctx,
                                        const uint8_t *bytes, cbvh_fast_child ch[2]) {
    uint32_t pm[3];
    return cbvh_fast_params_ok(p) && cbvh_fast_node_ctx_ok(p, ctx) &&
           cbvh_fast_pair_decode_valid(p, enc, ctx, bytes, ch, pm);
}

/* The context of child c along axis a, as cbvh_axis_child_ctx gives it from
 * the unit's decode: {scale, child_scale(s - r), (r + pmod) mod 2^N,
 * clb = RD(u + r 2^e)}.  ppm: the parent context's pmod along a (from
 * cbvh_fast_pair_decode_valid).  plo: u + r 2^e exactly in binary64 (or
 * NULL); clb is rounded from it when the result is normal or zero, else the
 * unit (cbvh_axis_decode) computes it.
 * Valid when pc is: parent_scale = pc's scale <= 126; the child scale lies in
 * [min_scale, pc's scale] (cells s - r <= 2^N, clamped to min_scale <= pc's
 * scale); lb_mod is masked; clb is finite or -Inf (RD never rounds to +Inf or
 * NaN: a positive overflow gives FLT_MAX). */
static inline void cbvh_fast_child_ctx(const cbvh_params *p, cbvh_encoding enc, const cbvh_axis_ctx *pc,
                                       uint32_t ppm, const cbvh_fast_child *fc, int a, const double *plo,
                                       cbvh_axis_ctx *cc) {
    uint32_t r = fc->r[a];
    cc->parent_scale = pc->scale;
    cc->scale = cbvh_grid_child_scale(p, pc->scale, fc->s[a] - r);
    cc->lb_mod = (r + ppm) & cbvh_grid_mask(p);
    if (!plo || !cbvh_rbf_rd32(*plo, &cc->clb)) {
        cbvh_axis_code code;
        cbvh_axis_decode(p, enc, pc, fc->lc[a], fc->uc[a], &code);
        cc->clb = code.clb;
    }
}

#endif
