/* Refit of the QBVH's own boxes for moved vertices (docs/qbvh.md §3): the
 * topology is kept (no re-collapse), every box recomputed bottom-up, as
 * cbvh_bvh_refit does for the binary BVH (rtl-model/src/build/refit.c). */
#include <math.h>
#include <stdio.h>

#include "cbvh/qbvh.h"

int cbvh_qbvh_refit_check(const cbvh_qbvh *q, char *err, size_t errlen) {
    for (uint32_t i = 0; i < q->nnodes; i++)
        if (!(q->count[i] & CBVH_QBVH_LEAF) && q->first[i] <= i) {
            snprintf(err, errlen, "qbvh: a child group lies before its parent (layout not breadth-first)");
            return -1;
        }
    return 0;
}

uint64_t cbvh_qbvh_refit(cbvh_qbvh *q, const cbvh_tri *tris) {
    for (uint32_t i = q->nnodes; i-- > 0;) {
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        uint32_t c = q->count[i], f = q->first[i];
        if (c & CBVH_QBVH_LEAF) {
            for (uint32_t k = 0; k < (c & ~CBVH_QBVH_LEAF); k++)
                for (int v = 0; v < 3; v++)
                    for (int a = 0; a < 3; a++) {
                        float x = tris[q->prims[f + k]].v[v][a];
                        lo[a] = fminf(lo[a], x);
                        hi[a] = fmaxf(hi[a], x);
                    }
        } else
            for (uint32_t k = 0; k < c; k++)
                for (int a = 0; a < 3; a++) {
                    lo[a] = fminf(lo[a], q->bmin[f + k][a]);
                    hi[a] = fmaxf(hi[a], q->bmax[f + k][a]);
                }
        for (int a = 0; a < 3; a++) {
            q->bmin[i][a] = lo[a];
            q->bmax[i][a] = hi[a];
        }
    }
    return q->nnodes;
}
