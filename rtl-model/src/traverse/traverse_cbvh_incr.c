/* The CBVH traversed with the incremental ray-box unit (unit 10,
 * docs/traversal.md §17.8).
 *
 * As cbvh_trace_cbvh (§5), but a node on the stack carries its six plane
 * distances (values of F(M, X), in binary64 for the unit's fast path,
 * fast/rbi_fast.h) and how many of its child cells it spans per axis (S: its
 * upper plane is u + S 2^e); a child with relative codes r, s is tested with
 * r and s' = S - s from those distances, and its own distances go on the
 * stack with it.  The root's are the anchor's (cbvh_rbi_anchor: exact
 * quotients rounded outward), after its float box passed unit 6 as in §5.  A
 * child with s > S (reaching past its parent's upper plane, which the
 * compressors never produce) is anchored afresh instead: conservative too.
 *
 * Same hits as the float BVH: every box holding an acceptable triangle is
 * kept, because the unit contains the exact interval (§17.5) and the culling
 * bound is §5's.  The counters: box_tests counts the incremental unit's
 * tests; each hit is also tested by unit 6 at the same M, and a child it
 * misses counts in st->fp_box_hits and marks the subtree: the triangle tests
 * of its leaves count in st->fp_tri_tests. */
#include "cbvh/traverse_incr.h"

#include "fast/decode_fast.h"
#include "fast/rbi_fast.h"
#include "traverse/traverse_cbvh_common.h"

typedef struct {
    int leaf, fp;          /* fp: reached through a child unit 6 rejects */
    uint32_t ptr;
    cbvh_node_ctx ctx;     /* inner: its context */
    uint32_t S[3];         /* inner: its extent in its own child cells */
    cbvh_rbi_fnode n;      /* inner: its plane distances (n.se is set when it is visited) */
    double t_near;
} entry;

/* The unit on node n's child with codes r, s': the fast path (rtl-model/src/
 * fast/rbi_fast.h), or, where it is off (-DCBVH_NO_FAST_PATHS, excess
 * precision), the integer path on the same values (F values convert to and
 * from binary64 exactly). */
static int child_test(const cbvh_rbi_params *p, const cbvh_rbi_ray *rr, const cbvh_rbi_fray *f, double tmax,
                      const cbvh_rbi_fnode *n, const int e[3], const uint32_t r[3], const uint32_t sp[3],
                      cbvh_rbi_fnode *ch, double *t_near) {
    double tf;
    if (CBVH_RBI_FAST) return cbvh_rbi_ftest(f, tmax, n, r, sp, ch, t_near, &tf);
    cbvh_rbi_ray ray = *rr;
    ray.tmax = cbvh_rbi_f(tmax);
    cbvh_rbi_planes par;
    cbvh_rbi_axis ax[3];
    for (int a = 0; a < 3; a++) {
        par.t_lb[a] = cbvh_f32_of((float)n->t[a][0]);
        par.t_ub[a] = cbvh_f32_of((float)n->t[a][1]);
        ax[a] = (cbvh_rbi_axis){e[a], r[a], sp[a]};
    }
    cbvh_rbi_result res;
    if (cbvh_ray_box_incr_int(p, &ray, &par, ax, &res) || !res.hit) return 0;
    for (int a = 0; a < 3; a++) {
        ch->t[a][0] = cbvh_rbi_d(res.planes.t_lb[a]);
        ch->t[a][1] = cbvh_rbi_d(res.planes.t_ub[a]);
    }
    *t_near = cbvh_rbi_d(res.t_near);
    return 1;
}

/* Plane distances of the grid box g (the anchor) as a node for the fast
 * path, and through it the box's hit and t_near (zero codes: the distances
 * themselves). */
