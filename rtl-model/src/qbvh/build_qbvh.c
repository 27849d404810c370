/* QBVH builder (seed 000): collapse a binary BVH into a 4-ary BVH with all
 * siblings contiguous, structure of arrays (docs/qbvh.md §3). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/qbvh.h"
#include "qbvh/collapse.h"

void cbvh_qbvh_free(cbvh_qbvh *q) {
    free(q->bmin);
    free(q->bmax);
    free(q->first);
    free(q->count);
    free(q->prims);
    memset(q, 0, sizeof *q);
}

size_t cbvh_qbvh_node_bytes(const cbvh_qbvh *q) { return (size_t)q->nnodes * CBVH_QBVH_NODE_BYTES; }

static double half_area(const cbvh_bvh_node *n) {
    double dx = (double)n->hi[0] - n->lo[0], dy = (double)n->hi[1] - n->lo[1], dz = (double)n->hi[2] - n->lo[2];
    return dx * dy + dy * dz + dz * dx;
}

int cbvh_collapse_gather(const cbvh_bvh *b, uint32_t src, int w, uint32_t *out, uint8_t *seen) {
    int n = 0;
    for (int c = 0; c < 2; c++) {
        uint32_t k = b->nodes[src].child[c];
        if (k >= b->nnodes || (seen && seen[k]++)) return -1;
        out[n++] = k;
    }
    while (n < w) {
        int best = -1;
        double ba = -1;
        for (int i = 0; i < n; i++) {
            const cbvh_bvh_node *c = &b->nodes[out[i]];
            if (cbvh_bvh_is_leaf(c)) continue;
            double a = half_area(c);
            if (a > ba) {
                ba = a;
                best = i;
            }
        }
        if (best < 0) break;
        uint32_t open = out[best], k0 = b->nodes[open].child[0], k1 = b->nodes[open].child[1];
        if (k0 >= b->nnodes || k1 >= b->nnodes || (seen && (seen[k0]++ || seen[k1]++))) return -1;
        memmove(&out[best + 2], &out[best + 1], (size_t)(n - best - 1) * sizeof out[0]);
        out[best] = k0;
        out[best + 1] = k1;
        n++;
    }
    return n;
}

static void set_box(cbvh_qbvh *q, uint32_t i, const cbvh_bvh_node *n) {
    for (int a = 0; a < 3; a++) {
        q->bmin[i][a] = n->lo[a];
        q->bmax[i][a] = n->hi[a];
    }
    q->bmin[i][3] = q->bmax[i][3] = 0;
}

int cbvh_qbvh_from_bvh(const cbvh_bvh *b, cbvh_qbvh *out, char *err, size_t errlen) {
    memset(out, 0, sizeof *out);
    if (!b->nnodes || b->root >= b->nnodes) {
        snprintf(err, errlen, "qbvh: empty or malformed binary BVH");
        return -1;
    }
    /* The QBVH never has more nodes than the binary tree. */
    uint32_t cap = b->nnodes;
    cbvh_qbvh q = {0};
    q.bmin = malloc((size_t)cap * sizeof *q.bmin);
    q.bmax = malloc((size_t)cap * sizeof *q.bmax);
    q.first = malloc((size_t)cap * sizeof *q.first);
    q.count = malloc((size_t)cap * sizeof *q.count);
    q.prims = malloc((size_t)(b->nprims ? b->nprims : 1) * sizeof *q.prims);
    uint32_t *src = malloc((size_t)cap * sizeof *src);   /* binary node of each QBVH node */
    uint32_t *level = malloc((size_t)cap * sizeof *level);
    if (!q.bmin || !q.bmax || !q.first || !q.count || !q.prims || !src || !level) {
        free(src);
        free(level);
        cbvh_qbvh_free(&q);
        snprintf(err, errlen, "qbvh: out of memory for %u nodes", cap);
        return -1;
    }
    memcpy(q.prims, b->prims, (size_t)b->nprims * sizeof *q.prims);
    q.nprims = b->nprims;
    /* Breadth-first: node i's children are appended as one contiguous group. */
    src[0] = b->root;
    level[0] = 0;
    q.nnodes = 1;
    for (uint32_t i = 0; i < q.nnodes; i++) {
        const cbvh_bvh_node *n = &b->nodes[src[i]];
        set_box(&q, i, n);
        if (level[i] > q.depth) q.depth = level[i];
        if (cbvh_bvh_is_leaf(n)) {
            if (n->count >= CBVH_QBVH_LEAF) {
                snprintf(err, errlen, "qbvh: leaf with %u primitives", n->count);
                goto fail;
            }
            q.first[i] = n->first;
            q.count[i] = n->count | CBVH_QBVH_LEAF;
            continue;
        }
        uint32_t ch[4];
        int k = cbvh_collapse_gather(b, src[i], 4, ch, NULL);
        if (k < 0 || q.nnodes > cap - (uint32_t)k) {
            snprintf(err, errlen,
                     "qbvh: binary BVH is not a tree (a child outside it, or more nodes reached than it has)");
            goto fail;
        }
        q.first[i] = q.nnodes;
        q.count[i] = (uint32_t)k;
        if (q.nnodes > q.max_first) q.max_first = q.nnodes;
        for (int c = 0; c < k; c++) {
            src[q.nnodes] = ch[c];
            level[q.nnodes] = level[i] + 1;
            q.nnodes++;
        }
    }
    free(src);
    free(level);
    *out = q;
    return 0;
