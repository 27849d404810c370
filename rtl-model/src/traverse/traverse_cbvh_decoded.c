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
 * on the grid planes, so hits and counters are the per-visit traversal's.
 * A record is one 64-byte line: the planes in binary32 when all twelve are
 * binary32 numbers (their binary64 values exactly), else in a second array;
 * what only the box unit's fallback needs (u, e, r, s) is kept apart. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "fast/decode_fast.h"
#include "traverse/traverse_cbvh_common.h"

_Static_assert(sizeof(cbvh_cbvh_dnode) == 64, "one record per 64-byte line");

void cbvh_cbvh_decoded_free(cbvh_cbvh_decoded *d) {
    free(d->nodes);
    free(d->rel);
    free(d->wide);
    free(d->leaf_tris);
    d->nodes = NULL;
    d->rel = NULL;
    d->wide = NULL;
    d->leaf_tris = NULL;
    d->leaf_src = NULL;
    d->nwide = 0;
    d->usable = 0;
}

int cbvh_cbvh_decode_leaves(cbvh_cbvh_decoded *d, const cbvh_tri *tris, uint32_t ntris, char *err, size_t errlen) {
    const cbvh_tree *t = d->tree;
    free(d->leaf_tris);
    d->leaf_tris = NULL;
    d->leaf_src = NULL;
    if (!d->usable || !tris || t->nids == 0) return 0;
    for (uint32_t i = 0; i < t->nids; i++)
        if ((t->ids[i] & ~CBVH_ID_LAST) >= ntris) return 0; /* left to the traversal's reads of tris */
    d->leaf_tris = aligned_alloc(64, ((size_t)t->nids * sizeof *d->leaf_tris + 63) / 64 * 64);
    if (!d->leaf_tris) {
        snprintf(err, errlen, "decoded CBVH: out of memory (%u primitive IDs)", t->nids);
        return -1;
    }
    for (uint32_t i = 0; i < t->nids; i++) {
        memcpy(d->leaf_tris[i].v, tris[t->ids[i] & ~CBVH_ID_LAST].v, sizeof d->leaf_tris[i].v);
        d->leaf_tris[i].id = t->ids[i];
    }
    d->leaf_src = tris;
    return 0;
}

/* trav_cbvh_leaf on the copy: the same triangles in the same order, the
 * same counters (the memory image is the tree's). */
static int leaf_copy(trav_state *ts, const cbvh_cbvh_dtri *lt, uint32_t nids, uint32_t first, cbvh_f32 *cull,
                     double *cull_d) {
    for (uint32_t i = first; i < nids && !ts->done; i++) {
        trav_fetch(ts, CBVH_FETCH_IDS, ts->ids_base + (uint64_t)i * 4u, 4u);
        trav_triangle_v(ts, lt[i].id & ~CBVH_ID_LAST, (const cbvh_f32(*)[3])lt[i].v);
        if (lt[i].id & CBVH_ID_LAST) break;
    }
    *cull = trav_box_tmax(ts);
    *cull_d = cbvh_rbf_f32(*cull);
    return ts->done;
}

/* x (a finite plane u + c 2^e, up to 2^137) is a binary32 number; beyond
 * FLT_MAX the conversion would overflow, so that is tested first. */
static int exact_f32(double x) { return fabs(x) <= FLT_MAX && (double)(float)x == x; }

typedef struct {
    uint32_t pair;
    cbvh_node_ctx ctx;
} walk_entry;

/* One pair's record from its context; 0 when the fast decode does not take
 * it (the per-visit traversal would then run the node-pair unit).  Pushes
 * the inner children with the contexts the traversal derives for them.
 * wide receives the binary64 planes; the caller keeps them only for a pair
 * whose planes are not all exact in binary32 (flags EXACT without F32). */
