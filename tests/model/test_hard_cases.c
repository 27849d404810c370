/* Named hard cases of the datapath (BRIEF: errata and traps).  Each case is
 * its own ctest; the ctest runs this program built at -O0 and at -O2 and
 * compares the printed digests (run_both.cmake).  Every case checks
 * enclosure, the FPU oracle of the compressor, modulo == relative == compress
 * and the scale rules on every box it touches.
 *
 * usage: test_hard_cases CASE      (CASE: see the table at the bottom) */
#include "prop_util.h"

static digest dg;
static long n_checks;

#define CHECK(cond, ...)                                                                                               \
    do {                                                                                                               \
        n_checks++;                                                                                                    \
        if (!(cond)) prop_fail(__VA_ARGS__);                                                                           \
    } while (0)

static const cbvh_params P6_30 = {6, CBVH_MIN_SCALE_DEFAULT};
static const cbvh_params P6_126 = {6, CBVH_SCALE_FLOOR};

/* Compress one box at scale e in the window of the node whose lower bound
 * is node_clb; compare with the FPU oracle and check enclosure and the
 * scale rules.  Returns the status. */
static uint32_t compress_checked_in(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, int e, cbvh_f32 node_clb,
                                    cbvh_axis_code *c) {
    uint32_t st = cbvh_axis_compress(p, lb, ub, e, node_clb, c);
    digest_code(&dg, st, c);
    cbvh_axis_code o;
    uint32_t ost = oracle_compress(p->quant_bits, p->min_scale, lb, ub, e, node_clb, &o);
    CHECK(st == ost && code_equal(c, &o),
          "compress [%08x,%08x] e=%d N=%d ms=%d: model st=%#x " CODE_FMT ", oracle st=%#x " CODE_FMT, lb, ub, e,
          p->quant_bits, p->min_scale, st, CODE_ARGS(*c), ost, CODE_ARGS(o));
    CHECK(encloses(c, lb, ub), "no enclosure: [%08x,%08x] e=%d -> [%08x,%08x]", lb, ub, e, c->clb, c->cub);
    CHECK(c->child_scale >= p->min_scale && c->child_scale <= e, "child scale %d outside [%d,%d]", c->child_scale,
          p->min_scale, e);
    return st;
}

/* The same in the window that starts at the box's own lowest cell
 * (node_clb = lb, as for a root): OUTSIDE exactly with NO_FIT. */
static uint32_t compress_checked(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, int e, cbvh_axis_code *c) {
    uint32_t st = compress_checked_in(p, lb, ub, e, lb, c);
    CHECK(!(st & CBVH_ST_OUTSIDE) == !(st & CBVH_ST_NO_FIT), "own window [%08x,%08x] e=%d: status %#x", lb, ub, e, st);
    return st;
}

/* A child box inside its node, under ctx: must fit, and both decodes must
 * equal the compressor field by field. */
static void child_checked(const cbvh_params *p, const cbvh_axis_ctx *ctx, cbvh_f32 lb, cbvh_f32 ub, cbvh_axis_code *c) {
    uint32_t st = compress_checked_in(p, lb, ub, ctx->scale, ctx->clb, c);
    CHECK(st == 0, "child [%08x,%08x] at scale %d: status %#x (NO_FIT or OUTSIDE inside its node)", lb, ub, ctx->scale,
          st);
    for (int enc = 0; enc < 2; enc++) {
        uint32_t lc, uc;
        cbvh_axis_code d;
        cbvh_axis_store_codes(p, (cbvh_encoding)enc, ctx, c, &lc, &uc);
        uint32_t dst = cbvh_axis_decode(p, (cbvh_encoding)enc, ctx, lc, uc, &d);
        digest_code(&dg, dst, &d);
        CHECK(dst == 0 && code_equal(&d, c), "%s decode st=%#x " CODE_FMT " != compress " CODE_FMT,
              enc ? "relative" : "modulo", dst, CODE_ARGS(d), CODE_ARGS(*c));
    }
}

static cbvh_axis_ctx root_checked(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub) {
    cbvh_axis_ctx ctx;
    uint32_t st = cbvh_axis_root_ctx(p, lb, ub, &ctx);
    digest_u32(&dg, st);
    digest_u32(&dg, (uint32_t)ctx.parent_scale);
    digest_u32(&dg, (uint32_t)ctx.scale);
    digest_u32(&dg, ctx.lb_mod);
    digest_u32(&dg, ctx.clb);
    CHECK(st == 0, "root_ctx [%08x,%08x] status %#x", lb, ub, st);
    CHECK(ctx.parent_scale >= p->min_scale && ctx.scale >= p->min_scale && ctx.scale <= ctx.parent_scale,
          "root_ctx scales %d/%d with min_scale %d", ctx.parent_scale, ctx.scale, p->min_scale);
    cbvh_axis_code c;
    compress_checked(p, lb, ub, ctx.parent_scale, &c); /* the root box itself */
    return ctx;
}

