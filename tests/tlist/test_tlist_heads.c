/* List heads (docs/tlist.md §7).
 *
 * Per-polygon heads: secondary rays made exactly as host/trace/effects.c makes them
 * (front hit of a one-sided camera/random ray, hit point fl(o + t d), origin
 * offset by eps along the unit normal, directions in the front hemisphere,
 * mirror directions, shadow rays to points with bounded tmax), started at
 * cbvh_tlist_poly_head with the margin of cbvh_tlist_hitpoint_margin: hits
 * equal the traversal from element 0 and the float BVH (closest and any,
 * one- and two-sided), for simple and regular heads, all list counts, both
 * orders, with and without culling; and the whole class of rays the heads
 * promise to serve (docs/tlist.md §7.1) at its boundary, with a wide margin:
 * origins up to 0.9 margin from the triangle on either side, tangent
 * directions (heads computed with margin 0 fail on these rays).
 * Per-screen-cell heads: every pixel ray of
 * a pinhole camera, started at its cell's head, hits what it hits from 0.
 * Both must be able to fail: a head one element past the reference hit's
 * element (a deliberately too-far head) is caught.  Also printed: how much
 * work the heads skip (sphere elements visited per ray, from 0 vs from the
 * head). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/tlist.h"
#include "scene/scene_load.h"
#include "test_trav_util.h"

static long fails;
#define CHECK(c, ...) TU_CHECK(fails, stdout, c, __VA_ARGS__)

static uint64_t rs = 0x13198A2E03707344ull;
static uint64_t rnd(void) { return tu_xorshift64(&rs); }
static float unit(void) { return tu_unit_f(&rs); }

static cbvh_ray mk(const float o[3], const float d[3], float tmax) {
    cbvh_ray r;
    for (int a = 0; a < 3; a++) {
        r.o[a] = fb(o[a]);
        r.d[a] = fb(d[a]);
    }
    r.tmin = 0;
    r.tmax = isinf(tmax) ? CBVH_F32_POS_INF : fb(tmax);
    return r;
}

/* Element index of triangle `prim` in list l (for the too-far head). */
static uint32_t elem_of(const cbvh_tlists *L, int l, uint32_t prim) {
    for (uint32_t i = 0; i < L->len[l]; i++)
        if ((L->list[l][i].escape == 1 || L->list[l][i].escape == 0) && L->list[l][i].data[0] == prim) return i;
    return UINT32_MAX;
}

typedef struct {
    long rays, with_head, caught, bad_tried;
    uint64_t nodes0, nodesh, elems0, elemsh;
} tally;

/* Trace r from 0, from head h, and the float BVH, in every mode. */
static void compare(const cbvh_scene *s, const cbvh_bvh *b, const cbvh_tlists *L, int l, uint32_t h,
                    const cbvh_ray *r, tally *T, const char *what) {
    for (int m = 0; m < 4; m++) {
        if (L->p.cull_back && !(m & CBVH_TRAV_FRONT_ONLY)) continue;
        cbvh_trav_hit ref, h0, hh;
        cbvh_trav_stats sb = {0}, s0 = {0}, sh = {0};
        CHECK(cbvh_trace_bvh(b, s->tris, r, 24, (cbvh_trav_mode)m, &ref, &sb) == 0, "bvh");
        CHECK(cbvh_trace_tlist(L, l, 0, s->tris, r, (cbvh_trav_mode)m, &h0, &s0) == 0, "tlist 0");
        CHECK(cbvh_trace_tlist(L, l, h, s->tris, r, (cbvh_trav_mode)m, &hh, &sh) == 0, "tlist head");
        if (m & CBVH_TRAV_ANY) {
            CHECK(hh.hit == ref.hit && h0.hit == ref.hit, "%s %s lists=%d order=%d cull=%d list %d head %u mode %d: any %d/%d, bvh %d",
                  s->name, what, L->p.nlists, L->p.order, L->p.cull_back, l, h, m, h0.hit, hh.hit, ref.hit);
        } else {
            CHECK(same_hit(&hh, &ref) && same_hit(&h0, &ref),
                  "%s %s lists=%d order=%d cull=%d list %d head %u mode %d: from head hit %d prim %u t %08x, bvh hit "
                  "%d prim %u t %08x",
                  s->name, what, L->p.nlists, L->p.order, L->p.cull_back, l, h, m, hh.hit, hh.prim, hh.t, ref.hit,
                  ref.prim, ref.t);
            if (m == CBVH_TRAV_CLOSEST_FRONT || (m == CBVH_TRAV_CLOSEST && !L->p.cull_back)) {
                T->nodes0 += s0.nodes;
                T->nodesh += sh.nodes;
                T->elems0 += s0.nodes + s0.tri_tests;
                T->elemsh += sh.nodes + sh.tri_tests;
            }
            /* a head one past the hit triangle's element must be caught */
            if (ref.hit && m == (L->p.cull_back ? CBVH_TRAV_CLOSEST_FRONT : CBVH_TRAV_CLOSEST)) {
                uint32_t e = elem_of(L, l, ref.prim);
                if (e != UINT32_MAX) {
                    cbvh_trav_hit hb;
                    cbvh_trav_stats sx = {0};
                    cbvh_trace_tlist(L, l, e + 1, s->tris, r, (cbvh_trav_mode)m, &hb, &sx);
                    T->caught += !same_hit(&hb, &ref);
                    T->bad_tried++;
                }
            }
        }
    }
    T->rays++;
    T->with_head += h != 0;
}

