/* Traversal over the CBVH (docs/traversal.md §5): node pairs are decoded with
 * the node-pair codec (unit 5) under the node's context, and each child box is
 * tested with the ray-box unit on the decoded grid (unit 6): planes
 * u + r 2^e and u + s 2^e with u, e from the node's context and r, s the
 * child's relative coordinates. */
#include "traverse_common.h"

typedef struct {
    int leaf;
    uint32_t ptr;
    cbvh_node_ctx ctx; /* inner: the child's own context */
    cbvh_f32 t_near;
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
    memset(&ts, 0, sizeof ts);
    memset(hit, 0, sizeof *hit);
    if (!trav_ray_ok(&ts, ray, mant_bits)) return -1;
    ts.ray = ray;
    ts.tris = tris;
    ts.mode = mode;
    ts.M = mant_bits;
    ts.ids_base = trav_align((uint64_t)t->npairs * t->pair_bytes);
    ts.tris_base = trav_align(ts.ids_base + (uint64_t)t->nids * 4u);

    entry stack[CBVH_TRAV_STACK];
    int sp = 0;
    cbvh_box_result r;
    ts.s.box_tests++;
    if (cbvh_ray_box_float_prep(&ts.prep, trav_box_tmax(&ts), mant_bits, t->root_lo, t->root_hi, &r) == 0 && r.hit) {
        stack[0].leaf = 0;
        stack[0].ptr = t->root_pair;
        stack[0].ctx = t->root_ctx;
        stack[0].t_near = r.t_near;
        sp = 1;
        ts.s.max_stack = 1;
    }
    while (sp > 0 && !ts.done) {
        entry e = stack[--sp];
        if (cbvh_f32_key(e.t_near) > cbvh_f32_key(trav_box_tmax(&ts))) continue;
        if (e.leaf) {
            for (uint32_t i = e.ptr; i < t->nids && !ts.done; i++) {
                trav_fetch(&ts, ts.ids_base + (uint64_t)i * 4u, 4u);
                trav_triangle(&ts, t->ids[i] & ~CBVH_ID_LAST);
                if (t->ids[i] & CBVH_ID_LAST) break;
            }
            continue;
        }
        if (e.ptr >= t->npairs) return -1;
        ts.s.nodes++;
        trav_fetch(&ts, (uint64_t)e.ptr * t->pair_bytes, t->pair_bytes);
        cbvh_child_out ch[2];
        if (cbvh_nodepair_decode(&t->params, t->enc, &e.ctx, t->pairs + (size_t)e.ptr * t->pair_bytes, ch) &
            CBVH_ST_REJECT)
            return -1;
        cbvh_box_result cr[2];
        int h[2] = {0, 0};
        cbvh_f32 cull_tmax = trav_box_tmax(&ts);
        for (int c = 0; c < 2; c++) {
            if (ch[c].empty) continue;
            cbvh_grid_axis g[3];
            for (int a = 0; a < 3; a++) {
                g[a].u = e.ctx.axis[a].clb;
                g[a].e = e.ctx.axis[a].scale;
                rel_coords(&t->params, &e.ctx.axis[a], &ch[c].axis[a], &g[a].r, &g[a].s);
            }
            ts.s.box_tests++;
            h[c] = cbvh_ray_box_prep(&ts.prep, cull_tmax, mant_bits, g, &cr[c]) == 0 && cr[c].hit;
        }
        int first = (h[0] && h[1] && cbvh_f32_key(cr[1].t_near) < cbvh_f32_key(cr[0].t_near)) ? 1 : 0;
        for (int k = 1; k >= 0; k--) {
            int c = k ? 1 - first : first;
            if (!h[c]) continue;
            if (sp == CBVH_TRAV_STACK) return -1;
            entry *n = &stack[sp++];
            n->leaf = ch[c].leaf;
            n->ptr = ch[c].ptr;
            for (int a = 0; a < 3; a++) n->ctx.axis[a] = cbvh_axis_child_ctx(&e.ctx.axis[a], &ch[c].axis[a]);
            n->t_near = cr[c].t_near;
            if ((uint32_t)sp > ts.s.max_stack) ts.s.max_stack = (uint32_t)sp;
        }
    }
    trav_finish(&ts, hit, st);
    return 0;
}
