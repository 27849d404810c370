/* Bottom-up streaming compression (Algorithm 1 of Viitanen et al.).
 *
 * Inner nodes arrive in post-order.  Each is encoded at once with an
 * *estimated* context: the one it would have as a root (cbvh_axis_root_ctx of
 * its own box, i.e. the finest scale it fits at; the true parent scale can
 * only be coarser).  The context goes on a stack; when the parent arrives it
 * pops its children's estimated contexts and compares them with the contexts
 * its own encoding implies.  A child whose context changed in a way that
 * changes its stored codes is backtracked: its pair is decoded with the old
 * context and re-encoded with the new one, recursively.
 *
 * When a context changes the codes (docs/study.md):
 *   modulo   codes depend only on the child grid scale -> compare scales
 *   relative codes also depend on the node's lower bound  -> compare scale and u
 * (Algorithm 1 compares scales only, which is right for modulo coordinates.)
 *
 * Re-encoding rule: a backtrack only sees the decoded box [u, v] with
 * v = (floor(ub/2^a)+1) 2^a.  The new scale b >= a, and Eq. 1 applied to v
 * itself gives one cell too many whenever v lies on the coarser grid.  Since
 * ub <= pred(v) < v, pred(v) lies in the same 2^a cell as ub and therefore in
 * the same 2^b cell, so re-encoding [u, pred(v)] reproduces the top-down codes
 * bit for bit.  (Likewise u = -Inf, the encoding of -2^128, is re-encoded as
 * -FLT_MAX, which lies in the same cell.)  naive_reencode = 1 re-encodes [u, v]
 * as printed, for the study; where that breaks the tree (a child grown past
 * its node's box wraps, a bound grown to 2^128 = +Inf cannot be encoded, or
 * an unchanged scale no longer decodes a pair's grown children) the pair is
 * repaired with the exact rule clipped to its node's box and counted in
 * naive_nofit, so a naive CBVH still decodes and encloses (docs/study.md).
 *
 * Treelets of depth M: pairs within M-1 levels below the node being processed
 * are still on chip, so re-encoding them is free; only deeper re-encodes are
 * DRAM backtracks.  The output is identical for every M.
 *
 * Speed (docs/results.md, "Build throughput"); the output bits are those of
 * the unit calls (tests/model/test_unit_fast.c, tests/build):
 * - A node's estimated context is computed once, with its exact grid
 *   coordinates k = floor(lb/2^e), ku = floor(ub/2^e) at its estimated scale
 *   e (unit_fast.h), and kept on the context stack.
 * - The parent's grid cs for that child is coarser or equal (the child box
 *   lies in the parent's quantized box), and floor(floor(x/2^e)/2^(cs-e)) =
 *   floor(x/2^cs), so the parent gets an inner child's codes and child scale
 *   by two shifts instead of a compression (when cs == e they are the
 *   child's own estimate).  Leaf children are floored directly.  Both use
 *   the compressor's own integer steps.
 * - The codes are packed straight into the pair (cbvh_fast_put_node).
 * - Only a child whose context may have changed (modulo: its child scale
 *   did; relative: also when its lower bound can have moved) gets its
 *   actual context from the compressor unit and the specified comparison;
 *   the decoded bounds clb = RD(k 2^e) are formed only there.
 * - Leaves are emitted without a walk step of their own.
 * Every input outside these cases (grid coordinates beyond 64 bits, a
 * rejected or non-fitting box, a leaf root, a malformed tree) takes the
 * general path, which calls the units exactly as specified.
 *
 * The per-node step (bu_step) is also the fused LBVH builder's
 * (build_lbvh_streaming.c, through bu_stream.h): the walk below only finds
 * the post-order, assigns slots and writes IDs. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "build/bu_stream.h"
#include "build/cbvh_layout.h"
#include "units/grid.h"
#include "fast/unit_fast.h"
#include "cbvh/oom.h"

static int ctx_differs(cbvh_encoding enc, const cbvh_node_ctx *a, const cbvh_node_ctx *b) {
    for (int x = 0; x < 3; x++) {
        if (a->axis[x].scale != b->axis[x].scale) return 1;
        if (enc == CBVH_ENC_RELATIVE && a->axis[x].clb != b->axis[x].clb) return 1;
    }
    return 0;
}

typedef struct {
    uint32_t pair;
    int depth;
    cbvh_node_ctx old_ctx, new_ctx;
    cbvh_f32 node_cub[3]; /* the node's decoded upper bounds under new_ctx */
} bt_item;