static int anchor_test(const cbvh_ray *ray, const cbvh_rbi_params *p, const cbvh_rbi_ray *rr,
                       const cbvh_rbi_fray *f, double tmax, const cbvh_grid_axis g[3], cbvh_rbi_fnode *out,
                       double *t_near) {
    cbvh_rbi_planes pl;
    if (cbvh_rbi_anchor(ray, p, g, &pl)) return -1;
    static const int e0[3] = {0, 0, 0};
    static const uint32_t zero[3] = {0, 0, 0};
    cbvh_rbi_fnode n;
    cbvh_rbi_fnode_of(f, &pl, e0, &n);
    *out = n;
    return child_test(p, rr, f, tmax, &n, e0, zero, zero, out, t_near);
}

/* Cells of the root box at its virtual parent's scale, in the root's child grid. */
static int root_extent(const cbvh_tree *t, uint32_t S[3]) {
    for (int a = 0; a < 3; a++) {
        const cbvh_axis_ctx *c = &t->root_ctx.axis[a];
        cbvh_axis_code code;
        if (cbvh_axis_compress(&t->params, t->root_lo[a], t->root_hi[a], c->parent_scale, t->root_lo[a], &code) & CBVH_ST_REJECT)
            return -1;
        uint32_t cells = (code.ub_mod - code.lb_mod) & ((1u << t->params.quant_bits) - 1u);
        if (cells == 0) cells = 1u << t->params.quant_bits;
        int sh = c->parent_scale - c->scale;
        if (sh < 0 || sh > 10) return -1;
        S[a] = cells << sh;
        if (S[a] > CBVH_CODE_MAX) return -1;
    }
    return 0;
}

