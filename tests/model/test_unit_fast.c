/* The inline fast paths of rtl-model/src/fast/unit_fast.h (used by the streaming
 * bottom-up compressor) against the units and an FPU oracle, and the
 * streaming compressor against the top-down one on hard scenes.
 *
 *   1. cbvh_fast_floor(x, e) == floor(x / 2^e) (FPU, exact in double) and
 *      its "huge" answer == cbvh_grid_floor's, on structured and random x,
 *      every e in [-126, 126].
 *   2. cbvh_fast_floor_shift(v, d) == cbvh_grid_floor_shift(v, d) for
 *      |v| < 2^62, d in 0..300.
 *   3. cbvh_scale_estimate_fast_nm: the scale == cbvh_scale_estimate's, and
 *      the grid coordinates it returns == floor(lb / 2^e), floor(ub / 2^e).
 *   4. cbvh_fast_code(e, k, ku) == cbvh_axis_compress (codes, child scale,
 *      fit), and RD(k 2^e), RU((ku + 1) 2^e) == its clb, cub: the lazily
 *      formed decoded bounds of the streaming compressor.
 *   5. The identity the streaming compressor relies on: for cs >= e,
 *      floor(floor(x / 2^e) / 2^(cs - e)) == floor(x / 2^cs), with the
 *      derived codes == cbvh_axis_compress at cs.
 *   6. Streaming (bottom-up) == top-down bit for bit, with consistent
 *      statistics, on random soups with mixed magnitudes (negative, zero,
 *      subnormal, up to +-FLT_MAX), flat boxes and far-away clusters, for
 *      N = 3..10, min_scale -126/-30/-10/0, both encodings, treelet depth
 *      1 and 4 and streaming refit; naive re-encoding (which may differ
 *      from top-down by design) independent of the treelet depth, never
 *      failing and always a valid CBVH (cbvh_tree_check).
 *
 * usage: test_unit_fast [--scale S]   (S multiplies the iteration counts) */
#include <float.h>

#include "cbvh/bvh.h"
#include "cbvh/cbvh_tree.h"
#include "units/grid.h"
#include "prop_util.h"
#include "fast/unit_fast.h"

static long n_cases;

static cbvh_f32 random_x(prng *r) {
    switch (prng_below(r, 5)) {
    case 0: return prop_structured((int)prng_below(r, PROP_N_STRUCT));
    case 1: return (cbvh_f32)prng_below(r, 0x800000u) | ((cbvh_f32)prng_below(r, 2) << 31); /* subnormal, zero */
    case 2: return (CBVH_F32_MAX - prng_below(r, 8)) | ((cbvh_f32)prng_below(r, 2) << 31);
    default: return prop_random_float(r);
    }
}

static void check_floor(cbvh_f32 x, int e) {
    if (cbvh_f32_is_nan_or_inf(x)) return; /* finite inputs only */
    int64_t k;
    int huge;
    int ok = cbvh_fast_floor(x, e, &k);
    int64_t kg = cbvh_grid_floor(x, e, &huge);
    n_cases++;
    if (ok != !huge) {
        prop_fail("fast_floor(%08x, %d): exact %d, grid_floor huge %d", x, e, ok, huge);
        return;
    }
    if (ok && ((double)k != oracle_floor(x, e) || k != kg))
        prop_fail("fast_floor(%08x, %d) = %lld, FPU %.17g, grid %lld", x, e, (long long)k, oracle_floor(x, e),
                  (long long)kg);
}

static void check_shift(int64_t v, int d) {
    int inexact;
    int64_t a = cbvh_fast_floor_shift(v, d), b = cbvh_grid_floor_shift(v, d, &inexact);
    n_cases++;
    if (a != b) prop_fail("fast_floor_shift(%lld, %d) = %lld, grid %lld", (long long)v, d, (long long)a, (long long)b);
}