typedef struct {
    const cbvh_compress_opts *o;
    cbvh_tree *t;
    cbvh_bu_stats *st;
    bt_item *stack;
    char *err;
    size_t errlen;
} bu_state;

/* What the encoder must not report for a pair the stream keeps: a reject, or
 * a child that does not fit its node's grid or leaves its window (OUTSIDE:
 * real BVH children never do; the exact rules keep them inside, and a naive
 * re-encode that grows one past its node is repaired below). */
#define ENC_FAIL (CBVH_ST_REJECT | CBVH_ST_BAD_FORMAT | CBVH_ST_NO_FIT | CBVH_ST_OUTSIDE)

/* naive_reencode only: 1 if the pair decodes under ctx to exactly `want`.
 * Exact re-encoding keeps children inside their node's box (the decoder's
 * window of 2^N cells); a naive one may not, and then the codes wrap.  The
 * encoder reports that (OUTSIDE, in ENC_FAIL); this is the decoder's side of
 * it, a guard. */
static int decodes_as(const bu_state *s, const cbvh_node_ctx *ctx, const uint8_t *bytes, uint32_t want_st,
                      const cbvh_child_out want[2]) {
    cbvh_child_out got[2];
    memset(got, 0, sizeof got);
    uint32_t st = cbvh_nodepair_decode(&s->o->params, s->o->enc, ctx, bytes, got);
    return st == want_st && !(st & (CBVH_ST_REJECT | CBVH_ST_BAD_FORMAT)) && !memcmp(got, want, sizeof got);
}

/* naive_reencode only.  A child whose context changed without changing its
 * codes (ctx_differs: 0) keeps its pair; that is sound when the pair's
 * children lie inside the child's box, as exact re-encoding guarantees.  A
 * naive re-encode may have grown them one cell past it, and under the new
 * context (a lower bound moved down) those codes can wrap.  1 if the pair
 * decodes under the new context exactly as under the old one; else it is
 * counted in naive_nofit and re-encoded like a changed context. */
static int same_decode(bu_state *s, const bt_item *it) {
    const uint8_t *bytes = s->t->pairs + (size_t)it->pair * s->t->pair_bytes;
    cbvh_child_out old[2];
    memset(old, 0, sizeof old);
    uint32_t st = cbvh_nodepair_decode(&s->o->params, s->o->enc, &it->old_ctx, bytes, old);
    if (decodes_as(s, &it->new_ctx, bytes, st, old)) return 1;
    s->st->naive_nofit++;
    return 0;
}

