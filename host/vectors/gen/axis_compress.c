/* Vectors of the single-axis compressor (docs/datapath.md §6). */
#include "vectors/gen/gen.h"

/* Input words: lb ub scale node_clb. */
static void emit_compress_in(gen_t *g, cbvh_f32 lo, cbvh_f32 hi, int e, cbvh_f32 node_clb) {
    if (!valid_scale_word(e)) return;
    uint32_t in[4] = {lo, hi, cbvh_scale_to_word(e), node_clb};
    vg_emit(g, in);
}

/* The cases of generators 1 to 8 (three inputs then): the box in the window
 * that starts at its own lowest cell, node_clb = lo, so that OUTSIDE is set
 * exactly with NO_FIT and every earlier expected output is unchanged. */
static void emit_compress(gen_t *g, cbvh_f32 lo, cbvh_f32 hi, int e) { emit_compress_in(g, lo, hi, e, lo); }

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

/* Level 2's random part (generator 9): a node lower bound for [lo, hi] at
 * scale e: lo's own window, one j cells lower or higher (the window's ends
 * around the box), off the grid, -Inf (-2^128) or any float.  Level 1's
 * random part keeps lo, so its inputs are generator 8's. */
static cbvh_f32 rnd_node_clb(rng_t *r, cbvh_f32 lo, int e, int n) {
    cbvh_params own = {n, CBVH_SCALE_FLOOR};
    cbvh_axis_code c;
    if (cbvh_axis_compress(&own, lo, lo, e, lo, &c) & CBVH_ST_REJECT) return lo;
    switch (rnd_below(r, 6)) {
    case 0: return lo;
    case 1: return rnd_below(r, 4) ? vg_rnd_float(r) : CBVH_F32_NEG_INF;
    case 2: return vg_add_cells(c.clb, -(int64_t)rnd_below(r, ((uint64_t)1 << n) + 3), e, CBVH_RND_DOWN);
    case 3: return vg_add_cells(c.clb, (int64_t)rnd_range(r, 1, 2), e, CBVH_RND_DOWN);
    default: return vg_nudge(r, vg_add_cells(c.clb, -(int64_t)rnd_below(r, 3), e, CBVH_RND_DOWN));
    }
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
        cbvh_f32 node = g->random_only && e >= g->ms ? rnd_node_clb(&g->rng, b.lo, e, g->N) : b.lo;
        emit_compress_in(g, b.lo, b.hi, e, node);
    }
}

/* ---- generator 9: the node's window (OUTSIDE, datapath.md §6) ------------------
 *
 * A node's children are compressed at its child scale e and decoded from its
 * lower bound u = node_clb over 2^N cells, the window [u, u + 2^(N+e)).  The
 * compressor had no node input, so a child leaving the window compressed with
 * status 0 to codes that decode elsewhere (N = 3, node [0, 7], child [8, 8]:
 * codes (0, 1), decoded [0, 1]).  Per node context: children inside it,
 * touching either end from inside (the window's first and last binary32),
 * one ulp past either end, across both, entirely below or above, the node's
 * own box and its upper bound; the same with node_clb one ulp off the grid
 * (the window is floor(node_clb / 2^e)'s); then random node/child pairs from
 * a stream of their own. */

static void window_children(gen_t *g, const cbvh_axis_ctx *c, box_t node) {
    vg_window w = vg_window_of(c, g->N);
    const cbvh_f32 below = down(w.first);
    const box_t ch[] = {
        node,                   {node.hi, node.hi},       {w.first, w.first},      {below, w.first},
        {below, below},         {w.last, w.last},         {up(w.first), down(w.last)}, {w.first, w.last},
        {w.last, w.past},       {w.past, w.past},         {below, w.past},          {w.past, up(w.past)},
    };
    const int nch = w.has_past ? 12 : 8; /* the window reaches past FLT_MAX: nothing lies beyond it */
    for (int i = 0; i < nch; i++) {
        box_t b = ch[i];
        if (cbvh_f32_cmp(b.lo, b.hi) > 0) continue;
        emit_compress_in(g, b.lo, b.hi, c->scale, c->clb);
    }
    /* node_clb off the grid: one ulp above u is in u's cell (the same
     * window); one ulp below moves the window down one cell */
    const cbvh_f32 off[2] = {up(c->clb), down(w.first)};
    for (int k = 0; k < 2; k++) {
        if (c->clb == CBVH_F32_NEG_INF || cbvh_f32_is_zero(c->clb)) break;
        emit_compress_in(g, w.first, w.first, c->scale, off[k]);
        emit_compress_in(g, w.last, w.last, c->scale, off[k]);
    }
}