/* 3 + 4 + 5 for one box and parameter set. */
static void check_box(int n, int ms, cbvh_f32 lb, cbvh_f32 ub, prng *r) {
    cbvh_params p = {n, ms};
    int e_unit, e_fast = -999;
    int64_t k = 0, ku = 0;
    uint32_t st = cbvh_scale_estimate(&p, lb, ub, &e_unit);
    int got = cbvh_scale_estimate_fast_nm(n, ms, lb, ub, &e_fast, &k, &ku);
    n_cases++;
    if (got && (st || e_fast != e_unit)) {
        prop_fail("estimate_fast N=%d ms=%d [%08x,%08x]: %d, unit st %#x e %d", n, ms, lb, ub, e_fast, st, e_unit);
        return;
    }
    if (st) return;
    if (got == 2 && ((double)k != oracle_floor(lb, e_unit) || (double)ku != oracle_floor(ub, e_unit))) {
        prop_fail("estimate_fast N=%d ms=%d [%08x,%08x] e %d: k %lld ku %lld", n, ms, lb, ub, e_unit, (long long)k,
                  (long long)ku);
        return;
    }
    /* the codes at the estimate and at coarser scales, directly and derived */
    int hl, hu;
    int64_t ke = cbvh_grid_floor(lb, e_unit, &hl), kue = cbvh_grid_floor(ub, e_unit, &hu);
    for (int t = 0; t < 3; t++) {
        int cs = t == 0 ? e_unit : e_unit + (int)prng_below(r, t == 1 ? 3u : 80u);
        if (cs > CBVH_SCALE_CEIL) cs = CBVH_SCALE_CEIL;
        int h1, h2;
        int64_t kc = cbvh_grid_floor(lb, cs, &h1), kuc = cbvh_grid_floor(ub, cs, &h2);
        if (h1 || h2) continue; /* the fast paths do not take it (checked in 1) */
        if (!hl && !hu && (cbvh_fast_floor_shift(ke, cs - e_unit) != kc || cbvh_fast_floor_shift(kue, cs - e_unit) != kuc))
            prop_fail("derived floors N=%d [%08x,%08x] e %d -> %d", n, lb, ub, e_unit, cs);
        cbvh_axis_code unit, orc;
        cbvh_f32 node = prng_below(r, 2) ? lb : prop_random_float(r); /* its own window, or any */
        uint32_t su = cbvh_axis_compress(&p, lb, ub, cs, node, &unit);
        uint32_t so = oracle_compress(n, ms, lb, ub, cs, node, &orc);
        uint32_t lbm, ubm;
        int ccs;
        int fit = cbvh_fast_code(n, ms, cs, kc, kuc, &lbm, &ubm, &ccs);
        n_cases++;
        if (su != so || !code_equal(&unit, &orc)) {
            prop_fail("compress vs FPU N=%d ms=%d [%08x,%08x] e %d: st %#x/%#x " CODE_FMT " / " CODE_FMT, n, ms, lb, ub,
                      cs, su, so, CODE_ARGS(unit), CODE_ARGS(orc));
            continue;
        }
        if (fit != !(su & CBVH_ST_NO_FIT) || (fit && (lbm != unit.lb_mod || ubm != unit.ub_mod || ccs != unit.child_scale))) {
            prop_fail("fast_code N=%d ms=%d [%08x,%08x] e %d: fit %d lb_mod %u ub_mod %u cs %d; unit st %#x " CODE_FMT,
                      n, ms, lb, ub, cs, fit, lbm, ubm, ccs, su, CODE_ARGS(unit));
            continue;
        }
        if (cbvh_grid_pack_signed(kc, cs, CBVH_RND_DOWN) != unit.clb ||
            cbvh_grid_pack_signed(kuc + 1, cs, CBVH_RND_UP) != unit.cub)
            prop_fail("lazy clb/cub N=%d [%08x,%08x] e %d: %08x %08x vs %08x %08x", n, lb, ub, cs,
                      cbvh_grid_pack_signed(kc, cs, CBVH_RND_DOWN), cbvh_grid_pack_signed(kuc + 1, cs, CBVH_RND_UP),
                      unit.clb, unit.cub);
    }
}

static cbvh_f32 finite_x(cbvh_f32 x) { return cbvh_f32_is_nan_or_inf(x) ? (x & CBVH_F32_SIGN) | CBVH_F32_MAX : x; }

static void random_box(prng *r, cbvh_f32 *lb, cbvh_f32 *ub) {
    cbvh_f32 a = finite_x(random_x(r)), b;
    switch (prng_below(r, 4)) {
    case 0: b = finite_x(random_x(r)); break;
    case 1: { /* narrow */
        int64_t k = cbvh_f32_key(a) + (int64_t)(prng_next(r) % (UINT64_C(1) << prng_range(r, 0, 24)));
        b = unkey(k > (int64_t)CBVH_F32_MAX ? (int64_t)CBVH_F32_MAX : k);
        break;
    }
    case 2: b = a; break; /* a point (flat axis) */
    default: /* scene-like: same or neighbouring binades, either sign */
        a = ((cbvh_f32)prng_below(r, 2) << 31) | ((cbvh_f32)prng_range(r, 100, 160) << CBVH_F32_FRAC_BITS) |
            ((cbvh_f32)prng_next(r) & CBVH_F32_FRAC);
        b = ((cbvh_f32)prng_below(r, 2) << 31) | ((cbvh_f32_exp_field(a) + (cbvh_f32)prng_below(r, 3)) << CBVH_F32_FRAC_BITS) |
            ((cbvh_f32)prng_next(r) & CBVH_F32_FRAC);
        break;
    }
    if (cbvh_f32_key(a) > cbvh_f32_key(b)) {
        cbvh_f32 t = a;
        a = b;
        b = t;
    }
    *lb = a;
    *ub = b;
}

