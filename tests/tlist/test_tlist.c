/* Traversal lists (seed 004, docs/tlist.md).
 *
 * On scenes/bunny-small.obj, procedural scenes and small hand-made ones
 * (mixed sizes with degenerate and duplicate triangles, coplanar ties,
 * coincident centroids):
 *   - the hierarchy: every triangle once, every binary32 sphere encloses all
 *     vertices of its subtree exactly (exact arithmetic), and radii are tight
 *     (one ulp less no longer encloses);
 *   - every list: escape-index invariants, DFS nesting, children sorted along
 *     the list direction by the order rule, exactly the triangles the culling
 *     rule keeps, culling never drops a triangle some direction of the list
 *     sees from the front;
 *   - hits: for 1/2/6/8 lists x earliest-first/latest-last x culling, closest
 *     and any hit equal cbvh_trace_bvh's (triangle, t, b1, b2 bits) on camera,
 *     random, axis-parallel (+-0), grazing (along edges, through vertices),
 *     inside, bounded and tmin > 0 rays; two-sided and one-sided (culled lists
 *     one-sided only, as docs/tlist.md §5 requires);
 *   - the harness can fail: a list with one shrunken sphere is caught;
 *   - bad input: bad parameters, a scene too large for binary32 spheres.
 * Per-polygon and per-screen-cell heads: test_tlist_heads.c. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/tlist.h"
#include "units/exact_wide.h"
#include "scene/scene_load.h"
#include "test_trav_util.h"

static long fails;
#define CHECK(c, ...) TU_CHECK(fails, stdout, c, __VA_ARGS__)

static uint64_t rs = 0x243F6A8885A308D3ull;
static uint64_t rnd(void) { return tu_xorshift64(&rs); }
static float unit(void) { return tu_unit_f(&rs); }

/* ---- exact enclosure ---------------------------------------------------- */
static int encloses(const uint32_t sph[4], const float v[3]) {
    cbvh_xw s, d, p, c;
    cbvh_xw_zero(&s);
    for (int a = 0; a < 3; a++) {
        cbvh_xw_from_f32(&d, fb(v[a]));
        cbvh_xw_from_f32(&c, sph[a]);
        cbvh_xw_sub(&d, &d, &c);
        cbvh_xw_mul(&p, &d, &d);
        cbvh_xw_add(&s, &s, &p);
    }
    cbvh_xw_from_f32(&d, sph[3]);
    cbvh_xw_mul(&p, &d, &d);
    return cbvh_xw_cmp(&s, &p) <= 0;
}

/* Radii are the smallest binary32 that encloses: one ulp less fails (count). */
static void check_tight(const cbvh_bsh *h, const cbvh_scene *s) {
    uint32_t loose = 0, nonzero = 0;
    uint32_t *stack = malloc((size_t)h->nnodes * sizeof *stack);
    for (uint32_t i = 0; i < h->nnodes; i++) {
        if (cbvh_f32_is_zero(h->sphere[i][3])) continue;
        nonzero++;
        uint32_t sph[4] = {h->sphere[i][0], h->sphere[i][1], h->sphere[i][2], cbvh_f32_next_down(h->sphere[i][3])};
        int all = 1, n = 0;
        stack[n++] = i;
        while (n && all) {
            uint32_t k = stack[--n];
            for (uint32_t j = 0; j < h->ntri[k] && all; j++)
                for (int v = 0; v < 3; v++) all &= encloses(sph, s->tris[h->tri_ids[h->first_tri[k] + j]].v[v]);
            for (uint32_t c = 0; c < h->nchild[k]; c++) stack[n++] = h->first_child[k] + c;
        }
        loose += all;
    }
    /* Every centre is 0.5f*lo + 0.5f*hi of its subtree's tight box (tlist.md §3.1). */
    uint32_t off_centre = 0;
    for (uint32_t i = 0; i < h->nnodes; i++) {
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        int n = 0;
        stack[n++] = i;
        while (n) {
            uint32_t k = stack[--n];
            for (uint32_t j = 0; j < h->ntri[k]; j++)
                for (int v = 0; v < 3; v++)
                    for (int a = 0; a < 3; a++) {
                        float x = s->tris[h->tri_ids[h->first_tri[k] + j]].v[v][a];
                        lo[a] = x < lo[a] ? x : lo[a];
                        hi[a] = x > hi[a] ? x : hi[a];
                    }
            for (uint32_t c = 0; c < h->nchild[k]; c++) stack[n++] = h->first_child[k] + c;
        }
        for (int a = 0; a < 3; a++) off_centre += h->sphere[i][a] != fb(0.5f * lo[a] + 0.5f * hi[a]);
    }
    free(stack);
    CHECK(loose * 1000u <= nonzero, "%s: %u of %u radii are not tight (one ulp less still encloses)", s->name, loose,
          nonzero);
    CHECK(off_centre == 0, "%s: %u sphere centre coordinates are not their box's centre", s->name, off_centre);
}

