/* The CBVH decoded once, and its traversal (docs/traversal.md §12).
 *
 * cbvh_trace_cbvh decodes a node pair on every visit: the fast pair decode,
 * three axis set-ups and, per pushed inner child, its context.  None of that
 * depends on the ray: a pair's context is fixed by its path from the root.
 * cbvh_cbvh_decode runs the same decode (decode_fast.h) and the same context
 * derivation (cbvh_fast_child_ctx, with the same exact lower plane) once per
 * pair, walking the tree from the root as a traversal does; the traversal
 * below then runs cbvh_trace_cbvh's loop on the records.  Every box still
 * goes through the binary64 filter and, when it cannot decide, the box unit
 * on the grid planes, so hits and counters are the per-visit traversal's. */
#include <stdio.h>
#include <stdlib.h>

#include "decode_fast.h"
#include "traverse_cbvh_common.h"

_Static_assert(sizeof(cbvh_cbvh_dnode) == 128, "one record per two 64-byte lines");

void cbvh_cbvh_decoded_free(cbvh_cbvh_decoded *d) {
    free(d->nodes);
    free(d->rel);
    d->nodes = NULL;
    d->rel = NULL;
    d->usable = 0;
}

typedef struct {
    uint32_t pair;
    cbvh_node_ctx ctx;
} walk_entry;

/* One pair's record from its context; 0 when the fast decode does not take
 * it (the per-visit traversal would then run the node-pair unit).  Pushes
 * the inner children with the contexts the traversal derives for them. */
static int decode_pair(const cbvh_tree *t, uint32_t i, const cbvh_node_ctx *ctx, cbvh_cbvh_dnode *rec,
                       cbvh_cbvh_drel *rel, walk_entry *push, int *npush) {
    const cbvh_params *prm = &t->params;
    cbvh_fast_child fc[2];
    uint32_t ppm[3];
    if (!cbvh_fast_pair_decode_valid(prm, t->enc, ctx, t->pairs + (size_t)i * t->pair_bytes, fc, ppm)) return 0;
    cbvh_rbf_axis ax[3];
    for (int a = 0; a < 3; a++) {
        ax[a] = cbvh_rbf_axis_prep(ctx->axis[a].clb, ctx->axis[a].scale);
        rec->clb[a] = ctx->axis[a].clb;
        rec->scale[a] = (int8_t)ctx->axis[a].scale;
    }
    int exact = ax[0].exact & ax[1].exact & ax[2].exact;
    rec->flags = exact ? CBVH_DEC_EXACT : 0;
    for (int c = 0; c < 2; c++) {
        rec->child[c] = fc[c].ptr;
        rec->flags |= (fc[c].leaf ? CBVH_DEC_LEAF0 << c : 0) | (fc[c].empty ? CBVH_DEC_EMPTY0 << c : 0);
        double lo[3]; /* the traversal's planes, formed the same way */
        for (int a = 0; a < 3; a++) { /* an empty slot gets the traversal's dummy box [u, u + 2^e] */
            rel->r[c][a] = (uint16_t)(fc[c].empty ? 0 : fc[c].r[a]);
            rel->s[c][a] = (uint16_t)(fc[c].empty ? 1 : fc[c].s[a]);
            lo[a] = ax[a].u + (double)rel->r[c][a] * ax[a].step;
            if (exact) {
                rec->lo[a][c] = lo[a];
                rec->hi[a][c] = ax[a].u + (double)rel->s[c][a] * ax[a].step;
            }
        }
        if (fc[c].empty || fc[c].leaf) continue;
        walk_entry *w = &push[(*npush)++];
        w->pair = fc[c].ptr;
        for (int a = 0; a < 3; a++)
            cbvh_fast_child_ctx(prm, t->enc, &ctx->axis[a], ppm[a], &fc[c], a, ax[a].exact ? &lo[a] : NULL,
                                &w->ctx.axis[a]);
    }
    return 1;
}

int cbvh_cbvh_decode(const cbvh_tree *t, cbvh_cbvh_decoded *out, char *err, size_t errlen) {
    memset(out, 0, sizeof *out);
    out->tree = t;
    const cbvh_params *prm = &t->params;
    if (!CBVH_FAST_PATHS || !cbvh_fast_params_ok(prm) || t->pair_bytes != cbvh_nodepair_bytes(prm->quant_bits) ||
        !cbvh_fast_node_ctx_ok(prm, &t->root_ctx) || t->npairs == 0 || t->root_pair >= t->npairs)
        return 0;
    size_t n = t->npairs;
    out->nodes = aligned_alloc(64, n * sizeof *out->nodes);
    out->rel = malloc(n * sizeof *out->rel);
    walk_entry *stack = malloc((n + 2) * sizeof *stack);
    uint8_t *seen = calloc(n, 1);
    if (!out->nodes || !out->rel || !stack || !seen) {
        free(stack);
        free(seen);
        cbvh_cbvh_decoded_free(out);
        snprintf(err, errlen, "decoded CBVH: out of memory (%u node pairs)", t->npairs);
        return -1;
    }
    memset(out->nodes, 0, n * sizeof *out->nodes); /* unreachable pairs: zero records */
    memset(out->rel, 0, n * sizeof *out->rel);
    /* Each reachable pair once: a pair reached twice or out of range is not a
     * tree, and is left to the per-visit traversal's own checks. */
    int ok = 1, sp = 0;
    stack[sp].pair = t->root_pair;
    stack[sp++].ctx = t->root_ctx;
    while (sp > 0 && ok) {
        walk_entry e = stack[--sp];
        if (e.pair >= n || seen[e.pair]) {
            ok = 0;
            break;
        }
        seen[e.pair] = 1;
        ok = decode_pair(t, e.pair, &e.ctx, &out->nodes[e.pair], &out->rel[e.pair], stack, &sp);
    }
    free(stack);
    free(seen);
    if (!ok) cbvh_cbvh_decoded_free(out);
    else out->usable = 1;
    return 0;
}