/* Root box, then `depth` random nested children, each checked. */
static void chain_checked(const cbvh_params *p, cbvh_f32 lb, cbvh_f32 ub, prng *r, int depth) {
    cbvh_axis_ctx ctx = root_checked(p, lb, ub);
    for (int d = 0; d < depth; d++) {
        cbvh_f32 a = prop_point_in(r, lb, ub), b = prop_point_in(r, lb, ub);
        if (cbvh_f32_key(a) > cbvh_f32_key(b)) { cbvh_f32 t = a; a = b; b = t; }
        cbvh_axis_code c;
        child_checked(p, &ctx, a, b, &c);
        ctx = cbvh_axis_child_ctx(&ctx, &c);
        lb = a;
        ub = b;
    }
}

static void chains_all_params(cbvh_f32 lb, cbvh_f32 ub, prng *r) {
    static const int mins[] = {CBVH_SCALE_FLOOR, CBVH_MIN_SCALE_DEFAULT, 0, 100};
    for (int n = CBVH_N_MIN; n <= CBVH_N_MAX; n++)
        for (int m = 0; m < 4; m++) {
            cbvh_params p = {n, mins[m]};
            for (int rep = 0; rep < 8; rep++) chain_checked(&p, lb, ub, r, 10);
        }
}

static cbvh_f32 ulps(cbvh_f32 x, int k) { return unkey(cbvh_f32_key(x) + k); }

/* ---- cloth: a finely tessellated plane at z = -0.4 ---------------------- */
#define CLOTH_G 64 /* 64 x 64 quads, 8192 triangles */
typedef struct {
    float lo[3], hi[3], c[3];
} tri_box;

typedef struct {
    long nodes, nofit, below_min, not_nested, inverted_scale;
    int z_scale_min, z_scale_max, max_depth;
    double z_width_max;
} cloth_stats;

static int cmp_axis;
static int cmp_centroid(const void *a, const void *b) {
    float x = ((const tri_box *)a)->c[cmp_axis], y = ((const tri_box *)b)->c[cmp_axis];
    return (x > y) - (x < y);
}

static void box_of(const tri_box *t, int n, float lo[3], float hi[3]) {
    for (int a = 0; a < 3; a++) {
        lo[a] = t[0].lo[a];
        hi[a] = t[0].hi[a];
    }
    for (int i = 1; i < n; i++)
        for (int a = 0; a < 3; a++) {
            if (t[i].lo[a] < lo[a]) lo[a] = t[i].lo[a];
            if (t[i].hi[a] > hi[a]) hi[a] = t[i].hi[a];
        }
}

/* Node [t, t+n) with context ctx and decoded box (from its parent): split at
 * the median of the longest centroid axis, compress both children with ctx
 * through the node-pair codec, check them, recurse. */
static void cloth_node(const cbvh_params *p, cbvh_encoding enc, tri_box *t, int n, const cbvh_node_ctx *ctx,
                       const cbvh_axis_code dec[3], int depth, cloth_stats *s) {
    if (n <= 2) return; /* leaf */
    if (depth > s->max_depth) s->max_depth = depth;
    float clo[3], chi[3];
    box_of(t, n, clo, chi);
    int axis = 0;
    for (int a = 1; a < 3; a++)
        if (chi[a] - clo[a] > chi[axis] - clo[axis]) axis = a;
    cmp_axis = axis;
    qsort(t, (size_t)n, sizeof *t, cmp_centroid);
    int half = n / 2;
    tri_box *part[2] = {t, t + half};
    int cnt[2] = {half, n - half};
    cbvh_child_in in[2];
    memset(in, 0, sizeof in);
    for (int c = 0; c < 2; c++) {
        float lo[3], hi[3];
        box_of(part[c], cnt[c], lo, hi);
        for (int a = 0; a < 3; a++) {
            in[c].lo[a] = fb(lo[a]);
            in[c].hi[a] = fb(hi[a]);
        }
        in[c].leaf = cnt[c] <= 2;
        in[c].ptr = (uint32_t)s->nodes;
    }
    uint8_t bytes[24];
    cbvh_child_out eo[2], dout[2];
    uint32_t st = cbvh_nodepair_encode(p, enc, ctx, in, bytes, eo);
    uint32_t dst = cbvh_nodepair_decode(p, enc, ctx, bytes, dout);
    for (size_t b = 0; b < cbvh_nodepair_bytes(p->quant_bits); b++) digest_u32(&dg, bytes[b]);
    digest_u32(&dg, st);
    s->nodes += 2;
    if (st & CBVH_ST_NO_FIT) s->nofit++;
    CHECK(st == 0 && dst == 0, "cloth: node pair status %#x / %#x at depth %d", st, dst, depth);
    for (int c = 0; c < 2; c++) {
        cbvh_node_ctx child_ctx;
        for (int a = 0; a < 3; a++) {
            const cbvh_axis_code *code = &dout[c].axis[a];
            cbvh_axis_code o;
            oracle_compress(p->quant_bits, p->min_scale, in[c].lo[a], in[c].hi[a], ctx->axis[a].scale, ctx->axis[a].clb,
                            &o);
            CHECK(code_equal(code, &eo[c].axis[a]) && code_equal(code, &o), "cloth: decode/oracle mismatch axis %d", a);
            CHECK(encloses(code, in[c].lo[a], in[c].hi[a]), "cloth: no enclosure at depth %d axis %d", depth, a);
            if (code->child_scale < p->min_scale) s->below_min++;
            if (code->child_scale > ctx->axis[a].scale) s->inverted_scale++;
            /* the child's decoded box lies inside its node's decoded box */
            if (f32_as_double(code->clb) < f32_as_double(dec[a].clb) || f32_as_double(code->cub) > f32_as_double(dec[a].cub))
                s->not_nested++;
            if (a == 2) {
                if (code->child_scale < s->z_scale_min) s->z_scale_min = code->child_scale;
                if (code->child_scale > s->z_scale_max) s->z_scale_max = code->child_scale;
                double w = f32_as_double(code->cub) - f32_as_double(code->clb);
                if (w > s->z_width_max) s->z_width_max = w;
            }
            child_ctx.axis[a] = cbvh_axis_child_ctx(&ctx->axis[a], code);
        }
        cloth_node(p, enc, part[c], cnt[c], &child_ctx, dout[c].axis, depth + 1, s);
    }
}