static float coord_max(const cbvh_scene *s) {
    float m = 0;
    for (uint32_t t = 0; t < s->ntris; t++)
        for (int v = 0; v < 3; v++)
            for (int a = 0; a < 3; a++) m = fmaxf(m, fabsf(s->tris[t].v[v][a]));
    return m;
}

/* Camera or random incoming ray; on a front hit, secondary rays as in
 * host/trace/effects.c (shade: q = p + eps * n). */
static void poly_rays(const cbvh_scene *s, const cbvh_bvh *b, const cbvh_tlists *L, int nrays, float eps, tally *T) {
    float lo[3], hi[3], c[3], ext = 0;
    cbvh_scene_bounds(s, lo, hi);
    for (int a = 0; a < 3; a++) {
        c[a] = 0.5f * (lo[a] + hi[a]);
        ext = fmaxf(ext, hi[a] - lo[a]);
    }
    for (int i = 0; i < nrays; i++) {
        float o[3], d[3];
        for (int a = 0; a < 3; a++) {
            o[a] = (i & 1) ? c[a] + (unit() * 4 - 2) * ext : lo[a] + unit() * (hi[a] - lo[a]);
            d[a] = (i & 1) ? lo[a] + unit() * (hi[a] - lo[a]) - o[a] : unit() * 2 - 1;
        }
        cbvh_ray in = mk(o, d, INFINITY);
        cbvh_trav_hit h;
        cbvh_trav_stats st = {0};
        if (cbvh_trace_bvh(b, s->tris, &in, 24, CBVH_TRAV_CLOSEST_FRONT, &h, &st) || !h.hit) continue;
        const cbvh_tri *tr = &s->tris[h.prim];
        float t = bf(h.t), p[3], n[3], e1[3], e2[3], q[3];
        for (int a = 0; a < 3; a++) {
            p[a] = o[a] + t * d[a];
            e1[a] = tr->v[1][a] - tr->v[0][a];
            e2[a] = tr->v[2][a] - tr->v[0][a];
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        float nl = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(nl > 0)) continue;
        for (int a = 0; a < 3; a++) n[a] /= nl;
        if (n[0] * d[0] + n[1] * d[1] + n[2] * d[2] > 0)
            for (int a = 0; a < 3; a++) n[a] = -n[a];
        for (int a = 0; a < 3; a++) q[a] = p[a] + eps * n[a];
        for (int k = 0; k < 4; k++) {
            float w[3], tmax = INFINITY;
            if (k == 0) { /* mirror */
                float dn = 2 * (d[0] * n[0] + d[1] * n[1] + d[2] * n[2]);
                for (int a = 0; a < 3; a++) w[a] = d[a] - dn * n[a];
            } else if (k == 3) { /* shadow ray to a point of the box */
                for (int a = 0; a < 3; a++) w[a] = lo[a] + unit() * (hi[a] - lo[a]) - q[a];
                tmax = 0.9999f;
            } else { /* hemisphere; k == 2: nearly tangent */
                for (int a = 0; a < 3; a++) w[a] = unit() * 2 - 1;
                float dn = w[0] * n[0] + w[1] * n[1] + w[2] * n[2];
                if (k == 2)
                    for (int a = 0; a < 3; a++) w[a] -= dn * n[a] * (1 - 1e-3f);
                else if (dn < 0)
                    for (int a = 0; a < 3; a++) w[a] = -w[a];
            }
            if (w[0] == 0 && w[1] == 0 && w[2] == 0) continue;
            cbvh_ray r = mk(q, w, tmax);
            int l = cbvh_tlist_pick(L, &r);
            uint32_t head = cbvh_tlist_poly_head(L, l, h.prim, s->tris, &r);
            compare(s, b, L, l, head, &r, T, "secondary");
        }
    }
}

