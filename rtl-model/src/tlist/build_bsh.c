/* Bounding-sphere hierarchy (seed 004, Toczek et al. 2010 §2.2; docs/tlist.md §2).
 *
 * Top-down, octree-like: a node's sphere is centred on the centre of the tight
 * box of its triangles, with the smallest binary32 radius that encloses every
 * vertex (computed in binary64 with a rigorous error bound, then rounded up;
 * cbvh_bsh_check verifies it with exact arithmetic).  Triangles big for the
 * node stay at the node; the others are split into up to eight groups by the
 * signs of (centroid - centre) and recursed on.  Nodes are numbered
 * breadth-first so the children of a node are contiguous. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/tlist.h"
#include "units/exact_wide.h"

void cbvh_bsh_default_params(cbvh_bsh_params *p) {
    p->leaf_max = 4;
    p->big_ratio = 2;
    p->max_depth = 32;
}

void cbvh_bsh_free(cbvh_bsh *h) {
    free(h->sphere);
    free(h->first_child);
    free(h->nchild);
    free(h->first_tri);
    free(h->ntri);
    free(h->tri_ids);
    memset(h, 0, sizeof *h);
}


static int encloses(const cbvh_f32 sph[4], const float v[3]);

/* The smallest binary32 radius about c that encloses every vertex exactly.
 * Binary64 first: each operation has relative error <= 2^-53, so the computed
 * max squared distance m is within (1 +- 2^-50) of the true one; the factor
 * (1 + 2^-40) and rounding up to binary32 give an enclosing radius.  Then one
 * ulp less is tried with exact arithmetic while it cannot be ruled out by m
 * (a distance that is itself a binary32, common on grids).  -1 if the radius
 * overflows binary32. */
static int radius_up(const cbvh_tri *tris, const uint32_t *ids, uint32_t n, const float c[3], cbvh_f32 *r) {
    double m = 0;
    for (uint32_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            const float *v = tris[ids[i]].v[k];
            double dx = (double)v[0] - c[0], dy = (double)v[1] - c[1], dz = (double)v[2] - c[2];
            double d2 = dx * dx + dy * dy + dz * dz;
            if (d2 > m) m = d2;
        }
    double d = sqrt(m) * (1.0 + 0x1p-40);
    if (d == 0) {
        *r = 0;
        return 0;
    }
    if (d > (double)3.4028234663852886e38f) return -1;
    float f = (float)d;
    if ((double)f < d) f = nextafterf(f, INFINITY);
    if (isinf(f)) return -1;
    for (;;) {
        float g = nextafterf(f, 0.0f);
        if ((double)g * g < m * (1.0 - 0x1p-49)) break; /* g^2 is exact: g is too small */
        cbvh_f32 sph[4] = {cbvh_f32_of(c[0]), cbvh_f32_of(c[1]), cbvh_f32_of(c[2]), cbvh_f32_of(g)};
        int all = 1;
        for (uint32_t i = 0; i < n && all; i++)
            for (int k = 0; k < 3 && all; k++) all = encloses(sph, tris[ids[i]].v[k]);
        if (!all) break;
        f = g;
        if (g == 0) break;
    }
    *r = cbvh_f32_of(f);
    return 0;
}

typedef struct {
    uint32_t node, begin, end, depth;
} work;