static int backtrack(bu_state *s, uint32_t pair, const cbvh_node_ctx *old_ctx, const cbvh_node_ctx *new_ctx,
                     const cbvh_f32 node_cub[3]) {
    const cbvh_params *p = &s->o->params;
    uint32_t sp = 0;
    s->stack[sp++] = (bt_item){pair, 1, *old_ctx, *new_ctx, {node_cub[0], node_cub[1], node_cub[2]}};
    while (sp) {
        bt_item it = s->stack[--sp];
        uint8_t *bytes = s->t->pairs + (size_t)it.pair * s->t->pair_bytes;
        cbvh_child_out od[2], nd[2];
        uint32_t st = cbvh_nodepair_decode(p, s->o->enc, &it.old_ctx, bytes, od);
        if (st & (CBVH_ST_REJECT | CBVH_ST_BAD_FORMAT)) {
            snprintf(s->err, s->errlen, "cbvh bottom-up: backtrack cannot decode pair %u (status 0x%x)", it.pair, st);
            return -1;
        }
        cbvh_child_in in[2];
        memset(in, 0, sizeof in);
        for (int c = 0; c < 2; c++) {
            in[c].empty = od[c].empty;
            in[c].leaf = od[c].leaf;
            in[c].ptr = od[c].ptr;
            if (od[c].empty) continue;
            for (int a = 0; a < 3; a++) {
                /* u = -Inf encodes -2^128; -FLT_MAX lies in the same 2^a cell
                 * (the rounding only happens for a > 104), so it re-encodes
                 * like the original lower bound. */
                in[c].lo[a] = od[c].axis[a].clb == CBVH_F32_NEG_INF ? (CBVH_F32_SIGN | CBVH_F32_MAX)
                                                                      : od[c].axis[a].clb;
                in[c].hi[a] = s->o->naive_reencode ? od[c].axis[a].cub : cbvh_f32_next_down(od[c].axis[a].cub);
            }
        }
        st = cbvh_nodepair_encode(p, s->o->enc, &it.new_ctx, in, bytes, nd);
        if (s->o->naive_reencode && !(st & ENC_FAIL)) {
            /* A grown child that touched its node's upper bound can land one
             * cell past the node's box: its codes wrap.  The encoder reports
             * it (OUTSIDE); the decoder (what traversal would see) checks it
             * again, and either falls back. */
            if (!decodes_as(s, &it.new_ctx, bytes, st, nd)) st |= CBVH_ST_NO_FIT;
        }
        /* ... or could not encode at all: a bound decoded as +Inf (2^128)
         * is no binary32 input. */
        if ((st & ENC_FAIL) && s->o->naive_reencode) {
            s->st->naive_nofit++;
            /* [u, pred(v)], clipped to the node's own [., pred(v_node)]:
             * children grown by earlier naive re-encodes can stick out of
             * a node box that a fallback shrank again, and would wrap.
             * Both bounds are >= the true upper bound, so the box still
             * encloses. */
            for (int c = 0; c < 2; c++)
                for (int a = 0; a < 3; a++) {
                    cbvh_f32 hi = cbvh_f32_next_down(od[c].axis[a].cub), top = cbvh_f32_next_down(it.node_cub[a]);
                    in[c].hi[a] = cbvh_float_of(top) < cbvh_float_of(hi) ? top : hi;
                }
            st = cbvh_nodepair_encode(p, s->o->enc, &it.new_ctx, in, bytes, nd);
            /* a guard: with the clip the repaired pair always decodes */
            if (!(st & ENC_FAIL) && !decodes_as(s, &it.new_ctx, bytes, st, nd)) {
                snprintf(s->err, s->errlen,
                         "cbvh bottom-up: naive re-encoding (as printed) left pair %u undecodable even after its "
                         "repair; the exact rule (naive_reencode = 0) does not",
                         it.pair);
                return -1;
            }
        }
        if (st & ENC_FAIL) {
            snprintf(s->err, s->errlen, "cbvh bottom-up: backtrack cannot re-encode pair %u (status 0x%x)", it.pair, st);
            return -1;
        }
        s->st->reencodes++;
        s->st->hist[it.depth < CBVH_BT_HIST ? it.depth : CBVH_BT_HIST - 1]++;
        if (it.depth >= s->o->treelet_depth) s->st->backtracks++;
        for (int c = 0; c < 2; c++) {
            if (od[c].empty || od[c].leaf) continue;
            bt_item nx = {od[c].ptr, it.depth + 1, {{{0}}}, {{{0}}},
                          {nd[c].axis[0].cub, nd[c].axis[1].cub, nd[c].axis[2].cub}};
            cbvh_child_ctx3(&it.old_ctx, &od[c], &nx.old_ctx);
            cbvh_child_ctx3(&it.new_ctx, &nd[c], &nx.new_ctx);
            if (ctx_differs(s->o->enc, &nx.old_ctx, &nx.new_ctx) ||
                (s->o->naive_reencode && !same_decode(s, &nx))) s->stack[sp++] = nx;
        }
    }
    return 0;
}

static void box_of_leaf(cbvh_bvh *b, uint32_t x, const cbvh_tri *tris) {
    cbvh_bvh_node *n = &b->nodes[x];
    for (uint32_t j = 0; j < n->count; j++) {
        float lo[3], hi[3];
        cbvh_tri_bounds(&tris[b->prims[n->first + j]], lo, hi);
        for (int a = 0; a < 3; a++) {
            if (j == 0 || lo[a] < n->lo[a]) n->lo[a] = lo[a];
            if (j == 0 || hi[a] > n->hi[a]) n->hi[a] = hi[a];
        }
    }
}

static void box_of_inner(cbvh_bvh *b, uint32_t x) {
    cbvh_bvh_node *n = &b->nodes[x];
    const cbvh_bvh_node *l = &b->nodes[n->child[0]], *r = &b->nodes[n->child[1]];
    for (int a = 0; a < 3; a++) {
        n->lo[a] = l->lo[a] < r->lo[a] ? l->lo[a] : r->lo[a];
        n->hi[a] = l->hi[a] > r->hi[a] ? l->hi[a] : r->hi[a];
    }
}