fail:
    free(src);
    free(level);
    cbvh_qbvh_free(&q);
    return -1;
}

static int encloses(const float alo[4], const float ahi[4], const float blo[3], const float bhi[3]) {
    for (int a = 0; a < 3; a++)
        if (!(alo[a] <= blo[a] && bhi[a] <= ahi[a])) return 0;
    return 1;
}

int cbvh_qbvh_check(const cbvh_qbvh *q, const cbvh_scene *s, char *err, size_t errlen) {
    if (!q->nnodes) {
        snprintf(err, errlen, "qbvh: no nodes");
        return -1;
    }
    uint8_t *seen = calloc(q->nnodes, 1);
    uint8_t *pseen = calloc(s->ntris ? s->ntris : 1, 1);
    int rc = -1;
    uint32_t nprim = 0;
    if (!seen || !pseen) {
        snprintf(err, errlen, "qbvh check: out of memory");
        goto done;
    }
    seen[0] = 1;
    for (uint32_t i = 0; i < q->nnodes; i++) {
        if (!seen[i]) {
            snprintf(err, errlen, "qbvh: node %u unreachable (or reached after its group)", i);
            goto done;
        }
        if (q->count[i] & CBVH_QBVH_LEAF) {
            uint32_t c = q->count[i] & ~CBVH_QBVH_LEAF;
            if (!c || q->first[i] > q->nprims || c > q->nprims - q->first[i]) {
                snprintf(err, errlen, "qbvh: leaf %u has a bad primitive range", i);
                goto done;
            }
            for (uint32_t j = 0; j < c; j++) {
                uint32_t p = q->prims[q->first[i] + j];
                float lo[3], hi[3];
                if (p >= s->ntris || pseen[p]) {
                    snprintf(err, errlen, "qbvh: primitive %u out of range or in two leaves", p);
                    goto done;
                }
                pseen[p] = 1;
                nprim++;
                cbvh_tri_bounds(&s->tris[p], lo, hi);
                if (!encloses(q->bmin[i], q->bmax[i], lo, hi)) {
                    snprintf(err, errlen, "qbvh: leaf %u does not enclose triangle %u", i, p);
                    goto done;
                }
            }
            continue;
        }
        uint32_t c = q->count[i], f = q->first[i];
        if (c < 2 || c > 4 || f <= i || f > q->nnodes - c) {
            snprintf(err, errlen, "qbvh: inner node %u has a bad child group (%u at %u)", i, c, f);
            goto done;
        }
        for (uint32_t j = f; j < f + c; j++) {
            if (seen[j]) {
                snprintf(err, errlen, "qbvh: node %u reached twice", j);
                goto done;
            }
            seen[j] = 1;
            if (!encloses(q->bmin[i], q->bmax[i], q->bmin[j], q->bmax[j])) {
                snprintf(err, errlen, "qbvh: node %u does not enclose child %u", i, j);
                goto done;
            }
        }
    }
    if (nprim != s->ntris) {
        snprintf(err, errlen, "qbvh: %u of %u primitives in leaves", nprim, s->ntris);
        goto done;
    }
    rc = 0;
done:
    free(seen);
    free(pseen);
    return rc;
}
