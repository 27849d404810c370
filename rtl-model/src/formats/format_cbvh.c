/* Format "cbvh": the binned-SAH float BVH compressed bottom-up by the
 * streaming compressor (modulo encoding, docs/datapath.md) and traversed with
 * the node-pair decoder (cbvh_trace_cbvh, docs/traversal.md §5).  Refit: the
 * streaming refit, which re-encodes the whole CBVH from the moved triangles
 * (cbvh_compress_bottomup with refit_tris). */
#include <stdio.h>
#include <stdlib.h>

#include "cbvh/bvh.h"
#include "cbvh/cbvh_tree.h"
#include "cbvh/format.h"
#include "cbvh/oom.h"
#include "cbvh/traverse_incr.h"

typedef struct {
    cbvh_bvh bvh; /* the float BVH the CBVH is compressed from (refitted by the streaming refit) */
    cbvh_tree tree;
    int have_tree;
    cbvh_params params;
    int mant;
    int incremental, texp; /* the box unit: unit 10 at X = texp, else unit 6 */
} state;

static void describe(const cbvh_format_params *p, char *out, size_t n) {
    if (p->box_unit == CBVH_FORMAT_BOX_INCREMENTAL)
        snprintf(out, n, "N=%d, M=%d, min scale %d, modulo, incremental box unit (X=%d)", p->cbvh.quant_bits, p->mant,
                 p->cbvh.min_scale, p->texp ? p->texp : CBVH_RBI_TEXP_DEFAULT);
    else
        snprintf(out, n, "N=%d, M=%d, min scale %d, modulo", p->cbvh.quant_bits, p->mant, p->cbvh.min_scale);
}

/* Compresses s->bvh (refitting it to refit_tris first unless NULL) into a
 * new CBVH; six axis compressions per pair encode or re-encode, three for the
 * root context. */
static int compress(state *s, const cbvh_tri *refit_tris, cbvh_unit_activity *u, char *err, size_t errlen) {
    cbvh_compress_opts co = {s->params, CBVH_ENC_MODULO, 1, 0};
    cbvh_tree nt;
    cbvh_bu_stats bs;
    if (cbvh_compress_bottomup(&s->bvh, refit_tris, &co, &nt, &bs, err, errlen)) return -1;
    if (s->have_tree) cbvh_tree_free(&s->tree);
    s->tree = nt;
    s->have_tree = 1;
    u->compressor += 6 * (bs.encodes + bs.reencodes) + 3;
    return 0;
}

static void release(void *st) {
    state *s = st;
    if (s->have_tree) cbvh_tree_free(&s->tree);
    cbvh_bvh_free(&s->bvh);
    free(s);
}

static int build(const cbvh_format_input *in, void **st, cbvh_unit_activity *u, char *err, size_t errlen) {
    if (cbvh_params_check(&in->p.cbvh)) {
        snprintf(err, errlen, "bad CBVH parameters N=%d min_scale=%d (N in %d..%d, min_scale in %d..%d)",
                 in->p.cbvh.quant_bits, in->p.cbvh.min_scale, CBVH_N_MIN, CBVH_N_MAX, CBVH_SCALE_FLOOR,
                 CBVH_SCALE_CEIL);
        return -1;
    }
    state *s = calloc(1, sizeof *s);
    if (!s) cbvh_out_of_memory("format state");
    s->params = in->p.cbvh;
    s->mant = in->p.mant;
    s->incremental = in->p.box_unit == CBVH_FORMAT_BOX_INCREMENTAL;
    s->texp = in->p.texp ? in->p.texp : CBVH_RBI_TEXP_DEFAULT;
    if (cbvh_build_sah(in->scene, 0, 0, &s->bvh, err, errlen) || compress(s, NULL, u, err, errlen)) {
        release(s);
        return -1;
    }
    *st = s;
    return 0;
}

static int refit(void *st, const cbvh_tri *tris, cbvh_unit_activity *u, char *err, size_t errlen) {
    state *s = st;
    if (compress(s, tris, u, err, errlen)) return -1;
    u->refit += s->bvh.nnodes;
    return 0;
}

static int trace(const void *st, const cbvh_tri *tris, const cbvh_ray *ray, cbvh_trav_mode mode,
                 const cbvh_format_from *from, cbvh_trav_hit *hit, cbvh_trav_stats *ts) {
    (void)from;
    const state *s = st;
    if (s->incremental) return cbvh_trace_cbvh_incr(&s->tree, tris, ray, s->mant, s->texp, mode, hit, ts);
    return cbvh_trace_cbvh(&s->tree, tris, ray, s->mant, mode, hit, ts);
}

static uint64_t bytes(const void *st) { return cbvh_tree_bytes(&((const state *)st)->tree); }

/* Every node pair fetched is decoded: six axis decodes. */
static void units(const cbvh_trav_stats *sum, cbvh_unit_activity *u) {
    u->ray_box += sum->box_tests;
    u->ray_triangle += sum->tri_tests;
    u->decoder += 6 * sum->nodes;
}

const cbvh_format cbvh_format_cbvh = {
    .name = "cbvh", .title = "CBVH", .help = "cbvh: the CBVH against the float BVH (default)", .memory = "node",
    .build_note = "CBVH: SAH build + bottom-up streaming compression", .refit_note = "",
    .flags = CBVH_FORMAT_USES_N | CBVH_FORMAT_USES_MANT | CBVH_FORMAT_BOX_UNIT,
    .describe = describe, .build = build, .refit = refit, .trace = trace, .bytes = bytes, .units = units, .free = release};