/* A node's estimated context along one axis, as the stream keeps it.
 * exact: k and ku are floor(lb/2^e) and floor(ub/2^e) of the node's box and
 * lb_mod / cs come from them; clb is formed on demand.  Otherwise the
 * context came from cbvh_axis_root_ctx and clb is stored. */
typedef struct {
    int64_t k, ku;
    int e, cs; /* parent_scale, scale of the context */
    uint32_t lb_mod;
    cbvh_f32 clb;
    int exact;
} bu_axis;

typedef struct {
    bu_axis ax[3];
} bu_rec;

static inline cbvh_f32 axis_clb(const bu_axis *a) {
    return a->exact ? cbvh_grid_pack_signed(a->k, a->e, CBVH_RND_DOWN) : a->clb;
}

static void rec_ctx(const bu_rec *r, cbvh_node_ctx *ctx) {
    for (int a = 0; a < 3; a++)
        ctx->axis[a] = (cbvh_axis_ctx){r->ax[a].e, r->ax[a].cs, r->ax[a].lb_mod, axis_clb(&r->ax[a])};
}

static void rec_of_ctx(const cbvh_node_ctx *ctx, bu_rec *r) {
    memset(r, 0, sizeof *r);
    for (int a = 0; a < 3; a++) {
        const cbvh_axis_ctx *c = &ctx->axis[a];
        r->ax[a].e = c->parent_scale;
        r->ax[a].cs = c->scale;
        r->ax[a].lb_mod = c->lb_mod;
        r->ax[a].clb = c->clb;
    }
}

/* Exact floor(lb/2^e), floor(ub/2^e) (0: a bound is beyond the kept range). */
static inline int floor2(cbvh_f32 lb, cbvh_f32 ub, int e, int64_t *k, int64_t *ku) {
    return cbvh_fast_floor(lb, e, k) & cbvh_fast_floor(ub, e, ku);
}

/* The estimated context of a box (cbvh_axis_root_ctx): 0, or a status. */
static inline uint32_t est_axis(const cbvh_params *p, int n, int ms, cbvh_f32 lb, cbvh_f32 ub, bu_axis *ax) {
    int e;
    int r = cbvh_scale_estimate_fast_nm(n, ms, lb, ub, &e, &ax->k, &ax->ku);
    if (r != 2) {
        uint32_t st = r ? 0 : cbvh_scale_estimate(p, lb, ub, &e);
        if (st || !floor2(lb, ub, e, &ax->k, &ax->ku)) {
            cbvh_axis_ctx c;
            st = cbvh_axis_root_ctx(p, lb, ub, &c);
            *ax = (bu_axis){0, 0, c.parent_scale, c.scale, c.lb_mod, c.clb, 0};
            return st;
        }
    }
    uint32_t ub_mod;
    ax->e = e;
    ax->exact = 1;
    /* fits by the choice of e; not fitting would be an estimator fault */
    return cbvh_fast_code(n, ms, e, ax->k, ax->ku, &ax->lb_mod, &ub_mod, &ax->cs) ? 0 : CBVH_ST_NO_FIT;
}

/* The node's side of the fast path, per axis: its child grid cs, its lower
 * bound's code at cs (relative encoding) and its record. */
typedef struct {
    int cs[3];
    uint32_t pm[3];
    const bu_axis *ax;
} bu_node;

/* One axis of a child through the compressor unit itself: codes (with the
 * relative offset pm removed) and child scale.  0 or a status. */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static uint32_t axis_unit(const cbvh_params *p, const cbvh_bvh_node *cn, int a, const bu_node *nd, uint64_t *w,
                          int *child_scale) {
    cbvh_axis_code code;
    int cs = nd->cs[a];
    uint32_t pm = nd->pm[a];
    uint32_t st =
        cbvh_axis_compress(p, cbvh_f32_of(cn->lo[a]), cbvh_f32_of(cn->hi[a]), cs, axis_clb(&nd->ax[a]), &code);
    int n = p->quant_bits;
    uint32_t mask = (1u << n) - 1u;
    *w |= (uint64_t)((code.lb_mod - pm) & mask) << (2 * a * n) | (uint64_t)((code.ub_mod - pm) & mask)
                                                                      << (2 * a * n + n);
    *child_scale = code.child_scale;
    return st;
}

/* Nonzero unless the child's box lies inside its node's box (NaN too).  The
 * fast path takes only such children: they lie in the window of the node's
 * context, which is estimated from that box (datapath.md §6), so the
 * compressor would not report OUTSIDE.  Any other child goes to the general
 * path, where the units decide (a tree whose child leaves its node's window
 * is refused there). */