/* ---- list structure ----------------------------------------------------- */
static int is_sphere(const cbvh_tlist_elem *e) { return e->escape >= 2 || e->escape == -1; }

static double key_of(const cbvh_tlist_elem *e, const cbvh_scene *s, const float dir[3], int latest) {
    double dl = sqrt((double)dir[0] * dir[0] + (double)dir[1] * dir[1] + (double)dir[2] * dir[2]);
    if (is_sphere(e)) {
        double c = 0;
        for (int a = 0; a < 3; a++) c += (double)dir[a] * bf(e->data[a]);
        return latest ? c + bf(e->data[3]) * dl : c - bf(e->data[3]) * dl;
    }
    const cbvh_tri *t = &s->tris[e->data[0]];
    double k = 0;
    for (int v = 0; v < 3; v++) {
        double p = 0;
        for (int a = 0; a < 3; a++) p += (double)dir[a] * t->v[v][a];
        if (v == 0 || (latest ? p > k : p < k)) k = p;
    }
    return k;
}

static void check_list(const cbvh_tlists *L, int l, const cbvh_bsh *h, const cbvh_scene *s, uint64_t *culled) {
    const cbvh_tlist_elem *E = L->list[l];
    uint32_t n = L->len[l];
    char tag[160];
    snprintf(tag, sizeof tag, "%s lists=%d order=%d cull=%d list %d", s->name, L->p.nlists, (int)L->p.order,
             L->p.cull_back, l);
    uint8_t *seen = calloc(s->ntris, 1);
    uint32_t *end = malloc((size_t)(n + 1) * sizeof *end), *anc = malloc((size_t)(n + 1) * sizeof *anc);
    uint32_t nanc = 0, nsph = 0;
    float dir[3], gen[6][3];
    cbvh_tlist_cone(L->p.nlists, l, dir, gen);
    int latest = L->p.order == CBVH_TLIST_LATEST_LAST;
    for (uint32_t i = 0; i < n; i++) {
        const cbvh_tlist_elem *e = &E[i];
        while (nanc && end[anc[nanc - 1]] <= i) nanc--;
        if (is_sphere(e)) {
            nsph++;
            uint32_t en = e->escape == -1 ? n : i + (uint32_t)e->escape;
            CHECK(en <= n && en >= i + 2, "%s: sphere %u escape %d out of range", tag, i, e->escape);
            if (en > n) en = n;
            CHECK((e->escape == -1) == (en == n), "%s: sphere %u ends at the list end but escape %d", tag, i,
                  e->escape);
            if (nanc) CHECK(en <= end[anc[nanc - 1]], "%s: sphere %u subtree crosses its parent's end", tag, i);
            end[i] = en;
            anc[nanc++] = i;
        } else {
            CHECK(e->escape == (i + 1 == n ? 0 : 1), "%s: triangle element %u escape %d", tag, i, e->escape);
            uint32_t t = e->data[0];
            CHECK(t < s->ntris && !seen[t], "%s: triangle %u out of range or twice", tag, t);
            if (t >= s->ntris) continue;
            seen[t] = 1;
            CHECK(nanc > 0, "%s: triangle %u outside every sphere", tag, t);
            /* the innermost sphere is enough: every sphere encloses its descendants' spheres' vertices */
            if (nanc)
                for (int v = 0; v < 3; v++)
                    CHECK(encloses(E[anc[nanc - 1]].data, s->tris[t].v[v]), "%s: sphere %u misses triangle %u",
                          tag, anc[nanc - 1], t);
        }
    }
    /* children of every sphere sorted along the direction (keys non-decreasing) */
    for (uint32_t i = 0; i < n; i++) {
        if (!is_sphere(&E[i])) continue;
        double prev = -INFINITY;
        for (uint32_t j = i + 1; j < end[i]; j = is_sphere(&E[j]) ? end[j] : j + 1) {
            double k = key_of(&E[j], s, dir, latest);
            CHECK(k >= prev, "%s: children of sphere %u out of order at %u", tag, i, j);
            prev = k;
        }
    }
    for (uint32_t t = 0; t < s->ntris; t++) {
        int c = L->p.cull_back && cbvh_tlist_culled(L->p.nlists, l, &s->tris[t]);
        CHECK(seen[t] == !c, "%s: triangle %u %s", tag, t, c ? "culled but listed" : "missing");
        *culled += c;
    }
    if (!L->p.cull_back) CHECK(nsph == h->nnodes && n == h->nnodes + s->ntris, "%s: %u spheres for %u nodes", tag, nsph,
                               h->nnodes);
    CHECK(n == 0 || E[n - 1].escape == 0, "%s: last element escape %d", tag, n ? E[n - 1].escape : 0);
    free(seen);
    free(end);
    free(anc);
}