int cbvh_bsh_build(const cbvh_scene *s, const cbvh_bsh_params *p, cbvh_bsh *out, char *err, size_t errlen) {
    memset(out, 0, sizeof *out);
    cbvh_bsh_params dp;
    if (!p) {
        cbvh_bsh_default_params(&dp);
        p = &dp;
    }
    if (p->leaf_max < 1 || p->big_ratio < 1 || p->max_depth < 1 || p->max_depth > 1000) {
        snprintf(err, errlen, "bsh: bad parameters leaf_max %u big_ratio %u max_depth %u (each >= 1, depth <= 1000)",
                 p->leaf_max, p->big_ratio, p->max_depth);
        return -1;
    }
    if (cbvh_scene_validate(s, err, errlen)) return -1;
    const uint32_t n = s->ntris;
    const cbvh_tri *T = s->tris;
    /* Nodes: leaves <= n, nodes with >= 2 children < leaves, nodes with one
     * child keep >= 1 big triangle: at most 3n. */
    uint32_t cap = 3u * n + 1u;
    if (n > (UINT32_MAX - 1u) / 3u) {
        snprintf(err, errlen, "bsh: %u triangles exceed the 32-bit node index", n);
        return -1;
    }
    out->sphere = malloc((size_t)cap * sizeof *out->sphere);
    out->first_child = calloc(cap, sizeof *out->first_child);
    out->nchild = calloc(cap, sizeof *out->nchild);
    out->first_tri = calloc(cap, sizeof *out->first_tri);
    out->ntri = calloc(cap, sizeof *out->ntri);
    out->tri_ids = malloc((size_t)n * sizeof *out->tri_ids);
    uint32_t *perm = malloc((size_t)n * sizeof *perm), *tmp = malloc((size_t)n * sizeof *tmp);
    uint8_t *grp = malloc(n);
    work *q = malloc((size_t)cap * sizeof *q);
    if (!out->sphere || !out->first_child || !out->nchild || !out->first_tri || !out->ntri || !out->tri_ids || !perm ||
        !tmp || !grp || !q) {
        snprintf(err, errlen, "bsh: out of memory for %u triangles", n);
        goto fail;
    }
    for (uint32_t i = 0; i < n; i++) perm[i] = i;
    uint32_t qh = 0, qt = 0, ntid = 0;
    out->nnodes = 1;
    q[qt++] = (work){0, 0, n, 0};
    while (qh < qt) {
        work w = q[qh++];
        uint32_t cnt = w.end - w.begin, *ids = perm + w.begin;
        if (w.depth > out->depth) out->depth = w.depth;
        float lo[3], hi[3], c[3];
        cbvh_tri_bounds(&T[ids[0]], lo, hi);
        for (uint32_t i = 1; i < cnt; i++) {
            float l2[3], h2[3];
            cbvh_tri_bounds(&T[ids[i]], l2, h2);
            for (int a = 0; a < 3; a++) {
                if (l2[a] < lo[a]) lo[a] = l2[a];
                if (h2[a] > hi[a]) hi[a] = h2[a];
            }
        }
        for (int a = 0; a < 3; a++) c[a] = 0.5f * lo[a] + 0.5f * hi[a]; /* no overflow near FLT_MAX */
        cbvh_f32 r;
        if (radius_up(T, ids, cnt, c, &r)) {
            snprintf(err, errlen, "bsh: a bounding sphere radius exceeds binary32 (scene extent too close to FLT_MAX)");
            goto fail;
        }
        for (int a = 0; a < 3; a++) out->sphere[w.node][a] = cbvh_f32_of(c[a]);
        out->sphere[w.node][3] = r;
        out->first_tri[w.node] = ntid;
        if (cnt <= p->leaf_max || w.depth >= p->max_depth) {
            memcpy(out->tri_ids + ntid, ids, (size_t)cnt * sizeof *ids);
            out->ntri[w.node] = cnt;
            ntid += cnt;
            continue;
        }
        /* Big triangles stay; the others go to the octant of their centroid. */
        double rn = cbvh_float_of(r);
        uint32_t gcount[8] = {0}, nbig = 0;
        for (uint32_t i = 0; i < cnt; i++) {
            const cbvh_tri *t = &T[ids[i]];
            float tl[3], th[3];
            cbvh_tri_bounds(t, tl, th);
            double hd2 = 0;
            for (int a = 0; a < 3; a++) {
                double h = 0.5 * ((double)th[a] - tl[a]);
                hd2 += h * h;
            }
            if (sqrt(hd2) * p->big_ratio >= rn) {
                grp[i] = 8;
                out->tri_ids[ntid + nbig++] = ids[i];
                continue;
            }
            int g = 0;
            for (int a = 0; a < 3; a++) {
                double gs = (double)t->v[0][a] + t->v[1][a] + t->v[2][a]; /* 3 x centroid */
                if (gs > 3.0 * c[a]) g |= 1 << a;
            }
            grp[i] = (uint8_t)g;
            gcount[g]++;
        }
        uint32_t ngroups = 0;
        for (int g = 0; g < 8; g++) ngroups += gcount[g] != 0;
        if (nbig == 0 && ngroups == 1) { /* nothing separates them: a leaf */
            memcpy(out->tri_ids + ntid, ids, (size_t)cnt * sizeof *ids);
            out->ntri[w.node] = cnt;
            ntid += cnt;
            continue;
        }
        out->ntri[w.node] = nbig;
        ntid += nbig;
        /* Reorder the others by group (stable) and queue one child per group. */
        uint32_t start[8], pos = 0;
        for (int g = 0; g < 8; g++) {
            start[g] = pos;
            pos += gcount[g];
        }
        uint32_t fill[8];
        memcpy(fill, start, sizeof fill);
        for (uint32_t i = 0; i < cnt; i++)
            if (grp[i] < 8) tmp[fill[grp[i]]++] = ids[i];
        memcpy(ids, tmp, (size_t)pos * sizeof *ids);
        out->first_child[w.node] = out->nnodes;
        out->nchild[w.node] = ngroups;
        for (int g = 0; g < 8; g++) {
            if (!gcount[g]) continue;
            if (out->nnodes >= cap) {
                snprintf(err, errlen, "bsh: node capacity exceeded (internal error)");
                goto fail;
            }
            q[qt++] = (work){out->nnodes++, w.begin + start[g], w.begin + start[g] + gcount[g], w.depth + 1};
        }
    }
    out->ntri_ids = ntid;
    free(perm);
    free(tmp);
    free(grp);
    free(q);
    return 0;
fail:
    free(perm);
    free(tmp);
    free(grp);
    free(q);
    cbvh_bsh_free(out);
    return -1;
}