static void window_cases(gen_t *g) {
    const cbvh_params *p = &g->spec->cfg.params;
    /* the root boxes, and the example above at every N: node [0, 2^N - 1],
     * window [0, 2^N) at scale 0, whose first binary32 past it gives the
     * child [2^N, 2^N] */
    const box_t example = {0, dyadic(((int64_t)1 << g->N) - 1, 0)};
    for (int i = 0; i <= N_ROOT; i++) {
        box_t node = i < N_ROOT ? vg_root_boxes[i] : example;
        cbvh_axis_ctx c;
        if (cbvh_axis_root_ctx(p, node.lo, node.hi, &c) != 0) continue;
        window_children(g, &c, node);
    }
    /* random node/child pairs: a node box and its context (the root's or one
     * level down), and a child inside it, at the window's ends or anywhere */
    rng_t wr;
    rng_seed(&wr, g->stream ^ UINT64_C(0x0D1DE5C0FFEE0009));
    for (int i = 0; i < 160 && !g->oom; i++) {
        box_t node = vg_rnd_box(&wr);
        cbvh_axis_ctx c;
        if (cbvh_axis_root_ctx(p, node.lo, node.hi, &c) != 0) continue;
        if (rnd_below(&wr, 2)) {
            box_t sub = vg_rnd_sub_box(&wr, node);
            cbvh_axis_code code;
            if (cbvh_axis_compress(p, sub.lo, sub.hi, c.scale, c.clb, &code) != 0) continue;
            c = cbvh_axis_child_ctx(&c, &code);
            node = sub;
        }
        vg_window w = vg_window_of(&c, g->N);
        box_t b;
        switch (rnd_below(&wr, 4)) {
        case 0: b = vg_rnd_sub_box(&wr, node); break;
        case 1: /* from near the window's start */
            b.lo = vg_nudge(&wr, rnd_below(&wr, 2) ? w.first : down(w.first));
            b.hi = vg_nudge(&wr, rnd_below(&wr, 2) ? w.last : b.lo);
            break;
        case 2: /* to near its end */
            b.hi = vg_nudge(&wr, w.has_past && rnd_below(&wr, 2) ? w.past : w.last);
            b.lo = vg_nudge(&wr, rnd_below(&wr, 2) ? w.first : b.hi);
            break;
        default: b = vg_rnd_box(&wr); break;
        }
        if (cbvh_f32_cmp(b.lo, b.hi) > 0) {
            cbvh_f32 t = b.lo;
            b.lo = b.hi;
            b.hi = t;
        }
        emit_compress_in(g, b.lo, b.hi, c.scale, c.clb);
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
    window_cases(g);
    /* Generator 9: node_clb's faults (NaN, signalling NaN, +Inf; -Inf is the
     * valid -2^128) with each of the box and scale faults above: NAN_INF
     * comes before BAD_SCALE and INVERTED, from node_clb as from a bound. */
    static const cbvh_f32 nodes[] = {F_QNAN, 0x7F800001u, CBVH_F32_POS_INF, CBVH_F32_NEG_INF};
    for (size_t k = 0; k < sizeof nodes / sizeof nodes[0]; k++)
        for (size_t b = 0; b < sizeof boxes / sizeof boxes[0]; b++)
            for (size_t e = 0; e < sizeof scales / sizeof scales[0]; e++)
                emit_compress_in(g, boxes[b][0], boxes[b][1], scales[e], nodes[k]);
}

const vg_unit vg_axis_compress = {"axis_compress", 2000, gen_compress, NULL, 0, reject_combinations_compress, 1, 1};