/* ---- 6. streaming vs top-down ---- */

static char errbuf[512];

static float rand_unit(prng *r) { return (float)((double)(prng_next(r) >> 11) * 0x1p-53 * 2.0 - 1.0); }

/* A soup of `nt` small triangles; kind 0: mixed magnitudes (some scaled to
 * 1e-40 .. 3e38, some exactly 0), 1: flat (z = const) cloth-like patches
 * far from the origin, 2: scene-like. */
static void soup(prng *r, int kind, uint32_t nt, cbvh_scene *s) {
    memset(s, 0, sizeof *s);
    snprintf(s->name, sizeof s->name, "soup%d", kind);
    s->ntris = nt;
    s->tris = calloc(nt, sizeof *s->tris);
    static const float scales[] = {1.0f, 1e-30f, 1e-38f, 1e-40f, 1e30f, 3e38f, 1e-3f, 1e10f, 0.0f};
    for (uint32_t i = 0; i < nt; i++) {
        float c[3], sc = kind == 0 ? scales[prng_below(r, 9)] : 1.0f;
        for (int a = 0; a < 3; a++) c[a] = rand_unit(r);
        for (int v = 0; v < 3; v++)
            for (int a = 0; a < 3; a++) {
                double x = (double)c[a] + 0.01 * rand_unit(r);
                if (kind == 1) x = a == 2 ? -0.4 : 1000.0 + 50.0 * x;
                x *= sc;
                if (x > FLT_MAX) x = FLT_MAX;
                if (x < -FLT_MAX) x = -FLT_MAX;
                s->tris[i].v[v][a] = (float)x;
            }
    }
}

static void copy_bvh(const cbvh_bvh *b, cbvh_bvh *c) {
    *c = *b;
    c->nodes = malloc(b->nnodes * sizeof *b->nodes);
    memcpy(c->nodes, b->nodes, b->nnodes * sizeof *b->nodes);
}

static void check_stream(const cbvh_bvh *b, const cbvh_tri *moved, const cbvh_compress_opts *o, const char *what) {
    cbvh_bvh c1, c2;
    copy_bvh(b, &c1);
    copy_bvh(b, &c2);
    cbvh_tree td, bu;
    cbvh_bu_stats st;
    n_cases++;
    if (moved) cbvh_bvh_refit(&c1, moved);
    int rt = cbvh_compress_topdown(&c1, o, &td, errbuf, sizeof errbuf);
    int rb = cbvh_compress_bottomup(&c2, moved, o, &bu, &st, errbuf, sizeof errbuf);
    if (rt || rb) {
        prop_fail("%s N=%d ms=%d enc=%d: top-down %d, bottom-up %d (%s)", what, o->params.quant_bits,
                  o->params.min_scale, o->enc, rt, rb, errbuf);
    } else {
        long d = cbvh_tree_diff(&td, &bu);
        uint64_t hs = 0, deep = 0;
        for (int i = 0; i < CBVH_BT_HIST; i++) hs += st.hist[i], deep += i >= o->treelet_depth ? st.hist[i] : 0;
        if (o->naive_reencode) d = -1; /* may differ by design; only the run and the stats are checked */
        int same_boxes = 1; /* as values: refit.c and the stream may pick different zeros of min(-0, +0) */
        for (uint32_t i = 0; i < b->nnodes; i++)
            for (int a = 0; a < 3; a++)
                same_boxes &= c1.nodes[i].lo[a] == c2.nodes[i].lo[a] && c1.nodes[i].hi[a] == c2.nodes[i].hi[a];
        if (d != -1 || hs != st.reencodes || st.backtracks != deep || st.encodes != td.npairs || !same_boxes)
            prop_fail("%s N=%d ms=%d enc=%d M=%d naive=%d refit=%d: bottom-up differs from top-down at byte %ld", what,
                      o->params.quant_bits, o->params.min_scale, o->enc, o->treelet_depth, o->naive_reencode,
                      moved != NULL, d);
        if (cbvh_tree_check(&bu, &c1, errbuf, sizeof errbuf))
            prop_fail("%s N=%d: bottom-up tree check: %s", what, o->params.quant_bits, errbuf);
    }
    if (!rt) cbvh_tree_free(&td);
    if (!rb) cbvh_tree_free(&bu);
    free(c1.nodes);
    free(c2.nodes);
}