/* Culling is exact and conservative: a culled triangle is never seen from the
 * front by random directions of the list (picked by cbvh_tlist_pick). */
static void check_cull_rule(const cbvh_tlists *L, const cbvh_scene *s) {
    for (int k = 0; k < 2000; k++) {
        cbvh_ray r;
        memset(&r, 0, sizeof r);
        for (int a = 0; a < 3; a++) r.d[a] = fb(unit() * 2 - 1);
        if (k % 5 == 0) r.d[k % 3] = (rnd() & 1) ? 0 : CBVH_F32_SIGN; /* on the cone's boundary */
        if (k % 7 == 0) r.d[1] = r.d[0] ^ (rnd() & 1 ? CBVH_F32_SIGN : 0); /* |dx| == |dy|: sextant tie */
        if (cbvh_f32_is_zero(r.d[0]) && cbvh_f32_is_zero(r.d[1]) && cbvh_f32_is_zero(r.d[2])) r.d[0] = fb(1.0f);
        int l = cbvh_tlist_pick(L, &r);
        uint32_t t = (uint32_t)(rnd() % s->ntris);
        if (!cbvh_tlist_culled(L->p.nlists, l, &s->tris[t])) continue;
        cbvh_f32 v[3][3];
        for (int q = 0; q < 3; q++)
            for (int a = 0; a < 3; a++) v[q][a] = fb(s->tris[t].v[q][a]);
        CHECK(cbvh_tri_facing(r.d, v[0], v[1], v[2]) <= 0, "%s: culled triangle %u faces a ray of list %d", s->name,
              t, l);
    }
}