static inline int outside_box(const cbvh_bvh_node *n, const cbvh_bvh_node *cn) {
    int out = 0;
    for (int a = 0; a < 3; a++) out |= !(cn->lo[a] >= n->lo[a]) | !(cn->hi[a] <= n->hi[a]);
    return out;
}

/* The code bits [0, 6N) of a leaf child at the parent's scales cs: its box
 * floored directly.  0, or nonzero: the box does not fit (general path). */
static inline int leaf_codes(const cbvh_params *p, int n, const cbvh_bvh_node *cn, const bu_node *nd, uint64_t *w) {
    int bad = 0;
    uint32_t mask = (1u << n) - 1u;
    uint64_t acc = 0;
    for (int a = 0; a < 3; a++) {
        int64_t k, ku;
        int cs = nd->cs[a];
        uint32_t pm = nd->pm[a];
        if (!(cbvh_fast_floor(cbvh_f32_of(cn->lo[a]), cs, &k) & cbvh_fast_floor(cbvh_f32_of(cn->hi[a]), cs, &ku))) {
            int unused;
            bad |= axis_unit(p, cn, a, nd, &acc, &unused) != 0;
            continue;
        }
        bad |= (uint64_t)(ku - k) >= (UINT64_C(1) << n); /* cells = ku + 1 - k in 1..2^N */
        acc |= (uint64_t)(((uint32_t)(uint64_t)k - pm) & mask) << (2 * a * n) |
               (uint64_t)(((uint32_t)(uint64_t)(ku + 1) - pm) & mask) << (2 * a * n + n);
    }
    *w = acc;
    return bad;
}

/* The same for an inner child from its record r (exact k, ku at its
 * estimated scale e <= cs).  *maybe: its context may differ from its
 * estimate (modulo: a child scale changed, exactly; relative: also a lower
 * bound that can have moved); the caller decides with the units. */
static inline int inner_codes(const cbvh_params *p, int n, int ms, const bu_rec *r, const cbvh_bvh_node *cn,
                              const bu_node *nd, int rel, uint64_t *w, int *maybe) {
    int bad = 0, dif = 0;
    uint32_t mask = (1u << n) - 1u;
    uint64_t acc = 0;
    for (int a = 0; a < 3; a++) {
        const bu_axis *ra = &r->ax[a];
        int cs = nd->cs[a];
        uint32_t pm = nd->pm[a];
        int d = cs - ra->e, ccs;
        if (!ra->exact || d < 0) {
            bad |= axis_unit(p, cn, a, nd, &acc, &ccs) != 0;
            dif |= ccs != ra->cs || rel;
            continue;
        }
        int64_t k = cbvh_fast_floor_shift(ra->k, d), ku = cbvh_fast_floor_shift(ra->ku, d);
        uint64_t cells = (uint64_t)(ku + 1 - k);
        bad |= cells - 1u >= (UINT64_C(1) << n);
        ccs = cs - n + cbvh_grid_bitlen(cells - 1u);
        ccs = ccs < ms ? ms : ccs;
        dif |= ccs != ra->cs;
        /* relative: u = RD(k 2^cs) equals the estimate's RD(k_e 2^e) when
         * k_e is a multiple of 2^d (the same value); otherwise check */
        if (rel && d) dif |= d > 62 ? ra->k != 0 : ((uint64_t)ra->k & ((UINT64_C(1) << d) - 1u)) != 0;
        acc |= (uint64_t)(((uint32_t)(uint64_t)k - pm) & mask) << (2 * a * n) |
               (uint64_t)(((uint32_t)(uint64_t)(ku + 1) - pm) & mask) << (2 * a * n + n);
    }
    *w = acc;
    *maybe = dif;
    return bad;
}

struct cbvh_bu_stream {
    bu_state bt; /* options, output, statistics, backtracking stack, err */
    bu_rec *recs; /* the context stack */
    uint32_t sp;
};

cbvh_bu_stream *cbvh_bu_open(const cbvh_compress_opts *o, cbvh_tree *t, cbvh_bu_stats *st, uint32_t npairs,
                             char *err, size_t errlen) {
    cbvh_bu_stream *s = malloc(sizeof *s);
    if (!s) cbvh_out_of_memory("bottom-up compressor state");
    s->bt = (bu_state){o, t, st, malloc(((size_t)npairs + 2) * sizeof(bt_item)), err, errlen};
    s->recs = malloc(((size_t)npairs + 1) * sizeof *s->recs);
    s->sp = 0;
    if (!s->bt.stack || !s->recs) cbvh_out_of_memory("bottom-up compressor stacks");
    return s;
}

