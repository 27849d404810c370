/* QBVH traversal (seed 000) with the compressed stack unit (docs/qbvh.md §4).
 * Boxes: the ray-box unit on float bounds (the prepared entry point that
 * traverse_bvh.c uses, so rays/s compare like for like); triangles: the
 * ray-triangle unit; hit acceptance and box culling shared with the binary
 * traversals (traverse_common.h, docs/traversal.md §5). */
#include <stdio.h>
#include <string.h>

#include "cbvh/qbvh.h"
#include "traverse/traverse_common.h"

static int box(trav_state *qs, const cbvh_qbvh *q, uint32_t i, cbvh_box_result *r) {
    cbvh_f32 lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = cbvh_f32_of(q->bmin[i][a]);
        hi[a] = cbvh_f32_of(q->bmax[i][a]);
    }
    qs->s.box_tests++;
    return cbvh_ray_box_float_prep(&qs->prep, trav_box_tmax(qs), qs->M, lo, hi, r) == 0 && r->hit;
}

int cbvh_qbvh_stack_check(const cbvh_qbvh *q, cbvh_qstack_kind kind, char *err, size_t errlen) {
    if (kind == CBVH_QSTACK_COMPRESSED && q->max_first >= CBVH_QSTACK_ID_LIMIT) {
        snprintf(err, errlen,
                 "qbvh: first-child ID %u does not fit the 26-bit stack entry (limit %u); use the wide entry",
                 q->max_first, CBVH_QSTACK_ID_LIMIT - 1u);
        return -1;
    }
    if (kind < CBVH_QSTACK_AUTO || kind > CBVH_QSTACK_PLAIN) {
        snprintf(err, errlen, "qbvh: unknown stack kind %d", (int)kind);
        return -1;
    }
    return 0;
}

