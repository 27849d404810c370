/* Vectors of the node-pair codec, both directions (docs/datapath.md §9): the
 * decoder's inputs are the encoder's words for the same pairs. */
#include "vectors/gen/gen.h"

#include <string.h>

typedef struct {
    box_t axis[3];
    cbvh_node_ctx ctx;
} node_t;

static int make_node(gen_t *g, node_t *nd, int i) {
    for (int a = 0; a < 3; a++) {
        /* Mix structured roots per axis so a node sees different cases on x, y, z. */
        nd->axis[a] = i < N_ROOT ? vg_root_boxes[(i + 5 * a) % N_ROOT] : vg_rnd_box(&g->rng);
        if (cbvh_axis_root_ctx(&g->spec->cfg.params, nd->axis[a].lo, nd->axis[a].hi, &nd->ctx.axis[a]) != 0) return -1;
    }
    return 0;
}

static uint32_t ptr_ones(int n) {
    int pb = cbvh_node_ptr_bits(n);
    return pb >= 32 ? 0xFFFFFFFFu : (1u << pb) - 1u;
}

static void ctx_words(const cbvh_node_ctx *c, uint32_t *w) {
    for (int a = 0; a < 3; a++) {
        w[4 * a] = cbvh_scale_to_word(c->axis[a].parent_scale);
        w[4 * a + 1] = cbvh_scale_to_word(c->axis[a].scale);
        w[4 * a + 2] = c->axis[a].lb_mod;
        w[4 * a + 3] = c->axis[a].clb;
    }
}

typedef struct {
    box_t b[3];
    uint32_t flags, ptr;
} child_t;

static child_t rnd_child(gen_t *g, const node_t *nd) {
    child_t c;
    for (int a = 0; a < 3; a++) c.b[a] = vg_rnd_sub_box(&g->rng, nd->axis[a]);
    uint32_t ones = ptr_ones(g->N);
    c.flags = (uint32_t)rnd_below(&g->rng, 2); /* leaf or inner */
    switch (rnd_below(&g->rng, 4)) {
    case 0: c.ptr = (uint32_t)rnd_below(&g->rng, 16); break;
    case 1: c.ptr = ones - 1; break;
    default: c.ptr = (uint32_t)rnd_below(&g->rng, (uint64_t)ones); break;
    }
    return c;
}

/* Sequenced on purpose: the order of initializers is unspecified in C. */
static void two_children(gen_t *g, const node_t *nd, child_t ch[2]) {
    ch[0] = rnd_child(g, nd);
    ch[1] = rnd_child(g, nd);
}

static void encode_inputs(const node_t *nd, const child_t ch[2], uint32_t *in) {
    ctx_words(&nd->ctx, in);
    for (int c = 0; c < 2; c++) {
        uint32_t *w = in + 12 + 8 * c;
        for (int a = 0; a < 3; a++) {
            w[2 * a] = ch[c].b[a].lo;
            w[2 * a + 1] = ch[c].b[a].hi;
        }
        w[6] = ch[c].flags;
        w[7] = ch[c].ptr;
    }
}

