/* Vectors of the axis decoder (docs/datapath.md §7). */
#include "vectors/gen/gen.h"

static void emit_decode(gen_t *g, const cbvh_axis_ctx *c, uint32_t lb_code, uint32_t ub_code) {
    if (!valid_scale_word(c->parent_scale) || !valid_scale_word(c->scale)) return;
    uint32_t in[6] = {cbvh_scale_to_word(c->parent_scale), cbvh_scale_to_word(c->scale), c->lb_mod, c->clb, lb_code,
                      ub_code};
    vg_emit(g, in);
}

static box_t pick_root(gen_t *g, int i) {
    if (i < N_ROOT) return vg_root_boxes[i];
    return vg_rnd_box(&g->rng);
}

/* One chain: a root box, a child inside it and a grandchild inside the
 * child; emits the decode vectors of both levels (the stored codes of a real
 * compression) plus random codes under the same contexts. */
static void decode_chain(gen_t *g, box_t root, int extras) {
    const cbvh_params *p = &g->spec->cfg.params;
    cbvh_encoding enc = g->spec->cfg.enc;
    cbvh_axis_ctx ctx;
    if (cbvh_axis_root_ctx(p, root.lo, root.hi, &ctx) != 0) return;
    box_t node = root;
    for (int depth = 0; depth < 2; depth++) {
        box_t child = vg_rnd_sub_box(&g->rng, node);
        cbvh_axis_code code;
        if (cbvh_axis_compress(p, child.lo, child.hi, ctx.scale, ctx.clb, &code) & CBVH_ST_REJECT) return;
        uint32_t lc, uc;
        cbvh_axis_store_codes(p, enc, &ctx, &code, &lc, &uc);
        emit_decode(g, &ctx, lc, uc);
        if (extras) {
            uint32_t a = (uint32_t)rnd_below(&g->rng, g->mask + 1u), b = (uint32_t)rnd_below(&g->rng, g->mask + 1u);
            emit_decode(g, &ctx, a, b);
        }
        ctx = cbvh_axis_child_ctx(&ctx, &code);
        node = child;
    }
}

/* Generator 2, after the random part (no draws: level 1's random part and
 * level 2's are unchanged): contexts whose lower bound clb has its lowest
 * significand bit d = 33..40 binades above or below the scale, around the
 * widest alignment u + r 2^e that fits a 64-bit datapath (the model's fast
 * path takes |d| <= 36), with codes for the first, last and whole-node cells. */
static void decode_alignment_limits(gen_t *g) {
    static const uint32_t fracs[4] = {0, CBVH_F32_FRAC, 0x400001u, 0x123457u};
    for (int d = -40; d <= 40; d++) {
        if (d > -33 && d < 33) continue;
        for (int v = 0; v < 4; v++) {
            cbvh_axis_ctx c;
            c.scale = g->ms + 7 * v;
            int eu = c.scale + d + CBVH_F32_ULP_BIAS; /* biased exponent of clb */
            if (c.scale > CBVH_SCALE_CEIL || cbvh_f32_field_not_normal((uint32_t)eu)) continue;
            c.parent_scale = c.scale + v % 3 > CBVH_SCALE_CEIL ? c.scale : c.scale + v % 3;
            c.lb_mod = (uint32_t)v & g->mask;
            c.clb = ((v & 2) ? CBVH_F32_SIGN : 0u) | (uint32_t)eu << CBVH_F32_FRAC_BITS | fracs[v];
            int shift = c.parent_scale - c.scale;
            uint32_t pmod = shift >= g->N ? 0 : (c.lb_mod << shift) & g->mask;
            uint32_t r = (uint32_t)v % 3u, sc = g->mask + 1u - (uint32_t)(v % 2); /* r < s <= 2^N */
            int modulo = g->spec->cfg.enc == CBVH_ENC_MODULO;
            uint32_t lc = modulo ? (r + pmod) & g->mask : r, uc = modulo ? (sc + pmod) & g->mask : sc & g->mask;
            emit_decode(g, &c, lc, uc);
        }
    }
}