static int case_cloth_plane(void) {
    static tri_box tris[CLOTH_G * CLOTH_G * 2];
    int nt = 0;
    const float z = -0.4f;
    for (int i = 0; i < CLOTH_G; i++)
        for (int j = 0; j < CLOTH_G; j++) {
            float x0 = -1.0f + 2.0f * (float)i / CLOTH_G, x1 = -1.0f + 2.0f * (float)(i + 1) / CLOTH_G;
            float y0 = -1.0f + 2.0f * (float)j / CLOTH_G, y1 = -1.0f + 2.0f * (float)(j + 1) / CLOTH_G;
            for (int k = 0; k < 2; k++) { /* both triangles of the quad have the quad's box */
                tri_box *t = &tris[nt++];
                t->lo[0] = x0; t->hi[0] = x1;
                t->lo[1] = y0; t->hi[1] = y1;
                t->lo[2] = t->hi[2] = z;
                for (int a = 0; a < 3; a++) t->c[a] = 0.5f * (t->lo[a] + t->hi[a]) + (k ? 1e-4f : 0.0f) * (a < 2);
            }
        }
    printf("cloth: %d triangles on z = -0.4, recursive median split, top-down compression\n", nt);
    printf("%-4s %-9s %-8s %7s %6s %6s %10s %12s %14s\n", "N", "min_scale", "enc", "nodes", "NO_FIT", "depth",
           "z scales", "z width max", "root z scale");
    for (int n = CBVH_N_MIN; n <= CBVH_N_MAX; n++)
        for (int m = 0; m < 2; m++)
            for (int enc = 0; enc < 2; enc++) {
                cbvh_params p = {n, m ? CBVH_MIN_SCALE_DEFAULT : CBVH_SCALE_FLOOR};
                float lo[3], hi[3];
                box_of(tris, nt, lo, hi);
                cbvh_node_ctx ctx;
                cbvh_axis_code root[3];
                for (int a = 0; a < 3; a++) {
                    ctx.axis[a] = root_checked(&p, fb(lo[a]), fb(hi[a]));
                    compress_checked(&p, fb(lo[a]), fb(hi[a]), ctx.axis[a].parent_scale, &root[a]);
                }
                CHECK(ctx.axis[2].parent_scale == p.min_scale && ctx.axis[2].scale == p.min_scale,
                      "cloth: zero-width root z must sit at min_scale %d (got %d/%d)", p.min_scale,
                      ctx.axis[2].parent_scale, ctx.axis[2].scale);
                cloth_stats s = {0, 0, 0, 0, 0, 1000, -1000, 0, 0.0};
                cloth_node(&p, (cbvh_encoding)enc, tris, nt, &ctx, root, 1, &s);
                CHECK(s.nofit == 0, "cloth: %ld NO_FIT children", s.nofit);
                CHECK(s.below_min == 0 && s.inverted_scale == 0, "cloth: %ld scales below min, %ld child > parent",
                      s.below_min, s.inverted_scale);
                CHECK(s.not_nested == 0, "cloth: %ld decoded children outside their node", s.not_nested);
                CHECK(s.z_scale_min == p.min_scale && s.z_scale_max == p.min_scale,
                      "cloth: z scales [%d,%d], expected all at min_scale", s.z_scale_min, s.z_scale_max);
                /* the decoded z slab is one grid step at most one ulp of 0.4 wide */
                CHECK(s.z_width_max <= 0x1p-25, "cloth: decoded z slab %.3g wider than ulp(0.4)", s.z_width_max);
                if (n == 3 || n == 6 || n == 10)
                    printf("%-4d %-9d %-8s %7ld %6ld %6d %4d..%-4d %12.3g %14d\n", n, p.min_scale,
                           enc ? "relative" : "modulo", s.nodes, s.nofit, s.max_depth, s.z_scale_min, s.z_scale_max,
                           s.z_width_max, ctx.axis[2].parent_scale);
            }
    /* What min_scale changes: the z grid coordinate of -0.4 the hardware must
     * align (its bit length), which is what -30 bounds. */
    for (int m = 0; m < 2; m++) {
        int e = m ? CBVH_MIN_SCALE_DEFAULT : CBVH_SCALE_FLOOR;
        double k = oracle_floor(fb(z), e);
        printf("min_scale %4d: z grid coordinate floor(-0.4 / 2^%d) = -2^%.2f (needs %d bits)\n", e, e, log2(-k),
               (int)ceil(log2(-k)) + 1);
    }
    return 0;
}