/* The structured variations of one node's two children (encoder inputs). */
static int pair_cases(gen_t *g, const node_t *nd, child_t out[][2], int max) {
    int n = 0;
    uint32_t ones = ptr_ones(g->N);
    child_t a = rnd_child(g, nd), b = rnd_child(g, nd);
#define CASE(x, y)                                                                                                    \
    do {                                                                                                               \
        if (n < max) {                                                                                                 \
            out[n][0] = (x);                                                                                           \
            out[n][1] = (y);                                                                                           \
            n++;                                                                                                       \
        }                                                                                                              \
    } while (0)
    CASE(a, b);
    child_t t = a, u = b;
    t.flags = 1; /* two leaves */
    u.flags = 1;
    CASE(t, u);
    u.flags = 2; /* second empty, its box ignored */
    CASE(t, u);
    t.flags = 3; /* both empty (leaf bit with empty too) */
    u.flags = 2;
    CASE(t, u);
    t = a;
    t.flags = 0;
    t.ptr = ones; /* inner child at the all-ones pointer */
    u = b;
    u.flags = 1;
    u.ptr = ones - 1; /* largest leaf pointer */
    CASE(t, u);
    u.ptr = ones; /* leaf at the reserved pointer: bad format */
    CASE(t, u);
    if (ones != 0xFFFFFFFFu) {
        t.ptr = ones + 1; /* pointer too wide */
        CASE(t, b);
    }
    t = a;
    t.flags = 0xC; /* unused flag bits */
    CASE(t, b);
    /* A child box wider than the node: NO_FIT on that axis. */
    t = a;
    t.b[rnd_below(&g->rng, 3)] = (box_t){CBVH_F32_MAX | CBVH_F32_SIGN, CBVH_F32_MAX};
    CASE(t, b);
    /* NaN / inverted child. */
    t = a;
    t.b[rnd_below(&g->rng, 3)].lo = 0x7FC00000;
    CASE(b, t);
    t = a;
    t.b[1] = (box_t){t.b[1].hi, t.b[1].lo};
    if (cbvh_f32_cmp(t.b[1].lo, t.b[1].hi) > 0) CASE(t, b);
#undef CASE
    return n;
}

/* Level 1's node i (structured roots, twice round) and its pair cases; -1
 * when the node has no context. */
static int structured_node(gen_t *g, int i, node_t *nd, child_t cases[16][2]) {
    if (make_node(g, nd, i % N_ROOT) != 0) return -1;
    return pair_cases(g, nd, cases, 16);
}

static void emit_encode(gen_t *g, const node_t *nd, const child_t ch[2]) {
    uint32_t in[28];
    encode_inputs(nd, ch, in);
    vg_emit(g, in);
}

static void gen_encode_pair(gen_t *g, size_t target) {
    if (!g->random_only) { /* level-1 structured cases */
        for (int i = 0; i < N_ROOT * 2 && !g->oom; i++) {
            node_t nd;
            child_t cases[16][2];
            int nc = structured_node(g, i, &nd, cases);
            for (int k = 0; k < nc; k++) emit_encode(g, &nd, cases[k]);
        }
        /* Bad contexts: a bad scale, an out-of-range lb_mod, a NaN clb on one axis. */
        for (int i = 0; i < 6; i++) {
            node_t nd;
            if (make_node(g, &nd, i) != 0) continue;
            child_t ch[2];
            two_children(g, &nd, ch);
            cbvh_axis_ctx *ax = &nd.ctx.axis[i % 3];
            if (i < 3) ax->scale = g->ms - 1;
            else if (i < 5) ax->lb_mod = g->mask + 1u;
            else ax->clb = 0x7FC00000;
            emit_encode(g, &nd, ch);
        }
    }
    while (g->n < target && !g->oom) {
        node_t nd;
        if (make_node(g, &nd, N_ROOT) != 0) continue;
        child_t ch[2];
        two_children(g, &nd, ch);
        if (rnd_below(&g->rng, 8) == 0) ch[rnd_below(&g->rng, 2)].flags = 2;
        emit_encode(g, &nd, ch);
    }
}

static void emit_decode_pair(gen_t *g, const cbvh_node_ctx *ctx, const uint32_t *words, int nw) {
    uint32_t in[18];
    ctx_words(ctx, in);
    for (int i = 0; i < nw; i++) in[12 + i] = words[i];
    vg_emit(g, in);
}

/* Decoder inputs from real node pairs (encoded by the model's encoder unit),
 * then corruptions of them: reserved bits, flipped code bits, garbage. */