/* ---- rays ----------------------------------------------------------------- */
static cbvh_ray make_ray(const cbvh_scene *s, const cbvh_bsh *h, const float lo[3], const float hi[3], int i) {
    cbvh_ray r;
    float o[3], d[3];
    float c[3], ext = 0;
    for (int a = 0; a < 3; a++) {
        c[a] = 0.5f * (lo[a] + hi[a]);
        if (hi[a] - lo[a] > ext) ext = hi[a] - lo[a];
    }
    if (ext <= 0) ext = 1;
    const cbvh_tri *t = &s->tris[rnd() % s->ntris];
    int kind = i % 8;
    switch (kind) {
    case 0: /* camera-like: from outside toward a point of the box */
    case 1:
        for (int a = 0; a < 3; a++) {
            o[a] = c[a] + (unit() * 4 - 2) * ext;
            d[a] = lo[a] + unit() * (hi[a] - lo[a]) - o[a];
        }
        break;
    case 2: /* random: origin in the box, direction uniform-ish */
        for (int a = 0; a < 3; a++) {
            o[a] = lo[a] + unit() * (hi[a] - lo[a]);
            d[a] = unit() * 2 - 1;
        }
        break;
    case 3: /* aimed at a vertex */
    {
        const float *v = t->v[rnd() % 3];
        for (int a = 0; a < 3; a++) {
            o[a] = c[a] + (unit() * 4 - 2) * ext;
            d[a] = v[a] - o[a];
        }
        break;
    }
    case 4: /* grazing: along an edge of a triangle, from before its start */
    {
        int k = (int)(rnd() % 3);
        const float *a0 = t->v[k], *a1 = t->v[(k + 1) % 3];
        for (int a = 0; a < 3; a++) {
            d[a] = a1[a] - a0[a];
            o[a] = a0[a] - d[a];
        }
        break;
    }
    case 5: /* inside: from the centre of a node's sphere */
    {
        uint32_t nd = (uint32_t)(rnd() % h->nnodes);
        for (int a = 0; a < 3; a++) {
            o[a] = bf(h->sphere[nd][a]);
            d[a] = unit() * 2 - 1;
        }
        break;
    }
    case 6: /* axis-parallel through a vertex or centroid */
    {
        for (int a = 0; a < 3; a++) o[a] = (rnd() & 1) ? t->v[0][a] : (t->v[0][a] + t->v[1][a] + t->v[2][a]) / 3;
        int ax = (int)(rnd() % 3);
        float back = (rnd() & 1) ? 1.0f : -1.0f;
        o[ax] -= back * 2 * ext;
        d[0] = d[1] = d[2] = 0;
        d[ax] = back;
        break;
    }
    default: /* in the plane of a triangle (edge-on), through its centroid */
    {
        float e1[3], e2[3];
        for (int a = 0; a < 3; a++) {
            e1[a] = t->v[1][a] - t->v[0][a];
            e2[a] = t->v[2][a] - t->v[0][a];
        }
        float w = unit();
        for (int a = 0; a < 3; a++) {
            d[a] = e1[a] + w * (e2[a] - e1[a]);
            o[a] = (t->v[0][a] + t->v[1][a] + t->v[2][a]) / 3 - 3 * d[a];
        }
        break;
    }
    }
    for (int a = 0; a < 3; a++) {
        r.o[a] = fb(o[a]);
        r.d[a] = fb(d[a]);
    }
    if (kind == 6) /* +0 / -0 on the two other axes */
        for (int a = 0; a < 3; a++)
            if (cbvh_f32_is_zero(r.d[a])) r.d[a] = (rnd() & 1) ? 0 : CBVH_F32_SIGN;
    if (cbvh_f32_is_zero(r.d[0]) && cbvh_f32_is_zero(r.d[1]) && cbvh_f32_is_zero(r.d[2])) r.d[0] = fb(1.0f);
    r.tmin = (i % 11 == 0) ? fb(0.5f * unit()) : 0;
    r.tmax = (i % 5 == 0) ? fb(0.3f + 2 * unit()) : CBVH_F32_POS_INF;
    return r;
}

#define NCFG 16
static long rays_compared, traversals;

static void compare_rays(const cbvh_scene *s, const cbvh_bvh *b, const cbvh_bsh *h, cbvh_tlists *L, int nrays) {
    float lo[3], hi[3];
    cbvh_scene_bounds(s, lo, hi);
    cbvh_trav_stats st = {0};
    for (int i = 0; i < nrays; i++) {
        cbvh_ray r = make_ray(s, h, lo, hi, i);
        cbvh_trav_hit ref[4], got;
        for (int m = 0; m < 4; m++)
            CHECK(cbvh_trace_bvh(b, s->tris, &r, 24, (cbvh_trav_mode)m, &ref[m], &st) == 0, "bvh ray %d", i);
        for (int c = 0; c < NCFG; c++) {
            if (((c / 4) & 1) != (i & 1)) continue; /* node order alternates per ray */
            int l = cbvh_tlist_pick(&L[c], &r);
            /* culled lists: one-sided modes; the others alternate two-sided / one-sided per ray pair */
            int m0 = (L[c].p.cull_back || ((i >> 1) & 1)) ? 2 : 0;
            for (int m = m0; m < m0 + 2; m++) {
                traversals++;
                cbvh_trav_stats one = {0};
                CHECK(cbvh_trace_tlist(&L[c], l, 0, s->tris, &r, (cbvh_trav_mode)m, &got, &one) == 0,
                      "tlist ray %d rejected", i);
                CHECK(one.max_stack == 0 && one.box_tests == one.nodes, "stats: stack %u, %llu tests for %llu nodes",
                      one.max_stack, (unsigned long long)one.box_tests, (unsigned long long)one.nodes);
                if (m & CBVH_TRAV_ANY) {
                    CHECK(got.hit == ref[m].hit, "%s lists=%d order=%d cull=%d ray %d mode %d: any-hit %d, bvh %d",
                          s->name, L[c].p.nlists, L[c].p.order, L[c].p.cull_back, i, m, got.hit, ref[m].hit);
                    if (got.hit) CHECK(cbvh_f32_key(got.t) >= cbvh_f32_key(ref[m & 2].t), "any-hit closer than closest");
                } else {
                    CHECK(same_hit(&got, &ref[m]),
                          "%s lists=%d order=%d cull=%d ray %d mode %d: tlist hit %d prim %u t %08x, bvh hit %d prim %u "
                          "t %08x",
                          s->name, L[c].p.nlists, L[c].p.order, L[c].p.cull_back, i, m, got.hit, got.prim, got.t,
                          ref[m].hit, ref[m].prim, ref[m].t);
                }
            }
        }
        rays_compared++;
    }
}

