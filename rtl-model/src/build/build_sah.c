/* Binned SAH builder (Wald 2007): top-down, centroid bins on all three axes,
 * C_node = 1, C_tri = 1.  Deterministic: sequential, fixed bin order, ties go
 * to the lowest axis and bin.  Nodes in pre-order, root at 0. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbvh/bvh.h"
#include "cbvh/oom.h"

typedef struct {
    float lo[3], hi[3];
} box;

static void box_empty(box *b) {
    for (int a = 0; a < 3; a++) b->lo[a] = INFINITY, b->hi[a] = -INFINITY;
}
static void box_grow(box *b, const box *o) {
    for (int a = 0; a < 3; a++) {
        if (o->lo[a] < b->lo[a]) b->lo[a] = o->lo[a];
        if (o->hi[a] > b->hi[a]) b->hi[a] = o->hi[a];
    }
}
/* Centroid binning along one axis: bin = (c - lo) * bins / extent,
 * truncated and clamped to [0, bins - 1].  In binary32, as the builder has
 * always binned, unless the scale bins / extent is not a positive finite
 * binary32: the extent overflows (centroids near +-FLT_MAX: the scale is 0)
 * or is so small that the scale overflows (subnormal extents).  Those axes
 * are binned in binary64, where every operand is finite; in binary32 the
 * product would be NaN or Inf, whose conversion to int is undefined. */
typedef struct {
    float lo, sc;
    double dlo, dsc;
    int wide; /* binary64 */
} binner;

static binner binner_make(float lo, float hi, int bins) {
    binner b = {lo, (float)bins / (hi - lo), lo, (double)bins / ((double)hi - (double)lo), 0};
    b.wide = !(b.sc > 0.0f && b.sc < INFINITY);
    return b;
}

static int bin_of(const binner *b, float c, int bins) {
    double x = b->wide ? ((double)c - b->dlo) * b->dsc : (double)((c - b->lo) * b->sc);
    return x >= (double)bins ? bins - 1 : x >= 1.0 ? (int)x : 0;
}

static double box_area(const box *b) {
    if (b->lo[0] > b->hi[0]) return 0.0;
    double dx = (double)b->hi[0] - b->lo[0], dy = (double)b->hi[1] - b->lo[1], dz = (double)b->hi[2] - b->lo[2];
    return 2.0 * (dx * dy + dy * dz + dz * dx) + 1e-30 * (dx + dy + dz); /* flat boxes still rank by size */
}

typedef struct {
    uint32_t node, begin, end;
} task;

