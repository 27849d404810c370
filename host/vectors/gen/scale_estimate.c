/* Vectors of the scale estimator (docs/datapath.md §5). */
#include "vectors/gen/gen.h"

static void emit_box2(gen_t *g, cbvh_f32 lo, cbvh_f32 hi) {
    uint32_t in[2] = {lo, hi};
    vg_emit(g, in);
}

static void put_estimate(gen_t *g, cbvh_f32 lo, cbvh_f32 hi, int scale) {
    (void)scale;
    emit_box2(g, lo, hi);
}

static void gen_estimate(gen_t *g, size_t target) {
    if (!g->random_only) { /* level-1 structured cases */
        box_t boxes[2048];
        size_t nb = vg_structured_boxes(boxes, 2048, 1);
        for (size_t i = 0; i < nb && i < 2048; i++) emit_box2(g, boxes[i].lo, boxes[i].hi);
        vg_box_rejects(g, put_estimate, 0);
    }
    while (g->n < target && !g->oom) {
        box_t b = vg_rnd_box(&g->rng);
        emit_box2(g, b.lo, b.hi);
    }
}

/* Generator 6: a bound's last bit shifted out when the two are aligned.  A
 * bound far below the other's last bit is cut off, and only its sticky bit
 * can tell w = ub - lb from the width without it: ub just below 2^k and lb
 * = -2^j one to four binades below ub's last bit (and mirrored), so w is
 * just below or just above 2^k.  An RTL whose sticky bit ignored the last
 * bit shifted out failed one level-2 vector only (gateware/scripts/mutate-rtl). */
static void appended_estimate(gen_t *g) {
    static const int ks[] = {-20, 0, 13, 40, 100};
    for (size_t i = 0; i < sizeof ks / sizeof ks[0]; i++)
        for (int d = 1; d <= 4; d++)
            for (int m = 0; m < 2; m++) {
                cbvh_f32 big = cbvh_f32_next_down(cbvh_f32_make(0, ks[i], 0)); /* pred(2^k) */
                cbvh_f32 small = cbvh_f32_make(1, ks[i] - 24 - d, 0);        /* -2^(k-24-d) */
                if (m)
                    emit_box2(g, neg(big), neg(small)); /* [-pred(2^k), 2^(k-24-d)] */
                else
                    emit_box2(g, small, big);
            }
}

const vg_unit vg_scale_estimate = {"scale_estimate", 2000, gen_estimate, NULL, 0, appended_estimate, 1, 1};
