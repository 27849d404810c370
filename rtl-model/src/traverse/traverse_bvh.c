/* Reference traversal over the float BVH (docs/traversal.md §5): boxes are the
 * float boxes, tested with the ray-box unit (planes exact, M bits).  The box
 * unit's binary64 filter (ray_box_f64.h, docs/traversal.md §9) decides almost
 * every test; the unit itself decides the rest, so every result, counter and
 * visiting order is the unit's. */
#include "fast/ray_box_f64.h"
#include "traverse/traverse_common.h"

/* The ray-box unit itself on node n's box with culling bound tmax: hit, and
 * t_near (for the boxes the binary64 filter leaves undecided). */
static int unit_box(trav_state *ts, const cbvh_bvh_node *n, cbvh_f32 tmax, double *t_near) {
    cbvh_f32 flo[3], fhi[3];
    for (int a = 0; a < 3; a++) {
        flo[a] = cbvh_f32_of(n->lo[a]);
        fhi[a] = cbvh_f32_of(n->hi[a]);
    }
    cbvh_box_result r;
    if (cbvh_ray_box_float_prep(trav_prep(ts), tmax, ts->M, flo, fhi, &r) != 0 || !r.hit) return 0;
    *t_near = cbvh_rbf_f32(r.t_near);
    return 1;
}

/* The root box: the filter, else the unit. */
static int box(trav_state *ts, const cbvh_rbf_ray *fp, const cbvh_bvh_node *n, cbvh_f32 tmax, double tmax_d,
               double *t_near) {
    double lo[3] = {n->lo[0], n->lo[1], n->lo[2]}, hi[3] = {n->hi[0], n->hi[1], n->hi[2]};
    int hit;
    ts->s.box_tests++;
    if (cbvh_rbf_box(fp, tmax_d, lo, hi, &hit, t_near)) return hit;
    return unit_box(ts, n, tmax, t_near);
}

int cbvh_trace_bvh(const cbvh_bvh *b, const cbvh_tri *tris, const cbvh_ray *ray, int mant_bits, cbvh_trav_mode mode,
                   cbvh_trav_hit *hit, cbvh_trav_stats *st) {
    trav_state ts;
    if (trav_begin(&ts, hit, ray, mant_bits, tris, mode, (uint64_t)b->nnodes * 64u, b->nprims)) return -1;
    cbvh_rbf_ray fp;
    cbvh_rbf_prepare(ray, mant_bits, &fp);

    /* t_near as binary64: its order is the unit's key order */
    struct {
        uint32_t node;
        double t_near;
    } stack[CBVH_TRAV_STACK];
    int sp = 0;
    uint32_t max_stack = 0;
    const cbvh_bvh_node *nodes = b->nodes;
    /* the culling bound changes only when a triangle is accepted */
    cbvh_f32 cull = trav_box_tmax(&ts);
    double cull_d = cbvh_rbf_f32(cull);
    double tn;
    if (box(&ts, &fp, &nodes[b->root], cull, cull_d, &tn)) {
        stack[sp].node = b->root;
        stack[sp++].t_near = tn;
        max_stack = 1;
    }
    while (sp > 0) {
        sp--;
        uint32_t ni = stack[sp].node;
        const cbvh_bvh_node *n = &nodes[ni];
        /* culled since it was pushed (a closer hit was found) */
        if (stack[sp].t_near > cull_d) continue;
        if (cbvh_bvh_is_leaf(n)) {
            /* start the leaf's triangle loads together (memory latency) */
            for (uint32_t i = 0; i < n->count; i++) __builtin_prefetch(&tris[b->prims[n->first + i]]);
            trav_fetch(&ts, CBVH_FETCH_IDS, ts.ids_base + (uint64_t)n->first * 4u, (uint64_t)n->count * 4u);
            for (uint32_t i = 0; i < n->count && !ts.done; i++) trav_triangle(&ts, b->prims[n->first + i]);
            if (ts.done) break;
            cull = trav_box_tmax(&ts);
            cull_d = cbvh_rbf_f32(cull);
            continue;
        }
        ts.s.nodes++;
        trav_fetch(&ts, CBVH_FETCH_NODE, (uint64_t)ni * 64u, 64u);
        uint32_t c0 = n->child[0], c1 = n->child[1];
        const cbvh_bvh_node *n0 = &nodes[c0], *n1 = &nodes[c1];
        double pl[2][3][2], tn2[2]; /* [lower, upper][axis][child] */
        int hit2[2];
        for (int a = 0; a < 3; a++) {
            pl[0][a][0] = n0->lo[a];
            pl[0][a][1] = n1->lo[a];
            pl[1][a][0] = n0->hi[a];
            pl[1][a][1] = n1->hi[a];
        }
        int dec = cbvh_rbf_box2(&fp, cull_d, (const double(*)[3][2])pl, hit2, tn2);
        double t0 = tn2[0], t1 = tn2[1];
        int h0 = hit2[0], h1 = hit2[1];
        ts.s.box_tests += 2;
        if (!(dec & 1)) h0 = unit_box(&ts, n0, cull, &t0);
        if (!(dec & 2)) h1 = unit_box(&ts, n1, cull, &t1);
        if (sp + h0 + h1 > CBVH_TRAV_STACK) return -1;
        /* push the farther child first so the nearer one is visited next */
        if (h0 && h1 && t1 < t0) {
            stack[sp].node = c0;
            stack[sp++].t_near = t0;
            stack[sp].node = c1;
            stack[sp++].t_near = t1;
        } else {
            if (h1) {
                stack[sp].node = c1;
                stack[sp++].t_near = t1;
            }
            if (h0) {
                stack[sp].node = c0;
                stack[sp++].t_near = t0;
            }
        }
        if ((uint32_t)sp > max_stack) max_stack = (uint32_t)sp;
        /* the children's boxes (or primitive IDs) of what was pushed, which
         * are read next */
        for (int k = sp - h0 - h1; k < sp; k++) {
            const cbvh_bvh_node *c = &nodes[stack[k].node];
            if (cbvh_bvh_is_leaf(c)) {
                __builtin_prefetch(&b->prims[c->first]);
            } else {
                __builtin_prefetch(&nodes[c->child[0]]);
                __builtin_prefetch(&nodes[c->child[1]]);
            }
        }
    }
    ts.s.max_stack = max_stack;
    trav_finish(&ts, hit, st);
    return 0;
}