void cbvh_bu_close(cbvh_bu_stream *s) {
    if (!s) return;
    free(s->bt.stack);
    free(s->recs);
    free(s);
}

/* The step of Algorithm 1 for node n into pair `pair`: an inner node with
 * children cn[0], cn[1] (slots slot[0], slot[1]; their records, if inner, on
 * top of the context stack), or with cn == NULL a leaf root (slot[0] its
 * first ID).  Its record is pushed.  0 or -1 + reason. */
static inline int bu_step(cbvh_bu_stream *bs, const cbvh_bvh_node *n, const cbvh_bvh_node *const cn_in[2],
                          const uint32_t slot[2], uint32_t pair) {
    bu_state *s = &bs->bt;
    const cbvh_compress_opts *o = s->o;
    cbvh_bu_stats *stats = s->st;
    bu_rec *recs = bs->recs;
    /* cbvh_tree_init has checked the parameters and that every pointer fits
     * its field, so the fast path packs codes without the encoder's checks. */
    const cbvh_params *p = &o->params;
    const int nq = p->quant_bits, msc = p->min_scale, rel = o->enc == CBVH_ENC_RELATIVE;
    const uint32_t qmask = (1u << nq) - 1u;
    const size_t pbytes = s->t->pair_bytes, nbytes = pbytes / 2;
    uint32_t sp = bs->sp;
    int leaf = cn_in == NULL;
    uint8_t *bytes = s->t->pairs + (size_t)pair * pbytes;

    /* ---- fast path: an inner node whose boxes all take the integer steps */
    if (!leaf) {
        bu_rec rx;
        const cbvh_bvh_node *cn[2] = {cn_in[0], cn_in[1]};
        int cleaf[2] = {cbvh_bvh_is_leaf(cn[0]), cbvh_bvh_is_leaf(cn[1])};
        /* the children's records: child 1's on top */
        const bu_rec *cr[2] = {NULL, NULL};
        uint32_t inner_children = (uint32_t)(!cleaf[0] + !cleaf[1]);
        if (inner_children > sp) goto general; /* not a tree; the general path reports it */
        if (!cleaf[1]) cr[1] = &recs[sp - 1];
        if (!cleaf[0]) cr[0] = &recs[sp - 1 - !cleaf[1]];
        int bad = outside_box(n, cn[0]) | outside_box(n, cn[1]);
        for (int a = 0; a < 3; a++)
            bad |= est_axis(p, nq, msc, cbvh_f32_of(n->lo[a]), cbvh_f32_of(n->hi[a]), &rx.ax[a]) != 0;
        if (bad) goto general;
        bu_node nd = {{0, 0, 0}, {0, 0, 0}, rx.ax};
        const int *cs = nd.cs;
        for (int a = 0; a < 3; a++) {
            nd.cs[a] = rx.ax[a].cs;
            int shift = rx.ax[a].e - cs[a];
            if (rel) nd.pm[a] = shift >= nq ? 0 : (rx.ax[a].lb_mod << shift) & qmask; /* relative: u's code at cs */
        }
        uint64_t w[2];
        int maybe[2] = {0, 0};
        for (int c = 0; c < 2; c++) /* one branch per child, not per axis */
            bad |= cleaf[c] ? leaf_codes(p, nq, cn[c], &nd, &w[c])
                            : inner_codes(p, nq, msc, cr[c], cn[c], &nd, rel, &w[c], &maybe[c]);
        if (bad) goto general;
        for (int c = 0; c < 2; c++) cbvh_fast_put_node(nq, w[c], cleaf[c], slot[c], bytes + (size_t)c * nbytes);
        stats->encodes++;
        /* A child whose context may have changed: its actual context from
         * the compressor (as the general path), compared as specified. */
        for (int c = 1; c >= 0; c--) {
            if (!maybe[c]) continue;
            cbvh_node_ctx stored, actual;
            cbvh_f32 cub[3];
            rec_ctx(cr[c], &stored);
            for (int a = 0; a < 3; a++) {
                /* the child lies in the node's box (outside_box), hence in its
                 * window: its own lower bound as node_clb spares forming u */
                cbvh_axis_code code;
                cbvh_f32 lo = cbvh_f32_of(cn[c]->lo[a]);
                cbvh_axis_compress(p, lo, cbvh_f32_of(cn[c]->hi[a]), cs[a], lo, &code);
                actual.axis[a] = cbvh_axis_child_ctx(&(cbvh_axis_ctx){rx.ax[a].e, cs[a], rx.ax[a].lb_mod, 0}, &code);
                cub[a] = code.cub;
            }
            if (ctx_differs(o->enc, &stored, &actual) && backtrack(s, slot[c], &stored, &actual, cub)) return -1;
        }
        sp -= inner_children;
        recs[sp++] = rx;
        bs->sp = sp;
        return 0;
    }

general:;
    /* ---- general path: the units, as specified */
    cbvh_node_ctx est = {{{0}}};
    uint32_t st = 0;
    for (int a = 0; a < 3; a++) st |= cbvh_axis_root_ctx(p, cbvh_f32_of(n->lo[a]), cbvh_f32_of(n->hi[a]), &est.axis[a]);
    cbvh_child_in in[2];
    cbvh_child_out co[2];
    memset(in, 0, sizeof in);
    if (leaf) {
        cbvh_child_in_of(n, slot[0], &in[0]);
        in[1].empty = 1;
    } else {
        /* cppcheck-suppress nullPointer ; leaf == (cn_in == NULL) */
        for (int c = 0; c < 2; c++) cbvh_child_in_of(cn_in[c], slot[c], &in[c]);
        if ((uint32_t)(!in[0].leaf + !in[1].leaf) > sp) { /* the inner children were not streamed first */
            snprintf(s->err, s->errlen, "cbvh bottom-up: pair %u: its inner children came after it (not a tree)", pair);
            return -1;
        }
    }
    /* a node box without a context (a reject above) is reported as such: its
     * children's statuses under a zeroed context would mean nothing */
    if (!st) st = cbvh_nodepair_encode(p, o->enc, &est, in, bytes, co);
    if (st & ENC_FAIL) {
        snprintf(s->err, s->errlen, "cbvh bottom-up: pair %u rejected by the encoder (status 0x%x)", pair, st);
        return -1;
    }
    stats->encodes++;
    for (int c = 1; c >= 0 && !leaf; c--) {
        if (in[c].leaf) continue;
        cbvh_node_ctx stored, actual;
        rec_ctx(&recs[--sp], &stored);
        cbvh_child_ctx3(&est, &co[c], &actual);
        const cbvh_f32 cub[3] = {co[c].axis[0].cub, co[c].axis[1].cub, co[c].axis[2].cub};
        if (ctx_differs(o->enc, &stored, &actual) && backtrack(s, in[c].ptr, &stored, &actual, cub)) return -1;
    }
    bu_rec *r = &recs[sp++];
    rec_of_ctx(&est, r);
    for (int a = 0; a < 3 && !leaf; a++) /* exact coordinates for the parent's fast path */
        r->ax[a].exact = floor2(cbvh_f32_of(n->lo[a]), cbvh_f32_of(n->hi[a]), r->ax[a].e, &r->ax[a].k, &r->ax[a].ku);
    bs->sp = sp;
    return 0;
}

