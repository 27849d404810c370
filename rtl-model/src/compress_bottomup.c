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
 * as printed, for the study.
 *
 * Treelets of depth M: pairs within M-1 levels below the node being processed
 * are still on chip, so re-encoding them is free; only deeper re-encodes are
 * DRAM backtracks.  The output is identical for every M. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh_layout.h"

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
} bt_item;

typedef struct {
    const cbvh_compress_opts *o;
    cbvh_tree *t;
    cbvh_bu_stats *st;
    bt_item *stack;
    char *err;
    size_t errlen;
} bu_state;

#define ENC_FAIL (CBVH_ST_REJECT | CBVH_ST_BAD_FORMAT | CBVH_ST_NO_FIT)

static int backtrack(bu_state *s, uint32_t pair, const cbvh_node_ctx *old_ctx, const cbvh_node_ctx *new_ctx) {
    const cbvh_params *p = &s->o->params;
    uint32_t sp = 0;
    s->stack[sp++] = (bt_item){pair, 1, *old_ctx, *new_ctx};
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
             * cell past the node's box: its codes wrap.  Detect it with the
             * decoder (what traversal would see) and fall back. */
            cbvh_child_out chk[2];
            uint32_t dst = cbvh_nodepair_decode(p, s->o->enc, &it.new_ctx, bytes, chk);
            if ((dst & (CBVH_ST_REJECT | CBVH_ST_BAD_FORMAT)) || memcmp(chk, nd, sizeof chk)) st |= CBVH_ST_NO_FIT;
        }
        if ((st & CBVH_ST_NO_FIT) && s->o->naive_reencode) {
            s->st->naive_nofit++;
            for (int c = 0; c < 2; c++)
                for (int a = 0; a < 3; a++) in[c].hi[a] = cbvh_f32_next_down(od[c].axis[a].cub);
            st = cbvh_nodepair_encode(p, s->o->enc, &it.new_ctx, in, bytes, nd);
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
            bt_item nx = {od[c].ptr, it.depth + 1, {{{0}}}, {{{0}}}};
            cbvh_child_ctx3(&it.old_ctx, &od[c], &nx.old_ctx);
            cbvh_child_ctx3(&it.new_ctx, &nd[c], &nx.new_ctx);
            if (ctx_differs(s->o->enc, &nx.old_ctx, &nx.new_ctx)) s->stack[sp++] = nx;
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
    cbvh_node_ctx *ctx_stack = malloc(((size_t)l.npairs + 1) * sizeof *ctx_stack);
    uint32_t *walk = malloc(((size_t)b->nnodes + 1) * sizeof *walk); /* node << 1 | children pushed */
    bu_state s = {o, out, stats, malloc(((size_t)l.npairs + 2) * sizeof(bt_item)), err, errlen};
    if (!ctx_stack || !walk || !s.stack) abort();
    uint32_t sp = 0, ws = 0, npairs = 0, nids = 0, emitted = 0;
    int rc = 0, not_tree = 0;
    cbvh_node_ctx est = {{{0}}};
    walk[ws++] = b->root << 1;
    while (ws && rc == 0) {
        uint32_t e = walk[--ws], x = e >> 1;
        const cbvh_bvh_node *n = &b->nodes[x];
        int leaf = cbvh_bvh_is_leaf(n);
        if (!leaf && !(e & 1u)) {
            if ((not_tree = ws + 3 > b->nnodes + 1)) break; /* a node reached twice */
            walk[ws++] = e | 1u;
            walk[ws++] = n->child[1] << 1;
            walk[ws++] = n->child[0] << 1;
            continue;
        }
        if ((not_tree = ++emitted > b->nnodes)) break;
        if (leaf) {
            if ((not_tree = n->count > l.nids - nids)) break;
            l.slot[x] = nids;
            cbvh_tree_put_ids(out, b, n, nids);
            nids += n->count;
            if (refit_tris) box_of_leaf(b, x, refit_tris);
            if (x != b->root) continue; /* leaves have no pair of their own */
        } else {
            if ((not_tree = npairs >= l.npairs)) break;
            l.slot[x] = npairs++;
            if (refit_tris) box_of_inner(b, x);
        }
        uint32_t st = 0;
        for (int a = 0; a < 3; a++)
            st |= cbvh_axis_root_ctx(&o->params, cbvh_f32_of(n->lo[a]), cbvh_f32_of(n->hi[a]), &est.axis[a]);
        cbvh_child_in in[2];
        cbvh_child_out co[2];
        cbvh_pair_inputs(b, &l, x, in);
        uint32_t pair = leaf ? out->root_pair : l.slot[x];
        st |= cbvh_nodepair_encode(&o->params, o->enc, &est, in, out->pairs + (size_t)pair * out->pair_bytes, co);
        if (st & ENC_FAIL) {
            snprintf(err, errlen, "cbvh bottom-up: pair %u rejected by the encoder (status 0x%x)", pair, st);
            rc = -1;
            break;
        }
        stats->encodes++;
        for (int c = 1; c >= 0 && !leaf; c--) {
            if (in[c].leaf) continue;
            cbvh_node_ctx stored = ctx_stack[--sp], actual;
            cbvh_child_ctx3(&est, &co[c], &actual);
            if (ctx_differs(o->enc, &stored, &actual) && backtrack(&s, in[c].ptr, &stored, &actual)) {
                rc = -1;
                break;
            }
        }
        ctx_stack[sp++] = est;
    }
    if (rc == 0 && (not_tree || nids != l.nids || (!cbvh_bvh_is_leaf(&b->nodes[b->root]) && npairs != l.npairs))) {
        snprintf(err, errlen, "cbvh bottom-up: the BVH is not a tree (a node is reached twice or never)");
        rc = -1;
    }
    if (rc == 0) {
        /* The root's estimated context is the root context by definition. */
        const cbvh_bvh_node *r = &b->nodes[b->root];
        for (int a = 0; a < 3; a++) out->root_lo[a] = cbvh_f32_of(r->lo[a]), out->root_hi[a] = cbvh_f32_of(r->hi[a]);
        out->root_ctx = est;
    }
    free(ctx_stack);
    free(walk);
    free(s.stack);
    cbvh_layout_free(&l);
    if (rc) cbvh_tree_free(out);
    return rc;
}