static int decode_pair(const cbvh_tree *t, uint32_t i, const cbvh_node_ctx *ctx, cbvh_cbvh_dnode *rec,
                       cbvh_cbvh_drel *rel, cbvh_cbvh_dwide *wide, walk_entry *push, int *npush) {
    const cbvh_params *prm = &t->params;
    cbvh_fast_child fc[2];
    uint32_t ppm[3];
    if (!cbvh_fast_pair_decode_valid(prm, t->enc, ctx, t->pairs + (size_t)i * t->pair_bytes, fc, ppm)) return 0;
    cbvh_rbf_axis ax[3];
    for (int a = 0; a < 3; a++) {
        ax[a] = cbvh_rbf_axis_prep(ctx->axis[a].clb, ctx->axis[a].scale);
        rel->clb[a] = ctx->axis[a].clb;
        rel->scale[a] = (int8_t)ctx->axis[a].scale;
    }
    int exact = ax[0].exact & ax[1].exact & ax[2].exact, f32 = exact;
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
                wide->pl[0][a][c] = lo[a];
                wide->pl[1][a][c] = ax[a].u + (double)rel->s[c][a] * ax[a].step;
                f32 &= exact_f32(wide->pl[0][a][c]) & exact_f32(wide->pl[1][a][c]);
            }
        }
        if (fc[c].empty || fc[c].leaf) continue;
        walk_entry *w = &push[(*npush)++];
        w->pair = fc[c].ptr;
        for (int a = 0; a < 3; a++)
            cbvh_fast_child_ctx(prm, t->enc, &ctx->axis[a], ppm[a], &fc[c], a, ax[a].exact ? &lo[a] : NULL,
                                &w->ctx.axis[a]);
    }
    if (f32) {
        rec->flags |= CBVH_DEC_F32;
        for (int k = 0; k < 2; k++)
            for (int a = 0; a < 3; a++)
                for (int c = 0; c < 2; c++) rec->pl[k][a][c] = (float)wide->pl[k][a][c];
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
    uint32_t cap = 16;
    out->wide = malloc(cap * sizeof *out->wide);
    if (!out->nodes || !out->rel || !stack || !seen || !out->wide) {
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
        if (out->nwide == cap) { /* room for this pair's binary64 planes */
            cbvh_cbvh_dwide *w = cap <= UINT32_MAX / 2 ? realloc(out->wide, 2 * (size_t)cap * sizeof *w) : NULL;
            if (!w) {
                free(stack);
                free(seen);
                cbvh_cbvh_decoded_free(out);
                snprintf(err, errlen, "decoded CBVH: out of memory (%u node pairs)", t->npairs);
                return -1;
            }
            out->wide = w;
            cap *= 2;
        }
        cbvh_cbvh_dnode *rec = &out->nodes[e.pair];
        ok = decode_pair(t, e.pair, &e.ctx, rec, &out->rel[e.pair], &out->wide[out->nwide], stack, &sp);
        if (ok && (rec->flags & (CBVH_DEC_EXACT | CBVH_DEC_F32)) == CBVH_DEC_EXACT) rec->wide = out->nwide++;
        if (cbvh_lines_touched((uint64_t)e.pair * t->pair_bytes, t->pair_bytes) == 2) rec->flags |= CBVH_DEC_2LINES;
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
    const cbvh_cbvh_dtri *lt = d->leaf_tris && d->leaf_src == tris ? d->leaf_tris : NULL;
    entry stack[CBVH_TRAV_STACK];
    int sp = 0;
    uint32_t max_stack = 0;
    cbvh_f32 cull = trav_box_tmax(&ts);
    double cull_d = cbvh_rbf_f32(cull);
    cbvh_box_result r;
    double rtn;
    /* The entry being visited, cur, is kept out of the stack: a pair's nearer
     * hit child becomes cur instead of being pushed and popped at once.
     * Order, culling (the pop's t_near > cull check, on cur too), the
     * overflow check and max_stack (cur counted) are those of pushing it. */
    entry cur = {t->root_pair, 0, 0};
    int have = 0;
    if (trav_cbvh_root(&ts, &fp, t, cull, &rtn)) {
        cur.t_near = rtn;
        have = 1;
        max_stack = 1;
    }
    for (;;) {
        if (!have) {
            if (sp == 0) break;
            /* cppcheck-suppress uninitvar ; entries below sp were pushed */
            cur = stack[--sp];
        }
        have = 0;
        if (cur.t_near > cull_d) continue;
        if (cur.leaf) {
            if (lt ? leaf_copy(&ts, lt, t->nids, cur.ptr, &cull, &cull_d) : trav_cbvh_leaf(&ts, t, cur.ptr, &cull, &cull_d))
                break;
            continue;
        }
        uint32_t p = cur.ptr;
        ts.s.nodes++; /* the decode visited each pair once: no cycle, no pointer out of range */
        const cbvh_cbvh_dnode *rec = &d->nodes[p];
        uint32_t fl = rec->flags;
        trav_observe(&ts, CBVH_FETCH_NODE, (uint64_t)p * t->pair_bytes, t->pair_bytes);
        ts.s.lines += 1u + !!(fl & CBVH_DEC_2LINES); /* trav_fetch of the pair's bytes */
        for (int c = 0; c < 2; c++) { /* start the children's loads before their box tests */
            uint32_t q = rec->child[c];
            if (fl & (CBVH_DEC_EMPTY0 << c)) continue;
            if (!(fl & (CBVH_DEC_LEAF0 << c))) {
                __builtin_prefetch(&d->nodes[q]);
            } else if (q < t->nids) {
                if (lt) { /* a leaf's first triangles */
                    __builtin_prefetch(&lt[q]);
                    if (q + 2 < t->nids) __builtin_prefetch(&lt[q + 2]);
                } else {
                    __builtin_prefetch(&t->ids[q]);
                }
            }
        }
        double tn[2], tf[2] = {0, 0};
        int h[2] = {0, 0}, hf[2] = {0, 0}, dec = 0;
        if (fl & CBVH_DEC_F32) { /* binary32 planes, exactly the binary64 ones */
            dec = cbvh_rbf_box2_valid_f32(&fp, cull_d, rec->pl, hf, tf);
        } else if (fl & CBVH_DEC_EXACT) {
            const cbvh_cbvh_dwide *w = &d->wide[rec->wide];
            dec = cbvh_rbf_box2_valid(&fp, cull_d, w->pl, hf, tf);
        }
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
                g[a].u = d->rel[p].clb[a];
                g[a].e = d->rel[p].scale[a];
                g[a].r = d->rel[p].r[c][a];
                g[a].s = d->rel[p].s[c][a];
            }
            h[c] = cbvh_ray_box_prep(trav_prep(&ts), cull, mant_bits, g, &r) == 0 && r.hit;
            tn[c] = cbvh_rbf_f32(r.t_near);
        }
        if (sp + h[0] + h[1] > CBVH_TRAV_STACK) return -1;
        if (!(h[0] | h[1])) continue;
        int near = h[0] && h[1] ? tn[1] < tn[0] : h[1]; /* the nearer hit child (ties: child 0) */
        if (h[0] & h[1]) { /* the farther one pushed */
            entry *ne = &stack[sp++];
            ne->leaf = (fl & (CBVH_DEC_LEAF0 << (1 - near))) != 0;
            ne->ptr = rec->child[1 - near];
            ne->t_near = tn[1 - near];
        }
        cur.leaf = (fl & (CBVH_DEC_LEAF0 << near)) != 0;
        cur.ptr = rec->child[near];
        cur.t_near = tn[near];
        have = 1;
        if ((uint32_t)sp + 1u > max_stack) max_stack = (uint32_t)sp + 1u;
    }
    ts.s.max_stack = max_stack;
    trav_finish(&ts, hit, st);
    return 0;
}