static void gen_decode(gen_t *g, size_t target) {
    const cbvh_params *p = &g->spec->cfg.params;
    uint32_t full = g->mask + 1u;
    if (!g->random_only) { /* level-1 structured cases */
        /* Real chains from structured roots, several children each. */
        for (int i = 0; i < N_ROOT; i++)
            for (int k = 0; k < 12; k++) decode_chain(g, vg_root_boxes[i], 1);
        /* Corner codes under real contexts. */
        for (int i = 0; i < N_ROOT; i++) {
            cbvh_axis_ctx ctx;
            if (cbvh_axis_root_ctx(p, vg_root_boxes[i].lo, vg_root_boxes[i].hi, &ctx) != 0) continue;
            int shift = ctx.parent_scale - ctx.scale;
            uint32_t pmod = shift >= g->N ? 0 : (ctx.lb_mod << shift) & g->mask;
            emit_decode(g, &ctx, pmod, pmod);                       /* r = 0, s = 0 -> 2^N: the whole node */
            emit_decode(g, &ctx, pmod, (pmod + 1) & g->mask);       /* first cell */
            emit_decode(g, &ctx, (pmod + g->mask) & g->mask, pmod); /* last cell */
            emit_decode(g, &ctx, 0, 0);
            emit_decode(g, &ctx, g->mask, g->mask);                  /* r == s: inverted (unless s == 0) */
            emit_decode(g, &ctx, 1, 0);
            emit_decode(g, &ctx, full, 0);                           /* codes >= 2^N */
            emit_decode(g, &ctx, 0, full);
            emit_decode(g, &ctx, 0xFFF, 0xFFF);
            /* Bad contexts. */
            cbvh_axis_ctx b = ctx;
            b.lb_mod = full;
            emit_decode(g, &b, 0, 1);
            b = ctx;
            b.clb = 0x7FC00000;
            emit_decode(g, &b, 0, 1);
            b.clb = CBVH_F32_POS_INF;
            emit_decode(g, &b, 0, 1);
            b.clb = CBVH_F32_NEG_INF; /* valid: -2^128 */
            emit_decode(g, &b, 0, 1);
            emit_decode(g, &b, 0, 0);
            b = ctx;
            b.scale = g->ms - 1;
            emit_decode(g, &b, 0, 1);
            b = ctx;
            b.parent_scale = ctx.scale - 1;
            emit_decode(g, &b, 0, 1);
            b = ctx;
            b.parent_scale = 127;
            emit_decode(g, &b, 0, 1);
            b = ctx;
            b.parent_scale = CBVH_SCALE_CEIL;
            emit_decode(g, &b, 1, 3); /* shift >= N: p^ = 0 */
            b = ctx;
            b.scale = b.parent_scale = g->ms;
            emit_decode(g, &b, 2, 5); /* minimum-scale saturation */
        }
        /* Random contexts with every field in range. */
        for (int i = 0; i < 40; i++) {
            cbvh_axis_ctx c;
            c.scale = (int)rnd_range(&g->rng, g->ms, CBVH_SCALE_CEIL);
            c.parent_scale = (int)rnd_range(&g->rng, c.scale, CBVH_SCALE_CEIL);
            c.lb_mod = (uint32_t)rnd_below(&g->rng, full);
            c.clb = vg_rnd_float(&g->rng);
            uint32_t lc = (uint32_t)rnd_below(&g->rng, full);
            uint32_t uc = (uint32_t)rnd_below(&g->rng, full);
            emit_decode(g, &c, lc, uc);
        }
    }
    /* Then chains from random roots, every fourth from a structured one. */
    for (int i = 0; g->n < target && !g->oom; i++) decode_chain(g, pick_root(g, i % 4 == 0 ? (i / 4) % N_ROOT : N_ROOT), 1);
    if (!g->random_only) decode_alignment_limits(g);
}

