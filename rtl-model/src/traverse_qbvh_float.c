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
#include "ray_box_ref.h"
#include "traverse_common.h"
#include "traverse_plain.h"

_Static_assert(sizeof(cbvh_fqbvh_node) == 128, "one record per two 64-byte lines");

/* bits set in a 4-bit mask (the x86-64 baseline has no popcount
 * instruction), its lowest and highest set bit */
static const uint8_t ones4[16] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};
static const uint8_t low4[16] = {0, 0, 1, 0, 2, 0, 1, 0, 3, 0, 1, 0, 2, 0, 1, 0};
static const uint8_t high4[16] = {0, 0, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3, 3, 3, 3, 3};

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
    for (uint32_t i = 0; i < q->nnodes; i++) {
        if (q->count[i] & CBVH_QBVH_LEAF) continue;
        cbvh_fqbvh_node *r = &out->nodes[rec[i]];
        for (uint32_t c = 0; c < q->count[i]; c++) {
            uint32_t j = q->first[i] + c, cnt;
            for (int a = 0; a < 3; a++) {
                r->pl[CBVH_REF4_AT(0, a, c)] = q->bmin[j][a];
                r->pl[CBVH_REF4_AT(1, a, c)] = q->bmax[j][a];
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
        }
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

int cbvh_trace_qbvh_float(const cbvh_fqbvh *f, const cbvh_tri *tris, const cbvh_ray *ray, cbvh_trav_mode mode,
                          cbvh_trav_hit *hit, cbvh_trav_stats *st) {
    const cbvh_qbvh *q = f->q;
    trav_state ts;
    if (trav_begin(&ts, hit, ray, CBVH_MANT_MAX, tris, mode, (uint64_t)f->nnodes * sizeof(cbvh_fqbvh_node),
                   q->nprims))
        return -1;
    cbvh_ref_ray r;
    cbvh_ref_prepare(ray, &r);
    const cbvh_cbvh_dtri *lt = f->leaf_tris && f->leaf_src == tris ? f->leaf_tris : NULL;
    plain_entry stack[CBVH_TRAV_STACK];
    int sp = 0;
    uint32_t max_stack = 0;
    uint64_t nodes = 0, boxes = 0;
    double cull;
    int have = plain_root(&ts, &r, f->root_box, &cull);
    double tl[4];
    /* As in cbvh_trace_bvh_float: the nearest hit child is visited next
     * without a push, the others pushed farthest first; max_stack counts
     * the visited entry. */
    uint32_t e = f->root, cnt = f->root_count;
    if (have) max_stack = 1;
    while (have) {
        if (e & CBVH_FQBVH_LEAF) {
            uint32_t first = e & ~CBVH_FQBVH_LEAF;
            trav_fetch(&ts, ts.ids_base + (uint64_t)first * 4u, (uint64_t)cnt * 4u);
            if (lt) {
                for (uint32_t i = 0; i < cnt && !ts.done; i++)
                    trav_triangle_v(&ts, lt[first + i].id, (const cbvh_f32(*)[3])lt[first + i].v);
            } else {
                for (uint32_t i = 0; i < cnt && !ts.done; i++) trav_triangle(&ts, q->prims[first + i]);
            }
            if (ts.done) break;
            cull = cbvh_float_of(trav_box_tmax(&ts));
        } else {
            const cbvh_fqbvh_node *n = &f->nodes[e];
            nodes++;
            boxes += ones4[n->valid & 15u];
            int m;
            if (r.general) {
                int hh[4];
                cbvh_ref_boxw_any(&r, n->pl, 4, cull, hh, tl);
                m = hh[0] | hh[1] << 1 | hh[2] << 2 | hh[3] << 3;
            } else {
                m = cbvh_ref_box4(&r, n->pl, cull, tl);
            }
            m &= (int)n->valid;
            if (m) {
                int nh = ones4[m], next;
                if (sp + nh > CBVH_TRAV_STACK) return -1;
                if (nh == 1) {
                    next = low4[m];
                } else if (nh == 2) { /* the common case: one comparison (ties: the lower slot first) */
                    int a = low4[m], b = high4[m];
                    if (tl[b] < tl[a]) {
                        next = b;
                        b = a;
                    } else {
                        next = a;
                    }
                    plain_push(stack, &sp, n->child[b], n->count[b], tl[b]);
                    if (!(n->child[b] & CBVH_FQBVH_LEAF)) __builtin_prefetch(&f->nodes[n->child[b]]);
                } else { /* hit children by t_lo, ties by slot: push all but the nearest, farthest first */
                    int ord[4] = {0, 0, 0, 0}, k = 0;
                    for (int c = 0; c < 4; c++) {
                        if (!(m >> c & 1)) continue;
                        int j = k++;
                        while (j > 0 && tl[ord[j - 1]] > tl[c]) {
                            ord[j] = ord[j - 1];
                            j--;
                        }
                        ord[j] = c;
                    }
                    for (int j = k - 1; j > 0; j--) {
                        int c = ord[j];
                        plain_push(stack, &sp, n->child[c], n->count[c], tl[c]);
                        if (!(n->child[c] & CBVH_FQBVH_LEAF)) __builtin_prefetch(&f->nodes[n->child[c]]);
                    }
                    next = ord[0];
                }
                if ((uint32_t)sp + 1u > max_stack) max_stack = (uint32_t)sp + 1u;
                /* the pop's cull check (rounding can leave t_lo just above cull) */
                if (!(tl[next] > cull)) {
                    e = n->child[next];
                    cnt = n->count[next];
                    continue;
                }
            }
        }
        have = plain_pop(stack, &sp, cull, &e, &cnt);
    }
    ts.s.nodes += nodes;
    ts.s.box_tests += boxes;
    ts.s.lines += 2 * nodes;
    ts.s.max_stack = max_stack;
    trav_finish(&ts, hit, st);
    return 0;
}