int cbvh_trace_cbvh_incr(const cbvh_tree *t, const cbvh_tri *tris, const cbvh_ray *ray, int mant_bits, int texp,
                         cbvh_trav_mode mode, cbvh_trav_hit *hit, cbvh_trav_stats *st) {
    trav_state ts;
    if (trav_begin(&ts, hit, ray, mant_bits, tris, mode, (uint64_t)t->npairs * t->pair_bytes, t->nids)) return -1;
    const cbvh_params *prm = &t->params;
    cbvh_rbi_params p = {prm->quant_bits, mant_bits, texp};
    cbvh_rbi_ray rr;
    if (cbvh_rbi_ray_setup(ray, &p, &rr)) return -1;
    cbvh_rbi_fray f;
    cbvh_rbi_fprep(&p, &rr, &f);
    cbvh_rbf_ray fp;
    cbvh_rbf_prepare(ray, mant_bits, &fp);
    int fast_codec = CBVH_FAST_PATHS && cbvh_fast_params_ok(prm) &&
                     t->pair_bytes == cbvh_nodepair_bytes(prm->quant_bits);
    uint64_t fp_box = 0, fp_tri = 0;

    entry stack[CBVH_TRAV_STACK];
    int sp = 0;
    uint32_t max_stack = 0;
    cbvh_f32 cull = trav_box_tmax(&ts);
    double cull_d = cbvh_rbf_f32(cull);
    double rtn;
    if (trav_cbvh_root(&ts, &fp, t, cull, &rtn)) {
        entry *e = &stack[0];
        cbvh_grid_axis g[3];
        if (root_extent(t, e->S)) return -1;
        for (int a = 0; a < 3; a++) g[a] = (cbvh_grid_axis){t->root_ctx.axis[a].clb, t->root_ctx.axis[a].scale, 0, e->S[a]};
        double tn0;
        int h0 = anchor_test(ray, &p, &rr, &f, cull_d, g, &e->n, &tn0);
        if (h0 < 0) return -1;
        e->leaf = 0;
        e->fp = 0;
        e->ptr = t->root_pair;
        e->ctx = t->root_ctx;
        e->t_near = rtn;
        sp = 1;
        max_stack = 1;
    }
    while (sp > 0) {
        entry *e = &stack[--sp];
        if (e->t_near > cull_d) continue;
        if (e->leaf) {
            uint64_t before = ts.s.tri_tests;
            int done = trav_cbvh_leaf(&ts, t, e->ptr, &cull, &cull_d);
            if (e->fp) fp_tri += ts.s.tri_tests - before;
            if (done) break;
            continue;
        }
        const uint8_t *pair = trav_cbvh_pair(&ts, t, e->ptr);
        if (!pair) return -1;
        entry node = *e; /* e's slot is reused by the pushes below */
        for (int a = 0; a < 3; a++) cbvh_rbi_fnode_scale(&f, a, node.ctx.axis[a].scale, &node.n);
        cbvh_fast_child fc[2];
        uint32_t ppm[3];
        int fast = fast_codec && cbvh_fast_pair_decode_valid(prm, t->enc, &node.ctx, pair, fc, ppm);
        cbvh_child_out ch[2];
        if (!fast) {
            if (cbvh_nodepair_decode(prm, t->enc, &node.ctx, pair, ch) & CBVH_ST_REJECT) return -1;
            for (int c = 0; c < 2; c++) {
                fc[c].leaf = ch[c].leaf;
                fc[c].empty = ch[c].empty;
                fc[c].ptr = ch[c].ptr;
                for (int a = 0; a < 3; a++) {
                    cbvh_axis_store_codes(prm, CBVH_ENC_RELATIVE, &node.ctx.axis[a], &ch[c].axis[a], &fc[c].r[a],
                                          &fc[c].s[a]);
                    if (fc[c].s[a] == 0) fc[c].s[a] = 1u << prm->quant_bits;
                }
            }
        }
        entry kid[2];
        int h[2] = {0, 0};
        for (int c = 0; c < 2; c++) {
            if (fc[c].empty) continue;
            ts.s.box_tests++;
            uint32_t spr[3];
            int past = 0;
            cbvh_grid_axis g[3];
            for (int a = 0; a < 3; a++) {
                past |= fc[c].s[a] > node.S[a];
                spr[a] = node.S[a] - fc[c].s[a];
                g[a] = (cbvh_grid_axis){node.ctx.axis[a].clb, node.ctx.axis[a].scale, fc[c].r[a], fc[c].s[a]};
            }
            if (!past) {
                int e3[3] = {node.ctx.axis[0].scale, node.ctx.axis[1].scale, node.ctx.axis[2].scale};
                h[c] = child_test(&p, &rr, &f, cull_d, &node.n, e3, fc[c].r, spr, &kid[c].n, &kid[c].t_near);
            } else { /* past the parent's upper plane: the child's distances afresh */
                h[c] = anchor_test(ray, &p, &rr, &f, cull_d, g, &kid[c].n, &kid[c].t_near);
                if (h[c] < 0) return -1;
            }
            if (!h[c]) continue;
            cbvh_box_result r;
            int ex = cbvh_ray_box_prep(trav_prep(&ts), cull, mant_bits, g, &r) == 0 && r.hit;
            fp_box += !ex;
            kid[c].fp = node.fp || !ex;
            kid[c].leaf = fc[c].leaf;
            kid[c].ptr = fc[c].ptr;
            if (kid[c].leaf) continue;
            for (int a = 0; a < 3; a++) {
                if (fast) cbvh_fast_child_ctx(prm, t->enc, &node.ctx.axis[a], ppm[a], &fc[c], a, NULL, &kid[c].ctx.axis[a]);
                else kid[c].ctx.axis[a] = cbvh_axis_child_ctx(&node.ctx.axis[a], &ch[c].axis[a]);
                int sh = node.ctx.axis[a].scale - kid[c].ctx.axis[a].scale; /* >= 0 (trap T2) */
                kid[c].S[a] = (fc[c].s[a] - fc[c].r[a]) << (sh < 0 ? 0 : sh > 10 ? 10 : sh);
            }
        }
        if (sp + h[0] + h[1] > CBVH_TRAV_STACK) return -1;
        int first = h[0] && h[1] && kid[1].t_near < kid[0].t_near;
        for (int k = 1; k >= 0; k--) { /* farther first, so the nearer is popped next */
            int c = k ? 1 - first : first;
            if (h[c]) stack[sp++] = kid[c];
        }
        if ((uint32_t)sp > max_stack) max_stack = (uint32_t)sp;
    }
    ts.s.max_stack = max_stack;
    trav_finish(&ts, hit, st);
    st->fp_box_hits += fp_box;
    st->fp_tri_tests += fp_tri;
    return 0;
}
