/* Float BVH helpers shared by the builders: traversal order, SAH cost, checks. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/bvh.h"
#include "cbvh/oom.h"

/* The out-of-memory report (cbvh/oom.h) lives here, in libcbvh_build, the
 * lowest library that allocates; libcbvh proper (the units, also built for
 * the firmware) never does. */
static cbvh_oom_handler oom_handler;

cbvh_oom_handler cbvh_set_oom_handler(cbvh_oom_handler h) {
    cbvh_oom_handler old = oom_handler;
    oom_handler = h;
    return old;
}

_Noreturn void cbvh_out_of_memory(const char *what) {
    if (oom_handler) oom_handler(what);
    /* stderr is unbuffered: this line needs no allocation */
    fprintf(stderr, "cbvh: out of memory (%s)\n", what);
    abort();
}

void cbvh_bvh_free(cbvh_bvh *b) {
    free(b->nodes);
    free(b->prims);
    memset(b, 0, sizeof *b);
}

void cbvh_bvh_postorder(const cbvh_bvh *b, uint32_t *order) {
    /* Explicit stack of (node, children-pushed flag); depth <= nnodes. */
    uint32_t *stack = malloc(((size_t)b->nnodes + 1) * sizeof *stack);
    uint32_t sp = 0, n = 0;
    if (!stack) cbvh_out_of_memory("post-order stack");
    stack[sp++] = b->root << 1;
    while (sp) {
        uint32_t e = stack[--sp], i = e >> 1;
        const cbvh_bvh_node *nd = &b->nodes[i];
        if (cbvh_bvh_is_leaf(nd) || (e & 1u)) {
            order[n++] = i;
            continue;
        }
        stack[sp++] = e | 1u;
        stack[sp++] = nd->child[1] << 1;
        stack[sp++] = nd->child[0] << 1;
    }
    free(stack);
}

void cbvh_bvh_counts(const cbvh_bvh *b, uint32_t *leaves, uint32_t *inner) {
    uint32_t l = 0;
    for (uint32_t i = 0; i < b->nnodes; i++) l += cbvh_bvh_is_leaf(&b->nodes[i]) != 0;
    *leaves = l;
    *inner = b->nnodes - l;
}

static double area(const float lo[3], const float hi[3]) {
    double dx = (double)hi[0] - lo[0], dy = (double)hi[1] - lo[1], dz = (double)hi[2] - lo[2];
    return 2.0 * (dx * dy + dy * dz + dz * dx);
}

static double half_perimeter(const float lo[3], const float hi[3]) {
    return ((double)hi[0] - lo[0]) + ((double)hi[1] - lo[1]) + ((double)hi[2] - lo[2]);
}

double cbvh_bvh_sah(const cbvh_bvh *b) {
    const cbvh_bvh_node *r = &b->nodes[b->root];
    int degenerate = !(area(r->lo, r->hi) > 0.0);
    double ar = degenerate ? half_perimeter(r->lo, r->hi) : area(r->lo, r->hi);
    if (!(ar > 0.0)) return 0.0;
    double cost = 0.0;
    for (uint32_t i = 0; i < b->nnodes; i++) {
        const cbvh_bvh_node *n = &b->nodes[i];
        double a = degenerate ? half_perimeter(n->lo, n->hi) : area(n->lo, n->hi);
        cost += (cbvh_bvh_is_leaf(n) ? (double)n->count : 1.0) * a / ar;
    }
    return cost;
}

int cbvh_bvh_check(const cbvh_bvh *b, const cbvh_scene *s, char *err, size_t errlen) {
    if (b->root >= b->nnodes || b->nprims != s->ntris) {
        snprintf(err, errlen, "bvh: bad root or primitive count");
        return -1;
    }
    uint8_t *seen = calloc(b->nnodes, 1), *pseen = calloc(b->nprims, 1);
    uint32_t *stack = malloc(((size_t)b->nnodes + 1) * sizeof *stack);
    int rc = -1;
    uint32_t sp = 0, visited = 0, prims = 0;
    if (!seen || !pseen || !stack) cbvh_out_of_memory("BVH check buffers");
    stack[sp++] = b->root;
    while (sp) {
        uint32_t i = stack[--sp];
        if (i >= b->nnodes || seen[i]) {
            snprintf(err, errlen, "bvh: node %u out of range or reached twice", i);
            goto out;
        }
        seen[i] = 1;
        visited++;
        const cbvh_bvh_node *n = &b->nodes[i];
        if (cbvh_bvh_is_leaf(n)) {
            if ((uint64_t)n->first + n->count > b->nprims) {
                snprintf(err, errlen, "bvh: leaf %u range out of bounds", i);
                goto out;
            }
            for (uint32_t j = 0; j < n->count; j++) {
                uint32_t p = b->prims[n->first + j];
                float lo[3], hi[3];
                if (p >= b->nprims || pseen[p]) {
                    snprintf(err, errlen, "bvh: primitive %u missing or in two leaves", p);
                    goto out;
                }
                pseen[p] = 1;
                prims++;
                cbvh_tri_bounds(&s->tris[p], lo, hi);
                for (int a = 0; a < 3; a++)
                    if (!(n->lo[a] <= lo[a] && hi[a] <= n->hi[a])) { /* NaN boxes fail too */
                        snprintf(err, errlen, "bvh: leaf %u does not enclose triangle %u", i, p);
                        goto out;
                    }
            }
        } else {
            for (int c = 0; c < 2; c++) {
                const cbvh_bvh_node *ch = &b->nodes[n->child[c] < b->nnodes ? n->child[c] : i];
                for (int a = 0; a < 3; a++)
                    if (!(n->lo[a] <= ch->lo[a] && ch->hi[a] <= n->hi[a])) {
                        snprintf(err, errlen, "bvh: node %u does not enclose child %u", i, n->child[c]);
                        goto out;
                    }
                stack[sp++] = n->child[c];
            }
        }
    }
    if (visited != b->nnodes || prims != b->nprims) {
        snprintf(err, errlen, "bvh: %u of %u nodes and %u of %u primitives reachable", visited, b->nnodes, prims,
                 b->nprims);
        goto out;
    }
    rc = 0;
out:
    free(seen);
    free(pseen);
    free(stack);
    return rc;
}