/* ---- other named cases -------------------------------------------------- */
static int case_far_from_origin(void) {
    prng r = {1};
    const float centres[] = {0x1p30f, 1e20f, 0x1p100f, 1e38f, 3.0e38f, 123456.789f, 0x1p24f + 2.0f};
    for (size_t i = 0; i < sizeof centres / sizeof centres[0]; i++)
        for (int s = 0; s < 2; s++) {
            cbvh_f32 c = fb(s ? -centres[i] : centres[i]);
            for (int w = 0; w <= 5; w++) {
                cbvh_f32 lb = c, ub = ulps(c, w * w); /* 0, 1, 4, ... 25 ulps */
                if (cbvh_f32_key(lb) > cbvh_f32_key(ub)) { cbvh_f32 t = lb; lb = ub; ub = t; }
                chains_all_params(lb, ub, &r);
                /* tiny boxes must decode tight: within a few ulps of the box */
                cbvh_axis_ctx ctx = root_checked(&P6_126, lb, ub);
                cbvh_axis_code code;
                compress_checked(&P6_126, lb, ub, ctx.parent_scale, &code);
                CHECK(cbvh_f32_key(code.clb) >= cbvh_f32_key(lb) - 64 && cbvh_f32_key(code.cub) <= cbvh_f32_key(ub) + 64,
                      "far: [%08x,%08x] decoded loosely to [%08x,%08x]", lb, ub, code.clb, code.cub);
            }
        }
    return 0;
}

static int case_straddling_zero(void) {
    prng r = {2};
    const float ends[] = {1e-30f, 1e-7f, 0.25f, 1.0f, 3.0f, 1e10f, 3.4e38f, 0x1p-126f, 0x1p-149f};
    const int ne = (int)(sizeof ends / sizeof ends[0]);
    for (int i = 0; i < ne; i++)
        for (int j = 0; j < ne; j++) {
            cbvh_f32 lb = fb(-ends[i]), ub = fb(ends[j]);
            chains_all_params(lb, ub, &r);
            cbvh_axis_ctx ctx = root_checked(&P6_30, lb, ub);
            cbvh_axis_code c;
            compress_checked(&P6_30, lb, ub, ctx.parent_scale, &c);
            CHECK((c.clb & CBVH_F32_SIGN) && !(c.cub & CBVH_F32_SIGN) && !cbvh_f32_is_zero(c.cub),
                  "straddle [%08x,%08x]: decoded [%08x,%08x] does not straddle zero", lb, ub, c.clb, c.cub);
        }
    return 0;
}

static int case_signed_zero(void) {
    prng r = {3};
    const cbvh_f32 NZ = CBVH_F32_SIGN, PZ = 0;
    const cbvh_f32 others[] = {fb(1.0f), fb(-1.0f), fb(1e-40f), fb(-1e-40f), fb(3e38f), fb(-3e38f)};
    for (int n = CBVH_N_MIN; n <= CBVH_N_MAX; n++) {
        cbvh_params p = {n, CBVH_MIN_SCALE_DEFAULT};
        for (int e = p.min_scale; e <= CBVH_SCALE_CEIL; e += 7) {
            cbvh_axis_code a, b, c;
            compress_checked(&p, NZ, NZ, e, &a);
            compress_checked(&p, PZ, PZ, e, &b);
            compress_checked(&p, NZ, PZ, e, &c);
            CHECK(code_equal(&a, &b) && code_equal(&a, &c), "-0 and +0 compress differently at e=%d", e);
            CHECK(a.clb == 0 && a.lb_mod == 0 && a.ub_mod == (1u % (1u << n)),
                  "zero box at e=%d: clb %08x (must be +0), mods %u,%u", e, a.clb, a.lb_mod, a.ub_mod);
            for (size_t i = 0; i < sizeof others / sizeof others[0]; i++) {
                cbvh_f32 x = others[i];
                cbvh_axis_code u, v;
                if (x & CBVH_F32_SIGN) {
                    compress_checked(&p, x, NZ, e, &u);
                    compress_checked(&p, x, PZ, e, &v);
                } else {
                    compress_checked(&p, NZ, x, e, &u);
                    compress_checked(&p, PZ, x, e, &v);
                }
                CHECK(u.lb_mod == v.lb_mod && u.ub_mod == v.ub_mod && u.child_scale == v.child_scale &&
                          u.clb == v.clb && u.cub == v.cub,
                      "-0/+0 as a box end differ (x=%08x e=%d)", x, e);
            }
        }
        int s1, s2;
        cbvh_scale_estimate(&p, NZ, PZ, &s1);
        cbvh_scale_estimate(&p, PZ, PZ, &s2);
        CHECK(s1 == p.min_scale && s2 == p.min_scale, "zero box scale %d/%d, expected min_scale", s1, s2);
        chain_checked(&p, NZ, PZ, &r, 8);
        chain_checked(&p, NZ, fb(2.0f), &r, 8);
        /* a context whose clb is -0 decodes like one with +0 */
        cbvh_axis_ctx c0 = {p.min_scale + 5, p.min_scale, 3u & ((1u << n) - 1u), NZ}, c1 = c0;
        c1.clb = PZ;
        for (int enc = 0; enc < 2; enc++) {
            cbvh_axis_code d0, d1;
            uint32_t st0 = cbvh_axis_decode(&p, (cbvh_encoding)enc, &c0, 1, 2, &d0);
            uint32_t st1 = cbvh_axis_decode(&p, (cbvh_encoding)enc, &c1, 1, 2, &d1);
            digest_code(&dg, st0, &d0);
            CHECK(st0 == st1 && code_equal(&d0, &d1), "decode with clb -0 differs from +0");
        }
    }
    return 0;
}