/* Generator 7: node_clb far below the child grid, where the decoder's shift
 * of u_node reaches its clamp (every bit of u_node sticky).  The alignment
 * limits above stop at clb ~ 2^(scale-17); an RTL clamping that shift one
 * short left u_node's top bit in the sum and passed every vector, though it
 * gives pred(2^e) for a cub of 2^e - |clb| (a third mutation run,
 * docs/gateware.md).  clb = +-(1.f) 2^(scale+d+23) for d = -47 .. -51 (the
 * clamp starts at d = -49), -64 and -100, codes (r, s) = (0, 1), (1, 2),
 * (0, 2), (2, 3) with p^ = 0: with clb < 0, s = 1 and r = 1 the sum is
 * 2^24 - 1 units of 2^(e-24), on the binary32 grid. */
static void decode_clb_far_below(gen_t *g) {
    static const int ds[] = {-47, -48, -49, -50, -51, -64, -100};
    static const uint32_t fracs[] = {0, CBVH_F32_FRAC, 0x400001u};
    static const uint32_t rs[][2] = {{0, 1}, {1, 2}, {0, 2}, {2, 3}};
    cbvh_axis_ctx c;
    c.scale = g->ms + 3 > CBVH_SCALE_CEIL ? CBVH_SCALE_CEIL : g->ms + 3;
    c.parent_scale = c.scale;
    c.lb_mod = 0;
    for (size_t i = 0; i < sizeof ds / sizeof ds[0]; i++) {
        int eu = c.scale + ds[i] + CBVH_F32_ULP_BIAS; /* biased exponent of clb */
        if (cbvh_f32_field_not_normal((uint32_t)eu)) continue;
        for (size_t f = 0; f < sizeof fracs / sizeof fracs[0]; f++)
            for (int neg = 0; neg < 2; neg++)
                for (size_t k = 0; k < sizeof rs / sizeof rs[0]; k++) {
                    c.clb = (neg ? CBVH_F32_SIGN : 0u) | (uint32_t)eu << CBVH_F32_FRAC_BITS | fracs[f];
                    emit_decode(g, &c, rs[k][0], rs[k][1]);
                }
    }
}

static void reject_combinations_decode(gen_t *g) {
    const uint32_t full = g->mask + 1u;
    /* A valid context: ms <= scale <= parent_scale <= 126, p^ = 0. */
    cbvh_axis_ctx base;
    base.scale = g->ms + 2 > CBVH_SCALE_CEIL ? CBVH_SCALE_CEIL : g->ms + 2;
    base.parent_scale = base.scale + 2 > CBVH_SCALE_CEIL ? CBVH_SCALE_CEIL : base.scale + 2;
    base.lb_mod = 0;
    base.clb = F_ONE;
    for (int sc = 0; sc < 4; sc++)               /* none, scale < ms, parent_scale > 126, parent_scale < scale */
        for (int nc = 0; nc < 2; nc++)           /* none, node_lb_mod >= 2^N */
            for (int cl = 0; cl < 3; cl++)       /* none, clb NaN, clb +Inf */
                for (int cc = 0; cc < 3; cc++)   /* none, lb_code >= 2^N, ub_code >= 2^N */
                    for (int inv = 0; inv < 2; inv++) { /* r < s, r >= s */
                        cbvh_axis_ctx c = base;
                        if (sc == 1) c.scale = g->ms - 1;
                        if (sc == 2) c.parent_scale = 127;
                        if (sc == 3) c.parent_scale = c.scale - 1;
                        if (nc) c.lb_mod = full;
                        if (cl == 1) c.clb = F_QNAN;
                        if (cl == 2) c.clb = CBVH_F32_POS_INF;
                        uint32_t lc = inv ? 2 : 1, uc = inv ? 1 : 2;
                        if (cc == 1) lc = full;
                        if (cc == 2) uc = 0xFFF;
                        emit_decode(g, &c, lc, uc);
                    }
    decode_clb_far_below(g);
}

const vg_unit vg_axis_decode = {"axis_decode", 1500, gen_decode, NULL, 0, reject_combinations_decode, 1, 1};
