/* The float BVH collapsed 8-wide (docs/traversal.md §14): the layout the
 * 8-wide plain float traversal reads (traverse_f8bvh_float.c). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/f8bvh.h"
#include "qbvh/collapse.h"
#include "fast/ray_box_ref.h"

_Static_assert(sizeof(cbvh_f8bvh_node) == 256, "one record per four 64-byte lines");

void cbvh_f8bvh_free(cbvh_f8bvh *f) {
    free(f->nodes);
    free(f->leaf_tris);
    memset(f, 0, sizeof *f);
}

static int fail(cbvh_f8bvh *out, uint32_t *src, uint8_t *seen, char *err, size_t errlen, const char *why,
                uint32_t node) {
    free(src);
    free(seen);
    cbvh_f8bvh_free(out);
    snprintf(err, errlen, "8-wide float layout: %s (binary node %u)", why, node);
    return -1;
}

/* Leaf k of b checked: inside the primitive array, at most 65535 primitives. */
static int leaf_ok(const cbvh_bvh *b, uint32_t k) {
    const cbvh_bvh_node *n = &b->nodes[k];
    return n->count <= CBVH_F8BVH_MAX_LEAF && n->first <= b->nprims && n->count <= b->nprims - n->first;
}

int cbvh_f8bvh_build(const cbvh_bvh *b, const cbvh_tri *tris, uint32_t ntris, cbvh_f8bvh *out, char *err,
                     size_t errlen) {
    memset(out, 0, sizeof *out);
    if (b->nnodes == 0 || b->root >= b->nnodes || b->nnodes >= CBVH_F8BVH_LEAF || b->nprims >= CBVH_F8BVH_LEAF) {
        snprintf(err, errlen, "8-wide float layout: %u nodes (root %u), %u primitives; 1 to %u supported", b->nnodes,
                 b->root, b->nprims, CBVH_F8BVH_LEAF - 1u);
        return -1;
    }
    out->prims = b->prims;
    out->nprims = b->nprims;
    const cbvh_bvh_node *rt = &b->nodes[b->root];
    for (int c = 0; c < 2; c++)
        for (int a = 0; a < 3; a++) {
            out->root_box[CBVH_REF_AT(0, a, c)] = rt->lo[a];
            out->root_box[CBVH_REF_AT(1, a, c)] = rt->hi[a];
        }
    if (cbvh_bvh_is_leaf(rt)) {
        if (!leaf_ok(b, b->root))
            return fail(out, NULL, NULL, err, errlen, "leaf primitive range out of bounds or above 65535", b->root);
        out->root = CBVH_F8BVH_LEAF | rt->first;
        out->root_count = rt->count;
    }
    /* Pass 1: records in depth-first order (a record's first inner child
     * right after it, so a ray's way down tends to stay on nearby lines),
     * src = the binary node of each record, rec = the record of each inner
     * binary node; the structure checked on the way. */
    uint32_t nrec = 0, *src = NULL, *rec = NULL;
    uint8_t *seen = NULL;
    if (!cbvh_bvh_is_leaf(rt)) {
        src = malloc((size_t)b->nnodes * sizeof *src);
        rec = malloc((size_t)b->nnodes * sizeof *rec);
        seen = calloc(b->nnodes, 1);
        uint32_t *todo = malloc((size_t)b->nnodes * sizeof *todo), ntodo = 0;
        if (!src || !rec || !seen || !todo) {
            free(todo);
            free(rec);
            return fail(out, src, seen, err, errlen, "out of memory", 0);
        }
        seen[b->root] = 1;
        todo[ntodo++] = b->root;
        while (ntodo) {
            uint32_t k = todo[--ntodo], ch[8];
            rec[k] = nrec;
            src[nrec++] = k;
            int m = cbvh_collapse_gather(b, k, 8, ch, seen);
            const char *why = m < 0 ? "child outside the BVH or reached twice" : NULL;
            for (int c = m - 1; c >= 0 && !why; c--) {
                if (!cbvh_bvh_is_leaf(&b->nodes[ch[c]])) todo[ntodo++] = ch[c]; /* each node once: < nnodes */
                else if (!leaf_ok(b, ch[c])) why = "leaf primitive range out of bounds or above 65535";
            }
            if (why) {
                free(todo);
                free(rec);
                return fail(out, src, seen, err, errlen, why, k);
            }
        }
        free(todo);
        free(seen);
        seen = NULL;
        out->nodes = aligned_alloc(64, (size_t)nrec * sizeof *out->nodes);
        if (!out->nodes) {
            free(rec);
            return fail(out, src, seen, err, errlen, "out of memory", 0);
        }
        memset(out->nodes, 0, (size_t)nrec * sizeof *out->nodes); /* empty slots: zero planes, not valid */
    }
    out->nnodes = nrec;
    /* Pass 2: the records (the same gather); small: every plane fits the
     * binary32 box lanes (the root's too). */
    int small = 1;
    for (int a = 0; a < 3; a++) small &= cbvh_ref32_plane_ok(rt->lo[a]) & cbvh_ref32_plane_ok(rt->hi[a]);
    for (uint32_t i = 0; i < nrec; i++) {
        cbvh_f8bvh_node *r = &out->nodes[i];
        uint32_t ch[8];
        int m = cbvh_collapse_gather(b, src[i], 8, ch, NULL);
        for (int c = 0; c < m; c++) {
            const cbvh_bvh_node *n = &b->nodes[ch[c]];
            for (int a = 0; a < 3; a++) {
                r->pl[(0 * 3 + a) * 8 + c] = n->lo[a];
                r->pl[(1 * 3 + a) * 8 + c] = n->hi[a];
                small &= cbvh_ref32_plane_ok(n->lo[a]) & cbvh_ref32_plane_ok(n->hi[a]);
            }
            r->child[c] = cbvh_bvh_is_leaf(n) ? CBVH_F8BVH_LEAF | n->first : rec[ch[c]];
            r->count[c] = (uint16_t)n->count;
            r->valid |= 1u << c;
        }
    }
    free(rec);
    free(src);
    out->small_planes = small;
    if (!tris || b->nprims == 0) return 0;
    for (uint32_t i = 0; i < b->nprims; i++)
        if (b->prims[i] >= ntris) return 0; /* left to the traversal's reads of tris */
    out->leaf_tris = aligned_alloc(64, ((size_t)b->nprims * sizeof *out->leaf_tris + 63) / 64 * 64);
    if (!out->leaf_tris) return fail(out, NULL, NULL, err, errlen, "out of memory for the leaf copy", 0);
    for (uint32_t i = 0; i < b->nprims; i++) {
        memcpy(out->leaf_tris[i].v, tris[b->prims[i]].v, sizeof out->leaf_tris[i].v);
        out->leaf_tris[i].id = b->prims[i];
    }
    out->leaf_src = tris;
    return 0;
}