/* A list with one sphere shrunk to radius 0 must lose hits: the comparison
 * above would catch a non-conservative sphere. */
static void check_harness_fails(const cbvh_scene *s, const cbvh_bvh *b, const cbvh_bsh *h, cbvh_tlists *L) {
    cbvh_tlists *X = &L[0]; /* 1 list, earliest first, no culling */
    uint32_t victim = UINT32_MAX;
    for (uint32_t i = 1; i < X->len[0]; i++)
        if (X->list[0][i].escape >= 8) {
            victim = i;
            break;
        }
    if (victim == UINT32_MAX) return;
    uint32_t saved = X->list[0][victim].data[3];
    X->list[0][victim].data[3] = 0;
    float lo[3], hi[3];
    cbvh_scene_bounds(s, lo, hi);
    int diff = 0;
    cbvh_trav_stats st = {0};
    for (int i = 0; i < 4000 && !diff; i++) {
        cbvh_ray r = make_ray(s, h, lo, hi, i);
        cbvh_trav_hit a, c;
        cbvh_trace_bvh(b, s->tris, &r, 24, CBVH_TRAV_CLOSEST, &a, &st);
        cbvh_trace_tlist(X, 0, 0, s->tris, &r, CBVH_TRAV_CLOSEST, &c, &st);
        diff += !same_hit(&a, &c);
    }
    X->list[0][victim].data[3] = saved;
    CHECK(diff, "%s: a shrunken sphere went unnoticed", s->name);
}

static void run_scene(cbvh_scene *s, int nrays) {
    char err[256];
    cbvh_bvh b;
    cbvh_bsh h;
    CHECK(cbvh_build_sah(s, 0, 0, &b, err, sizeof err) == 0, "sah: %s", err);
    CHECK(cbvh_bsh_build(s, NULL, &h, err, sizeof err) == 0, "bsh: %s", err);
    CHECK(cbvh_bsh_check(&h, s, err, sizeof err) == 0, "%s: bsh check: %s", s->name, err);
    check_tight(&h, s);
    cbvh_tlists L[NCFG];
    static const int nl[4] = {1, 2, 6, 8};
    uint64_t culled[4] = {0};
    for (int c = 0; c < NCFG; c++) {
        cbvh_tlist_params p = {nl[c % 4], (cbvh_tlist_order)((c / 4) & 1), c >= 8};
        CHECK(cbvh_tlists_build(&h, s, &p, &L[c], err, sizeof err) == 0, "tlists: %s", err);
        uint64_t cu = 0;
        for (int l = 0; l < p.nlists; l++) check_list(&L[c], l, &h, s, &cu);
        if (p.cull_back && p.order == CBVH_TLIST_EARLIEST_FIRST) culled[c % 4] = cu;
        uint64_t elems = 0;
        for (int l = 0; l < p.nlists; l++) elems += L[c].len[l];
        CHECK(cbvh_tlists_bytes(&L[c]) == CBVH_TLIST_ELEM_BYTES * elems, "bytes");
        if (!p.cull_back) CHECK(elems == (uint64_t)p.nlists * (h.nnodes + s->ntris), "redundancy");
        if (p.cull_back) check_cull_rule(&L[c], s);
    }
    compare_rays(s, &b, &h, L, nrays);
    if (s->ntris > 1000) check_harness_fails(s, &b, &h, L); /* small ones: ties hide a lost triangle */
    printf("%-24s %7u tris  %6u spheres depth %2u  list 1: %u elems  culled per list: 1:%.2f%% 2:%.2f%% 6:%.2f%% "
           "8:%.2f%%  (%d rays)\n",
           s->name, s->ntris, h.nnodes, h.depth, L[0].len[0], 100.0 * culled[0] / s->ntris,
           100.0 * culled[1] / (2.0 * s->ntris), 100.0 * culled[2] / (6.0 * s->ntris),
           100.0 * culled[3] / (8.0 * s->ntris), nrays);
    for (int c = 0; c < NCFG; c++) cbvh_tlists_free(&L[c]);
    cbvh_bsh_free(&h);
    cbvh_bvh_free(&b);
}

