/* A wider plain floating-point reference (issue 4, results.md "Embree on the
 * same instruction set as ours"): how much of the distance to Embree is the
 * tree's width.  On the same rays, closest hit, one core:
 *   - Embree 3 rtcIntersect1 (if built with it; --embree-isa as bench_traverse),
 *   - the plain floating-point traversal of the binary SAH tree
 *     (cbvh_trace_bvh_float, the benchmark's reference),
 *   - a plain 4-wide traversal of the QBVH collapse of the same tree
 *     (cbvh_qbvh_from_bvh): 128-byte records with the four children's boxes,
 *     the same conservative binary64 slab test per child (ray_box_ref.h), the
 *     hit children sorted by entry t and the nearest visited without a push,
 *   - the same with the four box tests in SSE2 (two binary64 lanes per
 *     register, the margins unchanged; x86-64 only).
 * Triangles go through the ray-triangle unit in all three of ours, so their
 * hits are the units' hits: every ray's hit (triangle, t, b1, b2), and that of
 * the same ray with one direction component zeroed, is compared with the
 * binary traversal's, and any difference exits 1.  This is a
 * measurement, not a tracer the kit uses: the sweep, the charts and every
 * counter stay on the binary trees.
 *
 * usage: bench_wide [--rays R] [--seed S] [--reps K] [--embree-isa ISA] [--embree-robust] [SCENE...]
 *   as bench_traverse; default 20000 rays (half camera, half random), 7 reps. */
#define _POSIX_C_SOURCE 200809L
#include "cbvh/qbvh.h"
#define BENCH_NAME "bench_wide"
#include "bench_rays.h"
#include "ray_box_ref.h"
#include "traverse_common.h"

#ifdef CBVH_HAVE_EMBREE
#include "bench_embree.h"
#endif
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#ifndef CBVH_SCENES_DIR
#define CBVH_SCENES_DIR "scenes"
#endif

#define NO_CHILD 0xFFFFFFFFu

/* One inner QBVH node: plane (lo, hi) x axis x child, then the children's
 * entries (a record index, or CBVH_FBVH_LEAF | first with its count). */
typedef struct {
    float b[2][3][4];
    uint32_t child[4], count[4];
} rec4;
_Static_assert(sizeof(rec4) == 128, "two 64-byte lines per record");

typedef struct {
    rec4 *r;
    const cbvh_qbvh *q;
    uint32_t root, root_count; /* entry of the root */
} wide_tree;

static void wide_build(const cbvh_qbvh *q, wide_tree *w) {
    uint32_t *rec = malloc((size_t)q->nnodes * sizeof *rec), n = 0;
    w->r = aligned_alloc(64, ((size_t)q->nnodes * sizeof(rec4) + 63) / 64 * 64);
    if (!rec || !w->r) die("4-wide layout", "out of memory");
    for (uint32_t i = 0; i < q->nnodes; i++) rec[i] = (q->count[i] & CBVH_QBVH_LEAF) ? NO_CHILD : n++;
    for (uint32_t i = 0; i < q->nnodes; i++) {
        if (q->count[i] & CBVH_QBVH_LEAF) continue;
        rec4 *r = &w->r[rec[i]];
        for (uint32_t c = 0; c < 4; c++) {
            if (c >= q->count[i]) { /* no child: an inverted box, never hit */
                for (int a = 0; a < 3; a++) r->b[0][a][c] = 1, r->b[1][a][c] = 0;
                r->child[c] = NO_CHILD, r->count[c] = 0;
                continue;
            }
            uint32_t k = q->first[i] + c;
            for (int a = 0; a < 3; a++) r->b[0][a][c] = q->bmin[k][a], r->b[1][a][c] = q->bmax[k][a];
            int leaf = (q->count[k] & CBVH_QBVH_LEAF) != 0;
            r->child[c] = leaf ? CBVH_FBVH_LEAF | q->first[k] : rec[k];
            r->count[c] = leaf ? q->count[k] & ~CBVH_QBVH_LEAF : 0;
        }
    }
    int leaf_root = (q->count[0] & CBVH_QBVH_LEAF) != 0;
    w->root = leaf_root ? CBVH_FBVH_LEAF | q->first[0] : rec[0];
    w->root_count = leaf_root ? q->count[0] & ~CBVH_QBVH_LEAF : 0;
    w->q = q;
    free(rec);
}

