/* LBVH builder: 30-bit Morton codes of triangle centroids, LSD radix sort,
 * Karras 2012 binary radix tree over the *distinct* codes (triangles sharing a
 * code share one leaf, as the paper's modified hardware builder does), then
 * boxes bottom-up.  Node layout: inner nodes [0, m-1) with the root at 0,
 * leaves [m-1, 2m-1) in Morton order (m = number of distinct codes).
 *
 * The radix tree is built bottom-up in one pass that also merges the boxes
 * (Apetrei 2014): a node covering leaves [l, r] is the left child of the
 * split between r and r+1 if those codes share a longer prefix than l-1 and
 * l do, else the right child of the split between l-1 and l; the second child
 * to reach a split completes its parent.  It yields the same tree as Karras'
 * top-down search over the distinct codes, and the same node numbering: an
 * inner node is numbered by its range end that touches its parent's split
 * (hi for a left child, lo for a right child), the root is 0.
 *
 * The two phases (leaves; hierarchy and boxes) are shared with the fused
 * builder build_lbvh_streaming.c through lbvh_internal.h, which holds the
 * hierarchy pass. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "build/lbvh_internal.h"
#include "cbvh/oom.h"

/* Spread the low 10 bits of x to every third bit. */
static inline uint32_t spread3(uint32_t x) {
    x &= 0x3FFu;
    x = (x | (x << 16)) & 0x030000FFu;
    x = (x | (x << 8)) & 0x0300F00Fu;
    x = (x | (x << 4)) & 0x030C30C3u;
    x = (x | (x << 2)) & 0x09249249u;
    return x;
}

static inline uint32_t quant10(float x, float lo, float inv) {
    float q = (x - lo) * inv; /* +Inf only for ranges beyond FLT_MAX: clamps to 1023 */
    if (!(q > 0.0f)) return 0;
    if (q >= 1023.0f) return 1023;
    return (uint32_t)q;
}

/* Stable LSD radix sort of (code, index) pairs by the 30-bit code: 3 passes
 * of 10 bits (histograms fit L1, filled by the caller while it writes the
 * keys), buffers ping-ponged.  Returns the buffer holding the sorted keys. */
static uint64_t *radix_sort(uint64_t *a, uint64_t *tmp, uint32_t n, uint32_t hist[3][1024]) {
    for (int p = 0; p < 3; p++) {
        uint32_t sum = 0;
        for (int b = 0; b < 1024; b++) {
            uint32_t c = hist[p][b];
            hist[p][b] = sum;
            sum += c;
        }
    }
    for (int p = 0; p < 3; p++) {
        int sh = 32 + 10 * p;
        uint32_t *h = hist[p];
        for (uint32_t i = 0; i < n; i++) {
            uint64_t k = a[i];
            tmp[h[(k >> sh) & 1023u]++] = k;
        }
        uint64_t *t = a;
        a = tmp;
        tmp = t;
    }
    return a;
}

/* Centre of a triangle's box, without overflow for coordinates up to FLT_MAX. */
static inline void tri_centre(const cbvh_tri *t, float c[3]) {
    float lo[3], hi[3];
    cbvh_tri_bounds(t, lo, hi);
    for (int a = 0; a < 3; a++) c[a] = 0.5f * lo[a] + 0.5f * hi[a];
}

