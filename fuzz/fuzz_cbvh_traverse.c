/* libFuzzer: the CBVH traversals on built and corrupted trees.
 *
 * The input chooses a small soup (grid or raw binary32 coordinates), a
 * builder (SAH or LBVH), a compressor (top-down or bottom-up) with N, the
 * encoding, the minimum scale, the treelet depth and naive re-encoding, then
 * up to three byte corruptions of the node pairs and optionally a bad root
 * pair, and up to eight rays.  Properties, each an abort:
 *   - neither traversal crashes or reads out of bounds (ASan), whatever the
 *     tree (cycles, pointers out of range, pairs the unit rejects);
 *   - the CBVH decoded once (cbvh_trace_cbvh_decoded, docs/traversal.md §12),
 *     with or without its leaf copy, gives the per-visit traversal's return
 *     value, hit and counters;
 *   - on an uncorrupted tree both succeed and hit exactly what brute force
 *     over the ray-triangle unit hits (closest: the same triangle and t);
 *   - so do the plain float traversals of the float BVH (binary, 4-wide
 *     over its QBVH collapse and 8-wide, with the leaf copies when bit 64 is
 *     set), and they reject (-1) the rays the units reject. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/cbvh_tree.h"
#include "cbvh/f8bvh.h"
#include "cbvh/qbvh.h"
#include "cbvh/traverse.h"

typedef struct {
    const uint8_t *d;
    size_t n, i;
} reader;

static uint8_t get8(reader *r) { return r->i < r->n ? r->d[r->i++] : 0; }

static uint32_t get32(reader *r) {
    uint32_t v = 0;
    for (int k = 0; k < 4; k++) v = v << 8 | get8(r);
    return v;
}

/* A coordinate: on a 1/16 grid in [-8, 8), or (raw) any binary32. */
static float coord(reader *r, int raw) { return raw ? cbvh_float_of(get32(r)) : (float)((int)get8(r) - 128) / 16.0f; }

static cbvh_f32 coord_bits(reader *r, int raw) { return cbvh_f32_of(coord(r, raw)); }

/* The closest hit by brute force: the smallest (t, index) the unit hits in
 * [tmin, tmax] (docs/traversal.md §5). */