/* The whole class of docs/tlist.md §7.1 at its boundary: origins anywhere
 * within 0.9 margin of the triangle (also behind its plane), directions with
 * d . n >= 0 incl. tangent ones (edge directions), any list, bounded or not. */
static void class_rays(const cbvh_scene *s, const cbvh_bvh *b, const cbvh_tlists *L, int nrays, float margin,
                       tally *T) {
    for (int i = 0; i < nrays; i++) {
        uint32_t t = (uint32_t)(rnd() % s->ntris);
        const cbvh_tri *tr = &s->tris[t];
        double u = unit(), v = unit();
        if (u + v > 1) u = 1 - u, v = 1 - v;
        float o[3], d[3], w[3];
        double len = 0;
        for (int a = 0; a < 3; a++) {
            w[a] = unit() * 2 - 1;
            len += (double)w[a] * w[a];
        }
        double off = 0.9 * margin * unit() / (sqrt(len) + 1e-30);
        if (i % 4 == 0) off = 0; /* exactly from the triangle (rounded) */
        for (int a = 0; a < 3; a++)
            o[a] = (float)((1 - u - v) * tr->v[0][a] + u * tr->v[1][a] + v * tr->v[2][a] + off * w[a]);
        int k = (int)(rnd() % 3);
        for (int a = 0; a < 3; a++) {
            if (i % 3 == 0) d[a] = tr->v[(k + 1) % 3][a] - tr->v[k][a]; /* along an edge: tangent */
            else d[a] = unit() * 2 - 1;
        }
        if (d[0] == 0 && d[1] == 0 && d[2] == 0) continue;
        cbvh_ray r = mk(o, d, (i % 5 == 0) ? 0.5f * unit() : INFINITY);
        cbvh_f32 vv[3][3];
        for (int q = 0; q < 3; q++)
            for (int a = 0; a < 3; a++) vv[q][a] = fb(tr->v[q][a]);
        if (cbvh_tri_facing(r.d, vv[0], vv[1], vv[2]) > 0 && i % 3 != 0)
            for (int a = 0; a < 3; a++) r.d[a] ^= CBVH_F32_SIGN; /* leave on the front side */
        int l = cbvh_tlist_pick(L, &r);
        uint32_t head = cbvh_tlist_poly_head(L, l, t, s->tris, &r);
        compare(s, b, L, l, head, &r, T, "class");
    }
}

/* Pinhole camera, W x W pixels in cells of C x C; corner directions of a cell
 * at the pixel corners, computed like the pixel directions. */
/* Where a head may point (docs/tlist.md §7): at 0, or at an element whose
 * predecessor is not a sphere (escape 0 or 1) -- a head backs up over the
 * spheres whose first child it is, since they may still cull.  Also within
 * the list. */
static int head_ok(const cbvh_tlists *L, int l, uint32_t h) {
    if (h > L->len[l]) return 0;
    return h == 0 || h == L->len[l] || (L->list[l][h - 1].escape == 0 || L->list[l][h - 1].escape == 1);
}