/* Naive re-encoding (as printed) may differ from top-down by design; it must
 * still succeed, give a valid CBVH (its repairs: docs/study.md), and not
 * depend on the treelet depth. */
static void check_naive(const cbvh_bvh *b, const cbvh_compress_opts *o0) {
    cbvh_compress_opts o = *o0;
    cbvh_tree t[2];
    cbvh_bu_stats st[2];
    char e[2][512];
    int rc[2];
    for (int i = 0; i < 2; i++) {
        cbvh_bvh c;
        copy_bvh(b, &c);
        o.naive_reencode = 1;
        o.treelet_depth = 1 + 3 * i;
        rc[i] = cbvh_compress_bottomup(&c, NULL, &o, &t[i], &st[i], e[i], sizeof e[i]);
        if (rc[i])
            prop_fail("naive N=%d ms=%d enc=%d M=%d: %s", o.params.quant_bits, o.params.min_scale, o.enc,
                      o.treelet_depth, e[i]);
        else if (cbvh_tree_check(&t[i], &c, errbuf, sizeof errbuf))
            prop_fail("naive N=%d ms=%d enc=%d M=%d: tree check: %s", o.params.quant_bits, o.params.min_scale,
                      o.enc, o.treelet_depth, errbuf);
        free(c.nodes);
    }
    n_cases++;
    if (rc[0] != rc[1] || (rc[0] && strcmp(e[0], e[1])) ||
        (!rc[0] && (cbvh_tree_diff(&t[0], &t[1]) != -1 || st[0].reencodes != st[1].reencodes ||
                    st[0].naive_nofit != st[1].naive_nofit)))
        prop_fail("naive N=%d ms=%d enc=%d: depends on the treelet depth", o.params.quant_bits, o.params.min_scale,
                  o.enc);
    for (int i = 0; i < 2; i++)
        if (!rc[i]) cbvh_tree_free(&t[i]);
}

/* Not a BVH: a leaf child moved past its parent's box on one axis.  The
 * compressor reports OUTSIDE for it (its codes would decode elsewhere), and
 * both compressors refuse the tree with that status (0x80) instead of
 * writing wrapped codes.  Real children never leave their node's window, so
 * every other build here succeeding is the builders never seeing the bit. */
static void check_not_a_bvh(const cbvh_bvh *b, int n) {
    uint32_t x = 0;
    while (x < b->nnodes && (cbvh_bvh_is_leaf(&b->nodes[x]) || !cbvh_bvh_is_leaf(&b->nodes[b->nodes[x].child[1]]))) x++;
    if (x == b->nnodes) return;
    for (int a = 0; a < 3; a++) {
        cbvh_bvh c;
        copy_bvh(b, &c);
        const cbvh_bvh_node *nd = &c.nodes[x];
        cbvh_bvh_node *leaf = &c.nodes[nd->child[1]];
        double ext = 4.0 * ((double)nd->hi[a] - nd->lo[a]) + 1.0, v = nd->hi[a] + ext; /* past it, or below */
        if (v > FLT_MAX) v = nd->lo[a] - ext;
        if (v < -FLT_MAX) {
            free(c.nodes);
            continue;
        }
        leaf->lo[a] = leaf->hi[a] = (float)v;
        cbvh_compress_opts o = {{n, CBVH_MIN_SCALE_DEFAULT}, CBVH_ENC_MODULO, 1, 0};
        cbvh_tree t;
        cbvh_bu_stats st;
        char e[2][512];
        int rt = cbvh_compress_topdown(&c, &o, &t, e[0], sizeof e[0]);
        if (!rt) cbvh_tree_free(&t);
        int rb = cbvh_compress_bottomup(&c, NULL, &o, &t, &st, e[1], sizeof e[1]);
        if (!rb) cbvh_tree_free(&t);
        n_cases++;
        if (!rt || !rb || !strstr(e[0], "status 0x80") || !strstr(e[1], "status 0x80"))
            prop_fail("a child outside its node (axis %d, N=%d): top-down %d '%s', bottom-up %d '%s'", a, n, rt,
                      rt ? e[0] : "", rb, rb ? e[1] : "");
        free(c.nodes);
    }
}

