/* Traversal over the CBVH (docs/traversal.md §5): node pairs are decoded with
 * the node-pair codec (unit 5) under the node's context, and each child box is
 * tested with the ray-box unit on the decoded grid (unit 6): planes
 * u + r 2^e and u + s 2^e with u, e from the node's context and r, s the
 * child's relative coordinates.
 *
 * Fast paths (docs/traversal.md §9), each proven to give the units' outputs
 * and falling back to the units otherwise: the node-pair decode of
 * decode_fast.h, the box unit's binary64 filter (ray_box_f64.h) on planes
 * that are exact in binary64, and the child context's bound clb = RD(u + r 2^e)
 * rounded directly from that exact plane. */
#include "fast/decode_fast.h"
#include "traverse/traverse_cbvh_common.h"

typedef struct {
    int leaf;
    int ctx_ok; /* ctx known valid (the root's, checked, or derived by cbvh_fast_child_ctx) */
    uint32_t ptr;
    cbvh_node_ctx ctx; /* inner: the child's own context */
    double t_near;     /* binary64: its order is the unit's key order */
} entry;

/* Relative coordinates of a decoded child (r in [0, 2^N), s in [1, 2^N]). */
static void rel_coords(const cbvh_params *p, const cbvh_axis_ctx *ctx, const cbvh_axis_code *code, uint32_t *r,
                       uint32_t *s) {
    cbvh_axis_store_codes(p, CBVH_ENC_RELATIVE, ctx, code, r, s);
    if (*s == 0) *s = 1u << p->quant_bits;
}