static int case_subnormals(void) {
    prng r = {4};
    const cbvh_f32 sub[] = {0x00000001u, 0x00000002u, 0x00400000u, 0x007FFFFFu, 0x00800000u, 0x00012345u};
    const int ns = (int)(sizeof sub / sizeof sub[0]);
    for (int i = 0; i < ns; i++)
        for (int j = 0; j < ns; j++)
            for (int s = 0; s < 3; s++) {
                cbvh_f32 lb = sub[i] | (s >= 1 ? CBVH_F32_SIGN : 0), ub = sub[j] | (s == 2 ? CBVH_F32_SIGN : 0);
                if (cbvh_f32_key(lb) > cbvh_f32_key(ub)) { cbvh_f32 t = lb; lb = ub; ub = t; }
                chains_all_params(lb, ub, &r);
                for (int e = CBVH_SCALE_FLOOR; e <= -100; e++) {
                    cbvh_axis_code c;
                    compress_checked(&P6_126, lb, ub, e, &c);
                }
            }
    /* at the finest grid a positive subnormal lies in cell 0, a negative one in cell -1 */
    cbvh_axis_code c;
    compress_checked(&P6_126, 0x00000001u, 0x00000001u, CBVH_SCALE_FLOOR, &c);
    CHECK(c.clb == 0 && c.cub == 0x00800000u, "min subnormal at 2^-126: [%08x,%08x]", c.clb, c.cub);
    compress_checked(&P6_126, 0x80000001u, 0x80000001u, CBVH_SCALE_FLOOR, &c);
    CHECK(c.clb == 0x80800000u && c.cub == 0 && c.lb_mod == 63, "-min subnormal at 2^-126: [%08x,%08x] mod %u", c.clb,
          c.cub, c.lb_mod);
    return 0;
}

static int case_largest_finite(void) {
    prng r = {5};
    const cbvh_f32 M = CBVH_F32_MAX, NM = CBVH_F32_SIGN | CBVH_F32_MAX;
    const cbvh_f32 lbs[] = {NM, ulps(NM, 1), fb(-0x1p127f), fb(-1.0f), fb(0x1p127f), M};
    const cbvh_f32 ubs[] = {M, ulps(M, -1), fb(0x1p127f), fb(1.0f), fb(-0x1p127f), NM};
    for (size_t i = 0; i < sizeof lbs / sizeof lbs[0]; i++)
        for (size_t j = 0; j < sizeof ubs / sizeof ubs[0]; j++) {
            if (cbvh_f32_key(lbs[i]) > cbvh_f32_key(ubs[j])) continue;
            chains_all_params(lbs[i], ubs[j], &r);
        }
    /* the 2^128 grid point: RU -> +Inf, RD -> -Inf; contexts carry -Inf as -2^128 */
    for (int n = CBVH_N_MIN; n <= CBVH_N_MAX; n++) {
        cbvh_params p = {n, CBVH_MIN_SCALE_DEFAULT};
        cbvh_axis_code c;
        compress_checked(&p, M, M, 126, &c);
        /* floor(FLT_MAX / 2^126) = 3: l 2^126 = 2^128 -> +Inf */
        CHECK(c.cub == CBVH_F32_POS_INF && c.clb == fb(0x1.8p127f), "FLT_MAX at 2^126: [%08x,%08x]", c.clb, c.cub);
        compress_checked(&p, NM, NM, 126, &c);
        CHECK(c.clb == CBVH_F32_NEG_INF && c.cub == fb(-0x1.8p127f), "-FLT_MAX at 2^126: [%08x,%08x]", c.clb, c.cub);
        CHECK(c.lb_mod == ((uint32_t)-4 & ((1u << n) - 1u)), "-FLT_MAX lb_mod %u", c.lb_mod);
        compress_checked(&p, M, M, 100, &c); /* l * 2^100 = 2^128 exactly */
        CHECK(c.cub == CBVH_F32_POS_INF, "FLT_MAX at 2^100: cub %08x", c.cub);
        compress_checked(&p, M, M, 103, &c); /* FLT_MAX = (2^24-1) 2^104: l 2^103 = FLT_MAX + 2^103 -> +Inf */
        CHECK(c.cub == CBVH_F32_POS_INF, "FLT_MAX at 2^103: cub %08x", c.cub);
        compress_checked(&p, M, M, 104, &c); /* l 2^104 = 2^128 exactly */
        CHECK(c.cub == CBVH_F32_POS_INF, "FLT_MAX at 2^104: cub %08x", c.cub);
        compress_checked(&p, M, M, 80, &c); /* l 2^80 = FLT_MAX + 2^80 rounds up past FLT_MAX */
        CHECK(c.cub == CBVH_F32_POS_INF && c.clb == M, "FLT_MAX at 2^80: [%08x,%08x]", c.clb, c.cub);
        /* a node whose decoded lower bound is -Inf (= -2^128) still decodes its children exactly */
        cbvh_axis_ctx ctx = root_checked(&p, NM, fb(-1e38f));
        CHECK(ctx.clb == CBVH_F32_NEG_INF, "root [-FLT_MAX,-1e38]: clb %08x, expected -Inf", ctx.clb);
        cbvh_axis_code k;
        child_checked(&p, &ctx, NM, ulps(NM, 5), &k);
        child_checked(&p, &ctx, fb(-2e38f), fb(-1.5e38f), &k);
        CHECK(!cbvh_f32_is_nan_or_inf(k.clb), "child far above -2^128 decodes to a finite clb (%08x)", k.clb);
    }
    return 0;
}