typedef struct {
    uint32_t ptr;
    int leaf;
    double t_near; /* binary64: its order is the unit's key order */
} entry;

int cbvh_trace_cbvh_decoded(const cbvh_cbvh_decoded *d, const cbvh_tri *tris, const cbvh_ray *ray, int mant_bits,
                            cbvh_trav_mode mode, cbvh_trav_hit *hit, cbvh_trav_stats *st) {
    const cbvh_tree *t = d->tree;
    if (!d->usable) return cbvh_trace_cbvh(t, tris, ray, mant_bits, mode, hit, st);
    trav_state ts;
    if (trav_begin(&ts, hit, ray, mant_bits, tris, mode, (uint64_t)t->npairs * t->pair_bytes, t->nids)) return -1;
    cbvh_rbf_ray fp;
    cbvh_rbf_prepare(ray, mant_bits, &fp);
    entry stack[CBVH_TRAV_STACK];
    int sp = 0;
    uint32_t max_stack = 0;
    cbvh_f32 cull = trav_box_tmax(&ts);
    double cull_d = cbvh_rbf_f32(cull);
    cbvh_box_result r;
    double rtn;
    if (trav_cbvh_root(&ts, &fp, t, cull, &rtn)) {
        stack[0].leaf = 0;
        stack[0].ptr = t->root_pair;
        stack[0].t_near = rtn;
        sp = 1;
        max_stack = 1;
    }
    while (sp > 0) {
        entry *e = &stack[--sp];
        if (e->t_near > cull_d) continue;
        if (e->leaf) {
            if (trav_cbvh_leaf(&ts, t, e->ptr, &cull, &cull_d)) break;
            continue;
        }
        uint32_t p = e->ptr;
        ts.s.nodes++; /* the decode visited each pair once: no cycle, no pointer out of range */
        trav_fetch(&ts, (uint64_t)p * t->pair_bytes, t->pair_bytes);
        const cbvh_cbvh_dnode *rec = &d->nodes[p];
        uint32_t fl = rec->flags;
        double tn[2], tf[2] = {0, 0};
        int h[2] = {0, 0}, hf[2] = {0, 0};
        int dec = (fl & CBVH_DEC_EXACT) ? cbvh_rbf_box2_valid(&fp, cull_d, rec->lo, rec->hi, hf, tf) : 0;
        for (int c = 0; c < 2; c++) {
            if (fl & (CBVH_DEC_EMPTY0 << c)) continue;
            ts.s.box_tests++;
            if (dec >> c & 1) {
                h[c] = hf[c];
                tn[c] = tf[c];
                continue;
            }
            cbvh_grid_axis g[3];
            for (int a = 0; a < 3; a++) {
                g[a].u = rec->clb[a];
                g[a].e = rec->scale[a];
                g[a].r = d->rel[p].r[c][a];
                g[a].s = d->rel[p].s[c][a];
            }
            h[c] = cbvh_ray_box_prep(trav_prep(&ts), cull, mant_bits, g, &r) == 0 && r.hit;
            tn[c] = cbvh_rbf_f32(r.t_near);
        }
        if (sp + h[0] + h[1] > CBVH_TRAV_STACK) return -1;
        int first = h[0] && h[1] && tn[1] < tn[0];
        for (int k = 1; k >= 0; k--) {
            int c = k ? 1 - first : first;
            if (!h[c]) continue;
            entry *ne = &stack[sp++];
            ne->leaf = (fl & (CBVH_DEC_LEAF0 << c)) != 0;
            ne->ptr = rec->child[c];
            ne->t_near = tn[c];
        }
        if ((uint32_t)sp > max_stack) max_stack = (uint32_t)sp;
        for (int k = sp - h[0] - h[1]; k < sp; k++) { /* what the pushed children read next */
            if (stack[k].leaf) {
                if (stack[k].ptr < t->nids) __builtin_prefetch(&t->ids[stack[k].ptr]);
            } else {
                __builtin_prefetch(&d->nodes[stack[k].ptr]);
            }
        }
    }
    ts.s.max_stack = max_stack;
    trav_finish(&ts, hit, st);
    return 0;
}