int cbvh_trace_cbvh(const cbvh_tree *t, const cbvh_tri *tris, const cbvh_ray *ray, int mant_bits,
                    cbvh_trav_mode mode, cbvh_trav_hit *hit, cbvh_trav_stats *st) {
    trav_state ts;
    if (trav_begin(&ts, hit, ray, mant_bits, tris, mode, (uint64_t)t->npairs * t->pair_bytes, t->nids)) return -1;
    cbvh_rbf_ray fp;
    cbvh_rbf_prepare(ray, mant_bits, &fp);
    const cbvh_params *prm = &t->params;
    int fast_codec = CBVH_FAST_PATHS && cbvh_fast_params_ok(prm) &&
                     t->pair_bytes == cbvh_nodepair_bytes(prm->quant_bits);

    entry stack[CBVH_TRAV_STACK];
    int sp = 0;
    uint32_t max_stack = 0;
    cbvh_f32 cull = trav_box_tmax(&ts);
    double cull_d = cbvh_rbf_f32(cull);
    cbvh_box_result r;
    double rtn;
    if (trav_cbvh_root(&ts, &fp, t, cull, &rtn)) {
        stack[0].leaf = 0;
        stack[0].ctx_ok = fast_codec && cbvh_fast_node_ctx_ok(prm, &t->root_ctx);
        stack[0].ptr = t->root_pair;
        stack[0].ctx = t->root_ctx;
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
        const uint8_t *pair = trav_cbvh_pair(&ts, t, e->ptr);
        if (!pair) return -1;
        cbvh_node_ctx ctx = e->ctx; /* e's slot is reused by the pushes below */
        double tn[2];
        int h[2] = {0, 0};
        cbvh_fast_child fc[2];
        uint32_t ppm[3];
        if (fast_codec && (e->ctx_ok || cbvh_fast_node_ctx_ok(prm, &ctx)) &&
            cbvh_fast_pair_decode_valid(prm, t->enc, &ctx, pair, fc, ppm)) {
            cbvh_rbf_axis ax[3];
            for (int a = 0; a < 3; a++) ax[a] = cbvh_rbf_axis_prep(ctx.axis[a].clb, ctx.axis[a].scale);
            int exact = ax[0].exact & ax[1].exact & ax[2].exact;
            double pl[2][3][2], tf[2] = {0, 0}; /* [lower, upper][axis][child] */
            int hf[2] = {0, 0};
            for (int a = 0; a < 3; a++)
                for (int c = 0; c < 2; c++) { /* an empty slot gets a dummy box, its lane is ignored */
                    pl[0][a][c] = ax[a].u + (double)(fc[c].empty ? 0 : fc[c].r[a]) * ax[a].step;
                    pl[1][a][c] = ax[a].u + (double)(fc[c].empty ? 1 : fc[c].s[a]) * ax[a].step;
                }
            /* r < s (the decode's check) and exact finite planes: valid boxes */
            int dec = exact ? cbvh_rbf_box2_valid(&fp, cull_d, (const double(*)[3][2])pl, hf, tf) : 0;
            for (int c = 0; c < 2; c++) {
                if (fc[c].empty) continue;
                ts.s.box_tests++;
                if (dec >> c & 1) {
                    h[c] = hf[c];
                    tn[c] = tf[c];
                    continue;
                }
                cbvh_grid_axis g[3];
                for (int a = 0; a < 3; a++) {
                    g[a].u = ctx.axis[a].clb;
                    g[a].e = ctx.axis[a].scale;
                    g[a].r = fc[c].r[a];
                    g[a].s = fc[c].s[a];
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
                ne->leaf = fc[c].leaf;
                ne->ctx_ok = 1;
                ne->ptr = fc[c].ptr;
                ne->t_near = tn[c];
                if (ne->leaf) continue; /* a leaf entry's context is never read */
                for (int a = 0; a < 3; a++) {
                    cbvh_fast_child_ctx(prm, t->enc, &ctx.axis[a], ppm[a], &fc[c], a,
                                        ax[a].exact ? &pl[0][a][c] : NULL, &ne->ctx.axis[a]);
                }
            }
        } else {
            cbvh_child_out ch[2];
            if (cbvh_nodepair_decode(prm, t->enc, &ctx, pair, ch) & CBVH_ST_REJECT) return -1;
            for (int c = 0; c < 2; c++) {
                if (ch[c].empty) continue;
                cbvh_grid_axis g[3];
                for (int a = 0; a < 3; a++) {
                    g[a].u = ctx.axis[a].clb;
                    g[a].e = ctx.axis[a].scale;
                    rel_coords(prm, &ctx.axis[a], &ch[c].axis[a], &g[a].r, &g[a].s);
                }
                ts.s.box_tests++;
                h[c] = cbvh_ray_box_prep(trav_prep(&ts), cull, mant_bits, g, &r) == 0 && r.hit;
                tn[c] = cbvh_rbf_f32(r.t_near);
            }
            if (sp + h[0] + h[1] > CBVH_TRAV_STACK) return -1;
            int first = h[0] && h[1] && tn[1] < tn[0];
            for (int k = 1; k >= 0; k--) {
                int c = k ? 1 - first : first;
                if (!h[c]) continue;
                entry *ne = &stack[sp++];
                ne->leaf = ch[c].leaf;
                ne->ctx_ok = 0; /* from the unit: checked when popped */
                ne->ptr = ch[c].ptr;
                for (int a = 0; a < 3; a++) ne->ctx.axis[a] = cbvh_axis_child_ctx(&ctx.axis[a], &ch[c].axis[a]);
                ne->t_near = tn[c];
            }
        }
        if ((uint32_t)sp > max_stack) max_stack = (uint32_t)sp;
        /* what the pushed children read next: their pair or their IDs */
        for (int k = sp - h[0] - h[1]; k < sp; k++) {
            if (stack[k].leaf) {
                if (stack[k].ptr < t->nids) __builtin_prefetch(&t->ids[stack[k].ptr]);
            } else if (stack[k].ptr < t->npairs) {
                __builtin_prefetch(t->pairs + (size_t)stack[k].ptr * t->pair_bytes);
            }
        }
    }
    ts.s.max_stack = max_stack;
    trav_finish(&ts, hit, st);
    return 0;
}