/* ---- hand-made scenes ------------------------------------------------------ */
static void set_tri(cbvh_tri *t, float ax, float ay, float az, float bx, float by, float bz, float cx, float cy,
                    float cz) {
    float v[9] = {ax, ay, az, bx, by, bz, cx, cy, cz};
    memcpy(t->v, v, sizeof v);
}

/* Five triangles no octant split separates: none is "big" (twice its half
 * diagonal below the node's radius, 0.866), and every centroid lies in the
 * lower octant of the box [0, 1]^3 (three slivers each reach 1 on one axis
 * with their centroid exactly at 0.5, which is not above the centre).  The
 * builder must make them one leaf, though there are more than leaf_max. */
static void make_unsplittable(cbvh_scene *s) {
    memset(s, 0, sizeof *s);
    snprintf(s->name, sizeof s->name, "unsplittable");
    s->ntris = 5;
    s->tris = malloc(5 * sizeof *s->tris);
    set_tri(&s->tris[0], 0.25f, 0, 0, 0.25f, 0.01f, 0, 1, 0, 0);
    set_tri(&s->tris[1], 0, 0.25f, 0, 0.01f, 0.25f, 0, 0, 1, 0);
    set_tri(&s->tris[2], 0, 0, 0.25f, 0.01f, 0, 0.25f, 0, 0, 1);
    set_tri(&s->tris[3], 0, 0, 0, 0.01f, 0, 0, 0, 0.01f, 0);
    set_tri(&s->tris[4], 0, 0, 0.01f, 0.01f, 0, 0.01f, 0, 0.01f, 0.01f);
}

/* Random soup: mostly small triangles, some huge (stay at high nodes), some
 * degenerate (collinear, a point), duplicates (same t: index rule). */
static void make_soup(cbvh_scene *s, uint32_t n) {
    memset(s, 0, sizeof *s);
    snprintf(s->name, sizeof s->name, "soup");
    s->tris = malloc((size_t)n * sizeof *s->tris);
    s->ntris = n;
    for (uint32_t i = 0; i < n; i++) {
        cbvh_tri *t = &s->tris[i];
        float sz = (i % 37 == 0) ? 1.5f : 0.05f;
        float c[3] = {unit() * 2 - 1, unit() * 2 - 1, unit() * 2 - 1};
        for (int v = 0; v < 3; v++)
            for (int a = 0; a < 3; a++) t->v[v][a] = c[a] + sz * (unit() - 0.5f);
        if (i % 53 == 0) /* collinear */
            for (int a = 0; a < 3; a++) t->v[2][a] = 2 * t->v[1][a] - t->v[0][a];
        if (i % 97 == 0) /* a point */
            for (int v = 1; v < 3; v++) memcpy(t->v[v], t->v[0], sizeof t->v[0]);
        if (i % 29 == 0 && i > 0) s->tris[i] = s->tris[i - 1 - rnd() % i]; /* duplicate of an earlier one */
    }
}

/* Coplanar ties: a grid of small triangles at z = 0 and one big triangle in
 * the same plane, first (index 0) or last: equal t, the index decides. */
static void make_ties(cbvh_scene *s, int big_first) {
    const int g = 12;
    uint32_t n = (uint32_t)(2 * g * g + 1), k = 0;
    memset(s, 0, sizeof *s);
    snprintf(s->name, sizeof s->name, "ties-big-%s", big_first ? "first" : "last");
    s->tris = malloc((size_t)n * sizeof *s->tris);
    s->ntris = n;
    if (big_first) set_tri(&s->tris[k++], -1, -1, 0, 3, -1, 0, -1, 3, 0);
    for (int j = 0; j < g; j++)
        for (int i = 0; i < g; i++) {
            float x0 = -1 + 2.0f * i / g, x1 = -1 + 2.0f * (i + 1) / g, y0 = -1 + 2.0f * j / g, y1 = -1 + 2.0f * (j + 1) / g;
            set_tri(&s->tris[k++], x0, y0, 0, x1, y0, 0, x1, y1, 0);
            set_tri(&s->tris[k++], x0, y0, 0, x1, y1, 0, x0, y1, 0);
        }
    if (!big_first) set_tri(&s->tris[k++], -1, -1, 0, 3, -1, 0, -1, 3, 0);
}