static void decode_pair_node(gen_t *g, const cbvh_unit *enc_unit, const node_t *nd, child_t cases[][2], int nc,
                             int corrupt) {
    int nw = (int)cbvh_nodepair_bytes(g->N) / 4;
    int w = cbvh_node_bits(g->N), pb = cbvh_node_ptr_bits(g->N);
    int reserved = w - 6 * g->N - 1 - pb; /* per node */
    for (int k = 0; k < nc; k++) {
        uint32_t in[28], out[8];
        encode_inputs(nd, cases[k], in);
        enc_unit->eval(&g->spec->cfg, in, out);
        if (out[nw] & (CBVH_ST_REJECT | CBVH_ST_BAD_FORMAT)) continue; /* zeroed words: nothing to decode */
        emit_decode_pair(g, &nd->ctx, out, nw);
        if (!corrupt || k > 1) continue;
        uint32_t bad[6];
        if (reserved > 0) {
            memcpy(bad, out, sizeof bad);
            int node = (int)rnd_below(&g->rng, 2);
            int bit = node * w + 6 * g->N + 1 + pb + (int)rnd_below(&g->rng, (uint64_t)reserved);
            bad[bit / 32] ^= 1u << (bit % 32);
            emit_decode_pair(g, &nd->ctx, bad, nw);
        }
        memcpy(bad, out, sizeof bad);
        int cb = (int)rnd_below(&g->rng, (uint64_t)g->N * 6); /* one code bit of node 0 flipped */
        bad[cb / 32] ^= 1u << (cb % 32);
        emit_decode_pair(g, &nd->ctx, bad, nw);
        for (int j = 0; j < nw; j++) bad[j] = (uint32_t)rng_next(&g->rng); /* garbage words */
        emit_decode_pair(g, &nd->ctx, bad, nw);
    }
}

static void gen_decode_pair(gen_t *g, size_t target) {
    const cbvh_unit *enc_unit = cbvh_unit_find("nodepair_encode");
    int nw = (int)cbvh_nodepair_bytes(g->N) / 4;
    if (!g->random_only) { /* level-1 structured cases */
        for (int i = 0; i < N_ROOT * 2 && !g->oom; i++) {
            node_t nd;
            child_t cases[16][2];
            int nc = structured_node(g, i, &nd, cases);
            if (nc < 0) continue;
            decode_pair_node(g, enc_unit, &nd, cases, nc, 1);
            if (i >= N_ROOT) continue;
            /* Malformed empty marker: leaf + all-ones pointer but a nonzero code. */
            child_t ch[2];
            two_children(g, &nd, ch);
            ch[0].flags = 2;
            uint32_t in[28], out[8];
            encode_inputs(&nd, ch, in);
            enc_unit->eval(&g->spec->cfg, in, out);
            out[0] |= 1u;
            emit_decode_pair(g, &nd.ctx, out, nw);
            static const uint32_t zero[6], ones[6] = {~0u, ~0u, ~0u, ~0u, ~0u, ~0u};
            emit_decode_pair(g, &nd.ctx, zero, nw);
            emit_decode_pair(g, &nd.ctx, ones, nw);
            cbvh_node_ctx bc = nd.ctx;
            bc.axis[i % 3].parent_scale = bc.axis[i % 3].scale - 1; /* bad context */
            emit_decode_pair(g, &bc, out, nw);
        }
    }
    while (g->n < target && !g->oom) {
        node_t nd;
        if (make_node(g, &nd, N_ROOT) != 0) continue;
        if (rnd_below(&g->rng, 16) == 0) { /* garbage words under a real context */
            uint32_t junk[6];
            for (int j = 0; j < nw; j++) junk[j] = (uint32_t)rng_next(&g->rng);
            emit_decode_pair(g, &nd.ctx, junk, nw);
            continue;
        }
        child_t ch[1][2];
        two_children(g, &nd, ch[0]);
        decode_pair_node(g, enc_unit, &nd, ch, 1, 0);
    }
}

/* Node pairs: the status is an OR over the axes and children (datapath.md §9),
 * so these combine a context rejected on one or several axes (one fault or
 * two on one axis) with children that are NaN, inverted, too wide for the
 * grid (NO_FIT), with a pointer wider than its field, empty with a NaN box and
 * a stray pointer, or with unused flag bits; the decoder gets the encoder's
 * words for such pairs (and an all-empty pair, a malformed empty marker with a
 * reserved bit) under the same contexts. */
