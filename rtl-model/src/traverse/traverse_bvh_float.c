/* Plain floating-point traversal over the float BVH (docs/traversal.md §11):
 * what a software renderer does, not a model of the accelerator's box unit.
 * Boxes are tested with a conservative binary64 slab test (ray_box_ref.h:
 * every rounding error bounded, never a false miss), triangles with the
 * ray-triangle unit, so its hits are the units' hits bit for bit. */
#include <stdio.h>
#include <stdlib.h>

#include "fast/ray_box_ref.h"
#include "traverse/traverse_common.h"
#include "traverse/traverse_plain.h"

_Static_assert(sizeof(cbvh_fbvh_node) == 64, "one record per 64-byte line");

static void set_box(float box[12], int c, const cbvh_bvh_node *n) {
    for (int a = 0; a < 3; a++) {
        box[CBVH_REF_AT(0, a, c)] = n->lo[a];
        box[CBVH_REF_AT(1, a, c)] = n->hi[a];
    }
}

/* A child's entry: its record, or for a leaf CBVH_FBVH_LEAF | first and its
 * count. */
static void set_child(cbvh_fbvh_node *r, int c, const cbvh_bvh *b, uint32_t node, const uint32_t *rec) {
    const cbvh_bvh_node *n = &b->nodes[node];
    r->child[c] = cbvh_bvh_is_leaf(n) ? CBVH_FBVH_LEAF | n->first : rec[node];
    r->count[c] = n->count; /* 0 for an inner node */
}

int cbvh_fbvh_build(const cbvh_bvh *b, cbvh_fbvh *out, char *err, size_t errlen) {
    memset(out, 0, sizeof *out);
    out->bvh = b;
    if (b->nnodes >= CBVH_FBVH_LEAF || b->nprims >= CBVH_FBVH_LEAF) {
        snprintf(err, errlen, "float BVH: %u nodes, %u primitives; at most %u supported", b->nnodes, b->nprims,
                 CBVH_FBVH_LEAF - 1u);
        return -1;
    }
    uint32_t *rec = malloc((size_t)b->nnodes * sizeof *rec);
    uint32_t *stack = malloc(((size_t)b->nnodes + 1) * sizeof *stack);
    size_t bytes = ((size_t)b->nnodes * sizeof(cbvh_fbvh_node) + 63u) / 64u * 64u;
    out->nodes = aligned_alloc(64, bytes ? bytes : 64);
    if (!rec || !stack || !out->nodes) {
        free(rec);
        free(stack);
        cbvh_fbvh_free(out);
        snprintf(err, errlen, "float BVH layout: out of memory (%u nodes)", b->nnodes);
        return -1;
    }
    /* record numbers in depth-first order (child 0 first); a tree has at
     * most nnodes reachable nodes, so more visits mean a cycle or sharing */
    uint32_t sp = 0, n = 0, visits = 0;
    stack[sp++] = b->root;
    while (sp) {
        uint32_t i = stack[--sp];
        if (i >= b->nnodes || ++visits > b->nnodes) {
            free(rec);
            free(stack);
            cbvh_fbvh_free(out);
            snprintf(err, errlen, "float BVH: not a tree (node %u out of range or reached twice)", i);
            return -1;
        }
        const cbvh_bvh_node *nd = &b->nodes[i];
        if (cbvh_bvh_is_leaf(nd)) continue;
        rec[i] = n++;
        stack[sp++] = nd->child[1];
        stack[sp++] = nd->child[0];
    }
    out->nnodes = n;
    sp = 0;
    stack[sp++] = b->root;
    while (sp) {
        uint32_t i = stack[--sp];
        const cbvh_bvh_node *nd = &b->nodes[i];
        if (cbvh_bvh_is_leaf(nd)) continue;
        cbvh_fbvh_node *r = &out->nodes[rec[i]];
        for (int c = 0; c < 2; c++) {
            set_box(r->box, c, &b->nodes[nd->child[c]]);
            set_child(r, c, b, nd->child[c], rec);
        }
        stack[sp++] = nd->child[1];
        stack[sp++] = nd->child[0];
    }
    cbvh_fbvh_node root;
    set_child(&root, 0, b, b->root, rec);
    out->root = root.child[0];
    out->root_count = root.count[0];
    set_box(out->root_box, 0, &b->nodes[b->root]);
    set_box(out->root_box, 1, &b->nodes[b->root]);

    free(rec);
    free(stack);
    return 0;
}

void cbvh_fbvh_free(cbvh_fbvh *f) {
    free(f->nodes);
    memset(f, 0, sizeof *f);
}

int cbvh_trace_bvh_float(const cbvh_fbvh *f, const cbvh_tri *tris, const cbvh_ray *ray, cbvh_trav_mode mode,
                         cbvh_trav_hit *hit, cbvh_trav_stats *st) {
    const cbvh_bvh *b = f->bvh;
    trav_state ts;
    /* the float BVH's memory image (§5), whatever layout is read */
    if (trav_begin(&ts, hit, ray, CBVH_MANT_MAX, tris, mode, (uint64_t)b->nnodes * 64u, b->nprims)) return -1;
    cbvh_ref_ray r;
    cbvh_ref_prepare(ray, &r);

    /* the stack holds child entries as in the records: a record index, or
     * CBVH_FBVH_LEAF | first and the count */
    plain_entry stack[CBVH_TRAV_STACK];
    int sp = 0;
    uint32_t max_stack = 0;
    uint64_t nodes = 0;
    double cull;
    int have = plain_root(&ts, &r, f->root_box, &cull);
    int h[2];
    double tl[2];
    /* the node being visited is kept out of the stack (e, cnt): a node's
     * nearer hit child is visited next without a push and a pop, the farther
     * one pushed.  Visiting order, culling and max_stack are those of pushing
     * both (farther first) and popping: max_stack counts the visited entry. */
    uint32_t e = f->root, cnt = f->root_count;
    if (have) max_stack = 1;
    while (have) {
        if (e & CBVH_FBVH_LEAF) {
            if (plain_leaf(&ts, e & ~CBVH_FBVH_LEAF, cnt, NULL, b->prims, &cull)) break;
        } else {
            const cbvh_fbvh_node *n = &f->nodes[e];
            nodes++; /* in the float BVH's image one 64-byte line, and two box tests */
            cbvh_ref_box2_for(&r, n->box, cull, h, tl);
            if (sp + h[0] + h[1] > CBVH_TRAV_STACK) return -1;
            int next = -1; /* the child visited next, if any */
            if (h[0] & h[1]) { /* push the farther (ties: child 1), visit the nearer */
                int far = tl[1] < tl[0] ? 0 : 1;
                plain_push(stack, &sp, n->child[far], n->count[far], tl[far]);
                next = far ^ 1;
            } else if (h[0] | h[1]) {
                next = h[1];
            }
            if (next >= 0) {
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
    plain_finish(&ts, nodes, 2 * nodes, nodes, max_stack, hit, st);
    return 0;
}