/* The four boxes of a record against [tmin, cull] for rays without zero
 * direction components and tmin >= 0 (!r->general): the bit mask of children
 * the ray may meet, and lower bounds of their entry t (cbvh_ref_box2's
 * margins, per child, four at a time). */
static unsigned box4(const cbvh_ref_ray *r, const rec4 *n, double cull, double tl[4]) {
    double nn[4], ff[4];
    for (int c = 0; c < 4; c++) nn[c] = r->tmin, ff[c] = cull;
    for (int a = 0; a < 3; a++) {
        int neg = r->inv[a] < 0;
        const float *pn = n->b[neg][a], *pf = n->b[!neg][a];
        double o = r->o[a], inv = r->inv[a];
        for (int c = 0; c < 4; c++) {
            double tn = ((double)pn[c] - o) * inv, tf = ((double)pf[c] - o) * inv;
            nn[c] = tn > nn[c] ? tn : nn[c];
            ff[c] = tf < ff[c] ? tf : ff[c];
        }
    }
    unsigned m = 0;
    for (int c = 0; c < 4; c++) {
        tl[c] = nn[c] * (1 - CBVH_REF_EPS);
        m |= (unsigned)(nn[c] <= ff[c] * (1 + CBVH_REF_EPS) && n->child[c] != NO_CHILD) << c;
    }
    return m;
}

/* Any valid ray (cbvh_ref_box2_any's test, per child). */
static unsigned box4_any(const cbvh_ref_ray *r, const rec4 *n, double cull, double tl[4]) {
    unsigned m = 0;
    for (int c = 0; c < 4; c++) {
        double nn = r->tmin, ff = cull;
        int in = 1;
        for (int a = 0; a < 3; a++) {
            double lo = n->b[0][a][c], hi = n->b[1][a][c];
            if (r->inv[a] == 0) { /* parallel: inside the closed slab or missed */
                in &= r->o[a] >= lo && r->o[a] <= hi;
                continue;
            }
            int neg = r->inv[a] < 0;
            double tn = ((neg ? hi : lo) - r->o[a]) * r->inv[a], tf = ((neg ? lo : hi) - r->o[a]) * r->inv[a];
            nn = tn > nn ? tn : nn;
            ff = tf < ff ? tf : ff;
        }
        tl[c] = nn - fabs(nn) * CBVH_REF_EPS;
        in &= nn <= ff + (fabs(nn) + fabs(ff)) * CBVH_REF_EPS;
        m |= (unsigned)(in && n->child[c] != NO_CHILD) << c;
    }
    return m;
}

#if defined(__SSE2__)
/* box4 for rays without zero direction components and tmin >= 0. */
static unsigned box4_sse2(const cbvh_ref_ray *r, const rec4 *n, double cull, double tl[4]) {
    __m128d nA = _mm_set1_pd(r->tmin), nB = nA, fA = _mm_set1_pd(cull), fB = fA;
    for (int a = 0; a < 3; a++) {
        int neg = r->inv[a] < 0;
        __m128 pn = _mm_load_ps(n->b[neg][a]), pf = _mm_load_ps(n->b[!neg][a]);
        __m128d o = _mm_set1_pd(r->o[a]), inv = _mm_set1_pd(r->inv[a]);
        nA = _mm_max_pd(nA, _mm_mul_pd(_mm_sub_pd(_mm_cvtps_pd(pn), o), inv));
        nB = _mm_max_pd(nB, _mm_mul_pd(_mm_sub_pd(_mm_cvtps_pd(_mm_movehl_ps(pn, pn)), o), inv));
        fA = _mm_min_pd(fA, _mm_mul_pd(_mm_sub_pd(_mm_cvtps_pd(pf), o), inv));
        fB = _mm_min_pd(fB, _mm_mul_pd(_mm_sub_pd(_mm_cvtps_pd(_mm_movehl_ps(pf, pf)), o), inv));
    }
    const __m128d hi = _mm_set1_pd(1 + CBVH_REF_EPS), lo = _mm_set1_pd(1 - CBVH_REF_EPS);
    unsigned m = (unsigned)_mm_movemask_pd(_mm_cmple_pd(nA, _mm_mul_pd(fA, hi))) |
                 (unsigned)_mm_movemask_pd(_mm_cmple_pd(nB, _mm_mul_pd(fB, hi))) << 2;
    _mm_storeu_pd(tl, _mm_mul_pd(nA, lo));
    _mm_storeu_pd(tl + 2, _mm_mul_pd(nB, lo));
    for (int c = 0; c < 4; c++)
        if (n->child[c] == NO_CHILD) m &= ~(1u << c);
    return m;
}
#endif

