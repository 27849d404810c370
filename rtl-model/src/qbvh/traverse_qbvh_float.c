/* Plain floating-point traversal of the QBVH (docs/traversal.md §13): the
 * float BVH collapsed 4-wide (cbvh_qbvh_from_bvh), what a software renderer
 * runs on SIMD hardware, not a model of the accelerator.  Boxes go through
 * the plain float traversal's conservative binary64 slab test, four lanes
 * per node (ray_box_ref.h: the same operations per box as cbvh_ref_box2, so
 * the same proof: never a false miss); triangles through the ray-triangle
 * unit, so the closest hit is the units' bit for bit. */
#include <stdio.h>
#include <stdlib.h>

#include "cbvh/qbvh.h"
#include "qbvh/traverse_wide_float.h"

_Static_assert(sizeof(cbvh_fqbvh_node) == 128, "one record per two 64-byte lines");

void cbvh_fqbvh_free(cbvh_fqbvh *f) {
    free(f->nodes);
    free(f->leaf_tris);
    memset(f, 0, sizeof *f);
}

/* Node j of q as a child entry: a record index (rec[j]) or a leaf. */
static void child_entry(const cbvh_qbvh *q, uint32_t j, const uint32_t *rec, uint32_t *entry, uint32_t *count) {
    if (q->count[j] & CBVH_QBVH_LEAF) {
        *entry = CBVH_FQBVH_LEAF | q->first[j];
        *count = q->count[j] & ~CBVH_QBVH_LEAF;
    } else {
        *entry = rec[j];
        *count = 0;
    }
}

static int fail(cbvh_fqbvh *out, uint32_t *rec, char *err, size_t errlen, const char *why, uint32_t node) {
    free(rec);
    cbvh_fqbvh_free(out);
    snprintf(err, errlen, "4-wide float layout: %s (QBVH node %u)", why, node);
    return -1;
}

int cbvh_fqbvh_build(const cbvh_qbvh *q, const cbvh_tri *tris, uint32_t ntris, cbvh_fqbvh *out, char *err,
                     size_t errlen) {
    memset(out, 0, sizeof *out);
    out->q = q;
    if (q->nnodes == 0 || q->nnodes >= CBVH_FQBVH_LEAF || q->nprims >= CBVH_FQBVH_LEAF) {
        snprintf(err, errlen, "4-wide float layout: %u nodes, %u primitives; 1 to %u supported", q->nnodes,
                 q->nprims, CBVH_FQBVH_LEAF - 1u);
        return -1;
    }
    uint32_t *rec = malloc((size_t)q->nnodes * sizeof *rec);
    if (!rec) return fail(out, rec, err, errlen, "out of memory", 0);
    /* Structure checked before anything is read through it: children after
     * their parent (so no cycle), inside the node array, leaves inside the
     * primitive array and at most 65535 primitives (the record's count). */
    uint32_t n = 0;
    for (uint32_t i = 0; i < q->nnodes; i++) {
        uint32_t c = q->count[i];
        if (c & CBVH_QBVH_LEAF) {
            c &= ~CBVH_QBVH_LEAF;
            if (c == 0 || c > 65535u || q->first[i] > q->nprims || c > q->nprims - q->first[i])
                return fail(out, rec, err, errlen, "leaf primitive range out of bounds or above 65535", i);
            continue;
        }
        if (c < 2 || c > 4 || q->first[i] <= i || q->first[i] > q->nnodes - c)
            return fail(out, rec, err, errlen, "inner node with bad children", i);
        rec[i] = n++;
    }
    out->nnodes = n;
    if (n) {
        out->nodes = aligned_alloc(64, (size_t)n * sizeof *out->nodes);
        if (!out->nodes) return fail(out, rec, err, errlen, "out of memory", 0);
        memset(out->nodes, 0, (size_t)n * sizeof *out->nodes); /* empty slots: zero planes, not valid */
    }
    int small = 1; /* every plane fits the binary32 box lanes (node 0 is the root) */
    for (uint32_t i = 0; i < q->nnodes; i++) {
        if (q->count[i] & CBVH_QBVH_LEAF) continue;
        cbvh_fqbvh_node *r = &out->nodes[rec[i]];
        for (uint32_t c = 0; c < q->count[i]; c++) {
            uint32_t j = q->first[i] + c, cnt;
            for (int a = 0; a < 3; a++) {
                r->pl[CBVH_REF4_AT(0, a, c)] = q->bmin[j][a];
                r->pl[CBVH_REF4_AT(1, a, c)] = q->bmax[j][a];
                small &= cbvh_ref32_plane_ok(q->bmin[j][a]) & cbvh_ref32_plane_ok(q->bmax[j][a]);
            }
            child_entry(q, j, rec, &r->child[c], &cnt);
            r->count[c] = (uint16_t)cnt;
            r->valid |= 1u << c;
        }
    }
    child_entry(q, 0, rec, &out->root, &out->root_count);
    for (int c = 0; c < 2; c++)
        for (int a = 0; a < 3; a++) {
            out->root_box[CBVH_REF_AT(0, a, c)] = q->bmin[0][a];
            out->root_box[CBVH_REF_AT(1, a, c)] = q->bmax[0][a];
            small &= cbvh_ref32_plane_ok(q->bmin[0][a]) & cbvh_ref32_plane_ok(q->bmax[0][a]);
        }
    out->small_planes = small;
    free(rec);
    if (!tris || q->nprims == 0) return 0;
    for (uint32_t i = 0; i < q->nprims; i++)
        if (q->prims[i] >= ntris) return 0; /* left to the traversal's reads of tris */
    out->leaf_tris = aligned_alloc(64, ((size_t)q->nprims * sizeof *out->leaf_tris + 63) / 64 * 64);
    if (!out->leaf_tris) return fail(out, NULL, err, errlen, "out of memory for the leaf copy", 0);
    for (uint32_t i = 0; i < q->nprims; i++) {
        memcpy(out->leaf_tris[i].v, tris[q->prims[i]].v, sizeof out->leaf_tris[i].v);
        out->leaf_tris[i].id = q->prims[i];
    }
    out->leaf_src = tris;
    return 0;
}

_Static_assert(sizeof(cbvh_fqbvh_node) == WIDE_REC_BYTES(4) && offsetof(cbvh_fqbvh_node, child) == WIDE_CHILD_AT(4) &&
                   offsetof(cbvh_fqbvh_node, count) == WIDE_COUNT_AT(4) &&
                   offsetof(cbvh_fqbvh_node, valid) == WIDE_VALID_AT(4) && CBVH_FQBVH_LEAF == WIDE_LEAF,
               "the 4-wide record is traverse_wide_float.h's of width 4");

int cbvh_trace_qbvh_float(const cbvh_fqbvh *f, const cbvh_tri *tris, const cbvh_ray *ray, cbvh_trav_mode mode,
                          cbvh_trav_hit *hit, cbvh_trav_stats *st) {
    const wide_tree w = {(const unsigned char *)f->nodes, f->nnodes, f->root, f->root_count,
                         f->root_box, f->leaf_tris, f->leaf_src, f->q->prims, f->q->nprims, f->small_planes};
    return wide_trace_isa(4, &w, tris, ray, mode, hit, st);
}