int cbvh_build_sah(const cbvh_scene *s, int bins, int max_leaf, cbvh_bvh *out, char *err, size_t errlen) {
    memset(out, 0, sizeof *out);
    if (bins == 0) bins = 16;
    if (max_leaf == 0) max_leaf = 4;
    if (bins < 4 || bins > 64 || max_leaf < 1 || max_leaf > 64) {
        snprintf(err, errlen, "sah: bins must be 4..64 and max_leaf 1..64");
        return -1;
    }
    if (cbvh_scene_validate(s, err, errlen)) return -1;
    uint32_t n = s->ntris;
    box *tb = malloc((size_t)n * sizeof *tb);
    float(*cen)[3] = malloc((size_t)n * sizeof *cen);
    uint32_t *prims = malloc((size_t)n * sizeof *prims), *tmp = malloc((size_t)n * sizeof *tmp);
    cbvh_bvh_node *nodes = calloc(2 * (size_t)n, sizeof *nodes);
    task *stack = malloc(2 * (size_t)n * sizeof *stack);
    if (!tb || !cen || !prims || !tmp || !nodes || !stack) cbvh_out_of_memory("SAH build buffers");
    for (uint32_t i = 0; i < n; i++) {
        cbvh_tri_bounds(&s->tris[i], tb[i].lo, tb[i].hi);
        for (int a = 0; a < 3; a++) cen[i][a] = 0.5f * tb[i].lo[a] + 0.5f * tb[i].hi[a]; /* no overflow */
        prims[i] = i;
    }
    uint32_t nn = 1, sp = 0;
    stack[sp++] = (task){0, 0, n};
    while (sp) {
        task t = stack[--sp];
        cbvh_bvh_node *nd = &nodes[t.node];
        box nb, cb;
        box_empty(&nb);
        box_empty(&cb);
        for (uint32_t i = t.begin; i < t.end; i++) {
            box c = {{cen[prims[i]][0], cen[prims[i]][1], cen[prims[i]][2]},
                     {cen[prims[i]][0], cen[prims[i]][1], cen[prims[i]][2]}};
            box_grow(&nb, &tb[prims[i]]);
            box_grow(&cb, &c);
        }
        memcpy(nd->lo, nb.lo, sizeof nb.lo);
        memcpy(nd->hi, nb.hi, sizeof nb.hi);
        uint32_t cnt = t.end - t.begin;
        /* Best binned split over the three axes. */
        double best = INFINITY;
        int best_axis = -1, best_bin = 0;
        if (cnt > 1) {
            for (int a = 0; a < 3; a++) {
                float ext = cb.hi[a] - cb.lo[a];
                if (!(ext > 0.0f)) continue;
                box bb[64];
                uint32_t bc[64] = {0};
                for (int k = 0; k < bins; k++) box_empty(&bb[k]);
                binner bn = binner_make(cb.lo[a], cb.hi[a], bins);
                for (uint32_t i = t.begin; i < t.end; i++) {
                    int k = bin_of(&bn, cen[prims[i]][a], bins);
                    bc[k]++;
                    box_grow(&bb[k], &tb[prims[i]]);
                }
                double rarea[64];
                uint32_t rcnt[64];
                box acc;
                box_empty(&acc);
                uint32_t c = 0;
                for (int k = bins - 1; k > 0; k--) {
                    box_grow(&acc, &bb[k]);
                    c += bc[k];
                    rarea[k] = box_area(&acc);
                    rcnt[k] = c;
                }
                box_empty(&acc);
                c = 0;
                for (int k = 0; k < bins - 1; k++) {
                    box_grow(&acc, &bb[k]);
                    c += bc[k];
                    /* cppcheck-suppress uninitvar ; rcnt[1 .. bins-1] were set by the loop above */
                    if (c == 0 || rcnt[k + 1] == 0) continue;
                    double cost = box_area(&acc) * c + rarea[k + 1] * rcnt[k + 1];
                    if (cost < best) best = cost, best_axis = a, best_bin = k;
                }
            }
        }
        double pa = box_area(&nb);
        double split_cost = pa > 0.0 ? 1.0 + best / pa : 1.0;
        int make_leaf = cnt == 1 || (cnt <= (uint32_t)max_leaf && (best_axis < 0 || split_cost >= (double)cnt));
        uint32_t mid = 0;
        if (!make_leaf) {
            if (best_axis >= 0) {
                /* Stable partition by bin. */
                binner bn = binner_make(cb.lo[best_axis], cb.hi[best_axis], bins);
                uint32_t l = t.begin, r = 0;
                for (uint32_t i = t.begin; i < t.end; i++) {
                    int k = bin_of(&bn, cen[prims[i]][best_axis], bins);
                    if (k <= best_bin)
                        prims[l++] = prims[i];
                    else
                        tmp[r++] = prims[i];
                }
                memcpy(prims + l, tmp, (size_t)r * sizeof *prims);
                mid = l;
            } else {
                mid = t.begin + cnt / 2; /* coincident centroids: split the list */
            }
        }
        if (make_leaf) {
            nd->first = t.begin;
            nd->count = cnt;
            continue;
        }
        nd->child[0] = nn;
        nd->child[1] = nn + 1;
        nn += 2;
        stack[sp++] = (task){nd->child[1], mid, t.end};
        stack[sp++] = (task){nd->child[0], t.begin, mid};
    }
    free(tb);
    free(cen);
    free(tmp);
    free(stack);
    /* Shrink to the nodes used; if the smaller block cannot be had, keep the
     * larger one (realloc left it untouched). */
    cbvh_bvh_node *shrunk = realloc(nodes, (size_t)nn * sizeof *nodes);
    out->nodes = shrunk ? shrunk : nodes;
    out->nnodes = nn;
    out->root = 0;
    out->prims = prims;
    out->nprims = n;
    return 0;
}