static int case_min_scale_saturation(void) {
    prng r = {6};
    const int mins[] = {CBVH_SCALE_FLOOR, CBVH_MIN_SCALE_DEFAULT, -5, 0, 20};
    for (size_t m = 0; m < sizeof mins / sizeof mins[0]; m++)
        for (int n = CBVH_N_MIN; n <= CBVH_N_MAX; n++) {
            cbvh_params p = {n, mins[m]};
            /* boxes far narrower than 2^min_scale: root and every child saturate */
            const cbvh_f32 lbs[] = {fb(1.0f), fb(-0.4f), fb(1e-30f), fb(3e7f), 0x00000010u};
            for (size_t i = 0; i < sizeof lbs / sizeof lbs[0]; i++) {
                cbvh_f32 lb = lbs[i], ub = ulps(lbs[i], 3);
                if (cbvh_f32_key(lb) > cbvh_f32_key(ub)) { cbvh_f32 t = lb; lb = ub; ub = t; }
                int est;
                cbvh_scale_estimate(&p, lb, ub, &est);
                cbvh_axis_ctx ctx = root_checked(&p, lb, ub);
                /* clamp on the root: both root scales are >= min_scale, the
                 * child scale never exceeds its parent (Fig. 4 shift >= 0) */
                CHECK(est >= p.min_scale && ctx.parent_scale == est, "root scale %d vs estimate %d", ctx.parent_scale,
                      est);
                int natural = (int)floor(log2(f32_as_double(ub) - f32_as_double(lb))) - n;
                if (natural < p.min_scale - 2)
                    CHECK(ctx.parent_scale == p.min_scale && ctx.scale == p.min_scale,
                          "tiny root [%08x,%08x] N=%d: scales %d/%d, expected saturation at %d", lb, ub, n,
                          ctx.parent_scale, ctx.scale, p.min_scale);
                for (int d = 0; d < 6; d++) {
                    cbvh_f32 a = prop_point_in(&r, lb, ub), b = prop_point_in(&r, lb, ub);
                    if (cbvh_f32_key(a) > cbvh_f32_key(b)) { cbvh_f32 t = a; a = b; b = t; }
                    cbvh_axis_code c;
                    child_checked(&p, &ctx, a, b, &c);
                    CHECK(c.child_scale >= p.min_scale && c.child_scale <= ctx.scale,
                          "child scale %d outside [min %d, parent %d]", c.child_scale, p.min_scale, ctx.scale);
                    ctx = cbvh_axis_child_ctx(&ctx, &c);
                    lb = a;
                    ub = b;
                }
            }
            chains_all_params(fb(1.0f), fb(1.0f + 0x1p-20f), &r);
            /* scales below min_scale are rejected, outputs zero */
            cbvh_axis_code c, zero = {0, 0, 0, 0, 0};
            if (p.min_scale > CBVH_SCALE_FLOOR) {
                uint32_t st = cbvh_axis_compress(&p, fb(1.0f), fb(2.0f), p.min_scale - 1, 0, &c);
                digest_code(&dg, st, &c);
                CHECK(st == CBVH_ST_BAD_SCALE && code_equal(&c, &zero), "compress below min_scale: st %#x", st);
                cbvh_axis_ctx bad = {p.min_scale, p.min_scale - 1, 0, 0};
                st = cbvh_axis_decode(&p, CBVH_ENC_MODULO, &bad, 0, 1, &c);
                CHECK(st == CBVH_ST_BAD_SCALE && code_equal(&c, &zero), "decode below min_scale: st %#x", st);
            }
            cbvh_axis_ctx inv = {p.min_scale, p.min_scale + 1, 0, 0}; /* child coarser than parent */
            uint32_t st = cbvh_axis_decode(&p, CBVH_ENC_MODULO, &inv, 0, 1, &c);
            CHECK(st == CBVH_ST_BAD_SCALE && code_equal(&c, &zero), "decode with scale > parent_scale: st %#x", st);
        }
    return 0;
}