int cbvh_lbvh_leaves(const cbvh_scene *s, cbvh_lbvh_work *w, int with_ids, char *err, size_t errlen) {
    memset(w, 0, sizeof *w);
    /* The full validation runs up front only for what the fast vertex scan
     * below cannot see, and afterwards to word the error when it finds a
     * non-finite vertex (same message either way). */
    if ((s->ntris == 0 || !s->tris || s->ntris >= 0x80000000u || s->nmorph) &&
        cbvh_scene_validate(s, err, errlen))
        return -1;
    uint32_t n = s->ntris;
    /* Non-finite vertex: two floats per 64-bit word, bit 31/63 of
     * (exponent field + 1 ulp of the exponent) set iff the field is all ones. */
    {
        const uint8_t *raw = (const uint8_t *)s->tris;
        size_t nw = (size_t)n * 9u, i = 0;
        uint64_t acc = 0;
        for (; i + 2 <= nw; i += 2) {
            uint64_t w;
            memcpy(&w, raw + 4 * i, sizeof w);
            acc |= (w & UINT64_C(0x7F8000007F800000)) + UINT64_C(0x0080000000800000);
        }
        if (i < nw) {
            uint32_t w;
            memcpy(&w, raw + 4 * i, sizeof w);
            acc |= (w & 0x7F800000u) + 0x00800000u;
        }
        if ((acc & UINT64_C(0x8000000080000000)) && cbvh_scene_validate(s, err, errlen)) return -1;
    }
    float(*cen)[3] = malloc((size_t)n * sizeof *cen);
    uint64_t *keys = malloc((size_t)n * sizeof *keys), *tmp = malloc((size_t)n * sizeof *tmp);
    uint32_t *prims = malloc((size_t)n * sizeof *prims);
    if (!cen || !keys || !tmp || !prims) {
        free(cen);
        free(keys);
        free(tmp);
        free(prims);
        snprintf(err, errlen, "lbvh: out of memory for %u triangles", n);
        return -1;
    }
    /* Pass 1: triangle box centres and their bounds. */
    float clo[3], chi[3];
    tri_centre(&s->tris[0], clo);
    memcpy(chi, clo, sizeof chi);
    for (uint32_t i = 0; i < n; i++) {
        float *c = cen[i];
        tri_centre(&s->tris[i], c);
        for (int a = 0; a < 3; a++) {
            clo[a] = c[a] < clo[a] ? c[a] : clo[a];
            chi[a] = c[a] > chi[a] ? c[a] : chi[a];
        }
    }
    float inv[3];
    for (int a = 0; a < 3; a++) {
        double ext = (double)chi[a] - (double)clo[a]; /* may exceed FLT_MAX */
        inv[a] = ext > 0.0 ? (float)(1024.0 / ext) : 0.0f;
    }
    /* Pass 2: Morton codes with the triangle index, and the radix histograms. */
    uint32_t spread[1024]; /* spread3 of every 10-bit value, 4 KiB */
    for (uint32_t v = 0; v < 1024; v++) spread[v] = spread3(v);
    uint32_t h[3][1024]; /* 12 KiB */
    memset(h, 0, sizeof h);
    for (uint32_t i = 0; i < n; i++) {
        const float *c = cen[i];
        uint32_t code = spread[quant10(c[0], clo[0], inv[0])] << 2 | spread[quant10(c[1], clo[1], inv[1])] << 1 |
                        spread[quant10(c[2], clo[2], inv[2])];
        keys[i] = (uint64_t)code << 32 | i;
        h[0][code & 1023u]++;
        h[1][(code >> 10) & 1023u]++;
        h[2][(code >> 20) & 1023u]++;
    }
    free(cen);
    if (radix_sort(keys, tmp, n, h) != keys) { /* sorted data ended in tmp */
        uint64_t *t = keys;
        keys = tmp;
        tmp = t;
    }

    /* Distinct codes (into the upper half of tmp), then the leaves in Morton
     * order with their boxes (and the IDs into the lower half: pages the sort
     * has touched already). */
    uint32_t *codes = (uint32_t *)tmp + n, *ids = with_ids ? (uint32_t *)tmp : NULL;
    uint32_t m = 0;
    for (uint32_t i = 0; i < n; i++) {
        uint32_t c = (uint32_t)(keys[i] >> 32);
        if (i == 0 || c != codes[m - 1]) codes[m++] = c;
    }
    uint32_t nn = 2 * m - 1, L = m - 1; /* L: first leaf node index */
    cbvh_bvh_node *nodes = malloc((size_t)nn * sizeof *nodes);
    if (!nodes) cbvh_out_of_memory("LBVH nodes");
    cbvh_bvh_node *lf = NULL; /* the current leaf */
    for (uint32_t i = 0, c = 0; i < n; i++) {
        uint32_t code = (uint32_t)(keys[i] >> 32), t = (uint32_t)keys[i];
        float lo[3], hi[3];
        cbvh_tri_bounds(&s->tris[t], lo, hi);
        prims[i] = t;
        if (ids) ids[i] = t;
        if (i == 0 || code != c) {
            if (ids && i) ids[i - 1] |= CBVH_ID_LAST; /* the previous leaf's last ID */
            c = code;
            lf = lf ? lf + 1 : &nodes[L];
            lf->child[0] = lf->child[1] = 0;
            lf->first = i;
            lf->count = 1;
            memcpy(lf->lo, lo, sizeof lf->lo);
            memcpy(lf->hi, hi, sizeof lf->hi);
            continue;
        }
        lf->count++;
        for (int a = 0; a < 3; a++) {
            if (lo[a] < lf->lo[a]) lf->lo[a] = lo[a];
            if (hi[a] > lf->hi[a]) lf->hi[a] = hi[a];
        }
    }
    if (ids) ids[n - 1] |= CBVH_ID_LAST;
    w->nodes = nodes;
    w->prims = prims;
    w->ids = ids;
    w->codes = codes;
    w->split = (uint32_t *)keys; /* keys are dead: 8n >= 8(m-1) bytes */
    w->buf[0] = keys;
    w->buf[1] = tmp;
    w->n = n;
    w->m = m;
    return 0;
}

void cbvh_lbvh_finish(cbvh_lbvh_work *w, cbvh_bvh *out) {
    free(w->buf[0]);
    free(w->buf[1]);
    out->nodes = w->nodes;
    out->nnodes = 2 * w->m - 1;
    out->root = 0; /* with m == 1 the single leaf is node 0 */
    out->prims = w->prims;
    out->nprims = w->n;
    memset(w, 0, sizeof *w);
}

int cbvh_build_lbvh(const cbvh_scene *s, cbvh_bvh *out, char *err, size_t errlen) {
    memset(out, 0, sizeof *out);
    cbvh_lbvh_work w;
    if (cbvh_lbvh_leaves(s, &w, 0, err, errlen)) return -1;
    cbvh_lbvh_hierarchy(&w, NULL, NULL);
    cbvh_lbvh_finish(&w, out);
    return 0;
}