/* Many triangles with one centroid (nothing separates them: a leaf of 40). */
static void make_same_centroid(cbvh_scene *s) {
    uint32_t n = 40;
    memset(s, 0, sizeof *s);
    snprintf(s->name, sizeof s->name, "same-centroid");
    s->tris = malloc((size_t)n * sizeof *s->tris);
    s->ntris = n;
    for (uint32_t i = 0; i < n; i++) { /* p, q, -(p + q): small integers, centroid exactly 0 */
        float px = (float)(i % 5) - 2, py = (float)(i % 7) - 3, qx = (float)(i % 3) - 1, qy = (float)(i % 4) + 1;
        set_tri(&s->tris[i], px, py, 1, qx, qy, -3, -(px + qx), -(py + qy), 2);
    }
}

static void bad_input(void) {
    char err[256];
    cbvh_scene s;
    memset(&s, 0, sizeof s);
    snprintf(s.name, sizeof s.name, "huge");
    s.tris = malloc(sizeof *s.tris);
    s.ntris = 1;
    set_tri(&s.tris[0], -3e38f, -3e38f, -3e38f, 3e38f, 3e38f, 3e38f, 3e38f, -3e38f, 3e38f);
    cbvh_bsh h;
    CHECK(cbvh_bsh_build(&s, NULL, &h, err, sizeof err) == -1 && strstr(err, "binary32"),
          "a radius past FLT_MAX must be refused (%s)", err);
    set_tri(&s.tris[0], 0, 0, 0, 1, 0, 0, 0, 1, 0);
    cbvh_bsh_params p;
    cbvh_bsh_default_params(&p);
    p.leaf_max = 0;
    CHECK(cbvh_bsh_build(&s, &p, &h, err, sizeof err) == -1 && strstr(err, "leaf_max"), "leaf_max 0 accepted");
    CHECK(cbvh_bsh_build(&s, NULL, &h, err, sizeof err) == 0, "one triangle: %s", err);
    cbvh_tlists L;
    cbvh_tlist_params tp = {3, CBVH_TLIST_EARLIEST_FIRST, 0};
    CHECK(cbvh_tlists_build(&h, &s, &tp, &L, err, sizeof err) == -1 && strstr(err, "1, 2, 6 or 8"), "3 lists accepted");
    tp.nlists = 6;
    tp.order = (cbvh_tlist_order)2;
    CHECK(cbvh_tlists_build(&h, &s, &tp, &L, err, sizeof err) == -1 && strstr(err, "unknown node order 2"),
          "node order 2 accepted");
    tp.order = CBVH_TLIST_EARLIEST_FIRST;
    /* a hierarchy built for another scene (here: one triangle more) */
    s.ntris = 2;
    CHECK(cbvh_tlists_build(&h, &s, &tp, &L, err, sizeof err) == -1 && strstr(err, "does not match the scene (1 "),
          "a hierarchy of 1 triangle accepted for 2");
    s.ntris = 1;
    tp.cull_back = 1;
    CHECK(cbvh_tlists_build(&h, &s, &tp, &L, err, sizeof err) == 0, "%s", err);
    /* the triangle's normal is +z: only the +z sextant never sees its front */
    for (int l = 0; l < 6; l++) CHECK((L.len[l] != 0) == (l != 4), "sextant %d has %u elements", l, L.len[l]);
    cbvh_ray r = {{fb(0.2f), fb(0.2f), fb(1)}, {0, 0, fb(-1)}, 0, CBVH_F32_POS_INF};
    cbvh_trav_hit hit;
    cbvh_trav_stats st = {0};
    CHECK(cbvh_tlist_pick(&L, &r) == 5, "pick -z");
    CHECK(cbvh_trace_tlist(&L, 5, 0, s.tris, &r, CBVH_TRAV_CLOSEST_FRONT, &hit, &st) == 0 && hit.hit && hit.prim == 0,
          "front hit");
    r.o[2] = fb(-1);
    r.d[2] = fb(1);
    CHECK(cbvh_trace_tlist(&L, 4, 0, s.tris, &r, CBVH_TRAV_CLOSEST_FRONT, &hit, &st) == 0 && !hit.hit,
          "empty list: miss");
    CHECK(cbvh_trace_tlist(&L, 6, 0, s.tris, &r, CBVH_TRAV_CLOSEST, &hit, &st) == -1, "list 6 of 6 accepted");
    CHECK(cbvh_trace_tlist(&L, 5, L.len[5] + 1, s.tris, &r, CBVH_TRAV_CLOSEST, &hit, &st) == -1, "head past the end");
    r.d[2] = 0x7FC00000u;
    CHECK(cbvh_trace_tlist(&L, 5, 0, s.tris, &r, CBVH_TRAV_CLOSEST, &hit, &st) == -1, "NaN ray accepted");
    cbvh_tlists_free(&L);
    cbvh_bsh_free(&h);
    cbvh_scene_free(&s);
}