static int case_every_n(void) {
    prng r = {7};
    for (int n = CBVH_N_MIN; n <= CBVH_N_MAX; n++) {
        int w = cbvh_node_bits(n), pb = cbvh_node_ptr_bits(n);
        CHECK(w == (n <= 6 ? 64 : 96) && cbvh_nodepair_bytes(n) == (size_t)(w / 4), "N=%d: node bits %d", n, w);
        CHECK(pb == (w - 6 * n - 1 > 32 ? 32 : w - 6 * n - 1) && pb >= 27, "N=%d: pointer bits %d", n, pb);
        for (int i = 0; i < 2000; i++) {
            cbvh_f32 lb = prop_random_float(&r), ub = prop_random_float(&r);
            if (cbvh_f32_key(lb) > cbvh_f32_key(ub)) { cbvh_f32 t = lb; lb = ub; ub = t; }
            cbvh_params p = {n, i & 1 ? CBVH_SCALE_FLOOR : CBVH_MIN_SCALE_DEFAULT};
            chain_checked(&p, lb, ub, &r, 6);
            /* N bits fit the node box: at the root's own scale the box spans <= 2^N cells */
            int e;
            cbvh_scale_estimate(&p, lb, ub, &e);
            cbvh_axis_code c;
            CHECK(compress_checked(&p, lb, ub, e, &c) == 0, "N=%d: root box NO_FIT at its estimated scale", n);
        }
        /* node pairs: largest pointers, leaf/inner/empty, both encodings */
        cbvh_params p = {n, CBVH_MIN_SCALE_DEFAULT};
        cbvh_node_ctx ctx;
        for (int a = 0; a < 3; a++) ctx.axis[a] = root_checked(&p, fb(-3.0f), fb(5.0f));
        uint32_t ones = pb >= 32 ? 0xFFFFFFFFu : (1u << pb) - 1u;
        for (int k = 0; k < 6; k++) {
            cbvh_child_in in[2];
            memset(in, 0, sizeof in);
            for (int c = 0; c < 2; c++) {
                for (int a = 0; a < 3; a++) { in[c].lo[a] = fb(-1.0f - (float)c); in[c].hi[a] = fb(2.5f + (float)k * 0.25f); }
                in[c].leaf = (k + c) & 1;
                in[c].ptr = in[c].leaf ? ones - 1u : ones;
                in[c].empty = k == 5 && c == 1;
            }
            for (int enc = 0; enc < 2; enc++) {
                uint8_t bytes[24];
                cbvh_child_out eo[2], dout[2];
                uint32_t st = cbvh_nodepair_encode(&p, (cbvh_encoding)enc, &ctx, in, bytes, eo);
                uint32_t dst = cbvh_nodepair_decode(&p, (cbvh_encoding)enc, &ctx, bytes, dout);
                for (size_t b = 0; b < cbvh_nodepair_bytes(n); b++) digest_u32(&dg, bytes[b]);
                CHECK(st == 0 && dst == 0 && memcmp(eo, dout, sizeof eo) == 0, "N=%d: node pair round trip (st %#x/%#x)",
                      n, st, dst);
                for (int c = 0; c < 2; c++)
                    CHECK(dout[c].ptr == (in[c].empty ? ones : in[c].ptr) && dout[c].empty == in[c].empty,
                          "N=%d: pointer/empty not preserved", n);
            }
            /* a leaf with the all-ones pointer would read back as empty: rejected */
            in[0].leaf = 1;
            in[0].empty = 0;
            in[0].ptr = ones;
            uint8_t bytes[24];
            cbvh_child_out eo[2];
            CHECK(cbvh_nodepair_encode(&p, CBVH_ENC_MODULO, &ctx, in, bytes, eo) & CBVH_ST_BAD_FORMAT,
                  "N=%d: leaf with the empty marker pointer accepted", n);
        }
        /* an empty child's codes must all be 0: any single code bit set, of
         * either child, makes the pair BAD_FORMAT (each code field checked) */
        for (int c = 0; c < 2; c++)
            for (int bit = 0; bit < 6 * n; bit++) {
                cbvh_child_in in[2];
                memset(in, 0, sizeof in);
                in[0].empty = in[1].empty = 1;
                uint8_t bytes[24];
                cbvh_child_out out[2];
                uint32_t st = cbvh_nodepair_encode(&p, CBVH_ENC_MODULO, &ctx, in, bytes, out);
                CHECK(st == 0, "N=%d: two empty children: st %#x", n, st);
                int at = c * w + bit;
                bytes[at / 8] |= (uint8_t)(1u << (at % 8));
                st = cbvh_nodepair_decode(&p, CBVH_ENC_MODULO, &ctx, bytes, out);
                CHECK(st & CBVH_ST_BAD_FORMAT, "N=%d: empty child %d with code bit %d set decoded (st %#x)", n, c, bit,
                      st);
            }
    }
    return 0;
}

