/* Format "float": the binned-SAH float BVH traced by the units
 * (cbvh_trace_bvh, docs/traversal.md §5) — the reference whose hits every
 * other format must return.  Refit: cbvh_bvh_refit. */
#include <stdio.h>
#include <stdlib.h>

#include "cbvh/bvh.h"
#include "cbvh/cbvh_tree.h"
#include "cbvh/format.h"
#include "cbvh/oom.h"

typedef struct {
    cbvh_bvh bvh;
    int mant;
} state;

static void describe(const cbvh_format_params *p, char *out, size_t n) {
    snprintf(out, n, "M=%d", p->mant);
}

static int build(const cbvh_format_input *in, void **st, cbvh_unit_activity *u, char *err, size_t errlen) {
    (void)u;
    state *s = calloc(1, sizeof *s);
    if (!s) cbvh_out_of_memory("format state");
    s->mant = in->p.mant;
    if (cbvh_build_sah(in->scene, 0, 0, &s->bvh, err, errlen)) {
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
    cbvh_bvh_refit(&s->bvh, tris);
    u->refit += s->bvh.nnodes;
    return 0;
}

static int trace(const void *st, const cbvh_tri *tris, const cbvh_ray *ray, cbvh_trav_mode mode,
                 const cbvh_format_from *from, cbvh_trav_hit *hit, cbvh_trav_stats *ts) {
    (void)from;
    const state *s = st;
    return cbvh_trace_bvh(&s->bvh, tris, ray, s->mant, mode, hit, ts);
}

static uint64_t bytes(const void *st) { return cbvh_bvh_bytes(&((const state *)st)->bvh); }

static void units(const cbvh_trav_stats *sum, cbvh_unit_activity *u) {
    u->ray_box += sum->box_tests;
    u->ray_triangle += sum->tri_tests;
}

static void release(void *st) {
    state *s = st;
    cbvh_bvh_free(&s->bvh);
    free(s);
}

const cbvh_format cbvh_format_float = {
    .name = "float", .title = "float BVH", .help = "float: the float BVH only", .memory = "node",
    .build_note = "SAH build", .refit_note = "", .flags = CBVH_FORMAT_USES_MANT | CBVH_FORMAT_REFERENCE,
    .describe = describe, .build = build, .refit = refit, .trace = trace, .bytes = bytes, .units = units, .free = release};