static void cell_rays(const cbvh_scene *s, const cbvh_bvh *b, const cbvh_tlists *L, int W, int C, tally *T) {
    float lo[3], hi[3], c[3], ext = 0;
    cbvh_scene_bounds(s, lo, hi);
    for (int a = 0; a < 3; a++) {
        c[a] = 0.5f * (lo[a] + hi[a]);
        ext = fmaxf(ext, hi[a] - lo[a]);
    }
    float eye[3] = {c[0] + 0.3f * ext, c[1] + 0.4f * ext, c[2] + 1.6f * ext}, w[3], len = 0;
    for (int a = 0; a < 3; a++) w[a] = c[a] - eye[a], len += w[a] * w[a];
    len = sqrtf(len);
    for (int a = 0; a < 3; a++) w[a] /= len;
    float u[3] = {w[2], 0, -w[0]}, ul = sqrtf(u[0] * u[0] + u[2] * u[2]);
    for (int a = 0; a < 3; a++) u[a] /= ul;
    float v[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
#define PIXDIR(out, X, Y)                                                            \
    do {                                                                             \
        float px_ = (float)(X) / (float)W * 2 - 1, py_ = (float)(Y) / (float)W * 2 - 1; \
        for (int a_ = 0; a_ < 3; a_++) (out)[a_] = w[a_] + 0.45f * (px_ * u[a_] + py_ * v[a_]); \
    } while (0)
    for (int cy = 0; cy < W; cy += C)
        for (int cx = 0; cx < W; cx += C) {
            float cor[4][3];
            PIXDIR(cor[0], cx, cy);
            PIXDIR(cor[1], cx + C, cy);
            PIXDIR(cor[2], cx + C, cy + C);
            PIXDIR(cor[3], cx, cy + C);
            uint32_t head[CBVH_TLIST_MAX];
            CHECK(cbvh_tlist_cell_heads(L, s->tris, eye, cor, 1e-5, head) == 0, "cell heads");
            for (int l = 0; l < L->p.nlists; l++)
                CHECK(head_ok(L, l, head[l]), "cell (%d, %d) list %d: head %u stops right after a sphere", cx, cy, l,
                      head[l]);
            for (int y = cy; y < cy + C; y++)
                for (int x = cx; x < cx + C; x++) {
                    float d[3];
                    PIXDIR(d, x + 0.5f, y + 0.5f);
                    if (x == cx && y == cy) PIXDIR(d, x, y); /* a ray exactly on the cell's corner */
                    cbvh_ray r = mk(eye, d, INFINITY);
                    int l = cbvh_tlist_pick(L, &r);
                    compare(s, b, L, l, head[l], &r, T, "primary");
                }
        }
#undef PIXDIR
}

static void check_poly_heads(const cbvh_tlists *L, const char *name) {
    long bad = 0, past0 = 0;
    for (uint32_t t = 0; t < L->ntris; t++)
        for (int l = 0; l < L->p.nlists; l++) {
            uint32_t h = L->poly_head[(size_t)t * (size_t)L->p.nlists + (size_t)l];
            bad += !head_ok(L, l, h);
            past0 += h != 0;
        }
    CHECK(bad == 0, "%s: %ld per-polygon heads stop right after a sphere", name, bad);
    CHECK(past0 > 0, "%s: no per-polygon head past element 0 (the rule was not exercised)", name);
}

static void run_scene(const char *spec, int nrays, int W) {
    cbvh_scene s;
    char err[256];
    if (cbvh_scene_open(spec, &s, err, sizeof err)) {
        CHECK(0, "%s: %s", spec, err);
        return;
    }
    cbvh_bvh b;
    cbvh_bsh h;
    CHECK(cbvh_build_sah(&s, 0, 0, &b, err, sizeof err) == 0, "sah: %s", err);
    CHECK(cbvh_bsh_build(&s, NULL, &h, err, sizeof err) == 0, "bsh: %s", err);
    float lo[3], hi[3];
    cbvh_scene_bounds(&s, lo, hi);
    float dg[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
    float eps = 1e-4f * sqrtf(dg[0] * dg[0] + dg[1] * dg[1] + dg[2] * dg[2]); /* host/trace/effects.c */
    /* origins of incoming rays reach 2 extents beyond the centre: include them */
    float cm = coord_max(&s) + 3 * sqrtf(dg[0] * dg[0] + dg[1] * dg[1] + dg[2] * dg[2]);
    float margin = cbvh_tlist_hitpoint_margin(eps, cm);
    static const int nl[4] = {1, 2, 6, 8};
    for (int c = 0; c < 16; c++) {
        cbvh_tlist_params p = {nl[c % 4], (cbvh_tlist_order)((c / 4) & 1), c >= 8};
        cbvh_tlists L;
        CHECK(cbvh_tlists_build(&h, &s, &p, &L, err, sizeof err) == 0, "tlists: %s", err);
        for (int kind = CBVH_TLIST_HEADS_SIMPLE; kind <= CBVH_TLIST_HEADS_REGULAR; kind++) {
            CHECK(cbvh_tlists_poly_heads(&L, s.tris, (cbvh_tlist_heads_kind)kind, margin, err, sizeof err) == 0, "%s",
                  err);
            check_poly_heads(&L, s.name);
            CHECK(cbvh_tlists_bytes(&L) > (uint64_t)L.ntris * p.nlists * 4u, "bytes count the heads");
            tally T = {0};
            poly_rays(&s, &b, &L, nrays / 16, eps, &T);
            CHECK(T.bad_tried == 0 || T.caught > 0, "%s: no too-far head caught", s.name);
            /* a wide margin (2 % of the diagonal): the origin may be well behind the plane */
            float wide = 0.02f * sqrtf(dg[0] * dg[0] + dg[1] * dg[1] + dg[2] * dg[2]);
            tally W2 = {0};
            CHECK(cbvh_tlists_poly_heads(&L, s.tris, (cbvh_tlist_heads_kind)kind, wide, err, sizeof err) == 0, "%s", err);
            class_rays(&s, &b, &L, nrays / 32, wide, &W2);
            if (c % 4 == 2 && c < 8)
                printf("%-18s lists=%d order=%d cull=%d %-7s heads, margin %.3g: %5ld class rays, %4.1f%% start past 0, "
                       "spheres visited %.2f -> %.2f\n",
                       s.name, p.nlists, p.order, p.cull_back, kind == 1 ? "simple" : "regular", (double)wide, W2.rays,
                       100.0 * W2.with_head / (W2.rays ? W2.rays : 1), (double)W2.nodes0 / (W2.rays ? W2.rays : 1),
                       (double)W2.nodesh / (W2.rays ? W2.rays : 1));
            CHECK(cbvh_tlists_poly_heads(&L, s.tris, (cbvh_tlist_heads_kind)kind, margin, err, sizeof err) == 0, "%s", err);
            if (c % 4 == 2 && c < 8)
                printf("%-18s lists=%d order=%d cull=%d %-7s heads: %5ld secondary rays, %4.1f%% start past 0, spheres "
                       "visited %.2f -> %.2f per ray; too-far head caught %ld/%ld\n",
                       s.name, p.nlists, p.order, p.cull_back, kind == 1 ? "simple" : "regular", T.rays,
                       100.0 * T.with_head / (T.rays ? T.rays : 1), (double)T.nodes0 / (T.rays ? T.rays : 1),
                       (double)T.nodesh / (T.rays ? T.rays : 1), T.caught, T.bad_tried);
        }
        tally T = {0};
        cell_rays(&s, &b, &L, W, 8, &T);
        CHECK(T.bad_tried == 0 || T.caught > 0, "%s: no too-far cell head caught", s.name);
        if (c % 4 == 2 && c < 8)
            printf("%-18s lists=%d order=%d cull=%d cell heads: %5ld primary rays, %4.1f%% start past 0, elements "
                   "visited %.2f -> %.2f per ray; too-far head caught %ld/%ld\n",
                   s.name, p.nlists, p.order, p.cull_back, T.rays, 100.0 * T.with_head / (T.rays ? T.rays : 1),
                   (double)T.elems0 / (T.rays ? T.rays : 1), (double)T.elemsh / (T.rays ? T.rays : 1), T.caught,
                   T.bad_tried);
        cbvh_tlists_free(&L);
    }
    cbvh_bsh_free(&h);
    cbvh_bvh_free(&b);
    cbvh_scene_free(&s);
}

/* The plane half-space of a simple head, on its own: triangle A in z = 0
 * facing +z, triangle B a whole unit below it, nothing else.  A ray leaving
 * A's front toward +z cannot reach B, so A's head in the +z list must start
 * past B's element (which the list orders first). */
static void plane_skips(void) {
    cbvh_scene s;
    memset(&s, 0, sizeof s);
    s.ntris = 2;
    s.tris = calloc(2, sizeof *s.tris);
    cbvh_tri a = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}}, b = {{{0, 0, -1}, {1, 0, -1}, {0, 1, -1}}};
    s.tris[0] = a;
    s.tris[1] = b;
    char err[256];
    cbvh_bsh h;
    cbvh_tlists L;
    cbvh_tlist_params p = {6, CBVH_TLIST_EARLIEST_FIRST, 0};
    CHECK(cbvh_bsh_build(&s, NULL, &h, err, sizeof err) == 0 && cbvh_tlists_build(&h, &s, &p, &L, err, sizeof err) == 0,
          "%s", err);
    CHECK(cbvh_tlists_poly_heads(&L, s.tris, CBVH_TLIST_HEADS_SIMPLE, 0.01f, err, sizeof err) == 0, "%s", err);
    const float o[3] = {0.25f, 0.25f, 0.0f}, d[3] = {0, 0, 1};
    cbvh_ray r = mk(o, d, INFINITY);
    int l = cbvh_tlist_pick(&L, &r);
    uint32_t eb = elem_of(&L, l, 1), head = L.poly_head[0 * 6 + (uint32_t)l];
    CHECK(eb != UINT32_MAX && eb < elem_of(&L, l, 0), "list %d: B (element %u) is not before A", l, eb);
    CHECK(head > eb, "list %d: A's head %u does not skip B (element %u) behind A's plane", l, head, eb);
    cbvh_tlists_free(&L);
    cbvh_bsh_free(&h);
    cbvh_scene_free(&s);
}