int cbvh_trace_qbvh(const cbvh_qbvh *q, const cbvh_tri *tris, const cbvh_ray *ray, int mant_bits,
                    cbvh_trav_mode mode, cbvh_qstack_kind kind, cbvh_trav_hit *hit, cbvh_trav_stats *st) {
    memset(hit, 0, sizeof *hit);
    char err[160];
    if (cbvh_qbvh_stack_check(q, kind, err, sizeof err)) return -1;
    if (kind == CBVH_QSTACK_AUTO) kind = q->max_first < CBVH_QSTACK_ID_LIMIT ? CBVH_QSTACK_COMPRESSED : CBVH_QSTACK_WIDE;
    trav_state qs;
    memset(&qs, 0, sizeof qs);
    {
        cbvh_f32 z[3] = {0, 0, 0};
        cbvh_box_result r;
        cbvh_rb_prepare(ray, &qs.prep);
        if (cbvh_ray_box_float_prep(&qs.prep, ray->tmax, mant_bits, z, z, &r) != 0) return -1;
    }
    trav_set_ray(&qs, ray);
    qs.tris = tris;
    qs.mode = mode;
    qs.M = mant_bits;
    /* Memory image of the counters: bmin (16 B/node), bmax (16 B/node), info
     * (8 B/node), IDs, triangles.  The observer sees a node as hardware would
     * store it (docs/qbvh.md §3): its children's boxes and info words side by
     * side, 32 B per child, in a 128-byte record at first-child index x 128
     * (one line for up to two children, two for three or four); the IDs and
     * triangles after the records.  Moving a line-aligned region does not
     * change the line counts. */
    const uint64_t bmin_base = 0, bmax_base = trav_align((uint64_t)q->nnodes * 16u),
                   info_base = bmax_base + trav_align((uint64_t)q->nnodes * 16u);
    qs.ids_base = trav_align((uint64_t)q->nnodes * 128u);
    qs.tris_base = trav_align(qs.ids_base + (uint64_t)q->nprims * 4u);

    uint32_t s32[CBVH_TRAV_STACK];
    uint64_t s64[CBVH_TRAV_STACK];
    int head = 0; /* entries on the stack */
    cbvh_box_result r;
    int rc = 0;
    if (!box(&qs, q, 0, &r)) goto finish;
    uint32_t node = 0;
    for (;;) {
        uint32_t cnt = q->count[node];
        int go = 0; /* a child to descend into */
        if (!(cnt & CBVH_QBVH_LEAF)) {
            uint32_t f = q->first[node];
            if (qs.s.nodes >= q->nnodes) { /* each node is visited at most once: a cycle */
                rc = -1;
                goto finish;
            }
            qs.s.nodes++;
            trav_observe(&qs, CBVH_FETCH_NODE, (uint64_t)f * 128u, (uint64_t)cnt * 32u);
            qs.s.lines += cbvh_lines_touched(bmin_base + (uint64_t)f * 16u, (uint64_t)cnt * 16u) +
                          cbvh_lines_touched(bmax_base + (uint64_t)f * 16u, (uint64_t)cnt * 16u) +
                          cbvh_lines_touched(info_base + (uint64_t)f * 8u, (uint64_t)cnt * 8u);
            uint32_t t[4] = {0, 0, 0, 0}, mask = 0;
            for (uint32_t c = 0; c < cnt; c++) {
                cbvh_box_result cr;
                if (box(&qs, q, f + c, &cr)) {
                    mask |= 1u << c;
                    t[c] = cr.t_near;
                }
            }
            uint8_t order[4];
            int nhit;
            cbvh_qstack_sort(t, mask, order, &nhit);
            qs.s.qstack_pushes++;
            if (nhit >= 2) {
                if (head == CBVH_TRAV_STACK) {
                    rc = -1;
                    goto finish;
                }
                if (kind == CBVH_QSTACK_COMPRESSED) {
                    if (cbvh_qstack_push(f, order, nhit, &s32[head])) {
                        rc = -1;
                        goto finish;
                    }
                    head++;
                } else if (kind == CBVH_QSTACK_WIDE) {
                    s64[head++] = cbvh_qstack_push_wide(f, order, nhit);
                } else { /* plain: one entry per deferred child, farthest deepest */
                    if (head + nhit - 1 > CBVH_TRAV_STACK) {
                        rc = -1;
                        goto finish;
                    }
                    for (int k = nhit - 1; k >= 1; k--) s32[head++] = f + order[k];
                }
                if ((uint32_t)head > qs.s.max_stack) qs.s.max_stack = (uint32_t)head;
            }
            if (nhit >= 1) {
                node = f + order[0];
                go = 1;
            }
        } else {
            uint32_t c = cnt & ~CBVH_QBVH_LEAF, p = q->first[node];
            trav_fetch(&qs, CBVH_FETCH_IDS, qs.ids_base + (uint64_t)p * 4u, (uint64_t)c * 4u);
            for (uint32_t i = 0; i < c && !qs.done; i++) trav_triangle(&qs, q->prims[p + i]);
            if (qs.done) break;
        }
        if (go) continue;
        if (head == 0) break;
        qs.s.qstack_pops++;
        if (kind == CBVH_QSTACK_COMPRESSED) {
            uint32_t next;
            int keep;
            cbvh_qstack_pop(s32[head - 1], &node, &next, &keep);
            if (keep) s32[head - 1] = next;
            else head--;
        } else if (kind == CBVH_QSTACK_WIDE) {
            uint64_t next;
            int keep;
            node = cbvh_qstack_pop_wide(s64[head - 1], &next, &keep);
            if (keep) s64[head - 1] = next;
            else head--;
        } else {
            node = s32[--head];
        }
    }
finish:
    *hit = qs.best;
    if (rc) memset(hit, 0, sizeof *hit);
    st->nodes += qs.s.nodes;
    st->box_tests += qs.s.box_tests;
    st->tri_tests += qs.s.tri_tests;
    st->lines += qs.s.lines;
    st->bytes += qs.s.lines * CBVH_LINE_BYTES;
    if (qs.s.max_stack > st->max_stack) st->max_stack = qs.s.max_stack;
    st->qstack_pushes += qs.s.qstack_pushes;
    st->qstack_pops += qs.s.qstack_pops;
    return rc;
}