#define WIDE_STACK (3 * CBVH_TRAV_STACK)

/* Closest hit over the 4-wide tree; simd: the SSE2 box test where it applies. */
static int trace_wide(const wide_tree *w, const cbvh_tri *tris, const cbvh_ray *ray, int simd, cbvh_trav_hit *hit) {
    trav_state ts;
    if (trav_begin(&ts, hit, ray, CBVH_MANT_MAX, tris, CBVH_TRAV_CLOSEST, 0, 0)) return -1;
    cbvh_ref_ray r;
    cbvh_ref_prepare(ray, &r);
#if defined(__SSE2__)
    simd &= !r.general;
#else
    (void)simd;
#endif
    struct {
        uint32_t entry, count;
        double t_lo;
    } stack[WIDE_STACK];
    int sp = 0;
    double cull = cbvh_float_of(trav_box_tmax(&ts));
    uint32_t e = w->root, cnt = w->root_count;
    for (;;) {
        if (e & CBVH_FBVH_LEAF) {
            uint32_t first = e & ~CBVH_FBVH_LEAF;
            for (uint32_t i = 0; i < cnt; i++) trav_triangle(&ts, w->q->prims[first + i]);
            cull = cbvh_float_of(trav_box_tmax(&ts));
        } else {
            const rec4 *n = &w->r[e];
            double tl[4];
#if defined(__SSE2__)
            unsigned m = r.general ? box4_any(&r, n, cull, tl)
                         : simd    ? box4_sse2(&r, n, cull, tl)
                                   : box4(&r, n, cull, tl);
#else
            unsigned m = r.general ? box4_any(&r, n, cull, tl) : box4(&r, n, cull, tl);
#endif
            if (m) {
                int idx[4] = {0, 0, 0, 0}, nh = 0; /* hit children, farthest first */
                for (int c = 0; c < 4; c++) {
                    if (!(m >> c & 1u)) continue;
                    int j = nh++;
                    while (j > 0 && tl[idx[j - 1]] < tl[c]) idx[j] = idx[j - 1], j--;
                    idx[j] = c;
                }
                if (sp + nh - 1 > WIDE_STACK) return -1;
                for (int i = 0; i < nh - 1; i++) {
                    stack[sp].entry = n->child[idx[i]];
                    stack[sp].count = n->count[idx[i]];
                    stack[sp++].t_lo = tl[idx[i]];
                }
                e = n->child[idx[nh - 1]];
                cnt = n->count[idx[nh - 1]];
                continue;
            }
        }
        int have = 0;
        while (sp > 0 && !have) {
            sp--;
            /* cppcheck-suppress uninitvar ; entries below sp were pushed */
            have = !(stack[sp].t_lo > cull);
            e = stack[sp].entry;
            cnt = stack[sp].count;
        }
        if (!have) break;
    }
    *hit = ts.best;
    return 0;
}

/* tracer 0: binary (cbvh_trace_bvh_float), 1: 4-wide, 2: 4-wide SSE2; seconds. */
static double run_ours(int tracer, const cbvh_fbvh *fb, const wide_tree *w, const cbvh_tri *tris,
                       const cbvh_ray *rays, int n, long *hits) {
    long nh = 0;
    double t0 = now();
    for (int i = 0; i < n; i++) {
        cbvh_trav_hit h;
        cbvh_trav_stats st = {0};
        int rc = tracer == 0 ? cbvh_trace_bvh_float(fb, tris, &rays[i], CBVH_TRAV_CLOSEST, &h, &st)
                             : trace_wide(w, tris, &rays[i], tracer == 2, &h);
        if (rc) die("trace", "ray rejected or stack overflow");
        nh += h.hit;
    }
    *hits = nh;
    return now() - t0;
}