static void np_context(gen_t *g, int variant, cbvh_node_ctx *c) {
    int e = g->ms > -4 ? g->ms : -4;
    for (int a = 0; a < 3; a++) c->axis[a] = (cbvh_axis_ctx){e, e, 0, 0};
    if (variant == 1) c->axis[0].scale = g->ms - 1;
    if (variant == 2) c->axis[0].scale = g->ms - 1, c->axis[0].clb = F_QNAN;
    if (variant == 3) c->axis[0].scale = g->ms - 1, c->axis[1].clb = F_QNAN, c->axis[2].lb_mod = g->mask + 1u;
}

static void np_children(gen_t *g, int variant, child_t ch[2]) {
    const box_t good = {0x3E800000u /* 0.25 */, 0x3F000000u /* 0.5 */};
    for (int c = 0; c < 2; c++) {
        for (int a = 0; a < 3; a++) ch[c].b[a] = good;
        ch[c].flags = (uint32_t)c; /* inner, leaf */
        ch[c].ptr = 7;
    }
    switch (variant) {
    case 1: ch[0].b[0].lo = F_QNAN, ch[1].b[2].hi = 0x42C80000u /* 100: NO_FIT */; break;
    case 2: ch[0].b[1] = (box_t){0x40400000u, F_ONE}; break; /* inverted */
    case 3: ch[0].ptr = ptr_ones(g->N) == 0xFFFFFFFFu ? 0xFFFFFFFFu : ptr_ones(g->N) + 1u, /* inner: too wide */
            ch[1].b[0].hi = 0x42C80000u;
            break;
    case 4: ch[0].flags = 2, ch[0].b[0].lo = F_QNAN, ch[0].ptr = 0xFFFFFFFFu; break; /* empty */
    case 5: ch[0].flags = 0xD, ch[1].ptr = ptr_ones(g->N); break; /* unused flag bits; leaf at the marker */
    case 6: ch[0].flags = ch[1].flags = 2; break; /* both empty */
    default: break;
    }
}

static void emit_pair(gen_t *g, const node_t *nd, const child_t ch[2], int decode);
static void outside_pairs(gen_t *g, int decode);

static void reject_combinations_nodepair(gen_t *g, int decode) {
    const cbvh_unit *enc_unit = cbvh_unit_find("nodepair_encode");
    int nw = (int)cbvh_nodepair_bytes(g->N) / 4;
    for (int cv = 0; cv < 4; cv++)
        for (int kv = 0; kv < 7; kv++) {
            node_t nd;
            np_context(g, cv, &nd.ctx);
            child_t ch[2];
            np_children(g, kv, ch);
            if (!decode) {
                emit_encode(g, &nd, ch);
                continue;
            }
            /* the words of the pair under the valid context (zero if rejected) */
            node_t ok;
            np_context(g, 0, &ok.ctx);
            uint32_t in[28], out[8];
            encode_inputs(&ok, ch, in);
            enc_unit->eval(&g->spec->cfg, in, out);
            emit_decode_pair(g, &nd.ctx, out, nw);
            if (kv == 6) { /* both empty; node 0's marker with a code bit set, the top bit of the pair set
                            * (reserved where the layout has spare bits) */
                out[0] |= 1u;
                out[nw - 1] |= 0x80000000u;
                emit_decode_pair(g, &nd.ctx, out, nw);
            }
        }
    /* Generator 6, after the clean-room RTLs (docs/gateware.md): p^ is 0 for
     * every shift parent_scale - scale >= N the ports allow.  A tree's own
     * contexts have shifts <= N, so no earlier node-pair vector had one of 16
     * or more, and a p^ built from the shift's low four bits passed.  Shifts
     * N, N + 1 and 15 ... 130 (those that keep parent_scale <= 126), with a
     * nonzero node lower-bound code on every axis, and the shift differing
     * per axis; children a few cells wide at the child scale.  The decoder
     * gets the encoder's words under the same context. */
    static const int wide[] = {0, 1, 15, 16, 17, 20, 31, 32, 33, 48, 63, 64, 65, 96, 127, 128, 129, 130};
    for (size_t i = 0; i < sizeof wide / sizeof wide[0]; i++) {
        int sh = wide[i] < 2 ? g->N + wide[i] : wide[i];
        int e = CBVH_SCALE_CEIL - sh - 2 < -4 ? CBVH_SCALE_CEIL - sh - 2 : -4;
        if (e < g->ms) continue;
        node_t nd;
        child_t ch[2];
        for (int a = 0; a < 3; a++) {
            static const uint32_t lbm[3] = {1u, 0xFFFFFFFFu, 0x5u};
            nd.ctx.axis[a] = (cbvh_axis_ctx){e + sh + a, e, lbm[a] & g->mask, a == 1 ? cbvh_f32_make(1, e + 3, 0) : 0};
            for (int c = 0; c < 2; c++)
                ch[c].b[a] = (box_t){cbvh_f32_make(0, e + 2, c ? 0x400000u : 0), cbvh_f32_make(0, e + 3, c ? 0 : 0x200000u)};
        }
        ch[0].flags = 0, ch[0].ptr = 5; /* inner */
        ch[1].flags = 1, ch[1].ptr = 9; /* leaf */
        emit_pair(g, &nd, ch, decode);
    }
    outside_pairs(g, decode);
}