static void bad_input(void) {
    cbvh_scene s;
    char err[256];
    CHECK(cbvh_scene_open("proc:wave:4", &s, err, sizeof err) == 0, "%s", err);
    cbvh_bsh h;
    cbvh_tlists L;
    cbvh_tlist_params p = {6, CBVH_TLIST_EARLIEST_FIRST, 0};
    CHECK(cbvh_bsh_build(&s, NULL, &h, err, sizeof err) == 0 && cbvh_tlists_build(&h, &s, &p, &L, err, sizeof err) == 0,
          "%s", err);
    CHECK(cbvh_tlists_poly_heads(&L, s.tris, (cbvh_tlist_heads_kind)3, 0, err, sizeof err) == -1, "kind 3 accepted");
    CHECK(cbvh_tlists_poly_heads(&L, s.tris, CBVH_TLIST_HEADS_SIMPLE, -1, err, sizeof err) == -1, "margin -1 accepted");
    CHECK(cbvh_tlists_poly_heads(&L, s.tris, CBVH_TLIST_HEADS_SIMPLE, NAN, err, sizeof err) == -1, "NaN margin");
    float o[3] = {0, 0, 5}, cor[4][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}};
    uint32_t head[CBVH_TLIST_MAX];
    CHECK(cbvh_tlist_cell_heads(&L, s.tris, o, cor, 0, head) == -1, "tol 0 accepted");
    cor[2][1] = INFINITY;
    CHECK(cbvh_tlist_cell_heads(&L, s.tris, o, cor, 1e-5, head) == -1, "Inf corner accepted");
    /* a cell looking away from the scene: nothing needed */
    float away[4][3] = {{-0.1f, -0.1f, 1}, {0.1f, -0.1f, 1}, {0.1f, 0.1f, 1}, {-0.1f, 0.1f, 1}};
    CHECK(cbvh_tlist_cell_heads(&L, s.tris, o, away, 1e-5, head) == 0, "away");
    for (int l = 0; l < 6; l++) CHECK(head[l] == L.len[l], "list %d: head %u of %u for a cell that sees nothing", l, head[l], L.len[l]);
    /* a ray leaving on the back side gets head 0 */
    CHECK(cbvh_tlists_poly_heads(&L, s.tris, CBVH_TLIST_HEADS_REGULAR, 0, err, sizeof err) == 0, "%s", err);
    cbvh_ray r = {{0, 0, 0}, {0, 0, fb(1)}, 0, CBVH_F32_POS_INF};
    cbvh_f32 v[3][3];
    for (int k = 0; k < 3; k++)
        for (int a = 0; a < 3; a++) v[k][a] = fb(s.tris[0].v[k][a]);
    int f = cbvh_tri_facing(r.d, v[0], v[1], v[2]);
    if (f > 0) CHECK(cbvh_tlist_poly_head(&L, 4, 0, s.tris, &r) == 0, "back-side ray got a head");
    r.d[2] = fb(-1);
    if (-f > 0) CHECK(cbvh_tlist_poly_head(&L, 5, 0, s.tris, &r) == 0, "back-side ray got a head");
    cbvh_tlists_free(&L);
    cbvh_bsh_free(&h);
    cbvh_scene_free(&s);
}

int main(void) {
#ifdef CBVH_SANITIZE
    int n = 1000, W = 32;
#else
    int n = 8000, W = 64;
#endif
    bad_input();
    plane_skips();
    run_scene(CBVH_SCENES_DIR "/bunny-small.obj", 2 * n, W);
    run_scene("proc:cloth:32", n, W / 2);
    run_scene("proc:far", n, W / 2);
    run_scene("proc:instanced:1", n / 2, W / 2);
    printf("%s (%ld failures)\n", fails ? "FAILED" : "ok", fails);
    return fails ? 1 : 0;
}
