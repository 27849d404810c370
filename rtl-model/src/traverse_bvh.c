/* Reference traversal over the float BVH (docs/traversal.md §5): boxes are the
 * float boxes, tested with the ray-box unit (planes exact, M bits). */
#include "traverse_common.h"

static cbvh_f32 bits(float f) {
    cbvh_f32 b;
    memcpy(&b, &f, sizeof b);
    return b;
}

static int box(trav_state *ts, const cbvh_bvh_node *n, cbvh_box_result *r) {
    cbvh_f32 lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = bits(n->lo[a]);
        hi[a] = bits(n->hi[a]);
    }
    ts->s.box_tests++;
    return cbvh_ray_box_float_prep(&ts->prep, trav_box_tmax(ts), ts->M, lo, hi, r) == 0 && r->hit;
}

int cbvh_trace_bvh(const cbvh_bvh *b, const cbvh_tri *tris, const cbvh_ray *ray, int mant_bits, cbvh_trav_mode mode,
                   cbvh_trav_hit *hit, cbvh_trav_stats *st) {
    trav_state ts;
    memset(&ts, 0, sizeof ts);
    memset(hit, 0, sizeof *hit);
    if (!trav_ray_ok(&ts, ray, mant_bits)) return -1;
    ts.ray = ray;
    ts.tris = tris;
    ts.mode = mode;
    ts.M = mant_bits;
    ts.ids_base = trav_align((uint64_t)b->nnodes * 64u);
    ts.tris_base = trav_align(ts.ids_base + (uint64_t)b->nprims * 4u);

    struct {
        uint32_t node;
        cbvh_f32 t_near;
    } stack[CBVH_TRAV_STACK];
    int sp = 0;
    cbvh_box_result r;
    if (box(&ts, &b->nodes[b->root], &r)) {
        stack[sp].node = b->root;
        stack[sp++].t_near = r.t_near;
        ts.s.max_stack = 1;
    }
    while (sp > 0 && !ts.done) {
        sp--;
        const cbvh_bvh_node *n = &b->nodes[stack[sp].node];
        /* culled since it was pushed (a closer hit was found) */
        if (cbvh_f32_key(stack[sp].t_near) > cbvh_f32_key(trav_box_tmax(&ts))) continue;
        if (cbvh_bvh_is_leaf(n)) {
            trav_fetch(&ts, ts.ids_base + (uint64_t)n->first * 4u, (uint64_t)n->count * 4u);
            for (uint32_t i = 0; i < n->count && !ts.done; i++) trav_triangle(&ts, b->prims[n->first + i]);
            continue;
        }
        ts.s.nodes++;
        trav_fetch(&ts, (uint64_t)stack[sp].node * 64u, 64u);
        cbvh_box_result cr[2];
        int h[2];
        for (int c = 0; c < 2; c++) h[c] = box(&ts, &b->nodes[n->child[c]], &cr[c]);
        /* push the farther child first so the nearer one is visited next */
        int first = (h[0] && h[1] && cbvh_f32_key(cr[1].t_near) < cbvh_f32_key(cr[0].t_near)) ? 1 : 0;
        for (int k = 1; k >= 0; k--) {
            int c = k ? 1 - first : first;
            if (!h[c]) continue;
            if (sp == CBVH_TRAV_STACK) return -1;
            stack[sp].node = n->child[c];
            stack[sp++].t_near = cr[c].t_near;
            if ((uint32_t)sp > ts.s.max_stack) ts.s.max_stack = (uint32_t)sp;
        }
    }
    trav_finish(&ts, hit, st);
    return 0;
}