/* The pair's encoder vector, or (decode) the decoder's with the encoder's
 * words for it under the same context. */
static void emit_pair(gen_t *g, const node_t *nd, const child_t ch[2], int decode) {
    if (!decode) {
        emit_encode(g, nd, ch);
        return;
    }
    uint32_t in[28], out[8];
    encode_inputs(nd, ch, in);
    cbvh_unit_find("nodepair_encode")->eval(&g->spec->cfg, in, out);
    emit_decode_pair(g, &nd->ctx, out, (int)cbvh_nodepair_bytes(g->N) / 4);
}

/* Generator 9: children that leave their node's window on one axis
 * (OUTSIDE, datapath.md §6, §9).  Per structured node (a root context per
 * axis): both children inside; one ending on the window's last binary32
 * (inside) and the other one past it; a child starting one ulp below the
 * window; children outside on two axes; an empty child whose ignored box
 * lies outside.  The encoder reports OUTSIDE and still writes the pair (not
 * a reject); the decoder gets those words and cannot tell. */
static void outside_pairs(gen_t *g, int decode) {
    for (int i = 0; i < 6; i++) {
        node_t nd;
        if (make_node(g, &nd, i) != 0) continue;
        vg_window w[3];
        for (int a = 0; a < 3; a++) w[a] = vg_window_of(&nd.ctx.axis[a], g->N);
        int ax = i % 3, ay = (i + 1) % 3;
        for (int v = 0; v < 5; v++) {
            child_t ch[2];
            for (int c = 0; c < 2; c++) {
                for (int a = 0; a < 3; a++) ch[c].b[a] = nd.axis[a];
                ch[c].flags = (uint32_t)c; /* inner, leaf */
                ch[c].ptr = 3u + (uint32_t)c;
            }
            switch (v) {
            case 0: break; /* inside */
            case 1:        /* touching the window's end from inside; one past it */
                ch[0].b[ax].hi = w[ax].last;
                ch[1].b[ax].hi = w[ax].has_past ? w[ax].past : w[ax].last;
                break;
            case 2: ch[0].b[ay].lo = down(w[ay].first); break; /* one ulp below the window */
            case 3:                                              /* outside on two axes */
                ch[0].b[ax].lo = down(w[ax].first);
                ch[1].b[ay] = (box_t){w[ay].last, w[ay].has_past ? up(w[ay].past) : w[ay].last};
                break;
            default: /* an empty child: its box (outside) is ignored */
                ch[1].flags = 2;
                ch[1].b[ax].lo = down(w[ax].first);
                break;
            }
            emit_pair(g, &nd, ch, decode);
        }
    }
}

static void reject_combinations_encode_pair(gen_t *g) { reject_combinations_nodepair(g, 0); }
static void reject_combinations_decode_pair(gen_t *g) { reject_combinations_nodepair(g, 1); }

const vg_unit vg_nodepair_encode = {"nodepair_encode", 500, gen_encode_pair, NULL, 0, reject_combinations_encode_pair, 1, 0};
const vg_unit vg_nodepair_decode = {"nodepair_decode", 500, gen_decode_pair, NULL, 0, reject_combinations_decode_pair, 1, 0};