static int case_nan_inf_rejected(void) {
    const cbvh_f32 bad[] = {CBVH_F32_POS_INF, CBVH_F32_NEG_INF, 0x7FC00000u, 0xFFC00000u, 0x7F800001u, 0xFFFFFFFFu};
    const cbvh_f32 good[] = {0, fb(1.0f), fb(-2.0f), CBVH_F32_MAX};
    cbvh_axis_code zero = {0, 0, 0, 0, 0};
    for (int n = CBVH_N_MIN; n <= CBVH_N_MAX; n++) {
        cbvh_params p = {n, CBVH_MIN_SCALE_DEFAULT};
        for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
            for (size_t j = 0; j < sizeof good / sizeof good[0]; j++)
                for (int side = 0; side < 3; side++) {
                    cbvh_f32 lb = side == 1 ? good[j] : bad[i], ub = side == 0 ? good[j] : bad[i];
                    int e = 77;
                    uint32_t st = cbvh_scale_estimate(&p, lb, ub, &e);
                    digest_u32(&dg, st);
                    CHECK(st == CBVH_ST_NAN_INF && e == 0, "scale_estimate(%08x,%08x): st %#x e %d", lb, ub, st, e);
                    cbvh_axis_code c;
                    st = cbvh_axis_compress(&p, lb, ub, 0, 0, &c);
                    digest_code(&dg, st, &c);
                    CHECK(st == CBVH_ST_NAN_INF && code_equal(&c, &zero), "compress(%08x,%08x): st %#x", lb, ub, st);
                    cbvh_axis_ctx ctx = {1, 2, 3, 4};
                    st = cbvh_axis_root_ctx(&p, lb, ub, &ctx);
                    CHECK(st == CBVH_ST_NAN_INF && ctx.parent_scale == 0 && ctx.scale == 0 && ctx.lb_mod == 0 &&
                              ctx.clb == 0,
                          "root_ctx(%08x,%08x): st %#x", lb, ub, st);
                    /* node pair with a NaN/Inf child: everything zero */
                    cbvh_node_ctx nctx;
                    for (int a = 0; a < 3; a++) cbvh_axis_root_ctx(&p, fb(-1.0f), fb(1.0f), &nctx.axis[a]);
                    cbvh_child_in in[2];
                    memset(in, 0, sizeof in);
                    for (int c2 = 0; c2 < 2; c2++)
                        for (int a = 0; a < 3; a++) { in[c2].lo[a] = fb(-0.5f); in[c2].hi[a] = fb(0.5f); }
                    in[1].lo[side % 3] = lb;
                    in[1].hi[side % 3] = side == 0 ? fb(0.5f) : ub;
                    if (cbvh_f32_is_nan_or_inf(in[1].lo[side % 3]) || cbvh_f32_is_nan_or_inf(in[1].hi[side % 3])) {
                        uint8_t bytes[24];
                        memset(bytes, 0xAB, sizeof bytes);
                        cbvh_child_out out[2];
                        st = cbvh_nodepair_encode(&p, CBVH_ENC_MODULO, &nctx, in, bytes, out);
                        static const uint8_t zb[24];
                        static const cbvh_child_out zo[2];
                        CHECK((st & CBVH_ST_NAN_INF) && memcmp(bytes, zb, cbvh_nodepair_bytes(n)) == 0 &&
                                  memcmp(out, zo, sizeof zo) == 0,
                              "nodepair encode with NaN/Inf: st %#x, outputs not zero", st);
                    }
                }
        /* decoder: a context lower bound of +Inf or NaN is rejected, -Inf is -2^128 */
        for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
            cbvh_axis_ctx ctx = {0, -5, 1, bad[i]};
            cbvh_axis_code c;
            uint32_t st = cbvh_axis_decode(&p, CBVH_ENC_RELATIVE, &ctx, 0, 1, &c);
            digest_code(&dg, st, &c);
            if (bad[i] == CBVH_F32_NEG_INF)
                CHECK(st == 0 && c.clb == CBVH_F32_NEG_INF && c.cub == (CBVH_F32_SIGN | CBVH_F32_MAX),
                      "decode with clb -Inf: st %#x [%08x,%08x], expected [-Inf,-FLT_MAX]", st, c.clb, c.cub);
            else
                CHECK(st == CBVH_ST_NAN_INF && code_equal(&c, &zero), "decode with clb %08x: st %#x", bad[i], st);
        }
    }
    return 0;
}

static const struct {
    const char *name;
    int (*fn)(void);
} cases[] = {
    {"cloth_plane", case_cloth_plane},
    {"far_from_origin", case_far_from_origin},
    {"straddling_zero", case_straddling_zero},
    {"signed_zero", case_signed_zero},
    {"subnormals", case_subnormals},
    {"largest_finite", case_largest_finite},
    {"min_scale_saturation", case_min_scale_saturation},
    {"every_n", case_every_n},
    {"nan_inf_rejected", case_nan_inf_rejected},
};

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: %s CASE\ncases:", argv[0]);
        for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) fprintf(stderr, " %s", cases[i].name);
        fputc('\n', stderr);
        return 2;
    }
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        if (strcmp(argv[1], cases[i].name) == 0) {
            digest_init(&dg);
            cases[i].fn();
            if (n_checks == 0) prop_fail("no checks ran");
            return prop_finish(cases[i].name, &dg, n_checks, NULL);
        }
    fprintf(stderr, "error: unknown case '%s'\n", argv[1]);
    return 2;
}