int main(int argc, char **argv) {
    bench_args A = {.nrays = 20000, .reps = 7, .seed = 1};
    bench_parse(argc, argv, &A, CBVH_SCENES_DIR "/bunny-small.obj");
    int nrays = A.nrays, reps = A.reps, ns = A.ns;
    const char *const *specs = A.specs;
#ifdef CBVH_HAVE_EMBREE
    RTCDevice dev = embree_device(A.isa);
    if (A.robust) printf("embree scenes: RTC_SCENE_FLAG_ROBUST\n");
#else
    printf("(built without Embree: no baseline, absolute rays/s only)\n");
#endif
#if !defined(__SSE2__)
    printf("(no SSE2 on this target: the SSE2 column repeats the scalar 4-wide traversal)\n");
#endif
    printf("%-24s %9s %-6s %10s %10s %10s %10s %8s %8s %8s %8s\n", "scene", "tris", "rays", "embree_r/s",
           "binary_r/s", "wide_r/s", "sse2_r/s", "bin/emb", "wide/emb", "sse2/emb", "hits");
    int status = 0;
    for (int si = 0; si < ns; si++) {
        cbvh_scene s;
        cbvh_bvh b;
        char err[512];
        load_scene(specs[si], &s, &b, "SAH build");
        cbvh_ray *rays = malloc((size_t)nrays * sizeof *rays);
        if (!rays) die("rays", "out of memory");
        float lo[3], hi[3];
        cbvh_scene_bounds(&s, lo, hi);
        make_rays(lo, hi, nrays, rays);
        cbvh_fbvh fb;
        cbvh_qbvh q;
        if (cbvh_fbvh_build(&b, &fb, err, sizeof err)) die("float BVH layout", err);
        if (cbvh_qbvh_from_bvh(&b, &q, err, sizeof err)) die("QBVH collapse", err);
        wide_tree w;
        wide_build(&q, &w);
        /* the same hits, ray by ray, before any timing; also each ray with one
         * direction component zeroed (the general slab test) */
        long differ = 0;
        for (int i = 0; i < 2 * nrays; i++) {
            cbvh_ray ray = rays[i % nrays];
            if (i >= nrays) ray.d[i % 3] = 0;
            if (cbvh_f32_is_zero(ray.d[0]) && cbvh_f32_is_zero(ray.d[1]) && cbvh_f32_is_zero(ray.d[2])) continue;
            cbvh_trav_hit h0, h1, h2;
            cbvh_trav_stats st = {0};
            if (cbvh_trace_bvh_float(&fb, s.tris, &ray, CBVH_TRAV_CLOSEST, &h0, &st) ||
                trace_wide(&w, s.tris, &ray, 0, &h1) || trace_wide(&w, s.tris, &ray, 1, &h2))
                die("trace", "ray rejected or stack overflow");
            differ += memcmp(&h0, &h1, sizeof h0) != 0 || memcmp(&h0, &h2, sizeof h0) != 0;
        }
        if (differ) {
            fprintf(stderr, "bench_wide: %s: %ld rays hit differently in the 4-wide traversal\n", specs[si], differ);
            status = 1;
        }
#ifdef CBVH_HAVE_EMBREE
        RTCScene sc = embree_scene(dev, &s, A.robust);
#endif
        for (int half = 0; half < 2; half++) {
            const cbvh_ray *rr = rays + (half ? nrays / 2 : 0);
            int n = half ? nrays - nrays / 2 : nrays / 2;
            double best[4] = {1e30, 1e30, 1e30, 1e30};
            long hits[4] = {0, 0, 0, 0};
            for (int k = 0; k < reps; k++) /* interleaved: load changes hit all tracers alike */
                for (int t = 0; t < 4; t++) {
                    double dt;
                    if (t < 3) dt = run_ours(t, &fb, &w, s.tris, rr, n, &hits[t]);
#ifdef CBVH_HAVE_EMBREE
                    else dt = embree_trace(sc, rr, n, 0, &hits[3]);
#else
                    else continue;
#endif
                    if (dt < best[t]) best[t] = dt;
                }
            double e = best[3] < 1e30 ? n / best[3] : 0;
            printf("%-24.24s %9u %-6s %10.0f %10.0f %10.0f %10.0f %8.3f %8.3f %8.3f %8ld\n", scene_base(specs[si]),
                   s.ntris, half ? "random" : "camera", e, n / best[0], n / best[1], n / best[2],
                   e ? (n / best[0]) / e : 0, e ? (n / best[1]) / e : 0, e ? (n / best[2]) / e : 0,
                   hits[0]);
            if (hits[1] != hits[0] || hits[2] != hits[0]) status = 1;
        }
#ifdef CBVH_HAVE_EMBREE
        rtcReleaseScene(sc);
#endif
        free(w.r);
        cbvh_qbvh_free(&q);
        cbvh_fbvh_free(&fb);
        cbvh_bvh_free(&b);
        cbvh_scene_free(&s);
        free(rays);
    }
#ifdef CBVH_HAVE_EMBREE
    rtcReleaseDevice(dev);
#endif
    return status;
}