/* r^2 >= |v - c|^2, exactly. */
static int encloses(const cbvh_f32 sph[4], const float v[3]) {
    cbvh_xw s, d, p, cc;
    cbvh_xw_zero(&s);
    for (int a = 0; a < 3; a++) {
        cbvh_xw_from_f32(&d, cbvh_f32_of(v[a]));
        cbvh_xw_from_f32(&cc, sph[a]);
        cbvh_xw_sub(&d, &d, &cc);
        cbvh_xw_mul(&p, &d, &d);
        cbvh_xw_add(&s, &s, &p);
    }
    cbvh_xw_from_f32(&d, sph[3]);
    cbvh_xw_mul(&p, &d, &d);
    return cbvh_xw_cmp(&s, &p) <= 0;
}

int cbvh_bsh_check(const cbvh_bsh *h, const cbvh_scene *s, char *err, size_t errlen) {
    if (!h->nnodes) {
        snprintf(err, errlen, "bsh: no nodes");
        return -1;
    }
    uint8_t *seen = calloc(s->ntris, 1);
    uint32_t *parent = malloc((size_t)h->nnodes * sizeof *parent), *depth = NULL;
    int rc = -1;
    if (!seen || !parent) {
        snprintf(err, errlen, "bsh check: out of memory");
        goto out;
    }
    for (uint32_t i = 0; i < h->nnodes; i++) parent[i] = UINT32_MAX;
    for (uint32_t i = 0; i < h->nnodes; i++) {
        const cbvh_f32 *sp = h->sphere[i];
        for (int a = 0; a < 4; a++)
            if (cbvh_f32_is_nan_or_inf(sp[a]) || (a == 3 && (sp[3] & CBVH_F32_SIGN) && !cbvh_f32_is_zero(sp[3]))) {
                snprintf(err, errlen, "bsh: node %u has a non-finite or negative sphere", i);
                goto out;
            }
        if (h->nchild[i] + h->ntri[i] == 0) {
            snprintf(err, errlen, "bsh: node %u is empty", i);
            goto out;
        }
        if ((uint64_t)h->first_tri[i] + h->ntri[i] > h->ntri_ids) {
            snprintf(err, errlen, "bsh: node %u triangle range out of bounds", i);
            goto out;
        }
        if (h->nchild[i] > 8) { /* an octant split: the list builder's scratch holds 8 */
            snprintf(err, errlen, "bsh: node %u has %u children (at most 8)", i, h->nchild[i]);
            goto out;
        }
        if (h->nchild[i] && (h->first_child[i] <= i || (uint64_t)h->first_child[i] + h->nchild[i] > h->nnodes)) {
            snprintf(err, errlen, "bsh: node %u child range [%u, +%u) invalid", i, h->first_child[i], h->nchild[i]);
            goto out;
        }
        for (uint32_t k = 0; k < h->nchild[i]; k++) {
            uint32_t c = h->first_child[i] + k;
            if (parent[c] != UINT32_MAX || c == 0) {
                snprintf(err, errlen, "bsh: node %u has two parents", c);
                goto out;
            }
            parent[c] = i;
        }
    }
    for (uint32_t i = 1; i < h->nnodes; i++)
        if (parent[i] == UINT32_MAX) {
            snprintf(err, errlen, "bsh: node %u unreachable", i);
            goto out;
        }
    /* The recorded depth sizes the list builder's scratch: it must be the
     * hierarchy's (children have larger indices than their parent). */
    depth = malloc((size_t)h->nnodes * sizeof *depth);
    if (!depth) {
        snprintf(err, errlen, "bsh check: out of memory");
        goto out;
    }
    uint32_t deepest = 0;
    depth[0] = 0;
    for (uint32_t i = 1; i < h->nnodes; i++) {
        depth[i] = depth[parent[i]] + 1;
        if (depth[i] > deepest) deepest = depth[i];
    }
    if (h->depth != deepest) {
        snprintf(err, errlen, "bsh: depth recorded as %u, the hierarchy is %u deep", h->depth, deepest);
        goto out;
    }
    if (h->ntri_ids != s->ntris) {
        snprintf(err, errlen, "bsh: %u triangle slots for %u triangles", h->ntri_ids, s->ntris);
        goto out;
    }
    for (uint32_t i = 0; i < h->nnodes; i++)
        for (uint32_t k = 0; k < h->ntri[i]; k++) {
            uint32_t t = h->tri_ids[h->first_tri[i] + k];
            if (t >= s->ntris || seen[t]) {
                snprintf(err, errlen, "bsh: triangle %u missing or twice", t);
                goto out;
            }
            seen[t] = 1;
            /* every sphere from this node up to the root encloses its vertices */
            for (uint32_t a = i;; a = parent[a]) {
                for (int v = 0; v < 3; v++)
                    if (!encloses(h->sphere[a], s->tris[t].v[v])) {
                        snprintf(err, errlen, "bsh: sphere of node %u does not enclose vertex %d of triangle %u", a, v,
                                 t);
                        goto out;
                    }
                if (a == 0) break;
            }
        }
    /* ntri_ids == ntris and no triangle twice: a missing one leaves a slot
     * unused, which the loop above does not see. */
    for (uint32_t t = 0; t < s->ntris; t++)
        if (!seen[t]) {
            snprintf(err, errlen, "bsh: triangle %u is in no node", t);
            goto out;
        }
    rc = 0;
out:
    free(seen);
    free(parent);
    free(depth);
    return rc;
}