int cbvh_bu_inner(cbvh_bu_stream *s, const cbvh_bvh_node *n, const cbvh_bvh_node *const c[2], const uint32_t slot[2],
                  uint32_t pair) {
    return bu_step(s, n, c, slot, pair);
}

int cbvh_bu_leaf_root(cbvh_bu_stream *s, const cbvh_bvh_node *n, uint32_t slot, uint32_t pair) {
    const uint32_t sl[2] = {slot, 0};
    return bu_step(s, n, NULL, sl, pair);
}

int cbvh_compress_bottomup(cbvh_bvh *b, const cbvh_tri *refit_tris, const cbvh_compress_opts *o, cbvh_tree *out,
                           cbvh_bu_stats *stats, char *err, size_t errlen) {
    memset(stats, 0, sizeof *stats);
    if (o->treelet_depth < 1 || o->treelet_depth > 8) {
        snprintf(err, errlen, "cbvh bottom-up: treelet depth %d outside 1..8", o->treelet_depth);
        return -1;
    }
    /* One post-order walk does everything: slots are assigned and IDs
     * written as nodes are emitted (the layout of cbvh_layout_make), and each
     * inner node is compressed as soon as both children are done. */
    cbvh_layout l;
    if (cbvh_layout_count(b, &l)) {
        snprintf(err, errlen, "cbvh: out of memory");
        return -1;
    }
    if (cbvh_tree_init(out, b, o, &l, 0, err, errlen)) {
        cbvh_layout_free(&l);
        return -1;
    }
    const cbvh_params *p = &o->params;
    cbvh_bu_stream *s = cbvh_bu_open(o, out, stats, l.npairs, err, errlen);
    uint32_t *walk = malloc(((size_t)b->nnodes + 1) * sizeof *walk); /* node << 1 | children pushed */
    if (!walk) cbvh_out_of_memory("bottom-up walk stack");
    uint32_t ws = 0, npairs = 0, nids = 0, emitted = 0;
    int rc = 0, not_tree = 0;
    walk[ws++] = b->root << 1;
    /* Leaves are emitted without a walk step of their own: a left leaf child
     * when its parent is first visited (it is next in post-order), a right
     * one when the parent is revisited (after the left subtree). */
#define EMIT_LEAF(y)                                                               \
    do {                                                                           \
        const cbvh_bvh_node *ln_ = &b->nodes[y];                                   \
        if ((not_tree = ++emitted > b->nnodes || ln_->count > l.nids - nids)) break; \
        l.slot[y] = nids;                                                          \
        cbvh_tree_put_ids(out, b, ln_, nids);                                      \
        nids += ln_->count;                                                        \
        if (refit_tris) box_of_leaf(b, y, refit_tris);                             \
    } while (0)
    while (ws && rc == 0) {
        uint32_t e = walk[--ws], x = e >> 1;
        const cbvh_bvh_node *n = &b->nodes[x];
        int leaf = cbvh_bvh_is_leaf(n);
        if (!leaf && !(e & 1u)) {
            if ((not_tree = ws + 3 > b->nnodes + 1)) break; /* a node reached twice */
            uint32_t c0 = n->child[0], c1 = n->child[1];
            walk[ws++] = e | 1u;
            const cbvh_bvh_node *n1 = &b->nodes[c1];
            if (!cbvh_bvh_is_leaf(n1)) {
                walk[ws++] = c1 << 1;
#if defined(__GNUC__) /* needed once the left subtree is done */
                __builtin_prefetch(&b->nodes[n1->child[0]]);
                __builtin_prefetch(&b->nodes[n1->child[1]]);
#endif
            }
            if (!cbvh_bvh_is_leaf(&b->nodes[c0]))
                walk[ws++] = c0 << 1;
            else
                EMIT_LEAF(c0);
            if (not_tree) break;
            continue;
        }
        if (leaf) { /* only the root is walked as a leaf */
            EMIT_LEAF(x);
            if (not_tree) break;
            const uint32_t sl[2] = {l.slot[x], 0};
            rc = bu_step(s, n, NULL, sl, out->root_pair);
            continue;
        }
        if (cbvh_bvh_is_leaf(&b->nodes[n->child[1]])) EMIT_LEAF(n->child[1]);
        if (not_tree) break;
        if ((not_tree = ++emitted > b->nnodes || npairs >= l.npairs)) break;
        l.slot[x] = npairs++;
        if (refit_tris) box_of_inner(b, x);
        const cbvh_bvh_node *cn[2] = {&b->nodes[n->child[0]], &b->nodes[n->child[1]]};
        const uint32_t sl[2] = {l.slot[n->child[0]], l.slot[n->child[1]]};
        rc = bu_step(s, n, cn, sl, l.slot[x]);
    }
    if (rc == 0 && (not_tree || nids != l.nids || (!cbvh_bvh_is_leaf(&b->nodes[b->root]) && npairs != l.npairs))) {
        snprintf(err, errlen, "cbvh bottom-up: the BVH is not a tree (a node is reached twice or never)");
        rc = -1;
    }
    if (rc == 0) {
        /* The root's estimated context is the root context by definition. */
        const cbvh_bvh_node *r = &b->nodes[b->root];
        for (int a = 0; a < 3; a++) {
            out->root_lo[a] = cbvh_f32_of(r->lo[a]), out->root_hi[a] = cbvh_f32_of(r->hi[a]);
            cbvh_axis_root_ctx(p, out->root_lo[a], out->root_hi[a], &out->root_ctx.axis[a]);
        }
    }
#undef EMIT_LEAF
    free(walk);
    cbvh_bu_close(s);
    cbvh_layout_free(&l);
    if (rc) cbvh_tree_free(out);
    return rc;
}
