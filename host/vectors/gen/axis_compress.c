/* Vectors of the single-axis compressor (docs/datapath.md §6). */
#include "vectors/gen/gen.h"

static void emit_compress(gen_t *g, cbvh_f32 lo, cbvh_f32 hi, int e) {
    if (!valid_scale_word(e)) return;
    uint32_t in[3] = {lo, hi, cbvh_scale_to_word(e)};
    vg_emit(g, in);
}

static void put_compress(gen_t *g, cbvh_f32 lo, cbvh_f32 hi, int scale) { emit_compress(g, lo, hi, scale); }

/* Scales around the estimate: estimate-1 (forces NO_FIT), the estimate,
 * +1..+3, the minimum and the maximum scale. */
static void compress_scales(gen_t *g, cbvh_f32 lo, cbvh_f32 hi, int all) {
    cbvh_params p = g->spec->cfg.params;
    int est;
    if (cbvh_scale_estimate(&p, lo, hi, &est) != 0) est = 0;
    emit_compress(g, lo, hi, est);
    if (est - 1 >= g->ms) emit_compress(g, lo, hi, est - 1);
    emit_compress(g, lo, hi, est + 1);
    if (all) {
        emit_compress(g, lo, hi, est + 2);
        emit_compress(g, lo, hi, est + 3);
    }
    if (est != g->ms) emit_compress(g, lo, hi, g->ms);
    if (all && est != CBVH_SCALE_CEIL) emit_compress(g, lo, hi, CBVH_SCALE_CEIL);
}

static void gen_compress(gen_t *g, size_t target) {
    if (!g->random_only) { /* level-1 structured cases */
        box_t boxes[2048];
        size_t nb = vg_structured_boxes(boxes, 2048, 2);
        for (size_t i = 0; i < nb && i < 2048; i++) compress_scales(g, boxes[i].lo, boxes[i].hi, i % 3 == 0);
        vg_box_rejects(g, put_compress, 0);
        /* Bad scales: below min_scale, above 126, the 8-bit extremes. */
        static const cbvh_f32 some[][2] = {{F_ONE, 0x40400000}, {0, 0}, {F_NEG_0_4, F_NEG_0_4}, {CBVH_F32_MAX, CBVH_F32_MAX}};
        for (int i = 0; i < 4; i++) {
            emit_compress(g, some[i][0], some[i][1], g->ms - 1);
            emit_compress(g, some[i][0], some[i][1], 127);
            emit_compress(g, some[i][0], some[i][1], -128);
        }
    }
    while (g->n < target && !g->oom) {
        box_t b = vg_rnd_box(&g->rng);
        int est;
        cbvh_params p = g->spec->cfg.params;
        if (cbvh_scale_estimate(&p, b.lo, b.hi, &est) != 0) est = 0;
        int e;
        switch (rnd_below(&g->rng, 4)) {
        case 0: e = (int)rnd_range(&g->rng, g->ms, CBVH_SCALE_CEIL); break;
        case 1: e = est; break;
        default: e = est + (int)rnd_range(&g->rng, -2, 4); break;
        }
        if (e < g->ms - 1) e = g->ms - 1;
        emit_compress(g, b.lo, b.hi, e);
    }
}

static void reject_combinations_compress(gen_t *g) {
    const cbvh_f32 F3 = 0x40400000u; /* 3.0 */
    const cbvh_f32 boxes[][2] = {{F_ONE, F3},         {F_QNAN, F3}, {F_ONE, CBVH_F32_POS_INF}, {F3, F_ONE},
                                 {CBVH_F32_POS_INF, F_ONE}, {F_ONE, CBVH_F32_NEG_INF}, {F_QNAN, F_QNAN}};
    const int valid = g->ms <= 0 ? 0 : g->ms;
    const int scales[] = {valid, g->ms - 1, 127, -128};
    for (size_t b = 0; b < sizeof boxes / sizeof boxes[0]; b++)
        for (size_t e = 0; e < sizeof scales / sizeof scales[0]; e++) emit_compress(g, boxes[b][0], boxes[b][1], scales[e]);
}

const vg_unit vg_axis_compress = {"axis_compress", 2000, gen_compress, NULL, 0, reject_combinations_compress, 1, 1};