/* The pick rule on exact bit patterns. */
static void check_pick(void) {
    cbvh_tlists L;
    memset(&L, 0, sizeof L);
    cbvh_ray r;
    memset(&r, 0, sizeof r);
    L.p.nlists = 6;
    r.d[0] = fb(1);
    r.d[1] = fb(-1);
    r.d[2] = fb(0.5f);
    CHECK(cbvh_tlist_pick(&L, &r) == 0, "sextant tie x/y -> +x");
    r.d[0] = fb(-0.5f);
    CHECK(cbvh_tlist_pick(&L, &r) == 3, "-y");
    r.d[2] = fb(-1);
    CHECK(cbvh_tlist_pick(&L, &r) == 3, "tie y/z -> y");
    r.d[2] = fb(-2);
    CHECK(cbvh_tlist_pick(&L, &r) == 5, "-z");
    L.p.nlists = 8;
    r.d[0] = CBVH_F32_SIGN;
    r.d[1] = 0;
    r.d[2] = fb(1);
    CHECK(cbvh_tlist_pick(&L, &r) == 1, "octant: -0 counts as negative");
    L.p.nlists = 2;
    CHECK(cbvh_tlist_pick(&L, &r) == 1, "2 lists: -0 is -x");
    L.p.nlists = 1;
    CHECK(cbvh_tlist_pick(&L, &r) == 0, "1 list");
}

int main(void) {
#ifdef CBVH_SANITIZE
    int n = 1500;
#else
    int n = 9000;
#endif
    check_pick();
    bad_input();
    const char *specs[] = {CBVH_SCENES_DIR "/bunny-small.obj", "proc:cloth:40", "proc:far", "proc:wave:24",
                           "proc:instanced:2"};
    for (size_t k = 0; k < sizeof specs / sizeof *specs; k++) {
        cbvh_scene s;
        char err[256];
        if (cbvh_scene_open(specs[k], &s, err, sizeof err)) {
            CHECK(0, "%s: %s", specs[k], err);
            continue;
        }
        run_scene(&s, k == 0 ? 4 * n : n);
        cbvh_scene_free(&s);
    }
    cbvh_scene s;
    make_soup(&s, 3000);
    run_scene(&s, 2 * n);
    cbvh_scene_free(&s);
    for (int bf1 = 0; bf1 < 2; bf1++) {
        make_ties(&s, bf1);
        run_scene(&s, n / 2);
        cbvh_scene_free(&s);
    }
    make_same_centroid(&s);
    run_scene(&s, n / 4);
    cbvh_scene_free(&s);
    make_unsplittable(&s);
    {
        cbvh_bsh h;
        char err[256];
        CHECK(cbvh_bsh_build(&s, NULL, &h, err, sizeof err) == 0 && cbvh_bsh_check(&h, &s, err, sizeof err) == 0,
              "unsplittable: %s", err);
        CHECK(h.nnodes == 1 && h.ntri[0] == 5 && h.nchild[0] == 0, "unsplittable: %u nodes, root holds %u triangles",
              h.nnodes, h.ntri[0]);
        cbvh_bsh_free(&h);
    }
    run_scene(&s, n / 8);
    cbvh_scene_free(&s);
    printf("%ld rays, %ld list traversals compared with the float BVH\n", rays_compared, traversals);
    printf("%s (%ld failures)\n", fails ? "FAILED" : "ok", fails);
    return fails ? 1 : 0;
}