static int brute(const cbvh_tri *tris, uint32_t n, const cbvh_ray *ray, cbvh_trav_hit *best) {
    memset(best, 0, sizeof *best);
    for (uint32_t i = 0; i < n; i++) {
        cbvh_f32 v[3][3];
        memcpy(v, tris[i].v, sizeof v);
        cbvh_tri_result r;
        if (cbvh_ray_triangle(ray, v[0], v[1], v[2], &r)) return -1;
        if (!r.hit) continue;
        int64_t k = cbvh_f32_key(r.t);
        if (k < cbvh_f32_key(ray->tmin) || k > cbvh_f32_key(ray->tmax)) continue;
        if (best->hit && k >= cbvh_f32_key(best->t)) continue;
        best->hit = 1;
        best->prim = i;
        best->t = r.t;
        best->b1 = r.b1;
        best->b2 = r.b2;
    }
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    reader rd = {data, size, 0};
    uint8_t mode = get8(&rd);
    static const int min_scales[6] = {-126, -30, -10, 0, -20, 5};
    static const int mants[4] = {3, 8, 24, 13};
    cbvh_compress_opts o = {{3 + get8(&rd) % 8, min_scales[get8(&rd) % 6]}, (cbvh_encoding)(get8(&rd) & 1),
                            1 + get8(&rd) % 4, get8(&rd) & 1};
    int M = mants[get8(&rd) % 4];
    cbvh_tri tris[16];
    cbvh_scene s = {.tris = tris, .ntris = 1 + get8(&rd) % 16};
    for (uint32_t i = 0; i < s.ntris; i++)
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++) tris[i].v[k][a] = coord(&rd, mode & 1);
    cbvh_bvh b;
    char err[256];
    if ((mode & 2) ? cbvh_build_lbvh(&s, &b, err, sizeof err) : cbvh_build_sah(&s, 0, 1 + get8(&rd) % 4, &b, err, sizeof err))
        return 0; /* a soup the builders refuse (non-finite, too large) */
    cbvh_tree t;
    int rc;
    if (mode & 4) {
        cbvh_bu_stats bs;
        rc = cbvh_compress_bottomup(&b, NULL, &o, &t, &bs, err, sizeof err);
    } else {
        rc = cbvh_compress_topdown(&b, &o, &t, err, sizeof err);
    }
    if (rc) {
        cbvh_bvh_free(&b);
        return 0;
    }
    /* the float BVH's plain traversals (uncorrupted: built from b) */
    cbvh_fbvh fb;
    cbvh_qbvh qb;
    cbvh_fqbvh fq;
    cbvh_f8bvh f8;
    if (cbvh_fbvh_build(&b, &fb, err, sizeof err) || cbvh_qbvh_from_bvh(&b, &qb, err, sizeof err) ||
        cbvh_fqbvh_build(&qb, (mode & 64) ? tris : NULL, s.ntris, &fq, err, sizeof err) ||
        cbvh_f8bvh_build(&b, (mode & 64) ? tris : NULL, s.ntris, &f8, err, sizeof err))
        abort(); /* a BVH the builders emit is one the layouts take */
    if ((mode & 64) && (!fq.leaf_tris || !f8.leaf_tris)) abort();
    int corrupt = get8(&rd) % 4;
    for (int k = 0; k < corrupt && t.npairs; k++) t.pairs[get32(&rd) % (t.npairs * t.pair_bytes)] ^= get8(&rd);
    if (mode & 8) {
        t.root_pair = get32(&rd) % (t.npairs + 2);
        corrupt++;
    }
    cbvh_cbvh_decoded d;
    if (cbvh_cbvh_decode(&t, &d, err, sizeof err)) abort(); /* only out of memory, not here */
    if (!corrupt && !d.usable) abort(); /* a tree the compressors emit is one the fast decode takes */
    if ((mode & 64) && cbvh_cbvh_decode_leaves(&d, tris, s.ntris, err, sizeof err)) abort(); /* the leaf copy too */
    if ((mode & 64) && d.usable && !d.leaf_tris) abort(); /* every ID names one of the soup's triangles */
    int nrays = 1 + get8(&rd) % 8;
    for (int i = 0; i < nrays; i++) {
        cbvh_ray ray;
        for (int a = 0; a < 3; a++) {
            ray.o[a] = coord_bits(&rd, mode & 16);
            ray.d[a] = coord_bits(&rd, mode & 16);
        }
        ray.tmin = 0;
        ray.tmax = (mode & 32) ? coord_bits(&rd, 0) & ~CBVH_F32_SIGN : CBVH_F32_POS_INF;
        for (int m = 0; m < 2; m++) {
            cbvh_trav_hit h1, h2, want;
            cbvh_trav_stats s1 = {0}, s2 = {0};
            int r1 = cbvh_trace_cbvh(&t, tris, &ray, M, (cbvh_trav_mode)m, &h1, &s1);
            int r2 = cbvh_trace_cbvh_decoded(&d, tris, &ray, M, (cbvh_trav_mode)m, &h2, &s2);
            if (r1 != r2 || memcmp(&h1, &h2, sizeof h1) || memcmp(&s1, &s2, sizeof s1)) abort();
            cbvh_trav_hit hf, hq, h8;
            int rf = cbvh_trace_bvh_float(&fb, tris, &ray, (cbvh_trav_mode)m, &hf, &s2);
            int rq = cbvh_trace_qbvh_float(&fq, tris, &ray, (cbvh_trav_mode)m, &hq, &s2);
            int r8 = cbvh_trace_f8bvh_float(&f8, tris, &ray, (cbvh_trav_mode)m, &h8, &s2);
            int rejected = brute(tris, s.ntris, &ray, &want);
            if (rejected) { /* a ray the units reject */
                if (rf != -1 || rq != -1 || r8 != -1 || hf.hit || hq.hit || h8.hit) abort();
                continue;
            }
            if (rf || hf.hit != want.hit || rq || hq.hit != want.hit || r8 || h8.hit != want.hit) abort();
            if (m == 0 && want.hit && (hf.prim != want.prim || hf.t != want.t || hq.prim != want.prim || hq.t != want.t ||
                                       h8.prim != want.prim || h8.t != want.t))
                abort();
            if (corrupt) continue; /* -1 or any result above */
            if (r1 || h1.hit != want.hit) abort();
            if (m == 0 && want.hit && (h1.prim != want.prim || h1.t != want.t)) abort();
        }
    }
    cbvh_cbvh_decoded_free(&d);
    cbvh_tree_free(&t);
    cbvh_fqbvh_free(&fq);
    cbvh_f8bvh_free(&f8);
    cbvh_qbvh_free(&qb);
    cbvh_fbvh_free(&fb);
    cbvh_bvh_free(&b);
    return 0;
}