static void stream_tests(prng *r, uint32_t nt) {
    static const int ms_list[] = {-126, -30, -10, 0};
    for (int kind = 0; kind < 3; kind++) {
        cbvh_scene s;
        soup(r, kind, nt, &s);
        cbvh_tri *moved = malloc(nt * sizeof *moved);
        for (uint32_t i = 0; i < nt; i++)
            for (int v = 0; v < 3; v++)
                for (int a = 0; a < 3; a++) {
                    float x = s.tris[i].v[v][a];
                    moved[i].v[v][a] = kind == 0 ? x : x + 0.003f * rand_unit(r);
                }
        for (int builder = 0; builder < 2; builder++) {
            cbvh_bvh b;
            int rc = builder ? cbvh_build_sah(&s, 0, 0, &b, errbuf, sizeof errbuf)
                             : cbvh_build_lbvh(&s, &b, errbuf, sizeof errbuf);
            if (rc) {
                prop_fail("soup %d: build: %s", kind, errbuf);
                continue;
            }
            check_not_a_bvh(&b, CBVH_N_MIN + kind);
            for (int n = CBVH_N_MIN; n <= CBVH_N_MAX; n++)
                for (int m = 0; m < 4; m++)
                    for (int enc = 0; enc < 2; enc++) {
                        cbvh_compress_opts o = {{n, ms_list[m]}, (cbvh_encoding)enc, 1 + 3 * (int)(prng_below(r, 2)), 0};
                        check_stream(&b, NULL, &o, builder ? "sah" : "lbvh");
                        if (((n + m + enc) & 3) == 0) {
                            check_naive(&b, &o);
                            check_stream(&b, moved, &o, "refit");
                        }
                    }
            cbvh_bvh_free(&b);
        }
        free(moved);
        cbvh_scene_free(&s);
    }
}

int main(int argc, char **argv) {
    double scale = 1.0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--scale") && i + 1 < argc) {
            scale = atof(argv[++i]);
        } else {
            fprintf(stderr, "usage: test_unit_fast [--scale S]\n");
            return 2;
        }
    }
    if (!(scale > 0.0 && scale <= 100.0)) {
        fprintf(stderr, "test_unit_fast: --scale must be in (0, 100]\n");
        return 2;
    }
    prng r = {UINT64_C(0xFA57FA57C0DE0003)};

    /* 1. floors: every structured x at every scale, then random x */
    for (int i = 0; i < PROP_N_STRUCT; i++)
        for (int e = CBVH_SCALE_FLOOR; e <= CBVH_SCALE_CEIL; e++) check_floor(prop_structured(i), e);
    for (long i = 0, it = (long)(2000000 * scale); i < it; i++)
        check_floor(random_x(&r), prng_range(&r, CBVH_SCALE_FLOOR, CBVH_SCALE_CEIL));
    long floors = n_cases;

    /* 2. shifts */
    for (long i = 0, it = (long)(500000 * scale); i < it; i++) {
        int64_t v = (int64_t)(prng_next(&r) >> prng_range(&r, 2, 63));
        if (prng_below(&r, 2)) v = -v;
        check_shift(v, prng_below(&r, 4) ? prng_range(&r, 0, 64) : prng_range(&r, 0, 300));
    }
    check_shift((INT64_C(1) << 62) - 1, 62);
    check_shift(-((INT64_C(1) << 62) - 1), 62);
    check_shift(-((INT64_C(1) << 62) - 1), 61);
    check_shift(-1, 300);

    /* 3-5. boxes: every N, min_scale at the extremes, the default and random */
    for (long i = 0, it = (long)(1000000 * scale); i < it; i++) {
        cbvh_f32 lb, ub;
        random_box(&r, &lb, &ub);
        int ms;
        switch (prng_below(&r, 4)) {
        case 0: ms = CBVH_MIN_SCALE_DEFAULT; break;
        case 1: ms = prng_below(&r, 2) ? CBVH_SCALE_FLOOR : CBVH_SCALE_CEIL - (int)prng_below(&r, 3); break;
        default: ms = prng_range(&r, CBVH_SCALE_FLOOR, CBVH_SCALE_CEIL); break;
        }
        check_box(prng_range(&r, CBVH_N_MIN, CBVH_N_MAX), ms, lb, ub, &r);
    }
    long boxes = n_cases - floors;

    /* 6. streaming vs top-down */
    stream_tests(&r, (uint32_t)(600 * (scale < 1.0 ? scale : 1.0)) + 40);

    printf("test_unit_fast: %ld cases (%ld floors and shifts, %ld boxes), %ld failures\n", n_cases, floors, boxes,
           prop_failures);
    return prop_failures ? 1 : 0;
}
