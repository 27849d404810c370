/* Vectors of the QBVH stack unit (docs/qbvh.md §2). */
#include "vectors/gen/gen.h"

#include "cbvh/qbvh_stack.h"

static void emit_qstack(gen_t *g, uint32_t op, uint32_t first, uint32_t mask, const cbvh_f32 t[4], uint32_t entry) {
    uint32_t in[8] = {op, first, mask, t[0], t[1], t[2], t[3], entry};
    vg_emit(g, in);
}

static void gen_qbvh_stack(gen_t *g, size_t target) {
    static const cbvh_f32 zero_t[4] = {0, 0, 0, 0};
    if (!g->random_only) {
        /* every hit mask x hit-time patterns: distinct, all equal, pairs equal, +-0, Inf, FLT_MAX, reversed */
        static const cbvh_f32 tp[][4] = {
            {F_ONE, 0x40000000u, 0x40400000u, 0x40800000u}, {0x40800000u, 0x40400000u, 0x40000000u, F_ONE},
            {F_ONE, F_ONE, F_ONE, F_ONE},                   {0, CBVH_F32_SIGN, 0, CBVH_F32_SIGN},
            {0x40000000u, F_ONE, 0x40000000u, F_ONE},       {CBVH_F32_MAX, CBVH_F32_POS_INF, F_HALF, CBVH_F32_MAX},
            {0xBF800000u, F_ONE, CBVH_F32_NEG_INF, 0},      {0x3F800001u, F_ONE, 0x3F7FFFFFu, F_ONE}};
        static const uint32_t firsts[] = {0, 1, 5, 0x3FFFFFCu, 0x3FFFFFFu, 0x4000000u, 0xFFFFFFFFu};
        for (size_t k = 0; k < sizeof tp / sizeof tp[0]; k++)
            for (uint32_t m = 0; m < 16; m++) emit_qstack(g, 0, 5, m, tp[k], 0);
        for (size_t f = 0; f < sizeof firsts / sizeof firsts[0]; f++) {
            emit_qstack(g, 0, firsts[f], 15, tp[1], 0);
            emit_qstack(g, 0, firsts[f], 1, tp[1], 0); /* one hit: nothing pushed, ID still checked */
        }
        /* rejects: NaN hit time (hit and not hit), mask > 15, bad op */
        const cbvh_f32 tn[4] = {F_ONE, 0x7FC00000u, 0x40000000u, 0x7F800001u};
        emit_qstack(g, 0, 5, 15, tn, 0);
        emit_qstack(g, 0, 5, 5, tn, 0);
        emit_qstack(g, 0, 5, 16, tp[0], 0);
        emit_qstack(g, 2, 5, 15, tp[0], 0);
        emit_qstack(g, 0xF, 5, 15, tp[0], 0);
        /* pop: every offset block with IDs at the ends of the 26-bit range */
        static const uint32_t ids[] = {0, 7, 0x3FFFFFCu, 0x3FFFFFFu};
        for (size_t i = 0; i < sizeof ids / sizeof ids[0]; i++)
            for (uint32_t b = 0; b < 64; b++) emit_qstack(g, 1, 0, 0, zero_t, ids[i] | b << 26);
    }
    while (g->n < target && !g->oom) {
        uint32_t op = (uint32_t)rnd_below(&g->rng, 2);
        if (op == 1) {
            uint32_t entry = (uint32_t)rng_next(&g->rng);
            emit_qstack(g, 1, 0, 0, zero_t, entry);
            continue;
        }
        uint32_t first = (uint32_t)rnd_below(&g->rng, CBVH_QSTACK_ID_LIMIT + 4u);
        uint32_t mask = (uint32_t)rnd_below(&g->rng, 16);
        cbvh_f32 t[4];
        uint64_t tie = rnd_below(&g->rng, 4); /* 1 in 4: hit times from a set of two values */
        cbvh_f32 a = vg_rnd_float(&g->rng);
        cbvh_f32 b = vg_rnd_float(&g->rng);
        for (int c = 0; c < 4; c++) {
            if (tie == 0) {
                uint64_t pick = rnd_below(&g->rng, 2);
                t[c] = pick ? a : b;
            } else {
                t[c] = vg_rnd_float(&g->rng);
            }
        }
        emit_qstack(g, 0, first, mask, t, 0);
    }
    if (g->random_only) return;
    /* Generator 2, after the random part (no draws): NaN and Inf in the lanes
     * that did not hit (ignored, not rejected) for every mask, and the first
     * child ID at 2^26 - 1, 2^26 and 2^26 + 1 for masks with 0..4 hits. */
    static const cbvh_f32 odd[4] = {0x7FC00000u, 0x7F800001u, CBVH_F32_POS_INF, 0xFFC00000u};
    for (uint32_t m = 0; m < 15; m++) {
        cbvh_f32 t[4];
        for (int c = 0; c < 4; c++) t[c] = ((m >> c) & 1u) ? F_ONE + (uint32_t)c : odd[c];
        emit_qstack(g, 0, 5, m, t, 0);
    }
    static const cbvh_f32 tdist[4] = {0x40400000u, F_ONE, 0x40800000u, 0x40000000u};
    static const uint32_t masks[] = {0, 1, 3, 7, 15};
    for (size_t k = 0; k < sizeof masks / sizeof masks[0]; k++)
        for (uint32_t d = 0; d < 3; d++) emit_qstack(g, 0, CBVH_QSTACK_ID_LIMIT - 1u + d, masks[k], tdist, 0);
}

/* QBVH stack: a push with a NaN hit time and a first-child ID >= 2^26 (NAN_INF
 * wins), an invalid op with both, and pops whose push-only inputs (first,
 * hit_mask, t) hold those faults: a pop ignores them and never rejects. */
static void reject_combinations_qstack(gen_t *g) {
    const cbvh_f32 t_nan[4] = {F_ONE, F_QNAN, 0x40000000u, F_QNAN};
    const cbvh_f32 t_ok[4] = {F_ONE, 0x40400000u, 0x40000000u, 0x40800000u};
    static const uint32_t masks[] = {0, 1, 2, 3, 10, 15};
    static const uint32_t firsts[] = {5, CBVH_QSTACK_ID_LIMIT, 0xFFFFFFFFu};
    static const uint32_t entries[] = {0x00000005u, 0xE4000007u, 0x03FFFFFFu};
    for (size_t m = 0; m < sizeof masks / sizeof masks[0]; m++)
        for (size_t f = 0; f < sizeof firsts / sizeof firsts[0]; f++) {
            emit_qstack(g, 0, firsts[f], masks[m], t_nan, 0);
            emit_qstack(g, 0, firsts[f], masks[m], t_nan, entries[f]); /* entry is pop-only */
            emit_qstack(g, 2, firsts[f], masks[m], t_nan, 0);
            emit_qstack(g, 15, firsts[f], masks[m], t_ok, 0);
            emit_qstack(g, 1, firsts[f], masks[m], t_nan, entries[f]);
            emit_qstack(g, 1, firsts[f], masks[m], t_ok, entries[(f + 1) % 3]);
        }
}

const vg_unit vg_qbvh_stack = {"qbvh_stack", 2000, gen_qbvh_stack, NULL, 0, reject_combinations_qstack, 0, 0};
