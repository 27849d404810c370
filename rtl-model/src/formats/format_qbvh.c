/* Format "qbvh": the binned-SAH float BVH collapsed to 4-ary (docs/qbvh.md
 * §3) and traversed with the compressed 32-bit stack (cbvh_trace_qbvh,
 * CBVH_QSTACK_COMPRESSED).  Refit: the QBVH's own boxes bottom-up, topology
 * kept (cbvh_qbvh_refit). */
#include <stdio.h>
#include <stdlib.h>

#include "cbvh/bvh.h"
#include "cbvh/format.h"
#include "cbvh/oom.h"
#include "cbvh/qbvh.h"

typedef struct {
    cbvh_qbvh q;
    int mant;
} state;

static void describe(const cbvh_format_params *p, char *out, size_t n) {
    snprintf(out, n, "4-ary, compressed 32-bit stack, M=%d", p->mant);
}

static int build(const cbvh_format_input *in, void **st, cbvh_unit_activity *u, char *err, size_t errlen) {
    (void)u;
    cbvh_bvh bvh;
    if (cbvh_build_sah(in->scene, 0, 0, &bvh, err, errlen)) return -1;
    state *s = calloc(1, sizeof *s);
    if (!s) cbvh_out_of_memory("format state");
    s->mant = in->p.mant;
    int rc = cbvh_qbvh_from_bvh(&bvh, &s->q, err, errlen); /* the QBVH keeps its own primitive IDs */
    cbvh_bvh_free(&bvh);
    if (rc) {
        free(s);
        return -1;
    }
    if (cbvh_qbvh_stack_check(&s->q, CBVH_QSTACK_COMPRESSED, err, errlen) ||
        cbvh_qbvh_refit_check(&s->q, err, errlen)) {
        cbvh_qbvh_free(&s->q);
        free(s);
        return -1;
    }
    *st = s;
    return 0;
}

static int refit(void *st, const cbvh_tri *tris, cbvh_unit_activity *u, char *err, size_t errlen) {
    (void)err;
    (void)errlen;
    state *s = st;
    u->refit += cbvh_qbvh_refit(&s->q, tris);
    return 0;
}

static int trace(const void *st, const cbvh_tri *tris, const cbvh_ray *ray, cbvh_trav_mode mode,
                 const cbvh_format_from *from, cbvh_trav_hit *hit, cbvh_trav_stats *ts) {
    (void)from;
    const state *s = st;
    return cbvh_trace_qbvh(&s->q, tris, ray, s->mant, mode, CBVH_QSTACK_COMPRESSED, hit, ts);
}

/* The node arrays and the primitive IDs (4 bytes each). */
static uint64_t bytes(const void *st) {
    const cbvh_qbvh *q = &((const state *)st)->q;
    return cbvh_qbvh_node_bytes(q) + (uint64_t)q->nprims * 4u;
}

static void units(const cbvh_trav_stats *sum, cbvh_unit_activity *u) {
    u->ray_box += sum->box_tests;
    u->ray_triangle += sum->tri_tests;
    u->qbvh_stack += sum->qstack_pushes + sum->qstack_pops;
}

static void release(void *st) {
    state *s = st;
    cbvh_qbvh_free(&s->q);
    free(s);
}

const cbvh_format cbvh_format_qbvh = {
    .name = "qbvh", .title = "QBVH", .memory = "node", .flags = CBVH_FORMAT_USES_MANT | CBVH_FORMAT_STACK_UNIT,
    .help = "qbvh: the QBVH (4-ary, compressed 32-bit stack, docs/qbvh.md) against it",
    .build_note = "QBVH: SAH build + 4-ary collapse",
    .refit_note = "; refits: the QBVH's own boxes bottom-up, topology kept",
    .describe = describe, .build = build, .refit = refit, .trace = trace, .bytes = bytes, .units = units, .free = release};
