/* What the traversal tests share on top of test_util.h: hit equality, the
 * brute-force closest hit over all triangles, and the scene-box rays of the
 * traversal tests.  Header-only (static inline). */
#ifndef CBVH_TEST_TRAV_UTIL_H
#define CBVH_TEST_TRAV_UTIL_H

#include "cbvh/traverse.h"
#include "test_util.h"

/* Same hit: both miss, or same triangle and t, b1, b2 bits. */
static inline int same_hit(const cbvh_trav_hit *a, const cbvh_trav_hit *b) {
    return a->hit == b->hit && (!a->hit || (a->prim == b->prim && a->t == b->t && a->b1 == b->b1 && a->b2 == b->b2));
}

/* Closest hit by the ray-triangle unit over every triangle in [tmin, tmax]. */
static inline cbvh_trav_hit brute(const cbvh_scene *s, const cbvh_ray *r) {
    cbvh_trav_hit best = {0};
    for (uint32_t i = 0; i < s->ntris; i++) {
        cbvh_f32 v[3][3];
        memcpy(v, s->tris[i].v, sizeof v);
        cbvh_tri_result res;
        if (cbvh_ray_triangle(r, v[0], v[1], v[2], &res) || !res.hit) continue;
        int64_t k = cbvh_f32_key(res.t);
        if (k < cbvh_f32_key(r->tmin) || k > cbvh_f32_key(r->tmax)) continue;
        if (best.hit && k >= cbvh_f32_key(best.t)) continue; /* ascending ids: first wins ties */
        best.hit = 1;
        best.prim = i;
        best.t = res.t;
        best.b1 = res.b1;
        best.b2 = res.b2;
    }
    return best;
}

/* Ray i of a scene with box [lo, hi], drawn from generator state *rs: from
 * outside the box toward a point inside it, from inside (i % 3 == 0),
 * axis-parallel with +0/-0 components (i % 7 == 0), bounded tmax (i % 5 == 0),
 * and with edge_on, in the plane z = lo[2] (i % 4 == 1; the cloth's plane). */
static inline cbvh_ray box_ray(uint64_t *rs, const float lo[3], const float hi[3], int i, int edge_on) {
    cbvh_ray r;
    float o[3], t[3];
    for (int a = 0; a < 3; a++) {
        float ext = hi[a] - lo[a] > 0 ? hi[a] - lo[a] : 1.0f;
        float c = 0.5f * (lo[a] + hi[a]);
        t[a] = lo[a] + tu_unit_f(rs) * (hi[a] - lo[a]);
        o[a] = (i % 3 == 0) ? lo[a] + tu_unit_f(rs) * (hi[a] - lo[a]) : c + (tu_unit_f(rs) * 4 - 2) * ext;
    }
    if (edge_on && i % 4 == 1) { /* in the cloth's plane z = lo (= hi away from the bump) */
        o[2] = lo[2];
        t[2] = lo[2];
    }
    for (int a = 0; a < 3; a++) {
        r.o[a] = fb(o[a]);
        r.d[a] = fb(t[a] - o[a]);
    }
    if (i % 7 == 0) { /* axis-parallel */
        int a = (int)(tu_xorshift64(rs) % 3);
        for (int b = 0; b < 3; b++)
            if (b != a) r.d[b] = (tu_xorshift64(rs) & 1) ? 0 : CBVH_F32_SIGN;
        if (cbvh_f32_is_zero(r.d[a])) r.d[a] = fb(1.0f);
    }
    if (cbvh_f32_is_zero(r.d[0]) && cbvh_f32_is_zero(r.d[1]) && cbvh_f32_is_zero(r.d[2])) r.d[0] = fb(1.0f);
    r.tmin = 0;
    r.tmax = (i % 5 == 0) ? fb(0.5f + tu_unit_f(rs)) : CBVH_F32_POS_INF;
    return r;
}

#endif
